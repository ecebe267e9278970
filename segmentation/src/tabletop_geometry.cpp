/*
 * facyl: fast cylinder detection for PCL.
 */
#include <facyl/segmentation/support_planes.h>
#include <facyl/segmentation/tabletop_geometry.h>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>

namespace facyl {

Eigen::Vector4f
orientPlane(const Eigen::Vector4f& plane, const Eigen::Vector3f& viewpoint)
{
  const float norm = plane.head<3>().norm();
  Eigen::Vector4f p = plane / norm;
  if (p.head<3>().dot(viewpoint) + p[3] < 0.f)
    p = -p;
  return p;
}

bool
fitPlane(const Eigen::Matrix3Xf& points, const Eigen::Vector3f& viewpoint, Eigen::Vector4f& plane)
{
  if (points.cols() < 3)
    return false;
  const Eigen::Vector3f mean = points.rowwise().mean();
  const Eigen::Matrix3Xf centred = points.colwise() - mean;
  const Eigen::Matrix3f cov = centred * centred.transpose() / static_cast<float>(points.cols());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3f> eig(cov);
  const Eigen::Vector3f values = eig.eigenvalues();
  if (!(values[1] > 1e-12f) || !(values[1] > 4.f * values[0]))
    return false;
  const Eigen::Vector3f n = eig.eigenvectors().col(0);
  plane = orientPlane(Eigen::Vector4f(n.x(), n.y(), n.z(), -n.dot(mean)), viewpoint);
  return plane.allFinite();
}

Eigen::Affine3f
planeFrame(const Eigen::Vector4f& plane, const Eigen::Vector3f& origin_hint)
{
  const Eigen::Vector3f z = plane.head<3>().normalized();
  const Eigen::Vector3f origin = origin_hint - (z.dot(origin_hint) + plane[3]) * z;
  Eigen::Vector3f x = Eigen::Vector3f::UnitX() - z.x() * z;
  if (x.norm() < 0.3f)
    x = Eigen::Vector3f::UnitY() - z.y() * z;
  x.normalize();
  Eigen::Affine3f frame = Eigen::Affine3f::Identity();
  frame.linear().col(0) = x;
  frame.linear().col(1) = z.cross(x);
  frame.linear().col(2) = z;
  frame.translation() = origin;
  return frame;
}

bool
pointInPolygon(const Eigen::Vector2f& p, const std::vector<Eigen::Vector2f>& polygon)
{
  bool inside = false;
  const std::size_t n = polygon.size();
  for (std::size_t i = 0, j = n - 1; i < n; j = i++) {
    const Eigen::Vector2f& a = polygon[i];
    const Eigen::Vector2f& b = polygon[j];
    if ((a.y() > p.y()) != (b.y() > p.y()) &&
        p.x() < (b.x() - a.x()) * (p.y() - a.y()) / (b.y() - a.y()) + a.x())
      inside = !inside;
  }
  return inside;
}

Eigen::AlignedBox2f
polygonReach(const std::vector<Eigen::Vector2f>& polygon, float distance)
{
  Eigen::AlignedBox2f box;
  for (const auto& v : polygon)
    box.extend(v);
  if (!box.isEmpty()) {
    box.min().array() -= distance + 1e-3f;
    box.max().array() += distance + 1e-3f;
  }
  return box;
}

std::size_t
pointsInPolygon(const Eigen::Matrix3Xf& pts, const Eigen::Affine3f& to_plane,
                const std::vector<Eigen::Vector2f>& polygon)
{
  if (polygon.empty())
    return 0;
  // Outside the polygon's reach the even-odd test is false: no edge straddles the point's
  // row, or each that does lies on one side.
  const Eigen::AlignedBox2f box = polygonReach(polygon, 0.f);
  std::size_t in = 0;
  for (Eigen::Index k = 0; k < pts.cols(); ++k) {
    const Eigen::Vector2f p = (to_plane * Eigen::Vector3f(pts.col(k))).head<2>();
    in += box.contains(p) && pointInPolygon(p, polygon);
  }
  return in;
}

PixelBox
pixelBox(const pcl::Indices& indices, std::uint32_t width)
{
  if (indices.empty() || width == 0)
    return {-1, -1, -1, -1};
  PixelBox box{std::numeric_limits<int>::max(), std::numeric_limits<int>::max(), -1, -1};
  for (const auto i : indices) {
    const int u = static_cast<int>(static_cast<std::uint32_t>(i) % width);
    const int v = static_cast<int>(static_cast<std::uint32_t>(i) / width);
    box[0] = std::min(box[0], u);
    box[1] = std::min(box[1], v);
    box[2] = std::max(box[2], u);
    box[3] = std::max(box[3], v);
  }
  return box;
}

pcl::Indices
rowExtremes(const pcl::Indices& indices, std::uint32_t width, std::uint32_t height)
{
  const auto size = static_cast<pcl::index_t>(static_cast<std::size_t>(width) * height);
  std::vector<pcl::index_t> first(height, -1), last(height, -1);
  for (const auto i : indices) {
    if (i < 0 || i >= size)
      continue;
    const auto row = static_cast<std::size_t>(i) / width;
    if (first[row] < 0 || i < first[row])
      first[row] = i;
    if (i > last[row])
      last[row] = i;
  }
  pcl::Indices out;
  for (std::size_t row = 0; row < height; ++row)
    if (first[row] >= 0) {
      out.push_back(first[row]);
      if (last[row] != first[row])
        out.push_back(last[row]);
    }
  return out;
}

PixelBox
projectedBox(const Eigen::Matrix3Xf& points, const PinholeCamera& camera)
{
  PixelBox box{std::numeric_limits<int>::max(), std::numeric_limits<int>::max(), -1, -1};
  if (!camera.valid())
    return {-1, -1, -1, -1};
  bool any = false;
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    const Eigen::Vector3f p = points.col(i);
    if (!(p.z() > 0.f) || !p.allFinite())
      continue;
    const Eigen::Vector2f px = camera.project(p);
    const int u = static_cast<int>(std::lround(px.x())), v = static_cast<int>(std::lround(px.y()));
    if (u < 0 || v < 0 || u >= camera.width || v >= camera.height)
      continue;
    any = true;
    box[0] = std::min(box[0], u);
    box[1] = std::min(box[1], v);
    box[2] = std::max(box[2], u);
    box[3] = std::max(box[3], v);
  }
  return any ? box : PixelBox{-1, -1, -1, -1};
}

