/*
 * facyl: fast cylinder detection for PCL.
 */
#pragma once

#include <facyl/segmentation/object_segmentation.h>
#include <facyl/segmentation/plane_search.h>
#include <facyl/segmentation/segment_tabletop.h>
#include <facyl/segmentation/support_planes.h>
#include <facyl/segmentation/tabletop_geometry.h>

#include <pcl/ModelCoefficients.h>
#include <pcl/PointIndices.h>
#include <pcl/common/point_tests.h>
#include <pcl/common/transforms.h>
#include <pcl/pcl_base.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace facyl {

/** \brief The sensor pose of \a cloud (sensor_origin_, sensor_orientation_), checked against an
 * even sample of its points (see plausibleSensorPose). */
template <typename PointT>
Eigen::Affine3f
plausibleSensorPose(const pcl::PointCloud<PointT>& cloud)
{
  const std::size_t step = std::max<std::size_t>(1, cloud.size() / 2000);
  Eigen::Matrix3Xf sample(3, static_cast<Eigen::Index>((cloud.size() + step - 1) / step));
  Eigen::Index n = 0;
  for (std::size_t i = 0; i < cloud.size(); i += step)
    sample.col(n++) = cloud[i].getVector3fMap();
  return plausibleSensorPose(sample.leftCols(n), cloud.sensor_origin_, cloud.sensor_orientation_);
}

/** \brief Largest |coordinate| of a point the tabletop pipeline processes: a thousand km in
 * metres, a km in millimetres. Finite points beyond it (a corrupt file, a sensor's error code)
 * are treated as missing: the float arithmetic of the searches (bounding boxes, squared
 * distances) overflows near them, and FLANN's k-d tree aborts on such a box. */
constexpr float kMaxCoordinate = 1e6f;

/** \brief True when every coordinate of \a p is within +-kMaxCoordinate (false for NaN). */
inline bool
withinCoordinateRange(const Eigen::Vector3f& p)
{
  return (p.array().abs() <= kMaxCoordinate).all();
}

/** \brief Number of finite points of \a cloud with a coordinate beyond +-kMaxCoordinate. */
template <typename PointT>
std::size_t
countFarPoints(const pcl::PointCloud<PointT>& cloud)
{
  std::size_t far = 0;
  for (const auto& p : cloud)
    far += pcl::isFinite(p) && !withinCoordinateRange(p.getVector3fMap());
  return far;
}

/** \brief The copy of \a cloud that the tabletop pipeline works on: moved to the sensor's frame
 * (the inverse of \a pose applied, sensor pose reset), every point outside
 * withinCoordinateRange there set to NaN (is_dense false when any is). */
template <typename PointT>
typename pcl::PointCloud<PointT>::Ptr
sensorFrameCopy(const pcl::PointCloud<PointT>& cloud, const Eigen::Affine3f& pose)
{
  typename pcl::PointCloud<PointT>::Ptr local(new pcl::PointCloud<PointT>);
  pcl::transformPointCloud(cloud, *local, pose.inverse());
  local->sensor_origin_ = Eigen::Vector4f::Zero();
  local->sensor_orientation_ = Eigen::Quaternionf::Identity();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (auto& p : *local)
    if (!withinCoordinateRange(p.getVector3fMap())) {
      p.x = p.y = p.z = nan;
      local->is_dense = false;
    }
  return local;
}

