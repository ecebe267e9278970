/*
 * facyl: fast cylinder detection for PCL.
 * The search: candidate axes from the accumulators, a position for each, the best one
 * refined; several cylinders one after another (fitCylinders).
 */
#include "fitting_detail.h"

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
validate(const HoughCylinderParameters& p)
{
  std::ostringstream why;
  if (p.kernel_exponent < 1 || p.kernel_exponent > 16)
    why << "kernel exponent " << p.kernel_exponent << " is not in [1, 16]";
  else if (!(p.radius_min >= 0.f) || !std::isfinite(p.radius_min))
    why << "minimum radius " << p.radius_min << " is not a finite value >= 0";
  else if (!(p.radius_max > p.radius_min))
    why << "radius limits [" << p.radius_min << ", " << p.radius_max
        << "] are empty or inverted";
  else if (!(p.distance_threshold >= 0.f) || !std::isfinite(p.distance_threshold))
    why << "distance threshold " << p.distance_threshold << " is not a finite value >= 0";
  else if (!(p.normal_angle_threshold > 0.f) ||
           !(p.normal_angle_threshold <= static_cast<float>(M_PI / 2) + 1e-6f))
    why << "normal angle threshold " << p.normal_angle_threshold << " rad is not in (0, pi/2]";
  else if (p.orientation_candidates < 1)
    why << "at least one orientation candidate is needed";
  else if (p.max_cylinders < 1)
    why << "max cylinders must be at least 1";
  else if (p.circle_grid < 8 || p.circle_grid > 4096)
    why << "circle grid " << p.circle_grid << " is not in [8, 4096]";
  return why.str();
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
};

/** Robust noise estimate: 1.4826 MAD of the surface distances of the points near it. */
float
estimateThreshold(const CylinderCues& cues, const std::vector<int>& columns,
                  const Candidate& c)
{
  std::vector<float> residuals;
  residuals.reserve(columns.size());
  for (const int s : columns) {
    const float e = std::abs(distanceToLine(cues.points.col(s), c.point_on_axis, c.axis) - c.radius);
    if (e < 0.3f * c.radius)
      residuals.push_back(e);
  }
  const float sigma = 1.4826f * medianOf(residuals);
  return std::clamp(3.f * sigma, 1e-3f * c.radius, 0.1f * c.radius);
}

