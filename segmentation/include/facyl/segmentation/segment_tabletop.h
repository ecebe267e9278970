/*
 * facyl: fast cylinder detection for PCL.
 * The tabletop segmentation as a plain core: one function over the x, y, z of a frame in the
 * sensor's frame, its camera and its settings, returning supports and objects as values; its
 * scratch buffers in a workspace that the caller owns and reuses between frames.
 * TabletopSegmentation (tabletop_segmentation.h) is the PCL front over it.
 */
#pragma once

#include <facyl/segmentation/object_segmentation.h>
#include <facyl/segmentation/plane_search.h>
#include <facyl/segmentation/support_planes.h>
#include <facyl/segmentation/tabletop_geometry.h>

#include <pcl/PCLHeader.h>
#include <pcl/PointIndices.h>
#include <pcl/point_cloud.h>
#include <pcl/point_struct_traits.h>
#include <pcl/point_types.h>

#include <Eigen/Geometry>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <type_traits>
#include <utility>
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
   * round(width / lattice_width) (640: a 1280 x 720 frame at 640 x 360, about as a VGA frame;
   * see latticeStep), and each object and support then takes the pixels of its lattice pixels'
   * s x s blocks that continue its surface. It trades a few objects for time: measured in
   * docs/speed.md, "The whole segmentation on a lattice". 0 or in [160, 8192]. */
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

/** \brief Where the support of the last frames of a stream is expected in this one (the
 * tracker's prediction, CylinderTracker::supportPrior): the segmentation then prefers it as the
 * table, and its family of parallel planes over the others, so that a wall or a far plane that
 * holds more objects in one frame does not replace it. A default (invalid) prior changes
 * nothing: a single frame is segmented alone. (It does not make a plane the plane search missed:
 * grown from the cells near the predicted plane, a dark or glossy table with few depth pixels
 * gave mixtures of it, the table beside it and the objects, bands of +-0.15 m, on the 7-Scenes
 * stream.) A frame's plane is the prior's (consistentWithPrior) when its
 * normal lies within max_angle of the prior's and it passes within max_offset of the prior's
 * centre, where the support was seen last: the tolerances of the prediction (how far the
 * camera's motion may have moved the plane since it was measured, and how far its estimate
 * varies from frame to frame), which is best there (away from it an error of the predicted
 * tilt grows with the distance). */
struct SupportPrior {
  /** a, b, c, d with a unit normal towards the sensor, in the frame of the points segmented;
   * zero: no prior. */
  Eigen::Vector4f plane{Eigen::Vector4f::Zero()};
  /** A point of the plane where the support was seen last (the centre of its points). */
  Eigen::Vector3f centre{Eigen::Vector3f::Zero()};
  /** rad, in (0, pi/2]: how far the predicted normal may be off. */
  float max_angle{0.f};
  /** m, >= 0: how far the predicted plane may be off along its normal at the centre. */
  float max_offset{0.f};
  /** Points of the support's extent as the last frames saw it (the corners of their regions'
   * hulls, on the plane, in the frame of the points segmented); empty: none. A support that is
   * the prior's plane holds the objects over them too (priorExtentHull): a frame that sees less
   * of a table (a dark or glossy top, a view that cuts it) keeps the objects the stream saw on
   * it. */
  std::vector<Eigen::Vector3f> extent;

  /** \brief True when the prior holds a plane and a usable angle (else it is ignored). */
  bool valid() const
  {
    return plane.allFinite() && centre.allFinite() &&
           std::abs(plane.head<3>().norm() - 1.f) < 1e-3f && max_angle > 0.f &&
           max_angle <= 1.5708f && max_offset >= 0.f && std::isfinite(max_offset);
  }
  /** \brief \a prior moved by the rigid transform \a t (its plane, centre and extent). */
  SupportPrior transformed(const Eigen::Affine3f& t) const;
};

