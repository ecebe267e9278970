/*
 * facyl: reliability. Inputs that crashed or gave silent wrong answers (narrow organized
 * clouds, frames stored in world coordinates, high resolutions, missing pixels), the parallel
 * loop, and thread safety and determinism of the pipeline.
 */
#include "test_helpers.h"
#include <facyl/tools/cli.h>
#include <facyl/tools/detect_json.h>
#include <facyl/tools/json_writer.h>

#include <facyl/features/parallel.h>
#include <facyl/recognition/tabletop_cylinder_recognizer.h>
#include <facyl/simulation/random.h>
#include <facyl/simulation/tabletop_scene.h>

#include <pcl/common/transforms.h>
#include <pcl/console/print.h>
#include <pcl/io/pcd_io.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <thread>

namespace {

using Cloud = pcl::PointCloud<pcl::PointXYZRGBA>;

Cloud::Ptr
defaultScene()
{
  Cloud::Ptr cloud(new Cloud);
  EXPECT_EQ(pcl::io::loadPCDFile(FACYL_SOURCE_DIR "/data/default_scene.pcd", *cloud), 0);
  return cloud;
}

std::vector<facyl::RecognizedObject>
recognize(const Cloud::ConstPtr& cloud, bool* ok = nullptr)
{
  facyl::TabletopCylinderRecognizer<pcl::PointXYZRGBA> rec;
  rec.setInputCloud(cloud);
  std::vector<facyl::RecognizedObject> objects;
  const bool found = rec.recognize(objects);
  if (ok)
    *ok = found;
  return objects;
}

/** The pixels [u0, u0 + w) x [v0, v0 + h) of an organized cloud. */
Cloud::Ptr
crop(const Cloud& in, int u0, int v0, int w, int h)
{
  Cloud::Ptr out(new Cloud);
  out->width = static_cast<std::uint32_t>(w);
  out->height = static_cast<std::uint32_t>(h);
  out->is_dense = false;
  for (int v = v0; v < v0 + h; ++v)
    for (int u = u0; u < u0 + w; ++u)
      out->push_back(in.at(u, v));
  out->width = static_cast<std::uint32_t>(w);
  out->height = static_cast<std::uint32_t>(h);
  return out;
}

/** Every field the JSON of facyl_detect reports (but the timing), to compare runs bit for bit. */
std::string
fingerprint(const std::vector<facyl::RecognizedObject>& objects)
{
  std::string s;
  for (std::size_t k = 0; k < objects.size(); ++k)
    s +=
      facyl_cli::dumpJson(facyl_cli::objectJson(k, objects[k], facyl::CylinderDecision{})) + "\n";
  return s;
}

} // namespace

// ------------------------------------------------------------------ narrow organized clouds

TEST(Reliability, NarrowOrganizedCloudsAreSearchedAsPointSets)
{
  // Before: IntegralImageNormalEstimation on a grid of 3 x 120 cells crashed.
  const Cloud::Ptr scene = defaultScene();
  const int sizes[][2] = {{12, 480}, {640, 12}, {640, 5}, {8, 64}, {1, 2}, {3, 3}, {63, 480}};
  for (const auto& s : sizes) {
    const Cloud::Ptr part = crop(*scene, 320 - s[0] / 2, 240 - s[1] / 2, s[0], s[1]);
    bool ok = false;
    const auto objects = recognize(part, &ok);
    SCOPED_TRACE(std::to_string(s[0]) + " x " + std::to_string(s[1]));
    for (const auto& o : objects)
      for (const auto i : o.cluster.indices.indices)
        ASSERT_LT(static_cast<std::size_t>(i), part->size());
  }
  // The same points as 8 rows (the layout of an 8-ring LiDAR scan) give the table and the
  // objects (as a point set).
  Cloud::Ptr rings(new Cloud(*scene));
  rings->width = static_cast<std::uint32_t>(scene->size() / 8);
  rings->height = 8;
  bool ok = false;
  const auto objects = recognize(rings, &ok);
  EXPECT_TRUE(ok);
  EXPECT_GE(
    std::count_if(objects.begin(), objects.end(), [](const auto& o) { return o.is_cylinder; }), 3);
}

