/// @file projection.hpp
/// @brief Planar (seed 001 eq. 39-44) and triplanar (eq. 45-50, seed 003) projections of height
/// maps, tangent-space normal maps and object-space normal maps, as surface gradients.
///
/// **Orientation conventions.** Each axis plane is textured at a cyclic pair of object
/// coordinates, so that (s axis) × (t axis) = the plane's axis (right-handed, seen from the
/// positive side of the axis the image is not mirrored):
///
///   | plane | (s, t) before tiling | s axis | t axis | normal axis |
///   |-------|----------------------|--------|--------|-------------|
///   | X     | (y, z)               | +Y     | +Z     | +X          |
///   | Y     | (z, x)               | +Z     | +X     | +Y          |
///   | Z     | (x, y)               | +X     | +Y     | +Z          |
///
/// and the texture is looked up at (s, t) = tiling ∘ (plane coordinates) + offset. "Triplanar's
/// Z plane is textured at (x, y) · tiling."
///
/// **Volume-gradient formulation.** A planar height map is a height volume constant along the
/// plane's axis (eq. 8); its volume gradient is
/// ∇h = scale · (tiling.x·∂h/∂s · e_s + tiling.y·∂h/∂t · e_t), and Γ is its projection onto the
/// tangent plane, ∇h − ⟨∇h, N⟩N (eq. 30, 50; equal to eq. 44). A tangent-space normal map on a
/// plane is read as the slopes of such a height (eq. 14, in the plane's frame
/// I = e_s, J = e_t, K = e_n). Triplanar blends the three volume gradients with weights frozen
/// at the point (eq. 46-49, the weights' own derivatives are neglected as in eq. 48) and
/// projects once. There are no per-side sign flips: the height always displaces along the
/// surface normal, so faces looking down −axis see the image mirrored, with bumps still outward.
/// Object-space normal maps are blended as surface gradients (eq. 45).
///
/// **Blender's Box projection** (TriplanarProjection::kBox, PlaneLayout::kBox) is the other
/// triplanar: Cycles' Image Texture with Projection "Box", as a technical artist sets it up in
/// Blender. Its planes are textured at (y, z) on X, (x, z) on Y and (y, x) on Z, the first
/// coordinate mirrored (s ↦ 1 − s) on the −X, +Y and +Z sides of the normal Cycles shades with,
/// so no side sees its image mirrored; its weights are boxProjectionWeights. Its slopes are
/// taken as the blended ones (frozen weights; a mirrored plane's s axis is −e_s).
///
/// **Blender's Sphere and Tube projections** (TriplanarProjection::kSphere, kTube;
/// PlaneLayout::kSphere, kTube) are single lookups that wrap the image around the z axis of
/// c = 2 · (P' − ½) (Cycles remaps the [0, 1] box to [−1, 1] first): both take
/// u = ½ − atan2(c_x, c_y) / 2π (the seam at −y), the Sphere v = 1 − acos(c_z / |c|) / π, the
/// Tube v = (c_z + 1) / 2. Their slopes are exact: the volume gradient is the chain rule
/// through (u, v) (projectedVolumeGradient), which does not depend on any plane.
#pragma once

#include <array>

#include "sgbake/core/vec.hpp"
#include "sgbake/gradient/surface_gradient.hpp"
#include "sgbake/gradient/surface_point.hpp"
#include "sgbake/gradient/texture.hpp"

namespace sgbake {

/// @brief The object axis a plane is perpendicular to (also the index into weight arrays).
enum class ProjectionAxis : int { kX = 0, kY = 1, kZ = 2 };

/// @brief A projection plane's unit axes in object space: texture s, texture t, and normal
/// (s × t = n), see the table in the file comment.
struct PlaneAxes {
  Vec3d s, t, n;
};

/// @brief The axes of the plane perpendicular to @p axis.
PlaneAxes planeAxes(ProjectionAxis axis);

/// @brief Plane coordinates of an object-space point, before tiling: (x, y) for Z, (y, z) for X,
/// (z, x) for Y.
Vec2d planeCoordinates(Vec3d position, ProjectionAxis axis);

/// @brief How Blender's Mapping node moves a vector (its type; Normal, which normalizes, does
/// not keep coordinates affine and is not one).
enum class MappingType {
  kPoint,    ///< R · (scale ∘ P) + location
  kTexture,  ///< the inverse of Point: (Rᵀ · (P − location)) / scale (a zero scale gives 0)
  kVector,   ///< R · (scale ∘ P): Point without the location
};

/// @brief Object coordinates moved before a projection reads them, as Blender's Mapping node
/// moves a Texture Coordinate node's Object output: P' = linear · P + translation; for type
/// Point linear = R · diag(scale), R the rotation of an XYZ Euler (x first, then y, then z).
/// A projection's planes and slopes are those of P' (the slopes pulled back by linearᵀ); a
/// Box projection still picks its planes by the object's normal, as Cycles does.
struct CoordinateMapping {
  Mat3 linear = Mat3::identity();
  Vec3d translation{};
  bool identity = true;  ///< linear the identity and no translation: P' = P, nothing to do

