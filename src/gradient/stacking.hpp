/// @file stacking.hpp
/// @brief Private: the step of a layer that bumps the normal of the layers above it
/// (LayerBase::kLayersAbove), shared by compositeGradient (object space) and shadeLayersInWorld
/// (world space), which differ only in the space its vectors are in.
#pragma once

#include "sgbake/core/vec.hpp"

namespace sgbake::gradient_detail {

/// @brief stackLayerGradient's step (see there) from the layer's weighted, masked Γ without its
/// Strength, @p gamma: the Γ after it, from @p gammaAbove, at unit normal @p n with unit
/// geometric normal @p ng. @p strength > 0. gammaAbove when anything is not finite.
Vec3d stackGradient(const Vec3d& gamma, double strength, const Vec3d& n, const Vec3d& ng,
                    const Vec3d& gammaAbove);

}  // namespace sgbake::gradient_detail
