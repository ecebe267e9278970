/*
 * facyl: fast cylinder detection for PCL.
 */
#include <facyl/simulation/tabletop_scene.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <random>
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
  else if (!(p.cylinder_share >= 0.f && p.cylinder_share <= 1.f))
    why << "cylinder_share must be in [0, 1]";
  else if (!(p.lying_share >= 0.f && p.lying_share <= 1.f))
    why << "lying_share must be in [0, 1]";
  else if (!(p.table_width >= 0.5f && p.table_depth >= 0.4f && p.table_height > 0.f))
    why << "the table must be at least 0.5 x 0.4 m and above the floor";
  else if (!(p.camera_distance_min > 0.2f && p.camera_distance_max >= p.camera_distance_min))
    why << "camera distances must satisfy 0.2 < min <= max";
  else if (!(p.camera_elevation_min > 0.f && p.camera_elevation_max >= p.camera_elevation_min &&
             p.camera_elevation_max < 1.57f))
    why << "camera elevations must satisfy 0 < min <= max < pi/2";
  else if (c.width < 8 || c.height < 8 || c.width > 8192 || c.height > 8192 || !(c.fx > 0.f) ||
           !(c.fy > 0.f))
    why << "camera intrinsics are invalid";
  else if (!(s.noise_coefficient >= 0.f) || !(s.baseline_focal > 0.f) ||
           !(s.disparity_step >= 0.f) || !(s.edge_jump >= 0.f) || !(s.grazing_cos >= 0.f) ||
           !(s.dropout >= 0.f && s.dropout < 1.f) || !(s.min_range >= 0.f) ||
           !(s.max_range > s.min_range) || !(s.colour_noise >= 0.f))
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

namespace {

constexpr float kPi = 3.14159265358979f;

Eigen::Vector3f
randomColour(std::mt19937_64& rng)
{
  std::uniform_real_distribution<float> u(0.1f, 0.95f);
  return {u(rng), u(rng), u(rng)};
}

/** Rotation whose z column is \a z. */
Eigen::Matrix3f
frameWithZ(const Eigen::Vector3f& z, float yaw)
{
  Eigen::Vector3f helper = std::abs(z.z()) < 0.9f ? Eigen::Vector3f::UnitZ()
                                                  : Eigen::Vector3f::UnitX();
  Eigen::Vector3f x = helper.cross(z).normalized();
  Eigen::Vector3f y = z.cross(x);
  Eigen::Matrix3f r;
  r.col(0) = x;
  r.col(1) = y;
  r.col(2) = z;
  return r * Eigen::AngleAxisf(yaw, Eigen::Vector3f::UnitZ()).toRotationMatrix();
}

/** Footprint radius on the table, for the overlap test. */
float
footprint(const SceneObject& o)
{
  switch (o.cls) {
  case SceneClass::Cylinder:
    if (o.lying)
      return 0.5f * std::hypot(o.height, 2.f * o.radius);
    return o.radius + (o.handle ? 0.045f : 0.f);
  case SceneClass::Box: return 0.5f * std::hypot(o.size.x(), o.size.y());
  default: return o.radius;
  }
}

} // namespace

