/*
 * facyl: the options of a bare cylinder fit (no table), shared by facyl_fit and the Python
 * module's fit_cylinders: one table (settings_table.h), hence one parser, one help text, the
 * defaults of FitSettings and the ranges of its validate(). The Python keywords are these
 * options' names with '_' for '-' (radius_limits= is --radius-limits).
 */
#pragma once

#include <facyl/tools/cli.h>
#include <facyl/tools/cylinder_fit.h>
#include <facyl/tools/settings_table.h>

#include <facyl/features/neighbourhoods.h>
#include <facyl/features/setting_problem.h>
#include <facyl/sample_consensus_alt/cylinder_fitting.h>

#include <pcl/common/point_tests.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <set>
#include <stdexcept>
#include <string>
#include <tuple>
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
  std::string method{"facyl"};               ///< facyl | pcl-ransac
  int neighbours{facyl::kDefaultNeighbours}; ///< k of the normal and curvature estimation
  int threads{0};                            ///< 0: all cores
  Units units{Units::Auto};
  bool radius_given{false}; ///< radius limits were given (not the default: auto)
  // The radius limits default to the estimator's own (HoughCylinderParameters: auto, 0 to
  // twice the data's extent across each candidate axis), as PCL's segmentation has none: a bare
  // fit knows nothing of the objects. The tabletop recognizer keeps cans to buckets.
};

/** Checks \a s: the fit's own settings, then its estimator's (facyl::validate).
 * \return an empty string, or what is wrong; \a rule: see facyl::settingProblem. */
inline std::string
validate(const FitSettings& s, std::string* rule = nullptr)
{
  if (s.neighbours < 3 || s.neighbours > 1000)
    return facyl::settingProblem("neighbours", s.neighbours, "is not in [3, 1000]", rule);
  if (s.threads < 0 || s.threads > 256)
    return facyl::settingProblem("threads", s.threads, "is not in [0, 256]", rule);
  return facyl::validate(s.params, rule);
}

namespace detail {

/** With Units::Auto: radius limits up to \a r_max (as \a written) that look like millimetres
 * are refused. \throws std::invalid_argument. */
inline void
refuseMillimetreRadii(const FitSettings& s, double r_max, const std::string& written,
                      const Vocabulary& say)
{
  if (s.units == Units::Auto && std::isfinite(r_max) && r_max > 1.0)
    throw std::invalid_argument(
      "radii up to " + written +
      ": facyl works in metres, and radii beyond 1 m look like millimetres. Give the cloud and "
      "the limits in metres, or " +
      say.option("units", "mm") +
      " (a cloud in millimetres, converted to metres and the results back), or " +
      say.option("units", "m") + " for cylinders that large");
}

/** Radius limits given in the cloud's units, in metres. */
inline void
setRadii(FitSettings& s, double r_min, double r_max)
{
  const float scale = metresPerUnit(s.units);
  s.params.radius_min = static_cast<float>(r_min) * scale;
  s.params.radius_max = static_cast<float>(r_max) * scale;
  s.radius_given = true;
}

} // namespace detail

/** The options of a bare fit (facyl_fit; Python's fit_cylinders). Lengths are given in the
 * cloud's units (--units, applied first) and kept in metres. */
