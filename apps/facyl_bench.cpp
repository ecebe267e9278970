/*
 * facyl_bench: the paper's robustness study (Fig. 10, section IV-A) against PCL's
 * SACMODEL_CYLINDER. Sweeps noise, lid outliers (eq. 5) and occlusion (eq. 6) over simulated
 * cylinders; fits every scene with facyl's voting modes and priors and with PCL RANSAC/MLESAC on
 * the same cloud and normals; writes every fit (fits.csv) and a summary (summary.md).
 * scripts/bench_plot.py draws the figure from fits.csv.
 */
#include <facyl/tools/cli.h>
#include <facyl/tools/json_writer.h>
#include <facyl/tools/pcl_baseline.h>

#include <facyl/features/normal_curvature_estimation.h>
#include <facyl/features/parallel.h>
#include <facyl/sample_consensus_alt/hough_cylinder_estimation.h>
#include <facyl/simulation/cylinder_simulation.h>

#include <pcl/common/io.h>
#include <pcl/common/time.h>
#include <pcl/console/print.h>
#include <pcl/io/pcd_io.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <mutex>
#include <random>
#include <sstream>

namespace {

using Cloud = pcl::PointCloud<pcl::PointXYZ>;
using Cues = pcl::PointCloud<facyl::NormalCurvature>;
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

struct Level {
  std::string sweep; ///< noise | outliers | occlusion | clutter
  float value;       ///< the swept quantity (noise: sigma / r; outliers: eq. 5; occlusion: eq. 6)
  float noise, lids, occlusion;
};

/** The level of \a sweep at \a value: the swept quantity, the others at their fixed values
 * (1% noise, no lids, no occlusion; clutter: lids at 300% and the occlusion \a value). */
Level
levelOf(const std::string& sweep, float value)
{
  if (sweep == "noise")
    return {sweep, value, value, 0.f, 0.f};
  if (sweep == "outliers")
    return {sweep, value, 0.01f, value, 0.f};
  if (sweep == "occlusion")
    return {sweep, value, 0.01f, 0.f, value};
  if (sweep == "clutter")
    return {sweep, value, 0.01f, 3.f, value};
  throw std::invalid_argument("unknown sweep '" + sweep + "'");
}

/** --levels "SWEEP:V,V,...;SWEEP:V,...": the levels to run instead of the paper's. */
std::vector<Level>
parseLevels(const std::string& spec)
{
  std::vector<Level> out;
  std::stringstream groups(spec);
  for (std::string group; std::getline(groups, group, ';');) {
    const auto colon = group.find(':');
    if (colon == std::string::npos)
      throw std::invalid_argument("--levels wants SWEEP:V,V,...;SWEEP:V,... (got '" + group + "')");
    const std::string sweep = group.substr(0, colon);
    std::stringstream values(group.substr(colon + 1));
    for (std::string v; std::getline(values, v, ',');) {
      std::size_t used = 0;
      float value = 0.f;
      try {
        value = std::stof(v, &used);
      }
      catch (const std::exception&) {
        used = 0;
      }
      if (used != v.size() || !(value >= 0.f) || (sweep != "outliers" && !(value < 1.f)))
        throw std::invalid_argument("--levels: '" + v + "' is not a level of " + sweep);
      out.push_back(levelOf(sweep, value));
    }
  }
  if (out.empty())
    throw std::invalid_argument("--levels names no level");
  return out;
}

std::vector<Level>
levels()
{
  std::vector<Level> out;
  for (int i = 0; i <= 8; ++i) // noise 0-20% of the radius, 9 levels
    out.push_back(levelOf("noise", 0.025f * i));
  for (int i = 0; i <= 10; ++i) // lids 0-500%, 11 levels
    out.push_back(levelOf("outliers", 0.5f * i));
  for (int i = 0; i <= 9; ++i) // occlusion 0-90%, 10 levels
    out.push_back(levelOf("occlusion", 0.1f * i));
  return out;
}

struct Method {
  std::string name;
  bool pcl{false};
  facyl::VotingMode mode{facyl::VotingMode::SoftCurvature};
  facyl::OrientationPrior prior{facyl::OrientationPrior::Uniform};
  int sac{pcl::SAC_RANSAC};
  bool axis{false};
  /** facyl 0.1's refinement: the best candidate alone, on its inliers (point_candidates 0),
   * to compare with the refinement on the points on the same clouds. */
  bool inliers_only{false};
};

std::vector<Method>
methods(const std::string& setting)
{
  using facyl::OrientationPrior;
  using facyl::VotingMode;
  std::vector<Method> m = {
    {"facyl-rabbani", false, VotingMode::Rabbani},
    {"facyl-soft-normal", false, VotingMode::SoftNormal},
    {"facyl-soft-curvature", false, VotingMode::SoftCurvature},
    {"facyl-soft-curvature-0.1", false, VotingMode::SoftCurvature, OrientationPrior::Uniform,
     pcl::SAC_RANSAC, false, true},
  };
  if (setting == "paper") { // the axis is vertical: the priors of Table II apply
    m.push_back(
      {"facyl-soft-curvature-mild", false, VotingMode::SoftCurvature, OrientationPrior::Vertical});
    m.push_back({"facyl-soft-curvature-strong", false, VotingMode::SoftCurvature,
                 OrientationPrior::VerticalStrong});
  }
  m.push_back(
    {"pcl-ransac", true, VotingMode::SoftCurvature, OrientationPrior::Uniform, pcl::SAC_RANSAC});
  m.push_back(
    {"pcl-mlesac", true, VotingMode::SoftCurvature, OrientationPrior::Uniform, pcl::SAC_MLESAC});
  if (setting == "paper")
    m.push_back({"pcl-ransac-axis", true, VotingMode::SoftCurvature, OrientationPrior::Uniform,
                 pcl::SAC_RANSAC, true});
  return m;
}

struct Fit {
  bool found{false};
  float axis_deg{kNaN}, radius_err{kNaN}, position_err{kNaN}, time_ms{0.f};
};

struct Task {
  std::string setting;
  std::size_t level;
  int scene;
};

/** One scene of a setting at a level: the cloud and its ground truth. */
struct Scene {
  Cloud::Ptr cloud{new Cloud};
  facyl::CylinderGroundTruth truth;
};

Scene
makeScene(const std::string& setting, const Level& level, int scene, std::uint64_t seed)
{
  // One seed per (setting, scene): every level sees the same cylinders, as in the paper.
  const std::uint64_t salt = setting == "paper" ? 0ULL : setting == "practical" ? 1ULL : 2ULL;
  std::mt19937_64 rng(seed * 1000003ULL + static_cast<std::uint64_t>(scene) * 7919ULL + salt);
  std::uniform_real_distribution<float> unit(0.f, 1.f);
  facyl::CylinderSimulationParameters p;
  p.lateral_points = 900;
  p.noise = level.noise;
  p.lid_ratio = level.lids;
  p.occlusion = level.occlusion;
  p.height = 0.05f + 1.95f * unit(rng);
  if (setting == "paper") {
    p.radius = 0.3f;
    p.axis = Eigen::Vector3f::UnitZ();
    p.base = Eigen::Vector3f(0.2f, -0.1f, 1.5f);
  }
  else {
    p.radius = 0.02f + 0.28f * unit(rng);
    p.random_axis = true;
    p.base = Eigen::Vector3f(0.1f, 0.f, 1.5f);
  }
  p.seed = rng();
  const auto sim = facyl::simulateCylinder(p);
  Scene s;
  s.truth = sim.truth;
  for (const auto& q : sim.cloud)
    s.cloud->push_back(pcl::PointXYZ(q.x, q.y, q.z));
  if (setting == "practical") {
    // A table-like plane beside the cylinder: twice its size, as many points as its side,
    // random orientation, the same noise.
    std::normal_distribution<float> g;
    Eigen::Vector3f n(g(rng), g(rng), g(rng));
    n.normalize();
    Eigen::Vector3f d = n.cross(Eigen::Vector3f(g(rng), g(rng), g(rng))).normalized();
    const float size = 2.f * std::max(p.height, 2.f * p.radius);
    const Eigen::Vector3f centre =
      sim.truth.base + 0.5f * p.height * sim.truth.axis + (p.radius + 0.5f * size + 0.02f) * d;
    const auto plane =
      facyl::simulatePlane(centre, n, size, size, 900, level.noise * p.radius, rng());
    for (const auto& q : plane)
      s.cloud->push_back(pcl::PointXYZ(q.x, q.y, q.z));
  }
  s.cloud->width = static_cast<std::uint32_t>(s.cloud->size());
  s.cloud->height = 1;
  return s;
}

Fit
score(const std::vector<facyl::CylinderModel>& models, const facyl::CylinderGroundTruth& t,
      double ms)
{
  Fit f;
  f.time_ms = static_cast<float>(ms);
  if (models.empty())
    return f;
  const auto& m = models.front();
  f.found = true;
  f.axis_deg = facyl::axisAngle(m.axis, t.axis) * 180.f / static_cast<float>(M_PI);
  f.radius_err = std::abs(m.radius - t.radius);
  f.position_err = facyl::distanceToLine(t.base, m.point_on_axis, m.axis);
  return f;
}

std::vector<Fit>
runTask(const Task& task, const Level& level, const std::vector<Method>& ms, std::uint64_t seed)
{
  const Scene s = makeScene(task.setting, level, task.scene, seed);
  Cues::Ptr cues(new Cues);
  facyl::NormalCurvatureEstimation<pcl::PointXYZ> ne;
  ne.setInputCloud(s.cloud);
  ne.setKSearch(facyl::kDefaultNeighbours);
  ne.setNumberOfThreads(1);
  ne.compute(*cues);
  pcl::PointCloud<pcl::Normal>::Ptr normals(new pcl::PointCloud<pcl::Normal>);
  pcl::copyPointCloud(*cues, *normals);
  const float r_min = 0.01f, r_max = 0.6f; // the same radius limits for every method
  std::vector<Fit> fits;
  for (const auto& m : ms) {
    std::vector<facyl::CylinderModel> models;
    pcl::StopWatch watch;
    if (m.pcl) {
      facyl_cli::PclCylinderOptions o;
      o.method = m.sac;
      // PCL needs a fixed inlier threshold; it is given the true noise (2.5 sigma, at least
      // 5 mm), which facyl estimates by itself.
      o.distance_threshold = std::max(0.005f, 2.5f * level.noise * s.truth.radius);
      o.radius_min = r_min;
      o.radius_max = r_max;
      o.max_iterations = 500; // the tutorial's 10000 takes seconds per cloud with lids
      o.use_axis = m.axis;
      models = facyl_cli::fitPclCylinders<pcl::PointXYZ>(s.cloud, normals, o);
    }
    else {
      facyl::HoughCylinderEstimation<pcl::PointXYZ, facyl::NormalCurvature> hough;
      hough.setVotingMode(m.mode);
      hough.setDiagnoseFailures(false); // timed: no second search when none is found
      hough.setOrientationPrior(m.prior);
      hough.setRadiusLimits(r_min, r_max);
      if (m.inliers_only)
        hough.setPointCandidates(0);
      hough.setSeed(seed * 7919ULL + static_cast<std::uint64_t>(task.scene)); // a fresh draw
      hough.setInputCloud(s.cloud);
      hough.setInputNormals(cues);
      hough.segment(models);
    }
    fits.push_back(score(models, s.truth, watch.getTime()));
  }
  return fits;
}

float
quantile(std::vector<float> v, double q)
{
  if (v.empty())
    return kNaN;
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1) + 0.5)];
}