TabletopScene
generateTabletopScene(const TabletopSceneParameters& params)
{
  const std::string why = validate(params);
  if (!why.empty())
    throw std::invalid_argument("facyl::generateTabletopScene: " + why);
  std::mt19937_64 rng(params.seed);
  auto uniform = [&rng](float a, float b) {
    return std::uniform_real_distribution<float>(a, b)(rng);
  };

  TabletopScene scene;
  scene.table_width = params.table_width;
  scene.table_depth = params.table_depth;
  scene.table_height = params.table_height;
  scene.table_colour[0] = Eigen::Vector3f(uniform(0.4f, 0.8f), uniform(0.3f, 0.6f), uniform(0.2f, 0.5f));
  scene.table_colour[1] = 0.8f * scene.table_colour[0];

  // Camera: looks at the scene centre from the -y side, above the table.
  const float distance = uniform(params.camera_distance_min, params.camera_distance_max);
  const float elevation = uniform(params.camera_elevation_min, params.camera_elevation_max);
  const float azimuth = uniform(-0.35f, 0.35f);
  const Eigen::Vector3f target(uniform(-0.05f, 0.05f), uniform(-0.05f, 0.05f), 0.05f);
  const Eigen::Vector3f eye =
    target + distance * Eigen::Vector3f(std::sin(azimuth) * std::cos(elevation),
                                        -std::cos(azimuth) * std::cos(elevation),
                                        std::sin(elevation));
  const Eigen::Vector3f forward = (target - eye).normalized();
  const Eigen::Vector3f right = forward.cross(Eigen::Vector3f::UnitZ()).normalized();
  const Eigen::Vector3f down = forward.cross(right);
  Eigen::Matrix3f rotation;
  rotation.col(0) = right;
  rotation.col(1) = down;
  rotation.col(2) = forward;
  const float roll = uniform(-0.08f, 0.08f);
  scene.camera_to_world.linear() =
    rotation * Eigen::AngleAxisf(roll, Eigen::Vector3f::UnitZ()).toRotationMatrix();
  scene.camera_to_world.translation() = eye;

  // Objects: placed in a region the camera sees, without overlapping footprints.
  const std::size_t count =
    params.min_objects +
    std::uniform_int_distribution<std::size_t>(0, params.max_objects - params.min_objects)(rng);
  const float half_x = std::min(0.36f, 0.5f * params.table_width - 0.1f);
  const float half_y = std::min(0.24f, 0.5f * params.table_depth - 0.1f);
  for (std::size_t attempt = 0; scene.objects.size() < count && attempt < 400; ++attempt) {
    SceneObject o;
    o.colour[0] = randomColour(rng);
    o.colour[1] = randomColour(rng);
    o.texture = std::uniform_int_distribution<int>(0, 2)(rng);
    const float yaw = uniform(-kPi, kPi);
    Eigen::Vector3f z_axis = Eigen::Vector3f::UnitZ();
    float lift = 0.f;
    if (uniform(0.f, 1.f) < params.cylinder_share) {
      o.cls = SceneClass::Cylinder;
      const int kind = std::uniform_int_distribution<int>(0, 2)(rng);
      if (kind == 0) {
        o.kind = "can";
        o.radius = uniform(0.028f, 0.05f);
        o.height = uniform(0.07f, 0.16f);
      } else if (kind == 1) {
        o.kind = "cup";
        o.radius = uniform(0.035f, 0.05f);
        o.height = uniform(0.07f, 0.11f);
        o.open_top = true;
        o.handle = uniform(0.f, 1.f) < 0.6f;
      } else {
        o.kind = "tube";
        o.radius = uniform(0.02f, 0.038f);
        o.height = uniform(0.15f, 0.27f);
      }
      if (!o.open_top && uniform(0.f, 1.f) < params.lying_share) {
        o.lying = true;
        z_axis = Eigen::Vector3f(std::cos(yaw), std::sin(yaw), 0.f);
        lift = o.radius;
      }
    } else {
      const int kind = std::uniform_int_distribution<int>(0, 3)(rng);
      if (kind == 0) {
        o.cls = SceneClass::Box;
        o.kind = "box";
        o.size = Eigen::Vector3f(uniform(0.04f, 0.2f), uniform(0.04f, 0.15f), uniform(0.03f, 0.2f));
      } else if (kind == 1) {
        o.cls = SceneClass::Sphere;
        o.kind = "sphere";
        o.radius = uniform(0.03f, 0.07f);
      } else if (kind == 2) {
        o.cls = SceneClass::Cone;
        o.kind = "cone";
        o.radius = uniform(0.03f, 0.06f);
        o.height = uniform(0.08f, 0.18f);
      } else {
        o.cls = SceneClass::Bowl;
        o.kind = "bowl";
        o.radius = uniform(0.05f, 0.09f);
      }
    }
    const Eigen::Vector2f centre(uniform(-half_x, half_x), uniform(-half_y, half_y));
    const float r = footprint(o);
    bool overlaps = false;
    for (const SceneObject& other : scene.objects) {
      Eigen::Vector3f c3 = other.pose.translation();
      if (other.lying)
        c3 += 0.5f * other.height * other.pose.linear().col(2);
      const Eigen::Vector2f c = c3.head<2>();
      overlaps = overlaps || (c - centre).norm() < r + footprint(other) + 0.02f;
    }
    if (overlaps)
      continue;
    o.pose.linear() = frameWithZ(z_axis, o.lying ? 0.f : yaw);
    Eigen::Vector3f base(centre.x(), centre.y(), lift);
    if (o.lying)
      base -= 0.5f * o.height * z_axis; // centre of the footprint at `centre`
    o.pose.translation() = base;
    scene.objects.push_back(o);
  }
  return scene;
}

