/*
 * facyl: fast cylinder detection for PCL.
 */
#pragma once

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <Eigen/Geometry>

#include <cstdint>
#include <optional>
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
  /** Far furniture, robots and what stands on them: seen, but neither a target nor a
   * distractor (an evaluator ignores what it detects there). */
  Scenery = 7,
};

/** \brief "background", "table", "cylinder", "box", "sphere", "cone", "bowl" or "scenery". */
std::string toString(SceneClass c);

/** \brief Pixel id of scenery item 0 (RenderedScene::object_id); item j has this id + j. */
constexpr std::uint16_t kFirstSceneryId = 1000;

/** \brief How a surface returns the depth sensor's (infrared) light. The default is the
 * reference matte surface the sensor models are specified on: it changes nothing. */
struct SurfaceMaterial {
  /** Infrared reflectance relative to the reference surface, in [0, 2]: a black counter or
   * black plastic 0.1-0.4, white paper up to 1.5. */
  float reflectance{1.f};
  /** Share of the light reflected like a mirror, in [0, 0.95]: varnish, metal, glazing
   * 0.3-0.8. It is lost to the diffuse return, and where the surface faces the sensor the
   * mirrored pattern saturates the camera (a highlight without depth). */
  float gloss{0.f};
  /** Share of the light that passes through, in [0, 1]: clear glass or plastic 0.7-1. The
   * sensor may measure the surface behind (DepthSensorModel::see_through). */
  float transparency{0.f};

  /** \brief True for the reference surface (all defaults). */
  bool isReference() const
  {
    return reflectance == 1.f && gloss == 0.f && transparency == 0.f;
  }
};

/** \brief One analytic object. Local frame: z along the object's axis, origin at the centre of
 * its base (for spheres and bowls: the lowest point). */
struct SceneObject {
  SceneClass cls{SceneClass::Cylinder};
  std::string kind; ///< can, tin, cup, tube, box, sphere, cone, bowl
  Eigen::Isometry3f pose{Eigen::Isometry3f::Identity()}; ///< local to world (table) frame
  float radius{0.04f};                                   ///< cylinder, cone base, sphere, bowl
  float height{0.1f};                                    ///< cylinder, cone
  Eigen::Vector3f size{Eigen::Vector3f::Constant(0.1f)}; ///< box: x, y, z
  bool open_top{false};     ///< cylinder: a cup (inner wall and bottom visible)
  float wall{0.004f};       ///< wall thickness of cups and bowls
  bool handle{false};       ///< cylinder: a handle on the local +x side
  bool lying{false};        ///< cylinder with a horizontal axis
  bool leaning{false};      ///< tilted against another object
  int support{-1};          ///< index of the object it stands on; -1: the table
  std::vector<int> touches; ///< indices of the objects it was placed in contact with
  Eigen::Vector3f colour[2]{Eigen::Vector3f::Ones(), Eigen::Vector3f::Ones()}; ///< RGB in [0, 1]
  int texture{0};           ///< 0 plain, 1 stripes, 2 checker (between the two colours)
  SurfaceMaterial material; ///< what the depth sensor sees of it
  /** Box and closed cylinder (table tops): the top face is a paraboloid that rises this far
   * (m) above the top's corners (box) or rim (cylinder) at its centre; < 0: it sags. */
  float top_sag{0.f};
};

/** \brief Height (local z, above the flat top) of the curved top of \a o at local (x, y):
 * top_sag * (1 - (x^2 + y^2) / rho^2), rho the half diagonal of a box or a cylinder's radius. */
float curvedTopHeight(const SceneObject& o, float x, float y);

/** \brief A piece of scenery: its parts share one pixel id and SceneClass::Scenery. */
struct SceneryItem {
  std::string kind;               ///< table, shelf, chair, cabinet, boxes, robot
  std::vector<SceneObject> parts; ///< world frame; cls gives the shape only
};

/** \brief Pinhole camera; the cloud is in its frame (x right, y down, z forward). */
struct CameraIntrinsics {
  int width{640};
  int height{480};
  float fx{525.f}, fy{525.f}, cx{319.5f}, cy{239.5f};
};

/** \brief \a camera with a \a width x \a height image of the same field of view: focal
 * lengths scaled with the image's sides, the principal point with them (pixel centres at
 * half-integers). */
CameraIntrinsics resizedCamera(const CameraIntrinsics& camera, int width, int height);

/** \brief Depth sensor model. The defaults are a structured-light sensor (Kinect-like);
 * activeStereo() gives a RealSense D4xx-like one. The systematic errors, time-of-flight noise
 * and flying pixels are off by default; the response to materials acts only on surfaces that
 * are not the reference material (SurfaceMaterial). docs/simulation.md names the real
 * artefact behind each setting. */