// --------------------------------------------------------------------------- sensor pose

TEST(Reliability, AFrameInWorldCoordinatesGivesTheSameAnswer)
{
  // The PCD VIEWPOINT (sensor_origin_, sensor_orientation_) of a frame stored in world
  // coordinates. Before: the table normal pointed down, 0 objects, no error.
  const Cloud::Ptr scene = defaultScene();
  const Eigen::Affine3f pose = Eigen::Translation3f(0.3f, -0.5f, 1.2f) *
                               Eigen::AngleAxisf(0.7f, Eigen::Vector3f::UnitZ()) *
                               Eigen::AngleAxisf(-2.0f, Eigen::Vector3f::UnitX());
  Cloud::Ptr world(new Cloud);
  pcl::transformPointCloud(*scene, *world, pose);
  world->sensor_origin_ << pose.translation(), 0.f;
  world->sensor_orientation_ = Eigen::Quaternionf(pose.linear());

  facyl::TabletopCylinderRecognizer<pcl::PointXYZRGBA> a, b;
  a.setInputCloud(scene);
  b.setInputCloud(world);
  std::vector<facyl::RecognizedObject> in_sensor, in_world;
  ASSERT_TRUE(a.recognize(in_sensor));
  ASSERT_TRUE(b.recognize(in_world));
  ASSERT_EQ(in_sensor.size(), in_world.size());
  ASSERT_GE(in_sensor.size(), 5u);
  for (std::size_t k = 0; k < in_sensor.size(); ++k) {
    const auto &s = in_sensor[k], &w = in_world[k];
    EXPECT_EQ(s.cluster.indices.indices, w.cluster.indices.indices);
    EXPECT_EQ(s.is_cylinder, w.is_cylinder);
    EXPECT_LT((pose * s.cluster.centroid - w.cluster.centroid).norm(), 1e-4f);
    if (s.evidence.fitted) {
      EXPECT_NEAR(s.cylinder.radius, w.cylinder.radius, 1e-5f);
      EXPECT_LT((pose.linear() * s.cylinder.axis - w.cylinder.axis).norm(), 1e-4f);
      EXPECT_LT((pose * s.cylinder.point_on_axis - w.cylinder.point_on_axis).norm(), 1e-4f);
    }
  }
  // The table: its normal points up in the world (towards the sensor) and is the same plane.
  const auto& c = b.getTableCoefficients().values;
  ASSERT_EQ(c.size(), 4u);
  const Eigen::Vector4f mine(c[0], c[1], c[2], c[3]);
  const auto& r = a.getTableCoefficients().values;
  const Eigen::Vector4f expected =
    facyl::transformPlane(Eigen::Vector4f(r[0], r[1], r[2], r[3]), pose);
  EXPECT_LT((mine - expected).norm(), 1e-4f);
  EXPECT_GT(mine.head<3>().dot(pose.translation()) + mine[3], 0.f);
  EXPECT_TRUE(b.getTableFrame().isApprox(pose * a.getTableFrame(), 1e-4f));
  // The cloud is left as it was given.
  EXPECT_EQ(b.getInputCloud(), world);
}

/** The default scene with every 97th point beyond kMaxCoordinate (\a garbage), or NaN there
 * (\a missing); both unorganized (one row) when \a organized is false. */
void
hugeCoordinates(bool organized, Cloud::Ptr& garbage, Cloud::Ptr& missing)
{
  const Cloud::Ptr scene = defaultScene();
  garbage.reset(new Cloud(*scene));
  missing.reset(new Cloud(*scene));
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (std::size_t i = 0; i < scene->size(); i += 97) {
    (*garbage)[i].x = (i % 2 ? 3.3e38f : -2e7f);
    (*garbage)[i].y = 1.f;
    (*garbage)[i].z = (i % 3 ? 3.2e38f : 1.f);
    (*missing)[i].x = (*missing)[i].y = (*missing)[i].z = nan;
  }
  if (!organized)
    for (auto* c : {garbage.get(), missing.get()}) {
      c->width = static_cast<std::uint32_t>(c->size());
      c->height = 1;
    }
}

