/*
 * facyl: fast cylinder detection for PCL.
 * Exact ray casting of the analytic tabletop scene.
 */
#include <facyl/simulation/random.h>
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
lateral(Hit& best, const Eigen::Vector3f& o, const Eigen::Vector3f& d, float r, float z0, float z1,
        float side)
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
    }
    else {
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
  default:
    break;
  }
  return best;
}

/** The nearest hit, after \a t_min, of the curved top z = flat_top + top_sag (1 - (x^2 + y^2) /
 * rho^2) of \a obj within its footprint (local frame). */
void
paraboloid(Hit& best, const SceneObject& obj, float flat_top, const Eigen::Vector3f& o,
           const Eigen::Vector3f& d, float t_min)
{
  const bool box = obj.cls == SceneClass::Box;
  const double rho2 = box ? 0.25 * (static_cast<double>(obj.size.x()) * obj.size.x() +
                                    static_cast<double>(obj.size.y()) * obj.size.y())
                          : static_cast<double>(obj.radius) * obj.radius;
  const double k = obj.top_sag / rho2;
  // In double: the curve is a few mm over a metre, its quadratic term tiny.
  const double a = k * (static_cast<double>(d.x()) * d.x() + static_cast<double>(d.y()) * d.y());
  const double b =
    2.0 * k * (static_cast<double>(o.x()) * d.x() + static_cast<double>(o.y()) * d.y()) + d.z();
  const double c = k * (static_cast<double>(o.x()) * o.x() + static_cast<double>(o.y()) * o.y()) +
                   o.z() - flat_top - obj.top_sag;
  double ts[2] = {std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
  if (std::abs(a) < 1e-15) {
    if (std::abs(b) > 1e-15)
      ts[0] = -c / b;
  }
  else {
    const double disc = b * b - 4.0 * a * c;
    if (disc < 0.0)
      return;
    const double q = -0.5 * (b + std::copysign(std::sqrt(disc), b)); // stable roots
    ts[0] = q / a;
    ts[1] = q != 0.0 ? c / q : ts[0];
  }
  for (const double t : ts) {
    if (!(t >= t_min - 1e-6) || !std::isfinite(t))
      continue;
    const Eigen::Vector3f p = o + static_cast<float>(t) * d;
    const bool inside =
      box ? std::abs(p.x()) <= 0.5f * obj.size.x() && std::abs(p.y()) <= 0.5f * obj.size.y()
          : p.x() * p.x() + p.y() * p.y() <= obj.radius * obj.radius;
    if (inside)
      keep(best, static_cast<float>(t), o, d,
           Eigen::Vector3f(static_cast<float>(2.0 * k * p.x()), static_cast<float>(2.0 * k * p.y()),
                           1.f)
             .normalized());
  }
}

/** A box or closed cylinder whose top is curved (top_sag != 0): the solid raised to the
 * curve's highest point; where the ray enters it below the curve (a side, the bottom) that is
 * the hit, otherwise the curve itself. */
Hit
intersectCurvedTop(const SceneObject& obj, const Eigen::Vector3f& o, const Eigen::Vector3f& d)
{
  const bool box = obj.cls == SceneClass::Box;
  const float flat_top = box ? obj.size.z() : obj.height;
  SceneObject raised = obj;
  raised.top_sag = 0.f;
  raised.open_top = raised.handle = false;
  (box ? raised.size.z() : raised.height) += std::max(obj.top_sag, 0.f);
  const Hit entry = intersect(raised, o, d);
  if (!std::isfinite(entry.t))
    return entry;
  const bool through_top = entry.normal.z() > 0.5f;
  if (!through_top &&
      entry.local.z() <= flat_top + curvedTopHeight(obj, entry.local.x(), entry.local.y()))
    return entry;
  Hit best;
  paraboloid(best, obj, flat_top, o, d, entry.t);
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
  SceneClass pixel_class; ///< of its pixels
  Eigen::Matrix3f r_lw;   ///< world to local rotation
  Eigen::Vector3f eye_local;
  Eigen::Vector3f centre; ///< world
  float bound;
};

Prepared
prepare(const SceneObject& o, std::uint16_t id, SceneClass pixel_class, const Eigen::Vector3f& eye)
{
  Prepared p;
  p.object = &o;
  p.id = id;
  p.pixel_class = pixel_class;
  p.r_lw = o.pose.linear().transpose();
  p.eye_local = p.r_lw * (eye - o.pose.translation());
  float extent_z = o.height, extent_r = o.radius + (o.handle ? 0.05f : 0.f);
  if (o.cls == SceneClass::Box) {
    extent_z = o.size.z();
    extent_r = 0.5f * std::hypot(o.size.x(), o.size.y());
  }
  else if (o.cls == SceneClass::Sphere || o.cls == SceneClass::Bowl) {
    extent_z = 2.f * o.radius;
  }
  if (o.top_sag > 0.f)
    extent_z += o.top_sag;
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
  SurfaceMaterial material;
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
      s.material = scene.floor_material;
    }
  }
  if (scene.wall && d.y() > 0.f) {
    const float t = (scene.wall_y - eye.y()) / d.y();
    if (t > 0.f && t < s.t) {
      s.t = t;
      s.normal = -Eigen::Vector3f::UnitY();
      s.albedo = scene.wall_colour;
      s.material = scene.wall_material;
    }
  }
}

