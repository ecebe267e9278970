/*
 * facyl_detect: every cylinder on the table of RGB-D frames (paper III-A without the CNN).
 * One JSON object per scene on stdout.
 */
#include <facyl/tools/cli.h>
#include <facyl/tools/depth_colours.h>
#include <facyl/tools/detect_json.h>
#include <facyl/tools/detect_overlay.h>
#include <facyl/tools/pcd_input.h>
#include <facyl/tools/recognizer_options.h>
#include <facyl/tools/track_json.h>
#include <facyl/tools/tracker_options.h>

#include <facyl/recognition/tabletop_cylinder_recognizer.h>
#include <facyl/simulation/frame_roll.h>
#include <facyl/tracking/cylinder_tracker.h>

#include <pcl/common/io.h>
#include <pcl/console/print.h>
#include <pcl/conversions.h>
#include <pcl/io/pcd_io.h>
#include <pcl/io/png_io.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>

namespace {

using Cloud = pcl::PointCloud<pcl::PointXYZRGBA>;

void
printHelp(const char* self)
{
  std::printf(
    "Usage: %s [options] SCENE.pcd...\n"
    "Finds the supports (tables), the objects on them and the cylinders among them; prints\n"
    "one JSON object per scene. Organized clouds (RGB-D frames) and unorganized clouds are\n"
    "accepted.\n%s"
    "Output:\n"
    "  --camera fx,fy,cx,cy   intrinsics for boxes of unorganized clouds (and their overlay)\n"
    "  --overlay OUT.png      RGB image with boxes (green: cylinder, red: not) and fitted\n"
    "                         outlines; a cloud without colour is coloured by depth (near\n"
    "                         red, middle grey, far blue). With several scenes a folder\n"
    "                         (<stem>.png; <stem>-<k>.png when scenes share a name, k from\n"
    "                         1). A path not ending in .png, or one that is an input, is\n"
    "                         refused\n"
    "  --save-clusters DIR    each object's cloud (<stem>_obj<k>.pcd) and RGB crop (.png);\n"
    "                         refused when DIR holds an input (a later *.pcd there would\n"
    "                         read the clusters as scenes) or a name it would write is one\n"
    "  --repeat N             run N times, report the median timing (default 1)\n"
    "  --verbose              what each step found (PCL's debug messages, on standard\n"
    "                         output between the JSON lines)\n"
    "  --roll DEG             each frame as a camera rolled by DEG (90, 180, 270) clockwise\n"
    "                         about its optical axis would have taken it (organized frames;\n"
    "                         boxes and overlays are in the rolled image)\n"
    "Streams:\n"
    "  --track                the scenes, in the order given, are one stream (frames of a\n"
    "                         camera moving over a static table): objects are tracked\n"
    "                         (facyl::CylinderTracker). Each object gets \"track_id\" (an\n"
    "                         integer, stable across frames), \"is_cylinder\" and \"cylinder\"\n"
    "                         become the track's decision and filtered estimate (in this\n"
    "                         frame), \"is_cylinder_frame\" and \"cylinder_frame\" the frame's\n"
    "                         own; each line adds \"stream\" and \"tracks\" (every live track).\n"
    "                         --overlay shows the same: boxes and solid outlines by the\n"
    "                         track, the frame's own cylinder dashed magenta, the track's id\n"
    "                         (\"#7\") over each box.\n"
    "                         A frame that fails (its line has \"error\") does not end the\n"
    "                         stream; frames of a new scene start new tracks. docs/tracking.md\n"
    "%s%s"
    "Exit status: 0 all scenes processed (warnings, e.g. no overlay for an unorganized cloud\n"
    "without --camera, go to standard error and do not change it), 1 a scene failed or an\n"
    "output could not be written (its JSON has \"error\"), 2 bad usage (nothing written).\n",
    self, facyl_cli::recognizerOptionsHelp(),
    facyl_cli::helpText(facyl_cli::trackerOptions(), facyl::CylinderTrackerParameters{}).c_str(),
    facyl_cli::commonHelp());
}

/** The name of each scene's outputs (overlay, clusters): its file name's stem, or, when
 * several scenes share a stem, "<stem>-<k>" with k its position among the scenes (from 1). */
std::vector<std::string>
outputNames(const std::vector<std::string>& files)
{
  std::map<std::string, int> uses;
  for (const auto& f : files)
    ++uses[std::filesystem::path(f).stem().string()];
  std::vector<std::string> names;
  for (std::size_t k = 0; k < files.size(); ++k) {
    const std::string stem = std::filesystem::path(files[k]).stem().string();
    names.push_back(uses[stem] > 1 ? stem + "-" + std::to_string(k + 1) : stem);
  }
  return names;
}

struct Settings {
  facyl::TabletopRecognizerParameters params;
  facyl::PinholeCamera camera;
  Eigen::Vector3f up{Eigen::Vector3f::Zero()};
  std::string overlay, clusters_dir;
  int repeat{1};
  bool many{false};
  bool verbose{false}; ///< --verbose: PCL's debug messages (what the segmentation found)
  int roll{0};         ///< --roll: quarter turns of the camera about its optical axis
  facyl::ShapeClassifier::Ptr classifier; ///< --model; nullptr: none
  bool track{false};                      ///< --track: the scenes are one stream
  facyl::CylinderTrackerParameters tracking;
};

/** --track: the stream's tracker and what its frames looked like. */
struct Stream {
  facyl::CylinderTracker tracker;
  std::uint32_t width{0}, height{0}; ///< the first organized frame's size
};

/** Camera for drawing: given, or estimated from an organized cloud (every 17th pixel). */
facyl::PinholeCamera
drawingCamera(const Cloud& cloud, const facyl::PinholeCamera& given)
{
  facyl::PinholeCamera camera = given;
  if (camera.valid() || !cloud.isOrganized())
    return camera;
  const auto samples = static_cast<Eigen::Index>(cloud.size() / 17 + 1);
  Eigen::Matrix3Xf pts(3, samples);
  Eigen::Matrix2Xf px(2, samples);
  Eigen::Index n = 0;
  for (std::size_t i = 0; i < cloud.size(); i += 17)
    if (pcl::isFinite(cloud[i])) {
      pts.col(n) = cloud[i].getVector3fMap();
      px.col(n++) =
        Eigen::Vector2f(static_cast<float>(i % cloud.width), static_cast<float>(i / cloud.width));
    }
  facyl::estimatePinhole(pts.leftCols(n), px.leftCols(n), static_cast<int>(cloud.width),
                         static_cast<int>(cloud.height), camera);
  return camera;
}

/** The overlay image: the RGB frame (or the points projected with the camera; a cloud without
 * colour coloured by depth) with the objects \a shown (detect_overlay.h: a box per object,
 * green: cylinder, red: not; the cylinders' outlines; with --track the tracks' ids).
 * \return false when the image could not be written (\a why says so); true with \a why set
 * when there is no overlay to draw (a warning), true with \a why empty when it was written. */
bool
drawOverlay(const std::string& path, const Cloud& cloud, const facyl::PinholeCamera& camera,
            const std::vector<facyl_cli::OverlayObject>& shown, std::string& why)
{
  why.clear();
  // A cloud without colour is drawn by its depth: black points on black show nothing.
  Cloud by_depth;
  if (!facyl_cli::hasColour(cloud)) {
    by_depth = cloud;
    facyl_cli::colourByDepth(by_depth);
  }
  const Cloud& drawn = by_depth.empty() ? cloud : by_depth;
  facyl_cli::Canvas canvas;
  if (drawn.isOrganized()) {
    canvas.width = static_cast<int>(drawn.width);
    canvas.height = static_cast<int>(drawn.height);
    canvas.rgb.resize(3 * drawn.size());
    for (std::size_t i = 0; i < drawn.size(); ++i) {
      const auto& p = drawn[i];
      canvas.rgb[3 * i] = p.r, canvas.rgb[3 * i + 1] = p.g, canvas.rgb[3 * i + 2] = p.b;
    }
  }
  else if (camera.valid()) {
    canvas.width = camera.width;
    canvas.height = camera.height;
    canvas.rgb.assign(3 * static_cast<std::size_t>(camera.width) * camera.height, 0);
    for (const auto& p : drawn)
      if (pcl::isFinite(p) && p.z > 0.f) {
        const Eigen::Vector2f q = camera.project(p.getVector3fMap());
        canvas.put(static_cast<int>(std::lround(q.x())), static_cast<int>(std::lround(q.y())),
                   {p.r, p.g, p.b});
      }
  }
  if (canvas.rgb.empty()) {
    why = "no overlay: an unorganized cloud needs --camera fx,fy,cx,cy";
    return true;
  }
  facyl_cli::drawOverlayObjects(canvas, camera, shown);
  std::error_code ec;
  std::filesystem::remove(path, ec); // so that a stale image does not pass for this one
  pcl::io::saveRgbPNGFile(path, canvas.rgb.data(), canvas.width, canvas.height);
  if (!std::filesystem::exists(path)) {
    why = "cannot write the overlay " + path;
    return false;
  }
  return true;
}

/** Each object's cloud (<stem>_obj<k>.pcd) and RGB crop (.png) in \a dir.
 * \return an empty string, or what could not be written. */
std::string
saveClusters(const std::string& dir, const std::string& name, const Cloud& cloud, bool has_colour,
             const std::vector<facyl::RecognizedObject>& objects)
{
  for (std::size_t k = 0; k < objects.size(); ++k) {
    const auto& o = objects[k];
    const std::string base =
      (std::filesystem::path(dir) / (name + "_obj" + std::to_string(k))).string();
    Cloud part;
    pcl::copyPointCloud(cloud, o.cluster.indices, part);
    if (pcl::io::savePCDFileBinaryCompressed(base + ".pcd", part) < 0)
      return "cannot write " + base + ".pcd";
    const auto& b = o.cluster.box;
    if (b[0] >= 0 && cloud.isOrganized() && has_colour) {
      const int w = b[2] - b[0] + 1, h = b[3] - b[1] + 1;
      std::vector<unsigned char> crop(3 * static_cast<std::size_t>(w) * h);
      for (int v = 0; v < h; ++v)
        for (int u = 0; u < w; ++u) {
          const auto& p = cloud.at(b[0] + u, b[1] + v);
          unsigned char* q = &crop[3 * (static_cast<std::size_t>(v) * w + u)];
          q[0] = p.r, q[1] = p.g, q[2] = p.b;
        }
      pcl::io::saveRgbPNGFile(base + ".png", crop.data(), w, h);
      if (!std::filesystem::exists(base + ".png"))
        return "cannot write " + base + ".png";
    }
  }
  return {};
}

bool
processScene(const std::string& file, const std::string& name, const Settings& s, std::ostream& out,
             Stream* stream)
{
  auto fail = [&](const std::string& why) {
    facyl_cli::Json line;
    line["file"] = file;
    line["error"] = why;
    if (stream) { // the stream goes on: nothing is known of this frame, the tracks are kept
      stream->tracker.skipFrame();
      facyl_cli::addStreamFields(line, stream->tracker, nullptr);
    }
    out << facyl_cli::dumpJson(line) << std::endl;
    return false;
  };
  pcl::PCLPointCloud2 blob;
  facyl_cli::Viewpoint viewpoint;
  const std::string why = facyl_cli::readPcd(file, blob, &viewpoint);
  if (!why.empty())
    return fail(why);
  Cloud::Ptr cloud(new Cloud);
  pcl::fromPCLPointCloud2(blob, *cloud);
  cloud->sensor_origin_ = viewpoint.origin;
  cloud->sensor_orientation_ = viewpoint.orientation;
  if (s.roll != 0) {
    if (!cloud->isOrganized())
      return fail("--roll needs an organized cloud");
    *cloud = facyl::rollFrame(*cloud, s.roll);
  }
  const bool has_colour = facyl_cli::hasField(blob, "rgb") || facyl_cli::hasField(blob, "rgba");
  if (cloud->empty())
    return fail("the cloud is empty");
  if (std::none_of(cloud->begin(), cloud->end(), [](const auto& p) { return pcl::isFinite(p); }))
    return fail("the cloud has no finite point");

  facyl::TabletopCylinderRecognizer<pcl::PointXYZRGBA> rec;
  rec.setParameters(s.params);
  rec.setCamera(s.camera);
  rec.setUpDirection(s.up);
  rec.setClassifier(s.classifier);
  rec.setInputCloud(cloud);
  if (stream) // the tracks' table, where the camera's motion puts it
    stream->tracker.prepare(rec);
  std::vector<facyl::RecognizedObject> objects;
  std::vector<facyl::RecognitionTiming> timings;
  for (int r = 0; r < s.repeat; ++r) {
    if (!rec.recognize(objects))
      return fail("recognition failed (see the message above)");
    timings.push_back(rec.getTiming());
  }
  // Median over the repetitions, by total.
  std::sort(timings.begin(), timings.end(),
            [](const auto& a, const auto& b) { return a.total < b.total; });
  std::string warning, error;
  facyl_cli::Json line;
  if (stream) {
    // Frames of another size are no error (the tracks are in the table's frame), but worth a
    // word: a stream usually comes from one sensor.
    if (cloud->isOrganized()) {
      if (stream->width == 0) {
        stream->width = cloud->width;
        stream->height = cloud->height;
      }
      else if (cloud->width != stream->width || cloud->height != stream->height)
        warning = "frame of " + std::to_string(cloud->width) + "x" + std::to_string(cloud->height) +
                  " pixels in a stream of " + std::to_string(stream->width) + "x" +
                  std::to_string(stream->height) + ": tracked on (the tracks are kept)";
    }
    stream->tracker.update(rec, objects);
    line = facyl_cli::trackedSceneJson(file, *cloud, rec, objects, timings[timings.size() / 2],
                                       stream->tracker);
  }
  else
    line = facyl_cli::sceneJson(file, *cloud, rec, objects, timings[timings.size() / 2]);

  // Outputs: a warning (no overlay possible) goes to standard error and keeps the status; an
  // output that could not be written is an error of the scene.
  if (!s.overlay.empty()) {
    const std::string path =
      s.many ? (std::filesystem::path(s.overlay) / (name + ".png")).string() : s.overlay;
    std::string why;
    const auto shown = stream ? facyl_cli::trackedOverlayObjects(objects, stream->tracker)
                              : facyl_cli::overlayObjects(objects);
    if (!drawOverlay(path, *cloud, drawingCamera(*cloud, s.camera), shown, why))
      error = why;
    else if (!why.empty())
      warning += (warning.empty() ? "" : "; ") + why;
  }
  if (!s.clusters_dir.empty() && error.empty())
    error = saveClusters(s.clusters_dir, name, *cloud, has_colour, objects);
  if (!warning.empty()) {
    facyl_cli::warn("facyl_detect", file + ": " + warning);
    line["warning"] = warning;
  }
  if (!error.empty()) {
    std::fprintf(stderr, "facyl_detect: %s: %s\n", file.c_str(), error.c_str());
    line["error"] = error;
  }
  out << facyl_cli::dumpJson(line) << std::endl;
  return error.empty();
}

/** Refuses outputs that would replace an input or are not of the kind asked for (before
 * anything is read or written). \throws std::invalid_argument. */
void
checkOutputs(const Settings& s, const std::vector<std::string>& files, const std::string& model)
{
  std::vector<std::string> inputs = files;
  if (!model.empty() && model != "default" && model != "none") {
    inputs.push_back(model);
    inputs.push_back(std::filesystem::path(model).replace_extension(".cfg").string());
  }
  const std::vector<std::string> names = outputNames(files);
  const auto isName = [&names](const std::string& filename, const std::string& suffix_pattern) {
    for (const auto& n : names)
      if (filename.size() > n.size() && filename.compare(0, n.size(), n) == 0) {
        const std::string rest = filename.substr(n.size());
        if (suffix_pattern == ".png" && rest == ".png")
          return true;
        // "_obj<k>.pcd" or "_obj<k>.png"
        if (suffix_pattern == "_obj" && rest.size() > 8 && rest.compare(0, 4, "_obj") == 0) {
          const std::string ext = rest.substr(rest.size() - 4);
          const std::string k = rest.substr(4, rest.size() - 8);
          if ((ext == ".pcd" || ext == ".png") && !k.empty() &&
              k.find_first_not_of("0123456789") == std::string::npos)
            return true;
        }
      }
    return false;
  };
  if (!s.overlay.empty()) {
    if (s.many) {
      if (!std::filesystem::is_directory(s.overlay))
        throw std::invalid_argument("--overlay " + s.overlay +
                                    ": with several scenes, a folder "
                                    "that exists (one <stem>.png per scene). Nothing was written.");
      facyl_cli::checkOutputFolder(
        "--overlay", s.overlay, [&](const std::string& f) { return isName(f, ".png"); }, inputs);
    }
    else {
      facyl_cli::checkOutputFile("--overlay", s.overlay, {".png"}, "PNG image", inputs);
      const auto parent = std::filesystem::path(s.overlay).parent_path();
      if (!parent.empty() && !std::filesystem::is_directory(parent))
        throw std::invalid_argument("folder '" + parent.string() + "' does not exist");
    }
  }
  if (!s.clusters_dir.empty()) {
    if (!std::filesystem::is_directory(s.clusters_dir))
      throw std::invalid_argument("folder '" + s.clusters_dir + "' does not exist");
    facyl_cli::checkOutputFolder(
      "--save-clusters", s.clusters_dir, [&](const std::string& f) { return isName(f, "_obj"); },
      inputs);
    // Not into a folder of scenes: its next *.pcd would read the clusters as scenes.
    for (const auto& f : files) {
      const std::filesystem::path p(f);
      if (facyl_cli::samePath(p.has_parent_path() ? p.parent_path() : ".", s.clusters_dir))
        throw std::invalid_argument("--save-clusters " + s.clusters_dir + ": holds the input " + f +
                                    "; a later *.pcd of that folder would read the clusters "
                                    "(<stem>_obj<k>.pcd) as scenes. Give another folder. "
                                    "Nothing was written.");
    }
  }
}

/** Settings from the command line. \throws std::invalid_argument for bad usage. */
Settings
parseSettings(int argc, char** argv, std::vector<std::string>& files)
{
  Settings s;
  const facyl_cli::Arguments args(
    argc, argv,
    facyl_cli::joined(facyl_cli::joined(facyl_cli::recognizerValueOptions(),
                                        facyl_cli::valueOptions(facyl_cli::trackerOptions())),
                      {"--camera", "--overlay", "--save-clusters", "--repeat", "--roll"}),
    facyl_cli::joined(facyl_cli::recognizerSwitches(), {"--verbose", "--track"}),
    facyl_cli::recognizerAliases());
  files = args.positional();
  if (files.empty())
    throw std::invalid_argument("give at least one scene (see -h)");
  facyl_cli::RecognizerSettings recognizer;
  s.classifier = facyl_cli::applyRecognizerOptions(args, recognizer);
  s.params = recognizer.params;
  s.up = recognizer.up;
  if (args.has("--camera")) {
    std::istringstream in(args.text("--camera", ""));
    char c1 = 0, c2 = 0, c3 = 0;
    facyl::PinholeCamera& cam = s.camera;
    if (!(in >> cam.fx >> c1 >> cam.fy >> c2 >> cam.cx >> c3 >> cam.cy) || c1 != ',' || c2 != ',' ||
        c3 != ',' || !in.eof() || !(cam.fx > 0.f && cam.fx <= 1e5f) ||
        !(cam.fy > 0.f && cam.fy <= 1e5f) || !(cam.cx >= 0.f && cam.cx <= 4000.f) ||
        !(cam.cy >= 0.f && cam.cy <= 4000.f))
      throw std::invalid_argument("--camera: expected fx,fy,cx,cy with 0 < fx, fy <= 1e5 and "
                                  "0 <= cx, cy <= 4000 (images up to 8001 x 8001 pixels)");
    cam.width = static_cast<int>(std::ceil(2.f * cam.cx + 1.f));
    cam.height = static_cast<int>(std::ceil(2.f * cam.cy + 1.f));
  }
  s.overlay = args.text("--overlay", "");
  s.clusters_dir = args.text("--save-clusters", "");
  s.repeat = static_cast<int>(args.integer("--repeat", 1, 1, 1000));
  const long long roll = args.integer("--roll", 0, 0, 270);
  if (roll % 90 != 0)
    throw std::invalid_argument("--roll must be 0, 90, 180 or 270 (degrees)");
  s.roll = static_cast<int>(roll / 90);
  s.verbose = args.has("--verbose");
  s.track = args.has("--track");
  if (!s.track && (args.has("--track-confirm-hits") || args.has("--track-max-misses") ||
                   args.has("--track-support-switch-frames")))
    throw std::invalid_argument(
      "--track-confirm-hits, --track-max-misses and --track-support-switch-frames need --track");
  facyl_cli::applyOptions(facyl_cli::trackerOptions(), args, s.tracking);
  s.many = files.size() > 1;
  checkOutputs(s, files, args.text("--model", ""));
  return s;
}

} // namespace

