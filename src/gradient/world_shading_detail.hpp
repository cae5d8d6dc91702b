/// @file world_shading_detail.hpp
/// @brief Private: shadeLayersInWorld with the world triangle's UV frames prepared once per
/// triangle (the bake shaders' way, as BakeShaderBase::preparedUv for object space).
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

}  // namespace sgbake::gradient_detail
