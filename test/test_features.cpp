/*
 * facyl: tests of NormalCurvatureEstimation and NeighbourSearch.
 */
#include "test_helpers.h"

#include <facyl/features/neighbourhoods.h>
#include <facyl/features/normal_curvature_estimation.h>
#include <facyl/features/point_cues.h>
#include <facyl/features/polygon.h>
#include <facyl/simulation/cylinder_simulation.h>
#include <facyl/simulation/tabletop_scene.h>

#include <pcl/common/io.h>
#include <pcl/features/normal_3d.h>
#include <pcl/features/principal_curvatures.h>
#include <pcl/search/kdtree.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>

using Cues = pcl::PointCloud<facyl::NormalCurvature>;

namespace {
pcl::PointCloud<pcl::PointXYZ>::Ptr
cylinderXYZ(float noise, std::uint64_t seed)
{
  facyl::CylinderSimulationParameters p;
  p.radius = 0.1f;
  p.height = 0.4f;
  p.base = Eigen::Vector3f::Zero(); // the checks below are about the origin
  p.lateral_points = 2000;
  p.noise = noise;
  p.seed = seed;
  const auto sim = facyl::simulateCylinder(p);
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>);
  for (const auto& q : sim.cloud)
    cloud->push_back(pcl::PointXYZ(q.x, q.y, q.z));
  return cloud;
}

/** An organized view (\a width x \a height pixels) of a noisy bump on a slanted plane, a
 * tenth of the pixels without depth. */
pcl::PointCloud<pcl::PointXYZ>::Ptr
organizedBump(int width, int height, unsigned seed)
{
  std::mt19937 rng(seed);
  std::normal_distribution<float> noise(0.f, 0.001f);
  std::uniform_real_distribution<float> u01(0.f, 1.f);
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>(
    static_cast<std::uint32_t>(width), static_cast<std::uint32_t>(height)));
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (int v = 0; v < height; ++v)
    for (int u = 0; u < width; ++u) {
      const float x = 0.004f * static_cast<float>(u - width / 2);
      const float y = 0.004f * static_cast<float>(v - height / 2);
      const float z = 1.f + 0.3f * y + 0.05f * std::exp(-(x * x + y * y) / 0.002f) + noise(rng);
      cloud->at(u, v) = u01(rng) < 0.1f ? pcl::PointXYZ(nan, nan, nan) : pcl::PointXYZ(x, y, z);
    }
  cloud->is_dense = false;
  return cloud;
}

/** Whether two float fields are the same value (NaN equals NaN). */
bool
same(float a, float b)
{
  return a == b || (std::isnan(a) && std::isnan(b));
}

/** Whether \a a and \a b hold the same normals and curvatures, bit for bit but for NaNs. */
bool
sameCues(const Cues& a, const Cues& b)
{
  if (a.size() != b.size() || a.is_dense != b.is_dense)
    return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const auto &p = a[i], &q = b[i];
    if (!same(p.normal_x, q.normal_x) || !same(p.normal_y, q.normal_y) ||
        !same(p.normal_z, q.normal_z) || !same(p.curvature, q.curvature) ||
        !same(p.principal_curvature_x, q.principal_curvature_x) ||
        !same(p.principal_curvature_y, q.principal_curvature_y) ||
        !same(p.principal_curvature_z, q.principal_curvature_z) || !same(p.pc1, q.pc1) ||
        !same(p.pc2, q.pc2))
      return false;
  }
  return true;
}
} // namespace

TEST(NeighbourSearch, MatchesBruteForce)
{
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-1.f, 1.f);
  Eigen::Matrix3Xf pts(3, 500);
  for (Eigen::Index i = 0; i < pts.cols(); ++i)
    pts.col(i) = Eigen::Vector3f(u(rng), u(rng), u(rng));
  pts.col(7).setConstant(std::numeric_limits<float>::quiet_NaN());
  const facyl::NeighbourSearch search(pts);
  const auto knn = search.nearest(pts, 8, 2);
  const auto ball = search.within(pts, 0.3f, 2);
  ASSERT_EQ(knn.size(), 500u);
  EXPECT_EQ(knn.count(7), 0u);
  EXPECT_EQ(ball.count(7), 0u);
  for (std::size_t i = 0; i < 500; ++i) {
    if (i == 7)
      continue;
    std::vector<std::pair<float, int>> all;
    for (Eigen::Index j = 0; j < pts.cols(); ++j)
      if (j != 7)
        all.emplace_back((pts.col(j) - pts.col(i)).squaredNorm(), static_cast<int>(j));
    std::sort(all.begin(), all.end());
    ASSERT_EQ(knn.count(i), 8u);
    for (std::size_t j = 0; j < 8; ++j)
      EXPECT_FLOAT_EQ((pts.col(knn.begin(i)[j]) - pts.col(i)).squaredNorm(), all[j].first);
    const auto inside =
      std::count_if(all.begin(), all.end(), [](const auto& d) { return d.first <= 0.09f; });
    EXPECT_EQ(ball.count(i), static_cast<std::size_t>(inside));
  }
  EXPECT_THROW(search.nearest(pts, 0), std::invalid_argument);
  EXPECT_THROW(search.within(pts, -1.f), std::invalid_argument);
}

