/*
 * facyl: fast cylinder detection for PCL.
 * The search: candidate axes from the accumulators, a position for each, the best one
 * refined; several cylinders one after another (fitCylinders).
 */
#include "fitting_detail.h"

#include <facyl/features/point_cues.h>
#include <facyl/features/setting_problem.h>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>

namespace facyl {

using detail::basisFor;
using detail::kOneDegree;
using detail::medianOf;
using detail::normalScatter;

std::string
validate(const HoughCylinderParameters& p, std::string* rule)
{
  const auto in = [](std::size_t lo, std::size_t hi) {
    return "is not in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
  };
  if (rule)
    rule->clear();
  if (p.orientations < kMinOrientations || p.orientations > kMaxOrientations)
    return settingProblem("orientations (N_d)", p.orientations,
                          in(kMinOrientations, kMaxOrientations), rule);
  if (p.accumulators < 1 || p.accumulators > kMaxAccumulators)
    return settingProblem("accumulators", p.accumulators, in(1, kMaxAccumulators), rule);
  if (p.kernel_exponent < 1 || p.kernel_exponent > 16)
    return settingProblem("kernel exponent", p.kernel_exponent, "is not in [1, 16]", rule);
  if (!(p.radius_min >= 0.f) || !std::isfinite(p.radius_min))
    return settingProblem("minimum radius", p.radius_min, "is not a finite value >= 0", rule);
  if (!(p.radius_max > p.radius_min)) { // two settings: no rule of one value
    std::ostringstream limits;
    limits << "[" << p.radius_min << ", " << p.radius_max << "]";
    return settingProblem("radius limits", limits.str(), "are empty or inverted", nullptr);
  }
  if (!(p.distance_threshold >= 0.f) || !std::isfinite(p.distance_threshold))
    return settingProblem("distance threshold", p.distance_threshold, "is not a finite value >= 0",
                          rule);
  if (!(p.normal_angle_threshold > 0.f) ||
      !(p.normal_angle_threshold <= static_cast<float>(M_PI / 2) + 1e-6f))
    return settingProblem("normal angle threshold", p.normal_angle_threshold,
                          "rad is not in (0, pi/2]", rule);
  if (p.orientation_candidates < 1)
    return "at least one orientation candidate is needed";
  if (p.max_cylinders < 1)
    return "max cylinders must be at least 1";
  if (p.circle_grid < 8 || p.circle_grid > 4096)
    return settingProblem("circle grid", p.circle_grid, "is not in [8, 4096]", rule);
  if (!(p.noisy_cues_ratio > 0.f) || !std::isfinite(p.noisy_cues_ratio))
    return settingProblem("noisy cues ratio", p.noisy_cues_ratio, "is not a finite value > 0",
                          rule);
  if (!(p.coarse_scale >= 0.f) || !(p.coarse_scale <= 2.f))
    return settingProblem("coarse scale", p.coarse_scale, "is not in [0, 2]", rule);
  return {};
}

std::size_t
minimumInliers(const HoughCylinderParameters& params, std::size_t n)
{
  return params.min_inliers > 0 ? params.min_inliers
                                : std::max<std::size_t>(10, static_cast<std::size_t>(0.05 * n));
}

namespace {

/** Cues of the listed columns, as voting arrays. */
VotingCues
gatherVotingCues(const CylinderCues& cues, const std::vector<int>& columns, bool curvature)
{
  VotingCues v;
  v.resize(static_cast<Eigen::Index>(columns.size()));
  for (std::size_t k = 0; k < columns.size(); ++k) {
    const auto i = static_cast<Eigen::Index>(k);
    const int s = columns[k];
    v.nx(i) = cues.normals(0, s);
    v.ny(i) = cues.normals(1, s);
    v.nz(i) = cues.normals(2, s);
    if (curvature) {
      v.cx(i) = cues.curvature_directions(0, s);
      v.cy(i) = cues.curvature_directions(1, s);
      v.cz(i) = cues.curvature_directions(2, s);
      v.weight(i) = cues.weights(s);
    }
    else {
      v.cx(i) = v.cy(i) = v.cz(i) = 0.f;
      v.weight(i) = 1.f;
    }
  }
  return v;
}

/** Evenly strided subset of at most \a limit entries (all when limit is 0). */
std::vector<int>
subsample(const std::vector<int>& columns, std::size_t limit)
{
  if (limit == 0 || columns.size() <= limit)
    return columns;
  std::vector<int> out(limit);
  for (std::size_t k = 0; k < limit; ++k)
    out[k] = columns[k * columns.size() / limit];
  return out;
}

struct Candidate {
  Eigen::Vector3f point_on_axis;
  Eigen::Vector3f axis;
  float radius{0.f};
  float threshold{0.f};
  float radius_limit{std::numeric_limits<float>::infinity()}; ///< given or from the data
  float normal_angle{0.f}; ///< inliers' largest normal angle (0: params.normal_angle_threshold)
  float scale{0.f};        ///< robust sigma of the points' distances, once settled (0: unknown)
};

/** The largest inlier threshold estimateThreshold gives, in radii: residuals spread wider than
 * this are not the points' noise about the candidate but its misfit. */
constexpr float kThresholdCap = 0.1f;

/** Robust noise estimate: 1.4826 MAD of the surface distances of the points near it (3 sigma,
 * between a thousandth and kThresholdCap of the radius). */
float
estimateThreshold(const CylinderCues& cues, const std::vector<int>& columns, const Candidate& c)
{
  std::vector<float> residuals;
  residuals.reserve(columns.size());
  for (const int s : columns) {
    const float e =
      std::abs(distanceToLine(cues.points.col(s), c.point_on_axis, c.axis) - c.radius);
    if (e < 0.3f * c.radius)
      residuals.push_back(e);
  }
  const float sigma = 1.4826f * medianOf(residuals);
  return std::clamp(3.f * sigma, 1e-3f * c.radius, kThresholdCap * c.radius);
}

/** Inliers: near the surface, and with a normal close to the surface normal. */
std::vector<int>
selectInliers(const CylinderCues& cues, const std::vector<int>& columns, const Candidate& c,
              float cos_normal, bool outward)
{
  std::vector<int> inliers;
  // |rho - r| < threshold tested on rho^2 first: most points fail it, without a square root.
  const float lo = std::max(0.f, c.radius - c.threshold), hi = c.radius + c.threshold;
  const float lo2 = lo * lo, hi2 = hi * hi;
  for (const int s : columns) {
    const Eigen::Vector3f w = cues.points.col(s) - c.point_on_axis;
    const float wa = w.dot(c.axis);
    const float rho2 = w.squaredNorm() - wa * wa;
    if (!(rho2 > lo2 && rho2 < hi2))
      continue;
    const Eigen::Vector3f d = w - wa * c.axis;
    const float rho = d.norm();
    if (std::abs(rho - c.radius) >= c.threshold || !(rho > 0.f))
      continue;
    const float along = cues.normals.col(s).dot(d);
    if ((outward ? along : std::abs(along)) < cos_normal * rho)
      continue;
    inliers.push_back(s);
  }
  return inliers;
}

/** The points whose normal is within the normal angle threshold of orthogonal to \a axis:
 * those a cylinder about it can explain. */
std::vector<int>
supporters(const CylinderCues& cues, const std::vector<int>& active, const Eigen::Vector3f& axis,
           const HoughCylinderParameters& params)
{
  const float sin_n = std::sin(params.normal_angle_threshold);
  std::vector<int> support;
  for (const int s : active)
    if (std::abs(axis.dot(cues.normals.col(s))) < sin_n)
      support.push_back(s);
  return support;
}

/** The supporters of one axis projected on the plane orthogonal to it (q), with their unit
 * projected normals (qm) and the normals' projected lengths. */
struct Section {
  Eigen::Matrix2Xf q, qm;
  Eigen::RowVectorXf m_len;
  float extent{0.f}; ///< diagonal of the projected points' bounding box
};

/** The indices of the \a section points that agree with circle \a c: within \a band of it, with
 * a normal along its radius (params.normal_angle_threshold). Other structure that shares the
 * axis direction (a table under a lying can) drops out here. */
std::vector<Eigen::Index>
agreeing(const Eigen::Matrix2Xf& pts, const Eigen::Matrix2Xf& nrm, const Circle& c, float band,
         const HoughCylinderParameters& params)
{
  const float cos_n = std::cos(params.normal_angle_threshold);
  std::vector<Eigen::Index> keep;
  for (Eigen::Index i = 0; i < pts.cols(); ++i) {
    const Eigen::Vector2f w = pts.col(i) - c.center;
    const float d = w.norm();
    const float along = nrm.col(i).dot(w);
    if (std::abs(d - c.radius) < band &&
        (params.outward_normals ? along : std::abs(along)) >= cos_n * d)
      keep.push_back(i);
  }
  return keep;
}

/** The circle Hough of a section (an even subset of at most 300 supporters whose normal is not
 * along the axis votes); coarse to fine: with a wide radius range the first grid's cells can
 * exceed the radius, so the agreeing points vote again over a range around the first estimate.
 * \a cell: the final grid's cell. */
std::optional<Circle>
voteCircle(const Section& section, float r_max, const HoughCylinderParameters& params, float& cell)
{
  std::vector<Eigen::Index> voters;
  const auto n_support = section.q.cols();
  const Eigen::Index n_voters = std::min<Eigen::Index>(n_support, 300);
  for (Eigen::Index k = 0; k < n_voters; ++k) {
    const Eigen::Index i = k * n_support / n_voters;
    if (section.m_len(i) > 0.3f)
      voters.push_back(i);
  }
  const Eigen::Matrix2Xf vq = section.q(Eigen::all, voters);
  const Eigen::Matrix2Xf vm = section.qm(Eigen::all, voters);
  Circle circle;
  if (!houghCircle(vq, vm, params.radius_min, r_max, params.circle_grid, circle))
    return std::nullopt;
  cell = (section.extent + 2.f * r_max) / static_cast<float>(params.circle_grid);
  if (cell > 0.1f * circle.radius) {
    const auto keep = agreeing(vq, vm, circle, std::max(0.5f * circle.radius, 2.f * cell), params);
    if (keep.size() >= 5) {
      const float lo = std::max(params.radius_min, 0.5f * circle.radius - cell);
      const float hi = std::min(r_max, 1.5f * circle.radius + cell);
      Circle fine;
      if (hi > lo && houghCircle(vq(Eigen::all, keep), vm(Eigen::all, keep), lo, hi,
                                 params.circle_grid, fine)) {
        Eigen::Matrix2Xf kept = vq(Eigen::all, keep);
        const float fine_extent = (kept.rowwise().maxCoeff() - kept.rowwise().minCoeff()).norm();
        circle = fine;
        cell = (fine_extent + 2.f * hi) / static_cast<float>(params.circle_grid);
      }
    }
  }
  return circle;
}

/** \a start refined on the section points that agree with it (fitCircle), if at least 5 (and
 * \a min_agreeing) do and the result keeps within [params.radius_min, r_max]. */
std::optional<Circle>
settleCircle(const Section& section, Circle start, float cell, float r_max,
             const HoughCylinderParameters& params, std::size_t min_agreeing = 5)
{
  const float band = std::max(0.3f * start.radius, 3.f * cell);
  const auto keep = agreeing(section.q, section.qm, start, band, params);
  if (keep.size() < std::max<std::size_t>(5, min_agreeing) ||
      !fitCircle(section.q(Eigen::all, keep), band, start))
    return std::nullopt;
  if (start.radius < params.radius_min || start.radius > r_max)
    return std::nullopt;
  return start;
}

/** A section at least this many times longer along its axis than across is a sliver. */
constexpr float kSliverElongation = 3.f;

/** The circle of the section's points alone: the algebraic circle (fitCircleAlgebraic) settled
 * (settleCircle), if at least half the points agree with it. */
std::optional<Circle>
pointsCircle(const Section& section, float cell, float r_max, const HoughCylinderParameters& params)
{
  Circle start;
  if (!fitCircleAlgebraic(section.q, start))
    return std::nullopt;
  const auto half = (static_cast<std::size_t>(section.q.cols()) + 1) / 2;
  return settleCircle(section, start, cell, r_max, params, half);
}

/** Whether the \a support points reach along \a axis kSliverElongation times the \a extent
 * of their section. */
bool
isSliver(const CylinderCues& cues, const std::vector<int>& support, const Eigen::Vector3f& axis,
         float extent)
{
  float lo = std::numeric_limits<float>::max(), hi = std::numeric_limits<float>::lowest();
  for (const int s : support) {
    const float t = axis.dot(cues.points.col(s));
    lo = std::min(lo, t);
    hi = std::max(hi, t);
  }
  return hi - lo > kSliverElongation * extent;
}

/** Step 2 for one axis: circle Hough on the supporters (voteCircle), circle least squares
 * (settleCircle). A sliver's normals may not place the centre: a tall cylinder seen over a
 * narrow arc (mostly occluded) and sampled sparsely gets normals from neighbourhoods that span
 * the whole arc, so they point nearly one way and the vote may find nothing. There the
 * circle of the points alone (pointsCircle) is the start instead. Elsewhere (lids, clutter) a
 * circle the normals do not see is not proposed. */
std::optional<Candidate>
fitPosition(const CylinderCues& cues, const std::vector<int>& active, const Eigen::Vector3f& axis,
            const HoughCylinderParameters& params)
{
  Eigen::Vector3f u, v;
  basisFor(axis, u, v);
  const std::vector<int> support = supporters(cues, active, axis, params);
  if (support.size() < 5)
    return std::nullopt;
  Eigen::Matrix<float, 2, 3> project;
  project << u.transpose(), v.transpose();
  // The supporters gathered first: a product with an indexed view copies far more.
  const Eigen::Matrix3Xf support_points = cues.points(Eigen::all, support);
  const Eigen::Matrix3Xf support_normals = cues.normals(Eigen::all, support);
  Section section;
  section.q = project * support_points;
  const Eigen::Matrix2Xf m = project * support_normals;
  section.m_len = m.colwise().norm();
  section.qm = m.array().rowwise() / section.m_len.array();
  section.extent = (section.q.rowwise().maxCoeff() - section.q.rowwise().minCoeff()).norm();
  const float r_max = std::min(params.radius_max, 2.f * section.extent);
  if (!(r_max > params.radius_min))
    return std::nullopt;

  float cell = (section.extent + 2.f * r_max) / static_cast<float>(params.circle_grid);
  const std::optional<Circle> voted = voteCircle(section, r_max, params, cell);
  std::optional<Circle> circle =
    voted ? settleCircle(section, *voted, cell, r_max, params) : std::nullopt;
  if (!circle && isSliver(cues, support, axis, section.extent))
    circle = pointsCircle(section, cell, r_max, params);
  if (!circle)
    return std::nullopt;

  Candidate c;
  c.axis = axis;
  c.point_on_axis = circle->center.x() * u + circle->center.y() * v;
  c.radius = circle->radius;
  c.radius_limit = r_max;
  const bool auto_threshold = params.distance_threshold <= 0.f;
  c.threshold = auto_threshold ? estimateThreshold(cues, support, c) : params.distance_threshold;
  return c;
}

/** Least squares on all five parameters, alternating with the choice of inliers. */
Candidate
refineCandidate(const CylinderCues& cues, const std::vector<int>& active, Candidate c,
                const HoughCylinderParameters& params)
{
  const bool auto_threshold = params.distance_threshold <= 0.f;
  const std::vector<int> support = supporters(cues, active, c.axis, params);
  const float cos_normal = std::cos(params.normal_angle_threshold);
  std::vector<int> previous;
  for (int round = 0; round < 3; ++round) {
    std::vector<int> inliers = selectInliers(cues, active, c, cos_normal, params.outward_normals);
    // The same inliers again: the least squares on them converged last round already.
    if (inliers.size() < 6 || inliers == previous)
      break;
    const Eigen::Matrix3Xf pts = cues.points(Eigen::all, inliers);
    Candidate next = c;
    if (!refineCylinder(pts, next.point_on_axis, next.axis, next.radius) ||
        next.radius < params.radius_min || next.radius > c.radius_limit)
      break;
    if (auto_threshold)
      next.threshold = estimateThreshold(cues, support, next);
    const bool settled =
      axisAngle(next.axis, c.axis) < 1e-5f && std::abs(next.radius - c.radius) < 1e-6f * c.radius;
    c = next;
    if (settled)
      break;
    previous = std::move(inliers);
  }
  return c;
}

/** The finished model of a candidate: inliers, extent, quality figures. */
CylinderModel
describe(const CylinderCues& cues, const std::vector<int>& active, const Candidate& c,
         const HoughCylinderParameters& params)
{
  CylinderModel m;
  m.axis = c.axis;
  m.point_on_axis = c.point_on_axis;
  m.radius = c.radius;
  m.distance_threshold = c.threshold;
  const float normal_angle = c.normal_angle > 0.f ? c.normal_angle : params.normal_angle_threshold;
  const std::vector<int> inliers =
    selectInliers(cues, active, c, std::cos(normal_angle), params.outward_normals);
  m.inliers.assign(inliers.begin(), inliers.end());
  describeInliers(cues.points(Eigen::all, inliers), m);
  return m;
}

} // namespace

namespace {

/** A candidate axis direction and the cell radius of the accumulator that proposed it. */
struct AxisSeed {
  Eigen::Vector3f axis;
  float cell_radius;
  bool from_points{false}; ///< not refined by the normals (addElongationSeed)
};

/** Appends to \a seeds the \a count highest peaks of \a acc's votes (mode \a mode) that are not
 * within reach of a seed there already: the cell radius for peaks of the fit's own mode (the
 * refinement reaches that far), the peaks' separation for another mode's. */
void
addVotePeaks(const OrientationAccumulator& acc, const VotingCues& voting, VotingMode mode,
             const HoughCylinderParameters& params, std::size_t count, std::vector<AxisSeed>& seeds)
{
  const float cell = acc.cellRadius();
  const float separation = std::max(4.f * cell, 10.f * kOneDegree);
  Eigen::VectorXf votes;
  castVotes(acc.directions(), voting, mode, params.kernel_exponent, std::sin(cell), votes);
  for (const auto i : findPeaks(acc.directions(), votes, count, separation)) {
    const Eigen::Vector3f d = acc.directions().col(i);
    const bool known = std::any_of(seeds.begin(), seeds.end(), [&](const AxisSeed& s) {
      return axisAngle(s.axis, d) <
             (mode == params.voting_mode ? std::max(s.cell_radius, cell) : separation);
    });
    if (!known)
      seeds.push_back({d, cell});
  }
}

/** One more seed beyond the paper: the dominant direction of the planar points' normals.
 * Lids and the table under an upright object are planar and orthogonal to its axis, so the
 * points that spoil the votes (eq. 3 spreads theirs over a great circle) point at the axis
 * themselves. The seed only competes; the fit decides. Appended unless a seed is near. */
void
addPlanarNormalsSeed(const VotingCues& voting, float cell, std::vector<AxisSeed>& seeds)
{
  const Eigen::Matrix3d m = normalScatter(voting, 1.f - voting.weight);
  if (!(m.trace() > 0.0))
    return;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
  solver.computeDirect(m);
  const Eigen::Vector3f d = foldToHemisphere(solver.eigenvectors().col(2).cast<float>());
  const float separation = std::max(4.f * cell, 10.f * kOneDegree);
  if (d.allFinite() && std::none_of(seeds.begin(), seeds.end(), [&](const AxisSeed& s) {
        return axisAngle(s.axis, d) < separation;
      }))
    seeds.push_back({d, cell});
}

/** One more seed for slivers: the direction along which the \a points reach furthest, when
 * they reach kSliverElongation times further along it than across (standard deviations). A
 * tall cylinder seen over a narrow arc gets normals that all point one way, so its votes spread
 * over a great circle and peak degrees off, and refineAxis, led by the same normals, stays off;
 * the points themselves lie along the axis. This seed is tried as it is (not refined by the
 * normals), even near another seed, and only competes (facyl_bench, paper setting, 90%
 * occlusion: 47 failures of 200 without it, 4 with it). */
bool
addElongationSeed(const Eigen::Matrix3Xf& points, float cell, std::vector<AxisSeed>& seeds)
{
  if (points.cols() < 5)
    return false;
  const Eigen::Vector3d mean = points.cast<double>().rowwise().mean();
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    const Eigen::Vector3d d = points.col(i).cast<double>() - mean;
    scatter.noalias() += d * d.transpose();
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
  solver.computeDirect(scatter);
  const Eigen::Vector3d lambda = solver.eigenvalues();
  if (!(lambda(2) > kSliverElongation * kSliverElongation * lambda(1)))
    return false;
  const Eigen::Vector3f d = foldToHemisphere(solver.eigenvectors().col(2).cast<float>());
  if (!d.allFinite())
    return false;
  seeds.push_back({d, cell, true});
  return true;
}

/** The \a active points whose normals lie more than 30 deg off the direction most normals
 * share (a plane's, when one dominates the points: a table beside a cylinder, or large lids);
 * nothing when they are fewer than 10, fewer than a twentieth of the points, or all of them.
 * Their spread is that of the rest: a sliver seen beside a table (facyl_bench, practical
 * setting, 90% occlusion: 152 failures of 200 with addElongationSeed on all the points, 99 with
 * it on these too). */
std::vector<int>
offDominantNormal(const CylinderCues& cues, const std::vector<int>& active)
{
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const int a : active) {
    const Eigen::Vector3d n = cues.normals.col(a).cast<double>();
    scatter.noalias() += n * n.transpose();
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
  solver.computeDirect(scatter);
  const Eigen::Vector3f dominant = solver.eigenvectors().col(2).cast<float>();
  const float cos_off = std::cos(30.f * kOneDegree);
  std::vector<int> off;
  for (const int a : active)
    if (std::abs(cues.normals.col(a).dot(dominant)) < cos_off)
      off.push_back(a);
  if (off.size() < 10 || 20 * off.size() < active.size() || off.size() == active.size())
    off.clear();
  return off;
}

/** The elongation seeds (addElongationSeed) of the \a active points and of those off their
 * dominant normal direction (offDominantNormal); when the latter are not elongated either, of
 * those off the dominant direction of theirs. Lids and a table beside a sliver are two planar
 * directions: once both are peeled off, the lateral points alone remain (facyl_bench, practical
 * setting, seeds 1-3, 180 clouds a level: lids at 300% with 75% occlusion 17 -> 13 failures,
 * lids at 300% and 500% 4 -> 1; noise 10-30% identical in failures). */
void
addElongationSeeds(const CylinderCues& cues, const std::vector<int>& active, float cell,
                   std::vector<AxisSeed>& seeds)
{
  addElongationSeed(cues.points(Eigen::all, active), cell, seeds);
  const std::vector<int> off = offDominantNormal(cues, active);
  if (off.empty() || addElongationSeed(cues.points(Eigen::all, off), cell, seeds))
    return;
  const std::vector<int> off_twice = offDominantNormal(cues, off);
  if (!off_twice.empty())
    addElongationSeed(cues.points(Eigen::all, off_twice), cell, seeds);
}

/** Candidates compete on their inliers. With curvature cues each inlier counts by its vote
 * for the candidate's axis (eq. 3): a plane strip that happens to fit a wide cylinder (a lid
 * seen along an axis in its plane) has random c_max and low weights, a real lateral surface
 * has c_max orthogonal to the axis and weights near 1. Either way the score is scaled by
 * normalRotationSlope: plane strips score ~0. */
double
candidateScore(const CylinderCues& cues, const CylinderModel& m, bool curvature)
{
  const double slope =
    normalRotationSlope(cues.points(Eigen::all, m.inliers), cues.normals(Eigen::all, m.inliers),
                        m.point_on_axis, m.axis);
  if (!curvature)
    return slope * static_cast<double>(m.inliers.size());
  double sum = 0.0;
  for (const auto s : m.inliers) {
    const float dn = std::abs(m.axis.dot(cues.normals.col(s)));
    const float dc = std::abs(m.axis.dot(cues.curvature_directions.col(s)));
    sum += cues.weights(s) * (1.f - dn) * (1.f - dc);
  }
  return slope * sum;
}

/** A candidate of the competition: its model (inliers by normals) and score. */
struct Contender {
  Candidate candidate;
  CylinderModel model;
  double score{-1.0};
  /** The seed's own axis, when refineAxis moved it by more than half the seed's cell. */
  std::optional<Eigen::Vector3f> seed_axis;
};

/** The points' own noise (estimateLocalNoise over 12 neighbours, 128 samples of the active
 * points), computed on first use only: a fit whose spread about the model is small never
 * needs it. */
class LocalNoise {
public:
  LocalNoise(const CylinderCues& cues, const std::vector<int>& active)
      : cues_(cues)
      , active_(active)
  {
  }
  float value() const
  {
    if (!value_)
      value_ = estimateLocalNoise(cues_.points(Eigen::all, active_), 12, 128);
    return *value_;
  }

private:
  const CylinderCues& cues_;
  const std::vector<int>& active_;
  mutable std::optional<float> value_;
};

/** Whether the noise of the points exceeds params.noisy_cues_ratio of the radius of \a c: both
 * their spread about its surface (its robust sigma) and their spread about their own local
 * planes (\a local). Then per-point normals and curvatures from small neighbourhoods are more
 * noise than cue. A large spread about the model alone is a misfit, not noise (a box that a
 * cylinder does not describe): the cues are then trusted. */
bool
cuesAreNoise(const Candidate& c, const LocalNoise& local, const HoughCylinderParameters& params)
{
  const float limit = params.noisy_cues_ratio * c.radius;
  return c.scale > limit && local.value() > limit;
}

/** \a candidate with its noise before any refinement on the points: the robust sigma of the
 * distances of the points whose normals fit its axis (lids left out), as the fixed point of
 * s = 1.4826 MAD of the distances within 3 s, from the MAD within one radius. The shrinking
 * window sheds what lies near the surface without being it (a table, the rims of large lids),
 * so the lateral points' own noise decides whether the cues are worth their name. */
Candidate
probeNoise(const CylinderCues& cues, const std::vector<int>& active, Candidate candidate,
           const HoughCylinderParameters& params)
{
  std::vector<float> distances;
  const std::vector<int> support = supporters(cues, active, candidate.axis, params);
  for (const int col : support)
    distances.push_back(
      std::abs(distanceToLine(cues.points.col(col), candidate.point_on_axis, candidate.axis) -
               candidate.radius));
  float window = candidate.radius;
  float scale = 0.f;
  std::vector<float> near;
  for (int round = 0; round < 5; ++round) {
    near.clear();
    for (const float e : distances)
      if (e < window)
        near.push_back(e);
    if (near.size() < 5)
      break;
    scale = 1.4826f * medianOf(near);
    window = 3.f * scale;
  }
  candidate.scale = std::max(scale, 1e-5f * candidate.radius);
  return candidate;
}

/** Steps of the robust refinement for every finalist, then for the winner. */
constexpr int kFirstRound = 8;
constexpr int kLastRound = 20;
/** Tukey's cut-off (robust sigmas) of the refinement on the points when the cues are noise:
 * tighter than the 4.685 of 95% Gaussian efficiency, so that a table that cuts the surface,
 * or continues it beyond the cylinder's end, pulls a noisy fit much less (facyl_bench,
 * practical setting, 20% noise: 8% failures instead of 27%). With clean cues the normal gate
 * keeps such points out, and the efficient 4.685 stays. */
constexpr float kNoisyCutoff = 2.5f;

/** A candidate refined on the points, with the normal gate its normals' noise asks for. */
struct Settled {
  Candidate candidate;
  RobustCylinder fit;
  NormalGate gate;
};

/** The normal gate for the points of \a fit: 2.6 median deviations of the normals within
 * \a window of its surface (the 96th percentile of a Rayleigh law), at least
 * params.normal_angle_threshold and at most 85 deg. Noisy normals then do not drop true points
 * and clean ones still keep a table or a lid's rim out. */
NormalGate
gateFor(const Eigen::Matrix3Xf& points, const Eigen::Matrix3Xf& normals, const RobustCylinder& fit,
        float window, const HoughCylinderParameters& params)
{
  NormalGate gate{params.normal_angle_threshold, params.outward_normals};
  gate.max_angle = std::clamp(2.6f * normalDeviation(points, normals, fit, window),
                              params.normal_angle_threshold, 85.f * kOneDegree);
  return gate;
}

/** The start of \a candidate's refinement on the points: its scale from the points whose
 * normals fit its axis (lids and tables left out), and its gate. \a points and \a normals: the
 * active ones. */
Settled
startOnPoints(const CylinderCues& cues, const std::vector<int>& active,
              const Eigen::Matrix3Xf& points, const Eigen::Matrix3Xf& normals,
              const Candidate& candidate, float cutoff, const HoughCylinderParameters& params)
{
  Settled s;
  s.candidate = probeNoise(cues, active, candidate, params);
  s.fit.point_on_axis = candidate.point_on_axis;
  s.fit.axis = candidate.axis;
  s.fit.radius = candidate.radius;
  s.fit.scale = s.candidate.scale;
  s.fit.cutoff = cutoff;
  s.gate = gateFor(points, normals, s.fit, s.fit.scale, params);
  return s;
}

/** At most \a iterations more steps of the robust refinement of \a s (refineCylinderRobust),
 * then its gate and candidate (threshold: 3 sigma, at most half the radius) follow. \return
 * false if the refinement fails or leaves the radius limits. */
bool
advanceOnPoints(const Eigen::Matrix3Xf& points, const Eigen::Matrix3Xf& normals, Settled& s,
                int iterations, const HoughCylinderParameters& params)
{
  if (!refineCylinderRobust(points, normals, s.gate, s.fit, iterations) ||
      s.fit.radius < params.radius_min || s.fit.radius > s.candidate.radius_limit)
    return false;
  s.gate = gateFor(points, normals, s.fit, s.fit.scale, params);
  Candidate& c = s.candidate;
  c.point_on_axis = s.fit.point_on_axis;
  c.axis = foldToHemisphere(s.fit.axis.normalized());
  c.radius = s.fit.radius;
  c.scale = s.fit.scale;
  c.normal_angle = s.gate.max_angle;
  c.threshold = params.distance_threshold > 0.f
                  ? params.distance_threshold
                  : std::clamp(3.f * c.scale, 1e-3f * c.radius, 0.5f * c.radius);
  return true;
}

/** How a settled contender competes: the points it explains at the common \a scale (the
 * smallest any contender reached), per unit of its own robust scale, times the turn of its
 * inliers' normals (\a slope; a plane strip still scores 0). A contender that bends to take in
 * structure beside the cylinder (a table within a few sigma of it) explains more points at the
 * common scale, but its own distances are then spread wider than the points' noise: per unit
 * of scale it loses to the one that fits the surface (facyl_bench, practical setting, noise
 * 10-30% of r, seeds 1-3: 2-12 failures fewer in 180 clouds a level, none more; the random
 * setting without a plane unchanged). */
double
settledScore(double slope, double support, float scale, float own_scale)
{
  return slope * support * static_cast<double>(scale) / static_cast<double>(own_scale);
}

/** Settles the competition on the points, once the cues are noise: each contender, refined
 * on its inliers (refineCandidate), is refined on the points with Tukey's cut-off at
 * kNoisyCutoff (startOnPoints, then kFirstRound steps of advanceOnPoints); all are compared by
 * settledScore (pointSupport at the smallest scale any of them reached); the winner converges
 * (kLastRound steps). \return the winner, or nothing if no refinement held. */
std::optional<Candidate>
settleOnPoints(const CylinderCues& cues, const std::vector<int>& active,
               const std::vector<const Contender*>& contenders,
               const HoughCylinderParameters& params)
{
  const Eigen::Matrix3Xf points = cues.points(Eigen::all, active);
  const Eigen::Matrix3Xf normals = cues.normals(Eigen::all, active);
  // Round one: a few steps each, enough to tell a converging start from a drifting one.
  std::vector<Settled> settled;
  for (const Contender* contender : contenders) {
    // The least squares on the candidate's inliers first: it mends a start whose radius is
    // off (a short arc), which the robust refinement, from the wide scale such a start shows,
    // could not.
    const Candidate start = refineCandidate(cues, active, contender->candidate, params);
    Settled s = startOnPoints(cues, active, points, normals, start, kNoisyCutoff, params);
    if (advanceOnPoints(points, normals, s, kFirstRound, params))
      settled.push_back(std::move(s));
  }
  if (settled.empty())
    return std::nullopt;
  // Round two: the winner converges (kLastRound more steps at most).
  const auto finish = [&](Settled& s) -> std::optional<Candidate> {
    if (!advanceOnPoints(points, normals, s, kLastRound, params))
      return std::nullopt;
    return s.candidate;
  };
  if (settled.size() == 1)
    return finish(settled.front());
  const auto sharpest =
    std::min_element(settled.begin(), settled.end(),
                     [](const Settled& a, const Settled& b) { return a.fit.scale < b.fit.scale; });
  const float scale = sharpest->fit.scale;
  const NormalGate gate = sharpest->gate;
  Settled* best = nullptr;
  double best_score = -1.0;
  for (Settled& s : settled) {
    const Candidate& c = s.candidate;
    const std::vector<int> inliers =
      selectInliers(cues, active, c, std::cos(c.normal_angle), params.outward_normals);
    const double slope = normalRotationSlope(
      cues.points(Eigen::all, inliers), cues.normals(Eigen::all, inliers), c.point_on_axis, c.axis);
    const double score =
      settledScore(slope, pointSupport(points, normals, gate, s.fit, scale), scale, s.fit.scale);
    if (score > best_score) {
      best_score = score;
      best = &s;
    }
  }
  return finish(*best);
}

/** Whether \a a beats \a b: a higher score, or the same with a smaller RMS error. */
bool
beats(const Contender& a, const Contender& b)
{
  return a.score > b.score || (a.score == b.score && a.model.rms_error < b.model.rms_error);
}

/** The \a count best of \a contenders, best first. */
std::vector<const Contender*>
ranked(const std::vector<Contender>& contenders, std::size_t count)
{
  std::vector<const Contender*> order;
  for (const Contender& c : contenders)
    order.push_back(&c);
  std::stable_sort(order.begin(), order.end(),
                   [](const Contender* a, const Contender* b) { return beats(*a, *b); });
  if (order.size() > count)
    order.resize(count);
  return order;
}

/** Whether the best of \a contenders is convincing: a quarter of the \a active points, half
 * the circumference. */
bool
convinces(const std::vector<Contender>& contenders, std::size_t active)
{
  const auto b = ranked(contenders, 1);
  return !b.empty() && b[0]->model.angular_coverage >= 0.5f &&
         4 * b[0]->model.inliers.size() >= active;
}

/** The candidate on \a axis among the \a active points (fitPosition), described and scored;
 * nothing if none. */
std::optional<Contender>
contend(const CylinderCues& cues, const std::vector<int>& active, const Eigen::Vector3f& axis,
        const HoughCylinderParameters& params)
{
  const auto candidate = fitPosition(cues, active, axis, params);
  if (!candidate)
    return std::nullopt;
  Contender c;
  c.candidate = *candidate;
  c.model = describe(cues, active, *candidate, params);
  c.score = candidateScore(cues, c.model, params.voting_mode == VotingMode::SoftCurvature);
  return c;
}

/** The better of \a a and \a b, scored at the tighter of their two inlier thresholds: each
 * threshold comes from its own residuals, so a loose fit (a circle twice too wide on an axis a
 * few degrees off a narrow arc) would otherwise win by the points its own looseness admits.
 * Ties go to \a a. */
const Contender&
fitterOfPair(const CylinderCues& cues, const std::vector<int>& active, const Contender& a,
             const Contender& b, const HoughCylinderParameters& params)
{
  const float common = std::min(a.candidate.threshold, b.candidate.threshold);
  const auto scoreAt = [&](const Contender& x) {
    if (x.candidate.threshold == common) // scored at it already
      return x.score;
    Candidate c = x.candidate;
    c.threshold = common;
    return candidateScore(cues, describe(cues, active, c, params),
                          params.voting_mode == VotingMode::SoftCurvature);
  };
  return scoreAt(b) > scoreAt(a) ? b : a;
}

/** The \a contenders whose refineAxis moved their seed by more than half a cell meet their
 * seed's own axis, and the better of the two stays (fitterOfPair): the normals of a plane
 * beside the cylinder, nearly parallel to its axis, fall in the refinement's window and can
 * pull it off (facyl_bench, practical setting, 75% occlusion: 4-6 failures of 60 instead of
 * 10-11). \return whether any contender changed. */
bool
meetSeedAxes(const CylinderCues& cues, const std::vector<int>& active,
             std::vector<Contender>& contenders, const HoughCylinderParameters& params)
{
  bool changed = false;
  for (Contender& c : contenders) {
    if (!c.seed_axis)
      continue;
    const std::optional<Contender> own = contend(cues, active, *c.seed_axis, params);
    c.seed_axis.reset();
    if (own && &fitterOfPair(cues, active, c, *own, params) == &*own) {
      c = *own;
      changed = true;
    }
  }
  return changed;
}

/** Whether \a c's inlier threshold, estimated from its residuals, reached kThresholdCap: its
 * points are spread about it far wider than noise (a circle through a plane strip and a narrow
 * arc). Never with a threshold the user gave. */
bool
looseFit(const Candidate& c, const HoughCylinderParameters& params)
{
  return params.distance_threshold <= 0.f && c.threshold >= 0.999f * kThresholdCap * c.radius;
}

/** The \a count best of \a contenders (ranked, at least 1), except that a loose best
 * (looseFit) meets the runner-up when that one is not loose, and the fitter of the two at the
 * tighter threshold (fitterOfPair) leads: scored each at its own threshold, the loose one wins
 * by the points its looseness admits (a wide cylinder through lids and a table beside a sliver:
 * facyl_bench, seeds 1-3, 180 clouds a level, lids at 300% with 75% occlusion, paper setting 5
 * -> 3 failures, random 4 -> 2; 75% occlusion beside a plane 9 -> 8; lids 500% beside it 1 ->
 * 0; no fit worse; noise 10-30% identical). Not with params.point_candidates 0 (facyl 0.1). */
std::vector<const Contender*>
finalistsOf(const CylinderCues& cues, const std::vector<int>& active,
            const std::vector<Contender>& contenders, const HoughCylinderParameters& params)
{
  const std::size_t count = std::max<std::size_t>(1, params.point_candidates);
  std::vector<const Contender*> order = ranked(contenders, std::max<std::size_t>(2, count));
  if (params.point_candidates > 0 && order.size() >= 2 && looseFit(order[0]->candidate, params) &&
      !looseFit(order[1]->candidate, params) &&
      &fitterOfPair(cues, active, *order[0], *order[1], params) == order[1])
    std::swap(order[0], order[1]);
  if (order.size() > count)
    order.resize(count);
  return order;
}

/** The competition of the seeds' candidates: each seed is refined (unless its refined axis
 * was tried already), positioned and scored by its inliers. */
class SeedCompetition {
public:
  SeedCompetition(const CylinderCues& cues, const std::vector<int>& active,
                  const VotingCues& refining, const HoughCylinderParameters& params)
      : cues_(cues)
      , active_(active)
      , refining_(refining)
      , params_(params)
  {
  }

