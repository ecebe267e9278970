/*
 * facyl: fast cylinder detection for PCL.
 * Explicit instantiations for the common point types (see PCL_NO_PRECOMPILE for others).
 */
#include <facyl/features/impl/normal_curvature_estimation.hpp>

#include <pcl/impl/instantiate.hpp>

FACYL_INSTANTIATE_NormalCurvatureEstimation(pcl::PointXYZ, facyl::NormalCurvature)
FACYL_INSTANTIATE_NormalCurvatureEstimation(pcl::PointXYZRGB, facyl::NormalCurvature)
FACYL_INSTANTIATE_NormalCurvatureEstimation(pcl::PointXYZRGBA, facyl::NormalCurvature)
FACYL_INSTANTIATE_NormalCurvatureEstimation(pcl::PointNormal, facyl::NormalCurvature)