TEST(NeighbourSearch, GridNeighboursAreTheTreesNeighbours)
{
  // nearestOnGrid against the k-d tree on the shapes it meets: a cylinder with lids, a plane,
  // a line, a filled box, coincident points; queries inside and far outside, not finite; k
  // from 1 to more than the points. The same neighbours at the same distances, nearest first.
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  std::normal_distribution<float> g(0.f, 0.003f);
  const auto shape = [&](int kind, Eigen::Index n) {
    Eigen::Matrix3Xf p(3, n);
    for (Eigen::Index i = 0; i < n; ++i) {
      const float t = 6.2832f * u(rng), a = u(rng), b = u(rng);
      switch (kind) {
      case 0: // cylinder, half its points on the lids
        p.col(i) = i % 2 ? Eigen::Vector3f(0.3f * std::cos(t), 0.3f * std::sin(t), a)
                         : Eigen::Vector3f(0.3f * std::sqrt(b) * std::cos(t),
                                           0.3f * std::sqrt(b) * std::sin(t), float(i % 4 == 0));
        p.col(i) += Eigen::Vector3f(g(rng), g(rng), g(rng));
        break;
      case 1: // a plane without noise
        p.col(i) = Eigen::Vector3f(2.f * a, b, 0.5f);
        break;
      case 2: // a line
        p.col(i) = Eigen::Vector3f(a, 0.f, 0.f);
        break;
      case 3: // a filled box
        p.col(i) = Eigen::Vector3f(a, b, u(rng));
        break;
      default: // ten places, each holding many coincident points
        p.col(i) = Eigen::Vector3f(float(i % 10), 0.f, 1.f);
      }
    }
    return p;
  };
  for (int kind = 0; kind < 5; ++kind) {
    Eigen::Matrix3Xf pts = shape(kind, 700);
    pts.col(5).setConstant(std::numeric_limits<float>::quiet_NaN());
    Eigen::Matrix3Xf queries(3, 103);
    for (Eigen::Index i = 0; i < 100; ++i)
      queries.col(i) = pts.col(i * 7);
    queries.col(100) = Eigen::Vector3f(40.f, -30.f, 7.f); // far outside
    queries.col(101) = Eigen::Vector3f(0.5f, 0.5f, 0.5f);
    queries.col(102).setConstant(std::numeric_limits<float>::infinity());
    const facyl::NeighbourSearch search(pts);
    for (const int k : {1, 12, 64, 1000}) {
      const auto tree = search.nearest(queries, k, 1);
      const auto grid = facyl::nearestOnGrid(pts, queries, k);
      ASSERT_EQ(grid.size(), tree.size());
      for (std::size_t i = 0; i < grid.size(); ++i) {
        ASSERT_EQ(grid.count(i), tree.count(i)) << "shape " << kind << " k " << k << " query " << i;
        const Eigen::Vector3f q = queries.col(static_cast<Eigen::Index>(i));
        for (std::size_t j = 0; j < grid.count(i); ++j) {
          const float dg = (pts.col(grid.begin(i)[j]) - q).squaredNorm();
          EXPECT_FLOAT_EQ(dg, (pts.col(tree.begin(i)[j]) - q).squaredNorm())
            << "shape " << kind << " k " << k << " query " << i << " rank " << j;
          if (j > 0) {
            EXPECT_LE((pts.col(grid.begin(i)[j - 1]) - q).squaredNorm(), dg);
          }
        }
      }
      EXPECT_EQ(grid.count(102), 0u);
      EXPECT_EQ(grid.count(0), std::min<std::size_t>(static_cast<std::size_t>(k), 699u));
      if (kind != 4) { // a surface point finds itself first (coincident points: any of them)
        EXPECT_EQ(grid.begin(0)[0], 0);
      }
    }
  }
  const Eigen::Matrix3Xf none(3, 0), one = Eigen::Vector3f(1.f, 2.f, 3.f);
  EXPECT_EQ(facyl::nearestOnGrid(none, one, 4).count(0), 0u);
  EXPECT_EQ(facyl::nearestOnGrid(one, one, 4).count(0), 1u);
  EXPECT_THROW(facyl::nearestOnGrid(one, one, 0), std::invalid_argument);
}

TEST(NeighbourSearch, NearestWithinIsNearestCutAtTheRadius)
{
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-1.f, 1.f);
  Eigen::Matrix3Xf pts(3, 800);
  for (Eigen::Index i = 0; i < pts.cols(); ++i)
    pts.col(i) = Eigen::Vector3f(u(rng), u(rng), u(rng));
  pts.col(3).setConstant(std::numeric_limits<float>::quiet_NaN());
  const facyl::NeighbourSearch search(pts);
  const int k = 24;
  const float radius = 0.4f;
  const auto knn = search.nearest(pts, k, 2);
  const auto cut = search.nearestWithin(pts, k, radius, 2);
  ASSERT_EQ(cut.size(), 800u);
  EXPECT_EQ(cut.count(3), 0u);
  std::size_t short_lists = 0, full_lists = 0;
  for (std::size_t i = 0; i < cut.size(); ++i) {
    std::size_t expected = 0;
    while (expected < knn.count(i) &&
           (pts.col(knn.begin(i)[expected]) - pts.col(static_cast<Eigen::Index>(i))).norm() <
             radius)
      ++expected;
    ASSERT_EQ(cut.count(i), expected) << "query " << i;
    for (std::size_t j = 0; j < expected; ++j)
      EXPECT_EQ(cut.begin(i)[j], knn.begin(i)[j]);
    short_lists += expected > 0 && expected < static_cast<std::size_t>(k);
    full_lists += expected == static_cast<std::size_t>(k);
  }
  EXPECT_GT(short_lists, 50u); // both cases occur: the radius cuts some lists, k others
  EXPECT_GT(full_lists, 50u);
  // An infinite radius is nearest().
  const auto all = search.nearestWithin(pts, k, std::numeric_limits<float>::infinity(), 1);
  EXPECT_EQ(all.indices, knn.indices);
  EXPECT_THROW(search.nearestWithin(pts, 0, radius), std::invalid_argument);
  EXPECT_THROW(search.nearestWithin(pts, k, 0.f), std::invalid_argument);
  EXPECT_THROW(search.nearestWithin(pts, k, std::nanf("")), std::invalid_argument);
}

