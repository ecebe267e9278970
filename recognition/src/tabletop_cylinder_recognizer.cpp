/*
 * facyl: fast cylinder detection for PCL.
 * Explicit instantiations for the common point types.
 */
#include <facyl/recognition/impl/tabletop_cylinder_recognizer.hpp>

#include <facyl/features/setting_problem.h>

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>

namespace facyl {

std::string
validate(const TabletopRecognizerParameters& p, std::string* rule)
{
  if (rule)
    rule->clear();
  if (const std::string why = validate(p.segmentation); !why.empty())
    return "segmentation: " + why;
  if (const std::string why = validate(p.hough, rule); !why.empty())
    return "fit: " + why;
  if (const std::string why = validate(p.decision, rule); !why.empty())
    return "decision: " + why;
  if (!(p.fit_point_angle >= 0.f && p.fit_point_angle <= 0.1f))
    return settingProblem("fit_point_angle", p.fit_point_angle, "is not in [0, 0.1] (rad)", rule);
  if (p.max_fit_points < 50 || p.max_fit_points > 1000000)
    return settingProblem("max_fit_points", p.max_fit_points, "is not in [50, 1000000]", rule);
  if (p.neighbours < 5 || p.neighbours > 200)
    return settingProblem("neighbours", p.neighbours, "is not in [5, 200]", rule);
  if (p.max_cylinders_per_cluster < 1 || p.max_cylinders_per_cluster > 20)
    return settingProblem("max_cylinders_per_cluster", p.max_cylinders_per_cluster,
                          "is not in [1, 20]", rule);
  if (!(p.min_explained_share > 0.f && p.min_explained_share <= 1.f))
    return settingProblem("min_explained_share", p.min_explained_share, "is not in (0, 1]", rule);
  if (p.max_stacked_objects < 1 || p.max_stacked_objects > 8)
    return settingProblem("max_stacked_objects", p.max_stacked_objects, "is not in [1, 8]", rule);
  if (!(p.reject_below >= 0.f && p.reject_below <= 1.f))
    return settingProblem("reject_below", p.reject_below, "is not in [0, 1]", rule);
  if (!(p.recovery_margin >= 0.f && p.recovery_margin <= 1.f))
    return settingProblem("recovery_margin", p.recovery_margin, "is not in [0, 1] (m)", rule);
  if (p.threads < 0 || p.threads > 64)
    return settingProblem("threads", p.threads, "is not in [0, 64]", rule);
  return {};
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

namespace {

/** Per coordinate x in [\a lo, \a hi], its lattice cell at \a spacing when x is the first of
 * that cell, else -1, at x - lo. */
std::vector<int>
firstOfCells(int lo, int hi, float spacing)
{
  std::vector<int> cell(static_cast<std::size_t>(hi - lo + 1), -1);
  for (int x = lo; x <= hi; ++x) {
    const int c = static_cast<int>(std::floor(static_cast<float>(x) / spacing));
    if (x == 0 || static_cast<int>(std::floor(static_cast<float>(x - 1) / spacing)) != c)
      cell[static_cast<std::size_t>(x - lo)] = c;
  }
  return cell;
}

} // namespace

PixelLattice
pixelLattice(const pcl::Indices& indices, std::uint32_t width, float spacing, std::size_t max_count)
{
  if (width == 0 || !(spacing >= 1.f) || max_count == 0)
    throw std::invalid_argument("facyl::pixelLattice: width " + std::to_string(width) +
                                ", spacing " + std::to_string(spacing) + " and max_count " +
                                std::to_string(max_count) + " must be positive (spacing >= 1)");
  const auto w = static_cast<pcl::index_t>(width);
  PixelLattice lattice;
  std::vector<Eigen::Vector2i> pixels, cells;
  pixels.reserve(indices.size());
  Eigen::Vector2i low(std::numeric_limits<int>::max(), std::numeric_limits<int>::max());
  Eigen::Vector2i high(0, 0);
  for (const auto i : indices) {
    pixels.emplace_back(static_cast<int>(i % w), static_cast<int>(i / w));
    low = low.cwiseMin(pixels.back());
    high = high.cwiseMax(pixels.back());
  }
  for (float s = spacing;;) {
    lattice.spacing = s;
    lattice.pixels.clear();
    cells.clear();
    if (!pixels.empty()) {
      const std::vector<int> column = firstOfCells(low.x(), high.x(), s);
      const std::vector<int> row = firstOfCells(low.y(), high.y(), s);
      for (std::size_t k = 0; k < pixels.size(); ++k) {
        const int cu = column[static_cast<std::size_t>(pixels[k].x() - low.x())];
        const int cv = row[static_cast<std::size_t>(pixels[k].y() - low.y())];
        if (cu >= 0 && cv >= 0) {
          lattice.pixels.push_back(indices[k]);
          cells.emplace_back(cu, cv);
        }
      }
    }
    if (lattice.pixels.size() <= max_count)
      break;
    // The count falls with the spacing squared: straight to about max_count, then by 5%.
    s *= std::max(
      1.05f, std::sqrt(static_cast<float>(lattice.pixels.size()) / static_cast<float>(max_count)));
  }
  if (cells.empty())
    return lattice;
  Eigen::Vector2i lo = cells.front(), hi = cells.front();
  for (const auto& c : cells) {
    lo = lo.cwiseMin(c);
    hi = hi.cwiseMax(c);
  }
  lattice.columns = hi.x() - lo.x() + 1;
  lattice.rows = hi.y() - lo.y() + 1;
  lattice.cell_of.reserve(cells.size());
  for (const auto& c : cells)
    lattice.cell_of.push_back((c.y() - lo.y()) * lattice.columns + (c.x() - lo.x()));
  return lattice;
}

pcl::PointCloud<pcl::PointXYZ>::Ptr
latticeCloud(const PixelLattice& lattice, const pcl::PointCloud<pcl::PointXYZ>& points)
{
  if (points.size() != lattice.pixels.size() || lattice.cell_of.size() != lattice.pixels.size())
    throw std::invalid_argument("facyl::latticeCloud: " + std::to_string(points.size()) +
                                " points for a lattice of " +
                                std::to_string(lattice.pixels.size()) + " pixels");
  const float nan = std::numeric_limits<float>::quiet_NaN();
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>(
    static_cast<std::uint32_t>(lattice.columns), static_cast<std::uint32_t>(lattice.rows),
    pcl::PointXYZ(nan, nan, nan)));
  cloud->is_dense = false;
  for (std::size_t k = 0; k < points.size(); ++k)
    (*cloud)[static_cast<std::size_t>(lattice.cell_of[k])] = points[k];
  return cloud;
}

pcl::Indices
angularGrid(const pcl::Indices& indices, const Eigen::Matrix3Xf& points, float angle)
{
  pcl::Indices out;
  if (!(angle > 0.f))
    return indices;
  std::unordered_set<std::uint64_t> taken;
  taken.reserve(indices.size());
  for (std::size_t k = 0; k < indices.size(); ++k) {
    const Eigen::Vector3f p = points.col(static_cast<Eigen::Index>(k));
    if (!p.allFinite())
      continue;
    const float azimuth = std::atan2(p.x(), p.z());
    const float elevation = std::atan2(p.y(), std::hypot(p.x(), p.z()));
    const auto cell = [&](float a) {
      return static_cast<std::uint64_t>(
        static_cast<std::uint32_t>(static_cast<std::int32_t>(std::floor(a / angle))));
    };
    if (taken.insert(cell(azimuth) << 32 | cell(elevation)).second)
      out.push_back(indices[k]);
  }
  return out;
}

} // namespace facyl

FACYL_INSTANTIATE_TabletopCylinderRecognizer(pcl::PointXYZ)
FACYL_INSTANTIATE_TabletopCylinderRecognizer(pcl::PointXYZRGB)
FACYL_INSTANTIATE_TabletopCylinderRecognizer(pcl::PointXYZRGBA)
