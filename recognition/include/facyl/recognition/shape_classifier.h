/*
 * facyl: fast cylinder detection for PCL.
 */
#pragma once

#include <facyl/recognition/cylinder_evidence.h>
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
  bool empty() const
  {
    return width <= 0 || height <= 0 || data.size() != static_cast<std::size_t>(width) * height * 3;
  }
};

/** \brief What a shape classifier sees of one cluster: its RGB crop (the pixels of the box;
 * for unorganized clouds, the points drawn at their projections), its points and the pixel
 * each point was seen at (see objectView). */
struct ObjectView {
  RgbImage crop;                ///< the pixels of box; empty when the cloud has no colour
  PixelBox box{-1, -1, -1, -1}; ///< in the full image; all -1 when unknown
  Eigen::Matrix3Xf points;      ///< camera frame
  /** Pixel (u, v) of each point in the full image; empty or -1 where unknown. */
  Eigen::Matrix2Xi pixels;
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
  virtual float cylinderProbability(const ObjectView& view) = 0;
  /** \brief cylinderProbability of every view, in order; implementations may run them as one
   * batch (the default calls cylinderProbability for each). */
  virtual std::vector<float> cylinderProbabilities(const std::vector<ObjectView>& views)
  {
    std::vector<float> p;
    p.reserve(views.size());
    for (const auto& v : views)
      p.push_back(cylinderProbability(v));
    return p;
  }
  /** \brief The final probability that a fitted object is a cylinder, from the classifier's
   * \a p_network for its view and the fit's \a evidence under \a decision (see
   * evidenceFeatures). The default returns \a p_network; a classifier with a calibrated
   * evidence model overrides it. */
  virtual float fuse(float p_network, const CylinderEvidence& evidence,
                     const CylinderDecision& decision) const
  {
    (void)evidence;
    (void)decision;
    return p_network;
  }
  /** \brief A short name for reports. */
  virtual std::string name() const = 0;
  /** \brief Whether cylinderProbability reads the views' RGB crop (ObjectView::crop); false
   * lets the recognizer skip copying it (the default: true). */
  virtual bool usesCrop() const
  {
    return true;
  }
};

} // namespace facyl
