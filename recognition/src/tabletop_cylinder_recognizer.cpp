/*
 * facyl: fast cylinder detection for PCL.
 * Explicit instantiations for the common point types.
 */
#include <facyl/recognition/impl/tabletop_cylinder_recognizer.hpp>

#include <cmath>
#include <sstream>

namespace facyl {

std::string
validate(const TabletopRecognizerParameters& p)
{
  std::string why = validate(p.segmentation);
  if (!why.empty())
    return "segmentation: " + why;
  why = validate(p.hough);
  if (!why.empty())
    return "fit: " + why;
  std::ostringstream s;
  if (p.orientations < 10)
    s << "orientations " << p.orientations << " must be >= 10";
  else if (p.max_fit_points < 50)
    s << "max_fit_points " << p.max_fit_points << " must be >= 50";
  else if (p.neighbours < 5)
    s << "neighbours " << p.neighbours << " must be >= 5";
  else if (!(p.min_inlier_ratio >= 0.f && p.min_inlier_ratio <= 1.f))
    s << "min_inlier_ratio " << p.min_inlier_ratio << " must be in [0, 1]";
  else if (!(p.max_curvature_ratio > 0.f && p.max_curvature_ratio <= 1.f))
    s << "max_curvature_ratio " << p.max_curvature_ratio << " must be in (0, 1]";
  else if (!(p.min_angular_coverage >= 0.f && p.min_angular_coverage <= 1.f))
    s << "min_angular_coverage " << p.min_angular_coverage << " must be in [0, 1]";
  else if (!(p.min_probability >= 0.f && p.min_probability <= 1.f))
    s << "min_probability " << p.min_probability << " must be in [0, 1]";
  return s.str();
}

namespace {
/** Counts the columns of \a points that are not in model.inliers (ascending) and satisfy
 * \a test(i, d, t): d = point - base, t = its coordinate along the unit axis. */
template <typename Test>
std::size_t
countOutliers(const CylinderModel& model, const Eigen::Matrix3Xf& points, Test test)
{
  const Eigen::Vector3f a = model.axis.normalized();
  std::size_t count = 0, next = 0;
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    while (next < model.inliers.size() && model.inliers[next] < i)
      ++next;
    if (next < model.inliers.size() && model.inliers[next] == i)
      continue;
    const Eigen::Vector3f d = points.col(i) - model.base;
    count += test(i, d, d.dot(a), a);
  }
  return count;
}
} // namespace

std::size_t
countCapPoints(const CylinderModel& model, const Eigen::Matrix3Xf& points,
               const Eigen::Matrix3Xf& normals, float distance, float max_angle)
{
  const float cos_max = std::cos(max_angle);
  const float h = (model.top - model.base).dot(model.axis.normalized());
  return countOutliers(model, points, [&](Eigen::Index i, const Eigen::Vector3f& d, float t,
                                          const Eigen::Vector3f& a) {
    const bool on_plane = std::abs(t) <= distance || std::abs(t - h) <= distance;
    return on_plane && (d - t * a).norm() <= model.radius + distance &&
           std::abs(normals.col(i).dot(a)) >= cos_max;
  });
}

std::size_t
countInnerWallPoints(const CylinderModel& model, const Eigen::Matrix3Xf& points,
                     const Eigen::Matrix3Xf& normals, float max_angle, float inner_ratio)
{
  const float cos_max = std::cos(max_angle);
  const float h = (model.top - model.base).dot(model.axis.normalized());
  return countOutliers(model, points, [&](Eigen::Index i, const Eigen::Vector3f& d, float t,
                                          const Eigen::Vector3f& a) {
    const Eigen::Vector3f radial = d - t * a;
    const float rho = radial.norm();
    if (t < 0.f || t > h || rho > model.radius || rho < inner_ratio * model.radius || !(rho > 0.f))
      return false;
    return -normals.col(i).dot(radial) >= cos_max * rho; // the normal points at the axis
  });
}

pcl::Indices
evenSubsample(const pcl::Indices& indices, std::size_t max_count)
{
  if (indices.size() <= max_count)
    return indices;
  pcl::Indices out;
  if (max_count == 0)
    return out;
  out.reserve(max_count);
  const double step = static_cast<double>(indices.size()) / static_cast<double>(max_count);
  for (std::size_t k = 0; k < max_count; ++k)
    out.push_back(indices[static_cast<std::size_t>(static_cast<double>(k) * step)]);
  return out;
}

} // namespace facyl

FACYL_INSTANTIATE_TabletopCylinderRecognizer(pcl::PointXYZ)
FACYL_INSTANTIATE_TabletopCylinderRecognizer(pcl::PointXYZRGB)
FACYL_INSTANTIATE_TabletopCylinderRecognizer(pcl::PointXYZRGBA)
