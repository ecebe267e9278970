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
  const auto near_region = [&](const Eigen::Vector2f& p) {
    if (!c || region.size() < 3 || pointInPolygon(p, region))
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

/** The support of a cluster (points \a pts) among \a supports, with \a extents the hulls of
 * all of their points. */
Placement
place(const Setup& setup, const Eigen::Matrix3Xf& pts, const std::vector<SupportPlane>& supports,
      const std::vector<std::vector<Eigen::Vector2f>>& extents)
{
  const auto& p = setup.params;
  const Eigen::Vector3f viewpoint = setup.frame.viewpoint;
  Placement out;
  std::vector<HeightProfile> profiles(supports.size());
  for (std::size_t s = 0; s < supports.size(); ++s) {
    profiles[s] = heightProfile(pts, supports[s].plane, supports[s].band, viewpoint, p.min_height,
                                p.max_height);
    const Eigen::Affine3f to_plane = supports[s].frame.inverse();
    std::size_t in_hull = 0;
    for (Eigen::Index k = 0; k < pts.cols(); ++k)
      in_hull +=
        pointInPolygon((to_plane * Eigen::Vector3f(pts.col(k))).head<2>(), supports[s].polygon);
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
    const Eigen::Affine3f to_plane = supports[s].frame.inverse();
    std::size_t under = 0;
    for (Eigen::Index k = 0; k < pts.cols(); ++k)
      under += pointInPolygon((to_plane * Eigen::Vector3f(pts.col(k))).head<2>(), extents[s]);
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

/** Each cluster (\a groups) to the support under it (\a supports, \a extents: see place); the
 * table; the supports that hold objects and the table moved into \a trial. \a scale: the
 * points each point of \a groups stands for (coarse trials, which keep no clusters). */
void
assignClusters(const Setup& setup, std::vector<pcl::Indices>& groups,
               std::vector<SupportPlane>& supports,
               const std::vector<std::vector<Eigen::Vector2f>>& extents, Trial& trial,
               std::size_t scale)
{
  const auto& p = setup.params;
  for (auto& group : groups) {
    if (group.size() * scale < p.min_cluster_size || group.size() * scale > p.max_cluster_size)
      continue;
    // At most 400 of its points, evenly: enough for the height and hull tests.
    const std::size_t stride = std::max<std::size_t>(1, group.size() / 400);
    Eigen::Matrix3Xf pts(3, static_cast<Eigen::Index>((group.size() + stride - 1) / stride));
    for (std::size_t k = 0, c = 0; k < group.size(); k += stride, ++c)
      pts.col(static_cast<Eigen::Index>(c)) = setup.frame.point(static_cast<std::size_t>(group[k]));
    const Placement pl = place(setup, pts, supports, extents);
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
  for (auto& c : trial.clusters)
    c.support = new_index[static_cast<std::size_t>(c.support)];
}

/** Whether candidate \a s lies inside the object band of a larger parallel candidate of \a
 * family (a shelf, a box top), at \a range from the sensor. */
bool
elevated(const Setup& setup, const std::vector<Candidate>& candidates,
         const std::vector<std::size_t>& family, std::size_t s, float range)
{
  bool out = false;
  for (const std::size_t t : family) {
    const float height = candidates[t].plane[3] - candidates[s].plane[3];
    out =
      out || (t != s && candidates[t].support > candidates[s].support &&
              height > candidates[t].band.halfWidth(range) && height <= setup.params.max_height);
  }
  return out;
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

Trial
tryFamily(const Setup& setup, const FrameCues& cues, SortedFrame& sorted,
          const std::vector<std::size_t>& family, int stride, bool final,
          TabletopWorkspace& workspace)
{
  const auto& p = setup.params;
  const bool largest = p.support == TabletopSegmentationParameters::Support::LargestPlane;
  const Eigen::Vector3f viewpoint = setup.frame.viewpoint;
  const auto& candidates = sorted.candidates;
  auto& all = sorted.all;
  std::vector<SupportPlane> supports;
  std::vector<std::vector<Eigen::Vector2f>> extents; ///< hulls of all the supports' points
  std::uint8_t kept = 0;
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
    // A plane inside the object band of a larger parallel one (a shelf, a box top) is judged
    // by the region found on it: its infinite plane slices through the objects around it.
    const bool high =
      elevated(setup, candidates, family, s, (support.frame.translation() - viewpoint).norm());
    // Its own region must be sizeable too: a small region's infinite plane can cross a
    // table.
    const float region = hulls.region;
    const float hull = polygonArea(support.polygon);
    if (final)
      PCL_DEBUG("[facyl::TabletopSegmentation] family plane %zu: normal (%.3f %.3f %.3f) d "
                "%.3f, %zu inliers, hull %.3f m^2, region %.3f m^2%s\n",
                s, support.plane[0], support.plane[1], support.plane[2], support.plane[3],
                all[s].inliers.indices.size(), hull, region, high ? ", elevated" : "");
    const bool large = high ? region >= p.min_shelf_area
                            : hull >= p.min_support_area && region >= 0.25f * p.min_support_area;
    if (support.polygon.size() < 3 || !(largest || large))
      continue;
    kept |= static_cast<std::uint8_t>(1u << s);
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
  pcl::Indices band;
  const auto w = static_cast<pcl::index_t>(setup.frame.width);
  for (const PointOverPlanes& a : *sorted.above)
    if ((a.above & kept) && !(a.on & kept) &&
        (stride == 1 || ((a.index % w) % stride == 0 && (a.index / w) % stride == 0)))
      band.push_back(a.index);
  std::vector<pcl::Indices> groups = stride == 1
                                       ? cluster(setup, cues, band, workspace)
                                       : clusterCoarse(setup, cues, band, stride, workspace);
  assignClusters(setup, groups, supports, extents, trial,
                 static_cast<std::size_t>(stride * stride));
  PCL_DEBUG("[facyl::TabletopSegmentation] stride %d: %zu supports, %zu object points, %zu "
            "groups, %zu clusters, %zu standing\n",
            stride, trial.supports.size(), band.size(), groups.size(), trial.clusters.size(),
            trial.standing);
  return trial;
}

} // namespace tabletop
} // namespace facyl
