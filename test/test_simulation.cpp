/*
 * facyl: tests of the cylinder simulator (paper III-D1, eq. 5 and 6).
 */
#include <facyl/simulation/cylinder_simulation.h>

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

using facyl::CylinderSimulationParameters;

TEST(CylinderSimulation, LateralPointsLieOnTheSurface)
{
  CylinderSimulationParameters p;
  p.radius = 0.05f;
  p.height = 0.2f;
  p.axis = Eigen::Vector3f(1, 2, 3);
  p.base = Eigen::Vector3f(0.5f, -1.f, 2.f);
  const auto sim = facyl::simulateCylinder(p);
  ASSERT_EQ(sim.cloud.size(), 900u);
  const Eigen::Vector3f a = p.axis.normalized();
  EXPECT_LT((sim.truth.axis - a).norm(), 1e-6f);
  for (const auto& q : sim.cloud) {
    const Eigen::Vector3f w = q.getVector3fMap() - p.base;
    const float t = w.dot(a);
    EXPECT_NEAR((w - t * a).norm(), p.radius, 1e-5f);
    EXPECT_GE(t, -1e-5f);
    EXPECT_LE(t, p.height + 1e-5f);
    EXPECT_NEAR(std::abs(q.getNormalVector3fMap().dot(a)), 0.f, 1e-5f);
  }
}

TEST(CylinderSimulation, LidsFollowEquation5)
{
  CylinderSimulationParameters p;
  p.lid_ratio = 3.f;
  p.base = Eigen::Vector3f::Zero(); // lids at z = 0 and z = height
  const auto sim = facyl::simulateCylinder(p);
  // eq. 5: outliers = total / |P| - 1
  EXPECT_NEAR(static_cast<float>(sim.cloud.size()) / 900.f - 1.f, 3.f, 1e-6f);
  EXPECT_EQ(sim.truth.lid_points, 2700u);
  std::size_t bottom = 0, top = 0;
  for (std::size_t i = 0; i < sim.cloud.size(); ++i) {
    if (!sim.is_lid[i])
      continue;
    const Eigen::Vector3f q = sim.cloud[i].getVector3fMap();
    EXPECT_LE(Eigen::Vector2f(q.x(), q.y()).norm(), p.radius + 1e-5f);
    if (std::abs(q.z()) < 1e-5f)
      ++bottom;
    else if (std::abs(q.z() - p.height) < 1e-5f)
      ++top;
  }
  EXPECT_EQ(bottom, 1350u);
  EXPECT_EQ(top, 1350u);
}

TEST(CylinderSimulation, OcclusionFollowsEquation6)
{
  CylinderSimulationParameters p;
  p.occlusion = 0.75f;
  const auto sim = facyl::simulateCylinder(p);
  // eq. 6: occlusion = 1 - |P'| / |P|
  EXPECT_NEAR(1.f - static_cast<float>(sim.cloud.size()) / 900.f, 0.75f, 1e-3f);
  // The visible part is one angular sector of a quarter turn.
  const Eigen::Vector3f u = p.axis.unitOrthogonal(), v = p.axis.cross(u);
  for (const auto& q : sim.cloud) {
    float angle = std::atan2(q.getVector3fMap().dot(v), q.getVector3fMap().dot(u));
    if (angle < 0)
      angle += 2.f * static_cast<float>(M_PI);
    EXPECT_LE(angle, 0.25f * 2.f * static_cast<float>(M_PI) + 1e-4f);
  }
}

TEST(CylinderSimulation, NoiseHasTheRequestedSpread)
{
  CylinderSimulationParameters p;
  p.noise = 0.05f;
  p.lateral_points = 20000;
  const auto sim = facyl::simulateCylinder(p);
  double sq = 0.0;
  for (const auto& q : sim.cloud) {
    const float radial = Eigen::Vector2f(q.x, q.y).norm() - p.radius;
    sq += radial * radial;
  }
  // Radial component of isotropic noise: std sigma = 0.05 r.
  EXPECT_NEAR(std::sqrt(sq / sim.cloud.size()), 0.05 * p.radius, 0.05 * 0.05 * p.radius);
}

