/*
 * facyl: fast cylinder detection for PCL.
 * The objects of a frame (tabletop_steps.h): its object points split into clusters, on an
 * image (edge-aware: object_segmentation.h; or Euclidean), on a coarse grid of an image (to
 * compare families of supports), or in a point set (projected into a depth image, or
 * Euclidean); and the compact segments of a frame without a support.
 */
#include "tabletop_steps.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace facyl {
namespace tabletop {
namespace {

/** The object points of an image split into clusters. */
std::vector<pcl::Indices>
clusterOrganized(const Setup& setup, const FrameCues& cues, const pcl::Indices& objects,
                 TabletopWorkspace& workspace)
{
  const PointFrame& frame = setup.frame;
  const auto& params = setup.params;
  if (params.clustering == TabletopSegmentationParameters::Clustering::EdgeAware &&
      cues.focal > 0.f) {
    std::vector<std::uint8_t> own; // when the plane search did not record them
    const std::vector<std::uint8_t>* has_depth = cues.has_depth;
    if (!has_depth || has_depth->size() != frame.size) {
      own.resize(frame.size);
      for (std::size_t i = 0; i < frame.size; ++i)
        own[i] = frame.finite(i);
      has_depth = &own;
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
      points.col(static_cast<Eigen::Index>(k)) = frame.point(static_cast<std::size_t>(pixels[k]));
    const ColourImage colour{frame.bgr, frame.bgr_stride};
    return segmentObjectsOrganized(points, pixels, frame.width, frame.height, *has_depth,
                                   cues.focal, frame.viewpoint, params.objects, cues.noiseBand(),
                                   frame.bgr ? &colour : nullptr, setup.threads);
  }
  // A sparse copy with only the object points finite: the components then never visit the
  // rest of the image. (Buffers kept between calls: fresh VGA-sized allocations cost more in
  // page faults than the work done on them; only the pixels written last time are cleared.)
  auto& masked = workspace.masked;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  if (masked.size() != frame.size) {
    masked.points.assign(frame.size, pcl::PointXYZ(nan, nan, nan));
    workspace.masked_written.clear();
  }
  for (const auto i : workspace.masked_written)
    masked[static_cast<std::size_t>(i)].getVector3fMap().setConstant(nan);
  masked.width = frame.width;
  masked.height = frame.height;
  masked.is_dense = false;
  for (const auto i : objects)
    masked[static_cast<std::size_t>(i)].getVector3fMap() = frame.point(static_cast<std::size_t>(i));
  workspace.masked_written = objects;
  // The workspace keeps the cloud: a pointer that does not own it.
  const pcl::PointCloud<pcl::PointXYZ>::ConstPtr view(std::shared_ptr<void>(), &masked);
  return organizedEuclideanClusters(view, params.cluster_tolerance, workspace.labels);
}

/** EdgeAware on point sets: the points projected into a depth image (the camera given, else a
 * pinhole at the sensor origin looking at the objects), segmented as an organized frame; each
 * point takes its pixel's segment. */
std::vector<pcl::Indices>
segmentProjected(const Setup& setup, const FrameCues& cues, const pcl::Indices& objects)
{
  const PointFrame& frame = setup.frame;
  // The camera: the one given, else a pinhole at the sensor origin looking at the objects
  // with a VGA sensor's angular resolution.
  const Eigen::Vector3f origin = frame.viewpoint;
  Eigen::Matrix3f to_camera = Eigen::Matrix3f::Identity(); // frame to camera rotation
  PinholeCamera camera = setup.camera;
  std::vector<pcl::Indices> out;
  if (!camera.valid()) {
    Eigen::Vector3f mean = Eigen::Vector3f::Zero();
    for (const auto i : objects)
      mean += frame.point(static_cast<std::size_t>(i)) - origin;
    const Eigen::Vector3f z = mean.normalized();
    const Eigen::Vector3f x = z.unitOrthogonal(), y = z.cross(x);
    to_camera.row(0) = x;
    to_camera.row(1) = y;
    to_camera.row(2) = z;
    camera = PinholeCamera{525.f, 525.f, 0.f, 0.f, 0, 0};
    Eigen::AlignedBox2f box;
    for (const auto i : objects) {
      const Eigen::Vector3f c = to_camera * (frame.point(static_cast<std::size_t>(i)) - origin);
      if (c.z() > 0.f)
        box.extend(Eigen::Vector2f(c.x() / c.z(), c.y() / c.z()));
    }
    if (box.isEmpty())
      return out;
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
  forEachPoint(frame, [&](pcl::index_t i) {
    if (!frame.finite(static_cast<std::size_t>(i)))
      return;
    const long k = pixel_of(frame.point(static_cast<std::size_t>(i)));
    if (k >= 0)
      has_depth[static_cast<std::size_t>(k)] = 1;
  });
  std::vector<long> pixel(objects.size(), -1);
  for (std::size_t j = 0; j < objects.size(); ++j) {
    const Eigen::Vector3f p = frame.point(static_cast<std::size_t>(objects[j]));
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
    image, has_depth, camera.fx, origin, setup.params.objects, cues.noiseBand());
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
  return out;
}

/** The object points of a point set split into clusters. */
std::vector<pcl::Indices>
clusterUnorganized(const Setup& setup, const FrameCues& cues, const pcl::Indices& objects)
{
  std::vector<pcl::Indices> out;
  if (objects.empty())
    return out;
  if (setup.params.clustering == TabletopSegmentationParameters::Clustering::EdgeAware)
    return segmentProjected(setup, cues, objects);
  Eigen::Matrix3Xf points(3, static_cast<Eigen::Index>(objects.size()));
  for (std::size_t k = 0; k < objects.size(); ++k)
    points.col(static_cast<Eigen::Index>(k)) =
      setup.frame.point(static_cast<std::size_t>(objects[k]));
  const auto groups = voxelEuclideanClusters(points, setup.params.cluster_tolerance);
  out.assign(groups.size(), pcl::Indices{});
  for (std::size_t g = 0; g < groups.size(); ++g) {
    out[g].reserve(groups[g].size());
    for (const std::size_t k : groups[g])
      out[g].push_back(objects[k]);
  }
  return out;
}

} // namespace

std::vector<pcl::Indices>
cluster(const Setup& setup, const FrameCues& cues, const pcl::Indices& objects,
        TabletopWorkspace& workspace)
{
  if (setup.as_image)
    return clusterOrganized(setup, cues, objects, workspace);
  return clusterUnorganized(setup, cues, objects);
}

std::vector<pcl::Indices>
clusterCoarse(const Setup& setup, const FrameCues& cues, const pcl::Indices& objects, int stride,
              TabletopWorkspace& workspace)
{
  if (!setup.as_image || stride <= 1)
    return cluster(setup, cues, objects, workspace);
  const PointFrame& frame = setup.frame;
  const auto& params = setup.params;
  // The object points on every stride-th pixel of every stride-th row (\a objects holds only
  // those), as an organized cloud of that grid, segmented like the full frame.
  const int w = static_cast<int>(frame.width), h = static_cast<int>(frame.height);
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
        frame.finite(static_cast<std::size_t>(v * stride) * w + u * stride);
  const auto coarse_index = [&](pcl::index_t i) {
    return static_cast<std::size_t>((i / w) / stride) * cw +
           static_cast<std::size_t>((i % w) / stride);
  };
  for (const auto i : objects)
    coarse[coarse_index(i)].getVector3fMap() = frame.point(static_cast<std::size_t>(i));
  std::vector<pcl::Indices> groups;
  if (params.clustering == TabletopSegmentationParameters::Clustering::EdgeAware &&
      cues.focal > 0.f) {
    ObjectSegmentationParameters op = params.objects;
    op.min_fragment =
      std::max<std::size_t>(1, op.min_fragment / static_cast<std::size_t>(stride * stride));
    op.bridge_occlusions = false; // a count of standing objects needs no joined occluded parts
    // Neighbours are stride pixels apart: the gaps that still connect them grow alike.
    op.min_gap *= static_cast<float>(stride);
    op.max_gap *= static_cast<float>(stride);
    groups = segmentObjectsOrganized(coarse, has_depth, cues.focal / static_cast<float>(stride),
                                     frame.viewpoint, op, cues.noiseBand());
  }
  else {
    pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>(coarse));
    pcl::PointCloud<pcl::Label> labels;
    groups = organizedEuclideanClusters(
      cloud, static_cast<float>(stride) * params.cluster_tolerance, labels);
  }
  std::vector<pcl::Indices> out;
  for (const auto& g : groups) {
    pcl::Indices full;
    full.reserve(g.size());
    for (const auto k : g)
      full.push_back(static_cast<pcl::index_t>(((k / cw) * stride) * w + (k % cw) * stride));
    out.push_back(std::move(full));
  }
  return out;
}

void
segmentWithoutSupport(const Setup& setup, const FrameCues& cues,
                      const std::vector<std::uint8_t>* taken,
                      std::vector<TabletopCluster>& clusters, TabletopWorkspace& workspace)
{
  const PointFrame& frame = setup.frame;
  const auto& params = setup.params;
  // Every point may belong to an object; objects are the segments of the frame that fit in
  // the object box (max_height in each direction): walls, floors and furniture do not.
  pcl::Indices points;
  forEachPoint(frame, [&](pcl::index_t i) {
    const auto k = static_cast<std::size_t>(i);
    if (frame.finite(k) && !(taken && (*taken)[k]))
      points.push_back(i);
  });
  std::vector<pcl::Indices> groups = cluster(setup, cues, points, workspace);
  const float max_extent = std::sqrt(3.f) * params.max_height;
  for (auto& g : groups) {
    if (g.size() < params.min_cluster_size || g.size() > params.max_cluster_size)
      continue;
    Eigen::AlignedBox3f box;
    for (const auto i : g)
      box.extend(frame.point(static_cast<std::size_t>(i)));
    if (box.diagonal().norm() <= max_extent)
      clusters.push_back(makeCluster(setup, std::move(g), -1));
  }
}

TabletopCluster
makeCluster(const Setup& setup, pcl::Indices indices, int support)
{
  const PointFrame& frame = setup.frame;
  if (!std::is_sorted(indices.begin(), indices.end())) // the segmentations give them ascending
    std::sort(indices.begin(), indices.end());
  TabletopCluster c;
  c.indices.header = frame.header;
  c.indices.indices = std::move(indices);
  c.support = support;
  Eigen::Matrix3Xf pts(3, static_cast<Eigen::Index>(c.indices.indices.size()));
  for (std::size_t k = 0; k < c.indices.indices.size(); ++k)
    pts.col(static_cast<Eigen::Index>(k)) =
      frame.point(static_cast<std::size_t>(c.indices.indices[k]));
  c.centroid = pts.rowwise().mean();
  c.box = frame.isOrganized() ? pixelBox(c.indices.indices, frame.width)
                              : projectedBox(pts, setup.camera);
  return c;
}

} // namespace tabletop
} // namespace facyl
