/*
 * facyl_detect: every cylinder on the table of RGB-D frames (paper III-A without the CNN).
 * One JSON object per scene on stdout.
 */
#include "cli.h"
#include "pcd_input.h"

#include <facyl/recognition/tabletop_cylinder_recognizer.h>

#include <pcl/common/io.h>
#include <pcl/conversions.h>
#include <pcl/io/pcd_io.h>
#include <pcl/io/png_io.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <sstream>

namespace {

using Cloud = pcl::PointCloud<pcl::PointXYZRGBA>;

void
printHelp(const char* self)
{
  std::printf(
    "Usage: %s [options] SCENE.pcd...\n"
    "Finds the table, the objects on it and the cylinders among them; prints one JSON object\n"
    "per scene. Organized clouds (RGB-D frames) and unorganized clouds are accepted.\n"
    "Decision (a fitted object is a cylinder if score >= R, curvature ratio <= C and\n"
    "angular coverage >= V):\n"
    "  --score S              surface (default: lateral inliers + points on the end caps, over\n"
    "                         all points) | inlier (the paper's eq. 4 inlier ratio)\n"
    "  --min-inlier-ratio R   score threshold (default 0.5)\n"
    "  --max-curvature-ratio C  median |k_min| / median |k_max| of the inliers at most C\n"
    "                         (default 0.35; 1 turns the check off)\n"
    "  --min-coverage V       inliers cover at least V of the circumference (default 0.2)\n"
    "  --no-retry             no second fit with upright/lying priors when the first fails\n"
    "  --retry-inside         a last retry also fits concave clusters (the inside of an open\n"
    "                         container; bowls too)\n"
    "  --any-normal-sign      inliers' normals may point at the axis (default: away from it)\n"
    "Fit:\n"
    "  --prior P              orientation prior in the table frame: uniform | vertical (default)\n"
    "                         | vertical-strong | horizontal\n"
    "  --radius-limits A,B    radius interval in m (default 0.01,0.25)\n"
    "  --orientations N       accumulator cells (default 450)\n"
    "  --max-fit-points N     clusters are subsampled to N points for the fit (default 1200)\n"
    "  --neighbours K         k of the normal/curvature estimation (default 16)\n"
    "  --seed S               accumulator seed (default 0)\n"
    "Segmentation:\n"
    "  --plane-distance D     table inlier distance in m (default 0.015)\n"
    "  --height-limits A,B    object points lie A..B m above the table (default 0.01,0.5)\n"
    "  --cluster-tolerance D  Euclidean cluster tolerance in m (default 0.02)\n"
    "  --cluster-size A,B     cluster size limits in points (default 300,200000)\n"
    "  --camera fx,fy,cx,cy   intrinsics for boxes of unorganized clouds (and their overlay)\n"
    "Output:\n"
    "  --overlay PATH         RGB image with boxes (green: cylinder, red: not) and fitted\n"
    "                         outlines; with several scenes PATH is a folder (<stem>.png)\n"
    "  --save-clusters DIR    each cluster's cloud (<stem>_obj<k>.pcd) and RGB crop (.png)\n"
    "  --repeat N             run N times, report the median timing (default 1)\n"
    "Exit status: 0 all scenes processed, 1 a scene failed (its JSON has \"error\"), 2 bad usage.\n",
    self);
}

std::pair<double, double>
pairOption(const facyl_cli::Arguments& args, const std::string& name, double a, double b)
{
  const std::string text = args.text(name, "");
  if (text.empty())
    return {a, b};
  std::istringstream in(text);
  char comma = 0;
  if (!(in >> a >> comma >> b) || comma != ',' || !in.eof())
    throw std::invalid_argument("option " + name + ": expected A,B, got '" + text + "'");
  return {a, b};
}

// ---- drawing on an RGB buffer ----
struct Canvas {
  int width{0}, height{0};
  std::vector<unsigned char> rgb;
  void
  put(int u, int v, const std::array<unsigned char, 3>& c)
  {
    if (u < 0 || v < 0 || u >= width || v >= height)
      return;
    std::copy(c.begin(), c.end(), rgb.begin() + 3 * (static_cast<std::size_t>(v) * width + u));
  }
  void
  line(Eigen::Vector2f a, Eigen::Vector2f b, const std::array<unsigned char, 3>& c, int thick = 1)
  {
    if (!a.allFinite() || !b.allFinite() || (a - b).norm() > 4.f * (width + height))
      return;
    const int steps = std::max(1, static_cast<int>(std::ceil((b - a).lpNorm<Eigen::Infinity>())));
    for (int s = 0; s <= steps; ++s) {
      const Eigen::Vector2f p = a + (b - a) * (static_cast<float>(s) / steps);
      for (int dv = 0; dv < thick; ++dv)
        for (int du = 0; du < thick; ++du)
          put(static_cast<int>(std::lround(p.x())) + du, static_cast<int>(std::lround(p.y())) + dv, c);
    }
  }
};

void
drawCylinder(Canvas& canvas, const facyl::PinholeCamera& cam, const facyl::CylinderModel& m,
             const std::array<unsigned char, 3>& colour)
{
  const Eigen::Vector3f a = m.axis.normalized();
  Eigen::Vector3f e1 = a.unitOrthogonal(), e2 = a.cross(e1);
  auto project = [&](const Eigen::Vector3f& p) {
    return p.z() > 0.f ? cam.project(p) : Eigen::Vector2f::Constant(NAN);
  };
  for (const Eigen::Vector3f& c : {m.base, m.top}) {
    Eigen::Vector2f prev;
    for (int k = 0; k <= 48; ++k) {
      const float t = 2.f * static_cast<float>(M_PI) * k / 48.f;
      const Eigen::Vector2f q = project(c + m.radius * (std::cos(t) * e1 + std::sin(t) * e2));
      if (k)
        canvas.line(prev, q, colour);
      prev = q;
    }
  }
  // Silhouette generators: perpendicular to both the axis and the line of sight.
  const Eigen::Vector3f centre = 0.5f * (m.base + m.top);
  Eigen::Vector3f side = a.cross(centre);
  if (side.norm() < 1e-6f)
    return;
  side = side.normalized() * m.radius;
  for (float s : {-1.f, 1.f})
    canvas.line(project(m.base + s * side), project(m.top + s * side), colour, 2);
}

std::string
stemOf(const std::string& file)
{
  return std::filesystem::path(file).stem().string();
}

struct Settings {
  facyl::TabletopRecognizerParameters params;
  facyl::PinholeCamera camera;
  std::string overlay, clusters_dir;
  int repeat{1};
  bool many{false};
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
      px.col(n++) = Eigen::Vector2f(static_cast<float>(i % cloud.width),
                                    static_cast<float>(i / cloud.width));
    }
  facyl::estimatePinhole(pts.leftCols(n), px.leftCols(n), static_cast<int>(cloud.width),
                         static_cast<int>(cloud.height), camera);
  return camera;
}

