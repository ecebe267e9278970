/*
 * facyl: fast cylinder detection for PCL.
 */
#pragma once

#include <facyl/features/neighbourhoods.h>

#include <Eigen/Core>

#include <vector>

namespace facyl {

/** \brief Per-point cues of the columns of a 3 x N matrix (the cues of facyl::NormalCurvature
 * in structure-of-arrays form). Columns without a usable neighbourhood hold NaN normals. */
struct PointCues {
  Eigen::Matrix3Xf normals;              ///< unit PCA normals
  Eigen::Matrix3Xf curvature_directions; ///< unit c_max (paper III-C2)
  Eigen::VectorXf weights;               ///< eq. 3 weight: curvatureAnisotropy(k_max, k_min)
};

/** \brief Normals and principal curvatures of every column of \a points from its neighbours
 * within \a radius (the \a max_neighbours nearest of them at most, so that dense points cost
 * no more than sparse ones), on one thread (callers may run concurrently).
 *
 * This is the same estimate as NormalCurvatureEstimation at a scale given in cloud units
 * instead of a neighbour count: an estimator that has measured the noise and the size of its
 * object can ask for cues at the scale where the noise averages out (a neighbourhood of half
 * the radius of a cylinder still sees a surface that its tangent plane fits).
 *
 * \param reference unit normals (3 x N) whose signs the output follows (flipped where the dot
 *        product is negative), or an empty matrix.
 * \param stride neighbourhoods are searched for every \a stride-th column only (1: every
 *        column, one query per point). Every other column takes the cues of the nearest of
 *        these centres whose neighbourhood holds it: a neighbourhood of many points, moved by a
 *        point's spacing, is nearly the same set (sharedNeighbourhoods). A column that no
 *        neighbourhood holds gets none.
 * \throws std::invalid_argument if \a radius is not positive and finite, \a max_neighbours < 3
 *         or \a stride < 1. */
PointCues estimatePointCues(const Eigen::Matrix3Xf& points, float radius, int max_neighbours,
                            const Eigen::Matrix3Xf& reference, int stride = 1);

/** \brief For every column of \a points, the centre whose neighbourhood it takes: the nearest of
 * the centres (indices into \a centres) whose neighbour list in \a nb holds it (nb: one list
 * per centre, of columns of \a points), ties to the first; -1 where no list holds it. A
 * centre holds itself at distance 0. */
std::vector<int> sharedNeighbourhoods(const Eigen::Matrix3Xf& points,
                                      const std::vector<int>& centres, const Neighbourhoods& nb);

/** \brief The points' own noise, whatever shape they lie on: the median over \a samples
 * evenly spread columns of sqrt(lambda_0 k / (k - 3)) of their \a k nearest neighbours (the
 * spread along the local normal of a patch small enough to be flat; k - 3 degrees of freedom
 * are left once the plane is fitted). Gaussian noise of sigma gives about sigma; a smooth surface
 * without noise about 0 (a box's faces, a cylinder much wider than the patch), whatever a model
 * fitted to the whole makes of it. 0 when no neighbourhood is usable. \throws std::invalid_argument
 * if k < 3. */
float estimateLocalNoise(const Eigen::Matrix3Xf& points, int k, int samples);

} // namespace facyl
