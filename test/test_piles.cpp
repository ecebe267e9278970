/*
 * facyl: piles. Thin supports (a box top in a pile, books, a tray) keep their objects: what
 * stands on them and what lies under them are objects, each one segment; a real elevated
 * support (a low table over the floor) stays a support.
 */
#include "tabletop_builders.h"

#include <facyl/features/polygon.h>
#include <facyl/segmentation/support_planes.h>

#include <pcl/io/pcd_io.h>

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <map>

namespace {

using namespace facyl_test;

facyl::SceneObject
bowl(float radius, const Eigen::Vector3f& base)
{
  facyl::SceneObject o;
  o.cls = facyl::SceneClass::Bowl;
  o.kind = "bowl";
  o.radius = radius;
  o.pose.translation() = base;
  o.colour[0] = Eigen::Vector3f(0.3f, 0.7f, 0.4f);
  return o;
}

/** A pile made by hand: its objects, and where the camera looks from. */
struct Pile {
  const char* name;
  std::vector<facyl::SceneObject> objects;
  Eigen::Vector3f eye, target;
};

/** A can (a bottle) lying along x, its side on \a z, centred at (x, y). */
facyl::SceneObject
lyingCan(float radius, float height, float x, float y, float z)
{
  facyl::SceneObject o = can(radius, height, {0.f, 0.f, 0.f}, "bottle");
  o.lying = true;
  o.pose.linear() = Eigen::AngleAxisf(0.5f * kPi, Eigen::Vector3f::UnitY()).toRotationMatrix();
  o.pose.translation() = Eigen::Vector3f(x - 0.5f * height, y, z + radius);
  o.colour[0] = Eigen::Vector3f(0.7f, 0.7f, 0.2f);
  return o;
}

std::vector<Pile>
piles()
{
  // The tops of the boxes and books are larger than min_shelf_area (0.1 m^2) where they are
  // seen, as in the large piles of the mOSD test scenes: only what holds them up tells them
  // from a shelf.
  std::vector<Pile> out;
  // A wide box (0.52 x 0.42 x 0.10 m) with a smaller box and a can on it, a can beside it and
  // a bottle lying in front of it.
  {
    Pile p{"boxes under boxes", {}, {0.1f, -0.9f, 0.8f}, {0.f, 0.f, 0.08f}};
    p.objects.push_back(box({0.52f, 0.42f, 0.10f}, {0.f, 0.05f, 0.f}));
    p.objects.push_back(box({0.14f, 0.10f, 0.09f}, {-0.12f, 0.12f, 0.10f}, 0.1f));
    p.objects.back().colour[0] = Eigen::Vector3f(0.2f, 0.6f, 0.3f);
    p.objects.push_back(can(0.035f, 0.11f, {0.12f, 0.12f, 0.10f}));
    p.objects.push_back(can(0.035f, 0.12f, {0.36f, -0.05f, 0.f}));
    p.objects.push_back(lyingCan(0.035f, 0.22f, 0.f, -0.26f, 0.f));
    out.push_back(std::move(p));
  }
  // A bowl on books: an atlas (0.46 x 0.34 x 0.04 m) under a smaller book, the bowl on them.
  {
    Pile p{"bowl on books", {}, {-0.1f, -0.8f, 0.75f}, {0.f, 0.f, 0.05f}};
    p.objects.push_back(box({0.46f, 0.34f, 0.04f}, {0.f, 0.f, 0.f}));
    p.objects.push_back(box({0.30f, 0.23f, 0.035f}, {-0.06f, 0.04f, 0.04f}, 0.05f));
    p.objects.back().colour[0] = Eigen::Vector3f(0.2f, 0.3f, 0.8f);
    p.objects.push_back(bowl(0.08f, {-0.05f, 0.04f, 0.075f}));
    out.push_back(std::move(p));
  }
  // A can on an atlas (0.44 x 0.34 x 0.035 m).
  {
    Pile p{"can on a book", {}, {0.15f, -0.75f, 0.65f}, {0.f, 0.f, 0.05f}};
    p.objects.push_back(box({0.44f, 0.34f, 0.035f}, {0.f, 0.f, 0.f}, 0.3f));
    p.objects.push_back(can(0.033f, 0.12f, {0.05f, 0.02f, 0.035f}));
    out.push_back(std::move(p));
  }
  // A tray (0.46 x 0.34 x 0.02 m) with three cans on it.
  {
    Pile p{"tray with cans", {}, {0.f, -0.85f, 0.7f}, {0.f, 0.f, 0.05f}};
    p.objects.push_back(box({0.46f, 0.34f, 0.02f}, {0.f, 0.f, 0.f}));
    p.objects.push_back(can(0.033f, 0.12f, {-0.12f, 0.05f, 0.02f}));
    p.objects.push_back(can(0.04f, 0.10f, {0.05f, -0.06f, 0.02f}));
    p.objects.push_back(can(0.03f, 0.14f, {0.13f, 0.08f, 0.02f}));
    out.push_back(std::move(p));
  }
  // A large pile seen from close above: its tops hold more pixels than the table around it.
  {
    Pile p{"large pile", {}, {0.f, -0.45f, 0.75f}, {0.f, 0.f, 0.1f}};
    p.objects.push_back(box({0.48f, 0.40f, 0.12f}, {-0.04f, 0.02f, 0.f}));
    p.objects.push_back(box({0.40f, 0.32f, 0.10f}, {-0.06f, 0.04f, 0.12f}, 0.06f));
    p.objects.back().colour[0] = Eigen::Vector3f(0.2f, 0.6f, 0.3f);
    p.objects.push_back(box({0.12f, 0.10f, 0.18f}, {0.30f, 0.0f, 0.f}));
    p.objects.back().colour[0] = Eigen::Vector3f(0.6f, 0.2f, 0.7f);
    p.objects.push_back(can(0.033f, 0.12f, {-0.08f, 0.06f, 0.22f}));
    out.push_back(std::move(p));
  }
  return out;
}

} // namespace