TEST(NeighbourSearch, ImageNeighboursAreTheWindowsNearest)
{
  // nearestInImage against brute force over each query's window: a noisy slanted plane of
  // 23 x 17 pixels, a tenth without depth, queries in the corners, on the edges and inside.
  const int width = 23, height = 17, k = 16;
  const int r = facyl::imageWindowRadius(k);
  EXPECT_EQ(r, 3); // 49 pixels for 16 neighbours
  EXPECT_EQ(facyl::imageWindowRadius(1), 1);
  std::mt19937 rng(5);
  std::normal_distribution<float> noise(0.f, 0.002f);
  std::uniform_real_distribution<float> u01(0.f, 1.f);
  Eigen::Matrix3Xf pixels(3, width * height);
  for (int v = 0; v < height; ++v)
    for (int u = 0; u < width; ++u)
      pixels.col(v * width + u) =
        u01(rng) < 0.1f ? Eigen::Vector3f::Constant(std::numeric_limits<float>::quiet_NaN())
                        : Eigen::Vector3f(0.003f * static_cast<float>(u),
                                          0.006f * static_cast<float>(v), 1.f + noise(rng));
  std::vector<int> queries(static_cast<std::size_t>(pixels.cols()));
  std::iota(queries.begin(), queries.end(), 0);
  // The default window (radius 0: imageWindowRadius(k)) and a wider one.
  for (const int radius : {0, 5}) {
    const int r_used = radius > 0 ? radius : r;
    const facyl::Neighbourhoods nb = facyl::nearestInImage(pixels, width, queries, k, 2, radius);
    ASSERT_EQ(nb.size(), queries.size());
    for (const int q : queries) {
      const auto i = static_cast<std::size_t>(q);
      if (!pixels.col(q).allFinite()) {
        EXPECT_EQ(nb.count(i), 0u);
        continue;
      }
      std::vector<std::pair<float, int>> window;
      const int u = q % width, v = q / width;
      for (int y = std::max(0, v - r_used); y <= std::min(height - 1, v + r_used); ++y)
        for (int x = std::max(0, u - r_used); x <= std::min(width - 1, u + r_used); ++x)
          if (pixels.col(y * width + x).allFinite())
            window.emplace_back((pixels.col(y * width + x) - pixels.col(q)).squaredNorm(),
                                y * width + x);
      std::sort(window.begin(), window.end());
      ASSERT_EQ(nb.count(i), std::min<std::size_t>(k, window.size())) << "pixel " << q;
      EXPECT_EQ(nb.begin(i)[0], q); // the query first
      for (std::size_t j = 0; j < nb.count(i); ++j)
        EXPECT_EQ(nb.begin(i)[j], window[j].second)
          << "pixel " << q << ", neighbour " << j << ", radius " << radius;
    }
  }
  // Lists written into a reused Neighbourhoods (which held more queries, then fewer) are the
  // lists of a fresh one.
  facyl::Neighbourhoods reused = facyl::nearestInImage(pixels, width, queries, k, 2);
  for (const std::size_t count : {queries.size() / 3, queries.size()}) {
    const std::vector<int> some(queries.begin(), queries.begin() + static_cast<long>(count));
    facyl::nearestInImage(pixels, width, some, k, reused, 2);
    const facyl::Neighbourhoods fresh = facyl::nearestInImage(pixels, width, some, k, 1);
    EXPECT_EQ(reused.offsets, fresh.offsets);
    EXPECT_EQ(reused.indices, fresh.indices);
  }
  EXPECT_THROW(facyl::nearestInImage(pixels, width, queries, 0), std::invalid_argument);
  EXPECT_THROW(facyl::nearestInImage(pixels, 22, queries, k), std::invalid_argument);
  EXPECT_THROW(facyl::nearestInImage(pixels, width, {width * height}, k), std::invalid_argument);
  EXPECT_THROW(facyl::nearestInImage(pixels, width, queries, k, 1, -1), std::invalid_argument);
  EXPECT_THROW(facyl::imageWindowRadius(0), std::invalid_argument);
}

