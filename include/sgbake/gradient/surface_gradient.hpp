/// @file surface_gradient.hpp
/// @brief The core of the surface-gradient framework (seed 001): height derivatives, normal maps
/// and object-space normals turned into a surface gradient Γ, and Γ resolved into a normal.
///
/// Every function here is a pure kernel on one surface point: object-space vectors in, an
/// object-space vector out, double precision, no allocation, thread-safe, and finite for every
/// finite input (each documents what it returns at the edge of its domain). A Γ that would
/// overflow double (only with absurd scale/tiling/strength products, ~1e300) or that meets a NaN
/// parameter is returned as 0, the unperturbed normal; the same holds for projection.hpp and
/// layers.hpp.
///
/// Conventions used throughout:
///  - Γ is the surface gradient of the height h, in object space: a vector in (or, for the
///    MikkTSpace form of tangent-space maps, near) the tangent plane, pointing uphill, with the
///    magnitude of the slope in object units of height per object unit of length (eq. 30).
///  - Heights displace along the shading normal N; the perturbed normal is N − Γ (eq. 33).
///  - Texture space (s, t) = tiling ∘ (u, v) + offset (eq. 2), so that
///    ∂h/∂u = tiling_u · ∂h/∂s (eq. 13).
#pragma once

#include <array>

#include "sgbake/core/vec.hpp"
#include "sgbake/gradient/surface_point.hpp"
#include "sgbake/gradient/texture.hpp"

namespace sgbake {

// ---------------------------------------------------------------------------------------------
// Named tolerances
// ---------------------------------------------------------------------------------------------

/// Smallest |⟨T̂ × B̂, N⟩| (T̂, B̂ the unit directions of ∂P/∂u, ∂P/∂v) for which a UV frame is
/// used. It is the sine of the angle between the two UV derivatives times the cosine between
/// their plane and N, so it does not depend on the scale of the mesh or of the UVs. Below it
/// (UV triangle folded to a line, ∂P/∂u ∥ ∂P/∂v, or N lying in the UV plane) every UV-based
/// source returns Γ = 0: the point keeps its unperturbed normal.
inline constexpr double kMinFrameSine = 1e-9;

/// Smallest z component allowed for a decoded tangent-space normal, relative to its length
/// (i.e. the sine of the lowest elevation above the tangent plane). 1/128 is one step of an
/// 8-bit channel (2/255), so anything below it is quantization noise; the resulting slope is at
/// most ~128. See slopesFromTangentNormal for what texels at or below it bake to.
inline constexpr double kMinTangentNormalZ = 1.0 / 128.0;

/// Smallest |⟨N̂_o, N⟩| used when turning an object-space normal into Γ (eq. 38, JCGT form);
/// same 8-bit rationale as kMinTangentNormalZ. See gradientFromObjectNormal.
inline constexpr double kMinObjectNormalCosine = 1.0 / 128.0;

// ---------------------------------------------------------------------------------------------
// A tiny 3×3 matrix for the object scale (eq. 20, 33)
// ---------------------------------------------------------------------------------------------

/// @brief A 3×3 matrix stored as three columns (column-major), acting on column vectors.
struct Mat3 {
  std::array<Vec3d, 3> col{Vec3d{1, 0, 0}, Vec3d{0, 1, 0}, Vec3d{0, 0, 1}};  ///< identity

  static constexpr Mat3 identity() { return {}; }
  /// diag(d.x, d.y, d.z), e.g. an object's non-uniform scale.
  static constexpr Mat3 diagonal(Vec3d d) {
    return {{Vec3d{d.x, 0, 0}, Vec3d{0, d.y, 0}, Vec3d{0, 0, d.z}}};
  }
  /// The matrix with columns @p c0, @p c1, @p c2.
  static constexpr Mat3 fromColumns(Vec3d c0, Vec3d c1, Vec3d c2) { return {{c0, c1, c2}}; }

