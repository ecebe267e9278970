/*
 * facyl: fast cylinder detection for PCL.
 * The support prior of a stream (SupportPrior, segment_tabletop.h; the steps' functions in
 * tabletop_steps.h): which plane of a frame is the
 * prior's, and the preference it gives its family and its plane over what the frame alone would
 * choose.
 */
#include "tabletop_steps.h"

#include <facyl/features/polygon.h>

#include <pcl/console/print.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

namespace facyl {

SupportPrior
SupportPrior::transformed(const Eigen::Affine3f& t) const
{
  SupportPrior out = *this;
  out.plane = transformPlane(plane, t);
  out.centre = t * centre;
  for (auto& e : out.extent)
    e = t * e;
  return out;
}

float
priorMismatch(const SupportPrior& prior, const Eigen::Vector4f& plane)
{
  const float inf = std::numeric_limits<float>::infinity();
  if (!prior.valid() || !plane.allFinite())
    return inf;
  const float cos_angle = prior.plane.head<3>().dot(plane.head<3>().normalized());
  const float offset = std::abs(plane.head<3>().dot(prior.centre) + plane[3]);
  if (!(cos_angle >= std::cos(prior.max_angle)) || !(offset <= prior.max_offset))
    return inf;
  const float angle = std::acos(std::min(1.f, cos_angle));
  return std::max(angle / prior.max_angle,
                  prior.max_offset > 0.f ? offset / prior.max_offset : 0.f);
}

bool
consistentWithPrior(const SupportPrior& prior, const Eigen::Vector4f& plane)
{
  return std::isfinite(priorMismatch(prior, plane));
}

std::vector<Eigen::Vector2f>
priorExtentHull(const SupportPrior& prior, const Eigen::Vector4f& plane,
                const Eigen::Affine3f& plane_to_frame, const std::vector<Eigen::Vector2f>& polygon)
{
  if (prior.extent.empty() || !consistentWithPrior(prior, plane))
    return polygon;
  const Eigen::Affine3f to_plane = plane_to_frame.inverse();
  std::vector<Eigen::Vector2f> points = polygon;
  for (const auto& e : prior.extent)
    if (e.allFinite())
      points.push_back((to_plane * e).head<2>());
  return convexHull2D(std::move(points));
}

namespace tabletop {

int
priorCandidate(const Setup& setup, const std::vector<Candidate>& candidates)
{
  if (!setup.prior)
    return -1;
  // Of several (a counter and the slabs lying on it), the nearest.
  int best = -1;
  float least = std::numeric_limits<float>::infinity();
  for (std::size_t k = 0; k < candidates.size(); ++k) {
    const float m = priorMismatch(*setup.prior, candidates[k].plane);
    if (!candidates[k].points.empty() && m < least)
      best = static_cast<int>(k), least = m;
  }
  return best;
}

namespace {

/** \a plane moved along its normal to the densest slab of the distances of \a points from it
 * (one band of \a band wide, its median; \a o the sensor): a top's few pixels with depth, among
 * the points of the objects on it and of what stands behind; \a plane unchanged when that slab
 * holds fewer than \a min_points or is no peak (no more points than the slabs as wide on
 * either side of it). */
Eigen::Vector4f
toDensestSlab(const PointFrame& frame, const pcl::Indices& points, Eigen::Vector4f plane,
              const DepthBand& band, const Eigen::Vector3f& o, std::size_t min_points)
{
  if (points.empty())
    return plane;
  std::vector<std::pair<float, float>> d; // distance, half-width
  for (const auto i : points) {
    const Eigen::Vector3f p = frame.point(static_cast<std::size_t>(i));
    d.emplace_back(plane.head<3>().dot(p) + plane[3], band.halfWidth((p - o).norm()));
  }
  std::sort(d.begin(), d.end());
  std::size_t best = 0, most = 0;
  for (std::size_t a = 0, b = 0; a < d.size(); ++a) {
    b = std::max(b, a);
    while (b < d.size() && d[b].first <= d[a].first + 2.f * d[a].second)
      ++b;
    if (b - a > most)
      most = b - a, best = a;
  }
  // A surface is a peak of the distances: more points in its slab than in the slabs on
  // either side together (the walls of the objects on it spread evenly).
  const float lo = d[best].first, hi = d[best + most - 1].first, width = hi - lo;
  std::size_t beside = 0;
  for (const auto& x : d)
    beside += (x.first >= lo - width && x.first < lo) || (x.first > hi && x.first <= hi + width);
  if (most > beside && most >= min_points)
    plane[3] -= d[best + most / 2].first;
  return plane;
}

/** The prior's normal, or that of the largest of \a candidates within its max_angle of it (a
 * frame's parallel planes, a table beside the counter, tell it better than a prediction). */
Eigen::Vector4f
priorPlaneAligned(const SupportPrior& prior, const std::vector<Candidate>& candidates)
{
  const float cos_max = std::cos(prior.max_angle);
  Eigen::Vector4f plane = prior.plane;
  std::size_t most = 0;
  for (const auto& c : candidates)
    if (c.support > most && c.plane.head<3>().dot(prior.plane.head<3>()) >= cos_max) {
      most = c.support;
      plane.head<3>() = c.plane.head<3>();
    }
  plane[3] = -plane.head<3>().dot(prior.centre);
  return plane;
}

/** The rays of every plane_step-th pixel and row that meet \a plane (n towards the sensor)
 * inside \a extent (in the plane's coordinates, \a to_plane: frame to them). */
struct ExtentInView {
  bool valid{false};       ///< the sensor above the plane
  std::size_t in_view{0};  ///< rays that meet it there
  pcl::Indices seen, near; ///< their finite points; those within the prior's offset of it
};

ExtentInView
extentInView(const Setup& setup, const FrameCues& cues, const Eigen::Vector4f& plane,
             const Eigen::Affine3f& to_plane, const std::vector<Eigen::Vector2f>& extent)
{
  const PointFrame& frame = setup.frame;
  const SupportPrior& prior = *setup.prior;
  // The camera's rays: its intrinsics, else the estimated focal length about the centre.
  const bool given = setup.camera.valid() && setup.camera.width == static_cast<int>(frame.width);
  const float fx = given ? setup.camera.fx : cues.focal, fy = given ? setup.camera.fy : cues.focal;
  const float cx = given ? setup.camera.cx : 0.5f * static_cast<float>(frame.width - 1);
  const float cy = given ? setup.camera.cy : 0.5f * static_cast<float>(frame.height - 1);
  const Eigen::Vector3f n = plane.head<3>(), o = frame.viewpoint;
  const float height = n.dot(o) + plane[3];
  ExtentInView out;
  out.valid = height > 0.f;
  if (!out.valid)
    return out;
  const auto step = static_cast<std::uint32_t>(std::max(1, setup.plane_step));
  for (std::uint32_t v = 0; v < frame.height; v += step)
    for (std::uint32_t u = 0; u < frame.width; u += step) {
      const Eigen::Vector3f ray((static_cast<float>(u) - cx) / fx,
                                (static_cast<float>(v) - cy) / fy, 1.f);
      const float towards = n.dot(ray);
      if (!(towards < 0.f)) // the ray does not meet the plane's upper side
        continue;
      const Eigen::Vector3f hit = o + (-height / towards) * ray;
      if (!pointInPolygon((to_plane * hit).head<2>(), extent))
        continue;
      ++out.in_view;
      const std::size_t i = static_cast<std::size_t>(v) * frame.width + u;
      if (!frame.finite(i))
        continue;
      out.seen.push_back(static_cast<pcl::index_t>(i));
      const Eigen::Vector3f p = frame.point(i);
      if (std::abs(n.dot(p) + plane[3]) <=
          std::max(prior.max_offset, cues.noise->halfWidth((p - o).norm())))
        out.near.push_back(static_cast<pcl::index_t>(i));
    }
  return out;
}

/** Of the rays of \a view, the points on \a plane (within the noise band of their range) and
 * the number beyond it (a ray that passed where it would be); whether the plane is there: its
 * points as many as a plane needs (min_plane_points) or most rays without depth (of those that
 * meet nothing in front of it: objects on it show it neither way, and hide less than half of
 * it), and fewer than half of the rays beyond it (a quarter for a prior the frame inferred:
 * Setup::prior_inferred). A plane hidden behind what is in front of it everywhere (another
 * table) is not there. */
struct PlaneOnRays {
  pcl::Indices on;
  std::size_t beyond{0};
  bool there{false};
};

PlaneOnRays
planeOnRays(const Setup& setup, const FrameCues& cues, const ExtentInView& view,
            const Eigen::Vector4f& plane)
{
  const PointFrame& frame = setup.frame;
  const Eigen::Vector3f o = frame.viewpoint;
  PlaneOnRays out;
  for (const auto i : view.seen) {
    const Eigen::Vector3f p = frame.point(static_cast<std::size_t>(i));
    const float d = plane.head<3>().dot(p) + plane[3], half = cues.noise->halfWidth((p - o).norm());
    if (d < -half)
      ++out.beyond;
    else if (d <= half)
      out.on.push_back(i);
  }
  const int step = std::max(1, setup.plane_step);
  const auto cell = static_cast<std::size_t>(step * step);
  // A ray that meets something in front of the plane (an object on it) shows it neither way;
  // objects on a plane hide less than half of it (another table in front hides all of it).
  const std::size_t missing = view.in_view - view.seen.size();
  const std::size_t in_front = view.seen.size() - out.on.size() - out.beyond;
  const std::size_t beyond_limit = setup.prior_inferred ? 4 : 2; // 1 / limit of the rays
  const bool holes = 2 * in_front < view.in_view && 2 * missing > view.in_view - in_front;
  out.there = (out.on.size() * cell >= setup.params.min_plane_points || holes) &&
              beyond_limit * out.beyond < view.in_view;
  return out;
}

} // namespace

bool
priorPlaneInView(const Setup& setup, const FrameCues& cues)
{
  if (!setup.prior || !setup.as_image || setup.prior->extent.size() < 3 || !cues.noise ||
      !(cues.focal > 0.f))
    return false;
  const SupportPrior& prior = *setup.prior;
  const Eigen::Affine3f plane_to_frame = planeFrame(prior.plane, prior.centre);
  const std::vector<Eigen::Vector2f> extent =
    priorExtentHull(prior, prior.plane, plane_to_frame, {});
  if (extent.size() < 3)
    return false;
  const ExtentInView view =
    extentInView(setup, cues, prior.plane, plane_to_frame.inverse(), extent);
  return view.valid && planeOnRays(setup, cues, view, prior.plane).there;
}

std::optional<Candidate>
priorPlaneCandidate(const Setup& setup, const FrameCues& cues,
                    const std::vector<Candidate>& candidates)
{
  const PointFrame& frame = setup.frame;
  if (!setup.prior || !setup.as_image || setup.prior->extent.size() < 3 || !cues.noise ||
      !(cues.focal > 0.f) || candidates.size() >= 8 || priorCandidate(setup, candidates) >= 0)
    return std::nullopt;
  const SupportPrior& prior = *setup.prior;
  const Eigen::Vector4f aligned = priorPlaneAligned(prior, candidates);
  const Eigen::Affine3f plane_to_frame = planeFrame(aligned, prior.centre);
  const std::vector<Eigen::Vector2f> extent = priorExtentHull(prior, aligned, plane_to_frame, {});
  if (extent.size() < 3)
    return std::nullopt;
  const ExtentInView view = extentInView(setup, cues, aligned, plane_to_frame.inverse(), extent);
  if (!view.valid)
    return std::nullopt;
  const int step = std::max(1, setup.plane_step);
  const auto cell = static_cast<std::size_t>(step * step);
  const Eigen::Vector3f o = frame.viewpoint;
  // The plane where the points near the prediction are densest (the top's few pixels with
  // depth; as many as a plane needs to be found), when it is still the prior's.
  Eigen::Vector4f plane = toDensestSlab(frame, view.near, aligned, *cues.noise, o,
                                        (setup.params.min_plane_points + cell - 1) / cell);
  if (!consistentWithPrior(prior, plane))
    plane = aligned;
  // Most rays that meet it in view must not see through it, and some of it is seen or most of
  // it gives no depth.
  PlaneOnRays rays = planeOnRays(setup, cues, view, plane);
  PCL_DEBUG("[facyl::TabletopSegmentation] the support prior's plane, not found: %zu cells of "
            "its extent in view, %zu on (%.3f %.3f %.3f) d %.3f, %zu beyond it: %s\n",
            view.in_view, rays.on.size(), plane[0], plane[1], plane[2], plane[3], rays.beyond,
            rays.there ? "a candidate" : "not there");
  if (!rays.there)
    return std::nullopt;
  Candidate out;
  out.points = std::move(rays.on);
  out.plane = plane;
  out.band = *cues.noise;
  out.support = out.points.size() * cell;
  out.from_prior = true;
  return out;
}

namespace {

/** An object's extent on an inferred support: its feet grown to this many times their size
 * about their centre (the top they stand on reaches beyond them; its rays must show holes). */
constexpr float kInferredExtentGrowth = 2.f;
/** rad: an inferred support is parallel to the table found by construction; a candidate within
 * 3 degrees of it is that plane. */
constexpr float kInferredMaxAngle = 0.05f;

/** The cells of the plane grid (every plane_step-th pixel and row) with depth: each its pixel
 * and height over \a plane (infinite without depth). */
struct HeightCells {
  std::size_t width{0}, height{0};
  std::vector<float> over;
  std::vector<pcl::index_t> pixel;
};

HeightCells
heightCells(const Setup& setup, const Eigen::Vector4f& plane)
{
  const PointFrame& frame = setup.frame;
  const auto step = static_cast<std::size_t>(std::max(1, setup.plane_step));
  HeightCells g;
  g.width = (frame.width + step - 1) / step;
  g.height = (frame.height + step - 1) / step;
  g.over.assign(g.width * g.height, std::numeric_limits<float>::infinity());
  g.pixel.assign(g.width * g.height, -1);
  for (std::size_t v = 0; v < frame.height; v += step)
    for (std::size_t u = 0; u < frame.width; u += step) {
      const std::size_t i = v * frame.width + u, c = (v / step) * g.width + u / step;
      if (!frame.finite(i))
        continue;
      g.over[c] = plane.head<3>().dot(frame.point(i)) + plane[3];
      g.pixel[c] = static_cast<pcl::index_t>(i);
    }
  return g;
}

/** Groups of adjacent cells of \a g (within cluster_tolerance per cell of each other) that are
 * \a floating, without those that go on into a neighbour below max_height (a chair's back, an
 * object taller than the band: standing on the plane). */
template <typename Floating>
std::vector<std::vector<std::size_t>>
floatingGroups(const Setup& setup, const HeightCells& g, Floating floating)
{
  const PointFrame& frame = setup.frame;
  const float reach =
    setup.params.cluster_tolerance * static_cast<float>(std::max(1, setup.plane_step));
  const auto near = [&](std::size_t a, std::size_t b) {
    return g.pixel[b] >= 0 && (frame.point(static_cast<std::size_t>(g.pixel[a])) -
                               frame.point(static_cast<std::size_t>(g.pixel[b])))
                                  .norm() <= reach;
  };
  std::vector<char> grouped(g.over.size(), 0);
  std::vector<std::vector<std::size_t>> out;
  for (std::size_t c = 0; c < g.over.size(); ++c) {
    if (!floating(c) || grouped[c])
      continue;
    std::vector<std::size_t> members{c}, todo{c};
    grouped[c] = 1;
    bool attached = false;
    while (!todo.empty()) {
      const std::size_t a = todo.back();
      todo.pop_back();
      const std::size_t u = a % g.width, v = a / g.width;
      const std::size_t beside[4] = {u > 0 ? a - 1 : a, u + 1 < g.width ? a + 1 : a,
                                     v > 0 ? a - g.width : a, v + 1 < g.height ? a + g.width : a};
      for (const std::size_t b : beside) {
        if (b == a || !near(a, b))
          continue;
        if (!floating(b))
          attached = attached || g.over[b] <= setup.params.max_height;
        else if (!grouped[b]) {
          grouped[b] = 1;
          members.push_back(b);
          todo.push_back(b);
        }
      }
    }
    if (!attached)
      out.push_back(std::move(members));
  }
  return out;
}

/** An object floating over the table found: its cells and its bottom (its lowest percent). */
struct Floater {
  float bottom;
  std::vector<std::size_t> cells;
};

/** The objects floating above \a table (floatingGroups beyond its object band, up to four of
 * its height: a table top over the floor) of min_cluster_size pixels that stand (their median
 * height two of the table's bands above their bottom; a far table's top lies flat). */
std::vector<Floater>
standingFloaters(const Setup& setup, const SupportPlane& table, const HeightCells& g)
{
  const PointFrame& frame = setup.frame;
  const auto& p = setup.params;
  const auto floating = [&](std::size_t c) {
    return g.over[c] > p.max_height && g.over[c] < 4.f * p.max_height;
  };
  const auto step = static_cast<std::size_t>(std::max(1, setup.plane_step));
  const std::size_t min_cells = std::max<std::size_t>(4, p.min_cluster_size / (step * step));
  std::vector<Floater> out;
  for (auto& cells : floatingGroups(setup, g, floating)) {
    if (cells.size() < min_cells)
      continue;
    std::vector<float> over;
    for (const auto c : cells)
      over.push_back(g.over[c]);
    std::sort(over.begin(), over.end());
    const float bottom = over[over.size() / 100], middle = over[over.size() / 2];
    const Eigen::Vector3f q = frame.point(static_cast<std::size_t>(g.pixel[cells.front()]));
    if (middle - bottom > 2.f * table.band.halfWidth((q - frame.viewpoint).norm()))
      out.push_back({bottom, std::move(cells)});
  }
  return out;
}

/** Of \a floaters (not empty), those of the densest slab of bottoms (\a slab wide, by cells);
 * \a top: the lowest of their bottoms (an object seen behind another shows a higher bottom;
 * none stands below the top). */
std::vector<const Floater*>
densestBottoms(const std::vector<Floater>& floaters, float slab, float& top)
{
  std::size_t best = 0, most = 0;
  for (std::size_t a = 0; a < floaters.size(); ++a) {
    std::size_t count = 0;
    for (const auto& b : floaters)
      if (std::abs(b.bottom - floaters[a].bottom) <= slab)
        count += b.cells.size();
    if (count > most)
      most = count, best = a;
  }
  std::vector<const Floater*> out;
  top = floaters[best].bottom;
  for (const auto& b : floaters)
    if (std::abs(b.bottom - floaters[best].bottom) <= slab) {
      out.push_back(&b);
      top = std::min(top, b.bottom);
    }
  return out;
}

} // namespace

std::optional<SupportPrior>
supportUnderFloatingObjects(const Setup& setup, const TabletopSegments& segments)
{
  const PointFrame& frame = setup.frame;
  if (!setup.as_image || frame.indices || segments.supports.empty())
    return std::nullopt;
  const SupportPlane& table = segments.supports[segments.table];
  // Bottoms within two of the table's bands (at 1 m) of each other are one top's.
  const float slab = 2.f * table.band.halfWidth(1.f);
  if (!(slab > 0.f))
    return std::nullopt;
  const HeightCells g = heightCells(setup, table.plane);
  const std::vector<Floater> floaters = standingFloaters(setup, table, g);
  if (floaters.empty())
    return std::nullopt;
  float top = 0.f;
  const std::vector<const Floater*> on_top = densestBottoms(floaters, slab, top);
  SupportPrior prior;
  prior.plane = table.plane;
  prior.plane[3] -= top;
  prior.max_angle = kInferredMaxAngle;
  prior.max_offset = slab;
  // Its extent: the feet of the objects on it, projected on it and grown.
  const Eigen::Vector3f n = table.plane.head<3>();
  std::vector<Eigen::Vector3f> feet;
  for (const Floater* b : on_top)
    for (const auto c : b->cells)
      if (g.over[c] <= b->bottom + slab) {
        const Eigen::Vector3f q = frame.point(static_cast<std::size_t>(g.pixel[c]));
        feet.push_back(q - (n.dot(q) + prior.plane[3]) * n);
      }
  Eigen::Vector3f centre = Eigen::Vector3f::Zero();
  for (const auto& f : feet)
    centre += f;
  prior.centre = centre / static_cast<float>(feet.size());
  for (const auto& f : feet)
    prior.extent.push_back(prior.centre + kInferredExtentGrowth * (f - prior.centre));
  PCL_DEBUG("[facyl::TabletopSegmentation] %zu objects float above the table; their bottoms at "
            "%.3f m over it: a support there?\n",
            floaters.size(), top);
  return prior;
}

void
adoptPriorRegion(const Setup& setup, SortedFrame& sorted)
{
  for (std::size_t s = 0; s < sorted.candidates.size(); ++s) {
    if (!sorted.candidates[s].from_prior || !setup.prior)
      continue;
    SupportPlane& a = sorted.all[s];
    a.frame = planeFrame(a.plane, setup.prior->centre);
    CandidateHulls& hulls = sorted.hulls[s];
    hulls.polygon = priorExtentHull(*setup.prior, a.plane, a.frame, {});
    hulls.extent = hulls.polygon;
    hulls.region = polygonArea(hulls.polygon);
    hulls.known = hulls.judged = true;
    hulls.elevated = hulls.elevated_support = false;
  }
}

void
keepPriorCandidate(const Setup& setup, std::vector<Candidate>& candidates, std::size_t kept)
{
  const int k = priorCandidate(setup, candidates);
  if (kept == 0 || k < 0 || static_cast<std::size_t>(k) < kept)
    return;
  // Its place: the last one kept; the candidates between move one on.
  std::rotate(candidates.begin() + static_cast<std::ptrdiff_t>(kept - 1), candidates.begin() + k,
              candidates.begin() + k + 1);
}

int
priorFamily(const Setup& setup, const SortedFrame& sorted,
            const std::vector<std::vector<std::size_t>>& families)
{
  if (!setup.prior)
    return -1;
  const SupportPrior& prior = *setup.prior;
  for (std::size_t f = 0; f < families.size(); ++f)
    for (const std::size_t s : families[f])
      if (consistentWithPrior(prior, sorted.all[s].plane))
        return static_cast<int>(f);
  const float cos_max = std::cos(prior.max_angle);
  for (std::size_t f = 0; f < families.size(); ++f)
    if (!families[f].empty() &&
        sorted.all[families[f].front()].plane.head<3>().dot(prior.plane.head<3>()) >= cos_max)
      return static_cast<int>(f);
  return -1;
}

std::size_t
familyWithPrior(int prior_family, std::size_t chosen, const std::vector<char>& with_supports,
                const std::vector<std::size_t>& standing, SupportPriorResult& result)
{
  if (prior_family < 0 || static_cast<std::size_t>(prior_family) >= with_supports.size() ||
      !with_supports[static_cast<std::size_t>(prior_family)])
    return chosen;
  const auto f = static_cast<std::size_t>(prior_family);
  result.challenged = chosen != f && standing[chosen] > standing[f];
  return f;
}

std::size_t
tableWithPrior(const Setup& setup, const std::vector<SupportPlane>& supports, Trial& trial)
{
  // The frame's own table: the most object points standing on it; else the largest support.
  std::size_t table = 0;
  for (std::size_t s = 0; s < supports.size(); ++s) {
    trial.standing += supports[s].standing_points;
    if (supports[s].standing_points > supports[table].standing_points ||
        (supports[s].standing_points == supports[table].standing_points &&
         supports[s].inliers.indices.size() > supports[table].inliers.indices.size()))
      table = s;
  }
  trial.table_is_prior = false;
  if (!setup.prior)
    return table;
  // Of several supports that are the prior's plane (a counter and the slabs lying on it), the
  // nearest: the table does not jump between them from frame to frame.
  float least = std::numeric_limits<float>::infinity();
  for (std::size_t s = 0; s < supports.size(); ++s) {
    const float m = priorMismatch(*setup.prior, supports[s].plane);
    if (m < least) {
      trial.table_is_prior = true;
      table = s, least = m;
    }
  }
  return table;
}

} // namespace tabletop
} // namespace facyl
