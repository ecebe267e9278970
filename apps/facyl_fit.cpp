/*
 * facyl_fit: fit cylinders to PCD files; one JSON object per file on stdout.
 */
#include "cli.h"
#include "cylinder_fit.h"
#include "pcd_input.h"
#include "pcl_baseline.h"

#include <facyl/features/normal_curvature_estimation.h>
#include <facyl/sample_consensus_alt/cylinder_fitting.h>
#include <facyl/sample_consensus_alt/hough_cylinder_estimation.h>

#include <pcl/common/common.h>
#include <pcl/common/io.h>
#include <pcl/common/point_tests.h>
#include <pcl/common/time.h>
#include <pcl/console/print.h>
#include <pcl/io/pcd_io.h>

#include <fstream>
#include <iostream>
#include <limits>

namespace {

// Defaults, PCL-tool style.
const char* default_method = "soft-curvature";
const char* default_prior = "uniform";
constexpr long long default_orientations = 450;
constexpr long long default_accumulators = 1;
constexpr long long default_k = 16;
constexpr long long default_max_cylinders = 1;

void
printHelp(const char* self)
{
  std::printf(
      "Usage: %s [options] FILE.pcd...\n"
      "Fits cylinders to each point cloud and prints one JSON object per file.\n\n"
      "  --method M           soft-curvature (default) | soft-normal | rabbani | pcl-ransac\n"
      "                       (pcl-ransac: pcl::SACSegmentationFromNormals, SACMODEL_CYLINDER)\n"
      "  --prior P            uniform (default) | vertical | vertical-strong | horizontal\n"
      "  --up x,y,z           the prior's \"up\" direction (default 0,0,1)\n"
      "  --orientations N     cells per orientation accumulator, N_d (default %lld)\n"
      "  --accumulators K     independent accumulators per fit (default %lld)\n"
      "  --radius-min R       smallest radius (default 0)\n"
      "  --radius-max R       largest radius (default: twice the extent of the data)\n"
      "  --distance-threshold D  inlier distance (default: estimated from the residuals;\n"
      "                       pcl-ransac: 1%% of the bounding-box diagonal)\n"
      "  --max-cylinders N    cylinders to extract, one after another (default %lld)\n"
      "  --k K                neighbours for normals and curvatures (default %lld)\n"
      "  --seed S             seed of the accumulator draws and of RANSAC (default 0)\n"
      "  --threads T          threads for normals (default: all)\n"
      "  --outward-normals    inliers' normals must point away from the axis (normals towards\n"
      "                       a sensor outside the cylinder: excludes a cup's inner wall)\n"
      "  --point-candidates N candidates refined and compared on the points (default %zu;\n"
      "                       0: the best alone, refined on its inliers, as facyl 0.1 did)\n"
      "  --coarse-scale S     at high noise, cues again from neighbours within S radii\n"
      "                       (default %g; 0: never)\n"
      "  -h, --help           this help\n\n"
      "Normals are estimated unless the file has normal_x/y/z. Exit status: 0 if every file\n"
      "was processed, 1 if some file failed (its object holds \"error\"), 2 on bad options.\n",
      self, default_orientations, default_accumulators, default_max_cylinders, default_k,
      facyl::HoughCylinderParameters{}.point_candidates,
      static_cast<double>(facyl::HoughCylinderParameters{}.coarse_scale));
}

struct Settings : facyl_cli::HoughSettings {
  std::string method{default_method};
  int k{default_k};
  unsigned threads{0};
};

using Cloud = pcl::PointCloud<pcl::PointXYZ>;
using Cues = pcl::PointCloud<facyl::NormalCurvature>;

/** PCL RANSAC on the same cloud and normals, with the same radius limits. */
std::vector<facyl::CylinderModel>
fitPclRansac(const Cloud::ConstPtr& cloud, const Cues& cues, const Settings& s)
{
  pcl::PointCloud<pcl::Normal>::Ptr normals(new pcl::PointCloud<pcl::Normal>);
  pcl::copyPointCloud(cues, *normals);
  Eigen::Vector4f lo, hi;
  pcl::getMinMax3D(*cloud, lo, hi);
  const float diagonal = (hi - lo).head<3>().norm();
  facyl_cli::PclCylinderOptions o;
  o.distance_threshold =
      s.params.distance_threshold > 0.f ? s.params.distance_threshold : 0.01f * diagonal;
  o.radius_min = s.params.radius_min;
  o.radius_max = std::isfinite(s.params.radius_max) ? s.params.radius_max : diagonal;
  o.max_cylinders = s.params.max_cylinders;
  return facyl_cli::fitPclCylinders<pcl::PointXYZ>(cloud, normals, o);
}

std::string
errorObject(const std::string& file, const std::string& message)
{
  return "{\"file\":" + facyl_cli::quote(file) + ",\"error\":" + facyl_cli::quote(message) + "}";
}

using facyl_cli::hasField;

/** One file: the JSON line, and whether it worked. */
std::string
processFile(const std::string& file, const Settings& s, bool& ok)
{
  ok = false;
  pcl::StopWatch total_watch;
  pcl::PCLPointCloud2 blob;
  facyl_cli::Viewpoint viewpoint;
  const std::string unreadable = facyl_cli::readPcd(file, blob, &viewpoint);
  if (!unreadable.empty())
    return errorObject(file, unreadable);
  Cloud::Ptr cloud(new Cloud);
  pcl::fromPCLPointCloud2(blob, *cloud);
  cloud->sensor_origin_ = viewpoint.origin; // normals are oriented towards it
  cloud->sensor_orientation_ = viewpoint.orientation;
  if (cloud->empty())
    return errorObject(file, "the cloud is empty");
  const auto finite = std::count_if(cloud->begin(), cloud->end(),
                                    [](const pcl::PointXYZ& p) { return pcl::isFinite(p); });
  if (finite == 0)
    return errorObject(file, "the cloud has no finite point");
  const double load_ms = total_watch.getTime();

  // Normals and curvatures (the file's normals when it has them).
  pcl::StopWatch normals_watch;
  pcl::PointCloud<pcl::Normal>::Ptr given;
  if (hasField(blob, "normal_x") && hasField(blob, "normal_y") && hasField(blob, "normal_z")) {
    given.reset(new pcl::PointCloud<pcl::Normal>);
    pcl::fromPCLPointCloud2(blob, *given);
  }
  const Cues::Ptr cues = facyl_cli::estimateFitCues(cloud, s.k, s.threads, given);
  if (cues->size() != cloud->size())
    return errorObject(file, "normal estimation failed (too few points for k = " +
                                 std::to_string(s.k) + "?)");
  const double normals_ms = normals_watch.getTime();
  if (std::none_of(cues->begin(), cues->end(),
                   [](const facyl::NormalCurvature& c) { return std::isfinite(c.normal_x); }))
    return errorObject(file, "no point has a normal: " + std::to_string(finite) +
                                 " finite points are too few or degenerate for k = " +
                                 std::to_string(s.k));

  pcl::StopWatch fit_watch;
  std::vector<facyl::CylinderModel> models;
  if (s.method == "pcl-ransac") {
    models = fitPclRansac(cloud, *cues, s);
  }
  else
    models = facyl_cli::houghFit(cloud, cues, s);
  const double fit_ms = fit_watch.getTime();

  using facyl_cli::number;
  using facyl_cli::vector;
  std::string out = "{\"file\":" + facyl_cli::quote(file) + ",\"method\":" +
                    facyl_cli::quote(s.method) + ",\"points\":" + std::to_string(cloud->size()) +
                    ",\"cylinders\":[";
  for (std::size_t i = 0; i < models.size(); ++i) {
    const auto& m = models[i];
    out += (i ? "," : "");
    out += "{\"point_on_axis\":" + vector(m.point_on_axis) + ",\"axis\":" + vector(m.axis) +
           ",\"radius\":" + number(m.radius) + ",\"height\":" + number(m.height) +
           ",\"base\":" + vector(m.base) + ",\"top\":" + vector(m.top) +
           ",\"inlier_ratio\":" + number(m.inlier_ratio) +
           ",\"inliers\":" + std::to_string(m.inliers.size()) +
           ",\"rms_error\":" + number(m.rms_error) +
           ",\"angular_coverage\":" + number(m.angular_coverage) + "}";
  }
  out += "],\"timing_ms\":{\"load\":" + number(load_ms) + ",\"normals\":" + number(normals_ms) +
         ",\"fit\":" + number(fit_ms) + ",\"total\":" + number(total_watch.getTime()) + "}}";
  ok = true;
  return out;
}

} // namespace

