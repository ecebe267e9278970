/*
 * facyl: fast cylinder detection for PCL.
 */
#pragma once

#include <facyl/features/normal_curvature_estimation.h>
#include <facyl/recognition/classifier_input.h>
#include <facyl/recognition/cylinder_evidence.h>
#include <facyl/recognition/shape_classifier.h>
#include <facyl/sample_consensus_alt/cylinder_fitting.h>
#include <facyl/sample_consensus_alt/cylinder_model.h>
#include <facyl/sample_consensus_alt/hough_cylinder_estimation.h>
#include <facyl/sample_consensus_alt/orientation_accumulator.h>
#include <facyl/segmentation/tabletop_segmentation.h>

#include <pcl/ModelCoefficients.h>
#include <pcl/pcl_base.h>
#include <pcl/point_cloud.h>

#include <chrono>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace facyl {

/** \brief The steepest inclination to the line of sight (rad, 78 degrees) at which the window of
 * a fit's cues (prepareFit: a lattice of pixels) still holds a point's k nearest points
 * (imageWindowRadius): all of a cylinder's side in the image but its outer 2% (1 - sin 78). */
constexpr float kFitCueInclination = 1.3614f;

/** \brief A lid fit (fitLidOf) is no lid when more of the frame's rays through its disc than
 * this see something behind it (seenThroughShare). */
constexpr float kMaxSeenThrough = 0.1f;

/** \brief The Hough settings of the recognizer: defaults, with the "mostly vertical" prior
 * (in the table frame), radii in [kDefaultRadiusMin, kDefaultRadiusMax] (0.01-0.25 m),
 * outward normals only, and the best candidate refined on its inliers alone
 * (point_candidates = 0): the decision (CylinderDecision) is calibrated on those fits, and a
 * refinement on the points can bend a cylinder around a box's edge, which the decision then
 * accepts (test_clutter, StackedCoaxialCylindersAndACanAgainstABox). */
inline HoughCylinderParameters
tabletopHoughDefaults()
{
  HoughCylinderParameters p;
  p.prior = OrientationPrior::Vertical; // expressed in the table frame (up = table normal)
  p.radius_min = static_cast<float>(kDefaultRadiusMin);
  p.radius_max = static_cast<float>(kDefaultRadiusMax);
  p.outward_normals = true; // objects on a table are seen from outside
  p.point_candidates = 0;
  return p;
}

/** \brief Settings of TabletopCylinderRecognizer. */
struct TabletopRecognizerParameters {
  TabletopSegmentationParameters segmentation;
  /** The fit's settings, the orientation prior (in the table frame), N_d and the seed
   * included. */
  HoughCylinderParameters hough{tabletopHoughDefaults()};
  CylinderDecision decision; ///< what makes a fitted object a cylinder
  /** When the fit with `prior` is not accepted, fit again with a lying (Horizontal) prior in
   * the table frame, then (objects on a support) upright: with the axis fixed along the
   * support's normal; and keep the best. */
  bool retry_upright_lying{true};
  /** With hough.outward_normals (the default), a last retry accepts inliers whose normals point
   * at the axis: clusters made of the inside of an open container are then fitted, and so are
   * the insides of bowls (see docs/tabletop.md for the trade-off). */
  bool retry_any_normal_sign{false};
  /** Cylinder-first recovery: when the best fit of a cluster explains less than
   * min_explained_share of its points (or is not accepted), the cluster may hold several
   * objects (touching, stacked): up to this many cylinders are extracted one after another,
   * each judged on the points around it, and each accepted one is reported as an object of
   * its own; the rest of the cluster is one more object. 1 turns the recovery off. */
  std::size_t max_cylinders_per_cluster{3};
  float min_explained_share{0.75f}; ///< in (0, 1]
  /** Stacked objects that one cylinder was fitted across (a can on a tin: the side is two
   * sections, findSectionStep): the cluster is cut at the step and each part recognized on its
   * own, when one of them is a cylinder; a part may be cut again, up to this many levels of
   * a stack (N - 1 cuts deep: 2 one cut, 3 a part of a cut cut once more). 1 turns it off;
   * in [1, 8]. */
  std::size_t max_stacked_objects{3};
  /** A cylinder found in a larger cluster is judged on the points within this distance (m,
   * at least; 15% of its radius beyond its surface, half its radius beyond its ends). */
  float recovery_margin{0.025f};
  /** The points fitted lie on a grid of directions from the sensor this many radians apart
   * (organized clouds searched as images: a lattice of pixels, pixelLattice, 3 pixels apart
   * at a 525 px focal length; other clouds: angularGrid), so normals and curvatures are
   * estimated at the same angular scale near and far; 0: every point. In [0, 0.1]. */
  float fit_point_angle{0.006f};
  /** Clusters are subsampled evenly to at most this many points (a wider lattice of pixels),
   * in [50, 1e6]. */
  std::size_t max_fit_points{1200};
  /** With a classifier: clusters whose network probability is below this are not fitted
   * (rejected before fitting, paper III-B), in [0, 1]. 0 (default): every cluster is fitted,
   * and the network is one piece of evidence beside the fit's (a network trained on one
   * sensor's views misjudges another's: docs/classifier.md). */
  float reject_below{0.f};
  int neighbours{kDefaultNeighbours}; ///< k of the normal/curvature estimation, in [5, 200]
  /** Clusters fitted at once, each thread with a cue estimation and estimators of its own;
   * threads that no cluster takes help with a cluster's cues and retries; the segmentation's
   * per-pixel passes run on as many while cores are idle (TabletopSegmentation::
   * setNumberOfThreads). 0 (default) the
   * hardware's concurrency, 1 the caller's thread alone; in [0, 64]. Waiting threads sleep
   * (parallelFor), and the results do not depend on it. */
  int threads{0};
};

