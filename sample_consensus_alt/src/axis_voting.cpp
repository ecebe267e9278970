/*
 * facyl: fast cylinder detection for PCL.
 * Step 1: orientation votes on the accumulator's cells, peaks, and the sub-cell axis refinement.
 */
#include "fitting_detail.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <numeric>

namespace facyl {

using detail::kOneDegree;
using detail::medianOf;
using detail::normalScatter;

bool
parseVotingMode(const std::string& name, VotingMode& mode)
{
  for (const auto m : {VotingMode::Rabbani, VotingMode::SoftNormal, VotingMode::SoftCurvature})
    if (name == toString(m)) {
      mode = m;
      return true;
    }
  return false;
}

std::string
toString(VotingMode mode)
{
  switch (mode) {
  case VotingMode::Rabbani:
    return "rabbani";
  case VotingMode::SoftNormal:
    return "soft-normal";
  case VotingMode::SoftCurvature:
    return "soft-curvature";
  }
  return "unknown";
}

void
VotingCues::resize(Eigen::Index n)
{
  for (auto* a : {&nx, &ny, &nz, &cx, &cy, &cz, &weight})
    a->resize(n);
}

namespace {
/** The vote of every point for one cell, summed: the hot loop (N_d x N evaluations). Plain
 * loops over arrays so that the compiler vectorises them, cloned for AVX2+FMA where the CPU
 * has it (the default build targets baseline x86-64). */
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define FACYL_VOTE_CLONES __attribute__((target_clones("avx2,fma", "default")))
#else
#define FACYL_VOTE_CLONES
#endif

FACYL_VOTE_CLONES float
softVotes(float dx, float dy, float dz, const float* nx, const float* ny, const float* nz,
          const float* cx, const float* cy, const float* cz, const float* w, Eigen::Index n, int p,
          bool curvature)
{
  float acc = 0.f;
  if (curvature && p == 1) {
#pragma omp simd reduction(+ : acc)
    for (Eigen::Index s = 0; s < n; ++s) {
      const float dn = std::abs(dx * nx[s] + dy * ny[s] + dz * nz[s]);
      const float dc = std::abs(dx * cx[s] + dy * cy[s] + dz * cz[s]);
      acc += w[s] * (1.f - dn) * (1.f - dc);
    }
  }
  else if (curvature && p == 2) {
#pragma omp simd reduction(+ : acc)
    for (Eigen::Index s = 0; s < n; ++s) {
      const float dn = std::abs(dx * nx[s] + dy * ny[s] + dz * nz[s]);
      const float dc = std::abs(dx * cx[s] + dy * cy[s] + dz * cz[s]);
      const float b = (1.f - dn) * (1.f - dc);
      acc += w[s] * b * b;
    }
  }
  else if (curvature) {
#pragma omp simd reduction(+ : acc)
    for (Eigen::Index s = 0; s < n; ++s) {
      const float dn = std::abs(dx * nx[s] + dy * ny[s] + dz * nz[s]);
      const float dc = std::abs(dx * cx[s] + dy * cy[s] + dz * cz[s]);
      const float b = (1.f - dn) * (1.f - dc);
      float v = b;
      for (int k = 1; k < p; ++k)
        v *= b;
      acc += w[s] * v;
    }
  }
  else if (p == 1) {
#pragma omp simd reduction(+ : acc)
    for (Eigen::Index s = 0; s < n; ++s)
      acc += w[s] * (1.f - std::abs(dx * nx[s] + dy * ny[s] + dz * nz[s]));
  }
  else if (p == 2) {
#pragma omp simd reduction(+ : acc)
    for (Eigen::Index s = 0; s < n; ++s) {
      const float b = 1.f - std::abs(dx * nx[s] + dy * ny[s] + dz * nz[s]);
      acc += w[s] * b * b;
    }
  }
  else {
#pragma omp simd reduction(+ : acc)
    for (Eigen::Index s = 0; s < n; ++s) {
      const float b = 1.f - std::abs(dx * nx[s] + dy * ny[s] + dz * nz[s]);
      float v = b;
      for (int k = 1; k < p; ++k)
        v *= b;
      acc += w[s] * v;
    }
  }
  return acc;
}

FACYL_VOTE_CLONES float
hardVotes(float dx, float dy, float dz, const float* nx, const float* ny, const float* nz,
          Eigen::Index n, float threshold)
{
  float count = 0.f;
#pragma omp simd reduction(+ : count)
  for (Eigen::Index s = 0; s < n; ++s)
    count += std::abs(dx * nx[s] + dy * ny[s] + dz * nz[s]) < threshold ? 1.f : 0.f;
  return count;
}
} // namespace

void
castVotes(const Eigen::Matrix3Xf& directions, const VotingCues& cues, VotingMode mode,
          int kernel_exponent, float hard_threshold, Eigen::VectorXf& votes)
{
  const Eigen::Index n = cues.size();
  votes.setZero(directions.cols());
  if (n == 0)
    return;
  const int p = std::max(1, kernel_exponent);
  const bool curvature = mode == VotingMode::SoftCurvature;
  for (Eigen::Index i = 0; i < directions.cols(); ++i) {
    const float dx = directions(0, i), dy = directions(1, i), dz = directions(2, i);
    votes(i) =
      mode == VotingMode::Rabbani
        ? hardVotes(dx, dy, dz, cues.nx.data(), cues.ny.data(), cues.nz.data(), n, hard_threshold)
        : softVotes(dx, dy, dz, cues.nx.data(), cues.ny.data(), cues.nz.data(), cues.cx.data(),
                    cues.cy.data(), cues.cz.data(), cues.weight.data(), n, p, curvature);
  }
}

std::vector<Eigen::Index>
findPeaks(const Eigen::Matrix3Xf& directions, const Eigen::VectorXf& votes, std::size_t max_peaks,
          float min_separation)
{
  std::vector<Eigen::Index> order(static_cast<std::size_t>(votes.size()));
  std::iota(order.begin(), order.end(), Eigen::Index{0});
  std::stable_sort(order.begin(), order.end(),
                   [&](Eigen::Index a, Eigen::Index b) { return votes(a) > votes(b); });
  const float cos_sep = std::cos(min_separation);
  std::vector<Eigen::Index> peaks;
  for (const auto i : order) {
    if (peaks.size() >= max_peaks || !(votes(i) > 0.f))
      break;
    bool far = true;
    for (const auto j : peaks)
      if (std::abs(directions.col(i).dot(directions.col(j))) > cos_sep) {
        far = false;
        break;
      }
    if (far)
      peaks.push_back(i);
  }
  return peaks;
}

Eigen::Vector3f
refineAxis(const VotingCues& cues, const Eigen::Vector3f& initial, float initial_tolerance,
           int iterations)
{
  Eigen::Vector3f a = initial.normalized();
  float tolerance = std::min(initial_tolerance, static_cast<float>(M_PI / 2));
  const Eigen::Index n = cues.size();
  Eigen::ArrayXf omega(n);
  std::vector<float> residuals;
  residuals.reserve(static_cast<std::size_t>(n));
  for (int it = 0; it < iterations; ++it) {
    const float s = std::sin(tolerance);
    const Eigen::ArrayXf dn = a.x() * cues.nx + a.y() * cues.ny + a.z() * cues.nz;
    omega = (dn.abs() < s).select(cues.weight * (1.f - (dn / s).square()).square(), 0.f);
    const float total = omega.sum();
    if (!(total > 0.f))
      break;
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
    solver.computeDirect(normalScatter(cues, omega));
    Eigen::Vector3f next = solver.eigenvectors().col(0).cast<float>().normalized();
    if (!next.allFinite())
      break;
    if (next.dot(a) < 0.f)
      next = -next;
    const float change = axisAngle(next, a);
    a = next;
    residuals.clear();
    for (Eigen::Index i = 0; i < n; ++i)
      if (omega(i) > 0.f)
        residuals.push_back(std::abs(dn(i)));
    const float sigma = 1.4826f * medianOf(residuals);
    const float next_tolerance =
      std::clamp(std::asin(std::min(1.f, 3.5f * sigma)), kOneDegree, tolerance);
    const bool settled = change < 1e-5f && next_tolerance == tolerance;
    tolerance = next_tolerance;
    if (settled)
      break;
  }
  return foldToHemisphere(a);
}

} // namespace facyl
