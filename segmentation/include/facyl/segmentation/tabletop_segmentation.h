/*
 * facyl: fast cylinder detection for PCL.
 */
#pragma once

#include <facyl/segmentation/object_segmentation.h>
#include <facyl/segmentation/plane_search.h>
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
#include <string>
#include <vector>

namespace facyl {

/** \brief Settings of TabletopSegmentation (lengths in cloud units, metres for sensors). */
struct TabletopSegmentationParameters {
  /** Half-width of a support's inlier band (m), >= 0. 0 (default): measured on each support
   * from its own points, as band_factor x the robust scale of their distances from the plane
   * at each range from the sensor (see DepthBand): the noise and bias of the sensor at hand,
   * growing with range. > 0: this band at every range (the behaviour of earlier versions,
   * 0.015 there). */
  float plane_distance{0.f};
  float band_factor{3.f}; ///< measured bands: half-width in robust sigmas, in [1, 10]
  /** Organized: regions of the plane search grow between neighbours whose normals differ by
   * less than this (rad, > 0); a seed setting, the support's own normal tolerance is measured
   * (see PlaneRegionSettings). */
  float plane_angle{0.05f};
  /** A plane needs this many points (full resolution) to be found; supports must also be
   * min_support_area large. */
  std::size_t min_plane_points{1000};
  /** Objects are the points between min_height and max_height above their support, and above
   * its band (the points clearly off the support at their range; see plane_distance):
   * min_height (m, default 0) only raises the band's lower end. min < max. */
  float min_height{0.f};
  float max_height{0.5f};
  /** How the object points are split into objects:
   * - EdgeAware (default): organized clouds are cut at depth discontinuities and concave
   *   creases, then fragments, enclosed parts and parts seen on both sides of an occluder are
   *   joined (segmentObjectsOrganized); unorganized clouds are first projected into a depth
   *   image from the sensor origin (the camera given with setCamera, else a pinhole looking at
   *   the objects), each point then taking its pixel's segment;
   * - Euclidean: connected components within cluster_tolerance (the paper's clustering). */
  enum class Clustering { Euclidean, EdgeAware } clustering{Clustering::EdgeAware};
  ObjectSegmentationParameters objects; ///< settings of the EdgeAware clustering
  float cluster_tolerance{0.02f};       ///< Euclidean cluster tolerance, > 0
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
  float max_support_tilt{0.35f}; ///< rad, with an up direction: support normal vs up
  /** Supports are at least this large (m^2, the convex hull of their points; a stool or a
   * chair-arm tablet shows 0.05 m^2): smaller planes are faces of objects, and their points
   * stay object points. */
  float min_support_area{0.04f};
  /** A plane inside the object band of a larger parallel support (a shelf, a box top) is a
   * support only when the region found on it is at least this large (m^2): smaller ones are
   * the tops of objects standing on the larger support. Planes of other orientations this large
   * (walls, a floor seen from a low camera) are structure: their points are never object
   * points (smaller ones may be the faces of boxes). */
  float min_shelf_area{0.1f};
  /** A cluster stands on a support when it reaches down to within this height of the
   * support's band (m): the lowest visible points of an object are above its contact. */
  float contact_height{0.03f};
  /** Organized: the plane search works on blocks of step x step pixels, in [0, 16]; 0
   * (default): the image width / 160 (4 at VGA), so that the search sees the same angular
   * grid at every resolution. */
  int plane_step{0};
  /** Speed for accuracy on large frames (0, the default: off). Organized frames wider than 1.5
   * times this many pixels are segmented on a lattice of every s-th pixel and row, s =
   * round(width / lattice_width) (640: a 1280 x 720 frame at 640 x 360, about as a VGA frame),
   * and each object and support then takes the pixels of its lattice pixels' s x s blocks that
   * continue its surface. On simulated 1280 x 720 frames it took the segmentation from about
   * 43 to 22-23 ms, and detected 38 cylinders instead of 41 on the realistic layout
   * (docs/speed.md, "1280 x 720 frames"). 0 or in [160, 8192]. */
  int lattice_width{0};
  std::size_t plane_samples{20000}; ///< unorganized: points sampled for the plane search, >= 100
  std::size_t max_planes{6};        ///< support candidates examined, in [1, 8]
};

/** \brief Checks \a params. \return an empty string, or what is wrong. */
std::string validate(const TabletopSegmentationParameters& params);

/** \brief The distance threshold (m, scaled by depth^2 inside PCL) with which
 * pcl::OrganizedMultiPlaneSegmentation grows the seed regions of the plane search when
 * plane_distance is 0: it only makes seeds; each support's band is measured on it afterwards. */
constexpr float kSeedDistance = 0.015f;

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

template <typename PointT> class TabletopCylinderRecognizer;

/** \brief Wall-clock time per step of the last TabletopSegmentation::segment() (ms). */
struct SegmentationTiming {
  double planes{0.0};  ///< the plane grid, its seeds and their regions (the candidates)
  double points{0.0};  ///< every point sorted onto and above the candidates (one pass)
  double objects{0.0}; ///< the families of supports tried, the objects clustered and placed
  double total{0.0};
};

/** \brief One object above a support. */
struct TabletopCluster {
  pcl::PointIndices indices;    ///< into the input cloud, ascending
  PixelBox box{-1, -1, -1, -1}; ///< pixel box (organized input, or projection with a camera)
  Eigen::Vector3f centroid{Eigen::Vector3f::Zero()};
  int support{0}; ///< index into TabletopSegmentation::getSupports()
};

/** \brief A plane that objects stand on (a table, a shelf, the floor). */
struct SupportPlane {
  Eigen::Vector4f plane{Eigen::Vector4f::Zero()}; ///< unit normal towards the sensor
  /** z = the plane's normal (up), origin = centre of its points; maps plane coordinates to
   * the cloud's. */
  Eigen::Affine3f frame{Eigen::Affine3f::Identity()};
  pcl::PointIndices inliers; ///< points within the band (full resolution)
  /** Distance from the plane that its points keep, by range from the sensor: the support's
   * measured noise and bias (or the fixed plane_distance). */
  DepthBand band;
  std::vector<Eigen::Vector2f> polygon; ///< convex hull of the inliers, plane coordinates
  std::size_t objects{0};               ///< clusters assigned to it
  std::size_t standing_points{0};       ///< points of the clusters standing on it
};

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
 * depth: glossy or dark). A frame without any support (a wall, a close-up) still gets its
 * objects: the compact segments of the frame, with support -1, tableFound() false and empty
 * table coefficients.
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

  /** \brief Runs the segmentation. \return false (with PCL_ERROR) on bad input. */
  bool segment(std::vector<TabletopCluster>& clusters)
  {
    return run(clusters, true);
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
    return *hull_;
  }

