/*
 * facyl: PCL's cylinder segmentation tutorial with facyl in place of the cylinder RANSAC
 * (examples/cpp/cylinder_segmentation.cpp), on the tutorial's own scene
 * (FACYL_REAL_DATA_DIR/pcl/table_scene_mug_stereo_textured.pcd; skipped when absent).
 */
#include "test_helpers.h"

#include <facyl/sample_consensus_alt/hough_cylinder_estimation.h>

#include <pcl/features/normal_3d.h>
#include <pcl/filters/extract_indices.h>
#include <pcl/filters/passthrough.h>
#include <pcl/io/pcd_io.h>
#include <pcl/sample_consensus/method_types.h>
#include <pcl/sample_consensus/model_types.h>
#include <pcl/search/kdtree.h>
#include <pcl/segmentation/sac_segmentation.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>

namespace {

using PointT = pcl::PointXYZ;
using Hough = facyl::HoughCylinderEstimation<PointT, pcl::Normal>;

/** The tutorial's scene after its pass-through, k = 50 normals and plane removal. */
struct TutorialScene {
  pcl::PointCloud<PointT>::Ptr cloud{new pcl::PointCloud<PointT>};
  pcl::PointCloud<pcl::Normal>::Ptr normals{new pcl::PointCloud<pcl::Normal>};
};

bool
loadTutorialScene(TutorialScene& scene)
{
  const std::string file = facyl_test::realFile("pcl/table_scene_mug_stereo_textured.pcd");
  if (file.empty())
    return false;
  pcl::PointCloud<PointT>::Ptr cloud(new pcl::PointCloud<PointT>);
  pcl::PointCloud<PointT>::Ptr filtered(new pcl::PointCloud<PointT>);
  pcl::PointCloud<pcl::Normal>::Ptr normals(new pcl::PointCloud<pcl::Normal>);
  EXPECT_EQ(pcl::io::loadPCDFile(file, *cloud), 0);
  pcl::PassThrough<PointT> pass;
  pass.setInputCloud(cloud);
  pass.setFilterFieldName("z");
  pass.setFilterLimits(0, 1.5);
  pass.filter(*filtered);
  pcl::NormalEstimation<PointT, pcl::Normal> ne;
  ne.setSearchMethod(pcl::search::KdTree<PointT>::Ptr(new pcl::search::KdTree<PointT>));
  ne.setInputCloud(filtered);
  ne.setKSearch(50);
  ne.compute(*normals);
  pcl::SACSegmentationFromNormals<PointT, pcl::Normal> seg;
  seg.setOptimizeCoefficients(true);
  seg.setModelType(pcl::SACMODEL_NORMAL_PLANE);
  seg.setNormalDistanceWeight(0.1);
  seg.setMethodType(pcl::SAC_RANSAC);
  seg.setMaxIterations(100);
  seg.setDistanceThreshold(0.03);
  seg.setInputCloud(filtered);
  seg.setInputNormals(normals);
  pcl::PointIndices::Ptr plane(new pcl::PointIndices);
  pcl::ModelCoefficients plane_coefficients;
  seg.segment(*plane, plane_coefficients);
  pcl::ExtractIndices<PointT> extract;
  extract.setInputCloud(filtered);
  extract.setIndices(plane);
  extract.setNegative(true);
  extract.filter(*scene.cloud);
  pcl::ExtractIndices<pcl::Normal> extract_normals;
  extract_normals.setNegative(true);
  extract_normals.setInputCloud(normals);
  extract_normals.setIndices(plane);
  extract_normals.filter(*scene.normals);
  return true;
}

/** The tutorial's cylinder RANSAC (SACSegmentation's fixed seed: the same answer every run). */
pcl::ModelCoefficients
pclRansacCylinder(const TutorialScene& scene)
{
  pcl::SACSegmentationFromNormals<PointT, pcl::Normal> seg;
  seg.setOptimizeCoefficients(true);
  seg.setModelType(pcl::SACMODEL_CYLINDER);
  seg.setMethodType(pcl::SAC_RANSAC);
  seg.setNormalDistanceWeight(0.1);
  seg.setMaxIterations(10000);
  seg.setDistanceThreshold(0.05);
  seg.setRadiusLimits(0, 0.1);
  seg.setInputCloud(scene.cloud);
  seg.setInputNormals(scene.normals);
  pcl::PointIndices inliers;
  pcl::ModelCoefficients coefficients;
  seg.segment(inliers, coefficients);
  return coefficients;
}

float
axisDegrees(const pcl::ModelCoefficients& a, const pcl::ModelCoefficients& b)
{
  const Eigen::Vector3f u(a.values[3], a.values[4], a.values[5]);
  const Eigen::Vector3f v(b.values[3], b.values[4], b.values[5]);
  const float c = std::abs(u.normalized().dot(v.normalized()));
  return facyl_test::degrees(std::acos(std::min(1.f, c)));
}

} // namespace

