/*
 * facyl: any table, any depth camera. Support bands measured from the data (noise and bias
 * that grow with range), plane regions that hold on noisy and bent tables, any camera roll
 * without an up direction, frames without a support, classifier views of unorganized clouds,
 * and (when ../shared/data/real is present) real frames of sensors and rooms the pipeline was
 * not tuned on.
 */
#include "test_helpers.h"

#include <facyl/tools/csv_reader.h>

#include <facyl/recognition/cylinder_classifier.h>
#include <facyl/recognition/tabletop_cylinder_recognizer.h>
#include <facyl/segmentation/plane_search.h>
#include <facyl/segmentation/support_planes.h>
#include <facyl/segmentation/tabletop_segmentation.h>
#include <facyl/simulation/frame_roll.h>
#include <facyl/simulation/random.h>
#include <facyl/simulation/tabletop_scene.h>

#include <pcl/common/point_tests.h>
#include <pcl/features/integral_image_normal.h>
#include <pcl/io/pcd_io.h>
#include <pcl/segmentation/organized_multi_plane_segmentation.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <limits>
#include <map>
#include <random>
#include <sstream>

using Cloud = pcl::PointCloud<pcl::PointXYZRGBA>;

namespace {

/** Standard normal samples of a seeded generator. */
struct Gauss {
  facyl::Random rng;
  explicit Gauss(std::uint64_t seed)
      : rng(seed)
  {
  }
  float operator()()
  {
    return rng.normal();
  }
};

facyl::RenderedScene
cluttered(std::uint64_t seed, const std::string& sensor = "kinect")
{
  facyl::TabletopSceneParameters p = facyl::clutteredSceneParameters();
  facyl::parseSensorPreset(sensor, p.sensor, p.camera);
  p.seed = seed;
  return facyl::simulateTabletopScene(p);
}

std::vector<facyl::RecognizedObject>
recognize(const Cloud::ConstPtr& cloud, facyl::TabletopCylinderRecognizer<pcl::PointXYZRGBA>& rec)
{
  rec.setInputCloud(cloud);
  std::vector<facyl::RecognizedObject> objects;
  EXPECT_TRUE(rec.recognize(objects));
  return objects;
}

/** The table plane (a, b, c, d) in the frame of a camera rolled by \a quarter_turns. */
Eigen::Vector4f
rolledPlane(Eigen::Vector4f plane, int quarter_turns)
{
  for (int t = 0; t < quarter_turns; ++t)
    plane.head<2>() = Eigen::Vector2f(-plane[1], plane[0]);
  return plane;
}

} // namespace

// ---------------------------------------------------------------- bands

TEST(DepthBand, RecoversNoiseThatGrowsWithRange)
{
  // A structured-light sensor's axial noise: sigma = 2.85e-3 range^2 (Kinect v1), over 0.5-3 m.
  Gauss gauss(3);
  facyl::Random pick(4);
  std::vector<float> ranges, residuals;
  for (int i = 0; i < 20000; ++i) {
    const float r = 0.5f + 2.5f * pick.uniform(0.f, 1.f);
    ranges.push_back(r);
    residuals.push_back(2.85e-3f * r * r * gauss());
  }
  const facyl::DepthBand band = facyl::estimateDepthBand(ranges, residuals, 3.f, 1e-4f);
  ASSERT_GE(band.ranges.size(), 4u);
  for (std::size_t b = 1; b < band.sigmas.size(); ++b)
    EXPECT_GE(band.sigmas[b], band.sigmas[b - 1]); // non-decreasing with range
  for (const float r : {0.8f, 1.5f, 2.5f}) {
    const float truth = 2.85e-3f * r * r;
    EXPECT_NEAR(band.sigma(r), truth, 0.15f * truth) << "range " << r;
    EXPECT_FLOAT_EQ(band.halfWidth(r), 3.f * band.sigma(r));
  }
  // Beyond the farthest bin the band keeps growing with range^2; nearer, it stays.
  EXPECT_NEAR(band.sigma(6.f) / band.sigma(band.ranges.back()),
              std::pow(6.f / band.ranges.back(), 2.f), 1e-3f);
  EXPECT_FLOAT_EQ(band.sigma(0.1f), band.sigmas.front());
  // A fixed band, and the floor of a noise-free plane.
  EXPECT_FLOAT_EQ(facyl::fixedBand(0.015f).halfWidth(2.f), 0.015f);
  const facyl::DepthBand flat =
    facyl::estimateDepthBand(ranges, std::vector<float>(ranges.size(), 0.f), 3.f, 1e-4f);
  EXPECT_FLOAT_EQ(flat.halfWidth(1.f), 3e-4f);
  EXPECT_FLOAT_EQ(facyl::estimateDepthBand({}, {}, 3.f, 1e-4f).halfWidth(1.f), 3e-4f);
}