/** One object of the JSON output. */
void
writeObject(std::ostream& out, std::size_t id, const facyl::RecognizedObject& o)
{
  const auto& b = o.cluster.box;
  const auto& e = o.evidence;
  const auto optional = [](float v) {
    return std::isfinite(v) ? facyl_cli::number(v) : std::string("null");
  };
  out << "{\"id\":" << id << ",\"centroid\":" << facyl_cli::vector(o.cluster.centroid)
      << ",\"n_points\":" << o.cluster.indices.indices.size() << ",\"bbox\":";
  if (b[0] < 0)
    out << "null";
  else
    out << "[" << b[0] << "," << b[1] << "," << b[2] << "," << b[3] << "]";
  out << ",\"p_cylinder\":" << optional(e.p_cylinder)
      << ",\"inlier_ratio\":" << facyl_cli::number(e.inlier_ratio)
      << ",\"surface_ratio\":" << facyl_cli::number(e.surface_ratio)
      << ",\"curvature_ratio\":" << optional(e.curvature_ratio)
      << ",\"is_cylinder\":" << (o.is_cylinder ? "true" : "false") << ",\"cylinder\":";
  if (e.fitted)
    out << "{\"point_on_axis\":" << facyl_cli::vector(o.cylinder.base)
        << ",\"axis\":" << facyl_cli::vector(o.cylinder.axis)
        << ",\"radius\":" << facyl_cli::number(o.cylinder.radius)
        << ",\"height\":" << facyl_cli::number(o.cylinder.height)
        << ",\"angular_coverage\":" << facyl_cli::number(o.cylinder.angular_coverage) << "}";
  else
    out << "null";
  out << "}";
}

