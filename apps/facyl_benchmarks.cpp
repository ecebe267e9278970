/*
 * facyl_benchmarks: speed of the estimator and of the per-point cues (Google Benchmark).
 * Run: ./build/apps/facyl_benchmarks [--benchmark_filter=REGEX]
 */
#include <facyl/features/normal_curvature_estimation.h>
#include <facyl/sample_consensus_alt/hough_cylinder_estimation.h>
#include <facyl/simulation/cylinder_simulation.h>

#include <pcl/common/io.h>
#include <pcl/features/normal_3d.h>
#include <pcl/features/principal_curvatures.h>
#include <pcl/sample_consensus/method_types.h>
#include <pcl/sample_consensus/model_types.h>
#include <pcl/segmentation/sac_segmentation.h>

#include <benchmark/benchmark.h>

#include <cstdio>
#include <string>

namespace {

using Cloud = pcl::PointCloud<pcl::PointXYZ>;
using Cues = pcl::PointCloud<facyl::NormalCurvature>;

struct Scene {
  Cloud::Ptr cloud{new Cloud};
  Cues::Ptr cues{new Cues};
};

/** |P| lateral points plus as many lid points (100% outliers, eq. 5), 1% noise, r = 0.3 m. */
Scene
makeScene(std::size_t lateral, int k = 16)
{
  facyl::CylinderSimulationParameters p;
  p.radius = 0.3f;
  p.height = 1.f;
  p.lateral_points = lateral;
  p.lid_ratio = 1.f;
  p.noise = 0.01f;
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

void
BM_Fit(benchmark::State& state, facyl::VotingMode mode)
{
  const Scene s = makeScene(static_cast<std::size_t>(state.range(0)));
  facyl::HoughCylinderEstimation<pcl::PointXYZ, facyl::NormalCurvature> hough;
  hough.setVotingMode(mode);
  hough.setNumberOfOrientations(static_cast<std::size_t>(state.range(1)));
  hough.setInputCloud(s.cloud);
  hough.setInputNormals(s.cues);
  std::vector<facyl::CylinderModel> models;
  hough.segment(models); // draws the accumulator once
  for (auto _ : state) {
    hough.segment(models);
    benchmark::DoNotOptimize(models);
  }
  state.counters["points"] = static_cast<double>(s.cloud->size());
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
    ne.setKSearch(16);
    ne.compute(*normals);
    pcl::PrincipalCurvaturesEstimation<pcl::PointXYZ, pcl::Normal> pce;
    pce.setInputCloud(s.cloud);
    pce.setInputNormals(normals);
    pce.setKSearch(16);
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
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv))
    return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