TEST(Reliability, PointsWithHugeCoordinatesAreTreatedAsMissing)
{
  // Found by fuzz_pcd: finite points near FLT_MAX made FLANN's k-d tree abort (an assertion in
  // middleSplit) in the unorganized plane search. Now they count as missing pixels: the answer
  // is the one for the same frame with those pixels NaN, organized or not.
  for (const bool organized : {true, false}) {
    SCOPED_TRACE(organized ? "organized" : "unorganized");
    Cloud::Ptr a, b;
    hugeCoordinates(organized, a, b);
    EXPECT_EQ(facyl::countFarPoints(*a), (a->size() + 96) / 97);
    EXPECT_EQ(facyl::countFarPoints(*b), 0u);
    bool ok_a = false, ok_b = false;
    const auto with_garbage = recognize(a, &ok_a);
    const auto with_holes = recognize(b, &ok_b);
    EXPECT_TRUE(ok_a);
    EXPECT_EQ(ok_a, ok_b);
    EXPECT_EQ(fingerprint(with_garbage), fingerprint(with_holes));
    EXPECT_GE(with_garbage.size(), 5u);
  }
}

TEST(Reliability, DegenerateCloudsFailWithOneLine)
{
  // Identical or collinear points hold no plane: PCL's plane RANSAC printed "Sample points
  // too similar or collinear!" for each of its 1,000 tries, and the frame came out as one
  // without a table. Now the segmentation says what is wrong, once, and fails.
  const pcl::console::VERBOSITY_LEVEL level = pcl::console::getVerbosityLevel();
  pcl::console::setVerbosityLevel(pcl::console::L_ERROR); // as the tools run
  for (const bool collinear : {false, true}) {
    SCOPED_TRACE(collinear ? "collinear" : "identical");
    Cloud::Ptr cloud(new Cloud);
    for (int i = 0; i < (collinear ? 50 : 10); ++i) {
      pcl::PointXYZRGBA p;
      const float t = collinear ? 0.01f * static_cast<float>(i) : 0.f;
      p.getVector3fMap() = Eigen::Vector3f(0.1f + t, 0.2f + 2.f * t, 1.f + 0.5f * t);
      cloud->push_back(p);
    }
    testing::internal::CaptureStderr();
    bool ok = true;
    recognize(cloud, &ok);
    const std::string err = testing::internal::GetCapturedStderr();
    EXPECT_FALSE(ok);
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err.substr(0, 500);
    EXPECT_NE(err.find("lie on one line"), std::string::npos) << err.substr(0, 500);
  }
  // A table with a line of points above it: the table is found; the line, left over, is no
  // second plane and makes no noise.
  Cloud::Ptr cloud(new Cloud);
  facyl::Random rng(5);
  for (int i = 0; i < 4000; ++i) {
    pcl::PointXYZRGBA p;
    p.getVector3fMap() = Eigen::Vector3f(rng.uniform(-0.5f, 0.5f), 0.4f, rng.uniform(0.8f, 1.8f));
    cloud->push_back(p);
  }
  for (int i = 0; i < 400; ++i) {
    pcl::PointXYZRGBA p;
    p.getVector3fMap() = Eigen::Vector3f(0.001f * static_cast<float>(i), 0.f, 1.2f);
    cloud->push_back(p);
  }
  testing::internal::CaptureStderr();
  recognize(cloud);
  const std::string err = testing::internal::GetCapturedStderr();
  EXPECT_EQ(err.find("collinear"), std::string::npos) << err.substr(0, 500);
  pcl::console::setVerbosityLevel(level);
}

