/*
 * facyl: fast cylinder detection for PCL.
 */
#pragma once

#include <facyl/features/point_types.h>
#include <facyl/sample_consensus_alt/cylinder_fitting.h>
#include <facyl/sample_consensus_alt/cylinder_model.h>
#include <facyl/sample_consensus_alt/orientation_accumulator.h>

#include <pcl/ModelCoefficients.h>
#include <pcl/PointIndices.h>
#include <pcl/pcl_base.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/type_traits.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace facyl {

/** \brief Why HoughCylinderEstimation::segment() returned false (getFailureReason()). */
enum class HoughFailure {
  None,              ///< the last segment() found a cylinder (or none has run)
  NoInputCloud,      ///< setInputCloud was not called
  EmptyCloud,        ///< the input cloud has no points
  NoNormals,         ///< setInputNormals was not called
  SizeMismatch,      ///< normals or curvatures not one per point
  InvalidParameters, ///< a setting is out of range (radius limits inverted, ...)
  InvalidIndices,    ///< an index outside the cloud, or PCL refused the input
  NoFinitePoints,    ///< no point has a finite position and normal
  NoCurvatures,      ///< SoftCurvature without curvatures, and their estimation is off
  TooFewPoints,      ///< fewer usable points than a cylinder needs inliers
  RadiusLimits,      ///< a cylinder is there, but the radius limits exclude it
  NoCylinder,        ///< the points hold no cylinder with enough inliers
  InternalError      ///< an exception inside the fit (reported in the message)
};

/** \brief Two-step Hough cylinder estimator (Rabbani & van den Heuvel; Figueiredo et al. 2019)
 * with a randomized Gaussian-mixture orientation accumulator, curvature-weighted soft voting,
 * sub-cell refinement, and extraction of several cylinders.
 *
 * Step 1 votes for the axis direction on N_d cells drawn from an orientation prior (paper
 * eq. 1-3). The strongest peaks are refined below the cell size (refineAxis); points that
 * reach much further along one direction than across (a tall cylinder seen over a narrow arc;
 * all the points, those whose normals are off a dominant plane's, or, when those are not
 * elongated, those off a second plane's too: lids and a table) also propose that direction.
 * Step 2 aligns each axis with z and finds position and radius with a circle Hough transform.
 * Candidates compete on their inliers, each at the threshold its residuals give; a best whose
 * residuals spread far wider than noise meets a runner-up at the runner-up's tighter
 * threshold. The best candidates are then refined on the points themselves (robust least squares on
 * the point-to-surface distances) and compared on the points they explain; when the noise makes the
 * given normals useless, normals and curvatures are estimated again from neighbours within one
 * radius and propose candidates too (see HoughCylinderParameters::point_candidates). The goodness
 * of fit is the inlier ratio of eq. 4.
 *
 * \code
 * facyl::HoughCylinderEstimation<pcl::PointXYZ, facyl::NormalCurvature> hough;
 * hough.setInputCloud(cloud);
 * hough.setInputNormals(cues);            // from facyl::NormalCurvatureEstimation
 * hough.setRadiusLimits(0.01f, 0.2f);
 * pcl::PointIndices inliers;
 * pcl::ModelCoefficients coefficients;    // SACMODEL_CYLINDER layout
 * if (hough.segment(inliers, coefficients)) ...
 * \endcode
 *
 * <b>Normals without curvatures (a drop-in for PCL's cylinder tutorial).</b> The default
 * SoftCurvature voting needs principal curvatures. When PointNT carries none (pcl::Normal,
 * pcl::PointNormal) and none were given with setInputCurvatures, the estimator estimates them
 * from the points itself, at the scale of facyl's own NormalCurvatureEstimation (normals of
 * the 16 nearest points, then the spread of those normals), whatever scale the given normals
 * have: with curvatures from normals smoothed over k = 50 neighbours (the tutorial's
 * pcl::NormalEstimation, then pcl::PrincipalCurvaturesEstimation at k = 50) the axis found on
 * the tutorial's mug is far off (README, "Use it from C++"). The given normals stay the normals
 * of the vote and of the inlier test. setEstimateCurvatures(false) turns this off: segment()
 * then fails with HoughFailure::NoCurvatures. The other voting modes need normals only.
 *
 * Inputs that cannot give an answer (no cloud, no normals, sizes that differ, no finite point,
 * invalid parameters, SoftCurvature without curvatures when their estimation is off) are
 * reported with PCL_ERROR; a search that finds no cylinder (too few points, a cylinder outside
 * the radius limits, none at all) with PCL_WARN (PCL_DEBUG after setDiagnoseFailures(false)).
 * Either way segment() returns false with empty outputs, and getFailureReason() /
 * getFailureMessage() say why. segment() is not reentrant on one object; distinct objects may
 * run concurrently.
 *
 * \tparam PointT a point type with x, y, z
 * \tparam PointNT a type with normal_x/y/z; if it also has principal_curvature_x/y/z, pc1 and
 *         pc2 (facyl::NormalCurvature), those are the curvatures used by SoftCurvature voting;
 *         otherwise they are estimated from the points (see above).
 */
