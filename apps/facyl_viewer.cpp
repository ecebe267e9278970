/*
 * facyl_viewer: a pcl_viewer-style 3-D viewer of scenes and their cylinders
 * (pcl::visualization::PCLVisualizer). The cloud in its colours (by depth without colour),
 * the table outline, accepted cylinders as finite green meshes from base to top, rejected
 * objects as red boxes, a label per object; optionally PCL's SACMODEL_CYLINDER on the same
 * clusters in a second viewport, or one object's orientation accumulators for the three voting
 * modes. --screenshot renders and exits (under xvfb-run without a screen).
 */
#include "viewer/scene_drawing.h"
#include "viewer/stream_view.h"

#include <facyl/tools/cli.h>
#include <facyl/tools/cylinder_fit.h>
#include <facyl/tools/json_writer.h>
#include <facyl/tools/pcd_input.h>
#include <facyl/tools/pcl_baseline.h>
#include <facyl/tools/recognizer_options.h>

#include <facyl/features/local_geometry.h>
#include <facyl/features/normal_curvature_estimation.h>
#include <facyl/recognition/tabletop_cylinder_recognizer.h>
#include <facyl/sample_consensus_alt/cylinder_fitting.h>
#include <facyl/sample_consensus_alt/orientation_accumulator.h>

#include <pcl/common/common.h>
#include <pcl/common/io.h>
#include <pcl/common/point_tests.h>
#include <pcl/console/print.h>
#include <pcl/conversions.h>
#include <pcl/visualization/pcl_visualizer.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>

