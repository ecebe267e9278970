/*
 * facyl: fast cylinder detection for PCL.
 * segmentTabletop (segment_tabletop.h): the run of one frame, its steps in order
 * (tabletop_steps.h), and the choice of the family of supports.
 */
#include "tabletop_steps.h"

#include <facyl/features/parallel.h>

#include <pcl/console/print.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <sstream>
#include <stdexcept>

namespace facyl {

std::string
validate(const TabletopSegmentationParameters& p)
{
  std::ostringstream why;
  if (!(p.plane_distance >= 0.f) || !std::isfinite(p.plane_distance))
    why << "plane distance " << p.plane_distance << " must be >= 0 (0: measured)";
  else if (!(p.band_factor >= 1.f && p.band_factor <= 10.f))
    why << "band factor " << p.band_factor << " must be in [1, 10]";
  else if (!(p.plane_angle > 0.f && p.plane_angle < 1.58f))
    why << "plane angle " << p.plane_angle << " must be in (0, pi/2]";
  else if (p.min_plane_points < 3)
    why << "min_plane_points must be >= 3";
  else if (!(p.min_height < p.max_height) || !std::isfinite(p.min_height) ||
           !std::isfinite(p.max_height))
    why << "height limits [" << p.min_height << ", " << p.max_height
        << "] must be finite, min < max";
  else if (!(p.cluster_tolerance > 0.f))
    why << "cluster tolerance " << p.cluster_tolerance << " must be > 0";
  else if (p.min_cluster_size < 1 || p.min_cluster_size > p.max_cluster_size)
    why << "cluster sizes must satisfy 1 <= min <= max";
  else if (!(p.min_hull_share > 0.f && p.min_hull_share <= 1.f))
    why << "min_hull_share " << p.min_hull_share << " must be in (0, 1]";
  else if (p.plane_step < 0 || p.plane_step > 16)
    why << "plane step " << p.plane_step << " must be in [0, 16] (0: automatic)";
  else if (p.lattice_width != 0 && (p.lattice_width < 160 || p.lattice_width > 8192))
    why << "lattice width " << p.lattice_width << " must be 0 (every pixel) or in [160, 8192]";
  else if (p.plane_samples < 100)
    why << "plane_samples " << p.plane_samples << " must be >= 100";
  else if (p.max_planes < 1 || p.max_planes > 8)
    why << "max_planes " << p.max_planes << " must be in [1, 8]";
  else if (!(p.max_support_tilt > 0.f && p.max_support_tilt < 1.58f))
    why << "max_support_tilt " << p.max_support_tilt << " must be in (0, pi/2]";
  else if (!(p.min_support_area >= 0.f) || !std::isfinite(p.min_support_area))
    why << "min_support_area must be >= 0";
  else if (!(p.min_shelf_area >= 0.f) || !std::isfinite(p.min_shelf_area))
    why << "min_shelf_area must be >= 0";
  else if (!(p.contact_height > 0.f) || !std::isfinite(p.contact_height))
    why << "contact_height must be > 0";
  else if (const std::string o = validate(p.objects); !o.empty())
    why << "objects: " << o;
  return why.str();
}

namespace tabletop {
namespace {

using Clock = std::chrono::steady_clock;

double
msSince(Clock::time_point a)
{
  return std::chrono::duration<double, std::milli>(Clock::now() - a).count();
}

/** How many times more standing objects another family of supports needs than the one an
 * upright camera would choose (see chooseFamily). */
constexpr float kFamilyMargin = 1.5f;

/** Of \a families (rankFamilies' order), the one whose supports most objects stand on; with a
 * prior, its family while it has supports (familyWithPrior; \a prior: whether the frame alone
 * chose another). */
std::size_t
chooseFamily(const Setup& setup, const FrameCues& cues, SortedFrame& sorted,
             const std::vector<std::vector<std::size_t>>& families, std::size_t& tried,
             TabletopWorkspace& workspace, SupportPriorResult& prior)
{
  // The family of supports is the one most objects stand on: no camera roll is assumed.
  // Several families: each is judged on a coarse grid of its object points (a clustering at
  // full resolution costs several milliseconds), and only the one most objects stand on is
  // segmented at full resolution. Objects are counted, not points (a flat patch of a floor
  // next to a wall may stand on the wall as one large "object"). The first in rankFamilies'
  // order (an upright camera's choice) is kept unless another holds clearly more
  // (kFamilyMargin times): with few objects in view, a box's faces can hold as many as the
  // table.
  std::size_t chosen = 0, most = 0;
  tried = 0;
  if (families.size() < 2)
    return chosen;
  const int stride = setup.as_image ? setup.plane_step : 1;
  std::vector<char> with_supports(families.size(), 0);
  std::vector<std::size_t> standing(families.size(), 0);
  for (std::size_t f = 0; f < families.size(); ++f) {
    const Trial coarse = tryFamily(setup, cues, sorted, families[f], stride, false, workspace);
    tried += !coarse.supports.empty();
    with_supports[f] = !coarse.supports.empty();
    standing[f] = coarse.standing_objects;
    const Eigen::Vector4f& first = sorted.candidates[families[f].front()].plane;
    PCL_DEBUG("[facyl::TabletopSegmentation] family %zu (%zu planes, first (%.3f %.3f %.3f)): "
              "%zu supports, %zu objects standing (%zu points, coarse)\n",
              f, families[f].size(), first[0], first[1], first[2], coarse.supports.size(),
              coarse.standing_objects, coarse.standing);
    if (!coarse.supports.empty() && (tried == 1 || static_cast<float>(coarse.standing_objects) >
                                                     kFamilyMargin * static_cast<float>(most)))
      chosen = f, most = coarse.standing_objects;
  }
  return familyWithPrior(priorFamily(setup, sorted, families), chosen, with_supports, standing,
                         prior);
}

/** \a out's supports, table and clusters from \a trial; when nothing stands on the supports,
 * also the compact segments off them and off the clusters found. */
void
adoptTrial(const Setup& setup, const FrameCues& cues, Trial trial, TabletopSegments& out,
           TabletopWorkspace& workspace)
{
  out.supports = std::move(trial.supports);
  out.table = trial.table;
  // Something stands on the supports (the frame's own table is the one most stands on; the
  // prior's may hold less).
  out.table_found = std::any_of(out.supports.begin(), out.supports.end(),
                                [](const SupportPlane& s) { return s.standing_points > 0; });
  out.prior.support = trial.table_is_prior ? static_cast<int>(out.table) : -1;
  out.prior.predicted = trial.table_is_prior && trial.from_prior == static_cast<int>(out.table);
  out.clusters = std::move(trial.clusters);
  if (out.table_found)
    return;
  // Nothing stands on the supports in view (a table without depth: glossy, dark): the compact
  // segments off them and off the clusters found are objects too, without a support.
  std::vector<std::uint8_t> taken(setup.frame.size, 0);
  for (const auto& support : out.supports)
    for (const auto i : support.inliers.indices)
      taken[static_cast<std::size_t>(i)] = 1;
  for (const auto& c : out.clusters)
    for (const auto i : c.indices.indices)
      taken[static_cast<std::size_t>(i)] = 1;
  segmentWithoutSupport(setup, cues, &taken, out.clusters, workspace);
}

} // namespace

int
planeStep(const PointFrame& frame, const TabletopSegmentationParameters& params)
{
  if (params.plane_step > 0)
    return params.plane_step;
  return std::clamp(static_cast<int>(std::lround(frame.width / 160.0)), 1, 16);
}

bool
searchedAsImage(const PointFrame& frame, const TabletopSegmentationParameters& params)
{
  const auto cells = static_cast<std::uint32_t>(16 * planeStep(frame, params));
  return frame.isOrganized() && frame.width >= cells && frame.height >= cells;
}

Setup
makeSetup(const PointFrame& frame, const TabletopSegmentationParameters& params,
          const PinholeCamera& camera, const Eigen::Vector3f& up, const SupportPrior* prior,
          int threads)
{
  // The prior guides the choice among the planes objects stand on (ObjectsStanding).
  const bool use_prior = prior && prior->valid() &&
                         params.support == TabletopSegmentationParameters::Support::ObjectsStanding;
  return Setup{frame,
               params,
               camera,
               up,
               planeStep(frame, params),
               searchedAsImage(frame, params),
               use_prior ? prior : nullptr,
               threads};
}

void
sortLargestFirst(std::vector<TabletopCluster>& clusters)
{
  std::stable_sort(clusters.begin(), clusters.end(), [](const auto& a, const auto& b) {
    return a.indices.indices.size() > b.indices.indices.size();
  });
}

void
adoptSupportUnderFloatingObjects(const Setup& setup, FrameCues& cues, TabletopWorkspace& workspace,
                                 TabletopSegments& out)
{
  if (setup.prior) // a given prior decides the support
    return;
  const std::optional<SupportPrior> under = supportUnderFloatingObjects(setup, out);
  if (!under)
    return;
  Setup again =
    makeSetup(setup.frame, setup.params, setup.camera, setup.up, &*under, setup.threads);
  again.prior_inferred = true;
  if (!priorPlaneInView(again, cues)) {
    PCL_DEBUG("[facyl::TabletopSegmentation] the support under the floating objects: not in "
              "view (its rays see beyond it)\n");
    return;
  }
  FrameCues cues_again;
  TabletopSegments other = segmentFrame(again, cues_again, workspace);
  const bool kept = other.prior.support >= 0 &&
                    other.table == static_cast<std::size_t>(other.prior.support) &&
                    other.table_found;
  PCL_DEBUG("[facyl::TabletopSegmentation] the support under the floating objects: %s\n",
            kept ? "the table" : "not kept");
  SegmentationTiming& t = kept ? other.timing : out.timing;
  const SegmentationTiming& u = kept ? out.timing : other.timing;
  t.planes += u.planes;
  t.points += u.points;
  t.objects += u.objects;
  if (kept) {
    other.prior = SupportPriorResult{}; // none was given
    out = std::move(other);
    cues = cues_again;
  }
}

TabletopSegments
segmentFrame(const Setup& setup, FrameCues& cues, TabletopWorkspace& workspace)
{
  const auto t0 = Clock::now();
  TabletopSegments out;
  out.prior.given = setup.prior != nullptr;
  if (setup.prior)
    PCL_DEBUG("[facyl::TabletopSegmentation] support prior (%.3f %.3f %.3f) d %.3f, within %.3f "
              "rad and %.3f m\n",
              setup.prior->plane[0], setup.prior->plane[1], setup.prior->plane[2],
              setup.prior->plane[3], setup.prior->max_angle, setup.prior->max_offset);
  // 1. The support candidates; 2. every point sorted onto and above them.
  std::vector<Candidate> candidates = findCandidates(setup, cues, workspace);
  if (auto prior_plane = priorPlaneCandidate(setup, cues, candidates))
    candidates.push_back(std::move(*prior_plane));
  const double t_planes = msSince(t0);
  SortedFrame sorted = classifyPoints(setup, std::move(candidates), workspace);
  adoptPriorRegion(setup, sorted);
  const double t_points = msSince(t0);
  // 3. The family of supports that objects stand on, and its objects at full resolution.
  const auto families = rankFamilies(setup, cues, sorted);
  std::size_t tried = 0;
  const std::size_t chosen =
    chooseFamily(setup, cues, sorted, families, tried, workspace, out.prior);
  std::optional<Trial> best;
  if (!families.empty()) {
    Trial trial = tryFamily(setup, cues, sorted, families[chosen], 1, true, workspace);
    if (!trial.supports.empty())
      best = std::move(trial);
  }
  out.timing.planes = t_planes;
  out.timing.points = t_points - t_planes;
  PCL_DEBUG("[facyl::TabletopSegmentation] %.2f ms: planes %.2f, points %.2f, family %zu of "
            "%zu (%zu with supports)\n",
            msSince(t0), t_planes, t_points - t_planes, chosen, families.size(), tried);
  if (best)
    adoptTrial(setup, cues, std::move(*best), out, workspace);
  else {
    // 4. No support in view: the compact segments of the frame.
    PCL_DEBUG("[facyl::TabletopSegmentation] no support in view: %zu candidate planes, none "
              "of at least %g m^2\n",
              sorted.candidates.size(), static_cast<double>(setup.params.min_support_area));
    segmentWithoutSupport(setup, cues, nullptr, out.clusters, workspace);
  }
  sortLargestFirst(out.clusters);
  out.focal = cues.focal;
  out.timing.objects = msSince(t0) - t_points;
  return out;
}

} // namespace tabletop

TabletopSegments
segmentTabletop(const PointFrame& frame, const PinholeCamera& camera, const Eigen::Vector3f& up,
                const TabletopSegmentationParameters& params, TabletopWorkspace& workspace,
                const SupportPrior* prior)
{
  const auto t0 = tabletop::Clock::now();
  if (const std::string why = validate(params); !why.empty())
    throw std::invalid_argument("facyl::segmentTabletop: invalid parameters: " + why);
  if (camera.valid() && !cameraUsable(camera))
    throw std::invalid_argument("facyl::segmentTabletop: the camera is not usable (finite "
                                "intrinsics, at most 8192 x 8192 pixels)");
  if (!up.allFinite())
    throw std::invalid_argument("facyl::segmentTabletop: the up direction is not finite");
  if ((frame.size > 0 && !frame.xyz) || frame.stride < 3)
    throw std::invalid_argument("facyl::segmentTabletop: a frame needs its points' memory and "
                                "a stride of at least 3 floats");
  const tabletop::Setup setup =
    tabletop::makeSetup(frame, params, camera, up, prior, threadsForIdleCores(workspace.threads));
  const int step = latticeStep(frame, params);
  TabletopSegments out;
  if (step > 1)
    out = tabletop::segmentOnLattice(setup, step, workspace);
  else {
    tabletop::FrameCues cues;
    out = tabletop::segmentFrame(setup, cues, workspace);
    tabletop::adoptSupportUnderFloatingObjects(setup, cues, workspace, out);
  }
  out.timing.total = tabletop::msSince(t0);
  return out;
}

} // namespace facyl