/** The scene's JSON object, without its closing brace (a warning may follow). */
void
writeScene(std::ostream& out, const std::string& file, const Cloud& cloud,
           const facyl::TabletopCylinderRecognizer<pcl::PointXYZRGBA>& rec,
           const std::vector<facyl::RecognizedObject>& objects,
           const facyl::RecognitionTiming& t)
{
  const auto& tc = rec.getTableCoefficients().values;
  out << "{\"file\":" << facyl_cli::quote(file) << ",\"organized\":"
      << (cloud.isOrganized() ? "true" : "false") << ",\"table\":{\"coefficients\":["
      << facyl_cli::number(tc[0]) << "," << facyl_cli::number(tc[1]) << ","
      << facyl_cli::number(tc[2]) << "," << facyl_cli::number(tc[3]) << "]},\"objects\":[";
  for (std::size_t k = 0; k < objects.size(); ++k) {
    out << (k ? "," : "");
    writeObject(out, k, objects[k]);
  }
  out << "],\"timing_ms\":{\"segmentation\":" << facyl_cli::number(t.segmentation)
      << ",\"classification\":" << facyl_cli::number(t.classification)
      << ",\"fitting\":" << facyl_cli::number(t.fitting) << ",\"total\":"
      << facyl_cli::number(t.total) << "}";
}

/** The overlay image: the RGB frame (or the points projected with the camera) with a box per
 * object (green: cylinder, red: not) and the fitted cylinders' outlines.
 * \return an empty string, or why there is no overlay. */
std::string
drawOverlay(const std::string& path, const Cloud& cloud, const facyl::PinholeCamera& camera,
            const std::vector<facyl::RecognizedObject>& objects)
{
  Canvas canvas;
  if (cloud.isOrganized()) {
    canvas.width = static_cast<int>(cloud.width);
    canvas.height = static_cast<int>(cloud.height);
    canvas.rgb.resize(3 * cloud.size());
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      const auto& p = cloud[i];
      canvas.rgb[3 * i] = p.r, canvas.rgb[3 * i + 1] = p.g, canvas.rgb[3 * i + 2] = p.b;
    }
  } else if (camera.valid()) {
    canvas.width = camera.width;
    canvas.height = camera.height;
    canvas.rgb.assign(3 * static_cast<std::size_t>(camera.width) * camera.height, 0);
    for (const auto& p : cloud)
      if (pcl::isFinite(p) && p.z > 0.f) {
        const Eigen::Vector2f q = camera.project(p.getVector3fMap());
        canvas.put(static_cast<int>(std::lround(q.x())), static_cast<int>(std::lround(q.y())),
                   {p.r, p.g, p.b});
      }
  }
  if (canvas.rgb.empty())
    return "no overlay: an unorganized cloud needs --camera";
  const std::array<unsigned char, 3> green{0, 230, 0}, red{230, 0, 0}, yellow{255, 230, 0};
  for (const auto& o : objects) {
    const auto& b = o.cluster.box;
    if (b[0] >= 0) {
      const auto& c = o.is_cylinder ? green : red;
      const Eigen::Vector2f p00(b[0], b[1]), p10(b[2], b[1]), p11(b[2], b[3]), p01(b[0], b[3]);
      canvas.line(p00, p10, c, 2), canvas.line(p10, p11, c, 2);
      canvas.line(p11, p01, c, 2), canvas.line(p01, p00, c, 2);
    }
    if (o.is_cylinder && camera.valid())
      drawCylinder(canvas, camera, o.cylinder, yellow);
  }
  pcl::io::saveRgbPNGFile(path, canvas.rgb.data(), canvas.width, canvas.height);
  if (!std::filesystem::exists(path))
    return "cannot write the overlay " + path;
  return {};
}

/** Each object's cloud (<stem>_obj<k>.pcd) and RGB crop (.png) in \a dir.
 * \return an empty string, or what could not be written. */
