/*
 * facyl: fast cylinder detection for PCL.
 */
#include <facyl/segmentation/object_segmentation.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <numeric>
#include <sstream>
#include <unordered_map>

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
  return s.str();
}

namespace {

bool
finite(const pcl::PointXYZ& p)
{
  return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
}

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

/** The valid pixels of an organized cloud, numbered compactly (in image order), with their
 * ranges and the connection test between neighbours. */
class Grid {
public:
  /** The finite pixels of \a cloud: \a finite (ascending) when given, else all of them. */
  Grid(const pcl::PointCloud<pcl::PointXYZ>& cloud, float focal, const Eigen::Vector3f& viewpoint,
       const ObjectSegmentationParameters& p, const DepthBand* noise = nullptr,
       const pcl::Indices* finite_pixels = nullptr)
      : Grid(static_cast<int>(cloud.width), static_cast<int>(cloud.height), focal, viewpoint, p,
             noise, finite_pixels ? finite_pixels->size() : countFinite(cloud), finite_pixels)
  {
    if (finite_pixels) {
      for (const auto idx : *finite_pixels) {
        const auto i = static_cast<std::size_t>(idx);
        if (finite(cloud[i]))
          add(i, static_cast<int>(i % static_cast<std::size_t>(w_)),
              static_cast<int>(i / static_cast<std::size_t>(w_)), cloud[i].getVector3fMap());
      }
      return;
    }
    // Row by row: the pixel's column and row without a division per pixel.
    for (int v = 0, i = 0; v < h_; ++v)
      for (int u = 0; u < w_; ++u, ++i)
        if (finite(cloud[static_cast<std::size_t>(i)]))
          add(static_cast<std::size_t>(i), u, v,
              cloud[static_cast<std::size_t>(i)].getVector3fMap());
  }
  /** The finite columns of \a points, at the pixels \a pixels (ascending) of a \a width x
   * \a height image. */
  Grid(const Eigen::Matrix3Xf& points, const pcl::Indices& pixels, int width, int height,
       float focal, const Eigen::Vector3f& viewpoint, const ObjectSegmentationParameters& p,
       const DepthBand* noise)
      : Grid(width, height, focal, viewpoint, p, noise, pixels.size(), &pixels)
  {
    for (std::size_t k = 0; k < pixels.size(); ++k) {
      const auto i = static_cast<std::size_t>(pixels[k]);
      const auto c = static_cast<Eigen::Index>(k);
      if (points.col(c).allFinite())
        add(i, static_cast<int>(i % static_cast<std::size_t>(w_)),
            static_cast<int>(i / static_cast<std::size_t>(w_)), points.col(c));
    }
  }
  int width() const
  {
    return w_;
  }
  int height() const
  {
    return h_;
  }
  /** Valid pixels. */
  std::size_t size() const
  {
    return pixel_.size();
  }
  std::size_t pixel(int c) const
  {
    return pixel_[static_cast<std::size_t>(c)];
  }
  /** Compact number of pixel (u, v), or -1 (outside the image, or not valid). */
  int at(int u, int v) const
  {
    // One unsigned comparison per coordinate: negative ones wrap beyond the size.
    if (static_cast<unsigned>(u) >= static_cast<unsigned>(w_) ||
        static_cast<unsigned>(v - v0_) >= static_cast<unsigned>(rows_))
      return -1;
    return slot_[static_cast<std::size_t>(v - v0_) * static_cast<std::size_t>(w_) +
                 static_cast<std::size_t>(u)];
  }
  /** at() of the five pixels centred on the valid pixel (\a u, \a v) along a column
   * (\a vertical) or a row: one bounds test per pixel, no multiplication. */
  void across(int u, int v, bool vertical, int (&out)[5]) const
  {
    const std::ptrdiff_t step = vertical ? w_ : 1;
    const int along = vertical ? v - v0_ : u, size = vertical ? rows_ : w_;
    const int* centre = slot_.data() +
                        static_cast<std::ptrdiff_t>(v - v0_) * static_cast<std::ptrdiff_t>(w_) +
                        static_cast<std::ptrdiff_t>(u);
    for (int d = -2; d <= 2; ++d)
      out[d + 2] =
        static_cast<unsigned>(along + d) < static_cast<unsigned>(size) ? centre[d * step] : -1;
  }
  const Eigen::Vector3f& point(int c) const
  {
    return xyz_[static_cast<std::size_t>(c)];
  }
  float range(int c) const
  {
    return range_[static_cast<std::size_t>(c)];
  }
  /** Neighbours a and b are on one surface: no depth discontinuity. */
  bool linked(int a, int b) const
  {
    const float g2 =
      std::min(gap2_[static_cast<std::size_t>(a)], gap2_[static_cast<std::size_t>(b)]);
    return (point(a) - point(b)).squaredNorm() < g2;
  }
  /** Calls f(b) for each valid 4-neighbour b of a, and g() for each other neighbour. */
  template <typename F, typename G> void forNeighbours(int a, F f, G g) const
  {
    const int u = u_[static_cast<std::size_t>(a)], v = v_[static_cast<std::size_t>(a)];
    for (const int b : {at(u + 1, v), at(u - 1, v), at(u, v + 1), at(u, v - 1)}) {
      if (b >= 0)
        f(b);
      else
        g();
    }
  }
  /** Image position of valid pixel c. */
  void position(int c, int& u, int& v) const
  {
    u = u_[static_cast<std::size_t>(c)];
    v = v_[static_cast<std::size_t>(c)];
  }

private:
  /** An empty grid of a \a width x \a height image, with room for \a valid pixels; given
   * its \a pixels (ascending), its slots span only their rows. */
  Grid(int width, int height, float focal, const Eigen::Vector3f& viewpoint,
       const ObjectSegmentationParameters& p, const DepthBand* noise, std::size_t valid,
       const pcl::Indices* pixels)
      : w_(width)
      , h_(height)
      , v0_(pixels && !pixels->empty() && width > 0 ? pixels->front() / width : 0)
      , rows_(pixels && width > 0 ? (pixels->empty() ? 0 : pixels->back() / width - v0_ + 1)
                                  : height)
      , slot_(static_cast<std::size_t>(width) * static_cast<std::size_t>(rows_), -1)
      , focal_(focal)
      , viewpoint_(viewpoint)
      , p_(p)
  {
    if (noise)
      noise_half_ = tabulateHalfWidths(*noise);
    pixel_.reserve(valid);
    xyz_.reserve(valid);
    u_.reserve(valid);
    v_.reserve(valid);
    range_.reserve(valid);
    gap2_.reserve(valid);
  }
  static std::size_t countFinite(const pcl::PointCloud<pcl::PointXYZ>& cloud)
  {
    std::size_t valid = 0;
    for (const auto& q : cloud)
      valid += finite(q);
    return valid;
  }
  /** Pixel \a i at (\a u, \a v) with the point \a q. */
  void add(std::size_t i, int u, int v, const Eigen::Vector3f& q)
  {
    slot_[i - static_cast<std::size_t>(v0_) * static_cast<std::size_t>(w_)] =
      static_cast<int>(pixel_.size());
    pixel_.push_back(i);
    xyz_.push_back(q);
    u_.push_back(u);
    v_.push_back(v);
    const float r = (q - viewpoint_).norm();
    range_.push_back(r);
    const float gap = connectionGap(p_, r, focal_, noise_half_);
    gap2_.push_back(gap * gap);
  }
  int w_, h_;
  int v0_, rows_; ///< the rows that slot_ spans: [v0_, v0_ + rows_)
  std::vector<int> slot_;
  float focal_;
  Eigen::Vector3f viewpoint_;
  ObjectSegmentationParameters p_;
  std::vector<float> noise_half_;
  std::vector<std::size_t> pixel_;
  std::vector<Eigen::Vector3f> xyz_; ///< per valid pixel: its point
  std::vector<int> u_, v_;
  std::vector<float> range_, gap2_;
};

/** Per valid pixel: the mean of the valid points among the 5 pixels centred on it across a
 * test direction (vertical for horizontal tests), when at least 3 are valid. */
struct AcrossMeans {
  std::vector<Eigen::Vector3f> mean;
  std::vector<std::uint8_t> ok;
};

AcrossMeans
acrossMeans(const Grid& grid, bool horizontal)
{
  AcrossMeans m;
  m.mean.resize(grid.size());
  m.ok.assign(grid.size(), 0);
  for (std::size_t c = 0; c < grid.size(); ++c) {
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

/** Per valid pixel: 1 on a concave crease (see concaveCreases). */
std::vector<std::uint8_t>
creases(const Grid& grid, float focal, const Eigen::Vector3f& viewpoint,
        const ObjectSegmentationParameters& p)
{
  std::vector<std::uint8_t> crease(grid.size(), 0);
  if (!(p.crease_angle > 0.f) || !(focal > 0.f))
    return crease;
  const float cos_max = std::cos(p.crease_angle);
  const AcrossMeans across[2] = {acrossMeans(grid, true), acrossMeans(grid, false)};
  for (std::size_t c = 0; c < grid.size(); ++c) {
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
      if (e1.dot(e2) > cos_max * l1 * l2)
        continue;
      // Concave seen from the sensor: the middle lies behind the chord.
      crease[c] = (pb - 0.5f * (pa + pc)).dot(pb - viewpoint) > 0.f;
    }
  }
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

/** Segments as groups of labels, with the statistics the merges need. */
class Segments {
public:
  Segments(const Grid& grid, std::vector<int> label, int count)
      : grid_(grid)
      , label_(std::move(label))
      , group_(static_cast<std::size_t>(count))
      , size_(static_cast<std::size_t>(count), 0)
      , boundary_(static_cast<std::size_t>(count), 0)
  {
    std::iota(group_.begin(), group_.end(), 0);
    // The pairs of neighbours across segment borders, then summed per pair of segments.
    std::vector<std::pair<std::uint64_t, std::uint8_t>> pairs; // (labels, connected)
    for (int i = 0; i < static_cast<int>(grid_.size()); ++i) {
      const int a = label_[static_cast<std::size_t>(i)];
      ++size_[static_cast<std::size_t>(a)];
      grid_.forNeighbours(
        i,
        [&](int j) {
          const int b = label_[static_cast<std::size_t>(j)];
          if (b == a)
            return;
          ++boundary_[static_cast<std::size_t>(a)];
          pairs.emplace_back(key(a, b), static_cast<std::uint8_t>(grid_.linked(i, j)));
        },
        [&] { ++boundary_[static_cast<std::size_t>(a)]; });
    }
    std::sort(pairs.begin(), pairs.end(),
              [](const auto& x, const auto& y) { return x.first < y.first; });
    for (const auto& [k, connected] : pairs) {
      if (links_.empty() || links_.back().first != k)
        links_.emplace_back(k, Link{});
      ++links_.back().second.all;
      links_.back().second.connected += connected;
    }
  }

  /** Fragments, then enclosed segments, join a neighbour, until nothing changes. */
  void mergeNeighbours(std::size_t min_fragment, float enclosed_share)
  {
    // Each pass joins every segment to its best neighbour at once; chains of fragments need a
    // pass per link. A noisy frame can shatter into thousands of fragments: after kMaxPasses
    // the few still apart are left to the cluster size limits.
    constexpr int kMaxPasses = 12;
    bool changed = true;
    for (int pass = 0; changed && pass < kMaxPasses; ++pass) {
      changed = false;
      const GroupStats stats = groupStats();
      for (int g = 0; g < static_cast<int>(stats.size.size()); ++g) {
        const auto gs = static_cast<std::size_t>(g);
        if (stats.size[gs] == 0 || find(g) != g)
          continue; // not a group, or merged in this pass already
        int best = -1;
        std::size_t best_links = 0;
        for (std::size_t l = stats.first[gs]; l < stats.first[gs + 1]; ++l) {
          const GroupLink& link = stats.links[l];
          if (find(link.to) != g && link.connected > best_links &&
              stats.size[static_cast<std::size_t>(link.to)] >= stats.size[gs])
            best = link.to, best_links = link.connected;
        }
        if (best < 0)
          continue;
        const bool fragment = stats.size[gs] < min_fragment;
        const bool enclosed =
          static_cast<float>(best_links) >= enclosed_share * static_cast<float>(stats.boundary[gs]);
        if (fragment || enclosed) {
          group_[gs] = find(best);
          changed = true;
        }
      }
    }
  }

  /** Joins the parts of one surface on both sides of a nearer occluder. */
  void bridgeOcclusions(const std::vector<std::uint8_t>& has_depth, std::size_t min_part,
                        const ObjectSegmentationParameters& p)
  {
    // The pixels of each group of at least min_part (ascending), the groups by their root.
    std::vector<int> root(grid_.size());
    std::vector<std::size_t> size(group_.size(), 0);
    for (std::size_t i = 0; i < grid_.size(); ++i)
      ++size[static_cast<std::size_t>(root[i] = find(label_[i]))];
    std::vector<int> groups, slot(group_.size(), -1);
    for (std::size_t g = 0; g < size.size(); ++g)
      if (size[g] > 0 && size[g] >= min_part) {
        slot[g] = static_cast<int>(groups.size());
        groups.push_back(static_cast<int>(g));
      }
    std::vector<std::vector<int>> pixels(groups.size());
    for (std::size_t k = 0; k < groups.size(); ++k)
      pixels[k].reserve(size[static_cast<std::size_t>(groups[k])]);
    for (std::size_t i = 0; i < grid_.size(); ++i)
      if (const int k = slot[static_cast<std::size_t>(root[i])]; k >= 0)
        pixels[static_cast<std::size_t>(k)].push_back(static_cast<int>(i));
    std::vector<std::vector<int>> borders(groups.size());
    std::vector<Eigen::AlignedBox3f> boxes(groups.size());
    for (std::size_t k = 0; k < groups.size(); ++k) {
      borders[k] = border(pixels[k], groups[k], root);
      for (const int i : pixels[k])
        boxes[k].extend(grid_.point(i));
    }
    for (std::size_t a = 0; a < groups.size(); ++a)
      for (std::size_t b = a + 1; b < groups.size(); ++b) {
        const int g = find(groups[a]), h = find(groups[b]);
        if (g == h || boxes[a].exteriorDistance(boxes[b]) > p.bridge_max_gap)
          continue;
        if (sameSurfaceBehind(pixels[a], pixels[b], borders[a], borders[b], g, h, has_depth, p))
          group_[static_cast<std::size_t>(std::max(g, h))] = std::min(g, h);
      }
  }

  /** Point indices of every group, ascending. */
  std::vector<pcl::Indices> indices() const
  {
    std::vector<int> slot(group_.size(), -1);
    std::vector<pcl::Indices> out;
    for (int i = 0; i < static_cast<int>(grid_.size()); ++i) {
      const int g = findConst(label_[static_cast<std::size_t>(i)]);
      int& k = slot[static_cast<std::size_t>(g)];
      if (k < 0) {
        k = static_cast<int>(out.size());
        out.emplace_back();
      }
      out[static_cast<std::size_t>(k)].push_back(static_cast<pcl::index_t>(grid_.pixel(i)));
    }
    return out;
  }

private:
  struct Link {
    std::size_t all{0};       ///< 4-neighbour pairs across the border
    std::size_t connected{0}; ///< of which without a depth discontinuity
  };
  /** A link from one group to another, summed over their labels. */
  struct GroupLink {
    int from{0}, to{0};
    std::size_t all{0}, connected{0};
  };
  /** Per group (indexed by its root label; size 0 for other labels): size, boundary, and its
   * links to other groups, links[first[g] .. first[g + 1]). */
  struct GroupStats {
    std::vector<std::size_t> size, boundary, first;
    std::vector<GroupLink> links;
  };

  static std::uint64_t key(int a, int b)
  {
    return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) |
           static_cast<std::uint32_t>(b);
  }
  int find(int a)
  {
    while (group_[static_cast<std::size_t>(a)] != a)
      a = group_[static_cast<std::size_t>(a)] =
        group_[static_cast<std::size_t>(group_[static_cast<std::size_t>(a)])];
    return a;
  }
  int findConst(int a) const
  {
    while (group_[static_cast<std::size_t>(a)] != a)
      a = group_[static_cast<std::size_t>(a)];
    return a;
  }

  GroupStats groupStats()
  {
    const std::size_t n = size_.size();
    GroupStats stats;
    stats.size.assign(n, 0);
    stats.boundary.assign(n, 0);
    for (std::size_t s = 0; s < n; ++s) {
      const auto g = static_cast<std::size_t>(find(static_cast<int>(s)));
      stats.size[g] += size_[s];
      stats.boundary[g] += boundary_[s];
    }
    for (const auto& [k, link] : links_) {
      const int g = find(static_cast<int>(k >> 32)), h = find(static_cast<int>(k & 0xffffffffu));
      if (g == h) { // inside one group now: not boundary
        stats.boundary[static_cast<std::size_t>(g)] -= link.all;
        continue;
      }
      stats.links.push_back({g, h, link.all, link.connected});
    }
    // Summed per pair of groups, grouped by the first.
    std::sort(stats.links.begin(), stats.links.end(), [](const GroupLink& a, const GroupLink& b) {
      return a.from != b.from ? a.from < b.from : a.to < b.to;
    });
    std::vector<GroupLink> summed;
    for (const GroupLink& l : stats.links) {
      if (!summed.empty() && summed.back().from == l.from && summed.back().to == l.to) {
        summed.back().all += l.all;
        summed.back().connected += l.connected;
      }
      else
        summed.push_back(l);
    }
    stats.links.swap(summed);
    stats.first.assign(n + 1, 0);
    for (const GroupLink& l : stats.links)
      ++stats.first[static_cast<std::size_t>(l.from) + 1];
    for (std::size_t g = 0; g < n; ++g)
      stats.first[g + 1] += stats.first[g];
    return stats;
  }

  /** Boundary pixels of a part (a 4-neighbour in another group or none), at most 100; \a root:
   * each pixel's group now. */
  std::vector<int> border(const std::vector<int>& px, int g, const std::vector<int>& root) const
  {
    std::vector<int> out;
    for (const int i : px) {
      bool edge = false;
      grid_.forNeighbours(
        i, [&](int j) { edge = edge || root[static_cast<std::size_t>(j)] != g; },
        [&] { edge = true; });
      if (edge)
        out.push_back(i);
    }
    if (out.size() > 100) {
      std::vector<int> thin;
      for (std::size_t k = 0; k < 100; ++k)
        thin.push_back(out[k * out.size() / 100]);
      out.swap(thin);
    }
    return out;
  }

  /** Plane (centroid, unit normal) of the points of \a px within \a radius of \a centre. */
  bool localPlane(const std::vector<int>& px, const Eigen::Vector3f& centre, float radius,
                  Eigen::Vector3f& centroid, Eigen::Vector3f& normal) const
  {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();
    std::size_t n = 0;
    const std::size_t step = std::max<std::size_t>(1, px.size() / 3000);
    for (std::size_t k = 0; k < px.size(); k += step) {
      const Eigen::Vector3f q = grid_.point(px[k]);
      if ((q - centre).squaredNorm() > radius * radius)
        continue;
      const Eigen::Vector3d d = q.cast<double>();
      sum += d;
      outer += d * d.transpose();
      ++n;
    }
    if (n < 10)
      return false;
    const Eigen::Vector3d mean = sum / static_cast<double>(n);
    const Eigen::Matrix3d cov = outer / static_cast<double>(n) - mean * mean.transpose();
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
    centroid = mean.cast<float>();
    normal = eig.eigenvectors().col(0).cast<float>();
    return true;
  }

  bool sameSurfaceBehind(const std::vector<int>& pa, const std::vector<int>& pb,
                         const std::vector<int>& ba, const std::vector<int>& bb, int g, int h,
                         const std::vector<std::uint8_t>& has_depth,
                         const ObjectSegmentationParameters& p) const
  {
    // The closest border pixels of the two parts, in the image.
    int ia = -1, ib = -1;
    long best = std::numeric_limits<long>::max();
    for (const int i : ba) {
      int ui, vi;
      grid_.position(i, ui, vi);
      for (const int j : bb) {
        int uj, vj;
        grid_.position(j, uj, vj);
        const long du = ui - uj, dv = vi - vj;
        if (du * du + dv * dv < best)
          best = du * du + dv * dv, ia = i, ib = j;
      }
    }
    if (ia < 0 || best <= 4)
      return false; // adjacent: split on purpose (a crease or a jump), not seen through a gap
    const Eigen::Vector3f xa = grid_.point(ia), xb = grid_.point(ib);
    if ((xa - xb).norm() > p.bridge_max_gap)
      return false;
    // Everything between them is nearer (an occluder) or without depth (its shadow).
    const float ra = grid_.range(ia), rb = grid_.range(ib);
    int ua, va, ub, vb;
    grid_.position(ia, ua, va);
    grid_.position(ib, ub, vb);
    const int steps = std::max(std::abs(ub - ua), std::abs(vb - va));
    std::size_t occluder = 0;
    for (int s = 1; s < steps; ++s) {
      const float t = static_cast<float>(s) / static_cast<float>(steps);
      const int u =
        static_cast<int>(std::lround(static_cast<float>(ua) + t * static_cast<float>(ub - ua)));
      const int v =
        static_cast<int>(std::lround(static_cast<float>(va) + t * static_cast<float>(vb - va)));
      const int c = grid_.at(u, v);
      if (c >= 0) {
        const int k = findConst(label_[static_cast<std::size_t>(c)]);
        if (k == g || k == h)
          continue;
        if (grid_.range(c) > (1.f - t) * ra + t * rb - 0.01f)
          return false; // an object behind, or level with them: not an occluder
        ++occluder;
      }
      else if (has_depth[static_cast<std::size_t>(v) * static_cast<std::size_t>(grid_.width()) +
                         static_cast<std::size_t>(u)]) {
        return false; // the table or the background shows between them
      }
    }
    if (occluder == 0)
      return false;
    // One surface: local planes at both ends agree.
    const float radius = 0.04f;
    Eigen::Vector3f ca, na, cb, nb;
    if (!localPlane(pa, xa, radius, ca, na) || !localPlane(pb, xb, radius, cb, nb))
      return false;
    return std::abs(na.dot(nb)) >= std::cos(p.bridge_angle) &&
           std::abs(na.dot(cb - ca)) <= p.bridge_distance &&
           std::abs(nb.dot(ca - cb)) <= p.bridge_distance;
  }

  const Grid& grid_;
  std::vector<int> label_; ///< per valid pixel
  std::vector<int> group_;
  std::vector<std::size_t> size_, boundary_;
  std::vector<std::pair<std::uint64_t, Link>> links_; ///< by pair of labels (key), ascending
};

} // namespace

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
    if (finite(p) && std::abs(du) > 0.1f * cloud.width && p.z > 0.f)
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
      if (finite(cloud.at(u, v))) {
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
  const Grid grid(cloud, focal, viewpoint, p);
  const std::vector<std::uint8_t> crease = creases(grid, focal, viewpoint, p);
  for (std::size_t c = 0; c < grid.size(); ++c)
    out[grid.pixel(static_cast<int>(c))] = crease[c];
  return out;
}

bool
strictlyAscending(const pcl::Indices& indices)
{
  return std::adjacent_find(indices.begin(), indices.end(),
                            [](auto a, auto b) { return a >= b; }) == indices.end();
}

namespace {

/** segmentObjectsOrganized on its grid of valid pixels. */
std::vector<pcl::Indices>
segmentGrid(const Grid& grid, const std::vector<std::uint8_t>& has_depth, float focal,
            const Eigen::Vector3f& viewpoint, const ObjectSegmentationParameters& p)
{
  if (grid.size() == 0)
    return {};
  const std::vector<std::uint8_t> crease = creases(grid, focal, viewpoint, p);
  // 1. Components without the crease pixels.
  std::vector<int> label(grid.size(), -1);
  int count = components(
    grid, [&](int a) { return !crease[static_cast<std::size_t>(a)]; }, label, 0);
  // Crease pixels join the component that reaches them first (breadth first from all).
  std::vector<int> queue;
  queue.reserve(grid.size());
  for (int a = 0; a < static_cast<int>(grid.size()); ++a)
    if (label[static_cast<std::size_t>(a)] >= 0)
      queue.push_back(a);
  for (std::size_t head = 0; head < queue.size(); ++head) {
    const int a = queue[head];
    grid.forNeighbours(
      a,
      [&](int b) {
        if (label[static_cast<std::size_t>(b)] < 0 && grid.linked(a, b)) {
          label[static_cast<std::size_t>(b)] = label[static_cast<std::size_t>(a)];
          queue.push_back(b);
        }
      },
      [] {});
  }
  // Crease pixels no component reached (thin parts) are components of their own.
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

std::vector<pcl::Indices>
segmentObjectsOrganized(const pcl::PointCloud<pcl::PointXYZ>& cloud,
                        const std::vector<std::uint8_t>& has_depth, float focal,
                        const Eigen::Vector3f& viewpoint, const ObjectSegmentationParameters& p,
                        const DepthBand* noise, const pcl::Indices* finite)
{
  if (!cloud.isOrganized() || !(focal > 0.f) || has_depth.size() != cloud.size())
    return {};
  if (finite && !strictlyAscending(*finite))
    finite = nullptr; // not strictly ascending: the grid's order is the image's, so scan
  return segmentGrid(Grid(cloud, focal, viewpoint, p, noise, finite), has_depth, focal, viewpoint,
                     p);
}

std::vector<pcl::Indices>
segmentObjectsOrganized(const Eigen::Matrix3Xf& points, const pcl::Indices& pixels,
                        std::uint32_t width, std::uint32_t height,
                        const std::vector<std::uint8_t>& has_depth, float focal,
                        const Eigen::Vector3f& viewpoint, const ObjectSegmentationParameters& p,
                        const DepthBand* noise)
{
  const std::size_t size = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  if (width == 0 || height < 2 || !(focal > 0.f) || has_depth.size() != size ||
      points.cols() != static_cast<Eigen::Index>(pixels.size()) || !strictlyAscending(pixels) ||
      (!pixels.empty() && (pixels.front() < 0 || static_cast<std::size_t>(pixels.back()) >= size)))
    return {};
  return segmentGrid(Grid(points, pixels, static_cast<int>(width), static_cast<int>(height), focal,
                          viewpoint, p, noise),
                     has_depth, focal, viewpoint, p);
}

} // namespace facyl
