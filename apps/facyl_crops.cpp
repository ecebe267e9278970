/*
 * facyl_crops: the shape classifier's data. Runs the tabletop recognizer (without a
 * classifier) on simulated scenes and writes, for every object it reports, the network's input
 * images (classifierImage, both channel sets) and one CSV row: the ground truth and the fit's
 * evidence (evidenceFeatures). Also the single-object crops of the UW RGB-D Object dataset, and
 * real crops harvested from mOSD's scenes of boxes only.
 * recognition/training reads what it writes; with --model the rows also get the network's
 * probability from CylinderClassifier (the C++ side of a model, for checks and evaluation).
 *
 *   OUT/rgb.u8    3 x size x size bytes per object, planar
 *   OUT/depth.u8  2 x size x size bytes per object, planar
 *   OUT/objects.csv
 */
#include <facyl/tools/cli.h>
#include <facyl/tools/cylinder_fit.h>
#include <facyl/tools/json_writer.h>
#include <facyl/tools/recognizer_options.h>
#include <facyl/tools/scene_options.h>

#include <facyl/features/normal_curvature_estimation.h>
#include <facyl/recognition/classifier_input.h>
#include <facyl/recognition/cylinder_classifier.h>
#include <facyl/recognition/tabletop_cylinder_recognizer.h>
#include <facyl/sample_consensus_alt/hough_cylinder_estimation.h>
#include <facyl/simulation/tabletop_scene.h>

#include <pcl/PCLPointCloud2.h>
#include <pcl/common/io.h>
#include <pcl/console/print.h>
#include <pcl/io/pcd_io.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

namespace {

using Cloud = pcl::PointCloud<pcl::PointXYZRGBA>;
using Recognizer = facyl::TabletopCylinderRecognizer<pcl::PointXYZRGBA>;

constexpr int kDefaultSize = 64;
constexpr std::uint64_t kDefaultSeed = 50000;

void
printHelp(const char* self)
{
  std::printf(
    "Usage: %s [options] OUT_DIR\n"
    "Writes the shape classifier's data to OUT_DIR: rgb.u8 and depth.u8 (the network's input\n"
    "images of every object, 3 resp. 2 x size x size bytes, planar; depthrgb is depth's\n"
    "planes followed by rgb's) and objects.csv (one row per object: ground truth, fit\n"
    "evidence and fusion features).\n"
    "  --sim N            simulated scenes: the recognizer's objects, labelled by the\n"
    "                     ground truth (default 0)\n"
    "  --seed S           seed of the first scene (default %llu); scene k uses S + k\n"
    "  --layout L[,L...]  layouts taken in turn: scene k has layout k mod n of the list\n"
    "                     (spread | cluttered | realistic; a layout may repeat to weigh it);\n"
    "                     mix (default) = spread,cluttered\n"
    "  --sensor S[,S...]  sensors taken in turn after each round of layouts: scene k has\n"
    "                     sensor (k / layouts) mod n (kinect | stereo | random);\n"
    "                     mix (default) = kinect,stereo\n"
    "                     Objects that are mostly scenery (far furniture, robots of the\n"
    "                     realistic layout) are skipped: neither targets nor distractors.\n"
    "  --uw DIR           also the UW RGB-D Object crops in DIR (*.pcd with x y z rgb imX imY;\n"
    "                     the category is the file name up to _<digit>)\n"
    "  --mosd DIR         also real crops harvested from mOSD frames DIR/learnK.pcd the\n"
    "                     paper's way (III-B1): scenes that hold boxes only, so every object\n"
    "                     is a non-cylinder; an object the recognizer reports is kept where\n"
    "                     it agrees with one of the dataset's labelled objects (IoU >= 0.5)\n"
    "  --mosd-scenes A-B  those scenes (default 0-29; learn30-44 hold cylinders, and\n"
    "                     learn33-44 are an evaluation set: refused)\n"
    "  --size S           image size (default %d)\n"
    "  --model M          none (default) | default | PATH.onnx: adds the network's probability\n"
    "OUT is a folder that exists; it gets rgb.u8, depth.u8 and objects.csv (refused when\n"
    "one of them is an input).\n%s"
    "Exit status: 0, 1 when a scene or file failed, 2 for bad usage (nothing written).\n",
    self, static_cast<unsigned long long>(kDefaultSeed), kDefaultSize, facyl_cli::commonHelp());
}

struct Settings {
  std::size_t sim{0};
  std::uint64_t seed{kDefaultSeed};
  std::vector<std::string> layouts{"spread", "cluttered"}, sensors{"kinect", "stereo"};
  std::string uw, mosd, out;
  int mosd_first{0}, mosd_last{29};
  int size{kDefaultSize};
  facyl::ShapeClassifier::Ptr classifier;
};

/** Appends the images and rows of objects. */
class DataWriter {
public:
  DataWriter(const std::string& dir, int size)
      : size_(size)
  {
    rgb_.open(dir + "/rgb.u8", std::ios::binary);
    depth_.open(dir + "/depth.u8", std::ios::binary);
    csv_.open(dir + "/objects.csv");
    if (!rgb_ || !depth_ || !csv_)
      throw std::invalid_argument("cannot write to " + dir);
    csv_ << "row,source,scene,object,kind,label,purity,n_points,fitted,passes_gates,"
            "inlier_ratio,surface_ratio";
    for (std::size_t i = 0; i < facyl::kEvidenceFeatures; ++i)
      csv_ << ",f" << i;
    csv_ << ",p_network\n";
  }

