/*
 * facyl: tabletop scenes, segmentation and recognition.
 */
#include "test_helpers.h"

#include <facyl/features/polygon.h>
#include <facyl/recognition/tabletop_cylinder_recognizer.h>
#include <facyl/segmentation/plane_search.h>
#include <facyl/segmentation/tabletop_segmentation.h>
#include <facyl/simulation/tabletop_scene.h>

#include <pcl/common/io.h>
#include <pcl/common/point_tests.h>
#include <pcl/io/pcd_io.h>
#include <pcl/segmentation/extract_polygonal_prism_data.h>

#include <gtest/gtest.h>

#include <filesystem>
#include <map>
#include <numeric>
#include <random>

using Cloud = pcl::PointCloud<pcl::PointXYZRGBA>;

namespace {

facyl::RenderedScene
scene(std::uint64_t seed)
{
  facyl::TabletopSceneParameters p;
  p.seed = seed;
  return facyl::simulateTabletopScene(p);
}

/** The object id most of the cluster's points carry. */
int
majorityId(const facyl::RenderedScene& s, const pcl::Indices& indices)
{
  std::map<int, std::size_t> votes;
  for (const auto i : indices)
    ++votes[s.object_id[static_cast<std::size_t>(i)]];
  return std::max_element(votes.begin(), votes.end(),
                          [](const auto& a, const auto& b) { return a.second < b.second; })
    ->first;
}

/** majorityId for indices into the scene's finite points, in pixel order. */
int
majorityIdOfUnorganized(const facyl::RenderedScene& s, const pcl::Indices& indices)
{
  std::vector<pcl::index_t> pixel_of;
  for (std::size_t i = 0; i < s.cloud.size(); ++i)
    if (pcl::isFinite(s.cloud[i]))
      pixel_of.push_back(static_cast<pcl::index_t>(i));
  pcl::Indices pixels;
  for (const auto i : indices)
    pixels.push_back(pixel_of[static_cast<std::size_t>(i)]);
  return majorityId(s, pixels);
}

} // namespace

// ---------------------------------------------------------------- geometry helpers

TEST(TabletopGeometry, FitPlaneOrientsTowardsTheViewpoint)
{
  Eigen::Matrix3Xf pts(3, 100);
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> u(-1.f, 1.f);
  for (int i = 0; i < 100; ++i)
    pts.col(i) = Eigen::Vector3f(u(rng), u(rng), 2.f + 0.001f * u(rng));
  Eigen::Vector4f plane;
  ASSERT_TRUE(facyl::fitPlane(pts, Eigen::Vector3f::Zero(), plane));
  EXPECT_NEAR(plane[2], -1.f, 1e-3f); // normal towards the origin
  EXPECT_NEAR(plane[3], 2.f, 1e-3f);
  // A line is not a plane.
  Eigen::Matrix3Xf line(3, 10);
  for (int i = 0; i < 10; ++i)
    line.col(i) = Eigen::Vector3f(static_cast<float>(i), 0.f, 0.f);
  EXPECT_FALSE(facyl::fitPlane(line, Eigen::Vector3f::Zero(), plane));
  EXPECT_FALSE(facyl::fitPlane(Eigen::Matrix3Xf(3, 2), Eigen::Vector3f::Zero(), plane));
  const Eigen::Vector4f flipped =
    facyl::orientPlane(Eigen::Vector4f(0.f, 0.f, 2.f, -4.f), Eigen::Vector3f::Zero());
  EXPECT_TRUE(flipped.isApprox(Eigen::Vector4f(0.f, 0.f, -1.f, 2.f)));
}

TEST(TabletopGeometry, PlaneFrameHasTheNormalAsZ)
{
  const Eigen::Vector4f plane(0.f, -0.6f, -0.8f, 1.f);
  const Eigen::Affine3f f = facyl::planeFrame(plane, Eigen::Vector3f(0.f, 0.f, 3.f));
  EXPECT_TRUE(f.linear().col(2).isApprox(plane.head<3>()));
  EXPECT_NEAR(f.linear().determinant(), 1.f, 1e-5f);
  EXPECT_NEAR(plane.head<3>().dot(f.translation()) + plane[3], 0.f, 1e-5f);
}

TEST(TabletopGeometry, BoxesAndPolygons)
{
  const facyl::PixelBox box = facyl::pixelBox({5 + 10 * 3, 7 + 10 * 1, 2 + 10 * 8}, 10);
  EXPECT_EQ(box, (facyl::PixelBox{2, 1, 7, 8}));
  EXPECT_EQ(facyl::pixelBox({}, 10), (facyl::PixelBox{-1, -1, -1, -1}));
  const std::vector<Eigen::Vector2f> square{{0.f, 0.f}, {1.f, 0.f}, {1.f, 1.f}, {0.f, 1.f}};
  EXPECT_TRUE(facyl::pointInPolygon({0.5f, 0.5f}, square));
  EXPECT_FALSE(facyl::pointInPolygon({1.5f, 0.5f}, square));
  EXPECT_FALSE(facyl::pointInPolygon({0.5f, -0.1f}, square));
  // Counted in a plane's coordinates: the same as the test point by point.
  const Eigen::Affine3f to_plane =
    Eigen::Translation3f(0.2f, -0.1f, 0.3f) * Eigen::AngleAxisf(0.3f, Eigen::Vector3f::UnitZ());
  const std::vector<Eigen::Vector2f> hexagon{{0.f, 0.f}, {1.f, 0.f}, {1.5f, 0.5f},
                                             {1.f, 1.f}, {0.f, 1.f}, {-0.5f, 0.5f}};
  Eigen::Matrix3Xf scattered(3, 500); // a lattice over and around both, each point its own z
  for (Eigen::Index k = 0; k < scattered.cols(); ++k)
    scattered.col(k) << -1.5f + 0.13f * static_cast<float>(k % 25),
      -1.5f + 0.15f * static_cast<float>(k / 25), 0.01f * static_cast<float>(k % 7);
  for (const auto* polygon : {&square, &hexagon}) {
    std::size_t expected = 0;
    for (Eigen::Index k = 0; k < scattered.cols(); ++k)
      expected +=
        facyl::pointInPolygon((to_plane * Eigen::Vector3f(scattered.col(k))).head<2>(), *polygon);
    EXPECT_GT(expected, 0u);
    EXPECT_LT(expected, 500u);
    EXPECT_EQ(facyl::pointsInPolygon(scattered, to_plane, *polygon), expected);
  }
  EXPECT_EQ(facyl::pointsInPolygon(scattered, to_plane, {}), 0u);
  facyl::PinholeCamera cam{500.f, 500.f, 320.f, 240.f, 640, 480};
  Eigen::Matrix3Xf pts(3, 3);
  pts << 0.f, 0.1f, 5.f, //
    0.f, 0.1f, 0.f,      //
    1.f, 1.f, -1.f;      // the third is behind the camera
  EXPECT_EQ(facyl::projectedBox(pts, cam), (facyl::PixelBox{320, 240, 370, 290}));
  EXPECT_EQ(facyl::projectedBox(pts, facyl::PinholeCamera{}), (facyl::PixelBox{-1, -1, -1, -1}));
}

