/*
 * facyl: fast cylinder detection for PCL.
 * The supports of a frame (tabletop_steps.h): every point sorted onto and above the
 * candidates, the families of parallel candidates ranked, and a family tried: its supports'
 * hulls, its objects clustered and each placed on the support under it.
 */
#include "tabletop_steps.h"

#include <facyl/features/polygon.h>

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <cstdint>

namespace facyl {
namespace tabletop {
namespace {

/** Where a cluster goes among the supports. */
struct Placement {
  int support{-1};      ///< index into the supports, -1: none (not over one, or a leg)
  bool standing{false}; ///< reaches down to it and is whole in its object band
};

/** Convex hull of a support's \a inliers, in the coordinates of its plane's \a frame: on
 * images those near the region found as candidate \a c (every point when nullptr). */
std::vector<Eigen::Vector2f>
supportHull(const Setup& setup, const Eigen::Affine3f& frame, const pcl::Indices& idx,
            const Candidate* c)
{
  const PointFrame& points_of = setup.frame;
  const Eigen::Affine3f to_plane = frame.inverse();
  const auto flat = [&](pcl::index_t i) {
    return Eigen::Vector2f((to_plane * points_of.point(static_cast<std::size_t>(i))).head<2>());
  };
  std::vector<Eigen::Vector2f> points;
  if (!setup.as_image) {
    const std::size_t stride = std::max<std::size_t>(1, idx.size() / setup.params.plane_samples);
    for (std::size_t k = 0; k < idx.size(); k += stride)
      points.push_back(flat(idx[k]));
    return convexHull2D(std::move(points));
  }
  if (c)
    for (const auto i : hullCandidates(setup, c->points))
      points.push_back(flat(i));
  // The region found on the plane, grown by the plane's points within 5 cm of it: the region
  // may miss a table's near edge, where a real sensor's depth bends, but the infinite plane's
  // points also hold the lines where it cuts walls and other objects. The image of a plane is
  // a projective map of it, which keeps convex hulls: only the first and the last point of each
  // image row can be a vertex.
  const std::vector<Eigen::Vector2f> region = convexHull2D(points); // none: every point
  constexpr float grow = 0.05f;
  // Nothing outside the region's reach is near it, which most of an infinite plane's points
  // are not.
  const Eigen::AlignedBox2f reach = polygonReach(region, grow);
  const auto near_region = [&](const Eigen::Vector2f& p) {
    if (!c || region.size() < 3)
      return true;
    if (!reach.contains(p))
      return false;
    if (pointInPolygon(p, region))
      return true;
    for (std::size_t e = 0; e < region.size(); ++e) {
      const Eigen::Vector2f a = region[e], b = region[(e + 1) % region.size()];
      const float t =
        std::clamp((p - a).dot(b - a) / std::max((b - a).squaredNorm(), 1e-12f), 0.f, 1.f);
      if ((a + t * (b - a) - p).squaredNorm() <= grow * grow)
        return true;
    }
    return false;
  };
  const auto w = static_cast<pcl::index_t>(points_of.width);
  const auto add = [&](pcl::index_t i) {
    const Eigen::Vector2f p = flat(i);
    if (near_region(p))
      points.push_back(p);
  };
  // Each image row: its first and last point near the region. The pixel sort of the whole
  // frame writes the lists in image order: a row's end is then found by a binary search, not
  // a walk over its points.
  const bool ascending = !points_of.indices;
  assert(!ascending || std::is_sorted(idx.begin(), idx.end()));
  std::size_t k = 0;
  while (k < idx.size()) {
    const pcl::index_t row_end = (idx[k] / w + 1) * w;
    std::size_t end = k;
    if (ascending)
      end = static_cast<std::size_t>(
        std::lower_bound(idx.begin() + static_cast<std::ptrdiff_t>(k), idx.end(), row_end) -
        idx.begin());
    else
      while (end < idx.size() && idx[end] < row_end)
        ++end;
    for (std::size_t j = k; j < end; ++j)
      if (near_region(flat(idx[j]))) {
        add(idx[j]);
        break;
      }
    for (std::size_t j = end; j-- > k;)
      if (near_region(flat(idx[j]))) {
        add(idx[j]);
        break;
      }
    k = end;
  }
  return convexHull2D(std::move(points));
}

/** The support of a cluster (points \a pts) among \a supports, with \a regions the hulls
 * objects are placed over (their polygons; the stream's table's with its prior extent) and
 * \a extents the hulls of all of their points. */
Placement
place(const Setup& setup, const Eigen::Matrix3Xf& pts, const std::vector<SupportPlane>& supports,
      const std::vector<std::vector<Eigen::Vector2f>>& regions,
      const std::vector<std::vector<Eigen::Vector2f>>& extents)
{
  const auto& p = setup.params;
  const Eigen::Vector3f viewpoint = setup.frame.viewpoint;
  Placement out;
  std::vector<HeightProfile> profiles(supports.size());
  for (std::size_t s = 0; s < supports.size(); ++s) {
    profiles[s] = heightProfile(pts, supports[s].plane, supports[s].band, viewpoint, p.min_height,
                                p.max_height);
    const std::size_t in_hull = pointsInPolygon(pts, supports[s].frame.inverse(), regions[s]);
    const float over = static_cast<float>(in_hull) / static_cast<float>(pts.cols());
    // The nearest support under the cluster: most of it in its band and over its hull (the
    // prism test of pcl::ExtractPolygonalPrismData, per cluster).
    if (profiles[s].in_band < 0.5f || over < p.min_hull_share)
      continue;
    if (out.support < 0 || profiles[s].base < profiles[static_cast<std::size_t>(out.support)].base)
      out.support = static_cast<int>(s);
  }
  if (out.support < 0)
    return out;
  // Under a higher support (its legs, or what stands under it) is furniture, not an object
  // on the lower one. "Under" takes every point of the higher plane: seen at a grazing angle, a
  // table's region may miss its edges.
  for (std::size_t s = 0; s < supports.size(); ++s) {
    if (static_cast<int>(s) == out.support || !(profiles[s].top < 0.f))
      continue;
    const std::size_t under = pointsInPolygon(pts, supports[s].frame.inverse(), extents[s]);
    if (2 * under >= static_cast<std::size_t>(pts.cols())) {
      out.support = -1;
      return out;
    }
  }
  // Standing: it reaches down to the support's band (at its range) within contact_height.
  const SupportPlane& support = supports[static_cast<std::size_t>(out.support)];
  const float range = (Eigen::Vector3f(pts.rowwise().mean()) - viewpoint).norm();
  out.standing = standsOn(profiles[static_cast<std::size_t>(out.support)],
                          p.contact_height + support.band.halfWidth(range), p.max_height, 0.02f);
  return out;
}

/** The candidates of other families than a trial's (a candidate is in one family only), for
 * pieceOfSurface: their bits, planes, bands and regions (on images). */
struct OtherFamilies {
  OtherFamilies(const Setup& setup, const SortedFrame& sorted,
                const std::vector<std::size_t>& family)
      : sorted(sorted)
  {
    if (!setup.as_image || sorted.regions.bits.empty())
      return;
    for (std::size_t s = 0; s < sorted.candidates.size() && s < 8; ++s)
      if (std::find(family.begin(), family.end(), s) == family.end())
        mask |= static_cast<std::uint8_t>(1u << s);
  }
  const SortedFrame& sorted;
  std::uint8_t mask{0};
};

/** Whether a \a group (every \a stride-th point tested; \a size: the points it stands for)
 * lies mostly (half of its points) on one candidate of \a others, within its band and on its
 * region (not anywhere on its infinite plane), that stands for at least four times its points:
 * a piece of that larger surface, not an object. E.g. patches of the table top in front of two
 * cans, whose camera-facing sides pass as one plane: a family of its own whose "objects" are
 * the table (simulated 1280 x 720 room, seed 708); or a strip of the room's wall within the
 * table's object band (seed 706). */
bool
pieceOfSurface(const Setup& setup, const OtherFamilies& others, const pcl::Indices& group,
               std::size_t stride, std::size_t size)
{
  if (!others.mask)
    return false;
  const SortedFrame& sorted = others.sorted;
  const std::size_t n = std::min<std::size_t>(8, sorted.candidates.size());
  std::array<std::size_t, 8> count{};
  std::size_t sampled = 0;
  for (std::size_t k = 0; k < group.size(); k += stride, ++sampled) {
    const std::uint8_t bits = others.mask & sorted.regions.bits[sorted.regions.cellOf(group[k])];
    if (!bits)
      continue;
    const Eigen::Vector3f p = setup.frame.point(static_cast<std::size_t>(group[k]));
    const float range = (p - setup.frame.viewpoint).norm();
    for (std::size_t c = 0; c < n; ++c) {
      const SupportPlane& s = sorted.all[c];
      if ((bits >> c) & 1u &&
          std::abs(s.plane.head<3>().dot(p) + s.plane[3]) <= s.band.halfWidth(range))
        ++count[c];
    }
  }
  for (std::size_t c = 0; c < n; ++c)
    if (sampled > 0 && 2 * count[c] >= sampled && sorted.candidates[c].support >= 4 * size)
      return true;
  return false;
}

/** Each cluster (\a groups) to the support under it (\a supports, \a regions, \a extents: see
 * place), except the pieces of other families' surfaces (\a others: pieceOfSurface); the
 * table; the supports that hold objects and the table moved into \a trial. \a scale: the
 * points each point of \a groups stands for (coarse trials, which keep no clusters). */
void
assignClusters(const Setup& setup, std::vector<pcl::Indices>& groups,
               std::vector<SupportPlane>& supports,
               const std::vector<std::vector<Eigen::Vector2f>>& regions,
               const std::vector<std::vector<Eigen::Vector2f>>& extents,
               const OtherFamilies& others, Trial& trial, std::size_t scale)
{
  const auto& p = setup.params;
  for (auto& group : groups) {
    if (group.size() * scale < p.min_cluster_size || group.size() * scale > p.max_cluster_size)
      continue;
    // At most 400 of its points, evenly: enough for the height and hull tests.
    const std::size_t stride = std::max<std::size_t>(1, group.size() / 400);
    if (pieceOfSurface(setup, others, group, stride, group.size() * scale)) {
      PCL_DEBUG("[facyl::TabletopSegmentation] a group of %zu points lies on a larger plane of "
                "another family: not an object\n",
                group.size() * scale);
      continue;
    }
    Eigen::Matrix3Xf pts(3, static_cast<Eigen::Index>((group.size() + stride - 1) / stride));
    for (std::size_t k = 0, c = 0; k < group.size(); k += stride, ++c)
      pts.col(static_cast<Eigen::Index>(c)) = setup.frame.point(static_cast<std::size_t>(group[k]));
    const Placement pl = place(setup, pts, supports, regions, extents);
    if (pl.support < 0)
      continue;
    SupportPlane& support = supports[static_cast<std::size_t>(pl.support)];
    ++support.objects;
    if (pl.standing) {
      support.standing_points += group.size() * scale;
      ++trial.standing_objects;
    }
    if (scale == 1)
      trial.clusters.push_back(makeCluster(setup, std::move(group), pl.support));
  }
  // The table: the most object points standing on it, else the largest support; or the prior's.
  const std::size_t table = tableWithPrior(setup, supports, trial);
  // Keep the supports that hold objects, and the table.
  std::vector<int> new_index(supports.size(), -1);
  for (std::size_t s = 0; s < supports.size(); ++s)
    if (supports[s].objects > 0 || s == table) {
      new_index[s] = static_cast<int>(trial.supports.size());
      trial.supports.push_back(std::move(supports[s]));
    }
  trial.table = static_cast<std::size_t>(new_index[table]);
  if (trial.from_prior >= 0)
    trial.from_prior = new_index[static_cast<std::size_t>(trial.from_prior)];
  for (auto& c : trial.clusters)
    c.support = new_index[static_cast<std::size_t>(c.support)];
}

/** 2-D points in a grid of cells \a distance wide: near(p) tells whether one of them lies
 * within \a distance of p. */
class NearPoints2D {
public:
  NearPoints2D(const std::vector<Eigen::Vector2f>& points, float distance)
      : cell_(distance > 0.f ? distance : 1.f)
  {
    for (const auto& p : points)
      if (p.allFinite())
        entries_.emplace_back(key(cellOf(p.x()), cellOf(p.y())), p);
    std::sort(entries_.begin(), entries_.end(),
              [](const auto& a, const auto& b) { return a.first < b.first; });
  }
  bool near(const Eigen::Vector2f& p) const
  {
    const std::int64_t cx = cellOf(p.x()), cy = cellOf(p.y());
    for (std::int64_t dx = -1; dx <= 1; ++dx)
      for (std::int64_t dy = -1; dy <= 1; ++dy) {
        const std::int64_t k = key(cx + dx, cy + dy);
        auto it = std::lower_bound(entries_.begin(), entries_.end(), k,
                                   [](const auto& e, std::int64_t v) { return e.first < v; });
        for (; it != entries_.end() && it->first == k; ++it)
          if ((it->second - p).squaredNorm() <= cell_ * cell_)
            return true;
      }
    return false;
  }

private:
  std::int64_t cellOf(float x) const
  {
    return static_cast<std::int64_t>(std::floor(x / cell_));
  }
  static std::int64_t key(std::int64_t x, std::int64_t y)
  {
    return (x << 32) ^ (y & 0xffffffff);
  }
  float cell_;
  std::vector<std::pair<std::int64_t, Eigen::Vector2f>> entries_;
};

/** The candidate of \a family that \a s lies on: the highest one below it whose object band
 * holds it (above its band at \a s's centre, at most max_height) and whose region's hull holds
 * that centre (it lies over it, not beside it: a bench seat, a far table), or -1. By height
 * and place, not size: a box top in a large pile may hold more points than the table seen
 * around it. */
int
lowerSupportOf(const Setup& setup, const SortedFrame& sorted,
               const std::vector<std::size_t>& family, std::size_t s)
{
  const Eigen::Affine3f to_plane = sorted.all[s].frame.inverse();
  const Eigen::Vector3f centre = sorted.all[s].frame.translation();
  const float range = (centre - setup.frame.viewpoint).norm();
  int out = -1;
  float nearest = 0.f;
  for (const std::size_t t : family) {
    const Eigen::Vector4f& plane = sorted.candidates[t].plane;
    const float height = plane.head<3>().dot(centre) + plane[3];
    if (t == s || !(height > sorted.candidates[t].band.halfWidth(range)) ||
        height > setup.params.max_height || (out >= 0 && height >= nearest))
      continue;
    std::vector<Eigen::Vector2f> region;
    for (const auto i : hullCandidates(setup, sorted.candidates[t].points))
      region.push_back((to_plane * setup.frame.point(static_cast<std::size_t>(i))).head<2>());
    if (pointInPolygon((to_plane * centre).head<2>(), convexHull2D(std::move(region))))
      out = static_cast<int>(t), nearest = height;
  }
  return out;
}

/** The walls under the edge of E's region hull \a region (counter-clockwise, in the
 * coordinates of E's plane \a to_plane): \a e's facing_pieces and walled (see ElevatedPlane).
 * The points of the frame above L (in its object band) that lie below E's band and within \a
 * margin of the hull's edge are the sides under it; a piece of the edge is walled when they
 * fill the height from L up to E there, in slices as high as L's contact (e.contact): noise
 * over L beside E's edge fills the lowest slice, a table's apron the highest, its legs few
 * pieces. */
void
measureWalls(const Setup& setup, const SortedFrame& sorted, const Eigen::Affine3f& to_plane,
             const std::vector<Eigen::Vector2f>& region, std::size_t s, std::size_t lower,
             float margin, ElevatedPlane& e)
{
  const std::size_t n = region.size();
  std::vector<float> start(n + 1, 0.f); // arc length at each vertex
  for (std::size_t i = 0; i < n; ++i)
    start[i + 1] = start[i] + (region[(i + 1) % n] - region[i]).norm();
  const float perimeter = start[n];
  if (!(perimeter > 0.f))
    return;
  const Eigen::Vector2f eye = (to_plane * setup.frame.viewpoint).head<2>();
  const auto pieceOf = [&](float arc) {
    return std::min(kEdgePieces - 1, static_cast<int>(arc / perimeter * kEdgePieces));
  };
  // A piece faces the sensor when the edge at its middle has the sensor on its outer side.
  std::vector<char> facing(kEdgePieces, 0);
  for (int k = 0; k < kEdgePieces; ++k) {
    const float arc = (static_cast<float>(k) + 0.5f) / kEdgePieces * perimeter;
    const std::size_t i = static_cast<std::size_t>(
      std::upper_bound(start.begin(), start.end(), arc) - start.begin() - 1);
    const Eigen::Vector2f a = region[std::min(i, n - 1)], d = region[(i + 1) % n] - a;
    facing[static_cast<std::size_t>(k)] = (d.y() * (eye - a).x() - d.x() * (eye - a).y()) > 0.f;
  }
  // Slices of e.contact up to E's band at E's centre (at most 32: bits of a mask).
  const Eigen::Vector3f centre = sorted.all[s].frame.translation();
  const float wall =
    e.height - sorted.candidates[s].band.halfWidth((centre - setup.frame.viewpoint).norm());
  const int slices = std::clamp(static_cast<int>(std::ceil(wall / e.contact)), 1, 32);
  const std::uint32_t full = slices == 32 ? ~0u : (1u << slices) - 1u;
  std::vector<std::uint32_t> filled(kEdgePieces, 0u);
  const Eigen::Vector4f& over = sorted.candidates[lower].plane;
  const Eigen::Vector4f& top = sorted.candidates[s].plane;
  const DepthBand& band = sorted.candidates[s].band;
  const auto bit = static_cast<std::uint8_t>(1u << lower);
  // Only the points near the hull's edge, and at most about 20000 of the points above L: a
  // piece of wall holds hundreds of pixels at any range a plane is found at.
  Eigen::AlignedBox2f near_edge;
  for (const auto& v : region)
    near_edge.extend(v);
  near_edge.min().array() -= margin;
  near_edge.max().array() += margin;
  const std::vector<PointOverPlanes>& above = *sorted.above;
  const std::size_t stride = std::max<std::size_t>(1, above.size() / 20000);
  for (std::size_t k = 0; k < above.size(); k += stride) {
    const PointOverPlanes& a = above[k];
    if (!(a.above & bit))
      continue;
    const Eigen::Vector3f x = setup.frame.point(static_cast<std::size_t>(a.index));
    const Eigen::Vector2f q = (to_plane * x).head<2>();
    // Near the edge and below E's band (not E itself, nor what stands on it).
    if (!near_edge.contains(q) ||
        top.head<3>().dot(x) + top[3] >= -band.halfWidth((x - setup.frame.viewpoint).norm()))
      continue;
    const int slice =
      std::clamp(static_cast<int>((over.head<3>().dot(x) + over[3]) / e.contact), 0, slices - 1);
    float best = margin;
    int piece = -1;
    for (std::size_t i = 0; i < n; ++i) {
      const Eigen::Vector2f d = region[(i + 1) % n] - region[i];
      const float t =
        std::clamp((q - region[i]).dot(d) / std::max(d.squaredNorm(), 1e-12f), 0.f, 1.f);
      const float dist = (region[i] + t * d - q).norm();
      if (dist <= best)
        best = dist, piece = pieceOf(start[i] + t * (start[i + 1] - start[i]));
    }
    if (piece >= 0)
      filled[static_cast<std::size_t>(piece)] |= 1u << slice;
  }
  int walled = 0;
  for (int k = 0; k < kEdgePieces; ++k)
    if (facing[static_cast<std::size_t>(k)]) {
      ++e.facing_pieces;
      walled += filled[static_cast<std::size_t>(k)] == full;
    }
  e.walled =
    e.facing_pieces ? static_cast<float>(walled) / static_cast<float>(e.facing_pieces) : 0.f;
}

/** What isElevatedSupport measures of candidate \a s lying on candidate \a lower. */
ElevatedPlane
measureElevated(const Setup& setup, const SortedFrame& sorted, std::size_t s, std::size_t lower,
                float min_area)
{
  const Candidate& c = sorted.candidates[s];
  const Eigen::Affine3f& frame = sorted.all[s].frame;
  const Eigen::Affine3f to_plane = frame.inverse();
  const Eigen::Vector3f centre = frame.translation();
  const Eigen::Vector4f& under = sorted.candidates[lower].plane;
  ElevatedPlane e;
  e.height = under.head<3>().dot(centre) + under[3];
  e.contact = setup.params.contact_height +
              sorted.candidates[lower].band.halfWidth((centre - setup.frame.viewpoint).norm());
  std::vector<Eigen::Vector2f> region_points;
  for (const auto i : c.points)
    region_points.push_back((to_plane * setup.frame.point(static_cast<std::size_t>(i))).head<2>());
  const std::vector<Eigen::Vector2f> region = convexHull2D(region_points);
  e.region_area = polygonArea(region);
  e.diameter = polygonDiameter(region);
  // What isElevatedSupport reads first is measured first: the rest only when it could
  // change the verdict.
  if (c.points.empty() || region.size() < 3 || !(e.region_area >= min_area) ||
      !(e.height > e.contact))
    return e;
  // L's points under E: inside E's region hull shrunk by the uncertainty of its edges (about
  // a cell of the region: a block of the plane grid, a sample's spacing; L's points that close
  // may be the foot of E's own sides), and under the region itself, near one of its cells:
  // the tops of separate objects at one height (boxes side by side, a box and a can) make one
  // region whose hull spans the table seen between them.
  const float spacing = std::sqrt(e.region_area / static_cast<float>(c.points.size()));
  const NearPoints2D cells(region_points, 2.f * spacing);
  const pcl::Indices& lower_points = sorted.all[lower].inliers.indices;
  const std::size_t stride = std::max<std::size_t>(1, lower_points.size() / 20000);
  Eigen::AlignedBox2f bounds;
  for (const auto& v : region)
    bounds.extend(v);
  std::size_t seen = 0;
  for (std::size_t k = 0; k < lower_points.size(); k += stride) {
    const Eigen::Vector2f p =
      (to_plane * setup.frame.point(static_cast<std::size_t>(lower_points[k]))).head<2>();
    seen += bounds.contains(p) && insideConvexBy(p, region, 2.f * spacing) && cells.near(p);
  }
  e.seen_under =
    static_cast<float>(seen * stride) / static_cast<float>(std::max<std::size_t>(1, c.support));
  if (e.seen_under >= kSeenUnderShare)
    return e;
  measureWalls(setup, sorted, to_plane, region, s, lower, 2.f * spacing, e);
  return e;
}

/** For each candidate of \a family not judged yet: whether it lies inside the object band of
 * a lower one (a shelf, a low table; a box top, books, a tray) and, if so, whether it is a
 * support of its own (isElevatedSupport). Before any trial moves the inliers out. */
void
judgeElevated(const Setup& setup, SortedFrame& sorted, const std::vector<std::size_t>& family)
{
  const auto& p = setup.params;
  for (const std::size_t s : family) {
    CandidateHulls& hulls = sorted.hulls[s];
    if (hulls.judged)
      continue;
    hulls.judged = true;
    const int lower = lowerSupportOf(setup, sorted, family, s);
    hulls.elevated = lower >= 0;
    if (!hulls.elevated)
      continue;
    const ElevatedPlane e =
      measureElevated(setup, sorted, s, static_cast<std::size_t>(lower), p.min_shelf_area);
    hulls.elevated_support = isElevatedSupport(e, p.min_shelf_area, p.max_height);
    PCL_DEBUG("[facyl::TabletopSegmentation] plane %zu on plane %d: %.3f m above it (contact "
              "%.3f), region %.3f m^2, %.2f m across, seen under it %.2f, walled %.2f of "
              "%d pieces: %s\n",
              s, lower, e.height, e.contact, e.region_area, e.diameter, e.seen_under, e.walled,
              e.facing_pieces, hulls.elevated_support ? "a support" : "an object's top");
  }
}

} // namespace

SortedFrame
classifyPoints(const Setup& setup, std::vector<Candidate> candidates, TabletopWorkspace& workspace)
{
  // One pass: each candidate's points, and the points above some candidate (in its object
  // band) with the candidates they lie on and above. Bands by range, tabulated every 5 mm.
  const PointFrame& frame = setup.frame;
  SortedFrame out;
  out.candidates = std::move(candidates);
  out.above = &workspace.above;
  const std::size_t n = out.candidates.size(); // <= 8 (max_planes)
  out.all.assign(n, SupportPlane{});
  out.hulls.assign(n, CandidateHulls{});
  workspace.above.clear();
  if (n == 0)
    return out;
  std::vector<Eigen::Vector4f> planes;
  std::vector<DepthBand> bands;
  for (const auto& c : out.candidates) {
    planes.push_back(c.plane);
    bands.push_back(c.band);
  }
  const PlaneSorter sorter(std::move(planes), std::move(bands), frame.viewpoint,
                           setup.params.min_height, setup.params.max_height);
  // Each candidate's points go to a slice of a buffer kept between frames that could take
  // every point (no growth test per point); no list of every index is read when the frame
  // has no indices.
  const pcl::index_t* given = frame.indices ? frame.indices->data() : nullptr;
  const std::size_t count = frame.indices ? frame.indices->size() : frame.size;
  auto& lists = workspace.on_planes;
  if (lists.size() < n * count) {
    lists.clear(); // nothing to move to the new allocation
    lists.resize(n * count);
  }
  std::array<pcl::index_t*, 8> ends;
  for (std::size_t s = 0; s < n; ++s)
    ends[s] = lists.data() + s * count;
  sorter.sort(frame.xyz, frame.stride, count, given, ends.data(), workspace.above);
  for (std::size_t s = 0; s < n; ++s)
    out.all[s].inliers.indices.assign(lists.data() + s * count, ends[s]);
  for (std::size_t s = 0; s < n; ++s) {
    const Candidate& c = out.candidates[s];
    SupportPlane& a = out.all[s];
    a.plane = c.plane;
    a.band = c.band;
    a.inliers.header = frame.header;
    Eigen::Vector3f centre = Eigen::Vector3f::Zero();
    for (const auto i : c.points)
      centre += frame.point(static_cast<std::size_t>(i));
    a.frame =
      planeFrame(c.plane, centre / static_cast<float>(std::max<std::size_t>(1, c.points.size())));
  }
  return out;
}

std::vector<std::vector<std::size_t>>
rankFamilies(const Setup& setup, const FrameCues& cues, const SortedFrame& sorted)
{
  if (sorted.candidates.empty())
    return {};
  if (setup.params.support == TabletopSegmentationParameters::Support::LargestPlane)
    return {{0}};
  std::vector<Eigen::Vector4f> planes;
  std::vector<std::size_t> points;
  for (std::size_t s = 0; s < sorted.candidates.size(); ++s) {
    planes.push_back(sorted.candidates[s].plane);
    points.push_back(sorted.all[s].inliers.indices.size());
  }
  return rankSupportFamilies(planes, points, !setup.up.isZero(), cues.image_down);
}

RegionCells::RegionCells(const Setup& setup, const std::vector<Candidate>& candidates)
    : width(static_cast<pcl::index_t>(setup.frame.width))
{
  if (!setup.as_image || width <= 0)
    return;
  const auto cell = static_cast<std::size_t>(2 * std::max(1, setup.plane_step));
  const std::size_t cw = (setup.frame.width + cell - 1) / cell;
  row.resize(setup.frame.height);
  for (std::size_t v = 0; v < row.size(); ++v)
    row[v] = v / cell * cw;
  column.resize(setup.frame.width);
  for (std::size_t u = 0; u < column.size(); ++u)
    column[u] = static_cast<std::uint32_t>(u / cell);
  bits.assign(cw * ((setup.frame.height + cell - 1) / cell), 0);
  for (std::size_t s = 0; s < candidates.size() && s < 8; ++s)
    for (const auto i : candidates[s].points)
      bits[cellOf(i)] |= static_cast<std::uint8_t>(1u << s);
}

Trial
tryFamily(const Setup& setup, const FrameCues& cues, SortedFrame& sorted,
          const std::vector<std::size_t>& family, int stride, bool final,
          TabletopWorkspace& workspace)
{
  const auto& p = setup.params;
  const bool largest = p.support == TabletopSegmentationParameters::Support::LargestPlane;
  const auto& candidates = sorted.candidates;
  auto& all = sorted.all;
  std::vector<SupportPlane> supports;
  std::vector<std::vector<Eigen::Vector2f>> extents; ///< hulls of all the supports' points
  std::vector<std::vector<Eigen::Vector2f>> regions; ///< hulls objects are placed over
  std::uint8_t kept = 0;
  int from_prior = -1; // the support of a Candidate::from_prior
  judgeElevated(setup, sorted, family);
  for (const std::size_t s : family) {
    SupportPlane support;
    support.plane = all[s].plane;
    support.band = all[s].band;
    support.frame = all[s].frame;
    CandidateHulls& hulls = sorted.hulls[s];
    if (!hulls.known) { // once per candidate: every trial of its family needs them
      hulls.polygon = supportHull(setup, support.frame, all[s].inliers.indices, &candidates[s]);
      hulls.region = regionArea(setup, candidates[s], support.frame);
      hulls.known = true;
    }
    support.polygon = hulls.polygon;
    // A plane inside the object band of a lower parallel one (a shelf, a box top) is judged
    // by the region found on it (its infinite plane slices through the objects around it) and
    // by what holds it up (judgeElevated).
    const bool high = hulls.elevated;
    // Its own region must be sizeable too: a small region's infinite plane can cross a
    // table.
    const float region = hulls.region;
    const float hull = polygonArea(support.polygon);
    if (final)
      PCL_DEBUG("[facyl::TabletopSegmentation] family plane %zu: normal (%.3f %.3f %.3f) d "
                "%.3f, %zu inliers, hull %.3f m^2, region %.3f m^2%s\n",
                s, support.plane[0], support.plane[1], support.plane[2], support.plane[3],
                all[s].inliers.indices.size(), hull, region, high ? ", elevated" : "");
    const bool large = high ? hulls.elevated_support
                            : hull >= p.min_support_area && region >= 0.25f * p.min_support_area;
    if (support.polygon.size() < 3 || !(largest || large))
      continue;
    // The hull objects are placed over: the stream's table adds what the last frames saw of
    // it (its own polygon stays the frame's).
    regions.push_back(
      setup.prior ? priorExtentHull(*setup.prior, support.plane, support.frame, support.polygon)
                  : support.polygon);
    kept |= static_cast<std::uint8_t>(1u << s);
    if (candidates[s].from_prior)
      from_prior = static_cast<int>(supports.size());
    if (hulls.extent.empty())
      hulls.extent = supportHull(setup, support.frame, all[s].inliers.indices, nullptr);
    extents.push_back(hulls.extent);
    if (final)
      support.inliers = std::move(all[s].inliers); // a candidate is in one family only
    else
      support.inliers.indices.resize(all[s].inliers.indices.size()); // only the count is used
    supports.push_back(std::move(support));
  }
  Trial trial;
  if (supports.empty())
    return trial;
  trial.from_prior = from_prior;
  // The candidates' regions, once a frame, when there are other families.
  if (setup.as_image && sorted.regions.bits.empty() && family.size() < candidates.size())
    sorted.regions = RegionCells(setup, candidates);
  const OtherFamilies others(setup, sorted, family);
  pcl::Indices band;
  const auto w = static_cast<pcl::index_t>(setup.frame.width);
  for (const PointOverPlanes& a : *sorted.above)
    if ((a.above & kept) && !(a.on & kept) &&
        (stride == 1 || ((a.index % w) % stride == 0 && (a.index / w) % stride == 0)))
      band.push_back(a.index);
  std::vector<pcl::Indices> groups = stride == 1
                                       ? cluster(setup, cues, band, workspace)
                                       : clusterCoarse(setup, cues, band, stride, workspace);
  assignClusters(setup, groups, supports, regions, extents, others, trial,
                 static_cast<std::size_t>(stride * stride));
  PCL_DEBUG("[facyl::TabletopSegmentation] stride %d: %zu supports, %zu object points, %zu "
            "groups, %zu clusters, %zu standing\n",
            stride, trial.supports.size(), band.size(), groups.size(), trial.clusters.size(),
            trial.standing);
  return trial;
}

} // namespace tabletop
} // namespace facyl
