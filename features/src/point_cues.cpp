/*
 * facyl: fast cylinder detection for PCL.
 */
#include <facyl/features/local_geometry.h>
#include <facyl/features/neighbourhoods.h>
#include <facyl/features/point_cues.h>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <vector>

namespace facyl {

std::vector<int>
sharedNeighbourhoods(const Eigen::Matrix3Xf& points, const std::vector<int>& centres,
                     const Neighbourhoods& nb)
{
  const std::size_t n = static_cast<std::size_t>(points.cols());
  std::vector<int> owner(n, -1);
  std::vector<float> nearest(n, std::numeric_limits<float>::infinity());
  for (std::size_t c = 0; c < centres.size() && c < nb.size(); ++c) {
    const Eigen::Vector3f centre = points.col(centres[c]);
    const int* list = nb.begin(c);
    for (std::size_t j = 0; j < nb.count(c); ++j) {
      const std::size_t col = static_cast<std::size_t>(list[j]);
      const float d = (points.col(list[j]) - centre).squaredNorm();
      if (d < nearest[col]) {
        nearest[col] = d;
        owner[col] = static_cast<int>(c);
      }
    }
  }
  return owner;
}

PointCues
estimatePointCues(const Eigen::Matrix3Xf& points, float radius, int max_neighbours,
                  const Eigen::Matrix3Xf& reference, int stride)
{
  if (!(radius > 0.f) || !std::isfinite(radius))
    throw std::invalid_argument("estimatePointCues: the radius must be positive and finite");
  if (max_neighbours < 3)
    throw std::invalid_argument("estimatePointCues: a normal needs at least 3 neighbours");
  if (stride < 1)
    throw std::invalid_argument("estimatePointCues: the stride must be at least 1");
  const Eigen::Index n = points.cols();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  PointCues out;
  out.normals.setConstant(3, n, nan);
  out.curvature_directions.setConstant(3, n, nan);
  out.weights.setZero(n);
  if (n == 0)
    return out;
  // The centres: the columns whose neighbourhoods are searched.
  std::vector<int> centres;
  for (Eigen::Index i = 0; i < n; i += stride)
    centres.push_back(static_cast<int>(i));
  // The k nearest within the radius: the cost stays that of k neighbours where the points
  // are dense, and that of the few within the radius where they are sparse.
  const NeighbourSearch search(points);
  const Eigen::Matrix3Xf centre_points =
    stride == 1 ? Eigen::Matrix3Xf() : Eigen::Matrix3Xf(points(Eigen::all, centres));
  const Neighbourhoods nb =
    search.nearestWithin(stride == 1 ? points : centre_points, max_neighbours, radius, 1);
  std::vector<int> owner;
  if (stride == 1) {
    owner.resize(static_cast<std::size_t>(n));
    std::iota(owner.begin(), owner.end(), 0);
  }
  else
    owner = sharedNeighbourhoods(points, centres, nb);
  // A normal per centre, shared with the columns it holds (each with its own sign).
  std::vector<Eigen::Vector3f> centre_normals(centres.size(), Eigen::Vector3f::Constant(nan));
  for (std::size_t c = 0; c < centres.size(); ++c) {
    const int* list = nb.begin(c);
    Eigen::Vector3f normal;
    float variation = 0.f;
    if (nb.count(c) >= 3 &&
        estimateNormal(
          nb.count(c), [&](std::size_t j) { return Eigen::Vector3f(points.col(list[j])); }, normal,
          variation))
      centre_normals[c] = normal;
  }
  const bool oriented = reference.cols() == n;
  for (Eigen::Index i = 0; i < n; ++i) {
    const int c = owner[static_cast<std::size_t>(i)];
    if (c < 0 || !centre_normals[static_cast<std::size_t>(c)].allFinite())
      continue;
    Eigen::Vector3f normal = centre_normals[static_cast<std::size_t>(c)];
    if (oriented && normal.dot(reference.col(i)) < 0.f)
      normal = -normal;
    out.normals.col(i) = normal;
  }
  // Principal curvatures at the centres, from their neighbours' normals, shared likewise.
  std::vector<PrincipalCurvatures> centre_curvatures(centres.size());
  std::vector<char> curved(centres.size(), 0);
  for (std::size_t c = 0; c < centres.size(); ++c) {
    const Eigen::Index i = centres[c];
    if (!out.normals.col(i).allFinite())
      continue;
    const int* list = nb.begin(c);
    curved[c] = principalCurvaturesFromNormals(
      out.normals.col(i), nb.count(c),
      [&](std::size_t j) { return Eigen::Vector3f(out.normals.col(list[j])); },
      centre_curvatures[c]);
  }
  for (Eigen::Index i = 0; i < n; ++i) {
    const int c = owner[static_cast<std::size_t>(i)];
    if (c < 0 || !curved[static_cast<std::size_t>(c)])
      continue;
    const PrincipalCurvatures& pc = centre_curvatures[static_cast<std::size_t>(c)];
    out.curvature_directions.col(i) = pc.direction;
    out.weights(i) = curvatureAnisotropy(pc.k_max, pc.k_min);
  }
  return out;
}

float
estimateLocalNoise(const Eigen::Matrix3Xf& points, int k, int samples)
{
  if (k < 3)
    throw std::invalid_argument("estimateLocalNoise: a neighbourhood needs at least 3 points");
  const Eigen::Index n = points.cols();
  if (n < k || samples < 1)
    return 0.f;
  const Eigen::Index m = std::min<Eigen::Index>(n, samples);
  Eigen::Matrix3Xf queries(3, m);
  for (Eigen::Index i = 0; i < m; ++i)
    queries.col(i) = points.col(i * n / m);
  // A few queries: a grid is cheaper than a tree (the same neighbours).
  const Neighbourhoods nb = nearestOnGrid(points, queries, k);
  std::vector<float> spreads;
  for (Eigen::Index i = 0; i < m; ++i) {
    const std::size_t q = static_cast<std::size_t>(i);
    if (nb.count(q) < 4)
      continue;
    const int* list = nb.begin(q);
    Eigen::Vector3f mean = Eigen::Vector3f::Zero();
    for (std::size_t j = 0; j < nb.count(q); ++j)
      mean += points.col(list[j]);
    mean /= static_cast<float>(nb.count(q));
    Eigen::Matrix3f cov = Eigen::Matrix3f::Zero();
    for (std::size_t j = 0; j < nb.count(q); ++j) {
      const Eigen::Vector3f d = points.col(list[j]) - mean;
      cov.noalias() += d * d.transpose();
    }
    cov /= static_cast<float>(nb.count(q));
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3f> solver;
    solver.computeDirect(cov, Eigen::EigenvaluesOnly);
    // The smallest eigenvalue of k points keeps k - 3 of their degrees of freedom (a plane
    // was fitted): E = sigma^2 (k - 3) / k.
    const float unbias = static_cast<float>(nb.count(q)) / static_cast<float>(nb.count(q) - 3);
    spreads.push_back(std::sqrt(std::max(0.f, solver.eigenvalues()(0)) * unbias));
  }
  if (spreads.empty())
    return 0.f;
  const auto mid = spreads.begin() + static_cast<std::ptrdiff_t>(spreads.size() / 2);
  std::nth_element(spreads.begin(), mid, spreads.end());
  return *mid;
}

} // namespace facyl
