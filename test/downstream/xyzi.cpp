// A facyl user with a point type facyl does not instantiate: PCL_NO_PRECOMPILE and
// pcl::PointXYZI, linking facyl::sample_consensus_alt only. The templates are compiled here,
// and with them PCL's (features, search, kd-tree: FLANN, whose headers call LZ4): the exported
// targets must bring every library that code needs.
#define PCL_NO_PRECOMPILE
#include <facyl/features/normal_curvature_estimation.h>
#include <facyl/sample_consensus_alt/hough_cylinder_estimation.h>

#include <cmath>
#include <cstdio>

int
main()
{
  pcl::PointCloud<pcl::PointXYZI>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZI>);
  for (int i = 0; i < 2000; ++i) { // a can: radius 3 cm, axis along z
    pcl::PointXYZI p;
    p.x = 0.03f * std::cos(i * 0.1f);
    p.y = 0.03f * std::sin(i * 0.1f) + 0.5f;
    p.z = 0.8f + 0.12f * static_cast<float>(i % 97) / 97.f;
    p.intensity = static_cast<float>(i % 255);
    cloud->push_back(p);
  }
  pcl::PointCloud<facyl::NormalCurvature>::Ptr cues(new pcl::PointCloud<facyl::NormalCurvature>);
  facyl::NormalCurvatureEstimation<pcl::PointXYZI> ne;
  ne.setInputCloud(cloud);
  ne.setKSearch(16);
  ne.compute(*cues);

  facyl::HoughCylinderEstimation<pcl::PointXYZI, facyl::NormalCurvature> hough;
  hough.setInputCloud(cloud);
  hough.setInputNormals(cues);
  hough.setRadiusLimits(0.01f, 0.1f);
  pcl::PointIndices inliers;
  pcl::ModelCoefficients coefficients;
  if (!hough.segment(inliers, coefficients))
    return 1;
  std::printf("PointXYZI: radius %.4f m, %zu inliers\n", coefficients.values[6],
              inliers.indices.size());
  return std::abs(coefficients.values[6] - 0.03f) < 3e-4f ? 0 : 1;
}
