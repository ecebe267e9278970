/*
 * facyl: fast cylinder detection for PCL.
 * Random tabletop scenes: table, objects (apart, touching, stacked, leaning) and camera.
 */
#include "scene_realism.h"

#include <facyl/features/polygon.h>
#include <facyl/simulation/random.h>
#include <facyl/simulation/tabletop_scene.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace facyl {

namespace {

constexpr float kPi = 3.14159265358979f;
constexpr float kSlab = 0.03f; ///< table top thickness (m)

float
draw(Random& rng, const Range& r)
{
  return rng.uniform(r.min, r.max);
}

Eigen::Vector3f
randomColour(Random& rng)
{
  const float r = rng.uniform(0.1f, 0.95f), g = rng.uniform(0.1f, 0.95f);
  return {r, g, rng.uniform(0.1f, 0.95f)};
}

/** Rotation whose z column is \a z, turned by \a yaw about it. */
Eigen::Matrix3f
frameWithZ(const Eigen::Vector3f& z, float yaw)
{
  const Eigen::Vector3f helper =
    std::abs(z.z()) < 0.9f ? Eigen::Vector3f::UnitZ() : Eigen::Vector3f::UnitX();
  const Eigen::Vector3f x = helper.cross(z).normalized();
  Eigen::Matrix3f r;
  r.col(0) = x;
  r.col(1) = z.cross(x);
  r.col(2) = z;
  return r * Eigen::AngleAxisf(yaw, Eigen::Vector3f::UnitZ()).toRotationMatrix();
}

// ---------------------------------------------------------------- footprints

/** What an object occupies, for the placement tests: the convex hull of its projection on the
 * table (world xy) and its vertical extent. */
struct Footprint {
  std::vector<Eigen::Vector2f> hull; ///< counter-clockwise
  float z0{0.f}, z1{0.f};
};

/** Points that bound the object's shape, in its local frame. */
std::vector<Eigen::Vector3f>
skeleton(const SceneObject& o)
{
  std::vector<Eigen::Vector3f> s;
  const auto circle = [&s](float r, float z) {
    for (int k = 0; k < 32; ++k) {
      const float t = 2.f * kPi * static_cast<float>(k) / 32.f;
      // Circumscribed 32-gon: the polygon contains the circle.
      const float rr = r / std::cos(kPi / 32.f);
      s.emplace_back(rr * std::cos(t), rr * std::sin(t), z);
    }
  };
  switch (o.cls) {
  case SceneClass::Cylinder:
    circle(o.radius, 0.f);
    circle(o.radius, o.height);
    if (o.handle) {
      const float a = std::min(0.3f * o.height, 0.035f) + 0.008f;
      for (float dz : {-a, a})
        for (float dy : {-0.008f, 0.008f})
          s.emplace_back(o.radius + a, dy, 0.5f * o.height + dz);
    }
    break;
  case SceneClass::Box:
    for (int k = 0; k < 8; ++k)
      s.emplace_back((k & 1 ? 0.5f : -0.5f) * o.size.x(), (k & 2 ? 0.5f : -0.5f) * o.size.y(),
                     k & 4 ? o.size.z() : 0.f);
    break;
  case SceneClass::Sphere:
    circle(o.radius, o.radius);
    s.emplace_back(0.f, 0.f, 0.f);
    s.emplace_back(0.f, 0.f, 2.f * o.radius);
    break;
  case SceneClass::Cone:
    circle(o.radius, 0.f);
    s.emplace_back(0.f, 0.f, o.height);
    break;
  case SceneClass::Bowl:
    circle(o.radius, o.radius);
    s.emplace_back(0.f, 0.f, 0.f);
    break;
  default:
    break;
  }
  return s;
}

Eigen::Vector2f
centroid(const std::vector<Eigen::Vector2f>& points)
{
  Eigen::Vector2f c = Eigen::Vector2f::Zero();
  for (const auto& p : points)
    c += p;
  return points.empty() ? c : Eigen::Vector2f(c / static_cast<float>(points.size()));
}

Footprint
footprintOf(const SceneObject& o)
{
  Footprint f;
  f.z0 = std::numeric_limits<float>::infinity();
  f.z1 = -f.z0;
  std::vector<Eigen::Vector2f> xy;
  for (const Eigen::Vector3f& p : skeleton(o)) {
    const Eigen::Vector3f w = o.pose * p;
    xy.push_back(w.head<2>());
    f.z0 = std::min(f.z0, w.z());
    f.z1 = std::max(f.z1, w.z());
  }
  f.hull = convexHull2D(xy);
  return f;
}

/** Largest gap between the projections of two convex polygons over their edge normals
 * (separating axis test): > 0 apart, <= 0 overlapping or touching. */
float
separation(const std::vector<Eigen::Vector2f>& a, const std::vector<Eigen::Vector2f>& b)
{
  float best = -std::numeric_limits<float>::infinity();
  for (const auto* poly : {&a, &b})
    for (std::size_t i = 0; i < poly->size(); ++i) {
      const Eigen::Vector2f e = (*poly)[(i + 1) % poly->size()] - (*poly)[i];
      if (e.squaredNorm() < 1e-12f)
        continue;
      const Eigen::Vector2f n = Eigen::Vector2f(e.y(), -e.x()).normalized();
      float a0 = std::numeric_limits<float>::infinity(), a1 = -a0, b0 = a0, b1 = -a0;
      for (const auto& p : a)
        a0 = std::min(a0, n.dot(p)), a1 = std::max(a1, n.dot(p));
      for (const auto& p : b)
        b0 = std::min(b0, n.dot(p)), b1 = std::max(b1, n.dot(p));
      best = std::max(best, std::max(b0 - a1, a0 - b1));
    }
  return best;
}

// ---------------------------------------------------------------- objects

/** A random object in its local frame (pose not set). */
SceneObject
randomObject(Random& rng, const TabletopSceneParameters& params)
{
  SceneObject o;
  o.colour[0] = randomColour(rng);
  o.colour[1] = randomColour(rng);
  o.texture = rng.integer(0, 2);
  if (rng.chance(params.cylinder_share)) {
    o.cls = SceneClass::Cylinder;
    switch (rng.integer(0, 3)) {
    case 0:
      o.kind = "can";
      o.radius = rng.uniform(0.028f, 0.05f);
      o.height = rng.uniform(0.07f, 0.16f);
      break;
    case 1:
      o.kind = "cup";
      o.radius = rng.uniform(0.035f, 0.05f);
      o.height = rng.uniform(0.07f, 0.11f);
      o.open_top = true;
      o.handle = rng.chance(0.6);
      break;
    case 2:
      o.kind = "tube";
      o.radius = rng.uniform(0.02f, 0.038f);
      o.height = rng.uniform(0.15f, 0.27f);
      break;
    default:
      o.kind = "tin";
      o.radius = rng.uniform(0.05f, 0.1f);
      o.height = rng.uniform(0.04f, 0.1f);
      break;
    }
    o.lying = !o.open_top && o.kind != "tin" && rng.chance(params.lying_share);
    return o;
  }
  switch (rng.integer(0, 3)) {
  case 0:
    o.cls = SceneClass::Box;
    o.kind = "box";
    o.size = Eigen::Vector3f(rng.uniform(0.04f, 0.2f), rng.uniform(0.04f, 0.15f),
                             rng.uniform(0.03f, 0.2f));
    break;
  case 1:
    o.cls = SceneClass::Sphere;
    o.kind = "sphere";
    o.radius = rng.uniform(0.03f, 0.07f);
    break;
  case 2:
    o.cls = SceneClass::Cone;
    o.kind = "cone";
    o.radius = rng.uniform(0.03f, 0.06f);
    o.height = rng.uniform(0.08f, 0.18f);
    break;
  default:
    o.cls = SceneClass::Bowl;
    o.kind = "bowl";
    o.radius = rng.uniform(0.05f, 0.09f);
    break;
  }
  return o;
}

/** Pose of \a o standing (or lying) with its footprint centred at \a centre, its base at
 * height \a z. */
void
setPose(SceneObject& o, const Eigen::Vector2f& centre, float z, float yaw)
{
  if (o.lying) {
    const Eigen::Vector3f axis(std::cos(yaw), std::sin(yaw), 0.f);
    o.pose.linear() = frameWithZ(axis, 0.f);
    o.pose.translation() =
      Eigen::Vector3f(centre.x(), centre.y(), z + o.radius) - 0.5f * o.height * axis;
  }
  else {
    o.pose.linear() = frameWithZ(Eigen::Vector3f::UnitZ(), yaw);
    o.pose.translation() = Eigen::Vector3f(centre.x(), centre.y(), z);
  }
}

/** Height of the flat top of \a o, or NaN when nothing can stand on it. */
float
flatTop(const SceneObject& o)
{
  if (o.leaning || o.lying)
    return std::numeric_limits<float>::quiet_NaN();
  if (o.cls == SceneClass::Box)
    return o.pose.translation().z() + o.size.z();
  if (o.cls == SceneClass::Cylinder && !o.open_top)
    return o.pose.translation().z() + o.height;
  return std::numeric_limits<float>::quiet_NaN();
}

/** Placed objects and the tests a new one must pass. */
class Layout {
public:
  Layout(const TabletopScene& scene, const Eigen::Vector2f& half_area)
      : scene_(scene)
      , half_area_(half_area)
  {
  }