TEST(DepthBand, HalfWidthFloorIsBelowTheBandEverywhere)
{
  // Measured bands (sigmas growing, and a hand-made one that shrinks between samples and whose
  // interpolation rounds), a fixed band and an empty one: the floor is never above the
  // half-width, at ranges before, between, on and beyond the samples.
  Gauss gauss(5);
  std::vector<float> ranges, residuals;
  for (int i = 0; i < 8000; ++i) {
    const float r = 0.4f + 3.f * static_cast<float>(i) / 8000.f;
    ranges.push_back(r);
    residuals.push_back(1.5e-3f * r * r * gauss());
  }
  facyl::DepthBand measured = facyl::estimateDepthBand(ranges, residuals, 3.f, 1e-4f);
  facyl::DepthBand shrinking;
  shrinking.factor = 2.5f;
  shrinking.ranges = {0.5f, 0.7f, 1.3f, 2.9f};
  shrinking.sigmas = {3e-3f, 1.1e-3f, 1.0000001e-3f, 4e-3f};
  for (const facyl::DepthBand& band : {measured, shrinking}) {
    const float floor = facyl::halfWidthFloor(band);
    EXPECT_GT(floor,
              0.9f * band.factor * *std::min_element(band.sigmas.begin(), band.sigmas.end()));
    for (int k = 0; k <= 20000; ++k) {
      const float r = 0.01f + 6.f * static_cast<float>(k) / 20000.f;
      ASSERT_LE(floor, band.halfWidth(r)) << "range " << r;
    }
    for (const float r : band.ranges)
      ASSERT_LE(floor, band.halfWidth(r));
  }
  EXPECT_EQ(facyl::halfWidthFloor(facyl::fixedBand(0.015f)), 0.015f);
  EXPECT_EQ(facyl::halfWidthFloor(facyl::DepthBand{}), 0.f);
}

TEST(PlaneRegion, GrowsANoisyBentTableFromOnePieceAndStaysOffTheWall)
{
  // Cells of a 1.6 x 1 m table seen from the origin 0.6-2 m away, bent by 6 mm (a sensor's
  // radial bias), with 2 mm-at-1-m noise growing with range^2; a wall across its far edge.
  Gauss gauss(11);
  std::vector<Eigen::Vector3f> cells, normals;
  std::vector<std::uint8_t> is_table;
  const Eigen::Vector3f up(0.f, -0.8f, -0.6f); // towards the sensor
  const Eigen::Vector3f along = Eigen::Vector3f(0.f, 0.6f, -0.8f).cross(up).normalized();
  const Eigen::Vector3f depth(0.f, 0.6f, -0.8f);
  const Eigen::Vector3f centre(0.f, 0.5f, 1.2f);
  for (int i = -40; i <= 40; ++i)
    for (int j = -25; j <= 25; ++j) {
      const float x = 0.02f * static_cast<float>(i), y = 0.02f * static_cast<float>(j);
      const Eigen::Vector3f flat = centre + x * along - y * depth;
      const float bend = 0.006f * (x * x + y * y) / 0.89f;
      const float r = flat.norm();
      cells.push_back(flat + (bend + 2e-3f * r * r * gauss()) * up);
      normals.push_back((up + 0.02f * Eigen::Vector3f(gauss(), gauss(), gauss())).normalized());
      is_table.push_back(1);
    }
  const Eigen::Vector3f wall_base = centre - 0.5f * (-depth);
  for (int i = -40; i <= 40; ++i)
    for (int k = 1; k <= 20; ++k) {
      cells.push_back(wall_base + 0.02f * static_cast<float>(i) * along + 0.02f * k * up +
                      0.5f * depth + 1e-3f * gauss() * depth);
      normals.push_back(-depth);
      is_table.push_back(0);
    }
  const auto n = static_cast<Eigen::Index>(cells.size());
  Eigen::Matrix3Xf c(3, n), q(3, n);
  for (Eigen::Index k = 0; k < n; ++k) {
    c.col(k) = cells[static_cast<std::size_t>(k)];
    q.col(k) = normals[static_cast<std::size_t>(k)];
  }
  // The seed: a 20 x 20 cm piece near the table's centre.
  std::vector<std::uint8_t> seed(cells.size(), 0);
  for (std::size_t k = 0; k < cells.size(); ++k)
    seed[k] = is_table[k] && (cells[k] - centre).norm() < 0.1f;
  facyl::PlaneRegion region;
  ASSERT_TRUE(facyl::refinePlaneRegion(c, q, c, seed, Eigen::Vector3f::Zero(), {}, region));
  std::size_t table_members = 0, wall_members = 0, table = 0;
  for (std::size_t k = 0; k < cells.size(); ++k) {
    table += is_table[k];
    table_members += is_table[k] && region.member[k];
    wall_members += !is_table[k] && region.member[k];
  }
  EXPECT_GE(table_members, 95 * table / 100); // the whole (bent, noisy) table
  EXPECT_EQ(wall_members, 0u);
  EXPECT_GT(region.plane.head<3>().dot(up), std::cos(0.02f));
  // The band covers noise and bend: wider than the noise alone at 1 m, narrower than a table
  // of 3 cm.
  EXPECT_GT(region.band.halfWidth(1.f), 3.f * 2e-3f);
  EXPECT_LT(region.band.halfWidth(1.f), 0.03f);
  // Cells prepared once grow the same region, call after call; with the table's cells
  // excluded (a plane found before), the seed does not grow.
  const facyl::PlaneRegionCells prepared(c, q, c, Eigen::Vector3f::Zero());
  for (int call = 0; call < 2; ++call) {
    facyl::PlaneRegion again;
    ASSERT_TRUE(facyl::refinePlaneRegion(prepared, seed, {}, again));
    EXPECT_EQ(again.member, region.member);
    EXPECT_EQ(again.plane, region.plane);
  }
  facyl::PlaneRegion none;
  EXPECT_FALSE(facyl::refinePlaneRegion(prepared, seed, {}, none, &is_table));
  // Matrices of different sizes are no cells.
  const Eigen::Matrix3Xf fewer = q.leftCols(n - 1);
  EXPECT_FALSE(facyl::refinePlaneRegion(
    facyl::PlaneRegionCells(c, fewer, c, Eigen::Vector3f::Zero()), seed, {}, none));
  // A seed whose normals spread like a dome's is no plane.
  facyl::PlaneRegionSettings strict;
  strict.max_angle = 0.01f;
  EXPECT_FALSE(facyl::refinePlaneRegion(c, q, c, seed, Eigen::Vector3f::Zero(), strict, region));
}

