/*
 * facyl: fast cylinder detection for PCL.
 */
#pragma once

#include <facyl/segmentation/tabletop_segmentation.h>

#include <pcl/common/io.h>
#include <pcl/common/point_tests.h>
#include <pcl/features/integral_image_normal.h>
#include <pcl/features/normal_3d.h>
#include <pcl/filters/random_sample.h>
#include <pcl/sample_consensus/method_types.h>
#include <pcl/sample_consensus/model_types.h>
#include <pcl/search/kdtree.h>
#include <pcl/segmentation/euclidean_cluster_comparator.h>
#include <pcl/segmentation/extract_clusters.h>
#include <pcl/segmentation/organized_connected_component_segmentation.h>
#include <pcl/segmentation/organized_multi_plane_segmentation.h>
#include <pcl/segmentation/sac_segmentation.h>
#include <pcl/surface/convex_hull.h>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <unordered_map>

namespace facyl {

template <typename PointT>
void
TabletopSegmentation<PointT>::reset()
{
  plane_.setZero();
  table_coefficients_.values.clear();
  table_frame_.setIdentity();
  table_indices_.indices.clear();
  hull_->clear();
}

template <typename PointT>
bool
TabletopSegmentation<PointT>::segment(std::vector<TabletopCluster>& clusters)
{
  clusters.clear();
  reset();
  const std::string why = validate(params_);
  if (!why.empty()) {
    PCL_ERROR("[facyl::TabletopSegmentation::segment] Invalid parameters: %s.\n", why.c_str());
    return false;
  }
  if (!input_ || input_->empty()) {
    PCL_ERROR("[facyl::TabletopSegmentation::segment] No input cloud, or an empty one.\n");
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
    PCL_ERROR("[facyl::TabletopSegmentation::segment] The cloud has no finite points.\n");
    this->deinitCompute();
    return false;
  }

  pcl::Indices plane_points;
  const bool organized = input_->isOrganized();
  const bool found = organized ? findTableOrganized(plane_points) : findTableUnorganized(plane_points);
  if (!found) {
    PCL_ERROR("[facyl::TabletopSegmentation::segment] No plane with at least %zu points found.\n",
              params_.min_plane_points);
    reset();
    this->deinitCompute();
    return false;
  }

  // Least-squares refit on the plane region, then every point near it is a table point.
  const Eigen::Vector3f viewpoint = input_->sensor_origin_.head(3);
  {
    Eigen::Matrix3Xf pts(3, static_cast<Eigen::Index>(plane_points.size()));
    for (std::size_t k = 0; k < plane_points.size(); ++k)
      pts.col(static_cast<Eigen::Index>(k)) = (*input_)[plane_points[k]].getVector3fMap();
    Eigen::Vector4f refined;
    if (fitPlane(pts, viewpoint, refined))
      plane_ = refined;
  }
  // One pass: the table points, and the band of object candidates above it.
  pcl::Indices band;
  for (const auto i : *indices_) {
    const auto& p = (*input_)[i];
    if (!pcl::isFinite(p))
      continue;
    const float h = plane_.head<3>().dot(p.getVector3fMap()) + plane_[3];
    if (std::abs(h) < params_.plane_distance)
      table_indices_.indices.push_back(i);
    if (h >= params_.min_height && h <= params_.max_height)
      band.push_back(i);
  }

  // Convex hull of the table.
  {
    Eigen::Vector3f centre = Eigen::Vector3f::Zero();
    for (const auto i : plane_points)
      centre += (*input_)[i].getVector3fMap();
    table_frame_ = planeFrame(plane_, centre / static_cast<float>(plane_points.size()));
  }
  const Eigen::Affine3f to_table = table_frame_.inverse();
  // Hull of every table point (the plane regions found may miss parts of the table, e.g. the
  // near edge where a real sensor's depth bends), thinned on organized clouds.
  typename PointCloud::Ptr region(new PointCloud);
  region->reserve(table_indices_.indices.size());
  const auto w = static_cast<pcl::index_t>(input_->width);
  const pcl::index_t step = organized ? params_.plane_step : 1;
  const std::size_t stride =
    organized ? 1 : std::max<std::size_t>(1, table_indices_.indices.size() / params_.plane_samples);
  for (std::size_t k = 0; k < table_indices_.indices.size(); k += stride) {
    const auto i = table_indices_.indices[k];
    if (!organized || ((i % w) % step == 0 && (i / w) % step == 0))
      region->push_back((*input_)[i]);
  }
  pcl::ConvexHull<PointT> convex_hull;
  convex_hull.setInputCloud(region);
  convex_hull.setDimension(2);
  convex_hull.reconstruct(*hull_);
  std::vector<Eigen::Vector2f> polygon;
  for (const auto& v : *hull_)
    polygon.push_back((to_table * v.getVector3fMap()).template head<2>());
  if (polygon.size() < 3) {
    PCL_ERROR("[facyl::TabletopSegmentation::segment] The table's hull is degenerate.\n");
    reset();
    this->deinitCompute();
    return false;
  }
  table_coefficients_.header = input_->header;
  table_coefficients_.values = {plane_[0], plane_[1], plane_[2], plane_[3]};

  std::vector<pcl::PointIndices> groups;
  if (organized)
    clusterOrganized(band, groups);
  else
    clusterUnorganized(band, groups);
  for (auto& g : groups) {
    if (g.indices.size() < params_.min_cluster_size || g.indices.size() > params_.max_cluster_size)
      continue;
    // The prism test of pcl::ExtractPolygonalPrismData (inside the hull, in table coordinates),
    // applied per cluster: objects at the border of the visible table (cut by the image edge, or
    // hiding the table behind them) stick out of the hull and are kept whole.
    std::size_t in_hull = 0;
    for (const auto i : g.indices)
      in_hull +=
        pointInPolygon((to_table * (*input_)[i].getVector3fMap()).template head<2>(), polygon);
    if (static_cast<float>(in_hull) < params_.min_hull_share * static_cast<float>(g.indices.size()))
      continue;
    std::sort(g.indices.begin(), g.indices.end());
    TabletopCluster c;
    c.indices.header = input_->header;
    c.indices.indices = std::move(g.indices);
    Eigen::Matrix3Xf pts(3, static_cast<Eigen::Index>(c.indices.indices.size()));
    for (std::size_t k = 0; k < c.indices.indices.size(); ++k)
      pts.col(static_cast<Eigen::Index>(k)) = (*input_)[c.indices.indices[k]].getVector3fMap();
    c.centroid = pts.rowwise().mean();
    c.box = organized ? pixelBox(c.indices.indices, input_->width) : projectedBox(pts, camera_);
    clusters.push_back(std::move(c));
  }
  // Largest first, like pcl::EuclideanClusterExtraction.
  std::stable_sort(clusters.begin(), clusters.end(), [](const auto& a, const auto& b) {
    return a.indices.indices.size() > b.indices.indices.size();
  });
  this->deinitCompute();
  return true;
}

template <typename PointT>
bool
TabletopSegmentation<PointT>::findTableOrganized(pcl::Indices& plane_points)
{
  const int step = params_.plane_step;
  const int w = static_cast<int>(input_->width), h = static_cast<int>(input_->height);
  std::vector<std::uint8_t> allowed; // only when indices were given
  if (!fake_indices_) {
    allowed.assign(input_->size(), 0);
    for (const auto i : *indices_)
      allowed[i] = 1;
  }
  pcl::PointCloud<pcl::PointXYZ>::Ptr small(new pcl::PointCloud<pcl::PointXYZ>);
  small->width = static_cast<std::uint32_t>((w + step - 1) / step);
  small->height = static_cast<std::uint32_t>((h + step - 1) / step);
  small->is_dense = false;
  small->resize(static_cast<std::size_t>(small->width) * small->height);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (int v = 0, k = 0; v < h; v += step)
    for (int u = 0; u < w; u += step, ++k) {
      const std::size_t idx = static_cast<std::size_t>(v) * w + u;
      const auto& p = (*input_)[idx];
      auto& q = (*small)[k];
      if ((fake_indices_ || allowed[idx]) && pcl::isFinite(p))
        q.getVector3fMap() = p.getVector3fMap();
      else
        q.x = q.y = q.z = nan;
    }
  pcl::PointCloud<pcl::Normal>::Ptr normals(new pcl::PointCloud<pcl::Normal>);
  pcl::IntegralImageNormalEstimation<pcl::PointXYZ, pcl::Normal> ne;
  ne.setNormalEstimationMethod(ne.AVERAGE_3D_GRADIENT);
  ne.setMaxDepthChangeFactor(0.02f * static_cast<float>(step));
  ne.setNormalSmoothingSize(std::max(4.f, 10.f / static_cast<float>(step)));
  ne.setInputCloud(small);
  ne.compute(*normals);

  pcl::OrganizedMultiPlaneSegmentation<pcl::PointXYZ, pcl::Normal, pcl::Label> mps;
  mps.setMinInliers(static_cast<unsigned>(
    std::max<std::size_t>(10, params_.min_plane_points / static_cast<std::size_t>(step * step))));
  mps.setAngularThreshold(params_.plane_angle);
  mps.setDistanceThreshold(params_.plane_distance);
  mps.setInputNormals(normals);
  mps.setInputCloud(small);
  std::vector<pcl::ModelCoefficients> coefficients;
  std::vector<pcl::PointIndices> inliers;
  mps.segment(coefficients, inliers);
  std::size_t best = inliers.size();
  for (std::size_t i = 0; i < inliers.size(); ++i)
    if (coefficients[i].values.size() == 4 &&
        (best == inliers.size() || inliers[i].indices.size() > inliers[best].indices.size()))
      best = i;
  if (best == inliers.size())
    return false;
  const Eigen::Vector3f viewpoint = input_->sensor_origin_.head(3);
  const auto plane_of = [&](std::size_t i) {
    const auto& c = coefficients[i].values;
    return orientPlane(Eigen::Vector4f(c[0], c[1], c[2], c[3]), viewpoint);
  };
  plane_ = plane_of(best);
  // The table is every region on that plane (objects split it into several).
  plane_points.clear();
  for (std::size_t i = 0; i < inliers.size(); ++i) {
    if (coefficients[i].values.size() != 4)
      continue;
    const Eigen::Vector4f q = plane_of(i);
    if (i != best && (q.head<3>().dot(plane_.head<3>()) < std::cos(params_.plane_angle) ||
                      std::abs(q[3] - plane_[3]) > params_.plane_distance))
      continue;
    for (const auto k : inliers[i].indices) {
      const int u = (k % static_cast<int>(small->width)) * step;
      const int v = (k / static_cast<int>(small->width)) * step;
      plane_points.push_back(static_cast<pcl::index_t>(v * w + u));
    }
  }
  return plane_points.size() * static_cast<std::size_t>(step * step) >= params_.min_plane_points;
}

template <typename PointT>
bool
TabletopSegmentation<PointT>::findTableUnorganized(pcl::Indices& plane_points)
{
  // Plane search on a uniform random sample of the points, with normals: like the pixels of an
  // organized frame, the sample follows the sensor's density, so the table outweighs a larger
  // but farther floor (a voxel grid would weigh surfaces by their area).
  pcl::IndicesPtr finite(new pcl::Indices);
  for (const auto i : *indices_)
    if (pcl::isFinite((*input_)[i]))
      finite->push_back(i);
  typename PointCloud::Ptr coarse(new PointCloud);
  pcl::RandomSample<PointT> sample;
  sample.setInputCloud(input_);
  sample.setIndices(finite);
  sample.setSample(static_cast<unsigned>(std::min<std::size_t>(params_.plane_samples, finite->size())));
  sample.setSeed(1);
  sample.filter(*coarse);
  if (coarse->size() < 10)
    return false;
  pcl::PointCloud<pcl::Normal>::Ptr normals(new pcl::PointCloud<pcl::Normal>);
  typename pcl::search::KdTree<PointT>::Ptr tree(new pcl::search::KdTree<PointT>);
  pcl::NormalEstimation<PointT, pcl::Normal> ne;
  ne.setInputCloud(coarse);
  ne.setSearchMethod(tree);
  ne.setKSearch(12);
  ne.compute(*normals);
  pcl::SACSegmentationFromNormals<PointT, pcl::Normal> sac;
  sac.setOptimizeCoefficients(true);
  sac.setModelType(pcl::SACMODEL_NORMAL_PLANE);
  sac.setMethodType(pcl::SAC_RANSAC);
  sac.setNormalDistanceWeight(0.1);
  sac.setDistanceThreshold(params_.plane_distance);
  sac.setMaxIterations(300);
  sac.setInputCloud(coarse);
  sac.setInputNormals(normals);
  pcl::PointIndices inliers;
  pcl::ModelCoefficients coefficients;
  sac.segment(inliers, coefficients);
  if (coefficients.values.size() != 4 || inliers.indices.size() < 3)
    return false;
  const auto& c = coefficients.values;
  plane_ = orientPlane(Eigen::Vector4f(c[0], c[1], c[2], c[3]),
                       input_->sensor_origin_.head(3));
  // Every input point near that plane supports it.
  plane_points.clear();
  for (const auto i : *indices_) {
    const auto& p = (*input_)[i];
    if (pcl::isFinite(p) &&
        std::abs(plane_.head<3>().dot(p.getVector3fMap()) + plane_[3]) < params_.plane_distance)
      plane_points.push_back(i);
  }
  return plane_points.size() >= params_.min_plane_points;
}

template <typename PointT>
void
TabletopSegmentation<PointT>::clusterOrganized(const pcl::Indices& objects,
                                               std::vector<pcl::PointIndices>& out) const
{
  // A sparse copy with only the object points finite: the connected components then never
  // visit the rest of the image.
  // (Buffers kept between calls: fresh VGA-sized allocations cost more in page faults than the
  // work done on them.)
  if (!masked_)
    masked_.reset(new pcl::PointCloud<pcl::PointXYZ>);
  const auto& masked = masked_;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  masked->points.assign(input_->size(), pcl::PointXYZ(nan, nan, nan));
  masked->width = input_->width;
  masked->height = input_->height;
  masked->is_dense = false;
  for (const auto i : objects)
    (*masked)[i].getVector3fMap() = (*input_)[i].getVector3fMap();
  pcl::EuclideanClusterComparator<pcl::PointXYZ, pcl::Label>::Ptr comparator(
    new pcl::EuclideanClusterComparator<pcl::PointXYZ, pcl::Label>);
  comparator->setInputCloud(masked);
  comparator->setDistanceThreshold(params_.cluster_tolerance, false);
  pcl::OrganizedConnectedComponentSegmentation<pcl::PointXYZ, pcl::Label> components(comparator);
  components.setInputCloud(masked);
  labels_.clear(); // PCL's segment() resizes without resetting: start empty (capacity stays)
  components.segment(labels_, out);
}

template <typename PointT>
void
TabletopSegmentation<PointT>::clusterUnorganized(const pcl::Indices& objects,
                                                 std::vector<pcl::PointIndices>& out) const
{
  if (objects.empty())
    return;
  // Euclidean clusters of one representative per voxel of a quarter of the tolerance (any two
  // points of neighbouring voxels are closer than the tolerance), then every point joins its
  // voxel's cluster: on dense sensor clouds the radius searches then return few neighbours.
  const float leaf = 0.25f * params_.cluster_tolerance;
  std::unordered_map<std::uint64_t, std::size_t> voxel_of_key;
  pcl::IndicesPtr representatives(new pcl::Indices);
  std::vector<std::size_t> voxel(objects.size());
  for (std::size_t k = 0; k < objects.size(); ++k) {
    const Eigen::Vector3f p = (*input_)[objects[k]].getVector3fMap() / leaf;
    const auto cell = [](float v) {
      return static_cast<std::uint64_t>(static_cast<std::int64_t>(std::floor(v)) + (1 << 20)) &
             0x1fffffULL;
    };
    const std::uint64_t key = cell(p.x()) | (cell(p.y()) << 21) | (cell(p.z()) << 42);
    const auto it = voxel_of_key.emplace(key, representatives->size());
    if (it.second)
      representatives->push_back(objects[k]);
    voxel[k] = it.first->second;
  }
  typename pcl::search::KdTree<PointT>::Ptr tree(new pcl::search::KdTree<PointT>);
  tree->setInputCloud(input_, representatives);
  pcl::EuclideanClusterExtraction<PointT> ec;
  ec.setClusterTolerance(params_.cluster_tolerance);
  ec.setMinClusterSize(1);
  ec.setMaxClusterSize(std::numeric_limits<pcl::uindex_t>::max());
  ec.setSearchMethod(tree);
  ec.setInputCloud(input_);
  ec.setIndices(representatives);
  std::vector<pcl::PointIndices> groups;
  ec.extract(groups);
  std::unordered_map<pcl::index_t, std::size_t> group_of;
  for (std::size_t g = 0; g < groups.size(); ++g)
    for (const auto i : groups[g].indices)
      group_of[i] = g;
  out.assign(groups.size(), pcl::PointIndices{});
  for (std::size_t k = 0; k < objects.size(); ++k)
    out[group_of.at((*representatives)[voxel[k]])].indices.push_back(objects[k]);
}

} // namespace facyl