namespace {

using facyl_viewer::boxOf;
using facyl_viewer::Cloud;
using facyl_viewer::drawCylinder;
using facyl_viewer::drawnCloud;
using facyl_viewer::drawTable;
using facyl_viewer::Layers;
using facyl_viewer::sensorCamera;
using facyl_viewer::tableOutline;

constexpr int kDefaultWidth = 1024, kDefaultHeight = 768;
constexpr float kPclMinInlierRatio = 0.5f; // PCL's fit is drawn as a cylinder from this on

void
printHelp(const char* self)
{
  std::printf(
    "Usage: %s [options] SCENE.pcd...\n"
    "       %s --stream SOURCE [--rate FPS] [--loop] [--frames N] [options]\n"
    "Shows each cloud with its table and cylinders (green: accepted, finite from base to top;\n"
    "red boxes: objects that are not cylinders; a label per object).\n"
    "  --stream SOURCE       a stream, tracked live (facyl::CylinderTracker): SOURCE is a\n"
    "                        folder of PCD frames played in name order by pcl::PCDGrabber,\n"
    "                        or openni2 / openni2:DEVICE (pcl::io::OpenNI2Grabber, when PCL\n"
    "                        has OpenNI2 and a device is present). Each track is drawn in its\n"
    "                        own colour with its id (\"#7\"): confirmed cylinders as meshes\n"
    "                        of the filtered cylinder (faint while hidden or missed), with\n"
    "                        this frame's own fit as a white outline beside it; other objects\n"
    "                        as boxes. One JSON line per frame on standard output: \"frame\"\n"
    "                        and what facyl_detect --track prints for it (the objects with\n"
    "                        their track ids and cylinders, \"stream\", \"tracks\").\n"
    "                        Unreadable frames are skipped with a message; the tracks are kept\n"
    "  --rate FPS            --stream of PCD frames: play at FPS frames per second (frames\n"
    "                        that arrive while one is processed are dropped, as from a\n"
    "                        sensor); 0 (default): every frame, as fast as processed\n"
    "  --loop                --stream of PCD frames: start again after the last\n"
    "  --frames N            --stream: stop after N frames (with --screenshot: the last one\n"
    "                        is rendered)\n"
    "  --detect              run the recognizer (default unless --detections)\n"
    "  --detections F.jsonl  show facyl_detect's output instead (one JSON line per scene,\n"
    "                        matched by \"file\", else by order)\n"
    "  --compare-pcl         a second viewport: PCL SACSegmentationFromNormals +\n"
    "                        SACMODEL_CYLINDER on the same clusters and normals, both times\n"
    "                        (PCL's cylinder drawn when it holds half of the object's points)\n"
    "  --accumulator ID      object ID's orientation accumulator (%zu cells, uniform) for the\n"
    "                        voting modes rabbani, soft-normal, soft-curvature side by side:\n"
    "                        cells coloured by votes, the chosen axis, normals (white) and\n"
    "                        principal-curvature directions (yellow)\n"
    "  --screenshot OUT.png  render the first scene to OUT.png and exit (needs an X display:\n"
    "                        run under xvfb-run without a screen)\n"
    "                        (a path not ending in .png, or one that is an input, is\n"
    "                        refused)\n"
    "  --size W,H            window / screenshot size (default %d,%d)\n"
    "The cloud, the table and the cylinders are drawn in the cloud's own frame, seen from its\n"
    "sensor (the VIEWPOINT; a pose that puts the points behind the sensor, as PCL's grabber\n"
    "frames store, is taken as the identity rotation, as the recognizer does). A frame\n"
    "without any support is shown with its objects and no table outline. A cloud without\n"
    "colour (x y z only) is coloured by depth: near red, middle grey, far blue.\n"
    "The recognizer's options (--detect; as in facyl_detect):\n%s"
    "Keys (besides pcl_viewer's: r reset camera, j screenshot, h help): n / p next /\n"
    "previous file, o next object (prints its numbers), t table, c cylinders, b boxes,\n"
    "l labels.\n%s"
    "Exit status: 0; 1 when a file cannot be shown; 2 for bad usage (nothing written).\n",
    self, self, facyl::HoughCylinderParameters{}.orientations, kDefaultWidth, kDefaultHeight,
    facyl_cli::recognizerOptionsHelp(), facyl_cli::commonHelp());
}

// ------------------------------------------------------------------------------- scene

/** One object as the viewer draws it. */
struct ViewObject {
  bool is_cylinder{false};
  bool fitted{false};
  facyl::CylinderModel cylinder;
  Eigen::Vector3f box_min{Eigen::Vector3f::Zero()}, box_max{Eigen::Vector3f::Zero()};
  Eigen::Vector3f centroid{Eigen::Vector3f::Zero()};
  float p_cylinder{std::numeric_limits<float>::quiet_NaN()};
  pcl::Indices indices; ///< empty for --detections
};

struct Scene {
  std::string file;
  Cloud::Ptr cloud;
  std::vector<ViewObject> objects;
  std::vector<Eigen::Vector3f> table_outline;
  double facyl_ms{0.0}; ///< the recognizer's fitting time (--detect)
};

struct Settings {
  std::vector<std::string> files;
  facyl::TabletopRecognizerParameters params; ///< the recognizer's options
  Eigen::Vector3f up{Eigen::Vector3f::Zero()};
  bool detect{true};
  std::string detections;
  bool compare_pcl{false};
  long long accumulator{-1};
  std::string screenshot;
  int width{kDefaultWidth}, height{kDefaultHeight};
  facyl::ShapeClassifier::Ptr classifier;
  std::string stream;  ///< --stream SOURCE
  float rate{0.f};     ///< --rate
  bool loop{false};    ///< --loop
  long long frames{0}; ///< --frames; 0: all
};

/** The file as an XYZRGBA cloud (black without colour: drawnCloud colours it by depth).
 * \throws std::runtime_error. */
Cloud::Ptr
loadCloud(const std::string& file)
{
  pcl::PCLPointCloud2 blob;
  facyl_cli::Viewpoint viewpoint;
  const std::string why = facyl_cli::readPcd(file, blob, &viewpoint);
  if (!why.empty())
    throw std::runtime_error(why);
  Cloud::Ptr cloud(new Cloud);
  pcl::fromPCLPointCloud2(blob, *cloud);
  cloud->sensor_origin_ = viewpoint.origin;
  cloud->sensor_orientation_ = viewpoint.orientation;
  if (std::none_of(cloud->begin(), cloud->end(), [](const auto& p) { return pcl::isFinite(p); }))
    throw std::runtime_error("the cloud has no finite point");
  return cloud;
}

/** --detect: the recognizer's objects. */
void
detectObjects(const Settings& s, Scene& scene)
{
  facyl::TabletopCylinderRecognizer<pcl::PointXYZRGBA> rec;
  rec.setParameters(s.params);
  rec.setUpDirection(s.up);
  rec.setClassifier(s.classifier);
  rec.setInputCloud(scene.cloud);
  std::vector<facyl::RecognizedObject> objects;
  if (!rec.recognize(objects))
    throw std::runtime_error("recognition failed (see the message above)");
  scene.facyl_ms = rec.getTiming().fitting + rec.getTiming().classification;
  scene.table_outline = tableOutline(rec);
  for (const auto& r : objects) {
    ViewObject o;
    o.is_cylinder = r.is_cylinder;
    o.fitted = r.evidence.fitted;
    o.cylinder = r.cylinder;
    o.centroid = r.cluster.centroid;
    o.p_cylinder = r.evidence.p_cylinder;
    o.indices = r.cluster.indices.indices;
    boxOf(*scene.cloud, o.indices, o.box_min, o.box_max);
    scene.objects.push_back(std::move(o));
  }
}

using facyl_cli::Json;

/** The field \a key of the object \a j; nullptr when absent or \a j is no object. */
const Json*
field(const Json& j, const char* key)
{
  if (!j.is_object())
    return nullptr;
  const auto it = j.find(key);
  return it == j.end() ? nullptr : &*it;
}

/** The number \a v, or \a otherwise when it is absent or no number. */
double
numberOr(const Json* v, double otherwise)
{
  return v && v->is_number() ? v->get<double>() : otherwise;
}

Eigen::Vector3f
vectorOf(const Json* v)
{
  if (!v || !v->is_array() || v->size() != 3 ||
      !std::all_of(v->begin(), v->end(), [](const Json& x) { return x.is_number(); }))
    throw std::runtime_error("a vector of 3 numbers is missing");
  return Eigen::Vector3f((*v)[0].get<float>(), (*v)[1].get<float>(), (*v)[2].get<float>());
}

/** --detections: the objects of facyl_detect's line for the scene. */
void
objectsFromJson(const Json& line, Scene& scene)
{
  if (const auto* error = field(line, "error"))
    throw std::runtime_error("the detections say: " +
                             (error->is_string() ? error->get<std::string>() : error->dump()));
  const auto* objects = field(line, "objects");
  if (!objects || !objects->is_array())
    throw std::runtime_error("the detections line has no \"objects\"");
  for (const auto& j : *objects) {
    ViewObject o;
    o.centroid = vectorOf(field(j, "centroid"));
    const auto* is = field(j, "is_cylinder");
    o.is_cylinder = is && is->is_boolean() && is->get<bool>();
    if (const auto* p = field(j, "p_cylinder"); p && p->is_number())
      o.p_cylinder = p->get<float>();
    const auto* c = field(j, "cylinder");
    if (c && c->is_object()) {
      o.fitted = true;
      o.cylinder.point_on_axis = vectorOf(field(*c, "point_on_axis"));
      o.cylinder.axis = vectorOf(field(*c, "axis")).normalized();
      o.cylinder.radius = static_cast<float>(numberOr(field(*c, "radius"), 0.0));
      o.cylinder.height = static_cast<float>(numberOr(field(*c, "height"), 0.0));
      if (field(*c, "base") && field(*c, "top")) { // facyl_detect's JSON since 0.1: the extent
        o.cylinder.base = vectorOf(field(*c, "base"));
        o.cylinder.top = vectorOf(field(*c, "top"));
      }
      else {
        o.cylinder.base = o.cylinder.point_on_axis;
        o.cylinder.top = o.cylinder.base + o.cylinder.height * o.cylinder.axis;
      }
    }
    o.box_min = o.centroid - Eigen::Vector3f::Constant(0.03f);
    o.box_max = o.centroid + Eigen::Vector3f::Constant(0.03f);
    scene.objects.push_back(std::move(o));
  }
}

/** The lines of a --detections file, by "file" (and in order). */
std::vector<Json>
readDetections(const std::string& path)
{
  std::ifstream in(path);
  if (!in)
    throw std::invalid_argument("--detections: cannot read " + path);
  std::vector<Json> lines;
  std::string text;
  int number = 0;
  while (std::getline(in, text)) {
    ++number;
    if (text.find_first_not_of(" \t\r") == std::string::npos)
      continue;
    try {
      lines.push_back(Json::parse(text));
    }
    catch (const Json::parse_error& e) {
      throw std::invalid_argument("--detections: " + path + " line " + std::to_string(number) +
                                  ": " + e.what());
    }
  }
  return lines;
}

const Json*
detectionFor(const std::vector<Json>& lines, const std::string& file, std::size_t k)
{
  for (const auto& l : lines)
    if (const auto* f = field(l, "file"); f && f->is_string() && f->get<std::string>() == file)
      return &l;
  return k < lines.size() ? &lines[k] : nullptr;
}

// ----------------------------------------------------------------------------- drawing

std::string
labelOf(const ViewObject& o, std::size_t id)
{
  char buf[160];
  const std::string p =
    std::isfinite(o.p_cylinder) ? " p=" + std::to_string(o.p_cylinder).substr(0, 4) : "";
  if (o.is_cylinder)
    std::snprintf(buf, sizeof buf, "#%zu r=%.1fmm h=%.1fmm%s", id, o.cylinder.radius * 1e3f,
                  o.cylinder.height * 1e3f, p.c_str());
  else
    std::snprintf(buf, sizeof buf, "#%zu not a cylinder%s", id, p.c_str());
  return buf;
}

void
drawObjects(pcl::visualization::PCLVisualizer& viewer, const Scene& scene, const Layers& layers,
            const std::string& tag, int viewport)
{
  for (std::size_t k = 0; k < scene.objects.size(); ++k) {
    const ViewObject& o = scene.objects[k];
    const std::string id = tag + std::to_string(k);
    if (o.is_cylinder && layers.cylinders)
      drawCylinder(viewer, o.cylinder, id + "_cyl", viewport, 0.1, 0.9, 0.2);
    if (!o.is_cylinder && layers.boxes) {
      viewer.addCube(o.box_min.x(), o.box_max.x(), o.box_min.y(), o.box_max.y(), o.box_min.z(),
                     o.box_max.z(), 1.0, 0.1, 0.1, id + "_box", viewport);
      viewer.setShapeRenderingProperties(
        pcl::visualization::PCL_VISUALIZER_REPRESENTATION,
        pcl::visualization::PCL_VISUALIZER_REPRESENTATION_WIREFRAME, id + "_box", viewport);
    }
    if (layers.labels) {
      const Eigen::Vector3f at =
        o.is_cylinder ? Eigen::Vector3f(o.cylinder.top) : Eigen::Vector3f(o.box_min);
      viewer.addText3D(labelOf(o, k), pcl::PointXYZ(at.x(), at.y(), at.z()), 0.008,
                       o.is_cylinder ? 0.6 : 1.0, o.is_cylinder ? 1.0 : 0.5, 0.6, id + "_label",
                       viewport);
    }
  }
}

// ------------------------------------------------------------------------ PCL comparison

/** PCL's SACMODEL_CYLINDER on every object's points, with facyl's normals. \return its ms. */
double
pclObjects(const Scene& scene, Scene& pcl_scene)
{
  pcl_scene.file = scene.file;
  pcl_scene.cloud = scene.cloud;
  pcl_scene.table_outline = scene.table_outline;
  const auto t0 = std::chrono::steady_clock::now();
  for (const ViewObject& o : scene.objects) {
    ViewObject q = o;
    q.is_cylinder = false;
    q.p_cylinder = std::numeric_limits<float>::quiet_NaN();
    pcl::PointCloud<pcl::PointXYZ>::Ptr points(new pcl::PointCloud<pcl::PointXYZ>);
    pcl::copyPointCloud(*scene.cloud, o.indices, *points);
    if (points->size() >= 20) {
      const auto cues = facyl_cli::estimateFitCues(points, facyl::kDefaultNeighbours, 0, nullptr);
      pcl::PointCloud<pcl::Normal>::Ptr normals(new pcl::PointCloud<pcl::Normal>);
      pcl::copyPointCloud(*cues, *normals);
      facyl_cli::PclCylinderOptions options;
      options.distance_threshold = 0.005f;
      options.radius_min = static_cast<float>(facyl::kDefaultRadiusMin);
      options.radius_max = static_cast<float>(facyl::kDefaultRadiusMax);
      const auto fits = facyl_cli::fitPclCylinders<pcl::PointXYZ>(points, normals, options);
      if (!fits.empty() && fits.front().inlier_ratio >= kPclMinInlierRatio) {
        q.is_cylinder = true;
        q.cylinder = fits.front();
      }
    }
    pcl_scene.objects.push_back(std::move(q));
  }
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// --------------------------------------------------------------------------- accumulator

/** One object's orientation accumulators, one viewport per voting mode. */
void
drawAccumulators(pcl::visualization::PCLVisualizer& viewer, const Scene& scene, std::size_t id,
                 const int viewports[3])
{
  const ViewObject& o = scene.objects.at(id);
  pcl::PointCloud<pcl::PointXYZ>::Ptr points(new pcl::PointCloud<pcl::PointXYZ>);
  pcl::copyPointCloud(*scene.cloud, o.indices, *points);
  const auto cues = facyl_cli::estimateFitCues(points, 16, 0, nullptr);
  facyl::VotingCues voting;
  voting.resize(std::count_if(cues->begin(), cues->end(),
                              [](const auto& c) { return std::isfinite(c.normal_x); }));
  Eigen::Index n = 0;
  for (const auto& c : *cues) {
    if (!std::isfinite(c.normal_x))
      continue;
    voting.nx(n) = c.normal_x, voting.ny(n) = c.normal_y, voting.nz(n) = c.normal_z;
    voting.cx(n) = c.principal_curvature_x, voting.cy(n) = c.principal_curvature_y,
    voting.cz(n) = c.principal_curvature_z;
    voting.weight(n) = facyl::curvatureAnisotropy(c.pc1, c.pc2);
    ++n;
  }
  const facyl::HoughCylinderParameters defaults; // N_d and seed as the estimator's
  const auto acc = facyl::OrientationAccumulator::sample(
    facyl::GaussianMixture::fromPrior(facyl::OrientationPrior::Uniform), defaults.orientations,
    defaults.seed);
  const float radius = 0.6f * (o.box_max - o.box_min).maxCoeff() + 0.02f;
  const char* names[] = {"rabbani", "soft-normal", "soft-curvature"};
  const facyl::VotingMode modes[] = {facyl::VotingMode::Rabbani, facyl::VotingMode::SoftNormal,
                                     facyl::VotingMode::SoftCurvature};
  for (int m = 0; m < 3; ++m) {
    Eigen::VectorXf votes;
    facyl::castVotes(acc.directions(), voting, modes[m], 2, std::sin(acc.cellRadius()), votes);
    const float top = std::max(votes.maxCoeff(), 1e-9f);
    pcl::PointCloud<pcl::PointXYZRGB>::Ptr cells(new pcl::PointCloud<pcl::PointXYZRGB>);
    for (Eigen::Index k = 0; k < votes.size(); ++k)
      for (const float sign : {1.f, -1.f}) {
        const Eigen::Vector3f d = o.centroid + sign * radius * acc.directions().col(k);
        pcl::PointXYZRGB q(static_cast<std::uint8_t>(255 * votes(k) / top), 40,
                           static_cast<std::uint8_t>(255 * (1 - votes(k) / top)));
        q.x = d.x(), q.y = d.y(), q.z = d.z();
        cells->push_back(q);
      }
    const std::string tag = std::string("acc_") + names[m];
    viewer.addPointCloud<pcl::PointXYZRGB>(cells, tag, viewports[m]);
    viewer.setPointCloudRenderingProperties(pcl::visualization::PCL_VISUALIZER_POINT_SIZE, 6, tag,
                                            viewports[m]);
    Eigen::Index best = 0;
    votes.maxCoeff(&best);
    const Eigen::Vector3f a = acc.directions().col(best) * radius * 1.3f;
    viewer.addLine(
      pcl::PointXYZ(o.centroid.x() - a.x(), o.centroid.y() - a.y(), o.centroid.z() - a.z()),
      pcl::PointXYZ(o.centroid.x() + a.x(), o.centroid.y() + a.y(), o.centroid.z() + a.z()), 0.1,
      1.0, 0.2, tag + "_axis", viewports[m]);
    viewer.setShapeRenderingProperties(pcl::visualization::PCL_VISUALIZER_LINE_WIDTH, 4,
                                       tag + "_axis", viewports[m]);
    viewer.addPointCloud<pcl::PointXYZ>(points, tag + "_points", viewports[m]);
    pcl::PointCloud<pcl::Normal>::Ptr normals(new pcl::PointCloud<pcl::Normal>);
    pcl::copyPointCloud(*cues, *normals);
    viewer.addPointCloudNormals<pcl::PointXYZ, pcl::Normal>(points, normals, 10, 0.01f,
                                                            tag + "_normals", viewports[m]);
    pcl::PointCloud<pcl::Normal>::Ptr directions(new pcl::PointCloud<pcl::Normal>);
    for (const auto& c : *cues)
      directions->push_back(
        pcl::Normal(c.principal_curvature_x, c.principal_curvature_y, c.principal_curvature_z));
    viewer.addPointCloudNormals<pcl::PointXYZ, pcl::Normal>(points, directions, 10, 0.01f,
                                                            tag + "_dirs", viewports[m]);
    viewer.setPointCloudRenderingProperties(pcl::visualization::PCL_VISUALIZER_COLOR, 1.0, 0.9, 0.1,
                                            tag + "_dirs", viewports[m]);
    viewer.addText(std::string(names[m]) + " voting", 10, 10, 14, 1, 1, 1, tag + "_title",
                   viewports[m]);
  }
}

// ---------------------------------------------------------------------------- the viewer

class Viewer {
public:
  explicit Viewer(const Settings& s)
      : s_(s)
      , viewer_("facyl_viewer")
  {
    viewer_.setSize(s.width, s.height);
    viewer_.setBackgroundColor(0.05, 0.05, 0.08);
    viewer_.setShowFPS(false);
    viewer_.registerKeyboardCallback(
      [this](const pcl::visualization::KeyboardEvent& e) { onKey(e); });
  }
  /** Loads and draws scene \a k. \return false (with a message) when it cannot be shown. */
  bool show(std::size_t k)
  {
    current_ = k;
    viewer_.removeAllPointClouds();
    viewer_.removeAllShapes();
    focus_ = 0;
    try {
      scene_ = load(s_.files[k]);
    }
    catch (const std::exception& e) {
      std::fprintf(stderr, "facyl_viewer: %s: %s\n", s_.files[k].c_str(), e.what());
      return false;
    }
    draw();
    return true;
  }
  void screenshot(const std::string& path)
  {
    viewer_.spinOnce(1, true);
    viewer_.saveScreenshot(path);
  }
  void run()
  {
    while (!viewer_.wasStopped())
      viewer_.spinOnce(50);
  }

private:
  Scene load(const std::string& file) const
  {
    Scene scene;
    scene.file = file;
    scene.cloud = loadCloud(file);
    if (!s_.detections.empty()) {
      const auto* line = detectionFor(detections_(), file, current_);
      if (!line)
        throw std::runtime_error("no line for it in " + s_.detections);
      objectsFromJson(*line, scene);
    }
    else
      detectObjects(s_, scene);
    return scene;
  }
  const std::vector<Json>& detections_() const
  {
    if (!lines_loaded_) {
      lines_ = readDetections(s_.detections);
      lines_loaded_ = true;
    }
    return lines_;
  }
  void draw()
  {
    const Cloud::ConstPtr drawn = drawnCloud(*scene_.cloud);
    pcl::visualization::PointCloudColorHandlerRGBField<pcl::PointXYZRGBA> rgb(drawn);
    if (s_.accumulator >= 0) {
      if (static_cast<std::size_t>(s_.accumulator) >= scene_.objects.size() ||
          scene_.objects[static_cast<std::size_t>(s_.accumulator)].indices.empty()) {
        std::fprintf(stderr,
                     "facyl_viewer: --accumulator %lld: the scene has %zu objects (with "
                     "points: --detect)\n",
                     s_.accumulator, scene_.objects.size());
        return;
      }
      int vp[3];
      for (int m = 0; m < 3; ++m) {
        viewer_.createViewPort(m / 3.0, 0.0, (m + 1) / 3.0, 1.0, vp[m]);
        viewer_.setBackgroundColor(0.05, 0.05, 0.08, vp[m]);
      }
      drawAccumulators(viewer_, scene_, static_cast<std::size_t>(s_.accumulator), vp);
      viewer_.resetCamera();
      return;
    }
    int left = 0, right = 0;
    if (s_.compare_pcl) {
      viewer_.createViewPort(0.0, 0.0, 0.5, 1.0, left);
      viewer_.createViewPort(0.5, 0.0, 1.0, 1.0, right);
    }
    viewer_.addPointCloud<pcl::PointXYZRGBA>(drawn, rgb, "cloud", left);
    if (layers_.table)
      drawTable(viewer_, scene_.table_outline, "f_", left);
    drawObjects(viewer_, scene_, layers_, "f_", left);
    sensorCamera(viewer_, *scene_.cloud, left);
    if (s_.compare_pcl) {
      Scene pcl_scene;
      const double pcl_ms = pclObjects(scene_, pcl_scene);
      viewer_.addPointCloud<pcl::PointXYZRGBA>(drawn, rgb, "cloud_pcl", right);
      drawObjects(viewer_, pcl_scene, layers_, "p_", right);
      sensorCamera(viewer_, *scene_.cloud, right);
      char text[200];
      std::snprintf(text, sizeof text, "facyl: %.1f ms (classification + fitting)",
                    scene_.facyl_ms);
      viewer_.addText(text, 10, 10, 16, 1, 1, 1, "title_f", left);
      std::snprintf(text, sizeof text, "PCL SACMODEL_CYLINDER: %.1f ms (normals + RANSAC)", pcl_ms);
      viewer_.addText(text, 10, 10, 16, 1, 1, 1, "title_p", right);
    }
    viewer_.addText(scene_.file, 10, s_.height - 24, 14, 0.8, 0.8, 0.8, "file", left);
  }
  void onKey(const pcl::visualization::KeyboardEvent& e)
  {
    if (!e.keyDown())
      return;
    const std::string key = e.getKeySym();
    if ((key == "n" || key == "p") && s_.files.size() > 1) {
      const std::size_t n = s_.files.size();
      show(key == "n" ? (current_ + 1) % n : (current_ + n - 1) % n);
      return;
    }
    if (key == "o" && !scene_.objects.empty()) {
      focus_ = (focus_ + 1) % scene_.objects.size();
      const ViewObject& o = scene_.objects[focus_];
      std::printf("%s object %zu: %s, centroid (%.3f, %.3f, %.3f)", scene_.file.c_str(), focus_,
                  labelOf(o, focus_).c_str(), o.centroid.x(), o.centroid.y(), o.centroid.z());
      if (o.fitted)
        std::printf(", axis (%.3f, %.3f, %.3f), base (%.3f, %.3f, %.3f)", o.cylinder.axis.x(),
                    o.cylinder.axis.y(), o.cylinder.axis.z(), o.cylinder.base.x(),
                    o.cylinder.base.y(), o.cylinder.base.z());
      std::printf("\n");
      std::fflush(stdout);
      viewer_.setCameraPosition(o.centroid.x(), o.centroid.y(), o.centroid.z() - 0.5,
                                o.centroid.x(), o.centroid.y(), o.centroid.z(), 0, -1, 0);
      return;
    }
    bool* layer = key == "t"   ? &layers_.table
                  : key == "c" ? &layers_.cylinders
                  : key == "b" ? &layers_.boxes
                  : key == "l" ? &layers_.labels
                               : nullptr;
    if (layer) {
      *layer = !*layer;
      viewer_.removeAllShapes();
      viewer_.removeAllPointClouds();
      draw();
    }
  }

  const Settings& s_;
  pcl::visualization::PCLVisualizer viewer_;
  Scene scene_;
  Layers layers_;
  std::size_t current_{0}, focus_{0};
  mutable std::vector<Json> lines_;
  mutable bool lines_loaded_{false};
};

Settings
parseSettings(int argc, char** argv)
{
  const facyl_cli::Arguments args(
    argc, argv,
    facyl_cli::joined(facyl_cli::recognizerValueOptions(),
                      {"--detections", "--accumulator", "--screenshot", "--size", "--stream",
                       "--rate", "--frames"}),
    facyl_cli::joined(facyl_cli::recognizerSwitches(), {"--detect", "--compare-pcl", "--loop"}),
    facyl_cli::recognizerAliases());
  Settings s;
  s.files = args.positional();
  s.stream = args.text("--stream", "");
  if (args.has("--stream")) {
    if (s.stream.empty())
      throw std::invalid_argument("--stream needs a source: a folder of PCD frames, or openni2");
    if (!s.files.empty())
      throw std::invalid_argument("--stream and scene files exclude each other (the stream's "
                                  "frames come from its source)");
    if (args.has("--detections") || args.has("--compare-pcl") || args.has("--accumulator"))
      throw std::invalid_argument("--stream runs the recognizer and the tracker; it excludes "
                                  "--detections, --compare-pcl and --accumulator");
    s.rate = static_cast<float>(args.number("--rate", 0.0, 0.0, 1000.0));
    s.loop = args.has("--loop");
    s.frames = args.integer("--frames", 0, 0, 100000000);
    if (s.loop && s.frames == 0 && args.has("--screenshot"))
      throw std::invalid_argument("--loop with --screenshot needs --frames N (a loop never ends)");
  }
  else {
    if (args.has("--rate") || args.has("--loop") || args.has("--frames"))
      throw std::invalid_argument("--rate, --loop and --frames need --stream");
    if (s.files.empty())
      throw std::invalid_argument("give at least one scene (see -h)");
  }
  facyl_cli::RecognizerSettings recognizer;
  facyl_cli::applyOptions(facyl_cli::recognizerOptions(), args, recognizer);
  s.params = recognizer.params;
  s.up = recognizer.up;
  s.detections = args.text("--detections", "");
  if (!s.detections.empty() && args.has("--detect"))
    throw std::invalid_argument("--detect and --detections exclude each other");
  s.detect = s.detections.empty();
  s.compare_pcl = args.has("--compare-pcl");
  s.accumulator = args.integer("--accumulator", -1, -1, 100000);
  if ((s.compare_pcl || s.accumulator >= 0) && !s.detect)
    throw std::invalid_argument(
      "--compare-pcl and --accumulator need the objects' points: use --detect");
  if (s.compare_pcl && s.accumulator >= 0)
    throw std::invalid_argument("--compare-pcl and --accumulator exclude each other");
  s.screenshot = args.text("--screenshot", "");
  if (args.has("--screenshot")) {
    std::vector<std::string> inputs = s.files;
    inputs.push_back(s.detections);
    const std::string model = args.text("--model", "");
    if (!model.empty() && model != "default" && model != "none") {
      inputs.push_back(model);
      inputs.push_back(std::filesystem::path(model).replace_extension(".cfg").string());
    }
    facyl_cli::checkOutputFile("--screenshot", s.screenshot, {".png"}, "PNG image", inputs);
  }
  const auto size = facyl_cli::pairOption(args, "--size", kDefaultWidth, kDefaultHeight);
  if (!(size.first >= 64 && size.second >= 64 && size.first <= 8192 && size.second <= 8192))
    throw std::invalid_argument("--size: expected W,H with 64 <= W, H <= 8192");
  s.width = static_cast<int>(size.first);
  s.height = static_cast<int>(size.second);
  if (s.detect)
    s.classifier = facyl_cli::classifierFor(recognizer.model);
  return s;
}

} // namespace

int
main(int argc, char** argv)
{
  Settings s;
  const int rc = facyl_cli::startTool(argc, argv, "facyl_viewer", printHelp,
                                      [&] { s = parseSettings(argc, argv); });
  if (rc >= 0)
    return rc;
  const char* display = std::getenv("DISPLAY");
  if (!display || !*display) {
    std::fprintf(stderr, "facyl_viewer: no X display (DISPLAY is not set)%s\n",
                 s.screenshot.empty() ? "; on a machine without a screen, render with "
                                        "--screenshot OUT.png under xvfb-run"
                                      : "; run it under xvfb-run (Debian: apt-get install xvfb)");
    return 1;
  }
  pcl::console::setVerbosityLevel(pcl::console::L_ERROR);
  if (!s.stream.empty()) {
    try {
      facyl_viewer::StreamSettings stream;
      stream.source = s.stream;
      stream.rate = s.rate;
      stream.loop = s.loop;
      stream.frames = s.frames;
      stream.params = s.params;
      stream.up = s.up;
      stream.classifier = s.classifier;
      stream.screenshot = s.screenshot;
      stream.width = s.width;
      stream.height = s.height;
      return facyl_viewer::runStream(stream);
    }
    catch (const std::invalid_argument& e) {
      std::fprintf(stderr, "facyl_viewer: %s\n", e.what());
      return 2;
    }
    catch (const std::exception& e) {
      std::fprintf(stderr, "facyl_viewer: %s\n", e.what());
      return 1;
    }
  }
  try {
    Viewer viewer(s);
    if (!s.screenshot.empty()) {
      if (!viewer.show(0))
        return 1;
      viewer.screenshot(s.screenshot);
      Json line;
      line["file"] = s.files[0];
      line["screenshot"] = s.screenshot;
      std::printf("%s\n", facyl_cli::dumpJson(line).c_str());
      return 0;
    }
    bool any = false;
    for (std::size_t k = 0; k < s.files.size() && !any; ++k)
      any = viewer.show(k);
    if (!any)
      return 1;
    viewer.run();
  }
  catch (const std::exception& e) {
    std::fprintf(stderr, "facyl_viewer: %s\n", e.what());
    return 1;
  }
  return 0;
}
