/*
 * facyl: fast cylinder detection for PCL.
 */
#pragma once

#include <facyl/features/neighbourhoods.h>
#include <facyl/features/normal_curvature_estimation.h>
#include <facyl/features/parallel.h>

#include <pcl/common/point_tests.h>
#include <pcl/console/print.h>

#include <atomic>
#include <limits>
#include <stdexcept>
#include <type_traits>
#include <vector>

namespace facyl {

template <typename PointInT, typename PointOutT>
bool
NormalCurvatureEstimation<PointInT, PointOutT>::initCompute()
{
  const char* name = this->getClassName().c_str();
  use_pcl_search_ = static_cast<bool>(this->tree_);
  if (use_pcl_search_) {
    // A search method was given: PCL's own set-up (builds it on the surface).
    if (!pcl::Feature<PointInT, PointOutT>::initCompute())
      return false;
  }
  else {
    // Same checks as pcl::Feature::initCompute, without building a FLANN tree that the
    // internal kd-tree would not use.
    if (!pcl::PCLBase<PointInT>::initCompute()) {
      PCL_ERROR("[facyl::%s::compute] no input cloud or invalid indices.\n", name);
      return false;
    }
    if (this->input_->empty()) {
      PCL_ERROR("[facyl::%s::compute] the input cloud is empty.\n", name);
      this->deinitCompute();
      return false;
    }
    if (!this->surface_) {
      this->fake_surface_ = true;
      this->surface_ = this->input_;
    }
    if ((this->k_ != 0) == (this->search_radius_ != 0.0)) {
      PCL_ERROR("[facyl::%s::compute] set exactly one of setKSearch (k = %d) and "
                "setRadiusSearch (r = %g).\n",
                name, this->k_, this->search_radius_);
      this->deinitCompute();
      return false;
    }
    this->search_parameter_ = this->k_ != 0 ? this->k_ : this->search_radius_;
  }
  if (this->k_ != 0 && this->k_ < 3) {
    PCL_ERROR("[facyl::%s::compute] k = %d: a normal needs at least 3 neighbours.\n", name,
              this->k_);
    this->deinitCompute();
    return false;
  }
  if (this->k_ == 0 && !(this->search_radius_ > 0.0 && std::isfinite(this->search_radius_))) {
    PCL_ERROR("[facyl::%s::compute] search radius %g is not positive.\n", name,
              this->search_radius_);
    this->deinitCompute();
    return false;
  }
  if (input_normals_ && input_normals_->size() != this->surface_->size()) {
    PCL_ERROR("[facyl::%s::compute] %zu input normals for %zu surface points.\n", name,
              input_normals_->size(), this->surface_->size());
    this->deinitCompute();
    return false;
  }
  // An organized cloud whose size is not width x height (built by hand) gets the tree.
  use_image_ = image_neighbourhoods_ && !use_pcl_search_ && this->k_ != 0 &&
               this->surface_ == this->input_ && this->input_->isOrganized() &&
               this->input_->size() == static_cast<std::size_t>(this->input_->width) *
                                         static_cast<std::size_t>(this->input_->height);
  return true;
}

template <typename PointInT, typename PointOutT>
void
NormalCurvatureEstimation<PointInT, PointOutT>::neighbourhoods(
  const std::vector<int>& surface_queries, bool queries_are_input, int threads,
  Neighbourhoods& out) const
{
  const auto& input = *this->input_;
  const auto& surface = *this->surface_;
  const std::size_t n = surface_queries.size();
  const auto query_point = [&](std::size_t i) -> const PointInT& {
    return queries_are_input ? input[surface_queries[i]] : surface[surface_queries[i]];
  };
  if (use_pcl_search_) {
    std::vector<pcl::Indices> lists(n);
    parallelFor(n, threads, kGrain, [&](std::size_t begin, std::size_t end) {
      std::vector<float> distances;
      for (std::size_t s = begin; s < end; ++s) {
        if (!pcl::isFinite(query_point(s)))
          continue;
        if (queries_are_input)
          this->searchForNeighbors(surface_queries[s], this->search_parameter_, lists[s],
                                   distances);
        else
          this->searchForNeighbors(surface, surface_queries[s], this->search_parameter_, lists[s],
                                   distances);
      }
    });
    out = Neighbourhoods::fromLists(lists);
    return;
  }
  if (use_image_) { // queries are input pixels either way: the surface is the input
    nearestInImage(surface_points_, static_cast<int>(surface.width), surface_queries, this->k_, out,
                   threads, image_window_radius_);
    return;
  }
  Eigen::Matrix3Xf queries(3, static_cast<Eigen::Index>(n));
  for (std::size_t i = 0; i < n; ++i)
    queries.col(static_cast<Eigen::Index>(i)) = query_point(i).getVector3fMap();
  out = this->k_ != 0 ? search_->nearest(queries, this->k_, threads)
                      : search_->within(queries, static_cast<float>(this->search_radius_), threads);
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
  const int threads = static_cast<int>(threads_); // 0: the hardware's concurrency

  if (!use_pcl_search_) {
    surface_points_.resize(3, static_cast<Eigen::Index>(surface.size()));
    for (std::size_t j = 0; j < surface.size(); ++j)
      surface_points_.col(static_cast<Eigen::Index>(j)) = surface[j].getVector3fMap();
    if (!use_image_)
      search_ = std::make_unique<NeighbourSearch>(surface_points_);
  }

  // Normals oriented towards the view point, so that neighbouring normals agree in sign.
  const Eigen::Vector3f view_point = getViewPoint();
  const auto pcaNormal = [&](const Neighbourhoods& nb, std::size_t i, const Eigen::Vector3f& at,
                             Eigen::Vector3f& normal, float& variation) {
    const int* list = nb.begin(i);
    if (nb.count(i) < 3 ||
        !estimateNormal(
          nb.count(i), [&](std::size_t j) { return surface[list[j]].getVector3fMap(); }, normal,
          variation))
      return false;
    if ((view_point - at).dot(normal) < 0.f)
      normal = -normal;
    return true;
  };

  // 1. One neighbourhood query per point, and the query points' normals. The working buffers
  //    are members: a stream of frames allocates nothing once they hold the largest frame.
  static_assert(std::is_same_v<pcl::Indices, std::vector<int>>,
                "the indices are passed as neighbour queries: pcl::index_t must be int (PCL's "
                "default)");
  neighbourhoods(indices, true, threads, nb_);
  const Neighbourhoods& nb = nb_;
  std::vector<Eigen::Vector3f>& normals = normals_;
  std::vector<float>& variation = variation_;
  normals.assign(n, nan3);
  variation.assign(n, nan);
  if (input_normals_) {
    for (std::size_t i = 0; i < n; ++i) {
      const auto& m = (*input_normals_)[indices[i]];
      const Eigen::Vector3f v(m.normal_x, m.normal_y, m.normal_z);
      const float len = v.norm();
      if (this->fake_surface_ && std::isfinite(len) && len > 0.f) {
        normals[i] = v / len;
        variation[i] = m.curvature;
      }
      else if (!this->fake_surface_)
        pcaNormal(nb, i, input[indices[i]].getVector3fMap(), normals[i], variation[i]);
    }
  }
  else {
    parallelFor(n, threads, kGrain, [&](std::size_t begin, std::size_t end) {
      for (std::size_t s = begin; s < end; ++s)
        if (pcl::isFinite(input[indices[s]]))
          pcaNormal(nb, s, input[indices[s]].getVector3fMap(), normals[s], variation[s]);
    });
  }

  // 2. A normal at every neighbour. In the common case (no search surface, no indices) the
  //    neighbours are the query points; otherwise the others get their own PCA normal.
  std::vector<Eigen::Vector3f>& surface_normals = surface_normals_;
  surface_normals.assign(surface.size(), nan3);
  if (input_normals_) {
    for (std::size_t j = 0; j < surface.size(); ++j) {
      const auto& m = (*input_normals_)[j];
      surface_normals[j] = Eigen::Vector3f(m.normal_x, m.normal_y, m.normal_z);
    }
  }
  else {
    std::vector<char>& known = known_;
    known.assign(surface.size(), 0);
    if (this->fake_surface_)
      for (std::size_t i = 0; i < n; ++i) {
        surface_normals[indices[i]] = normals[i];
        known[indices[i]] = 1;
      }
    std::vector<int>& missing = missing_;
    missing.clear();
    for (const int j : nb.indices)
      if (!known[j]) {
        known[j] = 1;
        missing.push_back(j);
      }
    if (!missing.empty()) {
      neighbourhoods(missing, false, threads, extra_nb_);
      const Neighbourhoods& extra = extra_nb_;
      parallelFor(missing.size(), threads, kGrain, [&](std::size_t begin, std::size_t end) {
        for (std::size_t s = begin; s < end; ++s) {
          float sv;
          pcaNormal(extra, s, surface[missing[s]].getVector3fMap(), surface_normals[missing[s]],
                    sv);
        }
      });
    }
  }

  // 3. Principal curvatures from the neighbours' normals, and the output.
  std::atomic<bool> dense{true};
  parallelFor(n, threads, kGrain, [&](std::size_t begin, std::size_t end) {
    for (std::size_t s = begin; s < end; ++s) {
      PointOutT& out = output[s];
      PrincipalCurvatures pc;
      const int* list = nb.begin(s);
      const bool ok =
        normals[s].allFinite() &&
        principalCurvaturesFromNormals(
          normals[s], nb.count(s), [&](std::size_t j) { return surface_normals[list[j]]; }, pc);
      if (!ok) {
        out.normal_x = out.normal_y = out.normal_z = nan;
        out.principal_curvature_x = out.principal_curvature_y = out.principal_curvature_z = nan;
        out.curvature = out.pc1 = out.pc2 = nan;
        dense.store(false, std::memory_order_relaxed);
        continue;
      }
      out.normal_x = normals[s].x();
      out.normal_y = normals[s].y();
      out.normal_z = normals[s].z();
      out.curvature = variation[s];
      out.principal_curvature_x = pc.direction.x();
      out.principal_curvature_y = pc.direction.y();
      out.principal_curvature_z = pc.direction.z();
      out.pc1 = pc.k_max;
      out.pc2 = pc.k_min;
    }
  });
  output.is_dense = dense.load();
  search_.reset();
}

} // namespace facyl

#define FACYL_INSTANTIATE_NormalCurvatureEstimation(T, OutT)                                       \
  template class facyl::NormalCurvatureEstimation<T, OutT>;
