/*
 * facyl: fast cylinder detection for PCL.
 */
#include <facyl/recognition/cylinder_evidence.h>

#include <algorithm>
#include <cmath>
#include <sstream>

namespace facyl {

std::string
validate(const CylinderDecision& d)
{
  std::ostringstream s;
  if (!(d.min_score >= 0.f && d.min_score <= 1.f))
    s << "min_score " << d.min_score << " must be in [0, 1]";
  else if (!(d.max_curvature_ratio > 0.f && d.max_curvature_ratio <= 1.f))
    s << "max_curvature_ratio " << d.max_curvature_ratio << " must be in (0, 1]";
  else if (!(d.min_angular_coverage >= 0.f && d.min_angular_coverage <= 1.f))
    s << "min_angular_coverage " << d.min_angular_coverage << " must be in [0, 1]";
  else if (!(d.min_probability >= 0.f && d.min_probability <= 1.f))
    s << "min_probability " << d.min_probability << " must be in [0, 1]";
  return s.str();
}

bool
acceptCylinder(const CylinderEvidence& e, const CylinderDecision& d)
{
  return e.fitted && !(e.p_cylinder < d.min_probability) && e.score(d) >= d.min_score &&
         !(e.curvature_ratio > d.max_curvature_ratio) &&
         e.angular_coverage >= d.min_angular_coverage;
}

float
curvatureRatio(const pcl::PointCloud<NormalCurvature>& cues, const pcl::Indices& inliers)
{
  std::vector<float> k_max, k_min;
  for (const auto i : inliers) {
    if (i < 0 || static_cast<std::size_t>(i) >= cues.size())
      continue;
    const auto& c = cues[static_cast<std::size_t>(i)];
    if (std::isfinite(c.pc1) && std::isfinite(c.pc2))
      k_max.push_back(std::abs(c.pc1)), k_min.push_back(std::abs(c.pc2));
  }
  if (k_max.empty())
    return std::numeric_limits<float>::quiet_NaN();
  const auto mid = static_cast<std::ptrdiff_t>(k_max.size() / 2);
  std::nth_element(k_max.begin(), k_max.begin() + mid, k_max.end());
  std::nth_element(k_min.begin(), k_min.begin() + mid, k_min.end());
  return k_max[mid] > 0.f ? k_min[mid] / k_max[mid] : 1.f;
}

namespace {
/** Position of \a p in the model's frame: coordinate along the unit axis from the base, and
 * the radial vector. */
struct AxialPosition {
  float t;
  Eigen::Vector3f radial;
};
AxialPosition
axial(const CylinderModel& m, const Eigen::Vector3f& p)
{
  const Eigen::Vector3f a = m.axis.normalized();
  const Eigen::Vector3f d = p - m.base;
  const float t = d.dot(a);
  return {t, d - t * a};
}
float
length(const CylinderModel& m)
{
  return (m.top - m.base).dot(m.axis.normalized());
}

/** Counts the columns of \a points not in model.inliers (ascending) for which test(i) holds. */
template <typename Test>
std::size_t
countOutliers(const CylinderModel& model, const Eigen::Matrix3Xf& points, Test test)
{
  std::size_t count = 0, next = 0;
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    while (next < model.inliers.size() && model.inliers[next] < i)
      ++next;
    if (next < model.inliers.size() && model.inliers[next] == i)
      continue;
    count += test(i);
  }
  return count;
}
} // namespace

bool
onCap(const CylinderModel& model, const Eigen::Vector3f& p, const Eigen::Vector3f& n,
      float distance, float cos_max)
{
  const AxialPosition x = axial(model, p);
  const float h = length(model);
  const bool on_plane = std::abs(x.t) <= distance || std::abs(x.t - h) <= distance;
  return on_plane && x.radial.norm() <= model.radius + distance &&
         std::abs(n.dot(model.axis.normalized())) >= cos_max;
}

bool
onInnerWall(const CylinderModel& model, const Eigen::Vector3f& p, const Eigen::Vector3f& n,
            float cos_max, float inner_ratio)
{
  const AxialPosition x = axial(model, p);
  const float rho = x.radial.norm();
  if (x.t < 0.f || x.t > length(model) || rho > model.radius ||
      rho < inner_ratio * model.radius || !(rho > 0.f))
    return false;
  return -n.dot(x.radial) >= cos_max * rho; // the normal points at the axis
}

std::size_t
countCapPoints(const CylinderModel& model, const Eigen::Matrix3Xf& points,
               const Eigen::Matrix3Xf& normals, float distance, float max_angle)
{
  const float cos_max = std::cos(max_angle);
  return countOutliers(model, points, [&](Eigen::Index i) {
    return onCap(model, points.col(i), normals.col(i), distance, cos_max);
  });
}

std::size_t
countInnerWallPoints(const CylinderModel& model, const Eigen::Matrix3Xf& points,
                     const Eigen::Matrix3Xf& normals, float max_angle, float inner_ratio)
{
  const float cos_max = std::cos(max_angle);
  return countOutliers(model, points, [&](Eigen::Index i) {
    return onInnerWall(model, points.col(i), normals.col(i), cos_max, inner_ratio);
  });
}

std::vector<std::uint8_t>
explainedPoints(const CylinderModel& model, const Eigen::Matrix3Xf& points,
                const Eigen::Matrix3Xf& normals, const ExplainSettings& s)
{
  const bool with_normals = normals.cols() == points.cols();
  const float cos_max = std::cos(s.max_angle), h = length(model), d = s.distance;
  std::vector<std::uint8_t> out(static_cast<std::size_t>(points.cols()), 0);
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    const AxialPosition x = axial(model, points.col(i));
    const float rho = x.radial.norm();
    const bool normal_known = with_normals && normals.col(i).allFinite();
    const Eigen::Vector3f n = normal_known ? Eigen::Vector3f(normals.col(i)) : Eigen::Vector3f::Zero();
    bool lateral = std::abs(rho - model.radius) <= d && x.t >= -s.axial_margin &&
                   x.t <= h + s.axial_margin && rho > 0.f;
    if (lateral && normal_known) {
      const float along = n.dot(x.radial);
      lateral = (s.outward ? along : std::abs(along)) >= cos_max * rho;
    }
    bool cap = false, inner = false;
    if (!lateral) {
      const bool on_plane = std::abs(x.t) <= 2.f * d || std::abs(x.t - h) <= 2.f * d;
      cap = on_plane && rho <= model.radius + 2.f * d &&
            (!normal_known || std::abs(n.dot(model.axis.normalized())) >= cos_max);
      inner = s.inner_wall && x.t >= 0.f && x.t <= h && rho <= model.radius &&
              rho >= s.inner_ratio * model.radius &&
              (!normal_known || -n.dot(x.radial) >= cos_max * rho);
    }
    out[static_cast<std::size_t>(i)] = lateral || cap || inner;
  }
  return out;
}

} // namespace facyl
