/*
 * facyl: fast cylinder detection for PCL.
 */
#pragma once

#include <facyl/segmentation/object_segmentation.h>
#include <facyl/segmentation/tabletop_geometry.h>

#include <pcl/ModelCoefficients.h>
#include <pcl/common/point_tests.h>
#include <pcl/common/transforms.h>
#include <pcl/PointIndices.h>
#include <pcl/pcl_base.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace facyl {

/** \brief Settings of TabletopSegmentation (lengths in cloud units, metres for sensors). */
struct TabletopSegmentationParameters {
  float plane_distance{0.015f};   ///< table inlier distance, > 0
  float plane_angle{0.05f};       ///< organized: normal deviation inside the plane (rad), > 0
  /** A plane needs this many points (full resolution) to be found; supports must also be
   * min_support_area large. */
  std::size_t min_plane_points{1000};
  float min_height{0.01f};        ///< objects: signed height above the support in
  float max_height{0.5f};         ///< [min_height, max_height], min < max
  /** How the object points are split into objects:
   * - EdgeAware (default): organized clouds are cut at depth discontinuities and concave
   *   creases, then fragments, enclosed parts and parts seen on both sides of an occluder are
   *   joined (segmentObjectsOrganized); unorganized clouds are first projected into a depth
   *   image from the sensor origin (the camera given with setCamera, else a pinhole looking at
   *   the objects), each point then taking its pixel's segment;
   * - Euclidean: connected components within cluster_tolerance (the paper's clustering). */
  enum class Clustering { Euclidean, EdgeAware } clustering{Clustering::EdgeAware};
  ObjectSegmentationParameters objects; ///< settings of the EdgeAware clustering
  float cluster_tolerance{0.02f}; ///< Euclidean cluster tolerance, > 0
  std::size_t min_cluster_size{300};
  std::size_t max_cluster_size{200000};
  /** A cluster is an object on a support if at least this share of its points lies over the
   * support's convex hull, in (0, 1] (1: every point, as pcl::ExtractPolygonalPrismData). */
  float min_hull_share{0.25f};
  /** Which planes support objects:
   * - ObjectsStanding (default): planes of at least min_support_area are candidates (with an
   *   up direction, only those within max_support_tilt of it); families of parallel candidates
   *   (a table, the floor, a shelf) compete by the object points standing on them; each
   *   cluster belongs to the nearest candidate of the winning family under it, and the table
   *   is the one with the most object points standing on it;
   * - LargestPlane: the plane with the most points is the table (the paper's choice). */
  enum class Support { LargestPlane, ObjectsStanding } support{Support::ObjectsStanding};
  float max_support_tilt{0.35f};  ///< rad, with an up direction: support normal vs up
  /** Supports are at least this large (m^2, the convex hull of their points): smaller planes
   * are faces of objects (a box top), and their points stay object points. */
  float min_support_area{0.1f};
  /** A cluster stands on a support when it reaches down to within this height of it. */
  float contact_height{0.03f};
  /** Organized: the plane search works on blocks of step x step pixels, in [0, 16]; 0
   * (default): the image width / 160 (4 at VGA), so that the search sees the same angular
   * grid at every resolution. */
  int plane_step{0};
  std::size_t plane_samples{20000}; ///< unorganized: points sampled for the plane search, >= 100
  std::size_t max_planes{6};      ///< support candidates examined, in [1, 8]
};

/** \brief Checks \a params. \return an empty string, or what is wrong. */
std::string
validate(const TabletopSegmentationParameters& params);

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

/** \brief One object above a support. */
struct TabletopCluster {
  pcl::PointIndices indices;   ///< into the input cloud, ascending
  PixelBox box{-1, -1, -1, -1}; ///< pixel box (organized input, or projection with a camera)
  Eigen::Vector3f centroid{Eigen::Vector3f::Zero()};
  int support{0};              ///< index into TabletopSegmentation::getSupports()
};

/** \brief A plane that objects stand on (a table, a shelf, the floor). */
struct SupportPlane {
  Eigen::Vector4f plane{Eigen::Vector4f::Zero()}; ///< unit normal towards the sensor
  /** z = the plane's normal (up), origin = centre of its points; maps plane coordinates to
   * the cloud's. */
  Eigen::Affine3f frame{Eigen::Affine3f::Identity()};
  pcl::PointIndices inliers;            ///< points within plane_distance (full resolution)
  std::vector<Eigen::Vector2f> polygon; ///< convex hull of the inliers, plane coordinates
  std::size_t objects{0};               ///< clusters assigned to it
  std::size_t standing_points{0};       ///< points of the clusters standing on it
};

