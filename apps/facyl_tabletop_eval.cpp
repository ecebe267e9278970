/*
 * facyl_tabletop_eval: measures TabletopCylinderRecognizer against ground truth.
 *   --sim N       N simulated scenes (facyl_synth's renderer, seeds S..S+N-1)
 *   --mosd DIR    the labelled mOSD scenes learn33..44 (DIR/labels.csv)
 * Prints figures (markdown) and, with --csv FILE, one row per object.
 */
#include "cli.h"

#include <facyl/recognition/tabletop_cylinder_recognizer.h>
#include <facyl/simulation/tabletop_scene.h>

#include <pcl/io/pcd_io.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <tuple>

namespace {

using Cloud = pcl::PointCloud<pcl::PointXYZRGBA>;

/** One evaluated object (a ground-truth object, or a cluster matching none). */
struct Row {
  std::string scene, kind, pose;
  int object{-1};
  std::size_t cluster{0};   ///< its best (largest) cluster, when found
  bool positive{false};     ///< ground truth: a cylinder
  bool found{false};        ///< a cluster maps to it
  std::size_t clusters{0};  ///< clusters mapping to it
  bool merged{false};       ///< its best cluster holds >= 20% of another object's points too
  float inlier_ratio{0.f}, surface_ratio{0.f}, curvature_ratio{NAN}, coverage{0.f}; ///< best cluster
  bool fitted{false};
  float radius{NAN}, true_radius{NAN}, axis_error_deg{NAN};
};

double
median(std::vector<double> v)
{
  if (v.empty())
    return NAN;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}
double
percentile(std::vector<double> v, double q)
{
  if (v.empty())
    return NAN;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size())))];
}

/** (inlier ratio, surface ratio, curvature ratio, angular coverage) of a fitted cluster that
 * matches no object. */
using Stray = std::tuple<float, float, float, float>;

/** Maps each cluster to the label most of its points carry; fills the rows' cluster fields and
 * adds the fitted clusters that match no row to \a stray. */
template <typename LabelOf>
void
matchClusters(const std::vector<facyl::RecognizedObject>& objects, LabelOf label_of,
              std::map<int, Row>& rows, std::vector<Stray>& stray)
{
  std::map<int, std::size_t> best_size;
  for (std::size_t k = 0; k < objects.size(); ++k) {
    const auto& o = objects[k];
    std::map<int, std::size_t> votes;
    for (const auto i : o.cluster.indices.indices)
      ++votes[label_of(i)];
    int label = -1;
    std::size_t most = 0;
    for (const auto& [l, c] : votes)
      if (c > most)
        label = l, most = c;
    auto it = rows.find(label);
    if (it == rows.end()) {
      if (o.fitted)
        stray.emplace_back(o.inlier_ratio, o.surface_ratio, o.curvature_ratio,
                           o.cylinder.angular_coverage);
      continue;
    }
    Row& r = it->second;
    r.found = true;
    ++r.clusters;
    if (o.cluster.indices.indices.size() < best_size[label])
      continue;
    best_size[label] = o.cluster.indices.indices.size();
    r.cluster = k;
    r.inlier_ratio = o.inlier_ratio;
    r.surface_ratio = o.surface_ratio;
    r.curvature_ratio = o.curvature_ratio;
    r.coverage = o.fitted ? o.cylinder.angular_coverage : 0.f;
    r.fitted = o.fitted;
    r.radius = o.fitted ? o.cylinder.radius : NAN;
    r.merged = false;
    for (const auto& [l, c] : votes)
      if (l != label && rows.count(l) && c >= 0.2 * static_cast<double>(most))
        r.merged = true;
  }
}

struct Decision {
  bool use_surface;
  float threshold;
  float max_curvature_ratio{1.f};
  float min_coverage{0.f};
  bool
  operator()(float inlier, float surface, bool fitted, float curvature_ratio, float coverage) const
  {
    return fitted && (use_surface ? surface : inlier) >= threshold &&
           !(curvature_ratio > max_curvature_ratio) && coverage >= min_coverage;
  }
};