TEST(CylinderSimulation, IsDeterministicForASeed)
{
  CylinderSimulationParameters p;
  p.random_axis = true;
  p.noise = 0.01f;
  p.lid_ratio = 1.f;
  p.seed = 42;
  const auto a = facyl::simulateCylinder(p);
  const auto b = facyl::simulateCylinder(p);
  ASSERT_EQ(a.cloud.size(), b.cloud.size());
  for (std::size_t i = 0; i < a.cloud.size(); ++i)
    EXPECT_EQ(a.cloud[i].getVector3fMap(), b.cloud[i].getVector3fMap());
  p.seed = 43;
  const auto c = facyl::simulateCylinder(p);
  EXPECT_GT((a.truth.axis - c.truth.axis).norm(), 1e-3f);
  EXPECT_NEAR(a.truth.axis.norm(), 1.f, 1e-6f);
}

TEST(CylinderSimulation, RejectsInvalidParameters)
{
  CylinderSimulationParameters p;
  p.radius = 0.f;
  EXPECT_THROW(facyl::simulateCylinder(p), std::invalid_argument);
  p = {};
  p.occlusion = 1.f;
  EXPECT_THROW(facyl::simulateCylinder(p), std::invalid_argument);
  p = {};
  p.axis = Eigen::Vector3f::Zero();
  EXPECT_THROW(facyl::simulateCylinder(p), std::invalid_argument);
  p = {};
  p.noise = -1.f;
  EXPECT_FALSE(facyl::validate(p).empty());
  EXPECT_THROW(
    facyl::simulatePlane(Eigen::Vector3f::Zero(), Eigen::Vector3f::UnitZ(), 0.f, 1.f, 10, 0.f, 0),
    std::invalid_argument);
}

TEST(PlaneSimulation, PointsLieOnThePlane)
{
  const Eigen::Vector3f n(0, 1, 1);
  const auto plane = facyl::simulatePlane(Eigen::Vector3f(1, 2, 3), n, 2.f, 1.f, 500, 0.f, 7);
  ASSERT_EQ(plane.size(), 500u);
  for (const auto& q : plane)
    EXPECT_NEAR((q.getVector3fMap() - Eigen::Vector3f(1, 2, 3)).dot(n.normalized()), 0.f, 1e-5f);
}

// ---------------------------------------------------------------- real sensors' artefacts

#include <facyl/simulation/scene_rendering.h>
#include <facyl/simulation/sensor_effects.h>
#include <facyl/simulation/tabletop_scene.h>

#include <algorithm>
#include <set>

namespace {

/** A sensor without noise, quantisation or random dropouts: only what a test turns on. */
facyl::DepthSensorModel
idealSensor()
{
  facyl::DepthSensorModel s;
  s.noise_coefficient = 0.f;
  s.disparity_step = 0.f;
  s.dropout = 0.f;
  s.colour_noise = 0.f;
  return s;
}

/** An empty 3 m x 3 m table seen by a camera \a height above its centre, looking at it at
 * \a elevation (rad; pi/2: straight down, the image's x along world x). */
facyl::TabletopScene
bareTable(float height, float elevation)
{
  facyl::TabletopSceneParameters p;
  p.min_objects = p.max_objects = 0;
  p.table_width = p.table_depth = {3.f, 3.f};
  const facyl::TabletopScene drawn = facyl::generateTabletopScene(p);
  facyl::TabletopScene scene = drawn;
  const Eigen::Vector3f forward(0.f, std::cos(elevation), -std::sin(elevation));
  const Eigen::Vector3f right = Eigen::Vector3f::UnitX();
  Eigen::Matrix3f r;
  r.col(0) = right;
  r.col(1) = forward.cross(right);
  r.col(2) = forward;
  scene.camera_to_world.linear() = r;
  scene.camera_to_world.translation() =
    Eigen::Vector3f(0.f, -height * std::cos(elevation) / std::sin(elevation), height);
  return scene;
}

facyl::SceneObject&
tableTop(facyl::TabletopScene& scene)
{
  for (auto& f : scene.furniture)
    if (f.kind == "table")
      return f;
  throw std::logic_error("no table top");
}

/** Share of the table's pixels without depth. */
double
missingOnTable(const facyl::RenderedScene& r)
{
  std::size_t table = 0, missing = 0;
  for (std::size_t i = 0; i < r.cloud.size(); ++i)
    if (r.pixel_class[i] == facyl::SceneClass::Table) {
      ++table;
      missing += !std::isfinite(r.cloud[i].z);
    }
  return table ? static_cast<double>(missing) / static_cast<double>(table) : NAN;
}

} // namespace