TEST(TabletopGeometry, RowExtremesHoldThePlanesHull)
{
  EXPECT_EQ(facyl::rowExtremes({12, 3, 25, 14, 11, 99, -1}, 10, 3), (pcl::Indices{3, 11, 14, 25}));
  // Pixels of a random blob seen on a tilted plane: the hull of each row's extremes, on the
  // plane, is the hull of every pixel (a projective map keeps convex hulls).
  const facyl::PinholeCamera cam{525.f, 525.f, 319.5f, 239.5f, 640, 480};
  const Eigen::Vector3f n = Eigen::Vector3f(0.1f, -0.8f, -0.5f).normalized();
  const float d = 0.6f; // plane n.x + d = 0, in front of the camera
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> uni(0.f, 1.f);
  pcl::Indices all;
  for (int v = 0; v < cam.height; ++v)
    for (int u = 0; u < cam.width; ++u) {
      const float du = (u - 320.f) / 200.f, dv = (v - 300.f) / 120.f;
      if (du * du + dv * dv < 1.f && uni(rng) < 0.7f)
        all.push_back(v * cam.width + u);
    }
  const auto flat = [&](const pcl::Indices& idx) {
    std::vector<Eigen::Vector2f> out;
    for (const auto i : idx) {
      const Eigen::Vector3f ray((i % cam.width - cam.cx) / cam.fx,
                                (i / cam.width - cam.cy) / cam.fy, 1.f);
      const Eigen::Vector3f p = ray * (-d / n.dot(ray));
      out.emplace_back(p.x(), p.z() * 0.5f + p.y()); // any affine chart of the plane
    }
    return out;
  };
  const float full = facyl::polygonArea(facyl::convexHull2D(flat(all)));
  const pcl::Indices ends = facyl::rowExtremes(all, cam.width, cam.height);
  EXPECT_LT(ends.size() * 20, all.size());
  EXPECT_NEAR(facyl::polygonArea(facyl::convexHull2D(flat(ends))), full, 1e-4f * full);
}

TEST(TabletopGeometry, LatticeAndItsBlocks)
{
  // A 5 x 3 image, every second pixel and row: a 3 x 2 lattice.
  pcl::PointCloud<pcl::PointXYZ> image(5, 3), lattice;
  for (std::size_t i = 0; i < image.size(); ++i)
    image[i] = pcl::PointXYZ(static_cast<float>(i), 0.f, 1.f);
  image.sensor_origin_ = Eigen::Vector4f(1.f, 2.f, 3.f, 0.f);
  facyl::latticeOf(image, 2, lattice);
  ASSERT_EQ(lattice.width, 3u);
  ASSERT_EQ(lattice.height, 2u);
  EXPECT_EQ(lattice.sensor_origin_, image.sensor_origin_);
  const std::vector<float> x{0.f, 2.f, 4.f, 10.f, 12.f, 14.f};
  for (std::size_t k = 0; k < lattice.size(); ++k)
    EXPECT_EQ(lattice[k].x, x[k]);
  // Lattice pixels (0, 0), (2, 0) and (1, 1): their 2 x 2 blocks, cut at the image's edges.
  const auto all = [](pcl::index_t, pcl::index_t) { return true; };
  EXPECT_EQ(facyl::blockPixels({0, 2, 4}, 5, 3, 2, all), (pcl::Indices{0, 1, 4, 5, 6, 9, 12, 13}));
  const auto parents = [](pcl::index_t pixel, pcl::index_t parent) { return pixel == parent; };
  EXPECT_EQ(facyl::blockPixels({0, 2, 4}, 5, 3, 2, parents), (pcl::Indices{0, 4, 12}));
  EXPECT_TRUE(facyl::blockPixels({}, 5, 3, 2, all).empty());
}

TEST(TabletopGeometry, PinholeFromAnOrganizedCloud)
{
  const auto s = scene(3);
  std::vector<Eigen::Vector3f> p3;
  std::vector<Eigen::Vector2f> p2;
  for (std::size_t i = 0; i < s.cloud.size(); i += 13)
    if (pcl::isFinite(s.cloud[i])) {
      p3.push_back(s.cloud[i].getVector3fMap());
      p2.emplace_back(static_cast<float>(i % 640), static_cast<float>(i / 640));
    }
  Eigen::Matrix3Xf pts(3, static_cast<Eigen::Index>(p3.size()));
  Eigen::Matrix2Xf px(2, static_cast<Eigen::Index>(p2.size()));
  for (std::size_t k = 0; k < p3.size(); ++k)
    pts.col(static_cast<Eigen::Index>(k)) = p3[k], px.col(static_cast<Eigen::Index>(k)) = p2[k];
  facyl::PinholeCamera cam;
  ASSERT_TRUE(facyl::estimatePinhole(pts, px, 640, 480, cam));
  EXPECT_NEAR(cam.fx, 525.f, 0.5f);
  EXPECT_NEAR(cam.fy, 525.f, 0.5f);
  EXPECT_NEAR(cam.cx, 319.5f, 0.5f);
  EXPECT_NEAR(cam.cy, 239.5f, 0.5f);
  EXPECT_FALSE(facyl::estimatePinhole(pts.leftCols(5), px.leftCols(5), 640, 480, cam));
}

TEST(TabletopGeometry, APixelLatticeKeepsEvenlySpacedPixelsUpToItsCap)
{
  // A 30 x 20 block of a 100-pixel-wide image, from column 10 and row 5.
  pcl::Indices block;
  for (int v = 5; v < 25; ++v)
    for (int u = 10; u < 40; ++u)
      block.push_back(v * 100 + u);
  // Spacing 3: columns 12, 15, ..., 39 and rows 6, 9, ..., 24 (10 x 7), in the block's order,
  // each in its cell of the lattice's box (cells 4-13 and 2-8).
  const facyl::PixelLattice three = facyl::pixelLattice(block, 100, 3.f, 1000);
  ASSERT_EQ(three.pixels.size(), 70u);
  EXPECT_EQ(three.columns, 10);
  EXPECT_EQ(three.rows, 7);
  EXPECT_EQ(three.pixels.front(), 6 * 100 + 12);
  EXPECT_EQ(three.pixels.back(), 24 * 100 + 39);
  ASSERT_EQ(three.cell_of.size(), 70u);
  for (std::size_t k = 0; k < three.pixels.size(); ++k) {
    const int u = three.pixels[k] % 100, v = three.pixels[k] / 100;
    EXPECT_EQ(u % 3, 0);
    EXPECT_EQ(v % 3, 0);
    EXPECT_EQ(three.cell_of[k], (v / 3 - 2) * 10 + (u / 3 - 4));
  }
  // Capped at 20: a wider lattice, evenly spread over the block (never a stripe of rows).
  const facyl::PixelLattice capped = facyl::pixelLattice(block, 100, 3.f, 20);
  EXPECT_LE(capped.pixels.size(), 20u);
  EXPECT_GE(capped.pixels.size(), 12u);
  EXPECT_GT(capped.spacing, 3.f);
  int u_lo = 100, u_hi = 0, v_lo = 100, v_hi = 0;
  for (const auto i : capped.pixels) {
    u_lo = std::min(u_lo, i % 100);
    u_hi = std::max(u_hi, i % 100);
    v_lo = std::min(v_lo, i / 100);
    v_hi = std::max(v_hi, i / 100);
  }
  EXPECT_GE(u_hi - u_lo, 20);
  EXPECT_GE(v_hi - v_lo, 12);
  EXPECT_EQ(facyl::pixelLattice(block, 100, 1.f, 1000).pixels, block);
  // As an organized cloud: each kept pixel's point at its cell, the other cells empty.
  pcl::PointCloud<pcl::PointXYZ> points;
  for (const auto i : three.pixels)
    points.push_back(pcl::PointXYZ(static_cast<float>(i % 100), static_cast<float>(i / 100), 1.f));
  const auto cloud = facyl::latticeCloud(three, points);
  ASSERT_EQ(cloud->width, 10u);
  ASSERT_EQ(cloud->height, 7u);
  EXPECT_FALSE(cloud->is_dense);
  EXPECT_EQ((*cloud)(0, 0).x, 12.f); // pixel (12, 6)
  EXPECT_EQ((*cloud)(9, 6).y, 24.f); // pixel (39, 24)
  EXPECT_EQ(std::count_if(cloud->begin(), cloud->end(),
                          [](const pcl::PointXYZ& p) { return pcl::isFinite(p); }),
            70);
  points.push_back(pcl::PointXYZ(0.f, 0.f, 1.f));
  EXPECT_THROW(facyl::latticeCloud(three, points), std::invalid_argument);
  EXPECT_TRUE(facyl::pixelLattice({}, 100, 3.f, 10).pixels.empty());
  EXPECT_THROW(facyl::pixelLattice(block, 100, 0.5f, 10), std::invalid_argument);
  EXPECT_THROW(facyl::pixelLattice(block, 0, 3.f, 10), std::invalid_argument);
}

