/*
 * facyl: fast cylinder detection for PCL.
 */
#pragma once

#include <Eigen/Core>

#include <cstddef>
#include <memory>
#include <vector>

namespace facyl {

/** \brief facyl's neighbourhood for normals and principal curvatures: the k nearest points
 * (NormalCurvatureEstimation::setKSearch) of the recognizer, of the tools and of the
 * estimator's own curvatures (HoughCylinderEstimation with normals only). */
constexpr int kDefaultNeighbours = 16;

/** \brief Neighbour lists in compressed-row form: the neighbours of query i are
 * indices[offsets[i]] .. indices[offsets[i + 1] - 1], nearest first. */
struct Neighbourhoods {
  std::vector<std::size_t> offsets{0};
  std::vector<int> indices;

  /** \brief Number of queries. */
  std::size_t size() const
  {
    return offsets.size() - 1;
  }
  /** \brief Number of neighbours of query \a i. */
  std::size_t count(std::size_t i) const
  {
    return offsets[i + 1] - offsets[i];
  }
  /** \brief Compressed rows from one list of neighbour indices per query. */
  template <typename List> static Neighbourhoods fromLists(const std::vector<List>& lists)
  {
    Neighbourhoods out;
    out.offsets.assign(lists.size() + 1, 0);
    for (std::size_t i = 0; i < lists.size(); ++i)
      out.offsets[i + 1] = out.offsets[i] + lists[i].size();
    out.indices.reserve(out.offsets.back());
    for (const auto& list : lists)
      out.indices.insert(out.indices.end(), list.begin(), list.end());
    return out;
  }
  /** \brief Pointer to the first neighbour of query \a i. */
  const int* begin(std::size_t i) const
  {
    return indices.data() + offsets[i];
  }
};

/** \brief Exact neighbour search among the finite columns of a 3 x N matrix (a nanoflann
 * kd-tree, built once in the constructor). Queries are const, run in parallel on \a threads
 * threads (0: the hardware's concurrency; one per 512 queries at most; see parallelFor: waiting
 * threads sleep, never spin), and may be issued concurrently. Indices refer to columns of
 * the surface; a query that is not finite gets no neighbour; a query that is a surface point
 * finds itself first.
 */
class NeighbourSearch {
public:
  /** \brief Builds the tree. \a surface must outlive this object. */
  explicit NeighbourSearch(const Eigen::Matrix3Xf& surface);
  ~NeighbourSearch();
  NeighbourSearch(const NeighbourSearch&) = delete;
  NeighbourSearch& operator=(const NeighbourSearch&) = delete;

  /** \brief The k nearest surface points of every query column, nearest first.
   * \throws std::invalid_argument if k < 1. */
  Neighbourhoods nearest(const Eigen::Matrix3Xf& queries, int k, int threads = 0) const;

  /** \brief The k nearest surface points of every query column that lie within \a radius of
   * it, nearest first: nearest() cut at the radius, at the cost of the points within it (the
   * search prunes at the radius from the start, so sparse neighbourhoods stay cheap).
   * \throws std::invalid_argument if k < 1 or radius is not positive (infinity: nearest()). */
  Neighbourhoods nearestWithin(const Eigen::Matrix3Xf& queries, int k, float radius,
                               int threads = 0) const;

  /** \brief Every surface point within \a radius of each query column, nearest first.
   * \throws std::invalid_argument if radius is not positive and finite. */
  Neighbourhoods within(const Eigen::Matrix3Xf& queries, float radius, int threads = 0) const;

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/** \brief The \a k nearest of the finite columns of \a surface to every column of \a queries,
 * nearest first, found on a uniform grid of cells about as wide as a surface's k-neighbourhood
 * (rings of cells are searched until no nearer point can remain). The same neighbours as
 * NeighbourSearch::nearest (ties at equal distance aside), without building a tree: cheaper
 * when the queries are few (estimateLocalNoise: 128 queries among 1,800 points). A query
 * that is not finite gets no neighbour; a query that is a surface point finds itself first.
 * Thread-safe (no shared state).
 * \throws std::invalid_argument if k < 1. */
Neighbourhoods nearestOnGrid(const Eigen::Matrix3Xf& surface, const Eigen::Matrix3Xf& queries,
                             int k);

/** \brief Half-width of the image window that nearestInImage searches for \a k neighbours:
 * the smallest r whose (2r + 1)^2 pixels are at least three times k (k = 16: r = 3, 7 x 7
 * pixels). On a surface seen at an angle the pixels lie further apart along one image axis
 * than along the other; a window of 3k pixels still holds the k nearest while that ratio stays
 * below about 3 (a surface inclined up to about 70 degrees to the line of sight).
 * \throws std::invalid_argument if k < 1. */
int imageWindowRadius(int k);

/** \brief Half-width of the image window that holds the \a k nearest points of a surface
 * inclined by up to \a inclination (rad, in [0, pi/2)) to the line of sight, its pixels evenly
 * spaced: the k nearest fill a disc on the surface whose image is an ellipse of semi-axes
 * sqrt(k / (pi cos(inclination))) and cos(inclination) times that pixels, so the radius is the
 * ceiling of the first (k = 16: 3 up to 55 degrees, 5 up to 78 degrees).
 * \throws std::invalid_argument if k < 1 or the inclination is outside [0, pi/2). */
int imageWindowRadius(int k, float inclination);

/** \brief The \a k nearest finite pixels to each query pixel among those of the window of
 * half-width \a radius (0: imageWindowRadius(k)) centred on it, nearest first (the query itself
 * first), in an organized cloud: \a surface holds its pixels row by row, \a width to a row, a pixel
 * without depth not finite. Neighbourhoods from the image grid, without a tree (as
 * pcl::search::OrganizedNeighbor for organized input): where the window holds the k nearest
 * points these are NeighbourSearch::nearest's neighbours. Where it does not, the
 * neighbourhood stays compact in the image: across a depth edge the window holds fewer points
 * of the query's surface (a tree reaches further along it), and on a surface seen at a
 * grazing angle (a far floor) a tree takes a strip of the row, the window a patch. Ties go to
 * the pixel nearer in the image. A query that is not finite gets no neighbour. Runs on
 * \a threads threads as NeighbourSearch does; thread-safe (no shared state).
 * \throws std::invalid_argument if k < 1, radius < 0, width < 1, surface.cols() is not a
 * multiple of width, or a query is not a pixel of the surface. */
Neighbourhoods nearestInImage(const Eigen::Matrix3Xf& surface, int width,
                              const std::vector<int>& queries, int k, int threads = 0,
                              int radius = 0);

/** \brief nearestInImage into \a out, whose storage is reused: a caller that keeps \a out
 * between frames allocates nothing once it has held the largest frame's lists.
 * \throws std::invalid_argument as nearestInImage. */
void nearestInImage(const Eigen::Matrix3Xf& surface, int width, const std::vector<int>& queries,
                    int k, Neighbourhoods& out, int threads = 0, int radius = 0);

} // namespace facyl
