/*
 * facyl: fast cylinder detection for PCL.
 * Explicit instantiations for the common point types.
 */
#include <facyl/segmentation/impl/tabletop_segmentation.hpp>

FACYL_INSTANTIATE_TabletopSegmentation(pcl::PointXYZ)
FACYL_INSTANTIATE_TabletopSegmentation(pcl::PointXYZRGB)
FACYL_INSTANTIATE_TabletopSegmentation(pcl::PointXYZRGBA)