/** \brief True when \a plane (a, b, c, d, unit normal towards the sensor) is \a prior's plane
 * (see SupportPrior): its normal within max_angle of the prior's, its height at the prior's
 * centre within max_offset. */
bool consistentWithPrior(const SupportPrior& prior, const Eigen::Vector4f& plane);

/** \brief How far \a plane is from \a prior's: the larger of its normal's angle over max_angle
 * and its height at the prior's centre over max_offset, in [0, 1] when consistentWithPrior,
 * infinity when not. Of several planes that are the prior's, the nearest has the least. */
float priorMismatch(const SupportPrior& prior, const Eigen::Vector4f& plane);

/** \brief The convex hull of \a polygon (a support's region hull, in the coordinates of its
 * plane's frame \a plane_to_frame) and of \a prior's extent projected on that plane: the
 * support's hull when it is \a prior's plane (consistentWithPrior of \a plane), else
 * \a polygon unchanged. */
std::vector<Eigen::Vector2f> priorExtentHull(const SupportPrior& prior,
                                             const Eigen::Vector4f& plane,
                                             const Eigen::Affine3f& plane_to_frame,
                                             const std::vector<Eigen::Vector2f>& polygon);

/** \brief What a segmentation made of its SupportPrior. */
struct SupportPriorResult {
  bool given{false}; ///< a valid prior was given
  /** The support (index into the supports) that is the prior's plane, -1: none was found. */
  int support{-1};
  /** The frame alone would have chosen another family of supports, which holds more objects
   * standing on it than the prior's (of parallel supports, the prior's stays the table while it
   * is in view: its objects are found on every one of them alike). */
  bool challenged{false};
  /** The prior's plane was none of the frame's planes (a dark or glossy top without depth in
   * this frame): \a support is the prior's plane moved to the few points near it, which the
   * image did not refute. A tracker takes no motion from it. */
  bool predicted{false};
};

/** \brief Wall-clock time per step of a segmentation (ms). */
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

/** \brief The points a segmentation reads: the x, y and z of point i are the floats
 * xyz[i * stride], xyz[i * stride + 1], xyz[i * stride + 2]. It refers to memory it does not
 * own (a PCL cloud's points, see pointFrame), which must outlive it. */
struct PointFrame {
  const float* xyz{nullptr};
  /** Floats from one point to the next, >= 3; >= 4 (the fourth float of each point readable)
   * lets the pixel sort read four points at a time. */
  std::size_t stride{4};
  std::size_t size{0};                  ///< points
  std::uint32_t width{0}, height{1};    ///< as pcl::PointCloud's: organized when height > 1
  const pcl::Indices* indices{nullptr}; ///< the points to segment; nullptr: every point
  Eigen::Vector3f viewpoint{Eigen::Vector3f::Zero()}; ///< the sensor origin
  pcl::PCLHeader header;                              ///< given to the outputs' indices
  /** The points' colours (blue, green, red bytes of point i at bgr + i * bgr_stride), or
   * nullptr: none. */
  const std::uint8_t* bgr{nullptr};
  std::size_t bgr_stride{0};

  bool isOrganized() const
  {
    return height > 1;
  }
  Eigen::Map<const Eigen::Vector3f> point(std::size_t i) const
  {
    return Eigen::Map<const Eigen::Vector3f>(xyz + i * stride);
  }
  /** \brief pcl::isFinite of point \a i: x, y and z finite. */
  bool finite(std::size_t i) const
  {
    const float* p = xyz + i * stride;
    return std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]);
  }
};

/** \brief The PointFrame of \a cloud (sensor origin, header, organization) with \a indices
 * (nullptr: every point). PCL's point types start with x, y, z (PCL_ADD_POINT4D): the frame
 * reads the cloud's own memory. Other types are copied into \a buffer (four floats a point),
 * which must then outlive the frame. */