/** \brief Checks \a params. \return an empty string, or what is wrong; \a rule, when given,
 * receives the rule broken alone (see settingProblem; empty for the segmentation's settings). */
std::string validate(const TabletopRecognizerParameters& params, std::string* rule = nullptr);

/** \brief One object on the table and what was decided about it. */
struct RecognizedObject {
  TabletopCluster cluster;   ///< the object's points, pixel box and centroid
  CylinderEvidence evidence; ///< what the decision looked at
  bool is_cylinder{false};   ///< the decision (acceptCylinder)
  /** The fitted cylinder (valid when evidence.fitted); its inliers index the input cloud and
   * come from the subsample that was fitted. */
  CylinderModel cylinder;
};

/** \brief Wall-clock time per stage of the last recognize() (ms), like the paper's Table III. */
struct RecognitionTiming {
  double segmentation{0.0};
  SegmentationTiming segmentation_steps; ///< the segmentation's own split
  double classification{0.0};
  double fitting{0.0};
  double total{0.0};
};

/** \brief The paper's tabletop framework (III-A): table and clusters (TabletopSegmentation), an
 * optional shape classifier, then a Hough cylinder fit per cluster (normals and curvatures by
 * NormalCurvatureEstimation, prior in the table frame) and the decision acceptCylinder (see
 * CylinderDecision).
 *
 * \code
 * facyl::TabletopCylinderRecognizer<pcl::PointXYZRGBA> rec;
 * rec.setInputCloud(cloud);
 * std::vector<facyl::RecognizedObject> objects;
 * if (rec.recognize(objects))
 *   for (const auto& o : objects) if (o.is_cylinder) use(o.cylinder);
 * \endcode
 * Errors (bad parameters, no cloud or an empty one) are reported with PCL_ERROR and make
 * recognize() return false with no objects. A frame without a table is no error:
 * recognize() returns true, tableFound() is false and the objects off any support are still
 * reported (see TabletopSegmentation). Without setClassifier the decision is the evidence
 * model's alone (facyl_detect --model none); facyl_detect loads the shipped network
 * (CylinderClassifier::defaultModelPath()). Each object's points are its cluster.indices
 * (into the input cloud). recognize() is not reentrant on one object;
 * distinct objects may run concurrently. Within recognize(), clusters are fitted on
 * TabletopRecognizerParameters::threads threads.
 */
