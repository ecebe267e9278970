/*
 * facyl: fast cylinder detection for PCL.
 * The steps of segmentTabletop (segment_tabletop.h), internal to the library: each takes what
 * it reads (the run's Setup, what earlier steps found) and returns what it found.
 *   tabletop_planes.cpp    the support candidates: plane grid or point sample, seeds, regions
 *   tabletop_supports.cpp  the pixel sort, the families of candidates and their trials, the
 *                          supports' hulls, each cluster's support
 *   tabletop_objects.cpp   the object points split into clusters (object_segmentation.h for
 *                          the edge-aware split of an image), the frame without a support
 *   tabletop_lattice.cpp   the run on a lattice of a large frame, and back to full resolution
 *   segment_tabletop.cpp   the run of one frame: the steps in order, the family chosen
 */
#pragma once

#include <facyl/segmentation/segment_tabletop.h>

#include <optional>
#include <vector>

namespace facyl {
namespace tabletop {

/** What every step reads of a run: the frame, its settings, its camera and up direction, and
 * how the frame is searched. Holds references: they outlive the run. */
struct Setup {
  const PointFrame& frame;
  const TabletopSegmentationParameters& params;
  const PinholeCamera& camera;
  Eigen::Vector3f up;
  int plane_step; ///< the block size of the plane search on an image (see plane_step)
  bool as_image;  ///< searched as an image (see searchedAsImage), else as a point set
  /** Where the last frames' support is expected (a valid SupportPrior), nullptr: none. */
  const SupportPrior* prior{nullptr};
  /** Threads of the per-pixel passes: the workspace's while the helpers find idle cores
   * (threadsForIdleCores), else 1. */
  int threads{1};
  /** The prior was inferred from this frame's floating objects (supportUnderFloatingObjects),
   * not carried from the last frames: its plane must show mostly holes, few points beyond it. */
  bool prior_inferred{false};
};

/** The block size of the plane search on organized frames: plane_step, or width / 160. */
int planeStep(const PointFrame& frame, const TabletopSegmentationParameters& params);

/** True when \a frame is searched as an image: organized and at least 16 plane-grid cells wide
 * and high (its normals use a window of several cells); narrower organized frames (a LiDAR's
 * few rings, a strip) are point sets. */
bool searchedAsImage(const PointFrame& frame, const TabletopSegmentationParameters& params);

/** The Setup of a run; \a prior is kept only when valid (SupportPrior::valid). */
Setup makeSetup(const PointFrame& frame, const TabletopSegmentationParameters& params,
                const PinholeCamera& camera, const Eigen::Vector3f& up,
                const SupportPrior* prior = nullptr, int threads = 1);

/** Calls \a f with each index of the points to segment (the frame's indices, else all). */
template <typename F>
void
forEachPoint(const PointFrame& frame, F f)
{
  if (frame.indices) {
    for (const auto i : *frame.indices)
      f(i);
    return;
  }
  for (std::size_t i = 0; i < frame.size; ++i)
    f(static_cast<pcl::index_t>(i));
}

/** What the plane search learns of the frame, for the steps after it. */
struct FrameCues {
  float focal{0.f}; ///< pixels, images: the camera's, or estimated
  Eigen::Vector3f image_down{Eigen::Vector3f::Zero()}; ///< images; zero: unknown
  /** The sensor's noise by range, as measured on the largest candidate: the depth gaps of the
   * object segmentation are never below it. */
  std::optional<DepthBand> noise;
  /** Images: per pixel, finite (recorded by the plane grid's pass over the image). */
  const std::vector<std::uint8_t>* has_depth{nullptr};