TEST(TabletopGeometry, EvenSubsampleAndCapPoints)
{
  pcl::Indices all(1000);
  std::iota(all.begin(), all.end(), 0);
  const pcl::Indices sub = facyl::evenSubsample(all, 100);
  ASSERT_EQ(sub.size(), 100u);
  EXPECT_EQ(sub[1] - sub[0], 10);
  EXPECT_EQ(facyl::evenSubsample(all, 5000).size(), 1000u);

  facyl::CylinderModel m;
  m.base = Eigen::Vector3f::Zero();
  m.top = Eigen::Vector3f(0.f, 0.f, 0.1f);
  m.axis = Eigen::Vector3f::UnitZ();
  m.radius = 0.05f;
  Eigen::Matrix3Xf pts(3, 4), nrm(3, 4);
  pts << 0.01f, 0.f, 0.2f, 0.f, //
    0.f, 0.02f, 0.f, 0.f,       //
    0.1f, 0.1f, 0.1f, 0.05f;
  nrm << 0.f, 0.f, 0.f, 1.f, //
    0.f, 0.f, 0.f, 0.f,      //
    1.f, 1.f, 1.f, 0.f;
  // Points 0 and 1 lie on the top cap; 2 is beyond the radius, 3 is mid-height.
  EXPECT_EQ(facyl::countCapPoints(m, pts, nrm, 0.005f, 0.5f), 2u);
  m.inliers = {1};
  EXPECT_EQ(facyl::countCapPoints(m, pts, nrm, 0.005f, 0.5f), 1u); // inliers are not counted
}

// ---------------------------------------------------------------- simulator

TEST(PlaneSearch, GridAndSeedsOfAPlane)
{
  // A 160 x 120 frame of a plane z = 1 (a few pixels without depth): the grid of 4-pixel blocks
  // holds the block means, and one seed region covers the cells.
  pcl::PointCloud<pcl::PointXYZ> frame(160, 120);
  facyl::BlockMeans blocks(4, 160, 120);
  for (int v = 0; v < 120; ++v)
    for (int u = 0; u < 160; ++u) {
      const Eigen::Vector3f p((u - 80) / 160.f, (v - 60) / 160.f, 1.f);
      if ((u * 7 + v * 13) % 50 != 0)
        blocks.add(u, v, v * 160 + u, p);
    }
  facyl::PlaneGrid grid;
  facyl::finishPlaneGrid(blocks, 160, grid);
  ASSERT_EQ(grid.small->width, 40u);
  ASSERT_EQ(grid.small->height, 30u);
  EXPECT_NEAR((*grid.small)(10, 10).z, 1.f, 1e-6f);
  EXPECT_TRUE(grid.samples.col(0).allFinite());
  const auto seeds = facyl::planeSeeds(grid, 1000, 0.05f, 0.015f);
  ASSERT_FALSE(seeds.empty());
  // Every cell but a border of 4 (the normals' smoothing window) is in it, with a normal along z.
  EXPECT_GE(seeds.front().indices.size(), 32u * 22u * 9u / 10u);
  for (const auto i : seeds.front().indices)
    EXPECT_GT(std::abs(grid.cell_normals(2, i)), 0.99f);
}

TEST(PlaneSearch, FamiliesFacingUpComeFirst)
{
  // A wall (normal along the image's down direction: it faces the side) with more points than
  // the table (normal against image down) and a floor parallel to the table.
  const Eigen::Vector3f down(0.f, 1.f, 0.f);
  const std::vector<Eigen::Vector4f> planes = {{0.f, 0.f, -1.f, 3.f},   // wall, facing the camera
                                               {0.f, -1.f, 0.f, 0.5f},  // table
                                               {0.f, -1.f, 0.f, 1.2f}}; // floor
  const std::vector<std::size_t> points = {50000, 20000, 10000};
  const auto families = facyl::rankSupportFamilies(planes, points, false, down);
  ASSERT_EQ(families.size(), 2u);
  EXPECT_EQ(families[0], (std::vector<std::size_t>{1, 2}));
  EXPECT_EQ(families[1], (std::vector<std::size_t>{0}));
  // With a known up every family may be a support: most points first.
  EXPECT_EQ(facyl::rankSupportFamilies(planes, points, true, down)[0],
            (std::vector<std::size_t>{0}));
}

TEST(PlaneSearch, SpansPlaneIsFalseForCoincidentAndCollinearPoints)
{
  pcl::PointCloud<pcl::PointXYZ> c;
  const auto indices = [&c] {
    pcl::Indices all(c.size());
    std::iota(all.begin(), all.end(), 0);
    return all;
  };
  c.push_back(pcl::PointXYZ(0.1f, 0.2f, 1.f));
  c.push_back(pcl::PointXYZ(0.1f, 0.2f, 1.f));
  EXPECT_FALSE(facyl::spansPlane(c, indices())); // fewer than 3 distinct points
  for (int i = 0; i < 40; ++i) // on one line (float rounding and all), NaN between
    c.push_back(i % 7 ? pcl::PointXYZ(0.1f + 0.01f * i, 0.2f + 0.02f * i, 1.f + 0.005f * i)
                      : pcl::PointXYZ(NAN, NAN, NAN));
  EXPECT_FALSE(facyl::spansPlane(c, indices()));
  // A point 1 mm off the line, 0.4 m long: the cross product is 4e-4 m^2, a plane.
  c.push_back(pcl::PointXYZ(0.1f + 0.001f, 0.2f, 1.f));
  EXPECT_TRUE(facyl::spansPlane(c, indices()));
  const pcl::Indices all = indices();
  EXPECT_FALSE(facyl::spansPlane(c, pcl::Indices(all.begin(), all.end() - 1))); // not indexed
  // ... not at 1 micrometre, where PCL's plane model takes no sample either.
  c.back() = pcl::PointXYZ(0.1f + 1e-6f, 0.2f, 1.f);
  EXPECT_FALSE(facyl::spansPlane(c, indices()));
}

TEST(PlaneSearch, VoxelEuclideanClusters)
{
  // Two blobs 10 cm apart, 2 cm tolerance: two clusters, the larger first, every point in one.
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0.f, 0.03f);
  Eigen::Matrix3Xf points(3, 300);
  for (int k = 0; k < 300; ++k)
    points.col(k) = Eigen::Vector3f(u(rng) + (k < 100 ? 0.13f : 0.f), u(rng), u(rng) + 1.f);
  const auto groups = facyl::voxelEuclideanClusters(points, 0.02f);
  ASSERT_EQ(groups.size(), 2u);
  EXPECT_EQ(groups[0].size(), 200u);
  EXPECT_EQ(groups[1].size(), 100u);
  EXPECT_EQ(groups[1].front(), 0u);
}