template <typename PointT> class TabletopCylinderRecognizer : public pcl::PCLBase<PointT> {
public:
  using Ptr = std::shared_ptr<TabletopCylinderRecognizer<PointT>>;
  using ConstPtr = std::shared_ptr<const TabletopCylinderRecognizer<PointT>>;
  using PointCloud = pcl::PointCloud<PointT>;
  using pcl::PCLBase<PointT>::input_;
  using pcl::PCLBase<PointT>::indices_;
  using PointCloudConstPtr = typename PointCloud::ConstPtr;

  /** \brief All settings. */
  void setParameters(const TabletopRecognizerParameters& params)
  {
    params_ = params;
    configured_ = false;
  }
  const TabletopRecognizerParameters& getParameters() const
  {
    return params_;
  }
  /** \brief Optional classifier; nullptr (default): every cluster is fitted. */
  void setClassifier(const ShapeClassifier::Ptr& classifier)
  {
    classifier_ = classifier;
  }
  ShapeClassifier::Ptr getClassifier() const
  {
    return classifier_;
  }
  /** \brief Camera for boxes and crops of unorganized clouds. */
  void setCamera(const PinholeCamera& camera)
  {
    camera_ = camera;
  }
  /** \brief Gravity's opposite in the cloud's frame (see TabletopSegmentation::setUpDirection);
   * zero (default): unknown. */
  void setUpDirection(const Eigen::Vector3f& up)
  {
    up_ = up;
  }

  /** \brief Where the support of the last frames of a stream is expected in this cloud (see
   * TabletopSegmentation::setSupportPrior; in the cloud's frame); the default leaves every
   * frame to itself. CylinderTracker::prepare sets it. */
  void setSupportPrior(const SupportPrior& prior)
  {
    prior_ = prior;
  }
  const SupportPrior& getSupportPrior() const
  {
    return prior_;
  }
  /** \brief What the last run made of the support prior (TabletopSegmentation's). */
  const SupportPriorResult& getSupportPriorResult() const
  {
    return segmentation_.getSupportPriorResult();
  }

  /** \brief Runs the pipeline. \return false on error (see the class description). */
  bool recognize(std::vector<RecognizedObject>& objects);

  /** \brief Table plane of the last run (unit normal towards the sensor). */
  const pcl::ModelCoefficients& getTableCoefficients() const
  {
    return segmentation_.getTableCoefficients();
  }
  /** \brief Supports of the last run (RecognizedObject::cluster.support indexes them). */
  const std::vector<SupportPlane>& getSupports() const
  {
    return segmentation_.getSupports();
  }
  /** \brief False when no object stood on any plane in the last run: the "table" is then the
   * largest plane. */
  bool tableFound() const
  {
    return segmentation_.tableFound();
  }
  /** \brief Table frame of the last run (z up). */
  const Eigen::Affine3f& getTableFrame() const
  {
    return segmentation_.getTableFrame();
  }
  /** \brief Stage timing of the last run. */
  const RecognitionTiming& getTiming() const
  {
    return timing_;
  }

private:
  /** The points of a cluster that are fitted, with their cues. */
  struct FitInput;
  /** One fit of a FitInput and its evidence. */
  struct Fit;

  /** recognize() on a cloud in the sensor's frame (identity sensor pose); \a t0: its start. */
  bool recognizeInSensorFrame(std::vector<RecognizedObject>& objects,
                              std::chrono::steady_clock::time_point t0);
  /** Builds the fitters (one per thread of the fits). */
  void configure();
  /** What the classifier sees of the points \a indices: the image's pixels, or (an unorganized
   * cloud without a camera) a virtual camera's at the sensor origin (lookAtObjectView). */
  ObjectView viewOf(const pcl::Indices& indices) const;
  /** The classifier's network probability of each cluster (one batch); NaN without one. */
  std::vector<float> classifyClusters(const std::vector<TabletopCluster>& clusters);
  /** The objects [first, end) made of one cluster of network probability \a p_cluster: their
   * p_network (split parts: of their own view), p_cylinder (fused) and the decision. */
  void applyClassifier(std::vector<RecognizedObject>& objects, std::size_t first, float p_cluster);
  /** What fits one cluster at a time: the cue estimation and the estimators (one per prior of
   * the retries), configured alike; one per thread of the fits. */
  struct Fitter {
    NormalCurvatureEstimation<pcl::PointXYZ, NormalCurvature> cues;
    std::vector<HoughCylinderEstimation<pcl::PointXYZ, NormalCurvature>> estimators;
    std::size_t upright{0};   ///< index of the estimator with the axis along the support's normal
    bool with_support{false}; ///< the cluster being fitted has a support
    Eigen::Vector3f up{Eigen::Vector3f::UnitZ()}; ///< z of the prior frame (usePriorFrameOf)
    Eigen::Vector4f support_plane{Eigen::Vector4f::Zero()}; ///< the support's, with_support
    int retry_threads{1}; ///< threads that run a cluster's first fit and retries at once
  };
  /** Builds a fitter from the settings. */
  std::unique_ptr<Fitter> makeFitter() const;
  /** Sets the prior frame of \a fitter's estimators to that of support \a support (-1: none). */
  void usePriorFrameOf(Fitter& fitter, int support) const;
  /** recognizeCluster for every cluster that the classifier does not reject before fitting
   * (p_network below reject_below: one object, not fitted), on params_.threads threads (one
   * fitter each, largest cluster first): the objects of cluster k in element k. Sets
   * timing_.fitting (0 when no cluster is fitted). */
  std::vector<std::vector<RecognizedObject>> fitClusters(std::vector<TabletopCluster>& clusters,
                                                         const std::vector<float>& p_network);
  /** Joins each object that is a part of another's cylinder (cylinder_parts.h: the inside of
   * an open container, cut off at its rim; a small fragment beside it, a mug's handle; an end
   * set into its rim, a tin's lid) to that one, which keeps its fit and is classified again
   * as a whole. */
  void joinCylinderParts(std::vector<RecognizedObject>& objects);
  /** About 200 of \a indices' points (organized input), each with its normal from the pixel
   * grid (NaN where unknown), as columns. */
  void sampleWithNormals(const pcl::Indices& indices, Eigen::Matrix3Xf& points,
                         Eigen::Matrix3Xf& normals) const;
  /** Subsamples \a cluster and estimates normals and curvatures (with \a fitter). The fitting
   * functions below change only their fitter: threads with fitters of their own may run them
   * at once. */
  FitInput prepareFit(Fitter& fitter, const TabletopCluster& cluster) const;
  /** in.points: the input's points at in.subset. */
  void copySubset(FitInput& in) const;
  /** Fits the points of \a input flagged in \a alive (all when empty) with the configured
   * prior, then (when not accepted) the retries. The evidence is relative to those points. */
  Fit fitWithRetries(Fitter& fitter, const FitInput& input,
                     const std::vector<std::uint8_t>& alive) const;
  Fit fitOnce(Fitter& fitter, const FitInput& input, const std::vector<std::uint8_t>& alive,
              std::size_t estimator) const;
  /** The cylinder of \a cluster's lid alone (fitLid), on objects with a support in organized
   * clouds: an upright object seen from above. Not fitted when there is no lid, or the frame
   * sees through its disc (seenThroughShare above kMaxSeenThrough). */
  Fit fitLidOf(const Fitter& fitter, const TabletopCluster& cluster, const FitInput& input) const;
  /** The points of the organized input around pixel box \a box (grown by half its size each
   * way, every other pixel), as columns. */
  Eigen::Matrix3Xf pointsAround(const PixelBox& box) const;
  /** Whether retry \a estimator would look where \a fit's axis already is (retryRepeats). */
  bool retryRepeats(const Fitter& fitter, std::size_t estimator, const Fit& fit) const;
  /** Fits and decides one cluster: one object, or several (recovery); the classifier's
   * probability \a p_network asks for the recovery when in doubt (applyClassifier judges the
   * objects). */
  void recognizeCluster(Fitter& fitter, TabletopCluster cluster, float p_network,
                        std::vector<RecognizedObject>& objects) const;
  /** recognizeCluster for a cluster that may be cut \a stacked - 1 levels deep (splitStack) and
   * yield up to \a cylinders cylinders by recovery (extractCylinders; 1: no recovery). */
  void recognizeStack(Fitter& fitter, TabletopCluster cluster, float p_network, std::size_t stacked,
                      std::size_t cylinders, std::vector<RecognizedObject>& objects) const;
  /** Where \a fit's side shows two stacked objects, along its axis from its base: a step
   * between two sections (findSectionStep), else a lid inside its extent (interiorLid), else,
   * when \a fit explains less than min_explained_share of the cluster, where its side stops
   * being a circle and shows a box's faces (findSectionEnd); NaN: none. */
  float stackCut(const FitInput& input, const Fit& fit) const;
  /** When \a fit's side shows two stacked objects (stackCut): \a whole cut there, each part
   * recognized (recognizeStack, \a stacked - 1 levels) and appended to \a objects
   * when one of them is a cylinder. \return whether it was cut. */
  bool splitStack(Fitter& fitter, const RecognizedObject& whole, const FitInput& input,
                  const Fit& fit, float p_network, std::size_t stacked,
                  std::vector<RecognizedObject>& objects) const;
  /** A cluster of \a indices (ascending) cut from \a whole: its support, centroid and box. */
  TabletopCluster partOf(const TabletopCluster& whole, pcl::Indices indices) const;
  /** Cylinder-first recovery: up to \a cylinders cylinders of a cluster, one after another,
   * starting with its best fit. */
  std::vector<Fit> extractCylinders(Fitter& fitter, const FitInput& input, Fit first,
                                    std::size_t cylinders) const;
  /** Least squares of \a model on the cluster's points (\a indices) near its surface: every
   * pixel of the \a stride x \a stride cells of its inliers (the fit's lattice; organized
   * clouds, stride > 1). */
  void refineOnAllPoints(const pcl::Indices& indices, int stride, CylinderModel& model) const;
  /** Which points a fitted cylinder explains, from the recognizer's settings. */
  ExplainSettings explainSettings(const CylinderModel& model) const;
  /** The cluster split into one object per cylinder that keeps points of its own (pointOwners,
   * appended to \a objects) and the rest: \a rest receives its indices (ascending) when it is an
   * object of its own, else none (a small rest goes to the first cylinder's object).
   * \return false, appending nothing, when no cylinder keeps enough points. */
  bool splitCluster(const RecognizedObject& whole, const FitInput& input,
                    const std::vector<Fit>& parts, std::vector<RecognizedObject>& objects,
                    pcl::Indices& rest) const;

  TabletopRecognizerParameters params_;
  PinholeCamera camera_;
  Eigen::Vector3f up_{Eigen::Vector3f::Zero()};
  SupportPrior prior_;
  ShapeClassifier::Ptr classifier_;
  TabletopSegmentation<PointT> segmentation_;
  /** What segmentation_ was last given by setIndices (none at first, as it starts): given
   * again only when it changes, so that the segmentation keeps the index list it makes of a
   * whole frame (else made again at every frame: 1.2 MB zeroed and numbered at VGA). */
  pcl::IndicesConstPtr segmentation_indices_;
  RecognitionTiming timing_;
  bool configured_{false};
  std::vector<std::unique_ptr<Fitter>> fitters_; ///< one per thread of the fits
};

