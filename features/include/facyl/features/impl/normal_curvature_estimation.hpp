/*
 * facyl: fast cylinder detection for PCL.
 */
#pragma once

#include <facyl/features/normal_curvature_estimation.h>

#include <pcl/common/point_tests.h>
#include <pcl/console/print.h>

#include <limits>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

namespace facyl {

template <typename PointInT, typename PointOutT>
bool
NormalCurvatureEstimation<PointInT, PointOutT>::initCompute()
{
  if (!pcl::Feature<PointInT, PointOutT>::initCompute())
    return false;
  if (this->k_ != 0 && this->k_ < 3) {
    PCL_ERROR("[facyl::%s::compute] k = %d: a normal needs at least 3 neighbours.\n",
              this->getClassName().c_str(), this->k_);
    this->deinitCompute();
    return false;
  }
  if (this->search_radius_ < 0.0) {
    PCL_ERROR("[facyl::%s::compute] negative search radius %g.\n",
              this->getClassName().c_str(), this->search_radius_);
    this->deinitCompute();
    return false;
  }
  if (input_normals_ && input_normals_->size() != this->surface_->size()) {
    PCL_ERROR("[facyl::%s::compute] %zu input normals for %zu surface points.\n",
              this->getClassName().c_str(), input_normals_->size(), this->surface_->size());
    this->deinitCompute();
    return false;
  }
  return true;
}

template <typename PointInT, typename PointOutT>
void
NormalCurvatureEstimation<PointInT, PointOutT>::computeFeature(PointCloudOut& output)
{
  const auto& input = *this->input_;
  const auto& surface = *this->surface_;
  const auto& indices = *this->indices_;
  const std::size_t n = indices.size();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const Eigen::Vector3f nan3 = Eigen::Vector3f::Constant(nan);
  const int threads =
#ifdef _OPENMP
      threads_ > 0 ? static_cast<int>(threads_) : omp_get_max_threads();
#else
      1;
#endif
  (void)threads;

  // Orientation towards the view point, so neighbouring normals agree in sign.
  const auto orient = [this](const Eigen::Vector3f& p, Eigen::Vector3f& normal) {
    if ((view_point_ - p).dot(normal) < 0.f)
      normal = -normal;
  };

  // 1. One neighbourhood query per point; PCA normals of the query points.
  std::vector<pcl::Indices> neighbours(n);
  std::vector<Eigen::Vector3f> normals(n, nan3);
  std::vector<float> variation(n, nan);
#pragma omp parallel num_threads(threads)
  {
    std::vector<float> distances;
#pragma omp for schedule(dynamic, 128)
    for (std::ptrdiff_t i = 0; i < static_cast<std::ptrdiff_t>(n); ++i) {
      const auto& q = input[indices[i]];
      if (!pcl::isFinite(q) ||
          this->searchForNeighbors(indices[i], this->search_parameter_, neighbours[i],
                                   distances) < 3) {
        neighbours[i].clear();
        continue;
      }
      if (input_normals_)
        continue; // normals are known; only the neighbour lists are needed
      const auto& nb = neighbours[i];
      Eigen::Vector3f normal;
      float sv;
      if (estimateNormal(
              nb.size(),
              [&](std::size_t j) { return surface[nb[j]].getVector3fMap(); }, normal, sv)) {
        orient(q.getVector3fMap(), normal);
        normals[i] = normal;
        variation[i] = sv;
      }
    }
  }

  // 2. Normals at every neighbour. When the neighbours are the query points themselves (no
  //    search surface, no indices: the common case) nothing more is searched; otherwise the
  //    missing neighbours get their own PCA normal.
  std::vector<Eigen::Vector3f> surface_normals;
  if (input_normals_) {
    surface_normals.resize(surface.size());
    for (std::size_t j = 0; j < surface.size(); ++j) {
      const auto& m = (*input_normals_)[j];
      surface_normals[j] = Eigen::Vector3f(m.normal_x, m.normal_y, m.normal_z);
    }
    for (std::size_t i = 0; i < n; ++i) {
      if (neighbours[i].empty())
        continue;
      Eigen::Vector3f m = (*input_normals_)[indices[i]].getNormalVector3fMap();
      const float len = m.norm();
      if (this->fake_surface_ && std::isfinite(len) && len > 0.f) {
        normals[i] = m / len;
        variation[i] = (*input_normals_)[indices[i]].curvature;
      }
      else if (!this->fake_surface_) {
        // The query points are not surface points: their normal is the PCA normal.
        Eigen::Vector3f normal;
        float sv;
        const auto& nb = neighbours[i];
        if (estimateNormal(
                nb.size(),
                [&](std::size_t j) { return surface[nb[j]].getVector3fMap(); }, normal,
                sv)) {
          orient(input[indices[i]].getVector3fMap(), normal);
          normals[i] = normal;
          variation[i] = sv;
        }
      }
    }
  }
  else {
    surface_normals.assign(surface.size(), nan3);
    std::vector<char> known(surface.size(), 0);
    if (this->fake_surface_) {
      for (std::size_t i = 0; i < n; ++i) {
        surface_normals[indices[i]] = normals[i];
        known[indices[i]] = 1;
      }
    }
    pcl::Indices missing;
    for (std::size_t i = 0; i < n; ++i)
      for (const auto j : neighbours[i])
        if (!known[j]) {
          known[j] = 1;
          missing.push_back(j);
        }
#pragma omp parallel num_threads(threads)
    {
      pcl::Indices nb;
      std::vector<float> distances;
#pragma omp for schedule(dynamic, 128)
      for (std::ptrdiff_t m = 0; m < static_cast<std::ptrdiff_t>(missing.size()); ++m) {
        const auto j = missing[m];
        if (this->searchForNeighbors(surface, j, this->search_parameter_, nb, distances) < 3)
          continue;
        Eigen::Vector3f normal;
        float sv;
        if (estimateNormal(
                nb.size(), [&](std::size_t t) { return surface[nb[t]].getVector3fMap(); },
                normal, sv)) {
          orient(surface[j].getVector3fMap(), normal);
          surface_normals[j] = normal;
        }
      }
    }
  }

  // 3. Principal curvatures from the neighbours' normals, and the output.
  bool dense = true;
#pragma omp parallel for num_threads(threads) schedule(dynamic, 128) reduction(&& : dense)
  for (std::ptrdiff_t i = 0; i < static_cast<std::ptrdiff_t>(n); ++i) {
    PointOutT& out = output[i];
    PrincipalCurvatures pc;
    const auto& nb = neighbours[i];
    const bool ok = normals[i].allFinite() &&
                    principalCurvaturesFromNormals(
                        normals[i], nb.size(),
                        [&](std::size_t j) { return surface_normals[nb[j]]; }, pc);
    if (!ok) {
      out.normal_x = out.normal_y = out.normal_z = nan;
      out.principal_curvature_x = out.principal_curvature_y = out.principal_curvature_z = nan;
      out.curvature = out.pc1 = out.pc2 = nan;
      dense = false;
      continue;
    }
    out.normal_x = normals[i].x();
    out.normal_y = normals[i].y();
    out.normal_z = normals[i].z();
    out.curvature = variation[i];
    out.principal_curvature_x = pc.direction.x();
    out.principal_curvature_y = pc.direction.y();
    out.principal_curvature_z = pc.direction.z();
    out.pc1 = pc.k_max;
    out.pc2 = pc.k_min;
  }
  output.is_dense = dense;
}

} // namespace facyl

#define FACYL_INSTANTIATE_NormalCurvatureEstimation(T, OutT)                                \
  template class facyl::NormalCurvatureEstimation<T, OutT>;
