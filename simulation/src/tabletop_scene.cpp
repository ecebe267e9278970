/*
 * facyl: fast cylinder detection for PCL.
 */
#include <facyl/simulation/scene_rendering.h>
#include <facyl/tools/json_writer.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace facyl {

std::string
toString(SceneClass c)
{
  switch (c) {
  case SceneClass::Background:
    return "background";
  case SceneClass::Table:
    return "table";
  case SceneClass::Cylinder:
    return "cylinder";
  case SceneClass::Box:
    return "box";
  case SceneClass::Sphere:
    return "sphere";
  case SceneClass::Cone:
    return "cone";
  case SceneClass::Bowl:
    return "bowl";
  case SceneClass::Scenery:
    return "scenery";
  }
  return "unknown";
}

namespace {
bool
inside(const Range& r, float lo, float hi)
{
  return r.min >= lo && r.max <= hi && r.min <= r.max;
}

bool
share(float x)
{
  return x >= 0.f && x <= 1.f;
}

bool
shares(const MaterialShares& m, bool transparent_allowed)
{
  return share(m.glossy) && share(m.dark) && share(m.transparent) &&
         (transparent_allowed || m.transparent == 0.f);
}

/** What is wrong with the settings of \a s added for real sensors' artefacts, or "". */
std::string
validateArtefacts(const DepthSensorModel& s)
{
  if (!(std::abs(s.depth_scale_error) <= 0.05f) || !(std::abs(s.radial_depth_bias) <= 0.03f) ||
      !(std::abs(s.incidence_bias) <= 0.01f))
    return "sensor bias: depth_scale_error must be in [-0.05, 0.05], radial_depth_bias in "
           "[-0.03, 0.03] m and incidence_bias in [-0.01, 0.01] m";
  if (!(s.noise_constant >= 0.f && s.noise_constant <= 0.02f) ||
      !(s.noise_linear >= 0.f && s.noise_linear <= 0.02f) || !share(s.flying_pixels))
    return "sensor noise_constant and noise_linear must be in [0, 0.02], flying_pixels in [0, 1]";
  if (!share(s.weak_return_dropout) || !share(s.see_through) ||
      !(s.highlight_width >= 0.f && s.highlight_width <= 0.5f))
    return "sensor weak_return_dropout and see_through must be in [0, 1], highlight_width in "
           "[0, 0.5] rad";
  return "";
}

/** What is wrong with the scene settings added for realism, or "". */
std::string
validateRealism(const TabletopSceneParameters& p)
{
  if (!share(p.any_roll_share) || !share(p.robot_share))
    return "any_roll_share and robot_share must be in [0, 1]";
  if (!inside(p.table_sag, -0.02f, 0.02f))
    return "table_sag must be an ordered range within [-0.02, 0.02] m";
  if (!shares(p.table_materials, false) || !shares(p.floor_materials, false) ||
      !shares(p.object_materials, true))
    return "material shares must be in [0, 1] (transparent: objects only)";
  if (p.min_background_items > p.max_background_items || p.max_background_items > 20)
    return "background items: min must be <= max <= 20";
  if (!inside(p.background_distance, 0.5f, 20.f))
    return "background_distance must be an ordered range within [0.5, 20] m";
  return "";
}
} // namespace

