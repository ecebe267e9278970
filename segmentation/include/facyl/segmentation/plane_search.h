/*
 * facyl: fast cylinder detection for PCL.
 * The point-type-independent steps of TabletopSegmentation, as free functions on Eigen data
 * and PointXYZ clouds (compiled once, in src/plane_search.cpp): the plane-search grid of an
 * organized frame and its seeds, the plane seeds of a point sample, the ranking of families of
 * parallel supports, and Euclidean clusters.
 */
#pragma once

#include <facyl/segmentation/support_planes.h>

#include <pcl/PointIndices.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

namespace facyl {

/** \brief The plane-search grid of an organized frame at one block size. */
struct PlaneGrid {
  int step{1};                                   ///< block size (pixels)
  pcl::PointCloud<pcl::PointXYZ>::Ptr small;     ///< the cells, organized
  std::vector<pcl::index_t> source;              ///< each cell's first pixel (-1: none)
  pcl::PointCloud<pcl::Normal>::Ptr normals;     ///< the cells' normals
  Eigen::Matrix3Xf cells, cell_normals, samples; ///< as columns; samples: the first pixels
};

/** \brief Means of the pixels of the blocks of one plane grid, filled pixel by pixel in row
 * order: each block's first pixel with depth, and the mean of those with depth near the
 * first's (within 2 %). */
struct BlockMeans {
  BlockMeans(int step_, int w, int h)
      : step(step_)
      , cw(static_cast<std::size_t>((w + step_ - 1) / step_))
      , ch(static_cast<std::size_t>((h + step_ - 1) / step_))
      , sum(cw * ch, Eigen::Vector3f::Zero())
      , first(cw * ch, Eigen::Vector3f::Zero())
      , count(cw * ch, 0)
      , source(cw * ch, -1)
      , column_block(static_cast<std::size_t>(std::max(w, 0)))
  {
    for (std::size_t u = 0; u < column_block.size(); ++u)
      column_block[u] = static_cast<std::uint32_t>(u / static_cast<std::size_t>(step_));
  }
  /** The first block of the row of blocks that holds pixel row \a v. */
  std::size_t rowBase(int v) const
  {
    return static_cast<std::size_t>(v / step) * cw;
  }
  /** The pixel (\a u, \a v), input index \a idx, with the finite point \a p. */
  void add(int u, int v, pcl::index_t idx, const Eigen::Vector3f& p)
  {
    addTo(rowBase(v) + column_block[static_cast<std::size_t>(u)], idx, p);
  }
  /** add() into block \a k (rowBase(v) + column_block[u]: no division per pixel). */
  void addTo(std::size_t k, pcl::index_t idx, const Eigen::Vector3f& p)
  {
    if (count[k] == 0) {
      first[k] = p;
      source[k] = idx;
    }
    else if (std::abs(p.z() - first[k].z()) > 0.02f * std::abs(first[k].z()))
      return;
    sum[k] += p;
    ++count[k];
  }
  int step;
  std::size_t cw, ch;
  std::vector<Eigen::Vector3f> sum;
  std::vector<Eigen::Vector3f> first; ///< each block's first pixel
  std::vector<int> count;
  std::vector<pcl::index_t> source;
  std::vector<std::uint32_t> column_block; ///< u / step for each pixel column u
};

/** \brief The normals of pcl::IntegralImageNormalEstimation<PointXYZ, Normal> on the organized
 * \a cloud with AVERAGE_3D_GRADIENT, BORDER_POLICY_IGNORE, a fixed \a smoothing_size
 * (setNormalSmoothingSize), \a max_depth_change_factor (setMaxDepthChangeFactor) and the
 * cloud's sensor origin as the viewpoint: the same floats in the same order, without what PCL
 * sets up per call and this method does not use (a search tree, index lists, four-float
 * difference images). Curvatures are NaN, as PCL's. Clouds too small for PCL's borders (fewer
 * than 2 x smoothing_size rows or columns) get NaN normals everywhere.
 * Reentrant: no state outside \a normals.
 * \throws std::invalid_argument if \a smoothing_size is not positive and finite or
 *         \a max_depth_change_factor is negative or not finite. */
void averageGradientNormals(const pcl::PointCloud<pcl::PointXYZ>& cloud,
                            float max_depth_change_factor, float smoothing_size,
                            pcl::PointCloud<pcl::Normal>& normals);

/** \brief The grid of \a blocks (of a frame \a image_width pixels wide): the cells (block
 * means; NaN without depth), their normals (integral images, depth changes scaled to the
 * grid's angular spacing), the columns and each cell's first pixel. Empties \a blocks. */
void finishPlaneGrid(BlockMeans& blocks, int image_width, PlaneGrid& grid);

/** \brief The planar regions of pcl::OrganizedMultiPlaneSegmentation<PointXYZ, Normal, Label>
 * (its comparator's defaults, the thresholds of setMinInliers, setAngularThreshold,
 * setDistanceThreshold and setMaximumCurvature) on the organized \a cloud and its \a normals:
 * the same regions, in the same order, without its per-call set-up (index lists, a label cloud,
 * a virtual comparison per pair of neighbours). Empty when the sizes differ or the cloud is not
 * organized. Reentrant. */
std::vector<pcl::PointIndices> planarRegions(const pcl::PointCloud<pcl::PointXYZ>& cloud,
                                             const pcl::PointCloud<pcl::Normal>& normals,
                                             unsigned min_inliers, double angular_threshold,
                                             double distance_threshold, double maximum_curvature);

/** \brief The seed regions (cells) of the plane search on \a grid, largest first:
 * pcl::OrganizedMultiPlaneSegmentation's regions of \a min_plane_points (in pixels) at \a
 * plane_angle (rad) and \a seed_distance (m). Its thresholds only make seeds (the band of each
 * plane is measured afterwards); on a frame too noisy for any seed of the least plane size they are
 * relaxed, twice at most. */
std::vector<pcl::PointIndices> planeSeeds(const PlaneGrid& grid, std::size_t min_plane_points,
                                          float plane_angle, float seed_distance);

/** \brief What the plane search of a point sample works on: the points, their normals (12
 * nearest neighbours) and RANSAC's seed threshold (\a plane_distance, or 2 % of the median
 * range from \a viewpoint). */
struct SampledPlaneCues {
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud;
  Eigen::Matrix3Xf points, normals;
  float seed_distance{0.f};
};

/** \brief SampledPlaneCues of \a sample. */
SampledPlaneCues sampledPlaneCues(const pcl::PointCloud<pcl::PointXYZ>::Ptr& sample,
                                  const Eigen::Vector3f& viewpoint, float plane_distance);

/** \brief True when three of the finite points of \a cloud at \a indices span a plane: the
 * cross product of two sides of their triangle is at least \a min_cross long (m^2; PCL's plane
 * model takes a sample from 1e-5 on). False for coincident or collinear points, fewer than 3:
 * there a plane RANSAC finds no sample and PCL prints an error for every one of its tries.
 * Found against the first point and the farthest from it; stops at the first that spans one
 * (a few points of a real frame). */
template <typename PointT>
bool
spansPlane(const pcl::PointCloud<PointT>& cloud, const pcl::Indices& indices,
           float min_cross = 1e-5f)
{
  bool have_first = false;
  Eigen::Vector3f first = Eigen::Vector3f::Zero(), far = Eigen::Vector3f::Zero();
  float far2 = 0.f;
  for (const auto i : indices) {
    const auto& p = cloud[static_cast<std::size_t>(i)];
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
      continue;
    const Eigen::Vector3f d = p.getVector3fMap() - first;
    if (!have_first) {
      first = p.getVector3fMap();
      have_first = true;
    }
    else if (far.cross(d).norm() >= min_cross)
      return true;
    else if (d.squaredNorm() > far2) {
      far2 = d.squaredNorm();
      far = d;
    }
  }
  if (far2 == 0.f)
    return false;
  for (const auto i : indices) { // against the farthest point
    const auto& p = cloud[static_cast<std::size_t>(i)];
    if (std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z) &&
        far.cross(p.getVector3fMap() - first).norm() >= min_cross)
      return true;
  }
  return false;
}