/** \brief Supports (tables), objects above them, and object clusters (paper III-A).
 *
 * Candidate planes: organized clouds (at least 16 blocks wide and high) use
 * pcl::IntegralImageNormalEstimation and pcl::OrganizedMultiPlaneSegmentation on a grid of
 * blocks of plane_step pixels (each cell the mean of its pixels with depth, so missing pixels
 * do not break the normals), coplanar regions are joined; unorganized clouds (and narrower
 * organized ones: a LiDAR's few rings) use pcl::RandomSample, pcl::NormalEstimation and repeated
 * pcl::SACSegmentationFromNormals (SACMODEL_NORMAL_PLANE). Each candidate is refitted on its
 * points. Objects are the points within [min_height, max_height] above a candidate and on no
 * candidate, clustered (see Clustering). A cluster belongs to the nearest candidate under it
 * when at least min_hull_share of its points lie over that candidate's convex hull (the prism
 * test of pcl::ExtractPolygonalPrismData, per cluster, so objects at the border of the visible
 * table stay whole); clusters that hold up another candidate (table legs) are not objects. The
 * table is the candidate with the most object points standing on it; when nothing stands on any
 * candidate, the largest one (tableFound() is then false).
 *
 * \code
 * facyl::TabletopSegmentation<pcl::PointXYZRGBA> seg;
 * seg.setInputCloud(cloud);
 * std::vector<facyl::TabletopCluster> clusters;
 * if (seg.segment(clusters)) { seg.getTableCoefficients(); seg.getSupports(); ... }
 * \endcode
 * Bad input (no cloud, no finite point, no plane, invalid parameters) is reported with
 * PCL_ERROR and makes segment() return false with empty outputs. segment() is not reentrant on
 * one object; distinct objects may run concurrently.
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
  using PointCloudConstPtr = typename PointCloud::ConstPtr;

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
  /** \brief Camera for the boxes of unorganized clouds (organized clouds use pixel indices);
   * its focal length also sets the pixel footprint of organized clouds (else estimated). */
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
  /** \brief Gravity's opposite in the cloud's frame (e.g. from an IMU or tf): supports are
   * within max_support_tilt of horizontal. Zero (default): unknown, and "up" is the normal of
   * the family of parallel planes with the most points. */
  void
  setUpDirection(const Eigen::Vector3f& up)
  {
    up_ = up;
  }
  const Eigen::Vector3f&
  getUpDirection() const
  {
    return up_;
  }

  /** \brief Runs the segmentation. \return false (with PCL_ERROR) if no plane was found. */
  bool
  segment(std::vector<TabletopCluster>& clusters);

  /** \brief Moves the results of the last run (supports, table, hull, and \a clusters'
   * centroids) by the rigid transform \a t: for a caller that ran segment() on a copy of its
   * cloud in another frame. segment() itself does this for a cloud with a sensor pose. */
  void
  transformResults(const Eigen::Affine3f& t, std::vector<TabletopCluster>& clusters);

  /** \brief Supports of the last run that hold objects, and the table (always there). */
  const std::vector<SupportPlane>&
  getSupports() const
  {
    return supports_;
  }
  /** \brief Focal length in pixels of the last organized input (the camera's, or estimated
   * from the cloud); 0 for unorganized clouds. */
  float
  getFocalLength() const
  {
    return focal_;
  }
  /** \brief Index of the table in getSupports(). */
  std::size_t
  getTableIndex() const
  {
    return table_;
  }
  /** \brief False when no object stands on any plane: the table is then the largest plane. */
  bool
  tableFound() const
  {
    return table_found_;
  }
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
    return supports_.empty() ? identity_ : supports_[table_].frame;
  }
  /** \brief Table inliers (full resolution). */
  const pcl::PointIndices&
  getTableIndices() const
  {
    return supports_.empty() ? no_indices_ : supports_[table_].inliers;
  }
  /** \brief Vertices of the table's convex hull. */
  const PointCloud&
  getTableHull() const
  {
    return *hull_;
  }