  const std::vector<SceneObject>& objects() const
  {
    return objects_;
  }

  /** True if \a f lies on the table and keeps \a margin from every placed object except
   * those in \a partners (which it may touch). */
  bool fits(const Footprint& f, float margin, const std::vector<int>& partners) const
  {
    for (const auto& p : f.hull)
      if (!onTableTop(p))
        return false;
    for (std::size_t i = 0; i < objects_.size(); ++i) {
      if (std::find(partners.begin(), partners.end(), static_cast<int>(i)) != partners.end())
        continue;
      const Footprint& g = footprints_[i];
      const bool same_level = f.z0 < g.z1 - 0.001f && g.z0 < f.z1 - 0.001f;
      if (same_level && separation(f.hull, g.hull) < margin)
        return false;
    }
    return true;
  }

  /** A point of the objects' area on the table. */
  Eigen::Vector2f randomSpot(Random& rng) const
  {
    return {rng.uniform(-half_area_.x(), half_area_.x()),
            rng.uniform(-half_area_.y(), half_area_.y())};
  }

  void add(SceneObject o)
  {
    const int index = static_cast<int>(objects_.size());
    for (const int j : o.touches)
      objects_[static_cast<std::size_t>(j)].touches.push_back(index);
    footprints_.push_back(footprintOf(o));
    objects_.push_back(std::move(o));
  }