/** \brief A frame whose z axis is \a up (normalized; x any unit vector orthogonal to it): the
 * reference frame HoughCylinderEstimation::setUpDirection sets. */
inline Eigen::Matrix3f
frameAboutUp(const Eigen::Vector3f& up)
{
  const Eigen::Vector3f z = up.normalized();
  const Eigen::Vector3f x = z.unitOrthogonal();
  Eigen::Matrix3f frame;
  frame << x, z.cross(x), z;
  return frame;
}

template <typename PointT, typename PointNT>
class HoughCylinderEstimation : public pcl::PCLBase<PointT> {
public:
  using Ptr = std::shared_ptr<HoughCylinderEstimation<PointT, PointNT>>;
  using ConstPtr = std::shared_ptr<const HoughCylinderEstimation<PointT, PointNT>>;
  using PointCloud = pcl::PointCloud<PointT>;
  using PointCloudConstPtr = typename PointCloud::ConstPtr;
  using Normals = pcl::PointCloud<PointNT>;
  using NormalsConstPtr = typename Normals::ConstPtr;
  using Curvatures = pcl::PointCloud<pcl::PrincipalCurvatures>;
  using CurvaturesConstPtr = Curvatures::ConstPtr;

  HoughCylinderEstimation() = default;

  /** \brief Normals, one per input point (required). */
  void setInputNormals(const NormalsConstPtr& normals)
  {
    normals_ = normals;
  }
  /** \brief The normals given, or nullptr. */
  NormalsConstPtr getInputNormals() const
  {
    return normals_;
  }
  /** \brief Principal curvatures, one per input point, for SoftCurvature voting when PointNT
   * carries none (e.g. from pcl::PrincipalCurvaturesEstimation). Overrides PointNT's. */
  void setInputCurvatures(const CurvaturesConstPtr& curvatures)
  {
    curvatures_ = curvatures;
  }
  /** \brief The curvatures given, or nullptr. */
  CurvaturesConstPtr getInputCurvatures() const
  {
    return curvatures_;
  }

  /** \brief With SoftCurvature voting, when PointNT carries no curvatures and none were
   * given: estimate the curvatures from the 16 nearest points (default true). false:
   * segment() fails with HoughFailure::NoCurvatures instead. */
  void setEstimateCurvatures(bool estimate)
  {
    estimate_curvatures_ = estimate;
  }
  /** \brief Whether missing curvatures are estimated. */
  bool getEstimateCurvatures() const
  {
    return estimate_curvatures_;
  }
  /** \brief Whether the last segment() estimated the curvatures itself. */
  bool curvaturesWereEstimated() const
  {
    return curvatures_estimated_;
  }

