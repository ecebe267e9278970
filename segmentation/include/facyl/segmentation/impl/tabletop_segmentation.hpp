/*
 * facyl: fast cylinder detection for PCL.
 */
#pragma once

#include <facyl/features/polygon.h>
#include <facyl/segmentation/plane_search.h>
#include <facyl/segmentation/support_planes.h>
#include <facyl/segmentation/tabletop_segmentation.h>

#include <pcl/common/transforms.h>

#include <pcl/common/io.h>
#include <pcl/common/point_tests.h>
#include <pcl/filters/random_sample.h>
#include <pcl/point_struct_traits.h>

#include <algorithm>
#include <array>
#include <cassert>
#include <chrono>
#include <cstdint>
#include <limits>
#include <numeric>
#include <optional>
#include <unordered_map>

namespace facyl {

/** How many times more standing objects another family of supports needs than the one an
 * upright camera would choose (see segmentInSensorFrame). */
constexpr float kFamilyMargin = 1.5f;

template <typename PointT>
void
TabletopSegmentation<PointT>::reset()
{
  supports_.clear();
  extents_.clear();
  table_ = 0;
  table_found_ = false;
  has_noise_ = false;
  focal_ = 0.f;
  image_down_.setZero();
  table_coefficients_.values.clear();
  hull_->clear();
  has_depth_known_ = false;
}

template <typename PointT>
bool
TabletopSegmentation<PointT>::run(std::vector<TabletopCluster>& clusters, bool check_pose)
{
  clusters.clear();
  reset();
  timing_ = SegmentationTiming{};
  const auto t0 = std::chrono::steady_clock::now();
  const std::string why = validate(params_);
  if (!why.empty()) {
    PCL_ERROR("[facyl::TabletopSegmentation::segment] Invalid parameters: %s.\n", why.c_str());
    return false;
  }
  if (!input_ || input_->empty()) {
    PCL_ERROR("[facyl::TabletopSegmentation::segment] No input cloud, or an empty one.\n");
    return false;
  }
  if (!up_.allFinite()) {
    PCL_ERROR("[facyl::TabletopSegmentation::segment] The up direction is not finite.\n");
    return false;
  }
  if (camera_.valid() && !cameraUsable(camera_)) {
    PCL_ERROR("[facyl::TabletopSegmentation::segment] The camera given with setCamera (%g, %g, "
              "%g, %g, %d x %d pixels) is not usable: finite intrinsics and at most 8192 x 8192 "
              "pixels.\n",
              camera_.fx, camera_.fy, camera_.cx, camera_.cy, camera_.width, camera_.height);
    return false;
  }
  if (!this->initCompute()) {
    PCL_ERROR("[facyl::TabletopSegmentation::segment] Invalid input or indices.\n");
    return false;
  }
  std::size_t finite = 0;
  for (auto it = indices_->begin(); it != indices_->end() && finite < 3; ++it)
    finite += pcl::isFinite((*input_)[*it]);
  if (finite < 3) {
    PCL_ERROR("[facyl::TabletopSegmentation::segment] The cloud has fewer than 3 finite points.\n");
    this->deinitCompute();
    return false;
  }
  if (!spansPlane(*input_, *indices_)) {
    PCL_ERROR("[facyl::TabletopSegmentation::segment] The finite points lie on one line (or at "
              "one point): they hold no plane.\n");
    this->deinitCompute();
    return false;
  }
  const Eigen::Affine3f pose =
    check_pose ? plausibleSensorPose(*input_) : Eigen::Affine3f(Eigen::Affine3f::Identity());
  const std::size_t far = check_pose ? countFarPoints(*input_) : 0;
  if (far > 0)
    PCL_WARN("[facyl::TabletopSegmentation::segment] %zu points have a coordinate beyond +-%g "
             "and are ignored (treated as missing).\n",
             far, static_cast<double>(kMaxCoordinate));
  bool found = false;
  if (isIdentityPose(pose) && far == 0)
    found = segmentInSensorFrame(clusters);
  else {
    // The search works in the sensor's frame (depth along the line of sight, pixels seen
    // from the origin): the cloud is moved there, the results back to the cloud's frame.
    const PointCloudConstPtr given = input_;
    const Eigen::Vector3f given_up = up_;
    input_ = sensorFrameCopy(*given, pose);
    up_ = pose.linear().transpose() * up_;
    found = segmentInSensorFrame(clusters);
    input_ = given;
    up_ = given_up;
    if (found)
      transformResults(pose, clusters);
  }
  this->deinitCompute();
  timing_.total =
    std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return found;
}

template <typename PointT>
void
TabletopSegmentation<PointT>::transformResults(const Eigen::Affine3f& pose,
                                               std::vector<TabletopCluster>& clusters)
{
  for (auto& c : clusters)
    c.centroid = pose * c.centroid;
  for (auto& s : supports_) {
    s.plane = transformPlane(s.plane, pose);
    s.frame = pose * s.frame;
  }
  auto& t = table_coefficients_.values;
  if (t.size() == 4) {
    const Eigen::Vector4f moved = transformPlane(Eigen::Vector4f(t[0], t[1], t[2], t[3]), pose);
    t = {moved[0], moved[1], moved[2], moved[3]};
  }
  pcl::transformPointCloud(*hull_, *hull_, pose);
  image_down_ = pose.linear() * image_down_;
}

template <typename PointT>
bool
TabletopSegmentation<PointT>::segmentInSensorFrame(std::vector<TabletopCluster>& clusters)
{
  const int step = latticeStep();
  return step > 1 ? segmentOnLattice(clusters, step) : segmentFrame(clusters);
}

template <typename PointT>
int
TabletopSegmentation<PointT>::latticeStep() const
{
  const int lattice = params_.lattice_width;
  if (lattice <= 0 || !fake_indices_ || !searchedAsImage() ||
      2 * input_->width <= static_cast<std::uint32_t>(3 * lattice))
    return 1;
  return static_cast<int>(std::lround(static_cast<double>(input_->width) / lattice));
}

namespace detail {
/** A support's band, tabulated by range (tabulateHalfWidths) as classifyPoints reads it, and
 * not looked up for points within its narrowest half-width. */
struct TabulatedBand {
  explicit TabulatedBand(const SupportPlane& support)
      : plane(support.plane)
      , floor(halfWidthFloor(support.band))
      , widths(tabulateHalfWidths(support.band))
  {
  }
  /** Signed distance of \a p above the plane; \a half_width: the band's there (range from
   * \a viewpoint). */
  float above(const Eigen::Vector3f& p, const Eigen::Vector3f& viewpoint, float& half_width) const
  {
    const float distance = plane.head<3>().dot(p) + plane[3];
    half_width =
      std::abs(distance) <= floor ? floor : tabulatedHalfWidth(widths, (p - viewpoint).norm());
    return distance;
  }
  Eigen::Vector4f plane;
  float floor;
  std::vector<float> widths;
};
} // namespace detail

template <typename PointT>
TabletopSegmentationParameters
TabletopSegmentation<PointT>::latticeParameters(int step) const
{
  // A lattice point stands for step^2 pixels: counts of points scale down; lengths stay.
  TabletopSegmentationParameters p = params_;
  const auto area = static_cast<std::size_t>(step * step);
  p.min_plane_points = std::max<std::size_t>(1, p.min_plane_points / area);
  p.min_cluster_size = std::max<std::size_t>(1, p.min_cluster_size / area);
  p.max_cluster_size = std::max(p.min_cluster_size, p.max_cluster_size / area);
  p.objects.min_fragment = std::max<std::size_t>(1, p.objects.min_fragment / area);
  if (p.plane_step > 0)
    p.plane_step = std::max(1, p.plane_step / step);
  return p;
}

template <typename PointT>
bool
TabletopSegmentation<PointT>::segmentOnLattice(std::vector<TabletopCluster>& clusters, int step)
{
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  const auto ms = [](Clock::time_point a) {
    return std::chrono::duration<double, std::milli>(Clock::now() - a).count();
  };
  const PointCloudConstPtr full = input_;
  const auto full_indices = indices_;
  const PinholeCamera full_camera = camera_;
  const TabletopSegmentationParameters full_params = params_;
  typename PointCloud::Ptr lattice(new PointCloud);
  latticeOf(*full, step, *lattice);
  params_ = latticeParameters(step);
  if (camera_.valid()) {
    const float s = static_cast<float>(step);
    camera_.fx /= s, camera_.fy /= s, camera_.cx /= s, camera_.cy /= s;
    camera_.width = static_cast<int>(lattice->width);
    camera_.height = static_cast<int>(lattice->height);
  }
  input_ = lattice;
  indices_.reset(new pcl::Indices(lattice->size()));
  std::iota(indices_->begin(), indices_->end(), 0);
  const double t_lattice = ms(t0);
  std::vector<TabletopCluster> coarse;
  bool found = false;
  {
    // The input, indices, camera and settings are the caller's again however segmentFrame
    // ends (an exception included).
    struct Restore {
      TabletopSegmentation& seg;
      const PointCloudConstPtr& input;
      const pcl::IndicesPtr& indices;
      const PinholeCamera& camera;
      const TabletopSegmentationParameters& params;
      ~Restore()
      {
        seg.input_ = input;
        seg.indices_ = indices;
        seg.camera_ = camera;
        seg.params_ = params;
      }
    } restore{*this, full, full_indices, full_camera, full_params};
    found = segmentFrame(coarse);
  }
  const auto t1 = Clock::now();
  clustersAtFullResolution(coarse, *lattice, step, clusters);
  supportsAtFullResolution(step);
  focal_ *= static_cast<float>(step); // the full frame's, as getFocalLength says
  timing_.planes += t_lattice;
  timing_.objects += ms(t1);
  return found;
}

template <typename PointT>
void
TabletopSegmentation<PointT>::clustersAtFullResolution(const std::vector<TabletopCluster>& coarse,
                                                       const PointCloud& lattice, int step,
                                                       std::vector<TabletopCluster>& clusters) const
{
  const PointCloud& full = *input_;
  const auto& op = params_.objects;
  const Eigen::Vector3f viewpoint = full.sensor_origin_.head(3);
  const int w = static_cast<int>(full.width), h = static_cast<int>(full.height);
  const int lw = static_cast<int>(lattice.width), lh = static_cast<int>(lattice.height);
  const std::vector<float> half = has_noise_ ? tabulateHalfWidths(noise_) : std::vector<float>();
  std::vector<detail::TabulatedBand> bands;
  for (const auto& support : supports_)
    bands.emplace_back(support);
  std::vector<int> label(lattice.size(), -1); // each lattice pixel's object
  for (std::size_t k = 0; k < coarse.size(); ++k)
    for (const auto i : coarse[k].indices.indices)
      label[static_cast<std::size_t>(i)] = static_cast<int>(k);
  // The object of the lattice pixel nearest to \a p among the corners of its lattice cell.
  const auto nearest = [&](int u, int v, const Eigen::Vector3f& p) {
    const int lu = u / step, lv = v / step;
    float best = std::numeric_limits<float>::infinity();
    int owner = -1;
    for (int dv = 0; dv <= (v % step ? 1 : 0); ++dv)
      for (int du = 0; du <= (u % step ? 1 : 0); ++du) {
        if (lu + du >= lw || lv + dv >= lh)
          continue;
        const auto l = static_cast<std::size_t>((lv + dv) * lw + lu + du);
        if (!pcl::isFinite(lattice[l]))
          continue;
        const float d2 = (lattice[l].getVector3fMap() - p).squaredNorm();
        if (d2 < best)
          best = d2, owner = label[l];
      }
    return owner;
  };
  clusters.clear();
  for (std::size_t k = 0; k < coarse.size(); ++k) {
    const auto& c = coarse[k];
    // A block's pixel joins its lattice pixel's object when it continues its surface (within
    // the lattice's connection gap, as segmentObjectsOrganized has it for neighbours one lattice
    // step apart), the nearest lattice pixel of its lattice cell's corners is this object's (a
    // pixel between an object's foot and what it stands on goes to the nearer), and it is an
    // object point (above its support's band, as classifyPoints has it).
    const detail::TabulatedBand* band =
      c.support >= 0 ? &bands[static_cast<std::size_t>(c.support)] : nullptr;
    // The gap of the block's lattice pixel, computed once for the pixels of its block's row.
    pcl::index_t gap_of = -1;
    float gap2 = 0.f;
    const auto continues = [&](pcl::index_t pixel, pcl::index_t parent) {
      const auto& p = full[pixel];
      if (!pcl::isFinite(p))
        return false;
      if (pixel == parent)
        return true;
      const Eigen::Vector3f q = full[parent].getVector3fMap();
      if (parent != gap_of) {
        const float gap = connectionGap(op, (q - viewpoint).norm(), focal_, half);
        gap2 = gap * gap;
        gap_of = parent;
      }
      if (!((p.getVector3fMap() - q).squaredNorm() < gap2) ||
          nearest(pixel % w, pixel / w, p.getVector3fMap()) != static_cast<int>(k))
        return false;
      float half_width = 0.f;
      return !band || band->above(p.getVector3fMap(), viewpoint, half_width) > half_width;
    };
    pcl::Indices pixels = blockPixels(c.indices.indices, w, h, step, continues);
    if (pixels.size() >= params_.min_cluster_size && pixels.size() <= params_.max_cluster_size)
      clusters.push_back(makeCluster(std::move(pixels), c.support));
  }
  std::stable_sort(clusters.begin(), clusters.end(), [](const auto& a, const auto& b) {
    return a.indices.indices.size() > b.indices.indices.size();
  });
}

template <typename PointT>
void
TabletopSegmentation<PointT>::supportsAtFullResolution(int step)
{
  const PointCloud& full = *input_;
  const Eigen::Vector3f viewpoint = full.sensor_origin_.head(3);
  const int w = static_cast<int>(full.width), h = static_cast<int>(full.height);
  for (auto& support : supports_) {
    const detail::TabulatedBand band(support);
    const auto within = [&](pcl::index_t pixel, pcl::index_t) {
      const auto& p = full[pixel];
      if (!pcl::isFinite(p))
        return false;
      float half_width = 0.f;
      return std::abs(band.above(p.getVector3fMap(), viewpoint, half_width)) <= half_width;
    };
    support.inliers.indices = blockPixels(support.inliers.indices, w, h, step, within);
    support.standing_points *= static_cast<std::size_t>(step * step);
  }
}

template <typename PointT>
bool
TabletopSegmentation<PointT>::segmentFrame(std::vector<TabletopCluster>& clusters)
{
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  const auto ms = [](Clock::time_point a) {
    return std::chrono::duration<double, std::milli>(Clock::now() - a).count();
  };
  std::vector<Candidate> candidates;
  if (searchedAsImage())
    findPlanesOrganized(candidates);
  else
    findPlanesUnorganized(candidates);
  keepSupportCandidates(candidates);
  // The sensor's noise by range, as measured on the largest plane: the depth gaps of the object
  // segmentation are never below it.
  noise_ = candidates.empty() ? DepthBand{} : candidates.front().band;
  has_noise_ = !candidates.empty();
  const double t_planes = ms(t0);
  std::vector<SupportPlane> all;
  std::vector<Above>& above = above_;
  classifyPoints(candidates, all, above);
  hulls_.assign(candidates.size(), Hulls{});
  const double t_points = ms(t0);
  // The family of supports is the one most objects stand on: no camera roll is assumed.
  // Several families: each is judged on a coarse grid of its object points (a clustering at
  // full resolution costs several milliseconds), and only the one most objects stand on is
  // segmented at full resolution. Objects are counted, not points (a flat patch of a floor
  // next to a wall may stand on the wall as one large "object"). The first in rankFamilies'
  // order (an upright camera's choice) is kept unless another holds clearly more
  // (kFamilyMargin times): with few objects in view, a box's faces can hold as many as the
  // table.
  const auto families = rankFamilies(candidates, all);
  std::size_t chosen = 0, tried = 0;
  if (families.size() > 1) {
    std::size_t most = 0;
    for (std::size_t f = 0; f < families.size(); ++f) {
      const Trial coarse = tryFamily(families[f], candidates, all, above, coarseStride(), false);
      tried += !coarse.supports.empty();
      PCL_DEBUG("[facyl::TabletopSegmentation] family %zu (%zu planes, first (%.3f %.3f %.3f)): "
                "%zu supports, %zu objects standing (%zu points, coarse)\n",
                f, families[f].size(), candidates[families[f].front()].plane[0],
                candidates[families[f].front()].plane[1], candidates[families[f].front()].plane[2],
                coarse.supports.size(), coarse.standing_objects, coarse.standing);
      if (!coarse.supports.empty() && (tried == 1 || static_cast<float>(coarse.standing_objects) >
                                                       kFamilyMargin * static_cast<float>(most)))
        chosen = f, most = coarse.standing_objects;
    }
  }
  std::optional<Trial> best;
  if (!families.empty()) {
    Trial trial = tryFamily(families[chosen], candidates, all, above, 1, true);
    if (!trial.supports.empty())
      best = std::move(trial);
  }
  timing_.planes = t_planes;
  timing_.points = t_points - t_planes;
  PCL_DEBUG("[facyl::TabletopSegmentation] %.2f ms: planes %.2f, points %.2f, family %zu of "
            "%zu (%zu with supports)\n",
            ms(t0), t_planes, t_points - t_planes, chosen, families.size(), tried);
  if (best) {
    adopt(std::move(*best), clusters);
    if (!table_found_) {
      // Nothing stands on the supports in view (a table without depth: glossy, dark): the
      // compact segments off them and off the clusters found are objects too, without a
      // support.
      std::vector<std::uint8_t> taken(input_->size(), 0);
      for (const auto& support : supports_)
        for (const auto i : support.inliers.indices)
          taken[static_cast<std::size_t>(i)] = 1;
      for (const auto& c : clusters)
        for (const auto i : c.indices.indices)
          taken[static_cast<std::size_t>(i)] = 1;
      segmentWithoutSupport(clusters, &taken);
    }
  }
  else {
    PCL_DEBUG("[facyl::TabletopSegmentation] no support in view: %zu candidate planes, none "
              "of at least %g m^2\n",
              candidates.size(), static_cast<double>(params_.min_support_area));
    segmentWithoutSupport(clusters);
  }
  // Largest first, like pcl::EuclideanClusterExtraction.
  std::stable_sort(clusters.begin(), clusters.end(), [](const auto& a, const auto& b) {
    return a.indices.indices.size() > b.indices.indices.size();
  });
  timing_.objects = ms(t0) - t_points;
  return true;
}

template <typename PointT>
int
TabletopSegmentation<PointT>::planeStep() const
{
  if (params_.plane_step > 0)
    return params_.plane_step;
  return std::clamp(static_cast<int>(std::lround(input_->width / 160.0)), 1, 16);
}

template <typename PointT>
bool
TabletopSegmentation<PointT>::searchedAsImage() const
{
  // The image path needs a plane grid of at least 16 x 16 cells (its normals use a window of
  // several cells); narrower organized clouds (a LiDAR's few rings, a strip) are point sets.
  const auto cells = static_cast<std::uint32_t>(16 * planeStep());
  return input_->isOrganized() && input_->width >= cells && input_->height >= cells;
}

template <typename PointT>
PlaneRegionSettings
TabletopSegmentation<PointT>::regionSettings() const
{
  PlaneRegionSettings s;
  s.band_factor = params_.band_factor;
  s.fixed_band = params_.plane_distance;
  s.min_angle = params_.plane_angle;
  return s;
}

template <typename PointT>
void
TabletopSegmentation<PointT>::planeGrid(int step, PlaneGrid& grid, PlaneGrid* twice) const
{
  const int w = static_cast<int>(input_->width), h = static_cast<int>(input_->height);
  std::vector<std::uint8_t> allowed; // only when indices were given
  if (!fake_indices_) {
    allowed.assign(input_->size(), 0);
    for (const auto i : *indices_)
      allowed[i] = 1;
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
  const PointT* points = input_->points.data();
  // The first pass of a run also records which pixels have depth (the object segmentation's
  // occlusion test); the coarser grids of a noisy frame do not record them again.
  const bool record = !has_depth_known_;
  if (record)
    has_depth_.resize(input_->size());
  for (int v = 0; v < h; ++v) {
    const std::size_t base = static_cast<std::size_t>(v) * static_cast<std::size_t>(w);
    const std::size_t fine_row = fine.rowBase(v), coarse_row = coarse ? coarse->rowBase(v) : 0;
    for (int u = 0; u < w; ++u) {
      const std::size_t idx = base + static_cast<std::size_t>(u);
      const PointT& p = points[idx];
      const bool finite = std::isfinite(p.z) && pcl::isFinite(p);
      if (record)
        has_depth_[idx] = finite;
      if (!finite || !(fake_indices_ || allowed[idx]))
        continue;
      const auto uu = static_cast<std::size_t>(u);
      fine.addTo(fine_row + fine.column_block[uu], static_cast<pcl::index_t>(idx),
                 p.getVector3fMap());
      if (coarse)
        coarse->addTo(coarse_row + coarse->column_block[uu], static_cast<pcl::index_t>(idx),
                      p.getVector3fMap());
    }
  }
  has_depth_known_ = true;
  finishPlaneGrid(fine, w, grid);
  if (twice)
    finishPlaneGrid(*coarse, w, *twice);
}

template <typename PointT>
bool
TabletopSegmentation<PointT>::growCandidate(const PlaneRegionCells& cells,
                                            const std::vector<std::uint8_t>& seed,
                                            const std::vector<pcl::index_t>& source,
                                            std::size_t cell_points,
                                            std::vector<std::uint8_t>& taken, Candidate& out) const
{
  PlaneRegion region;
  if (!refinePlaneRegion(cells, seed, regionSettings(), region, &taken))
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
  if (out.support < params_.min_plane_points)
    return false;
  for (std::size_t k = 0; k < region.member.size(); ++k)
    taken[k] = taken[k] || region.member[k];
  return true;
}

template <typename PointT>
void
TabletopSegmentation<PointT>::findPlanesOrganized(std::vector<Candidate>& candidates)
{
  // The grid of planeStep(); on a frame too noisy for any seed there (a stereo camera far
  // from a table), coarser grids, whose means are less noisy, up to 16 pixels.
  PlaneGrid grid, twice;
  std::vector<pcl::PointIndices> seeds;
  const bool two_grids = 32 * 2 * planeStep() <= static_cast<int>(input_->width) &&
                         32 * 2 * planeStep() <= static_cast<int>(input_->height);
  for (int step = planeStep(); step <= 16; step *= 2) {
    if (step == planeStep())
      planeGrid(step, grid, two_grids ? &twice : nullptr);
    else if (step == 2 * planeStep() && two_grids)
      grid = twice;
    else
      planeGrid(step, grid);
    if (step == planeStep()) {
      focal_ =
        camera_.valid() ? camera_.fx : estimateFocalLength(*grid.small) * static_cast<float>(step);
      image_down_ = imageDownDirection(*grid.small, input_->sensor_origin_.head(3));
    }
    seeds = planeSeeds(grid, params_.min_plane_points, params_.plane_angle, seedDistance());
    PCL_DEBUG("[facyl::TabletopSegmentation] grid of %d pixels: %zu seeds, largest %zu cells\n",
              step, seeds.size(), seeds.empty() ? std::size_t{0} : seeds.front().indices.size());
    const std::size_t cell = static_cast<std::size_t>(step * step);
    if (std::any_of(
          seeds.begin(), seeds.end(),
          [&](const auto& r) { return r.indices.size() * cell >= params_.min_plane_points; }) ||
        static_cast<int>(input_->width) < 32 * step || static_cast<int>(input_->height) < 32 * step)
      break;
  }
  growCandidates(grid, seeds, candidates);
  // A surface full of holes (a dark or glossy table: weak returns lost in clumps) has few
  // cells whose neighbourhood is whole enough for a normal on the fine grid, and no seed
  // there; a grid twice as coarse bridges the holes. Its seeds away from the planes found
  // grow as well.
  if (grid.step == planeStep() && two_grids) {
    // Only seeds over the holes of the fine grid: most of the fine cells under them that have
    // depth have no normal (where the fine grid saw normals, its own seeds spoke already).
    std::vector<pcl::PointIndices> over_holes;
    const auto fw = static_cast<std::size_t>(grid.small->width);
    const auto fh = static_cast<std::size_t>(grid.small->height);
    const auto tw = static_cast<std::size_t>(twice.small->width);
    for (auto& r :
         planeSeeds(twice, params_.min_plane_points, params_.plane_angle, seedDistance())) {
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
    growCandidates(twice, over_holes, candidates);
  }
}

template <typename PointT>
void
TabletopSegmentation<PointT>::growCandidates(const PlaneGrid& grid,
                                             const std::vector<pcl::PointIndices>& seeds,
                                             std::vector<Candidate>& candidates) const
{
  const std::size_t cell = static_cast<std::size_t>(grid.step * grid.step);
  // The cells of the candidates found already (on this grid or another) are taken.
  std::vector<std::uint8_t> taken(grid.small->size(), 0);
  const auto w = static_cast<pcl::index_t>(input_->width);
  const auto cw = static_cast<pcl::index_t>(grid.small->width);
  for (const auto& c : candidates)
    for (const auto i : c.points) {
      const auto k = static_cast<std::size_t>((i / w) / grid.step * cw + (i % w) / grid.step);
      if (k < taken.size())
        taken[k] = 1;
    }
  const PlaneRegionCells region_cells(grid.cells, grid.cell_normals, grid.samples,
                                      input_->sensor_origin_.head(3));
  for (const auto& r : seeds) {
    // A seed mostly on a plane found already is a part of it (a noisy table's regions).
    std::size_t on_earlier = 0;
    for (const auto k : r.indices)
      on_earlier += taken[static_cast<std::size_t>(k)];
    if (2 * on_earlier >= r.indices.size() || candidates.size() >= 2 * params_.max_planes + 4)
      continue;
    std::vector<std::uint8_t> seed(grid.small->size(), 0);
    for (const auto k : r.indices)
      seed[static_cast<std::size_t>(k)] = 1;
    Candidate c;
    if (growCandidate(region_cells, seed, grid.source, cell, taken, c))
      candidates.push_back(std::move(c));
  }
}

template <typename PointT>
void
TabletopSegmentation<PointT>::findPlanesUnorganized(std::vector<Candidate>& candidates)
{
  // Plane search on a uniform random sample of the points, with normals: like the pixels of an
  // organized frame, the sample follows the sensor's density, so the table outweighs a larger
  // but farther floor (a voxel grid would weigh surfaces by their area).
  pcl::IndicesPtr finite(new pcl::Indices);
  for (const auto i : *indices_)
    if (pcl::isFinite((*input_)[i]))
      finite->push_back(i);
  pcl::RandomSample<PointT> sample;
  sample.setInputCloud(input_);
  sample.setIndices(finite);
  sample.setSample(
    static_cast<unsigned>(std::min<std::size_t>(params_.plane_samples, finite->size())));
  sample.setSeed(1);
  pcl::Indices sampled;
  sample.filter(sampled);
  if (sampled.size() < 10)
    return;
  pcl::PointCloud<pcl::PointXYZ>::Ptr points(new pcl::PointCloud<pcl::PointXYZ>);
  points->resize(sampled.size());
  points->sensor_origin_ = input_->sensor_origin_; // normals face it, as on the input
  points->sensor_orientation_ = input_->sensor_orientation_;
  for (std::size_t k = 0; k < sampled.size(); ++k)
    (*points)[k].getVector3fMap() = (*input_)[sampled[k]].getVector3fMap();
  const SampledPlaneCues cues =
    sampledPlaneCues(points, input_->sensor_origin_.head(3), params_.plane_distance);
  const double scale = static_cast<double>(finite->size()) / static_cast<double>(sampled.size());
  const std::size_t cell_points = static_cast<std::size_t>(std::max(1.0, std::round(scale)));
  std::vector<std::uint8_t> taken(sampled.size(), 0);
  const PlaneRegionCells region_cells(cues.points, cues.normals, cues.points,
                                      input_->sensor_origin_.head(3));
  ransacPlaneSeeds(
    cues, params_.max_planes, scale, params_.min_plane_points,
    [&](const std::vector<std::uint8_t>& seed) {
      Candidate cand;
      if (growCandidate(region_cells, seed, sampled, cell_points, taken, cand))
        candidates.push_back(std::move(cand));
    },
    taken);
}

template <typename PointT>
void
TabletopSegmentation<PointT>::keepSupportCandidates(std::vector<Candidate>& candidates) const
{
  const Eigen::Vector3f viewpoint = input_->sensor_origin_.head(3);
  // A support does not pass by the sensor (it would be seen edge-on).
  candidates.erase(std::remove_if(candidates.begin(), candidates.end(),
                                  [&](const Candidate& c) {
                                    return c.plane.template head<3>().dot(viewpoint) + c.plane[3] <
                                           0.05f;
                                  }),
                   candidates.end());
  std::stable_sort(candidates.begin(), candidates.end(),
                   [](const Candidate& a, const Candidate& b) { return a.support > b.support; });
  // A region lying on a larger candidate, nearly parallel and level with it at its centre (a
  // part of the same table seen through a sensor's bend, with a slope of its own), is a part
  // of it, not another support; a box top or a shelf is above the larger one's band.
  std::vector<Candidate> distinct;
  for (auto& c : candidates) {
    Eigen::Vector3f centre = Eigen::Vector3f::Zero();
    for (const auto i : c.points)
      centre += (*input_)[i].getVector3fMap();
    centre /= static_cast<float>(std::max<std::size_t>(1, c.points.size()));
    const bool part = std::any_of(distinct.begin(), distinct.end(), [&](const Candidate& big) {
      return big.plane.template head<3>().dot(c.plane.template head<3>()) >= std::cos(0.2f) &&
             std::abs(big.plane.template head<3>().dot(centre) + big.plane[3]) <
               big.band.halfWidth((centre - viewpoint).norm());
    });
    if (!part)
      distinct.push_back(std::move(c));
  }
  candidates.swap(distinct);
  // A region too small to be a support (see tryFamily) is a face of an object: its points are
  // object points, and it is not searched further.
  if (params_.support != TabletopSegmentationParameters::Support::LargestPlane)
    candidates.erase(std::remove_if(candidates.begin(), candidates.end(),
                                    [&](const Candidate& c) {
                                      Eigen::Vector3f centre = Eigen::Vector3f::Zero();
                                      for (const auto i : c.points)
                                        centre += (*input_)[i].getVector3fMap();
                                      centre /= static_cast<float>(c.points.size());
                                      return regionArea(c, planeFrame(c.plane, centre)) <
                                             std::min(0.25f * params_.min_support_area,
                                                      params_.min_shelf_area);
                                    }),
                     candidates.end());
  if (!up_.isZero()) {
    const Eigen::Vector3f up = up_.normalized();
    const float cos_max = std::cos(params_.max_support_tilt);
    candidates.erase(std::remove_if(candidates.begin(), candidates.end(),
                                    [&](const Candidate& c) {
                                      return c.plane.template head<3>().dot(up) < cos_max;
                                    }),
                     candidates.end());
  }
  if (params_.support == TabletopSegmentationParameters::Support::LargestPlane) {
    if (candidates.size() > 1)
      candidates.resize(1);
    return;
  }
  if (candidates.size() > params_.max_planes)
    candidates.resize(params_.max_planes);
}

template <typename PointT>
void
TabletopSegmentation<PointT>::classifyPoints(const std::vector<Candidate>& candidates,
                                             std::vector<SupportPlane>& all,
                                             std::vector<Above>& above) const
{
  // One pass: each candidate's points, and the points above some candidate (in its object
  // band) with the candidates they lie on and above. Bands by range, tabulated every 5 mm.
  const std::size_t n = candidates.size(); // <= 8 (max_planes)
  all.assign(n, SupportPlane{});
  above.clear();
  if (n == 0)
    return;
  std::vector<Eigen::Vector4f> planes;
  std::vector<DepthBand> bands;
  for (const auto& c : candidates) {
    planes.push_back(c.plane);
    bands.push_back(c.band);
  }
  const PlaneSorter sorter(std::move(planes), std::move(bands), input_->sensor_origin_.head(3),
                           params_.min_height, params_.max_height);
  // Each candidate's points go to a slice of a buffer kept between frames that could take
  // every point (no growth test per point); PCL's list of every index is not read when no
  // indices were given.
  const pcl::index_t* given = fake_indices_ ? nullptr : indices_->data();
  const std::size_t count = fake_indices_ ? input_->size() : indices_->size();
  if (on_buffer_.size < n * count) {
    on_buffer_.data.reset(new pcl::index_t[n * count]); // not initialised: only writes touch it
    on_buffer_.size = n * count;
  }
  std::array<pcl::index_t*, 8> ends;
  for (std::size_t s = 0; s < n; ++s)
    ends[s] = on_buffer_.data.get() + s * count;
  // PCL's point types start with x, y, z (PCL_ADD_POINT4D): the sort reads the cloud itself.
  if constexpr (pcl::traits::offset<PointT, pcl::fields::x>::value == 0 &&
                pcl::traits::offset<PointT, pcl::fields::y>::value == 4 &&
                pcl::traits::offset<PointT, pcl::fields::z>::value == 8 &&
                sizeof(PointT) % sizeof(float) == 0 && sizeof(PointT) >= 4 * sizeof(float))
    sorter.sort(reinterpret_cast<const float*>(input_->points.data()),
                sizeof(PointT) / sizeof(float), count, given, ends.data(), above);
  else {
    std::vector<float> xyz(4 * input_->size());
    for (std::size_t i = 0; i < input_->size(); ++i)
      Eigen::Map<Eigen::Vector3f>(xyz.data() + 4 * i) = (*input_)[i].getVector3fMap();
    sorter.sort(xyz.data(), 4, count, given, ends.data(), above);
  }
  for (std::size_t s = 0; s < n; ++s)
    all[s].inliers.indices.assign(on_buffer_.data.get() + s * count, ends[s]);
  for (std::size_t s = 0; s < n; ++s) {
    all[s].plane = candidates[s].plane;
    all[s].band = candidates[s].band;
    all[s].inliers.header = input_->header;
    Eigen::Vector3f centre = Eigen::Vector3f::Zero();
    for (const auto i : candidates[s].points)
      centre += (*input_)[i].getVector3fMap();
    all[s].frame = planeFrame(
      candidates[s].plane,
      centre / static_cast<float>(std::max<std::size_t>(1, candidates[s].points.size())));
  }
}

template <typename PointT>
std::vector<std::vector<std::size_t>>
TabletopSegmentation<PointT>::rankFamilies(const std::vector<Candidate>& candidates,
                                           const std::vector<SupportPlane>& all) const
{
  if (candidates.empty())
    return {};
  if (params_.support == TabletopSegmentationParameters::Support::LargestPlane)
    return {{0}};
  std::vector<Eigen::Vector4f> planes;
  std::vector<std::size_t> points;
  for (std::size_t s = 0; s < candidates.size(); ++s) {
    planes.push_back(candidates[s].plane);
    points.push_back(all[s].inliers.indices.size());
  }
  return rankSupportFamilies(planes, points, !up_.isZero(), image_down_);
}

template <typename PointT>
float
TabletopSegmentation<PointT>::seedDistance() const
{
  return params_.plane_distance > 0.f ? params_.plane_distance : kSeedDistance;
}

template <typename PointT>
int
TabletopSegmentation<PointT>::coarseStride() const
{
  return searchedAsImage() ? planeStep() : 1;
}

template <typename PointT>
typename TabletopSegmentation<PointT>::Trial
TabletopSegmentation<PointT>::tryFamily(const std::vector<std::size_t>& family,
                                        const std::vector<Candidate>& candidates,
                                        std::vector<SupportPlane>& all,
                                        const std::vector<Above>& above, int stride, bool final)
{
  const bool largest = params_.support == TabletopSegmentationParameters::Support::LargestPlane;
  const Eigen::Vector3f viewpoint = input_->sensor_origin_.head(3);
  supports_.clear();
  extents_.clear();
  std::uint8_t kept = 0;
  for (const std::size_t s : family) {
    SupportPlane support;
    support.plane = all[s].plane;
    support.band = all[s].band;
    support.frame = all[s].frame;
    if (!hulls_[s].known) { // once per candidate: every trial of its family needs them
      hulls_[s].polygon = supportHull(support.frame, all[s].inliers.indices, &candidates[s]);
      hulls_[s].region = regionArea(candidates[s], support.frame);
      hulls_[s].known = true;
    }
    support.polygon = hulls_[s].polygon;
    // A plane inside the object band of a larger parallel one (a shelf, a box top) is judged
    // by the region found on it: its infinite plane slices through the objects around it.
    const float range = (support.frame.translation() - viewpoint).norm();
    bool elevated = false;
    for (const std::size_t t : family) {
      const float height = candidates[t].plane[3] - candidates[s].plane[3];
      elevated =
        elevated || (t != s && candidates[t].support > candidates[s].support &&
                     height > candidates[t].band.halfWidth(range) && height <= params_.max_height);
    }
    // Its own region must be sizeable too: a small region's infinite plane can cross a
    // table.
    const float region = hulls_[s].region;
    const float hull = polygonArea(support.polygon);
    if (final)
      PCL_DEBUG("[facyl::TabletopSegmentation] family plane %zu: normal (%.3f %.3f %.3f) d "
                "%.3f, %zu inliers, hull %.3f m^2, region %.3f m^2%s\n",
                s, support.plane[0], support.plane[1], support.plane[2], support.plane[3],
                all[s].inliers.indices.size(), hull, region, elevated ? ", elevated" : "");
    const bool large =
      elevated ? region >= params_.min_shelf_area
               : hull >= params_.min_support_area && region >= 0.25f * params_.min_support_area;
    if (support.polygon.size() < 3 || !(largest || large))
      continue;
    kept |= static_cast<std::uint8_t>(1u << s);
    if (hulls_[s].extent.empty())
      hulls_[s].extent = supportHull(support.frame, all[s].inliers.indices, nullptr);
    extents_.push_back(hulls_[s].extent);
    if (final)
      support.inliers = std::move(all[s].inliers); // a candidate is in one family only
    else
      support.inliers.indices.resize(all[s].inliers.indices.size()); // only the count is used
    supports_.push_back(std::move(support));
  }
  Trial trial;
  if (supports_.empty())
    return trial;
  pcl::Indices band;
  const auto w = static_cast<pcl::index_t>(input_->width);
  for (const Above& a : above)
    if ((a.above & kept) && !(a.on & kept) &&
        (stride == 1 || ((a.index % w) % stride == 0 && (a.index / w) % stride == 0)))
      band.push_back(a.index);
  std::vector<pcl::Indices> groups;
  if (stride == 1)
    cluster(band, groups);
  else
    clusterCoarse(band, stride, groups);
  assignClusters(groups, trial, static_cast<std::size_t>(stride * stride));
  PCL_DEBUG("[facyl::TabletopSegmentation] stride %d: %zu supports, %zu object points, %zu "
            "groups, %zu clusters, %zu standing\n",
            stride, trial.supports.size(), band.size(), groups.size(), trial.clusters.size(),
            trial.standing);
  return trial;
}

template <typename PointT>
pcl::Indices
TabletopSegmentation<PointT>::hullCandidates(const pcl::Indices& region) const
{
  return searchedAsImage() ? rowExtremes(region, input_->width, input_->height) : region;
}

template <typename PointT>
float
TabletopSegmentation<PointT>::regionArea(const Candidate& c, const Eigen::Affine3f& frame) const
{
  const Eigen::Affine3f to_plane = frame.inverse();
  std::vector<Eigen::Vector2f> flat;
  for (const auto i : hullCandidates(c.points))
    flat.push_back((to_plane * (*input_)[i].getVector3fMap()).template head<2>());
  return polygonArea(convexHull2D(std::move(flat)));
}

template <typename PointT>
std::vector<Eigen::Vector2f>
TabletopSegmentation<PointT>::supportHull(const Eigen::Affine3f& frame, const pcl::Indices& idx,
                                          const Candidate* c) const
{
  const Eigen::Affine3f to_plane = frame.inverse();
  const auto flat = [&](pcl::index_t i) {
    return Eigen::Vector2f((to_plane * (*input_)[i].getVector3fMap()).template head<2>());
  };
  std::vector<Eigen::Vector2f> points;
  if (!searchedAsImage()) {
    const std::size_t stride = std::max<std::size_t>(1, idx.size() / params_.plane_samples);
    for (std::size_t k = 0; k < idx.size(); k += stride)
      points.push_back(flat(idx[k]));
    return convexHull2D(std::move(points));
  }
  if (c)
    for (const auto i : hullCandidates(c->points))
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
  const auto w = static_cast<pcl::index_t>(input_->width);
  const auto add = [&](pcl::index_t i) {
    const Eigen::Vector2f p = flat(i);
    if (near_region(p))
      points.push_back(p);
  };
  // Each image row: its first and last point near the region. The pixel sort of the whole
  // frame writes the lists in image order: a row's end is then found by a binary search, not
  // a walk over its points.
  const bool ascending = fake_indices_;
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

template <typename PointT>
typename TabletopSegmentation<PointT>::Placement
TabletopSegmentation<PointT>::place(const Eigen::Matrix3Xf& pts) const
{
  const auto& p = params_;
  const Eigen::Vector3f viewpoint = input_->sensor_origin_.head(3);
  Placement out;
  std::vector<HeightProfile> profiles(supports_.size());
  for (std::size_t s = 0; s < supports_.size(); ++s) {
    profiles[s] = heightProfile(pts, supports_[s].plane, supports_[s].band, viewpoint, p.min_height,
                                p.max_height);
    const Eigen::Affine3f to_plane = supports_[s].frame.inverse();
    std::size_t in_hull = 0;
    for (Eigen::Index k = 0; k < pts.cols(); ++k)
      in_hull += pointInPolygon((to_plane * Eigen::Vector3f(pts.col(k))).template head<2>(),
                                supports_[s].polygon);
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
  for (std::size_t s = 0; s < supports_.size(); ++s) {
    if (static_cast<int>(s) == out.support || !(profiles[s].top < 0.f))
      continue;
    const Eigen::Affine3f to_plane = supports_[s].frame.inverse();
    std::size_t under = 0;
    for (Eigen::Index k = 0; k < pts.cols(); ++k)
      under +=
        pointInPolygon((to_plane * Eigen::Vector3f(pts.col(k))).template head<2>(), extents_[s]);
    if (2 * under >= static_cast<std::size_t>(pts.cols())) {
      out.support = -1;
      return out;
    }
  }
  // Standing: it reaches down to the support's band (at its range) within contact_height.
  const SupportPlane& support = supports_[static_cast<std::size_t>(out.support)];
  const float range = (Eigen::Vector3f(pts.rowwise().mean()) - viewpoint).norm();
  out.standing = standsOn(profiles[static_cast<std::size_t>(out.support)],
                          p.contact_height + support.band.halfWidth(range), p.max_height, 0.02f);
  return out;
}

template <typename PointT>
void
TabletopSegmentation<PointT>::assignClusters(std::vector<pcl::Indices>& groups, Trial& trial,
                                             std::size_t scale)
{
  const auto& p = params_;
  for (auto& group : groups) {
    if (group.size() * scale < p.min_cluster_size || group.size() * scale > p.max_cluster_size)
      continue;
    // At most 400 of its points, evenly: enough for the height and hull tests.
    const std::size_t stride = std::max<std::size_t>(1, group.size() / 400);
    Eigen::Matrix3Xf pts(3, static_cast<Eigen::Index>((group.size() + stride - 1) / stride));
    for (std::size_t k = 0, c = 0; k < group.size(); k += stride, ++c)
      pts.col(static_cast<Eigen::Index>(c)) = (*input_)[group[k]].getVector3fMap();
    const Placement pl = place(pts);
    if (pl.support < 0)
      continue;
    SupportPlane& support = supports_[static_cast<std::size_t>(pl.support)];
    ++support.objects;
    if (pl.standing) {
      support.standing_points += group.size() * scale;
      ++trial.standing_objects;
    }
    if (scale == 1)
      trial.clusters.push_back(makeCluster(std::move(group), pl.support));
  }
  // The table: the most object points standing on it; else the largest support.
  std::size_t table = 0;
  for (std::size_t s = 0; s < supports_.size(); ++s) {
    trial.standing += supports_[s].standing_points;
    if (supports_[s].standing_points > supports_[table].standing_points ||
        (supports_[s].standing_points == supports_[table].standing_points &&
         supports_[s].inliers.indices.size() > supports_[table].inliers.indices.size()))
      table = s;
  }
  // Keep the supports that hold objects, and the table.
  std::vector<int> new_index(supports_.size(), -1);
  for (std::size_t s = 0; s < supports_.size(); ++s)
    if (supports_[s].objects > 0 || s == table) {
      new_index[s] = static_cast<int>(trial.supports.size());
      trial.supports.push_back(std::move(supports_[s]));
    }
  trial.table = static_cast<std::size_t>(new_index[table]);
  for (auto& c : trial.clusters)
    c.support = new_index[static_cast<std::size_t>(c.support)];
  supports_.clear();
  extents_.clear();
}

template <typename PointT>
void
TabletopSegmentation<PointT>::adopt(Trial trial, std::vector<TabletopCluster>& clusters)
{
  supports_ = std::move(trial.supports);
  table_ = trial.table;
  table_found_ = supports_[table_].standing_points > 0;
  clusters = std::move(trial.clusters);
  const SupportPlane& table = supports_[table_];
  table_coefficients_.header = input_->header;
  table_coefficients_.values = {table.plane[0], table.plane[1], table.plane[2], table.plane[3]};
  hull_->clear();
  for (const auto& v : table.polygon) {
    PointT q;
    q.getVector3fMap() = table.frame * Eigen::Vector3f(v.x(), v.y(), 0.f);
    hull_->push_back(q);
  }
}

template <typename PointT>
void
TabletopSegmentation<PointT>::segmentWithoutSupport(std::vector<TabletopCluster>& clusters,
                                                    const std::vector<std::uint8_t>* taken)
{
  // Every point may belong to an object; objects are the segments of the frame that fit in
  // the object box (max_height in each direction): walls, floors and furniture do not.
  pcl::Indices points;
  for (const auto i : *indices_)
    if (pcl::isFinite((*input_)[i]) && !(taken && (*taken)[static_cast<std::size_t>(i)]))
      points.push_back(i);
  std::vector<pcl::Indices> groups;
  cluster(points, groups);
  const float max_extent = std::sqrt(3.f) * params_.max_height;
  for (auto& g : groups) {
    if (g.size() < params_.min_cluster_size || g.size() > params_.max_cluster_size)
      continue;
    Eigen::AlignedBox3f box;
    for (const auto i : g)
      box.extend((*input_)[i].getVector3fMap());
    if (box.diagonal().norm() <= max_extent)
      clusters.push_back(makeCluster(std::move(g), -1));
  }
}

template <typename PointT>
TabletopCluster
TabletopSegmentation<PointT>::makeCluster(pcl::Indices indices, int support) const
{
  if (!std::is_sorted(indices.begin(), indices.end())) // the segmentations give them ascending
    std::sort(indices.begin(), indices.end());
  TabletopCluster c;
  c.indices.header = input_->header;
  c.indices.indices = std::move(indices);
  c.support = support;
  Eigen::Matrix3Xf pts(3, static_cast<Eigen::Index>(c.indices.indices.size()));
  for (std::size_t k = 0; k < c.indices.indices.size(); ++k)
    pts.col(static_cast<Eigen::Index>(k)) = (*input_)[c.indices.indices[k]].getVector3fMap();
  c.centroid = pts.rowwise().mean();
  c.box =
    input_->isOrganized() ? pixelBox(c.indices.indices, input_->width) : projectedBox(pts, camera_);
  return c;
}

template <typename PointT>
void
TabletopSegmentation<PointT>::cluster(const pcl::Indices& objects,
                                      std::vector<pcl::Indices>& out) const
{
  if (searchedAsImage())
    clusterOrganized(objects, out);
  else
    clusterUnorganized(objects, out);
}

template <typename PointT>
void
TabletopSegmentation<PointT>::clusterOrganized(const pcl::Indices& objects,
                                               std::vector<pcl::Indices>& out) const
{
  if (params_.clustering == TabletopSegmentationParameters::Clustering::EdgeAware && focal_ > 0.f) {
    if (!has_depth_known_ || has_depth_.size() != input_->size()) { // else from planeGrid
      has_depth_.resize(input_->size());
      for (std::size_t i = 0; i < input_->size(); ++i)
        has_depth_[i] = pcl::isFinite((*input_)[i]);
      has_depth_known_ = true;
    }
    // The object points alone, at their pixels in image order: no image-sized copy is filled
    // or read.
    pcl::Indices sorted;
    const bool ascending = strictlyAscending(objects);
    if (!ascending) {
      sorted = objects;
      std::sort(sorted.begin(), sorted.end());
      sorted.erase(std::unique(sorted.begin(), sorted.end()), sorted.end());
    }
    const pcl::Indices& pixels = ascending ? objects : sorted;
    Eigen::Matrix3Xf points(3, static_cast<Eigen::Index>(pixels.size()));
    for (std::size_t k = 0; k < pixels.size(); ++k)
      points.col(static_cast<Eigen::Index>(k)) = (*input_)[pixels[k]].getVector3fMap();
    out = segmentObjectsOrganized(points, pixels, input_->width, input_->height, has_depth_, focal_,
                                  input_->sensor_origin_.head(3), params_.objects,
                                  has_noise_ ? &noise_ : nullptr);
    return;
  }
  // A sparse copy with only the object points finite: the components then never visit the
  // rest of the image. (Buffers kept between calls: fresh VGA-sized allocations cost more in
  // page faults than the work done on them; only the pixels written last time are cleared.)
  if (!masked_)
    masked_.reset(new pcl::PointCloud<pcl::PointXYZ>);
  const auto& masked = masked_;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  if (masked->size() != input_->size()) {
    masked->points.assign(input_->size(), pcl::PointXYZ(nan, nan, nan));
    masked_written_.clear();
  }
  for (const auto i : masked_written_)
    (*masked)[i].getVector3fMap().setConstant(nan);
  masked->width = input_->width;
  masked->height = input_->height;
  masked->is_dense = false;
  for (const auto i : objects)
    (*masked)[i].getVector3fMap() = (*input_)[i].getVector3fMap();
  masked_written_ = objects;
  out = organizedEuclideanClusters(masked, params_.cluster_tolerance, labels_);
}

template <typename PointT>
void
TabletopSegmentation<PointT>::clusterCoarse(const pcl::Indices& objects, int stride,
                                            std::vector<pcl::Indices>& out) const
{
  if (!searchedAsImage() || stride <= 1) {
    cluster(objects, out);
    return;
  }
  // The object points on every stride-th pixel of every stride-th row (\a objects holds only
  // those), as an organized cloud of that grid, segmented like the full frame.
  const int w = static_cast<int>(input_->width), h = static_cast<int>(input_->height);
  const int cw = (w + stride - 1) / stride, ch = (h + stride - 1) / stride;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  pcl::PointCloud<pcl::PointXYZ> coarse;
  coarse.width = static_cast<std::uint32_t>(cw);
  coarse.height = static_cast<std::uint32_t>(ch);
  coarse.is_dense = false;
  coarse.points.assign(static_cast<std::size_t>(cw) * ch, pcl::PointXYZ(nan, nan, nan));
  std::vector<std::uint8_t> has_depth(coarse.size());
  for (int v = 0; v < ch; ++v)
    for (int u = 0; u < cw; ++u)
      has_depth[static_cast<std::size_t>(v) * cw + u] =
        pcl::isFinite((*input_)[static_cast<std::size_t>(v * stride) * w + u * stride]);
  const auto coarse_index = [&](pcl::index_t i) {
    return static_cast<std::size_t>((i / w) / stride) * cw +
           static_cast<std::size_t>((i % w) / stride);
  };
  for (const auto i : objects)
    coarse[coarse_index(i)].getVector3fMap() = (*input_)[i].getVector3fMap();
  std::vector<pcl::Indices> groups;
  if (params_.clustering == TabletopSegmentationParameters::Clustering::EdgeAware && focal_ > 0.f) {
    ObjectSegmentationParameters op = params_.objects;
    op.min_fragment =
      std::max<std::size_t>(1, op.min_fragment / static_cast<std::size_t>(stride * stride));
    op.bridge_occlusions = false; // a count of standing objects needs no joined occluded parts
    // Neighbours are stride pixels apart: the gaps that still connect them grow alike.
    op.min_gap *= static_cast<float>(stride);
    op.max_gap *= static_cast<float>(stride);
    groups =
      segmentObjectsOrganized(coarse, has_depth, focal_ / static_cast<float>(stride),
                              input_->sensor_origin_.head(3), op, has_noise_ ? &noise_ : nullptr);
  }
  else {
    pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>(coarse));
    pcl::PointCloud<pcl::Label> labels;
    groups = organizedEuclideanClusters(
      cloud, static_cast<float>(stride) * params_.cluster_tolerance, labels);
  }
  out.clear();
  for (const auto& g : groups) {
    pcl::Indices full;
    full.reserve(g.size());
    for (const auto k : g)
      full.push_back(static_cast<pcl::index_t>(((k / cw) * stride) * w + (k % cw) * stride));
    out.push_back(std::move(full));
  }
}

template <typename PointT>
void
TabletopSegmentation<PointT>::clusterUnorganized(const pcl::Indices& objects,
                                                 std::vector<pcl::Indices>& out) const
{
  out.clear();
  if (objects.empty())
    return;
  if (params_.clustering == TabletopSegmentationParameters::Clustering::EdgeAware) {
    segmentProjected(objects, out);
    return;
  }
  Eigen::Matrix3Xf points(3, static_cast<Eigen::Index>(objects.size()));
  for (std::size_t k = 0; k < objects.size(); ++k)
    points.col(static_cast<Eigen::Index>(k)) = (*input_)[objects[k]].getVector3fMap();
  const auto groups = voxelEuclideanClusters(points, params_.cluster_tolerance);
  out.assign(groups.size(), pcl::Indices{});
  for (std::size_t g = 0; g < groups.size(); ++g) {
    out[g].reserve(groups[g].size());
    for (const std::size_t k : groups[g])
      out[g].push_back(objects[k]);
  }
}

template <typename PointT>
void
TabletopSegmentation<PointT>::segmentProjected(const pcl::Indices& objects,
                                               std::vector<pcl::Indices>& out) const
{
  // The camera: the one given, else a pinhole at the sensor origin looking at the objects
  // with a VGA sensor's angular resolution.
  const Eigen::Vector3f origin = input_->sensor_origin_.head(3);
  Eigen::Matrix3f to_camera = Eigen::Matrix3f::Identity(); // cloud to camera rotation
  PinholeCamera camera = camera_;
  if (!camera.valid()) {
    Eigen::Vector3f mean = Eigen::Vector3f::Zero();
    for (const auto i : objects)
      mean += (*input_)[i].getVector3fMap() - origin;
    const Eigen::Vector3f z = mean.normalized();
    const Eigen::Vector3f x = z.unitOrthogonal(), y = z.cross(x);
    to_camera.row(0) = x;
    to_camera.row(1) = y;
    to_camera.row(2) = z;
    camera = PinholeCamera{525.f, 525.f, 0.f, 0.f, 0, 0};
    Eigen::AlignedBox2f box;
    for (const auto i : objects) {
      const Eigen::Vector3f c = to_camera * ((*input_)[i].getVector3fMap() - origin);
      if (c.z() > 0.f)
        box.extend(Eigen::Vector2f(c.x() / c.z(), c.y() / c.z()));
    }
    if (box.isEmpty())
      return;
    // At most 1280 x 960 pixels: a wider view gets a coarser grid.
    const float f = std::min(
      {525.f, 1279.f / std::max(box.sizes().x(), 1e-6f), 959.f / std::max(box.sizes().y(), 1e-6f)});
    camera.fx = camera.fy = f;
    camera.cx = -f * box.min().x();
    camera.cy = -f * box.min().y();
    camera.width = static_cast<int>(std::ceil(f * box.sizes().x())) + 1;
    camera.height = static_cast<int>(std::ceil(f * box.sizes().y())) + 1;
  }
  const auto pixel_of = [&](const Eigen::Vector3f& p) -> long {
    const Eigen::Vector3f c = to_camera * (p - origin);
    if (!(c.z() > 0.f))
      return -1;
    const long u = std::lround(camera.fx * c.x() / c.z() + camera.cx);
    const long v = std::lround(camera.fy * c.y() / c.z() + camera.cy);
    if (u < 0 || v < 0 || u >= camera.width || v >= camera.height)
      return -1;
    return v * camera.width + u;
  };
  // A depth image of the nearest object point per pixel, and which pixels see any surface.
  const std::size_t n =
    static_cast<std::size_t>(camera.width) * static_cast<std::size_t>(camera.height);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  pcl::PointCloud<pcl::PointXYZ> image;
  image.width = static_cast<std::uint32_t>(camera.width);
  image.height = static_cast<std::uint32_t>(camera.height);
  image.points.assign(n, pcl::PointXYZ(nan, nan, nan));
  std::vector<float> range(n, std::numeric_limits<float>::infinity());
  std::vector<std::uint8_t> has_depth(n, 0);
  for (const auto i : *indices_) {
    const auto& p = (*input_)[i];
    if (!pcl::isFinite(p))
      continue;
    const long k = pixel_of(p.getVector3fMap());
    if (k >= 0)
      has_depth[static_cast<std::size_t>(k)] = 1;
  }
  std::vector<long> pixel(objects.size(), -1);
  for (std::size_t j = 0; j < objects.size(); ++j) {
    const Eigen::Vector3f p = (*input_)[objects[j]].getVector3fMap();
    const long k = pixel_of(p);
    pixel[j] = k;
    if (k < 0)
      continue;
    const float r = (p - origin).norm();
    if (r < range[static_cast<std::size_t>(k)]) {
      range[static_cast<std::size_t>(k)] = r;
      image[static_cast<std::size_t>(k)].getVector3fMap() = p;
    }
  }
  const std::vector<pcl::Indices> segments = segmentObjectsOrganized(
    image, has_depth, camera.fx, origin, params_.objects, has_noise_ ? &noise_ : nullptr);
  // Every object point takes the segment of its pixel.
  std::vector<int> segment_of(n, -1);
  for (std::size_t s = 0; s < segments.size(); ++s)
    for (const auto k : segments[s])
      segment_of[static_cast<std::size_t>(k)] = static_cast<int>(s);
  out.assign(segments.size(), pcl::Indices{});
  for (std::size_t j = 0; j < objects.size(); ++j)
    if (pixel[j] >= 0 && segment_of[static_cast<std::size_t>(pixel[j])] >= 0)
      out[static_cast<std::size_t>(segment_of[static_cast<std::size_t>(pixel[j])])].push_back(
        objects[j]);
}

} // namespace facyl
