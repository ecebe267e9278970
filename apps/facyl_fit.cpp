/*
 * facyl_fit: fit cylinders to PCD files; one JSON object per file on stdout.
 */
#include <facyl/tools/cli.h>
#include <facyl/tools/cylinder_fit.h>
#include <facyl/tools/cylinder_json.h>
#include <facyl/tools/fit_options.h>
#include <facyl/tools/json_writer.h>
#include <facyl/tools/pcd_input.h>

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

void
printHelp(const char* self)
{
  std::printf(
    "Usage: %s [options] FILE.pcd...\n"
    "Fits cylinders to each point cloud (a bare fit: no table) and prints one JSON object\n"
    "per file: {\"file\", \"method\", \"voting\", \"units\", \"points\", \"cylinders\": [{\n"
    "\"point_on_axis\", \"axis\", \"radius\", \"height\", \"base\", \"top\", \"inlier_ratio\",\n"
    "\"n_inliers\", \"confidence\", \"rms_error\", \"angular_coverage\"}], \"timing_ms\"}.\n\n"
    "%s"
    "  --inliers            also print each cylinder's inlier indices (\"inliers\")\n"
    "%s\n"
    "Normals are estimated unless the file has normal_x/y/z. Writes no file. Exit status: 0\n"
    "if every file was processed, 1 if some file failed (its object holds \"error\"), 2 on\n"
    "bad options.\n",
    self, facyl_cli::fitOptionsHelp(), facyl_cli::commonHelp());
}

struct Settings : facyl_cli::FitSettings {
  bool inlier_indices{false}; ///< --inliers
};

using Cloud = pcl::PointCloud<pcl::PointXYZ>;
using Cues = pcl::PointCloud<facyl::NormalCurvature>;

std::string
errorObject(const std::string& file, const std::string& message)
{
  facyl_cli::Json line;
  line["file"] = file;
  line["error"] = message;
  return facyl_cli::dumpJson(line);
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
  const std::string units = facyl_cli::unitsProblem(*cloud, s.units);
  if (!units.empty())
    return errorObject(file, units);
  const float to_metres = facyl_cli::metresPerUnit(s.units);
  facyl_cli::scaleCloud(*cloud, facyl_cli::metresPerUnitExact(s.units));
  const Cues::Ptr cues =
    facyl_cli::estimateFitCues(cloud, s.neighbours, static_cast<unsigned>(s.threads), given);
  if (cues->size() != cloud->size())
    return errorObject(file, "normal estimation failed (too few points for k = " +
                               std::to_string(s.neighbours) + "?)");
  const double normals_ms = normals_watch.getTime();
  if (std::none_of(cues->begin(), cues->end(),
                   [](const facyl::NormalCurvature& c) { return std::isfinite(c.normal_x); }))
    return errorObject(
      file, "no point has a normal: " + std::to_string(finite) +
              " finite points are too few or degenerate for k = " + std::to_string(s.neighbours));

  pcl::StopWatch fit_watch;
  std::vector<facyl::CylinderModel> models;
  if (s.method == "pcl-ransac") {
    models = facyl_cli::pclRansacFit(cloud, *cues, s.params);
  }
  std::string why;
  if (s.method != "pcl-ransac")
    models = facyl_cli::houghFit(cloud, cues, s, &why);
  const double fit_ms = fit_watch.getTime();
  if (models.empty() && !why.empty())
    std::fprintf(stderr, "facyl_fit: %s: no cylinder: %s\n", file.c_str(), why.c_str());

  using facyl_cli::jsonNumber;
  facyl_cli::Json out;
  out["file"] = file;
  out["method"] = s.method;
  out["voting"] =
    s.method == "pcl-ransac" ? std::string("none") : facyl::toString(s.params.voting_mode);
  out["units"] = s.units == facyl_cli::Units::Millimetres ? "mm" : "m";
  out["points"] = cloud->size();
  out["cylinders"] = facyl_cli::Json::array();
  for (const auto& model : models) {
    facyl::CylinderModel m = model;
    facyl_cli::scaleModel(m, 1.f / to_metres);
    out["cylinders"].push_back(facyl_cli::cylinderObject(m, s.inlier_indices));
  }
  if (models.empty() && !why.empty())
    out["why_none"] = why;
  out["timing_ms"]["load"] = jsonNumber(load_ms);
  out["timing_ms"]["normals"] = jsonNumber(normals_ms);
  out["timing_ms"]["fit"] = jsonNumber(fit_ms);
  out["timing_ms"]["total"] = jsonNumber(total_watch.getTime());
  ok = true;
  return facyl_cli::dumpJson(out);
}

} // namespace

int
main(int argc, char** argv)
{
  Settings s;
  std::vector<std::string> files;
  const int rc = facyl_cli::startTool(argc, argv, "facyl_fit", printHelp, [&] {
    const facyl_cli::Arguments args(argc, argv, facyl_cli::fitValueOptions(),
                                    facyl_cli::joined(facyl_cli::fitSwitches(), {"--inliers"}),
                                    facyl_cli::fitAliases());
    files = args.positional();
    facyl_cli::applyFitOptions(args, s);
    s.inlier_indices = args.has("--inliers");
    if (files.empty())
      throw std::invalid_argument("no input file (see -h)");
  });
  if (rc >= 0)
    return rc;
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