struct DepthSensorModel {
  float noise_coefficient{1.5e-3f}; ///< axial sigma = coefficient * z^2 (m), >= 0
  float baseline_focal{43.5f};      ///< baseline (m) x focal (px) of the disparity, > 0
  float disparity_step{0.125f};     ///< disparity quantum (px); 0: no quantisation
  float edge_jump{0.04f};   ///< pixels next to a depth jump > edge_jump * z are missing; 0: off
  float grazing_cos{0.15f}; ///< pixels whose |cos(incidence)| is below this are missing
  float dropout{0.002f};    ///< share of pixels missing at random, in [0, 1)
  /** Speckled holes: blobs of missing pixels are centred on this share of the pixels, in
   * [0, 0.1]; 0: none. */
  float hole_rate{0.f};
  float hole_radius{2.f}; ///< mean radius of a hole (px), in [0.5, 20]
  /** Stereo matching fattens foreground objects: a background pixel beside a foreground
   * edge takes the foreground depth with this probability, in [0, 1]. */
  float edge_fattening{0.f};
  int colour_shift_u{0}; ///< colour-to-depth misregistration (px), |shift| <= 16
  int colour_shift_v{0};
  float min_range{0.4f};     ///< no depth nearer than this (m)
  float max_range{4.0f};     ///< or farther than this (m)
  float colour_noise{0.02f}; ///< std. dev. of RGB noise, in [0, 1] units

  // Systematic depth errors (calibration), off by default.
  /** Relative depth scale error: z becomes z (1 + depth_scale_error), in [-0.05, 0.05]. */
  float depth_scale_error{0.f};
  /** Lens-distortion-like depth error (m) at z = 1 m in the image corners, growing with z^2
   * and with the squared distance from the image centre (relative to the half diagonal): a
   * flat table bends into a bowl (> 0: the border too far) or a dome; in [-0.03, 0.03]. */
  float radial_depth_bias{0.f};
  /** Offset (m) at z = 1 m of surfaces seen at an angle of incidence theta: incidence_bias *
   * z * (1 / cos(theta) - 1), cos floored at 0.1; > 0: too far; in [-0.01, 0.01]. */
  float incidence_bias{0.f};

  // Time-of-flight noise and edges, off by default.
  float noise_constant{0.f}; ///< axial sigma term independent of z (m), in [0, 0.02]
  float noise_linear{0.f};   ///< axial sigma term proportional to z (m per m), in [0, 0.02]
  /** Flying pixels: a pixel beside a depth jump (edge_jump) that is neither missing nor
   * fattened takes, with this probability, a depth between its own and the other side's
   * (mixed returns); in [0, 1]. */
  float flying_pixels{0.f};

  // Response to materials (inert on the reference material).
  /** Extra missing share of a weak return: weak_return_dropout * (1 - rho)^2 of the pixels of
   * a surface whose diffuse return rho (reflectance x (1 - gloss) x (1 - transparency)) is
   * below 1 are lost in blobs; in [0, 1]. Pixels with rho * |cos(incidence)| < grazing_cos
   * are missing, and the range shrinks to max_range * sqrt(rho). */
  float weak_return_dropout{0.6f};
  /** Angular radius (rad) of the highlight of glossy surfaces: pixels at an angle of
   * incidence theta are missing with probability min(1, 2 gloss exp(-theta^2 / (2 w^2)));
   * in [0, 0.5]; 0: no highlights. */
  float highlight_width{0.12f};
  /** Probability (times the transparency) that a pixel on a transparent surface measures the
   * surface behind it; otherwise it sees the weak front return; in [0, 1]. */
  float see_through{0.1f};

  /** Domain randomization: renderTabletopScene and simulateTabletopScene replace this model
   * (and scale the focal length) by one drawn from the frame's seed (drawSensor); the other
   * settings are ignored. */
  bool randomize{false};

  /** \brief Kinect-like structured light (the defaults). */
  static DepthSensorModel structuredLight();
  /** \brief RealSense D4xx-like active stereo: noise growing with z^2 (sigma 3 mm at 1 m),
   * 1/32 px sub-pixel disparity, speckled holes, fattened edges and 2 px of colour/depth
   * misregistration. */
  static DepthSensorModel activeStereo();
};

/** \brief Sensor presets by name: "kinect" (structured light), "stereo" (active stereo) or
 * "random" (a sensor drawn per frame, see drawSensor). \return false for an unknown name. */
bool parseSensorPreset(const std::string& name, DepthSensorModel& sensor, CameraIntrinsics& camera);

/** \brief Depth sensing principle of a drawn sensor. */
enum class SensorFamily : std::uint8_t {
  StructuredLight, ///< Kinect v1, PrimeSense, Structure: disparity of a projected pattern
  ActiveStereo,    ///< RealSense D4xx: stereo matching helped by a projected pattern
  TimeOfFlight,    ///< Azure Kinect, Kinect v2, ToF cameras: phase of modulated light
};

