/*
 * facyl: fast cylinder detection for PCL.
 */
#pragma once

#include <facyl/recognition/shape_classifier.h>
#include <facyl/sample_consensus_alt/cylinder_fitting.h>
#include <facyl/sample_consensus_alt/cylinder_model.h>
#include <facyl/sample_consensus_alt/orientation_accumulator.h>
#include <facyl/segmentation/tabletop_segmentation.h>

#include <pcl/ModelCoefficients.h>
#include <pcl/pcl_base.h>
#include <pcl/point_cloud.h>

#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace facyl {

/** \brief The Hough settings of the recognizer: defaults, with radii in [0.01, 0.25] m and
 * outward normals only. */
inline HoughCylinderParameters
tabletopHoughDefaults()
{
  HoughCylinderParameters p;
  p.radius_min = 0.01f;
  p.radius_max = 0.25f;
  p.outward_normals = true; // objects on a table are seen from outside
  return p;
}

/** \brief Settings of TabletopCylinderRecognizer. */
struct TabletopRecognizerParameters {
  TabletopSegmentationParameters segmentation;
  HoughCylinderParameters hough{tabletopHoughDefaults()};
  /** Orientation prior, expressed in the table frame (up = table normal). */
  OrientationPrior prior{OrientationPrior::Vertical};
  std::size_t orientations{450};  ///< accumulator cells N_d, >= 10
  /** When the fit with `prior` is not accepted, fit again with an upright (VerticalStrong) and
   * a lying (Horizontal) prior in the table frame and keep the best. */
  bool retry_upright_lying{true};
  /** With hough.outward_normals (the default), a last retry accepts inliers whose normals point
   * at the axis: clusters made of the inside of an open container are then fitted, and so are
   * the insides of bowls (see docs/tabletop.md for the trade-off). */
  bool retry_any_normal_sign{false};
  std::size_t max_fit_points{1200}; ///< clusters are subsampled evenly to this many points, >= 50
  int neighbours{16};             ///< k of the normal/curvature estimation, >= 5
  /** Decision score: the inlier ratio of eq. 4 (the paper), or the surface ratio, which also
   * counts the points on the fitted cylinder's end caps (lids) as explained. */
  enum class Score { InlierRatio, SurfaceRatio } score{Score::SurfaceRatio};
  float min_inlier_ratio{0.5f};   ///< decision: score at least this, in [0, 1]
  float min_probability{0.5f};    ///< decision: classifier probability at least this, in [0, 1]
  /** Decision: the inliers' curvature ratio (RecognizedObject::curvature_ratio) at most this,
   * in (0, 1]; 1 turns the check off. Rejects most spheres and bowls. */
  float max_curvature_ratio{0.35f};
  /** Decision: the inliers cover at least this share of the circumference (a camera sees about
   * half of a cylinder), in [0, 1]; a large cylinder fitted to a shallow arc covers less. */
  float min_angular_coverage{0.2f};
  std::uint64_t seed{0};
};

/** \brief Checks \a params. \return an empty string, or what is wrong. */
std::string
validate(const TabletopRecognizerParameters& params);

/** \brief One object on the table and what was decided about it. */
struct RecognizedObject {
  TabletopCluster cluster;
  /** Classifier probability of "cylinder"; NaN without a classifier (or when it cannot tell). */
  float p_cylinder{std::numeric_limits<float>::quiet_NaN()};
  bool fitted{false};       ///< a cylinder was fitted (not rejected by the classifier, fit found)
  float inlier_ratio{0.f};  ///< paper eq. 4 on the points fitted; 0 when not fitted
  /** (lateral inliers + points on the end caps + points on the inner wall of an open
   * container) / points fitted */
  float surface_ratio{0.f};
  /** Median |k_min| / median |k_max| over the lateral inliers: near 0 on a cylinder, near 1 on
   * a sphere or bowl; NaN when not fitted. */
  float curvature_ratio{std::numeric_limits<float>::quiet_NaN()};
  bool is_cylinder{false};  ///< the decision
  /** The fitted cylinder (valid when fitted); its inliers index the input cloud and come from
   * the subsample that was fitted. */
  CylinderModel cylinder;
};

/** \brief Wall-clock time per stage of the last recognize() (ms), like the paper's Table III. */
struct RecognitionTiming {
  double segmentation{0.0};
  double classification{0.0};
  double fitting{0.0};
  double total{0.0};
};