TEST(ThinSupports, PilesKeepEveryObject)
{
  // Each object of a pile is one segment: the tops of the boxes, the books and the tray are
  // objects' faces, not shelves; what lies under them is no furniture.
  for (const std::string sensor : {"kinect", "stereo"})
    for (const Pile& pile : piles()) {
      facyl::TabletopScene scene = emptyTable();
      for (const auto& o : pile.objects)
        scene.objects.push_back(o);
      const facyl::RenderedScene s = render(scene, pile.eye, pile.target, sensor);
      if (std::getenv("FACYL_TEST_DUMP"))
        pcl::io::savePCDFileBinary(std::string("/tmp/pile_") + pile.name + "_" + sensor + ".pcd",
                                   s.cloud);
      const auto out = segmentAndScore(s);
      std::string line;
      for (const auto& o : out) {
        line += " " + std::to_string(o.object) + (o.recovered ? "+" : "-") + (o.merged ? "m" : "") +
                (o.split ? "s" : "");
        EXPECT_TRUE(o.recovered) << pile.name << ", " << sensor << ": object " << o.object << " ("
                                 << s.scene.objects[static_cast<std::size_t>(o.object - 2)].kind
                                 << "), IoU " << o.best_iou;
      }
      std::printf("[ figures ] %s, %s:%s\n", pile.name, sensor.c_str(), line.c_str());
    }
}

TEST(ThinSupports, ALowTableOverTheFloorStaysASupport)
{
  // A round stool-sized table (radius 0.21 m, 0.42 m high, on a pedestal: inside the floor's
  // object band, no wider than an object, its top large enough for a shelf) with a can and a
  // box on it, seen from in front and above: the floor shows under it, so it is a support,
  // and the objects stand on it.
  facyl::TabletopSceneParameters low;
  low.round_table_share = 1.f;
  low.table_height = {0.42f, 0.42f};
  low.table_legs = true;
  facyl::TabletopScene scene = emptyTable(low);
  // The generator's round tables are at least 0.25 m in radius.
  scene.table_radius = 0.21f;
  for (auto& part : scene.furniture)
    if (part.kind == "table")
      part.radius = scene.table_radius;
  scene.objects.push_back(can(0.03f, 0.1f, {-0.08f, 0.09f, 0.f}));
  scene.objects.push_back(box({0.08f, 0.06f, 0.08f}, {0.08f, 0.08f, 0.f}, 0.3f));
  for (const std::string sensor : {"kinect", "stereo"}) {
    const facyl::RenderedScene s = render(scene, {0.05f, -0.65f, 0.6f}, {0.f, 0.f, -0.1f}, sensor);
    if (std::getenv("FACYL_TEST_DUMP"))
      pcl::io::savePCDFileBinary("/tmp/pile_low_table_" + sensor + ".pcd", s.cloud);
    Cloud::Ptr cloud(new Cloud(s.cloud));
    facyl::TabletopSegmentation<pcl::PointXYZRGBA> seg;
    seg.setInputCloud(cloud);
    std::vector<facyl::TabletopCluster> clusters;
    ASSERT_TRUE(seg.segment(clusters)) << sensor;
    ASSERT_TRUE(seg.tableFound()) << sensor;
    const auto& c = seg.getTableCoefficients().values;
    EXPECT_NEAR(c[3], s.table_plane[3], 0.02f) << sensor << ": the table is the low table";
    std::vector<pcl::PointIndices> segments;
    for (const auto& k : clusters)
      segments.push_back(k.indices);
    for (const auto& o : facyl::scoreSegments(truthOf(s), segments, 300)) {
      EXPECT_TRUE(o.recovered) << sensor << ": object " << o.object;
      EXPECT_EQ(clusters[static_cast<std::size_t>(o.best_segment)].support,
                static_cast<int>(seg.getTableIndex()))
        << sensor << ": object " << o.object;
    }
  }
}

