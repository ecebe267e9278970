/*
 * facyl: fast cylinder detection for PCL.
 * Explicit instantiations for the common point types (see PCL_NO_PRECOMPILE for others).
 */
#include <facyl/sample_consensus_alt/impl/hough_cylinder_estimation.hpp>

#define FACYL_HOUGH_FOR_NORMALS(T)                                                                 \
  FACYL_INSTANTIATE_HoughCylinderEstimation(T, pcl::Normal)                                        \
  FACYL_INSTANTIATE_HoughCylinderEstimation(T, pcl::PointNormal)                                   \
  FACYL_INSTANTIATE_HoughCylinderEstimation(T, facyl::NormalCurvature)

FACYL_HOUGH_FOR_NORMALS(pcl::PointXYZ)
FACYL_HOUGH_FOR_NORMALS(pcl::PointXYZRGB)
FACYL_HOUGH_FOR_NORMALS(pcl::PointXYZRGBA)
FACYL_HOUGH_FOR_NORMALS(pcl::PointNormal)