TEST(NeighbourSearch, AWindowForAnInclinationHoldsTheNearestInSpace)
{
  // The window's radius for k neighbours on a surface inclined by up to a given angle
  // (imageWindowRadius(k, angle)): on an evenly sampled plane inclined by 75 degrees it holds
  // the k-d tree's k nearest of every pixel away from the border; the window for k alone
  // (radius 3, enough up to about 55 degrees) does not.
  constexpr float kDeg = static_cast<float>(M_PI) / 180.f;
  const int k = 16;
  EXPECT_EQ(facyl::imageWindowRadius(k, 0.f), 3);
  EXPECT_EQ(facyl::imageWindowRadius(k, 55.f * kDeg), 3);
  EXPECT_EQ(facyl::imageWindowRadius(k, 78.f * kDeg), 5);
  EXPECT_EQ(facyl::imageWindowRadius(1, 0.f), 1);
  EXPECT_THROW(facyl::imageWindowRadius(0, 0.f), std::invalid_argument);
  EXPECT_THROW(facyl::imageWindowRadius(k, -0.1f), std::invalid_argument);
  EXPECT_THROW(facyl::imageWindowRadius(k, 0.5f * static_cast<float>(M_PI)), std::invalid_argument);
  EXPECT_THROW(facyl::imageWindowRadius(k, std::numeric_limits<float>::quiet_NaN()),
               std::invalid_argument);

  // Pixels 1 mm apart across, 1 / cos 75 = 3.9 mm apart along the inclination (rows), with
  // a little noise so that no two distances tie.
  const int width = 31, height = 31;
  std::mt19937 rng(9);
  std::normal_distribution<float> noise(0.f, 1e-5f);
  Eigen::Matrix3Xf pixels(3, width * height);
  const float along = 0.001f / std::cos(75.f * kDeg);
  for (int v = 0; v < height; ++v)
    for (int u = 0; u < width; ++u)
      pixels.col(v * width + u) = Eigen::Vector3f(0.001f * static_cast<float>(u) + noise(rng),
                                                  along * static_cast<float>(v) + noise(rng), 1.f);
  std::vector<int> inside;
  for (int v = 8; v < height - 8; ++v)
    for (int u = 8; u < width - 8; ++u)
      inside.push_back(v * width + u);
  const facyl::NeighbourSearch tree(pixels);
  Eigen::Matrix3Xf queries(3, static_cast<Eigen::Index>(inside.size()));
  for (std::size_t i = 0; i < inside.size(); ++i)
    queries.col(static_cast<Eigen::Index>(i)) = pixels.col(inside[i]);
  const facyl::Neighbourhoods nearest = tree.nearest(queries, k, 1);
  const auto sameAsTree = [&](int radius) {
    const facyl::Neighbourhoods window = facyl::nearestInImage(pixels, width, inside, k, 1, radius);
    for (std::size_t i = 0; i < inside.size(); ++i) {
      std::vector<int> a(window.begin(i), window.begin(i) + window.count(i));
      std::vector<int> b(nearest.begin(i), nearest.begin(i) + nearest.count(i));
      std::sort(a.begin(), a.end());
      std::sort(b.begin(), b.end());
      if (a != b)
        return false;
    }
    return true;
  };
  EXPECT_TRUE(sameAsTree(facyl::imageWindowRadius(k, 78.f * kDeg)));
  EXPECT_FALSE(sameAsTree(facyl::imageWindowRadius(k)));
  facyl::NormalCurvatureEstimation<pcl::PointXYZ, facyl::NormalCurvature> cues;
  EXPECT_EQ(cues.getImageWindowRadius(), 0);
  EXPECT_THROW(cues.setImageWindowRadius(-1), std::invalid_argument);
  cues.setImageWindowRadius(5);
  EXPECT_EQ(cues.getImageWindowRadius(), 5);
}

