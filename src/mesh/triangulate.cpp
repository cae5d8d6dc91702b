#include "sgbake/mesh/triangulate.hpp"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <limits>

namespace sgbake {
namespace {

// Every quantity that decides a triangle is computed in float, in the order Blender computes it:
// the decisions on near-ties (nearly straight corners, corners on a triangle's edge) are then
// Blender's. The build does not contract float products into FMAs (-ffp-contract=off), as
// Blender's x86-64 build cannot.

struct P2 {
  float x, y;
};

/// The turn at @p b of a → b → c in the projected plane, where the polygon winds clockwise:
/// +1 convex, 0 straight, -1 reflex. Twice the signed area of (c, b, a), taken from c.
int turnSign(P2 a, P2 b, P2 c) {
  const float d2x = b.x - c.x, d2y = b.y - c.y;
  const float d3x = a.x - c.x, d3y = a.y - c.y;
  const float area = d2x * d3y - d3x * d2y;
  return area == 0.0f ? 0 : (area > 0.0f ? 1 : -1);
}

/// The polygon in the plane perpendicular to its Newell normal n, seen from −n (so that it winds
/// clockwise): the Newell sum from the edge (k−1, 0) on, normalized (z = 1 when it vanishes);
/// then an orthonormal (x, y) pair of that plane built from n's x and y components.
std::vector<P2> projectPolygon(std::span<const Vec3f> points) {
  const std::size_t k = points.size();
  float n[3] = {0.0f, 0.0f, 0.0f};
  const Vec3f* before = &points[k - 1];
  for (const Vec3f& at : points) {
    n[0] += (before->y - at.y) * (before->z + at.z);
    n[1] += (before->z - at.z) * (before->x + at.x);
    n[2] += (before->x - at.x) * (before->y + at.y);
    before = &at;
  }
  const float length2 = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
  if (length2 > 1.0e-35f) {
    const float scale = 1.0f / std::sqrt(length2);
    for (float& c : n) c *= scale;
  } else {
    n[0] = n[1] = 0.0f;
    n[2] = 1.0f;
  }
  const float m[3] = {-n[0], -n[1], -n[2]};  // looking down the normal
  float ax[3], ay[3];
  const float across2 = m[0] * m[0] + m[1] * m[1];
  if (across2 > FLT_EPSILON) {
    const float d = 1.0f / std::sqrt(across2);
    ax[0] = m[1] * d;
    ax[1] = -m[0] * d;
    ax[2] = 0.0f;
    ay[0] = -m[2] * ax[1];
    ay[1] = m[2] * ax[0];
    ay[2] = m[0] * ax[1] - m[1] * ax[0];
  } else {  // the normal along z
    ax[0] = m[2] < 0.0f ? -1.0f : 1.0f;
    ax[1] = ax[2] = ay[0] = ay[2] = 0.0f;
    ay[1] = 1.0f;
  }
  std::vector<P2> p(k);
  for (std::size_t i = 0; i < k; ++i) {
    const Vec3f& q = points[i];
    p[i] = {ax[0] * q.x + ax[1] * q.y + ax[2] * q.z, ay[0] * q.x + ay[1] * q.y + ay[2] * q.z};
  }
  return p;
}

/// The corners of the ring that are not convex, in a uniform grid over the polygon's bounds, to
/// find those inside a candidate ear without walking the whole ring. Corners leave it (they
/// become convex, or are clipped) and never come back.
class NonConvexCorners {
 public:
  NonConvexCorners(const std::vector<P2>& p, const std::vector<int>& sign) : p_(p) {
    std::size_t count = 0;
    for (const int s : sign) count += s != 1;
    count_ = count;
    in_.assign(p.size(), false);
    if (count == 0) return;
    min_ = max_ = p[0];
    for (const P2& q : p) {
      min_ = {std::min(min_.x, q.x), std::min(min_.y, q.y)};
      max_ = {std::max(max_.x, q.x), std::max(max_.y, q.y)};
    }
    // About two corners per cell.
    side_ = std::clamp<int>(static_cast<int>(std::sqrt(static_cast<double>(count) / 2)), 1, 1024);
    cells_.assign(static_cast<std::size_t>(side_) * static_cast<std::size_t>(side_), {});
    for (std::uint32_t i = 0; i < p.size(); ++i) {
      if (sign[i] == 1) continue;
      in_[i] = true;
      cells_[cellOf(cellX(p[i].x), cellY(p[i].y))].push_back(i);
    }
  }

  bool empty() const { return count_ == 0; }
  void remove(std::uint32_t i) {
    if (!in_[i]) return;
    in_[i] = false;
    --count_;
  }