TEST(TabletopScene, DeterministicAndConsistentWithItsGroundTruth)
{
  const auto a = scene(11), b = scene(11), c = scene(12);
  ASSERT_EQ(a.cloud.width, 640u);
  ASSERT_EQ(a.cloud.height, 480u);
  EXPECT_GE(a.scene.objects.size(), 3u);
  EXPECT_LE(a.scene.objects.size(), 10u);
  std::size_t same = 0, finite = 0, differ = 0;
  for (std::size_t i = 0; i < a.cloud.size(); ++i) {
    const bool fa = pcl::isFinite(a.cloud[i]);
    finite += fa;
    same += fa && a.cloud[i].z == b.cloud[i].z && a.cloud[i].rgba == b.cloud[i].rgba;
    differ += fa && pcl::isFinite(c.cloud[i]) && a.cloud[i].z != c.cloud[i].z;
  }
  EXPECT_EQ(same, finite);
  EXPECT_GT(differ, finite / 2);
  EXPECT_GT(finite, a.cloud.size() / 2);
  EXPECT_LT(finite, a.cloud.size()); // the sensor model drops pixels

  // Table pixels lie on the ground-truth plane within the sensor's noise; object pixels above.
  std::size_t table = 0, on_plane = 0;
  std::vector<std::size_t> visible(a.scene.objects.size(), 0);
  for (std::size_t i = 0; i < a.cloud.size(); ++i) {
    if (!pcl::isFinite(a.cloud[i]))
      continue;
    const float d = a.table_plane.head<3>().dot(a.cloud[i].getVector3fMap()) + a.table_plane[3];
    if (a.object_id[i] == 1) {
      ++table;
      on_plane += std::abs(d) < 0.01f;
      EXPECT_EQ(a.pixel_class[i], facyl::SceneClass::Table);
    }
    else if (a.object_id[i] >= 2) {
      EXPECT_GT(d, -0.01f);
      ++visible[a.object_id[i] - 2u];
    }
  }
  EXPECT_GT(table, 50000u);
  EXPECT_GT(on_plane, table * 99 / 100);
  EXPECT_EQ(visible, a.visible_pixels);

  // A cylinder's pixels lie on its ground-truth surface.
  for (std::size_t k = 0; k < a.scene.objects.size(); ++k) {
    const auto& o = a.scene.objects[k];
    if (o.cls != facyl::SceneClass::Cylinder || o.open_top || o.handle)
      continue;
    const facyl::CylinderTruth t = facyl::cylinderTruth(a.scene, o);
    std::vector<float> residual;
    for (std::size_t i = 0; i < a.cloud.size(); ++i)
      if (a.object_id[i] == k + 2 && pcl::isFinite(a.cloud[i])) {
        const Eigen::Vector3f p = a.cloud[i].getVector3fMap() - t.base;
        const float along = p.dot(t.axis);
        if (along > 0.01f && along < t.height - 0.01f) // the lateral surface
          residual.push_back(std::abs((p - along * t.axis).norm() - t.radius));
      }
    if (residual.size() > 100) {
      EXPECT_LT(facyl_test::quantile(residual, 0.5), 0.004f) << "object " << k;
    }
  }
  EXPECT_NE(facyl::groundTruthJson(a).find("\"class\":\""), std::string::npos);
}

TEST(TabletopScene, RejectsInvalidParameters)
{
  facyl::TabletopSceneParameters p;
  p.min_objects = 5;
  p.max_objects = 2;
  EXPECT_FALSE(facyl::validate(p).empty());
  EXPECT_THROW(facyl::generateTabletopScene(p), std::invalid_argument);
  p = facyl::TabletopSceneParameters{};
  p.sensor.dropout = 1.5f;
  EXPECT_THROW(facyl::simulateTabletopScene(p), std::invalid_argument);
  p = facyl::TabletopSceneParameters{};
  p.camera.fx = 0.f;
  EXPECT_FALSE(facyl::validate(p).empty());
}

// ---------------------------------------------------------------- segmentation

TEST(TabletopSegmentation, FindsTheTableAndEveryObject)
{
  for (std::uint64_t seed : {21u, 22u, 23u}) {
    const auto s = scene(seed);
    Cloud::Ptr cloud(new Cloud(s.cloud));
    facyl::TabletopSegmentation<pcl::PointXYZRGBA> seg;
    seg.setInputCloud(cloud);
    std::vector<facyl::TabletopCluster> clusters;
    ASSERT_TRUE(seg.segment(clusters));
    // Its own timing: each step measured, together within the total.
    const facyl::SegmentationTiming& t = seg.getTiming();
    EXPECT_GT(t.planes, 0.0);
    EXPECT_GT(t.points, 0.0);
    EXPECT_GT(t.objects, 0.0);
    EXPECT_GE(t.total + 1e-9, t.planes + t.points + t.objects);
    const auto& c = seg.getTableCoefficients().values;
    ASSERT_EQ(c.size(), 4u);
    EXPECT_LT(facyl_test::degrees(std::acos(
                std::min(1.f, Eigen::Vector3f(c[0], c[1], c[2]).dot(s.table_plane.head<3>())))),
              0.5f);
    EXPECT_NEAR(c[3], s.table_plane[3], 0.005f);
    EXPECT_TRUE(
      seg.getTableFrame().linear().col(2).isApprox(Eigen::Vector3f(c[0], c[1], c[2]), 1e-4f));
    std::map<int, int> clusters_of;
    for (const auto& cl : clusters) {
      const int id = majorityId(s, cl.indices.indices);
      EXPECT_GE(id, 2) << "a cluster of table or background, seed " << seed;
      ++clusters_of[id];
      // The box holds every pixel of the cluster.
      for (const auto i : cl.indices.indices) {
        const int u = i % 640, v = i / 640;
        ASSERT_TRUE(u >= cl.box[0] && u <= cl.box[2] && v >= cl.box[1] && v <= cl.box[3]);
      }
    }
    for (std::size_t k = 0; k < s.scene.objects.size(); ++k) {
      if (s.visible_pixels[k] >= 1000) {
        EXPECT_EQ(clusters_of[static_cast<int>(k + 2)], 1)
          << "object " << k << " (" << s.scene.objects[k].kind << "), seed " << seed;
      }
    }
  }
}

TEST(TabletopSegmentation, SegmentsALargeFrameOnALattice)
{
  // A 1280 x 720 frame (VGA's horizontal field of view) segmented on every pixel and on a
  // lattice of every second pixel and row (lattice_width 640): the same table, the same
  // objects, their pixels at full resolution.
  for (std::uint64_t seed : {21u, 23u}) {
    facyl::TabletopSceneParameters p;
    p.seed = seed;
    p.camera.fx *= 2.f;
    p.camera.fy *= 2.f;
    p.camera.cx = 639.5f;
    p.camera.cy = 359.5f;
    p.camera.width = 1280;
    p.camera.height = 720;
    const facyl::RenderedScene s = facyl::simulateTabletopScene(p);
    Cloud::Ptr cloud(new Cloud(s.cloud));
    facyl::TabletopSegmentation<pcl::PointXYZRGBA> every, lattice;
    facyl::TabletopSegmentationParameters lp;
    lp.lattice_width = 640;
    lattice.setParameters(lp);
    every.setInputCloud(cloud);
    lattice.setInputCloud(cloud);
    std::vector<facyl::TabletopCluster> a, b;
    ASSERT_TRUE(every.segment(a));
    ASSERT_TRUE(lattice.segment(b));
    SCOPED_TRACE("seed " + std::to_string(seed));
    EXPECT_NEAR(lattice.getFocalLength(), every.getFocalLength(), 0.01f * every.getFocalLength());
    const auto& ca = every.getTableCoefficients().values;
    const auto& cb = lattice.getTableCoefficients().values;
    ASSERT_EQ(ca.size(), 4u);
    ASSERT_EQ(cb.size(), 4u);
    EXPECT_GT(Eigen::Vector3f(ca[0], ca[1], ca[2]).dot(Eigen::Vector3f(cb[0], cb[1], cb[2])),
              std::cos(0.01f));
    EXPECT_NEAR(ca[3], cb[3], 0.002f);
    // The table's inliers: full-resolution pixels, nearly the same ones.
    const auto share = [](const pcl::Indices& x, const pcl::Indices& y) {
      pcl::Indices both;
      std::set_intersection(x.begin(), x.end(), y.begin(), y.end(), std::back_inserter(both));
      return static_cast<float>(both.size()) / static_cast<float>(std::max(x.size(), y.size()));
    };
    const auto& ta = every.getTableIndices().indices;
    const auto& tb = lattice.getTableIndices().indices;
    ASSERT_TRUE(std::is_sorted(tb.begin(), tb.end()));
    EXPECT_GT(share(ta, tb), 0.95f);
    // Every object seen over 4,000 pixels is one cluster of each, most of its pixels shared.
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t k = 0; k < s.scene.objects.size(); ++k) {
      if (s.visible_pixels[k] < 4000)
        continue;
      const int id = static_cast<int>(k + 2);
      const auto of = [&](const std::vector<facyl::TabletopCluster>& cs) {
        const facyl::TabletopCluster* found = nullptr;
        int count = 0;
        for (const auto& c : cs)
          if (majorityId(s, c.indices.indices) == id)
            found = &c, ++count;
        EXPECT_EQ(count, 1) << "object " << k;
        return found;
      };
      const auto* x = of(a);
      const auto* y = of(b);
      if (x && y) {
        EXPECT_GT(share(x->indices.indices, y->indices.indices), 0.9f) << "object " << k;
        EXPECT_EQ(x->support, y->support);
      }
    }
  }
}

