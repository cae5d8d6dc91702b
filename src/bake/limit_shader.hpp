/// @file limit_shader.hpp
/// @brief Private: shading from the exact limit surface ("subdivision": {"level": "limit"}).
///
/// The raster still walks a tessellation of the surface (subdivideMesh, with SurfaceParameters)
/// to find which texels a face covers and roughly where; for every sample the LimitShader then
/// finds the point of the limit surface whose UV is the sample's (LimitSurface::Evaluator::locate,
/// from the tessellation's interpolated surface parameters) and hands the wrapped shader a
/// triangle whose three corners all carry the limit surface's values there: position, normal
/// ∂P/∂s × ∂P/∂t, the UV sets and their exact ∂P/∂u, ∂P/∂v, and the tangent frame of UV set 0
/// (T = ∂P/∂u made orthogonal to N, sign from ∂P/∂v: what MikkTSpace approximates on meshes).
/// Whatever barycentrics the wrapped shader interpolates with, it gets those values.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <memory>

#include "bake/shaders.hpp"
#include "sgbake/subdiv/limit_surface.hpp"

namespace sgbake::bake_detail {

/// ∂P/∂u, ∂P/∂v of a UV map with Jacobian [a b] = [∂UV/∂s ∂UV/∂t] on a surface with
/// [∂P/∂s ∂P/∂t]: [∂P/∂u ∂P/∂v] = [∂P/∂s ∂P/∂t]·[a b]⁻¹; both 0 where the UV map folds or
/// collapses (kMinUvTriangleSine, as for triangles).
inline void limitUvDerivatives(const Vec3d& dPds, const Vec3d& dPdt, const Vec2d& a,
                               const Vec2d& b, Vec3d& dPdu, Vec3d& dPdv) {
  const double det = a.x * b.y - a.y * b.x;
  const double scale = std::sqrt(lengthSquared(a) * lengthSquared(b));
  if (!(std::abs(det) > kMinUvTriangleSine * scale) || !std::isfinite(det)) {
    dPdu = dPdv = Vec3d{0, 0, 0};
    return;
  }
  // [a b]⁻¹ = [[b.y, −b.x], [−a.y, a.x]] / det.
  dPdu = (b.y / det) * dPds + (-a.y / det) * dPdt;
  dPdv = (-b.x / det) * dPds + (a.x / det) * dPdt;
}

/// The tangent frame of UV set 0 on a limit surface (and of a tessellation triangle without
/// MikkTSpace frames): T = ∂P/∂u made orthogonal to the unit normal @p n (0 where ∂P/∂u is
/// along n or 0), the bitangent sign −1 where ∂P/∂v points against n × T.
inline void frameFromUvDerivatives(const Vec3d& n, const Vec3d& dPdu, const Vec3d& dPdv,
                                   Vec3d& tangent, double& sign) {
  tangent = normalizeOr(dPdu - dot(dPdu, n) * n, Vec3d{0, 0, 0});
  sign = dot(cross(n, tangent), dPdv) < 0 ? -1.0 : 1.0;
}

template <class Inner>
struct LimitShader {
  static constexpr int kChannels = Inner::kChannels;
  Inner inner;  ///< a bake shader (BakeShaderBase) whose mesh is the tessellation
  const LimitSurface* limit = nullptr;
  const SurfaceParameters* parameters = nullptr;
  std::array<std::uint32_t, 3> corners{};
  ShadingTriangle meshTriangle;  ///< the tessellation's triangle, as beginTriangle loaded it
  /// inner.tri holds a limit point (useLimitPoint), not meshTriangle.
  bool onLimit = false;
  /// Made on first use: every copy of the shader (one per row block) evaluates on its own.
  std::shared_ptr<LimitSurface::Evaluator> evaluator;

  LimitShader(Inner shader, const LimitSurface* surface, const SurfaceParameters* where)
      : inner(std::move(shader)), limit(surface), parameters(where) {}
  LimitShader(const LimitShader& other)
      : inner(other.inner), limit(other.limit), parameters(other.parameters) {}
  LimitShader& operator=(const LimitShader&) = delete;

