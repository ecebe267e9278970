/*
 * facyl: fast cylinder detection for PCL.
 * Small numerics of the tabletop pipeline, free functions so that tests reach them.
 */
#pragma once

#include <pcl/point_cloud.h>
#include <pcl/types.h>

#include <Eigen/Geometry>

#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

namespace facyl {

/** \brief A pinhole camera: pixel (u, v) = (fx x / z + cx, fy y / z + cy). */
struct PinholeCamera {
  float fx{0.f}, fy{0.f}, cx{0.f}, cy{0.f};
  int width{0}, height{0};
  /** \brief True when fx, fy > 0 and the image is not empty. */
  bool valid() const
  {
    return fx > 0.f && fy > 0.f && width > 0 && height > 0;
  }
  /** \brief The pixel of camera-frame point \a p (z > 0). */
  Eigen::Vector2f project(const Eigen::Vector3f& p) const
  {
    return {fx * p.x() / p.z() + cx, fy * p.y() / p.z() + cy};
  }
};

/** \brief Every \a step-th pixel of every \a step-th row of the organized \a cloud, starting
 * with the first: an organized cloud of ceil(width / step) x ceil(height / step) with the
 * cloud's header and sensor pose. \a step >= 1. */
template <typename PointT>
void
latticeOf(const pcl::PointCloud<PointT>& cloud, int step, pcl::PointCloud<PointT>& out)
{
  const auto w = static_cast<std::size_t>(cloud.width), h = static_cast<std::size_t>(cloud.height);
  const auto s = static_cast<std::size_t>(step);
  const std::size_t lw = (w + s - 1) / s, lh = (h + s - 1) / s;
  out.header = cloud.header;
  out.sensor_origin_ = cloud.sensor_origin_;
  out.sensor_orientation_ = cloud.sensor_orientation_;
  out.is_dense = cloud.is_dense;
  out.resize(lw * lh);
  out.width = static_cast<std::uint32_t>(lw);
  out.height = static_cast<std::uint32_t>(lh);
  for (std::size_t v = 0; v < lh; ++v)
    for (std::size_t u = 0; u < lw; ++u)
      out[v * lw + u] = cloud[v * s * w + u * s];
}

/** \brief The pixels of the \a step x \a step blocks of the lattice pixels \a lattice (strictly
 * ascending indices into the lattice image of latticeOf, ceil(\a width / \a step) wide) in a
 * \a width x \a height image, for which \a keep(pixel, the block's lattice pixel as an image
 * index) holds; ascending. */
template <typename Keep>
pcl::Indices
blockPixels(const pcl::Indices& lattice, int width, int height, int step, Keep keep)
{
  pcl::Indices out;
  const int lw = (width + step - 1) / step;
  std::size_t k = 0;
  while (k < lattice.size()) {
    // The lattice pixels of one lattice row, then the image rows of its blocks in order.
    const int row = lattice[k] / lw;
    std::size_t end = k;
    while (end < lattice.size() && lattice[end] / lw == row)
      ++end;
    for (int dv = 0; dv < step && row * step + dv < height; ++dv)
      for (std::size_t j = k; j < end; ++j) {
        const int u0 = (lattice[j] % lw) * step;
        const auto parent = static_cast<pcl::index_t>(row * step * width + u0);
        for (int du = 0; du < step && u0 + du < width; ++du) {
          const auto pixel = static_cast<pcl::index_t>((row * step + dv) * width + u0 + du);
          if (keep(pixel, parent))
            out.push_back(pixel);
        }
      }
    k = end;
  }
  return out;
}

/** \brief True when \a camera's intrinsics are finite and positive and its image is at most
 * 8192 x 8192 pixels (the images facyl builds from it stay below half a gigabyte). */
inline bool
cameraUsable(const PinholeCamera& camera)
{
  return camera.valid() && std::isfinite(camera.fx) && std::isfinite(camera.fy) &&
         std::isfinite(camera.cx) && std::isfinite(camera.cy) && camera.width <= 8192 &&
         camera.height <= 8192;
}

/** \brief Pixel box, inclusive: {u0, v0, u1, v1}; all -1 when unknown. */
using PixelBox = std::array<int, 4>;

/** \brief Least-squares plane through \a points (3 x n, n >= 3): unit normal, d; its normal
 * points to the side of \a viewpoint. \return false when the points do not span a plane. */
bool fitPlane(const Eigen::Matrix3Xf& points, const Eigen::Vector3f& viewpoint,
              Eigen::Vector4f& plane);

/** \brief \a plane (a, b, c, d) scaled to a unit normal that points to \a viewpoint's side. */
Eigen::Vector4f orientPlane(const Eigen::Vector4f& plane, const Eigen::Vector3f& viewpoint);

/** \brief Frame of a plane: z is its unit normal, origin the projection of \a origin_hint on it,
 * x the projection of the sensor's x axis (or y when x is nearly normal to the plane). Maps
 * table coordinates to sensor coordinates. */
Eigen::Affine3f planeFrame(const Eigen::Vector4f& plane, const Eigen::Vector3f& origin_hint);

/** \brief Even-odd test of \a p against a simple polygon (vertices in order). */
bool pointInPolygon(const Eigen::Vector2f& p, const std::vector<Eigen::Vector2f>& polygon);

/** \brief The box of \a polygon grown by \a distance and a millimetre (float rounding): no
 * point outside it lies in the polygon or within \a distance of it. Empty for no vertex. */
Eigen::AlignedBox2f polygonReach(const std::vector<Eigen::Vector2f>& polygon, float distance);

/** \brief How many of the points \a pts (3 x n), taken into a plane's coordinates by
 * \a to_plane, lie in \a polygon (pointInPolygon of their x and y). Points well outside the
 * polygon's box are counted out without the test. */
std::size_t pointsInPolygon(const Eigen::Matrix3Xf& pts, const Eigen::Affine3f& to_plane,
                            const std::vector<Eigen::Vector2f>& polygon);

/** \brief Bounding box of organized-cloud indices in an image \a width pixels wide. */
PixelBox pixelBox(const pcl::Indices& indices, std::uint32_t width);

/** \brief Of organized-cloud \a indices (an image \a width x \a height pixels), the first and the
 * last of each image row (one when a row holds one), rows in order. The image of a plane is a
 * projective map of it, which keeps convex hulls: the convex hull of points of a plane seen in
 * an image has its vertices among these. Indices outside the image are skipped. */
pcl::Indices rowExtremes(const pcl::Indices& indices, std::uint32_t width, std::uint32_t height);

/** \brief Bounding box of the projections of \a points (camera frame; points with z <= 0 are
 * skipped), clipped to the image. All -1 when nothing projects inside. */
PixelBox projectedBox(const Eigen::Matrix3Xf& points, const PinholeCamera& camera);

/** \brief The sensor's pose in a cloud's frame (PCL's sensor_origin_ and sensor_orientation_,
 * the PCD file's VIEWPOINT): maps sensor coordinates to the cloud's. */
Eigen::Affine3f sensorPose(const Eigen::Vector4f& origin, const Eigen::Quaternionf& orientation);

/** \brief The sensor pose to use for a cloud whose points include \a sample (3 x n): the stored
 * one (sensorPose), unless its rotation puts fewer of the sample in front of the sensor (z > 0
 * in the sensor's frame) than the origin alone does. Some files store the pose of a viewer
 * rather than the sensor's (PCL's grabber frames: a 180-degree turn about x, with the points in
 * the camera's frame); an RGB-D frame's points lie in front of its sensor. The origin is always
 * kept. */
Eigen::Affine3f plausibleSensorPose(const Eigen::Matrix3Xf& sample, const Eigen::Vector4f& origin,
                                    const Eigen::Quaternionf& orientation);

/** \brief True when \a pose is the identity within 1e-6 (the cloud is in the sensor's frame). */
bool isIdentityPose(const Eigen::Affine3f& pose);

/** \brief Plane (a, b, c, d) with unit normal moved by the rigid transform \a t. */
Eigen::Vector4f transformPlane(const Eigen::Vector4f& plane, const Eigen::Affine3f& t);

/** \brief Pinhole intrinsics from points and the pixels they were measured at (least squares
 * on u = fx x/z + cx and v = fy y/z + cy). \return false with fewer than 10 usable points or a
 * degenerate fit. */
bool estimatePinhole(const Eigen::Matrix3Xf& points, const Eigen::Matrix2Xf& pixels, int width,
                     int height, PinholeCamera& camera);

} // namespace facyl