TEST(TabletopSegmentation, SortsTheWholeCloudAsItsIndices)
{
  // The whole cloud is sorted onto the planes four points at a time (SSE); given indices go
  // one at a time. Both give the same supports and objects, on a frame with holes, with
  // points beyond the tabulated 12 m and a size that is not a multiple of four (a last row
  // cut short is not organized: the same frame as PointXYZ, with one point more, is).
  const auto s = scene(21);
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>);
  pcl::copyPointCloud(s.cloud, *cloud);
  for (std::size_t i = 400 * 640; i < 401 * 640; i += 3) // far points in a row over the table
    if (pcl::isFinite((*cloud)[i]))
      (*cloud)[i].getVector3fMap() *= 13.f / (*cloud)[i].getVector3fMap().norm();
  for (const bool organized : {true, false}) {
    if (!organized)
      cloud->push_back(pcl::PointXYZ(0.01f, 0.02f, 0.9f)); // 307201 points, one row
    facyl::TabletopSegmentation<pcl::PointXYZ> whole, listed;
    whole.setInputCloud(cloud);
    listed.setInputCloud(cloud);
    pcl::IndicesPtr all(new pcl::Indices(cloud->size()));
    std::iota(all->begin(), all->end(), 0);
    listed.setIndices(all);
    if (!organized) {
      whole.setCamera(facyl::PinholeCamera{525.f, 525.f, 319.5f, 239.5f, 640, 480});
      listed.setCamera(whole.getCamera());
    }
    std::vector<facyl::TabletopCluster> a, b;
    ASSERT_TRUE(whole.segment(a));
    ASSERT_TRUE(listed.segment(b));
    ASSERT_EQ(whole.getSupports().size(), listed.getSupports().size());
    ASSERT_FALSE(whole.getSupports().empty());
    for (std::size_t k = 0; k < whole.getSupports().size(); ++k)
      EXPECT_EQ(whole.getSupports()[k].inliers.indices, listed.getSupports()[k].inliers.indices);
    ASSERT_EQ(a.size(), b.size());
    EXPECT_GE(a.size(), 3u);
    for (std::size_t k = 0; k < a.size(); ++k)
      EXPECT_EQ(a[k].indices.indices, b[k].indices.indices);
  }
}

TEST(TabletopSegmentation, PrismTestEqualsPclExtractPolygonalPrismData)
{
  const auto s = scene(24);
  Cloud::Ptr cloud(new Cloud(s.cloud));
  facyl::TabletopSegmentationParameters params;
  params.min_hull_share = 1.f;
  facyl::TabletopSegmentation<pcl::PointXYZRGBA> seg;
  seg.setParameters(params);
  seg.setInputCloud(cloud);
  std::vector<facyl::TabletopCluster> clusters;
  ASSERT_TRUE(seg.segment(clusters));
  // PCL's prism over the same hull and band.
  Cloud::Ptr hull(new Cloud(seg.getTableHull()));
  pcl::ExtractPolygonalPrismData<pcl::PointXYZRGBA> prism;
  prism.setInputCloud(cloud);
  prism.setInputPlanarHull(hull);
  prism.setHeightLimits(params.min_height, params.max_height);
  pcl::PointIndices inside;
  prism.segment(inside);
  std::vector<std::uint8_t> pcl_inside(cloud->size(), 0);
  for (const auto i : inside.indices)
    pcl_inside[i] = 1;
  std::size_t ours = 0, agree = 0;
  for (const auto& c : clusters)
    for (const auto i : c.indices.indices)
      ++ours, agree += pcl_inside[i];
  EXPECT_GT(ours, 10000u);
  // Points within a hair of the band limits may differ (PCL fits its own plane to the hull).
  EXPECT_GE(agree, ours * 995 / 1000);
}

TEST(TabletopSegmentation, UnorganizedCloudsWithACamera)
{
  const auto s = scene(25);
  Cloud::Ptr cloud(new Cloud);
  for (const auto& p : s.cloud)
    if (pcl::isFinite(p))
      cloud->push_back(p);
  ASSERT_EQ(cloud->height, 1u);
  facyl::TabletopSegmentation<pcl::PointXYZRGBA> seg;
  seg.setInputCloud(cloud);
  seg.setCamera(facyl::PinholeCamera{525.f, 525.f, 319.5f, 239.5f, 640, 480});
  std::vector<facyl::TabletopCluster> clusters;
  ASSERT_TRUE(seg.segment(clusters));
  const auto& c = seg.getTableCoefficients().values;
  EXPECT_NEAR(Eigen::Vector3f(c[0], c[1], c[2]).dot(s.table_plane.head<3>()), 1.f, 1e-3f);
  // Every object seen well is one cluster; every cluster is an object.
  std::map<int, std::size_t> clusters_of;
  for (const auto& cl : clusters) {
    EXPECT_GE(cl.box[0], 0);
    ++clusters_of[majorityIdOfUnorganized(s, cl.indices.indices)];
  }
  for (std::size_t k = 0; k < s.scene.objects.size(); ++k)
    if (s.visible_pixels[k] >= 1000) {
      EXPECT_EQ(clusters_of[static_cast<int>(k + 2)], 1u) << "object " << k + 2;
    }
  EXPECT_EQ(clusters_of.count(0) + clusters_of.count(1), 0u);
}

TEST(TabletopSegmentation, ReportsBadInput)
{
  facyl::TabletopSegmentation<pcl::PointXYZ> seg;
  std::vector<facyl::TabletopCluster> clusters(3);
  EXPECT_FALSE(seg.segment(clusters)); // no cloud
  EXPECT_TRUE(clusters.empty());
  pcl::PointCloud<pcl::PointXYZ>::Ptr nan(new pcl::PointCloud<pcl::PointXYZ>(64, 48));
  for (auto& p : *nan)
    p.x = p.y = p.z = std::numeric_limits<float>::quiet_NaN();
  seg.setInputCloud(nan);
  EXPECT_FALSE(seg.segment(clusters));
  // A lone cylinder: no support, which is not an error (see FramesWithoutSupport).
  facyl::CylinderSimulationParameters cp;
  cp.radius = 0.04f;
  cp.height = 0.12f;
  const auto cyl = facyl::simulateCylinder(cp);
  pcl::PointCloud<pcl::PointXYZ>::Ptr xyz(new pcl::PointCloud<pcl::PointXYZ>);
  pcl::copyPointCloud(cyl.cloud, *xyz);
  seg.setInputCloud(xyz);
  EXPECT_TRUE(seg.segment(clusters));
  EXPECT_GT(seg.getTiming().objects, 0.0);
  EXPECT_FALSE(seg.tableFound());
  EXPECT_TRUE(seg.getSupports().empty());
  EXPECT_TRUE(seg.getTableCoefficients().values.empty());
  facyl::TabletopSegmentationParameters bad;
  bad.lattice_width = 100;
  EXPECT_NE(facyl::validate(bad).find("lattice width"), std::string::npos);
  bad.lattice_width = 0;
  bad.min_height = 0.5f;
  bad.max_height = 0.1f;
  EXPECT_FALSE(facyl::validate(bad).empty());
  seg.setParameters(bad);
  EXPECT_FALSE(seg.segment(clusters));
  EXPECT_EQ(seg.getTiming().planes, 0.0); // no step ran
  EXPECT_EQ(seg.getTiming().objects, 0.0);
}