TEST(PlaneSimulation, ResizedCameraKeepsTheFieldOfView)
{
  // VGA to 1280 x 720: the focal lengths scale with the sides, and the corners' pixel edges
  // and the centre stay where the same rays meet the image.
  const facyl::CameraIntrinsics vga;
  const facyl::CameraIntrinsics c = facyl::resizedCamera(vga, 1280, 720);
  EXPECT_EQ(c.width, 1280);
  EXPECT_EQ(c.height, 720);
  EXPECT_FLOAT_EQ(c.fx, 1050.f);
  EXPECT_FLOAT_EQ(c.fy, 787.5f);
  EXPECT_FLOAT_EQ(c.cx, 639.5f);
  EXPECT_FLOAT_EQ(c.cy, 359.5f);
  for (const float u : {-0.5f, 100.f, 639.5f}) { // ray x / z of a pixel position
    const float ray = (u - vga.cx) / vga.fx;
    EXPECT_NEAR(c.fx * ray + c.cx, (u + 0.5f) * 2.f - 0.5f, 1e-3f);
  }
  const facyl::CameraIntrinsics back = facyl::resizedCamera(c, vga.width, vga.height);
  EXPECT_FLOAT_EQ(back.fx, vga.fx);
  EXPECT_FLOAT_EQ(back.cy, vga.cy);
}

TEST(RealSensorArtefacts, ExistingPresetsRenderTheirFramesOfBefore)
{
  // Fingerprints of frames rendered before the artefacts were added: finite pixels, table
  // pixels, sum of depths, weighted sum of colours.
  struct Golden {
    bool cluttered;
    const char* sensor;
    std::uint64_t seed;
    std::size_t finite, table;
    double depth_sum;
    unsigned long long colour_sum;
  };
  const Golden golden[] = {
    {false, "kinect", 5, 248637, 184785, 354831.605189, 268892908},
    {false, "stereo", 20, 292694, 233738, 303646.694193, 322302377},
    {true, "kinect", 20, 301510, 220059, 351748.430786, 328702810},
    {true, "stereo", 5, 291735, 80680, 308967.675631, 304922387},
  };
  for (const Golden& g : golden) {
    facyl::TabletopSceneParameters p =
      g.cluttered ? facyl::clutteredSceneParameters() : facyl::TabletopSceneParameters{};
    ASSERT_TRUE(facyl::parseSensorPreset(g.sensor, p.sensor, p.camera));
    p.seed = g.seed;
    const facyl::RenderedScene r = facyl::simulateTabletopScene(p);
    std::size_t finite = 0, table = 0;
    double depth_sum = 0.0;
    unsigned long long colour_sum = 0;
    for (std::size_t i = 0; i < r.cloud.size(); ++i) {
      if (std::isfinite(r.cloud[i].z)) {
        ++finite;
        depth_sum += r.cloud[i].z;
      }
      table += r.object_id[i] == 1;
      colour_sum += r.cloud[i].r + 3ull * r.cloud[i].g + 7ull * r.cloud[i].b;
    }
    EXPECT_EQ(finite, g.finite) << g.sensor << " " << g.seed;
    EXPECT_EQ(table, g.table) << g.sensor << " " << g.seed;
    EXPECT_NEAR(depth_sum, g.depth_sum, 1e-3) << g.sensor << " " << g.seed;
    EXPECT_EQ(colour_sum, g.colour_sum) << g.sensor << " " << g.seed;
    // Nothing of the realistic preset leaks into the old ones.
    EXPECT_TRUE(r.scene.scenery.empty());
    EXPECT_FALSE(r.sensor_family.has_value());
    EXPECT_EQ(r.scene.tableTop()->top_sag, 0.f);
    EXPECT_TRUE(r.scene.tableTop()->material.isReference());
    for (const auto& o : r.scene.objects)
      EXPECT_TRUE(o.material.isReference());
    EXPECT_EQ(facyl::groundTruthJson(r).find("scenery"), std::string::npos);
  }
}

