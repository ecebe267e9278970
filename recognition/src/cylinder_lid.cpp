/*
 * facyl: fast cylinder detection for PCL.
 */
#include <facyl/features/polygon.h>
#include <facyl/recognition/cylinder_evidence.h>
#include <facyl/recognition/cylinder_lid.h>
#include <facyl/sample_consensus_alt/cylinder_fitting.h>

#include "median.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace facyl {

namespace {

using detail::medianOf;

/** The circle through the outline \a hull's vertices: fitCircleAlgebraic, then fitCircle within
 * \a band; false unless 3 vertices lie within \a band of it. */
bool
circleOfOutline(const std::vector<Eigen::Vector2f>& hull, float band, Circle& circle)
{
  Eigen::Matrix2Xf vertices(2, static_cast<Eigen::Index>(hull.size()));
  for (std::size_t k = 0; k < hull.size(); ++k)
    vertices.col(static_cast<Eigen::Index>(k)) = hull[k];
  if (!fitCircleAlgebraic(vertices, circle) || !fitCircle(vertices, band, circle))
    return false;
  std::size_t on_circle = 0;
  for (const auto& v : hull)
    on_circle += std::abs((v - circle.center).norm() - circle.radius) <= band;
  return on_circle >= 3;
}

/** Three robust sigmas of the noise of a lid's \a dense points within \a spread of its \a level
 * (their heights by \a height, their places in the plane along \a e1, \a e2): adjacentNoise
 * of pixels beside each other within \a reach; 0 with fewer than \a min_pairs such pairs. */
template <typename Height>
float
ownBand(const Eigen::Matrix3Xf& dense, Height height, float level, float spread,
        const Eigen::Vector3f& e1, const Eigen::Vector3f& e2, float reach, std::size_t min_pairs)
{
  if (dense.cols() < 2)
    return 0.f;
  std::vector<float> h;
  std::vector<Eigen::Vector2f> xy;
  for (Eigen::Index i = 0; i < dense.cols(); ++i) {
    const Eigen::Vector3f p = dense.col(i);
    h.push_back(p.allFinite() && std::abs(height(p) - level) <= spread
                  ? height(p)
                  : std::numeric_limits<float>::quiet_NaN());
    xy.emplace_back(e1.dot(p), e2.dot(p));
  }
  const float sigma = adjacentNoise(h, xy, reach, min_pairs);
  return std::isfinite(sigma) ? 3.f * sigma : 0.f;
}

} // namespace

float
adjacentNoise(const std::vector<float>& heights, const std::vector<Eigen::Vector2f>& xy,
              float reach, std::size_t min_pairs)
{
  std::vector<float> d;
  for (std::size_t k = 1; k < heights.size() && k < xy.size(); ++k)
    if (std::isfinite(heights[k]) && std::isfinite(heights[k - 1]) &&
        (xy[k] - xy[k - 1]).norm() <= reach)
      d.push_back(std::abs(heights[k] - heights[k - 1]));
  if (d.size() < std::max<std::size_t>(1, min_pairs))
    return std::numeric_limits<float>::quiet_NaN();
  return 1.4826f * medianOf(d) / std::sqrt(2.f);
}

