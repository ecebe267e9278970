/*
 * facyl: PCL's own cylinder segmentation (SACSegmentationFromNormals + SACMODEL_CYLINDER), run
 * the way the tools compare it with facyl: same cloud, same normals, same radius limits.
 */
#pragma once

#include <facyl/sample_consensus_alt/cylinder_fitting.h>
#include <facyl/sample_consensus_alt/cylinder_model.h>

#include <pcl/common/point_tests.h>
#include <pcl/sample_consensus/method_types.h>
#include <pcl/sample_consensus/model_types.h>
#include <pcl/segmentation/sac_segmentation.h>

#include <algorithm>
#include <iterator>
#include <vector>

namespace facyl_cli {

struct PclCylinderOptions {
  int method{pcl::SAC_RANSAC}; ///< pcl::SAC_RANSAC, pcl::SAC_MLESAC, ...
  float distance_threshold{0.01f};
  float radius_min{0.f};
  float radius_max{1.f};
  double normal_distance_weight{0.1}; ///< as in PCL's cylinder segmentation tutorial
  int max_iterations{10000};          ///< as in the tutorial
  bool use_axis{false};               ///< PCL's way of stating an orientation prior
  Eigen::Vector3f axis{Eigen::Vector3f::UnitZ()};
  double eps_angle{0.26}; ///< rad, with use_axis
  std::size_t max_cylinders{1};
};

/** Up to max_cylinders cylinders, one after another (PCL fits one; the inliers are removed
 * and it runs again). Models are described like facyl's (extent, coverage). */
template <typename PointT>
std::vector<facyl::CylinderModel>
fitPclCylinders(const typename pcl::PointCloud<PointT>::ConstPtr& cloud,
                const pcl::PointCloud<pcl::Normal>::ConstPtr& normals, const PclCylinderOptions& o)
{
  pcl::SACSegmentationFromNormals<PointT, pcl::Normal> seg;
  seg.setOptimizeCoefficients(true);
  seg.setModelType(pcl::SACMODEL_CYLINDER);
  seg.setMethodType(o.method);
  seg.setNormalDistanceWeight(o.normal_distance_weight);
  seg.setMaxIterations(o.max_iterations);
  seg.setDistanceThreshold(o.distance_threshold);
  seg.setRadiusLimits(o.radius_min, o.radius_max);
  if (o.use_axis) {
    seg.setAxis(o.axis);
    seg.setEpsAngle(o.eps_angle);
  }
  seg.setInputCloud(cloud);
  seg.setInputNormals(normals);
  pcl::IndicesPtr remaining(new pcl::Indices);
  for (std::size_t i = 0; i < cloud->size(); ++i)
    if (pcl::isFinite((*cloud)[i]) && std::isfinite((*normals)[i].normal_x))
      remaining->push_back(static_cast<int>(i));
  std::vector<facyl::CylinderModel> models;
  for (std::size_t round = 0; round < o.max_cylinders && remaining->size() > 10; ++round) {
    seg.setIndices(remaining);
    pcl::PointIndices inliers;
    pcl::ModelCoefficients c;
    seg.segment(inliers, c);
    if (inliers.indices.size() < 10 || c.values.size() != 7)
      break;
    facyl::CylinderModel m;
    m.point_on_axis = Eigen::Vector3f(c.values[0], c.values[1], c.values[2]);
    m.axis = Eigen::Vector3f(c.values[3], c.values[4], c.values[5]).normalized();
    m.radius = c.values[6];
    m.inliers = inliers.indices;
    m.inlier_ratio = static_cast<float>(inliers.indices.size()) / static_cast<float>(cloud->size());
    m.distance_threshold = o.distance_threshold;
    Eigen::Matrix3Xf pts(3, static_cast<Eigen::Index>(inliers.indices.size()));
    for (std::size_t k = 0; k < inliers.indices.size(); ++k)
      pts.col(static_cast<Eigen::Index>(k)) = (*cloud)[inliers.indices[k]].getVector3fMap();
    facyl::describeInliers(pts, m);
    models.push_back(m);
    pcl::Indices rest;
    std::set_difference(remaining->begin(), remaining->end(), inliers.indices.begin(),
                        inliers.indices.end(), std::back_inserter(rest));
    remaining->swap(rest);
  }
  return models;
}

} // namespace facyl_cli