TEST(RealSensorArtefacts, RandomSensorVariesAcrossSeedsAndIsDeterministic)
{
  const facyl::CameraIntrinsics base;
  std::set<facyl::SensorFamily> families;
  std::set<float> noise, bias;
  for (std::uint64_t seed = 0; seed < 60; ++seed) {
    const facyl::DrawnSensor a = facyl::drawSensor(base, seed), b = facyl::drawSensor(base, seed);
    EXPECT_EQ(a.family, b.family);
    EXPECT_EQ(a.sensor.noise_coefficient, b.sensor.noise_coefficient);
    EXPECT_EQ(a.sensor.radial_depth_bias, b.sensor.radial_depth_bias);
    EXPECT_EQ(a.sensor.hole_rate, b.sensor.hole_rate);
    EXPECT_EQ(a.camera.fx, b.camera.fx);
    EXPECT_FALSE(a.sensor.randomize);
    families.insert(a.family);
    noise.insert(a.sensor.noise_coefficient + a.sensor.noise_constant);
    bias.insert(a.sensor.radial_depth_bias);
    facyl::TabletopSceneParameters check;
    check.sensor = a.sensor;
    check.camera = a.camera;
    EXPECT_EQ(facyl::validate(check), "") << "seed " << seed;
    EXPECT_GE(a.camera.fx, 0.9f * base.fx);
    EXPECT_LE(a.camera.fx, 1.2f * base.fx);
    if (a.family == facyl::SensorFamily::TimeOfFlight) { // no disparity, flying pixels
      EXPECT_EQ(a.sensor.disparity_step, 0.f);
      EXPECT_GE(a.sensor.flying_pixels, 0.4f);
      EXPECT_GT(a.sensor.noise_constant, 0.f);
    }
    else
      EXPECT_GT(a.sensor.disparity_step, 0.f);
  }
  EXPECT_EQ(families.size(), 3u);
  EXPECT_EQ(noise.size(), 60u);
  EXPECT_EQ(bias.size(), 60u);

  // The "random" preset draws per frame, from the frame's seed.
  facyl::TabletopSceneParameters p = facyl::clutteredSceneParameters();
  ASSERT_TRUE(facyl::parseSensorPreset("random", p.sensor, p.camera));
  EXPECT_TRUE(p.sensor.randomize);
  p.seed = 9;
  const facyl::RenderedScene a = facyl::simulateTabletopScene(p);
  const facyl::RenderedScene b = facyl::simulateTabletopScene(p);
  ASSERT_TRUE(a.sensor_family.has_value());
  EXPECT_EQ(*a.sensor_family, facyl::drawSensor(p.camera, 9).family);
  EXPECT_EQ(a.camera.fx, facyl::drawSensor(p.camera, 9).camera.fx);
  std::size_t same = 0;
  for (std::size_t i = 0; i < a.cloud.size(); ++i)
    same += (a.cloud[i].z == b.cloud[i].z ||
             (!std::isfinite(a.cloud[i].z) && !std::isfinite(b.cloud[i].z))) &&
            a.cloud[i].rgba == b.cloud[i].rgba;
  EXPECT_EQ(same, a.cloud.size());
  EXPECT_NE(facyl::groundTruthJson(a).find("\"sensor\":{\"family\":"), std::string::npos);
}