/** \brief Plane seeds of a point sample, one after another on what the previous ones left
 * (RANSAC on positions, 200 iterations, then the inliers whose normal is within 0.3 rad of the
 * plane's): each seed of at least \a min_plane_points (each sample standing for \a scale
 * points) goes to \a grow, which may mark samples \a taken; the RANSAC inliers are taken after
 * it. At most \a max_planes seeds; stops at the first too small, or when what is left spans no
 * plane (spansPlane). */
void ransacPlaneSeeds(const SampledPlaneCues& cues, std::size_t max_planes, double scale,
                      std::size_t min_plane_points,
                      const std::function<void(const std::vector<std::uint8_t>&)>& grow,
                      std::vector<std::uint8_t>& taken);

/** \brief True when \a plane (a, b, c, d, unit normal towards the sensor) faces the top of
 * the image, as an upright camera sees a support: its normal points against \a image_down
 * (the image's down direction, unit), by more than 0.1. */
bool facesImageTop(const Eigen::Vector4f& plane, const Eigen::Vector3f& image_down);

/** \brief The families of parallel \a planes (unit normals within 0.1 rad), those an upright
 * camera would see facing up first (\a up_known: all of them; else the normal points against
 * \a image_down, the image's down direction), then by their \a points. \a planes are largest
 * first (the order breaks ties). */