  /** \brief Whether a search that finds nothing is diagnosed (default true): with radius
   * limits, the search is run once more without them, so that a cylinder they exclude is
   * reported as HoughFailure::RadiusLimits with its radius, and the outcome is printed with
   * PCL_WARN. false (pipelines for which "no cylinder" is a normal answer, e.g. one fit per
   * cluster): no second search (HoughFailure::NoCylinder or TooFewPoints) and PCL_DEBUG. */
  void setDiagnoseFailures(bool diagnose)
  {
    diagnose_failures_ = diagnose;
  }
  /** \brief Whether a search that finds nothing is diagnosed. */
  bool getDiagnoseFailures() const
  {
    return diagnose_failures_;
  }

  /** \brief Why the last segment() returned false (HoughFailure::None after a success). */
  HoughFailure getFailureReason() const
  {
    return failure_;
  }
  /** \brief The reason in words, as printed (empty after a success). */
  const std::string& getFailureMessage() const
  {
    return failure_message_;
  }

  /** \brief All numeric settings at once (see HoughCylinderParameters). */
  void setParameters(const HoughCylinderParameters& params)
  {
    params_ = params;
    explicit_mixture_ = false; // params.prior is the prior again
    drawn_.clear();
  }
  /** \brief All numeric settings. */
  const HoughCylinderParameters& getParameters() const
  {
    return params_;
  }

  /** \brief Voting mode (default SoftCurvature, paper eq. 3). */
  void setVotingMode(VotingMode mode)
  {
    params_.voting_mode = mode;
  }
  /** \brief Voting mode. */
  VotingMode getVotingMode() const
  {
    return params_.voting_mode;
  }
  /** \brief Radius interval [min, max] in cloud units (default [0, inf): inf is read as twice
   * the extent of the points). */
  void setRadiusLimits(float min_radius, float max_radius)
  {
    params_.radius_min = min_radius;
    params_.radius_max = max_radius;
  }
  /** \brief Radius interval. */
  void getRadiusLimits(float& min_radius, float& max_radius) const
  {
    min_radius = params_.radius_min;
    max_radius = params_.radius_max;
  }
  /** \brief Inlier distance to the surface, > 0; 0 (default) estimates 3 robust sigmas of the
   * residuals, clamped to [0.001, 0.1] x radius. */
  void setDistanceThreshold(float threshold)
  {
    params_.distance_threshold = threshold;
  }
  /** \brief Inlier distance threshold (0: estimated). */
  float getDistanceThreshold() const
  {
    return params_.distance_threshold;
  }
  /** \brief Largest angle (rad) between an inlier's normal and the cylinder's surface normal,
   * in (0, pi/2] (default 0.6 rad, 34 deg). */
  void setNormalAngleThreshold(float radians)
  {
    params_.normal_angle_threshold = radians;
  }
  /** \brief Inlier normal angle threshold (rad). */
  float getNormalAngleThreshold() const
  {
    return params_.normal_angle_threshold;
  }
  /** \brief Extract up to n cylinders, one after another (default 1). */
  void setMaxCylinders(std::size_t n)
  {
    params_.max_cylinders = n;
  }
  /** \brief Largest number of cylinders extracted. */
  std::size_t getMaxCylinders() const
  {
    return params_.max_cylinders;
  }
  /** \brief A cylinder needs this many points: its inliers and the points of its end caps
   * (endCapPoints), at least 10 (or \a n, if smaller) of them inliers; 0 (default): max(10, 5% of
   * the points). */
  void setMinInliers(std::size_t n)
  {
    params_.min_inliers = n;
  }
  /** \brief Minimum inliers (0: automatic). */
  std::size_t getMinInliers() const
  {
    return params_.min_inliers;
  }
  /** \brief Accumulator peaks per accumulator that are refined and fitted (default 1;
   * with SoftCurvature, the dominant planar normal and the best normals-only peak are fitted too).
   */
  void setOrientationCandidates(std::size_t n)
  {
    params_.orientation_candidates = n;
  }
  /** \brief Peaks fitted per accumulator. */
  std::size_t getOrientationCandidates() const
  {
    return params_.orientation_candidates;
  }
  /** \brief Power applied to soft votes, >= 1 (default 2; 1 is the paper's eq. 3). */
  void setKernelExponent(int p)
  {
    params_.kernel_exponent = p;
  }
  /** \brief Soft-vote power. */
  int getKernelExponent() const
  {
    return params_.kernel_exponent;
  }
  /** \brief Sub-cell axis and least-squares refinement (default true; false reproduces the
   * paper's cell-quantised axis: the accumulators' peaks alone are the axes tried, as given,
   * e.g. one fixed axis). */
  void setRefine(bool refine)
  {
    params_.refine = refine;
  }
  /** \brief Whether the model is refined. */
  bool getRefine() const
  {
    return params_.refine;
  }
  /** \brief Candidates refined and compared on the points (default 3; 0: the best candidate
   * alone, refined by least squares on its inliers, as facyl 0.1 did). */
  void setPointCandidates(std::size_t n)
  {
    params_.point_candidates = n;
  }
  /** \brief Candidates refined and compared on the points. */
  std::size_t getPointCandidates() const
  {
    return params_.point_candidates;
  }
  /** \brief Noise (robust sigma / radius, > 0) above which the given cues count as noise
   * (default 0.04). */
  void setNoisyCuesRatio(float ratio)
  {
    params_.noisy_cues_ratio = ratio;
  }
  /** \brief Noise ratio above which the given cues count as noise. */
  float getNoisyCuesRatio() const
  {
    return params_.noisy_cues_ratio;
  }
  /** \brief Neighbourhood of the cues estimated again at high noise, as a share of the
   * radius, in [0, 2] (default 1; 0: never). */
  void setCoarseScale(float share_of_radius)
  {
    params_.coarse_scale = share_of_radius;
  }
  /** \brief Neighbourhood of the coarse cues, as a share of the radius. */
  float getCoarseScale() const
  {
    return params_.coarse_scale;
  }

