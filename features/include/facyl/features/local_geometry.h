/*
 * facyl: fast cylinder detection for PCL.
 */
#pragma once

#include <Eigen/Core>
#include <Eigen/Eigenvalues>

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
 * Accumulates in double around the first point, so clouds far from the origin keep precision.
 */
template <typename PointAt>
bool
estimateNormal(std::size_t count, PointAt point_at, Eigen::Vector3f& normal,
               float& surface_variation)
{
  Eigen::Vector3d origin{Eigen::Vector3d::Zero()}, sum{Eigen::Vector3d::Zero()};
  Eigen::Matrix3d sq{Eigen::Matrix3d::Zero()};
  std::size_t used = 0;
  for (std::size_t j = 0; j < count; ++j) {
    const Eigen::Vector3f p = point_at(j);
    if (!p.allFinite())
      continue;
    if (used == 0)
      origin = p.cast<double>();
    const Eigen::Vector3d q = p.cast<double>() - origin;
    sum += q;
    sq.noalias() += q * q.transpose();
    ++used;
  }
  if (used < 3)
    return false;
  const Eigen::Vector3d mean = sum / static_cast<double>(used);
  const Eigen::Matrix3d cov = sq / static_cast<double>(used) - mean * mean.transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
  solver.computeDirect(cov);
  const Eigen::Vector3d evals = solver.eigenvalues().cwiseMax(0.0);
  const double total = evals.sum();
  if (!(total > 0.0) || !(evals(1) > 1e-12 * total))
    return false; // all points on a line (or one point): no plane
  normal = solver.eigenvectors().col(0).cast<float>().normalized();
  surface_variation = static_cast<float>(evals(0) / total);
  return true;
}

/** \brief Principal curvature direction and magnitudes from the neighbours' normals
 * (paper III-C2, as pcl::PrincipalCurvaturesEstimation): project the normals returned by
 * \a normal_at(0..count-1) on the tangent plane of \a normal, then eigen-decompose the
 * covariance of the projections.
 *
 * Neighbour normals that point away from \a normal are flipped first, so unoriented input
 * normals give the same result as oriented ones.
 * \return false when fewer than 3 finite neighbour normals were given.
 */
template <typename NormalAt>
bool
principalCurvaturesFromNormals(const Eigen::Vector3f& normal, std::size_t count,
                               NormalAt normal_at, PrincipalCurvatures& out)
{
  const Eigen::Vector3d n = normal.cast<double>();
  const Eigen::Matrix3d projection = Eigen::Matrix3d::Identity() - n * n.transpose();
  Eigen::Vector3d sum{Eigen::Vector3d::Zero()};
  Eigen::Matrix3d sq{Eigen::Matrix3d::Zero()};
  std::size_t used = 0;
  for (std::size_t j = 0; j < count; ++j) {
    Eigen::Vector3d m = normal_at(j).template cast<double>();
    if (!m.allFinite())
      continue;
    if (m.dot(n) < 0.0)
      m = -m;
    const Eigen::Vector3d p = projection * m;
    sum += p;
    sq.noalias() += p * p.transpose();
    ++used;
  }
  if (used < 3)
    return false;
  const Eigen::Vector3d mean = sum / static_cast<double>(used);
  const Eigen::Matrix3d cov = sq / static_cast<double>(used) - mean * mean.transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
  solver.computeDirect(cov);
  const Eigen::Vector3d evals = solver.eigenvalues().cwiseMax(0.0);
  Eigen::Vector3d dir = solver.eigenvectors().col(2);
  dir -= n * n.dot(dir); // exactly tangent, despite rounding
  const double len = dir.norm();
  out.direction = len > 0.0 ? Eigen::Vector3f((dir / len).cast<float>()) : Eigen::Vector3f::Zero();
  out.k_max = static_cast<float>(evals(2));
  out.k_min = static_cast<float>(evals(1));
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
