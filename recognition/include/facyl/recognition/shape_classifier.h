/*
 * facyl: fast cylinder detection for PCL.
 */
#pragma once

#include <facyl/segmentation/tabletop_geometry.h>

#include <Eigen/Core>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace facyl {

/** \brief An 8-bit RGB image, rows top to bottom, 3 bytes per pixel. */
struct RgbImage {
  int width{0};
  int height{0};
  std::vector<std::uint8_t> data; ///< width * height * 3
  bool
  empty() const
  {
    return width <= 0 || height <= 0 || data.size() != static_cast<std::size_t>(width) * height * 3;
  }
};

/** \brief What a shape classifier sees of one cluster: its RGB crop (the pixels of the box;
 * for unorganized clouds, the points drawn at their projections) and its points. */
struct ObjectView {
  RgbImage crop;            ///< empty when the cloud has no colour and no image position
  PixelBox box{-1, -1, -1, -1};
  Eigen::Matrix3Xf points;  ///< camera frame
};

/** \brief Interface of the optional stage that rejects non-cylinders before fitting (paper
 * III-B). Implementations must be safe to call from one thread at a time. */
class ShapeClassifier {
public:
  using Ptr = std::shared_ptr<ShapeClassifier>;
  using ConstPtr = std::shared_ptr<const ShapeClassifier>;
  virtual ~ShapeClassifier() = default;
  /** \brief Probability in [0, 1] that \a view shows a cylinder; NaN when it cannot tell (the
   * object is then fitted as if there were no classifier). */
  virtual float
  cylinderProbability(const ObjectView& view) = 0;
  /** \brief A short name for reports. */
  virtual std::string
  name() const = 0;
};

} // namespace facyl