TEST(ThinSupports, ElevatedSupportVerdicts)
{
  // isElevatedSupport on measured quantities: a shelf with room seen under it; a low table
  // whose edge shows no wall down to the floor; a low table larger than an object seen from
  // above (no edge faces the sensor); a box top larger than an object whose sides are walls;
  // a tray within the contact height; a small shelf.
  const auto plane = [](float height, float area, float diameter, float seen_under,
                        int facing_pieces, float walled) {
    facyl::ElevatedPlane e;
    e.height = height;
    e.contact = 0.035f;
    e.region_area = area;
    e.diameter = diameter;
    e.seen_under = seen_under;
    e.facing_pieces = facing_pieces;
    e.walled = walled;
    return e;
  };
  EXPECT_TRUE(facyl::isElevatedSupport(plane(0.3f, 0.15f, 0.45f, 0.4f, 10, 0.6f), 0.1f, 0.5f));
  EXPECT_TRUE(facyl::isElevatedSupport(plane(0.4f, 0.3f, 0.45f, 0.f, 12, 0.2f), 0.1f, 0.5f));
  EXPECT_TRUE(facyl::isElevatedSupport(plane(0.4f, 0.3f, 0.8f, 0.f, 0, 0.f), 0.1f, 0.5f));
  EXPECT_FALSE(facyl::isElevatedSupport(plane(0.4f, 0.3f, 0.45f, 0.f, 0, 0.f), 0.1f, 0.5f));
  EXPECT_FALSE(facyl::isElevatedSupport(plane(0.12f, 0.15f, 0.6f, 0.02f, 10, 0.9f), 0.1f, 0.5f));
  EXPECT_FALSE(facyl::isElevatedSupport(plane(0.02f, 0.15f, 0.57f, 0.f, 10, 0.f), 0.1f, 0.5f));
  EXPECT_FALSE(facyl::isElevatedSupport(plane(0.3f, 0.05f, 0.45f, 0.4f, 10, 0.f), 0.1f, 0.5f));
}

TEST(ThinSupports, NearPointsAndShrunkHulls)
{
  // The polygon helpers of the support test: inside a square shrunk by a margin, its diameter.
  const std::vector<Eigen::Vector2f> square =
    facyl::convexHull2D({{0.f, 0.f}, {1.f, 0.f}, {1.f, 1.f}, {0.f, 1.f}});
  EXPECT_TRUE(facyl::insideConvexBy({0.5f, 0.5f}, square, 0.4f));
  EXPECT_FALSE(facyl::insideConvexBy({0.5f, 0.05f}, square, 0.1f));
  EXPECT_FALSE(facyl::insideConvexBy({1.5f, 0.5f}, square, 0.f));
  EXPECT_NEAR(facyl::polygonDiameter(square), std::sqrt(2.f), 1e-6f);
}