TEST(PlaneSorter, SortsOntoAndAboveItsPlanes)
{
  // A table (z up, through the origin) with a 1 cm band, seen from 1 m above; a wall.
  const Eigen::Vector3f viewpoint(0.f, 0.f, 1.f);
  const facyl::PlaneSorter sorter(
    {Eigen::Vector4f(0.f, 0.f, 1.f, 0.f), Eigen::Vector4f(1.f, 0.f, 0.f, 0.5f)},
    {facyl::fixedBand(0.01f), facyl::fixedBand(0.01f)}, viewpoint, 0.005f, 0.3f);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  // x, y, z, pad: on the table, above it, below it, on both, not finite, too high.
  const std::vector<float> xyz = {0.1f, 0.f, 0.005f, 1.f, 0.1f,  0.f, 0.1f, 1.f,
                                  0.1f, 0.f, -0.1f,  1.f, -0.5f, 0.f, 0.f,  1.f,
                                  nan,  0.f, 0.f,    1.f, 0.1f,  0.f, 0.5f, 1.f};
  for (const bool vectorized : {true, false}) {
    std::vector<pcl::index_t> lists(2 * 6);
    pcl::index_t* ends[2] = {lists.data(), lists.data() + 6};
    std::vector<facyl::PointOverPlanes> above;
    sorter.sort(xyz.data(), 4, 6, nullptr, ends, above, vectorized);
    EXPECT_EQ(std::vector<pcl::index_t>(lists.data(), ends[0]), (std::vector<pcl::index_t>{0, 3}));
    EXPECT_EQ(std::vector<pcl::index_t>(lists.data() + 6, ends[1]), (std::vector<pcl::index_t>{3}));
    // Point 1 is above the table and beside the wall (h = 0.6 > top); point 0 is above the
    // wall (h = 0.6 too): none above it.
    ASSERT_EQ(above.size(), 1u);
    EXPECT_EQ(above[0].index, 1);
    EXPECT_EQ(above[0].on, 0);
    EXPECT_EQ(above[0].above, 1);
  }
  EXPECT_THROW(facyl::PlaneSorter({Eigen::Vector4f::UnitZ()}, {}, viewpoint, 0.f, 1.f),
               std::invalid_argument);
}

TEST(PlaneSorter, FourAtATimeEqualsOneAtATime)
{
  // Random points around 8 random planes with measured bands, some not finite, some beyond
  // the tabulated 12 m, many at the bands' edges: the SSE sort gives the same lists.
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-1.f, 1.f);
  std::vector<Eigen::Vector4f> planes;
  std::vector<facyl::DepthBand> bands;
  for (int s = 0; s < 8; ++s) {
    const Eigen::Vector3f n = Eigen::Vector3f(u(rng), u(rng), u(rng)).normalized();
    planes.emplace_back(n.x(), n.y(), n.z(), 0.5f * u(rng));
    facyl::DepthBand b;
    b.ranges = {0.8f, 1.5f, 3.f};
    b.sigmas = {0.002f, 0.004f, 0.01f};
    bands.push_back(s % 3 == 0 ? facyl::fixedBand(0.01f) : b);
  }
  const Eigen::Vector3f viewpoint(0.1f, -0.2f, 0.f);
  const facyl::PlaneSorter sorter(planes, bands, viewpoint, 0.005f, 0.3f);
  const std::size_t count = 20003;
  std::vector<float> xyz(5 * count); // a stride of 5 floats
  for (std::size_t k = 0; k < count; ++k) {
    Eigen::Vector3f p(2.f * u(rng), 2.f * u(rng), 1.f + 1.5f * u(rng));
    if (k % 3 == 0) { // onto the edge of a band
      const std::size_t s = k % 8;
      const float range = (p - viewpoint).norm();
      const float h = planes[s].head<3>().dot(p) + planes[s][3];
      p += (bands[s].halfWidth(range) * (u(rng) > 0.f ? 1.f : -1.f) - h) * planes[s].head<3>();
    }
    if (k % 97 == 0)
      p *= 13.f / p.norm(); // beyond 12 m
    if (k % 89 == 0)
      p.y() = std::numeric_limits<float>::quiet_NaN();
    if (k % 101 == 0)
      p.z() = std::numeric_limits<float>::infinity();
    Eigen::Map<Eigen::Vector3f>(xyz.data() + 5 * k) = p;
  }
  std::vector<pcl::index_t> a(8 * count), b(8 * count);
  pcl::index_t *ea[8], *eb[8];
  for (std::size_t s = 0; s < 8; ++s)
    ea[s] = a.data() + s * count, eb[s] = b.data() + s * count;
  std::vector<facyl::PointOverPlanes> above_a, above_b;
  sorter.sort(xyz.data(), 5, count, nullptr, ea, above_a, true);
  sorter.sort(xyz.data(), 5, count, nullptr, eb, above_b, false);
  std::size_t on = 0;
  for (std::size_t s = 0; s < 8; ++s) {
    EXPECT_EQ(std::vector<pcl::index_t>(a.data() + s * count, ea[s]),
              std::vector<pcl::index_t>(b.data() + s * count, eb[s]))
      << "plane " << s;
    on += static_cast<std::size_t>(ea[s] - (a.data() + s * count));
  }
  EXPECT_GT(on, count / 8);
  ASSERT_EQ(above_a.size(), above_b.size());
  EXPECT_GT(above_a.size(), count / 20);
  for (std::size_t k = 0; k < above_a.size(); ++k) {
    EXPECT_EQ(above_a[k].index, above_b[k].index);
    EXPECT_EQ(above_a[k].on, above_b[k].on);
    EXPECT_EQ(above_a[k].above, above_b[k].above);
  }
}