TEST(RealSensorArtefacts, BiasNumerics)
{
  facyl::DepthSensorModel s;
  EXPECT_EQ(facyl::depthBias(s, 2.f, 1.f, 0.3f), 0.f); // off by default
  s.radial_depth_bias = 0.004f;
  EXPECT_NEAR(facyl::depthBias(s, 1.f, 1.f, 1.f), 0.004f, 1e-7f);   // 4 mm at 1 m, corner
  EXPECT_NEAR(facyl::depthBias(s, 2.f, 1.f, 1.f), 0.016f, 1e-7f);   // grows with z^2
  EXPECT_NEAR(facyl::depthBias(s, 2.f, 0.25f, 1.f), 0.004f, 1e-7f); // and with r^2
  EXPECT_EQ(facyl::depthBias(s, 2.f, 0.f, 1.f), 0.f);               // none in the centre
  s = {};
  s.incidence_bias = 0.002f;
  EXPECT_NEAR(facyl::depthBias(s, 1.f, 0.f, 0.5f), 0.002f, 1e-7f);  // 60 degrees
  EXPECT_NEAR(facyl::depthBias(s, 1.f, 0.f, 1.f), 0.f, 1e-9f);      // head on
  EXPECT_NEAR(facyl::depthBias(s, 1.f, 0.f, 0.01f), 0.018f, 1e-6f); // capped at cos 0.1
  s = {};
  s.depth_scale_error = 0.01f;
  EXPECT_NEAR(facyl::depthBias(s, 2.f, 0.5f, 0.5f), 0.02f, 1e-7f);
  const facyl::CameraIntrinsics c;
  EXPECT_NEAR(facyl::radialPosition2(c, c.cx, c.cy), 0.f, 1e-9f);
  EXPECT_NEAR(facyl::radialPosition2(c, -0.5f, -0.5f), 1.f, 1e-5f);

  // Noise: z^2 for triangulation, nearly constant for time of flight, larger on weak returns.
  s = {};
  EXPECT_FLOAT_EQ(facyl::axialNoiseSigma(s, 2.f, 1.f), 1.5e-3f * 4.f);
  s.noise_coefficient = 0.f;
  s.noise_constant = 1e-3f;
  s.noise_linear = 1e-3f;
  EXPECT_FLOAT_EQ(facyl::axialNoiseSigma(s, 2.f, 1.f), 3e-3f);
  EXPECT_FLOAT_EQ(facyl::axialNoiseSigma(s, 2.f, 0.25f), 6e-3f);
}

TEST(RealSensorArtefacts, RadialBiasBendsAFlatTable)
{
  const facyl::CameraIntrinsics camera;
  for (const float height : {1.f, 2.f}) {
    const facyl::TabletopScene scene = bareTable(height, static_cast<float>(M_PI) / 2.f);
    facyl::DepthSensorModel sensor = idealSensor();
    const facyl::RenderedScene flat = facyl::renderTabletopScene(scene, camera, sensor, 1);
    sensor.radial_depth_bias = 0.004f;
    const facyl::RenderedScene bent = facyl::renderTabletopScene(scene, camera, sensor, 1);
    const auto z = [&](const facyl::RenderedScene& r, int u, int v) {
      return r.cloud[static_cast<std::size_t>(v) * camera.width + u].z;
    };
    // Flat: the same depth everywhere. Bent: the corners 4 mm x z^2 farther than the centre.
    EXPECT_NEAR(z(flat, 0, 0) - z(flat, 320, 240), 0.f, 1e-4f);
    const float bow = (z(bent, 0, 0) - z(flat, 0, 0)) - (z(bent, 320, 240) - z(flat, 320, 240));
    std::printf("[ figures ] radial bias 0.004: table %.0f m below the camera bends by %.1f mm "
                "(corner against centre)\n",
                height, 1000.f * bow);
    EXPECT_NEAR(bow, 0.004f * height * height, 2e-4f * height);
    EXPECT_EQ(bent.pixel_class[0], facyl::SceneClass::Table); // still the table
  }
}

TEST(RealSensorArtefacts, GlossyAndDarkTablesLoseTheirDepth)
{
  const facyl::CameraIntrinsics camera;
  const facyl::DepthSensorModel kinect; // the default response to materials
  const auto render = [&](float reflectance, float gloss, float elevation) {
    facyl::TabletopScene scene = bareTable(1.f, elevation);
    tableTop(scene).material.reflectance = reflectance;
    tableTop(scene).material.gloss = gloss;
    return facyl::renderTabletopScene(scene, camera, kinect, 3);
  };
  const float down = static_cast<float>(M_PI) / 2.f, oblique = static_cast<float>(M_PI) / 4.f;
  const double matte = missingOnTable(render(1.f, 0.f, oblique));
  const double dark = missingOnTable(render(0.25f, 0.f, oblique));
  const double glossy = missingOnTable(render(1.f, 0.6f, oblique));
  const double counter = missingOnTable(render(0.15f, 0.6f, oblique)); // black kitchen counter
  const facyl::RenderedScene top_down = render(1.f, 0.6f, down);
  std::printf("[ figures ] table pixels without depth (Kinect-like sensor, 45 degrees): matte "
              "%.1f%%, dark %.1f%%, glossy %.1f%%, glossy and dark %.1f%%; glossy seen from "
              "above %.1f%%\n",
              100 * matte, 100 * dark, 100 * glossy, 100 * counter, 100 * missingOnTable(top_down));
  EXPECT_LT(matte, 0.01);
  EXPECT_GT(dark, 0.25);
  EXPECT_GT(glossy, matte + 0.1);
  EXPECT_GT(counter, 0.95);
  // Seen from above, the highlight: no depth where the table faces the sensor.
  std::size_t centre = 0;
  for (int v = 230; v < 250; ++v)
    for (int u = 310; u < 330; ++u)
      centre += !std::isfinite(top_down.cloud[static_cast<std::size_t>(v) * 640 + u].z);
  EXPECT_EQ(centre, 400u);
  EXPECT_GT(facyl::highlightProbability(kinect, 0.6f, 1.f), 0.99f);
  EXPECT_EQ(facyl::highlightProbability(kinect, 0.f, 1.f), 0.f);
  EXPECT_EQ(facyl::weakReturnDropout(kinect, 1.f), 0.f); // the reference material loses nothing
}