std::string
fmt(float v, int digits = 3)
{
  if (std::isinf(v))
    return "∞";
  if (std::isnan(v))
    return "—";
  char b[32];
  std::snprintf(b, sizeof b, "%.*f", digits, v);
  return b;
}

void
printHelp(const char* self)
{
  std::printf(
    "Usage: %s [options]\n"
    "Robustness study of the paper's Fig. 10 against PCL SACMODEL_CYLINDER.\n"
    "  --scenes N     cylinders per setting (default 1000, as in the paper)\n"
    "  --quick        50 scenes (a smoke test; about 4 minutes on 2 cores)\n"
    "  --settings S   paper,practical (default both): paper = r 0.3 m, vertical axis;\n"
    "                 practical = random axis, r 0.02-0.3 m, a table-like plane beside it;\n"
    "                 random = random axis, r 0.02-0.3 m, nothing else (other cylinders)\n"
    "  --levels L     levels to run instead of the paper's sweeps, e.g.\n"
    "                 'noise:0.1,0.15,0.2,0.3;outliers:1,3,5;occlusion:0.75;clutter:0.5'\n"
    "                 (sweeps noise, outliers, occlusion, and clutter: lids at 300%% with\n"
    "                 that occlusion; 1%% noise where noise is not swept)\n"
    "  --methods M    only these methods (comma-separated names as in fits.csv)\n"
    "  --seed S       seed (default 1); the same seed gives the same fits\n"
    "  --threads T    threads (default: all cores)\n"
    "  --out DIR      output folder (default bench_out): fits.csv, summary.md\n"
    "  --dump SETTING,SWEEP,LEVEL,SCENE  write that scene to DIR/scene.pcd (to rerun one fit\n"
    "                 with facyl_fit) and stop; LEVEL as in fits.csv\n%s",
    self, facyl_cli::commonHelp());
}

} // namespace

