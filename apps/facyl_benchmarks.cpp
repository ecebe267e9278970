/*
 * facyl_benchmarks: speed of the estimator, of the per-point cues and of whole frames
 * (Google Benchmark).
 * Run: ./build/apps/facyl_benchmarks [--benchmark_filter=REGEX]
 * BM_Frame runs the tabletop recognizer with the shipped classifier on the bundled scene, on
 * simulated scenes at 640 x 480 and at 1280 x 720 (spread and realistic layouts) and, when the
 * shared data is there (FACYL_REAL_DATA, default ../shared/data/real beside the sources), on
 * every 4th mOSD learn frame and on every rgbd frame of other sensors; counters: the stages in
 * ms per frame.
 */
#include <facyl/features/normal_curvature_estimation.h>
#include <facyl/features/point_cues.h>
#include <facyl/recognition/cylinder_classifier.h>
#include <facyl/recognition/tabletop_cylinder_recognizer.h>
#include <facyl/sample_consensus_alt/hough_cylinder_estimation.h>
#include <facyl/segmentation/tabletop_geometry.h>
#include <facyl/simulation/cylinder_simulation.h>
#include <facyl/simulation/random.h>
#include <facyl/simulation/tabletop_scene.h>
#include <facyl/tracking/cylinder_tracker.h>

#include <pcl/common/io.h>
#include <pcl/features/normal_3d.h>
#include <pcl/features/principal_curvatures.h>
#include <pcl/io/pcd_io.h>
#include <pcl/sample_consensus/method_types.h>
#include <pcl/sample_consensus/model_types.h>
#include <pcl/segmentation/sac_segmentation.h>

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <memory>
#include <string>
#include <utility>

namespace {

using Cloud = pcl::PointCloud<pcl::PointXYZ>;
using Cues = pcl::PointCloud<facyl::NormalCurvature>;

struct Scene {
  Cloud::Ptr cloud{new Cloud};
  Cues::Ptr cues{new Cues};
};

/** |P| lateral points plus \a lid_ratio times as many lid points (outliers, eq. 5), noise
 * \a noise of the radius, r = 0.3 m. */
Scene
makeScene(std::size_t lateral, int k = facyl::kDefaultNeighbours, float noise = 0.01f,
          float lid_ratio = 1.f)
{
  facyl::CylinderSimulationParameters p;
  p.radius = 0.3f;
  p.height = 1.f;
  p.lateral_points = lateral;
  p.lid_ratio = lid_ratio;
  p.noise = noise;
  p.axis = Eigen::Vector3f(0.3f, 0.2f, 1.f);
  p.seed = 1;
  const auto sim = facyl::simulateCylinder(p);
  Scene s;
  for (const auto& q : sim.cloud)
    s.cloud->push_back(pcl::PointXYZ(q.x, q.y, q.z));
  facyl::NormalCurvatureEstimation<pcl::PointXYZ> ne;
  ne.setInputCloud(s.cloud);
  ne.setKSearch(k);
  ne.compute(*s.cues);
  return s;
}

using Hough = facyl::HoughCylinderEstimation<pcl::PointXYZ, facyl::NormalCurvature>;

/** Times \a hough's segment() on \a s, the accumulator drawn once before. */
void
timeFits(benchmark::State& state, const Scene& s, Hough& hough)
{
  hough.setInputCloud(s.cloud);
  hough.setInputNormals(s.cues);
  std::vector<facyl::CylinderModel> models;
  hough.segment(models); // draws the accumulator once
  for (auto _ : state) {
    hough.segment(models);
    benchmark::DoNotOptimize(models);
  }
  state.counters["points"] = static_cast<double>(s.cloud->size());
}

void
BM_Fit(benchmark::State& state, facyl::VotingMode mode)
{
  Hough hough;
  hough.setVotingMode(mode);
  hough.setNumberOfOrientations(static_cast<std::size_t>(state.range(1)));
  timeFits(state, makeScene(static_cast<std::size_t>(state.range(0))), hough);
  state.counters["N_d"] = static_cast<double>(state.range(1));
}
// Default settings on 900 + 900 points, then growth with points and with N_d.
BENCHMARK_CAPTURE(BM_Fit, soft_curvature, facyl::VotingMode::SoftCurvature)
  ->Args({900, 450})
  ->Args({225, 450})
  ->Args({450, 450})
  ->Args({1800, 450})
  ->Args({3600, 450})
  ->Args({7200, 450})
  ->Args({900, 100})
  ->Args({900, 900})
  ->Args({900, 1800})
  ->Args({900, 3600})
  ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Fit, rabbani, facyl::VotingMode::Rabbani)
  ->Args({900, 450})
  ->Unit(benchmark::kMillisecond);