  /** One object; \a p_network NaN without a model. */
  void write(const facyl::ObjectView& view, const std::string& source, const std::string& scene,
             int object, const std::string& kind, int label, float purity,
             const facyl::CylinderEvidence& evidence, float p_network)
  {
    for (const auto channels : {facyl::ClassifierChannels::Rgb, facyl::ClassifierChannels::Depth}) {
      std::vector<std::uint8_t> image = facyl::classifierImage(view, {channels, size_});
      image.resize(static_cast<std::size_t>(facyl::channelCount(channels) * size_ * size_), 0);
      auto& out = channels == facyl::ClassifierChannels::Rgb ? rgb_ : depth_;
      out.write(reinterpret_cast<const char*>(image.data()),
                static_cast<std::streamsize>(image.size()));
    }
    const facyl::CylinderDecision decision;
    const auto f = facyl::evidenceFeatures(std::numeric_limits<float>::quiet_NaN(), evidence);
    csv_ << rows_++ << "," << source << "," << scene << "," << object << "," << kind << "," << label
         << "," << purity << "," << view.points.cols() << "," << evidence.fitted << ","
         << facyl::passesGates(evidence, decision) << "," << evidence.inlier_ratio << ","
         << evidence.surface_ratio;
    for (const float x : f)
      csv_ << "," << x;
    csv_ << "," << p_network << "\n";
  }
  std::size_t rows() const
  {
    return rows_;
  }

private:
  int size_;
  std::ofstream rgb_, depth_, csv_;
  std::size_t rows_{0};
};

float
networkProbability(const Settings& s, const facyl::ObjectView& view)
{
  return s.classifier ? s.classifier->cylinderProbability(view)
                      : std::numeric_limits<float>::quiet_NaN();
}

/** The scene parameters of simulated scene \a k: its layout and sensor from the lists, taken
 * in turn (the default lists give the first model's mix: spread and cluttered alternate, two
 * Kinect-like scenes, then two stereo ones). */
facyl::TabletopSceneParameters
sceneParameters(const Settings& s, std::size_t k)
{
  facyl::TabletopSceneParameters p;
  facyl::parseLayoutPreset(s.layouts[k % s.layouts.size()], p);
  facyl::parseSensorPreset(s.sensors[(k / s.layouts.size()) % s.sensors.size()], p.sensor,
                           p.camera);
  p.seed = s.seed + k;
  return p;
}

/** The objects of one simulated scene. \return false when the recognizer found no table. */
bool
simulatedScene(const Settings& s, std::size_t k, Recognizer& rec, DataWriter& out)
{
  const facyl::TabletopSceneParameters p = sceneParameters(s, k);
  const facyl::RenderedScene scene = facyl::simulateTabletopScene(p);
  Cloud::Ptr cloud(new Cloud(scene.cloud));
  rec.setInputCloud(cloud);
  std::vector<facyl::RecognizedObject> objects;
  if (!rec.recognize(objects))
    return false;
  const facyl::PinholeCamera none;
  for (std::size_t j = 0; j < objects.size(); ++j) {
    const auto& o = objects[j];
    std::map<int, std::size_t> votes;
    for (const auto i : o.cluster.indices.indices)
      ++votes[scene.object_id[static_cast<std::size_t>(i)]];
    int id = 0;
    std::size_t most = 0;
    for (const auto& [l, c] : votes)
      if (c > most)
        id = l, most = c;
    const float purity =
      static_cast<float>(most) /
      static_cast<float>(std::max<std::size_t>(1, o.cluster.indices.indices.size()));
    // Scenery (far furniture and what stands on it, robots) holds cans and cylindrical
    // links as well as boxes, and its class says nothing about its shape: neither a
    // cylinder nor a distractor, as facyl_tabletop_eval scores it.
    if (id >= facyl::kFirstSceneryId)
      continue;
    std::string kind = id == 0 ? "background" : (id == 1 ? "table" : "");
    int label = 0;
    if (id >= 2) {
      const auto& so = scene.scene.objects[static_cast<std::size_t>(id - 2)];
      kind = so.kind + (so.handle ? "_handle" : "");
      label = so.cls == facyl::SceneClass::Cylinder && purity >= 0.5f ? 1 : 0;
    }
    const facyl::ObjectView view = facyl::objectView(*cloud, o.cluster.indices.indices, none);
    out.write(view, "sim", std::to_string(p.seed), static_cast<int>(j), kind, label, purity,
              o.evidence, networkProbability(s, view));
  }
  return true;
}

/** Reads a float field of a PCLPointCloud2 (FLOAT32 only); empty when absent. */
std::vector<float>
floatField(const pcl::PCLPointCloud2& blob, const std::string& name)
{
  for (const auto& f : blob.fields)
    if (f.name == name && f.datatype == pcl::PCLPointField::FLOAT32) {
      std::vector<float> v(blob.width * blob.height);
      for (std::size_t i = 0; i < v.size(); ++i)
        std::memcpy(&v[i], &blob.data[i * blob.point_step + f.offset], sizeof(float));
      return v;
    }
  return {};
}

/** The category of a UW file name: up to the first "_<digit>". */
std::string
uwCategory(const std::string& stem)
{
  for (std::size_t i = 0; i + 1 < stem.size(); ++i)
    if (stem[i] == '_' && std::isdigit(static_cast<unsigned char>(stem[i + 1])))
      return stem.substr(0, i);
  return stem;
}

bool
uwIsCylinder(const std::string& category)
{
  for (const char* c : {"soda_can", "food_can", "food_jar", "coffee_mug", "glue_stick", "marker",
                        "dry_battery", "flashlight"})
    if (category == c)
      return true;
  return false;
}

/** The evidence of a UW crop: the paper's fit (HoughCylinderEstimation, defaults) and its
 * inlier ratio (eq. 4); surface ratio is left at the inlier ratio. */
facyl::CylinderEvidence
uwEvidence(const pcl::PointCloud<pcl::PointXYZRGB>& cloud)
{
  pcl::PointCloud<pcl::PointXYZ>::Ptr xyz(new pcl::PointCloud<pcl::PointXYZ>);
  pcl::copyPointCloud(cloud, *xyz);
  const auto cues = facyl_cli::estimateFitCues(xyz, 16, 0, nullptr);
  facyl::HoughCylinderEstimation<pcl::PointXYZ, facyl::NormalCurvature> hough;
  hough.setInputCloud(xyz);
  hough.setInputNormals(cues);
  std::vector<facyl::CylinderModel> models;
  facyl::CylinderEvidence e;
  if (hough.segment(models) && !models.empty()) {
    e.fitted = true;
    e.inlier_ratio = models.front().inlier_ratio;
    e.surface_ratio = e.inlier_ratio;
    e.angular_coverage = 1.f;
  }
  return e;
}

/** The UW crops of \a dir. \return the number of files that failed. */
std::size_t
uwCrops(const Settings& s, DataWriter& out)
{
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(s.uw))
    if (e.path().extension() == ".pcd")
      files.push_back(e.path());
  std::sort(files.begin(), files.end());
  std::size_t failed = 0;
  for (const auto& f : files) {
    pcl::PCLPointCloud2 blob;
    pcl::PointCloud<pcl::PointXYZRGB> cloud;
    if (pcl::io::loadPCDFile(f.string(), blob) < 0) {
      std::fprintf(stderr, "facyl_crops: cannot read %s\n", f.c_str());
      ++failed;
      continue;
    }
    pcl::fromPCLPointCloud2(blob, cloud);
    const std::vector<float> u = floatField(blob, "imX"), v = floatField(blob, "imY");
    if (u.size() != cloud.size() || v.size() != cloud.size()) {
      std::fprintf(stderr, "facyl_crops: %s has no float imX, imY fields\n", f.c_str());
      ++failed;
      continue;
    }
    // The dataset's frame: z up, y depth. The view is in the camera's (x right, y down, z
    // forward).
    pcl::PointCloud<pcl::PointXYZRGB> camera(cloud);
    for (auto& p : camera) {
      const float y = p.y, z = p.z;
      p.y = -z;
      p.z = y;
    }
    facyl::ObjectView view;
    pcl::Indices all(camera.size());
    for (std::size_t i = 0; i < all.size(); ++i)
      all[i] = static_cast<pcl::index_t>(i);
    view = facyl::objectView(camera, all, facyl::PinholeCamera{});
    for (std::size_t i = 0; i < camera.size(); ++i) {
      view.pixels(0, static_cast<Eigen::Index>(i)) = static_cast<int>(std::lround(u[i]));
      view.pixels(1, static_cast<Eigen::Index>(i)) = static_cast<int>(std::lround(v[i]));
    }
    facyl::viewBoxAndCrop(view, camera, all);
    const std::string category = uwCategory(f.stem().string());
    out.write(view, "uw", f.stem().string(), 0, category, uwIsCylinder(category) ? 1 : 0, 1.f,
              uwEvidence(camera), networkProbability(s, view));
  }
  return failed;
}