TEST(RealSensorArtefacts, TransparentObjectsGiveNoDepthOrWhatLiesBehind)
{
  facyl::TabletopScene scene = bareTable(1.f, static_cast<float>(M_PI) / 3.f);
  facyl::SceneObject glass;
  glass.kind = "can";
  glass.radius = 0.05f;
  glass.height = 0.15f;
  glass.material.transparency = 1.f;
  glass.material.gloss = 0.5f;
  scene.objects.push_back(glass);
  const facyl::CameraIntrinsics camera;
  facyl::DepthSensorModel sensor = idealSensor();
  sensor.see_through = 0.f;
  const facyl::RenderedScene blind = facyl::renderTabletopScene(scene, camera, sensor, 4);
  sensor.see_through = 1.f;
  const facyl::RenderedScene through = facyl::renderTabletopScene(scene, camera, sensor, 4);
  std::size_t glass_pixels = 0, glass_depth = 0;
  for (std::size_t i = 0; i < blind.cloud.size(); ++i)
    if (blind.object_id[i] == 2) {
      ++glass_pixels;
      glass_depth += std::isfinite(blind.cloud[i].z);
    }
  ASSERT_GT(glass_pixels, 1000u);
  EXPECT_EQ(glass_depth, 0u); // no light comes back from the glass itself
  EXPECT_EQ(blind.visible_pixels[0], 0u);
  // Seen through: the pixels measure (and are labelled as) the table behind, on its plane.
  std::size_t relabelled = 0;
  for (std::size_t i = 0; i < blind.cloud.size(); ++i)
    if (blind.object_id[i] == 2 && through.object_id[i] == 1 && std::isfinite(through.cloud[i].z)) {
      ++relabelled;
      const float d = through.table_plane.head<3>().dot(through.cloud[i].getVector3fMap()) +
                      through.table_plane[3];
      EXPECT_NEAR(d, 0.f, 1e-3f);
    }
  EXPECT_GT(relabelled, glass_pixels / 2);
  EXPECT_EQ(through.visible_pixels[0], 0u);
}

TEST(RealSensorArtefacts, CurvedTableCarriesItsObjects)
{
  facyl::TabletopSceneParameters p = facyl::clutteredSceneParameters();
  p.table_sag = {0.005f, 0.005f};
  p.seed = 4;
  const facyl::TabletopScene scene = facyl::generateTabletopScene(p);
  ASSERT_NE(scene.tableTop(), nullptr);
  EXPECT_FLOAT_EQ(scene.tableTop()->top_sag, 0.005f);
  EXPECT_FLOAT_EQ(facyl::tableTopHeight(scene, 0.f, 0.f), 0.005f);
  for (const auto& o : scene.objects) {
    if (o.support < 0 && !o.leaning && !o.lying) {
      EXPECT_NEAR(o.pose.translation().z(),
                  facyl::tableTopHeight(scene, o.pose.translation().x(), o.pose.translation().y()),
                  1e-6f);
    }
  }
  // Rendered without noise, the table's pixels lie on the curved top (world frame).
  const facyl::RenderedScene r = facyl::renderTabletopScene(scene, p.camera, idealSensor(), p.seed);
  const Eigen::Isometry3f& to_world = scene.camera_to_world;
  std::size_t on_top = 0, above_flat = 0;
  for (std::size_t i = 0; i < r.cloud.size(); ++i) {
    if (r.pixel_class[i] != facyl::SceneClass::Table || !std::isfinite(r.cloud[i].z))
      continue;
    const Eigen::Vector3f w = to_world * r.cloud[i].getVector3fMap();
    if (w.z() < -0.004f)
      continue; // legs and the slab's sides
    ++on_top;
    EXPECT_NEAR(w.z(), facyl::tableTopHeight(scene, w.x(), w.y()), 2e-4f);
    above_flat += w.z() > 0.001f;
  }
  EXPECT_GT(on_top, 10000u);
  EXPECT_GT(above_flat, on_top / 4); // a dome, measurably off the flat plane
  p.table_sag = {-0.03f, 0.f};
  EXPECT_NE(facyl::validate(p).find("table_sag"), std::string::npos);
}

