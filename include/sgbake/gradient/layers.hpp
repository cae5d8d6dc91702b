/// @file layers.hpp
/// @brief Bump layers and their composite (seed 001 eq. 34-35): Γ = Σ weight · mask · Γ_i.
///
/// A Layer names one source of surface gradient (a UV-mapped height map, a tangent- or
/// object-space normal map, a height volume, a planar or triplanar projection) plus a weight and
/// an optional mask. Because Γ is linear in the height (eq. 35), blending layers is adding their
/// surface gradients; the composite is resolved once into the perturbed normal (eq. 33). A
/// height layer may instead bump the normal the layers above it make (LayerBase::kLayersAbove),
/// as a chain of Blender's Bump nodes does; that step is not linear.
///
/// Textures and volumes are **non-owning** const pointers: the caller (the baker's planner) owns
/// them and keeps them alive while layers are evaluated. Every texture is sampled only through
/// its thread-safe sample(), so a span of layers may be evaluated from many threads at once.
///
/// Invalid layers are values, not crashes: a missing texture, a UV set the point does not have
/// or a non-finite weight makes that layer contribute Γ = 0; validateLayers() reports such
/// layers as an Error for the caller to show.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <variant>
#include <vector>

#include "sgbake/core/result.hpp"
#include "sgbake/core/vec.hpp"
#include "sgbake/gradient/projection.hpp"
#include "sgbake/gradient/surface_gradient.hpp"
#include "sgbake/gradient/surface_point.hpp"
#include "sgbake/gradient/texture.hpp"
#include "sgbake/gradient/volume.hpp"

