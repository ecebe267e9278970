/*
 * facyl: fast cylinder detection for PCL.
 *
 * The numerics of the two-step Hough cylinder estimator (Rabbani & van den Heuvel 2005;
 * Figueiredo et al., RAS 2019), as free functions on plain Eigen data. The PCL-style class
 * HoughCylinderEstimation gathers a cloud into CylinderCues and calls fitCylinders.
 */
#pragma once

#include <facyl/sample_consensus_alt/cylinder_model.h>
#include <facyl/sample_consensus_alt/orientation_accumulator.h>

#include <Eigen/Core>

#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <vector>

namespace facyl {

/** \brief How points vote for axis directions. */
enum class VotingMode {
  Rabbani,       ///< hard votes, normals only: +1 to cells with |d.n| < sin(cell radius) [6]
  SoftNormal,    ///< soft votes (1 - |d.n|), normals only
  SoftCurvature, ///< paper eq. 3: w (1 - |d.c_max|)(1 - |d.n|), w = (k_max-k_min)/(k_max+k_min)
};

/** \brief Parses "rabbani", "soft-normal", "soft-curvature". */
bool parseVotingMode(const std::string& name, VotingMode& mode);
/** \brief The name parseVotingMode accepts. */
std::string toString(VotingMode mode);

/** \brief Per-point voting cues in structure-of-arrays form (the hot loop is vectorised over
 * points). c_* are only read by VotingMode::SoftCurvature. */
struct VotingCues {
  Eigen::ArrayXf nx, ny, nz; ///< unit normals
  Eigen::ArrayXf cx, cy, cz; ///< unit c_max directions
  Eigen::ArrayXf weight;     ///< per-point vote weight (eq. 3's curvature term; 1 otherwise)

