// The README's example: fit a cylinder to a cloud with facyl.
#include <cmath>
#include <cstdio>
#include <facyl/features/normal_curvature_estimation.h>
#include <facyl/sample_consensus_alt/hough_cylinder_estimation.h>

int
main()
{
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>);
  for (int i = 0; i < 2000; ++i) // a can: radius 3 cm, axis along z
    cloud->push_back(pcl::PointXYZ(0.03f * std::cos(i * 0.1f), 0.03f * std::sin(i * 0.1f) + 0.5f,
                                   0.8f + 0.12f * static_cast<float>(i % 97) / 97.f));

  pcl::PointCloud<facyl::NormalCurvature>::Ptr cues(new pcl::PointCloud<facyl::NormalCurvature>);
  facyl::NormalCurvatureEstimation<pcl::PointXYZ> ne; // normals + curvatures, one query each
  ne.setInputCloud(cloud);
  ne.setKSearch(16);
  ne.compute(*cues);

  facyl::HoughCylinderEstimation<pcl::PointXYZ, facyl::NormalCurvature> hough;
  hough.setInputCloud(cloud);
  hough.setInputNormals(cues);
  hough.setRadiusLimits(0.01f, 0.1f);
  pcl::PointIndices inliers;
  pcl::ModelCoefficients coefficients; // SACMODEL_CYLINDER layout
  if (!hough.segment(inliers, coefficients))
    return 1;
  std::printf("radius %.4f m, axis (%.3f %.3f %.3f), %zu inliers\n", coefficients.values[6],
              coefficients.values[3], coefficients.values[4], coefficients.values[5],
              inliers.indices.size());
  return std::abs(coefficients.values[6] - 0.03f) < 3e-4f ? 0 : 1;
}