int
main(int argc, char** argv)
{
  Settings s;
  std::vector<std::string> files;
  const int rc = facyl_cli::startTool(argc, argv, "facyl_detect", printHelp,
                                      [&] { s = parseSettings(argc, argv, files); });
  if (rc >= 0)
    return rc;
  // PCL's warnings about a file (e.g. a cloud without colour) would drown the output; the
  // errors that explain a failed scene stay.
  pcl::console::setVerbosityLevel(s.verbose ? pcl::console::L_DEBUG : pcl::console::L_ERROR);
  const std::vector<std::string> names = outputNames(files);
  std::unique_ptr<Stream> stream;
  if (s.track) {
    stream = std::make_unique<Stream>();
    stream->tracker.setParameters(s.tracking);
    stream->tracker.setCamera(s.camera);
  }
  bool all_ok = true;
  facyl_cli::Progress progress("facyl_detect", files.size());
  for (std::size_t k = 0; k < files.size(); ++k) {
    bool ok = false;
    try {
      ok = processScene(files[k], names[k], s, std::cout, stream.get());
    }
    catch (const std::exception& e) { // e.g. std::bad_alloc: this scene fails, the batch goes on
      facyl_cli::Json line;
      line["file"] = files[k];
      line["error"] = std::string("unexpected failure: ") + e.what();
      if (stream) {
        stream->tracker.skipFrame();
        facyl_cli::addStreamFields(line, stream->tracker, nullptr);
      }
      std::cout << facyl_cli::dumpJson(line) << std::endl;
    }
    all_ok = ok && all_ok;
    progress.step();
  }
  return all_ok ? 0 : 1;
}
