/*
 * facyl: fast cylinder detection for PCL.
 * Exact ray casting of the analytic tabletop scene.
 */
#include <facyl/simulation/scene_rendering.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace facyl {

namespace {

constexpr float kPi = 3.14159265358979f;

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


/** An object ready for ray casting: the eye in its frame and a bounding sphere. */
struct Prepared {
  const SceneObject* object;
  std::uint16_t id;
  Eigen::Matrix3f r_lw; ///< world to local rotation
  Eigen::Vector3f eye_local;
  Eigen::Vector3f centre; ///< world
  float bound;
};

Prepared
prepare(const SceneObject& o, std::uint16_t id, const Eigen::Vector3f& eye)
{
  Prepared p;
  p.object = &o;
  p.id = id;
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
  return p;
}

/** The nearest surface along one ray. */
struct Surface {
  float t{std::numeric_limits<float>::infinity()};
  Eigen::Vector3f normal{Eigen::Vector3f::UnitZ()}; ///< world
  Eigen::Vector3f albedo{Eigen::Vector3f::Constant(0.45f)};
  std::uint16_t id{0};
  SceneClass cls{SceneClass::Background};
};

/** Floor (z = -table_height) and wall (y = wall_y). */
void
castBackground(const TabletopScene& scene, const Eigen::Vector3f& eye, const Eigen::Vector3f& d,
               Surface& s)
{
  if (d.z() < 0.f) {
    const float t = (-scene.table_height - eye.z()) / d.z();
    if (t > 0.f && t < s.t) {
      s.t = t;
      s.normal = Eigen::Vector3f::UnitZ();
      s.albedo = scene.floor_colour;
    }
  }
  if (scene.wall && d.y() > 0.f) {
    const float t = (scene.wall_y - eye.y()) / d.y();
    if (t > 0.f && t < s.t) {
      s.t = t;
      s.normal = -Eigen::Vector3f::UnitY();
      s.albedo = scene.wall_colour;
    }
  }
}

void
castObjects(const std::vector<Prepared>& prepared, const TabletopScene& scene,
            const Eigen::Vector3f& eye, const Eigen::Vector3f& d, Surface& s)
{
  const float dd = d.squaredNorm();
  for (const Prepared& p : prepared) {
    const Eigen::Vector3f oc = eye - p.centre;
    const float b = oc.dot(d);
    if (b * b - dd * (oc.squaredNorm() - p.bound * p.bound) < 0.f)
      continue;
    const Hit hit = intersect(*p.object, p.eye_local, p.r_lw * d);
    if (!(hit.t < s.t))
      continue;
    s.t = hit.t;
    s.normal = p.object->pose.linear() * hit.normal;
    s.id = p.id;
    if (p.id == 1) { // the table: a checker of 10 cm cells on the top, plain legs
      s.cls = SceneClass::Table;
      const Eigen::Vector3f w = eye + hit.t * d;
      const int cell = static_cast<int>(std::floor(w.x() / 0.1f)) +
                       static_cast<int>(std::floor(w.y() / 0.1f));
      s.albedo = w.z() > -0.005f ? scene.table_colour[cell & 1] : scene.table_colour[1];
    } else {
      s.cls = p.object->cls;
      s.albedo = albedo(*p.object, hit.local);
    }
  }
}

} // namespace

RayCastImage
castRays(const TabletopScene& scene, const CameraIntrinsics& camera)
{
  const int w = camera.width, h = camera.height;
  const std::size_t n = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
  RayCastImage image;
  image.width = w;
  image.height = h;
  image.depth.assign(n, std::numeric_limits<float>::infinity());
  image.incidence.assign(n, 1.f);
  image.colour.assign(n, Eigen::Vector3f::Zero());
  image.id.assign(n, 0);
  image.cls.assign(n, SceneClass::Background);

  const Eigen::Matrix3f r_cw = scene.camera_to_world.linear();
  const Eigen::Vector3f eye = scene.camera_to_world.translation();
  const Eigen::Vector3f light = Eigen::Vector3f(0.3f, -0.4f, 1.f).normalized();
  std::vector<Prepared> prepared;
  for (const SceneObject& f : scene.furniture)
    prepared.push_back(prepare(f, 1, eye));
  for (std::size_t i = 0; i < scene.objects.size(); ++i)
    prepared.push_back(prepare(scene.objects[i], static_cast<std::uint16_t>(i + 2), eye));

  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      const std::size_t idx = static_cast<std::size_t>(v) * w + u;
      const Eigen::Vector3f ray_c((u - camera.cx) / camera.fx, (v - camera.cy) / camera.fy, 1.f);
      const Eigen::Vector3f d = r_cw * ray_c; // t along d is the camera depth
      Surface s;
      castBackground(scene, eye, d, s);
      castObjects(prepared, scene, eye, d, s);
      if (!std::isfinite(s.t))
        continue;
      image.id[idx] = s.id;
      image.cls[idx] = s.cls;
      image.depth[idx] = s.t;
      const Eigen::Vector3f dn = d.normalized();
      Eigen::Vector3f normal = s.normal;
      if (normal.dot(dn) > 0.f)
        normal = -normal;
      image.incidence[idx] = std::abs(normal.dot(dn));
      const float shade =
        0.35f + 0.5f * std::max(0.f, normal.dot(light)) + 0.15f * image.incidence[idx];
      image.colour[idx] = shade * s.albedo;
    }
  return image;
}

} // namespace facyl