void
castObjects(const std::vector<Prepared>& prepared, const TabletopScene& scene,
            const Eigen::Vector3f& eye, const Eigen::Vector3f& d, bool skip_transparent, Surface& s)
{
  const float dd = d.squaredNorm();
  for (const Prepared& p : prepared) {
    if (skip_transparent && p.object->material.transparency > 0.f)
      continue;
    const Eigen::Vector3f oc = eye - p.centre;
    const float b = oc.dot(d);
    if (b * b - dd * (oc.squaredNorm() - p.bound * p.bound) < 0.f)
      continue;
    const Hit hit = p.object->top_sag != 0.f
                      ? intersectCurvedTop(*p.object, p.eye_local, p.r_lw * d)
                      : intersect(*p.object, p.eye_local, p.r_lw * d);
    if (!(hit.t < s.t))
      continue;
    s.t = hit.t;
    s.normal = p.object->pose.linear() * hit.normal;
    s.id = p.id;
    s.cls = p.pixel_class;
    s.material = p.object->material;
    if (p.id == 1) { // the table: a checker of 10 cm cells on the top, plain legs
      const Eigen::Vector3f w = eye + hit.t * d;
      const int cell =
        static_cast<int>(std::floor(w.x() / 0.1f)) + static_cast<int>(std::floor(w.y() / 0.1f));
      const float top =
        p.object->top_sag != 0.f ? curvedTopHeight(*p.object, hit.local.x(), hit.local.y()) : 0.f;
      s.albedo = w.z() - top > -0.005f ? scene.table_colour[cell & 1] : scene.table_colour[1];
    }
    else {
      s.albedo = albedo(*p.object, hit.local);
    }
  }
}

bool
hasNonReferenceMaterials(const TabletopScene& scene)
{
  const auto any = [](const std::vector<SceneObject>& v) {
    return std::any_of(v.begin(), v.end(),
                       [](const SceneObject& o) { return !o.material.isReference(); });
  };
  bool scenery = false;
  for (const SceneryItem& item : scene.scenery)
    scenery = scenery || any(item.parts);
  return !scene.floor_material.isReference() || !scene.wall_material.isReference() ||
         any(scene.furniture) || any(scene.objects) || scenery;
}

/** Casts the rays of one camera through one scene. */
class RayCaster {
public:
  RayCaster(const TabletopScene& scene, const CameraIntrinsics& camera)
      : scene_(scene)
      , camera_(camera)
      , r_cw_(scene.camera_to_world.linear())
      , eye_(scene.camera_to_world.translation())
  {
    for (const SceneObject& f : scene.furniture)
      prepared_.push_back(prepare(f, 1, SceneClass::Table, eye_));
    for (std::size_t i = 0; i < scene.objects.size(); ++i)
      prepared_.push_back(
        prepare(scene.objects[i], static_cast<std::uint16_t>(i + 2), scene.objects[i].cls, eye_));
    for (std::size_t j = 0; j < scene.scenery.size(); ++j)
      for (const SceneObject& part : scene.scenery[j].parts)
        prepared_.push_back(prepare(part, static_cast<std::uint16_t>(kFirstSceneryId + j),
                                    SceneClass::Scenery, eye_));
  }

  /** The ray through pixel (u, v), in the world frame: t along it is the camera depth. */
  Eigen::Vector3f direction(int u, int v) const
  {
    const Eigen::Vector3f ray_c((u - camera_.cx) / camera_.fx, (v - camera_.cy) / camera_.fy, 1.f);
    return r_cw_ * ray_c;
  }

  /** The nearest surface along \a d; transparent objects are skipped if asked. */
  Surface cast(const Eigen::Vector3f& d, bool skip_transparent) const
  {
    Surface s;
    castBackground(scene_, eye_, d, s);
    castObjects(prepared_, scene_, eye_, d, skip_transparent, s);
    return s;
  }

