/// @file valid_reflection.hpp
/// @brief Private: Cycles' guard on bumped and normal-mapped shading normals, shared by the
/// layer composite (a layer that bumps the normal of the layers above it sees that normal
/// guarded, as a Bump node sees the output of the node before it) and the bake shaders (which
/// end with it).
#pragma once

#include <algorithm>
#include <cmath>

#include "sgbake/core/math.hpp"
#include "sgbake/core/vec.hpp"

namespace sgbake::gradient_detail {

/// @brief Whether unit @p n passes Cycles' valid-reflection test (validReflectionNormal) for
/// the unit geometric normal @p ng and the unit incoming direction @p incoming: the mirror
/// image R = 2⟨n, I⟩n − I of I rises above the surface by ⟨Ng, R⟩ ≥ min(0.9⟨Ng, I⟩, 0.01).
/// For n of squared length @p len2 (not unit) the same test scaled by it.
inline bool reflectsAboveSurface(const Vec3d& n, const Vec3d& ng, const Vec3d& incoming,
                                 double len2 = 1) {
  const double iz = dot(incoming, ng);
  return 2 * dot(n, incoming) * dot(n, ng) - iz * len2 >= std::min(0.9 * iz, 0.01) * len2;
}

/// @brief Cycles' guard on a bumped or normal-mapped shading normal (its Bump and Normal Map
/// nodes end with it; at a bake the incoming direction I is the unit shading normal): unit
/// @p n is kept when reflectsAboveSurface, otherwise turned in the plane of n and Ng to the
/// nearest tilt whose reflection rises exactly by t = min(0.9⟨Ng, I⟩, 0.01).
///
/// In the plane, with X the unit direction of n's part across Ng and I's components (Ix, Iz)
/// along (X, Ng), the normal sinθ·X + cosθ·Ng reflects I to ⟨Ng, R⟩ = Ix·sin2θ + Iz·cos2θ =
/// a·cos(2θ − φ), a = |(Ix, Iz)|, φ = atan2(Ix, Iz): the tilts with ⟨Ng, R⟩ ≥ t are
/// |2θ − φ| ≤ acos(t/a). For I = Ng the largest is acos(0.01)/2 = 44.71° from Ng. Ng itself
/// when no tilt reaches t (or n lies along Ng).
inline Vec3d validReflectionNormal(const Vec3d& n, const Vec3d& ng, const Vec3d& incoming) {
  if (reflectsAboveSurface(n, ng, incoming)) return n;
  const double threshold = std::min(0.9 * dot(incoming, ng), 0.01);
  const double nz = dot(n, ng);
  const Vec3d across = n - nz * ng;
  const double acrossLength = std::sqrt(lengthSquared(across));
  if (!(acrossLength > 0)) return ng;
  const Vec3d x = (1 / acrossLength) * across;
  const double ix = dot(incoming, x), iz = dot(incoming, ng);
  const double a = std::sqrt(ix * ix + iz * iz);
  if (!(a > 0) || !(threshold <= a)) return ng;
  const double phi = std::atan2(ix, iz);
  const double half = std::acos(std::max(threshold / a, -1.0));
  const double tilt = std::atan2(acrossLength, nz);
  const double theta = tilt > phi / 2 ? 0.5 * (phi + half) : 0.5 * (phi - half);
  if (!(std::cos(theta) > 0)) return ng;
  return std::sin(theta) * x + std::cos(theta) * ng;
}

}  // namespace sgbake::gradient_detail