// ---------------------------------------------------------------- supports

TEST(PlaneGrid, AverageGradientNormalsArePcls)
{
  // Bent surfaces with depth jumps, holes, a row and a column without depth, at the plane
  // grids' sizes and settings and at sizes PCL's borders barely fit: the same floats as
  // pcl::IntegralImageNormalEstimation (AVERAGE_3D_GRADIENT), NaN where it gives NaN.
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  struct Case {
    int w, h;
    float depth_factor, smoothing;
  };
  const Case cases[] = {{160, 120, 0.02f, 4.f},  {80, 60, 0.04f, 4.f},  {40, 30, 0.08f, 4.f},
                        {160, 120, 0.02f, 10.f}, {53, 41, 0.03f, 6.5f}, {9, 9, 0.02f, 4.f},
                        {12, 200, 0.02f, 4.f},   {8, 8, 0.02f, 4.f}};
  std::size_t compared = 0, finite = 0;
  for (const Case& c : cases) {
    pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>);
    cloud->width = static_cast<std::uint32_t>(c.w);
    cloud->height = static_cast<std::uint32_t>(c.h);
    cloud->is_dense = false;
    if (c.w == 53)
      cloud->sensor_origin_ = Eigen::Vector4f(0.1f, -0.2f, 0.3f, 0.f);
    for (int v = 0; v < c.h; ++v)
      for (int u_ = 0; u_ < c.w; ++u_) {
        const float x = (static_cast<float>(u_) - 0.5f * c.w) / 120.f,
                    y = (static_cast<float>(v) - 0.5f * c.h) / 120.f;
        float z = 1.f + 0.3f * std::sin(3.f * x) * std::cos(2.f * y) + 0.002f * u(rng);
        if (u_ > c.w / 2 && v > c.h / 3)
          z -= 0.25f; // an object in front: a depth jump
        const bool hole = u(rng) < 0.005f || v == c.h / 4 || u_ == c.w / 5;
        cloud->push_back(hole ? pcl::PointXYZ(nan, nan, nan) : pcl::PointXYZ(x * z, y * z, z));
      }
    cloud->width = static_cast<std::uint32_t>(c.w);
    cloud->height = static_cast<std::uint32_t>(c.h);
    pcl::PointCloud<pcl::Normal> ours, pcls;
    facyl::averageGradientNormals(*cloud, c.depth_factor, c.smoothing, ours);
    pcl::IntegralImageNormalEstimation<pcl::PointXYZ, pcl::Normal> ne;
    ne.setNormalEstimationMethod(ne.AVERAGE_3D_GRADIENT);
    ne.setMaxDepthChangeFactor(c.depth_factor);
    ne.setNormalSmoothingSize(c.smoothing);
    ne.setInputCloud(cloud);
    ne.compute(pcls);
    SCOPED_TRACE(std::to_string(c.w) + " x " + std::to_string(c.h));
    ASSERT_EQ(ours.size(), pcls.size());
    EXPECT_EQ(ours.width, pcls.width);
    EXPECT_EQ(ours.height, pcls.height);
    const auto same = [](float a, float b) { return std::isnan(a) ? std::isnan(b) : a == b; };
    for (std::size_t i = 0; i < ours.size(); ++i) {
      const pcl::Normal &a = ours[i], &b = pcls[i];
      ASSERT_TRUE(same(a.normal_x, b.normal_x) && same(a.normal_y, b.normal_y) &&
                  same(a.normal_z, b.normal_z) && same(a.curvature, b.curvature))
        << "cell " << i << ": (" << a.normal_x << ", " << a.normal_y << ", " << a.normal_z
        << ") against PCL's (" << b.normal_x << ", " << b.normal_y << ", " << b.normal_z << ")";
      ++compared;
      finite += std::isfinite(a.normal_x);
    }
  }
  EXPECT_GT(finite, compared / 3); // most cells of the larger grids have a normal
  pcl::PointCloud<pcl::PointXYZ> grid(16, 16, pcl::PointXYZ(0.f, 0.f, 1.f));
  pcl::PointCloud<pcl::Normal> out;
  EXPECT_THROW(facyl::averageGradientNormals(grid, 0.02f, 0.f, out), std::invalid_argument);
  EXPECT_THROW(facyl::averageGradientNormals(grid, 0.02f, nan, out), std::invalid_argument);
  EXPECT_THROW(facyl::averageGradientNormals(grid, -1.f, 4.f, out), std::invalid_argument);
  facyl::averageGradientNormals(pcl::PointCloud<pcl::PointXYZ>(), 0.02f, 4.f, out);
  EXPECT_TRUE(out.empty());
}