private:
  /** A candidate plane: coefficients and the points that found it (grid or sample). */
  struct Candidate {
    Eigen::Vector4f plane;
    pcl::Indices points; ///< input indices
    std::size_t support{0}; ///< full-resolution points it stands for
  };
  /** Where a cluster goes among a family of supports. */
  struct Placement {
    int support{-1};      ///< index into supports_, -1: none (not over one, or a leg)
    bool standing{false}; ///< reaches down to it and is whole in its object band
  };

  /** The block size of the plane search on organized input (see plane_step). */
  int
  planeStep() const;
  /** True when the input is searched as an image (organized and at least 16 plane-grid cells
   * wide and high), else as a point set. */
  bool
  searchedAsImage() const;
  /** segment() on a cloud in the sensor's frame (identity sensor pose). */
  bool
  segmentInSensorFrame(std::vector<TabletopCluster>& clusters);
  bool
  findPlanesOrganized(std::vector<Candidate>& candidates);
  bool
  findPlanesUnorganized(std::vector<Candidate>& candidates);
  /** Least-squares refit; supports are large and (with an up direction) horizontal. */
  void
  keepSupportCandidates(std::vector<Candidate>& candidates) const;
  /** One pass over the points: each candidate's inliers; the candidates large enough are
   * the supports; the object band above them. */
  void
  classifyPoints(const std::vector<Candidate>& candidates, pcl::Indices& band);
  /** The candidates (indices) of the family of parallel planes that holds the supports. */
  std::vector<std::size_t>
  supportFamily(const std::vector<Candidate>& candidates,
                const std::vector<SupportPlane>& all) const;
  /** Area of the convex hull of the points that found \a c, in \a frame's plane. */
  float
  regionArea(const Candidate& c, const Eigen::Affine3f& frame) const;
  /** Convex hull of a support's points, in its plane's coordinates: on organized clouds
   * those near the region found as candidate \a c (every point when nullptr). */
  std::vector<Eigen::Vector2f>
  supportHull(const SupportPlane& support, const Candidate* c) const;
  void
  clusterOrganized(const pcl::Indices& objects, std::vector<pcl::Indices>& out) const;
  void
  clusterUnorganized(const pcl::Indices& objects, std::vector<pcl::Indices>& out) const;
  /** EdgeAware on unorganized clouds: the points projected into a depth image (the camera
   * given, else a pinhole at the sensor origin looking at the objects), segmented as an
   * organized frame; each point takes its pixel's segment. */
  void
  segmentProjected(const pcl::Indices& objects, std::vector<pcl::Indices>& out) const;
  /** The support of a cluster (points \a pts) among the supports of \a family. */
  Placement
  place(const Eigen::Matrix3Xf& pts, const std::vector<std::size_t>& family) const;
  /** Each cluster to the support under it; the table; supports without objects dropped. */
  void
  chooseSupports(std::vector<pcl::Indices>& groups, std::vector<TabletopCluster>& clusters);
  TabletopCluster
  makeCluster(pcl::Indices indices, int support) const;
  void
  reset();

  TabletopSegmentationParameters params_;
  PinholeCamera camera_;
  Eigen::Vector3f up_{Eigen::Vector3f::Zero()};
  std::vector<SupportPlane> supports_;
  std::vector<std::vector<Eigen::Vector2f>> extents_; ///< hulls of all the supports' points
  std::size_t table_{0};
  bool table_found_{false};
  float focal_{0.f}; ///< pixels (organized input)
  Eigen::Vector3f image_down_{Eigen::Vector3f::Zero()}; ///< organized input; zero: unknown
  pcl::ModelCoefficients table_coefficients_;
  typename PointCloud::Ptr hull_{new PointCloud};
  const Eigen::Affine3f identity_{Eigen::Affine3f::Identity()};
  const pcl::PointIndices no_indices_{};
  mutable pcl::PointCloud<pcl::PointXYZ>::Ptr masked_; ///< buffers of clusterOrganized
  mutable std::vector<std::uint8_t> has_depth_;
  mutable pcl::PointCloud<pcl::Label> labels_;
};

} // namespace facyl

#define FACYL_INSTANTIATE_TabletopSegmentation(T) template class facyl::TabletopSegmentation<T>;

#ifdef PCL_NO_PRECOMPILE
#include <facyl/segmentation/impl/tabletop_segmentation.hpp>
#endif