  /// The Mapping node of type @p type with Location, Rotation (radians, XYZ Euler) and Scale.
  static CoordinateMapping fromMappingNode(Vec3d location, Vec3d rotation, Vec3d scale,
                                           MappingType type = MappingType::kPoint);
  /// P' = @p linear · P + @p translation: any affine map, e.g. the coordinates another object
  /// (Texture Coordinate Object with an object) or the texture space (Generated) gives P.
  static CoordinateMapping affine(const Mat3& linear, Vec3d translation);
  /// This mapping applied after @p first.
  CoordinateMapping after(const CoordinateMapping& first) const;
  /// P'.
  Vec3d apply(Vec3d position) const {
    return identity ? position : linear * position + translation;
  }
  /// The object-space gradient of a function of P' whose gradient w.r.t. P' is @p gradient:
  /// linearᵀ · gradient.
  Vec3d pullBack(Vec3d gradient) const {
    if (identity) return gradient;
    return {dot(linear.col[0], gradient), dot(linear.col[1], gradient),
            dot(linear.col[2], gradient)};
  }
};

/// @brief Which object coordinates texture a plane (before tiling), or how a wrapped lookup
/// reads them.
enum class PlaneLayout {
  kCyclic,  ///< the cyclic pairs of the table above: (y, z), (z, x), (x, y)
  /// Blender's Box projection: (y, z) on X, (x, z) on Y, (y, x) on Z; see PlanarMapping::mirrored
  kBox,
  /// Not a plane: Blender's Sphere projection, (u, v) = sphereCoordinates(P') (the file
  /// comment); the axis is not read.
  kSphere,
  /// Not a plane: Blender's Tube projection, (u, v) = tubeCoordinates(P').
  kTube,
};

/// @brief Whether @p layout wraps the image around an axis (kSphere, kTube) rather than laying
/// it on a plane.
constexpr bool isWrapped(PlaneLayout layout) {
  return layout == PlaneLayout::kSphere || layout == PlaneLayout::kTube;
}

/// @brief Cycles' Sphere projection of P' (its map_to_sphere of c = 2 · (P' − ½)):
/// u = ½ − atan2(c_x, c_y) / 2π, v = 1 − acos(c_z / |c|) / π; u = 0 on the z axis and
/// (0, 0) at c = 0, as Cycles gives them.
Vec2d sphereCoordinates(Vec3d mapped);
/// @brief Cycles' Tube projection of P' (its map_to_tube of c = 2 · (P' − ½)): u as the
/// Sphere's, v = (c_z + 1) / 2; (0, 0) on the z axis, as Cycles gives them.
Vec2d tubeCoordinates(Vec3d mapped);

/// @brief The gradients w.r.t. P' of a lookup's two texture coordinates before tiling.
struct CoordinateGradients {
  Vec3d s, t;
};

/// @brief ∇u and ∇v of sphereCoordinates or tubeCoordinates (@p layout) at @p mapped; zero
/// where they are not differentiable (the z axis, for u and the Sphere's v).
CoordinateGradients wrappedCoordinateGradients(Vec3d mapped, PlaneLayout layout);

/// @brief How a plane is textured: (s, t) = tiling ∘ planeCoordinates(P, mapping) + offset.
struct PlanarMapping {
  ProjectionAxis axis = ProjectionAxis::kZ;
  Vec2d tiling{1, 1};  ///< repeats per object unit along s and t
  Vec2d offset{0, 0};  ///< texture units
  PlaneLayout layout = PlaneLayout::kCyclic;
  /// The first plane coordinate is 1 − s (its axis −e_s): a Box plane seen from the side that
  /// Cycles mirrors (boxPlaneMirrored). Only kBox mappings are mirrored.
  bool mirrored = false;
};

/// The object's own coordinates: P' = P.
inline const CoordinateMapping kObjectCoordinates{};

/// @brief The axes of a plane as @p mapping lays it out: s and t the object-space directions
/// its two texture coordinates grow along (before tiling), n = s × t (±the plane's axis).
/// Planar layouts only: a wrapped one (isWrapped) has no fixed axes and gets zero ones.
PlaneAxes planeAxes(const PlanarMapping& mapping);

/// @brief Plane coordinates of @p position (P', after any CoordinateMapping) under @p mapping's
/// layout and mirror, before tiling (a wrapped layout's (u, v)).
Vec2d planeCoordinates(Vec3d position, const PlanarMapping& mapping);

/// @brief Texture coordinates of @p position (P', after any CoordinateMapping) under
/// @p mapping.
Vec2d planarTextureCoordinates(Vec3d position, const PlanarMapping& mapping);

/// @brief Volume gradient of `scale · h(planarTextureCoordinates(P', mapping))` w.r.t. P':
/// scale · (tiling.x · dhdst.x · s + tiling.y · dhdst.y · t) with s, t = planeAxes(mapping)
/// (CoordinateMapping::pullBack takes it to P); object units per object unit.
///
/// @param[in] dhdst (∂h/∂s, ∂h/∂t) at the point, per texture unit
Vec3d planeVolumeGradient(Vec2d dhdst, const PlanarMapping& mapping, double scale);

/// @brief Volume gradient w.r.t. P' of `scale · h(planarTextureCoordinates(P', mapping))` at
/// @p mapped (P'), for any layout: planeVolumeGradient on a plane; on a wrapped layout
/// scale · (tiling.x · dhdst.x · ∇u + tiling.y · dhdst.y · ∇v) (wrappedCoordinateGradients).
Vec3d projectedVolumeGradient(Vec2d dhdst, const PlanarMapping& mapping, Vec3d mapped,
                              double scale);

/// @brief Options shared by planar and triplanar normal-map lookups.
struct ProjectedNormalOptions {
  NormalMapGreen green = NormalMapGreen::kOpenGL;  ///< tangent-space maps only
  double minNormalZ = kMinTangentNormalZ;     ///< tangent-space guard (slopesFromTangentNormal)
  double minCosine = kMinObjectNormalCosine;  ///< object-space guard (gradientFromObjectNormal)
};

/// @brief Γ of a height map projected on one axis plane (eq. 39-44, 50), read at the point's
/// @p coordinates (the object's own by default).
/// @param[in] scale object units of height per texture unit of value
/// @note Samples @p texture once.
Vec3d planarHeightGradient(const ScalarTexture& texture, const PlanarMapping& mapping, double scale,
                           const SurfacePoint& point,
                           const CoordinateMapping& coordinates = kObjectCoordinates);

/// @brief Γ of a tangent-space normal map projected on one axis plane (eq. 42-44): the decoded
/// normal, read in the plane's frame (x along e_s, y along e_t, z along e_n), gives the slopes of
/// a planar height (with the n_z guard of slopesFromTangentNormal); Γ is that height's projected
/// volume gradient, times @p strength.
/// @note Samples @p texture once.
Vec3d planarTangentNormalGradient(const VectorTexture& texture, const PlanarMapping& mapping,
                                  double strength, const SurfacePoint& point,
                                  const ProjectedNormalOptions& options = {},
                                  const CoordinateMapping& coordinates = kObjectCoordinates);

/// @brief Γ of an object-space normal map looked up through a planar projection (eq. 38): the
/// decoded normal is an object-space normal whatever the projection, so tiling moves the lookup
/// but does not scale Γ; @p strength does. Negative/grazing normals as gradientFromObjectNormal.
/// @note Samples @p texture once.
Vec3d planarObjectNormalGradient(const VectorTexture& texture, const PlanarMapping& mapping,
                                 double strength, const SurfacePoint& point,
                                 const ProjectedNormalOptions& options = {},
                                 const CoordinateMapping& coordinates = kObjectCoordinates);

// ---------------------------------------------------------------------------------------------
// Triplanar
// ---------------------------------------------------------------------------------------------

/// Default exponent of the triplanar blend weights.
inline constexpr double kDefaultTriplanarSharpness = 4;
/// Default threshold below which a plane's blend weight counts as zero and it is not sampled.
inline constexpr double kDefaultMinTriplanarWeight = 1e-3;

/// @brief Blend weights of the three planes at one normal, indexed by ProjectionAxis.
struct TriplanarWeights {
  std::array<double, 3> w{};  ///< sum to 1 over the active planes; 0 for skipped planes
  int active = 0;             ///< number of planes with w > 0 (0 only for a zero/NaN normal)
};

/// @brief Triplanar blend weights from the shading normal N:
/// w_i = |n_i|^sharpness / Σ_j |n_j|^sharpness, then planes with w_i < minWeight are dropped
/// (not sampled) and the remaining weights are renormalized to sum to 1.
///
/// Renormalizing keeps the bump strength independent of the threshold and makes a point whose
/// normal is within the threshold of an axis exactly the planar projection on that axis (eq. 50).
/// Weights are computed as (|n_i| / max_j |n_j|)^sharpness, so no exponent under- or overflows
/// all three (the dominant plane always gets ratio 1). sharpness is clamped to ≥ 0; 0 gives 1/3
/// to every plane (0^0 = 1), larger values give narrower transitions (4 by default; 1 is the
/// plain |n_i| / Σ|n_j|). minWeight is clamped to [0, 1/3] so the
/// dominant plane (weight ≥ 1/3) always survives. A zero or non-finite N gives no active plane.
TriplanarWeights triplanarWeights(Vec3d normal, double sharpness = kDefaultTriplanarSharpness,
                                  double minWeight = kDefaultMinTriplanarWeight);

/// @brief Whether Blender's Box projection mirrors the plane perpendicular to @p axis where
/// Cycles shades with normal @p seenNormal (object space; −N seen from behind): on the −X, +Y and
/// +Z sides.
bool boxPlaneMirrored(ProjectionAxis axis, Vec3d seenNormal);

/// @brief Blend weights of Blender's Box projection (Cycles' Image Texture, Projection "Box")
/// at @p normal, with its Blend @p blend ∈ [0, 1].
///
/// With a_i = |n_i| / Σ|n_j| and L = (1 + blend)/2, a plane whose ratio a_i/(a_i + a_j) exceeds
/// L against both others is used alone; else, with blend > 0, where one plane k has
/// a_k < (1 − L)(a_i + a_j) the two others blend as clamp((a_i/(a_i + a_j) − (1 − blend)/2) /
/// blend, 0, 1) and its complement; else all three take ((2 − L)·a_i + L − 1) / (2L − 1). With
/// blend 0 the largest component wins alone (X on ties, where no plane exceeds another). The
/// zones are tested in Cycles' order (X, Y, Z alone; then without Z, X, Y), so points on their
/// borders get what Cycles gives them. Planes with weight ≤ 0 are not counted or sampled. A
/// zero or non-finite N gives no active plane; blend is clamped to [0, 1] (NaN → 0).
TriplanarWeights boxProjectionWeights(Vec3d normal, double blend);

/// @brief How a triplanar projection lays out and blends its planes.
enum class TriplanarProjection {
  /// Seed 003: the cyclic planes (PlaneLayout::kCyclic), weights triplanarWeights (sharpness,
  /// minWeight).
  kBlended,
  /// Blender's Box projection: PlaneLayout::kBox, weights boxProjectionWeights (boxBlend).
  kBox,
  /// Blender's Flat projection: the one plane (x, y) of P' (the Z plane, cyclic layout), weight
  /// 1 whatever the normal. A height so projected is a planar one on z; it serves a normal
  /// map's projected read (TangentNormalSource::projection).
  kFlat,
  /// Blender's Sphere projection: one lookup of PlaneLayout::kSphere, weight 1. A height so
  /// projected is a planar one of that layout.
  kSphere,
  /// Blender's Tube projection: one lookup of PlaneLayout::kTube, weight 1.
  kTube,
};

/// @brief Whether @p projection is one lookup whatever the normal (kFlat, kSphere, kTube).
constexpr bool isSingleLookup(TriplanarProjection projection) {
  return projection == TriplanarProjection::kFlat || projection == TriplanarProjection::kSphere ||
         projection == TriplanarProjection::kTube;
}

/// @brief The one lookup of a single-lookup projection (isSingleLookup) with @p tiling and
/// @p offset: the Z plane (kFlat), or the Sphere's or Tube's wrap.
PlanarMapping singleLookupMapping(TriplanarProjection projection, Vec2d tiling = {1, 1},
                                  Vec2d offset = {0, 0});

/// Default Blend of a Box projection, Blender's.
inline constexpr double kDefaultBoxBlend = 0;

/// @brief Options of a triplanar lookup (the same mapping on all three planes).
struct TriplanarOptions {
  Vec2d tiling{1, 1};  ///< repeats per object unit, on every plane
  Vec2d offset{0, 0};  ///< texture units, on every plane
  /// Multiplies Γ: the height scale (object units per unit of value) for height maps, the
  /// strength for normal maps.
  double scale = 1;
  double sharpness = kDefaultTriplanarSharpness;  ///< see triplanarWeights
  double minWeight = kDefaultMinTriplanarWeight;  ///< see triplanarWeights
  ProjectedNormalOptions normal{};                ///< decoding of normal maps
  TriplanarProjection projection = TriplanarProjection::kBlended;
  double boxBlend = kDefaultBoxBlend;  ///< kBox: Blender's Blend, see boxProjectionWeights
  CoordinateMapping coordinates{};     ///< applied to P before every plane reads it
};

/// @brief One plane of a triplanar lookup: how it is textured and its weight (> 0).
struct WeightedPlane {
  PlanarMapping mapping{};
  double weight = 0;
};

/// @brief The planes a triplanar lookup samples at a point whose normal Cycles shades with is
/// @p seenNormal (object space; N, or −N seen from behind), with their weights; planes of zero
/// weight are left out (not sampled). The one place the three kinds, the height map and the
/// Bump node's reads agree on planes, weights and mirrors.
struct TriplanarPlanes {
  std::array<WeightedPlane, 3> plane{};
  int count = 0;
  const WeightedPlane* begin() const { return plane.data(); }
  const WeightedPlane* end() const { return plane.data() + count; }
};
TriplanarPlanes triplanarPlanes(const TriplanarOptions& options, Vec3d seenNormal);

/// @brief The colour an Image Texture with Projection Box, Flat, Sphere or Tube gives at
/// @p point: the texels of the planes triplanarPlanes picks for the normal Cycles shades with
/// there (point.seenNormal(); the single lookups' one whatever the normal), read at @p options'
/// coordinates of P, blended by their weights, not decoded (what a Normal Map node receives). Reads
/// @p options' projection, boxBlend, tiling, offset and coordinates.
Vec3d projectedTexel(const VectorTexture& texture, const TriplanarOptions& options,
                     const SurfacePoint& point);
/// @brief projectedTexel at object position @p position (before @p options' coordinates),
/// the planes picked by @p seenNormal (in world space Cycles picks them by the world normal
/// taken back to object space, not by the object's interpolated one).
Vec3d projectedTexel(const VectorTexture& texture, const TriplanarOptions& options, Vec3d position,
                     Vec3d seenNormal);

/// @brief Γ of a height map by triplanar projection (seed 003; eq. 46-49 then eq. 30):
/// ∇h = Σ_i w_i · planeVolumeGradient_i, Γ = ∇h − ⟨∇h, N⟩N.
/// @note Samples @p texture once per active plane (planes below minWeight are not sampled).
Vec3d triplanarHeightGradient(const ScalarTexture& texture, const TriplanarOptions& options,
                              const SurfacePoint& point);

/// @brief Γ of a tangent-space normal map by triplanar projection: each active plane's texel,
/// read in that plane's frame, gives slopes (eq. 14), blended into one volume gradient like
/// triplanarHeightGradient (Mikkelsen's volume-gradient triplanar, seed 003).
/// @note Samples @p texture once per active plane.
Vec3d triplanarTangentNormalGradient(const VectorTexture& texture, const TriplanarOptions& options,
                                     const SurfacePoint& point);

/// @brief Γ of an object-space normal map by triplanar projection (eq. 45):
/// Γ = scale · Σ_i w_i · gradientFromObjectNormal(N_i, N). Blender's Box projection blends the
/// texels and decodes once, as Cycles' Image Texture feeds a Normal Map node:
/// Γ = scale · gradientFromObjectNormal(Σ_i w_i N_i, N).
/// @note Samples @p texture once per active plane.
Vec3d triplanarObjectNormalGradient(const VectorTexture& texture, const TriplanarOptions& options,
                                    const SurfacePoint& point);

}  // namespace sgbake