  Eigen::Index size() const
  {
    return nx.size();
  }
  void resize(Eigen::Index n);
};

/** \brief Casts the votes of all \a cues into the cells \a directions (3 x N_d): one inner
 * product per cell and point, no trigonometry (paper III-C2).
 *
 * \param kernel_exponent p >= 1: soft votes are raised to the power p (p = 1 is eq. 3
 *        exactly; larger p narrows each point's vote and so the spread of votes that planar
 *        points put on the great circle orthogonal to their normal).
 * \param hard_threshold Rabbani only: a cell gets a vote when |d.n| < hard_threshold.
 * \param[out] votes A(i), one per cell.
 */
void castVotes(const Eigen::Matrix3Xf& directions, const VotingCues& cues, VotingMode mode,
               int kernel_exponent, float hard_threshold, Eigen::VectorXf& votes);

/** \brief Up to \a max_peaks cells in decreasing vote order, each at least
 * \a min_separation (rad) from the cells already taken (non-maximum suppression on the
 * sphere of axes). Cells without votes are never peaks. */
std::vector<Eigen::Index> findPeaks(const Eigen::Matrix3Xf& directions,
                                    const Eigen::VectorXf& votes, std::size_t max_peaks,
                                    float min_separation);

/** \brief Sub-cell axis refinement: iteratively reweighted least squares on the normals.
 *
 * A cylinder's normals are orthogonal to its axis, so the axis is the eigenvector of the
 * smallest eigenvalue of sum_s omega_s n_s n_s^T. omega_s is the point's vote weight times a
 * Tukey biweight of |a.n_s| whose cut-off starts at \a initial_tolerance (rad) and shrinks to
 * 3.5 robust standard deviations of the supporters' |a.n| (never below 1 deg). Points whose
 * normal is near the axis (lids, tables under an upright can) get no weight.
 * \return the refined unit axis (folded), or \a initial if there was no support.
 */
Eigen::Vector3f refineAxis(const VotingCues& cues, const Eigen::Vector3f& initial,
                           float initial_tolerance, int iterations = 10);

/** \brief A circle in the plane. */
struct Circle {
  Eigen::Vector2f center{Eigen::Vector2f::Zero()};
  float radius{0.f};
};

/** \brief Circle Hough transform with normals [43]: each point votes for the centres on its
 * normal line at distances [r_min, r_max] from it, on a \a grid x \a grid accumulator over the
 * points' bounding box grown by r_max; the radius is then the mode of the distances to the
 * winning centre. Accuracy is the cell size; refine with fitCircle.
 * \param normals unit 2-D normals, one per point (sign not needed)
 * \return false if no centre got votes.
 */
bool houghCircle(const Eigen::Matrix2Xf& points, const Eigen::Matrix2Xf& normals, float r_min,
                 float r_max, int grid, Circle& circle);

/** \brief Algebraic circle fit (Kasa): the least squares of x^2 + y^2 + D x + E y + F = 0 over
 * \a points, without normals. A start for fitCircle where the normals cannot place the centre
 * (an arc whose normals come from neighbourhoods spanning all of it). Slightly short on a short,
 * noisy arc; exact on exact points.
 * \return false if fewer than 3 points or they are collinear. */
bool fitCircleAlgebraic(const Eigen::Matrix2Xf& points, Circle& circle);

/** \brief Geometric circle fit (Gauss-Newton on sum (|p - c| - r)^2), robust: the points within
 * \a threshold of the current circle are refitted, the threshold shrinking to 3 robust sigmas.
 * \return false if fewer than 3 points support the circle. */
bool fitCircle(const Eigen::Matrix2Xf& points, float threshold, Circle& circle, int iterations = 8);

/** \brief Least-squares refinement of all 5 degrees of freedom of an infinite cylinder (axis
 * direction, axis position, radius) on \a points (Gauss-Newton, analytic Jacobian).
 * \return false if the system is degenerate (the model is then unchanged). */
bool refineCylinder(const Eigen::Matrix3Xf& points, Eigen::Vector3f& point_on_axis,
                    Eigen::Vector3f& axis, float& radius, int iterations = 5);

/** \brief Which normals agree with a cylinder's surface normal at their point. */
struct NormalGate {
  float max_angle{1.5707964f}; ///< rad, largest angle to the surface normal (pi/2: any)
  bool outward{false};         ///< the normal must also point away from the axis
};

/** \brief An infinite cylinder with the robust scale of the points' distances to it. */
struct RobustCylinder {
  Eigen::Vector3f point_on_axis{Eigen::Vector3f::Zero()};
  Eigen::Vector3f axis{Eigen::Vector3f::UnitZ()};
  float radius{0.f};
  float scale{0.f};   ///< robust standard deviation of the surface distances (0: estimate)
  float support{0.f}; ///< sum of the final Tukey weights: the points the surface explains
  /** Tukey's cut-off in robust sigmas, > 0: 4.685 (95% Gaussian efficiency), or tighter
   * when structure near the surface (a table cutting it) must pull less. */
  float cutoff{4.685f};
};

/** \brief Robust refinement of all 5 degrees of freedom on the point-to-surface distances
 * e = |P_a(x - p)| - r (normals, when given, only decide which points count): iteratively
 * reweighted Gauss-Newton with Tukey's biweight at c.cutoff x s, the scale s re-estimated after
 * every step as 1.4826 MAD of the distances within 4.685 s and never growing (so a start a few
 * degrees off still sees its surface, and the window then closes on the points the converged model
 * explains). Points far from the surface (lids, a table, other objects) get no weight. \param
 * normals unit normals of \a points, or an empty matrix: with normals, a point whose normal does
 * not pass \a gate gets no weight (a table cutting the surface, a lid's rim). \param c in: the
 * start, and its scale (0: 1.4826 MAD of the distances below the radius); out: the refined
 * cylinder, its scale and support. \return false if the system is degenerate or too few points
 * support it (c unchanged). */
bool refineCylinderRobust(const Eigen::Matrix3Xf& points, const Eigen::Matrix3Xf& normals,
                          const NormalGate& gate, RobustCylinder& c, int iterations = 20);

/** \brief \a radius without the essential bias of a fit on point-to-surface distances
 * (refineCylinderRobust, refineCylinder) to points whose noise is isotropic with standard
 * deviation \a scale. A point moved by t along its section's tangent lies
 * sqrt(r^2 + t^2) ~ r + t^2 / (2 r) from the axis, so such a fit finds the radius too large by
 * about scale^2 / (2 r): 2% of r at noise 20% of r, 4.5% at 30%. Noise along a camera's rays
 * moves the points of a half-visible arc less along its tangent (a third of the variance against
 * two thirds across the surface): there the correction errs the other way, by as much as the
 * bias it removes. \return radius - scale^2 / (2 radius), at least radius / 2; \a radius
 * itself when \a scale is not positive and finite.
 * \throws std::invalid_argument if \a radius is not positive and finite. */
float unbiasedRadius(float radius, float scale);

/** \brief The points that the surface of \a c explains at \a scale: the sum of their Tukey
 * weights (cut-off c.cutoff x \a scale), with \a normals (or an empty matrix) through
 * \a gate. Compared at one scale, it ranks cylinders by the points they explain. */
float pointSupport(const Eigen::Matrix3Xf& points, const Eigen::Matrix3Xf& normals,
                   const NormalGate& gate, const RobustCylinder& c, float scale);

/** \brief The median angle (rad) between the normals of the points within \a window of the
 * surface of \a c and the surface normal there: the normals' own noise once the model is
 * right (Rayleigh-distributed, median = 1.18 sigma). 0 when fewer than 5 points are near. */
float normalDeviation(const Eigen::Matrix3Xf& points, const Eigen::Matrix3Xf& normals,
                      const RobustCylinder& c, float window);

/** \brief How fast the inliers' normals turn with their position around the axis: the
 * least-squares slope of (normal angle) against (position angle) over the inliers, about 1 on
 * a cylinder and about 0 on a plane strip that a wide cylinder happens to fit (a lid seen from
 * an axis in its plane). Angles are taken modulo pi, so strips on opposite sides (two lids)
 * pool their slopes, each side with its own intercept. The line is Tukey-reweighted, so what
 * most inliers say decides: a fit to two lids that also catches a few points of the true arc
 * between them is still a plane. Returns the slope's lower 2-sigma bound clamped to [0, 1],
 * so an arc too narrow for the normals' noise to show the turn scores 0; 1 when the inliers
 * spread over more than a quarter turn (modulo pi, about each side's mean; no plane strip
 * does) with normals within 20 deg (rms) of their radial directions (pieces of several planes
 * spread as wide, with normals far off: their turn is measured), or are fewer than 3.
 * \param normals unit normals of \a points (sign not needed)
 */
float normalRotationSlope(const Eigen::Matrix3Xf& points, const Eigen::Matrix3Xf& normals,
                          const Eigen::Vector3f& point_on_axis, const Eigen::Vector3f& axis);

/** \brief Completes \a model from its inlier points (3 x N): base and top (the extreme
 * sections along the axis, with point_on_axis set to the base), height, rms_error and
 * angular_coverage. Axis, a point on it and radius must be set; the axis is folded. */
void describeInliers(const Eigen::Matrix3Xf& inlier_points, CylinderModel& model);

/** \brief The points of \a model's end caps (its lids) among \a points (3 x N, unit
 * \a normals): within the radius plus the distance threshold of the axis, with a normal within
 * \a normal_angle (rad) of the axis, and along the axis from one radius outside either end to
 * the distance threshold inside it. Beyond the ends because the inliers stop short of a lid's
 * rim, where the normals of neighbourhoods across the rim bend (by less than a radius on a
 * cylinder sampled densely enough for its curvature to show). A lid ends at the rim: an end
 * whose ring out to 1.5 times that reach holds such points at least half as densely as the
 * disc is a plane going on (a table under a fit), and has no cap points. \a model as
 * describeInliers completes it (base, axis from base to top, height). \return column indices,
 * ascending. */
std::vector<Eigen::Index> endCapPoints(const Eigen::Matrix3Xf& points,
                                       const Eigen::Matrix3Xf& normals, const CylinderModel& model,
                                       float normal_angle);

/** \brief Allowed range of HoughCylinderParameters::orientations (N_d); validate() checks it. */
constexpr std::size_t kMinOrientations = 10;
constexpr std::size_t kMaxOrientations = 100000;
/** \brief Most accumulators per fit (HoughCylinderParameters::accumulators). */
constexpr std::size_t kMaxAccumulators = 64;
/** \brief The radius limits (m) of the tabletop recognizer (tabletopHoughDefaults): cans to
 * buckets. A bare fit (this estimator, facyl_fit, Python's fit_cylinders) has none by default
 * (radius_min 0, radius_max infinity: the data's extent), as PCL's segmentation. */
constexpr double kDefaultRadiusMin = 0.01;
constexpr double kDefaultRadiusMax = 0.25;

/** \brief Every setting of the estimator, with its default (see HoughCylinderEstimation). Each
 * setting has its home here: the tools, the recognizer and the Python module read their
 * defaults from a default-constructed struct and validate() is the one range check. */
struct HoughCylinderParameters {
  /** Orientation prior of the accumulator draws (paper eq. 1-2), about the estimator's
   * reference frame; HoughCylinderEstimation::setOrientationMixture replaces it with an
   * explicit mixture. */
  OrientationPrior prior{OrientationPrior::Uniform};
  /** N_d, cells per orientation accumulator (450, as in the paper), in [kMinOrientations,
   * kMaxOrientations]. */
  std::size_t orientations{450};
  std::size_t accumulators{1}; ///< independent accumulators per fit, in [1, kMaxAccumulators]
  std::uint64_t seed{0};       ///< seed of the accumulator draws: equal seeds, equal results
  VotingMode voting_mode{VotingMode::SoftCurvature};
  int kernel_exponent{2};                                   ///< >= 1; 1 is the paper's eq. 3
  float radius_min{0.f};                                    ///< >= 0
  float radius_max{std::numeric_limits<float>::infinity()}; ///< > radius_min; inf: data extent
  float distance_threshold{0.f};         ///< > 0, or 0: estimated from the residuals
  float normal_angle_threshold{0.6f};    ///< rad, in (0, pi/2]: normal vs surface normal
  std::size_t orientation_candidates{1}; ///< peaks per accumulator that are fitted
  bool refine{true}; ///< sub-cell axis + 5-dof least squares; false: the accumulators' peaks alone
  /** With refine: how many candidates (the best by their normals' score) are refined on the
   * points (refineCylinderRobust) and then compared on the points they explain at one scale
   * (pointSupport), per unit of their own robust scale (a fit that bends to take in a table
   * beside the cylinder spreads wider than the points' noise). Points stay informative where
   * normals turn to noise (sigma above ~10% of the radius with k = 16 neighbours). 0: only the best
   * candidate is refined, by least squares on its inliers (facyl 0.1). */
  std::size_t point_candidates{3};
  /** With point_candidates: above this noise (robust sigma of the points' distances to the
   * settled winner's surface, as a share of its radius; > 0) the given per-point cues count
   * as noise: candidates are compared on their points alone, and cues estimated again at the
   * coarse scale propose candidates too. Below it, each point counts by its eq. 3 vote. */
  float noisy_cues_ratio{0.04f};
  /** The coarse scale, in [0, 2]: neighbours within this share of the winner's radius (at
   * most 64). The coarse cues also judge the candidates: their normals' noise sets the
   * gate that keeps a plane beside the cylinder out of its refinement, so wide patches pay
   * where a plane lies within a few sigma (the failures at 0.5 to 1.5, beside a plane and
   * elsewhere: docs/benchmark.md, "The coarse scale and more seeds"). 0: cues are never
   * estimated again. */
  float coarse_scale{1.f};
  std::size_t max_cylinders{1}; ///< >= 1
  /** A cylinder needs this many points: its inliers and the points of its end caps
   * (endCapPoints), so that a can seen mostly by its lids still counts; its inliers alone must
   * reach 10 (or min_inliers, if smaller). 0: max(10, 5% of the points) (minimumInliers). */
  std::size_t min_inliers{0};
  std::size_t max_voting_points{500}; ///< voters are subsampled above this; 0: all
  int circle_grid{48};                ///< CHT accumulator size per side, >= 8
  /** Inliers' normals must point away from the axis, as normals oriented towards a sensor
   * outside the cylinder do: a cup's inner wall, seen through its opening, is then no inlier.
   * Off by default (pipes seen from inside). */
  bool outward_normals{false};
};

/** \brief Checks \a params. \return an empty string, or what is wrong ("NAME VALUE RULE",
 * settingProblem); \a rule, when given, receives the RULE alone (see settingProblem). */
std::string validate(const HoughCylinderParameters& params, std::string* rule = nullptr);

/** \brief The points a cylinder needs among \a n (HoughCylinderParameters::min_inliers, or
 * its automatic value when 0). */
std::size_t minimumInliers(const HoughCylinderParameters& params, std::size_t n);

/** \brief The cloud in the form the estimator works on: finite points with finite normals. */
struct CylinderCues {
  Eigen::Matrix3Xf points;
  Eigen::Matrix3Xf normals;              ///< unit
  Eigen::Matrix3Xf curvature_directions; ///< unit c_max (empty: none given)
  Eigen::VectorXf weights;               ///< eq. 3 curvature weights (empty: none given)
};

/** \brief Fits up to params.max_cylinders cylinders to \a cues, one after another: vote with
 * every accumulator, refine the strongest peaks, fit position and radius, keep the candidate
 * with most inliers, remove its inliers and the points inside it, and repeat while a cylinder
 * has at least min_inliers points on its side and end caps (minimumInliers, endCapPoints). Model
 * inliers index the columns of cues.points. \a total_points is N_cluster of eq. 4 (the points
 * given, finite or not).
 */
std::vector<CylinderModel> fitCylinders(const CylinderCues& cues,
                                        const std::vector<OrientationAccumulator>& accumulators,
                                        const HoughCylinderParameters& params,
                                        std::size_t total_points);

} // namespace facyl
