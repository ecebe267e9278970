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
#include <utility>
#include <vector>

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

namespace {

/** Points sorted into a uniform grid of cubic cells (a counting sort by cell). */
class PointGrid {
public:
  PointGrid(const Eigen::Matrix3Xf& surface, int k)
  {
    lo_ = Eigen::Vector3f::Constant(std::numeric_limits<float>::max());
    Eigen::Vector3f hi = Eigen::Vector3f::Constant(std::numeric_limits<float>::lowest());
    std::vector<int> columns; // the finite columns
    for (Eigen::Index i = 0; i < surface.cols(); ++i)
      if (surface.col(i).allFinite()) {
        columns.push_back(static_cast<int>(i));
        lo_ = lo_.cwiseMin(surface.col(i));
        hi = hi.cwiseMax(surface.col(i));
      }
    if (columns.empty())
      return;
    // Cells about as wide as a k-neighbourhood of points spread over a surface that fills the
    // box's two largest extents, or over a line along its largest; at most about 4 cells a
    // point. Any width gives the same neighbours; this one keeps the rings few and small.
    const double m = static_cast<double>(columns.size());
    Eigen::Vector3d extent = (hi - lo_).cast<double>();
    std::sort(extent.data(), extent.data() + 3);
    const double reach =
      std::max(std::sqrt(extent(1) * extent(2) * k / m), extent(2) * k / (2.0 * m));
    cell_ = static_cast<float>(std::max(reach, 1e-6 * std::max(1.0, extent(2))));
    for (;;) {
      for (int d = 0; d < 3; ++d)
        size_[d] = 1 + static_cast<int>((hi(d) - lo_(d)) / cell_);
      if (static_cast<double>(size_[0]) * size_[1] * size_[2] <= 4.0 * m + 64.0)
        break;
      cell_ *= 1.26f;
    }
    const std::size_t cells = static_cast<std::size_t>(size_[0]) * size_[1] * size_[2];
    std::vector<std::uint32_t> cell_of(columns.size());
    starts_.assign(cells + 1, 0);
    for (std::size_t j = 0; j < columns.size(); ++j) {
      cell_of[j] = static_cast<std::uint32_t>(cellIndex(cellOf(surface.col(columns[j]))));
      ++starts_[cell_of[j] + 1];
    }
    for (std::size_t c = 0; c < cells; ++c)
      starts_[c + 1] += starts_[c];
    std::vector<std::uint32_t> next(starts_.begin(), starts_.end() - 1);
    xyz_.resize(3 * columns.size());
    sorted_.resize(columns.size());
    for (std::size_t j = 0; j < columns.size(); ++j) {
      const std::uint32_t at = next[cell_of[j]]++;
      sorted_[at] = columns[j];
      for (int d = 0; d < 3; ++d)
        xyz_[3 * at + static_cast<std::size_t>(d)] = surface(d, columns[j]);
    }
  }

  std::size_t points() const
  {
    return sorted_.size();
  }

