/*
 * facyl: the options of TabletopCylinderRecognizer shared by the tools that run it
 * (facyl_detect, facyl_viewer, facyl_tabletop_eval, facyl_track_eval) and the Python module's
 * detect() and Tracker: one table (settings_table.h), hence one parser, one help text, the
 * defaults of TabletopRecognizerParameters and the ranges of its validate().
 */
#pragma once

#include <facyl/tools/cli.h>
#include <facyl/tools/cylinder_fit.h>
#include <facyl/tools/settings_table.h>

#include <facyl/recognition/cylinder_classifier.h>
#include <facyl/recognition/tabletop_cylinder_recognizer.h>

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace facyl_cli {

/** What the recognizer options set: the recognizer's parameters, the up direction and the
 * classifier's model. */
struct RecognizerSettings {
  facyl::TabletopRecognizerParameters params;
  /** Gravity's opposite in the cloud's frame (TabletopCylinderRecognizer::setUpDirection);
   * zero: unknown. */
  Eigen::Vector3f up{Eigen::Vector3f::Zero()};
  std::string model{"default"}; ///< default | none | PATH.onnx (classifierFor)
};

/** The recognizer's options. */
inline const SettingsTable<RecognizerSettings>&
recognizerOptions()
{
  using S = RecognizerSettings;
  using Seg = facyl::TabletopSegmentationParameters;
  using Score = facyl::CylinderDecision::Score;
  static const SettingsTable<S> table = [] {
    const S d;
    SettingsTable<S> t;
    t.column = 25;
    t.validate = [](const S& s, std::string* rule) { return facyl::validate(s.params, rule); };
    t.exclusive = {{"outward-normals", "any-normal-sign", ""}};
    auto& o = t.options;

    Option<S> model;
    model.name = "model";
    model.metavar = "M";
    model.kind = ValueKind::Word;
    model.help = "default (the model shipped with facyl) | none | PATH.onnx\n"
                 "(with PATH.cfg beside it, see CylinderClassifier)";
    model.set = [](S& s, const OptionValue& v, const OptionContext&) { s.model = v.word; };
    model.show = [](const S& s) { return s.model; };
    model.heading =
      "Shape classifier (paper III-B; a CNN on each object's view, run by OpenCV DNN):\n";
    o.push_back(model);
    o.push_back(numberOption<S>(
      "reject-below", "P", [](auto& s) -> auto& { return s.params.reject_below; },
      "clusters whose network probability is below P are not\nfitted (default {}: every "
      "cluster is fitted)"));
    o.push_back(numberOption<S>(
      "min-probability", "P", [](auto& s) -> auto& { return s.params.decision.min_probability; },
      "a cylinder needs p_cylinder >= P, the probability of the\nevidence model (the fit's "
      "evidence, with the network's output\nwith a model; default {})"));

    o.push_back(choiceOption<S>(
      "score", "S", [](auto& s) -> auto& { return s.params.decision.score; },
      std::vector<std::pair<std::string, Score>>{{"surface", Score::SurfaceRatio},
                                                 {"inlier", Score::InlierRatio}},
      "surface (default: lateral inliers + points on the end caps\nand inner wall, over all "
      "points) | inlier (paper eq. 4)"));
    o.back().heading = "Decision (a fitted object is a cylinder if score >= R, curvature ratio "
                       "<= C,\nangular coverage >= V and taper <= T):\n";
    o.push_back(numberOption<S>(
      "min-score", "R", [](auto& s) -> auto& { return s.params.decision.min_score; },
      "score threshold (default {})"));
    o.push_back(numberOption<S>(
      "max-curvature-ratio", "C",
      [](auto& s) -> auto& { return s.params.decision.max_curvature_ratio; },
      "median |k_min| / median |k_max| of the inliers at most C\n(default {}; 1 turns the check "
      "off)"));
    o.push_back(numberOption<S>(
      "min-coverage", "V", [](auto& s) -> auto& { return s.params.decision.min_angular_coverage; },
      "inliers cover at least V of the circumference (default {})"));
    o.push_back(numberOption<S>(
      "max-taper", "T", [](auto& s) -> auto& { return s.params.decision.max_taper; },
      "the radius changes by at most T per unit of length along\nthe axis (default {}; 1 turns "
      "the check off)"));
    o.push_back(switchOption<S>(
      "no-retry", [](auto& s) -> auto& { return s.params.retry_upright_lying; }, false,
      "no second fit with upright/lying priors when the first fails"));
    o.push_back(switchOption<S>(
      "retry-inside", [](auto& s) -> auto& { return s.params.retry_any_normal_sign; }, true,
      "a last retry also fits concave clusters (the inside of an\nopen container; bowls too)"));
    o.push_back(switchOption<S>(
      "outward-normals", [](auto& s) -> auto& { return s.params.hough.outward_normals; }, true,
      "inliers' normals must point away from the axis (default:\nnormals face the sensor, a "
      "cup's inner wall is no inlier)"));
    o.push_back(switchOption<S>(
      "any-normal-sign", [](auto& s) -> auto& { return s.params.hough.outward_normals; }, false,
      "inliers' normals may point at the axis"));

    o.push_back(choiceOption<S>(
      "prior", "P", [](auto& s) -> auto& { return s.params.hough.prior; }, priorChoices(),
      "orientation prior in the table frame: uniform | vertical\n(default) | vertical-strong | "
      "horizontal"));
    o.back().heading = "Fit:\n";
    Option<S> radii;
    radii.name = "radius-limits";
    radii.metavar = "A,B";
    radii.kind = ValueKind::Pair;
    radii.help = "radius interval in m (default {}: objects on a table)";
    radii.set = [](S& s, const OptionValue& v, const OptionContext&) {
      if (!(v.pair.first >= 0 && v.pair.second <= 10))
        throw std::invalid_argument("expected 0 <= A < B <= 10 (m)");
      s.params.hough.radius_min = static_cast<float>(v.pair.first);
      s.params.hough.radius_max = static_cast<float>(v.pair.second);
    };
    radii.show = [](const S& s) {
      return shownPair(s.params.hough.radius_min, s.params.hough.radius_max);
    };
    o.push_back(radii);
    o.push_back(choiceOption<S>(
      "voting", "V", [](auto& s) -> auto& { return s.params.hough.voting_mode; }, votingChoices(),
      "soft-curvature (default; paper eq. 3) | soft-normal | rabbani"));
    o.push_back(numberOption<S>(
      "distance-threshold", "D", [](auto& s) -> auto& { return s.params.hough.distance_threshold; },
      "inlier distance in m (default: estimated from the residuals)", Limits<double>{0.0, 1.0}));
    o.push_back(integerOption<S>(
      "orientations", "N", [](auto& s) -> auto& { return s.params.hough.orientations; },
      "accumulator cells (default {})"));
    o.push_back(integerOption<S>(
      "max-fit-points", "N", [](auto& s) -> auto& { return s.params.max_fit_points; },
      "points fitted per cluster at most (default {})"));
    o.push_back(integerOption<S>(
      "neighbours", "K", [](auto& s) -> auto& { return s.params.neighbours; },
      "k of the normal/curvature estimation (default {}; old\nspelling --k)"));
    o.back().alias = "k";
    o.push_back(integerOption<S>(
      "threads", "N", [](auto& s) -> auto& { return s.params.threads; },
      "clusters fitted at once (default {}: the hardware's\nconcurrency; 1: the calling thread "
      "alone)"));
    o.push_back(integerOption<S>(
      "seed", "S", [](auto& s) -> auto& { return s.params.hough.seed; },
      "accumulator seed (default {})", Limits<long long>{0, kMaxSeed}));
    o.push_back(integerOption<S>(
      "max-cylinders-per-cluster", "N",
      [](auto& s) -> auto& { return s.params.max_cylinders_per_cluster; },
      "cylinders extracted from a cluster the best fit\ndoes not explain (touching, stacked "
      "objects; default {};\n1: off)"));
    o.push_back(integerOption<S>(
      "max-stacked", "N", [](auto& s) -> auto& { return s.params.max_stacked_objects; },
      "levels a cluster is cut into where its side changes\nsection (stacked objects; a part "
      "may be cut again;\ndefault {}; 1: off)"));

    Option<S> up;
    up.name = "up";
    up.metavar = "x,y,z";
    up.kind = ValueKind::Vector3;
    up.help = "gravity's opposite in the cloud's frame: supports are then\nthe planes within " +
              std::to_string(std::lround(d.params.segmentation.max_support_tilt * 180 / M_PI)) +
              " degrees of horizontal (default:\nunknown; the supports are the planes objects "
              "stand on,\nwhatever the camera's roll)";
    up.set = [](S& s, const OptionValue& v, const OptionContext&) {
      if (!(v.vector.norm() > 0.f))
        throw std::invalid_argument("must not be zero");
      s.up = v.vector;
    };
    up.show = [](const S& s) { return shownVector(s.up); };
    up.heading = "Segmentation:\n";
    o.push_back(up);
    o.push_back(choiceOption<S>(
      "support", "S", [](auto& s) -> auto& { return s.params.segmentation.support; },
      std::vector<std::pair<std::string, Seg::Support>>{{"standing", Seg::Support::ObjectsStanding},
                                                        {"largest", Seg::Support::LargestPlane}},
      "standing (default: the planes most objects stand on, each\nobject on the plane under it) "
      "| largest (the largest plane)"));
    o.push_back(choiceOption<S>(
      "clustering", "C", [](auto& s) -> auto& { return s.params.segmentation.clustering; },
      std::vector<std::pair<std::string, Seg::Clustering>>{
        {"edge-aware", Seg::Clustering::EdgeAware}, {"euclidean", Seg::Clustering::Euclidean}},
      "edge-aware (default: cut at depth jumps and concave\ncreases, join parts seen around an "
      "occluder) | euclidean"));
    o.push_back(numberOption<S>(
      "plane-distance", "D", [](auto& s) -> auto& { return s.params.segmentation.plane_distance; },
      "support inlier band in m (default {}: measured on each\nsupport, " +
        compactNumber(d.params.segmentation.band_factor) +
        " sigma of its points' distances by range)",
      Limits<double>{0.0, 1.0}));
    Option<S> heights;
    heights.name = "height-limits";
    heights.metavar = "A,B";
    heights.kind = ValueKind::Pair;
    heights.help = "object points lie A..B m above the support and above its\nband (default {})";
    heights.set = [](S& s, const OptionValue& v, const OptionContext&) {
      if (!(v.pair.first >= -10 && v.pair.second <= 10))
        throw std::invalid_argument("expected -10 <= A < B <= 10 (m)");
      s.params.segmentation.min_height = static_cast<float>(v.pair.first);
      s.params.segmentation.max_height = static_cast<float>(v.pair.second);
    };
    heights.show = [](const S& s) {
      return shownPair(s.params.segmentation.min_height, s.params.segmentation.max_height);
    };
    o.push_back(heights);
    o.push_back(numberOption<S>(
      "cluster-tolerance", "D",
      [](auto& s) -> auto& { return s.params.segmentation.cluster_tolerance; },
      "Euclidean clustering tolerance in m (default {})", Limits<double>{1e-4, 1.0}));
    Option<S> sizes;
    sizes.name = "cluster-size";
    sizes.metavar = "A,B";
    sizes.kind = ValueKind::Pair;
    sizes.help = "cluster size limits in points (default {})";
    sizes.set = [](S& s, const OptionValue& v, const OptionContext&) {
      const auto [a, b] = v.pair;
      if (!(a >= 1 && b >= a && b <= 1e9))
        throw std::invalid_argument("expected 1 <= A <= B <= 1e9");
      s.params.segmentation.min_cluster_size = static_cast<std::size_t>(a);
      s.params.segmentation.max_cluster_size = static_cast<std::size_t>(b);
    };
    sizes.show = [](const S& s) {
      return shownPair(s.params.segmentation.min_cluster_size,
                       s.params.segmentation.max_cluster_size);
    };
    o.push_back(sizes);
    o.push_back(integerOption<S>(
      "lattice-width", "W", [](auto& s) -> auto& { return s.params.segmentation.lattice_width; },
      "speed for accuracy on large frames: organized frames wider\nthan 1.5 W are segmented on "
      "every round(width / W)-th pixel\nand row (640: 1280 x 720 at 640 x 360; default {}: "
      "every\npixel; 0 or 160..8192)"));
    return t;
  }();
  return table;
}

/** The help lines of the recognizer's options. */
inline const char*
recognizerOptionsHelp()
{
  static const std::string help = helpText(recognizerOptions(), RecognizerSettings{});
  return help.c_str();
}

/** Options with a value of the recognizer (for Arguments). */
inline std::set<std::string>
recognizerValueOptions()
{
  return valueOptions(recognizerOptions());
}

/** Switches of the recognizer (for Arguments). */
inline std::set<std::string>
recognizerSwitches()
{
  return switches(recognizerOptions());
}

/** Old spellings of the recognizer's options (for Arguments). */
inline Arguments::Aliases
recognizerAliases()
{
  return aliases(recognizerOptions());
}

/** The classifier that \a model names: nullptr for "none"; the shipped model for "default";
 * else the .onnx at that path (with its .cfg). \a say names the option in messages.
 * \throws std::invalid_argument naming the model when it cannot be loaded. */
inline facyl::ShapeClassifier::Ptr
classifierFor(const std::string& model, const Vocabulary& say = {})
{
  if (model == "none")
    return nullptr;
  std::string path = model;
  if (model == "default") {
    path = facyl::CylinderClassifier::defaultModelPath();
    if (path.empty())
      throw std::invalid_argument(say.option("model", "default") +
                                  ": the shipped model (cylinder_net.onnx) is not installed; "
                                  "give " +
                                  say.option("model", "PATH") + " or " +
                                  say.option("model", "none"));
  }
  auto classifier = std::make_shared<facyl::CylinderClassifier>();
  try {
    classifier->load(path);
  }
  catch (const std::runtime_error& e) {
    throw std::invalid_argument(say.option("model") + ": " + e.what());
  }
  return classifier;
}

/** The recognizer's options of \a args in \a s, and the classifier that --model names.
 * \throws std::invalid_argument. */
inline facyl::ShapeClassifier::Ptr
applyRecognizerOptions(const Arguments& args, RecognizerSettings& s)
{
  applyOptions(recognizerOptions(), args, s);
  return classifierFor(s.model);
}

/** The classifier that --model of \a args names (\a fallback when not given); see
 * classifierFor. \throws std::invalid_argument. */
inline facyl::ShapeClassifier::Ptr
classifierFromOptions(const Arguments& args, const std::string& fallback = "default")
{
  return classifierFor(args.text("--model", fallback));
}

} // namespace facyl_cli
