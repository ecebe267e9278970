/*
 * facyl: fast cylinder detection for PCL.
 * Small 2-D polygon helpers shared by the segmentation and the simulators.
 */
#pragma once

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <vector>

namespace facyl {

/** \brief Drops the points of \a p strictly inside the polygon of its extreme points in eight
 * directions (Akl and Toussaint): none of them can be a vertex of the convex hull, and most of
 * a dense region's points are (nine tenths of a disc's). Points on or near that polygon stay.
 * The order of the rest is kept. */
inline void
dropInteriorPoints(std::vector<Eigen::Vector2f>& p)
{
  if (p.size() < 64)
    return;
  // Extremes in the directions 0, 45, ..., 315 degrees, in that (counter-clockwise) order.
  const float c = 0.70710678f;
  const Eigen::Vector2f dirs[8] = {{1.f, 0.f},  {c, c},   {0.f, 1.f},  {-c, c},
                                   {-1.f, 0.f}, {-c, -c}, {0.f, -1.f}, {c, -c}};
  std::vector<Eigen::Vector2f> poly;
  for (const auto& d : dirs) {
    const auto best = std::max_element(
      p.begin(), p.end(), [&d](const auto& a, const auto& b) { return a.dot(d) < b.dot(d); });
    if (poly.empty() || (*best - poly.back()).squaredNorm() > 0.f)
      poly.push_back(*best);
  }
  while (poly.size() > 1 && (poly.front() - poly.back()).squaredNorm() == 0.f)
    poly.pop_back();
  if (poly.size() < 3)
    return;
  // Strictly inside: left of every edge by more than a relative margin (rounding).
  float extent = 0.f;
  for (const auto& v : poly)
    extent = std::max(extent, (v - poly.front()).norm());
  const float margin = 1e-5f * extent;
  const auto inside = [&](const Eigen::Vector2f& q) {
    for (std::size_t i = 0; i < poly.size(); ++i) {
      const Eigen::Vector2f& a = poly[i];
      const Eigen::Vector2f e = poly[(i + 1) % poly.size()] - a;
      if (e.x() * (q - a).y() - e.y() * (q - a).x() <= margin * e.norm())
        return false;
    }
    return true;
  };
  p.erase(std::remove_if(p.begin(), p.end(), inside), p.end());
}

/** \brief Convex hull of 2-D points (Andrew's monotone chain), counter-clockwise, without
 * collinear vertices. Fewer than 3 points are returned sorted. O(n log n), the points inside
 * the polygon of their extremes dropped first (dropInteriorPoints). */
inline std::vector<Eigen::Vector2f>
convexHull2D(std::vector<Eigen::Vector2f> p)
{
  dropInteriorPoints(p);
  std::sort(p.begin(), p.end(), [](const Eigen::Vector2f& a, const Eigen::Vector2f& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  if (p.size() < 3)
    return p;
  const auto cross = [](const Eigen::Vector2f& o, const Eigen::Vector2f& a,
                        const Eigen::Vector2f& b) {
    return (a - o).x() * (b - o).y() - (a - o).y() * (b - o).x();
  };
  std::vector<Eigen::Vector2f> h(2 * p.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    while (k >= 2 && cross(h[k - 2], h[k - 1], p[i]) <= 0.f)
      --k;
    h[k++] = p[i];
  }
  for (std::size_t i = p.size() - 1, t = k + 1; i-- > 0;) {
    while (k >= t && cross(h[k - 2], h[k - 1], p[i]) <= 0.f)
      --k;
    h[k++] = p[i];
  }
  h.resize(k - 1);
  return h;
}

/** \brief Area of a simple polygon (shoelace formula), >= 0. */
inline float
polygonArea(const std::vector<Eigen::Vector2f>& polygon)
{
  double twice = 0.0;
  for (std::size_t i = 0; i < polygon.size(); ++i) {
    const Eigen::Vector2f& a = polygon[i];
    const Eigen::Vector2f& b = polygon[(i + 1) % polygon.size()];
    twice += static_cast<double>(a.x()) * b.y() - static_cast<double>(b.x()) * a.y();
  }
  return static_cast<float>(0.5 * std::abs(twice));
}

/** \brief Whether \a p lies inside the convex, counter-clockwise \a polygon (convexHull2D's
 * order) at least \a margin (>= 0) from each of its edges: inside the polygon shrunk by \a
 * margin. False for fewer than 3 vertices. */
inline bool
insideConvexBy(const Eigen::Vector2f& p, const std::vector<Eigen::Vector2f>& polygon, float margin)
{
  if (polygon.size() < 3)
    return false;
  for (std::size_t i = 0; i < polygon.size(); ++i) {
    const Eigen::Vector2f& a = polygon[i];
    const Eigen::Vector2f e = polygon[(i + 1) % polygon.size()] - a;
    const float length = e.norm();
    // Signed distance to the left of the edge (inside for a counter-clockwise polygon).
    if (!(length > 0.f) || (e.x() * (p - a).y() - e.y() * (p - a).x()) < margin * length)
      return false;
  }
  return true;
}

/** \brief Largest distance between two vertices of \a polygon (its diameter, for a convex
 * one); 0 for fewer than 2 vertices. */
inline float
polygonDiameter(const std::vector<Eigen::Vector2f>& polygon)
{
  float d2 = 0.f;
  for (std::size_t i = 0; i < polygon.size(); ++i)
    for (std::size_t j = i + 1; j < polygon.size(); ++j)
      d2 = std::max(d2, (polygon[i] - polygon[j]).squaredNorm());
  return std::sqrt(d2);
}

} // namespace facyl