TEST(Reliability, TheSegmentationTreatsHugeCoordinatesAsMissing)
{
  // The search meets such points in a pass it makes anyway, stops, and runs again on a copy
  // without them: the segments of the frame with those pixels NaN. A segmentation reused
  // across the two clouds, in both orders, keeps nothing of the stopped run.
  for (const bool organized : {true, false}) {
    SCOPED_TRACE(organized ? "organized" : "unorganized");
    Cloud::Ptr garbage, missing;
    hugeCoordinates(organized, garbage, missing);
    facyl::TabletopSegmentation<pcl::PointXYZRGBA> seg;
    std::vector<std::vector<std::vector<pcl::index_t>>> runs;
    std::vector<std::vector<float>> tables;
    for (const auto& cloud : {garbage, missing, garbage}) {
      seg.setInputCloud(cloud);
      std::vector<facyl::TabletopCluster> clusters;
      ASSERT_TRUE(seg.segment(clusters));
      runs.emplace_back();
      for (const auto& c : clusters)
        runs.back().push_back(c.indices.indices);
      tables.push_back(seg.getTableCoefficients().values);
    }
    EXPECT_GE(runs[0].size(), 5u);
    EXPECT_EQ(runs[0], runs[1]);
    EXPECT_EQ(runs[2], runs[1]);
    // The copy's results are moved back by the identity (rounding in the last bits).
    for (const std::size_t r : {0, 2}) {
      ASSERT_EQ(tables[r].size(), 4u);
      ASSERT_EQ(tables[1].size(), 4u);
      for (std::size_t k = 0; k < 4; ++k)
        EXPECT_NEAR(tables[r][k], tables[1][k], 1e-6f);
    }
  }
}

TEST(Reliability, AViewerOrientationThatPutsThePointsBehindTheSensorIsIgnored)
{
  // Some PCL files (grabber frames) store VIEWPOINT 0 0 0 0 1 0 0, a 180-degree turn about x
  // made for a viewer, with the points in the camera's frame.
  const Cloud::Ptr scene = defaultScene();
  Cloud::Ptr flagged(new Cloud(*scene));
  flagged->sensor_orientation_ = Eigen::Quaternionf(0.f, 1.f, 0.f, 0.f);
  EXPECT_TRUE(facyl::plausibleSensorPose(*flagged).isApprox(Eigen::Affine3f::Identity()));
  EXPECT_EQ(fingerprint(recognize(scene)), fingerprint(recognize(flagged)));
  // The same turn applied to the points is honoured.
  Cloud::Ptr turned(new Cloud);
  const Eigen::Affine3f turn(Eigen::AngleAxisf(static_cast<float>(M_PI), Eigen::Vector3f::UnitX()));
  pcl::transformPointCloud(*scene, *turned, turn);
  turned->sensor_orientation_ = Eigen::Quaternionf(turn.linear());
  EXPECT_TRUE(facyl::plausibleSensorPose(*turned).linear().isApprox(turn.linear(), 1e-5f));
}

TEST(Reliability, SensorPoseHelpers)
{
  const Eigen::Vector4f plane(0.f, 0.f, 1.f, -2.f); // z = 2
  const Eigen::Affine3f t =
    Eigen::Translation3f(1.f, 2.f, 3.f) * Eigen::AngleAxisf(0.5f, Eigen::Vector3f::UnitX());
  const Eigen::Vector4f moved = facyl::transformPlane(plane, t);
  const Eigen::Vector3f on = t * Eigen::Vector3f(5.f, -1.f, 2.f);
  EXPECT_NEAR(moved.head<3>().dot(on) + moved[3], 0.f, 1e-5f);
  EXPECT_NEAR(moved.head<3>().norm(), 1.f, 1e-6f);
  EXPECT_TRUE(facyl::isIdentityPose(Eigen::Affine3f::Identity()));
  EXPECT_FALSE(facyl::isIdentityPose(t));
  // A zero or NaN quaternion is no rotation; a NaN origin no translation.
  EXPECT_TRUE(facyl::isIdentityPose(facyl::sensorPose(Eigen::Vector4f(NAN, 0.f, 0.f, 0.f),
                                                      Eigen::Quaternionf(0.f, 0.f, 0.f, 0.f))));
}

