/*
 * facyl: fast cylinder detection for PCL.
 */
#include <facyl/simulation/cylinder_simulation.h>
#include <facyl/simulation/random.h>

#include <Eigen/Geometry>

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace facyl {

std::string
validate(const CylinderSimulationParameters& p)
{
  std::ostringstream why;
  if (!(p.radius > 0.f) || !std::isfinite(p.radius))
    why << "radius " << p.radius << " must be positive";
  else if (!(p.height > 0.f) || !std::isfinite(p.height))
    why << "height " << p.height << " must be positive";
  else if (!p.random_axis && (!p.axis.allFinite() || !(p.axis.norm() > 0.f)))
    why << "axis must be finite and non-zero";
  else if (!p.base.allFinite())
    why << "base must be finite";
  else if (!(p.lid_ratio >= 0.f) || !std::isfinite(p.lid_ratio))
    why << "lid ratio " << p.lid_ratio << " must be >= 0";
  else if (!(p.noise >= 0.f) || !std::isfinite(p.noise))
    why << "noise " << p.noise << " must be >= 0";
  else if (!(p.occlusion >= 0.f && p.occlusion < 1.f))
    why << "occlusion " << p.occlusion << " must be in [0, 1)";
  return why.str();
}

namespace {
pcl::PointNormal
makePoint(const Eigen::Vector3f& p, const Eigen::Vector3f& n)
{
  pcl::PointNormal q;
  q.getVector3fMap() = p;
  q.getNormalVector3fMap() = n;
  q.curvature = 0.f;
  return q;
}
/** Three standard normal deviates, drawn in order (the order of a constructor's arguments'
 * evaluation is unspecified). */
Eigen::Vector3f
gaussian3(Random& rng)
{
  Eigen::Vector3f g;
  g.x() = rng.normal();
  g.y() = rng.normal();
  g.z() = rng.normal();
  return g;
}
} // namespace

SimulatedCylinder
simulateCylinder(const CylinderSimulationParameters& params)
{
  const std::string why = validate(params);
  if (!why.empty())
    throw std::invalid_argument("facyl::simulateCylinder: " + why);
  Random rng(params.seed);

  Eigen::Vector3f axis = params.axis;
  if (params.random_axis)
    do
      axis = gaussian3(rng);
    while (!(axis.norm() > 1e-6f));
  axis.normalize();
  const Eigen::Vector3f u = axis.unitOrthogonal(), v = axis.cross(u);
  const float r = params.radius, h = params.height, sigma = params.noise * r;
  const auto noisy = [&](const Eigen::Vector3f& p) {
    return sigma > 0.f ? Eigen::Vector3f(p + sigma * gaussian3(rng)) : p;
  };

  SimulatedCylinder out;
  const float visible = 1.f - params.occlusion;
  const auto lateral = static_cast<std::size_t>(std::lround(visible * params.lateral_points));
  const float sector = 2.f * static_cast<float>(M_PI) * visible;
  for (std::size_t i = 0; i < lateral; ++i) {
    const float theta = sector * rng.uniform(0.f, 1.f);
    const Eigen::Vector3f radial = std::cos(theta) * u + std::sin(theta) * v;
    const Eigen::Vector3f p = params.base + h * rng.uniform(0.f, 1.f) * axis + r * radial;
    out.cloud.push_back(makePoint(noisy(p), radial));
    out.is_lid.push_back(0);
  }
  const auto lids = static_cast<std::size_t>(std::lround(params.lid_ratio * params.lateral_points));
  for (std::size_t i = 0; i < lids; ++i) {
    const bool top = (i % 2) == 1;
    const float rho = r * std::sqrt(rng.uniform(0.f, 1.f));
    const float theta = 2.f * static_cast<float>(M_PI) * rng.uniform(0.f, 1.f);
    const Eigen::Vector3f p =
      params.base + (top ? h : 0.f) * axis + rho * (std::cos(theta) * u + std::sin(theta) * v);
    out.cloud.push_back(makePoint(noisy(p), top ? axis : Eigen::Vector3f(-axis)));
    out.is_lid.push_back(1);
  }
  out.cloud.width = static_cast<std::uint32_t>(out.cloud.size());
  out.cloud.height = 1;
  out.cloud.is_dense = true;
  out.truth.base = params.base;
  out.truth.axis = axis;
  out.truth.radius = r;
  out.truth.height = h;
  out.truth.lateral_points = lateral;
  out.truth.lid_points = lids;
  return out;
}

pcl::PointCloud<pcl::PointNormal>
simulatePlane(const Eigen::Vector3f& centre, const Eigen::Vector3f& normal, float size_u,
              float size_v, std::size_t points, float sigma, std::uint64_t seed)
{
  if (!(size_u > 0.f) || !(size_v > 0.f) || !std::isfinite(size_u) || !std::isfinite(size_v))
    throw std::invalid_argument("facyl::simulatePlane: sizes must be positive");
  if (!normal.allFinite() || !(normal.norm() > 0.f) || !centre.allFinite())
    throw std::invalid_argument("facyl::simulatePlane: centre and normal must be finite, "
                                "normal non-zero");
  if (!(sigma >= 0.f))
    throw std::invalid_argument("facyl::simulatePlane: sigma must be >= 0");
  Random rng(seed);
  const Eigen::Vector3f n = normal.normalized();
  const Eigen::Vector3f u = n.unitOrthogonal(), v = n.cross(u);
  pcl::PointCloud<pcl::PointNormal> cloud;
  for (std::size_t i = 0; i < points; ++i) {
    const float a = rng.uniform(-0.5f, 0.5f);
    const float b = rng.uniform(-0.5f, 0.5f);
    Eigen::Vector3f p = centre + size_u * a * u + size_v * b * v;
    if (sigma > 0.f)
      p += sigma * gaussian3(rng);
    cloud.push_back(makePoint(p, n));
  }
  cloud.width = static_cast<std::uint32_t>(cloud.size());
  cloud.height = 1;
  return cloud;
}

} // namespace facyl