// ---------------------------------------------------------------- recognition

TEST(TabletopCylinderRecognizer, EndToEndOnSimulatedScenes)
{
  std::size_t cylinders = 0, detected = 0, false_positives = 0, distractors = 0, cones = 0,
              cones_called = 0;
  std::vector<float> radius_error, axis_error;
  for (std::uint64_t seed = 31; seed < 47; ++seed) {
    const auto s = scene(seed);
    Cloud::Ptr cloud(new Cloud(s.cloud));
    facyl::TabletopCylinderRecognizer<pcl::PointXYZRGBA> rec;
    rec.setInputCloud(cloud);
    std::vector<facyl::RecognizedObject> objects;
    ASSERT_TRUE(rec.recognize(objects));
    const auto& t = rec.getTiming();
    EXPECT_GT(t.total, 0.0);
    EXPECT_GE(t.total + 1e-9, t.segmentation + t.fitting);
    // The segmentation's own split: each step measured, together within its total.
    const auto& steps = t.segmentation_steps;
    EXPECT_GT(steps.planes, 0.0);
    EXPECT_GT(steps.points, 0.0);
    EXPECT_GT(steps.objects, 0.0);
    EXPECT_GE(steps.total + 1e-9, steps.planes + steps.points + steps.objects);
    EXPECT_GE(t.segmentation + 1e-9, steps.total);
    std::map<int, const facyl::RecognizedObject*> by_id;
    for (const auto& o : objects) {
      const int id = majorityId(s, o.cluster.indices.indices);
      if (id >= 2 && (!by_id.count(id) ||
                      o.cluster.indices.indices.size() > by_id[id]->cluster.indices.indices.size()))
        by_id[id] = &o;
      if (o.is_cylinder) {
        EXPECT_TRUE(o.evidence.fitted);
        EXPECT_FALSE(o.cylinder.inliers.empty());
        for (const auto i : o.cylinder.inliers) // inliers index the input cloud, in the cluster
          ASSERT_TRUE(std::binary_search(o.cluster.indices.indices.begin(),
                                         o.cluster.indices.indices.end(), i));
      }
    }
    for (std::size_t k = 0; k < s.scene.objects.size(); ++k) {
      if (s.visible_pixels[k] < 1000)
        continue;
      const auto& truth = s.scene.objects[k];
      const auto it = by_id.find(static_cast<int>(k + 2));
      const bool called = it != by_id.end() && it->second->is_cylinder;
      if (truth.cls == facyl::SceneClass::Cone) { // developable: geometry alone cannot tell
        ++cones;
        cones_called += called;
        continue;
      }
      if (truth.cls != facyl::SceneClass::Cylinder) {
        ++distractors;
        false_positives += called;
        continue;
      }
      ++cylinders;
      if (!called)
        continue;
      ++detected;
      const facyl::CylinderTruth gt = facyl::cylinderTruth(s.scene, truth);
      radius_error.push_back(std::abs(it->second->cylinder.radius - gt.radius) / gt.radius);
      axis_error.push_back(
        facyl_test::degrees(facyl::axisAngle(it->second->cylinder.axis, gt.axis)));
    }
  }
  std::printf("[ figures ] 16 scenes: %zu/%zu cylinders detected, %zu/%zu boxes, spheres and "
              "bowls and %zu/%zu cones called cylinders, median radius error %.2f%%, median axis "
              "error %.2f deg\n",
              detected, cylinders, false_positives, distractors, cones_called, cones,
              100.f * facyl_test::quantile(radius_error, 0.5),
              facyl_test::quantile(axis_error, 0.5));
  ASSERT_GT(cylinders, 10u);
  EXPECT_GE(detected, cylinders * 9 / 10);
  ASSERT_GT(distractors, 10u);
  EXPECT_LE(false_positives, distractors / 3); // without the curvature check: all of them
  EXPECT_LT(facyl_test::quantile(radius_error, 0.5), 0.02f);
  EXPECT_LT(facyl_test::quantile(axis_error, 0.5), 1.f);
  EXPECT_LT(facyl_test::quantile(axis_error, 0.9), 3.f);
}

TEST(TabletopCylinderRecognizer, ResultsDoNotDependOnTheThreads)
{
  // Clusters are fitted on several threads, each with estimators of its own: one thread, two
  // and more than there are clusters give the same objects, frame after frame.
  const auto run = [](facyl::TabletopCylinderRecognizer<pcl::PointXYZRGBA>& rec,
                      const Cloud::Ptr& cloud) {
    rec.setInputCloud(cloud);
    std::vector<facyl::RecognizedObject> objects;
    EXPECT_TRUE(rec.recognize(objects));
    return objects;
  };
  facyl::TabletopRecognizerParameters p;
  facyl::TabletopCylinderRecognizer<pcl::PointXYZRGBA> one, two, many;
  p.threads = 1;
  one.setParameters(p);
  p.threads = 2;
  two.setParameters(p);
  p.threads = 16;
  many.setParameters(p);
  std::size_t fitted = 0;
  for (std::uint64_t seed = 31; seed < 35; ++seed) {
    const Cloud::Ptr cloud(new Cloud(scene(seed).cloud));
    const auto a = run(one, cloud);
    for (auto* rec : {&two, &many}) {
      const auto b = run(*rec, cloud);
      ASSERT_EQ(a.size(), b.size()) << "seed " << seed;
      for (std::size_t k = 0; k < a.size(); ++k) {
        EXPECT_EQ(a[k].cluster.indices.indices, b[k].cluster.indices.indices);
        EXPECT_EQ(a[k].is_cylinder, b[k].is_cylinder);
        EXPECT_EQ(a[k].evidence.fitted, b[k].evidence.fitted);
        EXPECT_EQ(a[k].evidence.inlier_ratio, b[k].evidence.inlier_ratio);
        EXPECT_EQ(a[k].cylinder.radius, b[k].cylinder.radius);
        EXPECT_EQ(a[k].cylinder.axis, b[k].cylinder.axis);
        EXPECT_EQ(a[k].cylinder.point_on_axis, b[k].cylinder.point_on_axis);
        EXPECT_EQ(a[k].cylinder.inliers, b[k].cylinder.inliers);
      }
    }
    for (const auto& o : a)
      fitted += o.evidence.fitted;
  }
  EXPECT_GT(fitted, 8u); // several clusters a frame: the threads had work to share
}

/** Always says "not a cylinder", or NaN. */
class FixedClassifier : public facyl::ShapeClassifier {
public:
  explicit FixedClassifier(float p)
      : p_(p)
  {
  }
  float cylinderProbability(const facyl::ObjectView& view) override
  {
    ++calls;
    crop_ok = crop_ok && !view.crop.empty() && view.box[0] >= 0 &&
              view.crop.width == view.box[2] - view.box[0] + 1 && view.points.cols() > 0;
    return p_;
  }
  std::string name() const override
  {
    return "fixed";
  }
  int calls{0};
  bool crop_ok{true};

private:
  float p_;
};