bool
estimatePinhole(const Eigen::Matrix3Xf& points, const Eigen::Matrix2Xf& pixels, int width,
                int height, PinholeCamera& camera)
{
  if (points.cols() != pixels.cols() || width <= 0 || height <= 0)
    return false;
  // Normal equations of u = fx a + cx (a = x/z) and v = fy b + cy (b = y/z).
  Eigen::Matrix2d au = Eigen::Matrix2d::Zero(), av = Eigen::Matrix2d::Zero();
  Eigen::Vector2d bu = Eigen::Vector2d::Zero(), bv = Eigen::Vector2d::Zero();
  std::size_t n = 0;
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    const Eigen::Vector3f p = points.col(i);
    if (!p.allFinite() || !(p.z() > 0.f))
      continue;
    const double a = p.x() / p.z(), b = p.y() / p.z();
    au += Eigen::Matrix2d{{a * a, a}, {a, 1.0}};
    av += Eigen::Matrix2d{{b * b, b}, {b, 1.0}};
    bu += Eigen::Vector2d(a * pixels(0, i), pixels(0, i));
    bv += Eigen::Vector2d(b * pixels(1, i), pixels(1, i));
    ++n;
  }
  if (n < 10 || std::abs(au.determinant()) < 1e-12 || std::abs(av.determinant()) < 1e-12)
    return false;
  const Eigen::Vector2d su = au.ldlt().solve(bu), sv = av.ldlt().solve(bv);
  camera.fx = static_cast<float>(su[0]);
  camera.cx = static_cast<float>(su[1]);
  camera.fy = static_cast<float>(sv[0]);
  camera.cy = static_cast<float>(sv[1]);
  camera.width = width;
  camera.height = height;
  return camera.valid() && std::isfinite(camera.cx) && std::isfinite(camera.cy);
}

Eigen::Affine3f
sensorPose(const Eigen::Vector4f& origin, const Eigen::Quaternionf& orientation)
{
  Eigen::Affine3f pose = Eigen::Affine3f::Identity();
  const float norm = orientation.norm();
  if (std::isfinite(norm) && norm > 1e-6f)
    pose.linear() = orientation.normalized().toRotationMatrix();
  if (origin.head<3>().allFinite())
    pose.translation() = origin.head<3>();
  return pose;
}

Eigen::Affine3f
plausibleSensorPose(const Eigen::Matrix3Xf& sample, const Eigen::Vector4f& origin,
                    const Eigen::Quaternionf& orientation)
{
  const Eigen::Affine3f stored = sensorPose(origin, orientation);
  Eigen::Affine3f unrotated = Eigen::Affine3f::Identity();
  unrotated.translation() = stored.translation();
  if (stored.linear().isApprox(Eigen::Matrix3f::Identity(), 1e-6f))
    return stored;
  const Eigen::Affine3f to_stored = stored.inverse(), to_unrotated = unrotated.inverse();
  std::size_t ahead_stored = 0, ahead_unrotated = 0;
  for (Eigen::Index i = 0; i < sample.cols(); ++i) {
    const Eigen::Vector3f p = sample.col(i);
    if (!p.allFinite())
      continue;
    ahead_stored += (to_stored * p).z() > 0.f;
    ahead_unrotated += (to_unrotated * p).z() > 0.f;
  }
  return ahead_stored >= ahead_unrotated ? stored : unrotated;
}

bool
isIdentityPose(const Eigen::Affine3f& pose)
{
  return pose.matrix().isApprox(Eigen::Matrix4f::Identity(), 1e-6f) ||
         (pose.matrix() - Eigen::Matrix4f::Identity()).cwiseAbs().maxCoeff() < 1e-6f;
}

Eigen::Vector4f
transformPlane(const Eigen::Vector4f& plane, const Eigen::Affine3f& t)
{
  const Eigen::Vector3f n = t.linear() * plane.head<3>();
  const Eigen::Vector3f on_plane = -plane[3] * plane.head<3>() / plane.head<3>().squaredNorm();
  return Eigen::Vector4f(n.x(), n.y(), n.z(), -n.dot(t * on_plane));
}

} // namespace facyl
