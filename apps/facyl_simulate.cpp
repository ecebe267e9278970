/*
 * facyl_simulate: write a simulated cylinder (paper III-D1) as a PCD file, with its ground
 * truth as JSON on stdout.
 */
#include "cli.h"

#include <facyl/simulation/cylinder_simulation.h>

#include <pcl/io/pcd_io.h>

#include <iostream>

namespace {
void
printHelp(const char* self)
{
  std::printf("Usage: %s [options] OUT.pcd\n"
              "  --radius R        radius (default 0.05)\n"
              "  --height H        height (default 0.2)\n"
              "  --axis x,y,z      axis (default 0,0,1)\n"
              "  --base x,y,z      centre of the bottom cap (default 0,0,0.8)\n"
              "  --random-axis     draw the axis uniformly\n"
              "  --points N        lateral points |P| (default 900)\n"
              "  --lids L          lid outliers of eq. 5, e.g. 1 = 100%% (default 0)\n"
              "  --noise S         noise std. dev. relative to the radius (default 0)\n"
              "  --occlusion O     occlusion of eq. 6 in [0, 1) (default 0)\n"
              "  --seed S          seed (default 0)\n"
              "  --with-normals    also write the exact normals\n"
              "OUT.pcd must end in .pcd (anything else is refused, nothing written).\n%s",
              self, facyl_cli::commonHelp());
}
} // namespace

int
main(int argc, char** argv)
{
  if (const int rc = facyl_cli::standardOptions(argc, argv, "facyl_simulate", printHelp); rc >= 0)
    return rc;
  facyl::CylinderSimulationParameters p;
  std::string out;
  bool normals = false;
  try {
    const facyl_cli::Arguments args(argc, argv,
                                    {"--radius", "--height", "--axis", "--base", "--points",
                                     "--lids", "--noise", "--occlusion", "--seed"},
                                    {"--random-axis", "--with-normals"});
    if (args.positional().size() != 1)
      throw std::invalid_argument("give exactly one output file (see -h)");
    out = args.positional()[0];
    facyl_cli::checkOutputFile("", out, {".pcd"}, "PCD point cloud", {});
    p.radius = static_cast<float>(args.number("--radius", 0.05, 1e-4, 100.0));
    p.height = static_cast<float>(args.number("--height", 0.2, 1e-4, 1000.0));
    p.axis = args.vector3("--axis", Eigen::Vector3f::UnitZ());
    p.base = args.vector3("--base", Eigen::Vector3f(0.f, 0.f, 0.8f));
    p.random_axis = args.has("--random-axis");
    p.lateral_points = static_cast<std::size_t>(args.integer("--points", 900, 1, 10000000));
    p.lid_ratio = static_cast<float>(args.number("--lids", 0.0, 0.0, 10.0));
    p.noise = static_cast<float>(args.number("--noise", 0.0, 0.0, 10.0));
    p.occlusion = static_cast<float>(args.number("--occlusion", 0.0, 0.0, 1.0));
    p.seed = static_cast<std::uint64_t>(args.integer("--seed", 0, 0, facyl_cli::kMaxSeed));
    normals = args.has("--with-normals");
    const std::string why = facyl::validate(p);
    if (!why.empty())
      throw std::invalid_argument(why);
  }
  catch (const std::exception& e) {
    std::fprintf(stderr, "facyl_simulate: %s\n", e.what());
    return 2;
  }
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
  std::cout << "{\"file\":" << facyl_cli::quote(out) << ",\"radius\":" << facyl_cli::number(t.radius)
            << ",\"height\":" << facyl_cli::number(t.height) << ",\"axis\":"
            << facyl_cli::vector(t.axis) << ",\"base\":" << facyl_cli::vector(t.base)
            << ",\"lateral_points\":" << t.lateral_points << ",\"lid_points\":" << t.lid_points
            << "}" << std::endl;
  return 0;
}
