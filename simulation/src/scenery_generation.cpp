/*
 * facyl: fast cylinder detection for PCL.
 * Scenery of the tabletop scenes: far furniture (tables with things on them, shelves,
 * chairs, cabinets, stacked boxes) and robot arms reaching into the image. Scenery has
 * its own pixel ids and SceneClass::Scenery, so evaluators can ignore what is detected
 * on it.
 */
#include "scene_realism.h"

#include <algorithm>
#include <cmath>

namespace facyl {
namespace detail {

namespace {

constexpr float kPi = 3.14159265358979f;

// ---------------------------------------------------------------- parts

/** A colour of furniture or packaging: muted, drawn in order r, g, b. */
Eigen::Vector3f
mutedColour(Random& rng)
{
  const float grey = rng.uniform(0.25f, 0.75f);
  const float r = grey + rng.uniform(-0.15f, 0.15f);
  const float g = grey + rng.uniform(-0.15f, 0.15f);
  const float b = grey + rng.uniform(-0.15f, 0.15f);
  return {r, g, b};
}

SceneObject
part(SceneClass shape, const Eigen::Vector3f& colour)
{
  SceneObject p;
  p.cls = shape; // the shape only: the pixels are scenery
  p.colour[0] = p.colour[1] = colour;
  return p;
}

/** A box of \a size whose bottom face is centred at \a base, turned by \a yaw about z. */
SceneObject
boxPart(const Eigen::Vector3f& size, const Eigen::Vector3f& base, const Eigen::Vector3f& colour,
        float yaw = 0.f)
{
  SceneObject p = part(SceneClass::Box, colour);
  p.size = size;
  p.pose.linear() = Eigen::AngleAxisf(yaw, Eigen::Vector3f::UnitZ()).toRotationMatrix();
  p.pose.translation() = base;
  return p;
}

/** A closed cylinder of \a radius from \a from to \a to. */
SceneObject
rodPart(float radius, const Eigen::Vector3f& from, const Eigen::Vector3f& to,
        const Eigen::Vector3f& colour)
{
  SceneObject p = part(SceneClass::Cylinder, colour);
  p.radius = radius;
  p.height = (to - from).norm();
  p.pose.linear() =
    Eigen::Quaternionf::FromTwoVectors(Eigen::Vector3f::UnitZ(), to - from).toRotationMatrix();
  p.pose.translation() = from;
  return p;
}

/** A sphere of \a radius centred at \a centre (a joint). */
SceneObject
ballPart(float radius, const Eigen::Vector3f& centre, const Eigen::Vector3f& colour)
{
  SceneObject p = part(SceneClass::Sphere, colour);
  p.radius = radius;
  p.pose.translation() = centre - Eigen::Vector3f(0.f, 0.f, radius);
  return p;
}

/** A box or a can of household size standing at \a base. */
SceneObject
clutterPart(Random& rng, const Eigen::Vector3f& base)
{
  const Eigen::Vector3f colour = mutedColour(rng);
  if (rng.chance(0.5)) {
    const float w = rng.uniform(0.06f, 0.25f), d = rng.uniform(0.05f, 0.2f);
    const float h = rng.uniform(0.05f, 0.3f);
    return boxPart({w, d, h}, base, colour, rng.uniform(-0.3f, 0.3f));
  }
  const float radius = rng.uniform(0.03f, 0.07f);
  return rodPart(radius, base, base + Eigen::Vector3f(0.f, 0.f, rng.uniform(0.08f, 0.25f)), colour);
}

// ---------------------------------------------------------------- items (local frame:
// floor at z = 0, front towards -y, centred on the origin)

struct Built {
  SceneryItem item;
  float radius{0.f}; ///< of a circle round its footprint
};

/** Four legs under a rectangle of w x d at height h, inset by 5 cm. */
void
addLegs(std::vector<SceneObject>& parts, float w, float d, float h, const Eigen::Vector3f& c)
{
  for (int k = 0; k < 4; ++k) {
    const float x = (k & 1 ? 0.5f : -0.5f) * w + (k & 1 ? -0.05f : 0.05f);
    const float y = (k & 2 ? 0.5f : -0.5f) * d + (k & 2 ? -0.05f : 0.05f);
    parts.push_back(boxPart({0.04f, 0.04f, h}, {x, y, 0.f}, c));
  }
}

/** Things in a row along x on a surface of width w at height z. */
void
addRow(Random& rng, std::vector<SceneObject>& parts, float w, float z, int count)
{
  for (int i = 0; i < count; ++i) {
    const float x = -0.5f * w + (static_cast<float>(i) + 0.5f) * w / static_cast<float>(count);
    parts.push_back(clutterPart(rng, {x, rng.uniform(-0.05f, 0.05f), z}));
  }
}

Built
farTable(Random& rng)
{
  const float w = rng.uniform(0.6f, 1.6f), d = rng.uniform(0.5f, 0.9f);
  const float h = rng.uniform(0.7f, 0.8f);
  const Eigen::Vector3f c = mutedColour(rng);
  Built b;
  b.item.kind = "table";
  b.item.parts.push_back(boxPart({w, d, 0.03f}, {0.f, 0.f, h - 0.03f}, c));
  addLegs(b.item.parts, w, d, h - 0.03f, c);
  addRow(rng, b.item.parts, w, h, rng.integer(0, 3));
  b.radius = 0.5f * std::hypot(w, d);
  return b;
}

Built
shelf(Random& rng)
{
  const float w = rng.uniform(0.6f, 1.2f), d = rng.uniform(0.25f, 0.4f);
  const float h = rng.uniform(1.2f, 2.f);
  const Eigen::Vector3f c = mutedColour(rng);
  Built b;
  b.item.kind = "shelf";
  auto& parts = b.item.parts;
  for (const float x : {-0.5f * w + 0.01f, 0.5f * w - 0.01f})
    parts.push_back(boxPart({0.02f, d, h}, {x, 0.f, 0.f}, c));
  parts.push_back(boxPart({w, 0.01f, h}, {0.f, 0.5f * d - 0.005f, 0.f}, c));
  const int boards = rng.integer(3, 5);
  for (int i = 0; i < boards; ++i) {
    const float z = static_cast<float>(i) * (h - 0.02f) / static_cast<float>(boards - 1);
    parts.push_back(boxPart({w - 0.04f, d - 0.01f, 0.02f}, {0.f, -0.005f, z}, c));
    if (i + 1 < boards)
      addRow(rng, parts, w - 0.1f, z + 0.02f, rng.integer(0, 3));
  }
  b.radius = 0.5f * std::hypot(w, d);
  return b;
}

Built
chair(Random& rng)
{
  const Eigen::Vector3f c = mutedColour(rng);
  const float seat = rng.uniform(0.42f, 0.48f);
  Built b;
  b.item.kind = "chair";
  auto& parts = b.item.parts;
  parts.push_back(boxPart({0.45f, 0.45f, 0.04f}, {0.f, 0.f, seat}, c));
  parts.push_back(boxPart({0.45f, 0.03f, 0.45f}, {0.f, 0.21f, seat + 0.04f}, c));
  for (int k = 0; k < 4; ++k) {
    const Eigen::Vector3f foot((k & 1 ? 0.2f : -0.2f), (k & 2 ? 0.2f : -0.2f), 0.f);
    parts.push_back(rodPart(0.015f, foot, foot + Eigen::Vector3f(0.f, 0.f, seat), c));
  }
  b.radius = 0.35f;
  return b;
}

Built
cabinet(Random& rng)
{
  const float w = rng.uniform(0.5f, 1.f), d = rng.uniform(0.4f, 0.6f);
  const float h = rng.uniform(0.7f, 1.2f);
  Built b;
  b.item.kind = "cabinet";
  b.item.parts.push_back(boxPart({w, d, h}, Eigen::Vector3f::Zero(), mutedColour(rng)));
  addRow(rng, b.item.parts, w, h, rng.integer(0, 2));
  b.radius = 0.5f * std::hypot(w, d);
  return b;
}

Built
boxStack(Random& rng)
{
  Built b;
  b.item.kind = "boxes";
  float z = 0.f, w = rng.uniform(0.3f, 0.6f), d = rng.uniform(0.3f, 0.5f);
  b.radius = 0.5f * std::hypot(w, d);
  const int count = rng.integer(1, 3);
  for (int i = 0; i < count; ++i) {
    const float h = rng.uniform(0.2f, 0.45f);
    const Eigen::Vector3f colour = mutedColour(rng);
    b.item.parts.push_back(boxPart({w, d, h}, {0.f, 0.f, z}, colour, rng.uniform(-0.2f, 0.2f)));
    z += h;
    w *= rng.uniform(0.7f, 1.f);
    d *= rng.uniform(0.7f, 1.f);
  }
  return b;
}

Built
randomItem(Random& rng)
{
  switch (rng.integer(0, 4)) {
  case 0:
    return farTable(rng);
  case 1:
    return shelf(rng);
  case 2:
    return chair(rng);
  case 3:
    return cabinet(rng);
  default:
    return boxStack(rng);
  }
}

// ---------------------------------------------------------------- placement

/** The camera's viewing direction on the floor (unit, world xy). */
Eigen::Vector2f
horizontalView(const TabletopScene& scene)
{
  Eigen::Vector2f f = scene.camera_to_world.linear().col(2).head<2>();
  if (f.norm() < 0.1f) // looking straight down: towards the table's far side
    f = Eigen::Vector2f(0.f, 1.f);
  return f.normalized();
}

/** True if a circle of \a radius at \a c on the floor is clear of the table (and its
 * legs), the wall and the items placed. */
bool
clear(const TabletopScene& scene, const Eigen::Vector2f& c, float radius,
      const std::vector<std::pair<Eigen::Vector2f, float>>& placed)
{
  constexpr float gap = 0.15f;
  if (scene.table_shape == TableShape::Round) {
    if (c.norm() < scene.table_radius + radius + gap)
      return false;
  }
  else if (std::abs(c.x()) < 0.5f * scene.table_width + radius + gap &&
           std::abs(c.y()) < 0.5f * scene.table_depth + radius + gap)
    return false;
  if (scene.wall && c.y() + radius > scene.wall_y - 0.02f)
    return false;
  for (const auto& [other, r] : placed)
    if ((c - other).norm() < radius + r + 0.1f)
      return false;
  return true;
}

/** Moves \a item's parts from its local frame to the floor at \a c, turned by \a yaw. */
void
placeItem(SceneryItem& item, const Eigen::Vector2f& c, float floor_z, float yaw)
{
  Eigen::Isometry3f pose = Eigen::Isometry3f::Identity();
  pose.linear() = Eigen::AngleAxisf(yaw, Eigen::Vector3f::UnitZ()).toRotationMatrix();
  pose.translation() = Eigen::Vector3f(c.x(), c.y(), floor_z);
  for (SceneObject& p : item.parts)
    p.pose = pose * p.pose;
}

/** Highest point (world z) of the objects on the table, from their bounding spheres. */
float
tallestObject(const TabletopScene& scene)
{
  float top = 0.f;
  for (const SceneObject& o : scene.objects) {
    const bool box = o.cls == SceneClass::Box;
    const float h =
      box ? o.size.z()
          : (o.cls == SceneClass::Sphere || o.cls == SceneClass::Bowl ? 2.f * o.radius : o.height);
    const float r = box ? 0.5f * std::hypot(o.size.x(), o.size.y()) : o.radius;
    const Eigen::Vector3f centre = o.pose * Eigen::Vector3f(0.f, 0.f, 0.5f * h);
    top = std::max(top, centre.z() + std::hypot(r, 0.5f * h));
  }
  return top;
}

/** True if world point \a p is outside the image of \a camera (or behind it). */
bool
outsideImage(const TabletopScene& scene, const CameraIntrinsics& camera, const Eigen::Vector3f& p)
{
  const Eigen::Vector3f q = scene.camera_to_world.inverse() * p;
  if (q.z() < 0.05f)
    return true;
  const float u = camera.fx * q.x() / q.z() + camera.cx;
  const float v = camera.fy * q.y() / q.z() + camera.cy;
  return u < 0.f || v < 0.f || u >= static_cast<float>(camera.width) ||
         v >= static_cast<float>(camera.height);
}

/** Distance of \a p from the segment a-b. */
float
segmentDistance(const Eigen::Vector3f& p, const Eigen::Vector3f& a, const Eigen::Vector3f& b)
{
  const Eigen::Vector3f ab = b - a;
  const float t = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.f, 1.f);
  return (a + t * ab - p).norm();
}

/** The arm from its shoulder \a s to the gripper at \a g (fingers pointing down). */
SceneryItem
robotArm(Random& rng, const Eigen::Vector3f& s, const Eigen::Vector3f& g)
{
  const Eigen::Vector3f link = mutedColour(rng) + Eigen::Vector3f::Constant(0.2f);
  const Eigen::Vector3f dark = Eigen::Vector3f::Constant(rng.uniform(0.1f, 0.25f));
  const Eigen::Vector3f axis = (s - g).normalized();
  Eigen::Vector3f up = Eigen::Vector3f::UnitZ() - axis.z() * axis;
  up = up.norm() > 1e-3f ? up.normalized() : axis.unitOrthogonal();
  const Eigen::Vector3f elbow = 0.5f * (s + g) + rng.uniform(0.05f, 0.2f) * up;
  const Eigen::Vector3f wrist = g + Eigen::Vector3f(0.f, 0.f, 0.12f);
  const Eigen::Vector3f flange = g + Eigen::Vector3f(0.f, 0.f, 0.03f);
  const float yaw = rng.uniform(-kPi, kPi), gap = rng.uniform(0.015f, 0.04f);
  SceneryItem robot;
  robot.kind = "robot";
  auto& parts = robot.parts;
  parts.push_back(ballPart(0.06f, s, link));
  parts.push_back(rodPart(0.045f, s, elbow, link));
  parts.push_back(ballPart(0.05f, elbow, link));
  parts.push_back(rodPart(0.04f, elbow, wrist, link));
  parts.push_back(ballPart(0.04f, wrist, link));
  parts.push_back(rodPart(0.03f, wrist, flange, dark));
  parts.push_back(boxPart({0.09f, 0.04f, 0.03f}, g, dark, yaw));
  const Eigen::Vector3f across(std::cos(yaw), std::sin(yaw), 0.f);
  for (const float side : {-1.f, 1.f})
    parts.push_back(boxPart({0.012f, 0.025f, 0.06f},
                            g + side * gap * across - Eigen::Vector3f(0.f, 0.f, 0.06f), dark, yaw));
  SurfaceMaterial painted, rubber;
  painted.gloss = rng.uniform(0.2f, 0.6f);
  rubber.reflectance = rng.uniform(0.2f, 0.5f);
  for (std::size_t k = 0; k < parts.size(); ++k)
    parts[k].material = k < 5 ? painted : rubber;
  return robot;
}

} // namespace

void
addBackground(const TabletopSceneParameters& params, Random& rng, TabletopScene& scene)
{
  if (params.max_background_items == 0)
    return;
  const std::size_t count =
    params.min_background_items +
    static_cast<std::size_t>(
      rng.integer(0, static_cast<int>(params.max_background_items - params.min_background_items)));
  const Eigen::Vector2f eye = scene.camera_to_world.translation().head<2>();
  const Eigen::Vector2f view = horizontalView(scene);
  const MaterialShares shares{params.object_materials.glossy, params.object_materials.dark, 0.f};
  std::vector<std::pair<Eigen::Vector2f, float>> placed;
  for (std::size_t k = 0, attempt = 0; k < count && attempt < 30 * count; ++attempt) {
    Built b = randomItem(rng);
    const float bearing = rng.uniform(-0.7f, 0.7f);
    const float distance =
      rng.uniform(params.background_distance.min, params.background_distance.max);
    const Eigen::Vector2f c = eye + distance * (Eigen::Rotation2Df(bearing) * view);
    const Eigen::Vector2f to_eye = eye - c;
    // Its front (-y) towards the camera, give or take 25 degrees.
    const float yaw = std::atan2(-to_eye.x(), to_eye.y()) + rng.uniform(-0.45f, 0.45f);
    const SurfaceMaterial material = drawMaterial(rng, shares);
    if (!clear(scene, c, b.radius, placed))
      continue;
    placeItem(b.item, c, -scene.table_height, yaw);
    for (SceneObject& p : b.item.parts)
      p.material = material;
    placed.emplace_back(c, b.radius);
    scene.scenery.push_back(std::move(b.item));
    ++k;
  }
}

void
addRobot(const TabletopSceneParameters& params, Random& rng, TabletopScene& scene)
{
  if (!(params.robot_share > 0.f) || !rng.chance(params.robot_share))
    return;
  // The gripper above the objects' area, clear of the tallest object.
  const float x = rng.uniform(-0.3f, 0.3f), y = rng.uniform(-0.2f, 0.2f);
  const Eigen::Vector3f gripper(x, y, tallestObject(scene) + rng.uniform(0.1f, 0.35f));
  const Eigen::Vector3f eye = scene.camera_to_world.translation();
  for (int attempt = 0; attempt < 24; ++attempt) {
    const float heading = rng.uniform(-kPi, kPi), rise = rng.uniform(0.1f, 0.9f);
    const float length = rng.uniform(0.6f, 0.9f);
    const Eigen::Vector3f shoulder =
      gripper + length * Eigen::Vector3f(std::cos(rise) * std::cos(heading),
                                         std::cos(rise) * std::sin(heading), std::sin(rise));
    // It reaches in from a border and keeps clear of the camera.
    if (!outsideImage(scene, params.camera, shoulder) ||
        segmentDistance(eye, gripper, shoulder) < 0.3f)
      continue;
    scene.scenery.push_back(robotArm(rng, shoulder, gripper));
    return;
  }
}

} // namespace detail
} // namespace facyl
