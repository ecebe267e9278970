/*
 * facyl: fast cylinder detection for PCL.
 * A large frame segmented on a lattice of every s-th pixel and row (lattice_width), with the
 * lattice's settings and camera, and its clusters and supports then brought back to full
 * resolution (tabletop_steps.h).
 */
#include "tabletop_steps.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

namespace facyl {

int
latticeStep(const PointFrame& frame, const TabletopSegmentationParameters& params)
{
  const int lattice = params.lattice_width;
  if (lattice <= 0 || frame.indices || !tabletop::searchedAsImage(frame, params) ||
      2 * frame.width <= static_cast<std::uint32_t>(3 * lattice))
    return 1;
  return static_cast<int>(std::lround(static_cast<double>(frame.width) / lattice));
}

TabletopSegmentationParameters
latticeParameters(const TabletopSegmentationParameters& params, int step)
{
  // A lattice point stands for step^2 pixels: counts of points scale down; lengths stay.
  TabletopSegmentationParameters p = params;
  const auto area = static_cast<std::size_t>(step * step);
  p.min_plane_points = std::max<std::size_t>(1, p.min_plane_points / area);
  p.min_cluster_size = std::max<std::size_t>(1, p.min_cluster_size / area);
  p.max_cluster_size = std::max(p.min_cluster_size, p.max_cluster_size / area);
  p.objects.min_fragment = std::max<std::size_t>(1, p.objects.min_fragment / area);
  if (p.plane_step > 0)
    p.plane_step = std::max(1, p.plane_step / step);
  return p;
}

PinholeCamera
latticeCamera(const PinholeCamera& camera, int step, std::uint32_t width, std::uint32_t height)
{
  PinholeCamera out = camera;
  if (!out.valid())
    return out;
  const float s = static_cast<float>(step);
  out.fx /= s, out.fy /= s, out.cx /= s, out.cy /= s;
  out.width = static_cast<int>(width);
  out.height = static_cast<int>(height);
  return out;
}

namespace tabletop {
namespace {

/** A support's band, tabulated by range (tabulateHalfWidths) as the pixel sort reads it, and
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

/** Every \a step-th pixel of every \a step-th row of the image \a full, starting with the
 * first (as latticeOf), as a frame over \a buffer (four floats a point) and, when \a full has
 * colours, \a colours (three bytes a point: the colour edges of the object segmentation). */
PointFrame
latticeFrame(const PointFrame& full, int step,
             std::vector<float, detail::UninitialisedAllocator<float>>& buffer,
             std::vector<std::uint8_t, detail::UninitialisedAllocator<std::uint8_t>>& colours)
{
  const auto w = static_cast<std::size_t>(full.width), h = static_cast<std::size_t>(full.height);
  const auto s = static_cast<std::size_t>(step);
  const std::size_t lw = (w + s - 1) / s, lh = (h + s - 1) / s;
  if (buffer.size() < 4 * lw * lh) {
    buffer.clear(); // nothing to move to the new allocation
    buffer.resize(4 * lw * lh);
  }
  for (std::size_t v = 0; v < lh; ++v)
    for (std::size_t u = 0; u < lw; ++u) {
      const float* p = full.xyz + (v * s * w + u * s) * full.stride;
      float* q = buffer.data() + 4 * (v * lw + u);
      q[0] = p[0], q[1] = p[1], q[2] = p[2], q[3] = 1.f;
    }
  PointFrame lattice;
  if (full.bgr) {
    if (colours.size() < 3 * lw * lh) {
      colours.clear();
      colours.resize(3 * lw * lh);
    }
    for (std::size_t v = 0; v < lh; ++v)
      for (std::size_t u = 0; u < lw; ++u) {
        const std::uint8_t* c = full.bgr + (v * s * w + u * s) * full.bgr_stride;
        std::uint8_t* d = colours.data() + 3 * (v * lw + u);
        d[0] = c[0], d[1] = c[1], d[2] = c[2];
      }
    lattice.bgr = colours.data();
    lattice.bgr_stride = 3;
  }
  lattice.xyz = buffer.data();
  lattice.stride = 4;
  lattice.size = lw * lh;
  lattice.width = static_cast<std::uint32_t>(lw);
  lattice.height = static_cast<std::uint32_t>(lh);
  lattice.viewpoint = full.viewpoint;
  lattice.header = full.header;
  return lattice;
}

/** The clusters \a coarse of the \a lattice of \a step (segmented with \a cues), with the
 * pixels of the full frame of \a setup that continue them, largest first; \a supports: the
 * lattice's. */
std::vector<TabletopCluster>
clustersAtFullResolution(const Setup& setup, const FrameCues& cues,
                         const std::vector<TabletopCluster>& coarse,
                         const std::vector<SupportPlane>& supports, const PointFrame& lattice,
                         int step)
{
  const PointFrame& full = setup.frame;
  const auto& op = setup.params.objects;
  const Eigen::Vector3f viewpoint = full.viewpoint;
  const int w = static_cast<int>(full.width), h = static_cast<int>(full.height);
  const int lw = static_cast<int>(lattice.width), lh = static_cast<int>(lattice.height);
  const std::vector<float> half =
    cues.noise ? tabulateHalfWidths(*cues.noise) : std::vector<float>();
  std::vector<TabulatedBand> bands;
  for (const auto& support : supports)
    bands.emplace_back(support);
  std::vector<int> label(lattice.size, -1); // each lattice pixel's object
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
        if (!lattice.finite(l))
          continue;
        const float d2 = (lattice.point(l) - p).squaredNorm();
        if (d2 < best)
          best = d2, owner = label[l];
      }
    return owner;
  };
  std::vector<TabletopCluster> clusters;
  for (std::size_t k = 0; k < coarse.size(); ++k) {
    const auto& c = coarse[k];
    // A block's pixel joins its lattice pixel's object when it continues its surface (within
    // the lattice's connection gap, as segmentObjectsOrganized has it for neighbours one lattice
    // step apart), the nearest lattice pixel of its lattice cell's corners is this object's (a
    // pixel between an object's foot and what it stands on goes to the nearer), and it is an
    // object point (above its support's band, as the pixel sort has it).
    const TabulatedBand* band =
      c.support >= 0 ? &bands[static_cast<std::size_t>(c.support)] : nullptr;
    // The gap of the block's lattice pixel, computed once for the pixels of its block's row.
    pcl::index_t gap_of = -1;
    float gap2 = 0.f;
    const auto continues = [&](pcl::index_t pixel, pcl::index_t parent) {
      const auto at = static_cast<std::size_t>(pixel);
      if (!full.finite(at))
        return false;
      if (pixel == parent)
        return true;
      const Eigen::Vector3f p = full.point(at);
      const Eigen::Vector3f q = full.point(static_cast<std::size_t>(parent));
      if (parent != gap_of) {
        const float gap = connectionGap(op, (q - viewpoint).norm(), cues.focal, half);
        gap2 = gap * gap;
        gap_of = parent;
      }
      if (!((p - q).squaredNorm() < gap2) ||
          nearest(pixel % w, pixel / w, p) != static_cast<int>(k))
        return false;
      float half_width = 0.f;
      return !band || band->above(p, viewpoint, half_width) > half_width;
    };
    pcl::Indices pixels = blockPixels(c.indices.indices, w, h, step, continues);
    if (pixels.size() >= setup.params.min_cluster_size &&
        pixels.size() <= setup.params.max_cluster_size)
      clusters.push_back(makeCluster(setup, std::move(pixels), c.support));
  }
  sortLargestFirst(clusters);
  return clusters;
}

/** The \a supports' inliers of the lattice of \a step, as the pixels of their blocks in the
 * image \a full within their bands. */
void
supportsAtFullResolution(const PointFrame& full, int step, std::vector<SupportPlane>& supports)
{
  const Eigen::Vector3f viewpoint = full.viewpoint;
  const int w = static_cast<int>(full.width), h = static_cast<int>(full.height);
  for (auto& support : supports) {
    const TabulatedBand band(support);
    const auto within = [&](pcl::index_t pixel, pcl::index_t) {
      const auto at = static_cast<std::size_t>(pixel);
      if (!full.finite(at))
        return false;
      float half_width = 0.f;
      return std::abs(band.above(full.point(at), viewpoint, half_width)) <= half_width;
    };
    support.inliers.indices = blockPixels(support.inliers.indices, w, h, step, within);
    support.standing_points *= static_cast<std::size_t>(step * step);
  }
}

} // namespace

