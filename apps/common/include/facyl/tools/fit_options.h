/*
 * facyl: the options of a bare cylinder fit (no table), shared by facyl_fit and the Python
 * module's fit_cylinders: one parser, one help text, one set of defaults. The Python keywords
 * are these options' names with '_' for '-' (radius_limits= is --radius-limits).
 */
#pragma once

#include <facyl/tools/cli.h>
#include <facyl/tools/cylinder_fit.h>

#include <facyl/sample_consensus_alt/cylinder_fitting.h>

#include <pcl/common/point_tests.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

namespace facyl_cli {

/** The units of a cloud's coordinates (and of every length given with it). facyl works in
 * metres; Auto is metres, refusing clouds and limits that are evidently not (see unitsProblem). */
enum class Units { Auto, Metres, Millimetres };

/** Metres per unit of \a u. */
inline float
metresPerUnit(Units u)
{
  return u == Units::Millimetres ? 1e-3f : 1.f;
}

/** Metres per unit of \a u, in double precision (for coordinates). */
inline double
metresPerUnitExact(Units u)
{
  return u == Units::Millimetres ? 1e-3 : 1.0;
}

/** The settings of a bare fit. */
struct FitSettings : HoughSettings {
  std::string method{"facyl"}; ///< facyl | pcl-ransac
  int neighbours{16};          ///< k of the normal and curvature estimation
  unsigned threads{0};         ///< 0: all cores
  Units units{Units::Auto};
  bool radius_given{false}; ///< radius limits were given (not the data-driven default)
};

/** Options with a value that applyFitOptions reads. */
inline std::set<std::string>
fitValueOptions()
{
  return {
    "--method",           "--voting",        "--prior",      "--up",         "--orientations",
    "--accumulators",     "--radius-limits", "--radius-min", "--radius-max", "--distance-threshold",
    "--max-cylinders",    "--neighbours",    "--seed",       "--threads",    "--units",
    "--point-candidates", "--coarse-scale"};
}

/** Switches that applyFitOptions reads. */
inline std::set<std::string>
fitSwitches()
{
  return {"--outward-normals", "--any-normal-sign"};
}

/** Old spellings kept for a release. (--radius-min/--radius-max and --method with a voting
 * mode are read by applyFitOptions itself.) */
inline Arguments::Aliases
fitAliases()
{
  return {{"--k", "--neighbours"}};
}

/** The help lines of those options. */
inline const char*
fitOptionsHelp()
{
  static const std::string help =
    std::string(
      "  --radius-limits A,B  radius interval (default 0.01,0.25: cans to buckets, as in\n"
      "                       every facyl tool); auto: 0 to twice the extent of the data\n"
      "                       across each candidate axis (pipes, tanks)\n"
      "  --up x,y,z           gravity's opposite in the cloud's frame (default: unknown)\n"
      "  --prior P            orientation prior: uniform | vertical | vertical-strong |\n"
      "                       horizontal, about --up (0,0,1 when not given). Default: vertical\n"
      "                       when --up is given, else uniform (the tabletop tools know\n"
      "                       the table: vertical in its frame)\n"
      "  --voting V           soft-curvature (default; paper eq. 3) | soft-normal | rabbani\n"
      "  --method M           facyl (default) | pcl-ransac (pcl::SACSegmentationFromNormals,\n"
      "                       SACMODEL_CYLINDER on the same normals, for comparison)\n"
      "  --neighbours K       k of the normal and curvature estimation (default 16; old\n"
      "                       spelling --k)\n"
      "  --orientations N     cells per orientation accumulator, N_d (default " +
      std::to_string(facyl::HoughCylinderParameters{}.orientations) +
      ")\n"
      "  --accumulators K     independent accumulators per fit (default " +
      std::to_string(facyl::HoughCylinderParameters{}.accumulators) +
      ")\n"
      "  --distance-threshold D  inlier distance (default: estimated from the residuals;\n"
      "                       pcl-ransac: 1% of the bounding-box diagonal)\n"
      "  --max-cylinders N    cylinders to extract, one after another (default 1)\n"
      "  --point-candidates N candidates refined and compared on the points (default ") +
    std::to_string(facyl::HoughCylinderParameters{}.point_candidates) +
    "; 0:\n"
    "                       the best alone, refined on its inliers, as facyl 0.1 did)\n"
    "  --coarse-scale S     at high noise, cues again from neighbours within S radii\n"
    "                       (default " +
    compactNumber(facyl::HoughCylinderParameters{}.coarse_scale) +
    "; 0: never)\n"
    "  --outward-normals    inliers' normals must point away from the axis (normals\n"
    "                       towards a sensor outside the cylinder: excludes a cup's inner\n"
    "                       wall; the tabletop tools' default)\n"
    "  --any-normal-sign    inliers' normals may point either way (default of a bare fit:\n"
    "                       pipes seen from inside, normals of unknown orientation)\n"
    "  --seed S             seed of the accumulator draws and of RANSAC (default 0)\n"
    "  --threads T          threads for normals (default: all)\n"
    "  --units U            auto (default: metres; a cloud or radius limits evidently in\n"
    "                       millimetres are refused) | m (metres, no check) | mm (the\n"
    "                       cloud, the lengths given and the results in millimetres;\n"
    "                       converted to metres for the fit and back)\n"
    "  (old spellings kept for this release: --radius-min R, --radius-max R, --k K,\n"
    "  --method soft-curvature|soft-normal|rabbani)\n";
  return help.c_str();
}

/** Reads the fit options of \a args into \a s.
 * \throws std::invalid_argument for a malformed, contradictory or out-of-range value. */
inline void
applyFitOptions(const Arguments& args, FitSettings& s)
{
  // --method: facyl or pcl-ransac; a voting mode there is the old spelling of --voting.
  s.method = args.text("--method", "facyl");
  std::string voting = args.text("--voting", "soft-curvature");
  if (s.method != "facyl" && s.method != "pcl-ransac") {
    facyl::VotingMode unused;
    if (!facyl::parseVotingMode(s.method, unused))
      throw std::invalid_argument("option " + args.spelling("--method") + ": '" + s.method +
                                  "' is not facyl or pcl-ransac");
    if (args.has("--voting"))
      throw std::invalid_argument("give the voting mode once: --voting " + voting +
                                  " and --method " + s.method);
    voting = s.method;
    s.method = "facyl";
  }
  if (!facyl::parseVotingMode(voting, s.params.voting_mode))
    throw std::invalid_argument("option " + args.spelling("--voting") + ": '" + voting +
                                "' is not soft-curvature, soft-normal or rabbani");
  // One rule with the tabletop tools: the prior is vertical about a known up, uniform without.
  const std::string prior = args.text("--prior", args.has("--up") ? "vertical" : "uniform");
  if (!facyl::parseOrientationPrior(prior, s.params.prior))
    throw std::invalid_argument("option " + args.spelling("--prior") + ": '" + prior +
                                "' is not uniform, vertical, vertical-strong or horizontal");
  s.up = args.vector3("--up", Eigen::Vector3f::UnitZ());
  if (!(s.up.norm() > 0.f))
    throw std::invalid_argument("option " + args.spelling("--up") + " must not be zero");
  s.params.orientations = static_cast<std::size_t>(
    args.integer("--orientations", static_cast<long long>(s.params.orientations),
                 static_cast<long long>(facyl::kMinOrientations),
                 static_cast<long long>(facyl::kMaxOrientations)));
  s.params.accumulators = static_cast<std::size_t>(
    args.integer("--accumulators", static_cast<long long>(s.params.accumulators), 1,
                 static_cast<long long>(facyl::kMaxAccumulators)));

  const std::string units = args.text("--units", "auto");
  if (units == "auto")
    s.units = Units::Auto;
  else if (units == "m")
    s.units = Units::Metres;
  else if (units == "mm")
    s.units = Units::Millimetres;
  else
    throw std::invalid_argument("option " + args.spelling("--units") + ": '" + units +
                                "' is not auto, m or mm");

  // Radius limits, in the cloud's units: --radius-limits A,B, or the old --radius-min/-max.
  if (args.has("--radius-limits") && (args.has("--radius-min") || args.has("--radius-max")))
    throw std::invalid_argument("give the radius limits once: --radius-limits A,B (--radius-min "
                                "and --radius-max are its old spellings)");
  double r_min = 0.01 / metresPerUnit(s.units), r_max = 0.25 / metresPerUnit(s.units);
  if (args.text("--radius-limits", "") == "auto" || args.has("--radius-min") ||
      args.has("--radius-max")) // the old --radius-min/--radius-max: 0 and the data's extent
    r_min = 0.0, r_max = std::numeric_limits<double>::infinity();
  else if (args.has("--radius-limits")) {
    const auto r = pairOption(args, "--radius-limits", r_min, r_max);
    if (!(r.first >= 0.0 && r.second > r.first && r.second <= 1e4))
      throw std::invalid_argument("option " + args.spelling("--radius-limits") +
                                  ": expected 0 <= A < B <= 1e4");
    r_min = r.first, r_max = r.second;
  }
  r_min = args.number("--radius-min", r_min, 0.0, 1e4);
  r_max = args.number("--radius-max", r_max, 0.0, 1e4);
  s.radius_given =
    args.has("--radius-limits") || args.has("--radius-min") || args.has("--radius-max");
  if (s.units == Units::Auto && std::isfinite(r_max) && r_max > 1.0)
    throw std::invalid_argument(
      "option " + args.spelling(args.has("--radius-limits") ? "--radius-limits" : "--radius-max") +
      ": radii up to " +
      args.text(args.has("--radius-limits") ? "--radius-limits" : "--radius-max", "") +
      ": facyl works in metres, and radii beyond 1 m look like millimetres. Give the cloud and "
      "the limits in metres, or --units mm (a cloud in millimetres, converted to metres and the "
      "results back), or --units m for cylinders that large");
  const float scale = metresPerUnit(s.units);
  s.params.radius_min = static_cast<float>(r_min) * scale;
  s.params.radius_max = static_cast<float>(r_max) * scale;
  s.params.distance_threshold =
    static_cast<float>(args.number("--distance-threshold", 0.0, 0.0, 1e4)) * scale;
  s.params.max_cylinders = static_cast<std::size_t>(args.integer("--max-cylinders", 1, 1, 100));
  s.neighbours = static_cast<int>(args.integer("--neighbours", 16, 3, 1000));
  s.params.seed = static_cast<std::uint64_t>(
    args.integer("--seed", static_cast<long long>(s.params.seed), 0, kMaxSeed));
  s.threads = static_cast<unsigned>(args.integer("--threads", 0, 0, 256));
  if (args.has("--outward-normals") && args.has("--any-normal-sign"))
    throw std::invalid_argument("--outward-normals and --any-normal-sign exclude each other");
  s.params.outward_normals = args.has("--outward-normals");
  s.params.point_candidates = static_cast<std::size_t>(
    args.integer("--point-candidates", static_cast<long long>(s.params.point_candidates), 0, 64));
  s.params.coarse_scale = static_cast<float>(
    args.number("--coarse-scale", static_cast<double>(s.params.coarse_scale), 0.0, 2.0));
  const std::string why = facyl::validate(s.params);
  if (!why.empty())
    throw std::invalid_argument(why);
}

/** Above this robust extent (m) a cloud is evidently not in metres: a tabletop scene spans a
 * few metres, an RGB-D frame at most ~15 m; the same scene in millimetres spans thousands. */
constexpr float kMaxMetreExtent = 20.f;

/** The extent of \a cloud's finite points: the diagonal of the box between the 1st and 99th
 * percentiles of each coordinate (a few stray points do not count). */
template <typename PointT>
float
robustExtent(const pcl::PointCloud<PointT>& cloud)
{
  std::vector<float> c[3];
  for (const auto& p : cloud)
    if (pcl::isFinite(p))
      c[0].push_back(p.x), c[1].push_back(p.y), c[2].push_back(p.z);
  if (c[0].empty())
    return 0.f;
  float squared = 0.f;
  for (auto& v : c) {
    const auto lo = static_cast<std::ptrdiff_t>(0.01 * static_cast<double>(v.size() - 1));
    const auto hi = static_cast<std::ptrdiff_t>(0.99 * static_cast<double>(v.size() - 1));
    std::nth_element(v.begin(), v.begin() + lo, v.end());
    const float a = v[static_cast<std::size_t>(lo)];
    std::nth_element(v.begin(), v.begin() + hi, v.end());
    const float b = v[static_cast<std::size_t>(hi)];
    squared += (b - a) * (b - a);
  }
  return std::sqrt(squared);
}

/** With Units::Auto: why \a cloud is evidently not in metres ("" when it may be); \a say_mm and
 * \a say_m are how the caller spells the units options. */
template <typename PointT>
std::string
unitsProblem(const pcl::PointCloud<PointT>& cloud, Units units,
             const std::string& say_mm = "--units mm", const std::string& say_m = "--units m")
{
  if (units != Units::Auto)
    return {};
  const float extent = robustExtent(cloud);
  if (!(extent > kMaxMetreExtent))
    return {};
  return "the cloud spans " + std::to_string(static_cast<long long>(std::lround(extent))) +
         " units, far beyond a tabletop's few metres: millimetres? facyl works in metres. "
         "Convert the cloud to metres, or give " +
         say_mm +
         " (converted to metres and the "
         "results back to millimetres), or " +
         say_m + " for a cloud that large";
}

/** \a cloud's coordinates times \a scale (in place; in double precision, so that a
 * millimetre value becomes the float nearest to its metres). */
template <typename PointT>
void
scaleCloud(pcl::PointCloud<PointT>& cloud, double scale)
{
  if (scale == 1.0)
    return;
  for (auto& p : cloud) {
    p.x = static_cast<float>(scale * p.x);
    p.y = static_cast<float>(scale * p.y);
    p.z = static_cast<float>(scale * p.z);
  }
}

/** The lengths of \a m times \a scale (metres back to the cloud's units). */
inline void
scaleModel(facyl::CylinderModel& m, float scale)
{
  if (scale == 1.f)
    return;
  m.point_on_axis *= scale;
  m.base *= scale;
  m.top *= scale;
  m.radius *= scale;
  m.height *= scale;
  m.rms_error *= scale;
  m.distance_threshold *= scale;
}

} // namespace facyl_cli