namespace {

struct Hit {
  float t{std::numeric_limits<float>::infinity()};
  Eigen::Vector3f normal{Eigen::Vector3f::UnitZ()}; ///< local frame
  Eigen::Vector3f local{Eigen::Vector3f::Zero()};   ///< local point
};

constexpr float kEps = 1e-6f;

void
keep(Hit& best, float t, const Eigen::Vector3f& o, const Eigen::Vector3f& d,
     const Eigen::Vector3f& normal)
{
  if (t > kEps && t < best.t) {
    best.t = t;
    best.local = o + t * d;
    best.normal = normal;
  }
}

/** Both roots of a t^2 + b t + c = 0 (none: NaN). */
bool
roots(float a, float b, float c, float& t0, float& t1)
{
  if (std::abs(a) < 1e-12f)
    return false;
  const float disc = b * b - 4.f * a * c;
  if (disc < 0.f)
    return false;
  const float s = std::sqrt(disc);
  t0 = (-b - s) / (2.f * a);
  t1 = (-b + s) / (2.f * a);
  if (t0 > t1)
    std::swap(t0, t1);
  return true;
}

/** Lateral surface x^2 + y^2 = r^2 for z in [z0, z1]; normal outwards times \a side. */
void
lateral(Hit& best, const Eigen::Vector3f& o, const Eigen::Vector3f& d, float r, float z0,
        float z1, float side)
{
  float t0, t1;
  if (!roots(d.x() * d.x() + d.y() * d.y(), 2.f * (o.x() * d.x() + o.y() * d.y()),
             o.x() * o.x() + o.y() * o.y() - r * r, t0, t1))
    return;
  for (float t : {t0, t1}) {
    const Eigen::Vector3f p = o + t * d;
    if (p.z() >= z0 && p.z() <= z1)
      keep(best, t, o, d, side * Eigen::Vector3f(p.x(), p.y(), 0.f) / r);
  }
}

/** Disc or annulus at height z with radii [r0, r1], normal \a n_z along z. */
void
disc(Hit& best, const Eigen::Vector3f& o, const Eigen::Vector3f& d, float z, float r0, float r1,
     float n_z)
{
  if (std::abs(d.z()) < 1e-12f)
    return;
  const float t = (z - o.z()) / d.z();
  const Eigen::Vector3f p = o + t * d;
  const float rr = p.x() * p.x() + p.y() * p.y();
  if (rr <= r1 * r1 && rr >= r0 * r0)
    keep(best, t, o, d, Eigen::Vector3f(0.f, 0.f, n_z));
}

/** Sphere of radius r at c; \a z_max limits the part kept (bowls); normal times \a side. */
void
sphere(Hit& best, const Eigen::Vector3f& o, const Eigen::Vector3f& d, const Eigen::Vector3f& c,
       float r, float z_max, float side)
{
  const Eigen::Vector3f oc = o - c;
  float t0, t1;
  if (!roots(d.squaredNorm(), 2.f * oc.dot(d), oc.squaredNorm() - r * r, t0, t1))
    return;
  for (float t : {t0, t1}) {
    const Eigen::Vector3f p = o + t * d;
    if (p.z() <= z_max)
      keep(best, t, o, d, side * (p - c) / r);
  }
}

Hit
intersect(const SceneObject& obj, const Eigen::Vector3f& o, const Eigen::Vector3f& d)
{
  Hit best;
  switch (obj.cls) {
  case SceneClass::Cylinder: {
    const float r = obj.radius, h = obj.height;
    lateral(best, o, d, r, 0.f, h, 1.f);
    disc(best, o, d, 0.f, 0.f, r, -1.f);
    if (obj.open_top) {
      const float ri = r - obj.wall;
      lateral(best, o, d, ri, obj.wall, h, -1.f);
      disc(best, o, d, obj.wall, 0.f, ri, 1.f);
      disc(best, o, d, h, ri, r, 1.f);
    } else {
      disc(best, o, d, h, 0.f, r, 1.f);
    }
    if (obj.handle) { // a chain of small spheres on a half circle beside the wall
      const float a = std::min(0.3f * h, 0.035f);
      for (int k = 0; k <= 10; ++k) {
        const float phi = -0.5f * kPi + kPi * static_cast<float>(k) / 10.f;
        const Eigen::Vector3f c(r - 0.002f + a * std::cos(phi), 0.f, 0.5f * h + a * std::sin(phi));
        sphere(best, o, d, c, 0.007f, std::numeric_limits<float>::infinity(), 1.f);
      }
    }
    break;
  }
  case SceneClass::Box: {
    const Eigen::Vector3f lo(-0.5f * obj.size.x(), -0.5f * obj.size.y(), 0.f);
    const Eigen::Vector3f hi(0.5f * obj.size.x(), 0.5f * obj.size.y(), obj.size.z());
    float t_near = -std::numeric_limits<float>::infinity();
    float t_far = std::numeric_limits<float>::infinity();
    int axis = -1;
    float sign = 1.f;
    for (int i = 0; i < 3; ++i) {
      if (std::abs(d[i]) < 1e-12f) {
        if (o[i] < lo[i] || o[i] > hi[i])
          return best;
        continue;
      }
      float ta = (lo[i] - o[i]) / d[i], tb = (hi[i] - o[i]) / d[i];
      float s = -1.f;
      if (ta > tb) {
        std::swap(ta, tb);
        s = 1.f;
      }
      if (ta > t_near) {
        t_near = ta;
        axis = i;
        sign = s;
      }
      t_far = std::min(t_far, tb);
    }
    if (axis >= 0 && t_near <= t_far) {
      Eigen::Vector3f n = Eigen::Vector3f::Zero();
      n[axis] = sign;
      keep(best, t_near, o, d, n);
    }
    break;
  }
  case SceneClass::Sphere:
    sphere(best, o, d, Eigen::Vector3f(0.f, 0.f, obj.radius), obj.radius,
           std::numeric_limits<float>::infinity(), 1.f);
    break;
  case SceneClass::Cone: {
    const float k = obj.radius / obj.height, h = obj.height;
    const float w = h - o.z();
    float t0, t1;
    if (roots(d.x() * d.x() + d.y() * d.y() - k * k * d.z() * d.z(),
              2.f * (o.x() * d.x() + o.y() * d.y() + k * k * w * d.z()),
              o.x() * o.x() + o.y() * o.y() - k * k * w * w, t0, t1))
      for (float t : {t0, t1}) {
        const Eigen::Vector3f p = o + t * d;
        if (p.z() >= 0.f && p.z() <= h)
          keep(best, t, o, d, Eigen::Vector3f(p.x(), p.y(), k * k * (h - p.z())).normalized());
      }
    disc(best, o, d, 0.f, 0.f, obj.radius, -1.f);
    break;
  }
  case SceneClass::Bowl: {
    const float r = obj.radius;
    const Eigen::Vector3f c(0.f, 0.f, r);
    sphere(best, o, d, c, r, r, 1.f);
    sphere(best, o, d, c, r - obj.wall, r, -1.f);
    disc(best, o, d, r, r - obj.wall, r, 1.f);
    break;
  }
  default: break;
  }
  return best;
}

/** Texture coordinates of a local point: around the axis and along it. */
Eigen::Vector3f
albedo(const SceneObject& obj, const Eigen::Vector3f& p)
{
  if (obj.texture == 0)
    return obj.colour[0];
  const float angle = std::atan2(p.y(), p.x());
  const int along = static_cast<int>(std::floor(p.z() / 0.02f));
  int pick = 0;
  if (obj.texture == 1)
    pick = along & 1;
  else
    pick = (along + static_cast<int>(std::floor(angle / (kPi / 6.f)))) & 1;
  return obj.colour[pick];
}

} // namespace

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

  const int w = camera.width, h = camera.height;
  const std::size_t n = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
  RenderedScene out;
  out.scene = scene;
  out.camera = camera;
  out.object_id.assign(n, 0);
  out.pixel_class.assign(n, SceneClass::Background);
  out.visible_pixels.assign(scene.objects.size(), 0);
  std::vector<float> depth(n, std::numeric_limits<float>::quiet_NaN());
  std::vector<float> incidence(n, 1.f);
  std::vector<Eigen::Vector3f> colour(n, Eigen::Vector3f::Zero());

  const Eigen::Matrix3f r_cw = scene.camera_to_world.linear();
  const Eigen::Vector3f eye = scene.camera_to_world.translation();
  const Eigen::Vector3f light = Eigen::Vector3f(0.3f, -0.4f, 1.f).normalized();

  // Per object: ray origin in its frame and a bounding sphere for early rejection.
  struct Prepared {
    Eigen::Matrix3f r_lw; // world to local rotation
    Eigen::Vector3f eye_local;
    Eigen::Vector3f centre; // world
    float bound;
  };
  std::vector<Prepared> prepared;
  for (const SceneObject& o : scene.objects) {
    Prepared p;
    p.r_lw = o.pose.linear().transpose();
    p.eye_local = p.r_lw * (eye - o.pose.translation());
    float extent_z = o.height, extent_r = o.radius + (o.handle ? 0.05f : 0.f);
    if (o.cls == SceneClass::Box) {
      extent_z = o.size.z();
      extent_r = 0.5f * std::hypot(o.size.x(), o.size.y());
    } else if (o.cls == SceneClass::Sphere || o.cls == SceneClass::Bowl) {
      extent_z = 2.f * o.radius;
    }
    p.centre = o.pose * Eigen::Vector3f(0.f, 0.f, 0.5f * extent_z);
    p.bound = std::hypot(extent_r, 0.5f * extent_z) * 1.01f;
    prepared.push_back(p);
  }

  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      const std::size_t idx = static_cast<std::size_t>(v) * w + u;
      const Eigen::Vector3f ray_c((u - camera.cx) / camera.fx, (v - camera.cy) / camera.fy, 1.f);
      const Eigen::Vector3f d = r_cw * ray_c; // t along d is the camera depth
      float best_t = std::numeric_limits<float>::infinity();
      Eigen::Vector3f normal_w = Eigen::Vector3f::UnitZ();
      Eigen::Vector3f albedo_v = Eigen::Vector3f::Constant(0.45f);
      std::uint16_t id = 0;
      SceneClass cls = SceneClass::Background;
      // Table top (z = 0) and floor (z = -table_height).
      if (d.z() < 0.f) {
        const float t = -eye.z() / d.z();
        const Eigen::Vector3f p = eye + t * d;
        if (std::abs(p.x()) <= 0.5f * scene.table_width && std::abs(p.y()) <= 0.5f * scene.table_depth) {
          best_t = t;
          id = 1;
          cls = SceneClass::Table;
          const int cell = static_cast<int>(std::floor(p.x() / 0.1f)) + static_cast<int>(std::floor(p.y() / 0.1f));
          albedo_v = scene.table_colour[cell & 1];
        } else {
          best_t = (-scene.table_height - eye.z()) / d.z();
        }
      }
      for (std::size_t i = 0; i < scene.objects.size(); ++i) {
        const Prepared& p = prepared[i];
        // Bounding sphere test.
        const Eigen::Vector3f oc = eye - p.centre;
        const float b = oc.dot(d), dd = d.squaredNorm();
        if (b * b - dd * (oc.squaredNorm() - p.bound * p.bound) < 0.f)
          continue;
        const Hit hit = intersect(scene.objects[i], p.eye_local, p.r_lw * d);
        if (hit.t < best_t) {
          best_t = hit.t;
          normal_w = scene.objects[i].pose.linear() * hit.normal;
          albedo_v = albedo(scene.objects[i], hit.local);
          id = static_cast<std::uint16_t>(i + 2);
          cls = scene.objects[i].cls;
        }
      }
      if (!std::isfinite(best_t))
        continue;
      out.object_id[idx] = id;
      out.pixel_class[idx] = cls;
      depth[idx] = best_t;
      const Eigen::Vector3f dn = d.normalized();
      if (normal_w.dot(dn) > 0.f)
        normal_w = -normal_w;
      incidence[idx] = std::abs(normal_w.dot(dn));
      const float shade = 0.35f + 0.5f * std::max(0.f, normal_w.dot(light)) + 0.15f * incidence[idx];
      colour[idx] = shade * albedo_v;
    }

  // Sensor model.
  std::mt19937_64 rng(seed ^ 0x9e3779b97f4a7c15ULL);
  std::normal_distribution<float> gauss(0.f, 1.f);
  std::uniform_real_distribution<float> unit(0.f, 1.f);
  out.cloud.width = static_cast<std::uint32_t>(w);
  out.cloud.height = static_cast<std::uint32_t>(h);
  out.cloud.is_dense = false;
  out.cloud.resize(n);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      const std::size_t idx = static_cast<std::size_t>(v) * w + u;
      pcl::PointXYZRGBA& pt = out.cloud[idx];
      Eigen::Vector3f c = colour[idx];
      for (int k = 0; k < 3; ++k)
        c[k] = std::clamp(c[k] + sensor.colour_noise * gauss(rng), 0.f, 1.f);
      pt.r = static_cast<std::uint8_t>(std::lround(255.f * c[0]));
      pt.g = static_cast<std::uint8_t>(std::lround(255.f * c[1]));
      pt.b = static_cast<std::uint8_t>(std::lround(255.f * c[2]));
      pt.a = 255;
      pt.x = pt.y = pt.z = nan;
      float z = depth[idx];
      const float noise = gauss(rng);
      const float drop = unit(rng);
      if (!std::isfinite(z) || z < sensor.min_range || z > sensor.max_range)
        continue;
      if (incidence[idx] < sensor.grazing_cos || drop < sensor.dropout)
        continue;
      if (sensor.edge_jump > 0.f) {
        bool edge = false;
        for (const auto& [du, dv] : {std::pair{1, 0}, {-1, 0}, {0, 1}, {0, -1}}) {
          const int uu = u + du, vv = v + dv;
          if (uu < 0 || vv < 0 || uu >= w || vv >= h)
            continue;
          const float zn = depth[static_cast<std::size_t>(vv) * w + uu];
          edge = edge || !std::isfinite(zn) || std::abs(zn - z) > sensor.edge_jump * z;
        }
        if (edge)
          continue;
      }
      z += sensor.noise_coefficient * z * z * noise;
      if (sensor.disparity_step > 0.f) {
        const float disparity = sensor.baseline_focal / z;
        z = sensor.baseline_focal /
            (std::round(disparity / sensor.disparity_step) * sensor.disparity_step);
      }
      pt.x = (u - camera.cx) / camera.fx * z;
      pt.y = (v - camera.cy) / camera.fy * z;
      pt.z = z;
      if (out.object_id[idx] >= 2)
        ++out.visible_pixels[out.object_id[idx] - 2];
    }

  // Table plane in the camera frame, normal towards the camera.
  const Eigen::Isometry3f world_to_camera = scene.camera_to_world.inverse();
  const Eigen::Vector3f up = world_to_camera.linear() * Eigen::Vector3f::UnitZ();
  const Eigen::Vector3f origin = world_to_camera.translation();
  out.table_plane.head<3>() = up;
  out.table_plane[3] = -up.dot(origin);
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
  s << "\"table\":{\"coefficients\":[" << r.table_plane[0] << "," << r.table_plane[1] << ","
    << r.table_plane[2] << "," << r.table_plane[3] << "]},";
  s << "\"pixel_ids\":\"0 background, 1 table, 2+i object i\",\"objects\":[";
  const Eigen::Isometry3f world_to_camera = t.inverse();
  for (std::size_t i = 0; i < r.scene.objects.size(); ++i) {
    const SceneObject& o = r.scene.objects[i];
    const Eigen::Isometry3f pose = world_to_camera * o.pose;
    s << (i ? "," : "") << "{\"id\":" << i + 2 << ",\"class\":\"" << toString(o.cls)
      << "\",\"kind\":\"" << o.kind << "\",\"visible_pixels\":" << r.visible_pixels[i]
      << ",\"position\":" << vec(pose.translation()) << ",\"axis\":" << vec(pose.linear().col(2));
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
