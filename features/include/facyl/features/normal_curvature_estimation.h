/*
 * facyl: fast cylinder detection for PCL.
 */
#pragma once

#include <facyl/features/local_geometry.h>
#include <facyl/features/neighbourhoods.h>
#include <facyl/features/point_types.h>

#include <pcl/features/feature.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <stdexcept>
#include <string>

namespace facyl {

/** \brief Surface normals and principal curvatures (c_max, k_max, k_min; paper III-C2) from a
 * single neighbourhood query per point.
 *
 * PCL users get the same cues from pcl::NormalEstimation followed by
 * pcl::PrincipalCurvaturesEstimation, which searches every neighbourhood twice. This class
 * searches once, keeps the neighbour lists, computes PCA normals (oriented towards the view
 * point), then projects the neighbours' normals on each tangent plane.
 *
 * Usage is that of any pcl::Feature: setInputCloud, optionally setIndices and
 * setSearchSurface, then setKSearch(k) or setRadiusSearch(r), then compute(output). Unless a
 * search method is given with setSearchMethod, neighbours come from an internal nanoflann
 * kd-tree (exact), or, for
 * an organized input (height > 1) searched by k without a search surface, from the image grid
 * (facyl::nearestInImage: the k nearest pixels of a window around each point, no tree; as PCL
 * features take pcl::search::OrganizedNeighbor for organized input; see
 * setImageNeighbourhoods). Points that are not finite or have fewer than 3 finite neighbours
 * get NaN output and make output.is_dense false. Runs in parallel on std::threads (see
 * setNumberOfThreads and facyl::parallelFor: blocks of 256 points, waiting threads sleep rather
 * than spin); the result does not depend on the number of threads. compute() keeps its working
 * buffers between calls (about 115 bytes per point of the largest input with k = 16: 35 MB
 * after a VGA frame), so that an estimator reused frame after frame allocates nothing; destroy
 * it to free them. One estimator serves one thread at a time.
 *
 * If the normals are known already, give them with setInputNormals (one per point of the
 * search surface): only the curvatures are then computed.
 *
 * \tparam PointInT any point type with x, y, z
 * \tparam PointOutT facyl::NormalCurvature (or a type with the same fields)
 */
template <typename PointInT, typename PointOutT = facyl::NormalCurvature>
class NormalCurvatureEstimation : public pcl::Feature<PointInT, PointOutT> {
public:
  using Ptr = std::shared_ptr<NormalCurvatureEstimation<PointInT, PointOutT>>;
  using ConstPtr = std::shared_ptr<const NormalCurvatureEstimation<PointInT, PointOutT>>;
  using PointCloudOut = typename pcl::Feature<PointInT, PointOutT>::PointCloudOut;
  using NormalCloudConstPtr = pcl::PointCloud<pcl::Normal>::ConstPtr;

  NormalCurvatureEstimation()
  {
    this->feature_name_ = "NormalCurvatureEstimation";
  }

  /** \brief Point towards which the normals are flipped (default: the input cloud's
   * sensor_origin_, as in pcl::NormalEstimation; the origin for a cloud without a pose). */
  void setViewPoint(float vpx, float vpy, float vpz)
  {
    view_point_ = Eigen::Vector3f(vpx, vpy, vpz);
    use_sensor_origin_ = false;
  }
  /** \brief The view point set with setViewPoint, or the input's sensor origin. */
  Eigen::Vector3f getViewPoint() const
  {
    return use_sensor_origin_ && this->input_
             ? Eigen::Vector3f(this->input_->sensor_origin_.template head<3>())
             : view_point_;
  }
  /** \brief Flip the normals towards the input's sensor_origin_ again (the default). */
  void useSensorOriginAsViewPoint()
  {
    use_sensor_origin_ = true;
  }

  /** \brief Known normals, one per point of the search surface (the input when no surface was
   * set). Only the curvatures are then estimated. Pass nullptr to estimate normals again. */
  void setInputNormals(const NormalCloudConstPtr& normals)
  {
    input_normals_ = normals;
  }
  /** \brief The normals given with setInputNormals, or nullptr. */
  NormalCloudConstPtr getInputNormals() const
  {
    return input_normals_;
  }

  /** \brief Number of threads; 0 (default): the hardware's concurrency. Inputs of at most 256
   * points (one block) run on the calling thread alone. */
  void setNumberOfThreads(unsigned int threads)
  {
    threads_ = threads;
  }
  /** \brief Number of threads (0: the hardware's concurrency). */
  unsigned int getNumberOfThreads() const
  {
    return threads_;
  }

  /** \brief Whether an organized input (height > 1, width x height points) searched by k
   * (setKSearch) without a search surface or search method takes its neighbours from the image
   * grid (nearestInImage); default true. false: the kd-tree, whatever the input's layout. */
  void setImageNeighbourhoods(bool use)
  {
    image_neighbourhoods_ = use;
  }
  /** \brief Whether organized input takes its neighbours from the image grid. */
  bool getImageNeighbourhoods() const
  {
    return image_neighbourhoods_;
  }
  /** \brief Half-width of the image window searched for the k neighbours (nearestInImage); 0
   * (default): imageWindowRadius(k). A wider window holds the k nearest points on surfaces
   * seen at a more grazing angle, and costs its area. \throws std::invalid_argument if
   * negative. */
  void setImageWindowRadius(int radius)
  {
    if (radius < 0)
      throw std::invalid_argument("facyl::NormalCurvatureEstimation::setImageWindowRadius: " +
                                  std::to_string(radius) + " is negative");
    image_window_radius_ = radius;
  }
  /** \brief The image window's half-width (0: imageWindowRadius(k)). */
  int getImageWindowRadius() const
  {
    return image_window_radius_;
  }

protected:
  bool initCompute() override;

private:
  void computeFeature(PointCloudOut& output) override;

  /** Neighbour lists of surface_queries (indices into the input if queries_are_input, else
   * into the surface), from the PCL search method, the image grid or the internal kd-tree, in
   * \a out (its storage reused). */
  void neighbourhoods(const std::vector<int>& surface_queries, bool queries_are_input, int threads,
                      Neighbourhoods& out) const;

  Eigen::Vector3f view_point_{Eigen::Vector3f::Zero()};
  bool use_sensor_origin_{true};
  bool use_pcl_search_{false};
  bool image_neighbourhoods_{true};
  int image_window_radius_{0};
  bool use_image_{false};           ///< this compute: neighbours from the image grid
  Eigen::Matrix3Xf surface_points_; ///< this compute: the surface as columns (own search)
  // Working buffers of compute(), kept between calls so that a stream of frames does not
  // allocate (and return to the system) memory on every call.
  std::vector<int> missing_;
  Neighbourhoods nb_, extra_nb_;
  std::vector<Eigen::Vector3f> normals_, surface_normals_;
  std::vector<float> variation_;
  std::vector<char> known_;
  std::unique_ptr<NeighbourSearch> search_;
  NormalCloudConstPtr input_normals_;
  unsigned int threads_{0};
  /** Points per block of the parallel loops. */
  static constexpr std::size_t kGrain = 256;
};

} // namespace facyl

#ifdef PCL_NO_PRECOMPILE
#include <facyl/features/impl/normal_curvature_estimation.hpp>
#endif
