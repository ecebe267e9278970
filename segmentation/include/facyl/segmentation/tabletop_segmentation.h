/*
 * facyl: fast cylinder detection for PCL.
 */
#pragma once

#include <facyl/segmentation/tabletop_geometry.h>

#include <pcl/ModelCoefficients.h>
#include <pcl/PointIndices.h>
#include <pcl/pcl_base.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <memory>
#include <string>
#include <vector>

namespace facyl {

/** \brief Settings of TabletopSegmentation (lengths in cloud units, metres for sensors). */
struct TabletopSegmentationParameters {
  float plane_distance{0.015f};   ///< table inlier distance, > 0
  float plane_angle{0.05f};       ///< organized: normal deviation inside the plane (rad), > 0
  std::size_t min_plane_points{3000}; ///< the table needs this many points (full resolution)
  float min_height{0.01f};        ///< objects: signed height above the table in
  float max_height{0.5f};         ///< [min_height, max_height], min < max
  float cluster_tolerance{0.02f}; ///< Euclidean cluster tolerance, > 0
  std::size_t min_cluster_size{300};
  std::size_t max_cluster_size{200000};
  /** A cluster is an object on the table if at least this share of its points lies over the
   * table's convex hull, in (0, 1] (1: every point, as pcl::ExtractPolygonalPrismData). */
  float min_hull_share{0.25f};
  int plane_step{4};              ///< organized: the plane search sees every step-th pixel, >= 1
  std::size_t plane_samples{20000}; ///< unorganized: points sampled for the plane search, >= 100
};

/** \brief Checks \a params. \return an empty string, or what is wrong. */
std::string
validate(const TabletopSegmentationParameters& params);

/** \brief One object above the table. */
struct TabletopCluster {
  pcl::PointIndices indices;   ///< into the input cloud, ascending
  PixelBox box{-1, -1, -1, -1}; ///< pixel box (organized input, or projection with a camera)
  Eigen::Vector3f centroid{Eigen::Vector3f::Zero()};
};

/** \brief Table plane, objects above it, and Euclidean clusters (paper III-A).
 *
 * Organized clouds (width x height > 1): normals by pcl::IntegralImageNormalEstimation and
 * planes by pcl::OrganizedMultiPlaneSegmentation on every plane_step-th pixel; the largest plane
 * is the table, refitted on its full-resolution inliers; clusters are connected components
 * (pcl::OrganizedConnectedComponentSegmentation with pcl::EuclideanClusterComparator) of the
 * points above it. Unorganized clouds: pcl::RandomSample, pcl::NormalEstimation and
 * pcl::SACSegmentationFromNormals (SACMODEL_NORMAL_PLANE) find the plane;
 * pcl::EuclideanClusterExtraction the clusters. In both cases the clusters are made of the points
 * within [min_height, max_height] above the plane (on the side of the sensor, whose position is
 * the cloud's sensor_origin_), and a cluster is kept when at least min_hull_share of its points
 * lie over the table's convex hull (pcl::ConvexHull; the prism test of
 * pcl::ExtractPolygonalPrismData, done per point in table coordinates, then per cluster, so
 * that objects at the border of the visible table are kept whole).
 *
 * \code
 * facyl::TabletopSegmentation<pcl::PointXYZRGBA> seg;
 * seg.setInputCloud(cloud);
 * std::vector<facyl::TabletopCluster> clusters;
 * if (seg.segment(clusters)) { seg.getTableCoefficients(); seg.getTableFrame(); ... }
 * \endcode
 * Bad input (no cloud, no finite point, no plane, invalid parameters) is reported with
 * PCL_ERROR and makes segment() return false with empty outputs.
 */
template <typename PointT>
class TabletopSegmentation : public pcl::PCLBase<PointT> {
public:
  using Ptr = std::shared_ptr<TabletopSegmentation<PointT>>;
  using ConstPtr = std::shared_ptr<const TabletopSegmentation<PointT>>;
  using PointCloud = pcl::PointCloud<PointT>;
  using pcl::PCLBase<PointT>::input_;
  using pcl::PCLBase<PointT>::indices_;
  using pcl::PCLBase<PointT>::fake_indices_;

  /** \brief All settings. */
  void
  setParameters(const TabletopSegmentationParameters& params)
  {
    params_ = params;
  }
  const TabletopSegmentationParameters&
  getParameters() const
  {
    return params_;
  }
  /** \brief Table inlier distance. */
  void
  setPlaneDistanceThreshold(float d)
  {
    params_.plane_distance = d;
  }
  /** \brief Objects are points whose height above the table is in [min, max]. */
  void
  setHeightLimits(float min_height, float max_height)
  {
    params_.min_height = min_height;
    params_.max_height = max_height;
  }
  /** \brief Euclidean cluster tolerance. */
  void
  setClusterTolerance(float tolerance)
  {
    params_.cluster_tolerance = tolerance;
  }
  /** \brief Cluster size limits (points). */
  void
  setClusterSizeLimits(std::size_t min_size, std::size_t max_size)
  {
    params_.min_cluster_size = min_size;
    params_.max_cluster_size = max_size;
  }
  /** \brief Camera for the boxes of unorganized clouds (organized clouds use pixel indices). */
  void
  setCamera(const PinholeCamera& camera)
  {
    camera_ = camera;
  }
  const PinholeCamera&
  getCamera() const
  {
    return camera_;
  }

  /** \brief Runs the segmentation. \return false (with PCL_ERROR) if no table was found. */
  bool
  segment(std::vector<TabletopCluster>& clusters);

  /** \brief Table plane (a, b, c, d), unit normal towards the sensor (SACMODEL_PLANE layout). */
  const pcl::ModelCoefficients&
  getTableCoefficients() const
  {
    return table_coefficients_;
  }
  /** \brief Table frame: z = table normal (up), origin = centre of the table points; maps table
   * coordinates to the cloud's. */
  const Eigen::Affine3f&
  getTableFrame() const
  {
    return table_frame_;
  }
  /** \brief Table inliers (full resolution for organized clouds). */
  const pcl::PointIndices&
  getTableIndices() const
  {
    return table_indices_;
  }
  /** \brief Vertices of the table's convex hull. */
  const PointCloud&
  getTableHull() const
  {
    return *hull_;
  }

private:
  bool
  findTableOrganized(pcl::Indices& plane_points);
  bool
  findTableUnorganized(pcl::Indices& plane_points);
  void
  clusterOrganized(const pcl::Indices& objects, std::vector<pcl::PointIndices>& out) const;
  void
  clusterUnorganized(const pcl::Indices& objects, std::vector<pcl::PointIndices>& out) const;
  void
  reset();

  TabletopSegmentationParameters params_;
  PinholeCamera camera_;
  Eigen::Vector4f plane_{Eigen::Vector4f::Zero()};
  pcl::ModelCoefficients table_coefficients_;
  Eigen::Affine3f table_frame_{Eigen::Affine3f::Identity()};
  pcl::PointIndices table_indices_;
  typename PointCloud::Ptr hull_{new PointCloud};
  mutable pcl::PointCloud<pcl::PointXYZ>::Ptr masked_; ///< buffers of clusterOrganized
  mutable pcl::PointCloud<pcl::Label> labels_;
};

} // namespace facyl

#define FACYL_INSTANTIATE_TabletopSegmentation(T) template class facyl::TabletopSegmentation<T>;

#ifdef PCL_NO_PRECOMPILE
#include <facyl/segmentation/impl/tabletop_segmentation.hpp>
#endif