TEST(NormalCurvatureEstimation, OrganizedInputTakesTheImagesNeighbours)
{
  // A simulated VGA tabletop frame (Kinect-like noise and quantization, holes, depth edges):
  // on the table and the objects the cues from the image grid are the k-d tree's nearly
  // everywhere (on real frames of four sensors, 90% of all normals are identical and 99% within
  // 1.1-3.4 deg). The far floor, seen at a grazing angle, is left out: there a row's pixels
  // lie many times closer together than a column's, and the window's neighbours are not the
  // tree's (which take a strip of the row).
  facyl::TabletopSceneParameters params;
  params.seed = 4;
  const facyl::RenderedScene frame = facyl::simulateTabletopScene(params);
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>);
  pcl::copyPointCloud(frame.cloud, *cloud);
  ASSERT_TRUE(cloud->isOrganized());
  facyl::NormalCurvatureEstimation<pcl::PointXYZ> ne;
  ne.setInputCloud(cloud);
  ne.setKSearch(16);
  EXPECT_TRUE(ne.getImageNeighbourhoods());
  Cues image, tree;
  ne.compute(image);
  ne.setImageNeighbourhoods(false);
  ne.compute(tree);
  ASSERT_EQ(image.size(), cloud->size());
  std::size_t compared = 0, same_normal = 0, on_cylinders = 0, same_direction = 0;
  for (std::size_t i = 0; i < cloud->size(); ++i) {
    const auto& a = image[i];
    const auto& b = tree[i];
    const facyl::SceneClass seen = frame.pixel_class[i];
    if (!std::isfinite(b.normal_x) || seen == facyl::SceneClass::Background ||
        seen == facyl::SceneClass::Scenery)
      continue;
    ++compared;
    if (!std::isfinite(a.normal_x))
      continue;
    const float normals = Eigen::Vector3f(a.normal_x, a.normal_y, a.normal_z)
                            .dot(Eigen::Vector3f(b.normal_x, b.normal_y, b.normal_z));
    same_normal += normals > std::cos(1.f * static_cast<float>(M_PI) / 180.f);
    if (seen == facyl::SceneClass::Cylinder) {
      ++on_cylinders;
      const float directions = std::abs(
        Eigen::Vector3f(a.principal_curvature_x, a.principal_curvature_y, a.principal_curvature_z)
          .dot(Eigen::Vector3f(b.principal_curvature_x, b.principal_curvature_y,
                               b.principal_curvature_z)));
      same_direction += directions > std::cos(5.f * static_cast<float>(M_PI) / 180.f);
    }
  }
  ASSERT_GT(compared, 100000u);
  EXPECT_GT(same_normal, 0.95 * static_cast<double>(compared));
  ASSERT_GT(on_cylinders, 5000u);
  EXPECT_GT(same_direction, 0.9 * static_cast<double>(on_cylinders));
  // The normals are those of nearestInImage's neighbourhoods (where the two differ, the image
  // output is the grid's, not the tree's).
  Eigen::Matrix3Xf pixels(3, static_cast<Eigen::Index>(cloud->size()));
  for (std::size_t i = 0; i < cloud->size(); ++i)
    pixels.col(static_cast<Eigen::Index>(i)) = (*cloud)[i].getVector3fMap();
  std::vector<int> queries;
  for (std::size_t i = 0; i < cloud->size(); i += 13)
    queries.push_back(static_cast<int>(i));
  const facyl::Neighbourhoods nb =
    facyl::nearestInImage(pixels, static_cast<int>(cloud->width), queries, 16);
  std::size_t checked = 0;
  for (std::size_t s = 0; s < queries.size(); ++s) {
    Eigen::Vector3f n;
    float variation;
    const int* list = nb.begin(s);
    if (!facyl::estimateNormal(
          nb.count(s), [&](std::size_t j) { return Eigen::Vector3f(pixels.col(list[j])); }, n,
          variation))
      continue;
    const Eigen::Vector3f p = pixels.col(queries[s]);
    if (p.dot(n) > 0.f) // towards the sensor at the origin
      n = -n;
    const auto& a = image[static_cast<std::size_t>(queries[s])];
    ASSERT_TRUE(std::isfinite(a.normal_x));
    EXPECT_EQ(Eigen::Vector3f(a.normal_x, a.normal_y, a.normal_z), n) << "pixel " << queries[s];
    ++checked;
  }
  EXPECT_GT(checked, 10000u);

  // The points of a subset get what the whole frame gives them (their neighbours' normals
  // come from the same windows).
  ne.setImageNeighbourhoods(true);
  pcl::IndicesPtr subset(new pcl::Indices);
  for (std::size_t i = 0; i < cloud->size(); i += 97)
    subset->push_back(static_cast<pcl::index_t>(i));
  ne.setIndices(subset);
  Cues part;
  ne.compute(part);
  ASSERT_EQ(part.size(), subset->size());
  for (std::size_t k = 0; k < subset->size(); ++k) {
    const auto& a = image[static_cast<std::size_t>((*subset)[k])];
    const auto& b = part[k];
    ASSERT_EQ(std::isfinite(a.normal_x), std::isfinite(b.normal_x));
    if (std::isfinite(a.normal_x)) {
      EXPECT_EQ(a.normal_x, b.normal_x);
      EXPECT_EQ(a.pc1, b.pc1);
    }
  }
}

TEST(NormalCurvatureEstimation, AMisshapenOrganizedCloudGetsTheTree)
{
  // width x height that is not the cloud's size (fields set by hand): no image grid, no
  // exception; the kd-tree's cues.
  const auto cloud = cylinderXYZ(0.01f, 6);
  const std::size_t n = cloud->size();
  cloud->width = static_cast<std::uint32_t>((n - 1) / 2);
  cloud->height = 2; // one point more than 2 rows
  ASSERT_NE(static_cast<std::size_t>(cloud->width) * cloud->height, n);
  facyl::NormalCurvatureEstimation<pcl::PointXYZ> ne;
  ne.setInputCloud(cloud);
  ne.setKSearch(16);
  Cues image, tree;
  ASSERT_NO_THROW(ne.compute(image));
  ne.setImageNeighbourhoods(false);
  ne.compute(tree);
  ASSERT_EQ(image.size(), n);
  for (std::size_t i = 0; i < n; ++i) {
    EXPECT_EQ(image[i].normal_x, tree[i].normal_x);
    EXPECT_EQ(image[i].pc1, tree[i].pc1);
  }
}

TEST(NormalCurvatureEstimation, CylinderNormalsAreRadialAndCurvatureCircumferential)
{
  const auto cloud = cylinderXYZ(0.f, 1);
  facyl::NormalCurvatureEstimation<pcl::PointXYZ> ne;
  ne.setInputCloud(cloud);
  ne.setKSearch(16);
  Cues cues;
  ne.compute(cues);
  ASSERT_EQ(cues.size(), cloud->size());
  EXPECT_TRUE(cues.is_dense);
  int good_normal = 0, good_direction = 0, anisotropic = 0, interior = 0;
  for (std::size_t i = 0; i < cloud->size(); ++i) {
    const Eigen::Vector3f p = (*cloud)[i].getVector3fMap();
    if (p.z() < 0.05f || p.z() > 0.35f)
      continue; // neighbourhoods cut by the open ends
    ++interior;
    const Eigen::Vector3f radial = Eigen::Vector3f(p.x(), p.y(), 0.f).normalized();
    const Eigen::Vector3f n(cues[i].normal_x, cues[i].normal_y, cues[i].normal_z);
    const Eigen::Vector3f c = cues[i].principalCurvatureVector3fMap();
    good_normal +=
      std::abs(n.dot(radial)) > std::cos(5.f * M_PI / 180.f); // PCA tilts on curved, uneven patches
    good_direction += std::abs(c.z()) < 0.1f;
    anisotropic += facyl::curvatureAnisotropy(cues[i].pc1, cues[i].pc2) > 0.8f;
    // oriented towards the view point (the origin lies on the axis: inward)
    EXPECT_LE(n.dot(radial), 0.f);
  }
  EXPECT_GT(good_normal, 0.95 * interior);
  EXPECT_GT(good_direction, 0.9 * interior);
  EXPECT_GT(anisotropic, 0.95 * interior);
}