/** Default settings on 900 points of a cylinder without lids at the noise of issue 17's levels
 * (percent of the radius): the cues are then noise, and the fit settles its candidates on the
 * points (nothing lies beside this cylinder, so no coarse cues; see docs/benchmark.md, "Fit time
 * at high noise"). */
void
BM_FitAtNoise(benchmark::State& state)
{
  Hough hough;
  timeFits(
    state,
    makeScene(900, facyl::kDefaultNeighbours, 0.01f * static_cast<float>(state.range(0)), 0.f),
    hough);
}
BENCHMARK(BM_FitAtNoise)->Arg(1)->Arg(10)->Arg(20)->Arg(30)->Unit(benchmark::kMillisecond);

/** The points' own noise (estimateLocalNoise: 128 neighbourhoods of 12 points, found on a
 * grid), as a fit measures it once its spread looks like noise: |P| / 2 lateral points and as
 * many lid points. */
void
BM_LocalNoise(benchmark::State& state)
{
  const Scene s = makeScene(static_cast<std::size_t>(state.range(0)) / 2);
  Eigen::Matrix3Xf points(3, static_cast<Eigen::Index>(s.cloud->size()));
  for (std::size_t i = 0; i < s.cloud->size(); ++i)
    points.col(static_cast<Eigen::Index>(i)) = (*s.cloud)[i].getVector3fMap();
  for (auto _ : state)
    benchmark::DoNotOptimize(facyl::estimateLocalNoise(points, 12, 128));
  state.counters["points"] = static_cast<double>(points.cols());
}
BENCHMARK(BM_LocalNoise)->Arg(1800)->Arg(7200)->Unit(benchmark::kMicrosecond);

void
BM_NormalsAndCurvatures(benchmark::State& state)
{
  const Scene s = makeScene(static_cast<std::size_t>(state.range(0)) / 2);
  facyl::NormalCurvatureEstimation<pcl::PointXYZ> ne;
  ne.setInputCloud(s.cloud);
  ne.setKSearch(static_cast<int>(state.range(1)));
  ne.setNumberOfThreads(static_cast<unsigned>(state.range(2)));
  Cues out;
  for (auto _ : state) {
    ne.compute(out);
    benchmark::DoNotOptimize(out);
  }
  state.counters["points"] = static_cast<double>(s.cloud->size());
}
// points, k, threads (0: all cores)
BENCHMARK(BM_NormalsAndCurvatures)
  ->Args({1800, 16, 1})
  ->Args({1800, 16, 0})
  ->Args({1800, 10, 0})
  ->Args({7200, 16, 0})
  ->Unit(benchmark::kMillisecond);

/** An organized view of a can (r 6 cm, axis along the image's columns, 0.8 m away; focal
 * length 525 px): \a rows image rows of 84 pixels, about 79 of them on the can (NaN beside),
 * depth noise 1% of the radius. */