inline const SettingsTable<FitSettings>&
fitOptions()
{
  using S = FitSettings;
  static const SettingsTable<S> table = [] {
    const S d;
    SettingsTable<S> t;
    t.column = 23;
    t.validate = [](const S& s, std::string* rule) { return validate(s, rule); };
    const std::string once = "give the radius limits once: --radius-limits A,B (--radius-min "
                             "and --radius-max are its old spellings)";
    t.exclusive = {{"outward-normals", "any-normal-sign", ""},
                   {"radius-limits", "radius-min", once},
                   {"radius-limits", "radius-max", once}};
    auto& o = t.options;

    Option<S> radii;
    radii.name = "radius-limits";
    radii.metavar = "A,B";
    radii.kind = ValueKind::Pair;
    radii.words = {"auto"};
    radii.help = "radius interval, or auto (default): 0 to twice the\nextent of the data across "
                 "each candidate axis (pipes,\ntanks, cans: HoughCylinderEstimation's own; the "
                 "tabletop\ntools keep 0.01,0.25)";
    radii.set = [](S& s, const OptionValue& v, const OptionContext& c) {
      double r_min = 0.0, r_max = std::numeric_limits<double>::infinity(); // auto
      if (v.word.empty()) {
        std::tie(r_min, r_max) = v.pair;
        if (!(r_min >= 0.0 && r_max > r_min && r_max <= 1e4))
          throw std::invalid_argument("expected 0 <= A < B <= 1e4");
      }
      detail::refuseMillimetreRadii(s, r_max, v.written, c.say);
      detail::setRadii(s, r_min, r_max);
    };
    radii.show = [](const S& s) {
      return s.params.radius_min == 0.f && std::isinf(s.params.radius_max)
               ? std::string("auto")
               : shownPair(s.params.radius_min, s.params.radius_max);
    };
    o.push_back(radii);

    Option<S> up;
    up.name = "up";
    up.metavar = "x,y,z";
    up.kind = ValueKind::Vector3;
    up.help = "gravity's opposite in the cloud's frame (default: unknown);\ngiven, each cylinder's "
              "axis points up and its base is\nthe lower end";
    up.set = [](S& s, const OptionValue& v, const OptionContext&) {
      if (!(v.vector.norm() > 0.f))
        throw std::invalid_argument("must not be zero");
      s.up = v.vector;
      s.up_given = true;
      // One rule with the tabletop tools: the prior is vertical about a known up (--prior,
      // applied after, overrides it).
      s.params.prior = facyl::OrientationPrior::Vertical;
    };
    up.show = [](const S& s) { return shownVector(s.up); };
    o.push_back(up);
    o.push_back(choiceOption<S>(
      "prior", "P", [](auto& s) -> auto& { return s.params.prior; }, priorChoices(),
      "orientation prior: uniform | vertical | vertical-strong |\nhorizontal, about --up (" +
        shownVector(d.up) + " when not given). Default: vertical\nwhen --up is given, else " +
        facyl::toString(d.params.prior) +
        " (the tabletop tools know\nthe table: vertical in its frame)"));
    o.push_back(choiceOption<S>(
      "voting", "V", [](auto& s) -> auto& { return s.params.voting_mode; }, votingChoices(),
      "soft-curvature (default; paper eq. 3) | soft-normal | rabbani"));

    Option<S> method;
    method.name = "method";
    method.metavar = "M";
    method.kind = ValueKind::Word;
    method.help = "facyl (default) | pcl-ransac (pcl::SACSegmentationFromNormals,\n"
                  "SACMODEL_CYLINDER on the same normals, for comparison)";
    method.set = [](S& s, const OptionValue& v, const OptionContext& c) {
      if (v.word == "facyl" || v.word == "pcl-ransac") {
        s.method = v.word;
        return;
      }
      // The old spelling of --voting.
      if (!facyl::parseVotingMode(v.word, s.params.voting_mode))
        throw std::invalid_argument(v.written + " is not facyl or pcl-ransac");
      if (const OptionValue* voting = c.given("voting"))
        throw std::invalid_argument(
          "give the voting mode once: " + c.say.option("voting", voting->word) + " and " +
          c.say.option("method", v.word));
      s.method = "facyl";
    };
    method.show = [](const S& s) { return s.method; };
    o.push_back(method);

    o.push_back(integerOption<S>(
      "neighbours", "K", [](auto& s) -> auto& { return s.neighbours; },
      "k of the normal and curvature estimation (default {}; old\nspelling --k)"));
    o.back().alias = "k";
    o.push_back(integerOption<S>(
      "orientations", "N", [](auto& s) -> auto& { return s.params.orientations; },
      "cells per orientation accumulator, N_d (default {})"));
    o.push_back(integerOption<S>(
      "accumulators", "K", [](auto& s) -> auto& { return s.params.accumulators; },
      "independent accumulators per fit (default {})"));
    Option<S> threshold;
    threshold.name = "distance-threshold";
    threshold.metavar = "D";
    threshold.kind = ValueKind::Number;
    threshold.help = "inlier distance (default: estimated from the residuals;\npcl-ransac: 1% of "
                     "the bounding-box diagonal)";
    threshold.set = [](S& s, const OptionValue& v, const OptionContext&) {
      if (!(v.number >= 0.0 && v.number <= 1e4))
        throw std::invalid_argument(v.written + " is not in " + Limits<double>{0, 1e4}.text());
      s.params.distance_threshold = static_cast<float>(v.number) * metresPerUnit(s.units);
    };
    threshold.show = [](const S& s) { return compactNumber(s.params.distance_threshold); };
    o.push_back(threshold);
    o.push_back(integerOption<S>(
      "max-cylinders", "N", [](auto& s) -> auto& { return s.params.max_cylinders; },
      "cylinders to extract, one after another (default {})", Limits<long long>{1, 100}));
    o.push_back(integerOption<S>(
      "point-candidates", "N", [](auto& s) -> auto& { return s.params.point_candidates; },
      "candidates refined and compared on the points (default {}; 0:\nthe best alone, refined "
      "on its inliers, as facyl 0.1 did)",
      Limits<long long>{0, 64}));
    o.push_back(numberOption<S>(
      "coarse-scale", "S", [](auto& s) -> auto& { return s.params.coarse_scale; },
      "at high noise, cues again from neighbours within S radii\n(default {}; 0: never)"));
    o.push_back(switchOption<S>(
      "outward-normals", [](auto& s) -> auto& { return s.params.outward_normals; }, true,
      "inliers' normals must point away from the axis (normals\ntowards a sensor outside the "
      "cylinder: excludes a cup's inner\nwall; the tabletop tools' default)"));
    o.push_back(switchOption<S>(
      "any-normal-sign", [](auto& s) -> auto& { return s.params.outward_normals; }, false,
      "inliers' normals may point either way (default of a bare fit:\npipes seen from inside, "
      "normals of unknown orientation)"));
    o.push_back(integerOption<S>(
      "seed", "S", [](auto& s) -> auto& { return s.params.seed; },
      "seed of the accumulator draws and of RANSAC (default {})", Limits<long long>{0, kMaxSeed}));
    o.push_back(integerOption<S>(
      "threads", "T", [](auto& s) -> auto& { return s.threads; },
      "threads for normals (default: all)"));
    o.back().tool_only = true;

    Option<S> units;
    units.name = "units";
    units.metavar = "U";
    units.kind = ValueKind::Word;
    units.first = true;
    units.help = "auto (default: metres; a cloud or radius limits evidently in\nmillimetres are "
                 "refused) | m (metres, no check) | mm (the\ncloud, the lengths given and the "
                 "results in millimetres;\nconverted to metres for the fit and back)";
    units.set = [](S& s, const OptionValue& v, const OptionContext&) {
      if (v.word == "auto")
        s.units = Units::Auto;
      else if (v.word == "m")
        s.units = Units::Metres;
      else if (v.word == "mm")
        s.units = Units::Millimetres;
      else
        throw std::invalid_argument(v.written + " is not auto, m or mm");
    };
    units.show = [](const S& s) {
      return s.units == Units::Auto ? "auto" : s.units == Units::Metres ? "m" : "mm";
    };
    o.push_back(units);

    // Old spellings: one end of the radius limits, the other 0 or the data's extent.
    for (const bool lower : {true, false}) {
      Option<S> end;
      end.name = lower ? "radius-min" : "radius-max";
      end.metavar = "R";
      end.kind = ValueKind::Number;
      end.hidden = true;
      end.tool_only = true;
      end.set = [lower](S& s, const OptionValue& v, const OptionContext& c) {
        if (!(v.number >= 0.0 && v.number <= 1e4))
          throw std::invalid_argument(v.written + " is not in " + Limits<double>{0, 1e4}.text());
        const OptionValue* min = c.given("radius-min");
        const double r_min = lower ? v.number : min ? min->number : 0.0;
        const double r_max = lower ? std::numeric_limits<double>::infinity() : v.number;
        detail::refuseMillimetreRadii(s, r_max, v.written, c.say);
        detail::setRadii(s, r_min, r_max);
      };
      end.show = [lower](const S& s) {
        return compactNumber(lower ? s.params.radius_min : s.params.radius_max);
      };
      o.push_back(end);
    }
    return t;
  }();
  return table;
}

/** The help lines of the fit's options. */
inline const char*
fitOptionsHelp()
{
  static const std::string help =
    helpText(fitOptions(), FitSettings{}) +
    "  (old spellings kept for this release: --radius-min R, --radius-max R, --k K,\n"
    "  --method soft-curvature|soft-normal|rabbani)\n";
  return help.c_str();
}

/** Options with a value of the fit (for Arguments). */
inline std::set<std::string>
fitValueOptions()
{
  return valueOptions(fitOptions());
}

/** Switches of the fit (for Arguments). */
inline std::set<std::string>
fitSwitches()
{
  return switches(fitOptions());
}

/** Old spellings of the fit's options (for Arguments). */
inline Arguments::Aliases
fitAliases()
{
  return aliases(fitOptions());
}

/** Reads the fit options of \a args into \a s. \throws std::invalid_argument. */
inline void
applyFitOptions(const Arguments& args, FitSettings& s)
{
  applyOptions(fitOptions(), args, s);
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