/** \brief The paper's tabletop framework (III-A): table and clusters (TabletopSegmentation), an
 * optional shape classifier, then a Hough cylinder fit per cluster (normals and curvatures by
 * NormalCurvatureEstimation, prior in the table frame) and the decision
 * `p_cylinder >= min_probability` (when classified), `score >= min_inlier_ratio` (score: eq. 4
 * inlier ratio, or the surface ratio), `curvature_ratio <= max_curvature_ratio` and
 * `cylinder.angular_coverage >= min_angular_coverage`.
 *
 * \code
 * facyl::TabletopCylinderRecognizer<pcl::PointXYZRGBA> rec;
 * rec.setInputCloud(cloud);
 * std::vector<facyl::RecognizedObject> objects;
 * if (rec.recognize(objects))
 *   for (const auto& o : objects) if (o.is_cylinder) use(o.cylinder);
 * \endcode
 * Errors (bad parameters, no cloud, no table) are reported with PCL_ERROR and make
 * recognize() return false with no objects.
 */
template <typename PointT>
class TabletopCylinderRecognizer : public pcl::PCLBase<PointT> {
public:
  using Ptr = std::shared_ptr<TabletopCylinderRecognizer<PointT>>;
  using ConstPtr = std::shared_ptr<const TabletopCylinderRecognizer<PointT>>;
  using PointCloud = pcl::PointCloud<PointT>;
  using pcl::PCLBase<PointT>::input_;
  using pcl::PCLBase<PointT>::indices_;

  /** \brief All settings. */
  void
  setParameters(const TabletopRecognizerParameters& params)
  {
    params_ = params;
  }
  const TabletopRecognizerParameters&
  getParameters() const
  {
    return params_;
  }
  /** \brief Optional classifier; nullptr (default): every cluster is fitted. */
  void
  setClassifier(const ShapeClassifier::Ptr& classifier)
  {
    classifier_ = classifier;
  }
  ShapeClassifier::Ptr
  getClassifier() const
  {
    return classifier_;
  }
  /** \brief Camera for boxes and crops of unorganized clouds. */
  void
  setCamera(const PinholeCamera& camera)
  {
    camera_ = camera;
  }

  /** \brief Runs the pipeline. \return false on error (see the class description). */
  bool
  recognize(std::vector<RecognizedObject>& objects);

  /** \brief Table plane of the last run (unit normal towards the sensor). */
  const pcl::ModelCoefficients&
  getTableCoefficients() const
  {
    return segmentation_.getTableCoefficients();
  }
  /** \brief Table frame of the last run (z up). */
  const Eigen::Affine3f&
  getTableFrame() const
  {
    return segmentation_.getTableFrame();
  }
  /** \brief Stage timing of the last run. */
  const RecognitionTiming&
  getTiming() const
  {
    return timing_;
  }

private:
  ObjectView
  makeView(const TabletopCluster& cluster) const;

  TabletopRecognizerParameters params_;
  PinholeCamera camera_;
  ShapeClassifier::Ptr classifier_;
  TabletopSegmentation<PointT> segmentation_;
  RecognitionTiming timing_;
};

/** \brief Number of \a points (3 x n, unit \a normals alongside) that lie on an end cap of
 * \a model: within \a distance of the plane through model.base or model.top normal to the axis,
 * at most radius + distance from the axis, with a normal within \a max_angle (rad) of the axis.
 * Points listed in model.inliers (column indices, ascending) are not counted. */
std::size_t
countCapPoints(const CylinderModel& model, const Eigen::Matrix3Xf& points,
               const Eigen::Matrix3Xf& normals, float distance, float max_angle);

/** \brief Number of \a points (with unit \a normals) on the inner wall of \a model seen as an
 * open container (a cup's inside, seen through its opening): between inner_ratio x radius and
 * the radius from the axis, within the axial extent of the model, with a normal within
 * \a max_angle (rad) of pointing at the axis. Points in model.inliers are not counted. */
std::size_t
countInnerWallPoints(const CylinderModel& model, const Eigen::Matrix3Xf& points,
                     const Eigen::Matrix3Xf& normals, float max_angle, float inner_ratio);

/** \brief Evenly spaced subsample of \a indices of at most \a max_count elements (all of them
 * when there are fewer). */
pcl::Indices
evenSubsample(const pcl::Indices& indices, std::size_t max_count);

} // namespace facyl

#define FACYL_INSTANTIATE_TabletopCylinderRecognizer(T)                                     \
  template class facyl::TabletopCylinderRecognizer<T>;

#ifdef PCL_NO_PRECOMPILE
#include <facyl/recognition/impl/tabletop_cylinder_recognizer.hpp>
#endif