/** Precision and recall over rows (ground-truth objects) and false clusters. */
void
report(const std::vector<Row>& rows, const std::vector<Stray>& stray,
       const std::string& title, float max_kr, float min_coverage)
{
  std::printf("\n%s\n\n| score | threshold | TP | FP | FN | precision | recall |\n"
              "|---|---|---|---|---|---|---|\n",
              title.c_str());
  for (bool surface : {false, true})
    for (float t : {0.3f, 0.4f, 0.5f, 0.6f, 0.7f}) {
      const Decision d{surface, t, max_kr, min_coverage};
      std::size_t tp = 0, fp = 0, fn = 0;
      for (const Row& r : rows) {
        const bool yes = r.found && d(r.inlier_ratio, r.surface_ratio, r.fitted, r.curvature_ratio, r.coverage);
        tp += r.positive && yes;
        fn += r.positive && !yes;
        fp += !r.positive && yes;
      }
      for (const auto& [inlier, surface_ratio, kr, coverage] : stray)
        fp += d(inlier, surface_ratio, true, kr, coverage);
      std::printf("| %s | %.1f | %zu | %zu | %zu | %.3f | %.3f |\n",
                  surface ? "surface ratio" : "inlier ratio (eq. 4)", t, tp, fp, fn,
                  tp + fp ? static_cast<double>(tp) / static_cast<double>(tp + fp) : NAN,
                  tp + fn ? static_cast<double>(tp) / static_cast<double>(tp + fn) : NAN);
    }
}

void
timingReport(const std::vector<facyl::RecognitionTiming>& t)
{
  std::vector<double> s, c, f, total;
  for (const auto& x : t)
    s.push_back(x.segmentation), c.push_back(x.classification), f.push_back(x.fitting),
      total.push_back(x.total);
  std::printf("\nTiming per frame (ms, median over %zu frames; first frame excluded): "
              "segmentation %.2f, classification %.2f, fitting %.2f, total %.2f (p90 %.2f)\n",
              t.size(), median(s), median(c), median(f), median(total), percentile(total, 0.9));
}

void
printHelp(const char* self)
{
  std::printf(
    "Usage: %s [--sim N] [--seed S] [--mosd DIR] [--score inlier|surface] [--threshold R]\n"
    "          [--max-curvature-ratio C] [--min-coverage V] [--no-retry] [--retry-inside]\n"
    "          [--any-normal-sign] [--normal-angle A] [--distance D]\n"
    "          [--csv FILE]\n"
    "Runs TabletopCylinderRecognizer (default settings) on N simulated scenes and/or the\n"
    "labelled mOSD scenes and prints detection precision/recall for several thresholds, radius\n"
    "and axis errors of the detected cylinders (with --score/--threshold, default surface 0.5),\n"
    "and the stage timing.\n",
    self);
}

} // namespace

