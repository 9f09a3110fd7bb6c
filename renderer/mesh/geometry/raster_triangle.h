// Scan conversion of one 2-D triangle: every pixel centre inside it (edges included, so triangles
// sharing an edge leave no cracks) with its barycentric weights. Used by the mesh preview (screen
// space) and the tongue texture maps (UV space).
#pragma once
#include <algorithm>
#include <cmath>

#include <glm/vec2.hpp>

namespace ofl {

// Calls f(px, py, l0, l1, l2) for each pixel (px, py) of a width x height grid whose centre
// (px + 0.5, py + 0.5) lies in triangle (a, b, c); l0 + l1 + l2 = 1 are the weights of a, b, c.
// Degenerate triangles (|2 x area| <= min_area2) are skipped.
template <class F>
void raster_triangle(const glm::dvec2& a, const glm::dvec2& b, const glm::dvec2& c, int width, int height, F&& f,
                     double min_area2 = 1e-14) {
  const double area = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
  if (std::abs(area) <= min_area2) return;
  const int x0 = std::max(0, static_cast<int>(std::floor(std::min({a.x, b.x, c.x}))));
  const int x1 = std::min(width - 1, static_cast<int>(std::ceil(std::max({a.x, b.x, c.x}))));
  const int y0 = std::max(0, static_cast<int>(std::floor(std::min({a.y, b.y, c.y}))));
  const int y1 = std::min(height - 1, static_cast<int>(std::ceil(std::max({a.y, b.y, c.y}))));
  constexpr double kEdge = -1e-9;  // tolerance: a centre on a shared edge belongs to both triangles
  for (int py = y0; py <= y1; ++py)
    for (int px = x0; px <= x1; ++px) {
      const double qx = px + 0.5, qy = py + 0.5;
      const double l0 = ((b.x - qx) * (c.y - qy) - (b.y - qy) * (c.x - qx)) / area;
      const double l1 = ((c.x - qx) * (a.y - qy) - (c.y - qy) * (a.x - qx)) / area;
      const double l2 = 1 - l0 - l1;
      if (l0 < kEdge || l1 < kEdge || l2 < kEdge) continue;
      f(px, py, l0, l1, l2);
    }
}

}  // namespace ofl
