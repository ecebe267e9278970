/*
 * facyl: fast cylinder detection for PCL.
 */
#include <facyl/features/neighbourhoods.h>
#include <facyl/features/parallel.h>

#include <nanoflann.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <stdexcept>

namespace facyl {

namespace {
/** nanoflann's dataset contract over the finite columns of a 3 x N matrix, copied into one
 * contiguous block (the tree reads coordinates in its inner loop). */
struct FiniteColumns {
  std::vector<float> xyz;   // finite points, packed
  std::vector<int> columns; // their column in the surface

  explicit FiniteColumns(const Eigen::Matrix3Xf& p)
  {
    columns.reserve(static_cast<std::size_t>(p.cols()));
    xyz.reserve(3 * static_cast<std::size_t>(p.cols()));
    for (Eigen::Index i = 0; i < p.cols(); ++i)
      if (p.col(i).allFinite()) {
        columns.push_back(static_cast<int>(i));
        xyz.insert(xyz.end(), {p(0, i), p(1, i), p(2, i)});
      }
  }
  std::size_t kdtree_get_point_count() const
  {
    return columns.size();
  }
  float kdtree_get_pt(std::size_t idx, std::size_t dim) const
  {
    return xyz[3 * idx + dim];
  }
  template <class BBox> bool kdtree_get_bbox(BBox&) const
  {
    return false;
  }
};

using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, FiniteColumns>,
                                                 FiniteColumns, 3, std::uint32_t>;

/** Queries per block of a parallel search. */
constexpr std::size_t kQueryGrain = 512;

} // namespace

struct NeighbourSearch::Impl {
  FiniteColumns data;
  Tree tree;
  explicit Impl(const Eigen::Matrix3Xf& surface)
      : data(surface)
      , tree(3, data, nanoflann::KDTreeSingleIndexAdaptorParams(10))
  {
    if (!data.columns.empty())
      tree.buildIndex();
  }
};

NeighbourSearch::NeighbourSearch(const Eigen::Matrix3Xf& surface)
    : impl_(std::make_unique<Impl>(surface))
{
}

NeighbourSearch::~NeighbourSearch() = default;

Neighbourhoods
NeighbourSearch::nearest(const Eigen::Matrix3Xf& queries, int k, int threads) const
{
  if (k < 1)
    throw std::invalid_argument("facyl::NeighbourSearch::nearest: k must be at least 1");
  return nearestWithin(queries, k, std::numeric_limits<float>::infinity(), threads);
}

Neighbourhoods
NeighbourSearch::nearestWithin(const Eigen::Matrix3Xf& queries, int k, float radius,
                               int threads) const
{
  if (k < 1)
    throw std::invalid_argument("facyl::NeighbourSearch::nearestWithin: k must be at least 1");
  if (!(radius > 0.f))
    throw std::invalid_argument("facyl::NeighbourSearch::nearestWithin: radius must be positive");
  const auto& data = impl_->data;
  const auto& tree = impl_->tree;
  const std::size_t n = static_cast<std::size_t>(queries.cols());
  Neighbourhoods out;
  out.offsets.assign(n + 1, 0);
  const std::size_t kk = std::min<std::size_t>(static_cast<std::size_t>(k), data.columns.size());
  if (kk == 0)
    return out;
  // The result set's worst distance starts at the radius instead of the largest float: the
  // search then prunes every branch beyond it.
  const float reach = radius * radius;
  const float worst = std::isfinite(reach) ? reach : std::numeric_limits<float>::max();
  std::vector<std::uint32_t> found(n * kk);
  std::vector<std::uint32_t> counts(n, 0);
  parallelFor(n, threads, kQueryGrain, [&](std::size_t begin, std::size_t end) {
    std::vector<float> distances(kk);
    for (std::size_t i = begin; i < end; ++i) {
      const Eigen::Vector3f q = queries.col(static_cast<Eigen::Index>(i));
      if (!q.allFinite())
        continue;
      nanoflann::KNNResultSet<float, std::uint32_t> result(kk);
      result.init(found.data() + i * kk, distances.data());
      distances[kk - 1] = worst;
      tree.findNeighbors(result, q.data(), nanoflann::SearchParams());
      counts[i] = static_cast<std::uint32_t>(result.size());
    }
  });
  for (std::size_t i = 0; i < n; ++i)
    out.offsets[i + 1] = out.offsets[i] + counts[i];
  out.indices.resize(out.offsets[n]);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < counts[i]; ++j)
      out.indices[out.offsets[i] + j] = data.columns[found[i * kk + j]];
  return out;
}

Neighbourhoods
NeighbourSearch::within(const Eigen::Matrix3Xf& queries, float radius, int threads) const
{
  if (!(radius > 0.f) || !std::isfinite(radius))
    throw std::invalid_argument(
      "facyl::NeighbourSearch::within: radius must be positive and finite");
  const auto& data = impl_->data;
  const auto& tree = impl_->tree;
  const std::size_t n = static_cast<std::size_t>(queries.cols());
  std::vector<std::vector<int>> lists(n);
  if (data.columns.empty())
    return Neighbourhoods::fromLists(lists);
  parallelFor(n, threads, kQueryGrain / 2, [&](std::size_t begin, std::size_t end) {
    std::vector<std::pair<std::uint32_t, float>> matches;
    for (std::size_t i = begin; i < end; ++i) {
      const Eigen::Vector3f q = queries.col(static_cast<Eigen::Index>(i));
      if (!q.allFinite())
        continue;
      tree.radiusSearch(q.data(), radius * radius, matches, nanoflann::SearchParams(32, 0.f, true));
      auto& list = lists[i];
      list.reserve(matches.size());
      for (const auto& m : matches)
        list.push_back(data.columns[m.first]);
    }
  });
  return Neighbourhoods::fromLists(lists);
}

} // namespace facyl
