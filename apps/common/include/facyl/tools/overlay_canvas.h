/*
 * facyl: drawing on an RGB image, for facyl_detect's overlays: lines (solid or dashed), a
 * cylinder's outline as a pinhole camera sees it, and short labels ("#12": a track's id) in a
 * 5 x 7 pixel font.
 */
#pragma once

#include <facyl/sample_consensus_alt/cylinder_fitting.h>
#include <facyl/segmentation/tabletop_geometry.h>

#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
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
   * camera). \a dash > 0 draws it dashed: \a dash pixels drawn, \a dash left out, from
   * \a offset pixels into the pattern (the return value of the segment before, for a dashed
   * polyline). \return \a offset plus the segment's length. */
  float line(Eigen::Vector2f a, Eigen::Vector2f b, const std::array<unsigned char, 3>& c,
             int thick = 1, int dash = 0, float offset = 0.f)
  {
    if (!a.allFinite() || !b.allFinite() || (a - b).norm() > 4.f * (width + height))
      return offset;
    const int steps = std::max(1, static_cast<int>(std::ceil((b - a).lpNorm<Eigen::Infinity>())));
    const float length = (b - a).norm();
    for (int s = 0; s <= steps; ++s) {
      const float t = static_cast<float>(s) / steps;
      if (dash > 0 && std::fmod(offset + t * length, 2.f * dash) >= dash)
        continue;
      const Eigen::Vector2f p = a + (b - a) * t;
      for (int dv = 0; dv < thick; ++dv)
        for (int du = 0; du < thick; ++du)
          put(static_cast<int>(std::lround(p.x())) + du, static_cast<int>(std::lround(p.y())) + dv,
              c);
    }
    return offset + length;
  }
};

/** The outline of the finite cylinder \a m as camera \a cam sees it: its base and top circles
 * and its two silhouette generators (2 pixels wide); parts behind the camera are left out.
 * \a dash > 0: dashed (Canvas::line). */
inline void
drawCylinderOutline(Canvas& canvas, const facyl::PinholeCamera& cam, const facyl::CylinderModel& m,
                    const std::array<unsigned char, 3>& colour, int dash = 0)
{
  const Eigen::Vector3f a = m.axis.normalized();
  Eigen::Vector3f e1 = a.unitOrthogonal(), e2 = a.cross(e1);
  auto project = [&](const Eigen::Vector3f& p) {
    return p.z() > 0.f ? cam.project(p) : Eigen::Vector2f::Constant(NAN);
  };
  for (const Eigen::Vector3f& c : {m.base, m.top}) {
    Eigen::Vector2f prev;
    float travelled = 0.f;
    for (int k = 0; k <= 48; ++k) {
      const float t = 2.f * static_cast<float>(M_PI) * k / 48.f;
      const Eigen::Vector2f q = project(c + m.radius * (std::cos(t) * e1 + std::sin(t) * e2));
      if (k)
        travelled = canvas.line(prev, q, colour, 1, dash, travelled);
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
    canvas.line(project(m.base + s * side), project(m.top + s * side), colour, 2, dash);
}

/** The rows of the 5 x 7 glyph of \a c (bit 4 the left column) for '#' and the digits; empty
 * (a gap) for any other character. */
inline std::array<std::uint8_t, 7>
labelGlyph(char c)
{
  static constexpr std::array<std::array<std::uint8_t, 7>, 10> kDigits{{
    {0x0e, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0e}, // 0
    {0x04, 0x0c, 0x04, 0x04, 0x04, 0x04, 0x0e}, // 1
    {0x0e, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1f}, // 2
    {0x1f, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0e}, // 3
    {0x02, 0x06, 0x0a, 0x12, 0x1f, 0x02, 0x02}, // 4
    {0x1f, 0x10, 0x1e, 0x01, 0x01, 0x11, 0x0e}, // 5
    {0x06, 0x08, 0x10, 0x1e, 0x11, 0x11, 0x0e}, // 6
    {0x1f, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08}, // 7
    {0x0e, 0x11, 0x11, 0x0e, 0x11, 0x11, 0x0e}, // 8
    {0x0e, 0x11, 0x11, 0x0f, 0x01, 0x02, 0x0c}, // 9
  }};
  if (c >= '0' && c <= '9')
    return kDigits[static_cast<std::size_t>(c - '0')];
  if (c == '#')
    return {0x0a, 0x0a, 0x1f, 0x0a, 0x1f, 0x0a, 0x0a};
  return {};
}

/** The size in pixels of \a text as drawLabel draws it at \a scale: 6 scale a character
 * (a glyph and the gap after it) and a border of scale around; 7 scale high plus the border. */
inline Eigen::Vector2i
labelSize(const std::string& text, int scale)
{
  return {(6 * static_cast<int>(text.size()) + 1) * scale, 9 * scale};
}

/** \a text (labelGlyph's characters) in \a colour on a black box of labelSize whose top-left
 * corner is (\a u, \a v); each font pixel \a scale x \a scale image pixels. */
inline void
drawLabel(Canvas& canvas, int u, int v, const std::string& text,
          const std::array<unsigned char, 3>& colour, int scale)
{
  const Eigen::Vector2i size = labelSize(text, scale);
  for (int y = 0; y < size.y(); ++y)
    for (int x = 0; x < size.x(); ++x)
      canvas.put(u + x, v + y, {0, 0, 0});
  for (std::size_t k = 0; k < text.size(); ++k) {
    const auto glyph = labelGlyph(text[k]);
    const int left = u + (6 * static_cast<int>(k) + 1) * scale, top = v + scale;
    for (int row = 0; row < 7; ++row)
      for (int col = 0; col < 5; ++col)
        if (glyph[static_cast<std::size_t>(row)] & (0x10 >> col))
          for (int dy = 0; dy < scale; ++dy)
            for (int dx = 0; dx < scale; ++dx)
              canvas.put(left + col * scale + dx, top + row * scale + dy, colour);
  }
}

} // namespace facyl_cli