private:
  /** A candidate plane: coefficients, band and the points of the region found on it. */
  struct Candidate {
    Eigen::Vector4f plane{Eigen::Vector4f::Zero()};
    DepthBand band;
    pcl::Indices points;    ///< input indices, one per cell of the region (grid or sample)
    std::size_t support{0}; ///< full-resolution points it stands for
  };
  /** A point above some candidate: the candidates it lies on and above (bit masks). */
  using Above = PointOverPlanes;
  /** Where a cluster goes among the supports. */
  struct Placement {
    int support{-1};      ///< index into supports_, -1: none (not over one, or a leg)
    bool standing{false}; ///< reaches down to it and is whole in its object band
  };
  /** The supports and objects of one family of parallel candidates. */
  struct Trial {
    std::vector<SupportPlane> supports;
    std::vector<TabletopCluster> clusters;
    std::size_t table{0};
    std::size_t standing{0};         ///< object points standing on the supports
    std::size_t standing_objects{0}; ///< objects standing on them
  };

  /** The block size of the plane search on organized input (see plane_step). */
  int planeStep() const;
  /** True when the input is searched as an image (organized and at least 16 plane-grid cells
   * wide and high), else as a point set. */
  bool searchedAsImage() const;
  /** segment() on a cloud in the sensor's frame (identity sensor pose): on the lattice of
   * latticeStep(), or on every pixel (segmentFrame). */
  bool segmentInSensorFrame(std::vector<TabletopCluster>& clusters);
  /** segmentInSensorFrame on every pixel of the input. */
  bool segmentFrame(std::vector<TabletopCluster>& clusters);
  /** The lattice step of lattice_width for the input: 1 for point sets, given indices and
   * frames up to 1.5 lattice_width wide. */
  int latticeStep() const;
  /** segmentFrame on the lattice of every \a step-th pixel and row (latticeOf), the clusters
   * and supports then brought to full resolution (blockPixels). */
  bool segmentOnLattice(std::vector<TabletopCluster>& clusters, int step);
  /** The settings on the lattice of \a step: counts of points scaled by 1 / step^2. */
  TabletopSegmentationParameters latticeParameters(int step) const;
  /** The clusters \a coarse of the \a lattice of \a step, with the pixels of the (full) input
   * that continue them, as \a clusters (largest first). */
  void clustersAtFullResolution(const std::vector<TabletopCluster>& coarse,
                                const PointCloud& lattice, int step,
                                std::vector<TabletopCluster>& clusters) const;
  /** The supports' inliers of the lattice of \a step, as the pixels of their blocks within
   * their bands. */
  void supportsAtFullResolution(int step);
  /** segment(); with \a check_pose false, the cloud is known to be in the sensor's frame and
   * within kMaxCoordinate (the recognizer's own checks, or its copy, made it so): its sensor
   * pose and far points are not looked for again (a pass over the frame). */
  bool run(std::vector<TabletopCluster>& clusters, bool check_pose);
  template <typename> friend class TabletopCylinderRecognizer; // runs run(clusters, false)
  /** The grid of blocks of \a step pixels: each cell the mean of the pixels of its block with
   * depth near the first one's, its normal, and its first pixel; with \a twice, also the grid
   * of 2 \a step pixels, from the same pass over the image. */
  void planeGrid(int step, PlaneGrid& grid, PlaneGrid* twice = nullptr) const;
  void findPlanesOrganized(std::vector<Candidate>& candidates);
  /** Grows \a seeds of \a grid into candidates (growCandidate), skipping the seeds mostly on
   * the cells of \a candidates found before; appends them. */
  void growCandidates(const PlaneGrid& grid, const std::vector<pcl::PointIndices>& seeds,
                      std::vector<Candidate>& candidates) const;
  void findPlanesUnorganized(std::vector<Candidate>& candidates);
  /** The seed threshold of the plane search: plane_distance, or kSeedDistance. */
  float seedDistance() const;
  /** How seeds grow into planes: the band measured, or plane_distance. */
  PlaneRegionSettings regionSettings() const;
  /** Grows \a seed (cells of \a cells) into a candidate; cells already \a taken by earlier
   * candidates stay with them, the new ones are marked. \a source maps cells to input
   * indices, \a cell_points is the number of pixels a cell stands for.
   * \return false when the region is not a plane of min_plane_points. */
  bool growCandidate(const PlaneRegionCells& cells, const std::vector<std::uint8_t>& seed,
                     const std::vector<pcl::index_t>& source, std::size_t cell_points,
                     std::vector<std::uint8_t>& taken, Candidate& out) const;
  /** Supports span a plane that does not pass by the sensor, are not a part of a larger
   * candidate, and (with an up direction) are horizontal. */
  void keepSupportCandidates(std::vector<Candidate>& candidates) const;
  /** One pass over the points: each candidate's inliers (in \a all) and the points above
   * some candidate. */
  void classifyPoints(const std::vector<Candidate>& candidates, std::vector<SupportPlane>& all,
                      std::vector<Above>& above) const;
  /** The families of parallel candidates, those an upright camera would see facing up first,
   * then by their number of points. */
  std::vector<std::vector<std::size_t>> rankFamilies(const std::vector<Candidate>& candidates,
                                                     const std::vector<SupportPlane>& all) const;
  /** The supports of \a family (large enough, see min_support_area) and the objects on
   * them, on every \a stride-th pixel and row of an organized input (1: all; larger: only the
   * standing points are counted, to compare families). \a final: the result (the family's
   * planes are moved out of \a all). */
  Trial tryFamily(const std::vector<std::size_t>& family, const std::vector<Candidate>& candidates,
                  std::vector<SupportPlane>& all, const std::vector<Above>& above, int stride,
                  bool final);
  /** The pixel stride of the coarse trials of families (1 for point sets). */
  int coarseStride() const;
  /** Of a candidate's \a region, the points that can be vertices of its convex hull: on an
   * image, each row's first and last (rowExtremes); all of them in a point set. */
  pcl::Indices hullCandidates(const pcl::Indices& region) const;
  /** Area of the convex hull of the points that found \a c, in \a frame's plane. */
  float regionArea(const Candidate& c, const Eigen::Affine3f& frame) const;
  /** Convex hull of a support's \a inliers, in the coordinates of its plane's \a frame: on
   * organized clouds those near the region found as candidate \a c (every point when
   * nullptr). */
  std::vector<Eigen::Vector2f> supportHull(const Eigen::Affine3f& frame,
                                           const pcl::Indices& inliers, const Candidate* c) const;
  /** The object points split into clusters (see Clustering). */
  void cluster(const pcl::Indices& objects, std::vector<pcl::Indices>& out) const;
  /** cluster() on a grid of every \a stride-th pixel and row of an organized input (\a objects
   * on that grid), without joining parts seen around occluders: the clusters hold those
   * pixels only (enough to count the objects standing on a family of supports). */
  void clusterCoarse(const pcl::Indices& objects, int stride, std::vector<pcl::Indices>& out) const;
  void clusterOrganized(const pcl::Indices& objects, std::vector<pcl::Indices>& out) const;
  void clusterUnorganized(const pcl::Indices& objects, std::vector<pcl::Indices>& out) const;
  /** EdgeAware on unorganized clouds: the points projected into a depth image (the camera
   * given, else a pinhole at the sensor origin looking at the objects), segmented as an
   * organized frame; each point takes its pixel's segment. */
  void segmentProjected(const pcl::Indices& objects, std::vector<pcl::Indices>& out) const;
  /** The support of a cluster (points \a pts) among supports_. */
  Placement place(const Eigen::Matrix3Xf& pts) const;
  /** Each cluster to the support under it; the table; supports without objects dropped.
   * \a scale: the points each point of \a groups stands for (coarse trials, which keep no
   * clusters). */
  void assignClusters(std::vector<pcl::Indices>& groups, Trial& trial, std::size_t scale);
  /** Makes \a trial the result: supports, table, its coefficients and hull. */
  void adopt(Trial trial, std::vector<TabletopCluster>& clusters);
  /** No support in view (or none that objects stand on): the compact segments of the frame
   * (of its points not flagged in \a taken) are objects too, with support -1. */
  void segmentWithoutSupport(std::vector<TabletopCluster>& clusters,
                             const std::vector<std::uint8_t>* taken = nullptr);
  TabletopCluster makeCluster(pcl::Indices indices, int support) const;
  void reset();

  TabletopSegmentationParameters params_;
  PinholeCamera camera_;
  Eigen::Vector3f up_{Eigen::Vector3f::Zero()};
  std::vector<SupportPlane> supports_;
  SegmentationTiming timing_;
  std::vector<std::vector<Eigen::Vector2f>> extents_; ///< hulls of all the supports' points
  /** Per candidate of the last run: its hulls (see supportHull) and region area, computed once
   * for all the trials of its family. */
  struct Hulls {
    bool known{false};
    std::vector<Eigen::Vector2f> polygon, extent;
    float region{0.f};
  };
  std::vector<Hulls> hulls_;
  DepthBand noise_; ///< the band of the largest plane of the last run
  bool has_noise_{false};
  std::size_t table_{0};
  bool table_found_{false};
  float focal_{0.f};                                    ///< pixels (organized input)
  Eigen::Vector3f image_down_{Eigen::Vector3f::Zero()}; ///< organized input; zero: unknown
  pcl::ModelCoefficients table_coefficients_;
  typename PointCloud::Ptr hull_{new PointCloud};
  const Eigen::Affine3f identity_{Eigen::Affine3f::Identity()};
  const pcl::PointIndices no_indices_{};
  mutable pcl::PointCloud<pcl::PointXYZ>::Ptr masked_; ///< buffers of clusterOrganized
  mutable pcl::Indices masked_written_;                ///< the finite pixels of masked_
  mutable std::vector<std::uint8_t> has_depth_;        ///< per pixel of the input: finite
  mutable bool has_depth_known_{false}; ///< has_depth_ is this run's (planeGrid fills it)
  mutable pcl::PointCloud<pcl::Label> labels_;
  /** classifyPoints' lists of each candidate's points, a slice that could take every point
   * each. Not initialised (a frame touches only the pages it writes) and not copied with the
   * segmentation (a copy starts with none). */
  struct SortBuffer {
    std::unique_ptr<pcl::index_t[]> data;
    std::size_t size{0};
    SortBuffer() = default;
    SortBuffer(const SortBuffer&) {}
    SortBuffer& operator=(const SortBuffer&)
    {
      return *this;
    }
  };
  mutable SortBuffer on_buffer_;
  /** classifyPoints' points above the candidates, kept between frames for its capacity (the
   * list of a VGA frame grows to about 10^5 points). */
  std::vector<Above> above_;
};

} // namespace facyl

#define FACYL_INSTANTIATE_TabletopSegmentation(T) template class facyl::TabletopSegmentation<T>;

#ifdef PCL_NO_PRECOMPILE
#include <facyl/segmentation/impl/tabletop_segmentation.hpp>
#endif
