/*
 * facyl: fast cylinder detection for PCL.
 * Small helpers shared by the translation units of the cylinder fit (not installed).
 */
#pragma once

#include <facyl/sample_consensus_alt/cylinder_fitting.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <vector>

namespace facyl {
namespace detail {

/** The median of \a v (reordered); 0 when empty. */
template <typename T>
T
medianOf(std::vector<T>& v)
{
  if (v.empty())
    return T(0);
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

/** Two unit vectors completing \a a to a right-handed orthonormal frame. */
inline void
basisFor(const Eigen::Vector3f& a, Eigen::Vector3f& u, Eigen::Vector3f& v)
{
  u = a.unitOrthogonal();
  v = a.cross(u);
}

/** One degree in radians. */
constexpr float kOneDegree = static_cast<float>(M_PI / 180.0);

/** sum_s w_s n_s n_s^T over the cues' normals. */
inline Eigen::Matrix3d
normalScatter(const VotingCues& cues, const Eigen::ArrayXf& w)
{
  Eigen::Matrix3d m;
  m(0, 0) = (w * cues.nx * cues.nx).sum();
  m(1, 1) = (w * cues.ny * cues.ny).sum();
  m(2, 2) = (w * cues.nz * cues.nz).sum();
  m(0, 1) = m(1, 0) = (w * cues.nx * cues.ny).sum();
  m(0, 2) = m(2, 0) = (w * cues.nx * cues.nz).sum();
  m(1, 2) = m(2, 1) = (w * cues.ny * cues.nz).sum();
  return m;
}

} // namespace detail
} // namespace facyl
