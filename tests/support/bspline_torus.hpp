// Meshes whose Catmull-Clark limit surface is known in closed form (every vertex of valence 4:
// each face is one uniform bicubic B-spline patch), for the subdivision and limit-bake tests.
#pragma once

#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include "sgbake/core/math.hpp"
#include "sgbake/mesh/mesh.hpp"
#include "sgbake/mesh/normals.hpp"

namespace sgbake::test {

/// A mesh from faces of vertex indices; UVs are each corner's position x, y.
inline Mesh meshOf(std::vector<Vec3f> positions, const std::vector<std::vector<std::uint32_t>>& faces) {
  Mesh mesh;
  mesh.source = "test.obj";
  mesh.positions = std::move(positions);
  UvSet uv{"UVMap", {}};
  for (const auto& face : faces) {
    for (const std::uint32_t v : face) {
      mesh.cornerVertex.push_back(v);
      uv.uvs.push_back({mesh.positions[v].x, mesh.positions[v].y});
    }
    mesh.faceStart.push_back(static_cast<std::uint32_t>(mesh.cornerVertex.size()));
  }
  mesh.uvSets.push_back(std::move(uv));
  mesh.cornerNormals.resize(mesh.cornerVertex.size());
  computeSmoothNormals(mesh);
  return mesh;
}

/// A closed torus of nu × nv quads with every vertex of valence 4 (one regular B-spline patch
/// per face), its vertices displaced by a bumpy function so no symmetry hides an error.
inline Mesh torusGrid(int nu, int nv) {
  std::vector<Vec3f> positions;
  for (int j = 0; j < nv; ++j) {
    for (int i = 0; i < nu; ++i) {
      const double a = 2 * kPi * i / nu, b = 2 * kPi * j / nv;
      const double r = 0.35 + 0.05 * std::sin(3 * a + b);
      positions.push_back({static_cast<float>((1 + r * std::cos(b)) * std::cos(a)),
                           static_cast<float>((1 + r * std::cos(b)) * std::sin(a)),
                           static_cast<float>(r * std::sin(b))});
    }
  }
  const auto index = [&](int i, int j) {
    return static_cast<std::uint32_t>(((j + nv) % nv) * nu + (i + nu) % nu);
  };
  std::vector<std::vector<std::uint32_t>> faces;
  for (int j = 0; j < nv; ++j) {
    for (int i = 0; i < nu; ++i) {
      faces.push_back({index(i, j), index(i + 1, j), index(i + 1, j + 1), index(i, j + 1)});
    }
  }
  return meshOf(std::move(positions), faces);
}

/// The torus grid of torusGrid with UVs (i/nu, j/nv) per corner: a seam where the grid wraps.
inline Mesh torusGridWithUvs(int nu, int nv) {
  Mesh mesh = torusGrid(nu, nv);
  for (std::size_t f = 0; f < mesh.numFaces(); ++f) {
    const double i = static_cast<double>(f % static_cast<std::size_t>(nu));
    const double j = static_cast<double>(f / static_cast<std::size_t>(nu));
    const double di[4] = {0, 1, 1, 0}, dj[4] = {0, 0, 1, 1};
    for (std::size_t k = 0; k < 4; ++k) {
      mesh.uvSets[0].uvs[4 * f + k] = {static_cast<float>((i + di[k]) / nu),
                                       static_cast<float>((j + dj[k]) / nv)};
    }
  }
  return mesh;
}

/// The uniform cubic B-spline basis at t and its derivative.
inline void bspline(double t, double w[4], double d[4]) {
  const double u = 1 - t;
  w[0] = u * u * u / 6;
  w[1] = (3 * t * t * t - 6 * t * t + 4) / 6;
  w[2] = (-3 * t * t * t + 3 * t * t + 3 * t + 1) / 6;
  w[3] = t * t * t / 6;
  d[0] = -u * u / 2;
  d[1] = (9 * t * t - 12 * t) / 6;
  d[2] = (-9 * t * t + 6 * t + 3) / 6;
  d[3] = t * t / 2;
}

/// The limit surface of torusGrid(nu, nv) on face (i, j) at (s, t): position and derivatives.
inline void torusGridLimit(const Mesh& grid, int nu, int nv, int i, int j, double s, double t,
                           Vec3d& P, Vec3d& Ps, Vec3d& Pt) {
  double ws[4], ds[4], wt[4], dt[4];
  bspline(s, ws, ds);
  bspline(t, wt, dt);
  P = Ps = Pt = Vec3d{0, 0, 0};
  for (int b = 0; b < 4; ++b) {
    for (int a = 0; a < 4; ++a) {
      const int ci = (i - 1 + a + nu) % nu, cj = (j - 1 + b + nv) % nv;
      const Vec3d c = cast<double>(grid.positions[static_cast<std::size_t>(cj * nu + ci)]);
      P = P + (ws[a] * wt[b]) * c;
      Ps = Ps + (ds[a] * wt[b]) * c;
      Pt = Pt + (ws[a] * dt[b]) * c;
    }
  }
}

}  // namespace sgbake::test
