/*
 * facyl: fast cylinder detection for PCL.
 * The support candidates of a frame (tabletop_steps.h): the plane grid of an image or a
 * sample of a point set, their seeds grown into planes, and the candidates kept.
 */
#include "tabletop_steps.h"

#include <facyl/features/parallel.h>
#include <facyl/features/polygon.h>

#include <pcl/common/point_tests.h>
#include <pcl/filters/random_sample.h>

#include <algorithm>
#include <cmath>
#include <optional>

namespace facyl {
namespace tabletop {
namespace {

/** The seed threshold of the plane search: plane_distance, or kSeedDistance. */
float
seedDistance(const TabletopSegmentationParameters& params)
{
  return params.plane_distance > 0.f ? params.plane_distance : kSeedDistance;
}

/** How seeds grow into planes: the band measured, or plane_distance. */
PlaneRegionSettings
regionSettings(const TabletopSegmentationParameters& params)
{
  PlaneRegionSettings s;
  s.band_factor = params.band_factor;
  s.fixed_band = params.plane_distance;
  s.min_angle = params.plane_angle;
  return s;
}

/** The grid of blocks of \a step pixels: each cell the mean of the pixels of its block with
 * depth near the first one's, its normal, and its first pixel; with \a twice, also the grid of
 * 2 \a step pixels, from the same pass over the image; with \a has_depth, also which pixels
 * have depth (the object segmentation's occlusion test); on \a threads threads. */
void
planeGrid(const Setup& setup, int step, PlaneGrid& grid, PlaneGrid* twice,
          std::vector<std::uint8_t>* has_depth, int threads)
{
  const PointFrame& frame = setup.frame;
  const int w = static_cast<int>(frame.width), h = static_cast<int>(frame.height);
  std::vector<std::uint8_t> allowed; // only when indices were given
  if (frame.indices) {
    allowed.assign(frame.size, 0);
    for (const auto i : *frame.indices)
      allowed[static_cast<std::size_t>(i)] = 1;
  }
  // A grid of every step-th pixel; each cell is the mean of the pixels of its block that have
  // depth near the first one's: real sensors lose several percent of their pixels (a single
  // pixel per cell would spread NaN normals) and active stereo is noisy (the mean of up to
  // step^2 pixels is less so); the depth test keeps objects' edges sharp. One pass over the
  // image in row order (a block's first pixel in row order is its first valid one) fills the
  // grid and, when asked, the one of twice the step.
  BlockMeans fine(step, w, h);
  std::optional<BlockMeans> coarse;
  if (twice)
    coarse.emplace(2 * step, w, h);
  if (has_depth)
    has_depth->resize(frame.size);
  // In locals: the byte stores below could alias the frame's members, which would then be
  // read again at every pixel.
  const bool every = !frame.indices;
  const float* const xyz = frame.xyz;
  const std::size_t stride = frame.stride;
  std::uint8_t* const depth = has_depth ? has_depth->data() : nullptr;
  // Bands of whole rows of the largest blocks on the workspace's threads: each block is
  // filled by one thread, in row order, so the means are the same on any number.
  const int band = twice ? 2 * step : step;
  const auto bands = static_cast<std::size_t>((h + band - 1) / band);
  parallelFor(bands, threads, 8, [&](std::size_t b0, std::size_t b1) {
    for (int v = static_cast<int>(b0) * band; v < std::min(h, static_cast<int>(b1) * band); ++v) {
      const std::size_t base = static_cast<std::size_t>(v) * static_cast<std::size_t>(w);
      const std::size_t fine_row = fine.rowBase(v), coarse_row = coarse ? coarse->rowBase(v) : 0;
      const float* p = xyz + base * stride;
      for (int u = 0; u < w; ++u, p += stride) {
        const std::size_t idx = base + static_cast<std::size_t>(u);
        const bool finite = std::isfinite(p[2]) && std::isfinite(p[0]) && std::isfinite(p[1]);
        if (depth)
          depth[idx] = finite;
        if (!finite || !(every || allowed[idx]))
          continue;
        const auto uu = static_cast<std::size_t>(u);
        const Eigen::Map<const Eigen::Vector3f> q(p);
        fine.addTo(fine_row + fine.column_block[uu], static_cast<pcl::index_t>(idx), q);
        if (coarse)
          coarse->addTo(coarse_row + coarse->column_block[uu], static_cast<pcl::index_t>(idx), q);
      }
    }
  });
  finishPlaneGrid(fine, w, grid);
  if (twice)
    finishPlaneGrid(*coarse, w, *twice);
}

/** Grows \a seed (cells of \a cells) into a candidate; cells already \a taken by earlier
 * candidates stay with them, the new ones are marked. \a source maps cells to frame indices,
 * \a cell_points is the number of pixels a cell stands for.
 * \return false when the region is not a plane of min_plane_points. */
bool
growCandidate(const Setup& setup, const PlaneRegionCells& cells,
              const std::vector<std::uint8_t>& seed, const std::vector<pcl::index_t>& source,
              std::size_t cell_points, std::vector<std::uint8_t>& taken, Candidate& out)
{
  PlaneRegion region;
  if (!refinePlaneRegion(cells, seed, regionSettings(setup.params), region, &taken))
    return false;
  out.plane = region.plane;
  out.band = region.band;
  out.points.clear();
  for (std::size_t k = 0; k < region.member.size(); ++k)
    if (region.member[k] && source[k] >= 0)
      out.points.push_back(source[k]);
  out.support = out.points.size() * cell_points;
  PCL_DEBUG("[facyl::TabletopSegmentation] plane (%.3f %.3f %.3f) d %.3f: %zu points, band "
            "+-%.1f mm at 1 m, normals within %.1f deg\n",
            out.plane[0], out.plane[1], out.plane[2], out.plane[3], out.support,
            1e3 * out.band.halfWidth(1.f), region.max_angle * 180.f / static_cast<float>(M_PI));
  if (out.support < setup.params.min_plane_points)
    return false;
  for (std::size_t k = 0; k < region.member.size(); ++k)
    taken[k] = taken[k] || region.member[k];
  return true;
}

/** Grows \a seeds of \a grid into candidates (growCandidate), skipping the seeds mostly on the
 * cells of \a candidates found before; appends them. */
void
growCandidates(const Setup& setup, const PlaneGrid& grid,
               const std::vector<pcl::PointIndices>& seeds, std::vector<Candidate>& candidates)
{
  const std::size_t cell = static_cast<std::size_t>(grid.step * grid.step);
  // The cells of the candidates found already (on this grid or another) are taken.
  std::vector<std::uint8_t> taken(grid.small->size(), 0);
  const auto w = static_cast<pcl::index_t>(setup.frame.width);
  const auto cw = static_cast<pcl::index_t>(grid.small->width);
  for (const auto& c : candidates)
    for (const auto i : c.points) {
      const auto k = static_cast<std::size_t>((i / w) / grid.step * cw + (i % w) / grid.step);
      if (k < taken.size())
        taken[k] = 1;
    }
  const PlaneRegionCells region_cells(grid.cells, grid.cell_normals, grid.samples,
                                      setup.frame.viewpoint);
  for (const auto& r : seeds) {
    // A seed mostly on a plane found already is a part of it (a noisy table's regions).
    std::size_t on_earlier = 0;
    for (const auto k : r.indices)
      on_earlier += taken[static_cast<std::size_t>(k)];
    if (2 * on_earlier >= r.indices.size() || candidates.size() >= 2 * setup.params.max_planes + 4)
      continue;
    std::vector<std::uint8_t> seed(grid.small->size(), 0);
    for (const auto k : r.indices)
      seed[static_cast<std::size_t>(k)] = 1;
    Candidate c;
    if (growCandidate(setup, region_cells, seed, grid.source, cell, taken, c))
      candidates.push_back(std::move(c));
  }
}

/** Of the seeds of the grid \a twice (twice as coarse as \a grid), those over the holes of
 * \a grid: most of the fine cells under them that have depth have no normal (where the fine
 * grid saw normals, its own seeds spoke already). */
std::vector<pcl::PointIndices>
seedsOverHoles(const Setup& setup, const PlaneGrid& grid, const PlaneGrid& twice)
{
  const auto& p = setup.params;
  std::vector<pcl::PointIndices> over_holes;
  const auto fw = static_cast<std::size_t>(grid.small->width);
  const auto fh = static_cast<std::size_t>(grid.small->height);
  const auto tw = static_cast<std::size_t>(twice.small->width);
  for (auto& r : planeSeeds(twice, p.min_plane_points, p.plane_angle, seedDistance(p))) {
    std::size_t with_depth = 0, without_normal = 0;
    for (const auto k : r.indices) {
      const std::size_t cu = static_cast<std::size_t>(k) % tw,
                        cv = static_cast<std::size_t>(k) / tw;
      for (std::size_t dv = 0; dv < 2; ++dv)
        for (std::size_t du = 0; du < 2; ++du) {
          const std::size_t u = 2 * cu + du, v = 2 * cv + dv;
          if (u >= fw || v >= fh)
            continue;
          const auto f = static_cast<Eigen::Index>(v * fw + u);
          if (grid.cells.col(f).allFinite()) {
            ++with_depth;
            without_normal += !grid.cell_normals.col(f).allFinite();
          }
        }
    }
    if (2 * without_normal >= with_depth && with_depth > 0)
      over_holes.push_back(std::move(r));
  }
  return over_holes;
}

/** The candidates of an image: seeds of its plane grid grown into planes. */
std::vector<Candidate>
findPlanesOrganized(const Setup& setup, FrameCues& cues, TabletopWorkspace& workspace)
{
  const PointFrame& frame = setup.frame;
  const auto& p = setup.params;
  const int first = setup.plane_step;
  // The grid of plane_step; on a frame too noisy for any seed there (a stereo camera far from
  // a table), coarser grids, whose means are less noisy, up to 16 pixels.
  PlaneGrid grid, twice;
  std::vector<pcl::PointIndices> seeds;
  const bool two_grids = 32 * 2 * first <= static_cast<int>(frame.width) &&
                         32 * 2 * first <= static_cast<int>(frame.height);
  for (int step = first; step <= 16; step *= 2) {
    if (step == first) {
      // The first pass also records which pixels have depth.
      planeGrid(setup, step, grid, two_grids ? &twice : nullptr, &workspace.has_depth,
                setup.threads);
      cues.has_depth = &workspace.has_depth;
    }
    else if (step == 2 * first && two_grids)
      grid = twice;
    else
      planeGrid(setup, step, grid, nullptr, nullptr, setup.threads);
    if (step == first) {
      cues.focal = setup.camera.valid()
                     ? setup.camera.fx
                     : estimateFocalLength(*grid.small) * static_cast<float>(step);
      cues.image_down = imageDownDirection(*grid.small, frame.viewpoint);
    }
    seeds = planeSeeds(grid, p.min_plane_points, p.plane_angle, seedDistance(p));
    PCL_DEBUG("[facyl::TabletopSegmentation] grid of %d pixels: %zu seeds, largest %zu cells\n",
              step, seeds.size(), seeds.empty() ? std::size_t{0} : seeds.front().indices.size());
    const std::size_t cell = static_cast<std::size_t>(step * step);
    if (std::any_of(seeds.begin(), seeds.end(),
                    [&](const auto& r) { return r.indices.size() * cell >= p.min_plane_points; }) ||
        static_cast<int>(frame.width) < 32 * step || static_cast<int>(frame.height) < 32 * step)
      break;
  }
  std::vector<Candidate> candidates;
  growCandidates(setup, grid, seeds, candidates);
  // A surface full of holes (a dark or glossy table: weak returns lost in clumps) has few
  // cells whose neighbourhood is whole enough for a normal on the fine grid, and no seed
  // there; a grid twice as coarse bridges the holes. Its seeds away from the planes found
  // grow as well.
  if (grid.step == first && two_grids)
    growCandidates(setup, twice, seedsOverHoles(setup, grid, twice), candidates);
  return candidates;
}

/** The candidates of a point set: plane seeds of a uniform random sample grown into planes. */
std::vector<Candidate>
findPlanesUnorganized(const Setup& setup)
{
  const PointFrame& frame = setup.frame;
  const auto& p = setup.params;
  // Plane search on a uniform random sample of the points, with normals: like the pixels of an
  // organized frame, the sample follows the sensor's density, so the table outweighs a larger
  // but farther floor (a voxel grid would weigh surfaces by their area).
  pcl::IndicesPtr finite(new pcl::Indices);
  forEachPoint(frame, [&](pcl::index_t i) {
    if (frame.finite(static_cast<std::size_t>(i)))
      finite->push_back(i);
  });
  // pcl::RandomSample draws indices without reading the points: an empty cloud stands for
  // the frame.
  pcl::RandomSample<pcl::PointXYZ> sample;
  sample.setInputCloud(
    pcl::PointCloud<pcl::PointXYZ>::ConstPtr(new pcl::PointCloud<pcl::PointXYZ>));
  sample.setIndices(finite);
  sample.setSample(static_cast<unsigned>(std::min<std::size_t>(p.plane_samples, finite->size())));
  sample.setSeed(1);
  pcl::Indices sampled;
  sample.filter(sampled);
  std::vector<Candidate> candidates;
  if (sampled.size() < 10)
    return candidates;
  pcl::PointCloud<pcl::PointXYZ>::Ptr points(new pcl::PointCloud<pcl::PointXYZ>);
  points->resize(sampled.size());
  points->sensor_origin_ << frame.viewpoint, 0.f; // normals face it, as on the frame
  for (std::size_t k = 0; k < sampled.size(); ++k)
    (*points)[k].getVector3fMap() = frame.point(static_cast<std::size_t>(sampled[k]));
  const SampledPlaneCues cues = sampledPlaneCues(points, frame.viewpoint, p.plane_distance);
  const double scale = static_cast<double>(finite->size()) / static_cast<double>(sampled.size());
  const std::size_t cell_points = static_cast<std::size_t>(std::max(1.0, std::round(scale)));
  std::vector<std::uint8_t> taken(sampled.size(), 0);
  const PlaneRegionCells region_cells(cues.points, cues.normals, cues.points, frame.viewpoint);
  ransacPlaneSeeds(
    cues, p.max_planes, scale, p.min_plane_points,
    [&](const std::vector<std::uint8_t>& seed) {
      Candidate cand;
      if (growCandidate(setup, region_cells, seed, sampled, cell_points, taken, cand))
        candidates.push_back(std::move(cand));
    },
    taken);
  return candidates;
}

/** The mean of the points of \a c's region (\a at_least_one: divided by at least 1). */
Eigen::Vector3f
regionCentre(const PointFrame& frame, const Candidate& c, bool at_least_one)
{
  Eigen::Vector3f centre = Eigen::Vector3f::Zero();
  for (const auto i : c.points)
    centre += frame.point(static_cast<std::size_t>(i));
  return centre / static_cast<float>(at_least_one ? std::max<std::size_t>(1, c.points.size())
                                                  : c.points.size());
}

/** Supports span a plane that does not pass by the sensor, are not a part of a larger
 * candidate, and (with an up direction) are horizontal; at most max_planes, those facing the
 * top of the image (\a image_down; zero: unknown) first. */
void
keepSupportCandidates(const Setup& setup, const Eigen::Vector3f& image_down,
                      std::vector<Candidate>& candidates)
{
  const auto& p = setup.params;
  const Eigen::Vector3f viewpoint = setup.frame.viewpoint;
  // A support does not pass by the sensor (it would be seen edge-on).
  candidates.erase(std::remove_if(candidates.begin(), candidates.end(),
                                  [&](const Candidate& c) {
                                    return c.plane.head<3>().dot(viewpoint) + c.plane[3] < 0.05f;
                                  }),
                   candidates.end());
  std::stable_sort(candidates.begin(), candidates.end(),
                   [](const Candidate& a, const Candidate& b) { return a.support > b.support; });
  // A region lying on a larger candidate, nearly parallel and level with it at its centre (a
  // part of the same table seen through a sensor's bend, with a slope of its own), is a part
  // of it, not another support; a box top or a shelf is above the larger one's band.
  std::vector<Candidate> distinct;
  for (auto& c : candidates) {
    const Eigen::Vector3f centre = regionCentre(setup.frame, c, true);
    const bool part = std::any_of(distinct.begin(), distinct.end(), [&](const Candidate& big) {
      return big.plane.head<3>().dot(c.plane.head<3>()) >= std::cos(0.2f) &&
             std::abs(big.plane.head<3>().dot(centre) + big.plane[3]) <
               big.band.halfWidth((centre - viewpoint).norm());
    });
    if (!part)
      distinct.push_back(std::move(c));
  }
  candidates.swap(distinct);
  // A region too small to be a support (see tryFamily) is a face of an object: its points are
  // object points, and it is not searched further.
  const bool largest = p.support == TabletopSegmentationParameters::Support::LargestPlane;
  if (!largest)
    candidates.erase(std::remove_if(candidates.begin(), candidates.end(),
                                    [&](const Candidate& c) {
                                      const Eigen::Vector3f centre =
                                        regionCentre(setup.frame, c, false);
                                      return regionArea(setup, c, planeFrame(c.plane, centre)) <
                                             std::min(0.25f * p.min_support_area, p.min_shelf_area);
                                    }),
                     candidates.end());
  if (!setup.up.isZero()) {
    const Eigen::Vector3f up = setup.up.normalized();
    const float cos_max = std::cos(p.max_support_tilt);
    candidates.erase(
      std::remove_if(candidates.begin(), candidates.end(),
                     [&](const Candidate& c) { return c.plane.head<3>().dot(up) < cos_max; }),
      candidates.end());
  }
  if (largest) {
    if (candidates.size() > 1)
      candidates.resize(1);
    return;
  }
  if (candidates.size() > p.max_planes) {
    // The candidates an upright camera would see facing up (the first families tried, see
    // rankSupportFamilies) are kept before the others: a dark table's few pixels must not
    // give way to the walls and cabinet fronts that a room shows more of.
    if (setup.up.isZero() && !image_down.isZero())
      std::stable_partition(candidates.begin(), candidates.end(),
                            [&](const Candidate& c) { return facesImageTop(c.plane, image_down); });
    keepPriorCandidate(setup, candidates, p.max_planes);
    candidates.resize(p.max_planes);
  }
}

} // namespace

std::vector<Candidate>
findCandidates(const Setup& setup, FrameCues& cues, TabletopWorkspace& workspace)
{
  std::vector<Candidate> candidates =
    setup.as_image ? findPlanesOrganized(setup, cues, workspace) : findPlanesUnorganized(setup);
  keepSupportCandidates(setup, cues.image_down, candidates);
  if (!candidates.empty())
    cues.noise = candidates.front().band;
  return candidates;
}

pcl::Indices
hullCandidates(const Setup& setup, const pcl::Indices& region)
{
  return setup.as_image ? rowExtremes(region, setup.frame.width, setup.frame.height) : region;
}

float
regionArea(const Setup& setup, const Candidate& c, const Eigen::Affine3f& frame)
{
  const Eigen::Affine3f to_plane = frame.inverse();
  std::vector<Eigen::Vector2f> flat;
  for (const auto i : hullCandidates(setup, c.points))
    flat.push_back((to_plane * setup.frame.point(static_cast<std::size_t>(i))).head<2>());
  return polygonArea(convexHull2D(std::move(flat)));
}

} // namespace tabletop
} // namespace facyl
