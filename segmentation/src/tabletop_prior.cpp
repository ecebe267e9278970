/*
 * facyl: fast cylinder detection for PCL.
 * The support prior of a stream (SupportPrior, segment_tabletop.h; the steps' functions in
 * tabletop_steps.h): which plane of a frame is the
 * prior's, and the preference it gives its family and its plane over what the frame alone would
 * choose.
 */
#include "tabletop_steps.h"

#include <facyl/features/polygon.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace facyl {

SupportPrior
SupportPrior::transformed(const Eigen::Affine3f& t) const
{
  SupportPrior out = *this;
  out.plane = transformPlane(plane, t);
  out.centre = t * centre;
  for (auto& e : out.extent)
    e = t * e;
  return out;
}

float
priorMismatch(const SupportPrior& prior, const Eigen::Vector4f& plane)
{
  const float inf = std::numeric_limits<float>::infinity();
  if (!prior.valid() || !plane.allFinite())
    return inf;
  const float cos_angle = prior.plane.head<3>().dot(plane.head<3>().normalized());
  const float offset = std::abs(plane.head<3>().dot(prior.centre) + plane[3]);
  if (!(cos_angle >= std::cos(prior.max_angle)) || !(offset <= prior.max_offset))
    return inf;
  const float angle = std::acos(std::min(1.f, cos_angle));
  return std::max(angle / prior.max_angle,
                  prior.max_offset > 0.f ? offset / prior.max_offset : 0.f);
}

bool
consistentWithPrior(const SupportPrior& prior, const Eigen::Vector4f& plane)
{
  return std::isfinite(priorMismatch(prior, plane));
}

std::vector<Eigen::Vector2f>
priorExtentHull(const SupportPrior& prior, const Eigen::Vector4f& plane,
                const Eigen::Affine3f& plane_to_frame, const std::vector<Eigen::Vector2f>& polygon)
{
  if (prior.extent.empty() || !consistentWithPrior(prior, plane))
    return polygon;
  const Eigen::Affine3f to_plane = plane_to_frame.inverse();
  std::vector<Eigen::Vector2f> points = polygon;
  for (const auto& e : prior.extent)
    if (e.allFinite())
      points.push_back((to_plane * e).head<2>());
  return convexHull2D(std::move(points));
}

namespace tabletop {

int
priorCandidate(const Setup& setup, const std::vector<Candidate>& candidates)
{
  if (!setup.prior)
    return -1;
  // Of several (a counter and the slabs lying on it), the nearest.
  int best = -1;
  float least = std::numeric_limits<float>::infinity();
  for (std::size_t k = 0; k < candidates.size(); ++k) {
    const float m = priorMismatch(*setup.prior, candidates[k].plane);
    if (!candidates[k].points.empty() && m < least)
      best = static_cast<int>(k), least = m;
  }
  return best;
}

void
keepPriorCandidate(const Setup& setup, std::vector<Candidate>& candidates, std::size_t kept)
{
  const int k = priorCandidate(setup, candidates);
  if (kept == 0 || k < 0 || static_cast<std::size_t>(k) < kept)
    return;
  // Its place: the last one kept; the candidates between move one on.
  std::rotate(candidates.begin() + static_cast<std::ptrdiff_t>(kept - 1), candidates.begin() + k,
              candidates.begin() + k + 1);
}

int
priorFamily(const Setup& setup, const SortedFrame& sorted,
            const std::vector<std::vector<std::size_t>>& families)
{
  if (!setup.prior)
    return -1;
  const SupportPrior& prior = *setup.prior;
  for (std::size_t f = 0; f < families.size(); ++f)
    for (const std::size_t s : families[f])
      if (consistentWithPrior(prior, sorted.all[s].plane))
        return static_cast<int>(f);
  const float cos_max = std::cos(prior.max_angle);
  for (std::size_t f = 0; f < families.size(); ++f)
    if (!families[f].empty() &&
        sorted.all[families[f].front()].plane.head<3>().dot(prior.plane.head<3>()) >= cos_max)
      return static_cast<int>(f);
  return -1;
}

std::size_t
familyWithPrior(int prior_family, std::size_t chosen, const std::vector<char>& with_supports,
                const std::vector<std::size_t>& standing, SupportPriorResult& result)
{
  if (prior_family < 0 || static_cast<std::size_t>(prior_family) >= with_supports.size() ||
      !with_supports[static_cast<std::size_t>(prior_family)])
    return chosen;
  const auto f = static_cast<std::size_t>(prior_family);
  result.challenged = chosen != f && standing[chosen] > standing[f];
  return f;
}

std::size_t
tableWithPrior(const Setup& setup, const std::vector<SupportPlane>& supports, Trial& trial)
{
  // The frame's own table: the most object points standing on it; else the largest support.
  std::size_t table = 0;
  for (std::size_t s = 0; s < supports.size(); ++s) {
    trial.standing += supports[s].standing_points;
    if (supports[s].standing_points > supports[table].standing_points ||
        (supports[s].standing_points == supports[table].standing_points &&
         supports[s].inliers.indices.size() > supports[table].inliers.indices.size()))
      table = s;
  }
  trial.table_is_prior = false;
  if (!setup.prior)
    return table;
  // Of several supports that are the prior's plane (a counter and the slabs lying on it), the
  // nearest: the table does not jump between them from frame to frame.
  float least = std::numeric_limits<float>::infinity();
  for (std::size_t s = 0; s < supports.size(); ++s) {
    const float m = priorMismatch(*setup.prior, supports[s].plane);
    if (m < least) {
      trial.table_is_prior = true;
      table = s, least = m;
    }
  }
  return table;
}

} // namespace tabletop
} // namespace facyl
