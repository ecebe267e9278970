/*
 * The settings tables of the tools and the Python module (apps/common/include/facyl/tools/
 * settings_table.h): every option sets its field, the help prints every option with the
 * struct's default, a value out of range is refused naming the option, and validate() is the
 * one home of the ranges (its rule is what the option's message says).
 */
#include <facyl/tools/fit_options.h>
#include <facyl/tools/recognizer_options.h>
#include <facyl/tools/settings_table.h>
#include <facyl/tools/tracker_options.h>

#include <facyl/features/setting_problem.h>

#include <gtest/gtest.h>

#include <cmath>

#include <functional>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

using facyl_cli::Arguments;
using facyl_cli::FitSettings;
using facyl_cli::RecognizerSettings;
using facyl_cli::SettingsTable;
using facyl_cli::ValueKind;
using Tracking = facyl::CylinderTrackerParameters;

/** \a words parsed as a tool parses them, applied to a default S. \throws what the tool's
 * parser throws. */
template <typename S>
S
parsed(const SettingsTable<S>& table, const std::vector<std::string>& words)
{
  const Arguments args(words, facyl_cli::valueOptions(table), facyl_cli::switches(table),
                       facyl_cli::aliases(table));
  S s;
  facyl_cli::applyOptions(table, args, s);
  return s;
}

