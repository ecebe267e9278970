/*
 * facyl: fast cylinder detection for PCL.
 */
#pragma once

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <Eigen/Geometry>

#include <cstdint>
#include <string>
#include <vector>

namespace facyl {

/** \brief Ground-truth class of a simulated object (and of a pixel, see RenderedScene). */
enum class SceneClass : std::uint8_t {
  Background = 0, ///< floor, or no surface
  Table = 1,
  Cylinder = 2,   ///< cans, cups (open, optionally with a handle), tubes; upright or lying
  Box = 3,
  Sphere = 4,
  Cone = 5,
  Bowl = 6,
};

/** \brief "background", "table", "cylinder", "box", "sphere", "cone" or "bowl". */
std::string
toString(SceneClass c);

/** \brief One analytic object on the table. Local frame: z along the object's axis, origin at
 * the centre of its base (for spheres: the lowest point). */
struct SceneObject {
  SceneClass cls{SceneClass::Cylinder};
  std::string kind;            ///< can, cup, tube, box, sphere, cone, bowl
  Eigen::Isometry3f pose{Eigen::Isometry3f::Identity()}; ///< local to world (table) frame
  float radius{0.04f};         ///< cylinder, cone base, sphere, bowl
  float height{0.1f};          ///< cylinder, cone
  Eigen::Vector3f size{Eigen::Vector3f::Constant(0.1f)}; ///< box: x, y, z
  bool open_top{false};        ///< cylinder: a cup (inner wall and bottom visible)
  float wall{0.004f};          ///< wall thickness of cups and bowls
  bool handle{false};          ///< cylinder: a handle on the local +x side
  bool lying{false};           ///< cylinder with a horizontal axis
  Eigen::Vector3f colour[2]{Eigen::Vector3f::Ones(), Eigen::Vector3f::Ones()}; ///< RGB in [0, 1]
  int texture{0};              ///< 0 plain, 1 stripes, 2 checker (between the two colours)
};

/** \brief Pinhole camera; the cloud is in its frame (x right, y down, z forward). */
struct CameraIntrinsics {
  int width{640};
  int height{480};
  float fx{525.f}, fy{525.f}, cx{319.5f}, cy{239.5f};
};

/** \brief Structured-light sensor model (Kinect-like). */
struct DepthSensorModel {
  float noise_coefficient{1.5e-3f}; ///< axial sigma = coefficient * z^2 (m), >= 0
  float baseline_focal{43.5f};      ///< baseline (m) x focal (px) of the disparity, > 0
  float disparity_step{0.125f};     ///< disparity quantum (px); 0: no quantisation
  float edge_jump{0.04f};  ///< pixels next to a depth jump > edge_jump * z are missing; 0: off
  float grazing_cos{0.15f}; ///< pixels whose |cos(incidence)| is below this are missing
  float dropout{0.002f};    ///< share of pixels missing at random, in [0, 1)
  float min_range{0.4f};    ///< no depth nearer than this (m)
  float max_range{4.0f};    ///< or farther than this (m)
  float colour_noise{0.02f}; ///< std. dev. of RGB noise, in [0, 1] units
};

/** \brief Settings of a random tabletop scene. */
struct TabletopSceneParameters {
  std::size_t min_objects{3};
  std::size_t max_objects{10};
  float cylinder_share{0.5f};   ///< probability that an object is a cylinder, in [0, 1]
  float lying_share{0.25f};     ///< probability that a can or tube lies on its side
  float table_width{1.4f};      ///< table extent along world x (m)
  float table_depth{1.0f};      ///< along world y (m)
  float table_height{0.75f};    ///< table top above the floor (m)
  float camera_distance_min{0.7f}, camera_distance_max{1.1f}; ///< to the scene centre (m)
  float camera_elevation_min{0.6f}, camera_elevation_max{1.0f}; ///< above the table (rad)
  CameraIntrinsics camera;
  DepthSensorModel sensor;
  std::uint64_t seed{0};
};

/** \brief Checks \a params. \return an empty string, or what is wrong. */
std::string
validate(const TabletopSceneParameters& params);

/** \brief The scene's geometry: camera pose and objects, in the world frame (table top at
 * z = 0, z up). */
struct TabletopScene {
  Eigen::Isometry3f camera_to_world{Eigen::Isometry3f::Identity()};
  std::vector<SceneObject> objects;
  float table_width{1.4f}, table_depth{1.0f}, table_height{0.75f};
  Eigen::Vector3f table_colour[2]{Eigen::Vector3f::Ones(), Eigen::Vector3f::Ones()};
};

/** \brief A rendered RGB-D frame with per-pixel ground truth. Pixel ids: 0 background, 1 table,
 * 2 + i the i-th object; ids and classes are those of the surface seen, also where the sensor
 * gives no depth. */
struct RenderedScene {
  pcl::PointCloud<pcl::PointXYZRGBA> cloud; ///< organized, camera frame, NaN where no depth
  std::vector<std::uint16_t> object_id;     ///< per pixel
  std::vector<SceneClass> pixel_class;      ///< per pixel
  std::vector<std::size_t> visible_pixels;  ///< per object: pixels with depth
  TabletopScene scene;
  CameraIntrinsics camera;
  Eigen::Vector4f table_plane{Eigen::Vector4f::Zero()}; ///< camera frame, normal to the camera
};

/** \brief Ground truth of a cylinder object in the camera frame. */
struct CylinderTruth {
  Eigen::Vector3f base{Eigen::Vector3f::Zero()}; ///< base centre
  Eigen::Vector3f axis{Eigen::Vector3f::UnitZ()}; ///< unit, base to top
  float radius{0.f};
  float height{0.f};
};

/** \brief \a object's cylinder in the frame of the camera of \a scene. */
CylinderTruth
cylinderTruth(const TabletopScene& scene, const SceneObject& object);

/** \brief Draws a random scene: camera pose, 3 to 10 objects standing or lying on the table
 * without overlapping. Deterministic for a seed.
 * \throws std::invalid_argument if the parameters are invalid. */
TabletopScene
generateTabletopScene(const TabletopSceneParameters& params);

/** \brief Ray casts \a scene (exact intersections of the analytic shapes), shades it
 * (Lambertian, textures) and applies \a sensor. Deterministic for a seed. */
RenderedScene
renderTabletopScene(const TabletopScene& scene, const CameraIntrinsics& camera,
                    const DepthSensorModel& sensor, std::uint64_t seed);

/** \brief generateTabletopScene then renderTabletopScene with params.seed. */
RenderedScene
simulateTabletopScene(const TabletopSceneParameters& params);

/** \brief The scene's ground truth as a JSON object (camera intrinsics and frame, table plane,
 * objects with class, kind, pose, visible pixels and, for cylinders, axis/radius/height in the
 * camera frame). */
std::string
groundTruthJson(const RenderedScene& rendered);

} // namespace facyl