Cloud::Ptr
organizedCan(int rows)
{
  const float f = 525.f, r = 0.06f, z0 = 0.8f, noise = 0.01f * r;
  const int width = 84;
  facyl::Random random(1);
  Cloud::Ptr cloud(new Cloud(width, static_cast<std::uint32_t>(rows)));
  for (int v = 0; v < rows; ++v)
    for (int u = 0; u < width; ++u) {
      // The ray t (x, y, 1) meets x^2 + (z - z0)^2 = r^2 first at the smaller root.
      const float x = (static_cast<float>(u) - 0.5f * width) / f;
      const float y = (static_cast<float>(v) - 0.5f * static_cast<float>(rows)) / f;
      const float a = x * x + 1.f, b = -2.f * z0, c = z0 * z0 - r * r;
      const float disc = b * b - 4.f * a * c;
      pcl::PointXYZ& p = cloud->at(u, v);
      if (disc < 0.f) {
        p.x = p.y = p.z = std::numeric_limits<float>::quiet_NaN();
        continue;
      }
      const float t = (-b - std::sqrt(disc)) / (2.f * a) + noise * random.normal();
      p = pcl::PointXYZ(t * x, t * y, t);
    }
  cloud->is_dense = false;
  return cloud;
}

void
BM_NormalsAndCurvaturesOrganized(benchmark::State& state)
{
  // The can's pixels: 23 rows hold about 1,800.
  const Cloud::Ptr cloud = organizedCan(static_cast<int>(state.range(0)) / 79);
  facyl::NormalCurvatureEstimation<pcl::PointXYZ> ne;
  ne.setInputCloud(cloud);
  ne.setKSearch(static_cast<int>(state.range(1)));
  ne.setNumberOfThreads(static_cast<unsigned>(state.range(2)));
  ne.setImageNeighbourhoods(state.range(3) != 0);
  Cues out;
  for (auto _ : state) {
    ne.compute(out);
    benchmark::DoNotOptimize(out);
  }
  state.counters["points"] = static_cast<double>(std::count_if(
    cloud->begin(), cloud->end(), [](const pcl::PointXYZ& p) { return pcl::isFinite(p); }));
}
// points, k, threads (0: all cores), image neighbourhoods (0: the kd-tree)
BENCHMARK(BM_NormalsAndCurvaturesOrganized)
  ->Args({1800, 16, 1, 1})
  ->Args({1800, 16, 0, 1})
  ->Args({1800, 16, 1, 0})
  ->Args({1800, 16, 0, 0})
  ->Unit(benchmark::kMillisecond);

void
BM_PclNormalsThenCurvatures(benchmark::State& state)
{
  // What a PCL user runs today for the same cues: two passes, two neighbourhood searches.
  const Scene s = makeScene(static_cast<std::size_t>(state.range(0)) / 2);
  pcl::PointCloud<pcl::Normal>::Ptr normals(new pcl::PointCloud<pcl::Normal>);
  pcl::PointCloud<pcl::PrincipalCurvatures> curvatures;
  for (auto _ : state) {
    pcl::NormalEstimation<pcl::PointXYZ, pcl::Normal> ne;
    ne.setInputCloud(s.cloud);
    ne.setKSearch(facyl::kDefaultNeighbours);
    ne.compute(*normals);
    pcl::PrincipalCurvaturesEstimation<pcl::PointXYZ, pcl::Normal> pce;
    pce.setInputCloud(s.cloud);
    pce.setInputNormals(normals);
    pce.setKSearch(facyl::kDefaultNeighbours);
    pce.compute(curvatures);
    benchmark::DoNotOptimize(curvatures);
  }
}
BENCHMARK(BM_PclNormalsThenCurvatures)->Arg(1800)->Unit(benchmark::kMillisecond);

void
BM_PclRansac(benchmark::State& state)
{
  const Scene s = makeScene(static_cast<std::size_t>(state.range(0)));
  pcl::PointCloud<pcl::Normal>::Ptr normals(new pcl::PointCloud<pcl::Normal>);
  pcl::copyPointCloud(*s.cues, *normals);
  pcl::SACSegmentationFromNormals<pcl::PointXYZ, pcl::Normal> seg;
  seg.setOptimizeCoefficients(true);
  seg.setModelType(pcl::SACMODEL_CYLINDER);
  seg.setMethodType(pcl::SAC_RANSAC);
  seg.setNormalDistanceWeight(0.1);
  seg.setMaxIterations(10000);
  seg.setDistanceThreshold(0.01);
  seg.setRadiusLimits(0.0, 1.0);
  seg.setInputCloud(s.cloud);
  seg.setInputNormals(normals);
  pcl::PointIndices inliers;
  pcl::ModelCoefficients coefficients;
  for (auto _ : state) {
    seg.segment(inliers, coefficients);
    benchmark::DoNotOptimize(coefficients);
  }
}
BENCHMARK(BM_PclRansac)->Arg(900)->Unit(benchmark::kMillisecond);