  /** Writes \a s, seen along \a d, into pixel \a idx of \a image: depth, incidence, shaded
   * colour, id, class and (when \a image has materials) material. */
  void record(const Surface& s, const Eigen::Vector3f& d, std::size_t idx,
              RayCastImage& image) const
  {
    image.id[idx] = s.id;
    image.cls[idx] = s.cls;
    image.depth[idx] = s.t;
    const Eigen::Vector3f dn = d.normalized();
    Eigen::Vector3f normal = s.normal;
    if (normal.dot(dn) > 0.f)
      normal = -normal;
    image.incidence[idx] = std::abs(normal.dot(dn));
    const float shade =
      0.35f + 0.5f * std::max(0.f, normal.dot(light_)) + 0.15f * image.incidence[idx];
    image.colour[idx] = shade * s.albedo;
    if (!image.material.empty())
      image.material[idx] = s.material;
    if (s.material.gloss > 0.f) { // the room light's highlight (Phong)
      const Eigen::Vector3f mirrored = 2.f * normal.dot(light_) * normal - light_;
      const float spec = std::pow(std::max(0.f, -mirrored.dot(dn)), 40.f);
      image.colour[idx] += Eigen::Vector3f::Constant(0.8f * s.material.gloss * spec);
    }
  }

private:
  const TabletopScene& scene_;
  const CameraIntrinsics& camera_;
  Eigen::Matrix3f r_cw_;
  Eigen::Vector3f eye_;
  Eigen::Vector3f light_{Eigen::Vector3f(0.3f, -0.4f, 1.f).normalized()};
  std::vector<Prepared> prepared_;
};

RayCastImage
emptyImage(const CameraIntrinsics& camera, bool materials)
{
  const std::size_t n =
    static_cast<std::size_t>(camera.width) * static_cast<std::size_t>(camera.height);
  RayCastImage image;
  image.width = camera.width;
  image.height = camera.height;
  image.depth.assign(n, std::numeric_limits<float>::infinity());
  image.incidence.assign(n, 1.f);
  image.colour.assign(n, Eigen::Vector3f::Zero());
  image.id.assign(n, 0);
  image.cls.assign(n, SceneClass::Background);
  if (materials)
    image.material.assign(n, SurfaceMaterial{});
  return image;
}

/** Seed offset of the see-through draws. */
constexpr std::uint64_t kTransparencyStream = 0xbb67ae8584caa73bULL;

} // namespace

RayCastImage
castRays(const TabletopScene& scene, const CameraIntrinsics& camera)
{
  RayCastImage image = emptyImage(camera, hasNonReferenceMaterials(scene));
  const RayCaster caster(scene, camera);
  for (int v = 0; v < camera.height; ++v)
    for (int u = 0; u < camera.width; ++u) {
      const std::size_t idx = static_cast<std::size_t>(v) * camera.width + u;
      const Eigen::Vector3f d = caster.direction(u, v);
      const Surface s = caster.cast(d, false);
      if (std::isfinite(s.t))
        caster.record(s, d, idx, image);
    }
  return image;
}

bool
hasTransparentSurfaces(const RayCastImage& image)
{
  return std::any_of(image.material.begin(), image.material.end(),
                     [](const SurfaceMaterial& m) { return m.transparency > 0.f; });
}

RayCastImage
castRaysBehindTransparent(const TabletopScene& scene, const CameraIntrinsics& camera,
                          const RayCastImage& front)
{
  RayCastImage behind = emptyImage(camera, true);
  if (front.material.empty())
    return behind;
  const RayCaster caster(scene, camera);
  for (int v = 0; v < camera.height; ++v)
    for (int u = 0; u < camera.width; ++u) {
      const std::size_t idx = static_cast<std::size_t>(v) * camera.width + u;
      if (!(front.material[idx].transparency > 0.f))
        continue;
      const Eigen::Vector3f d = caster.direction(u, v);
      const Surface s = caster.cast(d, true);
      if (std::isfinite(s.t))
        caster.record(s, d, idx, behind);
    }
  return behind;
}

void
seeThroughTransparent(RayCastImage& image, const RayCastImage& behind,
                      const DepthSensorModel& sensor, std::uint64_t seed)
{
  if (image.material.empty())
    return;
  Random rng(seed ^ kTransparencyStream);
  for (std::size_t i = 0; i < image.depth.size(); ++i) {
    const float tau = image.material[i].transparency;
    if (!(tau > 0.f))
      continue;
    const bool has_behind = std::isfinite(behind.depth[i]);
    const Eigen::Vector3f back = has_behind ? behind.colour[i] : Eigen::Vector3f::Constant(0.5f);
    image.colour[i] = (1.f - tau) * image.colour[i] + tau * 0.9f * back; // a slight tint
    if (!has_behind || !rng.chance(tau * sensor.see_through))
      continue; // the weak front return (diffuseReturn counts the transparency)
    image.depth[i] = behind.depth[i];
    image.incidence[i] = behind.incidence[i];
    image.material[i] = behind.material[i];
    image.id[i] = behind.id[i];
    image.cls[i] = behind.cls[i];
  }
}

} // namespace facyl
