/*
 * facyl: fast cylinder detection for PCL.
 * The joins of the edge-aware object segmentation (object_joins.h).
 */
#include "object_joins.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <numeric>

namespace facyl {
namespace edge_aware {

Segments::Segments(const Grid& grid, std::vector<int> label, int count)
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

void
Segments::mergeNeighbours(std::size_t min_fragment, float enclosed_share)
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

void
Segments::bridgeOcclusions(const std::vector<std::uint8_t>& has_depth, std::size_t min_part,
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
  std::vector<PixelList> border_pixels(groups.size());
  std::vector<Eigen::AlignedBox3f> boxes(groups.size());
  for (std::size_t k = 0; k < groups.size(); ++k) {
    borders[k] = border(pixels[k], groups[k], root);
    for (const int i : borders[k]) {
      int u, v;
      grid_.position(i, u, v);
      border_pixels[k].u.push_back(u);
      border_pixels[k].v.push_back(v);
    }
    for (const int i : pixels[k])
      boxes[k].extend(grid_.point(i));
  }
  for (std::size_t a = 0; a < groups.size(); ++a)
    for (std::size_t b = a + 1; b < groups.size(); ++b) {
      const int g = find(groups[a]), h = find(groups[b]);
      if (g == h || boxes[a].exteriorDistance(boxes[b]) > p.bridge_max_gap)
        continue;
      if (sameSurfaceBehind(pixels[a], pixels[b], borders[a], borders[b], border_pixels[a],
                            border_pixels[b], g, h, has_depth, p))
        group_[static_cast<std::size_t>(std::max(g, h))] = std::min(g, h);
    }
}

std::vector<pcl::Indices>
Segments::indices() const
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

Segments::GroupStats
Segments::groupStats()
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

std::vector<int>
Segments::border(const std::vector<int>& px, int g, const std::vector<int>& root) const
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

bool
Segments::localPlane(const std::vector<int>& px, const Eigen::Vector3f& centre, float radius,
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

bool
Segments::sameSurfaceBehind(const std::vector<int>& pa, const std::vector<int>& pb,
                            const std::vector<int>& ba, const std::vector<int>& bb,
                            const PixelList& at_a, const PixelList& at_b, int g, int h,
                            const std::vector<std::uint8_t>& has_depth,
                            const ObjectSegmentationParameters& p) const
{
  // The closest border pixels of the two parts, in the image.
  constexpr long kAdjacent = 4; // squared pixels: neighbours, or one pixel between them
  std::size_t ka, kb;
  const long best = closestPixelPair(at_a, at_b, ka, kb, kAdjacent);
  if (best < 0 || best <= kAdjacent)
    return false; // adjacent: split on purpose (a crease or a jump), not seen through a gap
  const int ia = ba[ka], ib = bb[kb];
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

} // namespace edge_aware
} // namespace facyl