  /// Element in row @p r, column @p c.
  constexpr double operator()(int r, int c) const {
    return col[static_cast<std::size_t>(c)][static_cast<std::size_t>(r)];
  }
  friend constexpr Vec3d operator*(const Mat3& m, Vec3d v) {
    return v.x * m.col[0] + v.y * m.col[1] + v.z * m.col[2];
  }
  friend constexpr Mat3 operator*(const Mat3& a, const Mat3& b) {
    return {{a * b.col[0], a * b.col[1], a * b.col[2]}};
  }
};

/// @brief Mᵀ.
constexpr Mat3 transpose(const Mat3& m) {
  return Mat3::fromColumns({m(0, 0), m(0, 1), m(0, 2)}, {m(1, 0), m(1, 1), m(1, 2)},
                           {m(2, 0), m(2, 1), m(2, 2)});
}

/// @brief det(M) = ⟨c0 × c1, c2⟩.
double determinant(const Mat3& m);

/// @brief The cofactor matrix cof(M) = det(M) · M^{-T}, defined also for singular M.
///
/// Columns: [c1 × c2 | c2 × c0 | c0 × c1] for M = [c0 | c1 | c2]. It is the matrix that
/// transforms normals (axial vectors): (M a) × (M b) = cof(M) (a × b) (eq. 20). For a scale
/// diag(sx, sy, sz) it is diag(sy·sz, sz·sx, sx·sy).
Mat3 cofactor(const Mat3& m);

// ---------------------------------------------------------------------------------------------
// Height derivatives → Γ
// ---------------------------------------------------------------------------------------------

/// @brief Γ from the height's derivatives with respect to one UV set (eq. 31):
/// Γ = ((B × N)·∂h/∂u + (N × T)·∂h/∂v) / ⟨T × B, N⟩ with T = ∂P/∂u, B = ∂P/∂v.
///
/// This is the exact surface gradient of the height for any (non-orthogonal, non-unit, mirrored)
/// UV frame: ⟨Γ, T⟩ = ∂h/∂u, ⟨Γ, B⟩ = ∂h/∂v, ⟨Γ, N⟩ = 0 (eq. 32). It is evaluated with the unit
/// directions of T and B (and their lengths folded into the derivatives), so it neither
/// overflows nor loses its threshold when the mesh or UVs are scaled by 1e±100.
///
/// @param[in] frame   object-space ∂P/∂u, ∂P/∂v of the UV set (the uv member is not read)
/// @param[in] normal  N, unit object-space shading normal
/// @param[in] dhduv   (∂h/∂u, ∂h/∂v), object units of height per UV unit
/// @param[in] minFrameSine degenerate-frame threshold, see kMinFrameSine
/// @return Γ in object units per object unit; **0 when the frame is degenerate**: a zero or
///         non-finite ∂P/∂u or ∂P/∂v, or |⟨T̂ × B̂, N⟩| < minFrameSine; also 0 when the
///         derivatives are not finite or Γ overflows (a frame ~1e-300 long with O(1e10) slopes).
Vec3d gradientFromUvDerivatives(const UvFrame& frame, Vec3d normal, Vec2d dhduv,
                                double minFrameSine = kMinFrameSine);

/// @brief Texture coordinates of a UV set: (s, t) = tiling ∘ uv + offset (eq. 2).
constexpr Vec2d textureCoordinates(Vec2d uv, Vec2d tiling, Vec2d offset) {
  return {tiling.x * uv.x + offset.x, tiling.y * uv.y + offset.y};
}

/// @brief (∂h/∂u, ∂h/∂v) of the height `heightScale · texture(tiling ∘ uv + offset)` (eq. 13):
/// heightScale · (tiling.x · ∂h/∂s, tiling.y · ∂h/∂t). The offset does not enter.
///
/// @param[in] sample      the texture's value and exact (s, t) derivatives at tiling ∘ uv + offset
/// @param[in] tiling      repeats per UV unit along u and v (negative mirrors, 0 flattens)
/// @param[in] heightScale object units of height per texture unit of value
constexpr Vec2d uvDerivativesFromTexture(const ScalarSample& sample, Vec2d tiling,
                                         double heightScale) {
  return {heightScale * tiling.x * sample.gradient.x, heightScale * tiling.y * sample.gradient.y};
}

/// @brief Projection of a volume gradient onto the tangent plane: ∇h − ⟨∇h, N⟩ N (eq. 30).
///
/// This is Γ for a height defined in space (a volume, planar and triplanar projections).
/// @param[in] volumeGradient ∇h, object space
/// @param[in] normal N, unit
constexpr Vec3d projectOntoTangentPlane(Vec3d volumeGradient, Vec3d normal) {
  return volumeGradient - dot(volumeGradient, normal) * normal;
}

/// @brief Γ of a height defined in space on a triangle with unit geometric normal @p along,
/// shaded with unit normal @p normal, as Cycles' Bump node takes it: the height's slopes along
/// the triangle's plane (⊥ Ng), carried by the vector ⊥ N that has them,
/// ∇h − ⟨∇h, N⟩/⟨Ng, N⟩ · Ng (the projection onto the tangent plane along Ng, not along N).
/// It is projectOntoTangentPlane where N = Ng, and where @p along is zero or orthogonal to N
/// (a point without a triangle). A UV-mapped height's eq. 31 has the same slopes: its ∂P/∂u,
/// ∂P/∂v lie in the triangle's plane.
constexpr Vec3d projectOntoTangentPlaneAlong(Vec3d volumeGradient, Vec3d normal, Vec3d along) {
  const double cosine = dot(along, normal);
  if (!(cosine != 0)) return projectOntoTangentPlane(volumeGradient, normal);
  return volumeGradient - (dot(volumeGradient, normal) / cosine) * along;
}

// ---------------------------------------------------------------------------------------------
// Tangent-space normal maps → Γ (eq. 14-15)
// ---------------------------------------------------------------------------------------------

/// @brief Which way the green channel of a tangent-space normal map points.
enum class NormalMapGreen {
  kOpenGL,   ///< G = +bitangent ("Y+"): Blender, Maya, Unity
  kDirectX,  ///< G = −bitangent ("Y−"): DirectX engines, Unreal; flipped on decode
};

/// @brief Decodes a stored normal-map texel: n = 2c − 1 per channel (CONVENTIONS.md: channel =
/// n/2 + 0.5), then y = −y for NormalMapGreen::kDirectX. The result is not normalized (filtering
/// and quantization shorten it); the slope conversion does not need it to be.
constexpr Vec3d decodeNormalTexel(Vec3d channels, NormalMapGreen green = NormalMapGreen::kOpenGL) {
  const Vec3d n{2 * channels.x - 1, 2 * channels.y - 1, 2 * channels.z - 1};
  return green == NormalMapGreen::kDirectX ? Vec3d{n.x, -n.y, n.z} : n;
}

/// @brief Slopes (∂h/∂s, ∂h/∂t) of the height whose normal is the tangent-space normal @p n
/// (eq. 14): −(n_x, n_y) / n_z, with the n_z guard below.
///
/// **n_z guard**: n_z is replaced by max(n_z, minNormalZ·|n|), so the slopes are at most
/// ~1/minNormalZ (128 by default) in magnitude and always finite. Consequences:
///  - a texel with 0 ≤ n_z < minNormalZ·|n| bakes to a near-grazing normal leaning the way
///    (n_x, n_y) points, at elevation ≈ asin(minNormalZ) ≈ 0.45°;
///  - a texel with n_z < 0 (below the surface: invalid in a tangent-space map, produced by
///    compression or filtering) is not mirrored: it bakes like the clamped texel with the same
///    (n_x, n_y), i.e. grazing towards (n_x, n_y) with slope |n_xy|/(minNormalZ·|n|), which shrinks
///    continuously to a flat texel as n approaches (0, 0, −1);
///  - the zero vector (and any non-finite input) gives (0, 0): flat.
/// The map is continuous everywhere except at the zero vector.
///
/// @param[in] n decoded tangent-space normal (x = +tangent, y = +bitangent, z = +normal),
///              any length
Vec2d slopesFromTangentNormal(Vec3d n, double minNormalZ = kMinTangentNormalZ);

/// @brief Γ from texture-space slopes in an explicit tangent frame (the JCGT "surfgrad from
/// TBN" form): Γ = ∂h/∂s · T_m + ∂h/∂t · B_m.
///
/// With (∂h/∂s, ∂h/∂t) = −(x, y)/z from slopesFromTangentNormal, N − Γ = (x·T_m + y·B_m + z·N)/z,
/// so resolveNormal gives exactly normalize(x·T_m + y·B_m + z·N): the forward map with which
/// Blender's Normal Map node (and every MikkTSpace consumer) decodes a tangent-space map, for any
/// T_m (unit or not, orthogonal to N or not) and both signs. This is why this form, and not
/// eq. 31 with T_m, B_m (the inverse-transpose, which differs as soon as T_m is not orthonormal
/// to N), is used for tangent-space maps.
///
/// @param[in] slopes    (∂h/∂s, ∂h/∂t) with tiling already applied
/// @param[in] tangent   T_m, object space
/// @param[in] bitangent B_m, object space (for MikkTSpace: sign · N × T_m)
constexpr Vec3d gradientFromTangentFrame(Vec2d slopes, Vec3d tangent, Vec3d bitangent) {
  return slopes.x * tangent + slopes.y * bitangent;
}

/// @brief Which tangent frame decodes a tangent-space normal map.
enum class TangentFrameChoice {
  /// The point's MikkTSpace frame of the map's UV set when it has one
  /// (SurfacePoint::hasTangentFrame for set 0, hasUvTangentFrame for the others), otherwise the
  /// UV-derivative frame.
  kAuto,
  /// As kAuto, but a set without its own MikkTSpace frame takes set 0's when there is one.
  kMikkTSpace,
  kUvDerivatives,  ///< always the UV-derivative frame of the map's UV set
};

/// @brief The per-point tangent frame a MikkTSpace baker would build from one UV set, without
/// vertex averaging (the JCGT framework's basis for UV sets without precomputed tangents):
/// T = normalize(∂P/∂u − ⟨∂P/∂u, N⟩N), B = sign · N × T with sign = sign ⟨∂P/∂u × ∂P/∂v, N⟩.
///
/// @param[out] tangent, bitangent unit, orthogonal to N; both 0 when the frame is degenerate
///             (same test as gradientFromUvDerivatives, or ∂P/∂u ∥ N)
/// @return false for a degenerate frame
bool uvDerivativeTangentFrame(const UvFrame& frame, Vec3d normal, Vec3d& tangent, Vec3d& bitangent,
                              double minFrameSine = kMinFrameSine);

/// @brief Options of a tangent-space normal map lookup.
struct TangentNormalOptions {
  NormalMapGreen green = NormalMapGreen::kOpenGL;
  TangentFrameChoice frame = TangentFrameChoice::kAuto;
  /// Blender's Normal Map node Strength (withNormalMapStrength): 1 reproduces the map exactly,
  /// 0 is no bump, other values blend the decoded normal with N.
  double strength = 1;
  /// (s, t) = tiling ∘ uv + offset: the map repeats, its slopes unchanged (as in Blender, where
  /// a Mapping node only moves the Normal Map node's lookup)
  Vec2d tiling{1, 1};
  Vec2d offset{0, 0};
  double minNormalZ = kMinTangentNormalZ;  ///< see slopesFromTangentNormal
  double minFrameSine = kMinFrameSine;     ///< see gradientFromUvDerivatives
};

/// @brief Blender's Normal Map node Strength s on a layer's Γ: the decoded normal
/// n' = normalize(N − Γ) becomes normalize(N + s·(n' − N)) (a blend of normals, not a scaled
/// height), whose Γ (gradientFromObjectNormal) is returned; Γ itself for s = 1, zero for s ≤ 0
/// (Blender clamps Strength at 0) and NaN.
Vec3d withNormalMapStrength(Vec3d gamma, Vec3d normal, double strength);

/// @brief Γ of a decoded tangent-space normal @p n (eq. 14-15) at @p point on UV set @p uvSet.
///
/// Slopes = slopesFromTangentNormal(n) (tiling moves the lookup only), then
/// gradientFromTangentFrame in the frame
/// chosen by options.frame: the MikkTSpace frame T_m = point.tangent / point.normalLength,
/// B_m = bitangentSign · N × point.tangent (so that N − Γ is Blender's Normal Map node decode
/// normalize(x·T + y·B_i + z·N_i) with the unnormalized interpolated normal N_i), or
/// uvDerivativeTangentFrame of the UV set; then withNormalMapStrength. A degenerate frame (zero
/// MikkTSpace tangent, degenerate UV set, uvSet out of range) gives Γ = 0.
///
/// @param[in] n decoded normal (decodeNormalTexel), any length
Vec3d gradientFromTangentNormal(Vec3d n, const SurfacePoint& point, int uvSet,
                                const TangentNormalOptions& options = {});

/// @brief The object-space normal Blender's Normal Map node decodes @p n to, x·T + y·B + z·N in
/// the frame gradientFromTangentNormal uses (not normalized, before Strength; zero without a
/// frame). Where n_z > 0 it is a positive multiple of N − Γ; where n_z ≤ 0 it lies at or below
/// the tangent plane, where Γ only clamps it (see slopesFromTangentNormal).
Vec3d decodeTangentNormal(Vec3d n, const SurfacePoint& point, int uvSet,
                          const TangentNormalOptions& options = {});

// ---------------------------------------------------------------------------------------------
// Object-space normals → Γ (eq. 38)
// ---------------------------------------------------------------------------------------------

/// @brief Γ of an already-perturbed (object-space) normal N_o at a point with normal N (eq. 38),
/// in the JCGT form Γ = (k·N − N̂_o) / max(ε, |k|) with N̂_o = N_o/|N_o| and k = ⟨N̂_o, N⟩.
///
/// Policy:
///  - N_o of any length is normalized first (only its direction matters, and ε is relative);
///  - k ≥ ε: Γ = N − N̂_o/k, exactly eq. 38, and resolveNormal(N, Γ) = N̂_o;
///  - k ≤ −ε (N_o points below the surface): Γ = −(N − N̂_o/k), the negative of eq. 38, and
///    resolveNormal gives N̂_o mirrored across the tangent plane (tangential part kept, normal
///    part made positive). Eq. 38 as written would resolve to −N̂_o, flipping the tilt as well;
///  - |k| < ε: the divisor is ε, so the result leans along N̂_o's tangential part at elevation
///    ≈ asin(ε) (continuous with both neighbours);
///  - N_o zero or non-finite: Γ = 0.
/// Γ is always exactly tangent (⟨Γ, N⟩ = 0 up to round-off) and finite, |Γ| ≤ 1/ε.
///
/// @param[in] objectNormal N_o, decoded (decodeNormalTexel), object space, any length
/// @param[in] normal N, unit shading normal
Vec3d gradientFromObjectNormal(Vec3d objectNormal, Vec3d normal,
                               double minCosine = kMinObjectNormalCosine);

// ---------------------------------------------------------------------------------------------
// Γ → perturbed normal (eq. 33)
// ---------------------------------------------------------------------------------------------

/// @brief The perturbed normal N' = normalize(cof(M) (N − Γ)) (eq. 33).
///
/// @param[in] normal N, unit object-space shading normal
/// @param[in] gamma  Γ, object space (the composite of all layers)
/// @param[in] objectScaleCofactor cof(M) of the object's linear transform M (cofactor());
///            identity = N' stays in object space
/// @return unit vector; when cof(M)(N − Γ) has zero or non-finite length, the unperturbed
///         normalize(cof(M) N), and N itself if that vanishes too (singular M)
Vec3d resolveNormal(Vec3d normal, Vec3d gamma, const Mat3& objectScaleCofactor = Mat3::identity());

}  // namespace sgbake
