/// @file layers.hpp
/// @brief Bump layers and their composite (seed 001 eq. 34-35): Γ = Σ weight · mask · Γ_i.
///
/// A Layer names one source of surface gradient (a UV-mapped height map, a tangent- or
/// object-space normal map, a height volume, a planar or triplanar projection) plus a weight and
/// an optional mask. Because Γ is linear in the height (eq. 35), blending layers is adding their
/// surface gradients; the composite is resolved once into the perturbed normal (eq. 33).
///
/// Textures and volumes are **non-owning** const pointers: the caller (the baker's planner) owns
/// them and keeps them alive while layers are evaluated. Every texture is sampled only through
/// its thread-safe sample(), so a span of layers may be evaluated from many threads at once.
///
/// Invalid layers are values, not crashes: a missing texture, a UV set the point does not have
/// or a non-finite weight makes that layer contribute Γ = 0; validateLayers() reports such
/// layers as an Error for the caller to show.
#pragma once

#include <span>
#include <variant>

#include "sgbake/core/result.hpp"
#include "sgbake/core/vec.hpp"
#include "sgbake/gradient/projection.hpp"
#include "sgbake/gradient/surface_gradient.hpp"
#include "sgbake/gradient/surface_point.hpp"
#include "sgbake/gradient/texture.hpp"
#include "sgbake/gradient/volume.hpp"

namespace sgbake {

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
};

/// @brief A tangent-space normal map on a UV set (eq. 14-15), decoded in the MikkTSpace frame or
/// the UV-derivative frame (see TangentNormalOptions and gradientFromTangentNormal).
struct TangentNormalSource {
  const VectorTexture* texture = nullptr;  ///< [0,1]-encoded channels; not owned
  int uvSet = 0;
  TangentNormalOptions options{};  ///< green convention, frame, strength, tiling, offset, guards
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
};

/// @brief A height volume h(P) in object space: Γ = scale · (∇h − ⟨∇h, N⟩N) (eq. 30).
struct VolumeSource {
  const HeightVolume* volume = nullptr;  ///< not owned
  GradientScheme scheme = GradientScheme::kAnalytic;
  /// Finite-difference step, object units (ignored by kAnalytic); use defaultStep(objectSize).
  double step = 0;
  double scale = 1;  ///< multiplies the height
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
  double scale = 1;  ///< height scale (kHeight) or strength (normal maps)
  ProjectedNormalOptions normal{};
};

/// @brief A texture projected on the three axis planes and blended (seed 003, eq. 45-50); see
/// projection.hpp for orientations, weights and the skip threshold.
struct TriplanarSource {
  ProjectedKind kind = ProjectedKind::kHeight;
  const ScalarTexture* height = nullptr;   ///< for kHeight; not owned
  const VectorTexture* normals = nullptr;  ///< for the normal kinds; not owned
  TriplanarOptions options{};              ///< scale, tiling, offset, sharpness, minWeight, decode
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

/// @brief A source with its blend weight and optional mask.
struct Layer {
  LayerSource source;
  double weight = 1;  ///< any finite value (negative inverts the bumps); 0 disables
  LayerMask mask{};
};

/// @brief Γ of a layer's source alone (no weight, no mask), object space, at @p point.
///
/// Returns 0 for a missing texture/volume or a UV set outside [0, point.numUvSets).
Vec3d layerGradient(const LayerSource& source, const SurfacePoint& point);

/// @brief The layer's mask factor at @p point, in [0, 1]: 1 without a mask; 0 when the mask's UV
/// set is missing or the mask value is NaN.
double layerMask(const LayerMask& mask, const SurfacePoint& point);

/// @brief The composite surface gradient Σ_i weight_i · mask_i · Γ_i (eq. 34-35).
///
/// Layers with weight 0, a non-finite weight, or mask 0 are skipped without sampling their
/// source. Layer order does not matter up to round-off (the sum is taken in span order).
/// @return Γ, object space; 0 for an empty span.
Vec3d compositeGradient(std::span<const Layer> layers, const SurfacePoint& point);

/// @brief The perturbed normal resolveNormal(N, compositeGradient(layers, point), cof) (eq. 33).
/// @param[in] objectScaleCofactor cof(M) of the object's transform; identity = object space
Vec3d perturbedNormal(const SurfacePoint& point, std::span<const Layer> layers,
                      const Mat3& objectScaleCofactor = Mat3::identity());

/// @brief Checks every layer for what would make it contribute nothing silently: a missing
/// texture or volume for its kind, a UV set outside [0, min(numUvSets, kMaxUvSets)), non-finite
/// weight, scale, strength, tiling, offset, sharpness or step.
/// @return kBadInput naming the first bad layer ("layer 2 (tangent-space normal map): no texture").
Status validateLayers(std::span<const Layer> layers, int numUvSets);

}  // namespace sgbake