  /** \brief Orientation prior from a preset (HoughCylinderParameters::prior, default
   * Uniform). */
  void setOrientationPrior(OrientationPrior prior)
  {
    params_.prior = prior;
    explicit_mixture_ = false;
    drawn_.clear();
  }
  /** \brief Orientation prior as an explicit Gaussian mixture, in the reference frame; it
   * replaces the preset until setOrientationPrior or setParameters. */
  void setOrientationMixture(const GaussianMixture& mixture)
  {
    mixture_ = mixture;
    explicit_mixture_ = true;
    drawn_.clear();
  }
  /** \brief The orientation prior: the explicit mixture, or the preset's. */
  GaussianMixture getOrientationMixture() const
  {
    return explicit_mixture_ ? mixture_ : GaussianMixture::fromPrior(params_.prior);
  }
  /** \brief Frame of the prior: its columns are the prior's x, y, z ("up") axes in cloud
   * coordinates (default identity). */
  void setReferenceFrame(const Eigen::Matrix3f& frame)
  {
    frame_ = frame;
    drawn_.clear();
  }
  /** \brief Gravity's opposite (e.g. a table normal): the reference frame from this "up" axis,
   * and the cylinders found follow orientCylinder (cylinder_model.h): the axis points up and the
   * base (point_on_axis, the coefficients' point) is the lower end; a lying one points towards
   * the cloud's sensor_origin_. Zero: unknown (the default), the axis's sign is the fit's. */
  void setUpDirection(const Eigen::Vector3f& up);
  /** \brief The up direction (zero: unknown). */
  const Eigen::Vector3f& getUpDirection() const
  {
    return up_;
  }
  /** \brief Frame of the prior. */
  const Eigen::Matrix3f& getReferenceFrame() const
  {
    return frame_;
  }
  /** \brief Cells per accumulator, N_d (HoughCylinderParameters::orientations: default 450,
   * as in the paper). */
  void setNumberOfOrientations(std::size_t n)
  {
    params_.orientations = n;
    drawn_.clear();
  }
  /** \brief N_d. */
  std::size_t getNumberOfOrientations() const
  {
    return params_.orientations;
  }
  /** \brief Independent accumulators voted per fit (HoughCylinderParameters::accumulators,
   * default 1); their peaks compete. */
  void setNumberOfAccumulators(std::size_t n)
  {
    params_.accumulators = n;
    drawn_.clear();
  }
  /** \brief Accumulators per fit. */
  std::size_t getNumberOfAccumulators() const
  {
    return params_.accumulators;
  }
  /** \brief Seed of the accumulator draws (HoughCylinderParameters::seed, default 0): equal
   * seeds give equal results. */
  void setSeed(std::uint64_t seed)
  {
    params_.seed = seed;
    drawn_.clear();
  }
  /** \brief The seed. */
  std::uint64_t getSeed() const
  {
    return params_.seed;
  }
  /** \brief Explicit accumulators; they replace the drawn ones until cleared with {}. */
  void setAccumulators(const std::vector<OrientationAccumulator>& accumulators)
  {
    user_accumulators_ = accumulators;
  }
  /** \brief The accumulators the last segment() used (drawn lazily). */
  const std::vector<OrientationAccumulator>& getAccumulators()
  {
    return accumulators();
  }