/** The message with which \a words are refused ("" when they are not). */
template <typename S>
std::string
refusal(const SettingsTable<S>& table, const std::vector<std::string>& words)
{
  try {
    parsed(table, words);
  }
  catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

/** Whitespace runs as one space (the help's line breaks aside). */
std::string
oneLine(const std::string& text)
{
  std::string out;
  for (const char c : text)
    if (!(std::isspace(static_cast<unsigned char>(c)) && !out.empty() && out.back() == ' '))
      out += std::isspace(static_cast<unsigned char>(c)) ? ' ' : c;
  return out;
}

/** For each option, a value (none for a switch) and what the struct then holds: read from
 * the field itself, not through the table. */
template <typename S>
using Samples = std::map<std::string, std::pair<std::string, std::function<bool(const S&)>>>;

/** Each option of \a table, given on the command line with its sample value (both spellings
 * of a value), sets its field; the sample is not the default; every option has one. Options
 * with a value also show it as given. */
template <typename S>
void
expectRoundTrips(const SettingsTable<S>& table, const Samples<S>& samples)
{
  for (const auto& o : table.options) {
    SCOPED_TRACE(o.name);
    ASSERT_TRUE(samples.count(o.name)) << "no sample";
    const auto& [value, holds] = samples.at(o.name);
    if (o.kind == ValueKind::Switch) {
      EXPECT_TRUE(holds(parsed(table, {"--" + o.name})));
      continue;
    }
    EXPECT_FALSE(holds(S{})) << "the sample is the default";
    EXPECT_TRUE(holds(parsed(table, {"--" + o.name, value})));
    EXPECT_TRUE(holds(parsed(table, {"--" + o.name + "=" + value})));
    ASSERT_TRUE(o.show);
    EXPECT_EQ(o.show(parsed(table, {"--" + o.name, value})), value);
  }
}

/** Every option with a value in \a bad is refused, the message naming the option. */
template <typename S>
void
expectRefusals(const SettingsTable<S>& table, const std::map<std::string, std::string>& bad)
{
  for (const auto& o : table.options) {
    if (o.kind == ValueKind::Switch || o.name == "model") // a model is any path (loaded later)
      continue;
    SCOPED_TRACE(o.name);
    ASSERT_TRUE(bad.count(o.name)) << "no value out of range";
    const std::string why = refusal(table, {"--" + o.name, bad.at(o.name)});
    EXPECT_EQ(why.rfind("option --" + o.name + ": ", 0), 0u) << why;
  }
}

/** Every option of \a table is in its help, with the default where the help prints one. */
template <typename S>
void
expectHelpListsDefaults(const SettingsTable<S>& table)
{
  const std::string help = facyl_cli::helpText(table, S{});
  for (const auto& o : table.options) {
    SCOPED_TRACE(o.name);
    if (o.hidden) {
      EXPECT_EQ(help.find("--" + o.name + " "), std::string::npos);
      continue;
    }
    EXPECT_NE(help.find("  --" + o.name + (o.metavar.empty() ? "" : " " + o.metavar)),
              std::string::npos);
    if (o.help.find("{}") != std::string::npos) {
      EXPECT_NE(oneLine(help).find("default " + o.show(S{})), std::string::npos);
    }
  }
}

// -------------------------------------------------------------------------- recognizer

TEST(SettingsTable, RecognizerOptionsSetTheirFields)
{
  using S = RecognizerSettings;
  using Seg = facyl::TabletopSegmentationParameters;
  const Samples<S> samples = {
    {"model", {"none", [](const S& s) { return s.model == "none"; }}},
    {"reject-below", {"0.25", [](const S& s) { return s.params.reject_below == 0.25f; }}},
    {"min-probability",
     {"0.75", [](const S& s) { return s.params.decision.min_probability == 0.75f; }}},
    {"score",
     {"inlier",
      [](const S& s) {
        return s.params.decision.score == facyl::CylinderDecision::Score::InlierRatio;
      }}},
    {"min-score", {"0.625", [](const S& s) { return s.params.decision.min_score == 0.625f; }}},
    {"max-curvature-ratio",
     {"0.5", [](const S& s) { return s.params.decision.max_curvature_ratio == 0.5f; }}},
    {"min-coverage",
     {"0.375", [](const S& s) { return s.params.decision.min_angular_coverage == 0.375f; }}},
    {"max-taper", {"0.25", [](const S& s) { return s.params.decision.max_taper == 0.25f; }}},
    {"no-retry", {"", [](const S& s) { return !s.params.retry_upright_lying; }}},
    {"retry-inside", {"", [](const S& s) { return s.params.retry_any_normal_sign; }}},
    // The default: the switch is there to say so.
    {"outward-normals", {"", [](const S& s) { return s.params.hough.outward_normals; }}},
    {"any-normal-sign", {"", [](const S& s) { return !s.params.hough.outward_normals; }}},
    {"prior",
     {"horizontal",
      [](const S& s) { return s.params.hough.prior == facyl::OrientationPrior::Horizontal; }}},
    {"radius-limits",
     {"0.02,0.3",
      [](const S& s) {
        return s.params.hough.radius_min == 0.02f && s.params.hough.radius_max == 0.3f;
      }}},
    {"voting",
     {"rabbani",
      [](const S& s) { return s.params.hough.voting_mode == facyl::VotingMode::Rabbani; }}},
    {"distance-threshold",
     {"0.004", [](const S& s) { return s.params.hough.distance_threshold == 0.004f; }}},
    {"orientations", {"900", [](const S& s) { return s.params.hough.orientations == 900; }}},
    {"max-fit-points", {"800", [](const S& s) { return s.params.max_fit_points == 800; }}},
    {"neighbours", {"24", [](const S& s) { return s.params.neighbours == 24; }}},
    {"threads", {"3", [](const S& s) { return s.params.threads == 3; }}},
    {"seed",
     {"9223372036854775807",
      [](const S& s) { return s.params.hough.seed == 9223372036854775807ULL; }}},
    {"max-cylinders-per-cluster",
     {"5", [](const S& s) { return s.params.max_cylinders_per_cluster == 5; }}},
    {"max-stacked", {"2", [](const S& s) { return s.params.max_stacked_objects == 2; }}},
    {"up", {"0,-1,0", [](const S& s) { return s.up == Eigen::Vector3f(0, -1, 0); }}},
    {"support",
     {"largest",
      [](const S& s) { return s.params.segmentation.support == Seg::Support::LargestPlane; }}},
    {"clustering",
     {"euclidean",
      [](const S& s) { return s.params.segmentation.clustering == Seg::Clustering::Euclidean; }}},
    {"plane-distance",
     {"0.015", [](const S& s) { return s.params.segmentation.plane_distance == 0.015f; }}},
    {"height-limits",
     {"0.01,0.4",
      [](const S& s) {
        return s.params.segmentation.min_height == 0.01f &&
               s.params.segmentation.max_height == 0.4f;
      }}},
    {"cluster-tolerance",
     {"0.03", [](const S& s) { return s.params.segmentation.cluster_tolerance == 0.03f; }}},
    {"cluster-size",
     {"100,5000",
      [](const S& s) {
        return s.params.segmentation.min_cluster_size == 100 &&
               s.params.segmentation.max_cluster_size == 5000;
      }}},
    {"lattice-width",
     {"640", [](const S& s) { return s.params.segmentation.lattice_width == 640; }}},
  };
  expectRoundTrips(facyl_cli::recognizerOptions(), samples);
  // The old spelling sets the same field.
  EXPECT_EQ(parsed(facyl_cli::recognizerOptions(), {"--k", "24"}).params.neighbours, 24);
}

TEST(SettingsTable, RecognizerRefusesValuesOutOfRangeNamingTheOption)
{
  expectRefusals(facyl_cli::recognizerOptions(), {{"reject-below", "1.5"},
                                                  {"min-probability", "-0.1"},
                                                  {"score", "bogus"},
                                                  {"min-score", "2"},
                                                  {"max-curvature-ratio", "0"},
                                                  {"min-coverage", "1.1"},
                                                  {"max-taper", "0"},
                                                  {"prior", "sideways"},
                                                  {"radius-limits", "0.01,1e30"},
                                                  {"voting", "majority"},
                                                  {"distance-threshold", "2"},
                                                  {"orientations", "5"},
                                                  {"max-fit-points", "10"},
                                                  {"neighbours", "4294967299"},
                                                  {"threads", "65"},
                                                  {"seed", "-1"},
                                                  {"max-cylinders-per-cluster", "0"},
                                                  {"max-stacked", "9"},
                                                  {"up", "0,0,0"},
                                                  {"support", "bogus"},
                                                  {"clustering", "bogus"},
                                                  {"plane-distance", "2"},
                                                  {"height-limits", "-20,0.5"},
                                                  {"cluster-tolerance", "0"},
                                                  {"cluster-size", "500,100"},
                                                  {"lattice-width", "100"}});
  const auto& table = facyl_cli::recognizerOptions();
  // The range is validate()'s, printed after the value as typed.
  EXPECT_EQ(refusal(table, {"--neighbours", "4294967299"}),
            "option --neighbours: 4294967299 is not in [5, 200]");
  EXPECT_EQ(refusal(table, {"--k", "4"}), "option --k: 4 is not in [5, 200]");
  EXPECT_EQ(refusal(table, {"--min-score", "2"}), "option --min-score: 2 is not in [0, 1]");
  EXPECT_EQ(refusal(table, {"--orientations", "-5"}),
            "option --orientations: -5 is not in [10, 100000]");
  EXPECT_EQ(refusal(table, {"--voting", "x"}),
            "option --voting: 'x' is not soft-curvature, soft-normal or rabbani");
  EXPECT_EQ(refusal(table, {"--seed", "99999999999999999999"}),
            "option --seed: 99999999999999999999 is not in [0, 9223372036854775807]");
  EXPECT_EQ(refusal(table, {"--outward-normals", "--any-normal-sign"}),
            "--outward-normals and --any-normal-sign exclude each other");
  EXPECT_EQ(refusal(table, {"--min-score", "abc"}), "option --min-score: 'abc' is not a number");
  EXPECT_EQ(refusal(table, {"--threads", "1e3"}), "option --threads: '1e3' is not an integer");
  // Settings of several fields: validate()'s whole message, after the option.
  EXPECT_EQ(refusal(table, {"--radius-limits", "0.3,0.2"}),
            "option --radius-limits: fit: radius limits [0.3, 0.2] are empty or inverted");
}

TEST(SettingsTable, RecognizerHelpPrintsTheStructsDefaults)
{
  const auto& table = facyl_cli::recognizerOptions();
  expectHelpListsDefaults(table);
  // The default printed is the struct's: another struct, another help.
  RecognizerSettings other;
  other.params.hough.orientations = 451;
  other.params.neighbours = 17;
  other.params.hough.radius_min = 0.02f;
  const std::string help = facyl_cli::helpText(table, other);
  EXPECT_NE(help.find("accumulator cells (default 451)"), std::string::npos);
  EXPECT_NE(help.find("(default 17; old"), std::string::npos);
  EXPECT_NE(help.find("(default 0.02,0.25: objects on a table)"), std::string::npos);
  // A choice's default is the one the help marks.
  const RecognizerSettings d;
  for (const char* name : {"score", "prior", "voting", "support", "clustering"}) {
    SCOPED_TRACE(name);
    EXPECT_NE(
      oneLine(facyl_cli::recognizerOptionsHelp()).find(table.find(name)->show(d) + " (default"),
      std::string::npos);
  }
}

// --------------------------------------------------------------------------------- fit

TEST(SettingsTable, FitOptionsSetTheirFields)
{
  using S = FitSettings;
  const Samples<S> samples = {
    {"radius-limits",
     {"0.02,0.3",
      [](const S& s) { return s.params.radius_min == 0.02f && s.params.radius_max == 0.3f; }}},
    {"up", {"0,1,0", [](const S& s) { return s.up == Eigen::Vector3f(0, 1, 0); }}},
    {"prior",
     {"vertical-strong",
      [](const S& s) { return s.params.prior == facyl::OrientationPrior::VerticalStrong; }}},
    {"voting",
     {"soft-normal",
      [](const S& s) { return s.params.voting_mode == facyl::VotingMode::SoftNormal; }}},
    {"method", {"pcl-ransac", [](const S& s) { return s.method == "pcl-ransac"; }}},
    {"neighbours", {"30", [](const S& s) { return s.neighbours == 30; }}},
    {"orientations", {"900", [](const S& s) { return s.params.orientations == 900; }}},
    {"accumulators", {"3", [](const S& s) { return s.params.accumulators == 3; }}},
    {"distance-threshold",
     {"0.004", [](const S& s) { return s.params.distance_threshold == 0.004f; }}},
    {"max-cylinders", {"4", [](const S& s) { return s.params.max_cylinders == 4; }}},
    {"point-candidates", {"0", [](const S& s) { return s.params.point_candidates == 0; }}},
    {"coarse-scale", {"0.5", [](const S& s) { return s.params.coarse_scale == 0.5f; }}},
    {"outward-normals", {"", [](const S& s) { return s.params.outward_normals; }}},
    // The default of a bare fit: the switch is there to say so.
    {"any-normal-sign", {"", [](const S& s) { return !s.params.outward_normals; }}},
    {"seed", {"7", [](const S& s) { return s.params.seed == 7; }}},
    {"threads", {"2", [](const S& s) { return s.threads == 2; }}},
    {"units", {"mm", [](const S& s) { return s.units == facyl_cli::Units::Millimetres; }}},
    {"radius-min",
     {"0.05",
      [](const S& s) { return s.params.radius_min == 0.05f && std::isinf(s.params.radius_max); }}},
    {"radius-max",
     {"0.5", [](const S& s) { return s.params.radius_min == 0.f && s.params.radius_max == 0.5f; }}},
  };
  expectRoundTrips(facyl_cli::fitOptions(), samples);
  const auto& table = facyl_cli::fitOptions();
  // Rules of the bare fit: a known up makes the prior vertical; lengths in the cloud's units.
  EXPECT_EQ(parsed(table, {"--up", "0,0,1"}).params.prior, facyl::OrientationPrior::Vertical);
  EXPECT_EQ(parsed(table, {"--up", "0,0,1", "--prior", "uniform"}).params.prior,
            facyl::OrientationPrior::Uniform);
  const FitSettings mm =
    parsed(table, {"--units", "mm", "--radius-limits", "10,250", "--distance-threshold", "2"});
  EXPECT_FLOAT_EQ(mm.params.radius_min, 0.01f);
  EXPECT_FLOAT_EQ(mm.params.radius_max, 0.25f);
  EXPECT_FLOAT_EQ(mm.params.distance_threshold, 0.002f);
  EXPECT_TRUE(std::isinf(parsed(table, {"--radius-limits", "auto"}).params.radius_max));
  // Old spellings: --method VOTING is --voting; --radius-min R: R to the data's extent.
  EXPECT_EQ(parsed(table, {"--method", "rabbani"}).params.voting_mode, facyl::VotingMode::Rabbani);
  EXPECT_EQ(parsed(table, {"--method", "rabbani"}).method, "facyl");
  const FitSettings both = parsed(table, {"--radius-min", "0.05", "--radius-max", "0.5"});
  EXPECT_EQ(both.params.radius_min, 0.05f);
  EXPECT_EQ(both.params.radius_max, 0.5f);
  EXPECT_EQ(parsed(table, {"--k", "30"}).neighbours, 30);
}

TEST(SettingsTable, FitRefusesValuesOutOfRangeNamingTheOption)
{
  expectRefusals(facyl_cli::fitOptions(), {{"radius-limits", "0.3,0.2"},
                                           {"up", "0,0,0"},
                                           {"prior", "sideways"},
                                           {"voting", "majority"},
                                           {"method", "bogus"},
                                           {"neighbours", "2"},
                                           {"orientations", "5"},
                                           {"accumulators", "65"},
                                           {"distance-threshold", "-1"},
                                           {"max-cylinders", "101"},
                                           {"point-candidates", "65"},
                                           {"coarse-scale", "3"},
                                           {"seed", "-1"},
                                           {"threads", "-1"},
                                           {"units", "cm"},
                                           {"radius-min", "2e4"},
                                           {"radius-max", "-1"}});
  const auto& table = facyl_cli::fitOptions();
  // facyl_fit's messages (the reference outputs hold the first).
  EXPECT_EQ(refusal(table, {"--orientations", "5"}),
            "option --orientations: 5 is not in [10, 100000]");
  EXPECT_EQ(refusal(table, {"--k", "4294967299"}), "option --k: 4294967299 is not in [3, 1000]");
  EXPECT_EQ(refusal(table, {"--threads", "257"}), "option --threads: 257 is not in [0, 256]");
  EXPECT_EQ(refusal(table, {"--coarse-scale", "3"}), "option --coarse-scale: 3 is not in [0, 2]");
  EXPECT_EQ(refusal(table, {"--radius-limits", "0.3"}),
            "option --radius-limits: expected A,B, got '0.3'");
  EXPECT_EQ(refusal(table, {"--radius-limits", "0.1,0.2", "--radius-min", "0.1"}),
            "give the radius limits once: --radius-limits A,B (--radius-min and --radius-max "
            "are its old spellings)");
  EXPECT_NE(refusal(table, {"--radius-min", "0.2", "--radius-max", "0.1"})
              .find("radius limits [0.2, 0.1] are empty or inverted"),
            std::string::npos);
  EXPECT_EQ(refusal(table, {"--radius-limits", "10,250"})
              .rfind("option --radius-limits: radii up to 10,250: facyl works in metres", 0),
            0u);
  EXPECT_NE(refusal(table, {"--method", "rabbani", "--voting", "soft-normal"})
              .find("give the voting mode once: --voting soft-normal and --method rabbani"),
            std::string::npos);
}

TEST(SettingsTable, FitHelpPrintsTheStructsDefaults)
{
  expectHelpListsDefaults(facyl_cli::fitOptions());
  FitSettings other;
  other.params.accumulators = 2;
  other.params.coarse_scale = 0.5f;
  const std::string help = facyl_cli::helpText(facyl_cli::fitOptions(), other);
  EXPECT_NE(help.find("independent accumulators per fit (default 2)"), std::string::npos);
  EXPECT_NE(help.find("(default 0.5; 0: never)"), std::string::npos);
  const std::string shown = oneLine(facyl_cli::fitOptionsHelp());
  const FitSettings d;
  for (const char* name : {"voting", "method", "units"})
    EXPECT_NE(shown.find(facyl_cli::fitOptions().find(name)->show(d) + " (default"),
              std::string::npos)
      << name;
  EXPECT_NE(shown.find("else " + facyl_cli::fitOptions().find("prior")->show(d)),
            std::string::npos);
}

// ----------------------------------------------------------------------------- tracker

TEST(SettingsTable, TrackerOptions)
{
  const auto& table = facyl_cli::trackerOptions();
  expectRoundTrips(
    table, Samples<Tracking>{
             {"track-confirm-hits", {"3", [](const Tracking& s) { return s.confirm_hits == 3; }}},
             {"track-max-misses", {"9", [](const Tracking& s) { return s.max_misses == 9; }}},
             {"track-support-switch-frames",
              {"5", [](const Tracking& s) { return s.support_switch_frames == 5; }}}});
  expectRefusals(table, {{"track-confirm-hits", "0"},
                         {"track-max-misses", "1001"},
                         {"track-support-switch-frames", "0"}});
  expectHelpListsDefaults(table);
  // validate()'s message, after the option.
  EXPECT_EQ(refusal(table, {"--track-confirm-hits", "0"}),
            "option --track-confirm-hits: confirm_hits 0 is not in [1, 100]");
}

// --------------------------------------------------------------------------- machinery

TEST(SettingsTable, HelpLayout)
{
  // Descriptions start at the column, or two spaces after a longer name; continuation lines
  // are indented to the column; "{}" is the default.
  struct S {
    int n{7};
    bool on{false};
  };
  SettingsTable<S> t;
  t.column = 12;
  t.validate = [](const S&, std::string*) { return std::string(); };
  t.options.push_back(facyl_cli::integerOption<S>(
    "n", "N", [](auto& s) -> auto& { return s.n; }, "first line\nsecond (default {})"));
  t.options.push_back(facyl_cli::switchOption<S>(
    "long-switch", [](auto& s) -> auto& { return s.on; }, true, "set it"));
  t.options.back().heading = "Section:\n";
  EXPECT_EQ(facyl_cli::helpText(t, S{}), "  --n N     first line\n"
                                         "            second (default 7)\n"
                                         "Section:\n"
                                         "  --long-switch  set it\n");
}

TEST(SettingsTable, IntegersBeyondTheFieldSaturateForValidate)
{
  // 2^32 + 3 must not wrap to 3 (in range): it saturates, and validate() refuses it.
  struct S {
    int n{5};
  };
  SettingsTable<S> t;
  t.validate = [](const S& s, std::string* rule) {
    return s.n >= 3 && s.n <= 9 ? std::string()
                                : facyl::settingProblem("n", s.n, "is not in [3, 9]", rule);
  };
  t.options.push_back(facyl_cli::integerOption<S>(
    "n", "N", [](auto& s) -> auto& { return s.n; }, ""));
  EXPECT_EQ(refusal(t, {"--n", "4294967299"}), "option --n: 4294967299 is not in [3, 9]");
  EXPECT_EQ(refusal(t, {"--n", "-4294967299"}), "option --n: -4294967299 is not in [3, 9]");
  EXPECT_EQ(parsed(t, {"--n", "9"}).n, 9);
}

TEST(SettingsTable, ValidateNamesTheRuleBroken)
{
  std::string rule;
  facyl::HoughCylinderParameters hough;
  hough.orientations = 5;
  EXPECT_EQ(facyl::validate(hough, &rule), "orientations (N_d) 5 is not in [10, 100000]");
  EXPECT_EQ(rule, "is not in [10, 100000]");
  hough.orientations = 450;
  hough.radius_min = 0.3f;
  hough.radius_max = 0.2f;
  EXPECT_EQ(facyl::validate(hough, &rule), "radius limits [0.3, 0.2] are empty or inverted");
  EXPECT_EQ(rule, ""); // two settings
  facyl::TabletopRecognizerParameters p;
  p.decision.min_score = 2.f;
  EXPECT_EQ(facyl::validate(p, &rule), "decision: min_score 2 is not in [0, 1]");
  EXPECT_EQ(rule, "is not in [0, 1]");
  p = {};
  EXPECT_EQ(facyl::validate(p, &rule), "");
  EXPECT_EQ(rule, "");
}

TEST(SettingsTable, DefaultsAreValidAndShared)
{
  std::string rule;
  EXPECT_EQ(facyl_cli::validate(FitSettings{}, &rule), "");
  EXPECT_EQ(facyl::validate(facyl::TabletopRecognizerParameters{}, &rule), "");
  // One home for k; a bare fit's radius limits are the estimator's own (issue 41: the tools'
  // 0.01-0.25 m refused pipes and the paper's 0.3 m cylinder), the recognizer's the tabletop's.
  EXPECT_EQ(FitSettings{}.neighbours, facyl::kDefaultNeighbours);
  EXPECT_EQ(facyl::TabletopRecognizerParameters{}.neighbours, facyl::kDefaultNeighbours);
  EXPECT_EQ(FitSettings{}.params.radius_min, facyl::HoughCylinderParameters{}.radius_min);
  EXPECT_EQ(FitSettings{}.params.radius_max, facyl::HoughCylinderParameters{}.radius_max);
  EXPECT_EQ(facyl::TabletopRecognizerParameters{}.hough.radius_min,
            facyl::tabletopHoughDefaults().radius_min);
  EXPECT_EQ(facyl::TabletopRecognizerParameters{}.hough.radius_max,
            facyl::tabletopHoughDefaults().radius_max);
}

} // namespace
