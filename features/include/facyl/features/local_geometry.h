/*
 * facyl: fast cylinder detection for PCL.
 */
#pragma once

#include <Eigen/Core>
#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace facyl {

/** \brief Principal curvatures of one point (paper III-C2). */
struct PrincipalCurvatures {
  Eigen::Vector3f direction{Eigen::Vector3f::Zero()}; ///< c_max, unit, in the tangent plane
  float k_max{0.f}; ///< largest eigenvalue of the projected-normal covariance
  float k_min{0.f}; ///< second eigenvalue (the third is ~0: the normal direction)
};

/** \brief PCA normal of a neighbourhood: eigenvector of the smallest eigenvalue of the
 * covariance of the points returned by \a point_at(0..count-1).
 *
 * \param[out] normal unit normal (sign arbitrary)
 * \param[out] surface_variation lambda0 / (lambda0 + lambda1 + lambda2), PCL's "curvature"
 * \return false when fewer than 3 finite points were given or they are degenerate.
 * Accumulates around the first point, so clouds far from the origin keep precision.
 */
template <typename PointAt>
bool
estimateNormal(std::size_t count, PointAt point_at, Eigen::Vector3f& normal,
               float& surface_variation)
{
  // Float sums around the first point (neighbourhoods are small, so this keeps precision far
  // from the origin), then one 3x3 direct eigen-solve on the scaled covariance.
  Eigen::Vector3f origin{Eigen::Vector3f::Zero()}, sum{Eigen::Vector3f::Zero()};
  float xx = 0.f, xy = 0.f, xz = 0.f, yy = 0.f, yz = 0.f, zz = 0.f;
  std::size_t used = 0;
  for (std::size_t j = 0; j < count; ++j) {
    const Eigen::Vector3f p = point_at(j);
    if (!p.allFinite())
      continue;
    if (used == 0)
      origin = p;
    const Eigen::Vector3f q = p - origin;
    sum += q;
    xx += q.x() * q.x();
    xy += q.x() * q.y();
    xz += q.x() * q.z();
    yy += q.y() * q.y();
    yz += q.y() * q.z();
    zz += q.z() * q.z();
    ++used;
  }
  if (used < 3)
    return false;
  const float inv = 1.f / static_cast<float>(used);
  const Eigen::Vector3f mean = sum * inv;
  Eigen::Matrix3f cov;
  cov << xx * inv, xy * inv, xz * inv, //
    xy * inv, yy * inv, yz * inv,      //
    xz * inv, yz * inv, zz * inv;
  cov -= mean * mean.transpose();
  const float scale = cov.cwiseAbs().maxCoeff();
  if (!(scale > 0.f) || !std::isfinite(scale))
    return false;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3f> solver;
  solver.computeDirect(cov / scale);
  const Eigen::Vector3f evals = solver.eigenvalues().cwiseMax(0.f);
  const float total = evals.sum();
  if (!(total > 0.f) || !(evals(1) > 1e-6f * total))
    return false; // all points on a line (or one point): no plane
  normal = solver.eigenvectors().col(0).normalized();
  surface_variation = evals(0) / total;
  return normal.allFinite();
}

/** \brief Principal curvature direction and magnitudes from the neighbours' normals
 * (paper III-C2, as pcl::PrincipalCurvaturesEstimation): project the normals returned by
 * \a normal_at(0..count-1) on the tangent plane of \a normal, then eigen-decompose the
 * covariance of the projections. The projections have no component along the normal, so the
 * decomposition is that of a 2x2 matrix in a tangent basis, in closed form.
 *
 * Neighbour normals that point away from \a normal are flipped first, so unoriented input
 * normals give the same result as oriented ones.
 * \return false when fewer than 3 finite neighbour normals were given.
 */
template <typename NormalAt>
bool
principalCurvaturesFromNormals(const Eigen::Vector3f& normal, std::size_t count, NormalAt normal_at,
                               PrincipalCurvatures& out)
{
  const Eigen::Vector3f t1 = normal.unitOrthogonal();
  const Eigen::Vector3f t2 = normal.cross(t1);
  float su = 0.f, sv = 0.f, suu = 0.f, suv = 0.f, svv = 0.f;
  std::size_t used = 0;
  for (std::size_t j = 0; j < count; ++j) {
    const Eigen::Vector3f m = normal_at(j);
    if (!m.allFinite())
      continue;
    const float sign = m.dot(normal) < 0.f ? -1.f : 1.f;
    const float u = sign * m.dot(t1), v = sign * m.dot(t2);
    su += u;
    sv += v;
    suu += u * u;
    suv += u * v;
    svv += v * v;
    ++used;
  }
  if (used < 3)
    return false;
  const float inv = 1.f / static_cast<float>(used);
  const float mu = su * inv, mv = sv * inv;
  const float a = suu * inv - mu * mu, b = suv * inv - mu * mv, c = svv * inv - mv * mv;
  // Eigen-decomposition of [[a b] [b c]].
  const float half_trace = 0.5f * (a + c);
  const float radius = std::sqrt(0.25f * (a - c) * (a - c) + b * b);
  out.k_max = std::max(0.f, half_trace + radius);
  out.k_min = std::max(0.f, half_trace - radius);
  // Eigenvector of k_max, from the row of [[a b] [b c]] - k_max I that is best conditioned
  // (no angle: an atan2, a sine and a cosine were a fifth of the cues' time), signed so that
  // its t1 component is not negative; t1 when the two curvatures are equal.
  float x = 1.f, y = 0.f;
  if (radius > 0.f) {
    x = a >= c ? 0.5f * (a - c) + radius : b;
    y = a >= c ? b : 0.5f * (c - a) + radius;
    if (x < 0.f) {
      x = -x;
      y = -y;
    }
  }
  out.direction = (x * t1 + y * t2).normalized();
  return true;
}

/** \brief Soft-vote weight of paper eq. 3: (k_max - k_min) / (k_max + k_min), in [0, 1].
 * 1 on a cylinder (normals change along one direction only), near 0 where the normals spread
 * isotropically; 0 where neither curvature is measurable (k_max + k_min == 0).
 */
inline float
curvatureAnisotropy(float k_max, float k_min)
{
  const float sum = k_max + k_min;
  if (!(sum > 0.f) || !std::isfinite(sum))
    return 0.f;
  const float w = (k_max - k_min) / sum;
  return w < 0.f ? 0.f : (w > 1.f ? 1.f : w);
}

} // namespace facyl