std::string
validate(const TabletopSceneParameters& p)
{
  std::ostringstream why;
  const auto& c = p.camera;
  const auto& s = p.sensor;
  if (p.min_objects > p.max_objects)
    why << "min_objects " << p.min_objects << " > max_objects " << p.max_objects;
  else if (p.max_objects > 30)
    why << "max_objects " << p.max_objects << " must be <= 30";
  else if (!share(p.cylinder_share))
    why << "cylinder_share must be in [0, 1]";
  else if (!share(p.lying_share))
    why << "lying_share must be in [0, 1]";
  else if (!share(p.touch_share) || !share(p.stack_share) || !share(p.lean_share) ||
           !(p.touch_share + p.stack_share + p.lean_share <= 1.f))
    why << "touch, stack and lean shares must be in [0, 1] with a sum <= 1";
  else if (!share(p.round_table_share) || !share(p.wall_share))
    why << "round_table_share and wall_share must be in [0, 1]";
  else if (!inside(p.table_width, 0.5f, 10.f) || !inside(p.table_depth, 0.4f, 10.f) ||
           !inside(p.table_radius, 0.25f, 5.f) || !inside(p.table_height, 0.1f, 2.f))
    why << "table sizes must be ordered ranges within 0.5-10 m (width), 0.4-10 m (depth), "
           "0.25-5 m (radius) and heights within 0.1-2 m";
  else if (!inside(p.camera_distance, 0.2f, 20.f))
    why << "camera distances must be an ordered range within [0.2, 20] m";
  else if (!inside(p.camera_elevation, 1e-3f, 1.5f))
    why << "camera elevations must be an ordered range within (0, 1.5] rad";
  else if (!inside(p.camera_azimuth, -3.15f, 3.15f) || !inside(p.camera_roll, -3.15f, 3.15f))
    why << "camera azimuth and roll must be ordered ranges within [-pi, pi]";
  else if (!(p.camera_target_jitter >= 0.f && p.camera_target_jitter <= 1.f))
    why << "camera_target_jitter must be in [0, 1] m";
  else if (c.width < 8 || c.height < 8 || c.width > 8192 || c.height > 8192 || !(c.fx > 0.f) ||
           !(c.fy > 0.f) || !std::isfinite(c.cx) || !std::isfinite(c.cy))
    why << "camera intrinsics are invalid";
  else if (!(s.noise_coefficient >= 0.f) || !(s.baseline_focal > 0.f) ||
           !(s.disparity_step >= 0.f) || !(s.edge_jump >= 0.f) || !(s.grazing_cos >= 0.f) ||
           !(s.dropout >= 0.f && s.dropout < 1.f) || !(s.hole_rate >= 0.f && s.hole_rate <= 0.1f) ||
           !(s.hole_radius >= 0.5f && s.hole_radius <= 20.f) || !share(s.edge_fattening) ||
           std::abs(s.colour_shift_u) > 16 || std::abs(s.colour_shift_v) > 16 ||
           !(s.min_range >= 0.f) || !(s.max_range > s.min_range) || !(s.colour_noise >= 0.f))
    why << "sensor model is invalid";
  else
    why << validateArtefacts(s) << validateRealism(p);
  return why.str();
}

CylinderTruth
cylinderTruth(const TabletopScene& scene, const SceneObject& object)
{
  const Eigen::Isometry3f to_camera = scene.camera_to_world.inverse() * object.pose;
  CylinderTruth t;
  t.base = to_camera.translation();
  t.axis = to_camera.linear().col(2).normalized();
  t.radius = object.radius;
  t.height = object.height;
  return t;
}

float
curvedTopHeight(const SceneObject& o, float x, float y)
{
  if (o.top_sag == 0.f)
    return 0.f;
  const float rho2 = o.cls == SceneClass::Box
                       ? 0.25f * (o.size.x() * o.size.x() + o.size.y() * o.size.y())
                       : o.radius * o.radius;
  return o.top_sag * (1.f - (x * x + y * y) / rho2);
}

const SceneObject*
TabletopScene::tableTop() const
{
  for (const SceneObject& f : furniture)
    if (f.kind == "table")
      return &f;
  return nullptr;
}

float
tableTopHeight(const TabletopScene& scene, float x, float y)
{
  const SceneObject* top = scene.tableTop();
  if (top == nullptr || top->top_sag == 0.f)
    return 0.f;
  const Eigen::Vector3f local = top->pose.inverse() * Eigen::Vector3f(x, y, 0.f);
  return curvedTopHeight(*top, local.x(), local.y());
}