  /// Whether a corner of the set other than @p a, @p b, @p c lies in the bounds of the triangle
  /// (a, b, c) and on no reflex side of its edges (inside it or on its boundary).
  bool anyInside(std::uint32_t a, std::uint32_t b, std::uint32_t c) const {
    if (count_ == 0) return false;
    const P2 pa = p_[a], pb = p_[b], pc = p_[c];
    const P2 lo{std::min({pa.x, pb.x, pc.x}), std::min({pa.y, pb.y, pc.y})};
    const P2 hi{std::max({pa.x, pb.x, pc.x}), std::max({pa.y, pb.y, pc.y})};
    const int x0 = cellX(lo.x), x1 = cellX(hi.x), y0 = cellY(lo.y), y1 = cellY(hi.y);
    for (int y = y0; y <= y1; ++y) {
      for (int x = x0; x <= x1; ++x) {
        for (const std::uint32_t j : cells_[cellOf(x, y)]) {
          if (!in_[j]) continue;
          const P2 q = p_[j];
          if (q.x < lo.x || q.x > hi.x || q.y < lo.y || q.y > hi.y) continue;
          if (turnSign(pa, pb, q) == -1 || turnSign(pb, pc, q) == -1 || turnSign(pc, pa, q) == -1)
            continue;
          if (j != a && j != b && j != c) return true;
        }
      }
    }
    return false;
  }

 private:
  int cell(float v, float lo, float hi) const {
    if (!(hi > lo)) return 0;
    const double t = side_ * ((static_cast<double>(v) - lo) / (static_cast<double>(hi) - lo));
    if (!(t > 0)) return 0;  // (NaN too)
    return t < side_ - 1 ? static_cast<int>(t) : side_ - 1;
  }
  int cellX(float x) const { return cell(x, min_.x, max_.x); }
  int cellY(float y) const { return cell(y, min_.y, max_.y); }
  std::size_t cellOf(int x, int y) const {
    return static_cast<std::size_t>(y) * static_cast<std::size_t>(side_) +
           static_cast<std::size_t>(x);
  }

  const std::vector<P2>& p_;
  std::size_t count_ = 0;
  std::vector<bool> in_;
  P2 min_{0, 0}, max_{0, 0};
  int side_ = 1;
  std::vector<std::vector<std::uint32_t>> cells_;
};

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
  const std::vector<P2> p = projectPolygon(points);

  // The remaining polygon as a ring in corner order, each corner with its cached turn sign.
  std::vector<std::uint32_t> next(k), prev(k);
  for (std::size_t i = 0; i < k; ++i) {
    next[i] = static_cast<std::uint32_t>((i + 1) % k);
    prev[i] = static_cast<std::uint32_t>((i + k - 1) % k);
  }
  auto signAt = [&](std::uint32_t i) { return turnSign(p[prev[i]], p[i], p[next[i]]); };
  std::vector<int> sign(k);
  for (std::uint32_t i = 0; i < k; ++i) sign[i] = signAt(i);
  NonConvexCorners nonConvex(p, sign);

  // An ear: a corner that is not reflex, whose triangle (corner, next, prev) holds no other
  // non-convex corner of the ring inside or on its boundary (within its bounds).
  auto isEar = [&](std::uint32_t i) {
    if (nonConvex.empty()) return true;  // every corner convex
    if (sign[i] == -1) return false;
    return !nonConvex.anyInside(i, next[i], prev[i]);
  };

  std::size_t remaining = k;
  std::uint32_t start = 0;
  bool backward = false;
  while (remaining > 3) {
    // The first ear from `start` in the current direction; without one, the first corner that
    // is not reflex from `start` going forward, else `start`.
    std::uint32_t ear = start;
    bool found = false;
    std::uint32_t i = start;
    for (std::size_t n = 0; n < remaining; ++n, i = backward ? prev[i] : next[i]) {
      if (isEar(i)) {
        ear = i;
        found = true;
        break;
      }
    }
    if (!found) {
      i = start;
      for (std::size_t n = 0; n < remaining; ++n, i = next[i]) {
        if (sign[i] != -1) {
          ear = i;
          break;
        }
      }
    }

    const std::uint32_t a = prev[ear], c = next[ear];
    triangles.push_back({a, ear, c});
    next[a] = c;
    prev[c] = a;
    nonConvex.remove(ear);
    --remaining;
    // Clipping an ear only makes its neighbours more convex: convex ones keep their sign.
    for (const std::uint32_t j : {a, c}) {
      if (sign[j] == 1) continue;
      sign[j] = signAt(j);
      if (sign[j] == 1) nonConvex.remove(j);
    }

    // Continue two corners on, past the clipped ear's neighbour; if that corner is not convex,
    // step once more and reverse the walking direction.
    start = backward ? prev[a] : next[c];
    if (sign[start] != 1) {
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
