/// @file triplanar_sum.hpp
/// @brief Private: the one loop over the planes of a triplanar lookup, which the triplanar
/// kernels, a projection's texel read (projectedTexel) and the Bump node's height reads share.
#pragma once

#include "sgbake/gradient/projection.hpp"

namespace sgbake::gradient_detail {

/// @brief Σ over triplanarPlanes(options, seenNormal) of term(mapping, P', st, weight), st being
/// the texture coordinates in that plane of P', object position @p position moved by
/// options.coordinates (once for all planes). Planes of weight 0 are not sampled at all.
template <class T, class Term>
T sumOverPlanes(const TriplanarOptions& options, Vec3d position, Vec3d seenNormal,
                const Term& term) {
  const Vec3d mapped = options.coordinates.apply(position);
  T sum{};
  for (const WeightedPlane& p : triplanarPlanes(options, seenNormal))
    sum += term(p.mapping, mapped, planarTextureCoordinates(mapped, p.mapping), p.weight);
  return sum;
}

}  // namespace sgbake::gradient_detail
