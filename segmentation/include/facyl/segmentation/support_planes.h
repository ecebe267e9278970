/*
 * facyl: fast cylinder detection for PCL.
 * Choosing the planes that support objects: small numerics as free functions.
 */
#pragma once

#include <Eigen/Geometry>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace facyl {

/** \brief How far the points of a support lie from its plane, by their range from the
 * sensor: the noise and bias measured on the support itself. Depth noise of triangulating
 * sensors (structured light, stereo) grows with range^2, a time-of-flight sensor's more
 * slowly, and a real table is not quite a plane (a sensor's bias bends it, more with range and
 * towards the image border): no fixed band holds for every camera, so each support carries
 * its own.
 *
 * sigma(range) is a robust scale (1.4826 x the median |residual|, about the plane: bias
 * counts) in bins of range, non-decreasing with range; it is interpolated between bins,
 * constant below the nearest and grows with range^2 beyond the farthest (the fastest growth
 * of common sensors). A band made by fixedBand() has one half-width everywhere. */
struct DepthBand {
  std::vector<float> ranges; ///< bin centres (m from the sensor), ascending; empty: fixed
  std::vector<float> sigmas; ///< the residuals' robust scale in each bin (m)
  float factor{3.f};         ///< half-width = factor x sigma
  float fixed{0.f};          ///< > 0: the half-width at every range

  /** \brief The residuals' robust scale at \a range (m); the fixed half-width / factor for
   * a fixed band. */
  float sigma(float range) const;
  /** \brief Half-width of the band at \a range: a point is on the support when its
   * distance from the plane is at most this. */
  float halfWidth(float range) const
  {
    return fixed > 0.f ? fixed : factor * sigma(range);
  }
};

/** \brief A value at or below \a band's half-width at every range (0 when it cannot tell):
 * a residual within it is in the band without looking up its range. */
float halfWidthFloor(const DepthBand& band);

/** \brief A band of the same half-width \a half_width (> 0) at every range. */
DepthBand fixedBand(float half_width);

/** \brief Bins of range in which per-point loops look a band's half-width up (5 mm, up to
 * 12 m): see tabulateHalfWidths. */
constexpr float kHalfWidthBin = 0.005f;
constexpr std::size_t kHalfWidthBins = 2400;

/** \brief \a band's half-width at the centre of each of the kHalfWidthBins bins of range:
 * entry b is halfWidth((b + 0.5) kHalfWidthBin), for a point at range r in bin r /
 * kHalfWidthBin. */
std::vector<float> tabulateHalfWidths(const DepthBand& band);

/** \brief The half-width of tabulateHalfWidths' table \a half_widths at \a range (the last bin
 * beyond it). */
inline float
tabulatedHalfWidth(const std::vector<float>& half_widths, float range)
{
  return half_widths[std::min(static_cast<std::size_t>(range / kHalfWidthBin), kHalfWidthBins - 1)];
}

/** \brief The DepthBand of signed \a residuals (distances from a plane) measured at \a
 * ranges (at most 4000 of them, evenly): up to 8 bins of equal counts (at least 150 samples
 * each), each with 1.4826 x the
 * median |residual| (at least \a min_sigma), made non-decreasing with range. Pairs with a
 * non-finite value are skipped. With no finite pair, a fixed band of factor x min_sigma. */
DepthBand estimateDepthBand(const std::vector<float>& ranges, const std::vector<float>& residuals,
                            float factor, float min_sigma);

/** \brief Settings of refinePlaneRegion. */
struct PlaneRegionSettings {
  float band_factor{3.f}; ///< half-width of the band in sigmas (DepthBand::factor)
  float fixed_band{0.f};  ///< > 0: the band's half-width, not measured
  /** Numerical floor of the measured sigma (m): keeps a noise-free (simulated) plane's band
   * above float rounding. */
  float min_sigma{1e-4f};
  /** Normals of region cells lie within this angle of the plane's (rad): 3 x the median
   * angle of the seed's normals, at least min_angle; a seed whose normals spread more than
   * max_angle is not a plane (a dome, the top of a can). */
  float min_angle{0.05f};
  float max_angle{0.45f};
  int iterations{3}; ///< at most this many refits
};

