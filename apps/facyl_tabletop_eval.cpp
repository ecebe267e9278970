/*
 * facyl_tabletop_eval: measures TabletopCylinderRecognizer against ground truth.
 *   --sim N       N simulated scenes (facyl_synth's renderer, seeds S..S+N-1)
 *   --mosd DIR    the mOSD learn scenes: segmentation of learn0..44 by scene group, and
 *                 detection on the labelled learn33..44 (DIR/labels.csv)
 * Prints figures (markdown) and, with --csv FILE, one row per object.
 */
#include <facyl/tools/cli.h>
#include <facyl/tools/csv_reader.h>
#include <facyl/tools/recognizer_options.h>
#include <facyl/tools/scene_options.h>

#include <facyl/recognition/tabletop_cylinder_recognizer.h>
#include <facyl/segmentation/segmentation_score.h>
#include <facyl/simulation/frame_roll.h>
#include <facyl/simulation/tabletop_scene.h>

#include <pcl/common/point_tests.h>
#include <pcl/io/pcd_io.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>

namespace {

using Cloud = pcl::PointCloud<pcl::PointXYZRGBA>;
using Recognizer = facyl::TabletopCylinderRecognizer<pcl::PointXYZRGBA>;

/** One evaluated ground-truth object. */
struct Row {
  std::string scene, kind, pose;
  int object{-1};
  bool positive{false};  ///< ground truth: a cylinder
  bool touching{false};  ///< ground truth: in contact with another object
  bool found{false};     ///< an output object maps to it (most of its points are this one's)
  std::size_t pieces{0}; ///< output objects mapping to it
  facyl::SegmentOutcome segment;    ///< how the segmentation recovered it
  facyl::CylinderEvidence evidence; ///< of its best (largest) output object
  bool is_cylinder{false};          ///< the recognizer's decision on that object
  float radius{NAN}, true_radius{NAN}, axis_error_deg{NAN};
  std::size_t best{0}; ///< index of that output object
};

/** An output object that matches no ground-truth object: its evidence and the recognizer's
 * decision. */
struct Stray {
  facyl::CylinderEvidence evidence;
  bool is_cylinder{false};
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

/** Truth label of the points on scenery (simulated far furniture and robots): neither an
 * object nor the background; output objects mostly on it are not scored. */
constexpr int kSceneryLabel = -2;

/** Per point: object id (> 0) of the objects scored, 0 for the rest, kSceneryLabel on
 * scenery, -1 without depth. */
template <typename LabelOf>
std::vector<int>
truthVector(const Cloud& cloud, LabelOf label_of)
{
  std::vector<int> truth(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i)
    truth[i] = pcl::isFinite(cloud[i]) ? label_of(i) : -1;
  return truth;
}

/** Output objects on scenery (simulated far furniture and robots), and those of them called
 * cylinders (a robot's links are cylinder-like). */
struct SceneryCount {
  std::size_t objects{0}, cylinders{0};
};

/** Maps each output object to the ground-truth label most of its points carry and fills the
 * rows' detection fields; output objects matching no row go to \a stray, except those with at
 * least half their points on scenery (like unlabelled far objects in real data, they are
 * neither true nor false detections). \return those ignored. */
SceneryCount
matchObjects(const std::vector<facyl::RecognizedObject>& objects, const std::vector<int>& truth,
             std::map<int, Row>& rows, std::vector<Stray>& stray)
{
  std::map<int, std::size_t> best_size;
  SceneryCount on_scenery;
  for (std::size_t k = 0; k < objects.size(); ++k) {
    const auto& o = objects[k];
    std::map<int, std::size_t> votes;
    for (const auto i : o.cluster.indices.indices)
      ++votes[truth[static_cast<std::size_t>(i)]];
    const auto scenery = votes.find(kSceneryLabel);
    if (scenery != votes.end() && 2 * scenery->second >= o.cluster.indices.indices.size()) {
      ++on_scenery.objects;
      on_scenery.cylinders += o.is_cylinder;
      continue;
    }
    int label = -1;
    std::size_t most = 0;
    for (const auto& [l, c] : votes)
      if (c > most)
        label = l, most = c;
    auto it = rows.find(label);
    if (it == rows.end()) {
      if (o.evidence.fitted)
        stray.push_back({o.evidence, o.is_cylinder});
      continue;
    }
    Row& r = it->second;
    r.found = true;
    ++r.pieces;
    if (o.cluster.indices.indices.size() < best_size[label])
      continue;
    best_size[label] = o.cluster.indices.indices.size();
    r.best = k;
    r.evidence = o.evidence;
    r.is_cylinder = o.is_cylinder;
    r.radius = o.evidence.fitted ? o.cylinder.radius : NAN;
  }
  return on_scenery;
}

/** Segmentation outcome of every row (output objects as segments). */
void
scoreRows(const std::vector<facyl::RecognizedObject>& objects, const std::vector<int>& truth,
          std::map<int, Row>& rows)
{
  std::vector<pcl::PointIndices> segments;
  for (const auto& o : objects)
    segments.push_back(o.cluster.indices);
  for (const auto& outcome : facyl::scoreSegments(truth, segments, 1)) {
    const auto it = rows.find(outcome.object);
    if (it != rows.end())
      it->second.segment = outcome;
  }
}

/** The recognizer's decision on the row's object. */
bool
called(const Row& r)
{
  return r.found && r.is_cylinder;
}

/** Precision and recall over rows (ground-truth objects) and stray objects, for both scores
 * at several thresholds (the other settings of \a base). */
void
reportDetection(const std::vector<Row>& rows, const std::vector<Stray>& stray,
                const std::string& title, const facyl::CylinderDecision& base)
{
  std::printf("\n%s\n\n| score | threshold | TP | FP | FN | precision | recall |\n"
              "|---|---|---|---|---|---|---|\n",
              title.c_str());
  for (const auto score : {facyl::CylinderDecision::Score::InlierRatio,
                           facyl::CylinderDecision::Score::SurfaceRatio}) {
    // The thresholds, and the recognizer's own among them (its decisions: the default row).
    std::vector<float> thresholds{0.3f, 0.4f, 0.5f, 0.6f, 0.7f};
    if (score == base.score && std::none_of(thresholds.begin(), thresholds.end(), [&](float t) {
          return std::abs(t - base.min_score) < 1e-6f;
        })) {
      thresholds.push_back(base.min_score);
      std::sort(thresholds.begin(), thresholds.end());
    }
    for (float t : thresholds) {
      facyl::CylinderDecision d = base;
      d.score = score;
      d.min_score = t;
      // At the recognizer's own threshold, its decisions; at the others, what its rule
      // (acceptCylinder) would say.
      const bool is_default = score == base.score && std::abs(t - base.min_score) < 1e-6f;
      std::size_t tp = 0, fp = 0, fn = 0;
      for (const Row& r : rows) {
        const bool yes = is_default ? called(r) : r.found && facyl::acceptCylinder(r.evidence, d);
        tp += r.positive && yes;
        fn += r.positive && !yes;
        fp += !r.positive && yes;
      }
      for (const Stray& e : stray)
        fp += is_default ? e.is_cylinder : facyl::acceptCylinder(e.evidence, d);
      std::printf("| %s | %.2g%s | %zu | %zu | %zu | %.3f | %.3f |\n",
                  score == facyl::CylinderDecision::Score::SurfaceRatio ? "surface ratio"
                                                                        : "inlier ratio (eq. 4)",
                  t, is_default ? " (default)" : "", tp, fp, fn,
                  tp + fp ? static_cast<double>(tp) / static_cast<double>(tp + fp) : NAN,
                  tp + fn ? static_cast<double>(tp) / static_cast<double>(tp + fn) : NAN);
    }
  }
}

/** Segmentation totals of rows selected by \a keep, as a table line. */
template <typename Keep>
void
segmentationLine(const std::vector<Row>& rows, const std::string& name, Keep keep)
{
  facyl::SegmentTotals t;
  for (const Row& r : rows)
    if (keep(r))
      t.add(r.segment);
  std::printf("| %s | %zu | %zu (%.1f%%) | %zu | %zu |\n", name.c_str(), t.objects, t.recovered,
              100.0 * t.recoveredShare(), t.merged, t.split);
}

void
segmentationHeader(const std::string& title)
{
  std::printf("\n%s\n\n| objects | n | recovered (IoU >= 0.5) | merged | split |\n"
              "|---|---|---|---|---|\n",
              title.c_str());
}

void
timingReport(const std::vector<facyl::RecognitionTiming>& t, const std::vector<double>& objects)
{
  std::vector<double> s, c, f, total, planes, points, clustering;
  for (const auto& x : t) {
    s.push_back(x.segmentation), c.push_back(x.classification), f.push_back(x.fitting),
      total.push_back(x.total);
    planes.push_back(x.segmentation_steps.planes), points.push_back(x.segmentation_steps.points),
      clustering.push_back(x.segmentation_steps.objects);
  }
  const auto mean = [](const std::vector<double>& v) {
    double m = 0.0;
    for (const double x : v)
      m += x / static_cast<double>(std::max<std::size_t>(1, v.size()));
    return m;
  };
  std::printf("\nTiming per frame (ms, median over %zu frames): segmentation %.2f, "
              "classification %.2f, fitting %.2f, total %.2f (p90 %.2f)\n",
              t.size(), median(s), median(c), median(f), median(total), percentile(total, 0.9));
  std::printf("Mean per frame: %.2f objects; segmentation %.2f, classification %.2f, fitting "
              "%.2f, total %.2f ms\n",
              mean(objects), mean(s), mean(c), mean(f), mean(total));
  std::printf("Segmentation steps (ms, median): planes %.2f, points %.2f, objects %.2f\n",
              median(planes), median(points), median(clustering));
}

struct Options {
  Eigen::Vector3f up{Eigen::Vector3f::Zero()};
  std::size_t sim{0};
  std::uint64_t seed{1000};
  std::string layout{"spread"};
  std::string sensor{"kinect"};
  facyl::TabletopSceneParameters scene; ///< layout, sensor and image options; seed per scene
  std::string mosd, csv;
  int roll{0}; ///< quarter turns (clockwise) of the camera about its optical axis
  facyl::TabletopRecognizerParameters params;
  facyl::ShapeClassifier::Ptr classifier; ///< --model; nullptr: none
};

class CsvWriter {
public:
  explicit CsvWriter(const std::string& path)
  {
    if (path.empty())
      return;
    out_.open(path);
    out_ << "set,scene,object,kind,pose,positive,touching,found,pieces,recovered,iou,merged,"
            "split,fitted,inlier_ratio,surface_ratio,curvature_ratio,coverage,arc_gap,taper,"
            "radius,true_radius,axis_error_deg,p_network,p_cylinder,points,called,from_lid,seen_"
            "through,outside_share\n";
  }
  void write(const std::string& set, const std::vector<Row>& rows)
  {
    if (!out_.is_open())
      return;
    for (const Row& r : rows) {
      const auto& e = r.evidence;
      out_ << set << "," << r.scene << "," << r.object << "," << r.kind << "," << r.pose << ","
           << r.positive << "," << r.touching << "," << r.found << "," << r.pieces << ","
           << r.segment.recovered << "," << r.segment.best_iou << "," << r.segment.merged << ","
           << r.segment.split << "," << e.fitted << "," << e.inlier_ratio << "," << e.surface_ratio
           << "," << e.curvature_ratio << "," << e.angular_coverage << "," << e.arc_gap << ","
           << e.taper << "," << r.radius << "," << r.true_radius << "," << r.axis_error_deg << ","
           << e.p_network << "," << e.p_cylinder << "," << r.segment.points << "," << called(r)
           << "," << e.from_lid << "," << e.seen_through << "," << e.shape.outside_share << "\n";
    }
  }

private:
  std::ofstream out_;
};

// ---------------------------------------------------------------- simulated scenes

/** Rows of the objects of a simulated scene with enough visible pixels to be a cluster. */
std::map<int, Row>
simulatedRows(const facyl::RenderedScene& scene, std::uint64_t seed, std::size_t min_pixels)
{
  std::map<int, Row> rows;
  for (std::size_t i = 0; i < scene.scene.objects.size(); ++i) {
    const auto& o = scene.scene.objects[i];
    if (scene.visible_pixels[i] < min_pixels)
      continue;
    Row r;
    r.scene = std::to_string(seed);
    r.object = static_cast<int>(i + 2);
    r.kind = o.kind;
    r.pose = o.lying ? "lying" : (o.leaning ? "leaning" : (o.support >= 0 ? "stacked" : "upright"));
    r.positive = o.cls == facyl::SceneClass::Cylinder;
    r.touching = !o.touches.empty();
    if (r.positive)
      r.true_radius = o.radius;
    rows[r.object] = r;
  }
  return rows;
}

void
reportSimulated(const std::vector<Row>& all, const std::vector<Stray>& stray, const Options& opt,
                std::size_t failures, std::size_t wrong_plane, const SceneryCount& on_scenery)
{
  std::size_t cylinders = 0, touching = 0;
  for (const Row& r : all)
    cylinders += r.positive, touching += r.touching;
  char dropout[32] = "dropout drawn per scene";
  if (!opt.scene.sensor.randomize)
    std::snprintf(dropout, sizeof dropout, "%.1f%% dropout", 100.0 * opt.scene.sensor.dropout);
  std::printf("## Simulated scenes: %zu (%s layout, %s sensor, %dx%d, %s, seeds "
              "%llu..%llu), %zu objects with >= %zu visible pixels (%zu cylinders, %zu touching "
              "another object); %zu scenes failed (no table), %zu with a wrong support plane\n",
              opt.sim, opt.layout.c_str(), opt.sensor.c_str(), opt.scene.camera.width,
              opt.scene.camera.height, dropout, static_cast<unsigned long long>(opt.seed),
              static_cast<unsigned long long>(opt.seed + opt.sim - 1), all.size(),
              opt.params.segmentation.min_cluster_size, cylinders, touching, failures, wrong_plane);
  if (on_scenery.objects > 0)
    std::printf("Output objects on scenery (far furniture, robots), not scored: %zu (%zu called "
                "cylinders)\n",
                on_scenery.objects, on_scenery.cylinders);
  segmentationHeader("Segmentation (output objects as segments):");
  segmentationLine(all, "all", [](const Row&) { return true; });
  segmentationLine(all, "touching another", [](const Row& r) { return r.touching; });
  segmentationLine(all, "free-standing", [](const Row& r) { return !r.touching; });
  segmentationLine(all, "cylinders", [](const Row& r) { return r.positive; });
  reportDetection(all, stray,
                  "Detection (a ground-truth object is called a cylinder when its "
                  "largest output object is; an output object matching no object "
                  "and called a cylinder is a false positive):",
                  opt.params.decision);
  std::map<std::string, std::pair<std::size_t, std::size_t>> fp_by; // kind: (called, total)
  for (const Row& r : all)
    if (!r.positive) {
      auto& c = fp_by[r.kind];
      ++c.second;
      c.first += called(r);
    }
  std::printf("\nDistractors called cylinders (default decision):");
  for (const auto& [k, c] : fp_by)
    std::printf(" %s %zu/%zu;", k.c_str(), c.first, c.second);
  std::printf("\n");
  std::vector<double> radius_rel, axis;
  std::map<std::string, std::vector<double>> axis_by, radius_by;
  for (const Row& r : all)
    if (r.positive && called(r)) {
      const double rel = std::abs(r.radius - r.true_radius) / r.true_radius * 100.0;
      radius_rel.push_back(rel);
      axis.push_back(r.axis_error_deg);
      axis_by[r.kind + " " + r.pose].push_back(r.axis_error_deg);
      radius_by[r.kind + " " + r.pose].push_back(rel);
    }
  std::printf("\nDetected cylinders (default decision): %zu; radius error median %.2f%%, p90 "
              "%.2f%%; axis error median %.2f deg, p90 %.2f deg\n",
              radius_rel.size(), median(radius_rel), percentile(radius_rel, 0.9), median(axis),
              percentile(axis, 0.9));
  for (const auto& [k, v] : axis_by)
    std::printf("- %s: %zu, axis median %.2f deg (p90 %.2f), radius median %.2f%% (p90 %.2f%%)\n",
                k.c_str(), v.size(), median(v), percentile(v, 0.9), median(radius_by[k]),
                percentile(radius_by[k], 0.9));
}

/** \a scene as a camera rolled by \a quarter_turns would have seen it: the frame, the
 * per-pixel ground truth and the table plane in the rolled camera's frame. */
void
rollScene(facyl::RenderedScene& scene, int quarter_turns)
{
  const int w = static_cast<int>(scene.cloud.width), h = static_cast<int>(scene.cloud.height);
  scene.cloud = facyl::rollFrame(scene.cloud, quarter_turns);
  auto ids = scene.object_id;
  for (std::size_t i = 0; i < ids.size(); ++i)
    ids[facyl::rolledIndex(i, w, h, quarter_turns)] = scene.object_id[i];
  scene.object_id = std::move(ids);
  auto classes = scene.pixel_class;
  for (std::size_t i = 0; i < classes.size(); ++i)
    classes[facyl::rolledIndex(i, w, h, quarter_turns)] = scene.pixel_class[i];
  scene.pixel_class = std::move(classes);
  for (int t = 0; t < ((quarter_turns % 4) + 4) % 4; ++t) // (x, y) -> (-y, x)
    scene.table_plane.head<2>() = Eigen::Vector2f(-scene.table_plane[1], scene.table_plane[0]);
}

int
evaluateSimulated(const Options& opt, Recognizer& rec, CsvWriter& csv)
{
  std::vector<Row> all;
  std::vector<Stray> stray;
  std::vector<facyl::RecognitionTiming> timing;
  std::vector<double> object_counts;
  std::size_t failures = 0, wrong_plane = 0;
  SceneryCount on_scenery;
  facyl_cli::Progress progress("facyl_tabletop_eval", opt.sim, true);
  for (std::size_t k = 0; k < opt.sim; ++k) {
    progress.step(k > 0); // the scene before this one is done
    facyl::TabletopSceneParameters sp = opt.scene;
    sp.seed = opt.seed + k;
    facyl::RenderedScene scene = facyl::simulateTabletopScene(sp);
    if (opt.roll)
      rollScene(scene, opt.roll);
    Cloud::Ptr cloud(new Cloud(scene.cloud));
    rec.setInputCloud(cloud);
    std::vector<facyl::RecognizedObject> objects;
    std::map<int, Row> rows =
      simulatedRows(scene, sp.seed, opt.params.segmentation.min_cluster_size);
    if (!rec.recognize(objects)) {
      ++failures;
      for (auto& [id, r] : rows)
        all.push_back(r);
      continue;
    }
    if (k > 0) { // the first frame pays for the buffers
      timing.push_back(rec.getTiming());
      object_counts.push_back(static_cast<double>(objects.size()));
    }
    const auto& c = rec.getTableCoefficients().values;
    if (c.size() != 4 ||
        Eigen::Vector3f(c[0], c[1], c[2]).dot(scene.table_plane.head<3>()) < std::cos(0.1f) ||
        std::abs(c[3] - scene.table_plane[3]) > 0.03f) {
      if (c.size() != 4) {
        ++wrong_plane;
        std::fprintf(stderr, "scene %llu: no support found\n",
                     static_cast<unsigned long long>(sp.seed));
      }
      else {
        ++wrong_plane;
        std::fprintf(stderr,
                     "scene %llu: table (%.3f %.3f %.3f %.3f) is not the true one "
                     "(%.3f %.3f %.3f %.3f)\n",
                     static_cast<unsigned long long>(sp.seed), c[0], c[1], c[2], c[3],
                     scene.table_plane[0], scene.table_plane[1], scene.table_plane[2],
                     scene.table_plane[3]);
      }
    }
    const std::vector<int> truth = truthVector(*cloud, [&](std::size_t i) {
      if (scene.pixel_class[i] == facyl::SceneClass::Scenery)
        return kSceneryLabel;
      return scene.object_id[i] >= 2 ? static_cast<int>(scene.object_id[i]) : 0;
    });
    const SceneryCount scenery = matchObjects(objects, truth, rows, stray);
    on_scenery.objects += scenery.objects;
    on_scenery.cylinders += scenery.cylinders;
    scoreRows(objects, truth, rows);
    for (auto& [id, r] : rows) {
      if (r.positive && r.evidence.fitted) {
        const facyl::CylinderTruth t =
          facyl::cylinderTruth(scene.scene, scene.scene.objects[static_cast<std::size_t>(id - 2)]);
        r.axis_error_deg = facyl::axisAngle(objects[r.best].cylinder.axis, t.axis) * 180.f /
                           static_cast<float>(M_PI);
      }
      all.push_back(r);
    }
  }
  progress.step(); // the last scene
  csv.write(opt.layout == "spread" ? "sim-" + opt.sensor : "sim-" + opt.layout + "-" + opt.sensor,
            all);
  reportSimulated(all, stray, opt, failures, wrong_plane, on_scenery);
  timingReport(timing, object_counts);
  return 0;
}

// ---------------------------------------------------------------- mOSD

/** mOSD label field: object id = label / 10 for labels >= 20, 0 for the table (1..9). */
int
mosdObject(std::uint32_t label)
{
  return label >= 20 ? static_cast<int>(label / 10) : 0;
}

bool
loadMosd(const std::string& file, int roll, pcl::PointCloud<pcl::PointXYZRGBL>& labelled,
         Cloud& cloud)
{
  if (pcl::io::loadPCDFile(file, labelled) < 0)
    return false;
  if (roll)
    labelled = facyl::rollFrame(labelled, roll);
  pcl::copyPointCloud(labelled, cloud);
  return true;
}

/** scene -> object -> (class, pose, notes), from labels.csv. */
std::map<std::string, std::map<int, std::array<std::string, 3>>>
readMosdLabels(std::istream& in)
{
  std::map<std::string, std::map<int, std::array<std::string, 3>>> truth;
  for (const auto& f : facyl_cli::readCsvRows(in))
    if (f.size() >= 9)
      truth[f[1]][std::stoi(f[2])] = {f[3], f[4], f[8]};
  return truth;
}

/** Segmentation of learn0..44, by the dataset's scene groups. */
int
evaluateMosdSegmentation(const Options& opt, Recognizer& rec, CsvWriter& csv)
{
  const std::pair<int, int> groups[] = {{0, 16}, {17, 24}, {25, 32}, {33, 44}};
  const char* names[] = {"boxes (learn0-16)", "stacked boxes (learn17-24)",
                         "occluded objects (learn25-32)", "cylindric objects (learn33-44)"};
  std::vector<std::vector<Row>> by_group(4);
  std::vector<facyl::RecognitionTiming> timing;
  std::vector<double> object_counts;
  int status = 0;
  facyl_cli::Progress progress("facyl_tabletop_eval", 45, true);
  for (int g = 0; g < 4; ++g)
    for (int k = groups[g].first; k <= groups[g].second; ++k) {
      progress.step(k > 0); // the scene before this one is done
      const std::string name = "learn" + std::to_string(k);
      const std::string file = (std::filesystem::path(opt.mosd) / (name + ".pcd")).string();
      if (!std::filesystem::exists(file))
        continue;
      pcl::PointCloud<pcl::PointXYZRGBL> labelled;
      Cloud::Ptr cloud(new Cloud);
      if (!loadMosd(file, opt.roll, labelled, *cloud)) {
        std::fprintf(stderr, "facyl_tabletop_eval: cannot read %s\n", file.c_str());
        status = 1;
        continue;
      }
      const std::vector<int> truth =
        truthVector(*cloud, [&](std::size_t i) { return mosdObject(labelled[i].label); });
      std::map<int, Row> rows;
      for (const auto& outcome :
           facyl::scoreSegments(truth, {}, opt.params.segmentation.min_cluster_size)) {
        Row r;
        r.scene = name;
        r.object = outcome.object;
        rows[r.object] = r;
      }
      rec.setInputCloud(cloud);
      std::vector<facyl::RecognizedObject> objects;
      // Run twice: the second run gives the steady-state timing of a stream.
      if (rec.recognize(objects) && rec.recognize(objects)) {
        timing.push_back(rec.getTiming());
        object_counts.push_back(static_cast<double>(objects.size()));
      }
      else
        std::fprintf(stderr, "facyl_tabletop_eval: %s: no table\n", name.c_str());
      scoreRows(objects, truth, rows);
      for (auto& [id, r] : rows)
        by_group[static_cast<std::size_t>(g)].push_back(r);
    }
  progress.step(); // the last scene
  segmentationHeader("## mOSD learn scenes: segmentation against the dataset's labels (objects "
                     "with >= " +
                     std::to_string(opt.params.segmentation.min_cluster_size) + " points)");
  std::vector<Row> all;
  for (int g = 0; g < 4; ++g) {
    segmentationLine(by_group[g], names[g], [](const Row&) { return true; });
    all.insert(all.end(), by_group[g].begin(), by_group[g].end());
  }
  segmentationLine(all, "all", [](const Row&) { return true; });
  csv.write("mosd-segmentation", all);
  timingReport(timing, object_counts);
  return status;
}

/** Detection on the labelled cylinder scenes learn33..44. */
int
evaluateMosdDetection(const Options& opt, Recognizer& rec, CsvWriter& csv)
{
  std::ifstream labels_file(std::filesystem::path(opt.mosd) / "labels.csv");
  if (!labels_file) {
    std::fprintf(stderr, "facyl_tabletop_eval: cannot read %s/labels.csv\n", opt.mosd.c_str());
    return 1;
  }
  const auto truth_table = readMosdLabels(labels_file);
  std::vector<Row> all;
  std::vector<Stray> stray;
  std::map<std::string, std::vector<std::pair<std::string, float>>> radii; // by note
  int status = 0;
  const auto& d = opt.params.decision;
  for (const auto& [scene_name, objects_truth] : truth_table) {
    const std::string file = (std::filesystem::path(opt.mosd) / (scene_name + ".pcd")).string();
    pcl::PointCloud<pcl::PointXYZRGBL> labelled;
    Cloud::Ptr cloud(new Cloud);
    if (!loadMosd(file, opt.roll, labelled, *cloud)) {
      std::fprintf(stderr, "facyl_tabletop_eval: cannot read %s\n", file.c_str());
      status = 1;
      continue;
    }
    rec.setInputCloud(cloud);
    std::vector<facyl::RecognizedObject> objects;
    if (!rec.recognize(objects)) {
      std::fprintf(stderr, "facyl_tabletop_eval: %s: no table\n", scene_name.c_str());
      status = 1;
      continue;
    }
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
    const std::vector<int> truth =
      truthVector(*cloud, [&](std::size_t i) { return mosdObject(labelled[i].label); });
    matchObjects(objects, truth, rows, stray);
    scoreRows(objects, truth, rows);
    for (auto& [id, r] : rows) {
      all.push_back(r);
      const std::string& note = objects_truth.at(id)[2];
      if (called(r))
        for (const char* key :
             {"sticker", "plain white mug", "flower canister", "small white canister", "Pringles"})
          if (note.find(key) != std::string::npos)
            radii[key].emplace_back(scene_name, r.radius);
    }
  }
  csv.write("mosd", all);
  std::printf("\n## mOSD learn33-44 (%s): %zu labelled objects\n", opt.mosd.c_str(), all.size());
  for (const Row& r : all)
    std::printf(
      "- %s obj %d %s %s: pieces %zu%s%s, inlier ratio %.3f, surface ratio %.3f, "
      "radius %s%s\n",
      r.scene.c_str(), r.object, r.kind.c_str(), r.pose.c_str(), r.pieces,
      r.segment.merged ? " (merged with another object)" : "", r.segment.split ? " (split)" : "",
      r.evidence.inlier_ratio, r.evidence.surface_ratio,
      r.evidence.fitted ? (std::to_string(r.radius * 1000.f).substr(0, 5) + " mm").c_str() : "-",
      called(r) ? ", called a cylinder" : "");
  std::vector<Row> strict = all;
  for (Row& r : strict)
    r.positive = r.kind == "cylinder";
  reportDetection(strict, stray,
                  "Positives = class `cylinder` only (mugs and handled containers count as the "
                  "rest):",
                  d);
  reportDetection(all, stray, "Positives = `cylinder` and `cylinder_handle`:", d);
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
  return status;
}

void
printHelp(const char* self)
{
  std::printf(
    "Usage: %s [--sim N] [--first-seed S] [--layout spread|cluttered|realistic]\n"
    "          [--sensor kinect|stereo|random]\n"
    "          [--resolution WxH] [--dropout P] [--mosd DIR] [--roll DEG] [--csv FILE]\n"
    "          [recognizer options]\n"
    "Runs TabletopCylinderRecognizer on N simulated scenes (seeds S.., default 1000) and/or\n"
    "the mOSD learn scenes and prints: segmentation (objects recovered as one segment with\n"
    "IoU >= 0.5, merged, split; in simulation also for the objects touching another), cylinder\n"
    "precision/recall for both scores at several thresholds, radius and axis errors of the\n"
    "detected cylinders, and the stage timing. Output objects mostly on simulated scenery (far\n"
    "furniture, robots of --layout realistic) are neither true nor false detections. --csv\n"
    "writes one row per object. --roll turns every frame (and its ground truth) as a camera\n"
    "rolled by 90, 180 or 270 degrees clockwise about its optical axis would have taken it.\n"
    "--csv FILE must end in .csv and lie outside the --mosd folder (refused otherwise,\n"
    "nothing written).\n%s%s",
    self, facyl_cli::recognizerOptionsHelp(), facyl_cli::commonHelp());
}

Options
parseOptions(int argc, char** argv)
{
  Options opt;
  const facyl_cli::Arguments args(
    argc, argv,
    facyl_cli::joined(
      facyl_cli::recognizerValueOptions(),
      facyl_cli::joined(facyl_cli::sceneImageOptions(), {"--sim", "--first-seed", "--layout",
                                                         "--sensor", "--mosd", "--csv", "--roll"})),
    facyl_cli::recognizerSwitches(), facyl_cli::recognizerAliases());
  if (!args.positional().empty())
    throw std::invalid_argument("unexpected argument " + args.positional()[0]);
  opt.sim = static_cast<std::size_t>(args.integer("--sim", 0, 0, 100000));
  opt.seed = static_cast<std::uint64_t>(args.integer("--first-seed", 1000, 0, facyl_cli::kMaxSeed));
  opt.layout = args.text("--layout", "spread");
  if (!facyl::parseLayoutPreset(opt.layout, opt.scene))
    throw std::invalid_argument("--layout must be spread, cluttered or realistic");
  opt.sensor = args.text("--sensor", "kinect");
  if (!facyl::parseSensorPreset(opt.sensor, opt.scene.sensor, opt.scene.camera))
    throw std::invalid_argument("--sensor must be kinect, stereo or random");
  facyl_cli::applySceneImageOptions(args, opt.scene);
  opt.mosd = args.text("--mosd", "");
  opt.csv = args.text("--csv", "");
  if (args.has("--csv")) {
    std::vector<std::string> inputs;
    const std::string model = args.text("--model", "");
    if (!model.empty() && model != "default" && model != "none") {
      inputs.push_back(model);
      inputs.push_back(std::filesystem::path(model).replace_extension(".cfg").string());
    }
    facyl_cli::checkOutputFile("--csv", opt.csv, {".csv"}, "CSV table", inputs);
    // Never into the data set being read (its labels.csv, its scenes).
    if (!opt.mosd.empty()) {
      std::error_code ec;
      const auto data = std::filesystem::weakly_canonical(opt.mosd, ec);
      const auto csv = std::filesystem::weakly_canonical(opt.csv, ec).parent_path();
      const auto rel = csv.lexically_relative(data);
      if (!rel.empty() && rel.native().rfind("..", 0) != 0)
        throw std::invalid_argument("--csv " + opt.csv + ": lies in the --mosd folder " + opt.mosd +
                                    ", which is an input; facyl never writes into "
                                    "the data it reads. Nothing was written.");
    }
  }
  const long long roll = args.integer("--roll", 0, 0, 270);
  if (roll % 90 != 0)
    throw std::invalid_argument("--roll must be 0, 90, 180 or 270 (degrees)");
  opt.roll = static_cast<int>(roll / 90);
  facyl_cli::RecognizerSettings recognizer;
  opt.classifier = facyl_cli::applyRecognizerOptions(args, recognizer);
  opt.params = recognizer.params;
  opt.up = recognizer.up;
  if (opt.sim == 0 && opt.mosd.empty())
    throw std::invalid_argument("give --sim N and/or --mosd DIR");
  return opt;
}

} // namespace

int
main(int argc, char** argv)
{
  Options opt;
  const int rc = facyl_cli::startTool(argc, argv, "facyl_tabletop_eval", printHelp,
                                      [&] { opt = parseOptions(argc, argv); });
  if (rc >= 0)
    return rc;
  CsvWriter csv(opt.csv);
  Recognizer rec;
  rec.setParameters(opt.params);
  rec.setUpDirection(opt.up);
  rec.setClassifier(opt.classifier);
  int status = 0;
  if (opt.sim > 0)
    status = std::max(status, evaluateSimulated(opt, rec, csv));
  if (!opt.mosd.empty()) {
    status = std::max(status, evaluateMosdSegmentation(opt, rec, csv));
    status = std::max(status, evaluateMosdDetection(opt, rec, csv));
  }
  return status;
}