TEST(PlaneGrid, PlanarRegionsArePcls)
{
  // Planes at several depths and tilts, a bent surface, noise, holes: the regions of
  // pcl::OrganizedMultiPlaneSegmentation, the same cells in the same order, at the thresholds
  // of the plane search and its two relaxations.
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  std::normal_distribution<float> noise(0.f, 1.f);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::size_t regions = 0;
  for (const int w : {160, 80, 41}) {
    const int h = w * 3 / 4;
    pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>);
    for (int v = 0; v < h; ++v)
      for (int c = 0; c < w; ++c) {
        const float x = (static_cast<float>(c) - 0.5f * w) / (0.75f * w),
                    y = (static_cast<float>(v) - 0.5f * h) / (0.75f * w);
        float z = 1.2f + 0.4f * y; // a table seen from above
        if (x > 0.2f && y < 0.1f)  // a box in front of it
          z = 0.9f + 0.1f * x;
        else if (x < -0.3f && y < -0.2f) // a bent wall
          z = 1.6f + 0.3f * x * x;
        z += 0.002f * z * z * noise(rng);
        const bool hole = u(rng) < 0.01f || (c == w / 3 && v > h / 2);
        cloud->push_back(hole ? pcl::PointXYZ(nan, nan, nan) : pcl::PointXYZ(x * z, y * z, z));
      }
    cloud->width = static_cast<std::uint32_t>(w);
    cloud->height = static_cast<std::uint32_t>(h);
    cloud->is_dense = false;
    pcl::PointCloud<pcl::Normal>::Ptr normals(new pcl::PointCloud<pcl::Normal>);
    facyl::averageGradientNormals(*cloud, 0.02f * 160.f / static_cast<float>(w), 4.f, *normals);
    for (const float relax : {1.f, 2.f, 4.f}) {
      const unsigned min_inliers = w == 41 ? 3 : 10;
      const float angle = std::min(0.5f, relax * 0.1f), distance = relax * 0.02f;
      const double curvature = relax * relax * 0.001;
      const auto ours =
        facyl::planarRegions(*cloud, *normals, min_inliers, angle, distance, curvature);
      pcl::OrganizedMultiPlaneSegmentation<pcl::PointXYZ, pcl::Normal, pcl::Label> mps;
      mps.setMinInliers(min_inliers);
      mps.setAngularThreshold(angle);
      mps.setDistanceThreshold(distance);
      mps.setMaximumCurvature(curvature);
      mps.setInputNormals(normals);
      mps.setInputCloud(cloud);
      std::vector<pcl::ModelCoefficients> coefficients;
      std::vector<pcl::PointIndices> pcls;
      mps.segment(coefficients, pcls);
      SCOPED_TRACE(std::to_string(w) + " cells wide, relaxed " + std::to_string(relax));
      ASSERT_EQ(ours.size(), pcls.size());
      for (std::size_t r = 0; r < ours.size(); ++r)
        EXPECT_EQ(ours[r].indices, pcls[r].indices) << "region " << r;
      regions += ours.size();
    }
  }
  EXPECT_GE(regions, 9u); // the table and the box at least, at every size and threshold
  pcl::PointCloud<pcl::PointXYZ> row;
  row.push_back(pcl::PointXYZ(0.f, 0.f, 1.f));
  EXPECT_TRUE(
    facyl::planarRegions(row, pcl::PointCloud<pcl::Normal>(), 3, 0.1, 0.02, 0.001).empty());
}