/** The command line. */
struct Options {
  int scenes{1000}, threads{0};
  std::uint64_t seed{1};
  std::string out{"bench_out"}, dump, method_filter;
  std::vector<std::string> settings{"paper", "practical"};
  std::vector<Level> levels{::levels()};
};

/** Reads the options. \throws std::invalid_argument for a bad one. */
Options
parseOptions(int argc, char** argv)
{
  Options o;
  const facyl_cli::Arguments args(
    argc, argv,
    {"--scenes", "--settings", "--seed", "--threads", "--out", "--dump", "--levels", "--methods"},
    {"--quick"});
  o.dump = args.text("--dump", "");
  if (!args.positional().empty())
    throw std::invalid_argument("unexpected argument " + args.positional()[0]);
  o.scenes =
    static_cast<int>(args.integer("--scenes", args.has("--quick") ? 50 : 1000, 1, 1000000));
  o.seed = static_cast<std::uint64_t>(args.integer("--seed", 1, 0, facyl_cli::kMaxSeed));
  o.threads = static_cast<int>(args.integer("--threads", 0, 0, 256));
  o.out = args.text("--out", o.out);
  facyl_cli::checkOutputFolder("--out", o.out, [](const std::string&) { return false; }, {});
  o.settings.clear();
  std::stringstream ss(args.text("--settings", "paper,practical"));
  for (std::string s; std::getline(ss, s, ',');) {
    if (s != "paper" && s != "practical" && s != "random")
      throw std::invalid_argument("unknown setting '" + s + "'");
    o.settings.push_back(s);
  }
  if (args.has("--levels"))
    o.levels = parseLevels(args.text("--levels", ""));
  o.method_filter = args.text("--methods", "");
  return o;
}