namespace {

/** renderTabletopScene with a sensor that is not drawn. */
RenderedScene
render(const TabletopScene& scene, const CameraIntrinsics& camera, const DepthSensorModel& sensor,
       std::uint64_t seed)
{
  TabletopSceneParameters check;
  check.camera = camera;
  check.sensor = sensor;
  const std::string why = validate(check);
  if (!why.empty())
    throw std::invalid_argument("facyl::renderTabletopScene: " + why);
  RenderedScene out;
  out.scene = scene;
  out.camera = camera;
  out.sensor = sensor;
  RayCastImage image = castRays(scene, camera);
  if (hasTransparentSurfaces(image))
    seeThroughTransparent(image, castRaysBehindTransparent(scene, camera, image), sensor, seed);
  out.visible_pixels.assign(scene.objects.size(), 0);
  applySensorModel(image, camera, sensor, seed, out.cloud, out.visible_pixels);
  out.object_id = std::move(image.id);
  out.pixel_class = std::move(image.cls);
  // Table plane in the camera frame, normal towards the camera.
  const Eigen::Isometry3f world_to_camera = scene.camera_to_world.inverse();
  const Eigen::Vector3f up = world_to_camera.linear() * Eigen::Vector3f::UnitZ();
  out.table_plane.head<3>() = up;
  out.table_plane[3] = -up.dot(world_to_camera.translation());
  return out;
}

} // namespace

RenderedScene
renderTabletopScene(const TabletopScene& scene, const CameraIntrinsics& camera,
                    const DepthSensorModel& sensor, std::uint64_t seed)
{
  if (!sensor.randomize)
    return render(scene, camera, sensor, seed);
  const DrawnSensor drawn = drawSensor(camera, seed);
  RenderedScene out = render(scene, drawn.camera, drawn.sensor, seed);
  out.sensor_family = drawn.family;
  return out;
}

RenderedScene
simulateTabletopScene(const TabletopSceneParameters& params)
{
  if (!params.sensor.randomize)
    return render(generateTabletopScene(params), params.camera, params.sensor, params.seed);
  // The scene is made for the drawn sensor (its minimum range places the camera).
  const DrawnSensor drawn = drawSensor(params.camera, params.seed);
  TabletopSceneParameters p = params;
  p.sensor = drawn.sensor;
  p.camera = drawn.camera;
  RenderedScene out = render(generateTabletopScene(p), p.camera, p.sensor, p.seed);
  out.sensor_family = drawn.family;
  return out;
}

namespace {

using facyl_cli::Json;

/** Ground truth numbers are written with 7 significant digits (what a float holds). */
constexpr int kDigits = 7;

Json
number(float v)
{
  return static_cast<double>(v);
}

Json
vec(const Eigen::Vector3f& v)
{
  return Json::array({number(v.x()), number(v.y()), number(v.z())});
}

/** Sets j[key] to \a m when it is not the reference material. */
void
addMaterial(Json& j, const char* key, const SurfaceMaterial& m)
{
  if (m.isReference())
    return;
  j[key] = Json{{"reflectance", number(m.reflectance)},
                {"gloss", number(m.gloss)},
                {"transparency", number(m.transparency)}};
}

/** The scenery items (ids, kinds and part counts). */
Json
sceneryJson(const TabletopScene& scene)
{
  Json items = Json::array();
  for (std::size_t j = 0; j < scene.scenery.size(); ++j)
    items.push_back(Json{{"id", kFirstSceneryId + j},
                         {"kind", scene.scenery[j].kind},
                         {"parts", scene.scenery[j].parts.size()}});
  return items;
}

/** The drawn sensor's family and model. */
Json
drawnSensorJson(SensorFamily family, const DepthSensorModel& m)
{
  return Json{{"family", toString(family)},
              {"noise_coefficient", number(m.noise_coefficient)},
              {"noise_constant", number(m.noise_constant)},
              {"noise_linear", number(m.noise_linear)},
              {"baseline_focal", number(m.baseline_focal)},
              {"disparity_step", number(m.disparity_step)},
              {"edge_jump", number(m.edge_jump)},
              {"grazing_cos", number(m.grazing_cos)},
              {"dropout", number(m.dropout)},
              {"hole_rate", number(m.hole_rate)},
              {"hole_radius", number(m.hole_radius)},
              {"edge_fattening", number(m.edge_fattening)},
              {"flying_pixels", number(m.flying_pixels)},
              {"colour_shift", Json::array({number(m.colour_shift_u), number(m.colour_shift_v)})},
              {"min_range", number(m.min_range)},
              {"max_range", number(m.max_range)},
              {"colour_noise", number(m.colour_noise)},
              {"depth_scale_error", number(m.depth_scale_error)},
              {"radial_depth_bias", number(m.radial_depth_bias)},
              {"incidence_bias", number(m.incidence_bias)},
              {"weak_return_dropout", number(m.weak_return_dropout)},
              {"highlight_width", number(m.highlight_width)},
              {"see_through", number(m.see_through)}};
}

/** Object \a i of the scene, in the camera frame (\a world_to_camera). */
Json
objectJson(const RenderedScene& r, std::size_t i, const Eigen::Isometry3f& world_to_camera)
{
  const SceneObject& o = r.scene.objects[i];
  const Eigen::Isometry3f pose = world_to_camera * o.pose;
  Json j{{"id", i + 2},
         {"class", toString(o.cls)},
         {"kind", o.kind},
         {"visible_pixels", r.visible_pixels[i]},
         {"position", vec(pose.translation())},
         {"axis", vec(pose.linear().col(2))}};
  j["on"] = o.support >= 0 ? Json(o.support + 2) : Json("table");
  j["leaning"] = o.leaning;
  Json touches = Json::array();
  for (const int k : o.touches)
    touches.push_back(k + 2);
  j["touches"] = touches;
  if (o.cls == SceneClass::Box)
    j["size"] = vec(o.size);
  else
    j["radius"] = number(o.radius);
  if (o.cls == SceneClass::Cylinder) {
    const CylinderTruth ct = cylinderTruth(r.scene, o);
    j["pose"] = o.lying ? "lying" : "upright";
    j["open_top"] = o.open_top;
    j["handle"] = o.handle;
    j["cylinder"] = Json{{"point_on_axis", vec(ct.base)},
                         {"axis", vec(ct.axis)},
                         {"radius", number(ct.radius)},
                         {"height", number(ct.height)}};
  }
  else if (o.cls == SceneClass::Cone)
    j["height"] = number(o.height);
  addMaterial(j, "material", o.material);
  return j;
}
} // namespace