// ---------------------------------------------------------------- resolution and holes

TEST(Reliability, TheTableIsFoundAtHighResolutionAndWithMissingPixels)
{
  // Before: at 2000 x 1500, 4 of 6 frames found no table (the plane search was tuned in VGA
  // pixels); from 4 % missing pixels, "no table found".
  struct Case {
    int width, height;
    float dropout;
  };
  for (const Case c : {Case{2000, 1500, 0.002f}, Case{640, 480, 0.05f}, Case{1280, 960, 0.1f}}) {
    for (std::uint64_t seed : {1000u, 1003u}) {
      facyl::TabletopSceneParameters p;
      p.seed = seed;
      p.camera.fx *= static_cast<float>(c.width) / 640.f;
      p.camera.fy *= static_cast<float>(c.height) / 480.f;
      p.camera.cx = (c.width - 1) / 2.f;
      p.camera.cy = (c.height - 1) / 2.f;
      p.camera.width = c.width;
      p.camera.height = c.height;
      p.sensor.dropout = c.dropout;
      const facyl::RenderedScene s = facyl::simulateTabletopScene(p);
      Cloud::Ptr cloud(new Cloud(s.cloud));
      facyl::TabletopCylinderRecognizer<pcl::PointXYZRGBA> rec;
      rec.setInputCloud(cloud);
      std::vector<facyl::RecognizedObject> objects;
      SCOPED_TRACE(std::to_string(c.width) + " x " + std::to_string(c.height) + ", dropout " +
                   std::to_string(c.dropout) + ", seed " + std::to_string(seed));
      ASSERT_TRUE(rec.recognize(objects));
      EXPECT_TRUE(rec.tableFound());
      // The table: the plane z = 0 of the scene, seen from the camera.
      const auto& tc = rec.getTableCoefficients().values;
      const Eigen::Vector3f n(tc[0], tc[1], tc[2]);
      EXPECT_GT(n.dot(s.table_plane.head<3>()), 0.99f);
      EXPECT_NEAR(tc[3], s.table_plane[3], 0.01f);
      std::size_t cylinders = 0, found = 0;
      for (const auto& o : s.scene.objects)
        cylinders += o.cls == facyl::SceneClass::Cylinder;
      for (const auto& o : objects)
        found += o.is_cylinder;
      EXPECT_GE(found + 1, cylinders);
    }
  }
}

// ------------------------------------------------------------------------ parallel loop

TEST(Reliability, ShortLoopsTakeHelpersOnlyWhereCoresAreIdle)
{
  // The rule: the helpers only where the runnable tasks (the caller among them) leave cores.
  EXPECT_EQ(facyl::threadsForIdleCores(2, 1, 2), 2); // a quiet machine
  EXPECT_EQ(facyl::threadsForIdleCores(2, 2, 2), 1); // one busy process beside
  EXPECT_EQ(facyl::threadsForIdleCores(2, 3, 2), 1); // two
  EXPECT_EQ(facyl::threadsForIdleCores(4, 1, 4), 4);
  EXPECT_EQ(facyl::threadsForIdleCores(4, 2, 4), 1);
  EXPECT_EQ(facyl::threadsForIdleCores(2, -1, 2), 2); // the count unknown
  EXPECT_EQ(facyl::threadsForIdleCores(1, 1, 8), 1);
  // On this machine: a count of at least this thread, or unknown; one of the two answers.
  const int running = facyl::runnableTasks();
  EXPECT_TRUE(running == -1 || running >= 1);
  const int now = facyl::threadsForIdleCores(2);
  EXPECT_TRUE(now == 1 || now == 2);
  EXPECT_EQ(facyl::threadsForIdleCores(1), 1);
}

