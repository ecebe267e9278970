/*
 * facyl: fast cylinder detection for PCL.
 */
#pragma once

#include <Eigen/Core>

#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace facyl {

/** \brief One component of a 3-D Gaussian mixture over axis directions (paper eq. 2). */
struct GaussianComponent {
  float weight{1.f};                                              ///< phi^m, > 0
  Eigen::Vector3f mean{Eigen::Vector3f::Zero()};                  ///< mu^m
  Eigen::Matrix3f covariance{Eigen::Matrix3f::Identity() * 0.5f}; ///< Sigma^m, SPD
};

/** \brief Orientation priors: the paper's Table II, plus "horizontal".
 * Directions are expressed in a reference frame whose z axis is "up" (e.g. the table normal).
 */
enum class OrientationPrior {
  Uniform,        ///< Table II "unbiased": mean 0, Sigma = 0.5 I (rotationally symmetric)
  Vertical,       ///< Table II "mildly top-biased": mean (0,0,1), Sigma = 0.5 I
  VerticalStrong, ///< Table II "strongly top-biased": mean (0,0,1), Sigma = 0.05 I
  Horizontal,     ///< lying cylinders: mean 0, Sigma = diag(0.5, 0.5, 0.02)
};

/** \brief Parses "uniform", "vertical", "vertical-strong", "horizontal".
 * \return false for any other name. */
bool parseOrientationPrior(const std::string& name, OrientationPrior& prior);
/** \brief The name parseOrientationPrior accepts for \a prior. */
std::string toString(OrientationPrior prior);

/** \brief A Gaussian mixture over R^3 whose normalised samples are axis directions (eq. 2). */
struct GaussianMixture {
  std::vector<GaussianComponent> components;

  /** \brief The mixture of a preset prior. */
  static GaussianMixture fromPrior(OrientationPrior prior);

  /** \brief True if there is at least one component, weights are positive and finite, and
   * every covariance is symmetric positive definite. \a why (if given) says what is wrong. */
  bool isValid(std::string* why = nullptr) const;
};

/** \brief Folds an axis direction onto the hemisphere z > 0 (ties broken on y, then x): an
 * axis has no sign, so d and -d are the same cell. */
Eigen::Vector3f foldToHemisphere(const Eigen::Vector3f& direction);

/** \brief Draws \a count unit axis directions i.i.d. from \a mixture (paper eq. 1-2), rotated
 * by \a frame (columns: the prior frame's axes in the output frame) and folded onto one
 * hemisphere.
 *
 * Deterministic for a given seed on every platform (mt19937_64 and a Box-Muller transform of
 * our own; std::normal_distribution differs between standard libraries).
 * \throws std::invalid_argument if the mixture is invalid.
 */
Eigen::Matrix3Xf sampleOrientations(const GaussianMixture& mixture, std::size_t count,
                                    std::uint64_t seed,
                                    const Eigen::Matrix3f& frame = Eigen::Matrix3f::Identity());

/** \brief Median angular distance (rad) from a cell to its nearest other cell: the
 * accumulator's resolution. O(N^2); for N of a few thousand. */
float medianCellSpacing(const Eigen::Matrix3Xf& directions);

/** \brief A set of candidate axis directions (the cells of an orientation Hough accumulator,
 * paper eq. 1), with the votes cast into them. */
class OrientationAccumulator {
public:
  using Ptr = std::shared_ptr<OrientationAccumulator>;
  using ConstPtr = std::shared_ptr<const OrientationAccumulator>;

  OrientationAccumulator() = default;
  /** \brief Cells from explicit unit directions (3 x N). They are folded and normalised. */
  explicit OrientationAccumulator(const Eigen::Matrix3Xf& directions);

  /** \brief N_d cells drawn from a mixture; see sampleOrientations. */
  static OrientationAccumulator sample(const GaussianMixture& mixture, std::size_t count,
                                       std::uint64_t seed,
                                       const Eigen::Matrix3f& frame = Eigen::Matrix3f::Identity());

  /** \brief The cell directions, 3 x N, unit, on one hemisphere. */
  const Eigen::Matrix3Xf& directions() const
  {
    return directions_;
  }
  /** \brief Number of cells N_d. */
  std::size_t size() const
  {
    return static_cast<std::size_t>(directions_.cols());
  }
  /** \brief Nominal angular radius of a cell (rad): nominalCellRadius(size()). */
  float cellRadius() const
  {
    return nominalCellRadius(size());
  }
  /** \brief Nominal angular radius (rad) of a cell of an accumulator of \a cells cells:
   * sqrt(2 / N_d), the radius of N_d equal disks covering a hemisphere (3.8 deg for the
   * paper's N_d = 450); 0 without cells. */
  static float nominalCellRadius(std::size_t cells)
  {
    return cells > 0 ? std::sqrt(2.f / static_cast<float>(cells)) : 0.f;
  }

private:
  Eigen::Matrix3Xf directions_;
};

} // namespace facyl