  void run(const std::vector<AxisSeed>& seeds)
  {
    for (const AxisSeed& seed : seeds)
      tryOne(seed);
  }
  /** Whether the best candidate is convincing (convinces). */
  bool convincing() const
  {
    return convinces(contenders_, active_.size());
  }
  std::vector<Contender> contenders() &&
  {
    return std::move(contenders_);
  }

private:
  /** The seed's refined axis competes (unless it was tried already); the seed's own axis
   * instead when the refined one, moved by more than half a cell, gives no candidate. A moved
   * seed's own axis is kept for meetSeedAxes. A seed from the points competes as it is. */
  void tryOne(const AxisSeed& seed)
  {
    if (seed.from_points) {
      if (untried(seed.axis))
        add(contend(seed.axis));
      return;
    }
    if (!params_.refine) {
      add(contend(seed.axis));
      return;
    }
    const Eigen::Vector3f axis =
      refineAxis(refining_, seed.axis, std::max(3.f * seed.cell_radius, 10.f * kOneDegree));
    if (!untried(axis))
      return;
    std::optional<Contender> refined = contend(axis);
    const bool moved = axisAngle(axis, seed.axis) > 0.5f * seed.cell_radius;
    if (refined && moved)
      refined->seed_axis = seed.axis;
    else if (!refined && moved && untried(seed.axis))
      refined = contend(seed.axis);
    add(std::move(refined));
  }
  /** Whether no axis within half a degree of \a axis was tried; if so, it is now. */
  bool untried(const Eigen::Vector3f& axis)
  {
    if (std::any_of(tried_.begin(), tried_.end(), [&](const Eigen::Vector3f& t) {
          return axisAngle(t, axis) < 0.5f * kOneDegree;
        }))
      return false;
    tried_.push_back(axis);
    return true;
  }
  std::optional<Contender> contend(const Eigen::Vector3f& axis) const
  {
    return facyl::contend(cues_, active_, axis, params_);
  }
  void add(std::optional<Contender> c)
  {
    if (c)
      contenders_.push_back(std::move(*c));
  }

