/*
 * facyl: drawing on an RGB image, for facyl_detect's overlays: lines, and a cylinder's outline
 * as a pinhole camera sees it.
 */
#pragma once

#include <facyl/sample_consensus_alt/cylinder_fitting.h>
#include <facyl/segmentation/tabletop_geometry.h>

#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

namespace facyl_cli {

/** An RGB image (8 bits a channel, rows top down) to draw on; what falls outside is clipped. */
struct Canvas {
  int width{0}, height{0};
  std::vector<unsigned char> rgb;
  /** Pixel (\a u, \a v) in colour \a c. */
  void put(int u, int v, const std::array<unsigned char, 3>& c)
  {
    if (u < 0 || v < 0 || u >= width || v >= height)
      return;
    std::copy(c.begin(), c.end(), rgb.begin() + 3 * (static_cast<std::size_t>(v) * width + u));
  }
  /** The segment from \a a to \a b (pixels), \a thick pixels wide (right and down); nothing
   * when an end is not finite or the segment is far longer than the image (a point behind the
   * camera). */
  void line(Eigen::Vector2f a, Eigen::Vector2f b, const std::array<unsigned char, 3>& c,
            int thick = 1)
  {
    if (!a.allFinite() || !b.allFinite() || (a - b).norm() > 4.f * (width + height))
      return;
    const int steps = std::max(1, static_cast<int>(std::ceil((b - a).lpNorm<Eigen::Infinity>())));
    for (int s = 0; s <= steps; ++s) {
      const Eigen::Vector2f p = a + (b - a) * (static_cast<float>(s) / steps);
      for (int dv = 0; dv < thick; ++dv)
        for (int du = 0; du < thick; ++du)
          put(static_cast<int>(std::lround(p.x())) + du, static_cast<int>(std::lround(p.y())) + dv,
              c);
    }
  }
};

/** The outline of the finite cylinder \a m as camera \a cam sees it: its base and top circles
 * and its two silhouette generators (2 pixels wide); parts behind the camera are left out. */
inline void
drawCylinderOutline(Canvas& canvas, const facyl::PinholeCamera& cam, const facyl::CylinderModel& m,
                    const std::array<unsigned char, 3>& colour)
{
  const Eigen::Vector3f a = m.axis.normalized();
  Eigen::Vector3f e1 = a.unitOrthogonal(), e2 = a.cross(e1);
  auto project = [&](const Eigen::Vector3f& p) {
    return p.z() > 0.f ? cam.project(p) : Eigen::Vector2f::Constant(NAN);
  };
  for (const Eigen::Vector3f& c : {m.base, m.top}) {
    Eigen::Vector2f prev;
    for (int k = 0; k <= 48; ++k) {
      const float t = 2.f * static_cast<float>(M_PI) * k / 48.f;
      const Eigen::Vector2f q = project(c + m.radius * (std::cos(t) * e1 + std::sin(t) * e2));
      if (k)
        canvas.line(prev, q, colour);
      prev = q;
    }
  }
  // Silhouette generators: perpendicular to both the axis and the line of sight.
  const Eigen::Vector3f centre = 0.5f * (m.base + m.top);
  Eigen::Vector3f side = a.cross(centre);
  if (side.norm() < 1e-6f)
    return;
  side = side.normalized() * m.radius;
  for (float s : {-1.f, 1.f})
    canvas.line(project(m.base + s * side), project(m.top + s * side), colour, 2);
}

} // namespace facyl_cli
