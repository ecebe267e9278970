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
  Background = 0, ///< floor, wall, or no surface
  Table = 1,      ///< the table top and its legs
  Cylinder = 2,   ///< cans, tins, cups (open, optionally with a handle), tubes; upright or lying
  Box = 3,
  Sphere = 4,
  Cone = 5,
  Bowl = 6,
};

/** \brief "background", "table", "cylinder", "box", "sphere", "cone" or "bowl". */
std::string
toString(SceneClass c);

/** \brief One analytic object. Local frame: z along the object's axis, origin at the centre of
 * its base (for spheres and bowls: the lowest point). */
struct SceneObject {
  SceneClass cls{SceneClass::Cylinder};
  std::string kind;            ///< can, tin, cup, tube, box, sphere, cone, bowl
  Eigen::Isometry3f pose{Eigen::Isometry3f::Identity()}; ///< local to world (table) frame
  float radius{0.04f};         ///< cylinder, cone base, sphere, bowl
  float height{0.1f};          ///< cylinder, cone
  Eigen::Vector3f size{Eigen::Vector3f::Constant(0.1f)}; ///< box: x, y, z
  bool open_top{false};        ///< cylinder: a cup (inner wall and bottom visible)
  float wall{0.004f};          ///< wall thickness of cups and bowls
  bool handle{false};          ///< cylinder: a handle on the local +x side
  bool lying{false};           ///< cylinder with a horizontal axis
  bool leaning{false};         ///< tilted against another object
  int support{-1};             ///< index of the object it stands on; -1: the table
  std::vector<int> touches;    ///< indices of the objects it was placed in contact with
  Eigen::Vector3f colour[2]{Eigen::Vector3f::Ones(), Eigen::Vector3f::Ones()}; ///< RGB in [0, 1]
  int texture{0};              ///< 0 plain, 1 stripes, 2 checker (between the two colours)
};

/** \brief Pinhole camera; the cloud is in its frame (x right, y down, z forward). */
struct CameraIntrinsics {
  int width{640};
  int height{480};
  float fx{525.f}, fy{525.f}, cx{319.5f}, cy{239.5f};
};

/** \brief Depth sensor model. The defaults are a structured-light sensor (Kinect-like);
 * activeStereo() gives a RealSense D4xx-like one. */
struct DepthSensorModel {
  float noise_coefficient{1.5e-3f}; ///< axial sigma = coefficient * z^2 (m), >= 0
  float baseline_focal{43.5f};      ///< baseline (m) x focal (px) of the disparity, > 0
  float disparity_step{0.125f};     ///< disparity quantum (px); 0: no quantisation
  float edge_jump{0.04f};  ///< pixels next to a depth jump > edge_jump * z are missing; 0: off
  float grazing_cos{0.15f}; ///< pixels whose |cos(incidence)| is below this are missing
  float dropout{0.002f};    ///< share of pixels missing at random, in [0, 1)
  /** Speckled holes: blobs of missing pixels are centred on this share of the pixels, in
   * [0, 0.1]; 0: none. */
  float hole_rate{0.f};
  float hole_radius{2.f};   ///< mean radius of a hole (px), in [0.5, 20]
  /** Stereo matching fattens foreground objects: a background pixel beside a foreground
   * edge takes the foreground depth with this probability, in [0, 1]. */
  float edge_fattening{0.f};
  int colour_shift_u{0};    ///< colour-to-depth misregistration (px), |shift| <= 16
  int colour_shift_v{0};
  float min_range{0.4f};    ///< no depth nearer than this (m)
  float max_range{4.0f};    ///< or farther than this (m)
  float colour_noise{0.02f}; ///< std. dev. of RGB noise, in [0, 1] units

  /** \brief Kinect-like structured light (the defaults). */
  static DepthSensorModel
  structuredLight();
  /** \brief RealSense D4xx-like active stereo: noise growing with z^2 (sigma 3 mm at 1 m),
   * 1/32 px sub-pixel disparity, speckled holes, fattened edges and 2 px of colour/depth
   * misregistration. */
  static DepthSensorModel
  activeStereo();
};

/** \brief Sensor presets by name: "kinect" (structured light) or "stereo" (active stereo).
 * \return false for an unknown name. */
bool
parseSensorPreset(const std::string& name, DepthSensorModel& sensor, CameraIntrinsics& camera);

/** \brief A closed interval of a random setting. */
struct Range {
  float min{0.f}, max{0.f};
};

/** \brief Settings of a random tabletop scene. The defaults are the free-standing layout
 * (objects apart on a large table); clutteredSceneParameters() gives touching, stacked and
 * leaning objects on tables of any size, a floor and sometimes a wall. */
