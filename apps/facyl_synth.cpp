/*
 * facyl_synth: render random RGB-D tabletop scenes with ground truth.
 *
 * For each scene PREFIX_NNNN (or PREFIX when --count is 1) it writes PREFIX.pcd (organized
 * XYZRGBA, NaN where the sensor gives no depth), PREFIX_ids.png (16-bit object id per pixel:
 * 0 background, 1 table, 2+ objects), PREFIX_class.png (8-bit class per pixel, see --help),
 * PREFIX_rgb.png and PREFIX.json (ground truth), and prints one JSON line per scene. Scenery (far
 * furniture, robots) has ids 1000+ and class 7.
 */
#include <facyl/tools/cli.h>
#include <facyl/tools/json_writer.h>
#include <facyl/tools/scene_options.h>

#include <facyl/simulation/tabletop_scene.h>
#include <facyl/simulation/tabletop_sequence.h>

#include <pcl/io/pcd_io.h>
#include <pcl/io/png_io.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>

namespace {
void
printHelp(const char* self)
{
  std::printf(
    "Usage: %s [options] PREFIX\n"
    "Renders random tabletop scenes (pinhole 640x480 RGB-D camera with a depth sensor model)\n"
    "and writes PREFIX.pcd, PREFIX_rgb.png, PREFIX_ids.png, PREFIX_class.png and PREFIX.json;\n"
    "with --count N > 1, PREFIX_0000 ... PREFIX_{N-1}.\n"
    "  --layout L         spread (default: objects apart on a large table) | cluttered\n"
    "                     (touching, stacked and leaning objects; small, round or large\n"
    "                     tables with legs over a floor, sometimes a wall; wider camera poses)\n"
    "                     | realistic (cluttered, plus curved table tops, glossy, dark and\n"
    "                     transparent surfaces, far furniture, sometimes a robot arm,\n"
    "                     cameras 15-85 degrees above the table, any roll in 30%%)\n"
    "  --sensor S         kinect (default: structured light, disparity quantised to 1/8 px)\n"
    "                     | stereo (RealSense D4xx-like: speckled holes, fattened edges,\n"
    "                     colour/depth misregistration) | random (a structured-light,\n"
    "                     active-stereo or time-of-flight sensor drawn per scene: noise, bias,\n"
    "                     holes, edges, response to materials; see docs/simulation.md)\n"
    "  --seed S           seed of the first scene (default 0); scene k uses S + k\n"
    "  --count N          number of scenes (default 1)\n"
    "  --objects MIN,MAX  objects per scene (default 3,10; cluttered 4,10)\n"
    "  --cylinder-share P probability that an object is a cylinder (default 0.5)\n"
    "  --lying-share P    probability that a can or tube lies (default 0.25)\n"
    "  --noise K          axial depth noise sigma = K z^2 (default: the sensor's; not with\n"
    "                     --sensor random)\n"
    "  --no-quantisation  no disparity quantisation (not with --sensor random)\n"
    "  --sequence N       a stream of N frames (2..100000) instead of one: the camera moves\n"
    "                     along a smooth path around the static scene (an orbit about the\n"
    "                     point it looks at, slow changes of elevation and distance), so\n"
    "                     objects occlude each other and leave or enter the view; writes\n"
    "                     PREFIX_fNNNN.* per frame (PREFIX_SSSS_fNNNN.* with --count) and\n"
    "                     PREFIX_sequence.json (camera pose and object ids present per frame;\n"
    "                     object ids are the same in every frame's _ids.png and .json)\n"
    "  --orbit RAD        --sequence: how far the camera turns over the sequence, in\n"
    "                     [0, 6.3] (default 0.9)\n"
    "  --change C         --sequence: none (default) | remove (an object is taken away\n"
    "                     half-way) | add (an object is put down half-way)\n"
    "%s"
    "Class codes in PREFIX_class.png: 0 background, 1 table, 2 cylinder, 3 box, 4 sphere,\n"
    "5 cone, 6 bowl, 7 scenery (far furniture, robots: ids 1000+ in PREFIX_ids.png).\n"
    "PREFIX is a name without extension in a folder that exists (a PREFIX ending in .pcd,\n"
    ".png or .json, or naming a folder, is refused).\n%s",
    self, facyl_cli::sceneImageOptionsHelp(), facyl_cli::commonHelp());
}
/** PREFIX names files to write (PREFIX.pcd, PREFIX_rgb.png, ...): a name without an
 * extension of those files, not a folder. \throws std::invalid_argument. */
void
checkPrefix(const std::string& prefix)
{
  const std::string ext = facyl_cli::lowerExtension(prefix);
  if (prefix.empty() || prefix.back() == '/' || std::filesystem::is_directory(prefix))
    throw std::invalid_argument("PREFIX '" + prefix +
                                "' is a folder; give DIR/NAME (writes "
                                "DIR/NAME.pcd, DIR/NAME_rgb.png, ...). Nothing was written.");
  if (ext == ".pcd" || ext == ".png" || ext == ".json")
    throw std::invalid_argument("PREFIX '" + prefix + "' ends in " + ext +
                                "; give the name "
                                "without extension (facyl_synth adds .pcd, _rgb.png, _ids.png, "
                                "_class.png and .json). Nothing was written.");
  const auto parent = std::filesystem::path(prefix).parent_path();
  if (!parent.empty() && !std::filesystem::is_directory(parent))
    throw std::invalid_argument("folder '" + parent.string() + "' does not exist");
}

/** Writes one rendered frame as NAME.pcd, NAME_rgb.png, NAME_ids.png, NAME_class.png and
 * NAME.json. \return false when NAME.pcd or NAME.json could not be written. */
bool
writeFrame(const std::string& name, const facyl::RenderedScene& scene)
{
  const int w = scene.camera.width, h = scene.camera.height;
  std::vector<unsigned char> classes(scene.pixel_class.size());
  for (std::size_t i = 0; i < classes.size(); ++i)
    classes[i] = static_cast<unsigned char>(scene.pixel_class[i]);
  const std::string json = facyl::groundTruthJson(scene);
  std::ofstream js(name + ".json");
  js << json << "\n";
  if (pcl::io::savePCDFileBinaryCompressed(name + ".pcd", scene.cloud) < 0 || !js) {
    std::fprintf(stderr, "facyl_synth: cannot write %s.pcd/.json\n", name.c_str());
    return false;
  }
  std::vector<unsigned char> rgb(3 * scene.cloud.size());
  for (std::size_t i = 0; i < scene.cloud.size(); ++i) {
    rgb[3 * i] = scene.cloud[i].r;
    rgb[3 * i + 1] = scene.cloud[i].g;
    rgb[3 * i + 2] = scene.cloud[i].b;
  }
  pcl::io::saveRgbPNGFile(name + "_rgb.png", rgb.data(), w, h);
  pcl::io::saveShortPNGFile(name + "_ids.png", scene.object_id.data(), w, h, 1);
  pcl::io::saveCharPNGFile(name + "_class.png", classes.data(), w, h, 1);
  return true;
}

/** --sequence: the frames of one sequence and its PREFIX_sequence.json. \return false when a
 * file could not be written. */
bool
writeSequence(const std::string& name, const facyl::TabletopSceneParameters& p,
              const facyl::TabletopSequenceParameters& sp)
{
  facyl::TabletopSceneParameters scene_params = p;
  if (p.sensor.randomize) { // one sensor for the whole stream, drawn from the seed
    const facyl::DrawnSensor drawn = facyl::drawSensor(p.camera, p.seed);
    scene_params.sensor = drawn.sensor;
    scene_params.camera = drawn.camera;
  }
  const facyl::TabletopSequence seq = facyl::generateTabletopSequence(scene_params, sp);
  std::ofstream js(name + "_sequence.json");
  js << facyl::sequenceJson(seq) << "\n";
  if (!js) {
    std::fprintf(stderr, "facyl_synth: cannot write %s_sequence.json\n", name.c_str());
    return false;
  }
  for (std::size_t k = 0; k < seq.cameras.size(); ++k) {
    char suffix[32];
    std::snprintf(suffix, sizeof suffix, "_f%04zu", k);
    const facyl::RenderedScene frame = facyl::renderSequenceFrame(
      seq, k, scene_params.camera, scene_params.sensor, facyl::sequenceFrameSeed(p.seed, k));
    if (!writeFrame(name + suffix, frame))
      return false;
    std::size_t present = 0;
    for (std::size_t i = 0; i < seq.scene.objects.size(); ++i)
      present += seq.present(i, k);
    facyl_cli::Json line;
    line["file"] = name + suffix + ".pcd";
    line["seed"] = p.seed;
    line["frame"] = k;
    line["objects"] = present;
    std::cout << facyl_cli::dumpJson(line) << std::endl;
  }
  return true;
}

} // namespace