/* The recognizer's cylinders follow orientCylinder (cylinder_model.h) with \a up the support's
 * normal (without a support, an upright camera's up: against the image rows). */

/** \brief Evenly spaced subsample of \a indices of at most \a max_count elements (all of them
 * when there are fewer). */
pcl::Indices evenSubsample(const pcl::Indices& indices, std::size_t max_count);

/** \brief A lattice of the pixels of an organized cloud \a width pixels wide, \a spacing (>= 1)
 * pixels apart: pixel (u, v) is in lattice cell (floor(u / spacing), floor(v / spacing)), and
 * of \a indices those first in their cell's column and row are kept (an integer spacing keeps
 * the columns and rows that are its multiples). */
struct PixelLattice {
  float spacing{1.f};
  pcl::Indices pixels;      ///< the pixels kept, in the order of the indices given
  int columns{0}, rows{0};  ///< cells of the lattice's bounding box
  std::vector<int> cell_of; ///< per pixel kept, its cell in that box (row by row)
};

/** \brief The PixelLattice of \a indices (of a cloud \a width pixels wide) at \a spacing, widened
 * (by factors of at least 1.05) until it keeps at most \a max_count pixels (>= 1). */
PixelLattice pixelLattice(const pcl::Indices& indices, std::uint32_t width, float spacing,
                          std::size_t max_count);

/** \brief \a lattice as an organized cloud of its columns x rows cells: \a points (one per
 * pixel kept, in its order) each at its cell, the other cells not finite.
 * \throws std::invalid_argument if the sizes differ. */
pcl::PointCloud<pcl::PointXYZ>::Ptr latticeCloud(const PixelLattice& lattice,
                                                 const pcl::PointCloud<pcl::PointXYZ>& points);

/** \brief Of \a indices (with their coordinates \a points, one column each, in the sensor's
 * frame), the first in each cell of a grid of directions from the sensor \a angle (rad) apart
 * (azimuth about the image's y axis, elevation from the x-z plane): what pixelLattice keeps of an
 * organized cloud, for a cloud without pixels. All of them for \a angle <= 0; points that are
 * not finite are left out. */
pcl::Indices angularGrid(const pcl::Indices& indices, const Eigen::Matrix3Xf& points, float angle);

} // namespace facyl

#define FACYL_INSTANTIATE_TabletopCylinderRecognizer(T)                                            \
  template class facyl::TabletopCylinderRecognizer<T>;

#ifdef PCL_NO_PRECOMPILE
#include <facyl/recognition/impl/tabletop_cylinder_recognizer.hpp>
#endif