/** \brief Supports (tables), objects above them, and object clusters (paper III-A).
 *
 * Candidate planes: organized clouds (at least 16 blocks wide and high) use the normals of
 * pcl::IntegralImageNormalEstimation and the regions of pcl::OrganizedMultiPlaneSegmentation
 * (averageGradientNormals and planarRegions: the same results without PCL's per-call set-up)
 * on a grid of blocks of plane_step pixels (each cell the mean of its pixels with depth, so
 * missing pixels do not break the normals) for seed regions; unorganized clouds (and narrower
 * organized ones: a LiDAR's few rings) use pcl::RandomSample, pcl::NormalEstimation and repeated
 * pcl::SACSegmentation for seeds. Each seed grows into a whole plane with its own band
 * (refinePlaneRegion: the noise and bias measured on it, by range; regions of one noisy or
 * slightly bent table are one plane). Objects are the points between the band and max_height
 * above a candidate and on no candidate, clustered (see Clustering). A cluster belongs to the
 * nearest candidate under it when at least min_hull_share of its points lie over that
 * candidate's convex hull (the prism test of pcl::ExtractPolygonalPrismData, per cluster, so
 * objects at the border of the visible table stay whole); clusters that hold up another
 * candidate (table legs) are not objects.
 *
 * Which family of parallel planes holds the supports is decided by the objects standing on
 * them (the family with clearly the most objects standing on its planes), so that any camera
 * roll works without an up direction; an upright camera (supports facing the top of the image)
 * only breaks ties. The table is the candidate of that family with the most object points
 * standing on it; when nothing stands on any, the largest one (tableFound() is then false), and
 * the compact segments off the supports are objects too, with support -1 (a table without
 * depth: glossy or dark). Without a support prior, objects that float above the table found
 * (beyond its object band, nothing of them going on below it) over a region whose rays show
 * holes, not what lies beyond, stand on a top without depth: the frame is segmented again with
 * the plane of their bottoms, parallel to the table found, as an inferred prior
 * (supportUnderFloatingObjects), and that plane is the table when objects stand on it (organized
 * clouds without indices; on the lattice_width lattice too). A frame without any support (a wall, a
 * close-up) still gets its objects: the compact segments of the frame, with support -1,
 * tableFound() false and empty table coefficients.
 *
 * \code
 * facyl::TabletopSegmentation<pcl::PointXYZRGBA> seg;
 * seg.setInputCloud(cloud);
 * std::vector<facyl::TabletopCluster> clusters;
 * if (seg.segment(clusters)) { seg.getTableCoefficients(); seg.getSupports(); ... }
 * \endcode
 * Bad input (no cloud, no finite point, invalid parameters) is reported with PCL_ERROR and
 * makes segment() return false with empty outputs. segment() is not reentrant on one object;
 * distinct objects may run concurrently.
 *
 * The work is segmentTabletop's (segment_tabletop.h), on the x, y, z of the input (moved to the
 * sensor's frame when it is stored in another), with the scratch buffers of a TabletopWorkspace
 * that this object keeps from frame to frame; this class checks the input, holds the settings
 * and the results, and moves them back to the cloud's frame.
 */