/** --dump: writes the scene SETTING,SWEEP,LEVEL,SCENE to OUT/scene.pcd and prints its truth.
 * \return the exit status. */
int
dumpScene(const Options& o)
{
  std::stringstream ss(o.dump);
  std::string setting, sweep, level, scene;
  std::getline(ss, setting, ',');
  std::getline(ss, sweep, ',');
  std::getline(ss, level, ',');
  std::getline(ss, scene, ',');
  for (const auto& l : o.levels)
    if (l.sweep == sweep && !level.empty() && std::abs(l.value - std::stof(level)) < 1e-4f &&
        (setting == "paper" || setting == "practical" || setting == "random") && !scene.empty()) {
      const Scene s = makeScene(setting, l, std::stoi(scene), o.seed);
      pcl::io::savePCDFileBinary(o.out + "/scene.pcd", *s.cloud);
      facyl_cli::Json line;
      line["file"] = o.out + "/scene.pcd";
      line["radius"] = facyl_cli::jsonNumber(s.truth.radius);
      line["axis"] = facyl_cli::jsonVector(s.truth.axis);
      line["base"] = facyl_cli::jsonVector(s.truth.base);
      std::printf("%s\n", facyl_cli::dumpJson(line).c_str());
      return 0;
    }
  std::fprintf(stderr, "facyl_bench: --dump wants SETTING,SWEEP,LEVEL,SCENE as in fits.csv\n");
  return 2;
}

