#include "sgbake/mesh/triangulate.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace sgbake {
namespace {

struct P2 {
  double x, y;
};

/// Twice the signed area of (a, b, c): > 0 when a → b → c turns left.
double orient2(P2 a, P2 b, P2 c) { return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x); }

int signOf(double v) { return v > 0 ? 1 : (v < 0 ? -1 : 0); }

/// Whether @p q lies inside or on the boundary of the counter-clockwise (or degenerate)
/// triangle (a, b, c).
bool insideOrOn(P2 q, P2 a, P2 b, P2 c) {
  return orient2(a, b, q) >= 0 && orient2(b, c, q) >= 0 && orient2(c, a, q) >= 0;
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

  // Newell normal; the polygon is projected orthographically onto the plane perpendicular to it
  // (a rotation, not a drop of the dominant axis), where it winds counter-clockwise.
  Vec3d normal{};
  for (std::size_t i = 0; i < k; ++i) {
    const Vec3d a = cast<double>(points[i]), b = cast<double>(points[(i + 1) % k]);
    normal += Vec3d{(a.y - b.y) * (a.z + b.z), (a.z - b.z) * (a.x + b.x), (a.x - b.x) * (a.y + b.y)};
  }
  const double len = std::sqrt(dot(normal, normal));
  normal = len > 0 ? normal * (1.0 / len) : Vec3d{0, 0, 1};
  // Any unit vector perpendicular to the normal, then the third axis completing a right-handed
  // frame (u, v, normal): orientation tests in (u, v) equal those seen looking down the normal.
  const Vec3d helper = std::abs(normal.x) < 0.9 ? Vec3d{1, 0, 0} : Vec3d{0, 1, 0};
  Vec3d u = cross(helper, normal);
  u = u * (1.0 / std::sqrt(dot(u, u)));
  const Vec3d v = cross(normal, u);
  std::vector<P2> p(k);
  double area = 0;
  for (std::size_t i = 0; i < k; ++i) {
    const Vec3d q = cast<double>(points[i]);
    p[i] = {dot(q, u), dot(q, v)};
  }
  for (std::size_t i = 0; i < k; ++i) area += p[i].x * p[(i + 1) % k].y - p[(i + 1) % k].x * p[i].y;
  if (area < 0)  // only when the normal is degenerate; keep the polygon counter-clockwise
    for (P2& q : p) q.x = -q.x;

  // The remaining polygon as a ring, with each corner's cached turn sign (+1 convex,
  // 0 straight, -1 reflex).
  std::vector<std::uint32_t> next(k), prev(k);
  for (std::size_t i = 0; i < k; ++i) {
    next[i] = static_cast<std::uint32_t>((i + 1) % k);
    prev[i] = static_cast<std::uint32_t>((i + k - 1) % k);
  }
  auto turnSign = [&](std::uint32_t i) { return signOf(orient2(p[prev[i]], p[i], p[next[i]])); };
  std::vector<int> sign(k);
  for (std::uint32_t i = 0; i < k; ++i) sign[i] = turnSign(i);

  // A corner is an ear when it is not reflex and no non-convex corner of the ring lies inside or
  // on its triangle.
  auto isEar = [&](std::uint32_t i) {
    if (sign[i] < 0) return false;
    const std::uint32_t a = prev[i], c = next[i];
    for (std::uint32_t j = next[c]; j != a; j = next[j]) {
      if (sign[j] > 0) continue;
      if (insideOrOn(p[j], p[a], p[i], p[c])) return false;
    }
    return true;
  };

  std::size_t remaining = k;
  std::uint32_t start = 0;
  bool backward = false;
  while (remaining > 3) {
    // First ear from `start`, walking the ring in the current direction; without one, the first
    // convex corner, else the first straight one, else `start`.
    std::uint32_t ear = start, convex = UINT32_MAX, straight = UINT32_MAX;
    bool found = false;
    std::uint32_t i = start;
    for (std::size_t n = 0; n < remaining; ++n, i = backward ? prev[i] : next[i]) {
      if (isEar(i)) {
        ear = i;
        found = true;
        break;
      }
      if (sign[i] > 0 && convex == UINT32_MAX) convex = i;
      if (sign[i] == 0 && straight == UINT32_MAX) straight = i;
    }
    if (!found) ear = convex != UINT32_MAX ? convex : (straight != UINT32_MAX ? straight : start);

    const std::uint32_t a = prev[ear], c = next[ear];
    triangles.push_back({a, ear, c});
    next[a] = c;
    prev[c] = a;
    --remaining;
    // Clipping an ear only makes its neighbours more convex, so convex corners keep their sign.
    if (sign[a] <= 0) sign[a] = turnSign(a);
    if (sign[c] <= 0) sign[c] = turnSign(c);

    // Continue two corners on, past the clipped ear's neighbour; if that corner is not convex,
    // step once more and reverse the walking direction.
    start = backward ? prev[a] : next[c];
    if (sign[start] <= 0) {
      start = backward ? prev[start] : next[start];
      backward = !backward;
    }
  }
  // The last triangle, in ring order from its lowest corner.
  std::uint32_t first = start;
  for (std::uint32_t j = next[start]; j != start; j = next[j]) first = std::min(first, j);
  triangles.push_back({first, next[first], next[next[first]]});
}

}  // namespace sgbake
