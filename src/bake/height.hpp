/// @file height.hpp
/// @brief Private: the composite height of a layer stack, for the "height" map.
///
/// The gradient engine composites surface gradients (layers.hpp); the height map needs the
/// heights whose gradients those are: h = Σ weight · mask · h_i over the layers whose source is a
/// height (UV height map, volume, planar/triplanar projection of a height map), with each h_i
/// exactly the function whose Γ the engine computes:
///  - UvHeightSource: scale · texture(tiling ∘ uv + offset).value;
///  - VolumeSource:   scale · volume(P);
///  - PlanarSource (kHeight):    scale · texture(planarTextureCoordinates(P)).value;
///  - TriplanarSource (kHeight): Σ_planes w_i · scale · texture(plane i coordinates).value with
///    the frozen weights triplanarWeights(N, sharpness, minWeight).
/// Normal-map layers have no height (their integral is not defined locally) and contribute 0.
/// Masks, weights and the skipping of weight-0/non-finite layers are those of compositeGradient.
#pragma once

#include <span>

#include "sgbake/gradient/layers.hpp"
#include "sgbake/gradient/surface_point.hpp"

namespace sgbake::bake_detail {

/// @brief h of one layer's source alone (no weight, no mask); 0 for normal-map sources, missing
/// textures/volumes, missing UV sets and non-finite results.
double layerHeight(const LayerSource& source, const SurfacePoint& point);

/// @brief Σ weight · mask · layerHeight over @p layers (0 for an empty span or a non-finite sum).
double compositeHeight(std::span<const Layer> layers, const SurfacePoint& point);

}  // namespace sgbake::bake_detail