int
main(int argc, char** argv)
{
  facyl::TabletopSceneParameters p;
  std::string prefix;
  std::size_t count = 1;
  facyl::TabletopSequenceParameters sequence;
  bool stream = false;
  const int rc = facyl_cli::startTool(argc, argv, "facyl_synth", printHelp, [&] {
    const facyl_cli::Arguments args(
      argc, argv,
      facyl_cli::joined(facyl_cli::sceneImageOptions(),
                        {"--seed", "--count", "--objects", "--cylinder-share", "--lying-share",
                         "--noise", "--layout", "--sensor", "--sequence", "--orbit", "--change"}),
      {"--no-quantisation"});
    if (args.positional().size() != 1)
      throw std::invalid_argument("give exactly one output prefix (see -h)");
    prefix = args.positional()[0];
    checkPrefix(prefix);
    if (!facyl::parseLayoutPreset(args.text("--layout", "spread"), p))
      throw std::invalid_argument("--layout must be spread, cluttered or realistic");
    if (!facyl::parseSensorPreset(args.text("--sensor", "kinect"), p.sensor, p.camera))
      throw std::invalid_argument("--sensor must be kinect, stereo or random");
    if (p.sensor.randomize && (args.has("--noise") || args.has("--no-quantisation")))
      throw std::invalid_argument("--noise and --no-quantisation cannot be combined with "
                                  "--sensor random (its settings are drawn per scene)");
    p.seed = static_cast<std::uint64_t>(args.integer("--seed", 0, 0, facyl_cli::kMaxSeed));
    count = static_cast<std::size_t>(args.integer("--count", 1, 1, 100000));
    const std::string objects =
      args.text("--objects", std::to_string(p.min_objects) + "," + std::to_string(p.max_objects));
    unsigned lo = 0, hi = 0;
    char comma = 0, extra = 0;
    if (std::sscanf(objects.c_str(), "%u%c%u%c", &lo, &comma, &hi, &extra) != 3 || comma != ',')
      throw std::invalid_argument("--objects: expected MIN,MAX, got '" + objects + "'");
    p.min_objects = lo;
    p.max_objects = hi;
    p.cylinder_share =
      static_cast<float>(args.number("--cylinder-share", p.cylinder_share, 0.0, 1.0));
    p.lying_share = static_cast<float>(args.number("--lying-share", p.lying_share, 0.0, 1.0));
    p.sensor.noise_coefficient =
      static_cast<float>(args.number("--noise", p.sensor.noise_coefficient, 0.0, 0.1));
    if (args.has("--no-quantisation"))
      p.sensor.disparity_step = 0.f;
    facyl_cli::applySceneImageOptions(args, p);
    const std::string why = facyl::validate(p);
    if (!why.empty())
      throw std::invalid_argument(why);
    stream = args.has("--sequence");
    if (!stream && (args.has("--orbit") || args.has("--change")))
      throw std::invalid_argument("--orbit and --change need --sequence N");
    if (stream) {
      sequence.frames = static_cast<std::size_t>(args.integer("--sequence", 30, 2, 100000));
      sequence.orbit = static_cast<float>(args.number("--orbit", sequence.orbit, 0.0, 6.3));
      if (!facyl::parseSequenceChange(args.text("--change", "none"), sequence.change))
        throw std::invalid_argument("--change must be none, remove or add");
      const std::string bad = facyl::validate(sequence);
      if (!bad.empty())
        throw std::invalid_argument(bad);
    }
  });
  if (rc >= 0)
    return rc;
  const std::uint64_t first_seed = p.seed;
  for (std::size_t k = 0; k < count; ++k) {
    p.seed = first_seed + k;
    std::string name = prefix;
    if (count > 1) {
      char suffix[32];
      std::snprintf(suffix, sizeof suffix, "_%04zu", k);
      name += suffix;
    }
    if (stream) {
      if (!writeSequence(name, p, sequence))
        return 1;
      continue;
    }
    const facyl::RenderedScene scene = facyl::simulateTabletopScene(p);
    if (!writeFrame(name, scene))
      return 1;
    std::size_t cylinders = 0;
    for (const auto& o : scene.scene.objects)
      cylinders += o.cls == facyl::SceneClass::Cylinder;
    facyl_cli::Json line;
    line["file"] = name + ".pcd";
    line["seed"] = p.seed;
    line["objects"] = scene.scene.objects.size();
    line["cylinders"] = cylinders;
    std::cout << facyl_cli::dumpJson(line) << std::endl;
  }
  return 0;
}