/** The presets of a comma-separated list; "mix" is \a mix. \throws std::invalid_argument
 * naming \a option for an empty or unknown entry. */
template <typename Known>
std::vector<std::string>
presetList(const std::string& text, const std::vector<std::string>& mix, const char* option,
           Known known)
{
  if (text == "mix")
    return mix;
  std::vector<std::string> list;
  std::istringstream in(text);
  std::string name;
  while (std::getline(in, name, ','))
    if (name.empty() || !known(name))
      throw std::invalid_argument(std::string(option) + ": unknown preset '" + name + "' in '" +
                                  text + "' (see -h)");
    else
      list.push_back(name);
  if (list.empty() || text.back() == ',')
    throw std::invalid_argument(std::string(option) + ": expected a comma-separated list, got '" +
                                text + "'");
  return list;
}

/** Scenes learn0-29 of mOSD hold boxes only (learn30-32 a tube among boxes, learn33-44
 * cylindric objects, the labelled evaluation scenes). */
constexpr int kMosdLastBoxScene = 29;

/** Real crops of the mOSD scenes of boxes only (paper III-B1: a scene holds either cylinders
 * or not, so its objects are labelled by the scene). Kept where the recognizer's object is one
 * of the dataset's labelled objects (IoU >= 0.5): no fragments, merges or table parts.
 * \return the number of files that failed. */