/** \brief A plane, its band and the cells that lie on it. */
struct PlaneRegion {
  Eigen::Vector4f plane{Eigen::Vector4f::Zero()}; ///< unit normal towards the viewpoint
  DepthBand band;
  float max_angle{0.f};             ///< the normal tolerance used (rad)
  std::vector<std::uint8_t> member; ///< per cell: 1 on the plane
  std::size_t members{0};
};

/** \brief The cells of a plane search, prepared once for every region grown on them: which
 * may be members at all (finite position and normal) and their ranges from the viewpoint.
 * Holds references: \a cells, \a normals and \a samples (see refinePlaneRegion) must outlive
 * it and stay unchanged. */
struct PlaneRegionCells {
  PlaneRegionCells(const Eigen::Matrix3Xf& cells_, const Eigen::Matrix3Xf& normals_,
                   const Eigen::Matrix3Xf& samples_, const Eigen::Vector3f& viewpoint_);
  const Eigen::Matrix3Xf& cells;
  const Eigen::Matrix3Xf& normals;
  const Eigen::Matrix3Xf& samples;
  Eigen::Vector3f viewpoint;
  std::vector<std::uint32_t> usable; ///< cells with finite position and normal, ascending
  std::vector<float> range;          ///< per cell, its range (0 for cells not usable)
  /** false when the three matrices differ in their number of columns. */
  bool valid() const
  {
    return normals.cols() == cells.cols() && samples.cols() == cells.cols();
  }
};

/** \brief Grows a seed region into a whole support plane, with a band measured from the data
 * (robust to depth noise and bias: regions of a noisy or slightly bent table found apart are
 * one plane at the end). From the \a seed cells: fit the plane, measure its band on the
 * cells' raw \a samples and the spread of their normals; then take as members every cell
 * within the band whose normal agrees, refit (least squares, cells weighted by 1 /
 * sigma(range)^2) and re-measure the band (at most twice the seed's: a region does not run
 * away into a neighbouring surface); repeat until the members stop changing.
 * \param cells    3 x n positions (block means of an image grid, or sampled points)
 * \param normals  3 x n unit normals of the cells (non-finite: never a member)
 * \param samples  3 x n one raw measurement per cell, for the band (non-finite: the cell's
 *                 position is used)
 * \param seed     per cell, 1 for the cells of the seed region
 * \param viewpoint the sensor origin: ranges are measured from it, normals point to its side
 * \param excluded  per cell, 1 for cells that are never members (those of other planes);
 *                  nullptr: none
 * \return false when the region does not span a plane or its normals spread too much. */
bool refinePlaneRegion(const Eigen::Matrix3Xf& cells, const Eigen::Matrix3Xf& normals,
                       const Eigen::Matrix3Xf& samples, const std::vector<std::uint8_t>& seed,
                       const Eigen::Vector3f& viewpoint, const PlaneRegionSettings& settings,
                       PlaneRegion& region, const std::vector<std::uint8_t>* excluded = nullptr);

/** \brief refinePlaneRegion on cells prepared once (PlaneRegionCells): the same region, without
 * a pass over every cell for their ranges in each call (a frame grows a region from each of
 * its seeds). */
bool refinePlaneRegion(const PlaneRegionCells& cells, const std::vector<std::uint8_t>& seed,
                       const PlaneRegionSettings& settings, PlaneRegion& region,
                       const std::vector<std::uint8_t>* excluded = nullptr);

/** \brief Least-squares plane through the columns of \a points with \a weights (>= 0), unit
 * normal pointing to \a viewpoint's side. \return false when they do not span a plane. */
bool fitWeightedPlane(const Eigen::Matrix3Xf& points, const Eigen::VectorXf& weights,
                      const Eigen::Vector3f& viewpoint, Eigen::Vector4f& plane);

/** \brief Groups planes (a, b, c, d; unit normals on the same side, e.g. towards the sensor)
 * that are one plane: normals within \a angle (rad) and offsets within \a distance. Planes are
 * visited in \a order (e.g. largest first); each group is led by its first plane.
 * \return for each group, the indices of its planes. */
std::vector<std::vector<std::size_t>> groupCoplanar(const std::vector<Eigen::Vector4f>& planes,
                                                    const std::vector<std::size_t>& order,
                                                    float angle, float distance);

