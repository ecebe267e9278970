/*
 * facyl: fast cylinder detection for PCL.
 * What decides that a fitted object is a cylinder: the evidence of a fit and the one rule
 * (acceptCylinder) that the recognizer, the tools and the evaluators all call.
 */
#pragma once

#include <facyl/features/point_types.h>
#include <facyl/recognition/shape_evidence.h>
#include <facyl/sample_consensus_alt/cylinder_model.h>

#include <pcl/point_cloud.h>
#include <pcl/types.h>

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace facyl {

/** \brief Number of features of the evidence model (see evidenceFeatures). */
constexpr std::size_t kEvidenceFeatures = 20;
/** \brief Where the lid fits' features begin (see evidenceFeatures). */
constexpr std::size_t kLidFeaturesBegin = 14;
/** \brief Features of a model fitted before lid fits (CylinderEvidence::from_lid): the side's
 * and the network's logit, without the lid's (ClassifierModelInfo reads them). */
constexpr std::size_t kSideOnlyEvidenceFeatures = 15;

/** \brief Weights of the evidence model without a network: a logistic regression of
 * evidenceFeatures fitted by recognition/training/fit_evidence.py on simulated and real labelled
 * objects (docs/classifier.md, "The evidence model"); the network's weight is 0. */
constexpr std::array<float, kEvidenceFeatures> kGeometryWeights = {
  1.82662f,   0.843052f, 0.f,      -4.29659f, 0.f, -6.95642f, 0.f,
  -0.203624f, -3.09661f, 0.f,      -6.38006f, 0.f, -2.86157f, -6.59634f,
  -7.37701f,  6.78661f,  1.34869f, -33.3564f, 0.f, 0.f};

/** \brief The decision rule's settings. */
struct CylinderDecision {
  /** The fit score: the paper's inlier ratio (eq. 4), or the surface ratio, which also counts
   * the points on the fitted cylinder's end caps and inner wall as explained. */
  enum class Score { InlierRatio, SurfaceRatio } score{Score::SurfaceRatio};
  /** Score at least this, in [0, 1]: a floor, not the decision. The evidence model weighs the
   * surface ratio itself; below a quarter of its points explained a fit is not the object's
   * shape. Leave-one-source-out (fit_evidence.py, docs/classifier.md): with the floor at half
   * the points (0.5, before) the worst source (UW crops) had F1 0.46, anywhere in [0.2, 0.4]
   * 0.71-0.75; at 0.25 no real source loses a cylinder or gains a false positive. */
  float min_score{0.25f};
  /** p_cylinder at least this, in [0, 1]. p_cylinder is the calibrated probability of the
   * evidence model (a logistic regression of the fit's evidence, and of the network's output
   * when there is a classifier), so 0.5 calls an object a cylinder when that is the likelier
   * answer. */
  float min_probability{0.5f};
  /** The inliers' curvature ratio at most this, in (0, 1]; 1 turns the check off. Rejects
   * most spheres and bowls. */
  float max_curvature_ratio{0.35f};
  /** The inliers cover at least this share of the circumference, in [0, 1] (a camera sees
   * about half of a cylinder; a large cylinder fitted to a shallow arc covers less). */
  float min_angular_coverage{0.2f};
  /** The largest gap inside the arc of the circumference that the inliers span, as a share
   * of the circumference, at most this (when known: cylinders found inside larger clusters).
   * A thin cylinder fitted to the edge of a box has inliers only near its two tangent lines. */
  float max_arc_gap{0.1f};
  /** The surface's radius changes along the axis by at most this much per unit of length
   * (tan of the half-angle: 0.15 is 8.5 degrees): a cylinder fits a band of a cone, but the
   * cone's radius keeps changing beyond it. Slightly tapered cups pass; 1 turns it off. */
  float max_taper{0.15f};
  /** The evidence model without a network (see kGeometryWeights). */
  std::array<float, kEvidenceFeatures> geometry_weights{kGeometryWeights};
};

/** \brief Checks \a decision. \return an empty string, or what is wrong; \a rule, when given,
 * receives the rule broken alone (see settingProblem). */
std::string validate(const CylinderDecision& decision, std::string* rule = nullptr);

/** \brief What the decision looks at for one object. */
struct CylinderEvidence {
  bool fitted{false}; ///< a cylinder was fitted
  /** Fitted to its lid alone (fitLid): an upright object seen from above, whose side shows
   * too little for the Hough; angular_coverage is then the lid's rim seen. */
  bool from_lid{false};
  /** A lid fit's disc: the share of the frame's rays through it that see farther
   * (seenThroughShare); NaN for other fits. */
  float seen_through{std::numeric_limits<float>::quiet_NaN()};
  /** The probability that the object is a cylinder: with a classifier, its network's output
   * for the object's view fused with this evidence (ShapeClassifier::fuse; the network's alone
   * when the object was not fitted); NaN without a classifier. */
  float p_cylinder{std::numeric_limits<float>::quiet_NaN()};
  /** The classifier network's output for the object's view; NaN without a classifier. */
  float p_network{std::numeric_limits<float>::quiet_NaN()};
  float inlier_ratio{0.f}; ///< paper eq. 4 on the points fitted
  /** (lateral inliers + points on the end caps + points on the inner wall of an open
   * container) / points fitted */
  float surface_ratio{0.f};
  /** Median |k_min| / median |k_max| over the lateral inliers: near 0 on a cylinder, near 1
   * on a sphere or bowl; NaN when unknown. */
  float curvature_ratio{std::numeric_limits<float>::quiet_NaN()};
  float angular_coverage{0.f}; ///< share of the circumference with inliers
  /** Largest empty arc inside the span of the inliers, share of the circumference; NaN when
   * unknown. */
  float arc_gap{std::numeric_limits<float>::quiet_NaN()};
  /** |d radius / d axial position| of the side surface around the fit (0 on a cylinder,
   * tan(half-angle) on a cone); NaN when unknown. */
  float taper{std::numeric_limits<float>::quiet_NaN()};
  /** What the points say about the shape they come from (see ShapeEvidence): normal
   * agreement and concentration, the profile's range, the axis's bend, the shares inside and
   * outside; NaN when unknown. */
  ShapeEvidence shape{
    std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::quiet_NaN(),
    std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::quiet_NaN(),
    std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::quiet_NaN(),
    std::numeric_limits<float>::quiet_NaN()};

  /** \brief The score \a decision uses. */
  float score(const CylinderDecision& decision) const
  {
    return decision.score == CylinderDecision::Score::SurfaceRatio ? surface_ratio : inlier_ratio;
  }
};

/** \brief The gates of the decision: fitted, score >= min_score, curvature ratio <=
 * max_curvature_ratio (when known), angular coverage >= min_angular_coverage, arc gap <=
 * max_arc_gap and taper <= max_taper (both when known). The evidence model decides among the
 * fits that pass them. */
bool passesGates(const CylinderEvidence& evidence, const CylinderDecision& decision);

/** \brief What the evidence model sees of a fitted object: 1; then a side's fit's features,
 * 0 for a lid fit: surface ratio, inlier ratio, curvature ratio (1 when unknown), angular
 * coverage, taper clamped to [0, 1] (0 when unknown), arc gap (0 when unknown), normal
 * agreement clamped to [0, 4] (4 when unknown), normal concentration (1 when unknown), profile
 * range and axis bend clamped to [0, 1] (0 when unknown), inner share and outside share (0 when
 * unknown), the inner share of a shallow container (inner share x clamp(1 - aspect, 0, 1): a
 * bowl's inside; a cup is deeper than its radius); from kLidFeaturesBegin a lid fit's, 0 for a
 * side's fit: 1, surface ratio, angular coverage (its rim seen), seen through and outside share
 * (0 when unknown); last logit(p_network) (p clamped to [1e-4, 1 - 1e-4]; 0 without a network).
 * The two kinds of fit are two models in one: a lid's evidence means other things than a
 * side's. */
std::array<float, kEvidenceFeatures> evidenceFeatures(float p_network,
                                                      const CylinderEvidence& evidence);

/** \brief 1 / (1 + exp(-w . evidenceFeatures(p_network, evidence))). */
float evidenceProbability(const std::array<float, kEvidenceFeatures>& weights, float p_network,
                          const CylinderEvidence& evidence);

/** \brief The probability of the evidence model without a network (decision.geometry_weights);
 * 0 for an object that was not fitted. */
float geometricProbability(const CylinderEvidence& evidence, const CylinderDecision& decision);

/** \brief The decision without a network: passesGates and geometricProbability >=
 * min_probability. What the recognizer judges its fits by before the classifier has spoken. */
bool acceptGeometry(const CylinderEvidence& evidence, const CylinderDecision& decision);

/** \brief The decision: passesGates, and p_cylinder >= min_probability (p_cylinder when known,
 * else geometricProbability). */
bool acceptCylinder(const CylinderEvidence& evidence, const CylinderDecision& decision);

/** \brief Median |k_min| / median |k_max| of \a cues over \a inliers (indices into cues):
 * 0 on an ideal cylinder, 1 on a sphere. NaN when no inlier has finite curvatures; 1 when the
 * median |k_max| is 0. */
float curvatureRatio(const pcl::PointCloud<NormalCurvature>& cues, const pcl::Indices& inliers);

/** \brief True if \a p (unit normal \a n) lies on an end cap of \a model: within
 * max(\a distance, 0.1 x radius) of the plane through model.base or model.top normal to the
 * axis (lids sit a little below a can's rim), at most radius + \a distance from the axis,
 * with a normal within acos(\a cos_max) of the axis. */
bool onCap(const CylinderModel& model, const Eigen::Vector3f& p, const Eigen::Vector3f& n,
           float distance, float cos_max);

/** \brief True if \a p (unit normal \a n) lies on the inner wall of \a model seen as an open
 * container (a cup's inside, seen through its opening): between inner_ratio x radius and the
 * radius from the axis, within the axial extent, with a normal within acos(\a cos_max) of
 * pointing at the axis. */
bool onInnerWall(const CylinderModel& model, const Eigen::Vector3f& p, const Eigen::Vector3f& n,
                 float cos_max, float inner_ratio);

/** \brief Number of \a points (3 x n, unit \a normals alongside) on an end cap of \a model
 * (onCap with cos(max_angle)). Points listed in model.inliers (column indices, ascending) are
 * not counted. */
std::size_t countCapPoints(const CylinderModel& model, const Eigen::Matrix3Xf& points,
                           const Eigen::Matrix3Xf& normals, float distance, float max_angle);

/** \brief Number of \a points (with unit \a normals) on the inner wall of \a model
 * (onInnerWall with cos(max_angle)). Points in model.inliers are not counted. */
std::size_t countInnerWallPoints(const CylinderModel& model, const Eigen::Matrix3Xf& points,
                                 const Eigen::Matrix3Xf& normals, float max_angle,
                                 float inner_ratio);

/** \brief Which points a cylinder explains, for handing a cylinder found in a larger cluster
 * its own points. */
struct ExplainSettings {
  float distance{0.005f};    ///< lateral: |distance to the surface| at most this; caps: 2x
  float max_angle{0.6f};     ///< rad: normal vs the surface's normal (lateral, caps)
  bool outward{true};        ///< lateral normals must point away from the axis
  bool inner_wall{true};     ///< count the inner wall of an open container
  float inner_ratio{0.8f};   ///< see onInnerWall
  float axial_margin{0.01f}; ///< lateral points may lie this far beyond base and top
};

/** \brief What a cylinder explains a point as. */
enum class Explained : std::uint8_t { No = 0, Lateral, Cap, InnerWall };

/** \brief For each column of \a points: on \a model's lateral surface (within its axial
 * extent grown by the margin), on an end cap, on its inner wall, or none of them.
 * \param normals unit normals alongside the points, or an empty matrix: every point is then
 *        judged by its position alone. */
std::vector<Explained> explainedPoints(const CylinderModel& model, const Eigen::Matrix3Xf& points,
                                       const Eigen::Matrix3Xf& normals,
                                       const ExplainSettings& settings);

/** \brief Which of several cylinders owns each point, given what each explains
 * (\a explained: one explainedPoints list per cylinder, all as long as the points). In order,
 * each cylinder takes the points it explains that no cylinder before it took; one left with
 * fewer than \a min_points (those before it explain its surface: two fits of one object) takes
 * none, as if it were not there, and is not \a kept. \return per point the index of its
 * cylinder, -1 where none took it. \throws std::invalid_argument when the lists' lengths
 * differ. */
std::vector<int> pointOwners(const std::vector<std::vector<Explained>>& explained,
                             std::size_t min_points, std::vector<bool>& kept);

/** \brief How the radius of the side surface around \a model changes along its axis:
 * |slope| of a robust line fit of the distance to the axis against the position along it, over
 * the columns of \a points (flagged in \a alive; all when empty) between 0.5 and 1.5 radii
 * from the axis whose normals are within 45 degrees of perpendicular to it (the side, not the
 * lids), less two standard errors of that slope (at least 0): only a taper the points show.
 * About 0 on a cylinder, tan(half-angle) on a cone seen along enough of its height. NaN with
 * fewer than 20 such points or no axial spread.
 * \param normals unit normals alongside the points */
float taperAlongAxis(const CylinderModel& model, const Eigen::Matrix3Xf& points,
                     const Eigen::Matrix3Xf& normals, const std::vector<std::uint8_t>& alive);

/** \brief How a part of a cluster meets the rest: over the pairs (a point of the part, a
 * point of the rest) closer than \a distance, the share that is clearly convex, by the
 * criterion of LCCP (Stein et al. 2014): (n_a - n_b) . (a - b) >= tolerance |a - b|. Objects
 * that touch meet at a concave crease, tangentially, or not at all; a part of one object can
 * continue into the rest convexly (a box edge into its faces). NaN when no pair is that
 * close.
 * \param part,rest column indices into \a points (unit \a normals alongside) */
float convexJunctionShare(const Eigen::Matrix3Xf& points, const Eigen::Matrix3Xf& normals,
                          const std::vector<Eigen::Index>& part,
                          const std::vector<Eigen::Index>& rest, float distance, float tolerance);

/** \brief Largest empty arc inside the span of \a points (3 x n) around \a model's axis, as a
 * share of the circumference, on 36 sectors (a sector holds at least 2 points to count): 0
 * for a contiguous arc, larger where the points sit at two separate angles. 0 for fewer than
 * 2 occupied sectors. */
float arcGap(const CylinderModel& model, const Eigen::Matrix3Xf& points);

/** \brief The sector, of \a sectors equal ones counted from the direction -x round through -y,
 * that the direction (\a x, \a y) lies in: in [0, sectors). What arcGap and the lid's rim
 * (fitLid, walledShare) count sectors by. */
std::size_t circleSector(float x, float y, int sectors);

/** \brief Evidence for a cylinder found inside a larger cluster, judged on the points around
 * it: its region holds the columns of \a points flagged in \a alive (all when empty) within
 * radius + max(radial_margin x radius, margin) + 2 x distance of the axis and within
 * max(axial_margin x radius, margin) beyond base and top. surface_ratio is the share of the region
 * it explains, inlier_ratio the share on its lateral surface; angular_coverage is the model's,
 * curvature_ratio is left NaN (the caller knows the curvatures). A sphere's band or a cone's,
 * fitted by a cylinder, leaves the rest of the sphere or cone inside the region unexplained; so
 * does a thin cylinder fitted to the edge of a box, with the faces beyond the edge (hence the
 * absolute margin). Points whose normal lies along the axis (the box a can stands on) are left out
 * of the region. \param[out] explained when given, the explanation of every column (alive or not).
 */
CylinderEvidence localEvidence(const CylinderModel& model, const Eigen::Matrix3Xf& points,
                               const Eigen::Matrix3Xf& normals,
                               const std::vector<std::uint8_t>& alive,
                               const ExplainSettings& settings, float radial_margin,
                               float axial_margin, float margin,
                               std::vector<Explained>* explained = nullptr,
                               const Eigen::VectorXf& scatter = Eigen::VectorXf());

/** \brief Share of \a points (3 x n) inside the volume of \a model: within \a radial_factor x
 * radius of its axis and between base and top grown by \a axial_margin (m). The inside of an
 * open container (a cup, a bowl) seen through its opening lies inside the cylinder fitted to
 * its outer wall; an object behind or beside it does not. 0 for no points. */
float shareInside(const CylinderModel& model, const Eigen::Matrix3Xf& points, float radial_factor,
                  float axial_margin);

} // namespace facyl