std::vector<std::vector<std::size_t>>
rankSupportFamilies(const std::vector<Eigen::Vector4f>& planes,
                    const std::vector<std::size_t>& points, bool up_known,
                    const Eigen::Vector3f& image_down);

/** \brief A point above some support candidate: its index, and the candidates (bit s for
 * candidate s) it lies on and above. */
struct PointOverPlanes {
  pcl::index_t index;
  std::uint8_t on, above;
};

/** \brief One pass that sorts points onto and above up to 8 candidate planes, each with its
 * band: a point is on plane s when its height h over it is within the band's half-width at
 * the point's range from the viewpoint (tabulated every 5 mm up to 12 m, computed beyond), and
 * above it when h is in (max(floor, half-width), top]. Thread-safe: sort() is const. */
class PlaneSorter {
public:
  /** \brief \a planes (unit normals towards the viewpoint; at most 8) and their \a bands (as
   * many). \throws std::invalid_argument otherwise. */
  PlaneSorter(std::vector<Eigen::Vector4f> planes, std::vector<DepthBand> bands,
              const Eigen::Vector3f& viewpoint, float floor, float top);
  /** \brief Sorts \a count points, whose x, y and z are the first three of every \a stride
   * floats from \a xyz; the k-th is point k, or indices[k] when \a indices is given. Non-finite
   * points are skipped. Each plane s's points are written at ends[s] (one pointer per plane,
   * each with room for \a count; it advances), in the order visited; the points above some plane
   * are appended to \a above. \a vectorized: the whole cloud (no indices) four points at a time
   * where SSE2 is there (x86-64), with the same floats and lists as one at a time (false). */
  void sort(const float* xyz, std::size_t stride, std::size_t count, const pcl::index_t* indices,
            pcl::index_t** ends, std::vector<PointOverPlanes>& above, bool vectorized = true) const;

private:
  void sortOne(pcl::index_t i, const float* p, pcl::index_t** ends,
               std::vector<PointOverPlanes>& above) const;
  /** The whole cloud's points four at a time (SSE2), up to the last whole four; \return how
   * many were sorted. */
  std::size_t sortByFour(const float* xyz, std::size_t stride, std::size_t count,
                         pcl::index_t** ends, std::vector<PointOverPlanes>& above) const;
  std::vector<Eigen::Vector4f> planes_;
  std::vector<DepthBand> bands_;
  Eigen::Vector3f viewpoint_;
  float floor_, top_;
  std::vector<float> half_; ///< half-widths by bin of range (tabulateHalfWidths), then plane
};

/** \brief Connected components of the organized \a cloud, neighbours closer than \a
 * tolerance (pcl::EuclideanClusterComparator); \a labels is a buffer kept between calls. */
std::vector<pcl::Indices>
organizedEuclideanClusters(const pcl::PointCloud<pcl::PointXYZ>::ConstPtr& cloud, float tolerance,
                           pcl::PointCloud<pcl::Label>& labels);

/** \brief Euclidean clusters (neighbours closer than \a tolerance) of \a points (columns), as
 * lists of columns, largest first: clusters of one representative per voxel of a quarter of the
 * tolerance (any two points of neighbouring voxels are closer than it), then every point joins
 * its voxel's cluster: on dense sensor clouds the radius searches return few neighbours. */
std::vector<std::vector<std::size_t>> voxelEuclideanClusters(const Eigen::Matrix3Xf& points,
                                                             float tolerance);

} // namespace facyl
