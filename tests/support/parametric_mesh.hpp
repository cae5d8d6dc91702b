// Meshes of analytic surfaces with exact normals and parametric UVs, built in memory, for tests
// whose reference is a closed-form frame.
#pragma once

#include <cmath>
#include <functional>

#include "sgbake/core/math.hpp"
#include "sgbake/mesh/mesh.hpp"

namespace sgbake::test {

/// Samples of a parametric surface: position, unit normal and derivatives at (s, t) in [0,1]².
struct SurfacePoint {
  Vec3d position, normal, dPds, dPdt;
};
using Surface = std::function<SurfacePoint(double s, double t)>;

/// An nu × nv grid of quads over [0,1]² (one vertex per grid point: seams along s = 0/1 keep
/// separate vertices with the same position), UV = (s, t) mapped through @p uvOf.
inline Mesh gridMesh(const Surface& surface, int nu, int nv,
                     const std::function<Vec2d(double, double)>& uvOf =
                         [](double s, double t) { return Vec2d{s, t}; }) {
  Mesh mesh;
  mesh.source = "grid";
  std::vector<Vec3f> vertexNormal;
  for (int j = 0; j <= nv; ++j) {
    for (int i = 0; i <= nu; ++i) {
      const SurfacePoint p = surface(double(i) / nu, double(j) / nv);
      mesh.positions.push_back(cast<float>(p.position));
      vertexNormal.push_back(cast<float>(p.normal));
    }
  }
  UvSet uv{"UVMap", {}};
  auto index = [&](int i, int j) { return std::uint32_t(j * (nu + 1) + i); };
  for (int j = 0; j < nv; ++j) {
    for (int i = 0; i < nu; ++i) {
      const int ci[4] = {i, i + 1, i + 1, i};
      const int cj[4] = {j, j, j + 1, j + 1};
      for (int k = 0; k < 4; ++k) {
        const std::uint32_t v = index(ci[k], cj[k]);
        mesh.cornerVertex.push_back(v);
        mesh.cornerNormals.push_back(vertexNormal[v]);
        uv.uvs.push_back(cast<float>(uvOf(double(ci[k]) / nu, double(cj[k]) / nv)));
      }
      mesh.faceStart.push_back(std::uint32_t(mesh.cornerVertex.size()));
    }
  }
  mesh.uvSets.push_back(std::move(uv));
  return mesh;
}

inline SurfacePoint plane(double s, double t) {
  return {{s, t, 0}, {0, 0, 1}, {1, 0, 0}, {0, 1, 0}};
}

/// Unit-radius cylinder around z, height 2: P = (cos 2πs, sin 2πs, 2t).
inline SurfacePoint cylinder(double s, double t) {
  const double a = 2 * kPi * s;
  return {{std::cos(a), std::sin(a), 2 * t},
          {std::cos(a), std::sin(a), 0},
          {-2 * kPi * std::sin(a), 2 * kPi * std::cos(a), 0},
          {0, 0, 2}};
}

/// Unit sphere, s = longitude, t = latitude from the south pole: P = (sin φ cos θ, sin φ sin θ,
/// -cos φ) with θ = 2πs, φ = πt.
inline SurfacePoint sphere(double s, double t) {
  const double th = 2 * kPi * s, ph = kPi * t;
  const Vec3d p{std::sin(ph) * std::cos(th), std::sin(ph) * std::sin(th), -std::cos(ph)};
  return {p, p,
          {-2 * kPi * std::sin(ph) * std::sin(th), 2 * kPi * std::sin(ph) * std::cos(th), 0},
          {kPi * std::cos(ph) * std::cos(th), kPi * std::cos(ph) * std::sin(th), kPi * std::sin(ph)}};
}

/// Torus around z with radii 1 and 0.3: s runs around the ring, t around the tube.
inline SurfacePoint torus(double s, double t) {
  const double a = 2 * kPi * s, b = 2 * kPi * t, r = 0.3;
  const Vec3d n{std::cos(b) * std::cos(a), std::cos(b) * std::sin(a), std::sin(b)};
  return {{(1 + r * std::cos(b)) * std::cos(a), (1 + r * std::cos(b)) * std::sin(a), r * std::sin(b)},
          n,
          {-2 * kPi * (1 + r * std::cos(b)) * std::sin(a), 2 * kPi * (1 + r * std::cos(b)) * std::cos(a), 0},
          {-2 * kPi * r * std::sin(b) * std::cos(a), -2 * kPi * r * std::sin(b) * std::sin(a),
           2 * kPi * r * std::cos(b)}};
}

/// Unit direction of @p v projected into the plane orthogonal to unit @p n.
inline Vec3d projectedDirection(Vec3d v, Vec3d n) {
  return normalizeOr(v - dot(v, n) * n, Vec3d{0, 0, 0});
}

/// Angle in degrees between two vectors.
inline double angleDegrees(Vec3d a, Vec3d b) { return angleBetween(a, b) * 180.0 / kPi; }

}  // namespace sgbake::test