std::string
groundTruthJson(const RenderedScene& r)
{
  const auto& c = r.camera;
  Json j;
  j["camera"] = Json{{"width", c.width},   {"height", c.height}, {"fx", number(c.fx)},
                     {"fy", number(c.fy)}, {"cx", number(c.cx)}, {"cy", number(c.cy)}};
  const Eigen::Isometry3f& t = r.scene.camera_to_world;
  j["camera_to_world"] =
    Json{{"rotation",
          Json::array({vec(t.linear().row(0)), vec(t.linear().row(1)), vec(t.linear().row(2))})},
         {"translation", vec(t.translation())}};
  const TabletopScene& sc = r.scene;
  Json table{{"coefficients", Json::array({number(r.table_plane[0]), number(r.table_plane[1]),
                                           number(r.table_plane[2]), number(r.table_plane[3])})},
             {"shape", sc.table_shape == TableShape::Round ? "round" : "rectangle"}};
  if (sc.table_shape == TableShape::Round)
    table["radius"] = number(sc.table_radius);
  else {
    table["width"] = number(sc.table_width);
    table["depth"] = number(sc.table_depth);
  }
  table["height"] = number(sc.table_height);
  table["legs"] = sc.furniture.size() > 1;
  if (const SceneObject* top = sc.tableTop()) {
    if (top->top_sag != 0.f)
      table["sag"] = number(top->top_sag);
    addMaterial(table, "material", top->material);
  }
  j["table"] = table;
  j["wall"] = sc.wall;
  j["pixel_ids"] = std::string("0 background (floor, wall), 1 table, 2+i object i") +
                   (sc.scenery.empty() ? "" : ", 1000+j scenery item j");
  const Eigen::Isometry3f world_to_camera = t.inverse();
  Json objects = Json::array();
  for (std::size_t i = 0; i < r.scene.objects.size(); ++i)
    objects.push_back(objectJson(r, i, world_to_camera));
  j["objects"] = objects;
  addMaterial(j, "floor_material", sc.floor_material);
  if (!sc.scenery.empty())
    j["scenery"] = sceneryJson(sc);
  if (r.sensor_family)
    j["sensor"] = drawnSensorJson(*r.sensor_family, r.sensor);
  return facyl_cli::dumpJsonWithDigits(j, kDigits);
}

} // namespace facyl