template <typename PointT>
PointFrame
pointFrame(const pcl::PointCloud<PointT>& cloud, const pcl::Indices* indices,
           std::vector<float>& buffer)
{
  PointFrame f;
  f.size = cloud.size();
  f.width = cloud.width;
  f.height = cloud.height;
  f.indices = indices;
  f.viewpoint = cloud.sensor_origin_.template head<3>();
  f.header = cloud.header;
  // The colours: PCL's rgba or rgb field (blue, green, red, alpha bytes).
  using RgbField = std::conditional_t<pcl::traits::has_field<PointT, pcl::fields::rgba>::value,
                                      pcl::fields::rgba, pcl::fields::rgb>;
  if constexpr (pcl::traits::has_field<PointT, RgbField>::value)
    if (!cloud.empty()) {
      f.bgr = reinterpret_cast<const std::uint8_t*>(cloud.points.data()) +
              pcl::traits::offset<PointT, RgbField>::value;
      f.bgr_stride = sizeof(PointT);
    }
  if constexpr (pcl::traits::offset<PointT, pcl::fields::x>::value == 0 &&
                pcl::traits::offset<PointT, pcl::fields::y>::value == 4 &&
                pcl::traits::offset<PointT, pcl::fields::z>::value == 8 &&
                sizeof(PointT) % sizeof(float) == 0 && sizeof(PointT) >= 4 * sizeof(float)) {
    f.xyz = reinterpret_cast<const float*>(cloud.points.data());
    f.stride = sizeof(PointT) / sizeof(float);
  }
  else {
    buffer.resize(4 * cloud.size());
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      float* q = buffer.data() + 4 * i;
      q[0] = cloud[i].x, q[1] = cloud[i].y, q[2] = cloud[i].z, q[3] = 1.f;
    }
    f.xyz = buffer.data();
    f.stride = 4;
  }
  return f;
}

namespace detail {
/** A std::allocator whose value-less construct() leaves the value uninitialised: a vector of
 * such grows to a frame's size without writing every element first. */
template <typename T> struct UninitialisedAllocator : std::allocator<T> {
  template <typename U> struct rebind {
    using other = UninitialisedAllocator<U>;
  };
  UninitialisedAllocator() = default;
  template <typename U> UninitialisedAllocator(const UninitialisedAllocator<U>&) noexcept {}
  template <typename U>
  void construct(U* p) noexcept(std::is_nothrow_default_constructible<U>::value)
  {
    ::new (static_cast<void*>(p)) U;
  }
  template <typename U, typename... Args> void construct(U* p, Args&&... args)
  {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};
} // namespace detail

/** \brief The scratch buffers of segmentTabletop, owned by its caller and reused from frame to
 * frame (of any size): a VGA frame's buffers run to megabytes, and fresh ones cost more in page
 * faults and fills than the work done on them (docs/speed.md, "First frames"). What they hold
 * between calls has no meaning: a workspace used before gives the same results as a new one,
 * and a copy of a workspace is a new one (copying scratch would only cost time). Not to be
 * used by two calls at a time. */
struct TabletopWorkspace {
  TabletopWorkspace() = default;
  TabletopWorkspace(const TabletopWorkspace& other)
      : threads(other.threads)
  {
  }
  TabletopWorkspace& operator=(const TabletopWorkspace& other)
  {
    threads = other.threads;
    return *this;
  }
  TabletopWorkspace(TabletopWorkspace&&) = default;
  TabletopWorkspace& operator=(TabletopWorkspace&&) = default;