  const CylinderCues& cues_;
  const std::vector<int>& active_;
  const VotingCues& refining_;
  const HoughCylinderParameters& params_;
  std::vector<Contender> contenders_;
  std::vector<Eigen::Vector3f> tried_; ///< axes positioned so far
};

/** The candidates that the cues propose among the \a active points: the seeds (the
 * accumulators' peaks, the planar normals' direction) compete; when none is convincing and
 * curvature cues were used, the best normals-only peak competes too (curvature directions fade
 * into noise before normals do: a short or noisy cylinder). */
std::vector<Contender>
competeSeeds(const CylinderCues& cues, const std::vector<int>& active,
             const std::vector<OrientationAccumulator>& accumulators,
             const HoughCylinderParameters& params)
{
  const bool curvature = params.voting_mode == VotingMode::SoftCurvature;
  const std::vector<int> voters = subsample(active, params.max_voting_points);
  const VotingCues voting = gatherVotingCues(cues, voters, curvature);
  // The axis refinement needs fewer normals than the votes (the final least squares uses all
  // inliers anyway).
  const VotingCues refining =
    voters.size() > 400 ? gatherVotingCues(cues, subsample(voters, 400), curvature) : voting;
  std::vector<AxisSeed> seeds;
  for (const auto& acc : accumulators)
    addVotePeaks(acc, voting, params.voting_mode, params, params.orientation_candidates, seeds);
  // An axis held fixed (no refinement: an axis given, like the support's normal) is the only
  // one asked about: seeds of other axes would answer another question.
  if (params.refine) {
    if (curvature)
      addPlanarNormalsSeed(voting, accumulators.front().cellRadius(), seeds);
    addElongationSeeds(cues, active, accumulators.front().cellRadius(), seeds);
  }

  SeedCompetition competition(cues, active, refining, params);
  competition.run(seeds);
  if (curvature && !competition.convincing()) {
    std::vector<AxisSeed> more = seeds;
    addVotePeaks(accumulators.front(), voting, VotingMode::SoftNormal, params, 1, more);
    competition.run({more.begin() + static_cast<std::ptrdiff_t>(seeds.size()), more.end()});
  }
  return std::move(competition).contenders();
}

/** Neighbours of a coarse cue at most: four times the usual k (kDefaultNeighbours, 16), a
 * normal's noise halved. */
constexpr int kCoarseNeighbours = 4 * kDefaultNeighbours;
/** Coarse neighbourhoods are searched for every second point, and shared with the points they
 * hold (estimatePointCues): the search is most of the coarse cues' cost, and a neighbourhood
 * of up to 64 points moved by one point's spacing is nearly the same set (its normal turns
 * about the axis, which leaves the orientation votes alone). facyl_bench, issue 17's noise
 * levels (10-30% of r, six seeds, 2,880 clouds): 107 failures either way (11 fits fail that
 * did not, 12 no longer fail), median fit time 15-23% less in two alternated pairs; every
 * fourth point: 118 failures. */
constexpr int kCoarseStride = 2;

/** \a cues with the cues of the \a active points estimated again from their neighbours among
 * the active points within \a radius (estimatePointCues, signs kept; neighbourhoods shared by
 * kCoarseStride). */
CylinderCues
coarserCues(const CylinderCues& cues, const std::vector<int>& active, float radius)
{
  const Eigen::Matrix3Xf points = cues.points(Eigen::all, active);
  const Eigen::Matrix3Xf normals = cues.normals(Eigen::all, active);
  const PointCues coarse =
    estimatePointCues(points, radius, kCoarseNeighbours, normals, kCoarseStride);
  CylinderCues out = cues;
  const bool curvature = cues.weights.size() == cues.points.cols();
  for (std::size_t k = 0; k < active.size(); ++k) {
    const auto i = static_cast<Eigen::Index>(k);
    if (!coarse.normals.col(i).allFinite())
      continue;
    const int s = active[k];
    out.normals.col(s) = coarse.normals.col(i);
    if (curvature) {
      const bool measured = coarse.curvature_directions.col(i).allFinite();
      out.curvature_directions.col(s) =
        measured ? Eigen::Vector3f(coarse.curvature_directions.col(i)) : Eigen::Vector3f::Zero();
      out.weights(s) = measured ? coarse.weights(i) : 0.f;
    }
  }
  return out;
}

/** The answer while the cues are good: \a refined (the best of \a contenders, refined on its
 * inliers), unless no contender convinces and a seed's own axis, met (meetSeedAxes), gives
 * a new best; then that one, refined. Not at high noise: there refineAxis moves a seed by
 * noise, and the competition on the points decides instead (facyl_bench, paper setting, 10%
 * noise: meeting there turned 3 good fits of 200 into failures). */
Candidate
goodCuesFit(const CylinderCues& cues, const std::vector<int>& active,
            std::vector<Contender>& contenders, const Candidate& refined,
            const HoughCylinderParameters& params)
{
  if (convinces(contenders, active.size()) || !meetSeedAxes(cues, active, contenders, params))
    return refined;
  return refineCandidate(cues, active, ranked(contenders, 1).front()->candidate, params);
}

/** The share of the active points that a settled fit must explain for the coarse stage to be
 * skipped: less than a fifth of the points is then left beside it, and the coarse cues, which
 * tell a cylinder from structure beside it (a table) that noisy normals cannot, have nothing to
 * tell apart. facyl_bench, issue 17's noise levels (six seeds, 2,880 clouds): 107 -> 104
 * failures, the random setting's noisy fits 7.7-8.6 -> 2.8-2.9 ms, the practical setting (a
 * plane beside: the coarse stage runs) unchanged; at 0.7, practical 75 -> 93 failures; at 0.9
 * the random setting at 30% noise takes the coarse stage again (8.4 ms). */
constexpr double kExplainedShare = 0.8;

/** Whether \a m, a settled fit, explains kExplainedShare of the \a active points. */
bool
explainsTheCloud(const CylinderModel& m, std::size_t active)
{
  return static_cast<double>(m.inliers.size()) >= kExplainedShare * static_cast<double>(active);
}

/** The answer once the cues are noise: \a c, settled on the points, with its radius unbiased
 * at its robust scale (unbiasedRadius), described with \a cues. At 20% noise this halves the
 * median radius error (facyl_bench, issue 17's levels, six seeds). */
CylinderModel
describeSettled(const CylinderCues& cues, const std::vector<int>& active, Candidate c,
                const HoughCylinderParameters& params)
{
  c.radius = unbiasedRadius(c.radius, c.scale);
  return describe(cues, active, c, params);
}

/** One cylinder among the \a active points: the candidates of the cues (competeSeeds), the best
 * refined (with params.refine) and described. When the best candidate's normals are more noise
 * than cue, cues at a coarser scale (params.coarse_scale of its radius) propose candidates too,
 * and these cues judge them all. */
std::optional<CylinderModel>
fitOne(const CylinderCues& cues, const std::vector<int>& active,
       const std::vector<OrientationAccumulator>& accumulators,
       const HoughCylinderParameters& params)
{
  std::vector<Contender> contenders = competeSeeds(cues, active, accumulators, params);
  if (contenders.empty())
    return std::nullopt;
  const std::vector<const Contender*> finalists = finalistsOf(cues, active, contenders, params);
  const Contender& best = *finalists.front();
  if (!params.refine)
    return best.model;
  // The best, refined by least squares on its inliers: facyl 0.1's answer, and still the
  // answer while the cues are good.
  const Candidate refined = refineCandidate(cues, active, best.candidate, params);
  const LocalNoise local(cues, active);
  if (params.point_candidates == 0 ||
      !cuesAreNoise(probeNoise(cues, active, refined, params), local, params))
    return describe(cues, active, goodCuesFit(cues, active, contenders, refined, params), params);

  const auto settled = settleOnPoints(cues, active, finalists, params);
  if (!settled) // no refinement on the points held
    return describe(cues, active, refined, params);
  CylinderModel answer = describeSettled(cues, active, *settled, params);
  if (!(params.coarse_scale > 0.f) || !cuesAreNoise(*settled, local, params) ||
      explainsTheCloud(answer, active.size()))
    return answer;
  // The cues are more noise than cue, and structure beside the winner remains: cues at the
  // coarse scale propose candidates too, and the coarse cues judge them against the winner.
  const CylinderCues coarse = coarserCues(cues, active, params.coarse_scale * settled->radius);
  const std::vector<Contender> coarse_contenders =
    competeSeeds(coarse, active, accumulators, params);
  Contender leader;
  leader.candidate = *settled;
  std::vector<const Contender*> judged_ones{&leader};
  for (const Contender* c : ranked(coarse_contenders, params.point_candidates))
    judged_ones.push_back(c);
  const auto judged = settleOnPoints(coarse, active, judged_ones, params);
  return describeSettled(coarse, active, judged ? *judged : *settled, params);
}

/** Whether \a model has the \a min_inliers points a cylinder needs among the \a active ones:
 * its inliers and the points of its end caps (endCapPoints; counted only when the inliers
 * alone fall short), with at least 10 inliers (or min_inliers, if smaller) of its own. */
bool
enoughPoints(const CylinderCues& cues, const std::vector<int>& active, const CylinderModel& model,
             std::size_t min_inliers, const HoughCylinderParameters& params)
{
  const std::size_t inliers = model.inliers.size();
  if (inliers >= min_inliers)
    return true;
  if (inliers < std::min<std::size_t>(10, min_inliers))
    return false;
  // The caps among the active points that are not inliers.
  std::vector<char> inlier(static_cast<std::size_t>(cues.points.cols()), 0);
  for (const auto s : model.inliers)
    inlier[static_cast<std::size_t>(s)] = 1;
  std::vector<int> others;
  for (const int s : active)
    if (!inlier[static_cast<std::size_t>(s)])
      others.push_back(s);
  const auto caps = endCapPoints(cues.points(Eigen::all, others), cues.normals(Eigen::all, others),
                                 model, params.normal_angle_threshold);
  return inliers + caps.size() >= min_inliers;
}

} // namespace

std::vector<CylinderModel>
fitCylinders(const CylinderCues& cues, const std::vector<OrientationAccumulator>& accumulators,
             const HoughCylinderParameters& params, std::size_t total_points)
{
  std::vector<CylinderModel> models;
  const Eigen::Index n = cues.points.cols();
  if (n == 0 || accumulators.empty())
    return models;
  const bool curvature = params.voting_mode == VotingMode::SoftCurvature &&
                         cues.weights.size() == n && cues.curvature_directions.cols() == n;
  HoughCylinderParameters p = params;
  if (params.voting_mode == VotingMode::SoftCurvature && !curvature)
    p.voting_mode = VotingMode::SoftNormal; // the caller checks; this is a last guard
  const std::size_t min_inliers = minimumInliers(p, static_cast<std::size_t>(n));
  const double total_weight = curvature ? cues.weights.cast<double>().sum() : double(n);

  std::vector<char> alive(static_cast<std::size_t>(n), 1);
  for (std::size_t round = 0; round < p.max_cylinders; ++round) {
    std::vector<int> active;
    for (Eigen::Index s = 0; s < n; ++s)
      if (alive[static_cast<std::size_t>(s)])
        active.push_back(static_cast<int>(s));
    if (active.size() < min_inliers)
      break;
    auto model = fitOne(cues, active, accumulators, p);
    if (!model || !enoughPoints(cues, active, *model, min_inliers, p))
      break;
    double w = 0.0;
    for (const auto s : model->inliers)
      w += curvature ? cues.weights(s) : 1.0;
    model->confidence = total_weight > 0.0 ? static_cast<float>(w / total_weight) : 0.f;
    model->inlier_ratio = static_cast<float>(model->inliers.size()) /
                          static_cast<float>(std::max<std::size_t>(1, total_points));
    // Remove the inliers and whatever lies inside the finite cylinder (its lids).
    for (const auto s : model->inliers)
      alive[static_cast<std::size_t>(s)] = 0;
    const float reach = model->radius + model->distance_threshold;
    for (const int s : active) {
      const Eigen::Vector3f w3 = cues.points.col(s) - model->base;
      const float t = w3.dot(model->axis);
      if (t > -model->distance_threshold && t < model->height + model->distance_threshold &&
          (w3 - t * model->axis).norm() < reach)
        alive[static_cast<std::size_t>(s)] = 0;
    }
    models.push_back(std::move(*model));
  }
  return models;
}

} // namespace facyl