std::size_t
mosdCrops(const Settings& s, Recognizer& rec, DataWriter& out)
{
  std::size_t failed = 0;
  const facyl::PinholeCamera none;
  for (int k = s.mosd_first; k <= s.mosd_last; ++k) {
    const std::string name = "learn" + std::to_string(k);
    const std::string file = (std::filesystem::path(s.mosd) / (name + ".pcd")).string();
    pcl::PointCloud<pcl::PointXYZRGBL> labelled;
    Cloud::Ptr cloud(new Cloud);
    if (pcl::io::loadPCDFile(file, labelled) < 0) {
      std::fprintf(stderr, "facyl_crops: cannot read %s\n", file.c_str());
      ++failed;
      continue;
    }
    pcl::copyPointCloud(labelled, *cloud);
    rec.setInputCloud(cloud);
    std::vector<facyl::RecognizedObject> objects;
    if (!rec.recognize(objects)) {
      std::fprintf(stderr, "facyl_crops: %s: no table\n", file.c_str());
      ++failed;
      continue;
    }
    // The dataset's objects: label / 10 for labels >= 20 (parts of one object share a decade).
    std::map<int, std::size_t> truth_size;
    for (const auto& p : labelled)
      if (p.label >= 20)
        ++truth_size[static_cast<int>(p.label / 10)];
    for (std::size_t j = 0; j < objects.size(); ++j) {
      const auto& indices = objects[j].cluster.indices.indices;
      std::map<int, std::size_t> votes;
      for (const auto i : indices) {
        const auto label = labelled[static_cast<std::size_t>(i)].label;
        if (label >= 20)
          ++votes[static_cast<int>(label / 10)];
      }
      int id = 0;
      std::size_t most = 0;
      for (const auto& [l, c] : votes)
        if (c > most)
          id = l, most = c;
      if (id == 0)
        continue;
      const float iou =
        static_cast<float>(most) / static_cast<float>(indices.size() + truth_size[id] - most);
      if (iou < 0.5f)
        continue;
      const facyl::ObjectView view = facyl::objectView(*cloud, indices, none);
      out.write(view, "real", "mosd-" + name, static_cast<int>(j), "box", 0, iou,
                objects[j].evidence, networkProbability(s, view));
    }
  }
  return failed;
}

