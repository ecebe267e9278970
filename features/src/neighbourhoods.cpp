/*
 * facyl: fast cylinder detection for PCL.
 */
#include <facyl/features/neighbourhoods.h>
#include <facyl/features/parallel.h>

#include <nanoflann.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
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

int
imageWindowRadius(int k)
{
  if (k < 1)
    throw std::invalid_argument("facyl::imageWindowRadius: k must be at least 1");
  int r = 1;
  while ((2 * r + 1) * (2 * r + 1) < 3 * k)
    ++r;
  return r;
}

int
imageWindowRadius(int k, float inclination)
{
  if (k < 1)
    throw std::invalid_argument("facyl::imageWindowRadius: k must be at least 1");
  if (!(inclination >= 0.f && inclination < 0.5f * static_cast<float>(M_PI)))
    throw std::invalid_argument("facyl::imageWindowRadius: the inclination " +
                                std::to_string(inclination) + " rad is not in [0, pi/2)");
  const double semi_axis =
    std::sqrt(static_cast<double>(k) / (M_PI * std::cos(static_cast<double>(inclination))));
  return std::max(1, static_cast<int>(std::ceil(semi_axis - 1e-9)));
}

namespace {

/** The window of nearestInImage on an image \a width pixels wide: its offsets, nearest the
 * centre first (the centre first), and each as a step in the pixel index. */
struct ImageWindow {
  ImageWindow(int radius, int width)
      : r(radius)
  {
    for (int dy = -r; dy <= r; ++dy)
      for (int dx = -r; dx <= r; ++dx)
        offsets.emplace_back(dx, dy);
    std::stable_sort(offsets.begin(), offsets.end(), [](const auto& a, const auto& b) {
      return a.first * a.first + a.second * a.second < b.first * b.first + b.second * b.second;
    });
    for (const auto& [dx, dy] : offsets)
      steps.push_back(dy * width + dx);
  }
  int r;
  std::vector<std::pair<int, int>> offsets;
  std::vector<int> steps;
};

/** Squared distances from pixel \a q (at \a u, \a v, finite) to the pixels of \a window in
 * \a d2, in the window's order; infinite for a pixel outside the image or without depth. */
void
windowDistances(const Eigen::Matrix3Xf& surface, int width, int height, const ImageWindow& window,
                int q, int u, int v, std::vector<float>& d2)
{
  const Eigen::Vector3f p = surface.col(q);
  const float* data = surface.data();
  const bool inside =
    u >= window.r && u + window.r < width && v >= window.r && v + window.r < height;
  const float far = std::numeric_limits<float>::infinity();
  for (std::size_t o = 0; o < window.steps.size(); ++o) {
    d2[o] = far;
    if (!inside) {
      const int x = u + window.offsets[o].first, y = v + window.offsets[o].second;
      if (x < 0 || x >= width || y < 0 || y >= height)
        continue;
    }
    const float* c = data + 3 * static_cast<std::ptrdiff_t>(q + window.steps[o]);
    const float d = (c[0] - p.x()) * (c[0] - p.x()) + (c[1] - p.y()) * (c[1] - p.y()) +
                    (c[2] - p.z()) * (c[2] - p.z());
    d2[o] = d < far ? d : far; // a pixel without depth (NaN): far
  }
}

/** Candidates beyond which smallestInWindow selects by keys instead of counting ranks: the rank
 * count is quadratic in the candidates, the selection linear (a wide window on a surface seen
 * at an angle holds many candidates within the first k's reach). */
constexpr std::size_t kRankCountLimit = 32;

/** The places in the window of the \a k smallest of \a d2 that are finite, smallest first
 * (ties to the earlier place), in \a nearest (resized to their count). The k smallest are no
 * larger than the largest of the first k finite ones, so only those within it compete; each
 * one's rank among them, counted without a branch, is its place in the answer. Many
 * candidates are selected by a key instead (distance bits above place: the same order, as a
 * finite distance's bits order like the distance), in \a keys. */
void
smallestInWindow(const std::vector<float>& d2, std::size_t k, std::vector<float>& near_d2,
                 std::vector<std::uint32_t>& near_at, std::vector<std::uint64_t>& keys,
                 std::vector<std::uint32_t>& nearest)
{
  const float far = std::numeric_limits<float>::infinity();
  float reach = far, furthest = 0.f;
  for (std::size_t o = 0, seen = 0; o < d2.size(); ++o)
    if (d2[o] < far) {
      furthest = std::max(furthest, d2[o]);
      if (++seen == k) {
        reach = furthest;
        break;
      }
    }
  std::size_t c = 0;
  for (std::size_t o = 0; o < d2.size(); ++o)
    if (d2[o] <= reach && d2[o] < far) {
      near_d2[c] = d2[o];
      near_at[c++] = static_cast<std::uint32_t>(o);
    }
  nearest.resize(std::min(k, c));
  if (c > kRankCountLimit) {
    keys.resize(c);
    for (std::size_t a = 0; a < c; ++a) {
      std::uint32_t bits;
      std::memcpy(&bits, &near_d2[a], sizeof bits); // >= 0: the bits order as the value
      keys[a] = (static_cast<std::uint64_t>(bits) << 32) | near_at[a];
    }
    const auto kth = keys.begin() + static_cast<std::ptrdiff_t>(nearest.size());
    std::nth_element(keys.begin(), kth - 1, keys.end());
    std::sort(keys.begin(), kth);
    for (std::size_t j = 0; j < nearest.size(); ++j)
      nearest[j] = static_cast<std::uint32_t>(keys[j] & 0xffffffffu);
    return;
  }
  const float* nd = near_d2.data();
  for (std::size_t a = 0; a < c; ++a) {
    const float da = nd[a];
    unsigned rank = 0;
    for (std::size_t b = 0; b < a; ++b)
      rank += nd[b] <= da ? 1u : 0u;
    for (std::size_t b = a + 1; b < c; ++b)
      rank += nd[b] < da ? 1u : 0u;
    if (rank < k)
      nearest[rank] = near_at[a];
  }
}

} // namespace