TEST(Reliability, ParallelForCoversEveryItemOnceAndRethrows)
{
  for (const int threads : {0, 1, 2, 8}) {
    std::vector<int> hits(10007, 0);
    facyl::parallelFor(hits.size(), threads, 100, [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i)
        ++hits[i];
    });
    EXPECT_EQ(std::count(hits.begin(), hits.end(), 1), static_cast<long>(hits.size()));
  }
  EXPECT_EQ(facyl::parallelWorkers(100, 8, 256), 1);
  EXPECT_EQ(facyl::parallelWorkers(1000, 8, 256), 4);
  EXPECT_EQ(facyl::parallelWorkers(0, 8, 256), 1);
  EXPECT_THROW(facyl::parallelFor(5000, 4, 10,
                                  [](std::size_t b, std::size_t) {
                                    if (b == 2500)
                                      throw std::runtime_error("block 2500");
                                  }),
               std::runtime_error);
}

TEST(Reliability, ParallelLoopsNestAndRunFromManyThreadsAtOnce)
{
  // Loops within loops (the recognizer fits clusters in parallel and each fit runs its retries
  // in parallel) and loops started by several threads at once share the sleeping helpers; every
  // item is still done once, and each block's worker number is in [0, parallelWorkers).
  constexpr std::size_t kOuter = 24, kInner = 1000;
  const auto nested = [&](int threads) {
    std::vector<int> hits(kOuter * kInner, 0);
    std::atomic<bool> numbered{true};
    const int outer_workers = facyl::parallelWorkers(kOuter, threads, 1);
    facyl::parallelForWorkers(kOuter, threads, 1, [&](std::size_t b, std::size_t e, int w) {
      numbered = numbered && w >= 0 && w < outer_workers;
      for (std::size_t o = b; o < e; ++o)
        facyl::parallelForWorkers(kInner, threads, 64, [&](std::size_t ib, std::size_t ie, int iw) {
          numbered = numbered && iw >= 0 && iw < facyl::parallelWorkers(kInner, threads, 64);
          for (std::size_t i = ib; i < ie; ++i)
            ++hits[o * kInner + i];
        });
    });
    EXPECT_TRUE(numbered.load());
    return static_cast<std::size_t>(std::count(hits.begin(), hits.end(), 1));
  };
  EXPECT_EQ(nested(4), kOuter * kInner);
  std::vector<std::size_t> done(6, 0);
  std::vector<std::thread> callers;
  for (std::size_t t = 0; t < done.size(); ++t)
    callers.emplace_back([&, t] {
      for (int round = 0; round < 20; ++round)
        done[t] += nested(3) == kOuter * kInner;
    });
  for (auto& c : callers)
    c.join();
  for (const std::size_t d : done)
    EXPECT_EQ(d, 20u);
}

// ------------------------------------------------------ thread safety and determinism

TEST(Reliability, EightThreadsWithTheirOwnRecognizersMatchTheSerialRun)
{
  const Cloud::Ptr scene = defaultScene();
  const std::string serial = fingerprint(recognize(scene));
  ASSERT_FALSE(serial.empty());
  EXPECT_EQ(fingerprint(recognize(scene)), serial); // same seed, same answer
  std::vector<std::string> results(8);
  std::vector<std::thread> pool;
  for (std::size_t t = 0; t < results.size(); ++t)
    pool.emplace_back([&, t]() {
      for (int run = 0; run < 2; ++run)
        results[t] += fingerprint(recognize(scene));
    });
  for (auto& t : pool)
    t.join();
  for (const auto& r : results)
    EXPECT_EQ(r, serial + serial);
}