std::string
saveClusters(const std::string& dir, const std::string& file, const Cloud& cloud,
             bool has_colour, const std::vector<facyl::RecognizedObject>& objects)
{
  for (std::size_t k = 0; k < objects.size(); ++k) {
    const auto& o = objects[k];
    const std::string base =
      (std::filesystem::path(dir) / (stemOf(file) + "_obj" + std::to_string(k))).string();
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
    }
  }
  return {};
}

bool
processScene(const std::string& file, const Settings& s, std::ostream& out)
{
  auto fail = [&](const std::string& why) {
    out << "{\"file\":" << facyl_cli::quote(file) << ",\"error\":" << facyl_cli::quote(why) << "}"
        << std::endl;
    return false;
  };
  pcl::PCLPointCloud2 blob;
  const std::string why = facyl_cli::readPcd(file, blob);
  if (!why.empty())
    return fail(why);
  Cloud::Ptr cloud(new Cloud);
  pcl::fromPCLPointCloud2(blob, *cloud);
  const bool has_colour = facyl_cli::hasField(blob, "rgb") || facyl_cli::hasField(blob, "rgba");
  if (cloud->empty())
    return fail("the cloud is empty");
  if (std::none_of(cloud->begin(), cloud->end(), [](const auto& p) { return pcl::isFinite(p); }))
    return fail("the cloud has no finite point");

  facyl::TabletopCylinderRecognizer<pcl::PointXYZRGBA> rec;
  rec.setParameters(s.params);
  rec.setCamera(s.camera);
  rec.setInputCloud(cloud);
  std::vector<facyl::RecognizedObject> objects;
  std::vector<facyl::RecognitionTiming> timings;
  for (int r = 0; r < s.repeat; ++r) {
    if (!rec.recognize(objects))
      return fail("no table found: no plane with enough points (see the message above)");
    timings.push_back(rec.getTiming());
  }
  // Median over the repetitions, by total.
  std::sort(timings.begin(), timings.end(),
            [](const auto& a, const auto& b) { return a.total < b.total; });
  writeScene(out, file, *cloud, rec, objects, timings[timings.size() / 2]);

  std::string warning;
  if (!s.overlay.empty()) {
    const std::string path =
      s.many ? (std::filesystem::path(s.overlay) / (stemOf(file) + ".png")).string() : s.overlay;
    warning = drawOverlay(path, *cloud, drawingCamera(*cloud, s.camera), objects);
  }
  if (!s.clusters_dir.empty()) {
    const std::string w = saveClusters(s.clusters_dir, file, *cloud, has_colour, objects);
    warning = warning.empty() ? w : warning;
  }
  if (!warning.empty())
    out << ",\"warning\":" << facyl_cli::quote(warning);
  out << "}" << std::endl;
  return warning.empty();
}