void
nearestInImage(const Eigen::Matrix3Xf& surface, int width, const std::vector<int>& queries, int k,
               Neighbourhoods& out, int threads, int radius)
{
  if (k < 1)
    throw std::invalid_argument("facyl::nearestInImage: k must be at least 1");
  if (radius < 0)
    throw std::invalid_argument("facyl::nearestInImage: the window's radius " +
                                std::to_string(radius) + " is negative");
  if (width < 1 || surface.cols() % width != 0)
    throw std::invalid_argument("facyl::nearestInImage: " + std::to_string(surface.cols()) +
                                " pixels are not rows of width " + std::to_string(width));
  const Eigen::Index pixels = surface.cols();
  if (std::any_of(queries.begin(), queries.end(), [&](int q) { return q < 0 || q >= pixels; }))
    throw std::invalid_argument("facyl::nearestInImage: a query is not a pixel of the surface");
  const int height = static_cast<int>(pixels / width);
  const ImageWindow window(radius > 0 ? radius : imageWindowRadius(k), width);
  const std::size_t n = queries.size(), size = window.steps.size();
  const auto kk = static_cast<std::size_t>(k);
  // Query i's neighbours first go to indices[i * k ...] and its count to offsets[i + 1]; the
  // lists are then packed in place (each moves towards the front, in order), so a reused
  // \a out allocates nothing.
  out.indices.resize(n * kk);
  out.offsets.assign(n + 1, 0);
  parallelFor(n, threads, kQueryGrain, [&](std::size_t begin, std::size_t end) {
    std::vector<float> d2(size), near_d2(size);
    std::vector<std::uint32_t> near_at(size), nearest;
    std::vector<std::uint64_t> keys;
    for (std::size_t i = begin; i < end; ++i) {
      const int q = queries[i];
      if (!surface.col(q).allFinite())
        continue;
      windowDistances(surface, width, height, window, q, q % width, q / width, d2);
      smallestInWindow(d2, kk, near_d2, near_at, keys, nearest);
      for (std::size_t j = 0; j < nearest.size(); ++j)
        out.indices[i * kk + j] = q + window.steps[nearest[j]];
      out.offsets[i + 1] = nearest.size();
    }
  });
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t count = out.offsets[i + 1];
    out.offsets[i + 1] = out.offsets[i] + count;
    std::copy_n(out.indices.begin() + static_cast<std::ptrdiff_t>(i * kk), count,
                out.indices.begin() + static_cast<std::ptrdiff_t>(out.offsets[i]));
  }
  out.indices.resize(out.offsets[n]);
}

Neighbourhoods
nearestInImage(const Eigen::Matrix3Xf& surface, int width, const std::vector<int>& queries, int k,
               int threads, int radius)
{
  Neighbourhoods out;
  nearestInImage(surface, width, queries, k, out, threads, radius);
  return out;
}

} // namespace facyl