/** The methods of each setting, kept to --methods when given. \throws std::invalid_argument
 * when --methods leaves a setting without any. */
std::map<std::string, std::vector<Method>>
methodSets(const Options& o)
{
  std::map<std::string, std::vector<Method>> sets;
  for (const auto& s : o.settings) {
    auto& ms = sets[s] = methods(s);
    if (o.method_filter.empty())
      continue;
    const std::string list = "," + o.method_filter + ",";
    ms.erase(std::remove_if(
               ms.begin(), ms.end(),
               [&](const Method& m) { return list.find("," + m.name + ",") == std::string::npos; }),
             ms.end());
    if (ms.empty())
      throw std::invalid_argument("--methods names no method of setting " + s);
  }
  return sets;
}

/** Every fit, one line each, to OUT/fits.csv. */
void
writeFits(const Options& o, const std::vector<Task>& tasks,
          std::map<std::string, std::vector<Method>>& method_sets,
          const std::vector<std::vector<Fit>>& results)
{
  std::ofstream csv(o.out + "/fits.csv");
  csv << "setting,sweep,level,scene,method,found,axis_error_deg,radius_error_m,"
         "position_error_m,time_ms\n";
  for (std::size_t i = 0; i < tasks.size(); ++i) {
    const auto& t = tasks[i];
    const auto& ms = method_sets[t.setting];
    for (std::size_t m = 0; m < ms.size(); ++m) {
      const auto& f = results[i][m];
      csv << t.setting << ',' << o.levels[t.level].sweep << ',' << o.levels[t.level].value << ','
          << t.scene << ',' << ms[m].name << ',' << f.found << ',' << f.axis_deg << ','
          << f.radius_err << ',' << f.position_err << ',' << f.time_ms << '\n';
    }
  }
}

/** OUT/summary.md: per setting, sweep, method and level. A fit that found nothing counts as
 * an infinite error (and a failure), so medians stay honest. */
