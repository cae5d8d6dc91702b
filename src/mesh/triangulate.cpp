#include "sgbake/mesh/triangulate.hpp"

#include <cmath>
#include <numeric>

namespace sgbake {
namespace {

struct P2 {
  double x, y;
};

double orient2(P2 a, P2 b, P2 c) { return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x); }

bool insideOrOn(P2 p, P2 a, P2 b, P2 c) {
  return orient2(a, b, p) >= 0 && orient2(b, c, p) >= 0 && orient2(c, a, p) >= 0;
}

}  // namespace

void triangulatePolygon(std::span<const Vec3f> points,
                        std::vector<std::array<std::uint32_t, 3>>& triangles) {
  triangles.clear();
  const std::size_t k = points.size();
  if (k < 3) return;
  if (k == 3) {
    triangles.push_back({0, 1, 2});
    return;
  }

  // Newell normal, then a 2D projection in which the polygon winds counter-clockwise.
  Vec3d normal{};
  for (std::size_t i = 0; i < k; ++i) {
    const Vec3d a = cast<double>(points[i]), b = cast<double>(points[(i + 1) % k]);
    normal += Vec3d{(a.y - b.y) * (a.z + b.z), (a.z - b.z) * (a.x + b.x), (a.x - b.x) * (a.y + b.y)};
  }
  int drop = 2;
  if (std::abs(normal.x) >= std::abs(normal.y) && std::abs(normal.x) >= std::abs(normal.z)) {
    drop = 0;
  } else if (std::abs(normal.y) >= std::abs(normal.z)) {
    drop = 1;
  }
  int ax = (drop + 1) % 3, ay = (drop + 2) % 3;
  if (normal[static_cast<std::size_t>(drop)] < 0) std::swap(ax, ay);
  std::vector<P2> p(k);
  for (std::size_t i = 0; i < k; ++i)
    p[i] = {points[i][static_cast<std::size_t>(ax)], points[i][static_cast<std::size_t>(ay)]};

  std::vector<std::uint32_t> ring(k);
  std::iota(ring.begin(), ring.end(), 0u);
  while (ring.size() > 3) {
    const std::size_t n = ring.size();
    std::size_t ear = n;       // first proper ear
    std::size_t mostConvex = 0;  // fallback when there is none
    double bestTurn = -INFINITY;
    for (std::size_t i = 0; i < n && ear == n; ++i) {
      const std::uint32_t a = ring[(i + n - 1) % n], b = ring[i], c = ring[(i + 1) % n];
      const double turn = orient2(p[a], p[b], p[c]);
      if (turn > bestTurn) {
        bestTurn = turn;
        mostConvex = i;
      }
      if (turn <= 0) continue;
      bool empty = true;
      for (std::size_t j = 0; j < n && empty; ++j) {
        const std::uint32_t q = ring[j];
        if (q == a || q == b || q == c) continue;
        empty = !insideOrOn(p[q], p[a], p[b], p[c]);
      }
      if (empty) ear = i;
    }
    const std::size_t i = ear != n ? ear : mostConvex;
    triangles.push_back({ring[(i + n - 1) % n], ring[i], ring[(i + 1) % n]});
    ring.erase(ring.begin() + static_cast<std::ptrdiff_t>(i));
  }
  triangles.push_back({ring[0], ring[1], ring[2]});
}

}  // namespace sgbake