Settings
parseSettings(int argc, char** argv)
{
  const facyl_cli::Arguments args(argc, argv,
                                  {"--sim", "--seed", "--layout", "--sensor", "--uw", "--mosd",
                                   "--mosd-scenes", "--size", "--model"},
                                  {});
  if (args.positional().size() != 1)
    throw std::invalid_argument("give exactly one output folder (see -h)");
  Settings s;
  s.out = args.positional()[0];
  s.sim = static_cast<std::size_t>(args.integer("--sim", 0, 0, 100000));
  s.seed = static_cast<std::uint64_t>(
    args.integer("--seed", static_cast<long long>(kDefaultSeed), 0, facyl_cli::kMaxSeed));
  s.layouts = presetList(args.text("--layout", "mix"), {"spread", "cluttered"}, "--layout",
                         [](const std::string& name) {
                           facyl::TabletopSceneParameters p;
                           return facyl::parseLayoutPreset(name, p);
                         });
  s.sensors = presetList(args.text("--sensor", "mix"), {"kinect", "stereo"}, "--sensor",
                         [](const std::string& name) {
                           facyl::DepthSensorModel m;
                           facyl::CameraIntrinsics c;
                           return facyl::parseSensorPreset(name, m, c);
                         });
  s.uw = args.text("--uw", "");
  if (!s.uw.empty() && !std::filesystem::is_directory(s.uw))
    throw std::invalid_argument("--uw: folder '" + s.uw + "' does not exist");
  s.mosd = args.text("--mosd", "");
  if (!s.mosd.empty() && !std::filesystem::is_directory(s.mosd))
    throw std::invalid_argument("--mosd: folder '" + s.mosd + "' does not exist");
  const std::string scenes = args.text("--mosd-scenes", "0-29");
  char dash = 0, extra = 0;
  if (std::sscanf(scenes.c_str(), "%d%c%d%c", &s.mosd_first, &dash, &s.mosd_last, &extra) != 3 ||
      dash != '-' || s.mosd_first < 0 || s.mosd_last < s.mosd_first)
    throw std::invalid_argument("--mosd-scenes: expected A-B with 0 <= A <= B, got '" + scenes +
                                "'");
  if (s.mosd_last > kMosdLastBoxScene)
    throw std::invalid_argument("--mosd-scenes: only learn0-29 hold boxes only (learn30-44 "
                                "hold cylinders; learn33-44 are an evaluation set)");
  s.size = static_cast<int>(args.integer("--size", kDefaultSize, 8, 512));
  if (s.sim == 0 && s.uw.empty() && s.mosd.empty())
    throw std::invalid_argument("give --sim N, --uw DIR and/or --mosd DIR");
  if (!std::filesystem::is_directory(s.out))
    throw std::invalid_argument("folder '" + s.out + "' does not exist");
  std::vector<std::string> inputs;
  if (!s.uw.empty())
    for (const auto& e : std::filesystem::directory_iterator(s.uw))
      inputs.push_back(e.path().string());
  if (!s.mosd.empty())
    for (const auto& e : std::filesystem::directory_iterator(s.mosd))
      inputs.push_back(e.path().string());
  const std::string model = args.text("--model", "none");
  if (model != "default" && model != "none") {
    inputs.push_back(model);
    inputs.push_back(std::filesystem::path(model).replace_extension(".cfg").string());
  }
  facyl_cli::checkOutputFolder(
    "output folder", s.out,
    [](const std::string& f) { return f == "rgb.u8" || f == "depth.u8" || f == "objects.csv"; },
    inputs);
  s.classifier = facyl_cli::classifierFromOptions(args, "none");
  return s;
}

} // namespace