/** What the recognizer reports of a table with \a n objects (three in four cylinders), seen by a
 * camera swinging back and forth around it: the frames a tracker gets, with the sensor's view
 * (intrinsics, and the depth of an empty table: every unmatched track is tested). */
struct TrackerStream {
  std::vector<std::vector<facyl::SupportPlane>> supports;
  std::vector<std::vector<facyl::RecognizedObject>> objects;
  std::vector<facyl::TrackerView> views;
};

TrackerStream
makeTrackerStream(int n, int frames)
{
  TrackerStream s;
  facyl::Random rng(17);
  std::vector<Eigen::Vector3f> places;
  const int side = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(n))));
  for (int i = 0; i < n; ++i)
    places.emplace_back(0.12f * static_cast<float>(i % side - side / 2),
                        0.12f * static_cast<float>(i / side - side / 2), 0.f);
  const facyl::PinholeCamera cam{525.f, 525.f, 319.5f, 239.5f, 640, 480};
  for (int k = 0; k < frames; ++k) {
    const float az = 0.6f * std::sin(6.2832f * static_cast<float>(k) / static_cast<float>(frames));
    const Eigen::Vector3f eye =
      1.2f * Eigen::Vector3f(std::sin(az) * 0.7f, -std::cos(az) * 0.7f, 0.71f);
    Eigen::Affine3f pose = Eigen::Affine3f::Identity(); // camera to world
    const Eigen::Vector3f f = (-eye).normalized();
    const Eigen::Vector3f right = f.cross(Eigen::Vector3f::UnitZ()).normalized();
    pose.linear().col(0) = right;
    pose.linear().col(1) = f.cross(right);
    pose.linear().col(2) = f;
    pose.translation() = eye;
    const Eigen::Affine3f to_camera = pose.inverse();
    facyl::SupportPlane support;
    support.plane.head<3>() = to_camera.linear() * Eigen::Vector3f::UnitZ();
    support.plane[3] = -support.plane.head<3>().dot(to_camera * Eigen::Vector3f::Zero());
    support.frame = facyl::planeFrame(
      support.plane, to_camera * Eigen::Vector3f(rng.uniform(-0.1f, 0.1f), 0.f, 0.f));
    s.supports.push_back({support});
    std::vector<facyl::RecognizedObject> objects;
    for (int i = 0; i < n; ++i) {
      if (rng.chance(0.1)) // missed now and then
        continue;
      facyl::RecognizedObject o;
      o.cluster.support = 0;
      o.cluster.indices.indices.resize(1000);
      const Eigen::Vector3f jitter(0.002f * rng.normal(), 0.002f * rng.normal(), 0.f);
      if (i % 4 != 3) {
        o.is_cylinder = o.evidence.fitted = true;
        o.cylinder.base = to_camera * (places[static_cast<std::size_t>(i)] + jitter);
        o.cylinder.top =
          to_camera * (places[static_cast<std::size_t>(i)] + jitter + Eigen::Vector3f(0, 0, 0.1f));
        o.cylinder.point_on_axis = o.cylinder.base;
        o.cylinder.axis = (o.cylinder.top - o.cylinder.base).normalized();
        o.cylinder.radius = 0.03f * (1.f + 0.02f * rng.normal());
        o.cylinder.angular_coverage = 0.4f;
      }
      o.cluster.centroid =
        to_camera * (places[static_cast<std::size_t>(i)] + jitter + Eigen::Vector3f(0, 0, 0.05f));
      objects.push_back(o);
    }
    s.objects.push_back(std::move(objects));
    facyl::TrackerView view;
    view.camera = cam;
    view.depth = [pose, cam](int u, int v) {
      const Eigen::Vector3f w =
        pose.linear() * Eigen::Vector3f((u - cam.cx) / cam.fx, (v - cam.cy) / cam.fy, 1.f);
      return -pose.translation().z() / w.z();
    };
    s.views.push_back(view);
  }
  return s;
}

