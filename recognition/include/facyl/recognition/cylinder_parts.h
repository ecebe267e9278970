/*
 * facyl: fast cylinder detection for PCL.
 * Which other segment is a part of the object a cylinder was fitted to: the segmentation cuts an
 * object where its surface jumps or turns inwards, and some objects do both within themselves
 * (an open container's inside behind its rim, a mug's handle, a lid set into a tin's rim). Each
 * rule is a free function of the fitted cylinder and a sample of the other segment's points,
 * with their normals alongside (unit, towards the sensor; NaN where unknown).
 */
#pragma once

#include <facyl/sample_consensus_alt/cylinder_model.h>

#include <Eigen/Core>

namespace facyl {

/** \brief True when \a points (normals alongside) are the inside of the open container that
 * \a cylinder was fitted to (its outer wall): most of them (60 %) lie within the rim (1.3
 * radii from the axis, which may be wider than the wall fitted below it) and up to a radius
 * above the top (a bowl's rim rises above that wall), a good part (40 %) within the wall's
 * radius (an object beside or behind is not), and the normals that face across the axis
 * face it (60 %: concave, unlike an object stacked on a lid). */
bool isContainerInside(const CylinderModel& cylinder, const Eigen::Matrix3Xf& points,
                       const Eigen::Matrix3Xf& normals);

/** \brief True when \a points lie beside \a cylinder, within its height (+-0.2 radii) and two
 * radii of its axis (80 % of them): a mug's handle cut off at the depth jump between handle
 * and body. The caller sees that the fragment is small beside the cylinder's object. */
bool isAttachment(const CylinderModel& cylinder, const Eigen::Matrix3Xf& points);

/** \brief True when \a points (normals alongside) are an end of \a cylinder: a disc across its
 * axis within its volume, as a lid set into a tin's rim (cut off by the concave crease at the
 * rim), a can's end seen past its wall, or a cup's bottom seen through its opening.
 * 80 % of the points lie within 1.1 radii of the axis, within the height extended by the
 * band, and within the band of one section across the axis (their median); of the normals
 * known, 60 % run along the axis (within 45 degrees). The band is the larger of twice the fit's
 * inlier threshold (the noise) and 0.15 radii (a lid's relief, an end's curvature). A can
 * standing on a lying tin's side, an object beside or behind, a box face along the axis fail
 * it. */
bool isEndCap(const CylinderModel& cylinder, const Eigen::Matrix3Xf& points,
              const Eigen::Matrix3Xf& normals);

} // namespace facyl
