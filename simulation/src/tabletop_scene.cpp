/*
 * facyl: fast cylinder detection for PCL.
 */
#include <facyl/simulation/scene_rendering.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace facyl {

std::string
toString(SceneClass c)
{
  switch (c) {
  case SceneClass::Background: return "background";
  case SceneClass::Table: return "table";
  case SceneClass::Cylinder: return "cylinder";
  case SceneClass::Box: return "box";
  case SceneClass::Sphere: return "sphere";
  case SceneClass::Cone: return "cone";
  case SceneClass::Bowl: return "bowl";
  }
  return "unknown";
}

namespace {
bool
inside(const Range& r, float lo, float hi)
{
  return r.min >= lo && r.max <= hi && r.min <= r.max;
}
} // namespace

std::string
validate(const TabletopSceneParameters& p)
{
  std::ostringstream why;
  const auto& c = p.camera;
  const auto& s = p.sensor;
  const auto share = [](float x) { return x >= 0.f && x <= 1.f; };
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

RenderedScene
renderTabletopScene(const TabletopScene& scene, const CameraIntrinsics& camera,
                    const DepthSensorModel& sensor, std::uint64_t seed)
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
  RayCastImage image = castRays(scene, camera);
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

RenderedScene
simulateTabletopScene(const TabletopSceneParameters& params)
{
  return renderTabletopScene(generateTabletopScene(params), params.camera, params.sensor,
                             params.seed);
}

namespace {
std::string
vec(const Eigen::Vector3f& v)
{
  std::ostringstream s;
  s << std::setprecision(7) << "[" << v.x() << "," << v.y() << "," << v.z() << "]";
  return s.str();
}
} // namespace

std::string
groundTruthJson(const RenderedScene& r)
{
  std::ostringstream s;
  s << std::setprecision(7);
  const auto& c = r.camera;
  s << "{\"camera\":{\"width\":" << c.width << ",\"height\":" << c.height << ",\"fx\":" << c.fx
    << ",\"fy\":" << c.fy << ",\"cx\":" << c.cx << ",\"cy\":" << c.cy << "},";
  const Eigen::Isometry3f& t = r.scene.camera_to_world;
  s << "\"camera_to_world\":{\"rotation\":[" << vec(t.linear().row(0)) << ","
    << vec(t.linear().row(1)) << "," << vec(t.linear().row(2))
    << "],\"translation\":" << vec(t.translation()) << "},";
  const TabletopScene& sc = r.scene;
  s << "\"table\":{\"coefficients\":[" << r.table_plane[0] << "," << r.table_plane[1] << ","
    << r.table_plane[2] << "," << r.table_plane[3] << "],\"shape\":\""
    << (sc.table_shape == TableShape::Round ? "round" : "rectangle") << "\",";
  if (sc.table_shape == TableShape::Round)
    s << "\"radius\":" << sc.table_radius;
  else
    s << "\"width\":" << sc.table_width << ",\"depth\":" << sc.table_depth;
  s << ",\"height\":" << sc.table_height << ",\"legs\":" << (sc.furniture.size() > 1 ? "true" : "false")
    << "},\"wall\":" << (sc.wall ? "true" : "false") << ",";
  s << "\"pixel_ids\":\"0 background (floor, wall), 1 table, 2+i object i\",\"objects\":[";
  const Eigen::Isometry3f world_to_camera = t.inverse();
  for (std::size_t i = 0; i < r.scene.objects.size(); ++i) {
    const SceneObject& o = r.scene.objects[i];
    const Eigen::Isometry3f pose = world_to_camera * o.pose;
    s << (i ? "," : "") << "{\"id\":" << i + 2 << ",\"class\":\"" << toString(o.cls)
      << "\",\"kind\":\"" << o.kind << "\",\"visible_pixels\":" << r.visible_pixels[i]
      << ",\"position\":" << vec(pose.translation()) << ",\"axis\":" << vec(pose.linear().col(2))
      << ",\"on\":";
    if (o.support >= 0)
      s << o.support + 2;
    else
      s << "\"table\"";
    s << ",\"leaning\":" << (o.leaning ? "true" : "false") << ",\"touches\":[";
    for (std::size_t k = 0; k < o.touches.size(); ++k)
      s << (k ? "," : "") << o.touches[k] + 2;
    s << "]";
    if (o.cls == SceneClass::Box)
      s << ",\"size\":" << vec(o.size);
    else
      s << ",\"radius\":" << o.radius;
    if (o.cls == SceneClass::Cylinder) {
      const CylinderTruth ct = cylinderTruth(r.scene, o);
      s << ",\"pose\":\"" << (o.lying ? "lying" : "upright") << "\",\"open_top\":"
        << (o.open_top ? "true" : "false") << ",\"handle\":" << (o.handle ? "true" : "false")
        << ",\"cylinder\":{\"point_on_axis\":" << vec(ct.base) << ",\"axis\":" << vec(ct.axis)
        << ",\"radius\":" << ct.radius << ",\"height\":" << ct.height << "}";
    } else if (o.cls == SceneClass::Cone) {
      s << ",\"height\":" << o.height;
    }
    s << "}";
  }
  s << "]}";
  return s.str();
}

} // namespace facyl