TEST(NormalCurvatureEstimation, MatchesPclNormalAndPrincipalCurvatures)
{
  const auto cloud = cylinderXYZ(0.01f, 2);
  Cues cues;
  facyl::NormalCurvatureEstimation<pcl::PointXYZ> ne;
  ne.setInputCloud(cloud);
  ne.setKSearch(12);
  ne.compute(cues);

  pcl::PointCloud<pcl::Normal>::Ptr normals(new pcl::PointCloud<pcl::Normal>);
  pcl::NormalEstimation<pcl::PointXYZ, pcl::Normal> pne;
  pne.setInputCloud(cloud);
  pne.setKSearch(12);
  pne.compute(*normals);
  pcl::PointCloud<pcl::PrincipalCurvatures> pcs;
  pcl::PrincipalCurvaturesEstimation<pcl::PointXYZ, pcl::Normal> pce;
  pce.setInputCloud(cloud);
  pce.setInputNormals(normals);
  pce.setKSearch(12);
  pce.compute(pcs);

  int checked = 0;
  for (std::size_t i = 0; i < cloud->size(); ++i) {
    const Eigen::Vector3f a(cues[i].normal_x, cues[i].normal_y, cues[i].normal_z);
    const Eigen::Vector3f b = (*normals)[i].getNormalVector3fMap();
    ASSERT_NEAR(std::abs(a.dot(b)), 1.f, 1e-4f) << "point " << i;
    EXPECT_NEAR(cues[i].curvature, (*normals)[i].curvature, 1e-4f);
    // PCL flips towards the origin too; its curvatures use the same projected normals.
    EXPECT_NEAR(cues[i].pc1, pcs[i].pc1, 1e-4f + 1e-3f * pcs[i].pc1);
    EXPECT_NEAR(cues[i].pc2, pcs[i].pc2, 1e-4f + 1e-3f * pcs[i].pc2);
    if (pcs[i].pc1 > 2.f * pcs[i].pc2 + 1e-4f) { // a well-defined direction
      const Eigen::Vector3f c = cues[i].principalCurvatureVector3fMap();
      const Eigen::Vector3f d(pcs[i].principal_curvature_x, pcs[i].principal_curvature_y,
                              pcs[i].principal_curvature_z);
      EXPECT_NEAR(std::abs(c.dot(d.normalized())), 1.f, 1e-2f);
      ++checked;
    }
  }
  EXPECT_GT(checked, 100);
}

TEST(NormalCurvatureEstimation, IndicesSubsetGivesTheSameValues)
{
  const auto cloud = cylinderXYZ(0.01f, 3);
  facyl::NormalCurvatureEstimation<pcl::PointXYZ> ne;
  ne.setInputCloud(cloud);
  ne.setKSearch(10);
  Cues full, part;
  ne.compute(full);
  pcl::IndicesPtr subset(new pcl::Indices);
  for (int i = 0; i < static_cast<int>(cloud->size()); i += 7)
    subset->push_back(i);
  ne.setIndices(subset);
  ne.compute(part);
  ASSERT_EQ(part.size(), subset->size());
  for (std::size_t k = 0; k < subset->size(); ++k) {
    const auto& a = full[(*subset)[k]];
    const auto& b = part[k];
    EXPECT_NEAR(a.normal_x, b.normal_x, 1e-6f);
    EXPECT_NEAR(a.pc1, b.pc1, 1e-6f);
    EXPECT_NEAR(a.pc2, b.pc2, 1e-6f);
  }
}

TEST(NormalCurvatureEstimation, ThreadsAndSearchMethodsAgree)
{
  const auto cloud = cylinderXYZ(0.02f, 4);
  facyl::NormalCurvatureEstimation<pcl::PointXYZ> ne;
  ne.setInputCloud(cloud);
  ne.setKSearch(10);
  Cues one, two, pcl_tree;
  ne.setNumberOfThreads(1);
  ne.compute(one);
  ne.setNumberOfThreads(2);
  ne.compute(two);
  ne.setSearchMethod(
    pcl::search::KdTree<pcl::PointXYZ>::Ptr(new pcl::search::KdTree<pcl::PointXYZ>));
  ne.compute(pcl_tree);
  for (std::size_t i = 0; i < cloud->size(); ++i) {
    EXPECT_EQ(one[i].normal_x, two[i].normal_x);
    EXPECT_EQ(one[i].pc1, two[i].pc1);
    EXPECT_NEAR(one[i].normal_x, pcl_tree[i].normal_x, 1e-5f);
    EXPECT_NEAR(one[i].pc1, pcl_tree[i].pc1, 1e-5f + 1e-4f * one[i].pc1);
  }
}