  void beginTriangle(std::uint32_t triangle, const std::array<std::uint32_t, 3>& c) {
    corners = c;
    inner.beginTriangle(triangle,
                        c);  // the tessellation's triangle: the fallback where Bfr has nothing
    ShadingTriangle& t = inner.tri;
    if (!t.hasTangents) {  // no MikkTSpace frames (the planner skips them): the triangle's
      // own, as the limit surface's are made (T = ∂P/∂u made orthogonal to N)
      for (std::size_t i = 0; i < 3; ++i)
        frameFromUvDerivatives(t.normal[i], t.dPdu[0], t.dPdv[0], t.tangent[i], t.sign[i]);
      t.hasTangents = true;
    }
    meshTriangle = t;
    onLimit = false;
  }

  void shade(const Vec3d& b, int x, int y, double* out) {
    if (!evaluator) evaluator = std::make_shared<LimitSurface::Evaluator>(*limit);
    const Mesh& mesh = *inner.mesh;
    const int bakeSet = inner.uvSet;
    const std::uint32_t face = parameters->faceOrigin[corners[0] / 4];
    const std::uint32_t subFace = parameters->cornerSubFace[corners[0]];
    Vec2d start{0, 0}, target{0, 0};
    const std::vector<Vec2f>& uvs = mesh.uvSets[static_cast<std::size_t>(bakeSet)].uvs;
    for (std::size_t i = 0; i < 3; ++i) {
      start = start + b[i] * cast<double>(parameters->cornerCoord[corners[i]]);
      target = target + b[i] * cast<double>(uvs[corners[i]]);
    }
    LimitPoint p;
    if (evaluator->locate(face, subFace, start, bakeSet, target, p)) {
      useLimitPoint(p);
      onLimit = true;
    } else if (onLimit) {  // the fallback: the tessellation's triangle
      inner.tri = meshTriangle;
      onLimit = false;
    }
    inner.triangleChanged();
    inner.shade(b, x, y, out);
  }

 private:
  /// Rewrites inner.tri so that every corner carries the limit surface's values at @p p: every
  /// field a shader reads, so that inner.tri, meshTriangle or the last limit point before, need
  /// not be restored to meshTriangle first (a 2 KB copy per sample). The fields left as they are
  /// (hasTangents, polygonNormal, layerTangent, UVs past numUvSets) are meshTriangle's, or
  /// unread once polygonFrame and hasLayerTangents are false.
  void useLimitPoint(const LimitPoint& p) {
    ShadingTriangle& t = inner.tri;
    const Vec3d n = normalizeOr(cross(p.dPds, p.dPdt), meshTriangle.faceNormal);
    Vec3d tangent{0, 0, 0};
    double sign = 1;
    t.numUvSets = std::min(meshTriangle.numUvSets, p.numUvSets);
    for (int s = 0; s < t.numUvSets; ++s) {
      const std::size_t k = static_cast<std::size_t>(s);
      limitUvDerivatives(p.dPds, p.dPdt, p.dUVds[k], p.dUVdt[k], t.dPdu[k], t.dPdv[k]);
      t.uv[k] = {p.uv[k], p.uv[k], p.uv[k]};
      if (s == 0) frameFromUvDerivatives(n, t.dPdu[k], t.dPdv[k], tangent, sign);
    }
    const std::size_t bake = static_cast<std::size_t>(inner.uvSet);
    if (bake < static_cast<std::size_t>(t.numUvSets)) {
      t.bakeDPdu = t.dPdu[bake];
      t.bakeDPdv = t.dPdv[bake];
    }
    t.position = {p.position, p.position, p.position};
    t.normal = {n, n, n};
    t.faceNormal = n;
    t.flat = t.polygonFrame = false;  // the limit surface is smooth
    t.tangent = {tangent, tangent, tangent};
    t.sign = {sign, sign, sign};
    t.hasLayerTangents = {};  // the surface's own frames decode its layers too
  }
};

}  // namespace sgbake::bake_detail