/** CylinderTracker::update per frame: re-anchoring (registration), association, filtering
 * and the view tests of the tracks not seen, for a table of N objects. */
void
BM_TrackerUpdate(benchmark::State& state)
{
  const int n = static_cast<int>(state.range(0));
  const TrackerStream s = makeTrackerStream(n, 60);
  facyl::CylinderTracker tracker;
  std::size_t k = 0;
  for (auto _ : state) {
    tracker.update(s.supports[k], 0, s.objects[k], s.views[k]);
    benchmark::DoNotOptimize(tracker.getTracks().data());
    k = (k + 1) % s.objects.size();
  }
  state.counters["tracks"] = static_cast<double>(tracker.getTracks().size());
}
BENCHMARK(BM_TrackerUpdate)->Arg(5)->Arg(10)->Arg(30)->Unit(benchmark::kMicrosecond);

/** One frame through the recognizer, with the shipped classifier, as facyl_detect runs it
 * (buffers kept between frames as a stream would); segmented on the lattice of \a lattice_width
 * (TabletopSegmentationParameters; 0: every pixel). */
void
runFrames(benchmark::State& state, const pcl::PointCloud<pcl::PointXYZRGBA>::ConstPtr& cloud,
          int lattice_width = 0)
{
  auto classifier = std::make_shared<facyl::CylinderClassifier>();
  classifier->load(facyl::CylinderClassifier::defaultModelPath());
  facyl::TabletopCylinderRecognizer<pcl::PointXYZRGBA> rec;
  auto params = rec.getParameters();
  params.segmentation.lattice_width = lattice_width;
  rec.setParameters(params);
  rec.setClassifier(classifier);
  rec.setInputCloud(cloud);
  std::vector<facyl::RecognizedObject> objects;
  facyl::RecognitionTiming sum;
  for (auto _ : state) {
    if (!rec.recognize(objects)) {
      state.SkipWithError("recognition failed");
      return;
    }
    const auto& t = rec.getTiming();
    sum.segmentation += t.segmentation;
    sum.segmentation_steps.planes += t.segmentation_steps.planes;
    sum.segmentation_steps.points += t.segmentation_steps.points;
    sum.segmentation_steps.objects += t.segmentation_steps.objects;
    sum.classification += t.classification;
    sum.fitting += t.fitting;
  }
  const double n = static_cast<double>(state.iterations());
  state.counters["segmentation_ms"] = sum.segmentation / n;
  state.counters["planes_ms"] = sum.segmentation_steps.planes / n;
  state.counters["points_ms"] = sum.segmentation_steps.points / n;
  state.counters["objects_ms"] = sum.segmentation_steps.objects / n;
  state.counters["classification_ms"] = sum.classification / n;
  state.counters["fitting_ms"] = sum.fitting / n;
  state.counters["objects"] = static_cast<double>(objects.size());
}

/** One frame of a PCD file (runFrames). */
void
BM_Frame(benchmark::State& state, const std::string& file)
{
  pcl::PointCloud<pcl::PointXYZRGBA>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZRGBA>);
  if (pcl::io::loadPCDFile(file, *cloud) < 0) {
    state.SkipWithError(("cannot read " + file).c_str());
    return;
  }
  runFrames(state, cloud);
}

/** One simulated frame (runFrames): the same spread scene (seed 1) seen by a Kinect-like
 * sensor of \a width x \a height pixels with the field of view of a 640-pixel-wide one at
 * fx = 525 (a 16:9 frame sees less vertically). */
