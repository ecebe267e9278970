/*
 * facyl: fast cylinder detection for PCL.
 * Explicit instantiations for the common point types.
 */
#include <facyl/segmentation/impl/tabletop_segmentation.hpp>

#include <sstream>

namespace facyl {

std::string
validate(const TabletopSegmentationParameters& p)
{
  std::ostringstream why;
  if (!(p.plane_distance >= 0.f) || !std::isfinite(p.plane_distance))
    why << "plane distance " << p.plane_distance << " must be >= 0 (0: measured)";
  else if (!(p.band_factor >= 1.f && p.band_factor <= 10.f))
    why << "band factor " << p.band_factor << " must be in [1, 10]";
  else if (!(p.plane_angle > 0.f && p.plane_angle < 1.58f))
    why << "plane angle " << p.plane_angle << " must be in (0, pi/2]";
  else if (p.min_plane_points < 3)
    why << "min_plane_points must be >= 3";
  else if (!(p.min_height < p.max_height) || !std::isfinite(p.min_height) ||
           !std::isfinite(p.max_height))
    why << "height limits [" << p.min_height << ", " << p.max_height
        << "] must be finite, min < max";
  else if (!(p.cluster_tolerance > 0.f))
    why << "cluster tolerance " << p.cluster_tolerance << " must be > 0";
  else if (p.min_cluster_size < 1 || p.min_cluster_size > p.max_cluster_size)
    why << "cluster sizes must satisfy 1 <= min <= max";
  else if (!(p.min_hull_share > 0.f && p.min_hull_share <= 1.f))
    why << "min_hull_share " << p.min_hull_share << " must be in (0, 1]";
  else if (p.plane_step < 0 || p.plane_step > 16)
    why << "plane step " << p.plane_step << " must be in [0, 16] (0: automatic)";
  else if (p.lattice_width != 0 && (p.lattice_width < 160 || p.lattice_width > 8192))
    why << "lattice width " << p.lattice_width << " must be 0 (every pixel) or in [160, 8192]";
  else if (p.plane_samples < 100)
    why << "plane_samples " << p.plane_samples << " must be >= 100";
  else if (p.max_planes < 1 || p.max_planes > 8)
    why << "max_planes " << p.max_planes << " must be in [1, 8]";
  else if (!(p.max_support_tilt > 0.f && p.max_support_tilt < 1.58f))
    why << "max_support_tilt " << p.max_support_tilt << " must be in (0, pi/2]";
  else if (!(p.min_support_area >= 0.f) || !std::isfinite(p.min_support_area))
    why << "min_support_area must be >= 0";
  else if (!(p.min_shelf_area >= 0.f) || !std::isfinite(p.min_shelf_area))
    why << "min_shelf_area must be >= 0";
  else if (!(p.contact_height > 0.f) || !std::isfinite(p.contact_height))
    why << "contact_height must be > 0";
  else if (const std::string o = validate(p.objects); !o.empty())
    why << "objects: " << o;
  return why.str();
}

} // namespace facyl

FACYL_INSTANTIATE_TabletopSegmentation(pcl::PointXYZ)
FACYL_INSTANTIATE_TabletopSegmentation(pcl::PointXYZRGB)
FACYL_INSTANTIATE_TabletopSegmentation(pcl::PointXYZRGBA)