void
writeSummary(const Options& o, const std::vector<Task>& tasks,
             std::map<std::string, std::vector<Method>>& method_sets,
             const std::vector<std::vector<Fit>>& results, int workers, double elapsed)
{
  const auto& lv = o.levels;
  const auto& settings = o.settings;
  const int scenes = o.scenes;
  const std::uint64_t seed = o.seed;
  std::ofstream md(o.out + "/summary.md");
  md << "# facyl_bench summary\n\n"
     << scenes << " scenes per setting and level, seed " << seed << ", " << workers << " threads, "
     << fmt(static_cast<float>(elapsed), 0)
     << " s. Failure: axis error > 10 deg or no cylinder. Errors: median / 90th percentile; "
        "radius and position in mm; time: median fit time (normals excluded, shared).\n";
  for (const auto& s : settings) {
    const auto& ms = method_sets[s];
    for (const std::string sweep : {"noise", "outliers", "occlusion", "clutter"}) {
      if (std::none_of(lv.begin(), lv.end(), [&](const Level& l) { return l.sweep == sweep; }))
        continue;
      md << "\n## " << s << ": " << sweep << "\n\n| method | level | axis (deg) | radius (mm) | "
         << "position (mm) | failures | time (ms) |\n|---|---|---|---|---|---|---|\n";
      std::map<std::pair<std::size_t, std::size_t>, float> median_time;
      for (std::size_t m = 0; m < ms.size(); ++m)
        for (std::size_t l = 0; l < lv.size(); ++l) {
          if (lv[l].sweep != sweep)
            continue;
          std::vector<float> ax, ra, po, ti;
          int failures = 0, n = 0;
          for (std::size_t i = 0; i < tasks.size(); ++i) {
            if (tasks[i].setting != s || tasks[i].level != l)
              continue;
            const auto& f = results[i][m];
            const float inf = std::numeric_limits<float>::infinity();
            ax.push_back(f.found ? f.axis_deg : inf);
            ra.push_back(f.found ? 1000.f * f.radius_err : inf);
            po.push_back(f.found ? 1000.f * f.position_err : inf);
            ti.push_back(f.time_ms);
            failures += !f.found || f.axis_deg > 10.f;
            ++n;
          }
          median_time[{m, l}] = quantile(ti, 0.5);
          md << "| " << ms[m].name << " | " << fmt(lv[l].value, 3) << " | "
             << fmt(quantile(ax, 0.5)) << " / " << fmt(quantile(ax, 0.9)) << " | "
             << fmt(quantile(ra, 0.5), 2) << " / " << fmt(quantile(ra, 0.9), 2) << " | "
             << fmt(quantile(po, 0.5), 2) << " / " << fmt(quantile(po, 0.9), 2) << " | "
             << fmt(100.f * failures / std::max(1, n), 1) << "% | " << fmt(quantile(ti, 0.5))
             << " |\n";
        }
      // Speed against PCL RANSAC, same run, same clouds.
      const auto find = [&](const std::string& name) {
        for (std::size_t m = 0; m < ms.size(); ++m)
          if (ms[m].name == name)
            return m;
        return ms.size();
      };
      const std::size_t soft = find("facyl-soft-curvature"), ransac = find("pcl-ransac");
      if (soft == ms.size() || ransac == ms.size())
        continue;
      md << "\nMedian fit time, pcl-ransac / facyl-soft-curvature:";
      for (std::size_t l = 0; l < lv.size(); ++l)
        if (lv[l].sweep == sweep)
          md << " " << fmt(lv[l].value, 3) << ": "
             << fmt(median_time[{ransac, l}] / median_time[{soft, l}], 1) << "x;";
      md << "\n";
    }
  }
  md.close();
}

int
main(int argc, char** argv)
{
  Options o;
  const int rc = facyl_cli::startTool(argc, argv, "facyl_bench", printHelp,
                                      [&] { o = parseOptions(argc, argv); });
  if (rc >= 0)
    return rc;
  std::error_code ec;
  std::filesystem::create_directories(o.out, ec);
  if (ec) {
    std::fprintf(stderr, "facyl_bench: cannot create %s: %s\n", o.out.c_str(),
                 ec.message().c_str());
    return 1;
  }
  pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS); // "no cylinder" is a result here
  if (!o.dump.empty())
    return dumpScene(o);
  std::map<std::string, std::vector<Method>> method_sets;
  try {
    method_sets = methodSets(o);
  }
  catch (const std::exception& e) {
    std::fprintf(stderr, "facyl_bench: %s\n", e.what());
    return 2;
  }
  std::vector<Task> tasks;
  for (const auto& s : o.settings)
    for (std::size_t l = 0; l < o.levels.size(); ++l)
      for (int k = 0; k < o.scenes; ++k)
        tasks.push_back({s, l, k});
  std::vector<std::vector<Fit>> results(tasks.size());
  const int workers = facyl::parallelWorkers(tasks.size(), o.threads, 1);
  std::fprintf(stderr,
               "facyl_bench: %zu scene-levels (%d scenes x %zu levels x %zu settings) on "
               "%d threads\n",
               tasks.size(), o.scenes, o.levels.size(), o.settings.size(), workers);
  const auto start = std::chrono::steady_clock::now();
  {
    facyl_cli::Progress progress("facyl_bench", tasks.size(), true);
    facyl::parallelFor(tasks.size(), o.threads, 1, [&](std::size_t i, std::size_t) {
      const auto& t = tasks[i];
      results[i] = runTask(t, o.levels[t.level], method_sets[t.setting], o.seed);
      progress.step();
    });
  }
  const double elapsed =
    std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  writeFits(o, tasks, method_sets, results);
  writeSummary(o, tasks, method_sets, results, workers, elapsed);
  std::fprintf(stderr, "facyl_bench: wrote %s/fits.csv and %s/summary.md in %.0f s\n",
               o.out.c_str(), o.out.c_str(), elapsed);
  return 0;
}
