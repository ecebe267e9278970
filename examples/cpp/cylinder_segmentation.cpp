/*
 * facyl: fast cylinder detection for PCL.
 *
 * PCL's cylinder segmentation tutorial
 * (pcl/doc/tutorials/content/sources/cylinder_segmentation/cylinder_segmentation.cpp), step by
 * step, with facyl::HoughCylinderEstimation in place of the cylinder RANSAC. Everything else
 * is the tutorial's: pass-through z in [0, 1.5], pcl::NormalEstimation with k = 50, the table
 * plane removed by SACSegmentationFromNormals, radius limits (0, 0.1).
 *
 *   cylinder_segmentation [table_scene_mug_stereo_textured.pcd] [--ransac]
 *                         [--voting soft-curvature|soft-normal|rabbani]
 *
 * --ransac runs the tutorial's own RANSAC as well (SACSegmentation's fixed seed), to compare;
 * --voting chooses facyl's voting mode (default soft-curvature). Prints the
 * coefficients and, on failure, the reason the estimator gives.
 */
#include <facyl/sample_consensus_alt/hough_cylinder_estimation.h>

#include <pcl/ModelCoefficients.h>
#include <pcl/features/normal_3d.h>
#include <pcl/filters/extract_indices.h>
#include <pcl/filters/passthrough.h>
#include <pcl/io/pcd_io.h>
#include <pcl/point_types.h>
#include <pcl/sample_consensus/method_types.h>
#include <pcl/sample_consensus/model_types.h>
#include <pcl/search/kdtree.h>
#include <pcl/segmentation/sac_segmentation.h>

#include <cstdio>
#include <cstring>
#include <string>

using PointT = pcl::PointXYZ;