LidFit
fitLid(const Eigen::Matrix3Xf& points, const Eigen::Matrix3Xf& normals,
       const Eigen::Vector4f& support, const Eigen::Vector3f& up, const LidSettings& s,
       const Eigen::Matrix3Xf& dense)
{
  LidFit out;
  const Eigen::Vector3f u = up.normalized();
  const Eigen::Vector3f n = support.head<3>();
  const float side = u.dot(n) >= 0.f ? 1.f : -1.f; // heights grow towards the objects
  const float along = side * u.dot(n);             // height per metre along up
  if (!(along > 0.1f) || normals.cols() != points.cols() || !(s.rim_spacings > 0.f))
    return out;
  const auto height = [&](const Eigen::Vector3f& p) { return side * (n.dot(p) + support[3]); };
  // Flat points above the support.
  const float cos_max = std::cos(s.max_normal_angle);
  std::vector<Eigen::Index> flat;
  std::vector<float> h;
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    const Eigen::Vector3f nn = normals.col(i);
    if (!nn.allFinite() || !points.col(i).allFinite() || std::abs(nn.dot(u)) < cos_max)
      continue;
    const float hi = height(points.col(i));
    if (hi > 0.f)
      flat.push_back(i), h.push_back(hi);
  }
  if (flat.size() < s.min_points)
    return out;
  // The lid's level: the flat points' median height, its band from their spread (at least a
  // quarter of their spacing in the plane, the spacing of all flat points to begin with).
  const float level = medianOf(h);
  std::vector<float> dev(h.size());
  for (std::size_t k = 0; k < h.size(); ++k)
    dev[k] = std::abs(h[k] - level);
  const Eigen::Vector3f e1 = u.unitOrthogonal(), e2 = u.cross(e1);
  const auto spacing = [](const std::vector<Eigen::Vector2f>& hull, std::size_t count) {
    return std::sqrt(polygonArea(hull) / static_cast<float>(std::max<std::size_t>(1, count)));
  };
  std::vector<Eigen::Vector2f> flat2;
  for (const auto i : flat)
    flat2.emplace_back(e1.dot(points.col(i)), e2.dot(points.col(i)));
  const float spread = 3.f * 1.4826f * medianOf(dev);
  const float flat_spacing = spacing(convexHull2D(flat2), flat2.size());
  // The sensor's noise on the lid itself (a dark or glossy lid returns less light than its
  // support and is noisier): from the dense points near its level, pixel beside pixel.
  const float own = ownBand(dense, height, level, spread, e1, e2, flat_spacing, s.min_points);
  // The spread is measured on the flat points alone (a median absolute deviation of n
  // values: relative standard error 1.167 / sqrt(n) for normal noise): a lid is flatter than the
  // band unless its spread exceeds it by two standard errors.
  const float allowed =
    std::max(s.max_band, own) * (1.f + 2.f * 1.167f / std::sqrt(static_cast<float>(flat.size())));
  if (!(spread <= allowed))
    return out;
  const float band = std::max(spread, 0.25f * flat_spacing);
  // The lid's points in the support's plane: of the dense points when given (the outline to
  // their spacing), else of the flat ones.
  pcl::Indices lid;
  std::size_t kept = 0;
  for (std::size_t k = 0; k < flat.size(); ++k)
    if (dev[k] <= band) {
      flat2[kept++] = flat2[k];
      lid.push_back(static_cast<pcl::index_t>(flat[k]));
    }
  flat2.resize(kept);
  if (lid.size() < s.min_points)
    return out;
  if (dense.cols() > 0) {
    flat2.clear();
    for (Eigen::Index i = 0; i < dense.cols(); ++i) {
      const Eigen::Vector3f p = dense.col(i);
      if (p.allFinite() && std::abs(height(p) - level) <= band)
        flat2.emplace_back(e1.dot(p), e2.dot(p));
    }
    if (flat2.size() < s.min_points)
      return out;
  }
  // Its circle, from the outline: the convex hull's vertices lie on the rim, or where an
  // occluder's cut meets it.
  const std::vector<Eigen::Vector2f> hull = convexHull2D(flat2);
  if (hull.size() < 3)
    return out;
  out.rim_band = s.rim_spacings * spacing(hull, flat2.size());
  Circle circle;
  if (!circleOfOutline(hull, out.rim_band, circle) ||
      !(circle.radius >= s.min_radius && circle.radius <= s.max_radius))
    return out;
  // The rim seen, and what lies beyond it.
  const int sectors = std::max(4, s.sectors);
  std::vector<std::uint8_t> seen(static_cast<std::size_t>(sectors), 0);
  std::size_t outside = 0;
  for (const auto& q : flat2) {
    const Eigen::Vector2f d = q - circle.center;
    const float rho = d.norm();
    outside += rho > circle.radius + out.rim_band;
    if (std::abs(rho - circle.radius) <= out.rim_band)
      seen[circleSector(d.x(), d.y(), sectors)] = 1;
  }
  // The cylinder: from the support up to the lid.
  CylinderModel& m = out.model;
  const Eigen::Vector3f in_plane = e1 * circle.center.x() + e2 * circle.center.y();
  m.axis = u;
  m.base = in_plane - u * (height(in_plane) / along);
  m.top = m.base + u * (level / along);
  m.point_on_axis = m.base;
  m.height = (m.top - m.base).norm();
  m.radius = circle.radius;
  m.inliers = std::move(lid);
  m.inlier_ratio = 0.f;
  m.distance_threshold = band;
  double sq = 0.0;
  for (const float d : dev)
    if (d <= band)
      sq += static_cast<double>(d) * d;
  m.rms_error = static_cast<float>(std::sqrt(sq / static_cast<double>(m.inliers.size())));
  out.lid_points = m.inliers.size();
  out.rim_coverage =
    static_cast<float>(std::count(seen.begin(), seen.end(), 1)) / static_cast<float>(sectors);
  m.angular_coverage = out.rim_coverage;
  out.outside_share = static_cast<float>(outside) / static_cast<float>(flat2.size());
  out.found = out.rim_coverage >= s.min_rim_coverage;
  return out;
}

float
seenThroughShare(const Eigen::Matrix3Xf& seen, const CylinderModel& lid, float rim_band,
                 float depth_band)
{
  const Eigen::Vector3f a = lid.axis.normalized();
  const float plane = a.dot(lid.top); // the lid's plane: a . y = plane
  std::size_t crossing = 0, through = 0;
  for (Eigen::Index i = 0; i < seen.cols(); ++i) {
    const Eigen::Vector3f x = seen.col(i);
    const float along = a.dot(x);
    if (!x.allFinite() || std::abs(along) < 1e-6f)
      continue;
    const float t = plane / along; // the ray's point on the plane: t x
    if (!(t > 0.f))
      continue;
    const Eigen::Vector3f y = t * x - lid.top;
    if ((y - a * a.dot(y)).norm() > lid.radius - rim_band)
      continue;
    ++crossing;
    through += plane - along > depth_band; // x lies below the disc
  }
  return crossing == 0 ? std::numeric_limits<float>::quiet_NaN()
                       : static_cast<float>(through) / static_cast<float>(crossing);
}

float
walledShare(const Eigen::Matrix3Xf& seen, const CylinderModel& lid, float band)
{
  constexpr int sectors = 36;
  const Eigen::Vector3f a = lid.axis.normalized();
  const Eigen::Vector3f e1 = a.unitOrthogonal(), e2 = a.cross(e1);
  const float outer = lid.radius + std::max(3.f * band, 0.2f * lid.radius);
  std::vector<std::uint8_t> walled(sectors, 0);
  for (Eigen::Index i = 0; i < seen.cols(); ++i) {
    const Eigen::Vector3f d = seen.col(i) - lid.top;
    if (!d.allFinite() || a.dot(d) <= band)
      continue;
    const float x = e1.dot(d), y = e2.dot(d), rho = std::hypot(x, y);
    if (rho <= lid.radius + band || rho > outer)
      continue;
    walled[circleSector(x, y, sectors)] = 1;
  }
  return static_cast<float>(std::count(walled.begin(), walled.end(), 1)) / sectors;
}

} // namespace facyl