  const Footprint& footprint(std::size_t i) const
  {
    return footprints_[i];
  }

private:
  bool onTableTop(const Eigen::Vector2f& p) const
  {
    constexpr float inset = 0.005f;
    if (scene_.table_shape == TableShape::Round)
      return p.norm() <= scene_.table_radius - inset;
    return std::abs(p.x()) <= 0.5f * scene_.table_width - inset &&
           std::abs(p.y()) <= 0.5f * scene_.table_depth - inset;
  }

  const TabletopScene& scene_;
  Eigen::Vector2f half_area_;
  std::vector<SceneObject> objects_;
  std::vector<Footprint> footprints_;
};

/** A random index in [0, n) for which \a eligible holds, or -1. */
template <typename Eligible>
int
pickOne(Random& rng, std::size_t n, Eligible eligible)
{
  std::vector<int> candidates;
  for (std::size_t i = 0; i < n; ++i)
    if (eligible(i))
      candidates.push_back(static_cast<int>(i));
  if (candidates.empty())
    return -1;
  return candidates[static_cast<std::size_t>(
    rng.integer(0, static_cast<int>(candidates.size()) - 1))];
}

constexpr float kApart = 0.02f;   ///< gap between objects that do not touch (m)
constexpr float kContact = 5e-4f; ///< objects in contact overlap this much (m)

bool
placeApart(SceneObject& o, const Layout& layout, Random& rng)
{
  setPose(o, layout.randomSpot(rng), 0.f, rng.uniform(-kPi, kPi));
  return layout.fits(footprintOf(o), kApart, {});
}

/** Beside a random object on the table, footprints in contact. */
bool
placeTouching(SceneObject& o, const Layout& layout, Random& rng)
{
  const auto& placed = layout.objects();
  const int b = pickOne(rng, placed.size(),
                        [&](std::size_t i) { return placed[i].support < 0 && !placed[i].leaning; });
  if (b < 0)
    return false;
  const float yaw = rng.uniform(-kPi, kPi), phi = rng.uniform(-kPi, kPi);
  const Eigen::Vector2f dir(std::cos(phi), std::sin(phi));
  const Footprint& fb = layout.footprint(static_cast<std::size_t>(b));
  const Eigen::Vector2f from = centroid(fb.hull);
  // Smallest distance along dir at which the footprints no longer overlap: contact.
  float lo = 0.f, hi = 0.6f;
  for (int it = 0; it < 30; ++it) {
    const float mid = 0.5f * (lo + hi);
    setPose(o, from + mid * dir, 0.f, yaw);
    (separation(footprintOf(o).hull, fb.hull) < 0.f ? lo : hi) = mid;
  }
  setPose(o, from + (hi - kContact) * dir, 0.f, yaw);
  if (!layout.fits(footprintOf(o), 0.003f, {b}))
    return false;
  o.touches = {b};
  return true;
}

/** On the flat top of a box, can or tin. Cans, tins and boxes stand; a can or tube may lie on
 * a box. */
bool
stackable(const SceneObject& o)
{
  return o.cls == SceneClass::Box || (o.cls == SceneClass::Cylinder && !o.open_top);
}

bool
placeStacked(SceneObject& o, const Layout& layout, Random& rng)
{
  if (!stackable(o))
    return false;
  const auto& placed = layout.objects();
  // Supports: a flat top, at most one object below it already (stacks of three at most).
  const int b = pickOne(rng, placed.size(), [&](std::size_t i) {
    const SceneObject& c = placed[i];
    return std::isfinite(flatTop(c)) && (c.support < 0 || placed[c.support].support < 0) &&
           (!o.lying || c.cls == SceneClass::Box);
  });
  if (b < 0)
    return false;
  const SceneObject& base = placed[static_cast<std::size_t>(b)];
  const float top = flatTop(base);
  const Eigen::Vector2f c = base.pose.translation().head<2>();
  Eigen::Vector2f centre = c;
  if (base.cls == SceneClass::Box) {
    const Eigen::Vector2f local(rng.uniform(-0.3f, 0.3f) * base.size.x(),
                                rng.uniform(-0.3f, 0.3f) * base.size.y());
    centre += base.pose.linear().topLeftCorner<2, 2>() * local;
  }
  else {
    const float slack = std::max(0.f, base.radius - 0.8f * o.radius);
    const float t = rng.uniform(-kPi, kPi), r = rng.uniform(0.f, 0.5f) * slack;
    centre += r * Eigen::Vector2f(std::cos(t), std::sin(t));
  }
  setPose(o, centre, top, rng.uniform(-kPi, kPi));
  const Footprint f = footprintOf(o);
  // Mostly supported: the object's centre of mass lies over the support's top.
  const Footprint& fb = layout.footprint(static_cast<std::size_t>(b));
  const std::vector<Eigen::Vector2f> centre_only{centre, centre + Eigen::Vector2f(1e-4f, 0.f),
                                                 centre + Eigen::Vector2f(0.f, 1e-4f)};
  if (separation(centre_only, fb.hull) > -0.01f)
    return false;
  if (!layout.fits(f, 0.003f, {b}))
    return false;
  o.support = b;
  o.touches = {b};
  return true;
}

/** A can or tube tilted against the side of a taller box. */
bool
placeLeaning(SceneObject& o, const Layout& layout, Random& rng)
{
  if (o.cls != SceneClass::Cylinder || o.open_top || o.lying || o.kind == "tin")
    return false;
  const auto& placed = layout.objects();
  const float tilt = rng.uniform(0.15f, 0.4f);
  // A box on the table, taller than the point where the object rests on it (the object is
  // shortened to rest against the box's side, down to 5 cm).
  const auto rest_height = [&](const SceneObject& box) {
    return (box.size.z() - 0.005f - o.radius * std::sin(tilt)) / std::cos(tilt);
  };
  const int b = pickOne(rng, placed.size(), [&](std::size_t i) {
    const SceneObject& c = placed[i];
    return c.cls == SceneClass::Box && c.support < 0 && rest_height(c) >= 0.05f;
  });
  if (b < 0)
    return false;
  const SceneObject& box = placed[static_cast<std::size_t>(b)];
  o.height = std::min(o.height, rest_height(box));
  // One of the box's four faces; n points out of it.
  const int face = rng.integer(0, 3);
  const Eigen::Vector3f local_n = face < 2 ? Eigen::Vector3f(face ? -1.f : 1.f, 0.f, 0.f)
                                           : Eigen::Vector3f(0.f, face == 3 ? -1.f : 1.f, 0.f);
  const Eigen::Vector3f n = box.pose.linear() * local_n;
  const float half = face < 2 ? 0.5f * box.size.x() : 0.5f * box.size.y();
  const float along = rng.uniform(-0.3f, 0.3f) * (face < 2 ? box.size.y() : box.size.x());
  const Eigen::Vector3f side = Eigen::Vector3f::UnitZ().cross(n);
  const Eigen::Vector3f face_point = box.pose.translation() + half * n + along * side;
  const Eigen::Matrix3f rotation =
    Eigen::AngleAxisf(tilt, Eigen::Vector3f::UnitZ().cross(-n).normalized()).toRotationMatrix() *
    frameWithZ(Eigen::Vector3f::UnitZ(), rng.uniform(-kPi, kPi));
  const Footprint& fb = layout.footprint(static_cast<std::size_t>(b));
  const auto pose_at = [&](float s) {
    o.pose.linear() = rotation;
    o.pose.translation() = face_point + s * n;
    o.pose.translation().z() = o.radius * std::sin(tilt); // the base's low edge on the table
  };
  float lo = 0.f, hi = 0.6f;
  for (int it = 0; it < 30; ++it) {
    const float mid = 0.5f * (lo + hi);
    pose_at(mid);
    (separation(footprintOf(o).hull, fb.hull) < 0.f ? lo : hi) = mid;
  }
  pose_at(hi - kContact);
  if (!layout.fits(footprintOf(o), 0.003f, {b}))
    return false;
  o.leaning = true;
  o.touches = {b};
  return true;
}

void
drawTable(const TabletopSceneParameters& params, Random& rng, TabletopScene& scene)
{
  scene.table_shape =
    rng.chance(params.round_table_share) ? TableShape::Round : TableShape::Rectangle;
  scene.table_width = draw(rng, params.table_width);
  scene.table_depth = draw(rng, params.table_depth);
  scene.table_radius = draw(rng, params.table_radius);
  scene.table_height = draw(rng, params.table_height);
  scene.table_colour[0] =
    Eigen::Vector3f(rng.uniform(0.4f, 0.8f), rng.uniform(0.3f, 0.6f), rng.uniform(0.2f, 0.5f));
  scene.table_colour[1] = 0.8f * scene.table_colour[0];
  scene.floor_colour = Eigen::Vector3f::Constant(rng.uniform(0.3f, 0.6f));
  scene.wall_colour = Eigen::Vector3f::Constant(rng.uniform(0.55f, 0.9f));
  const bool round = scene.table_shape == TableShape::Round;

  // The top is a slab whose upper face is the plane z = 0.
  SceneObject top;
  top.cls = SceneClass::Table;
  top.kind = "table";
  if (round) {
    top.cls = SceneClass::Cylinder; // shape only: the pixels are the table's
    top.radius = scene.table_radius;
    top.height = kSlab;
  }
  else {
    top.cls = SceneClass::Box;
    top.size = Eigen::Vector3f(scene.table_width, scene.table_depth, kSlab);
  }
  top.pose.translation() = Eigen::Vector3f(0.f, 0.f, -kSlab);
  scene.furniture.push_back(top);
  if (params.table_legs) {
    const float leg_height = scene.table_height - kSlab;
    if (round) {
      SceneObject pedestal;
      pedestal.cls = SceneClass::Cylinder;
      pedestal.radius = 0.05f;
      pedestal.height = leg_height;
      pedestal.pose.translation() = Eigen::Vector3f(0.f, 0.f, -scene.table_height);
      scene.furniture.push_back(pedestal);
    }
    else {
      for (int k = 0; k < 4; ++k) {
        SceneObject leg;
        leg.cls = SceneClass::Box;
        leg.size = Eigen::Vector3f(0.05f, 0.05f, leg_height);
        leg.pose.translation() =
          Eigen::Vector3f((k & 1 ? 0.5f : -0.5f) * scene.table_width + (k & 1 ? -0.05f : 0.05f),
                          (k & 2 ? 0.5f : -0.5f) * scene.table_depth + (k & 2 ? -0.05f : 0.05f),
                          -scene.table_height);
        scene.furniture.push_back(leg);
      }
    }
  }
  scene.wall = rng.chance(params.wall_share);
  const float far_edge = round ? scene.table_radius : 0.5f * scene.table_depth;
  scene.wall_y = far_edge + rng.uniform(0.f, 0.3f);
}

/** Looks at the objects' area from the -y side, high enough to see the tallest object
 * beyond the sensor's minimum range. */
void
drawCamera(const TabletopSceneParameters& params, Random& rng, TabletopScene& scene)
{
  float tallest = 0.f;
  for (const SceneObject& o : scene.objects)
    tallest = std::max(tallest, footprintOf(o).z1);
  float distance = draw(rng, params.camera_distance);
  const float elevation = draw(rng, params.camera_elevation);
  const float azimuth = draw(rng, params.camera_azimuth);
  const float roll = draw(rng, params.camera_roll);
  const float j = params.camera_target_jitter;
  const Eigen::Vector3f target(rng.uniform(-j, j), rng.uniform(-j, j), 0.05f);
  distance = std::max(distance, (tallest - target.z() + params.sensor.min_range + 0.05f) /
                                  std::sin(elevation));
  const Eigen::Vector3f eye =
    target + distance * Eigen::Vector3f(std::sin(azimuth) * std::cos(elevation),
                                        -std::cos(azimuth) * std::cos(elevation),
                                        std::sin(elevation));
  const Eigen::Vector3f forward = (target - eye).normalized();
  const Eigen::Vector3f right = forward.cross(Eigen::Vector3f::UnitZ()).normalized();
  Eigen::Matrix3f rotation;
  rotation.col(0) = right;
  rotation.col(1) = forward.cross(right);
  rotation.col(2) = forward;
  scene.camera_to_world.linear() =
    rotation * Eigen::AngleAxisf(roll, Eigen::Vector3f::UnitZ()).toRotationMatrix();
  scene.camera_to_world.translation() = eye;
}

} // namespace