/** \brief "structured_light", "active_stereo" or "time_of_flight". */
std::string toString(SensorFamily f);

/** \brief A sensor drawn for one frame. */
struct DrawnSensor {
  SensorFamily family{SensorFamily::StructuredLight};
  DepthSensorModel sensor; ///< randomize is false
  CameraIntrinsics camera; ///< the base camera with its focal length scaled by 0.9-1.2
};

/** \brief Domain randomization: draws a sensor family (each a third of the frames) and its
 * settings (noise, bias, holes, dropout, edges, misregistration, response to materials, range)
 * over ranges that cover that family's real sensors (docs/simulation.md). Deterministic for a
 * seed on every platform; \a base gives the image size and the focal length to scale. */
DrawnSensor drawSensor(const CameraIntrinsics& base, std::uint64_t seed);

/** \brief A closed interval of a random setting. */
struct Range {
  float min{0.f}, max{0.f};
};

/** \brief Probabilities that a surface is glossy, dark (in the infrared) or transparent,
 * drawn independently, each in [0, 1] (a glossy dark table is a black kitchen counter). */
struct MaterialShares {
  float glossy{0.f};
  float dark{0.f};
  float transparent{0.f}; ///< objects only
};

/** \brief Settings of a random tabletop scene. The defaults are the free-standing layout
 * (objects apart on a large table); clutteredSceneParameters() gives touching, stacked and
 * leaning objects on tables of any size, a floor and sometimes a wall;
 * realisticSceneParameters() adds what real frames show besides (curved tables, materials, far
 * background, robots, any camera roll). What the defaults leave off draws no random numbers:
 * the scenes of the other settings stay the same. */
struct TabletopSceneParameters {
  std::size_t min_objects{3};
  std::size_t max_objects{10};
  float cylinder_share{0.5f}; ///< probability that an object is a cylinder, in [0, 1]
  float lying_share{0.25f};   ///< probability that a can or tube lies on its side
  /** Probabilities that an object is placed in contact with one already there, in [0, 1],
   * summing to at most 1: beside it (touching), on top of it (stacked), or tilted against it
   * (leaning). The rest stand apart. */
  float touch_share{0.f}, stack_share{0.f}, lean_share{0.f};
  float round_table_share{0.f};      ///< probability that the table is round
  Range table_width{1.4f, 1.4f};     ///< rectangular table: extent along world x (m)
  Range table_depth{1.0f, 1.0f};     ///< along world y (m)
  Range table_radius{0.3f, 0.5f};    ///< round table (m)
  Range table_height{0.75f, 0.75f};  ///< table top above the floor (m)
  bool table_legs{false};            ///< legs (rectangular) or a pedestal (round) down to the floor
  float wall_share{0.f};             ///< probability of a wall behind the table
  Range camera_distance{0.7f, 1.1f}; ///< to the look-at point (m)
  Range camera_elevation{0.6f, 1.0f};  ///< above the table plane (rad), in (0, pi/2)
  Range camera_azimuth{-0.35f, 0.35f}; ///< around the table's vertical (rad)
  Range camera_roll{-0.08f, 0.08f};    ///< about the optical axis (rad)
  /** The camera looks at a point this far (m, at most) from the objects' area centre, so
   * objects near the border are cut by the image edge. */
  float camera_target_jitter{0.05f};
  /** Probability that the camera is rolled uniformly in [-pi, pi] about its optical axis (on
   * top of camera_roll), in [0, 1]. */
  float any_roll_share{0.f};
  /** Curved table tops: the top's centre lies this far (m) above its corners or rim (< 0: it
   * sags), drawn per scene within [-0.02, 0.02]; the objects stand on the curved top. */
  Range table_sag{0.f, 0.f};
  MaterialShares table_materials;  ///< the table top (glossy, dark; not transparent)
  MaterialShares floor_materials;  ///< the floor (glossy, dark; not transparent)
  MaterialShares object_materials; ///< each object
  /** Far background: this many scenery items (tables with things on them, shelves, chairs,
   * cabinets, stacked boxes) on the floor, at most 20. */
  std::size_t min_background_items{0}, max_background_items{0};
  /** Horizontal distance of background items from the camera (m), within [0.5, 20]. */
  Range background_distance{1.5f, 4.f};
  /** Probability of a robot arm (links, joints, a gripper) reaching into the image from a
   * border to above the objects, in [0, 1]. Robots are scenery. */
  float robot_share{0.f};
  CameraIntrinsics camera;
  DepthSensorModel sensor;
  std::uint64_t seed{0};
};

