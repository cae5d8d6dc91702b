/// @file world_shading_detail.hpp
/// @brief Private: shadeLayersInWorld with the world triangle's UV frames prepared once per
/// triangle (the bake shaders' way, as BakeShaderBase::preparedUv for object space), and its
/// step for one layer (what the lane-parallel world shading takes sample by sample).
#pragma once

#include <span>

#include "gradient/prepared_uv_frame.hpp"
#include "gradient/stacking.hpp"
#include "sgbake/gradient/world_shading.hpp"

namespace sgbake::gradient_detail {

/// @brief sgbake::shadeLayersInWorld, bit for bit, with @p preparedWorldUv[s] =
/// prepareUvFrame(worldPoint.uv[s]) for every UV set s of the point (or null: prepared here).
WorldShadedNormal shadeLayersInWorld(std::span<const Layer> layers, const SurfacePoint& objectPoint,
                                     const SurfacePoint& worldPoint, const WorldSpace& space,
                                     const PreparedUvFrame* preparedWorldUv);

/// @brief One layer's step of shadeLayersInWorld's sum, bit for bit: @p gamma, the world Γ of
/// the layers before @p layer (whose weight is finite and nonzero), becomes the Γ after it,
/// its guards (a layer on the layers above) seeing the incoming direction @p incoming (the
/// world normal; its negation at a back-facing point). Arguments as shadeLayersInWorld's.
/// @param[out] below when non-null, set as NormalBelowSurface says for this layer
/// @param aboveNormal for a layer on the layers above: when non-null, the normal they hand on
///        (stackGradient's), when no Γ stands for it
void addWorldLayerGradient(const Layer& layer, const SurfacePoint& objectPoint,
                           const SurfacePoint& worldPoint, const WorldSpace& space,
                           const PreparedUvFrame* preparedWorldUv, const Vec3d& incoming,
                           Vec3d& gamma, NormalBelowSurface* below = nullptr,
                           const Vec3d* aboveNormal = nullptr);

}  // namespace sgbake::gradient_detail