TEST(Reliability, CuesDoNotDependOnTheNumberOfThreads)
{
  const Cloud::Ptr scene = defaultScene();
  pcl::PointCloud<pcl::PointXYZ>::Ptr points(new pcl::PointCloud<pcl::PointXYZ>);
  for (std::size_t i = 0; i < scene->size(); i += 7)
    if (pcl::isFinite((*scene)[i]))
      points->push_back(pcl::PointXYZ((*scene)[i].x, (*scene)[i].y, (*scene)[i].z));
  std::vector<pcl::PointCloud<facyl::NormalCurvature>> out(3);
  const unsigned threads[] = {1, 3, 8};
  for (int k = 0; k < 3; ++k) {
    facyl::NormalCurvatureEstimation<pcl::PointXYZ> ne;
    ne.setInputCloud(points);
    ne.setKSearch(16);
    ne.setNumberOfThreads(threads[k]);
    ne.compute(out[k]);
  }
  // Every field, bit for bit (NaN included; the structure's padding is not compared).
  const auto bits = [](const facyl::NormalCurvature& c) {
    const float f[] = {c.normal_x,
                       c.normal_y,
                       c.normal_z,
                       c.curvature,
                       c.principal_curvature_x,
                       c.principal_curvature_y,
                       c.principal_curvature_z,
                       c.pc1,
                       c.pc2};
    std::array<std::uint32_t, 9> b;
    std::memcpy(b.data(), f, sizeof f);
    return b;
  };
  for (int k = 1; k < 3; ++k) {
    ASSERT_EQ(out[k].size(), out[0].size());
    std::size_t differ = 0;
    for (std::size_t i = 0; i < out[0].size(); ++i)
      differ += bits(out[k][i]) != bits(out[0][i]);
    EXPECT_EQ(differ, 0u) << threads[k] << " threads";
  }
}

// --------------------------------------------------------------- option parsing

TEST(Reliability, IntegerOptionsNeitherWrapNorSaturate)
{
  const auto parse = [](std::vector<std::string> words, long long lo, long long hi) {
    std::vector<char*> argv{const_cast<char*>("tool")};
    for (auto& w : words)
      argv.push_back(w.data());
    const facyl_cli::Arguments args(static_cast<int>(argv.size()), argv.data(), {"--n"}, {});
    return args.integer("--n", 7, lo, hi);
  };
  EXPECT_EQ(parse({"--n", "12"}, 3, 1000), 12);
  EXPECT_EQ(parse({}, 3, 1000), 7);
  EXPECT_THROW(parse({"--n", "4294967299"}, 3, 1000), std::invalid_argument);
  EXPECT_THROW(parse({"--n", "99999999999999999999"}, 0, facyl_cli::kMaxSeed),
               std::invalid_argument);
  EXPECT_THROW(parse({"--n", "-1"}, 0, 10), std::invalid_argument);
  EXPECT_THROW(parse({"--n", " 5"}, 0, 10), std::invalid_argument);
  EXPECT_THROW(parse({"--n", "5x"}, 0, 10), std::invalid_argument);
  EXPECT_THROW(parse({"--n", "1e3"}, 0, 10000), std::invalid_argument);
  EXPECT_EQ(parse({"--n", "-3"}, -5, 5), -3);
  // JSON strings stay valid UTF-8 whatever bytes a file name or a corrupt header holds.
  EXPECT_EQ(facyl_cli::dumpJson(facyl_cli::Json("a\xff"
                                                "b")),
            "\"a\xef\xbf\xbd"
            "b\"");
  EXPECT_EQ(facyl_cli::dumpJson(facyl_cli::Json("\xc3\xa9")), "\"\xc3\xa9\"");
  // Numbers read as %g writes them: 6 significant digits, integral ones without a point.
  EXPECT_EQ(facyl_cli::dumpJson(facyl_cli::Json::array(
              {facyl_cli::jsonNumber(0.0362165123), facyl_cli::jsonNumber(3.0),
               facyl_cli::jsonNumber(1.5e-5), facyl_cli::jsonNumber(NAN)})),
            "[0.0362165,3,1.5e-05,null]");
}
