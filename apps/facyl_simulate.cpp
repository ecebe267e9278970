/*
 * facyl_simulate: write a simulated cylinder (paper III-D1) as a PCD file, with its ground
 * truth as JSON on stdout.
 */
#include <facyl/tools/cli.h>
#include <facyl/tools/json_writer.h>

#include <facyl/simulation/cylinder_simulation.h>

#include <pcl/io/pcd_io.h>

#include <iostream>

namespace {
/** "x,y,z" as the options take it. */
std::string
commaVector(const Eigen::Vector3f& v)
{
  return facyl_cli::compactNumber(v.x()) + "," + facyl_cli::compactNumber(v.y()) + "," +
         facyl_cli::compactNumber(v.z());
}

void
printHelp(const char* self)
{
  const facyl::CylinderSimulationParameters d; // the defaults' one home
  std::printf(
    "Usage: %s [options] OUT.pcd\n"
    "  --radius R        radius (default %s)\n"
    "  --height H        height (default %s)\n"
    "  --axis x,y,z      axis (default %s)\n"
    "  --base x,y,z      centre of the bottom cap (default %s)\n"
    "  --random-axis     draw the axis uniformly\n"
    "  --points N        lateral points |P| (default %zu)\n"
    "  --lids L          lid outliers of eq. 5, e.g. 1 = 100%% (default %s)\n"
    "  --noise S         noise std. dev. relative to the radius (default %s)\n"
    "  --occlusion O     occlusion of eq. 6 in [0, 1) (default %s)\n"
    "  --seed S          seed (default %llu)\n"
    "  --with-normals    also write the exact normals\n"
    "OUT.pcd must end in .pcd (anything else is refused, nothing written).\n%s",
    self, facyl_cli::compactNumber(d.radius).c_str(), facyl_cli::compactNumber(d.height).c_str(),
    commaVector(d.axis).c_str(), commaVector(d.base).c_str(), d.lateral_points,
    facyl_cli::compactNumber(d.lid_ratio).c_str(), facyl_cli::compactNumber(d.noise).c_str(),
    facyl_cli::compactNumber(d.occlusion).c_str(), static_cast<unsigned long long>(d.seed),
    facyl_cli::commonHelp());
}
} // namespace

int
main(int argc, char** argv)
{
  facyl::CylinderSimulationParameters p;
  std::string out;
  bool normals = false;
  const int status = facyl_cli::startTool(argc, argv, "facyl_simulate", printHelp, [&] {
    const facyl_cli::Arguments args(argc, argv,
                                    {"--radius", "--height", "--axis", "--base", "--points",
                                     "--lids", "--noise", "--occlusion", "--seed"},
                                    {"--random-axis", "--with-normals"});
    if (args.positional().size() != 1)
      throw std::invalid_argument("give exactly one output file (see -h)");
    out = args.positional()[0];
    facyl_cli::checkOutputFile("", out, {".pcd"}, "PCD point cloud", {});
    p.radius = static_cast<float>(args.number("--radius", p.radius, 1e-4, 100.0));
    p.height = static_cast<float>(args.number("--height", p.height, 1e-4, 1000.0));
    p.axis = args.vector3("--axis", p.axis);
    p.base = args.vector3("--base", p.base);
    p.random_axis = args.has("--random-axis");
    p.lateral_points = static_cast<std::size_t>(
      args.integer("--points", static_cast<long long>(p.lateral_points), 1, 10000000));
    p.lid_ratio = static_cast<float>(args.number("--lids", p.lid_ratio, 0.0, 10.0));
    p.noise = static_cast<float>(args.number("--noise", p.noise, 0.0, 10.0));
    p.occlusion = static_cast<float>(args.number("--occlusion", p.occlusion, 0.0, 1.0));
    p.seed = static_cast<std::uint64_t>(
      args.integer("--seed", static_cast<long long>(p.seed), 0, facyl_cli::kMaxSeed));
    normals = args.has("--with-normals");
    const std::string why = facyl::validate(p);
    if (!why.empty())
      throw std::invalid_argument(why);
  });
  if (status >= 0)
    return status;
  const auto sim = facyl::simulateCylinder(p);
  int rc;
  if (normals)
    rc = pcl::io::savePCDFileBinaryCompressed(out, sim.cloud);
  else {
    pcl::PointCloud<pcl::PointXYZ> xyz;
    for (const auto& q : sim.cloud)
      xyz.push_back(pcl::PointXYZ(q.x, q.y, q.z));
    rc = pcl::io::savePCDFileBinaryCompressed(out, xyz);
  }
  if (rc < 0) {
    std::fprintf(stderr, "facyl_simulate: cannot write %s\n", out.c_str());
    return 1;
  }
  const auto& t = sim.truth;
  facyl_cli::Json line;
  line["file"] = out;
  line["radius"] = facyl_cli::jsonNumber(t.radius);
  line["height"] = facyl_cli::jsonNumber(t.height);
  line["axis"] = facyl_cli::jsonVector(t.axis);
  line["base"] = facyl_cli::jsonVector(t.base);
  line["lateral_points"] = t.lateral_points;
  line["lid_points"] = t.lid_points;
  std::cout << facyl_cli::dumpJson(line) << std::endl;
  return 0;
}
