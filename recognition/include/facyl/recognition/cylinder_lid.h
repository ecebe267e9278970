/*
 * facyl: fast cylinder detection for PCL.
 * An upright cylinder seen from above shows its lid and little or none of its side: a flat disc
 * parallel to the support it stands on, at the object's height. The side's Hough cannot fit it
 * (no normal points across the axis); the lid's outline can. A free function of a cluster's
 * points with their normals and of its support's plane.
 */
#pragma once

#include <facyl/sample_consensus_alt/cylinder_model.h>

#include <Eigen/Core>

#include <cstddef>
#include <limits>

namespace facyl {

/** \brief Settings of fitLid. Lengths in metres. */
struct LidSettings {
  /** A lid point's normal lies within this angle (rad) of the support's normal. */
  float max_normal_angle{0.6f};
  /** How far the lid's outline may lie from its circle and still be its rim, in spacings of
   * the lid's points (the square root of its hull's area per point): the outline is known to
   * about one spacing. */
  float rim_spacings{1.5f};
  float min_radius{0.01f}, max_radius{0.25f}; ///< the circle's radius is in this interval
  std::size_t min_points{30};                 ///< lid points at least this many
  int sectors{36};                            ///< of the circle, for rim_coverage
  /** The rim is seen over at least this share of the circle: a shorter arc fits circles of
   * many radii (a flat fragment, a tab, is no lid). */
  float min_rim_coverage{0.5f};
  /** The lid's height band (3 robust sigmas of its n flat points' heights) is at most this,
   * give or take two standard errors of that measure (1.167 / sqrt(n) of it): a lid is as flat
   * as the sensor sees its support at that range (the caller: the support's band there), or as
   * its own pixels show their noise (with dense points: 3 adjacentNoise of those near the lid's
   * level; a dark or glossy lid returns less light than a matte table and is noisier); a dome's
   * top within max_normal_angle is not. Infinite: no limit. */
  float max_band{std::numeric_limits<float>::infinity()};
};

/** \brief What fitLid found. */
struct LidFit {
  bool found{false};
  /** Axis the support's normal (up), base on the support, top at the lid, the lid's circle's
   * radius; inliers: the lid's columns (ascending); inlier_ratio 0 (no point on the side);
   * distance_threshold: the lid's height band. */
  CylinderModel model;
  std::size_t lid_points{0}; ///< points on the lid: flat, at its height
  float rim_band{0.f};       ///< m: rim_spacings of the lid's point spacing
  /** Share of the circle's sectors where a lid point lies within rim_band of the circle: the
   * rim seen (1 for a whole disc; a box's top, whose sides fall inside the circle, covers
   * little). */
  float rim_coverage{0.f};
  /** Share of the lid points farther than rim_band beyond the circle: none on a disc, a box
   * top's corners. */
  float outside_share{0.f};
};

/** \brief The noise (a standard deviation) of a surface's \a heights sampled in order along
 * rows (an organized cloud's pixels), from the differences of consecutive samples whose
 * positions \a xy lie within \a reach of each other: 1.4826 x the median of their absolute
 * values over sqrt 2 (the difference of two independent errors). NaN heights are skipped. NaN
 * with fewer than \a min_pairs such pairs. */
float adjacentNoise(const std::vector<float>& heights, const std::vector<Eigen::Vector2f>& xy,
                    float reach, std::size_t min_pairs);

/** \brief The cylinder whose lid the columns of \a points (unit \a normals alongside, NaN where
 * unknown) show, standing on \a support (n . p + d = 0, n unit, either sign) with \a up its
 * normal towards the objects. \a dense: all the object's points, when \a points are a sample
 * of them (the lattice the cues come from): the lid's outline is then taken from those of them
 * at the lid's height, to their finer spacing (a box top's corners stick out of a circle by
 * less than a lattice's spacing).
 *
 * The lid points: normals within max_normal_angle of up, above the support, at the median
 * height of those within 3 robust sigmas of it (1.4826 x the median absolute deviation; at
 * least a quarter of the point spacing), or the dense points at that height. The circle:
 * fitCircleAlgebraic on the vertices of their convex hull in the support's plane (an occluder's cut
 * leaves a chord whose ends lie on the circle), then fitCircle on those vertices within rim_band.
 * Not found with fewer than min_points lid points, fewer than 3 hull vertices on the circle, a
 * radius outside the limits, or less of the rim seen than min_rim_coverage. */
LidFit fitLid(const Eigen::Matrix3Xf& points, const Eigen::Matrix3Xf& normals,
              const Eigen::Vector4f& support, const Eigen::Vector3f& up,
              const LidSettings& settings = {}, const Eigen::Matrix3Xf& dense = Eigen::Matrix3Xf());

/** \brief Share of the rays of \a seen (points of the frame around the object, the sensor at
 * the origin) that cross the lid of \a lid (its top's disc, within radius - \a rim_band of the
 * axis) and see something lower than it by more than \a depth_band (the sensor's noise there):
 * a solid lid hides what lies behind it, so where the frame sees through the disc, there is
 * none (beside a box top's sides, the table under the circle fitted across its corners). NaN
 * when no ray crosses the disc. */
float seenThroughShare(const Eigen::Matrix3Xf& seen, const CylinderModel& lid, float rim_band,
                       float depth_band);

/** \brief Share of the 36 sectors around the lid of \a lid (its top's disc) where a point of
 * \a seen rises above the lid's plane by more than \a band just beyond its rim (between
 * radius + band and radius + max(3 band, 0.2 radius) from the axis): a disc walled in all
 * round is the floor of a container or a recess seen through its opening, not an object's
 * top (a nearer object beside a lid walls a few sectors). */
float walledShare(const Eigen::Matrix3Xf& seen, const CylinderModel& lid, float band);

} // namespace facyl
