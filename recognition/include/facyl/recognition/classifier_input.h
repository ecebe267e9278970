/*
 * facyl: fast cylinder detection for PCL.
 * What the shape classifier's network sees of an object: the one preprocessing that the
 * classifier, the training-data tool and the evaluators share (recognition/training reads the
 * images it writes, so training and inference cannot drift apart).
 */
#pragma once

#include <facyl/recognition/shape_classifier.h>

#include <pcl/point_cloud.h>
#include <pcl/types.h>

#include <cstdint>
#include <string>
#include <vector>

namespace facyl {

/** \brief The network's input channels. */
enum class ClassifierChannels {
  Rgb,     ///< the RGB crop, as in the paper (3 channels)
  Depth,   ///< 2.5-D: the object's mask and its depth relative to its median (2 channels)
  DepthRgb ///< Depth's 2 channels followed by Rgb's 3 (5 channels)
};

/** \brief "rgb", "depth" or "depthrgb". */
std::string toString(ClassifierChannels channels);
/** \brief Parses "rgb", "depth" or "depthrgb". \return false for anything else. */
bool parseClassifierChannels(const std::string& text, ClassifierChannels& channels);
/** \brief 3 for Rgb, 2 for Depth, 5 for DepthRgb. */
int channelCount(ClassifierChannels channels);

/** \brief How a view becomes the network's input image. */
struct ClassifierInputSpec {
  ClassifierChannels channels{ClassifierChannels::Depth};
  int size{64}; ///< the image is size x size pixels, in [8, 512]
};

/** \brief The input image of \a view: channelCount x size x size bytes, channel-major (planar),
 * rows top to bottom. The object's pixel box is padded to a square about its centre and
 * sampled at size x size pixel centres (nearest pixel); outside the image: 0.
 * - Rgb: the crop's R, G, B (all pixels of the box, neighbours included, as in the paper).
 * - Depth: channel 0 is 255 where a point of the object was seen, else 0; channel 1 is
 *   128 + 127 clamp((z - median z) / extent, -1, 1) there (extent: the larger of the object's
 *   x and y spans in the camera frame, at least 1 cm), 128 elsewhere.
 * - DepthRgb: Depth's two planes, then Rgb's three (the same square, so pixel (x, y) of every
 *   plane is the same pixel of the frame; training data joins facyl_crops' depth and rgb
 *   images into it).
 * \return an empty vector when the view has no box, or (Rgb, DepthRgb) no crop, or (Depth,
 * DepthRgb) no pixels. */
std::vector<std::uint8_t> classifierImage(const ObjectView& view, const ClassifierInputSpec& spec);

/** \brief The view of the points \a indices of \a cloud: box, points, pixels and (for point
 * types with colour, \a with_crop) the RGB crop of the box. Organized clouds: pixels from the
 * indices; else projected with \a camera when it is valid (no pixels, box or crop otherwise).
 * A depth-only classifier reads no crop (ShapeClassifier::usesCrop): copying a box of a VGA
 * frame's points costs more than the classifier's input image. */
template <typename PointT>
ObjectView objectView(const pcl::PointCloud<PointT>& cloud, const pcl::Indices& indices,
                      const PinholeCamera& camera, bool with_crop = true);

/** \brief Sets \a view's box from its pixels (-1: unknown); [-1, -1, -1, -1] when it has
 * none. */
void viewBox(ObjectView& view);

/** \brief Sets \a view's box from its pixels (-1: unknown) and, for point types with colour
 * and \a with_crop, its RGB crop: the box's pixels of an organized \a cloud, else the points
 * \a indices drawn at their pixels (black elsewhere); without \a with_crop the crop stays
 * empty. For views whose pixels come from elsewhere (a file's image coordinates). */
template <typename PointT>
void viewBoxAndCrop(ObjectView& view, const pcl::PointCloud<PointT>& cloud,
                    const pcl::Indices& indices, bool with_crop = true);

/** \brief The view of the points \a indices of \a cloud by a virtual pinhole camera at \a
 * viewpoint looking at their centroid (its x axis along the cloud's x as far as possible):
 * for clouds without pixels (unorganized, no camera). Its focal length makes the object's
 * pixel box about as many pixels as it has points (the silhouette is then filled, as a
 * sensor's image of it is), clamped to [50, 2000] pixels. points are in that camera's frame;
 * box and crop as in objectView. An empty view (no box) when no point is in front. */
template <typename PointT>
ObjectView lookAtObjectView(const pcl::PointCloud<PointT>& cloud, const pcl::Indices& indices,
                            const Eigen::Vector3f& viewpoint, bool with_crop = true);

} // namespace facyl

#define FACYL_INSTANTIATE_objectView(T)                                                            \
  template facyl::ObjectView facyl::objectView<T>(const pcl::PointCloud<T>&, const pcl::Indices&,  \
                                                  const facyl::PinholeCamera&, bool);              \
  template void facyl::viewBoxAndCrop<T>(facyl::ObjectView&, const pcl::PointCloud<T>&,            \
                                         const pcl::Indices&, bool);                               \
  template facyl::ObjectView facyl::lookAtObjectView<T>(                                           \
    const pcl::PointCloud<T>&, const pcl::Indices&, const Eigen::Vector3f&, bool);

#ifdef PCL_NO_PRECOMPILE
#include <facyl/recognition/impl/classifier_input.hpp>
#endif