int
main(int argc, char** argv)
{
  Settings s;
  const int rc = facyl_cli::startTool(argc, argv, "facyl_crops", printHelp,
                                      [&] { s = parseSettings(argc, argv); });
  if (rc >= 0)
    return rc;
  pcl::console::setVerbosityLevel(pcl::console::L_ERROR);
  std::size_t failed = 0;
  try {
    DataWriter out(s.out, s.size);
    Recognizer rec;
    for (std::size_t k = 0; k < s.sim; ++k) {
      if (!simulatedScene(s, k, rec, out))
        ++failed;
      if ((k + 1) % 50 == 0 || k + 1 == s.sim)
        std::fprintf(stderr, "facyl_crops: %zu/%zu scenes, %zu objects\n", k + 1, s.sim,
                     out.rows());
    }
    if (!s.uw.empty())
      failed += uwCrops(s, out);
    if (!s.mosd.empty())
      failed += mosdCrops(s, rec, out);
    const facyl_cli::Json summary{{"objects", out.rows()}, {"failed", failed}, {"size", s.size}};
    std::printf("%s\n", facyl_cli::dumpJson(summary).c_str());
  }
  catch (const std::exception& e) {
    std::fprintf(stderr, "facyl_crops: %s\n", e.what());
    return 1;
  }
  return failed == 0 ? 0 : 1;
}