TabletopScene
generateTabletopScene(const TabletopSceneParameters& params)
{
  const std::string why = validate(params);
  if (!why.empty())
    throw std::invalid_argument("facyl::generateTabletopScene: " + why);
  Random rng(params.seed);
  TabletopScene scene;
  drawTable(params, rng, scene);

  const bool round = scene.table_shape == TableShape::Round;
  const Eigen::Vector2f half_area =
    round ? Eigen::Vector2f::Constant(std::min(0.36f, 0.7f * scene.table_radius))
          : Eigen::Vector2f(std::min(0.36f, 0.5f * scene.table_width - 0.1f),
                            std::min(0.24f, 0.5f * scene.table_depth - 0.1f));
  Layout layout(scene, half_area);
  const std::size_t count =
    params.min_objects + static_cast<std::size_t>(rng.integer(
                           0, static_cast<int>(params.max_objects - params.min_objects)));
  for (std::size_t attempt = 0; layout.objects().size() < count && attempt < 60 * count + 20;
       ++attempt) {
    const double mode = rng.unit();
    SceneObject o = randomObject(rng, params);
    const bool stack = mode >= params.touch_share && mode < params.touch_share + params.stack_share;
    for (int redraw = 0; stack && !stackable(o) && redraw < 10; ++redraw)
      o = randomObject(rng, params); // what is stacked: boxes, cans, tins, tubes
    bool placed = false;
    if (layout.objects().empty() ||
        mode >= params.touch_share + params.stack_share + params.lean_share)
      placed = placeApart(o, layout, rng);
    else if (mode < params.touch_share)
      placed = placeTouching(o, layout, rng);
    else if (mode < params.touch_share + params.stack_share)
      placed = placeStacked(o, layout, rng) || placeTouching(o, layout, rng);
    else
      placed = placeLeaning(o, layout, rng) || placeTouching(o, layout, rng);
    if (placed)
      layout.add(std::move(o));
  }
  scene.objects = layout.objects();
  drawCamera(params, rng, scene);
  detail::addRealism(params, scene);
  return scene;
}