TEST(RealSensorArtefacts, SceneryIsLabelledScenery)
{
  std::size_t items = 0, robots = 0, robot_pixels = 0, scenery_pixels = 0;
  for (std::uint64_t seed = 1; seed <= 12; ++seed) {
    facyl::TabletopSceneParameters p = facyl::realisticSceneParameters();
    p.seed = seed;
    const facyl::RenderedScene r = facyl::simulateTabletopScene(p);
    const Eigen::Vector3f eye = r.scene.camera_to_world.translation();
    for (std::size_t j = 0; j < r.scene.scenery.size(); ++j) {
      const auto& item = r.scene.scenery[j];
      ++items;
      if (item.kind == "robot") {
        ++robots;
        continue;
      }
      // Background items stand on the floor, 1.5-4 m from the camera (horizontally).
      const Eigen::Vector3f base = item.parts.front().pose.translation();
      const float distance = (base - eye).head<2>().norm();
      EXPECT_GT(distance, 1.f) << "seed " << seed << " item " << j;
      EXPECT_LT(distance, 4.7f) << "seed " << seed << " item " << j;
    }
    for (std::size_t i = 0; i < r.cloud.size(); ++i) {
      const bool scenery_id = r.object_id[i] >= facyl::kFirstSceneryId;
      EXPECT_EQ(scenery_id, r.pixel_class[i] == facyl::SceneClass::Scenery);
      if (scenery_id) {
        ++scenery_pixels;
        ASSERT_LT(r.object_id[i] - facyl::kFirstSceneryId, r.scene.scenery.size());
        robot_pixels += r.scene.scenery[r.object_id[i] - facyl::kFirstSceneryId].kind == "robot";
      }
    }
    if (!r.scene.scenery.empty()) {
      EXPECT_NE(facyl::groundTruthJson(r).find("\"scenery\":[{\"id\":1000"), std::string::npos);
    }
  }
  std::printf("[ figures ] 12 realistic scenes: %zu scenery items (%zu robots), %zu scenery "
              "pixels (%zu of robots)\n",
              items, robots, scenery_pixels, robot_pixels);
  EXPECT_GT(items, 12u);
  EXPECT_GT(robots, 0u);
  EXPECT_GT(robot_pixels, 0u);
  EXPECT_GT(scenery_pixels, 12u * 5000u);
}

TEST(RealSensorArtefacts, RealisticLayoutRollsAndTiltsTheCamera)
{
  int rolled = 0;
  float lowest = 10.f, highest = 0.f;
  const int n = 200;
  for (int seed = 0; seed < n; ++seed) {
    facyl::TabletopSceneParameters p;
    ASSERT_TRUE(facyl::parseLayoutPreset("realistic", p));
    p.seed = static_cast<std::uint64_t>(seed);
    const facyl::TabletopScene s = facyl::generateTabletopScene(p);
    // The world's up in the image: straight up for an upright camera.
    const Eigen::Vector3f up = s.camera_to_world.linear().transpose() * Eigen::Vector3f::UnitZ();
    rolled += std::abs(std::atan2(up.x(), -up.y())) > 0.5f;
    const float elevation = std::asin(-s.camera_to_world.linear()(2, 2));
    lowest = std::min(lowest, elevation);
    highest = std::max(highest, elevation);
  }
  // 30% rolled uniformly: |roll| > 0.5 rad in 30% x 84% of the scenes.
  EXPECT_GT(rolled, n * 15 / 100);
  EXPECT_LT(rolled, n * 35 / 100);
  EXPECT_LT(lowest, 0.35f);  // grazing, near 15 degrees
  EXPECT_GT(highest, 1.35f); // near 85 degrees
  facyl::TabletopSceneParameters p;
  EXPECT_FALSE(facyl::parseLayoutPreset("kitchen", p));
}

