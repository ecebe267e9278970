/*
 * facyl: fast cylinder detection for PCL.
 * The numerics of CylinderTracker as free functions on Eigen data, so that tests reach them:
 * the in-plane registration of a frame's support against the tracks, the association cost and
 * the assignment, the robust filters of position, axis, radius and extent, and the confidence
 * update.
 */
#pragma once

#include <Eigen/Geometry>

#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

namespace facyl {

// ------------------------------------------------------------------ in-plane registration

/** \brief A rigid motion of a plane about its normal (z): a rotation by \a yaw (rad) about z,
 * then a translation \a t in the plane. Heights (z) are left alone. */
struct PlanarRigid {
  float yaw{0.f};
  Eigen::Vector2f t{Eigen::Vector2f::Zero()};

  /** \brief The point \a p moved. */
  Eigen::Vector2f apply(const Eigen::Vector2f& p) const
  {
    const float c = std::cos(yaw), s = std::sin(yaw);
    return {c * p.x() - s * p.y() + t.x(), s * p.x() + c * p.y() + t.y()};
  }
  /** \brief The same motion in 3-D (about the z axis). */
  Eigen::Affine3f asAffine() const;
};

/** \brief The in-plane part of \a m, a transform between two frames whose z axes should agree
 * (support frames): the yaw of the image of x projected on the xy plane, and the x, y of the
 * translation. Exact when \a m is a PlanarRigid; the closest in-plane motion otherwise (the
 * rest, a tilt and a height, is what re-anchoring on the support plane removes). */
PlanarRigid inPlaneComponent(const Eigen::Affine3f& m);

/** \brief Weighted least-squares rigid motion (2-D Procrustes, Umeyama 1991 without scale)
 * taking the columns of \a from onto those of \a to, with \a weights (>= 0, same count). With
 * fewer than two points of positive weight, or points that all coincide, the rotation cannot be
 * observed: \a fallback_yaw is kept and only the translation is fitted (the identity
 * translation when no weight is positive). */
PlanarRigid fitPlanarRigid(const Eigen::Matrix2Xf& from, const Eigen::Matrix2Xf& to,
                           const Eigen::VectorXf& weights, float fallback_yaw);

/** \brief A possible correspondence between observation \a object and track \a track, with
 * the \a weight its agreement earns (a fitted cylinder's axis is a better landmark than the
 * centroid of a box's visible faces) and the distance \a tolerance (m) within which it agrees. */
struct RegistrationCandidate {
  int object{0};
  int track{0};
  float weight{1.f};
  float tolerance{0.02f};
};

/** \brief Settings of registerInPlane. */
struct RegistrationSettings {
  /** Correspondences farther apart than this under the prior (m) are not candidates: how far
   * the prior (the previous frame's pose) may be off, from the camera's motion between two
   * frames. */
  float search_radius{0.25f};
  /** Two correspondences make a hypothesis only when the distances between their objects and
   * between their tracks agree within this (m): rigid motions keep distances. */
  float pair_tolerance{0.03f};
  /** The yaw may differ from the prior's by at most this (rad). */
  float max_yaw_change{0.6f};
  /** Hypotheses examined at most (the pairs of candidates are visited in order of their
   * weights). */
  std::size_t max_hypotheses{4000};
};

/** \brief Result of registerInPlane. */
struct PlanarRegistration {
  PlanarRigid transform;          ///< frame plane coordinates to the tracks' (world) plane
  std::vector<int> inliers;       ///< candidates that agree (at most one per object and track)
  float score{0.f};               ///< sum of the inliers' weights x (1 - (r / tolerance)^2)
  std::size_t matched_objects{0}; ///< distinct objects among the inliers
  bool from_prior{true};          ///< no hypothesis beat the prior
};

/** \brief Robust in-plane registration of a frame's objects (\a objects: their positions in
 * the frame's support coordinates, x and y) against the tracks (\a tracks: world plane
 * coordinates) from \a candidates.
 *
 * Candidates farther than search_radius under the prior are dropped first. Then, from the
 * prior, each object's closest candidate is fitted (weighted Procrustes, fitPlanarRigid, with
 * Huber weights on the residuals, in a shrinking radius, four times: ICP-like); when at least
 * half of the objects with candidates, and two, agree, that is the answer. Otherwise (a jump)
 * the hypotheses are the prior, every candidate alone with the prior's yaw (a translation), and
 * every two candidates of distinct objects and tracks whose distances agree (a full rigid
 * motion: rotation from the two directions), each scored MSAC-like (truncated quadratic of the
 * residuals, each object and each track counted once). The answer is refined by weighted
 * Procrustes on its inliers, twice. Cost: O(c (n + m)) from the prior, O(c^2 (n + m)) for c
 * candidates (at most max_hypotheses) after a jump.
 *
 * \a object_axes and \a track_axes (optional; unit or zero columns, one per object and track)
 * give the horizontal directions of lying cylinders' axes: a candidate whose ends both have one
 * agrees along a line (its residual is the distance across the track's axis and the angle
 * between the axes as a distance at 30 cm; along the axis occlusion moves the visible centre),
 * and its yaw counts in the fits: a lying cylinder fixes the rotation better than points a few
 * centimetres apart. */
PlanarRegistration registerInPlane(const Eigen::Matrix2Xf& objects, const Eigen::Matrix2Xf& tracks,
                                   const std::vector<RegistrationCandidate>& candidates,
                                   const PlanarRigid& prior,
                                   const RegistrationSettings& settings = {},
                                   const Eigen::Matrix2Xf& object_axes = Eigen::Matrix2Xf(),
                                   const Eigen::Matrix2Xf& track_axes = Eigen::Matrix2Xf());

// ----------------------------------------------------------------------------- association

/** \brief What association compares of a track or an observation (world frame). */
struct AssociationGeometry {
  Eigen::Vector3f centroid{Eigen::Vector3f::Zero()}; ///< of the object's points
  bool cylinder{false};                              ///< the fields below hold a fitted cylinder
  Eigen::Vector3f centre{Eigen::Vector3f::Zero()};   ///< middle of the axis segment
  Eigen::Vector3f axis{Eigen::Vector3f::UnitZ()};    ///< unit (sign free)
  float radius{0.f};
  float height{0.f}; ///< length of the axis segment
};

/** \brief Settings of associationCost. */
struct AssociationSettings {
  float sigma_position{0.02f}; ///< m: of a cylinder's axis (view independent)
  /** m: of the centroid of an object's visible points, which moves with the viewpoint (the
   * faces of a box seen from another side). */
  float sigma_centroid{0.04f};
  float sigma_radius{0.01f}; ///< m, plus 10% of the radius
  float sigma_axis{0.25f};   ///< rad
  float gate{9.f};           ///< costs above this are no match (chi-square, about 3 sigma)
};

/** \brief Normalised squared distance (a chi-square-like cost) between track \a t and
 * observation \a o. Two cylinders: the distance of o's axis centre from t's axis segment (along
 * the axis, only beyond its ends: an occluded end moves the visible centre along the axis), the
 * radius difference and the angle between the axes. Otherwise: the distance of the centroids.
 * The centroid term is kept for cylinders too, loosely (sigma_centroid x 2), so that a cylinder
 * fitted to the wrong part of a cluster does not pass. */
float associationCost(const AssociationGeometry& t, const AssociationGeometry& o,
                      const AssociationSettings& settings = {});

/** \brief Minimum-cost one-to-one assignment of rows (observations) to columns (tracks) of
 * \a cost (Hungarian method, Kuhn-Munkres, O(n^2 m) with the shorter side first); pairs
 * costing more than \a gate (or not finite) are not assigned. \return the column of each row,
 * or -1. */
std::vector<int> assignMinimumCost(const Eigen::MatrixXf& cost, float gate);

// ------------------------------------------------------------------------------- filtering

/** \brief Huber weight of a residual \a r of standard deviation \a sigma: 1 within \a k
 * sigmas, k sigma / |r| beyond (an outlying fit pulls the estimate by at most k sigma). */
float huberWeight(float r, float sigma, float k = 2.f);

/** \brief One robust Kalman step of a scalar \a x of variance \a var with a measurement \a z of
 * variance \a var_z: the measurement's variance is divided by its Huber weight (huberWeight on
 * the innovation with the innovation's standard deviation). */
void filterScalar(float& x, float& var, float z, float var_z, float huber_k = 2.f);

/** \brief The same for a point \a x (isotropic variance \a var) and a measurement \a z. */
void filterPoint(Eigen::Vector3f& x, float& var, const Eigen::Vector3f& z, float var_z,
                 float huber_k = 2.f);

/** \brief The same for an axis \a a (unit, sign free) of angular variance \a var (rad^2): \a z
 * is turned to \a a's side, the unit vectors are blended by the Kalman gain and normalised. */
void filterAxis(Eigen::Vector3f& a, float& var, Eigen::Vector3f z, float var_z,
                float huber_k = 2.f);

/** \brief The extent [\a lo, \a hi] of a cylinder along its axis (variance \a var each),
 * updated with an observed extent [\a z_lo, \a z_hi]. Occlusion hides an end and never adds
 * one: an observed end inside the extent counts with \a shrink_weight (in (0, 1]), one beyond
 * it fully. */
void filterExtent(float& lo, float& hi, float& var, float z_lo, float z_hi, float var_z,
                  float shrink_weight);

/** \brief Median of \a values (the mean of the two middle ones for an even count); NaN when
 * empty. */
float median(std::vector<float> values);

/** \brief Weighted median of \a values with \a weights (> 0; same count): the smallest value
 * at which the cumulated weight reaches half the total. NaN when empty or no weight is
 * positive. */
float weightedMedian(const std::vector<float>& values, const std::vector<float>& weights);

/** \brief The axis most of the weighted \a axes (unit, sign free) agree with: for each axis,
 * the weight of the axes within \a inlier_angle (rad) of it; the best supported one's agreeing
 * axes are averaged (signs aligned, weighted; the later one wins a tie). A wrong first fit is
 * outvoted as soon as the right ones outweigh it, which a filter of the axis, robust or not,
 * only approaches step by step. \a inliers (optional) flags the agreeing axes. Zero when
 * \a axes is empty. Cost O(n^2). */
Eigen::Vector3f consensusAxis(const std::vector<Eigen::Vector3f>& axes,
                              const std::vector<float>& weights, float inlier_angle,
                              std::vector<char>* inliers = nullptr);

/** \brief Log-odds of a probability, \a p clamped to [0.01, 0.99]. */
float logOdds(float p);

/** \brief The confidence update of a track: log-odds \a l plus the evidence of one
 * observation \a p_observed (a calibrated probability that the object is a cylinder), clamped
 * to +-\a limit so that a long history can still be overturned by a few frames (Bayes' rule
 * with independent frames and a prior of 0.5). \return the new log-odds. */
float updateLogOdds(float l, float p_observed, float limit);

/** \brief Probability of log-odds \a l. */
float probability(float l);

/** \brief How far a prediction may be off, from how far it was (\a innovations: the last
 * frames' differences between the predicted and the measured value, e.g. of the support
 * plane's normal or height): 3 root-mean-square innovations, the mean taken with one pseudo
 * innovation of cap / 3 (the first frames, with few or none measured, get cap), at most
 * \a cap. */
float predictionTolerance(const std::vector<float>& innovations, float cap);

/** \brief The running \a mean and variance \a var of a track's per-frame evidence, updated with
 * the \a n-th value \a evidence (n >= 1; the first sets the mean, variance 0): Welford's update
 * with the weight max(1 / n, 1 / \a memory), so that it follows about the last \a memory frames
 * (exponential forgetting). */
void updateEvidenceSpread(float& mean, float& var, std::size_t n, float evidence, int memory);

/** \brief The hysteresis margin of a track's decision (log-odds): the standard deviation of its
 * frames' evidence, \a evidence_var (one typical frame's disagreement cannot flip a decision
 * that sits at the threshold), at most half of \a limit (the clamp of the log-odds: beyond it a
 * decision could never change back). */
float decisionMargin(float evidence_var, float limit);

/** \brief A decision with hysteresis: \a current (true: above) changes only when the log-odds
 * \a l pass \a threshold by \a margin on the other side (true: l below threshold - margin;
 * false: l at least threshold + margin). With margin 0, l >= threshold. */
bool decideWithHysteresis(bool current, float l, float threshold, float margin);

} // namespace facyl