  const DepthBand* noiseBand() const
  {
    return noise ? &*noise : nullptr;
  }
};

// ------------------------------------------------------------------ tabletop_planes.cpp

/** A candidate plane: coefficients, band and the points of the region found on it. */
struct Candidate {
  Eigen::Vector4f plane{Eigen::Vector4f::Zero()};
  DepthBand band;
  pcl::Indices points;    ///< frame indices, one per cell of the region (grid or sample)
  std::size_t support{0}; ///< full-resolution points it stands for
  /** The stream's support prior's plane, which the frame did not find (priorPlaneCandidate):
   * its region is the prior's extent. */
  bool from_prior{false};
};

/** The support candidates of the frame, largest first: seeds of the plane grid (images) or of
 * a point sample grown into planes (refinePlaneRegion), then keepSupportCandidates. Sets \a
 * cues: focal, image_down and has_depth (in \a workspace) on images, the noise. */
std::vector<Candidate> findCandidates(const Setup& setup, FrameCues& cues,
                                      TabletopWorkspace& workspace);

/** Of a candidate's \a region, the points that can be vertices of its convex hull: on an
 * image, each row's first and last (rowExtremes); all of them in a point set. */
pcl::Indices hullCandidates(const Setup& setup, const pcl::Indices& region);

/** Area of the convex hull of the points that found \a c, in \a frame's plane. */
float regionArea(const Setup& setup, const Candidate& c, const Eigen::Affine3f& frame);

// ------------------------------------------------------------------ tabletop_supports.cpp

/** Per candidate, its hulls (see supportHull) and region area: computed once for all the
 * trials of its family. */
struct CandidateHulls {
  bool known{false};
  std::vector<Eigen::Vector2f> polygon, extent;
  float region{0.f};
  /** Whether it lies inside the object band of a lower candidate of its family, and if so
   * whether it is a support of its own (isElevatedSupport); judged once (judged). */
  bool judged{false}, elevated{false}, elevated_support{false};
};

/** On an image: the cells of twice the plane grid's block (a candidate region's cells are of
 * the grid or of the twice coarser one) and, per cell, the bits of the candidates whose
 * regions hold it. */
struct RegionCells {
  RegionCells() = default;
  RegionCells(const Setup& setup, const std::vector<Candidate>& candidates);
  /** The cell of pixel \a i. */
  std::size_t cellOf(pcl::index_t i) const
  {
    const pcl::index_t v = i / width;
    return row[static_cast<std::size_t>(v)] + column[static_cast<std::size_t>(i - v * width)];
  }
  pcl::index_t width{0};
  std::vector<std::size_t> row;      ///< per image row: its first cell
  std::vector<std::uint32_t> column; ///< per image column: its cell in the row
  std::vector<std::uint8_t> bits;    ///< per cell: candidate bits
};

/** The candidates of a frame and the pixel sort's result, which every trial reads. */
struct SortedFrame {
  std::vector<Candidate> candidates;
  /** Per candidate: plane, band, frame and inliers (the final trial moves its family's
   * inliers out). */
  std::vector<SupportPlane> all;
  std::vector<CandidateHulls> hulls;
  /** The points above some candidate (the workspace's list). */
  const std::vector<PointOverPlanes>* above{nullptr};
  /** On images: the candidates' regions (built by the first trial that has other families). */
  RegionCells regions;
};

/** One pass over the points (the pixel sort): \a candidates with their inliers, frames and
 * the points above some candidate (\a workspace.above). */
SortedFrame classifyPoints(const Setup& setup, std::vector<Candidate> candidates,
                           TabletopWorkspace& workspace);

/** The families of parallel candidates, those an upright camera would see facing up first,
 * then by their number of points. */
std::vector<std::vector<std::size_t>> rankFamilies(const Setup& setup, const FrameCues& cues,
                                                   const SortedFrame& sorted);

/** The supports and objects of one family of parallel candidates. */
struct Trial {
  std::vector<SupportPlane> supports;
  std::vector<TabletopCluster> clusters;
  std::size_t table{0};
  std::size_t standing{0};         ///< object points standing on the supports
  std::size_t standing_objects{0}; ///< objects standing on them
  bool table_is_prior{false};      ///< the table is the prior's plane (tableWithPrior)
  int from_prior{-1};              ///< the support of a Candidate::from_prior, -1: none
};

/** The supports of \a family (large enough, see min_support_area) and the objects on them, on
 * every \a stride-th pixel and row of an image (1: all; larger: only the standing points are
 * counted, to compare families). \a final: the result (the family's inliers are moved out of
 * \a sorted). */
Trial tryFamily(const Setup& setup, const FrameCues& cues, SortedFrame& sorted,
                const std::vector<std::size_t>& family, int stride, bool final,
                TabletopWorkspace& workspace);

// --------------------------------------------------------------------- tabletop_prior.cpp

/** The index of the candidate of \a candidates that is setup.prior's plane (consistentWithPrior
 * of its plane; of several, the nearest: priorMismatch), -1: none or no prior. */
int priorCandidate(const Setup& setup, const std::vector<Candidate>& candidates);

/** With a prior: when the candidate that is the prior's plane (priorCandidate) comes after the
 * first \a kept of \a candidates (which are cut there), it takes the last of those places, so
 * that the cut keeps it. */
void keepPriorCandidate(const Setup& setup, std::vector<Candidate>& candidates, std::size_t kept);

/** With a prior whose plane no candidate is (a dark or glossy top without depth in this
 * frame, in view between frames that found it): the prior's plane as a candidate
 * (Candidate::from_prior), when the image supports it. Its normal: that of the largest
 * candidate parallel to it (within max_angle), else the prior's; its height: the densest slab
 * of the points within max_offset of it, when that is a peak of min_plane_points. Of the rays
 * of every plane_step-th pixel and row that meet it inside the prior's extent, the points on it
 * (band: \a cues.noise) must be min_plane_points or most rays give no depth (of those that meet
 * nothing in front of it first, where those are most), and fewer than half may see through it (a
 * point beyond its band is a ray that passed where it would be). Its band is cues.noise, its points
 * those rays' points on it. Images only; none without a prior with an extent, a focal length or a
 * noise band, or when the frame has 8 candidates. */
std::optional<Candidate> priorPlaneCandidate(const Setup& setup, const FrameCues& cues,
                                             const std::vector<Candidate>& candidates);

/** True when setup.prior's plane, as given, shows in the image as priorPlaneCandidate requires
 * (the rays of its extent: on it, without depth, or few beyond it): the check before a frame is
 * segmented again with an inferred prior. */
bool priorPlaneInView(const Setup& setup, const FrameCues& cues);

/** Where objects float above the table of \a segments (beyond its object band, up to four of
 * its height, and nothing of them going on below the band: a top without depth of its own, dark
 * or glossy), the support their bottoms share, as a prior for segmenting the frame again
 * (Setup::prior_inferred): parallel to that table, at the lowest bottom (each object's lowest
 * percent) of the densest slab of bottoms (two of the table's bands at 1 m); an object is a
 * group of adjacent plane-grid cells, of min_cluster_size pixels, that stands (its median
 * height two bands above its bottom, not a far top lying flat). Its extent: the objects' feet
 * grown to twice their size about their centre. Images without indices only; none when nothing
 * floats. */
std::optional<SupportPrior> supportUnderFloatingObjects(const Setup& setup,
                                                        const TabletopSegments& segments);

/** For the candidate of \a sorted that is the prior's plane without a region of its own
 * (Candidate::from_prior): its frame at the prior's centre, its hulls the prior's extent, and
 * no elevated plane (it was the tracks' support). */
void adoptPriorRegion(const Setup& setup, SortedFrame& sorted);

/** The family of \a families (rankFamilies') that holds setup.prior's plane (a candidate of
 * \a sorted consistent with it), else one parallel to it (normals within its max_angle); -1:
 * none, or no prior. */
int priorFamily(const Setup& setup, const SortedFrame& sorted,
                const std::vector<std::vector<std::size_t>>& families);

/** The family chosen with a prior: \a prior_family (priorFamily) when its coarse trial found
 * supports (\a with_supports), else \a chosen, the frame's own choice. \a result.challenged
 * when the frame's own choice is another family with more \a standing objects. */
std::size_t familyWithPrior(int prior_family, std::size_t chosen,
                            const std::vector<char>& with_supports,
                            const std::vector<std::size_t>& standing, SupportPriorResult& result);

/** The table among a family's \a supports, whose objects were counted: the one with the most
 * object points standing on it (else the one with the most inliers); with a prior, its plane
 * when it is one of them (the first consistent one): of parallel supports in view (a counter
 * and a table, a table and the floor), the one the tracks are anchored on stays the table, and
 * every object is found on whichever holds it. Sets \a trial.standing and table_is_prior. */
std::size_t tableWithPrior(const Setup& setup, const std::vector<SupportPlane>& supports,
                           Trial& trial);

// ------------------------------------------------------------------- tabletop_objects.cpp

/** The object points \a objects split into clusters (see Clustering). */
std::vector<pcl::Indices> cluster(const Setup& setup, const FrameCues& cues,
                                  const pcl::Indices& objects, TabletopWorkspace& workspace);

/** cluster() on a grid of every \a stride-th pixel and row of an image (\a objects on that
 * grid), without joining parts seen around occluders: the clusters hold those pixels only
 * (enough to count the objects standing on a family of supports). */
std::vector<pcl::Indices> clusterCoarse(const Setup& setup, const FrameCues& cues,
                                        const pcl::Indices& objects, int stride,
                                        TabletopWorkspace& workspace);

/** No support in view (or none that objects stand on): the compact segments of the frame (of
 * its points not flagged in \a taken) are objects too, with support -1; appended to \a
 * clusters. */
void segmentWithoutSupport(const Setup& setup, const FrameCues& cues,
                           const std::vector<std::uint8_t>* taken,
                           std::vector<TabletopCluster>& clusters, TabletopWorkspace& workspace);

/** The cluster of \a indices (sorted here if they are not): header, centroid and box. */
TabletopCluster makeCluster(const Setup& setup, pcl::Indices indices, int support);

// ------------------------------------------------------------------- tabletop_lattice.cpp

/** segmentFrame on the lattice of every \a step-th pixel and row of \a setup's frame, its
 * clusters and supports then brought to full resolution. */
TabletopSegments segmentOnLattice(const Setup& setup, int step, TabletopWorkspace& workspace);

// ------------------------------------------------------------------- segment_tabletop.cpp

/** The run on every point of \a setup's frame; \a cues: what its plane search learnt. */
TabletopSegments segmentFrame(const Setup& setup, FrameCues& cues, TabletopWorkspace& workspace);

/** Nothing when setup.prior is given (it decides the support). Else, where objects float above the
 * table of \a out over a support the image shows as holes (supportUnderFloatingObjects,
 * priorPlaneInView with \a cues of the run that gave \a out), the frame segmented again with that
 * support as an inferred prior; \a out and \a cues become that run's (its timing the sum of both)
 * when the support is its table and objects stand on it. */
void adoptSupportUnderFloatingObjects(const Setup& setup, FrameCues& cues,
                                      TabletopWorkspace& workspace, TabletopSegments& out);

/** Largest first, like pcl::EuclideanClusterExtraction (stable). */
void sortLargestFirst(std::vector<TabletopCluster>& clusters);

} // namespace tabletop
} // namespace facyl