TEST(TouchingObjects, ColourEdgesSplitWhatDepthJoins)
{
  // Cluttered simulated scenes (touching, stacked, leaning objects): where two objects of
  // other colours touch, the valley between them is blurred below the crease angle by noise
  // and the pixel footprint; colour edges on the weak creases there split them. Measured on
  // the same 30 scenes, both sensors, with colour edges off and at their default.
  for (const std::string sensor : {"kinect", "stereo"}) {
    std::size_t recovered[2] = {0, 0}, merged[2] = {0, 0}, split[2] = {0, 0}, n = 0;
    for (std::uint64_t seed = 2000; seed < 2030; ++seed) {
      facyl::TabletopSceneParameters p = facyl::clutteredSceneParameters();
      p.seed = seed;
      ASSERT_TRUE(facyl::parseSensorPreset(sensor, p.sensor, p.camera));
      const facyl::RenderedScene s = facyl::simulateTabletopScene(p);
      for (const int with : {0, 1}) {
        facyl::TabletopSegmentationParameters params;
        if (!with)
          params.objects.colour_edge = 0.f;
        for (const auto& o : segmentAndScore(s, params)) {
          recovered[with] += o.recovered;
          merged[with] += o.merged;
          split[with] += o.split;
          n += with;
        }
      }
    }
    std::printf("[ figures ] %s, %zu objects: recovered %zu -> %zu, merged %zu -> %zu, split "
                "%zu -> %zu (colour edges off -> on)\n",
                sensor.c_str(), n, recovered[0], recovered[1], merged[0], merged[1], split[0],
                split[1]);
    EXPECT_GT(recovered[1], recovered[0]) << sensor;
    EXPECT_LT(merged[1], merged[0]) << sensor;
    EXPECT_LE(split[1], split[0] + n / 50) << sensor; // labels and stripes are no edges
  }
}

TEST(TouchingObjects, ColourEdgesOnTheLattice)
{
  // A 1280 x 720 frame segmented on its lattice (lattice_width 640: every second pixel and
  // row) has the colour edges too: the lattice carries the colours of its pixels. Cluttered
  // simulated scenes at 1280 x 720, colour edges off and at their default.
  std::size_t recovered[2] = {0, 0}, merged[2] = {0, 0}, n = 0;
  for (std::uint64_t seed = 2000; seed < 2016; ++seed) {
    facyl::TabletopSceneParameters p = facyl::clutteredSceneParameters();
    p.seed = seed;
    ASSERT_TRUE(facyl::parseSensorPreset("kinect", p.sensor, p.camera));
    p.camera = facyl::resizedCamera(p.camera, 1280, 720); // the VGA camera's field of view
    const facyl::RenderedScene s = facyl::simulateTabletopScene(p);
    for (const int with : {0, 1}) {
      facyl::TabletopSegmentationParameters params;
      params.lattice_width = 640;
      if (!with)
        params.objects.colour_edge = 0.f;
      for (const auto& o : segmentAndScore(s, params)) {
        recovered[with] += o.recovered;
        merged[with] += o.merged;
        n += with;
      }
    }
  }
  std::printf("[ figures ] lattice, %zu objects: recovered %zu -> %zu, merged %zu -> %zu "
              "(colour edges off -> on)\n",
              n, recovered[0], recovered[1], merged[0], merged[1]);
  EXPECT_GT(recovered[1], recovered[0]);
  EXPECT_LT(merged[1], merged[0]);
}

TEST(TouchingObjects, AStripedCanIsOneObject)
{
  // Stripes and checkers of strongly different colours on a smooth surface lie on no crease:
  // each can is one segment.
  facyl::TabletopScene scene = emptyTable();
  scene.objects.push_back(can(0.04f, 0.12f, {-0.06f, 0.f, 0.f}));
  scene.objects.push_back(can(0.035f, 0.10f, {0.06f, 0.03f, 0.f}));
  scene.objects.push_back(can(0.03f, 0.14f, {0.f, 0.12f, 0.f}));
  for (std::size_t k = 0; k < scene.objects.size(); ++k) {
    auto& o = scene.objects[k];
    o.texture = 1 + static_cast<int>(k % 2); // stripes, checkers
    o.colour[0] = Eigen::Vector3f(0.9f, 0.9f, 0.1f);
    o.colour[1] = Eigen::Vector3f(0.1f, 0.1f, 0.7f);
  }
  for (const std::string sensor : {"kinect", "stereo"}) {
    const facyl::RenderedScene s =
      render(scene, {0.05f, -0.6f, 0.55f}, {0.f, 0.03f, 0.05f}, sensor);
    for (const auto& o : segmentAndScore(s)) {
      EXPECT_TRUE(o.recovered) << sensor << ": object " << o.object << ", IoU " << o.best_iou;
      EXPECT_FALSE(o.split) << sensor << ": object " << o.object;
    }
  }
}
