/*
 * facyl: fast cylinder detection for PCL.
 * Realism of the tabletop scenes: any camera roll, curved table tops, materials.
 */
#include "scene_realism.h"

#include <algorithm>
#include <cmath>

namespace facyl {
namespace detail {

namespace {

constexpr float kPi = 3.14159265358979f;

/** Seed offset of the realism steps: the scene's other random numbers stay the same. */
constexpr std::uint64_t kRealismStream = 0x3c6ef372fe94f82bULL;

bool
anyShare(const MaterialShares& m)
{
  return m.glossy > 0.f || m.dark > 0.f || m.transparent > 0.f;
}

/** Dark in the infrared is taken to be dark in colour too (a black counter, black
 * plastic). */
float
colourFactor(const SurfaceMaterial& m)
{
  return m.reflectance < 1.f ? 0.2f + 0.5f * m.reflectance : 1.f;
}

/** The point of \a o the table carries: its footprint's centre. */
Eigen::Vector2f
standingPoint(const SceneObject& o)
{
  if (o.lying)
    return (o.pose * Eigen::Vector3f(0.f, 0.f, 0.5f * o.height)).head<2>();
  return o.pose.translation().head<2>();
}

SceneObject*
tableTopOf(TabletopScene& scene)
{
  for (SceneObject& f : scene.furniture)
    if (f.kind == "table")
      return &f;
  return nullptr;
}

} // namespace

void
addRealism(const TabletopSceneParameters& params, TabletopScene& scene)
{
  Random rng(params.seed ^ kRealismStream);
  rollAnyWay(params, rng, scene);
  curveTable(params, rng, scene);
  drawMaterials(params, rng, scene);
  addBackground(params, rng, scene);
  addRobot(params, rng, scene);
}

void
rollAnyWay(const TabletopSceneParameters& params, Random& rng, TabletopScene& scene)
{
  if (!(params.any_roll_share > 0.f) || !rng.chance(params.any_roll_share))
    return;
  const float roll = rng.uniform(-kPi, kPi);
  scene.camera_to_world.linear() =
    scene.camera_to_world.linear() *
    Eigen::AngleAxisf(roll, Eigen::Vector3f::UnitZ()).toRotationMatrix();
}

void
curveTable(const TabletopSceneParameters& params, Random& rng, TabletopScene& scene)
{
  SceneObject* top = tableTopOf(scene);
  if ((params.table_sag.min == 0.f && params.table_sag.max == 0.f) || top == nullptr)
    return;
  top->top_sag = rng.uniform(params.table_sag.min, params.table_sag.max);
  // Objects on the table stand on the curve below their centre; stacked and leaning
  // objects move with what carries them (placed before them).
  std::vector<float> lift(scene.objects.size(), 0.f);
  for (std::size_t i = 0; i < scene.objects.size(); ++i) {
    SceneObject& o = scene.objects[i];
    if (o.support >= 0)
      lift[i] = lift[static_cast<std::size_t>(o.support)];
    else if (o.leaning && !o.touches.empty())
      lift[i] = lift[static_cast<std::size_t>(o.touches.front())];
    else {
      const Eigen::Vector2f c = standingPoint(o);
      lift[i] = tableTopHeight(scene, c.x(), c.y());
    }
    o.pose.translation().z() += lift[i];
  }
}

SurfaceMaterial
drawMaterial(Random& rng, const MaterialShares& shares)
{
  SurfaceMaterial m;
  const bool glossy = rng.chance(shares.glossy);
  const bool dark = rng.chance(shares.dark);
  const bool transparent = rng.chance(shares.transparent);
  if (glossy)
    m.gloss = rng.uniform(0.3f, 0.8f);
  if (dark)
    m.reflectance = rng.uniform(0.1f, 0.4f);
  if (transparent) { // glass and clear plastic: glossy too
    m.transparency = rng.uniform(0.7f, 1.f);
    m.gloss = std::max(m.gloss, rng.uniform(0.4f, 0.8f));
  }
  return m;
}

void
drawMaterials(const TabletopSceneParameters& params, Random& rng, TabletopScene& scene)
{
  SceneObject* top = tableTopOf(scene);
  if (anyShare(params.table_materials) && top != nullptr) {
    top->material = drawMaterial(rng, params.table_materials);
    for (Eigen::Vector3f& c : scene.table_colour)
      c *= colourFactor(top->material);
  }
  if (anyShare(params.floor_materials)) {
    scene.floor_material = drawMaterial(rng, params.floor_materials);
    scene.floor_colour *= colourFactor(scene.floor_material);
  }
  if (!anyShare(params.object_materials))
    return;
  for (SceneObject& o : scene.objects) {
    o.material = drawMaterial(rng, params.object_materials);
    for (Eigen::Vector3f& c : o.colour)
      c *= colourFactor(o.material);
  }
}

} // namespace detail
} // namespace facyl