  /** The \a kk nearest points of \a q (finite) into \a best, nearest first: rings of cells
   * about q's cell (clamped to the grid), until no cell outside them can hold a nearer point. */
  void nearest(const Eigen::Vector3f& q, std::size_t kk,
               std::vector<std::pair<float, int>>& best) const
  {
    best.clear();
    const Eigen::Vector3i c = cellOf(q);
    for (int r = 0;; ++r) {
      visitRing(c, r, q, kk, best);
      // The nearest face of the block of rings 0..r beyond which cells remain.
      float bound = std::numeric_limits<float>::max();
      bool more = false;
      for (int d = 0; d < 3; ++d) {
        if (c(d) + r + 1 < size_[d]) {
          more = true;
          bound = std::min(bound, lo_(d) + static_cast<float>(c(d) + r + 1) * cell_ - q(d));
        }
        if (c(d) - r - 1 >= 0) {
          more = true;
          bound = std::min(bound, q(d) - (lo_(d) + static_cast<float>(c(d) - r) * cell_));
        }
      }
      if (!more)
        break;
      bound = std::max(bound, 0.f);
      if (best.size() == kk && best.back().first <= bound * bound)
        break;
    }
  }

private:
  Eigen::Vector3i cellOf(const Eigen::Vector3f& p) const
  {
    Eigen::Vector3i c;
    for (int d = 0; d < 3; ++d) {
      const float t = (p(d) - lo_(d)) / cell_;
      c(d) = t <= 0.f ? 0 : std::min(size_[d] - 1, static_cast<int>(std::min(t, 1e9f)));
    }
    return c;
  }
  std::size_t cellIndex(const Eigen::Vector3i& c) const
  {
    return (static_cast<std::size_t>(c(2)) * static_cast<std::size_t>(size_[1]) +
            static_cast<std::size_t>(c(1))) *
             static_cast<std::size_t>(size_[0]) +
           static_cast<std::size_t>(c(0));
  }
  /** The cells of the grid at Chebyshev distance \a r from \a c. */
  void visitRing(const Eigen::Vector3i& c, int r, const Eigen::Vector3f& q, std::size_t kk,
                 std::vector<std::pair<float, int>>& best) const
  {
    int from[3], to[3];
    for (int d = 0; d < 3; ++d) {
      from[d] = std::max(-r, -c(d));
      to[d] = std::min(r, size_[d] - 1 - c(d));
    }
    for (int dx = from[0]; dx <= to[0]; ++dx)
      for (int dy = from[1]; dy <= to[1]; ++dy) {
        if (std::abs(dx) == r || std::abs(dy) == r) {
          for (int dz = from[2]; dz <= to[2]; ++dz)
            visit(c + Eigen::Vector3i(dx, dy, dz), q, kk, best);
          continue;
        }
        if (from[2] == -r)
          visit(c + Eigen::Vector3i(dx, dy, -r), q, kk, best);
        if (to[2] == r)
          visit(c + Eigen::Vector3i(dx, dy, r), q, kk, best);
      }
  }
  /** The points of cell \a c (inside the grid) offered to \a best. */
  void visit(const Eigen::Vector3i& c, const Eigen::Vector3f& q, std::size_t kk,
             std::vector<std::pair<float, int>>& best) const
  {
    const std::size_t cell = cellIndex(c);
    for (std::uint32_t at = starts_[cell]; at < starts_[cell + 1]; ++at) {
      const float* p = &xyz_[3 * static_cast<std::size_t>(at)];
      const float ex = p[0] - q(0), ey = p[1] - q(1), ez = p[2] - q(2);
      const float d2 = ex * ex + ey * ey + ez * ez;
      if (best.size() == kk && !(d2 < best.back().first))
        continue;
      const std::pair<float, int> entry{d2, sorted_[at]};
      if (best.size() == kk)
        best.pop_back();
      best.insert(std::upper_bound(best.begin(), best.end(), entry), entry);
    }
  }

  std::vector<int> sorted_;           // the finite columns, by cell
  std::vector<float> xyz_;            // their coordinates, by cell
  std::vector<std::uint32_t> starts_; // first point of each cell, and the end
  Eigen::Vector3f lo_;
  float cell_{1.f};
  int size_[3]{1, 1, 1};
};

} // namespace

Neighbourhoods
nearestOnGrid(const Eigen::Matrix3Xf& surface, const Eigen::Matrix3Xf& queries, int k)
{
  if (k < 1)
    throw std::invalid_argument("facyl::nearestOnGrid: k must be at least 1");
  const std::size_t n = static_cast<std::size_t>(queries.cols());
  Neighbourhoods out;
  out.offsets.assign(n + 1, 0);
  const PointGrid grid(surface, k);
  const std::size_t kk = std::min<std::size_t>(static_cast<std::size_t>(k), grid.points());
  if (kk == 0)
    return out;
  out.indices.reserve(n * kk);
  std::vector<std::pair<float, int>> best;
  best.reserve(kk + 1);
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3f q = queries.col(static_cast<Eigen::Index>(i));
    if (q.allFinite()) {
      grid.nearest(q, kk, best);
      for (const auto& b : best)
        out.indices.push_back(b.second);
    }
    out.offsets[i + 1] = out.indices.size();
  }
  return out;
}

} // namespace facyl