TEST(NormalCurvatureEstimation, OneEstimatorGivesEachCloudItsOwnCues)
{
  // compute() keeps its working buffers between calls (a stream allocates nothing): one
  // estimator over clouds of other sizes and layouts, with and without indices, gives what a
  // fresh estimator gives each.
  const auto big = organizedBump(60, 40, 1), small = organizedBump(30, 20, 2);
  const auto scattered = cylinderXYZ(0.01f, 3);
  pcl::IndicesPtr some(new pcl::Indices);
  for (int i = 0; i < static_cast<int>(big->size()); i += 3)
    some->push_back(i);
  struct Run {
    pcl::PointCloud<pcl::PointXYZ>::Ptr cloud;
    pcl::IndicesPtr indices;
  };
  const std::vector<Run> runs = {{big, nullptr}, {small, nullptr}, {scattered, nullptr},
                                 {big, some},    {small, nullptr}, {big, nullptr}};
  facyl::NormalCurvatureEstimation<pcl::PointXYZ> reused;
  reused.setKSearch(16);
  for (std::size_t r = 0; r < runs.size(); ++r) {
    facyl::NormalCurvatureEstimation<pcl::PointXYZ> fresh;
    fresh.setKSearch(16);
    for (auto* ne : {&reused, &fresh}) {
      ne->setInputCloud(runs[r].cloud);
      if (runs[r].indices)
        ne->setIndices(runs[r].indices);
      else
        ne->setIndices(pcl::IndicesPtr());
    }
    Cues a, b;
    reused.compute(a);
    fresh.compute(b);
    ASSERT_FALSE(a.empty()) << "run " << r;
    EXPECT_TRUE(sameCues(a, b)) << "run " << r;
  }
}

TEST(NormalCurvatureEstimation, RadiusSearchAndGivenNormals)
{
  const auto cloud = cylinderXYZ(0.f, 5);
  facyl::NormalCurvatureEstimation<pcl::PointXYZ> ne;
  ne.setInputCloud(cloud);
  ne.setRadiusSearch(0.03);
  Cues by_radius;
  ne.compute(by_radius);
  ASSERT_EQ(by_radius.size(), cloud->size());
  pcl::PointCloud<pcl::Normal>::Ptr given(new pcl::PointCloud<pcl::Normal>);
  for (const auto& c : by_radius)
    given->push_back(pcl::Normal(c.normal_x, c.normal_y, c.normal_z));
  ne.setInputNormals(given);
  Cues with_given;
  ne.compute(with_given);
  for (std::size_t i = 0; i < cloud->size(); ++i) {
    if (!std::isfinite(by_radius[i].pc1))
      continue;
    EXPECT_NEAR(by_radius[i].pc1, with_given[i].pc1, 1e-6f);
  }
}

TEST(NormalCurvatureEstimation, NanPointsGiveNanOutput)
{
  auto cloud = cylinderXYZ(0.f, 6);
  (*cloud)[10].x = std::numeric_limits<float>::quiet_NaN();
  facyl::NormalCurvatureEstimation<pcl::PointXYZ> ne;
  ne.setInputCloud(cloud);
  ne.setKSearch(10);
  Cues cues;
  ne.compute(cues);
  ASSERT_EQ(cues.size(), cloud->size());
  EXPECT_FALSE(cues.is_dense);
  EXPECT_TRUE(std::isnan(cues[10].normal_x));
  EXPECT_TRUE(std::isnan(cues[10].pc1));
  EXPECT_TRUE(std::isfinite(cues[11].normal_x));

  pcl::PointCloud<pcl::PointXYZ>::Ptr all_nan(new pcl::PointCloud<pcl::PointXYZ>);
  all_nan->resize(50, pcl::PointXYZ(NAN, NAN, NAN));
  ne.setInputCloud(all_nan);
  ne.compute(cues);
  ASSERT_EQ(cues.size(), 50u);
  EXPECT_FALSE(cues.is_dense);
  for (const auto& c : cues)
    EXPECT_TRUE(std::isnan(c.normal_x));
}

TEST(NormalCurvatureEstimation, BadInputsGiveEmptyOutput)
{
  facyl::NormalCurvatureEstimation<pcl::PointXYZ> ne;
  Cues cues;
  ne.setKSearch(10);
  ne.compute(cues); // no input
  EXPECT_TRUE(cues.empty());
  ne.setInputCloud(pcl::PointCloud<pcl::PointXYZ>::Ptr(new pcl::PointCloud<pcl::PointXYZ>));
  ne.compute(cues); // empty input
  EXPECT_TRUE(cues.empty());
  const auto cloud = cylinderXYZ(0.f, 7);
  ne.setInputCloud(cloud);
  ne.setKSearch(2); // too few neighbours for a plane
  ne.compute(cues);
  EXPECT_TRUE(cues.empty());
  ne.setKSearch(0); // neither k nor radius
  ne.compute(cues);
  EXPECT_TRUE(cues.empty());
  ne.setKSearch(10);
  ne.setRadiusSearch(0.1); // both
  ne.compute(cues);
  EXPECT_TRUE(cues.empty());
  ne.setRadiusSearch(0.0);
  pcl::PointCloud<pcl::Normal>::Ptr wrong(new pcl::PointCloud<pcl::Normal>);
  wrong->resize(3);
  ne.setInputNormals(wrong);
  ne.compute(cues);
  EXPECT_TRUE(cues.empty());
}

