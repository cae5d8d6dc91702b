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

/// @brief Cycles' guard's bounds (validReflectionNormal, its 1e-5f and 1.0f + 1e-5f in float): a
/// root cos²θ counts when kGuardEpsilon < cos²θ ≤ kGuardCosine2Max, a reflection rises when
/// ⟨Ng, R⟩ ≥ kGuardEpsilon.
inline constexpr double kGuardEpsilon = static_cast<double>(1e-5f);
inline constexpr double kGuardCosine2Max = static_cast<double>(1.0f + 1e-5f);

/// @brief Cycles' guard on a bumped or normal-mapped shading normal (ensure_valid_reflection
/// of Blender 3.4, which its Bump and Normal Map nodes and closures end with; at a bake the
/// incoming direction I is the unit shading normal), in double: unit @p n is kept when
/// reflectsAboveSurface, otherwise replaced by a unit normal in the plane of n and Ng,
/// sinθ·X + cosθ·Ng with X the unit direction of n's part across Ng.
///
/// With I's components (Ix, Iz) along (X, Ng), a = Ix² + Iz² and t = min(0.9⟨Ng, I⟩, 0.01),
/// such a normal reflects I to ⟨Ng, R⟩ = 2(sinθ·Ix + cosθ·Iz)cosθ − Iz, and Cycles solves
/// ⟨Ng, R⟩ = t for cos²θ, squared: cos²θ = (c ± b)/(2a), b = √(Ix²(a − t²)), c = Iz·t + a
/// (the angle form: tilts θ = (φ ± acos(t/√a))/2, φ = atan2(Ix, Iz), folded into [0°, 90°]).
/// A root counts when kGuardEpsilon < cos²θ ≤ kGuardCosine2Max (θ below 89.82°). Of two, it
/// computes each one's ⟨Ng, R⟩ and takes the lower when both rise by at least 1e-5 (squaring
/// admits a root that does not reach t), else the higher, the second on a tie; of one, that one;
/// of none, Ng. For I = Ng the largest tilt is acos(0.01)/2 = 44.71° from Ng.
///
/// What this differs in from turning n to the nearest tilt that reaches t: when I lies within
/// about 0.2° of the tangent plane (⟨Ng, I⟩ below ~0.0033) and n far enough from Ng that the
/// nearest such tilt is beyond 89.82°, Cycles drops that root and returns the other one, close
/// to Ng: the bake's normal turns by ~90° (BlenderBakeOracle sphere_backfacing: 60 texels at 90°,
/// stretch_sphere_backfacing: up to 117°, where a custom normal leaning ~90° meets its triangle
/// edge-on and the Bump node's determinant, ⟨N, dP.dx × dP.dy⟩, is near zero).
inline Vec3d validReflectionNormal(const Vec3d& n, const Vec3d& ng, const Vec3d& incoming) {
  if (reflectsAboveSurface(n, ng, incoming)) return n;
  const double threshold = std::min(0.9 * dot(incoming, ng), 0.01);
  const Vec3d across = n - dot(n, ng) * ng;
  const double acrossLength = std::sqrt(lengthSquared(across));
  if (!(acrossLength > 0)) return ng;  // Cycles normalizes a zero vector: NaN, no root counts
  const Vec3d x = (1 / acrossLength) * across;
  const double ix = dot(incoming, x), iz = dot(incoming, ng);
  const double ix2 = ix * ix;
  const double a = ix2 + iz * iz;
  if (!(a > 0)) return ng;
  const double b = std::sqrt(std::max(ix2 * (a - threshold * threshold), 0.0));
  const double c = iz * threshold + a;
  const double fac = 0.5 / a;
  const double z2[2] = {fac * (b + c), fac * (c - b)};
  bool valid[2];
  for (int k = 0; k < 2; ++k) valid[k] = z2[k] > kGuardEpsilon && z2[k] <= kGuardCosine2Max;
  const auto unitIn = [](double v) { return std::sqrt(std::max(v, 0.0)); };
  double sinTheta, cosTheta;
  if (valid[0] && valid[1]) {
    double s[2], r[2];
    for (int k = 0; k < 2; ++k) {
      s[k] = unitIn(1 - z2[k]);
      const double z = unitIn(z2[k]);
      r[k] = 2 * (s[k] * ix + z * iz) * z - iz;
    }
    const bool rise0 = r[0] >= kGuardEpsilon, rise1 = r[1] >= kGuardEpsilon;
    const int k = (rise0 && rise1) ? (r[0] < r[1] ? 0 : 1) : (r[0] > r[1] ? 0 : 1);
    sinTheta = s[k];
    cosTheta = unitIn(z2[k]);
  } else if (valid[0] || valid[1]) {
    const double z = valid[0] ? z2[0] : z2[1];
    sinTheta = unitIn(1 - z);
    cosTheta = unitIn(z);
  } else {
    return ng;
  }
  return sinTheta * x + cosTheta * ng;
}

}  // namespace sgbake::gradient_detail