/** \brief Where a cluster lies relative to a plane: robust lowest and highest heights, and the
 * share of its points inside a height band. */
struct HeightProfile {
  float base{0.f};    ///< 2nd percentile of the heights
  float top{0.f};     ///< 98th percentile
  float in_band{0.f}; ///< share of the points with height in [min, max]
  float extent{0.f};  ///< diagonal of the points' bounding box along the plane
};

/** \brief HeightProfile of \a points (3 x n) over \a plane (unit normal), band [min, max]. */
HeightProfile heightProfile(const Eigen::Matrix3Xf& points, const Eigen::Vector4f& plane,
                            float min_height, float max_height);

/** \brief HeightProfile of \a points over \a plane whose object band starts, for each point,
 * at the larger of \a min_height and the plane's \a band at the point's range from \a
 * viewpoint (the points clearly above the support), and ends at \a max_height. */
HeightProfile heightProfile(const Eigen::Matrix3Xf& points, const Eigen::Vector4f& plane,
                            const DepthBand& band, const Eigen::Vector3f& viewpoint,
                            float min_height, float max_height);

/** \brief What is measured of a plane E inside the object band of a lower parallel plane L
 * (a shelf or a low table over a table or the floor; or the top of a box in a pile, books, a
 * tray standing on it), to tell a support from the top face of an object. */
struct ElevatedPlane {
  float height{0.f};      ///< of E's region above L's plane (m)
  float contact{0.f};     ///< L's band there plus the contact height (m): see isElevatedSupport
  float region_area{0.f}; ///< of the convex hull of the region found on E (m^2)
  float diameter{0.f};    ///< of that hull (m)
  /** L's points seen under E (inside E's region hull shrunk by twice the spacing of its
   * region's cells), per point of E's region: the space under E, where the view shows it. */
  float seen_under{0.f};
  /** The pieces of E's hull edge that face the sensor (of kEdgePieces around it): where the
   * view would show what holds E up. */
  int facing_pieces{0};
  /** Of those, the share under which points reach down from E to L's contact (a wall): the
   * sides of a box, of books, of a tray. The legs of a table or a stool hold few of them. */
  float walled{0.f};
};

/** \brief The pieces of equal length E's hull edge is cut into to measure ElevatedPlane::walled:
 * a table's legs fill a piece or two at its corners, a box's side fills all those it shows. */
constexpr int kEdgePieces = 32;

/** \brief The share of E's points that L's points seen under E must reach for the space under
 * E to be seen (ElevatedPlane::seen_under): a tenth, so that a strip along E's edge (the
 * cells' uncertainty, a sensor's fattened edges) does not count, while the floor seen under a
 * low table, or a lower shelf board under the one above, does. */
constexpr float kSeenUnderShare = 0.1f;

/** \brief Whether E (\a e) is a support of its own rather than the top face of an object
 * standing on L. A shelf, a low table or a stool is held up by legs or panels with room
 * beneath; a box in a pile, books or a tray are solid down to L. So E is a support when its
 * region is at least \a min_area (m^2), it stands clear of L (height above \a e.contact:
 * what stands on a plane within the contact height of L stands on L as well), and either the
 * space under it is seen (seen_under >= kSeenUnderShare), or most of its edge that faces the
 * sensor shows no wall down to L (walled < 1/2), or, where no edge faces the sensor (seen
 * from above), it is larger than any object (diameter > \a max_extent, the object band's
 * width, as in standsOn). */
inline bool
isElevatedSupport(const ElevatedPlane& e, float min_area, float max_extent)
{
  if (!(e.region_area >= min_area && e.height > e.contact))
    return false;
  if (e.seen_under >= kSeenUnderShare)
    return true;
  return e.facing_pieces > 0 ? e.walled < 0.5f : e.diameter > max_extent;
}

/** \brief A cluster stands on a plane when it reaches down to it (base <= contact) and is
 * whole inside the object band, a box max_height high and wide (top below max_height -
 * margin, extent below max_height): a table's objects do; the legs of a table over a floor
 * (they reach up to the table top) and the foot of a wall (wide) do not. */
inline bool
standsOn(const HeightProfile& h, float contact, float max_height, float margin)
{
  return h.base <= contact && h.top <= max_height - margin && h.extent <= max_height;
}

} // namespace facyl