TEST(RealSensorArtefacts, InvalidSettingsAreRejected)
{
  facyl::TabletopSceneParameters p = facyl::realisticSceneParameters();
  EXPECT_EQ(facyl::validate(p), "");
  p.table_materials.transparent = 0.1f;
  EXPECT_NE(facyl::validate(p).find("transparent"), std::string::npos);
  p = facyl::realisticSceneParameters();
  p.robot_share = 2.f;
  EXPECT_FALSE(facyl::validate(p).empty());
  p = facyl::realisticSceneParameters();
  p.max_background_items = 21;
  EXPECT_FALSE(facyl::validate(p).empty());
  p = {};
  p.sensor.radial_depth_bias = 0.5f;
  EXPECT_NE(facyl::validate(p).find("bias"), std::string::npos);
  p = {};
  p.sensor.highlight_width = 1.f;
  EXPECT_THROW(facyl::simulateTabletopScene(p), std::invalid_argument);
  p = {};
  p.sensor.noise_linear = -1.f;
  EXPECT_FALSE(facyl::validate(p).empty());
}

// -------------------------------------------------------------------- the ground truth's JSON

#include <facyl/simulation/tabletop_sequence.h>
#include <facyl/tools/json_writer.h>

TEST(GroundTruthJson, NumbersAsAStreamWritesThemStringsEscaped)
{
  // %.7g for every float, as the text of a stream with setprecision(7); nlohmann's own
  // writer of the same rounded number can give 17 digits instead.
  using facyl_cli::Json;
  const Json j{{"a", 0.2154446f},
               {"b", Json::array({3.f, -0.5f, 1.5e-5f, 12345678.f})},
               {"c", std::nanf("")},
               {"d", "a \"quoted\"\nkind"},
               {"e", 7}};
  EXPECT_EQ(facyl_cli::dumpJsonWithDigits(j, 7),
            "{\"a\":0.2154446,\"b\":[3,-0.5,1.5e-05,1.234568e+07],\"c\":null,"
            "\"d\":\"a \\\"quoted\\\"\\nkind\",\"e\":7}");
  EXPECT_EQ(facyl_cli::dumpJson(facyl_cli::jsonNumber(0.2154446f, 7)), "0.21544460000000001");

  // A scene whose names need escaping, and a number that is not finite: valid JSON.
  facyl::TabletopSceneParameters p;
  p.camera.width = 80;
  p.camera.height = 60;
  p.camera.fx = p.camera.fy = 65.625f;
  p.camera.cx = 39.5f;
  p.camera.cy = 29.5f;
  p.seed = 3;
  facyl::RenderedScene r = facyl::simulateTabletopScene(p);
  ASSERT_FALSE(r.scene.objects.empty());
  r.scene.objects[0].kind = "can \"a\\b\"";
  r.scene.objects[0].radius = std::nanf("");
  const std::string text = facyl::groundTruthJson(r);
  Json truth;
  ASSERT_NO_THROW(truth = Json::parse(text)) << text;
  EXPECT_EQ(truth["objects"][0]["kind"], "can \"a\\b\"");
  EXPECT_TRUE(truth["objects"][0]["radius"].is_null());
  EXPECT_EQ(truth["camera"]["fx"].dump(), "65.625");
  EXPECT_NE(text.find("\"cx\":39.5,"), std::string::npos);

  facyl::TabletopSequenceParameters sp;
  sp.frames = 3;
  facyl::TabletopSequence seq = facyl::generateTabletopSequence(p, sp);
  seq.scene.objects[0].kind = "tube \"x\"";
  Json sequence;
  ASSERT_NO_THROW(sequence = Json::parse(facyl::sequenceJson(seq)));
  EXPECT_EQ(sequence["objects"][0]["kind"], "tube \"x\"");
  EXPECT_EQ(sequence["cameras"].size(), 3u);
}
