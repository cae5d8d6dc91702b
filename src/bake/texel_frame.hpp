/// @file texel_frame.hpp
/// @brief Private: Blender's per-texel frame (CONVENTIONS.md, "Per-texel frame in Blender's
/// baker") and the object ↔ tangent conversions built on it, shared by bakeMap and
/// convertNormalMap so that the two agree bit for bit.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

#include "gradient/valid_reflection.hpp"
#include "sgbake/core/math.hpp"
#include "sgbake/core/vec.hpp"
#include "sgbake/frames/tangents.hpp"
#include "sgbake/gradient/surface_point.hpp"
#include "sgbake/gradient/world_shading.hpp"
#include "sgbake/mesh/mesh.hpp"

namespace sgbake::bake_detail {

/// Smallest sine of the angle between a triangle's two UV edges (at corner 0) for which the
/// triangle defines ∂P/∂u, ∂P/∂v. UVs are floats (unit round-off 6e-8), so flatter UV triangles
/// are indistinguishable from a line; below it both derivatives are 0 (UV-based layers then give
/// Γ = 0), the same threshold as the per-corner driver's kMinCornerSine.
inline constexpr double kMinUvTriangleSine = 1e-6;

/// Smallest sine of the angle between the interpolated T and N for which [T B N] is inverted.
/// det [T B N] = sign·|N×T|², so the test is |det| > sine²·|T|²·|N|² (scale-free). Below it (a
/// zero tangent from a degenerate UV corner, T ∥ N) the tangent-space normal is the flat (0, 0, 1).
inline constexpr double kMinTexelFrameSine = 1e-6;

/// @brief Everything the shaders read of one triangle, in double, loaded once per (row block,
/// triangle).
struct ShadingTriangle {
  std::array<Vec3d, 3> position{}, normal{}, tangent{};
  std::array<double, 3> sign{1, 1, 1};
  int numUvSets = 0;  ///< UV sets carried into the SurfacePoint (≤ kMaxUvSets)
  std::array<std::array<Vec2d, 3>, kMaxUvSets> uv{};
  std::array<Vec3d, kMaxUvSets> dPdu{}, dPdv{};
  Vec3d bakeDPdu{}, bakeDPdv{};  ///< derivatives w.r.t. the bake's UV set (any index)
  Vec3d faceNormal{0, 0, 1};     ///< geometric normal, fallback when Σ bi·Ni vanishes
  /// Shaded with faceNormal (a flat face without Auto Smooth: Cycles' Ng, so a non-planar
  /// flat quad shows each triangle's normal) instead of the corner normals Σ bi·Ni.
  bool flat = false;
  /// A flat face's triangle: the tangent frame's N is polygonNormal (the face's unit polygon
  /// normal, faceNormalDirection, as Blender's object → tangent conversion uses), not Σ bi·Ni
  /// (which differ from it only with custom normals).
  bool polygonFrame = false;
  Vec3d polygonNormal{0, 0, 1};
  bool hasTangents = false;
  /// Per UV set, the frames tangent-space layers on it decode with (BakeInput::triangleTangents:
  /// MikkTSpace of the loop triangles, as Cycles' Normal Map node), when given; otherwise set
  /// 0's layers use tangent/sign and the other sets' their UV-derivative frames.
  std::array<std::array<Vec3d, 3>, kMaxUvSets> layerTangent{};
  std::array<std::array<double, 3>, kMaxUvSets> layerSign{};
  std::array<bool, kMaxUvSets> hasLayerTangents{};
};

/// @brief ∂P/∂u, ∂P/∂v of the affine map of a triangle from its positions and UVs; both 0 when the
/// UV triangle is degenerate (see kMinUvTriangleSine).
void triangleDerivatives(const std::array<Vec3d, 3>& p, const std::array<Vec2d, 3>& uv,
                         Vec3d& dPdu, Vec3d& dPdv);

/// @brief The face whose corners include @p corner (faceStart is ascending).
inline std::size_t faceOfCorner(const Mesh& mesh, std::uint32_t corner) {
  const auto next = std::upper_bound(mesh.faceStart.begin(), mesh.faceStart.end(), corner);
  return static_cast<std::size_t>(next - mesh.faceStart.begin()) - 1;
}

/// @brief Loads triangle @p corners of @p mesh.
/// @param[in] tangents per-corner MikkTSpace frames (UV set 0), or nullptr
/// @param[in] bakeUvSet the UV set whose derivatives bakeDPdu/bakeDPdv hold
void loadShadingTriangle(const Mesh& mesh, const CornerTangents* tangents,
                         const std::array<std::uint32_t, 3>& corners, int bakeUvSet,
                         ShadingTriangle& tri);

/// @brief @p tri as the world sees it through @p space (world_shading.hpp), for shading: positions
/// moved, corner normals carried as normals and normalized one by one (as Cycles carries them),
/// the geometric normal carried as a normal, ∂P/∂u and ∂P/∂v as directions; UVs and flatness
/// kept. No tangent frames: tangent-space layers decode in object space.
void worldTriangle(const ShadingTriangle& tri, const WorldSpace& space, ShadingTriangle& world);

/// @brief normalizeOr(a, fallback) bit for bit, with its common case (finite, nonzero squared
/// length) inlined: the compiler keeps normalizeOr itself out of line, and the shaders call it
/// two or three times per texel. The rescaling and fallback cases go through normalizeOr.
inline Vec3d unitOr(const Vec3d& a, const Vec3d& fallback) {
  const double len2 = lengthSquared(a);
  if (len2 > 0 && std::isfinite(len2)) [[likely]] return (1 / std::sqrt(len2)) * a;
  return normalizeOr(a, fallback);
}

/// @brief The per-texel frame at barycentrics b: T, N interpolated and not renormalized (N the
/// polygon normal on a flat face), sign = Σ bi·si < 0 ? −1 : +1, B = sign·N×T; and the
/// interpolated corner normal Σ bi·Ni the shading normal comes from.
struct TexelFrame {
  Vec3d tangent, bitangent, normal;
  Vec3d cornerNormal;       ///< Σ bi·Ni (= normal unless the face is flat)
  double interpolatedSign;  ///< Σ bi·si, as the SurfacePoint carries it
};

inline TexelFrame texelFrame(const ShadingTriangle& t, const Vec3d& b) {
  TexelFrame f;
  f.tangent = b.x * t.tangent[0] + b.y * t.tangent[1] + b.z * t.tangent[2];
  f.cornerNormal = b.x * t.normal[0] + b.y * t.normal[1] + b.z * t.normal[2];
  f.normal = t.polygonFrame ? t.polygonNormal : f.cornerNormal;
  f.interpolatedSign = b.x * t.sign[0] + b.y * t.sign[1] + b.z * t.sign[2];
  f.bitangent = (f.interpolatedSign < 0 ? -1.0 : 1.0) * cross(f.normal, f.tangent);
  return f;
}

/// @brief The unit shading normal: normalize(Σ bi·Ni), or the triangle's normal when that
/// vanishes or the face is shaded flat (ShadingTriangle::flat).
inline Vec3d unitNormal(const ShadingTriangle& t, const TexelFrame& f) {
  return t.flat ? t.faceNormal : unitOr(f.cornerNormal, t.faceNormal);
}

// Cycles' valid-reflection guard (gradient/valid_reflection.hpp), which the shaders end with.
using gradient_detail::reflectsAboveSurface;
using gradient_detail::validReflectionNormal;

/// @brief Sets the fields of @p p that are constant over triangle @p t (UV derivatives, number of
/// UV sets, whether there is a tangent frame); surfacePointAt fills in the rest per sample.
inline void beginSurfacePoint(const ShadingTriangle& t, SurfacePoint& p) {
  p = SurfacePoint{};
  p.geometricNormal = t.faceNormal;
  p.numUvSets = t.numUvSets;
  for (int s = 0; s < t.numUvSets; ++s) {
    const std::size_t k = static_cast<std::size_t>(s);
    p.uv[k].dPdu = t.dPdu[k];
    p.uv[k].dPdv = t.dPdv[k];
  }
  p.hasTangentFrame = t.hasTangents || t.hasLayerTangents[0];
  for (std::size_t s = 1; s < kMaxUvSets; ++s) {
    p.hasUvTangentFrame[s] = t.hasLayerTangents[s] && static_cast<int>(s) < t.numUvSets;
  }
}

/// @brief Completes @p p (prepared by beginSurfacePoint for @p t) for the sample at barycentrics
/// @p b: position, unit normal, UVs and the interpolated tangent frame. This is the SurfacePoint
/// the gradient engine evaluates layers at. Always inlined: out of line (as the compiler chose
/// once the shaders' per-sample paths grew) it cost 1 % of a one-thread bake.
[[gnu::always_inline]] inline const SurfacePoint& surfacePointAt(const ShadingTriangle& t,
                                                                 const Vec3d& b,
                                                                 const TexelFrame& f,
                                                                 SurfacePoint& p) {
  p.position = b.x * t.position[0] + b.y * t.position[1] + b.z * t.position[2];
  p.normal = unitNormal(t, f);
  const double length = t.flat ? 1.0 : std::sqrt(lengthSquared(f.cornerNormal));
  p.normalLength = length > 0 && std::isfinite(length) ? length : 1.0;
  for (int s = 0; s < t.numUvSets; ++s) {
    const std::size_t k = static_cast<std::size_t>(s);
    p.uv[k].uv = b.x * t.uv[k][0] + b.y * t.uv[k][1] + b.z * t.uv[k][2];
  }
  const auto interpolate = [&b](const auto& corners) {
    return b.x * corners[0] + b.y * corners[1] + b.z * corners[2];
  };
  if (t.hasLayerTangents[0]) {
    p.tangent = interpolate(t.layerTangent[0]);
    p.bitangentSign = interpolate(t.layerSign[0]);
  } else if (t.hasTangents) {
    p.tangent = f.tangent;
    p.bitangentSign = f.interpolatedSign;
  }
  for (std::size_t s = 1; s < kMaxUvSets; ++s) {
    if (!p.hasUvTangentFrame[s]) continue;
    p.uvTangent[s] = interpolate(t.layerTangent[s]);
    p.uvBitangentSign[s] = interpolate(t.layerSign[s]);
  }
  return p;
}

/// @brief Object → tangent space: normalize(inverse([T B N]) · n) (the inverse, not the
/// transpose). A degenerate frame (kMinTexelFrameSine) or a zero/non-finite result gives the flat
/// (0, 0, 1).
inline Vec3d objectToTangent(const TexelFrame& f, const Vec3d& n) {
  const Vec3d& T = f.tangent;
  const Vec3d& B = f.bitangent;
  const Vec3d& N = f.normal;
  // inverse([T B N]) has the rows B×N, N×T, T×B divided by det = ⟨T, B×N⟩.
  const Vec3d r0 = cross(B, N), r1 = cross(N, T), r2 = cross(T, B);
  const double det = dot(T, r0);
  constexpr double kMinDet = kMinTexelFrameSine * kMinTexelFrameSine;
  const Vec3d flat{0, 0, 1};
  if (!(std::abs(det) > kMinDet * lengthSquared(T) * lengthSquared(N))) return flat;
  // normalize(M⁻¹ n) = normalize(sign(det) · adj(M) n): only the sign of 1/det survives.
  const double s = det < 0 ? -1.0 : 1.0;
  return unitOr(Vec3d{s * dot(r0, n), s * dot(r1, n), s * dot(r2, n)}, flat);
}

/// @brief Tangent → object space: normalize(x·T + y·B + z·N), the forward map of Blender's
/// Normal Map node; normalize(N) (then the face normal) when that vanishes.
inline Vec3d tangentToObject(const ShadingTriangle& t, const TexelFrame& f, const Vec3d& n) {
  return unitOr(n.x * f.tangent + n.y * f.bitangent + n.z * f.normal, unitNormal(t, f));
}

/// @brief A unit vector as a normal-map colour: n/2 + 0.5 per channel.
inline Vec3d encodeNormal(const Vec3d& n) { return {0.5 * n.x + 0.5, 0.5 * n.y + 0.5, 0.5 * n.z + 0.5}; }

}  // namespace sgbake::bake_detail