TEST(TabletopCylinderRecognizer, ClassifierRejectsBeforeFitting)
{
  const auto s = scene(41);
  Cloud::Ptr cloud(new Cloud(s.cloud));
  facyl::TabletopCylinderRecognizer<pcl::PointXYZRGBA> rec;
  rec.setInputCloud(cloud);
  // reject_below is 0 by default (every cluster is fitted): the paper's rejection when set.
  facyl::TabletopRecognizerParameters params;
  EXPECT_EQ(params.reject_below, 0.f);
  params.reject_below = 0.1f;
  rec.setParameters(params);
  auto no = std::make_shared<FixedClassifier>(0.05f); // below reject_below
  rec.setClassifier(no);
  std::vector<facyl::RecognizedObject> objects;
  ASSERT_TRUE(rec.recognize(objects));
  ASSERT_FALSE(objects.empty());
  EXPECT_EQ(no->calls, static_cast<int>(objects.size()));
  EXPECT_TRUE(no->crop_ok);
  for (const auto& o : objects) {
    EXPECT_FLOAT_EQ(o.evidence.p_cylinder, 0.05f);
    EXPECT_FALSE(o.evidence.fitted);
    EXPECT_FALSE(o.is_cylinder);
  }
  EXPECT_EQ(rec.getTiming().fitting, 0.0);
  // NaN: the classifier cannot tell, every object is fitted.
  rec.setClassifier(std::make_shared<FixedClassifier>(std::numeric_limits<float>::quiet_NaN()));
  ASSERT_TRUE(rec.recognize(objects));
  std::size_t fitted = 0;
  for (const auto& o : objects)
    fitted += o.evidence.fitted;
  EXPECT_GT(fitted, 0u);
}

TEST(TabletopCylinderRecognizer, ReportsBadInput)
{
  facyl::TabletopCylinderRecognizer<pcl::PointXYZ> rec;
  std::vector<facyl::RecognizedObject> objects(2);
  EXPECT_FALSE(rec.recognize(objects));
  EXPECT_TRUE(objects.empty());
  pcl::PointCloud<pcl::PointXYZ>::Ptr empty(new pcl::PointCloud<pcl::PointXYZ>);
  rec.setInputCloud(empty);
  EXPECT_FALSE(rec.recognize(objects));
  facyl::TabletopRecognizerParameters p;
  p.decision.min_score = 1.5f;
  EXPECT_FALSE(facyl::validate(p).empty());
  p = facyl::TabletopRecognizerParameters{};
  for (const int threads : {-1, 65}) {
    p.threads = threads;
    EXPECT_NE(facyl::validate(p).find("threads"), std::string::npos);
  }
  p = facyl::TabletopRecognizerParameters{};
  p.hough.radius_min = 0.3f;
  p.hough.radius_max = 0.1f;
  EXPECT_FALSE(facyl::validate(p).empty());
  const auto s = scene(42);
  pcl::PointCloud<pcl::PointXYZ>::Ptr xyz(new pcl::PointCloud<pcl::PointXYZ>);
  pcl::copyPointCloud(s.cloud, *xyz);
  rec.setInputCloud(xyz);
  rec.setParameters(p);
  EXPECT_FALSE(rec.recognize(objects));
  rec.setParameters(facyl::TabletopRecognizerParameters{});
  EXPECT_TRUE(rec.recognize(objects)); // PointXYZ works too
  EXPECT_FALSE(objects.empty());
}

// ---------------------------------------------------------------- real data

namespace {
using facyl_test::realFile;
} // namespace

TEST(RealData, TheTutorialMug)
{
  const std::string file = realFile("pcl/table_scene_mug_stereo_textured.pcd");
  if (file.empty())
    GTEST_SKIP() << "no " << FACYL_REAL_DATA_DIR << "/pcl/table_scene_mug_stereo_textured.pcd";
  Cloud::Ptr cloud(new Cloud);
  ASSERT_EQ(pcl::io::loadPCDFile(file, *cloud), 0);
  facyl::TabletopCylinderRecognizer<pcl::PointXYZRGBA> rec;
  rec.setInputCloud(cloud);
  std::vector<facyl::RecognizedObject> objects;
  ASSERT_TRUE(rec.recognize(objects));
  std::size_t cylinders = 0;
  float radius = 0.f;
  for (const auto& o : objects)
    if (o.is_cylinder)
      ++cylinders, radius = o.cylinder.radius;
  std::printf("[ figures ] tutorial mug: %zu objects, %zu cylinder(s), radius %.4f m\n",
              objects.size(), cylinders, radius);
  EXPECT_EQ(cylinders, 1u);
  EXPECT_NEAR(radius, 0.039f, 0.003f);
  // One object for the mug (its inside joined to it; the handle may be a fragment of its own),
  // its base on the table and its axis pointing away from it.
  const auto& t = rec.getTableCoefficients().values;
  const Eigen::Vector4f table(t[0], t[1], t[2], t[3]);
  for (const auto& o : objects)
    if (o.is_cylinder) {
      EXPECT_GT(o.cylinder.axis.dot(table.head<3>()), 0.99f);
      EXPECT_NEAR(table.head<3>().dot(o.cylinder.point_on_axis) + table[3], 0.f, 0.01f);
      EXPECT_GT(table.head<3>().dot(o.cylinder.top) + table[3], 0.08f); // the mug is ~10 cm
      EXPECT_GT(o.cluster.indices.indices.size(), 10000u);
    }
}

TEST(TabletopCylinderRecognizer, BaseOnTheSupportAxisAwayFromIt)
{
  // Standing cans: base on the table, axis up. Lying cans: the axis towards the camera's side.
  // Without a support: up is against the image rows.
  std::size_t upright = 0, lying = 0;
  facyl::TabletopCylinderRecognizer<pcl::PointXYZRGBA> rec;
  for (const std::uint64_t seed : {3u, 4u, 5u, 6u}) {
    const facyl::RenderedScene s = scene(seed);
    Cloud::Ptr cloud(new Cloud(s.cloud));
    rec.setInputCloud(cloud);
    std::vector<facyl::RecognizedObject> objects;
    ASSERT_TRUE(rec.recognize(objects));
    const Eigen::Vector4f table = s.table_plane;
    for (const auto& o : objects) {
      if (!o.is_cylinder)
        continue;
      const float along = o.cylinder.axis.dot(table.head<3>());
      if (along > 0.9f) {
        ++upright;
        EXPECT_NEAR(table.head<3>().dot(o.cylinder.point_on_axis) + table[3], 0.f, 0.015f);
        EXPECT_EQ(o.cylinder.point_on_axis, o.cylinder.base);
      }
      else if (std::abs(along) < 0.1f) {
        ++lying;
        EXPECT_GE(o.cylinder.axis.dot(-0.5f * (o.cylinder.base + o.cylinder.top)), 0.f);
      }
      EXPECT_GT(along, -0.1f) << "seed " << seed; // never into the table
    }
  }
  EXPECT_GE(upright, 6u);
  EXPECT_GE(lying, 1u);
  facyl::CylinderModel m;
  m.axis = Eigen::Vector3f(0.f, 1.f, 0.f); // pointing down the image
  m.base = m.point_on_axis = Eigen::Vector3f(0.f, -0.1f, 1.f);
  m.top = Eigen::Vector3f(0.f, 0.f, 1.f);
  facyl::orientCylinder(m, Eigen::Vector3f(0.f, -1.f, 0.f), Eigen::Vector3f::Zero());
  EXPECT_EQ(m.axis, Eigen::Vector3f(0.f, -1.f, 0.f));
  EXPECT_EQ(m.point_on_axis, Eigen::Vector3f(0.f, 0.f, 1.f));
  EXPECT_EQ(m.top, Eigen::Vector3f(0.f, -0.1f, 1.f));
}