int
main(int argc, char** argv)
{
  std::string file = "table_scene_mug_stereo_textured.pcd";
  bool ransac = false;
  facyl::VotingMode voting = facyl::VotingMode::SoftCurvature;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--ransac") == 0)
      ransac = true;
    else if (std::strcmp(argv[i], "--voting") == 0 && i + 1 < argc) {
      const std::string mode = argv[++i];
      if (mode == "soft-curvature")
        voting = facyl::VotingMode::SoftCurvature;
      else if (mode == "soft-normal")
        voting = facyl::VotingMode::SoftNormal;
      else if (mode == "rabbani")
        voting = facyl::VotingMode::Rabbani;
      else {
        std::fprintf(stderr, "unknown voting mode %s (soft-curvature, soft-normal, rabbani)\n",
                     mode.c_str());
        return 2;
      }
    }
    else if (argv[i][0] == '-') {
      std::fprintf(stderr, "unknown option %s\n", argv[i]);
      return 2;
    }
    else
      file = argv[i];
  }

  pcl::PCDReader reader;
  pcl::PassThrough<PointT> pass;
  pcl::NormalEstimation<PointT, pcl::Normal> ne;
  pcl::SACSegmentationFromNormals<PointT, pcl::Normal> seg;
  pcl::ExtractIndices<PointT> extract;
  pcl::ExtractIndices<pcl::Normal> extract_normals;
  pcl::search::KdTree<PointT>::Ptr tree(new pcl::search::KdTree<PointT>());

  pcl::PointCloud<PointT>::Ptr cloud(new pcl::PointCloud<PointT>);
  pcl::PointCloud<PointT>::Ptr cloud_filtered(new pcl::PointCloud<PointT>);
  pcl::PointCloud<pcl::Normal>::Ptr cloud_normals(new pcl::PointCloud<pcl::Normal>);
  pcl::PointCloud<PointT>::Ptr cloud_filtered2(new pcl::PointCloud<PointT>);
  pcl::PointCloud<pcl::Normal>::Ptr cloud_normals2(new pcl::PointCloud<pcl::Normal>);
  pcl::ModelCoefficients::Ptr coefficients_plane(new pcl::ModelCoefficients);
  pcl::ModelCoefficients::Ptr coefficients_cylinder(new pcl::ModelCoefficients);
  pcl::PointIndices::Ptr inliers_plane(new pcl::PointIndices);
  pcl::PointIndices::Ptr inliers_cylinder(new pcl::PointIndices);

  if (reader.read(file, *cloud) != 0) {
    std::fprintf(stderr, "cannot read %s\n", file.c_str());
    return 1;
  }
  std::printf("PointCloud has: %zu data points.\n", cloud->size());

  // Build a passthrough filter to remove spurious NaNs and scene background.
  pass.setInputCloud(cloud);
  pass.setFilterFieldName("z");
  pass.setFilterLimits(0, 1.5);
  pass.filter(*cloud_filtered);
  std::printf("PointCloud after filtering has: %zu data points.\n", cloud_filtered->size());

  // Estimate point normals.
  ne.setSearchMethod(tree);
  ne.setInputCloud(cloud_filtered);
  ne.setKSearch(50);
  ne.compute(*cloud_normals);

  // The planar model: fit, then remove the plane inliers and their normals.
  seg.setOptimizeCoefficients(true);
  seg.setModelType(pcl::SACMODEL_NORMAL_PLANE);
  seg.setNormalDistanceWeight(0.1);
  seg.setMethodType(pcl::SAC_RANSAC);
  seg.setMaxIterations(100);
  seg.setDistanceThreshold(0.03);
  seg.setInputCloud(cloud_filtered);
  seg.setInputNormals(cloud_normals);
  seg.segment(*inliers_plane, *coefficients_plane);
  extract.setInputCloud(cloud_filtered);
  extract.setIndices(inliers_plane);
  extract.setNegative(true);
  extract.filter(*cloud_filtered2);
  extract_normals.setNegative(true);
  extract_normals.setInputCloud(cloud_normals);
  extract_normals.setIndices(inliers_plane);
  extract_normals.filter(*cloud_normals2);
  std::printf("Plane inliers: %zu; %zu points remain.\n", inliers_plane->indices.size(),
              cloud_filtered2->size());

  // The cylinder: facyl's Hough estimator where the tutorial has SACMODEL_CYLINDER + RANSAC.
  // The normals are the tutorial's pcl::Normal (k = 50): the estimator estimates the principal
  // curvatures it votes with from the points itself.
  facyl::HoughCylinderEstimation<PointT, pcl::Normal> hough;
  hough.setInputCloud(cloud_filtered2);
  hough.setInputNormals(cloud_normals2);
  hough.setRadiusLimits(0, 0.1);
  hough.setVotingMode(voting);
  if (hough.segment(*inliers_cylinder, *coefficients_cylinder)) {
    std::printf("facyl cylinder (%zu inliers): ", inliers_cylinder->indices.size());
    for (const float v : coefficients_cylinder->values)
      std::printf("%g ", v);
    std::printf("\n");
  }
  else {
    std::printf("facyl found no cylinder: %s\n", hough.getFailureMessage().c_str());
  }

  if (ransac) {
    pcl::SACSegmentationFromNormals<PointT, pcl::Normal> cyl;
    cyl.setOptimizeCoefficients(true);
    cyl.setModelType(pcl::SACMODEL_CYLINDER);
    cyl.setMethodType(pcl::SAC_RANSAC);
    cyl.setNormalDistanceWeight(0.1);
    cyl.setMaxIterations(10000);
    cyl.setDistanceThreshold(0.05);
    cyl.setRadiusLimits(0, 0.1);
    cyl.setInputCloud(cloud_filtered2);
    cyl.setInputNormals(cloud_normals2);
    pcl::PointIndices ransac_inliers;
    pcl::ModelCoefficients ransac_coefficients;
    cyl.segment(ransac_inliers, ransac_coefficients);
    std::printf("PCL RANSAC cylinder (%zu inliers): ", ransac_inliers.indices.size());
    for (const float v : ransac_coefficients.values)
      std::printf("%g ", v);
    std::printf("\n");
  }
  return inliers_cylinder->indices.empty() ? 1 : 0;
}
