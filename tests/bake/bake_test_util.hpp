// Helpers shared by the baker tests: hand-built meshes and analytic textures.
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include "sgbake/bake/bake.hpp"
#include "sgbake/core/math.hpp"
#include "sgbake/gradient/texture.hpp"
#include "sgbake/mesh/mesh.hpp"

namespace sgbake::test {

/// A mesh from positions, faces (vertex indices) and per-corner UVs (face after face); every
/// corner gets @p normal unless @p cornerNormals is given.
inline Mesh polygonMesh(const std::vector<Vec3f>& positions,
                        const std::vector<std::vector<std::uint32_t>>& faces,
                        const std::vector<Vec2f>& cornerUvs, Vec3f normal = {0, 0, 1},
                        const std::vector<Vec3f>& cornerNormals = {}) {
  Mesh mesh;
  mesh.source = "test";
  mesh.positions = positions;
  for (const auto& f : faces) {
    for (const std::uint32_t v : f) mesh.cornerVertex.push_back(v);
    mesh.faceStart.push_back(static_cast<std::uint32_t>(mesh.cornerVertex.size()));
  }
  mesh.cornerNormals = cornerNormals.empty()
                           ? std::vector<Vec3f>(mesh.cornerVertex.size(), normal)
                           : cornerNormals;
  mesh.uvSets.push_back({"UVMap", cornerUvs});
  return mesh;
}

/// A planar mesh z = 0 whose positions equal its UVs (one vertex per corner).
inline Mesh uvPlaneMesh(const std::vector<std::vector<Vec2f>>& faces) {
  std::vector<Vec3f> positions;
  std::vector<std::vector<std::uint32_t>> indices;
  std::vector<Vec2f> uvs;
  for (const auto& f : faces) {
    indices.emplace_back();
    for (const Vec2f uv : f) {
      indices.back().push_back(static_cast<std::uint32_t>(positions.size()));
      positions.push_back({uv.x, uv.y, 0});
      uvs.push_back(uv);
    }
  }
  return polygonMesh(positions, indices, uvs);
}

/// h(s, t) = a·s + b·t with its exact gradient (no wrapping).
class LinearHeight final : public ScalarTexture {
 public:
  LinearHeight(double a, double b) : a_(a), b_(b) {}
  ScalarSample sample(Vec2d st) const override { return {a_ * st.x + b_ * st.y, {a_, b_}}; }

 private:
  double a_, b_;
};

/// h(s, t) = A·sin(2πf s)·cos(2πf t) with its exact gradient.
class SineHeight final : public ScalarTexture {
 public:
  SineHeight(double amplitude, double frequency) : a_(amplitude), w_(2 * kPi * frequency) {}
  ScalarSample sample(Vec2d st) const override {
    const double ss = std::sin(w_ * st.x), cs = std::cos(w_ * st.x);
    const double st_ = std::sin(w_ * st.y), ct = std::cos(w_ * st.y);
    return {a_ * ss * ct, {a_ * w_ * cs * ct, -a_ * w_ * ss * st_}};
  }

 private:
  double a_, w_;
};

/// The same colour everywhere.
class ConstantColour final : public VectorTexture {
 public:
  explicit ConstantColour(Vec3d c) : c_(c) {}
  Vec3d sample(Vec2d) const override { return c_; }

 private:
  Vec3d c_;
};

/// Pixel (x, y) of @p image with y counted up from the bottom.
inline Vec3d pixelUp(const FloatImage& image, int x, int y) {
  const int row = image.height - 1 - y;
  Vec3d v{};
  for (int c = 0; c < std::min(image.channels, 3); ++c) v[static_cast<std::size_t>(c)] = image.at(x, row, c);
  return v;
}

inline float coverageUp(const FloatImage& image, int x, int y) {
  return image.coverage[static_cast<std::size_t>(image.height - 1 - y) * image.width + x];
}

}  // namespace sgbake::test