int
main(int argc, char** argv)
{
  if (facyl_cli::wantsHelp(argc, argv)) {
    printHelp(argv[0]);
    return 0;
  }
  Settings s;
  std::vector<std::string> files;
  try {
    const facyl_cli::Arguments args(
        argc, argv,
        {"--method", "--prior", "--up", "--orientations", "--accumulators", "--radius-min",
         "--radius-max", "--distance-threshold", "--max-cylinders", "--k", "--seed",
         "--threads", "--point-candidates", "--coarse-scale"},
        {"--outward-normals"});
    files = args.positional();
    s.method = args.text("--method", default_method);
    facyl::VotingMode mode;
    if (s.method != "pcl-ransac") {
      if (!facyl::parseVotingMode(s.method, mode))
        throw std::invalid_argument("unknown --method '" + s.method + "'");
      s.params.voting_mode = mode;
    }
    if (!facyl::parseOrientationPrior(args.text("--prior", default_prior), s.prior))
      throw std::invalid_argument("unknown --prior '" + args.text("--prior", "") + "'");
    s.up = args.vector3("--up", s.up);
    if (!(s.up.norm() > 0.f))
      throw std::invalid_argument("--up must not be zero");
    s.orientations = static_cast<std::size_t>(args.integer("--orientations", default_orientations, 1, 200000));
    s.accumulators = static_cast<std::size_t>(args.integer("--accumulators", default_accumulators, 1, 64));
    s.params.radius_min = static_cast<float>(args.number("--radius-min", 0.0, 0.0, 1e4));
    s.params.radius_max = static_cast<float>(
        args.number("--radius-max", std::numeric_limits<double>::infinity(), 0.0, 1e4));
    s.params.distance_threshold = static_cast<float>(args.number("--distance-threshold", 0.0, 0.0, 1e4));
    s.params.max_cylinders =
        static_cast<std::size_t>(args.integer("--max-cylinders", default_max_cylinders, 1, 100));
    s.k = static_cast<int>(args.integer("--k", default_k, 3, 1000));
    s.seed = static_cast<std::uint64_t>(args.integer("--seed", 0, 0, facyl_cli::kMaxSeed));
    s.threads = static_cast<unsigned>(args.integer("--threads", 0, 0, 256));
    s.params.outward_normals = args.has("--outward-normals");
    s.params.point_candidates = static_cast<std::size_t>(args.integer(
        "--point-candidates", static_cast<long long>(s.params.point_candidates), 0, 64));
    s.params.coarse_scale = static_cast<float>(
        args.number("--coarse-scale", static_cast<double>(s.params.coarse_scale), 0.0, 2.0));
    const std::string why = facyl::validate(s.params);
    if (!why.empty())
      throw std::invalid_argument(why);
    if (files.empty())
      throw std::invalid_argument("no input file (see -h)");
  }
  catch (const std::exception& e) {
    std::fprintf(stderr, "facyl_fit: %s\n", e.what());
    return 2;
  }
  // PCL's own console messages (warnings about a file) go to stderr; the JSON stays clean.
  pcl::console::setVerbosityLevel(pcl::console::L_ERROR);
  int failed = 0;
  for (const auto& file : files) {
    bool ok = false;
    std::string line;
    try {
      line = processFile(file, s, ok);
    }
    catch (const std::exception& e) {
      line = errorObject(file, e.what());
    }
    std::cout << line << std::endl;
    failed += !ok;
  }
  return failed ? 1 : 0;
}
