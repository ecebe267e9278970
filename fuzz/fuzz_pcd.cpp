/*
 * libFuzzer target: PCD bytes -> what facyl_fit and facyl_detect do with a file: the checked
 * reader (apps/common/include/facyl/tools/pcd_input.h), the conversion, then (for clouds small
 * enough to keep the fuzzer fast) normals and curvatures, the Hough fit and the tabletop
 * recognizer.
 */
#include <facyl/tools/pcd_input.h>

#include <facyl/features/normal_curvature_estimation.h>
#include <facyl/recognition/tabletop_cylinder_recognizer.h>
#include <facyl/sample_consensus_alt/hough_cylinder_estimation.h>

#include <pcl/common/point_tests.h>
#include <pcl/console/print.h>
#include <pcl/conversions.h>

#include <cstdint>
#include <cstdio>
#include <fstream>
#include <string>
#include <unistd.h>

namespace {

const std::string&
scratchFile()
{
  static const std::string path = "/tmp/facyl_fuzz_pcd_" + std::to_string(getpid()) + ".pcd";
  return path;
}

template <typename PointT>
void
detect(const pcl::PCLPointCloud2& blob, const facyl_cli::Viewpoint& viewpoint)
{
  typename pcl::PointCloud<PointT>::Ptr cloud(new pcl::PointCloud<PointT>);
  pcl::fromPCLPointCloud2(blob, *cloud);
  cloud->sensor_origin_ = viewpoint.origin;
  cloud->sensor_orientation_ = viewpoint.orientation;
  facyl::TabletopCylinderRecognizer<PointT> rec;
  rec.setInputCloud(cloud);
  std::vector<facyl::RecognizedObject> objects;
  rec.recognize(objects);
  for (const auto& o : objects)
    for (const auto i : o.cluster.indices.indices)
      if (i < 0 || static_cast<std::size_t>(i) >= cloud->size())
        __builtin_trap();
}

void
fit(const pcl::PCLPointCloud2& blob, const facyl_cli::Viewpoint& viewpoint)
{
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>);
  pcl::fromPCLPointCloud2(blob, *cloud);
  cloud->sensor_origin_ = viewpoint.origin;
  cloud->sensor_orientation_ = viewpoint.orientation;
  pcl::PointCloud<facyl::NormalCurvature>::Ptr cues(new pcl::PointCloud<facyl::NormalCurvature>);
  facyl::NormalCurvatureEstimation<pcl::PointXYZ> ne;
  ne.setInputCloud(cloud);
  ne.setKSearch(16);
  ne.setNumberOfThreads(1);
  ne.compute(*cues);
  if (cues->size() != cloud->size())
    return;
  facyl::HoughCylinderEstimation<pcl::PointXYZ, facyl::NormalCurvature> hough;
  hough.setInputCloud(cloud);
  hough.setInputNormals(cues);
  hough.setNumberOfOrientations(100);
  std::vector<facyl::CylinderModel> models;
  hough.segment(models);
}

} // namespace

extern "C" int
LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
  static const bool quiet = [] {
    pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS);
    return true;
  }();
  (void)quiet;
  {
    std::ofstream out(scratchFile(), std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  pcl::PCLPointCloud2 blob;
  facyl_cli::Viewpoint viewpoint;
  if (!facyl_cli::readPcd(scratchFile(), blob, &viewpoint).empty())
    return 0;
  if (static_cast<std::size_t>(blob.width) * blob.height > 5000)
    return 0; // read and checked; the pipeline on large clouds only slows the search
  fit(blob, viewpoint);
  if (facyl_cli::hasField(blob, "rgba") || facyl_cli::hasField(blob, "rgb"))
    detect<pcl::PointXYZRGBA>(blob, viewpoint);
  else
    detect<pcl::PointXYZ>(blob, viewpoint);
  return 0;
}