void
BM_SimulatedFrame(benchmark::State& state, int width, int height, int lattice_width,
                  const std::string& layout)
{
  facyl::TabletopSceneParameters params;
  if (!facyl::parseLayoutPreset(layout, params)) {
    state.SkipWithError(("unknown layout " + layout).c_str());
    return;
  }
  params.seed = 1;
  params.camera.width = width;
  params.camera.height = height;
  params.camera.fx = params.camera.fy = 525.f * static_cast<float>(width) / 640.f;
  params.camera.cx = 0.5f * static_cast<float>(width - 1);
  params.camera.cy = 0.5f * static_cast<float>(height - 1);
  pcl::PointCloud<pcl::PointXYZRGBA>::Ptr cloud(
    new pcl::PointCloud<pcl::PointXYZRGBA>(facyl::simulateTabletopScene(params).cloud));
  runFrames(state, cloud, lattice_width);
}

/** BM_Frame on the bundled scene, a simulated scene at VGA and at 1280 x 720 (and at 1280 x 720
 * on the lattice of lattice_width 640), the realistic layout (a room: floor, furniture, a far
 * background, many objects) at both sizes and, when present, every 4th mOSD learn frame and
 * every rgbd frame of other sensors (RealSense-class, Kinect v1 in a kitchen). */
void
registerFrames()
{
  const std::string scene = std::string(FACYL_SOURCE_DIR) + "/data/default_scene.pcd";
  benchmark::RegisterBenchmark("BM_Frame/default_scene", BM_Frame, scene)
    ->Unit(benchmark::kMillisecond);
  for (const auto& [w, h] : {std::pair{640, 480}, std::pair{1280, 720}})
    benchmark::RegisterBenchmark(
      ("BM_Frame/simulated_" + std::to_string(w) + "x" + std::to_string(h)).c_str(),
      BM_SimulatedFrame, w, h, 0, "spread")
      ->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("BM_Frame/simulated_1280x720_lattice640", BM_SimulatedFrame, 1280,
                               720, 640, "spread")
    ->Unit(benchmark::kMillisecond);
  for (const auto& [w, h] : {std::pair{640, 480}, std::pair{1280, 720}})
    benchmark::RegisterBenchmark(
      ("BM_Frame/realistic_" + std::to_string(w) + "x" + std::to_string(h)).c_str(),
      BM_SimulatedFrame, w, h, 0, "realistic")
      ->Unit(benchmark::kMillisecond);
  const char* env = std::getenv("FACYL_REAL_DATA");
  const std::string real = env ? env : std::string(FACYL_SOURCE_DIR) + "/../shared/data/real";
  for (int k = 0; k <= 44; k += 4) {
    const std::string file = real + "/mosd/learn" + std::to_string(k) + ".pcd";
    if (std::filesystem::exists(file))
      benchmark::RegisterBenchmark(("BM_Frame/mosd_learn" + std::to_string(k)).c_str(), BM_Frame,
                                   file)
        ->Unit(benchmark::kMillisecond);
  }
  for (const char* source : {"graspnet6dof", "posecnn", "sevenscenes"}) {
    std::vector<std::filesystem::path> files;
    const std::filesystem::path dir = real + "/rgbd/" + source;
    if (std::filesystem::is_directory(dir))
      for (const auto& entry : std::filesystem::directory_iterator(dir))
        if (entry.path().extension() == ".pcd")
          files.push_back(entry.path());
    std::sort(files.begin(), files.end());
    for (const auto& file : files)
      benchmark::RegisterBenchmark(
        ("BM_Frame/" + std::string(source) + "_" + file.stem().string()).c_str(), BM_Frame,
        file.string())
        ->Unit(benchmark::kMillisecond);
  }
}

} // namespace

// Google Benchmark's main, plus --version as every facyl tool answers it (-h lists
// Google Benchmark's own options, --benchmark_filter=REGEX and the like).
int
main(int argc, char** argv)
{
  for (int i = 1; i < argc; ++i)
    if (std::string(argv[i]) == "--version") {
      std::printf("facyl_benchmarks (facyl) %s\n", FACYL_VERSION);
      return 0;
    }
  registerFrames();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv))
    return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
