/*
 * facyl: fast cylinder detection for PCL.
 * Splitting the points above a table into objects that touch, stack or occlude each other:
 * free functions on an organized cloud, so that tests reach every step.
 */
#pragma once

#include <facyl/segmentation/support_planes.h>

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace facyl {

/** \brief Settings of segmentObjectsOrganized (lengths in metres). */
struct ObjectSegmentationParameters {
  /** Depth discontinuity: 4-neighbours farther apart than jump_factor times the footprint of a
   * pixel at their depth (z / focal) are not connected, clamped to [min_gap, max_gap]. At a
   * surface seen under a grazing angle neighbours are 1 / cos(incidence) footprints apart, so
   * 8 keeps surfaces up to about 83 degrees connected. */
  float jump_factor{8.f};
  float min_gap{0.006f};
  float max_gap{0.02f};
  /** Concave creases (where objects touch or stand on each other, seen from the sensor): over
   * crease_span(z) = max(crease_span, crease_span_z2 * z^2) on each side of a pixel, the
   * surface turns away from the sensor by more than crease_angle (rad). The span grows with
   * z^2 like depth noise. crease_angle 0 turns creases off. */
  float crease_span{0.012f};
  float crease_span_z2{0.012f};
  float crease_angle{0.45f};
  /** Segments of fewer points join the neighbour they share most connected boundary with. */
  std::size_t min_fragment{40};
  /** A segment whose boundary lies at least this share along one larger segment, connected
   * but cut by a crease, joins it (the bottom inside a cup, a lid's rim). In (0, 1]. */
  float enclosed_share{0.6f};
  /** Two segments on both sides of a nearer occluder that continue one surface (local planes
   * within bridge_angle rad, each part within bridge_distance of the other's plane, at most
   * bridge_max_gap apart) are one object seen through the gap. */
  bool bridge_occlusions{true};
  float bridge_max_gap{0.25f};
  float bridge_angle{0.3f};
  float bridge_distance{0.015f};
  /** Colour edges where depth alone cannot tell (segmentObjectsOrganized with a
   * ColourImage): where the surface turns concave by half crease_angle (a weak crease: two
   * touching objects, the valley blurred by noise and the pixel footprint) within 2 pixels of
   * an edge (a depth discontinuity, a crease, the object's outline), linked neighbours whose
   * colours differ by more than colour_edge times the frame's typical difference of linked
   * neighbours (the median: noise, texture, shading) are cut apart like a crease; the cut
   * pixels then join the segment of their colour. A label's edge on a smooth surface lies on
   * no crease and cuts nothing. In [0, 100]; 0 turns them off. */
  float colour_edge{6.f};
};

/** \brief The colours of an image's pixels: 8-bit blue, green, red at \a bgr + pixel *
 * \a stride (PCL's rgb/rgba field layout). */
struct ColourImage {
  const std::uint8_t* bgr{nullptr};
  std::size_t stride{0};
  /** The squared difference of the colours of pixels \a p and \a q (8-bit levels). */
  int distance2(std::size_t p, std::size_t q) const
  {
    const std::uint8_t* a = bgr + p * stride;
    const std::uint8_t* b = bgr + q * stride;
    const int d0 = a[0] - b[0], d1 = a[1] - b[1], d2 = a[2] - b[2];
    return d0 * d0 + d1 * d1 + d2 * d2;
  }
};

/** \brief Checks \a params. \return an empty string, or what is wrong. */
std::string validate(const ObjectSegmentationParameters& params);

/** \brief segmentObjectsOrganized's depth discontinuity at \a range: 4-neighbours farther apart
 * are not connected. jump_factor times a pixel's footprint (range / \a focal), clamped to
 * [min_gap, max_gap], and at least the sensor's noise there: \a noise_half, the half-widths of
 * its band (tabulateHalfWidths; empty: not known). */
float connectionGap(const ObjectSegmentationParameters& params, float range, float focal,
                    const std::vector<float>& noise_half);

/** \brief Focal length in pixels of an organized cloud taken by a pinhole camera: the median
 * of x / (u - cx) over finite pixels, with cx = (width - 1) / 2. 0 when it cannot tell. */
float estimateFocalLength(const pcl::PointCloud<pcl::PointXYZ>& cloud);

/** \brief The direction in which the image rows of an organized cloud go down (the camera's
 * y axis), in the cloud's frame, from the data alone: the mean over columns of the unit ray
 * (from \a viewpoint) of the lowest point minus that of the highest. Zero when it cannot tell.
 * Needs no sensor orientation, so clouds stored in any frame give the camera's. */
Eigen::Vector3f imageDownDirection(const pcl::PointCloud<pcl::PointXYZ>& cloud,
                                   const Eigen::Vector3f& viewpoint);

/** \brief Per pixel of \a cloud (organized, non-object pixels NaN): 1 on a concave crease
 * seen from \a viewpoint, in either image direction (see ObjectSegmentationParameters). Each
 * test compares three points, each the mean of 5 pixels across the test direction, which
 * averages depth noise along the crease without blurring it. */
std::vector<std::uint8_t> concaveCreases(const pcl::PointCloud<pcl::PointXYZ>& cloud, float focal,
                                         const Eigen::Vector3f& viewpoint,
                                         const ObjectSegmentationParameters& params);

/** \brief Splits the finite points of \a cloud (organized; only the candidate object points
 * finite) into objects:
 * 1. connected components over 4-neighbours without a depth discontinuity, crease pixels
 *    left out; crease pixels then join the component that reaches them first (breadth first);
 * 2. fragments and enclosed segments join their neighbour;
 * 3. (bridge_occlusions) parts of one surface on both sides of a nearer occluder are joined.
 * \param has_depth per pixel of the full frame: 1 where the sensor measured depth (table and
 *        background included), to tell an occluder's shadow from visible table.
 * \param focal focal length in pixels (> 0).
 * \param noise the sensor's noise and bias by range (a support's band), when known: a depth
 *        discontinuity is then at least its half-width (3 sigma), so that a noisy sensor's
 *        surfaces do not shatter into fragments.
 * \param finite the indices of the finite points of \a cloud, ascending, when the caller knows
 *        them (nullptr: the cloud is scanned for them); a VGA frame is then not read whole.
 * \param threads threads for the per-pixel crease test (threadCount: 0 the hardware's
 *        concurrency); the segments are the same on any number. Waiting threads sleep.
 * \return the segments' point indices, ascending, in no particular order of segments. */
std::vector<pcl::Indices> segmentObjectsOrganized(
  const pcl::PointCloud<pcl::PointXYZ>& cloud, const std::vector<std::uint8_t>& has_depth,
  float focal, const Eigen::Vector3f& viewpoint, const ObjectSegmentationParameters& params,
  const DepthBand* noise = nullptr, const pcl::Indices* finite = nullptr, int threads = 1);

/** \brief Pixels of two image regions: columns \a u and rows \a v, one entry per pixel. */
struct PixelList {
  std::vector<int> u, v;
};

/** \brief The closest pair of pixels of \a a and \a b (squared distance in pixels), and in
 * \a ka, \a kb their places in the lists: of several closest pairs, the first in \a a's order,
 * then in \a b's (as a loop over \a a around a loop over \a b that keeps strictly closer pairs
 * finds). With \a enough >= 0, the search stops at the first pixel of \a a whose closest pair
 * is within it (squared pixels): that pair, which need not be the closest. -1 and places
 * SIZE_MAX when either list is empty. */
long closestPixelPair(const PixelList& a, const PixelList& b, std::size_t& ka, std::size_t& kb,
                      long enough = -1);

/** \brief Whether \a indices ascend strictly (no repeat): the image order that
 * segmentObjectsOrganized's pixel lists keep. */
bool strictlyAscending(const pcl::Indices& indices);

/** \brief segmentObjectsOrganized on the object points alone: \a points (3 x n; non-finite
 * columns are left out) at the pixels \a pixels (strictly ascending indices into a \a width x
 * \a height image). The same segments as the cloud version on a cloud that holds these points
 * and NaN elsewhere, without an image-sized cloud to fill. Empty on invalid input (sizes that
 * disagree, pixels out of the image or not ascending, focal <= 0); \a threads as there. */
std::vector<pcl::Indices> segmentObjectsOrganized(
  const Eigen::Matrix3Xf& points, const pcl::Indices& pixels, std::uint32_t width,
  std::uint32_t height, const std::vector<std::uint8_t>& has_depth, float focal,
  const Eigen::Vector3f& viewpoint, const ObjectSegmentationParameters& params,
  const DepthBand* noise = nullptr, const ColourImage* colour = nullptr, int threads = 1);

} // namespace facyl