/** Inliers: near the surface, and with a normal close to the surface normal. */
std::vector<int>
selectInliers(const CylinderCues& cues, const std::vector<int>& columns, const Candidate& c,
              float cos_normal, bool outward)
{
  std::vector<int> inliers;
  for (const int s : columns) {
    const Eigen::Vector3f w = cues.points.col(s) - c.point_on_axis;
    const Eigen::Vector3f d = w - w.dot(c.axis) * c.axis;
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

/** Step 2 for one axis: circle Hough on the supporters, circle and cylinder least squares. */
std::optional<Candidate>
fitPosition(const CylinderCues& cues, const std::vector<int>& active, const Eigen::Vector3f& axis,
            const HoughCylinderParameters& params)
{
  Eigen::Vector3f u, v;
  basisFor(axis, u, v);
  const std::vector<int> support = supporters(cues, active, axis, params);
  if (support.size() < 5)
    return std::nullopt;

  // The supporters projected on the plane orthogonal to the axis, with their normals.
  Eigen::Matrix<float, 2, 3> project;
  project << u.transpose(), v.transpose();
  const Eigen::Matrix3Xf support_points = cues.points(Eigen::all, support);
  const Eigen::Matrix3Xf support_normals = cues.normals(Eigen::all, support);
  const Eigen::Matrix2Xf q = project * support_points;
  const Eigen::Matrix2Xf m = project * support_normals;
  const Eigen::RowVectorXf m_len = m.colwise().norm();
  const Eigen::Matrix2Xf qm = m.array().rowwise() / m_len.array();
  const float extent = (q.rowwise().maxCoeff() - q.rowwise().minCoeff()).norm();
  const float r_max = std::min(params.radius_max, 2.f * extent);
  if (!(r_max > params.radius_min))
    return std::nullopt;

  // Circle Hough voters: an even subset of the supporters whose normal is not along the axis.
  std::vector<Eigen::Index> voters;
  const auto n_support = static_cast<Eigen::Index>(support.size());
  const Eigen::Index n_voters = std::min<Eigen::Index>(n_support, 300);
  for (Eigen::Index k = 0; k < n_voters; ++k) {
    const Eigen::Index i = k * n_support / n_voters;
    if (m_len(i) > 0.3f)
      voters.push_back(i);
  }
  const Eigen::Matrix2Xf vq = q(Eigen::all, voters);
  const Eigen::Matrix2Xf vm = qm(Eigen::all, voters);
  Circle circle;
  if (!houghCircle(vq, vm, params.radius_min, r_max, params.circle_grid, circle))
    return std::nullopt;
  float cell = (extent + 2.f * r_max) / static_cast<float>(params.circle_grid);

  // The points that agree with a circle: near it, with a normal along its radius. Other
  // structure that shares the axis direction (a table under a lying can) drops out here.
  const float cos_n = std::cos(params.normal_angle_threshold);
  const auto agreeing = [&](const Eigen::Matrix2Xf& pts, const Eigen::Matrix2Xf& nrm,
                            const Circle& c, float band) {
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
  };
  // Coarse to fine: with a wide radius range the first grid's cells can exceed the radius;
  // vote again on the agreeing points over a range around the first estimate.
  if (cell > 0.1f * circle.radius) {
    const auto keep = agreeing(vq, vm, circle, std::max(0.5f * circle.radius, 2.f * cell));
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
  const auto keep = agreeing(q, qm, circle, std::max(0.3f * circle.radius, 3.f * cell));
  if (keep.size() < 5 ||
      !fitCircle(q(Eigen::all, keep), std::max(0.3f * circle.radius, 3.f * cell), circle))
    return std::nullopt;
  if (circle.radius < params.radius_min || circle.radius > r_max)
    return std::nullopt;

  Candidate c;
  c.axis = axis;
  c.point_on_axis = circle.center.x() * u + circle.center.y() * v;
  c.radius = circle.radius;
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
  for (int round = 0; round < 3; ++round) {
    const std::vector<int> inliers =
      selectInliers(cues, active, c, cos_normal, params.outward_normals);
    if (inliers.size() < 6)
      break;
    const Eigen::Matrix3Xf pts = cues.points(Eigen::all, inliers);
    Candidate next = c;
    if (!refineCylinder(pts, next.point_on_axis, next.axis, next.radius) ||
        next.radius < params.radius_min || next.radius > c.radius_limit)
      break;
    if (auto_threshold)
      next.threshold = estimateThreshold(cues, support, next);
    const bool settled = axisAngle(next.axis, c.axis) < 1e-5f &&
                         std::abs(next.radius - c.radius) < 1e-6f * c.radius;
    c = next;
    if (settled)
      break;
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
  const std::vector<int> inliers =
      selectInliers(cues, active, c, std::cos(params.normal_angle_threshold),
                    params.outward_normals);
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
};

/** Appends to \a seeds the \a count highest peaks of \a acc's votes (mode \a mode) that are not
 * within reach of a seed there already: the cell radius for peaks of the fit's own mode (the
 * refinement reaches that far), the peaks' separation for another mode's. */
void
addVotePeaks(const OrientationAccumulator& acc, const VotingCues& voting, VotingMode mode,
             const HoughCylinderParameters& params, std::size_t count,
             std::vector<AxisSeed>& seeds)
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

/** Candidates compete on their inliers. With curvature cues each inlier counts by its vote
 * for the candidate's axis (eq. 3): a plane strip that happens to fit a wide cylinder (a lid
 * seen along an axis in its plane) has random c_max and low weights, a real lateral surface
 * has c_max orthogonal to the axis and weights near 1. Either way the score is scaled by
 * normalRotationSlope: plane strips score ~0. */
double
candidateScore(const CylinderCues& cues, const CylinderModel& m, bool curvature)
{
  const double slope = normalRotationSlope(cues.points(Eigen::all, m.inliers),
                                           cues.normals(Eigen::all, m.inliers),
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

/** The competition of the seeds' candidates: each seed is refined (unless its refined axis
 * was tried already), positioned and scored; the best is kept. */
class SeedCompetition {
public:
  SeedCompetition(const CylinderCues& cues, const std::vector<int>& active,
                  const VotingCues& refining, const HoughCylinderParameters& params)
  : cues_(cues), active_(active), refining_(refining), params_(params),
    curvature_(params.voting_mode == VotingMode::SoftCurvature)
  {}

  void
  run(const std::vector<AxisSeed>& seeds)
  {
    for (const AxisSeed& seed : seeds)
      tryOne(seed);
  }
  /** Whether the best candidate is convincing: a quarter of the points, half the
   * circumference. */
  bool
  convincing() const
  {
    return best_ && best_->angular_coverage >= 0.5f && 4 * best_->inliers.size() >= active_.size();
  }
  /** The winner, refined by least squares on all five parameters (params.refine). */
  std::optional<CylinderModel>
  winner() const
  {
    if (best_ && params_.refine)
      return describe(cues_, active_, refineCandidate(cues_, active_, best_candidate_, params_),
                      params_);
    return best_;
  }

private:
  void
  tryOne(const AxisSeed& seed)
  {
    Eigen::Vector3f axis = seed.axis;
    if (params_.refine) {
      axis = refineAxis(refining_, seed.axis, std::max(3.f * seed.cell_radius, 10.f * kOneDegree));
      if (std::any_of(tried_.begin(), tried_.end(), [&](const Eigen::Vector3f& t) {
            return axisAngle(t, axis) < 0.5f * kOneDegree;
          }))
        return;
      tried_.push_back(axis);
    }
    const auto candidate = fitPosition(cues_, active_, axis, params_);
    if (!candidate)
      return;
    CylinderModel model = describe(cues_, active_, *candidate, params_);
    const double s = candidateScore(cues_, model, curvature_);
    if (!best_ || s > best_score_ || (s == best_score_ && model.rms_error < best_->rms_error)) {
      best_ = std::move(model);
      best_score_ = s;
      best_candidate_ = *candidate;
    }
  }

  const CylinderCues& cues_;
  const std::vector<int>& active_;
  const VotingCues& refining_;
  const HoughCylinderParameters& params_;
  const bool curvature_;
  std::optional<CylinderModel> best_;
  Candidate best_candidate_;
  double best_score_{-1.0};
  std::vector<Eigen::Vector3f> tried_; ///< refined axes
};

/** One cylinder among the \a active points: the seeds (the accumulators' peaks, the planar
 * normals' direction) compete; when none is convincing and curvature cues were used, the best
 * normals-only peak competes too (curvature directions fade into noise before normals do: a
 * short or noisy cylinder). */
std::optional<CylinderModel>
fitOne(const CylinderCues& cues, const std::vector<int>& active,
       const std::vector<OrientationAccumulator>& accumulators,
       const HoughCylinderParameters& params)
{
  const bool curvature = params.voting_mode == VotingMode::SoftCurvature;
  const std::vector<int> voters = subsample(active, params.max_voting_points);
  const VotingCues voting = gatherVotingCues(cues, voters, curvature);
  // The axis refinement needs fewer normals than the votes (the final least squares uses all
  // inliers anyway).
  const VotingCues refining = voters.size() > 400
                                  ? gatherVotingCues(cues, subsample(voters, 400), curvature)
                                  : voting;
  std::vector<AxisSeed> seeds;
  for (const auto& acc : accumulators)
    addVotePeaks(acc, voting, params.voting_mode, params, params.orientation_candidates, seeds);
  if (curvature)
    addPlanarNormalsSeed(voting, accumulators.front().cellRadius(), seeds);

  SeedCompetition competition(cues, active, refining, params);
  competition.run(seeds);
  if (curvature && !competition.convincing()) {
    std::vector<AxisSeed> more = seeds;
    addVotePeaks(accumulators.front(), voting, VotingMode::SoftNormal, params, 1, more);
    competition.run({more.begin() + static_cast<std::ptrdiff_t>(seeds.size()), more.end()});
  }
  return competition.winner();
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
  const std::size_t min_inliers =
      p.min_inliers > 0 ? p.min_inliers
                        : std::max<std::size_t>(10, static_cast<std::size_t>(0.05 * n));
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
    if (!model || model->inliers.size() < min_inliers)
      break;
    double w = 0.0;
    for (const auto s : model->inliers)
      w += curvature ? cues.weights(s) : 1.0;
    model->confidence = total_weight > 0.0 ? static_cast<float>(w / total_weight) : 0.f;
    model->inlier_ratio =
        static_cast<float>(model->inliers.size()) / static_cast<float>(std::max<std::size_t>(1, total_points));
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
