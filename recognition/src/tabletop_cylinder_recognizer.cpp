/*
 * facyl: fast cylinder detection for PCL.
 * Explicit instantiations for the common point types.
 */
#include <facyl/recognition/impl/tabletop_cylinder_recognizer.hpp>

#include <sstream>

namespace facyl {

std::string
validate(const TabletopRecognizerParameters& p)
{
  std::string why = validate(p.segmentation);
  if (!why.empty())
    return "segmentation: " + why;
  why = validate(p.hough);
  if (!why.empty())
    return "fit: " + why;
  why = validate(p.decision);
  if (!why.empty())
    return "decision: " + why;
  std::ostringstream s;
  if (p.orientations < 10)
    s << "orientations " << p.orientations << " must be >= 10";
  else if (p.max_fit_points < 50)
    s << "max_fit_points " << p.max_fit_points << " must be >= 50";
  else if (p.neighbours < 5)
    s << "neighbours " << p.neighbours << " must be >= 5";
  return s.str();
}

pcl::Indices
evenSubsample(const pcl::Indices& indices, std::size_t max_count)
{
  if (indices.size() <= max_count)
    return indices;
  pcl::Indices out;
  if (max_count == 0)
    return out;
  out.reserve(max_count);
  const double step = static_cast<double>(indices.size()) / static_cast<double>(max_count);
  for (std::size_t k = 0; k < max_count; ++k)
    out.push_back(indices[static_cast<std::size_t>(static_cast<double>(k) * step)]);
  return out;
}

} // namespace facyl

FACYL_INSTANTIATE_TabletopCylinderRecognizer(pcl::PointXYZ)
FACYL_INSTANTIATE_TabletopCylinderRecognizer(pcl::PointXYZRGB)
FACYL_INSTANTIATE_TabletopCylinderRecognizer(pcl::PointXYZRGBA)
