/*
 * facyl: fast cylinder detection for PCL.
 * Where a cylinder fitted to one segment spans two objects stacked on each other (a can standing
 * on a tin, a tube on a can): the section of the side changes at one height, abruptly, where the
 * section of one object stays the same (a can) or changes smoothly (a cup's taper); or a lid
 * shows inside the fitted extent; or the side stops being a circle where a box's faces begin
 * (a box standing on a tin). Free functions of the fitted axis and the segment's points with
 * their normals.
 */
#pragma once

#include <facyl/sample_consensus_alt/cylinder_model.h>

#include <Eigen/Core>

#include <cstddef>
#include <limits>

namespace facyl {

/** \brief Settings of findSectionStep. The sizes are shares and ratios: the noise is measured
 * on the points (the robust sigma of each model's residuals), not given. */
struct SectionStepSettings {
  /** Each section holds at least this share of the side points (a can's rim is no object of
   * its own; a short tin under a tall tube holds about a sixth) ... */
  float min_side_share{0.15f};
  std::size_t min_side_points{30}; ///< ... and at least this many
  /** The step explains the side better than any smooth change: the smooth model's robust sigma
   * is at least this many times the step's. */
  float min_improvement{1.5f};
  /** The two sections lie apart (SectionStep::gap) by at least this many of the step's
   * robust sigmas. */
  float min_step_sigmas{3.f};
  /** findSectionEnd: a circle fits one section this many times better (robust sigma) than
   * the other. */
  float min_end_ratio{4.f};
  /** findSectionEnd: the other section's normals lie within max_face_angle (rad) of two
   * directions (a box's faces) for at least min_faces_share of its points. */
  float max_face_angle{0.26f};
  float min_faces_share{0.7f};
};

/** \brief What findSectionStep measured. */
struct SectionStep {
  bool found{false}; ///< the side is two sections, one above the other
  /** Along the model's axis from its base: where the upper section starts. */
  float height{std::numeric_limits<float>::quiet_NaN()};
  float radius_below{std::numeric_limits<float>::quiet_NaN()}; ///< circle of the lower section
  float radius_above{std::numeric_limits<float>::quiet_NaN()}; ///< ... of the upper one
  float centre_shift{std::numeric_limits<float>::quiet_NaN()}; ///< between their centres
  /** How far apart the sections are where they are seen: the larger of the two medians of a
   * section's points' signed distances from the other section's circle, in absolute value. */
  float gap{std::numeric_limits<float>::quiet_NaN()};
  float sigma_step{std::numeric_limits<float>::quiet_NaN()};   ///< robust sigma, two sections
  float sigma_smooth{std::numeric_limits<float>::quiet_NaN()}; ///< ... one smooth section
  std::size_t side_points{0}; ///< the points used (see findSectionStep)
};

/** \brief Whether the side around \a model is two stacked sections. The side points: columns
 * of \a points between 0.5 and 1.5 radii from the axis whose normals (unit, alongside) are
 * within 45 degrees of perpendicular to it. Two models of their circles across the axis
 * (x, y), against the position t along it, are fitted by algebraic (Kasa) least squares, each
 * once more without the residuals beyond 3 robust sigmas (a handle, a neighbour's points):
 * - smooth: centre linear in t, radius^2 quadratic in t (a cylinder, a tilted fit's drift, a
 *   cone's taper), 7 parameters;
 * - step: one circle below a height and another above it (3 + 3 parameters), at the height
 *   (tried at 33 points between the quantiles min_side_share and 1 - min_side_share) whose
 *   two circles leave the smallest median residual.
 * Found when the smooth model's robust sigma (1.4826 x the median |residual|) is at least
 * min_improvement times the step's and the sections lie min_step_sigmas of it apart (gap).
 * Not found with fewer than 2 x min_side_points side points. */
SectionStep findSectionStep(const CylinderModel& model, const Eigen::Matrix3Xf& points,
                            const Eigen::Matrix3Xf& normals,
                            const SectionStepSettings& settings = {});

/** \brief What findSectionEnd measured. */
struct SectionEnd {
  bool found{false}; ///< the side is a circle on one side of the height and no circle beyond
  /** Along the model's axis from its base: where the circle's section ends (its last point);
   * NaN when no section fits a circle min_end_ratio times better than the other. */
  float height{std::numeric_limits<float>::quiet_NaN()};
  bool circle_below{false};                                    ///< the circle is the lower section
  float sigma_circle{std::numeric_limits<float>::quiet_NaN()}; ///< robust sigma, the circle's
  float sigma_other{std::numeric_limits<float>::quiet_NaN()};  ///< ... the other section's
  float faces_share{0.f};     ///< of the other section's normals, on two directions
  std::size_t side_points{0}; ///< the points used (see findSectionStep)
};

/** \brief Where the side around \a model stops being a circle: a box standing on a tin, whose
 * faces a circle through the tin's side cannot follow. The side points as in findSectionStep;
 * at each of its 33 heights (each section min_side_share of the points and of their extent), a
 * circle (Kasa) through each section; the height where one section's robust sigma is the
 * largest multiple of the other's; the circle's section then ends where most points stop lying
 * on its circle (3 robust sigmas). Found when that multiple is at least min_end_ratio, the
 * other section's normals lie on two faces (min_faces_share) and it spans at least the
 * model's radius along the axis. */
SectionEnd findSectionEnd(const CylinderModel& model, const Eigen::Matrix3Xf& points,
                          const Eigen::Matrix3Xf& normals,
                          const SectionStepSettings& settings = {});

/** \brief A lid seen inside a cylinder's extent (interiorLid). */
struct InteriorLid {
  /** Along the model's axis from its base; NaN: none. */
  float height{std::numeric_limits<float>::quiet_NaN()};
  /** +1 when the lid faces the axis's direction (its object lies below it, towards the base),
   * -1 when it faces the base. */
  int facing{0};
};

/** \brief Where an object's lid shows inside \a model's extent (a box standing on a tin, the
 * tin's lid seen round it): the median position along the axis (from the base) of the columns of
 * \a points whose normals (unit, alongside; facing the sensor) lie within \a max_angle (rad) of
 * the axis, within the radius plus \a band of it and between min_side_share of the extent from
 * either end, when there are at least min_side_points of them and they lie at one height (their
 * median absolute deviation at most \a band); which way it faces from their normals' mean.
 * A solid cylinder shows its lids at its ends only; a cup's floor lies at its bottom. */
InteriorLid interiorLid(const CylinderModel& model, const Eigen::Matrix3Xf& points,
                        const Eigen::Matrix3Xf& normals, float max_angle, float band,
                        const SectionStepSettings& settings = {});

} // namespace facyl