TEST(LocalGeometry, CurvatureAnisotropyIsBounded)
{
  EXPECT_FLOAT_EQ(facyl::curvatureAnisotropy(1.f, 0.f), 1.f);
  EXPECT_FLOAT_EQ(facyl::curvatureAnisotropy(1.f, 1.f), 0.f);
  EXPECT_FLOAT_EQ(facyl::curvatureAnisotropy(0.f, 0.f), 0.f);
  EXPECT_FLOAT_EQ(facyl::curvatureAnisotropy(NAN, 0.f), 0.f);
  EXPECT_NEAR(facyl::curvatureAnisotropy(3.f, 1.f), 0.5f, 1e-6f);
}

TEST(PointCues, SharedNeighbourhoodsGoToTheNearestCentreThatHoldsThem)
{
  // Six points on a line; centres at columns 0 and 3; the second centre's list leaves out 5.
  Eigen::Matrix3Xf pts = Eigen::Matrix3Xf::Zero(3, 6);
  for (int i = 0; i < 6; ++i)
    pts(0, i) = static_cast<float>(i);
  const std::vector<std::vector<int>> lists{{0, 1, 2, 3}, {3, 2, 4}};
  const auto nb = facyl::Neighbourhoods::fromLists(lists);
  const std::vector<int> owner = facyl::sharedNeighbourhoods(pts, {0, 3}, nb);
  EXPECT_EQ(owner, (std::vector<int>{0, 0, 1, 1, 1, -1}));
}

TEST(PointCues, EverySecondNeighbourhoodSharedKeepsTheCues)
{
  // A cylinder about z (r 0.1 m) at 10% noise, coarse cues at its radius (64 neighbours at
  // most): searched for every point, and for every second point, shared.
  const auto cloud = cylinderXYZ(0.01f, 5);
  Eigen::Matrix3Xf pts(3, static_cast<Eigen::Index>(cloud->size()));
  for (std::size_t i = 0; i < cloud->size(); ++i)
    pts.col(static_cast<Eigen::Index>(i)) = (*cloud)[i].getVector3fMap();
  const Eigen::Matrix3Xf none(3, 0);
  const facyl::PointCues every = facyl::estimatePointCues(pts, 0.1f, 64, none);
  const facyl::PointCues shared = facyl::estimatePointCues(pts, 0.1f, 64, none, 2);
  std::vector<float> tilt_every, tilt_shared, apart;
  for (Eigen::Index i = 0; i < pts.cols(); ++i) {
    ASSERT_TRUE(every.normals.col(i).allFinite()) << i;
    ASSERT_TRUE(shared.normals.col(i).allFinite()) << i;
    if (i % 2 == 0) { // a centre: its own neighbourhood, the same normal
      EXPECT_EQ(shared.normals.col(i), every.normals.col(i)) << i;
    }
    else { // a neighbour's normal: nearly its own
      apart.push_back(
        std::acos(std::min(1.f, std::abs(every.normals.col(i).dot(shared.normals.col(i))))));
    }
    // What the orientation votes need: normals across the axis (z).
    tilt_every.push_back(std::asin(std::abs(every.normals(2, i))));
    tilt_shared.push_back(std::asin(std::abs(shared.normals(2, i))));
    EXPECT_GE(shared.weights(i), 0.f);
  }
  const auto median = [](std::vector<float> v) {
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
    return v[v.size() / 2];
  };
  const float deg = 3.14159265f / 180.f;
  // Measured: tilt 0.71 deg (every) and 0.69 deg (shared); a shared normal 2.7 deg from the
  // point's own (it turns about the axis by the distance to its centre over the radius, which
  // leaves the orientation votes alone).
  EXPECT_LT(median(tilt_every), 1.5f * deg);
  EXPECT_LT(median(tilt_shared), median(tilt_every) + 0.3f * deg);
  EXPECT_LT(median(apart), 5.f * deg);
  EXPECT_THROW(facyl::estimatePointCues(pts, 0.1f, 64, none, 0), std::invalid_argument);
}

TEST(Polygon, HullsDropTheirInsideFirst)
{
  // A disc's pixels, 2 mm apart: most lie inside the polygon of the extremes and go; every
  // vertex of the hull stays, and what went lies inside it.
  std::vector<Eigen::Vector2f> disc;
  for (float x = -0.05f; x <= 0.05f; x += 0.002f)
    for (float y = -0.05f; y <= 0.05f; y += 0.002f)
      if (x * x + y * y <= 0.05f * 0.05f)
        disc.emplace_back(x + 0.3f, y - 0.1f);
  std::vector<Eigen::Vector2f> rest = disc;
  facyl::dropInteriorPoints(rest);
  EXPECT_LT(rest.size(), disc.size() / 5);
  const auto hull = facyl::convexHull2D(disc);
  // Every vertex of the hull survived, and the hull of what is left is the same polygon.
  for (const auto& v : hull)
    EXPECT_NE(std::find(rest.begin(), rest.end(), v), rest.end());
  std::vector<Eigen::Vector2f> inner;
  for (const auto& p : disc)
    if (std::find(rest.begin(), rest.end(), p) == rest.end())
      inner.push_back(p);
  ASSERT_FALSE(inner.empty());
  for (const auto& q : inner)
    EXPECT_TRUE(facyl::insideConvexBy(q, hull, 0.f));
  // A square's corners and a point inside: too few points to bother.
  std::vector<Eigen::Vector2f> few = {{0.f, 0.f}, {1.f, 0.f}, {1.f, 1.f}, {0.f, 1.f}, {0.5f, 0.5f}};
  facyl::dropInteriorPoints(few);
  EXPECT_EQ(few.size(), 5u);
  EXPECT_EQ(facyl::convexHull2D(few).size(), 4u);
}
