/*
 * facyl: fast cylinder detection for PCL.
 * The rules that tell a segment is a part of a fitted cylinder's object (cylinder_parts.h).
 */
#include <facyl/recognition/cylinder_parts.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace facyl {
namespace {

/** A point's place in a cylinder's frame: t along the axis from the base, r from the axis. */
struct AxialPlace {
  float t, r;
  Eigen::Vector3f radial;
};

AxialPlace
placeOn(const CylinderModel& c, const Eigen::Vector3f& axis, const Eigen::Vector3f& p)
{
  const Eigen::Vector3f d = p - c.base;
  const float t = d.dot(axis);
  const Eigen::Vector3f radial = d - t * axis;
  return {t, radial.norm(), radial};
}

bool
atLeast(std::size_t count, float share, std::size_t of)
{
  return static_cast<float>(count) >= share * static_cast<float>(of);
}

} // namespace

bool
isContainerInside(const CylinderModel& c, const Eigen::Matrix3Xf& points,
                  const Eigen::Matrix3Xf& normals)
{
  constexpr float kRim = 1.3f, kInside = 0.6f, kWithinWall = 0.4f, kFacingAxis = 0.6f;
  const Eigen::Vector3f axis = c.axis.normalized();
  const float height = (c.top - c.base).dot(axis);
  const auto n = static_cast<std::size_t>(points.cols());
  std::size_t inside = 0, within_wall = 0, facing = 0, sided = 0;
  for (Eigen::Index k = 0; k < points.cols(); ++k) {
    const AxialPlace at = placeOn(c, axis, points.col(k));
    if (at.r > kRim * c.radius || at.t < -0.2f * c.radius || at.t > height + c.radius)
      continue;
    ++inside;
    within_wall += at.r <= c.radius;
    const Eigen::Vector3f q = normals.col(k);
    const float side = q.allFinite() ? q.dot(at.radial.normalized()) : 0.f;
    if (std::abs(side) > 0.3f) {
      ++sided;
      facing += side < 0.f;
    }
  }
  return n > 0 && atLeast(inside, kInside, n) && atLeast(within_wall, kWithinWall, n) &&
         sided > 0 && atLeast(facing, kFacingAxis, sided);
}

bool
isAttachment(const CylinderModel& c, const Eigen::Matrix3Xf& points)
{
  constexpr float kReach = 2.f, kAttached = 0.8f;
  const Eigen::Vector3f axis = c.axis.normalized();
  const float height = (c.top - c.base).dot(axis);
  std::size_t near = 0;
  for (Eigen::Index k = 0; k < points.cols(); ++k) {
    const AxialPlace at = placeOn(c, axis, points.col(k));
    near +=
      at.r <= kReach * c.radius && at.t >= -0.2f * c.radius && at.t <= height + 0.2f * c.radius;
  }
  const auto n = static_cast<std::size_t>(points.cols());
  return n > 0 && atLeast(near, kAttached, n);
}

bool
isEndCap(const CylinderModel& c, const Eigen::Matrix3Xf& points, const Eigen::Matrix3Xf& normals)
{
  constexpr float kWithin = 1.1f, kOnDisc = 0.8f, kAlongAxis = 0.6f;
  const float cos_along = std::cos(0.785398f); // 45 degrees
  const Eigen::Vector3f axis = c.axis.normalized();
  const float height = (c.top - c.base).dot(axis);
  const float band = std::max(2.f * c.distance_threshold, 0.15f * c.radius);
  const auto n = static_cast<std::size_t>(points.cols());
  std::vector<float> sections; // t of the points within the volume
  std::size_t known = 0, along = 0;
  for (Eigen::Index k = 0; k < points.cols(); ++k) {
    const AxialPlace at = placeOn(c, axis, points.col(k));
    if (at.r > kWithin * c.radius || at.t < -band || at.t > height + band)
      continue;
    sections.push_back(at.t);
    const Eigen::Vector3f q = normals.col(k);
    if (q.allFinite()) {
      ++known;
      along += std::abs(q.dot(axis)) > cos_along;
    }
  }
  if (n == 0 || !atLeast(sections.size(), kOnDisc, n) || known == 0 ||
      !atLeast(along, kAlongAxis, known))
    return false;
  const auto mid = sections.begin() + static_cast<std::ptrdiff_t>(sections.size() / 2);
  std::nth_element(sections.begin(), mid, sections.end());
  const float median = *mid;
  const auto on_disc = static_cast<std::size_t>(std::count_if(
    sections.begin(), sections.end(), [&](float t) { return std::abs(t - median) <= band; }));
  return atLeast(on_disc, kOnDisc, n);
}

} // namespace facyl