/** \brief The cluttered preset: 4-10 objects, 45% placed touching another, 20% stacked, 8%
 * leaning; tins among the cylinders; rectangular (0.5-1.4 m) or round (r 0.3-0.55 m) tables
 * 0.45-0.8 m high with legs, a wall behind in 30% of the scenes; cameras 0.55-1.6 m away, 20-80
 * degrees above the table, looking off-centre so objects get cut by the border. */
TabletopSceneParameters clutteredSceneParameters();

/** \brief The realistic preset: the cluttered one plus table tops curved by up to 6 mm, glossy
 * (35%) and dark (30%) table tops, glossy, dark and transparent objects, 2-6 scenery items
 * 1.5-4 m from the camera, a robot arm in 35% of the scenes, cameras 15-85 degrees above the
 * table, rolled anywhere about the optical axis in 30% of the scenes, a wall in 15%. */
TabletopSceneParameters realisticSceneParameters();

/** \brief Layout presets by name: "spread" (the defaults), "cluttered" or "realistic"; sets
 * all of \a params (apply the sensor preset after). \return false for an unknown name. */
bool parseLayoutPreset(const std::string& name, TabletopSceneParameters& params);

/** \brief Checks \a params. \return an empty string, or what is wrong. */
std::string validate(const TabletopSceneParameters& params);

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
  SurfaceMaterial floor_material;
  SurfaceMaterial wall_material;
  /** Far furniture and robots; item j has pixel id kFirstSceneryId + j. */
  std::vector<SceneryItem> scenery;

  /** \brief True if (x, y) lies on the table top. */
  bool onTable(float x, float y) const;

  /** \brief The table top (the furniture piece of kind "table"), or nullptr. */
  const SceneObject* tableTop() const;
};

/** \brief Height (world z) of the table's upper surface at (x, y): 0 for a flat top. */
float tableTopHeight(const TabletopScene& scene, float x, float y);

/** \brief A rendered RGB-D frame with per-pixel ground truth. Pixel ids: 0 background (floor,
 * wall), 1 table, 2 + i the i-th object, kFirstSceneryId + j the j-th scenery item; ids and
 * classes are those of the surface seen, also where the sensor gives no depth. Where a
 * transparent surface lets the sensor measure what lies behind it, they are those of the
 * surface measured. */
struct RenderedScene {
  pcl::PointCloud<pcl::PointXYZRGBA> cloud; ///< organized, camera frame, NaN where no depth
  std::vector<std::uint16_t> object_id;     ///< per pixel
  std::vector<SceneClass> pixel_class;      ///< per pixel
  std::vector<std::size_t> visible_pixels;  ///< per object: pixels with depth
  TabletopScene scene;
  CameraIntrinsics camera;
  Eigen::Vector4f table_plane{Eigen::Vector4f::Zero()}; ///< camera frame, normal to the camera
  DepthSensorModel sensor;                              ///< the model applied
  std::optional<SensorFamily> sensor_family; ///< set when the sensor was drawn (randomize)
};

/** \brief Ground truth of a cylinder object in the camera frame. */
struct CylinderTruth {
  Eigen::Vector3f base{Eigen::Vector3f::Zero()};  ///< base centre
  Eigen::Vector3f axis{Eigen::Vector3f::UnitZ()}; ///< unit, base to top
  float radius{0.f};
  float height{0.f};
};

/** \brief \a object's cylinder in the frame of the camera of \a scene. */
CylinderTruth cylinderTruth(const TabletopScene& scene, const SceneObject& object);

/** \brief Draws a random scene: table, camera pose, objects standing, lying, touching,
 * stacked or leaning without interpenetrating. Deterministic for a seed on every platform.
 * \throws std::invalid_argument if the parameters are invalid. */
TabletopScene generateTabletopScene(const TabletopSceneParameters& params);

/** \brief Ray casts \a scene (exact intersections of the analytic shapes), shades it
 * (Lambertian, textures, highlights of glossy surfaces, transparency) and applies \a sensor
 * (drawn from \a seed first when sensor.randomize). Deterministic for a seed.
 * \throws std::invalid_argument if the camera or sensor settings are invalid. */
RenderedScene renderTabletopScene(const TabletopScene& scene, const CameraIntrinsics& camera,
                                  const DepthSensorModel& sensor, std::uint64_t seed);

/** \brief generateTabletopScene then renderTabletopScene with params.seed. */
RenderedScene simulateTabletopScene(const TabletopSceneParameters& params);

/** \brief The scene's ground truth as a JSON object (camera intrinsics and frame, table plane
 * and shape, objects with class, kind, pose, visible pixels, support and contacts and, for
 * cylinders, axis/radius/height in the camera frame). Only where they are used: the table's
 * sag, materials other than the reference, the scenery items and the drawn sensor. */
std::string groundTruthJson(const RenderedScene& rendered);

} // namespace facyl