/** Settings from the command line. \throws std::invalid_argument for bad usage. */
Settings
parseSettings(int argc, char** argv, std::vector<std::string>& files)
{
  Settings s;
  const facyl_cli::Arguments args(
    argc, argv,
    {"--min-inlier-ratio", "--score", "--max-curvature-ratio", "--prior", "--radius-limits",
     "--orientations", "--max-fit-points", "--neighbours", "--seed", "--plane-distance",
     "--height-limits", "--cluster-tolerance", "--cluster-size", "--camera", "--overlay",
     "--save-clusters", "--repeat", "--min-coverage"},
    {"--no-retry", "--retry-inside", "--any-normal-sign"});
  files = args.positional();
  if (files.empty())
    throw std::invalid_argument("give at least one scene (see -h)");
  auto& p = s.params;
  auto& d = p.decision;
  d.min_score = static_cast<float>(args.number("--min-inlier-ratio", d.min_score));
  const std::string score = args.text("--score", "surface");
  if (score != "surface" && score != "inlier")
    throw std::invalid_argument("--score must be surface or inlier");
  d.score = score == "surface" ? facyl::CylinderDecision::Score::SurfaceRatio
                               : facyl::CylinderDecision::Score::InlierRatio;
  d.max_curvature_ratio =
    static_cast<float>(args.number("--max-curvature-ratio", d.max_curvature_ratio));
  d.min_angular_coverage = static_cast<float>(args.number("--min-coverage", d.min_angular_coverage));
  p.retry_upright_lying = !args.has("--no-retry");
  p.retry_any_normal_sign = args.has("--retry-inside");
  p.hough.outward_normals = !args.has("--any-normal-sign");
  if (args.has("--prior") && !facyl::parseOrientationPrior(args.text("--prior", ""), p.prior))
    throw std::invalid_argument("unknown --prior '" + args.text("--prior", "") + "'");
  const auto radii = pairOption(args, "--radius-limits", p.hough.radius_min, p.hough.radius_max);
  p.hough.radius_min = static_cast<float>(radii.first);
  p.hough.radius_max = static_cast<float>(radii.second);
  p.orientations = static_cast<std::size_t>(args.integer("--orientations", 450, 10));
  p.max_fit_points = static_cast<std::size_t>(args.integer("--max-fit-points", 1200, 50));
  p.neighbours = static_cast<int>(args.integer("--neighbours", 16, 5));
  p.seed = static_cast<std::uint64_t>(args.integer("--seed", 0, 0));
  auto& g = p.segmentation;
  g.plane_distance = static_cast<float>(args.number("--plane-distance", g.plane_distance));
  const auto heights = pairOption(args, "--height-limits", g.min_height, g.max_height);
  g.min_height = static_cast<float>(heights.first);
  g.max_height = static_cast<float>(heights.second);
  g.cluster_tolerance = static_cast<float>(args.number("--cluster-tolerance", g.cluster_tolerance));
  const auto sizes = pairOption(args, "--cluster-size", static_cast<double>(g.min_cluster_size),
                                static_cast<double>(g.max_cluster_size));
  if (!(sizes.first >= 1 && sizes.second >= sizes.first))
    throw std::invalid_argument("--cluster-size: expected 1 <= A <= B");
  g.min_cluster_size = static_cast<std::size_t>(sizes.first);
  g.max_cluster_size = static_cast<std::size_t>(sizes.second);
  if (args.has("--camera")) {
    std::istringstream in(args.text("--camera", ""));
    char c1 = 0, c2 = 0, c3 = 0;
    facyl::PinholeCamera& cam = s.camera;
    if (!(in >> cam.fx >> c1 >> cam.fy >> c2 >> cam.cx >> c3 >> cam.cy) || c1 != ',' ||
        c2 != ',' || c3 != ',' || !(cam.fx > 0.f) || !(cam.fy > 0.f))
      throw std::invalid_argument("--camera: expected fx,fy,cx,cy with fx, fy > 0");
    cam.width = static_cast<int>(std::ceil(2.f * cam.cx + 1.f));
    cam.height = static_cast<int>(std::ceil(2.f * cam.cy + 1.f));
  }
  s.overlay = args.text("--overlay", "");
  s.clusters_dir = args.text("--save-clusters", "");
  s.repeat = static_cast<int>(args.integer("--repeat", 1, 1));
  s.many = files.size() > 1;
  const std::string why = facyl::validate(p);
  if (!why.empty())
    throw std::invalid_argument(why);
  if (!s.many && !s.overlay.empty()) {
    const auto parent = std::filesystem::path(s.overlay).parent_path();
    if (!parent.empty() && !std::filesystem::is_directory(parent))
      throw std::invalid_argument("folder '" + parent.string() + "' does not exist");
  }
  for (const std::string& dir : {s.clusters_dir, s.many ? s.overlay : std::string()})
    if (!dir.empty() && !std::filesystem::is_directory(dir))
      throw std::invalid_argument("folder '" + dir + "' does not exist");
  return s;
}

} // namespace

int
main(int argc, char** argv)
{
  if (facyl_cli::wantsHelp(argc, argv)) {
    printHelp(argv[0]);
    return 0;
  }
  Settings s;
  std::vector<std::string> files;
  try {
    s = parseSettings(argc, argv, files);
  }
  catch (const std::exception& e) {
    std::fprintf(stderr, "facyl_detect: %s\n", e.what());
    return 2;
  }
  bool all_ok = true;
  for (const auto& f : files)
    all_ok = processScene(f, s, std::cout) && all_ok;
  return all_ok ? 0 : 1;
}