TEST(AnyTable, NoisyFarTableIsOneSupport)
{
  // Active stereo at 1.6-2.2 m with 1.5 times the stereo preset's noise (sigma 18 mm at 2 m): a
  // fixed 15 mm band would cut the table into pieces; the measured band keeps it whole and finds
  // the objects on it.
  for (const std::uint64_t seed : {1000u, 1003u, 1004u}) {
    facyl::TabletopSceneParameters p = facyl::clutteredSceneParameters();
    facyl::parseSensorPreset("stereo", p.sensor, p.camera);
    p.sensor.noise_coefficient *= 1.5f;
    p.camera_distance = {1.6f, 2.2f};
    p.seed = seed;
    const facyl::RenderedScene s = facyl::simulateTabletopScene(p);
    Cloud::Ptr cloud(new Cloud(s.cloud));
    facyl::TabletopSegmentation<pcl::PointXYZRGBA> seg;
    seg.setInputCloud(cloud);
    std::vector<facyl::TabletopCluster> clusters;
    ASSERT_TRUE(seg.segment(clusters));
    ASSERT_TRUE(seg.tableFound()) << seed;
    const auto& c = seg.getTableCoefficients().values;
    EXPECT_GT(Eigen::Vector3f(c[0], c[1], c[2]).dot(s.table_plane.head<3>()), std::cos(0.03f))
      << seed;
    EXPECT_NEAR(c[3], s.table_plane[3], 0.02f) << seed;
    const auto& table = seg.getSupports()[seg.getTableIndex()];
    const float range = table.frame.translation().norm();
    EXPECT_GT(table.band.halfWidth(range), 0.015f) << seed; // wider than the old fixed band
    std::size_t visible = 0;
    for (std::size_t k = 0; k < s.scene.objects.size(); ++k)
      visible += s.visible_pixels[k] >= 1000;
    EXPECT_GE(clusters.size() + 1, visible) << seed; // (touching objects may merge)
  }
}

TEST(AnyTable, DarkTableFullOfHolesIsFound)
{
  // A dark table seen by a sensor that loses weak returns (and speckled holes besides): on the
  // fine plane grid few cells have a whole neighbourhood for a normal, and the floor (the
  // reference material) would be taken for the support; the coarser grid bridges the holes.
  // Every table with depth on a quarter of its pixels is found; no other plane is ever called
  // the table (one with almost no depth is not found at all).
  std::size_t visible = 0, found_visible = 0;
  for (std::uint64_t seed = 2000; seed < 2008; ++seed) {
    facyl::TabletopSceneParameters p = facyl::clutteredSceneParameters();
    facyl::parseSensorPreset("kinect", p.sensor, p.camera);
    p.table_materials.dark = 1.f;
    p.sensor.weak_return_dropout = 0.9f;
    p.sensor.hole_rate = 0.02f;
    p.sensor.hole_radius = 2.5f;
    p.seed = seed;
    const facyl::RenderedScene s = facyl::simulateTabletopScene(p);
    std::size_t table_px = 0, with_depth = 0;
    for (std::size_t i = 0; i < s.pixel_class.size(); ++i)
      if (s.pixel_class[i] == facyl::SceneClass::Table) {
        ++table_px;
        with_depth += pcl::isFinite(s.cloud[i]);
      }
    Cloud::Ptr cloud(new Cloud(s.cloud));
    facyl::TabletopSegmentation<pcl::PointXYZRGBA> seg;
    seg.setInputCloud(cloud);
    std::vector<facyl::TabletopCluster> clusters;
    ASSERT_TRUE(seg.segment(clusters)) << seed;
    const bool seen = 4 * with_depth >= table_px;
    visible += seen;
    if (!seg.tableFound())
      continue;
    const auto& c = seg.getTableCoefficients().values;
    EXPECT_GT(Eigen::Vector3f(c[0], c[1], c[2]).dot(s.table_plane.head<3>()), std::cos(0.05f))
      << seed;
    EXPECT_NEAR(c[3], s.table_plane[3], 0.03f) << seed;
    found_visible += seen;
  }
  EXPECT_GE(visible, 4u); // the set tests something
  EXPECT_EQ(found_visible, visible);
}

TEST(AnyTable, RolledCamerasNeedNoUpDirection)
{
  // The same frames as a camera rolled by 90, 180 and 270 degrees would take them: the table,
  // and the same objects within one, without --up.
  facyl::TabletopCylinderRecognizer<pcl::PointXYZRGBA> rec;
  // As facyl_detect runs by default: the decisions of these small, far objects are the evidence
  // model's with the network (without it they sit near 0.5 and a roll flips some).
  auto classifier = std::make_shared<facyl::CylinderClassifier>();
  classifier->load(facyl::CylinderClassifier::defaultModelPath());
  rec.setClassifier(classifier);
  for (const std::uint64_t seed : {1001u, 1002u, 1005u}) {
    const facyl::RenderedScene s = cluttered(seed);
    const auto upright = recognize(Cloud::ConstPtr(new Cloud(s.cloud)), rec);
    ASSERT_TRUE(rec.tableFound());
    std::size_t upright_cylinders = 0;
    for (const auto& o : upright)
      upright_cylinders += o.is_cylinder;
    for (int turns = 1; turns <= 3; ++turns) {
      const std::string what =
        "seed " + std::to_string(seed) + ", " + std::to_string(90 * turns) + " degrees";
      const auto objects =
        recognize(Cloud::ConstPtr(new Cloud(facyl::rollFrame(s.cloud, turns))), rec);
      ASSERT_TRUE(rec.tableFound()) << what;
      const auto& c = rec.getTableCoefficients().values;
      const Eigen::Vector4f truth = rolledPlane(s.table_plane, turns);
      EXPECT_GT(Eigen::Vector3f(c[0], c[1], c[2]).dot(truth.head<3>()), std::cos(0.05f)) << what;
      EXPECT_NEAR(c[3], truth[3], 0.02f) << what;
      EXPECT_NEAR(static_cast<double>(objects.size()), static_cast<double>(upright.size()), 1.0)
        << what;
      std::size_t cylinders = 0;
      for (const auto& o : objects)
        cylinders += o.is_cylinder;
      // Decisions of the small, far objects sit near p 0.5, and a roll changes their pixels:
      // with the surface-ratio floor at 0.25 (more of them are weighed by the evidence model)
      // seed 1005 at 90 degrees calls 2 more (4 against 2), the other 8 rolls 1 or none.
      EXPECT_NEAR(static_cast<double>(cylinders), static_cast<double>(upright_cylinders), 2.0)
        << what;
    }
  }
}