struct TabletopSceneParameters {
  std::size_t min_objects{3};
  std::size_t max_objects{10};
  float cylinder_share{0.5f};   ///< probability that an object is a cylinder, in [0, 1]
  float lying_share{0.25f};     ///< probability that a can or tube lies on its side
  /** Probabilities that an object is placed in contact with one already there, in [0, 1],
   * summing to at most 1: beside it (touching), on top of it (stacked), or tilted against it
   * (leaning). The rest stand apart. */
  float touch_share{0.f}, stack_share{0.f}, lean_share{0.f};
  float round_table_share{0.f}; ///< probability that the table is round
  Range table_width{1.4f, 1.4f};  ///< rectangular table: extent along world x (m)
  Range table_depth{1.0f, 1.0f};  ///< along world y (m)
  Range table_radius{0.3f, 0.5f}; ///< round table (m)
  Range table_height{0.75f, 0.75f}; ///< table top above the floor (m)
  bool table_legs{false};       ///< legs (rectangular) or a pedestal (round) down to the floor
  float wall_share{0.f};        ///< probability of a wall behind the table
  Range camera_distance{0.7f, 1.1f};  ///< to the look-at point (m)
  Range camera_elevation{0.6f, 1.0f}; ///< above the table plane (rad), in (0, pi/2)
  Range camera_azimuth{-0.35f, 0.35f}; ///< around the table's vertical (rad)
  Range camera_roll{-0.08f, 0.08f};   ///< about the optical axis (rad)
  /** The camera looks at a point this far (m, at most) from the objects' area centre, so
   * objects near the border are cut by the image edge. */
  float camera_target_jitter{0.05f};
  CameraIntrinsics camera;
  DepthSensorModel sensor;
  std::uint64_t seed{0};
};

/** \brief The cluttered preset: 4-10 objects, 45% placed touching another, 20% stacked, 8%
 * leaning; tins among the cylinders; rectangular (0.5-1.4 m) or round (r 0.3-0.55 m) tables
 * 0.45-0.8 m high with legs, a wall behind in 30% of the scenes; cameras 0.55-1.6 m away, 20-80
 * degrees above the table, looking off-centre so objects get cut by the border. */
TabletopSceneParameters
clutteredSceneParameters();

/** \brief Checks \a params. \return an empty string, or what is wrong. */
std::string
validate(const TabletopSceneParameters& params);

/** \brief Table shape. */
enum class TableShape : std::uint8_t { Rectangle, Round };

/** \brief The scene's geometry: camera pose and objects, in the world frame (table top at
 * z = 0, z up; the floor at z = -table_height; the wall, if any, is the plane y = wall_y
 * facing -y). */
struct TabletopScene {
  Eigen::Isometry3f camera_to_world{Eigen::Isometry3f::Identity()};
  std::vector<SceneObject> objects;
  TableShape table_shape{TableShape::Rectangle};
  float table_width{1.4f}, table_depth{1.0f}; ///< rectangle
  float table_radius{0.5f};                   ///< round
  float table_height{0.75f};
  /** Legs and pedestal: drawn as part of the table (pixel id 1), not objects. */
  std::vector<SceneObject> furniture;
  bool wall{false};
  float wall_y{1.f};
  Eigen::Vector3f table_colour[2]{Eigen::Vector3f::Ones(), Eigen::Vector3f::Ones()};
  Eigen::Vector3f floor_colour{Eigen::Vector3f::Constant(0.45f)};
  Eigen::Vector3f wall_colour{Eigen::Vector3f::Constant(0.7f)};

  /** \brief True if (x, y) lies on the table top. */
  bool
  onTable(float x, float y) const;
};

/** \brief A rendered RGB-D frame with per-pixel ground truth. Pixel ids: 0 background (floor,
 * wall), 1 table, 2 + i the i-th object; ids and classes are those of the surface seen, also
 * where the sensor gives no depth. */
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

/** \brief Draws a random scene: table, camera pose, objects standing, lying, touching,
 * stacked or leaning without interpenetrating. Deterministic for a seed on every platform.
 * \throws std::invalid_argument if the parameters are invalid. */
TabletopScene
generateTabletopScene(const TabletopSceneParameters& params);

/** \brief Ray casts \a scene (exact intersections of the analytic shapes), shades it
 * (Lambertian, textures) and applies \a sensor. Deterministic for a seed.
 * \throws std::invalid_argument if the camera or sensor settings are invalid. */
RenderedScene
renderTabletopScene(const TabletopScene& scene, const CameraIntrinsics& camera,
                    const DepthSensorModel& sensor, std::uint64_t seed);

/** \brief generateTabletopScene then renderTabletopScene with params.seed. */
RenderedScene
simulateTabletopScene(const TabletopSceneParameters& params);

/** \brief The scene's ground truth as a JSON object (camera intrinsics and frame, table plane
 * and shape, objects with class, kind, pose, visible pixels, support and contacts and, for
 * cylinders, axis/radius/height in the camera frame). */
std::string
groundTruthJson(const RenderedScene& rendered);

} // namespace facyl