int
main(int argc, char** argv)
{
  if (facyl_cli::wantsHelp(argc, argv)) {
    printHelp(argv[0]);
    return 0;
  }
  std::size_t sim = 0;
  std::uint64_t seed = 1000;
  std::string mosd, csv;
  Decision decision{true, 0.5f};
  facyl::TabletopRecognizerParameters params;
  try {
    const facyl_cli::Arguments args(argc, argv,
                                    {"--sim", "--seed", "--mosd", "--score", "--threshold", "--csv",
                                     "--normal-angle", "--distance", "--max-curvature-ratio",
                                     "--min-coverage"},
                                    {"--no-retry", "--retry-inside", "--any-normal-sign"});
    if (!args.positional().empty())
      throw std::invalid_argument("unexpected argument " + args.positional()[0]);
    sim = static_cast<std::size_t>(args.integer("--sim", 0, 0));
    seed = static_cast<std::uint64_t>(args.integer("--seed", 1000, 0));
    mosd = args.text("--mosd", "");
    csv = args.text("--csv", "");
    const std::string score = args.text("--score", "surface");
    if (score != "inlier" && score != "surface")
      throw std::invalid_argument("--score must be inlier or surface");
    decision.use_surface = score == "surface";
    decision.threshold = static_cast<float>(args.number("--threshold", 0.5));
    params.hough.normal_angle_threshold =
      static_cast<float>(args.number("--normal-angle", params.hough.normal_angle_threshold));
    params.hough.distance_threshold =
      static_cast<float>(args.number("--distance", params.hough.distance_threshold));
    params.max_curvature_ratio =
      static_cast<float>(args.number("--max-curvature-ratio", params.max_curvature_ratio));
    decision.max_curvature_ratio = params.max_curvature_ratio;
    params.retry_upright_lying = !args.has("--no-retry");
    params.retry_any_normal_sign = args.has("--retry-inside");
    params.hough.outward_normals = !args.has("--any-normal-sign");
    params.min_angular_coverage =
      static_cast<float>(args.number("--min-coverage", params.min_angular_coverage));
    decision.min_coverage = params.min_angular_coverage;
    const std::string why = facyl::validate(params);
    if (!why.empty())
      throw std::invalid_argument(why);
    if (sim == 0 && mosd.empty())
      throw std::invalid_argument("give --sim N and/or --mosd DIR");
  }
  catch (const std::exception& e) {
    std::fprintf(stderr, "facyl_tabletop_eval: %s\n", e.what());
    return 2;
  }
  std::ofstream csv_out;
  if (!csv.empty()) {
    csv_out.open(csv);
    csv_out << "set,scene,object,kind,pose,positive,found,clusters,merged,fitted,inlier_ratio,"
               "surface_ratio,curvature_ratio,radius,true_radius,axis_error_deg\n";
  }
  auto write_rows = [&](const std::string& set, const std::vector<Row>& rows) {
    if (!csv_out.is_open())
      return;
    for (const Row& r : rows)
      csv_out << set << "," << r.scene << "," << r.object << "," << r.kind << "," << r.pose << ","
              << r.positive << "," << r.found << "," << r.clusters << "," << r.merged << ","
              << r.fitted << "," << r.inlier_ratio << "," << r.surface_ratio << "," << r.curvature_ratio << "," << r.radius
              << "," << r.true_radius << "," << r.axis_error_deg << "\n";
  };

  facyl::TabletopCylinderRecognizer<pcl::PointXYZRGBA> rec;
  rec.setParameters(params);
  int status = 0;

  if (sim > 0) {
    std::vector<Row> all;
    std::vector<Stray> stray;
    std::vector<facyl::RecognitionTiming> timing;
    std::size_t failures = 0;
    for (std::size_t k = 0; k < sim; ++k) {
      facyl::TabletopSceneParameters sp;
      sp.seed = seed + k;
      const facyl::RenderedScene scene = facyl::simulateTabletopScene(sp);
      Cloud::Ptr cloud(new Cloud(scene.cloud));
      rec.setInputCloud(cloud);
      std::vector<facyl::RecognizedObject> objects;
      if (!rec.recognize(objects)) {
        ++failures;
        continue;
      }
      if (k > 0)
        timing.push_back(rec.getTiming());
      std::map<int, Row> rows;
      for (std::size_t i = 0; i < scene.scene.objects.size(); ++i) {
        const auto& o = scene.scene.objects[i];
        if (scene.visible_pixels[i] < rec.getParameters().segmentation.min_cluster_size)
          continue; // too little of it is seen to be a cluster
        Row r;
        r.scene = std::to_string(sp.seed);
        r.object = static_cast<int>(i + 2);
        r.kind = o.kind;
        r.pose = o.lying ? "lying" : "upright";
        r.positive = o.cls == facyl::SceneClass::Cylinder;
        if (r.positive)
          r.true_radius = o.radius;
        rows[r.object] = r;
      }
      matchClusters(objects, [&](pcl::index_t i) { return static_cast<int>(scene.object_id[i]); },
                    rows, stray);
      // Axis errors of the best cluster of each cylinder.
      for (auto& [id, r] : rows) {
        if (!r.positive || !r.fitted)
          continue;
        const facyl::CylinderTruth truth =
          facyl::cylinderTruth(scene.scene, scene.scene.objects[static_cast<std::size_t>(id - 2)]);
        r.axis_error_deg = facyl::axisAngle(objects[r.cluster].cylinder.axis, truth.axis) * 180.f /
                           static_cast<float>(M_PI);
      }
      for (auto& [id, r] : rows)
        all.push_back(r);
    }
    write_rows("sim", all);
    std::size_t cylinders = 0, found = 0, merged = 0, split = 0;
    for (const Row& r : all) {
      cylinders += r.positive;
      found += r.found;
      merged += r.merged;
      split += r.clusters > 1;
    }
    std::printf("## Simulated scenes: %zu (seeds %llu..%llu), %zu objects with >= %zu visible "
                "pixels (%zu cylinders); %zu scenes without a table\n",
                sim, static_cast<unsigned long long>(seed),
                static_cast<unsigned long long>(seed + sim - 1), all.size(),
                rec.getParameters().segmentation.min_cluster_size, cylinders, failures);
    std::printf("Clusters: %zu of %zu objects found; %zu merged with a neighbour; %zu split\n",
                found, all.size(), merged, split);
    report(all, stray, "Detection (object level; a cluster matching no object and called a "
                       "cylinder is a false positive):",
           params.max_curvature_ratio, params.min_angular_coverage);
    std::map<std::string, std::pair<std::size_t, std::size_t>> fp_by; // kind: (called, total)
    for (const Row& r : all)
      if (!r.positive) {
        auto& c = fp_by[r.kind];
        ++c.second;
        c.first += r.found && decision(r.inlier_ratio, r.surface_ratio, r.fitted, r.curvature_ratio, r.coverage);
      }
    std::printf("\nDistractors called cylinders (%s >= %.2f):",
                decision.use_surface ? "surface ratio" : "inlier ratio", decision.threshold);
    for (const auto& [k, c] : fp_by)
      std::printf(" %s %zu/%zu;", k.c_str(), c.first, c.second);
    std::printf("\n");
    std::vector<double> radius_rel, axis;
    std::map<std::string, std::vector<double>> axis_by, radius_by;
    for (const Row& r : all)
      if (r.positive && r.found && decision(r.inlier_ratio, r.surface_ratio, r.fitted, r.curvature_ratio, r.coverage)) {
        const double rel = std::abs(r.radius - r.true_radius) / r.true_radius * 100.0;
        radius_rel.push_back(rel);
        axis.push_back(r.axis_error_deg);
        axis_by[r.kind + " " + r.pose].push_back(r.axis_error_deg);
        radius_by[r.kind + " " + r.pose].push_back(rel);
      }
    std::printf("\nDetected cylinders (%s >= %.2f): %zu; radius error median %.2f%%, p90 %.2f%%; "
                "axis error median %.2f deg, p90 %.2f deg\n",
                decision.use_surface ? "surface ratio" : "inlier ratio", decision.threshold,
                radius_rel.size(), median(radius_rel), percentile(radius_rel, 0.9), median(axis),
                percentile(axis, 0.9));
    for (const auto& [k, v] : axis_by)
      std::printf("- %s: %zu, axis median %.2f deg (p90 %.2f), radius median %.2f%%\n", k.c_str(),
                  v.size(), median(v), percentile(v, 0.9), median(radius_by[k]));
    timingReport(timing);
  }

  if (!mosd.empty()) {
    std::ifstream labels_file(std::filesystem::path(mosd) / "labels.csv");
    if (!labels_file) {
      std::fprintf(stderr, "facyl_tabletop_eval: cannot read %s/labels.csv\n", mosd.c_str());
      return 1;
    }
    // scene -> object -> (class, pose, notes)
    std::map<std::string, std::map<int, std::array<std::string, 3>>> truth;
    std::string line;
    std::getline(labels_file, line);
    while (std::getline(labels_file, line)) {
      std::vector<std::string> f;
      std::string cur;
      bool quoted = false;
      for (char ch : line) {
        if (ch == '"')
          quoted = !quoted;
        else if (ch == ',' && !quoted)
          f.push_back(cur), cur.clear();
        else
          cur += ch;
      }
      f.push_back(cur);
      if (f.size() >= 9)
        truth[f[1]][std::stoi(f[2])] = {f[3], f[4], f[8]};
    }
    std::vector<Row> all;
    std::vector<Stray> stray;
    std::vector<facyl::RecognitionTiming> timing;
    std::map<std::string, std::vector<std::pair<std::string, float>>> radii; // by note
    for (const auto& [scene_name, objects_truth] : truth) {
      const std::string file = (std::filesystem::path(mosd) / (scene_name + ".pcd")).string();
      pcl::PointCloud<pcl::PointXYZRGBL> labelled;
      if (pcl::io::loadPCDFile(file, labelled) < 0) {
        std::fprintf(stderr, "facyl_tabletop_eval: cannot read %s\n", file.c_str());
        status = 1;
        continue;
      }
      Cloud::Ptr cloud(new Cloud);
      pcl::copyPointCloud(labelled, *cloud);
      rec.setInputCloud(cloud);
      std::vector<facyl::RecognizedObject> objects;
      // Run twice: the second run gives the steady-state timing of a stream.
      if (!rec.recognize(objects) || !rec.recognize(objects)) {
        std::fprintf(stderr, "facyl_tabletop_eval: %s: no table\n", scene_name.c_str());
        status = 1;
        continue;
      }
      timing.push_back(rec.getTiming());
      std::map<int, Row> rows;
      for (const auto& [id, t] : objects_truth) {
        Row r;
        r.scene = scene_name;
        r.object = id;
        r.kind = t[0];
        r.pose = t[1];
        r.positive = t[0] == "cylinder" || t[0] == "cylinder_handle";
        rows[id] = r;
      }
      matchClusters(
        objects,
        [&](pcl::index_t i) {
          const std::uint32_t l = labelled[i].label;
          return l >= 20 ? static_cast<int>(l / 10) : (l >= 1 ? 0 : -1);
        },
        rows, stray);
      for (auto& [id, r] : rows) {
        all.push_back(r);
        const std::string& note = objects_truth.at(id)[2];
        if (r.fitted && decision(r.inlier_ratio, r.surface_ratio, r.fitted, r.curvature_ratio, r.coverage))
          for (const char* key : {"sticker", "plain white mug", "flower canister", "small white canister", "Pringles"})
            if (note.find(key) != std::string::npos)
              radii[key].emplace_back(scene_name, r.radius);
      }
    }
    write_rows("mosd", all);
    std::printf("\n## mOSD learn scenes (%s): %zu labelled objects\n", mosd.c_str(), all.size());
    for (const Row& r : all)
      std::printf("- %s obj %d %s %s: clusters %zu%s, inlier ratio %.3f, surface ratio %.3f, "
                  "radius %s\n",
                  r.scene.c_str(), r.object, r.kind.c_str(), r.pose.c_str(), r.clusters,
                  r.merged ? " (merged with another object)" : "", r.inlier_ratio,
                  r.surface_ratio,
                  r.fitted ? (std::to_string(r.radius * 1000.f).substr(0, 5) + " mm").c_str() : "-");
    std::vector<Row> strict = all;
    for (Row& r : strict)
      r.positive = r.kind == "cylinder";
    report(strict, stray, "Positives = class `cylinder` only (mugs and handled containers count "
                          "as the rest):",
           params.max_curvature_ratio, params.min_angular_coverage);
    report(all, stray, "Positives = `cylinder` and `cylinder_handle`:", params.max_curvature_ratio, params.min_angular_coverage);
    std::printf("\nRadius of recurring objects (decided cylinders):\n");
    for (const auto& [key, v] : radii) {
      std::vector<double> r;
      std::string where;
      for (const auto& [s, x] : v)
        r.push_back(x * 1000.0), where += " " + s;
      double mean = 0, var = 0;
      for (double x : r)
        mean += x / static_cast<double>(r.size());
      for (double x : r)
        var += (x - mean) * (x - mean) / static_cast<double>(r.size());
      std::printf("- %s: n=%zu (%s), mean %.1f mm, std %.1f mm, range %.1f-%.1f mm\n", key.c_str(),
                  r.size(), where.c_str() + 1, mean, std::sqrt(var),
                  *std::min_element(r.begin(), r.end()), *std::max_element(r.begin(), r.end()));
    }
    timingReport(timing);
  }
  return status;
}