namespace sgbake {

/// @brief How a height layer's slopes are taken.
enum class HeightGradient {
  kAnalytic,  ///< the exact derivatives of the filtered height (eq. 31)
  /// Blender's Bump node as Cycles bakes it: the height read again at the point's BumpOffsets
  /// (half a bake texel along two directions of the geometric normal), Γ from those forward
  /// differences. Exact where the point has no offsets (per-corner tables).
  kBumpNode,
};

/// @brief A height map on a UV set: h = scale · texture(tiling ∘ uv + offset); Γ by eq. 31.
struct UvHeightSource {
  const ScalarTexture* texture = nullptr;  ///< heights; not owned
  int uvSet = 0;                           ///< index into SurfacePoint::uv
  double scale = 1;                        ///< object units of height per unit of texture value
  Vec2d tiling{1, 1};                      ///< repeats per UV unit (eq. 2)
  Vec2d offset{0, 0};                      ///< texture units
  double minFrameSine = kMinFrameSine;     ///< degenerate-frame threshold
  /// Blender's Bump node Strength (withNormalMapStrength: a blend of the bumped normal with N,
  /// as Cycles' Bump node ends, not a scale); heights are not changed by it.
  double strength = 1;
  HeightGradient gradient = HeightGradient::kAnalytic;
};

/// @brief A tangent-space normal map on a UV set (eq. 14-15), decoded in the MikkTSpace frame or
/// the UV-derivative frame (see TangentNormalOptions and gradientFromTangentNormal).
struct TangentNormalSource {
  const VectorTexture* texture = nullptr;  ///< [0,1]-encoded channels; not owned
  int uvSet = 0;                           ///< the UV set the map is looked up on
  TangentNormalOptions options{};  ///< green convention, frame, strength, tiling, offset, guards
  /// The UV set whose tangent frames decode the map, −1: uvSet. (Blender's Normal Map node
  /// takes them from its own UV Map, or the render UV map when that is empty, whatever UV map
  /// its image is read on.)
  int tangentUvSet = -1;
  /// When set, the texels are read by one of Blender's projections of the object coordinates
  /// instead of through uvSet (projectedTexel; the options' projection must be kBox, kFlat,
  /// kSphere or kTube, their tiling and offset replace those above): an Image Texture with
  /// Projection Box, Flat, Sphere or Tube on Texture Coordinate Object feeding a Normal Map
  /// node. The frame still comes from frameUvSet().
  std::optional<TriplanarOptions> projection{};
  int frameUvSet() const { return tangentUvSet >= 0 ? tangentUvSet : uvSet; }
};

/// @brief An object-space normal map on a UV set (eq. 38, JCGT form; see
/// gradientFromObjectNormal). Tiling and offset move the lookup only.
struct ObjectNormalSource {
  const VectorTexture* texture = nullptr;  ///< [0,1]-encoded object-space normals; not owned
  int uvSet = 0;
  Vec2d tiling{1, 1};
  Vec2d offset{0, 0};
  double strength = 1;  ///< Blender's Normal Map Strength (withNormalMapStrength)
  double minCosine = kMinObjectNormalCosine;
  /// When set, the texels are read by one of Blender's projections instead of through uvSet
  /// (see TangentNormalSource::projection; no UV set is read then).
  std::optional<TriplanarOptions> projection{};
};

/// @brief A height volume h(P) in object space: Γ = scale · (∇h − ⟨∇h, N⟩N) (eq. 30).
struct VolumeSource {
  const HeightVolume* volume = nullptr;  ///< not owned
  GradientScheme scheme = GradientScheme::kAnalytic;
  /// Finite-difference step, object units (ignored by kAnalytic); use defaultStep(objectSize).
  double step = 0;
  double scale = 1;  ///< multiplies the height
  /// kBumpNode: the volume read again at the point's BumpOffsets, as the Bump node reads a
  /// height at positions (Texture Coordinate Object); `scheme` where the point has none.
  HeightGradient gradient = HeightGradient::kAnalytic;
  double strength = 1;  ///< Blender's Bump node Strength, as UvHeightSource::strength
};

/// @brief What a projected texture holds.
enum class ProjectedKind {
  kHeight,         ///< a ScalarTexture of heights
  kTangentNormal,  ///< a VectorTexture tangent-space normal map, read in each plane's frame
  kObjectNormal,   ///< a VectorTexture object-space normal map
};

/// @brief A texture projected on one axis plane (eq. 39-44); see projection.hpp.
struct PlanarSource {
  ProjectedKind kind = ProjectedKind::kHeight;
  const ScalarTexture* height = nullptr;   ///< for kHeight; not owned
  const VectorTexture* normals = nullptr;  ///< for the normal kinds; not owned
  PlanarMapping mapping{};
  CoordinateMapping coordinates{};  ///< the coordinates the plane reads (the object's own)
  double scale = 1;  ///< height scale (kHeight) or strength (normal maps)
  ProjectedNormalOptions normal{};
  HeightGradient gradient = HeightGradient::kAnalytic;  ///< of kHeight, as VolumeSource's
  /// kHeight: Blender's Bump node Strength, as UvHeightSource::strength (normal kinds: scale)
  double strength = 1;
};

/// @brief A texture projected on the three axis planes and blended (seed 003, eq. 45-50); see
/// projection.hpp for orientations, weights and the skip threshold.
struct TriplanarSource {
  ProjectedKind kind = ProjectedKind::kHeight;
  const ScalarTexture* height = nullptr;   ///< for kHeight; not owned
  const VectorTexture* normals = nullptr;  ///< for the normal kinds; not owned
  TriplanarOptions options{};              ///< scale, tiling, offset, sharpness, minWeight, decode
  HeightGradient gradient = HeightGradient::kAnalytic;  ///< of kHeight, as VolumeSource's
  /// kHeight: Blender's Bump node Strength, as UvHeightSource::strength (normal kinds: scale)
  double strength = 1;
};

/// @brief One of the source kinds.
using LayerSource = std::variant<UvHeightSource, TangentNormalSource, ObjectNormalSource,
                                 VolumeSource, PlanarSource, TriplanarSource>;

/// @brief An optional scalar mask looked up on a UV set: the layer's Γ is multiplied by
/// clamp(mask(tiling ∘ uv + offset), 0, 1).
///
/// The mask scales Γ, not the height: its own derivatives are neglected, the same frozen-weight
/// approximation as triplanar blending (eq. 48). Where the mask is 0 the source is not sampled.
struct LayerMask {
  const ScalarTexture* texture = nullptr;  ///< nullptr = no mask (factor 1); not owned
  int uvSet = 0;
  Vec2d tiling{1, 1};
  Vec2d offset{0, 0};
};

/// @brief Which normal a layer bumps.
enum class LayerBase {
  /// The surface's shading normal N: the layer's Γ is added to the others' (eq. 34-35).
  kSurface,
  /// The normal the layers above it make, n₁ = normalize(N − Γ_above) (unguarded: in Blender
  /// 3.4 only the closure guards, not the nodes): Blender's Bump node with its Normal input
  /// linked to the node before it (a Normal Map node, another Bump node). Heights only (UV
  /// height maps, volumes, planar and triplanar heights): a Normal Map node has no Normal input.
  /// See stackLayerGradient.
  kLayersAbove,
};

/// @brief A source with its blend weight and optional mask.
struct Layer {
  LayerSource source;
  double weight = 1;  ///< any finite value (negative inverts the bumps); 0 disables
  LayerMask mask{};
  LayerBase base = LayerBase::kSurface;
  /// Heights only: the height is measured in object units along the normal, as Blender's
  /// Displacement node in Object space displaces (its Scale), not in world units as a Bump
  /// node's Distance. Under an object transform M, Cycles carries such a displacement to the
  /// world along the normal, so its world height is |Mᵀn| times it (n the unit world normal
  /// Cycles shades with; the object's scale along the normal): world shading multiplies the
  /// layer's Γ by that. Without a transform it changes nothing.
  bool objectSpaceHeight = false;
  /// The material whose faces the layer applies to (Mesh::faceMaterial: Blender's material
  /// slot), as a multi-material object's Bump and Normal Map nodes apply to their material's
  /// faces only; −1: every face. The engine's functions of a point do not read it: the baker
  /// and the corner table pick each face's layers (layersOfMaterial).
  int material = -1;
};

/// Largest material index a layer may name (Blender allows 32767 material slots).
inline constexpr int kMaxMaterialIndex = 32766;

/// @brief The layers of @p layers that apply to faces of material @p material (Layer::material
/// −1 or equal to it), in order.
std::vector<Layer> layersOfMaterial(std::span<const Layer> layers, std::uint32_t material);

/// @brief layersOfMaterial for every material index 0 … K + 1, K the highest a layer names
/// (entry K + 1 serves every material above K); empty when every layer applies to every face.
/// What a face of material m shades with: entry min(m, K + 1).
std::vector<std::vector<Layer>> layersByMaterial(std::span<const Layer> layers);

/// @brief Γ of a layer's source alone (no weight, no mask), object space, at @p point.
///
/// Returns 0 for a missing texture/volume or a UV set outside [0, point.numUvSets).
Vec3d layerGradient(const LayerSource& source, const SurfacePoint& point);

/// @brief The layer's mask factor at @p point, in [0, 1]: 1 without a mask; 0 when the mask's UV
/// set is missing or the mask value is NaN.
double layerMask(const LayerMask& mask, const SurfacePoint& point);

/// @brief The composite surface gradient Σ_i weight_i · mask_i · Γ_i (eq. 34-35), in span
/// order; a layer based on kLayersAbove replaces the sum so far with stackLayerGradient's.
///
/// Layers with weight 0, a non-finite weight, or mask 0 are skipped without sampling their
/// source. Without kLayersAbove layers, order does not matter up to round-off.
/// kLayersAbove layers bump along the point's plane, point.planeNormal() (a mesh triangle's Ng;
/// N where there is none: a corner, a limit surface).
/// @return Γ, object space; 0 for an empty span.
Vec3d compositeGradient(std::span<const Layer> layers, const SurfacePoint& point);

/// @brief Γ after a layer based on kLayersAbove (finite nonzero weight), from @p gammaAbove,
/// the composite of the layers before it: Cycles' Bump node with its Normal input linked.
///
/// With n₁ = normalize(N − Γ_above), the normal the layers above make (not guarded: Blender
/// 3.4's Normal Map and Bump nodes hand on what they make), and γ = weight · mask · Γ of the
/// layer's source without its Strength (⊥ N, and ⟨γ, e⟩ = the height's derivative along e for every
/// e in the plane of Ng): the Bump node's surface gradient relative to n₁ is the vector ⊥ n₁ with
/// the same derivatives along the plane, σ = γ − (⟨γ, n₁⟩ / ⟨Ng, n₁⟩) Ng (Cycles' (∂h/∂x R_x +
/// ∂h/∂y R_y) / det with R_x = ∂P/∂y × n₁, R_y = n₁ × ∂P/∂x, for any two directions ∂P/∂x, ∂P/∂y
/// spanning the plane). Then n₂ = normalize(n₁ − σ), blended with n₁ by the layer's Strength (UV
/// height maps), guarded as the closure guards it; returned as the Γ that resolves to it, N − n₂ /
/// ⟨n₂, N⟩ (gammaAbove where ⟨n₂, N⟩ ≤ 0: no Γ stands for a normal below the surface).
/// Ng is point.planeNormal().
Vec3d stackLayerGradient(const Layer& layer, const SurfacePoint& point, const Vec3d& gammaAbove);

/// @brief The perturbed normal resolveNormal(N, compositeGradient(layers, point), cof) (eq. 33).
/// @param[in] objectScaleCofactor cof(M) of the object's transform; identity = object space
Vec3d perturbedNormal(const SurfacePoint& point, std::span<const Layer> layers,
                      const Mat3& objectScaleCofactor = Mat3::identity());

/// @brief Checks every layer for what would make it contribute nothing silently: a missing
/// texture or volume for its kind, a UV set outside [0, min(numUvSets, kMaxUvSets)), non-finite
/// weight, scale, strength, tiling, offset, sharpness or step; a normal-map layer based on
/// kLayersAbove.
/// @return kBadInput naming the first bad layer ("layer 2 (tangent-space normal map): no texture").
Status validateLayers(std::span<const Layer> layers, int numUvSets);

}  // namespace sgbake