  /** \brief Fits the best cylinder: its inliers and the 7 SACMODEL_CYLINDER coefficients.
   * \return false (and empty outputs) on invalid input or when no cylinder was found. */
  bool segment(pcl::PointIndices& inliers, pcl::ModelCoefficients& coefficients);

  /** \brief Fits up to getMaxCylinders() cylinders, best first; inlier indices refer to the
   * input cloud. \return false on invalid input or when none was found. */
  bool segment(std::vector<CylinderModel>& cylinders);

  /** \brief "HoughCylinderEstimation". */
  std::string getClassName() const
  {
    return "HoughCylinderEstimation";
  }

private:
  const std::vector<OrientationAccumulator>& accumulators();

  static constexpr bool kNormalsCarryCurvature =
    pcl::traits::has_field<PointNT, pcl::fields::pc1>::value &&
    pcl::traits::has_field<PointNT, pcl::fields::pc2>::value &&
    pcl::traits::has_field<PointNT, pcl::fields::principal_curvature_x>::value;
  /** SoftCurvature voting without curvatures given (setInputCurvatures or in the normals). */
  bool curvaturesToEstimate() const
  {
    return params_.voting_mode == VotingMode::SoftCurvature && !curvatures_ &&
           !kNormalsCarryCurvature;
  }
  /** The checks before a fit (input, normals, parameters, prior); false, recorded, when one
   * fails. */
  bool checkInput();
  /** The indexed points with a finite position and normal as columns of \a cues (with the
   * given curvatures' directions and eq. 3 weights when SoftCurvature has them), and the cloud
   * index of each column; false, recorded, for a bad index or no such point. */
  bool gatherCues(CylinderCues& cues, std::vector<pcl::index_t>& column_to_index);

  enum class Level { Error, Warn, Debug };
  /** Records the failure, prints it at \a level, returns false. */
  bool fail(HoughFailure reason, const std::string& message, Level level = Level::Error);
  /** After fitCylinders found nothing among \a n usable points: the reason. */
  bool explainNoCylinder(const CylinderCues& cues, std::size_t total_points);

  bool estimate_curvatures_{true};
  bool diagnose_failures_{true};
  bool curvatures_estimated_{false};
  HoughFailure failure_{HoughFailure::None};
  std::string failure_message_;

  NormalsConstPtr normals_;
  CurvaturesConstPtr curvatures_;
  HoughCylinderParameters params_;
  GaussianMixture mixture_; ///< with explicit_mixture_: replaces params_.prior
  bool explicit_mixture_{false};
  Eigen::Matrix3f frame_{Eigen::Matrix3f::Identity()};
  Eigen::Vector3f up_{Eigen::Vector3f::Zero()}; ///< unit, or zero: unknown
  std::vector<OrientationAccumulator> user_accumulators_;
  std::vector<OrientationAccumulator> drawn_;
};

} // namespace facyl

#ifdef PCL_NO_PRECOMPILE
#include <facyl/sample_consensus_alt/impl/hough_cylinder_estimation.hpp>
#endif