TEST(AnyTable, AFrameWithoutASupportStillGetsItsObjects)
{
  // A close-up: only the objects have depth (table, floor and walls removed).
  facyl::TabletopSceneParameters p;
  p.min_objects = p.max_objects = 3;
  p.cylinder_share = 1.f;
  p.lying_share = 0.f;
  p.seed = 21;
  const facyl::RenderedScene s = facyl::simulateTabletopScene(p);
  Cloud::Ptr cloud(new Cloud(s.cloud));
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::size_t cans = 0;
  for (std::size_t i = 0; i < cloud->size(); ++i)
    if (s.object_id[i] < 2)
      (*cloud)[i].x = (*cloud)[i].y = (*cloud)[i].z = nan;
  for (std::size_t k = 0; k < s.scene.objects.size(); ++k)
    cans += s.visible_pixels[k] >= 1000;
  facyl::TabletopCylinderRecognizer<pcl::PointXYZRGBA> rec;
  const auto objects = recognize(cloud, rec);
  EXPECT_FALSE(rec.tableFound());
  EXPECT_TRUE(rec.getSupports().empty());
  EXPECT_TRUE(rec.getTableCoefficients().values.empty());
  std::size_t cylinders = 0;
  for (const auto& o : objects) {
    EXPECT_EQ(o.cluster.support, -1);
    cylinders += o.is_cylinder;
  }
  EXPECT_GE(cylinders + 1, cans);
  EXPECT_GE(cylinders, 1u);
  // A wall filling the frame: no error, no object.
  pcl::PointCloud<pcl::PointXYZRGBA>::Ptr wall(new Cloud(160, 120));
  for (std::uint32_t v = 0; v < wall->height; ++v)
    for (std::uint32_t u = 0; u < wall->width; ++u) {
      auto& q = wall->at(u, v);
      q.z = 1.5f;
      q.x = (static_cast<float>(u) - 79.5f) * q.z / 130.f;
      q.y = (static_cast<float>(v) - 59.5f) * q.z / 130.f;
    }
  EXPECT_TRUE(recognize(wall, rec).empty());
  EXPECT_FALSE(rec.tableFound());
}

TEST(AnyTable, UnorganizedCloudsGetAClassifierView)
{
  const facyl::RenderedScene s = cluttered(1007);
  Cloud::Ptr points(new Cloud);
  for (const auto& q : s.cloud)
    if (pcl::isFinite(q))
      points->push_back(q);
  auto classifier = std::make_shared<facyl::CylinderClassifier>();
  classifier->load(facyl::CylinderClassifier::defaultModelPath());
  facyl::TabletopCylinderRecognizer<pcl::PointXYZRGBA> rec;
  rec.setClassifier(classifier);
  const auto objects = recognize(points, rec);
  ASSERT_FALSE(objects.empty());
  std::size_t known = 0;
  for (const auto& o : objects)
    known += std::isfinite(o.evidence.p_network);
  EXPECT_EQ(known, objects.size());
  // The view itself: about one point per pixel of its box, in front of the virtual camera.
  const facyl::ObjectView view = facyl::lookAtObjectView(
    *points, objects.front().cluster.indices.indices, Eigen::Vector3f::Zero());
  ASSERT_GE(view.box[0], 0);
  const float box =
    static_cast<float>((view.box[2] - view.box[0] + 1) * (view.box[3] - view.box[1] + 1));
  const float n = static_cast<float>(objects.front().cluster.indices.indices.size());
  EXPECT_GT(box, 0.5f * n);
  EXPECT_LT(box, 2.f * n);
  EXPECT_GT(view.points.row(2).minCoeff(), 0.f);
}

// ---------------------------------------------------------------- real frames

namespace {

struct Label {
  std::string frame, object, cls;
  int u{0}, v{0};
};

std::vector<Label>
readLabels(const std::string& csv)
{
  std::vector<Label> out;
  std::ifstream in(csv);
  for (const auto& f : facyl_cli::readCsvRows(in))
    if (f.size() >= 5)
      out.push_back({f[0], f[1], f[2], std::stoi(f[3]), std::stoi(f[4])});
  return out;
}

} // namespace

