/*
 * facyl: fast cylinder detection for PCL.
 * What a fitted cylinder's points say about the shape they come from: the evidence that tells a
 * cylinder from the other shapes a cylinder also fits (a box's edge, a bowl, a cone's band, a
 * banana, two objects side by side). Each is a free function of the fit and the points, with
 * unit normals alongside (oriented towards the sensor, as NormalCurvatureEstimation gives
 * them), over the columns flagged in a mask (all when the mask is empty).
 */
#pragma once

#include <facyl/sample_consensus_alt/cylinder_model.h>

#include <Eigen/Core>

#include <cstdint>
#include <vector>

namespace facyl {

/** \brief The shape evidence of one fit (see shapeEvidence); NaN where unknown. */
struct ShapeEvidence {
  /** Median angle between a side point's normal, across the axis, and the radial line through
   * it, in units of how much neighbouring normals scatter (the square root of the side points'
   * median k_max + k_min: noise, and the turn of the surface within a neighbourhood). About
   * 0.5 on a cylinder whatever the sensor and the radius: its normals turn with the radial line
   * and only the noise and the estimate's smoothing separate them; 2 and more on a box, whose
   * flat faces, fitted by a cylinder across their edge, keep one normal each while the radial
   * line turns under them. */
  float normal_agreement;
  /** Largest share of the side points whose normals, across the axis, lie within 10 degrees of
   * one direction: a cylinder's normals turn evenly over the arc it shows (a half-visible can:
   * about 0.15), a box face's all point one way (0.5 and more). */
  float normal_concentration;
  /** Range of the side's radius along the axis, relative to the radius: the median distance
   * from the axis in the 4 middle slices of 6 along it (at least 3 with 8 points), max minus
   * min, over the radius. About 0 on a cylinder (its rims and a can's neck lie in the end
   * slices); a bowl's curved wall, a sphere, a cone and a bottle's shoulder change it. */
  float profile_range;
  /** How far the axis bends, relative to the radius: in 5 slices along the axis, the centre of
   * each slice's side points (each point moved one radius against its normal), the largest
   * distance of a slice's centre from their mean, over the radius. A banana, a bent tube. */
  float axis_bend;
  /** Share of the points inside the cylinder (under 0.85 radius from the axis, within its
   * extent) whose normals point at the axis: the inside of an open container (a bowl, a cup). */
  float inner_share;
  /** Share of the points farther from the axis than the surface (by more than
   * max(2 x distance, 0.1 x radius)): a box's corners beyond the circle fitted across its
   * faces, a second object beside the cylinder, a handle. */
  float outside_share;
  /** The fit's height over its radius: an open container shallower than its radius is a
   * bowl, one deeper a cup (see evidenceFeatures). */
  float aspect;
};

/** \brief The shape evidence of \a model on the columns of \a points (unit \a normals and the
 * scatter of the neighbouring normals, k_max + k_min of NormalCurvatureEstimation, alongside)
 * flagged in \a mask (all when empty). Side points are within \a distance (the fit's inlier
 * distance, > 0) of the surface, within its axial extent, with a normal within 60 degrees of
 * perpendicular to the axis. Fields are NaN when too few points say anything: fewer than 10
 * side points (agreement, concentration; agreement also without the scatter), too few slices
 * (profile, bend), no point (shares). */
ShapeEvidence shapeEvidence(const CylinderModel& model, const Eigen::Matrix3Xf& points,
                            const Eigen::Matrix3Xf& normals, const Eigen::VectorXf& scatter,
                            const std::vector<std::uint8_t>& mask, float distance);

/** \brief Largest share of \a angles (rad, any range: taken modulo 2 pi) within a window of
 * \a width (rad) on the circle; 0 for none. */
float largestCircularWindowShare(std::vector<float> angles, float width);

} // namespace facyl
