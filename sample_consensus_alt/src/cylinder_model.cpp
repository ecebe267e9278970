/*
 * facyl: fast cylinder detection for PCL.
 * The cylinder model: distances, angles, and the description of a model from its inliers.
 */
#include "fitting_detail.h"

#include <facyl/sample_consensus_alt/cylinder_model.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace facyl {

using detail::basisFor;

void
CylinderModel::toCoefficients(pcl::ModelCoefficients& coefficients) const
{
  coefficients.values = {
    point_on_axis.x(), point_on_axis.y(), point_on_axis.z(), axis.x(), axis.y(), axis.z(), radius};
}

float
CylinderModel::signedDistance(const Eigen::Vector3f& p) const
{
  return distanceToLine(p, point_on_axis, axis) - radius;
}

float
axisAngle(const Eigen::Vector3f& a, const Eigen::Vector3f& b)
{
  // atan2 of |cross| and |dot| keeps precision at small angles, where acos(dot) rounds to 0.
  const Eigen::Vector3f u = a.normalized(), v = b.normalized();
  return std::atan2(u.cross(v).norm(), std::abs(u.dot(v)));
}

float
distanceToLine(const Eigen::Vector3f& p, const Eigen::Vector3f& point, const Eigen::Vector3f& axis)
{
  const Eigen::Vector3f w = p - point;
  return (w - w.dot(axis) * axis).norm();
}

void
describeInliers(const Eigen::Matrix3Xf& points, CylinderModel& m)
{
  m.axis = foldToHemisphere(m.axis.normalized());
  Eigen::Vector3f u, v;
  basisFor(m.axis, u, v);
  const Eigen::Vector3f origin = m.point_on_axis;
  float t_min = std::numeric_limits<float>::max(), t_max = -t_min;
  double sq = 0.0;
  std::vector<char> sectors(36, 0);
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    const Eigen::Vector3f w = points.col(i) - origin;
    const float t = w.dot(m.axis);
    const Eigen::Vector3f d = w - t * m.axis;
    t_min = std::min(t_min, t);
    t_max = std::max(t_max, t);
    const double e = d.norm() - m.radius;
    sq += e * e;
    const float angle = std::atan2(d.dot(v), d.dot(u)) + static_cast<float>(M_PI);
    sectors[std::min<std::size_t>(35, static_cast<std::size_t>(angle / (2 * M_PI) * 36))] = 1;
  }
  if (points.cols() == 0)
    t_min = t_max = 0.f;
  m.base = origin + t_min * m.axis;
  m.top = origin + t_max * m.axis;
  m.point_on_axis = m.base;
  m.height = t_max - t_min;
  m.rms_error = points.cols() == 0 ? 0.f : static_cast<float>(std::sqrt(sq / points.cols()));
  m.angular_coverage = static_cast<float>(std::count(sectors.begin(), sectors.end(), 1)) / 36.f;
}

std::vector<Eigen::Index>
endCapPoints(const Eigen::Matrix3Xf& points, const Eigen::Matrix3Xf& normals,
             const CylinderModel& model, float normal_angle)
{
  std::vector<Eigen::Index> caps;
  if (normals.cols() != points.cols() || !(model.radius > 0.f) || !model.axis.allFinite())
    return caps;
  const Eigen::Vector3f axis = model.axis.normalized();
  const float reach = model.radius + model.distance_threshold;
  const float cos_normal = std::cos(normal_angle);
  // Per end: the points of its disc, and how many lie on the ring around it out to
  // kRingReach times the reach (the same plane going on past the rim).
  constexpr float kRingReach = 1.5f;
  std::vector<Eigen::Index> disc[2];
  std::size_t ring[2] = {0, 0};
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    const Eigen::Vector3f w = points.col(i) - model.base;
    const float t = w.dot(axis);
    const int end = t > -model.radius && t < model.distance_threshold ? 0
                    : t > model.height - model.distance_threshold && t < model.height + model.radius
                      ? 1
                      : -1;
    if (end < 0 || !(std::abs(normals.col(i).dot(axis)) > cos_normal))
      continue;
    const float rho = (w - t * axis).norm();
    if (rho < reach)
      disc[end].push_back(i);
    else if (rho < kRingReach * reach)
      ++ring[end];
  }
  // A lid ends at the rim; a plane there goes on: an end whose ring is at least half as dense
  // as its disc is no lid.
  const float ring_area = kRingReach * kRingReach - 1.f; // in units of the disc's
  for (int end = 0; end < 2; ++end)
    if (static_cast<float>(ring[end]) < 0.5f * ring_area * static_cast<float>(disc[end].size()))
      caps.insert(caps.end(), disc[end].begin(), disc[end].end());
  std::sort(caps.begin(), caps.end());
  return caps;
}

void
orientCylinder(CylinderModel& model, const Eigen::Vector3f& up, const Eigen::Vector3f& viewpoint)
{
  const Eigen::Vector3f a = model.axis.normalized();
  const Eigen::Vector3f centre = 0.5f * (model.base + model.top);
  // Up decides unless the axis lies across it (a lying can), then the side of the viewer.
  float side = a.dot(up.normalized());
  if (!(std::abs(side) > 0.1f))
    side = a.dot(viewpoint - centre);
  if (!(side < 0.f))
    return;
  model.axis = -a;
  std::swap(model.base, model.top);
  model.point_on_axis = model.base;
}

} // namespace facyl