TEST(RealData, MosdLabelledScenes)
{
  const std::string dir = realFile("mosd");
  if (dir.empty() || !std::filesystem::exists(dir + "/learn33.pcd"))
    GTEST_SKIP() << "no " << FACYL_REAL_DATA_DIR << "/mosd";
  // Scenes without stacking: every labelled object becomes one cluster (bowls may split in two:
  // inside and outside), and the upright mugs are cylinders of radius ~36-43 mm.
  std::size_t objects_seen = 0, labelled = 0, mugs = 0;
  for (const char* name : {"learn33", "learn38", "learn39", "learn44"}) {
    pcl::PointCloud<pcl::PointXYZRGBL> labelled_cloud;
    ASSERT_EQ(pcl::io::loadPCDFile(dir + "/" + name + ".pcd", labelled_cloud), 0);
    Cloud::Ptr cloud(new Cloud);
    pcl::copyPointCloud(labelled_cloud, *cloud);
    facyl::TabletopCylinderRecognizer<pcl::PointXYZRGBA> rec;
    rec.setInputCloud(cloud);
    std::vector<facyl::RecognizedObject> objects;
    ASSERT_TRUE(rec.recognize(objects)) << name;
    std::map<int, std::size_t> label_points;
    for (const auto& p : labelled_cloud)
      if (p.label >= 20)
        ++label_points[static_cast<int>(p.label / 10)];
    labelled += label_points.size();
    std::map<int, bool> seen;
    for (const auto& o : objects) {
      std::map<int, std::size_t> votes;
      for (const auto i : o.cluster.indices.indices)
        if (labelled_cloud[i].label >= 20)
          ++votes[static_cast<int>(labelled_cloud[i].label / 10)];
      if (votes.empty())
        continue;
      const auto best = std::max_element(votes.begin(), votes.end(),
                                         [](auto& a, auto& b) { return a.second < b.second; });
      seen[best->first] = true;
      const bool small =
        o.evidence.fitted && o.cylinder.radius < 0.05f && o.cylinder.radius > 0.03f;
      mugs += o.is_cylinder && small;
    }
    objects_seen += seen.size();
  }
  std::printf("[ figures ] mOSD learn33/38/39/44: %zu of %zu labelled objects clustered, %zu "
              "mug-sized cylinders\n",
              objects_seen, labelled, mugs);
  EXPECT_EQ(objects_seen, labelled);
  EXPECT_GE(mugs, 7u); // 9 mugs and canisters of r 36-43 mm stand in these scenes
}

TEST(RealData, LidDominatedAndLyingTins)
{
  const std::string dir = realFile("mosd");
  if (dir.empty() || !std::filesystem::exists(dir + "/learn35.pcd"))
    GTEST_SKIP() << "no " << FACYL_REAL_DATA_DIR << "/mosd";
  // Cookie tins (radius ~98 mm) whose lid or flat face fills most of the view: the fit with the
  // "mostly vertical" prior alone follows the domed lid; the upright/lying retry finds the tin.
  const std::vector<std::pair<const char*, int>> tins{
    {"learn35", 3}, {"learn38", 4}, {"learn39", 2}, {"learn44", 2}};
  for (bool retry : {false, true}) {
    std::size_t right = 0;
    std::string radii;
    for (const auto& [name, id] : tins) {
      pcl::PointCloud<pcl::PointXYZRGBL> labelled;
      ASSERT_EQ(pcl::io::loadPCDFile(dir + "/" + name + ".pcd", labelled), 0);
      Cloud::Ptr cloud(new Cloud);
      pcl::copyPointCloud(labelled, *cloud);
      facyl::TabletopRecognizerParameters params;
      params.retry_upright_lying = retry;
      facyl::TabletopCylinderRecognizer<pcl::PointXYZRGBA> rec;
      rec.setParameters(params);
      rec.setInputCloud(cloud);
      std::vector<facyl::RecognizedObject> objects;
      ASSERT_TRUE(rec.recognize(objects));
      // The tin is one object (learn38's lid, set into the rim, is cut off by the crease
      // there: joined again as the tin's end, cylinder_parts.h).
      const auto isTin = [&](pcl::index_t i) {
        return static_cast<int>(labelled[i].label / 10) == id && labelled[i].label >= 20;
      };
      std::size_t tin_points = 0, most = 0;
      for (std::size_t i = 0; i < labelled.size(); ++i)
        tin_points += isTin(static_cast<pcl::index_t>(i));
      const facyl::RecognizedObject* tin = nullptr;
      for (const auto& o : objects) {
        std::size_t on_tin = 0;
        for (const auto i : o.cluster.indices.indices)
          on_tin += isTin(i);
        if (2 * on_tin > o.cluster.indices.indices.size() && on_tin > most)
          tin = &o, most = on_tin;
      }
      ASSERT_NE(tin, nullptr) << name;
      const float r = tin->evidence.fitted ? tin->cylinder.radius : 0.f;
      radii += " " + std::to_string(static_cast<int>(std::lround(r * 1000.f)));
      right += tin->is_cylinder && r > 0.09f && r < 0.11f;
      if (retry) {
        EXPECT_GT(static_cast<float>(most), 0.9f * static_cast<float>(tin_points)) << name;
      }
    }
    std::printf("[ figures ] cookie tins, retry %s: %zu of %zu found with radius 90-110 mm; "
                "radii (mm):%s\n",
                retry ? "on" : "off", right, tins.size(), radii.c_str());
    if (retry) {
      EXPECT_EQ(right, tins.size());
    }
  }
}

TEST(RealData, FloorScenesOfPcl)
{
  const std::string bottles = realFile("pcl/milk_cartoon_all_small_clorox.pcd");
  const std::string negative = realFile("pcl/grabber_frame_laptop_box.pcd");
  if (bottles.empty() || negative.empty())
    GTEST_SKIP() << "no " << FACYL_REAL_DATA_DIR << "/pcl scenes";
  // (radius, centroid) of every object called a cylinder
  const auto cylinders = [](const std::string& file) {
    Cloud::Ptr cloud(new Cloud);
    EXPECT_EQ(pcl::io::loadPCDFile(file, *cloud), 0);
    facyl::TabletopCylinderRecognizer<pcl::PointXYZRGBA> rec;
    rec.setInputCloud(cloud);
    std::vector<facyl::RecognizedObject> objects;
    EXPECT_TRUE(rec.recognize(objects));
    std::vector<std::pair<float, Eigen::Vector3f>> found;
    for (const auto& o : objects)
      if (o.is_cylinder)
        found.emplace_back(o.cylinder.radius, o.cluster.centroid);
    return found;
  };
  // The detergent bottle (r ~8 cm, left) and the Clorox bottle (~6 cm, right of the carton)
  // stand on a carpet 0.6-0.7 m away; a round bin at the back (r ~8.6 cm, cut by the image
  // border, 1.8 m away). The bottles' sections are not circles (an oval, a handle): the labels
  // of the rgbd frames call such bottles "other", neither cylinders nor not, and the evidence
  // model, whose normals do not follow a circle there, does not call them cylinders. What holds
  // either way: a cylinder found there is one of them, never a large shallow arc; a laptop and
  // a box are no cylinders (at most a small cluster may pass). The Clorox bottle's blue cap
  // (r ~2.5 cm) on its white shoulder is cut off by the colour edge there: a cylinder too.
  const auto found = cylinders(bottles);
  const auto count = [](const auto& f, float lo, float hi, float x_lo, float x_hi) {
    return std::count_if(f.begin(), f.end(), [&](const auto& c) {
      return c.first >= lo && c.first <= hi && c.second.x() >= x_lo && c.second.x() <= x_hi &&
             c.second.z() < 1.f;
    });
  };
  EXPECT_EQ(static_cast<std::size_t>(count(found, 0.055f, 0.07f, 0.05f, 0.3f) +    // Clorox
                                     count(found, 0.02f, 0.03f, 0.05f, 0.3f) +     // its cap
                                     count(found, 0.075f, 0.09f, -0.35f, -0.1f)) + // detergent
              std::count_if(found.begin(), found.end(),
                            [](const auto& c) { return c.second.z() >= 1.f; }), // the bin
            found.size());
  EXPECT_EQ(count(found, 0.1f, 1.f, -10.f, 10.f), 0);
  for (const auto& [r, c] : found)
    std::printf("[ figures ] floor scene cylinder r %.3f m at (%.2f, %.2f, %.2f)\n", r, c.x(),
                c.y(), c.z());
  const auto none = cylinders(negative);
  EXPECT_LE(none.size(), 1u);
  EXPECT_EQ(count(none, 0.05f, 1.f, -10.f, 10.f), 0);
}