TEST(LabelTables, QuotedFieldsMayHoldCommas)
{
  // The rgbd labels.csv format: frame,object,class,u,v,u0,v0,u1,v1,note; a note in quotes
  // may hold commas, one without quotes is taken as it is.
  std::istringstream table(
    "frame,object,class,u,v,u0,v0,u1,v1,note\n"
    "graspnet6dof/blue_mug,blue_mug,cylinder_handle,330,235,267,163,421,302,\"dark blue mug "
    "with handle, upright\"\n"
    "posecnn/0001,can,cylinder,10,20,1,2,30,40,plain note; no quotes\n"
    "sevenscenes/frame150,,box,1,2,,,,,\n");
  const auto rows = facyl_cli::readCsvRows(table);
  ASSERT_EQ(rows.size(), 3u); // the header is skipped
  ASSERT_EQ(rows[0].size(), 10u);
  EXPECT_EQ(rows[0][0], "graspnet6dof/blue_mug");
  EXPECT_EQ(rows[0][3], "330");
  EXPECT_EQ(rows[0][9], "dark blue mug with handle, upright");
  EXPECT_EQ(rows[1][9], "plain note; no quotes");
  ASSERT_EQ(rows[2].size(), 10u); // empty fields count
  EXPECT_EQ(rows[2][1], "");
  EXPECT_EQ(rows[2][9], "");
  EXPECT_EQ(facyl_cli::splitCsvLine(""), std::vector<std::string>{""});
  EXPECT_EQ(facyl_cli::splitCsvLine("a,\"b, \"\"c\"\"\",d"),
            (std::vector<std::string>{"a", "b, c", "d"}));
}

TEST(RealFrames, OtherSensorsAndRooms)
{
  const std::string csv = facyl_test::realFile("rgbd/labels.csv");
  if (csv.empty())
    GTEST_SKIP() << "../shared/data/real/rgbd is absent";
  const std::vector<Label> labels = readLabels(csv);
  std::map<std::string, std::vector<Label>> by_frame;
  for (const auto& l : labels)
    by_frame[l.frame].push_back(l);
  auto classifier = std::make_shared<facyl::CylinderClassifier>();
  classifier->load(facyl::CylinderClassifier::defaultModelPath());
  facyl::TabletopCylinderRecognizer<pcl::PointXYZRGBA> rec;
  rec.setClassifier(classifier);
  for (const auto& [frame, frame_labels] : by_frame) {
    Cloud::Ptr cloud(new Cloud);
    ASSERT_EQ(pcl::io::loadPCDFile(facyl_test::realFile("rgbd/" + frame + ".pcd"), *cloud), 0);
    rec.setInputCloud(cloud);
    std::vector<facyl::RecognizedObject> objects;
    ASSERT_TRUE(rec.recognize(objects)) << frame; // never an error
    for (const auto& l : frame_labels) {
      if (l.cls == "none")
        continue;
      // The smallest object box holding the label's pixel.
      const facyl::RecognizedObject* best = nullptr;
      for (const auto& o : objects) {
        const auto& b = o.cluster.box;
        if (b[0] <= l.u && l.u <= b[2] && b[1] <= l.v && l.v <= b[3] &&
            (!best ||
             (b[2] - b[0]) * (b[3] - b[1]) < (best->cluster.box[2] - best->cluster.box[0]) *
                                               (best->cluster.box[3] - best->cluster.box[1])))
          best = &o;
      }
      if (l.cls == "cylinder") {
        ASSERT_NE(best, nullptr) << frame << " " << l.object;
        EXPECT_TRUE(best->is_cylinder) << frame << " " << l.object;
      }
    }
  }
}

TEST(RealFrames, ADarkCounterIsTheTableNotTheWallsAroundIt)
{
  // 7-Scenes' kitchen (Kinect v1): a black granite counter gives depth only on the white
  // slabs standing on it, while the tiled wall behind and the cabinet fronts below fill the
  // frame. The candidates an upright camera sees facing up are kept before the larger walls
  // (before, the slabs were the 7th and 8th of 8 candidates and cut: the wall became the
  // table, the objects on the counter "standing" out of it).
  const std::string file = facyl_test::realFile("rgbd/sevenscenes_stream/frame150.pcd");
  if (file.empty())
    GTEST_SKIP() << "../shared/data/real/rgbd/sevenscenes_stream is absent";
  Cloud::Ptr cloud(new Cloud);
  ASSERT_EQ(pcl::io::loadPCDFile(file, *cloud), 0);
  facyl::TabletopCylinderRecognizer<pcl::PointXYZRGBA> rec;
  rec.setInputCloud(cloud);
  std::vector<facyl::RecognizedObject> objects;
  ASSERT_TRUE(rec.recognize(objects));
  ASSERT_TRUE(rec.tableFound());
  const auto& v = rec.getTableCoefficients().values;
  ASSERT_EQ(v.size(), 4u);
  // The camera is upright (no roll, tilted down): the counter's normal points up the image.
  EXPECT_LT(v[1], -0.8f) << v[0] << " " << v[1] << " " << v[2] << " " << v[3];
  EXPECT_GT(objects.size(), 2u);
}