TabletopSegments
segmentOnLattice(const Setup& setup, int step, TabletopWorkspace& workspace)
{
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  const auto ms = [](Clock::time_point a) {
    return std::chrono::duration<double, std::milli>(Clock::now() - a).count();
  };
  const PointFrame lattice =
    latticeFrame(setup.frame, step, workspace.lattice, workspace.lattice_colours);
  const TabletopSegmentationParameters params = latticeParameters(setup.params, step);
  const PinholeCamera camera = latticeCamera(setup.camera, step, lattice.width, lattice.height);
  const double t_lattice = ms(t0);
  FrameCues cues;
  const Setup on_lattice = makeSetup(lattice, params, camera, setup.up, setup.prior, setup.threads);
  TabletopSegments out = segmentFrame(on_lattice, cues, workspace);
  adoptSupportUnderFloatingObjects(on_lattice, cues, workspace, out);
  const auto t1 = Clock::now();
  out.clusters = clustersAtFullResolution(setup, cues, out.clusters, out.supports, lattice, step);
  supportsAtFullResolution(setup.frame, step, out.supports);
  out.focal *= static_cast<float>(step); // the full frame's
  out.timing.planes += t_lattice;
  out.timing.objects += ms(t1);
  return out;
}

} // namespace tabletop
} // namespace facyl
