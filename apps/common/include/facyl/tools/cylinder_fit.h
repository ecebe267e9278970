/*
 * facyl: the fit that facyl_fit runs, shared with the Python module (facyl.fit_cylinders gives
 * facyl_fit's result for the same settings): normals and curvatures, then the Hough estimator
 * (or, for comparison, PCL's RANSAC).
 */
#pragma once

#include <facyl/tools/pcl_baseline.h>
#include <facyl/tools/settings_table.h>

#include <facyl/features/normal_curvature_estimation.h>
#include <facyl/sample_consensus_alt/hough_cylinder_estimation.h>

#include <pcl/common/common.h>
#include <pcl/common/io.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <cmath>
#include <string>
#include <utility>
#include <vector>

namespace facyl_cli {

/** The estimator's settings as the tools expose them: its parameters (prior, N_d, seed
 * included) and the "up" of the prior's frame. */
struct HoughSettings {
  facyl::HoughCylinderParameters params;
  Eigen::Vector3f up{Eigen::Vector3f::UnitZ()}; ///< the prior's "up"
  bool up_given{false}; ///< up is known (--up): the cylinders are oriented by it
};

/** The voting modes, in the help's order. */
inline std::vector<std::pair<std::string, facyl::VotingMode>>
votingChoices()
{
  using V = facyl::VotingMode;
  return namedChoices<V>({V::SoftCurvature, V::SoftNormal, V::Rabbani});
}

/** The orientation priors, in the help's order. */
inline std::vector<std::pair<std::string, facyl::OrientationPrior>>
priorChoices()
{
  using P = facyl::OrientationPrior;
  return namedChoices<P>({P::Uniform, P::Vertical, P::VerticalStrong, P::Horizontal});
}

/** Normals and curvatures of \a cloud from its \a k nearest neighbours (\a normals, when
 * given, instead of the estimated normals); \a threads 0: all cores. The result has the
 * cloud's size unless the estimation failed. */
inline pcl::PointCloud<facyl::NormalCurvature>::Ptr
estimateFitCues(const pcl::PointCloud<pcl::PointXYZ>::ConstPtr& cloud, int k, unsigned threads,
                const pcl::PointCloud<pcl::Normal>::ConstPtr& normals)
{
  pcl::PointCloud<facyl::NormalCurvature>::Ptr cues(new pcl::PointCloud<facyl::NormalCurvature>);
  facyl::NormalCurvatureEstimation<pcl::PointXYZ> ne;
  ne.setInputCloud(cloud);
  ne.setKSearch(k);
  ne.setNumberOfThreads(threads);
  if (normals)
    ne.setInputNormals(normals);
  ne.compute(*cues);
  return cues;
}

/** HoughCylinderEstimation of \a cloud with \a cues and \a s; an empty list when no cylinder
 * is found, and then, with \a why, the estimator's reason (getFailureMessage). */
inline std::vector<facyl::CylinderModel>
houghFit(const pcl::PointCloud<pcl::PointXYZ>::ConstPtr& cloud,
         const pcl::PointCloud<facyl::NormalCurvature>::ConstPtr& cues, const HoughSettings& s,
         std::string* why = nullptr)
{
  facyl::HoughCylinderEstimation<pcl::PointXYZ, facyl::NormalCurvature> hough;
  hough.setParameters(s.params);
  if (s.up_given)
    hough.setUpDirection(s.up); // the prior's frame and the cylinders' orientation
  else
    hough.setReferenceFrame(facyl::frameAboutUp(s.up)); // the prior's frame only
  hough.setInputCloud(cloud);
  hough.setInputNormals(cues);
  std::vector<facyl::CylinderModel> models;
  if (!hough.segment(models) && why) // no cylinder: an empty list and its reason, not an error
    *why = hough.getFailureMessage();
  return models;
}

/** PCL's RANSAC (pcl_baseline.h) on \a cloud with the normals of \a cues, as facyl_fit
 * --method pcl-ransac runs it: \a params' radius limits (the data's extent for an infinite
 * maximum), distance threshold (0: 1% of the bounding-box diagonal) and max_cylinders. */
inline std::vector<facyl::CylinderModel>
pclRansacFit(const pcl::PointCloud<pcl::PointXYZ>::ConstPtr& cloud,
             const pcl::PointCloud<facyl::NormalCurvature>& cues,
             const facyl::HoughCylinderParameters& params)
{
  pcl::PointCloud<pcl::Normal>::Ptr normals(new pcl::PointCloud<pcl::Normal>);
  pcl::copyPointCloud(cues, *normals);
  Eigen::Vector4f lo, hi;
  pcl::getMinMax3D(*cloud, lo, hi);
  const float diagonal = (hi - lo).head<3>().norm();
  PclCylinderOptions o;
  o.distance_threshold =
    params.distance_threshold > 0.f ? params.distance_threshold : 0.01f * diagonal;
  o.radius_min = params.radius_min;
  o.radius_max = std::isfinite(params.radius_max) ? params.radius_max : diagonal;
  o.max_cylinders = params.max_cylinders;
  return fitPclCylinders<pcl::PointXYZ>(cloud, normals, o);
}

} // namespace facyl_cli