TabletopSceneParameters
clutteredSceneParameters()
{
  TabletopSceneParameters p;
  p.min_objects = 4;
  p.max_objects = 10;
  p.touch_share = 0.45f;
  p.stack_share = 0.2f;
  p.lean_share = 0.08f;
  p.round_table_share = 0.3f;
  p.table_width = {0.5f, 1.4f};
  p.table_depth = {0.4f, 1.0f};
  p.table_radius = {0.3f, 0.55f};
  p.table_height = {0.45f, 0.8f};
  p.table_legs = true;
  p.wall_share = 0.3f;
  p.camera_distance = {0.55f, 1.6f};
  p.camera_elevation = {0.35f, 1.4f};
  p.camera_azimuth = {-0.6f, 0.6f};
  p.camera_roll = {-0.15f, 0.15f};
  p.camera_target_jitter = 0.12f;
  return p;
}

TabletopSceneParameters
realisticSceneParameters()
{
  TabletopSceneParameters p = clutteredSceneParameters();
  p.wall_share = 0.15f; // more room for the far background
  p.camera_distance = {0.55f, 1.8f};
  p.camera_elevation = {0.26f, 1.48f}; // 15 (grazing) to 85 degrees (straight above)
  p.any_roll_share = 0.3f;
  p.table_sag = {-0.006f, 0.006f};
  p.table_materials = {0.35f, 0.3f, 0.f};
  p.floor_materials = {0.3f, 0.15f, 0.f};
  p.object_materials = {0.3f, 0.15f, 0.08f};
  p.min_background_items = 2;
  p.max_background_items = 6;
  p.background_distance = {1.5f, 4.f};
  p.robot_share = 0.35f;
  return p;
}

bool
parseLayoutPreset(const std::string& name, TabletopSceneParameters& params)
{
  if (name == "spread")
    params = TabletopSceneParameters{};
  else if (name == "cluttered")
    params = clutteredSceneParameters();
  else if (name == "realistic")
    params = realisticSceneParameters();
  else
    return false;
  return true;
}

bool
TabletopScene::onTable(float x, float y) const
{
  if (table_shape == TableShape::Round)
    return x * x + y * y <= table_radius * table_radius;
  return std::abs(x) <= 0.5f * table_width && std::abs(y) <= 0.5f * table_depth;
}

} // namespace facyl
