/*
 * facyl: fast cylinder detection for PCL.
 * Choosing the planes that support objects: small numerics as free functions.
 */
#pragma once

#include <Eigen/Geometry>

#include <cstddef>
#include <vector>

namespace facyl {

/** \brief Groups planes (a, b, c, d; unit normals on the same side, e.g. towards the sensor)
 * that are one plane: normals within \a angle (rad) and offsets within \a distance. Planes are
 * visited in \a order (e.g. largest first); each group is led by its first plane.
 * \return for each group, the indices of its planes. */
std::vector<std::vector<std::size_t>>
groupCoplanar(const std::vector<Eigen::Vector4f>& planes, const std::vector<std::size_t>& order,
              float angle, float distance);

/** \brief Where a cluster lies relative to a plane: robust lowest and highest heights, and the
 * share of its points inside a height band. */
struct HeightProfile {
  float base{0.f};          ///< 2nd percentile of the heights
  float top{0.f};           ///< 98th percentile
  float in_band{0.f};       ///< share of the points with height in [min, max]
  float extent{0.f};        ///< diagonal of the points' bounding box along the plane
};

/** \brief HeightProfile of \a points (3 x n) over \a plane (unit normal), band [min, max]. */
HeightProfile
heightProfile(const Eigen::Matrix3Xf& points, const Eigen::Vector4f& plane, float min_height,
              float max_height);

/** \brief A cluster stands on a plane when it reaches down to it (base <= contact) and is
 * whole inside the object band, a box max_height high and wide (top below max_height -
 * margin, extent below max_height): a table's objects do; the legs of a table over a floor
 * (they reach up to the table top) and the foot of a wall (wide) do not. */
inline bool
standsOn(const HeightProfile& h, float contact, float max_height, float margin)
{
  return h.base <= contact && h.top <= max_height - margin && h.extent <= max_height;
}

} // namespace facyl