  /** The pixel sort's lists of each candidate's points: a slice per candidate that could take
   * every point, so the sort tests no growth per point; left uninitialised (a frame touches
   * only the pages it writes). */
  std::vector<pcl::index_t, detail::UninitialisedAllocator<pcl::index_t>> on_planes;
  std::vector<PointOverPlanes> above;  ///< the pixel sort's points above some candidate
  std::vector<std::uint8_t> has_depth; ///< organized frames: per pixel, finite
  /** The Euclidean clustering of organized frames: a copy of the frame with only the object
   * points finite, and the pixels last written (the only ones cleared for the next call). */
  pcl::PointCloud<pcl::PointXYZ> masked;
  pcl::Indices masked_written;
  pcl::PointCloud<pcl::Label> labels;
  /** The points of the lattice (lattice_width), four floats each; left uninitialised. */
  std::vector<float, detail::UninitialisedAllocator<float>> lattice;
  /** The colours of the lattice's points (blue, green, red bytes), when the frame has them. */
  std::vector<std::uint8_t, detail::UninitialisedAllocator<std::uint8_t>> lattice_colours;
  /** Threads for the per-pixel passes that run on several (the plane grid's pass, the object
   * segmentation's crease test): 0 the hardware's concurrency, 1 the caller's alone; more than
   * one only while the helpers find idle cores (threadsForIdleCores: beside busy processes a
   * preempted helper would stall the pass). The segments are the same on any number. Kept by
   * copies, unlike the buffers. */
  int threads{0};
};

/** \brief The supports and objects of a frame. */
struct TabletopSegments {
  std::vector<TabletopCluster> clusters; ///< largest first
  /** The supports that hold objects, and the table (there unless the frame showed no
   * support at all). */
  std::vector<SupportPlane> supports;
  std::size_t table{0};      ///< index into supports
  bool table_found{false};   ///< some object stands on the table
  float focal{0.f};          ///< pixels (organized frames: the camera's, or estimated); else 0
  SegmentationTiming timing; ///< its steps, and their total
  SupportPriorResult prior;  ///< what became of the prior (given false without one)
};

/** \brief Supports, objects above them and object clusters of \a frame (paper III-A; the steps:
 * TabletopSegmentation's description).
 * \param frame   in the sensor's frame (depth along the line of sight; its viewpoint the sensor
 *                origin, any rotation undone: see sensorFrameCopy), every finite coordinate
 *                within kMaxCoordinate (tabletop_segmentation.h).
 * \param camera  the sensor's intrinsics (PinholeCamera::valid(), cameraUsable), or an
 *                invalid one: unknown.
 * \param up      gravity's opposite in the sensor's frame, or zero: unknown.
 * \param params  valid settings (validate).
 * \param workspace  scratch buffers (see TabletopWorkspace).
 * \param prior   where the last frames' support is expected (in the sensor's frame, as \a frame);
 *                nullptr or an invalid one: none, the frame alone decides.
 * \throws std::invalid_argument on invalid \a params, an unusable valid \a camera, a non-finite
 *         \a up, or a frame without points memory or with a stride below 3. */
TabletopSegments segmentTabletop(const PointFrame& frame, const PinholeCamera& camera,
                                 const Eigen::Vector3f& up,
                                 const TabletopSegmentationParameters& params,
                                 TabletopWorkspace& workspace, const SupportPrior* prior = nullptr);

/** \brief The lattice step of \a params.lattice_width for a frame: s = round(width /
 * lattice_width) for organized frames searched as images (at least 16 plane-grid cells wide
 * and high) that are wider than 1.5 lattice_width and come without indices; else 1 (every
 * pixel). */
int latticeStep(const PointFrame& frame, const TabletopSegmentationParameters& params);

/** \brief \a params for the lattice of \a step (> 1): a lattice point stands for step^2
 * pixels, so counts of points (min_plane_points, cluster sizes, objects.min_fragment) scale
 * by 1 / step^2 (at least 1; the largest cluster at least the smallest) and a given
 * plane_step by 1 / step (at least 1); lengths stay. */
TabletopSegmentationParameters latticeParameters(const TabletopSegmentationParameters& params,
                                                 int step);

/** \brief \a camera for the lattice of \a step of its image (latticeOf): focal lengths and
 * principal point divided by \a step, the image \a width x \a height lattice pixels. An
 * invalid camera stays as it is. */
PinholeCamera latticeCamera(const PinholeCamera& camera, int step, std::uint32_t width,
                            std::uint32_t height);

} // namespace facyl
