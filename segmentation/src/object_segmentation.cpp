/*
 * facyl: fast cylinder detection for PCL.
 * The edge-aware object segmentation (object_segmentation.h): the grid of valid pixels
 * (object_grid.h), concave creases, connected components; the joins in object_joins.cpp.
 */
#include <facyl/segmentation/object_segmentation.h>

#include "object_grid.h"
#include "object_joins.h"

#include <facyl/features/parallel.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <numeric>
#include <sstream>

namespace facyl {

std::string
validate(const ObjectSegmentationParameters& p)
{
  std::ostringstream s;
  if (!(p.jump_factor > 0.f) || !std::isfinite(p.jump_factor))
    s << "jump_factor must be > 0";
  else if (!(p.min_gap > 0.f && p.max_gap >= p.min_gap && std::isfinite(p.max_gap)))
    s << "gaps must satisfy 0 < min_gap <= max_gap";
  else if (!(p.crease_span > 0.f && p.crease_span <= 0.2f) ||
           !(p.crease_span_z2 >= 0.f && p.crease_span_z2 <= 0.2f))
    s << "crease spans must be in (0, 0.2] m (crease_span_z2 in [0, 0.2])";
  else if (!(p.crease_angle >= 0.f && p.crease_angle < 3.1f))
    s << "crease_angle must be in [0, pi)";
  else if (!(p.enclosed_share > 0.f && p.enclosed_share <= 1.f))
    s << "enclosed_share must be in (0, 1]";
  else if (!(p.bridge_max_gap > 0.f && p.bridge_max_gap <= 2.f) ||
           !(p.bridge_angle > 0.f && p.bridge_angle < 1.57f) || !(p.bridge_distance > 0.f))
    s << "bridge settings must be positive (gap <= 2 m, angle < pi/2)";
  else if (!(p.colour_edge >= 0.f && p.colour_edge <= 100.f))
    s << "colour_edge must be in [0, 100] (0: off)";
  return s.str();
}

namespace edge_aware {
namespace {

/** A weak crease turns by this share of the crease angle: where two touching objects meet,
 * the surface turns less than at a crease once noise and the pixel footprint blur the valley
 * (colourCuts). */
constexpr float kWeakCrease = 0.5f;
/** How far (pixels) from an edge a weak crease may take a colour edge (colourCuts). */
constexpr int kColourReach = 2;

class UnionFind {
public:
  explicit UnionFind(std::size_t n)
      : parent_(n)
  {
    std::iota(parent_.begin(), parent_.end(), 0);
  }
  int find(int a)
  {
    while (parent_[static_cast<std::size_t>(a)] != a) {
      auto& p = parent_[static_cast<std::size_t>(a)];
      p = parent_[static_cast<std::size_t>(p)];
      a = p;
    }
    return a;
  }
  void unite(int a, int b)
  {
    a = find(a), b = find(b);
    if (a != b)
      parent_[static_cast<std::size_t>(std::max(a, b))] = std::min(a, b);
  }

private:
  std::vector<int> parent_;
};

/** The valid pixels a block of a per-pixel pass takes (blocks run on several threads). */
constexpr std::size_t kPixelBlock = 8192;

/** Per valid pixel: the mean of the valid points among the 5 pixels centred on it across a
 * test direction (vertical for horizontal tests), when at least 3 are valid; on \a threads
 * threads (each pixel alone: the same means on any number). */
struct AcrossMeans {
  std::vector<Eigen::Vector3f> mean;
  std::vector<std::uint8_t> ok;
};

AcrossMeans
acrossMeans(const Grid& grid, bool horizontal, int threads)
{
  AcrossMeans m;
  m.mean.resize(grid.size());
  m.ok.assign(grid.size(), 0);
  parallelFor(grid.size(), threads, kPixelBlock, [&](std::size_t begin, std::size_t end) {
    for (std::size_t c = begin; c < end; ++c) {
      int u, v;
      grid.position(static_cast<int>(c), u, v);
      Eigen::Vector3f sum = Eigen::Vector3f::Zero();
      int n = 0;
      int line[5]; // across the test direction: a column for horizontal tests
      grid.across(u, v, horizontal, line);
      for (const int b : line) {
        if (b >= 0) {
          sum += grid.point(b);
          ++n;
        }
      }
      if (n >= 3) {
        m.mean[c] = sum / static_cast<float>(n);
        m.ok[c] = 1;
      }
    }
  });
  return m;
}

/** std::lround(x), inline (lround is a library call): half away from zero in double, where
 * x + 0.5 is exact for every float; NaN, infinity and |x| >= 9.2e18 give LONG_MIN, as lround
 * does on x86-64 where a long does not hold the result. */
long
roundHalfAway(float x)
{
  if (!(std::abs(x) < 9.2e18f))
    return std::numeric_limits<long>::min();
  const double d = static_cast<double>(x);
  return static_cast<long>(d >= 0.0 ? std::floor(d + 0.5) : std::ceil(d - 0.5));
}

/** Per valid pixel: 1 on a concave crease (see concaveCreases); with \a weak, also 1 in it
 * where the surface turns by half the crease angle (kWeakCrease), in the same pass; on
 * \a threads threads (each pixel alone: the same answer on any number). */
std::vector<std::uint8_t>
creases(const Grid& grid, float focal, const Eigen::Vector3f& viewpoint,
        const ObjectSegmentationParameters& p, std::vector<std::uint8_t>* weak, int threads)
{
  std::vector<std::uint8_t> crease(grid.size(), 0);
  if (weak)
    weak->assign(grid.size(), 0);
  if (!(p.crease_angle > 0.f) || !(focal > 0.f))
    return crease;
  const float cos_max = std::cos(p.crease_angle);
  const float cos_weak = weak ? std::cos(kWeakCrease * p.crease_angle) : cos_max;
  const AcrossMeans across[2] = {acrossMeans(grid, true, threads),
                                 acrossMeans(grid, false, threads)};
  parallelFor(grid.size(), threads, kPixelBlock, [&](std::size_t begin, std::size_t end) {
    for (std::size_t c = begin; c < end; ++c) {
      const float range = grid.range(static_cast<int>(c));
      const float span = std::max(p.crease_span, p.crease_span_z2 * range * range);
      const int k = std::clamp(static_cast<int>(roundHalfAway(span * focal / range)), 2, 24);
      int u, v;
      grid.position(static_cast<int>(c), u, v);
      for (int dir = 0; dir < 2 && !crease[c]; ++dir) {
        const AcrossMeans& m = across[dir];
        const int a = dir == 0 ? grid.at(u - k, v) : grid.at(u, v - k);
        const int z = dir == 0 ? grid.at(u + k, v) : grid.at(u, v + k);
        if (a < 0 || z < 0 || !m.ok[c] || !m.ok[static_cast<std::size_t>(a)] ||
            !m.ok[static_cast<std::size_t>(z)])
          continue;
        const Eigen::Vector3f& pa = m.mean[static_cast<std::size_t>(a)];
        const Eigen::Vector3f& pb = m.mean[c];
        const Eigen::Vector3f& pc = m.mean[static_cast<std::size_t>(z)];
        const Eigen::Vector3f e1 = pb - pa, e2 = pc - pb;
        const float l1 = e1.norm(), l2 = e2.norm();
        // Much longer than the span: a depth jump, which the connection test handles.
        if (!(l1 > 0.f && l2 > 0.f) || l1 > 8.f * span || l2 > 8.f * span)
          continue;
        const float turn = e1.dot(e2);
        if (turn > cos_weak * l1 * l2)
          continue;
        // Concave seen from the sensor: the middle lies behind the chord.
        if ((pb - 0.5f * (pa + pc)).dot(pb - viewpoint) <= 0.f)
          continue;
        if (weak)
          (*weak)[c] = 1;
        crease[c] = turn <= cos_max * l1 * l2;
      }
    }
  });
  return crease;
}

/** Connected components of the valid pixels accepted by \a use (and unlabelled), over linked
 * neighbours; numbers them from \a next on in \a label. \return the next free number. */
template <typename Use>
int
components(const Grid& grid, Use use, std::vector<int>& label, int next)
{
  UnionFind uf(grid.size());
  for (int a = 0; a < static_cast<int>(grid.size()); ++a) {
    if (label[static_cast<std::size_t>(a)] >= 0 || !use(a))
      continue;
    int u, v;
    grid.position(a, u, v);
    for (const int b : {grid.at(u + 1, v), grid.at(u, v + 1)})
      if (b >= 0 && label[static_cast<std::size_t>(b)] < 0 && use(b) && grid.linked(a, b))
        uf.unite(a, b);
  }
  std::vector<int> number(grid.size(), -1);
  for (int a = 0; a < static_cast<int>(grid.size()); ++a) {
    if (label[static_cast<std::size_t>(a)] >= 0 || !use(a))
      continue;
    int& n = number[static_cast<std::size_t>(uf.find(a))];
    if (n < 0)
      n = next++;
    label[static_cast<std::size_t>(a)] = n;
  }
  return next;
}

/** The squared difference of the colours of valid pixels \a a and \a b (ColourImage::distance2). */
float
colourDifference2(const Grid& grid, const ColourImage& colour, int a, int b)
{
  return static_cast<float>(colour.distance2(grid.pixel(a), grid.pixel(b)));
}

/** The pixels where colour edges cut objects apart that depth alone cannot tell (see
 * ObjectSegmentationParameters::colour_edge): both pixels of each linked pair whose colours
 * differ by more than colour_edge times the typical difference of linked neighbours (the
 * median of a sample: noise, texture, shading), one of them on a weak crease that continues
 * an edge (a depth discontinuity, a missing neighbour or a crease within kColourReach pixels:
 * noise alone makes weak creases everywhere on a far surface). Sets \a threshold2 to the
 * squared colour difference of an edge. Empty without \a colour (nullptr: colour edges off). */
std::vector<std::uint8_t>
colourCuts(const Grid& grid, const ColourImage* colour, const std::vector<std::uint8_t>& weak,
           const std::vector<std::uint8_t>& crease, const ObjectSegmentationParameters& p,
           float& threshold2)
{
  std::vector<std::uint8_t> cut;
  if (!colour)
    return cut;
  const int n = static_cast<int>(grid.size());
  std::vector<float> sample;
  const int step = std::max(1, n / 4096);
  for (int a = 0; a < n; a += step) {
    int u, v;
    grid.position(a, u, v);
    for (const int b : {grid.at(u + 1, v), grid.at(u, v + 1)})
      if (b >= 0 && grid.linked(a, b))
        sample.push_back(colourDifference2(grid, *colour, a, b));
  }
  if (sample.empty())
    return cut;
  const auto mid = sample.begin() + static_cast<std::ptrdiff_t>(sample.size() / 2);
  std::nth_element(sample.begin(), mid, sample.end());
  // At least one level of an 8-bit channel: a flat colour has no edges.
  threshold2 = p.colour_edge * p.colour_edge * std::max(*mid, 1.f);
  // Whether a pixel is on an edge, found when first asked (0: not yet, 1: no, 2: yes).
  std::vector<std::uint8_t> edge(grid.size(), 0);
  const auto onEdge = [&](int b) {
    std::uint8_t& e = edge[static_cast<std::size_t>(b)];
    if (e == 0) {
      bool yes = crease[static_cast<std::size_t>(b)] != 0;
      if (!yes)
        grid.forNeighbours(
          b, [&](int c) { yes = yes || !grid.linked(b, c); }, [&] { yes = true; });
      e = yes ? 2 : 1;
    }
    return e == 2;
  };
  const auto nearEdge = [&](int a) {
    int u, v;
    grid.position(a, u, v);
    for (int dv = -kColourReach; dv <= kColourReach; ++dv)
      for (int du = -kColourReach; du <= kColourReach; ++du) {
        const int b = grid.at(u + du, v + dv);
        if (b >= 0 && onEdge(b))
          return true;
      }
    return false;
  };
  cut.assign(grid.size(), 0);
  for (int a = 0; a < n; ++a)
    if (weak[static_cast<std::size_t>(a)] && nearEdge(a))
      grid.forNeighbours(
        a,
        [&](int b) {
          if (colourDifference2(grid, *colour, a, b) > threshold2 && grid.linked(a, b))
            cut[static_cast<std::size_t>(a)] = cut[static_cast<std::size_t>(b)] = 1;
        },
        [] {});
  return cut;
}

/** The pixels left out of the components (\a label -1: on a crease or a colour cut) join the
 * component that reaches them first (breadth first from all); first a colour-cut pixel
 * (\a cut) only from a pixel of its colour (within \a threshold2: the other side's is another
 * object), then from any that reaches it. */
void
joinApartPixels(const Grid& grid, const ColourImage* colour, const std::vector<std::uint8_t>& cut,
                float threshold2, std::vector<int>& label)
{
  std::vector<int> queue;
  queue.reserve(grid.size());
  for (int a = 0; a < static_cast<int>(grid.size()); ++a)
    if (label[static_cast<std::size_t>(a)] >= 0)
      queue.push_back(a);
  std::vector<int> deferred; // reached a colour-cut pixel of another colour
  for (std::size_t head = 0; head < queue.size(); ++head) {
    const int a = queue[head];
    grid.forNeighbours(
      a,
      [&](int b) {
        if (label[static_cast<std::size_t>(b)] >= 0 || !grid.linked(a, b))
          return;
        if (!cut.empty() && cut[static_cast<std::size_t>(b)] &&
            colourDifference2(grid, *colour, a, b) > threshold2) {
          deferred.push_back(a);
          return;
        }
        label[static_cast<std::size_t>(b)] = label[static_cast<std::size_t>(a)];
        queue.push_back(b);
      },
      [] {});
  }
  // Then from those to the colour-cut pixels no pixel of their colour reached.
  for (std::size_t head = 0; head < deferred.size(); ++head) {
    const int a = deferred[head];
    grid.forNeighbours(
      a,
      [&](int b) {
        if (label[static_cast<std::size_t>(b)] < 0 && grid.linked(a, b)) {
          label[static_cast<std::size_t>(b)] = label[static_cast<std::size_t>(a)];
          deferred.push_back(b);
        }
      },
      [] {});
  }
}

/** segmentObjectsOrganized on its grid of valid pixels. */
std::vector<pcl::Indices>
segmentGrid(const Grid& grid, const std::vector<std::uint8_t>& has_depth, float focal,
            const Eigen::Vector3f& viewpoint, const ObjectSegmentationParameters& p,
            const ColourImage* colour, int threads)
{
  if (grid.size() == 0)
    return {};
  if (!(colour && colour->bgr && p.colour_edge > 0.f))
    colour = nullptr; // colour edges off
  std::vector<std::uint8_t> weak;
  const std::vector<std::uint8_t> crease =
    creases(grid, focal, viewpoint, p, colour ? &weak : nullptr, threads);
  float threshold2 = 0.f;
  const std::vector<std::uint8_t> cut = colourCuts(grid, colour, weak, crease, p, threshold2);
  const auto apart = [&](int a) {
    return crease[static_cast<std::size_t>(a)] ||
           (!cut.empty() && cut[static_cast<std::size_t>(a)]);
  };
  // 1. Components without the crease and colour-cut pixels.
  std::vector<int> label(grid.size(), -1);
  int count = components(
    grid, [&](int a) { return !apart(a); }, label, 0);
  joinApartPixels(grid, colour, cut, threshold2, label);
  // Pixels no component reached (thin parts) are components of their own.
  count = components(
    grid, [](int) { return true; }, label, count);
  // 2. Fragments and enclosed segments join their neighbour; 3. occluded parts are joined.
  Segments segments(grid, std::move(label), count);
  segments.mergeNeighbours(p.min_fragment, p.enclosed_share);
  if (p.bridge_occlusions)
    segments.bridgeOcclusions(has_depth, p.min_fragment, p);
  return segments.indices();
}

} // namespace
} // namespace edge_aware

float
connectionGap(const ObjectSegmentationParameters& params, float range, float focal,
              const std::vector<float>& noise_half)
{
  const float gap = std::clamp(params.jump_factor * range / focal, params.min_gap, params.max_gap);
  // Neighbours on one surface differ by the sensor's noise.
  return noise_half.empty() ? gap : std::max(gap, tabulatedHalfWidth(noise_half, range));
}

float
estimateFocalLength(const pcl::PointCloud<pcl::PointXYZ>& cloud)
{
  if (!cloud.isOrganized() || cloud.width < 8)
    return 0.f;
  const float cx = 0.5f * static_cast<float>(cloud.width - 1);
  std::vector<float> f;
  const std::size_t step = std::max<std::size_t>(1, cloud.size() / 4000);
  for (std::size_t i = 0; i < cloud.size(); i += step) {
    const auto& p = cloud[i];
    const float du = static_cast<float>(i % cloud.width) - cx;
    if (edge_aware::finite(p) && std::abs(du) > 0.1f * cloud.width && p.z > 0.f)
      f.push_back(du * p.z / p.x);
  }
  if (f.size() < 20)
    return 0.f;
  std::nth_element(f.begin(), f.begin() + f.size() / 2, f.end());
  const float focal = f[f.size() / 2];
  return std::isfinite(focal) && focal > 0.f ? focal : 0.f;
}

Eigen::Vector3f
imageDownDirection(const pcl::PointCloud<pcl::PointXYZ>& cloud, const Eigen::Vector3f& viewpoint)
{
  if (!cloud.isOrganized() || cloud.height < 2)
    return Eigen::Vector3f::Zero();
  Eigen::Vector3f sum = Eigen::Vector3f::Zero();
  for (std::uint32_t u = 0; u < cloud.width; ++u) {
    int top = -1, bottom = -1;
    for (std::uint32_t v = 0; v < cloud.height; ++v)
      if (edge_aware::finite(cloud.at(u, v))) {
        if (top < 0)
          top = static_cast<int>(v);
        bottom = static_cast<int>(v);
      }
    if (top < 0 || bottom <= top)
      continue;
    const auto ray = [&](int v) {
      return Eigen::Vector3f(
        (cloud.at(u, static_cast<std::uint32_t>(v)).getVector3fMap() - viewpoint).normalized());
    };
    sum += ray(bottom) - ray(top);
  }
  const float n = sum.norm();
  return n > 0.f && std::isfinite(n) ? Eigen::Vector3f(sum / n) : Eigen::Vector3f::Zero();
}

std::vector<std::uint8_t>
concaveCreases(const pcl::PointCloud<pcl::PointXYZ>& cloud, float focal,
               const Eigen::Vector3f& viewpoint, const ObjectSegmentationParameters& p)
{
  std::vector<std::uint8_t> out(cloud.size(), 0);
  if (!cloud.isOrganized() || !(focal > 0.f))
    return out;
  const edge_aware::Grid grid(cloud, focal, viewpoint, p);
  const std::vector<std::uint8_t> crease =
    edge_aware::creases(grid, focal, viewpoint, p, nullptr, 1);
  for (std::size_t c = 0; c < grid.size(); ++c)
    out[grid.pixel(static_cast<int>(c))] = crease[c];
  return out;
}

long
closestPixelPair(const PixelList& a, const PixelList& b, std::size_t& ka, std::size_t& kb,
                 long enough)
{
  ka = kb = std::numeric_limits<std::size_t>::max();
  const std::size_t na = std::min(a.u.size(), a.v.size()), nb = std::min(b.u.size(), b.v.size());
  if (na == 0 || nb == 0)
    return -1;
  // b's bounding box bounds each pixel's distance to b from below.
  const auto bu = std::minmax_element(b.u.begin(), b.u.begin() + static_cast<std::ptrdiff_t>(nb));
  const auto bv = std::minmax_element(b.v.begin(), b.v.begin() + static_cast<std::ptrdiff_t>(nb));
  const std::int64_t u0 = *bu.first, u1 = *bu.second, v0 = *bv.first, v1 = *bv.second;
  // Differences below 2^15 (b's box and a pixel's distance to it below 2^14 a side) have
  // squared distances within 32 bits: the reduction then runs 4 or 8 wide.
  const bool narrow = u1 - u0 < 16384 && v1 - v0 < 16384;
  const int* ub = b.u.data();
  const int* vb = b.v.data();
  std::int64_t best = std::numeric_limits<std::int64_t>::max();
  for (std::size_t i = 0; i < na; ++i) {
    const std::int64_t ui = a.u[i], vi = a.v[i];
    const std::int64_t du = std::max({u0 - ui, ui - u1, std::int64_t{0}});
    const std::int64_t dv = std::max({v0 - vi, vi - v1, std::int64_t{0}});
    if (du * du + dv * dv >= best)
      continue; // no pair of this pixel is strictly closer
    // Its closest distance first (a plain reduction), then the first pair at it.
    std::int64_t nearest = std::numeric_limits<std::int64_t>::max();
    if (narrow && du < 16384 && dv < 16384) {
      const int x0 = static_cast<int>(ui), y0 = static_cast<int>(vi);
      int m = std::numeric_limits<int>::max();
      for (std::size_t j = 0; j < nb; ++j) {
        const int x = ub[j] - x0, y = vb[j] - y0;
        m = std::min(m, x * x + y * y);
      }
      nearest = m;
    }
    else
      for (std::size_t j = 0; j < nb; ++j) {
        const std::int64_t x = ub[j] - ui, y = vb[j] - vi;
        nearest = std::min(nearest, x * x + y * y);
      }
    if (nearest >= best)
      continue;
    best = nearest;
    ka = i;
    for (std::size_t j = 0; j < nb; ++j) {
      const std::int64_t x = ub[j] - ui, y = vb[j] - vi;
      if (x * x + y * y == nearest) {
        kb = j;
        break;
      }
    }
    if (best <= enough)
      break;
  }
  return static_cast<long>(best);
}

bool
strictlyAscending(const pcl::Indices& indices)
{
  return std::adjacent_find(indices.begin(), indices.end(),
                            [](auto a, auto b) { return a >= b; }) == indices.end();
}

std::vector<pcl::Indices>
segmentObjectsOrganized(const pcl::PointCloud<pcl::PointXYZ>& cloud,
                        const std::vector<std::uint8_t>& has_depth, float focal,
                        const Eigen::Vector3f& viewpoint, const ObjectSegmentationParameters& p,
                        const DepthBand* noise, const pcl::Indices* finite, int threads)
{
  if (!cloud.isOrganized() || !(focal > 0.f) || has_depth.size() != cloud.size())
    return {};
  if (finite && !strictlyAscending(*finite))
    finite = nullptr; // not strictly ascending: the grid's order is the image's, so scan
  return edge_aware::segmentGrid(edge_aware::Grid(cloud, focal, viewpoint, p, noise, finite),
                                 has_depth, focal, viewpoint, p, nullptr, threads);
}

std::vector<pcl::Indices>
segmentObjectsOrganized(const Eigen::Matrix3Xf& points, const pcl::Indices& pixels,
                        std::uint32_t width, std::uint32_t height,
                        const std::vector<std::uint8_t>& has_depth, float focal,
                        const Eigen::Vector3f& viewpoint, const ObjectSegmentationParameters& p,
                        const DepthBand* noise, const ColourImage* colour, int threads)
{
  const std::size_t size = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  if (width == 0 || height < 2 || !(focal > 0.f) || has_depth.size() != size ||
      points.cols() != static_cast<Eigen::Index>(pixels.size()) || !strictlyAscending(pixels) ||
      (!pixels.empty() && (pixels.front() < 0 || static_cast<std::size_t>(pixels.back()) >= size)))
    return {};
  return edge_aware::segmentGrid(edge_aware::Grid(points, pixels, static_cast<int>(width),
                                                  static_cast<int>(height), focal, viewpoint, p,
                                                  noise),
                                 has_depth, focal, viewpoint, p, colour, threads);
}

} // namespace facyl
