/*
 * facyl: the options of TabletopCylinderRecognizer shared by the tools that run it
 * (facyl_detect, facyl_tabletop_eval): one parser, one help text.
 */
#pragma once

#include <facyl/tools/cli.h>

#include <facyl/recognition/cylinder_classifier.h>
#include <facyl/recognition/tabletop_cylinder_recognizer.h>

#include <set>
#include <stdexcept>
#include <string>

namespace facyl_cli {

/** Options with a value that applyRecognizerOptions reads. */
inline std::set<std::string>
recognizerValueOptions()
{
  return {"--min-score",
          "--score",
          "--max-curvature-ratio",
          "--min-coverage",
          "--max-taper",
          "--prior",
          "--radius-limits",
          "--orientations",
          "--max-fit-points",
          "--neighbours",
          "--threads",
          "--seed",
          "--plane-distance",
          "--lattice-width",
          "--height-limits",
          "--cluster-tolerance",
          "--cluster-size",
          "--up",
          "--clustering",
          "--support",
          "--max-cylinders-per-cluster",
          "--model",
          "--reject-below",
          "--min-probability",
          "--voting",
          "--distance-threshold"};
}

/** Switches that applyRecognizerOptions reads. */
inline std::set<std::string>
recognizerSwitches()
{
  return {"--no-retry", "--retry-inside", "--any-normal-sign", "--outward-normals"};
}

/** Old spellings kept for a release (the bare fit's names, so both tools read the same). */
inline Arguments::Aliases
recognizerAliases()
{
  return {{"--k", "--neighbours"}};
}

/** The help lines of those options. */
inline const char*
recognizerOptionsHelp()
{
  static const std::string help =
    std::string(
      "Shape classifier (paper III-B; a CNN on each object's view, run by OpenCV DNN):\n"
      "  --model M              default (the model shipped with facyl) | none | PATH.onnx\n"
      "                         (with PATH.cfg beside it, see CylinderClassifier)\n"
      "  --reject-below P       clusters whose network probability is below P are not\n"
      "                         fitted (default 0: every cluster is fitted)\n"
      "  --min-probability P    with a model: a cylinder also needs p_cylinder >= P, the\n"
      "                         network fused with the fit's evidence (default 0.5)\n"
      "Decision (a fitted object is a cylinder if score >= R, curvature ratio <= C,\n"
      "angular coverage >= V and taper <= T):\n"
      "  --score S              surface (default: lateral inliers + points on the end caps\n"
      "                         and inner wall, over all points) | inlier (paper eq. 4)\n"
      "  --min-score R          score threshold (default 0.5)\n"
      "  --max-curvature-ratio C  median |k_min| / median |k_max| of the inliers at most C\n"
      "                         (default 0.35; 1 turns the check off)\n"
      "  --min-coverage V       inliers cover at least V of the circumference (default 0.2)\n"
      "  --max-taper T          the radius changes by at most T per unit of length along\n"
      "                         the axis (default 0.15; 1 turns the check off)\n"
      "  --no-retry             no second fit with upright/lying priors when the first fails\n"
      "  --retry-inside         a last retry also fits concave clusters (the inside of an\n"
      "                         open container; bowls too)\n"
      "  --outward-normals      inliers' normals must point away from the axis (default:\n"
      "                         normals face the sensor, a cup's inner wall is no inlier)\n"
      "  --any-normal-sign      inliers' normals may point at the axis\n"
      "Fit:\n"
      "  --prior P              orientation prior in the table frame: uniform | vertical\n"
      "                         (default) | vertical-strong | horizontal\n"
      "  --radius-limits A,B    radius interval in m (default 0.01,0.25: objects on a table)\n"
      "  --voting V             soft-curvature (default; paper eq. 3) | soft-normal | rabbani\n"
      "  --distance-threshold D inlier distance in m (default: estimated from the residuals)\n"
      "  --orientations N       accumulator cells (default ") +
    std::to_string(facyl::TabletopRecognizerParameters{}.hough.orientations) +
    ")\n"
    "  --max-fit-points N     points fitted per cluster at most (default 1200)\n"
    "  --neighbours K         k of the normal/curvature estimation (default 16; old\n"
    "                         spelling --k)\n"
    "  --threads N            clusters fitted at once (default 0: the hardware's\n"
    "                         concurrency; 1: the calling thread alone)\n"
    "  --seed S               accumulator seed (default 0)\n"
    "  --max-cylinders-per-cluster N  cylinders extracted from a cluster the best fit\n"
    "                         does not explain (touching, stacked objects; default 3;\n"
    "                         1: off)\n"
    "Segmentation:\n"
    "  --up x,y,z             gravity's opposite in the cloud's frame: supports are then\n"
    "                         the planes within 20 degrees of horizontal (default:\n"
    "                         unknown; the supports are the planes objects stand on,\n"
    "                         whatever the camera's roll)\n"
    "  --support S            standing (default: the planes most objects stand on, each\n"
    "                         object on the plane under it) | largest (the largest plane)\n"
    "  --clustering C         edge-aware (default: cut at depth jumps and concave\n"
    "                         creases, join parts seen around an occluder) | euclidean\n"
    "  --plane-distance D     support inlier band in m (default 0: measured on each\n"
    "                         support, 3 sigma of its points' distances by range)\n"
    "  --height-limits A,B    object points lie A..B m above the support and above its\n"
    "                         band (default 0,0.5)\n"
    "  --cluster-tolerance D  Euclidean clustering tolerance in m (default 0.02)\n"
    "  --cluster-size A,B     cluster size limits in points (default 300,200000)\n"
    "  --lattice-width W      speed for accuracy on large frames: organized frames wider\n"
    "                         than 1.5 W are segmented on every round(width / W)-th pixel\n"
    "                         and row (640: 1280 x 720 at 640 x 360; default 0: every\n"
    "                         pixel; 0 or 160..8192)\n";
  return help.c_str();
}

/** Reads the recognizer options of \a args into \a p and \a up (zero when not given).
 * \throws std::invalid_argument for a malformed or out-of-range value. */
inline void
applyRecognizerOptions(const Arguments& args, facyl::TabletopRecognizerParameters& p,
                       Eigen::Vector3f& up)
{
  auto& d = p.decision;
  d.min_score = static_cast<float>(args.number("--min-score", d.min_score, 0.0, 1.0));
  const std::string score = args.text("--score", "surface");
  if (score != "surface" && score != "inlier")
    throw std::invalid_argument("--score must be surface or inlier");
  d.score = score == "surface" ? facyl::CylinderDecision::Score::SurfaceRatio
                               : facyl::CylinderDecision::Score::InlierRatio;
  d.max_curvature_ratio =
    static_cast<float>(args.number("--max-curvature-ratio", d.max_curvature_ratio, 1e-6, 1.0));
  d.min_angular_coverage =
    static_cast<float>(args.number("--min-coverage", d.min_angular_coverage, 0.0, 1.0));
  d.max_taper = static_cast<float>(args.number("--max-taper", d.max_taper, 1e-6, 1.0));
  p.retry_upright_lying = !args.has("--no-retry");
  p.retry_any_normal_sign = args.has("--retry-inside");
  if (args.has("--outward-normals") && args.has("--any-normal-sign"))
    throw std::invalid_argument("--outward-normals and --any-normal-sign exclude each other");
  p.hough.outward_normals = !args.has("--any-normal-sign");
  if (args.has("--voting") &&
      !facyl::parseVotingMode(args.text("--voting", ""), p.hough.voting_mode))
    throw std::invalid_argument("option --voting: '" + args.text("--voting", "") +
                                "' is not soft-curvature, soft-normal or rabbani");
  p.hough.distance_threshold =
    static_cast<float>(args.number("--distance-threshold", p.hough.distance_threshold, 0.0, 1.0));
  if (args.has("--prior") && !facyl::parseOrientationPrior(args.text("--prior", ""), p.hough.prior))
    throw std::invalid_argument("unknown --prior '" + args.text("--prior", "") + "'");
  const auto radii = pairOption(args, "--radius-limits", p.hough.radius_min, p.hough.radius_max);
  if (!(radii.first >= 0 && radii.second <= 10))
    throw std::invalid_argument("--radius-limits: expected 0 <= A < B <= 10 (m)");
  p.hough.radius_min = static_cast<float>(radii.first);
  p.hough.radius_max = static_cast<float>(radii.second);
  p.hough.orientations = static_cast<std::size_t>(
    args.integer("--orientations", static_cast<long long>(p.hough.orientations),
                 static_cast<long long>(facyl::kMinOrientations),
                 static_cast<long long>(facyl::kMaxOrientations)));
  p.max_fit_points = static_cast<std::size_t>(
    args.integer("--max-fit-points", static_cast<long long>(p.max_fit_points), 50, 1000000));
  p.neighbours = static_cast<int>(args.integer("--neighbours", p.neighbours, 5, 200));
  p.threads = static_cast<int>(args.integer("--threads", p.threads, 0, 64));
  p.hough.seed = static_cast<std::uint64_t>(
    args.integer("--seed", static_cast<long long>(p.hough.seed), 0, kMaxSeed));
  p.max_cylinders_per_cluster = static_cast<std::size_t>(args.integer(
    "--max-cylinders-per-cluster", static_cast<long long>(p.max_cylinders_per_cluster), 1, 20));
  auto& g = p.segmentation;
  g.plane_distance =
    static_cast<float>(args.number("--plane-distance", g.plane_distance, 0.0, 1.0));
  // Its range (0, or 160..8192) is validate's, checked below.
  g.lattice_width = static_cast<int>(args.integer("--lattice-width", g.lattice_width, 0, 8192));
  const auto heights = pairOption(args, "--height-limits", g.min_height, g.max_height);
  if (!(heights.first >= -10 && heights.second <= 10))
    throw std::invalid_argument("--height-limits: expected -10 <= A < B <= 10 (m)");
  g.min_height = static_cast<float>(heights.first);
  g.max_height = static_cast<float>(heights.second);
  g.cluster_tolerance =
    static_cast<float>(args.number("--cluster-tolerance", g.cluster_tolerance, 1e-4, 1.0));
  const auto sizes = pairOption(args, "--cluster-size", static_cast<double>(g.min_cluster_size),
                                static_cast<double>(g.max_cluster_size));
  if (!(sizes.first >= 1 && sizes.second >= sizes.first && sizes.second <= 1e9))
    throw std::invalid_argument("--cluster-size: expected 1 <= A <= B <= 1e9");
  g.min_cluster_size = static_cast<std::size_t>(sizes.first);
  g.max_cluster_size = static_cast<std::size_t>(sizes.second);
  const std::string clustering = args.text("--clustering", "edge-aware");
  if (clustering != "edge-aware" && clustering != "euclidean")
    throw std::invalid_argument("--clustering must be edge-aware or euclidean");
  g.clustering = clustering == "euclidean"
                   ? facyl::TabletopSegmentationParameters::Clustering::Euclidean
                   : facyl::TabletopSegmentationParameters::Clustering::EdgeAware;
  const std::string support = args.text("--support", "standing");
  if (support != "standing" && support != "largest")
    throw std::invalid_argument("--support must be standing or largest");
  g.support = support == "largest"
                ? facyl::TabletopSegmentationParameters::Support::LargestPlane
                : facyl::TabletopSegmentationParameters::Support::ObjectsStanding;
  p.reject_below = static_cast<float>(args.number("--reject-below", p.reject_below, 0.0, 1.0));
  d.min_probability =
    static_cast<float>(args.number("--min-probability", d.min_probability, 0.0, 1.0));
  up = Eigen::Vector3f::Zero();
  if (args.has("--up")) {
    up = args.vector3("--up", up);
    if (!(up.norm() > 0.f))
      throw std::invalid_argument("--up must be a non-zero vector");
  }
  const std::string why = facyl::validate(p);
  if (!why.empty())
    throw std::invalid_argument(why);
}

/** The classifier that --model names: nullptr for "none"; the shipped model for "default"
 * (\a fallback when --model is not given).
 * \throws std::invalid_argument naming the model when it cannot be loaded. */
inline facyl::ShapeClassifier::Ptr
classifierFromOptions(const Arguments& args, const std::string& fallback = "default")
{
  const std::string model = args.text("--model", fallback);
  if (model == "none")
    return nullptr;
  std::string path = model;
  if (model == "default") {
    path = facyl::CylinderClassifier::defaultModelPath();
    if (path.empty())
      throw std::invalid_argument("--model default: the shipped model (cylinder_net.onnx) is not "
                                  "installed; give --model PATH or --model none");
  }
  auto classifier = std::make_shared<facyl::CylinderClassifier>();
  try {
    classifier->load(path);
  }
  catch (const std::runtime_error& e) {
    throw std::invalid_argument(std::string("--model: ") + e.what());
  }
  return classifier;
}

} // namespace facyl_cli
