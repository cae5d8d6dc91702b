/// @file world_shading_detail.hpp
/// @brief Private: shadeLayersInWorld with the world triangle's UV frames prepared once per
/// triangle (the bake shaders' way, as BakeShaderBase::preparedUv for object space), and its
/// step for one layer (what the lane-parallel world shading takes sample by sample).
#pragma once

#include <span>

#include "gradient/prepared_uv_frame.hpp"
#include "sgbake/gradient/world_shading.hpp"

namespace sgbake::gradient_detail {

/// @brief sgbake::shadeLayersInWorld, bit for bit, with @p preparedWorldUv[s] =
/// prepareUvFrame(worldPoint.uv[s]) for every UV set s of the point (or null: prepared here).
WorldShadedNormal shadeLayersInWorld(std::span<const Layer> layers, const SurfacePoint& objectPoint,
                                     const SurfacePoint& worldPoint,
                                     const Vec3d& worldGeometricNormal, const WorldSpace& space,
                                     const PreparedUvFrame* preparedWorldUv);

/// @brief A layer that makes a world normal at or below the tangent plane (⟨n, N⟩ below
/// kMinObjectNormalCosine), which no Γ stands for: N − Γ resolves to its mirror image above the
/// plane. A stretched object turns an object-space normal 60° from N that far.
struct NormalBelowSurface {
  /// The layer is a normal map, unmasked, on the surface, at weight 1, that decodes there; or a
  /// layer on the layers above, given the normal they hand on, that bumps it there.
  bool found = false;
  Vec3d decoded{};  ///< that unit normal (a normal map's before its Strength)
  double strength = 1;
  /// The normal the layer hands on: `decoded` blended with @p n by Strength, as the Normal
  /// Map node blends it.
  Vec3d handedOn(const Vec3d& n) const {
    return strength == 1 ? decoded
                         : normalizeOr(n + (strength > 0 ? strength : 0.0) * (decoded - n), n);
  }
};

/// @brief One layer's step of shadeLayersInWorld's sum, bit for bit: @p gamma, the world Γ of
/// the layers before @p layer (whose weight is finite and nonzero), becomes the Γ after it,
/// its guards (a layer on the layers above) seeing the incoming direction @p incoming (the
/// world normal; its negation at a back-facing point). Arguments as shadeLayersInWorld's.
/// @param[out] below when non-null, set as NormalBelowSurface says for this layer
/// @param aboveNormal for a layer on the layers above: when non-null, the normal they hand on
///        (stackGradient's), when no Γ stands for it
void addWorldLayerGradient(const Layer& layer, const SurfacePoint& objectPoint,
                           const SurfacePoint& worldPoint, const Vec3d& worldGeometricNormal,
                           const WorldSpace& space, const PreparedUvFrame* preparedWorldUv,
                           const Vec3d& incoming, Vec3d& gamma, NormalBelowSurface* below = nullptr,
                           const Vec3d* aboveNormal = nullptr);

}  // namespace sgbake::gradient_detail