template <typename PointT> class TabletopSegmentation : public pcl::PCLBase<PointT> {
public:
  using Ptr = std::shared_ptr<TabletopSegmentation<PointT>>;
  using ConstPtr = std::shared_ptr<const TabletopSegmentation<PointT>>;
  using PointCloud = pcl::PointCloud<PointT>;
  using pcl::PCLBase<PointT>::input_;
  using pcl::PCLBase<PointT>::indices_;
  using pcl::PCLBase<PointT>::fake_indices_;
  using PointCloudConstPtr = typename PointCloud::ConstPtr;

  /** \brief All settings. */
  void setParameters(const TabletopSegmentationParameters& params)
  {
    params_ = params;
  }
  const TabletopSegmentationParameters& getParameters() const
  {
    return params_;
  }
  /** \brief Table inlier distance. */
  void setPlaneDistanceThreshold(float d)
  {
    params_.plane_distance = d;
  }
  /** \brief Objects are points whose height above the table is in [min, max]. */
  void setHeightLimits(float min_height, float max_height)
  {
    params_.min_height = min_height;
    params_.max_height = max_height;
  }
  /** \brief Euclidean cluster tolerance. */
  void setClusterTolerance(float tolerance)
  {
    params_.cluster_tolerance = tolerance;
  }
  /** \brief Cluster size limits (points). */
  void setClusterSizeLimits(std::size_t min_size, std::size_t max_size)
  {
    params_.min_cluster_size = min_size;
    params_.max_cluster_size = max_size;
  }
  /** \brief Camera for the boxes of unorganized clouds (organized clouds use pixel indices);
   * its focal length also sets the pixel footprint of organized clouds (else estimated). */
  void setCamera(const PinholeCamera& camera)
  {
    camera_ = camera;
  }
  const PinholeCamera& getCamera() const
  {
    return camera_;
  }
  /** \brief Gravity's opposite in the cloud's frame (e.g. from an IMU or tf): supports are
   * within max_support_tilt of horizontal. Zero (default): unknown, and "up" is the normal of
   * the family of parallel planes with the most points. */
  void setUpDirection(const Eigen::Vector3f& up)
  {
    up_ = up;
  }
  const Eigen::Vector3f& getUpDirection() const
  {
    return up_;
  }
  /** \brief Threads for the per-pixel passes that run on several (the plane grid's pass, the
   * object segmentation's crease test), as PCL's setNumberOfThreads: 0 (default) the
   * hardware's concurrency, 1 the caller's thread alone; at most 64 (std::invalid_argument
   * beyond). More than one only while the helpers find idle cores (threadsForIdleCores). The
   * results are the same on any number; waiting threads sleep, never spin. */
  void setNumberOfThreads(unsigned int threads = 0)
  {
    if (threads > 64)
      throw std::invalid_argument("facyl::TabletopSegmentation::setNumberOfThreads: " +
                                  std::to_string(threads) + " threads is not in [0, 64]");
    workspace_.threads = static_cast<int>(threads);
  }
  unsigned int getNumberOfThreads() const
  {
    return static_cast<unsigned int>(workspace_.threads);
  }

  /** \brief Where the support of the last frames of a stream is expected in this cloud (in the
   * cloud's frame; see SupportPrior): the table is then that plane while a support is found
   * there and its family is preferred over the others; getSupportPriorResult() tells what
   * became of it. A
   * tracker sets it before each frame (CylinderTracker::prepare); the default, an invalid prior,
   * leaves every frame to itself. */
  void setSupportPrior(const SupportPrior& prior)
  {
    prior_ = prior;
  }
  const SupportPrior& getSupportPrior() const
  {
    return prior_;
  }
  /** \brief What the last run made of the support prior (given false without a valid one). */
  const SupportPriorResult& getSupportPriorResult() const
  {
    return prior_result_;
  }

  /** \brief Runs the segmentation. \return false (with PCL_ERROR) on bad input. */
  bool segment(std::vector<TabletopCluster>& clusters)
  {
    return run(clusters, true);
  }

  /** \brief segment() on an input known to be in the sensor's frame (plausibleSensorPose is
   * the identity) with every finite coordinate within kMaxCoordinate, as a caller that checked
   * the cloud or copied it there knows (TabletopCylinderRecognizer): the pass over the frame
   * that looks for its pose and far points is left out. Other input is segmented as if its
   * points were seen from the origin. */
  bool segmentInSensorFrame(std::vector<TabletopCluster>& clusters)
  {
    return run(clusters, false);
  }

  /** \brief Moves the results of the last run (supports, table, hull, and \a clusters'
   * centroids) by the rigid transform \a t: for a caller that ran segment() on a copy of its
   * cloud in another frame. segment() itself does this for a cloud with a sensor pose. */
  void transformResults(const Eigen::Affine3f& t, std::vector<TabletopCluster>& clusters);

  /** \brief Supports of the last run that hold objects, and the table (there unless the
   * frame showed no support at all). */
  const std::vector<SupportPlane>& getSupports() const
  {
    return supports_;
  }
  /** \brief Time per step of the last segment(). */
  const SegmentationTiming& getTiming() const
  {
    return timing_;
  }
  /** \brief Focal length in pixels of the last organized input (the camera's, or estimated
   * from the cloud); 0 for unorganized clouds. */
  float getFocalLength() const
  {
    return focal_;
  }
  /** \brief Index of the table in getSupports() (0 when there is none). */
  std::size_t getTableIndex() const
  {
    return table_;
  }
  /** \brief False when no object stands on any plane: the table is then the largest plane,
   * or there is none (getSupports() empty). */
  bool tableFound() const
  {
    return table_found_;
  }
  /** \brief Table plane (a, b, c, d), unit normal towards the sensor (SACMODEL_PLANE layout),
   * in the cloud's frame; no values when the frame showed no support. */
  const pcl::ModelCoefficients& getTableCoefficients() const
  {
    return table_coefficients_;
  }
  /** \brief Table frame: z = table normal (up), origin = centre of the table points; maps table
   * coordinates to the cloud's. */
  const Eigen::Affine3f& getTableFrame() const
  {
    return supports_.empty() ? identity_ : supports_[table_].frame;
  }
  /** \brief Table inliers (full resolution). */
  const pcl::PointIndices& getTableIndices() const
  {
    return supports_.empty() ? no_indices_ : supports_[table_].inliers;
  }
  /** \brief Vertices of the table's convex hull. */
  const PointCloud& getTableHull() const
  {
    return hull_;
  }

private:
  /** segment(); with \a check_pose false, segmentInSensorFrame(). */
  bool run(std::vector<TabletopCluster>& clusters, bool check_pose);
  /** Makes \a segments (of the input, in the sensor's frame) the results. */
  void adopt(TabletopSegments segments, std::vector<TabletopCluster>& clusters);
  void reset();

  TabletopSegmentationParameters params_;
  PinholeCamera camera_;
  Eigen::Vector3f up_{Eigen::Vector3f::Zero()};
  SupportPrior prior_;
  SupportPriorResult prior_result_;
  std::vector<SupportPlane> supports_;
  SegmentationTiming timing_;
  std::size_t table_{0};
  bool table_found_{false};
  float focal_{0.f}; ///< pixels (organized input)
  pcl::ModelCoefficients table_coefficients_;
  PointCloud hull_;
  const Eigen::Affine3f identity_{Eigen::Affine3f::Identity()};
  const pcl::PointIndices no_indices_{};
  TabletopWorkspace workspace_;
  /** The input's x, y, z for point types that do not start with them (see pointFrame). */
  std::vector<float> xyz_;
};

} // namespace facyl

#define FACYL_INSTANTIATE_TabletopSegmentation(T) template class facyl::TabletopSegmentation<T>;

#ifdef PCL_NO_PRECOMPILE
#include <facyl/segmentation/impl/tabletop_segmentation.hpp>
#endif