TEST(Tutorial, FacylReplacesTheCylinderRansac)
{
  TutorialScene scene;
  if (!loadTutorialScene(scene))
    GTEST_SKIP() << "pcl/table_scene_mug_stereo_textured.pcd is absent from the real data";
  const pcl::ModelCoefficients pcl_cylinder = pclRansacCylinder(scene);
  ASSERT_EQ(pcl_cylinder.values.size(), 7u);
  // The tutorial's answer (the mug, r = 3.88 cm): the pipeline above is the tutorial's.
  EXPECT_NEAR(pcl_cylinder.values[6], 0.0388f, 0.002f);

  // The drop-in: pcl::Normal at k = 50, the default voting mode, the tutorial's limits.
  Hough hough;
  hough.setInputCloud(scene.cloud);
  hough.setInputNormals(scene.normals);
  hough.setRadiusLimits(0, 0.1);
  pcl::PointIndices inliers;
  pcl::ModelCoefficients coefficients;
  ASSERT_TRUE(hough.segment(inliers, coefficients)) << hough.getFailureMessage();
  EXPECT_TRUE(hough.curvaturesWereEstimated());
  EXPECT_EQ(hough.getFailureReason(), facyl::HoughFailure::None);
  EXPECT_TRUE(hough.getFailureMessage().empty());
  ASSERT_EQ(coefficients.values.size(), 7u);
  std::printf("facyl r = %.5f, PCL RANSAC r = %.5f, axes %.2f deg apart, %zu inliers\n",
              coefficients.values[6], pcl_cylinder.values[6],
              axisDegrees(coefficients, pcl_cylinder), inliers.indices.size());
  EXPECT_NEAR(coefficients.values[6], pcl_cylinder.values[6], 0.001f);
  EXPECT_LT(axisDegrees(coefficients, pcl_cylinder), 2.f);
  EXPECT_GT(inliers.indices.size(), scene.cloud->size() / 4);
  // Not one lucky draw of the orientation cells.
  for (const std::uint64_t seed : {1u, 2u, 3u, 4u}) {
    hough.setSeed(seed);
    ASSERT_TRUE(hough.segment(inliers, coefficients)) << seed << ": " << hough.getFailureMessage();
    EXPECT_NEAR(coefficients.values[6], pcl_cylinder.values[6], 0.001f) << seed;
    EXPECT_LT(axisDegrees(coefficients, pcl_cylinder), 2.f) << seed;
  }
}

TEST(Tutorial, WithoutCurvatureEstimationTheReasonIsReadable)
{
  TutorialScene scene;
  if (!loadTutorialScene(scene))
    GTEST_SKIP() << "pcl/table_scene_mug_stereo_textured.pcd is absent from the real data";
  Hough hough;
  hough.setInputCloud(scene.cloud);
  hough.setInputNormals(scene.normals);
  hough.setRadiusLimits(0, 0.1);
  hough.setEstimateCurvatures(false);
  pcl::PointIndices inliers;
  pcl::ModelCoefficients coefficients;
  EXPECT_FALSE(hough.segment(inliers, coefficients));
  EXPECT_EQ(hough.getFailureReason(), facyl::HoughFailure::NoCurvatures);
  EXPECT_NE(hough.getFailureMessage().find("curvatures"), std::string::npos);
  EXPECT_TRUE(coefficients.values.empty());
}
