/// @file prepared_uv_frame.hpp
/// @brief Private: gradientFromUvDerivatives (surface_gradient.hpp, eq. 31) split into the part
/// that depends only on ∂P/∂u, ∂P/∂v (constant over a triangle) and the part that depends on the
/// normal and the height derivatives (per sample).
///
/// gradientFromUvDerivatives is prepareUvFrame followed by gradientFromPreparedUvFrame, so a
/// caller that prepares a triangle's frames once (the baker) gets bitwise the same Γ as one that
/// calls gradientFromUvDerivatives per sample.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

#include "sgbake/core/math.hpp"
#include "sgbake/gradient/surface_point.hpp"

namespace sgbake::gradient_detail {

/// Smallest tolerance any relative guard is allowed to take: a caller passing 0 (or a negative
/// or NaN value) gets machine epsilon, so divisions by the guarded quantity stay finite.
inline constexpr double kToleranceFloor = std::numeric_limits<double>::epsilon();

inline double guardedTolerance(double tolerance) {
  return tolerance > kToleranceFloor ? tolerance : kToleranceFloor;  // NaN → floor
}

/// Length of @p a and its unit direction, without overflow or underflow for any finite input
/// (the vector is scaled by its largest component first). Returns 0 (and a zero unit vector)
/// for a zero or non-finite vector.
inline double unitAndLength(Vec3d a, Vec3d& unit) {
  const double m = std::max({std::abs(a.x), std::abs(a.y), std::abs(a.z)});
  if (!(m > 0) || !std::isfinite(m)) {
    unit = {};
    return 0;
  }
  const Vec3d scaled = (1 / m) * a;
  const double l = std::sqrt(lengthSquared(scaled));
  unit = (1 / l) * scaled;
  return m * l;
}

/// Γ as computed, or 0 when it overflowed (absurd scales) or met a NaN input.
inline Vec3d finiteOrZero(Vec3d gamma) { return isFinite(gamma) ? gamma : Vec3d{}; }

/// @brief The normal-independent terms of eq. 31 for one UV frame: T̂ = ∂P/∂u / |∂P/∂u|,
/// B̂ = ∂P/∂v / |∂P/∂v|, their lengths and T̂ × B̂.
struct PreparedUvFrame {
  Vec3d t{}, b{}, tCrossB{};
  double lengthT = 0, lengthB = 0;
  bool valid = false;  ///< both derivatives are nonzero and finite
};

/// @brief Prepares @p frame's ∂P/∂u, ∂P/∂v (its uv is not used).
inline PreparedUvFrame prepareUvFrame(const UvFrame& frame) {
  PreparedUvFrame p;
  p.lengthT = unitAndLength(frame.dPdu, p.t);
  p.lengthB = unitAndLength(frame.dPdv, p.b);
  p.valid = p.lengthT != 0 && p.lengthB != 0;
  if (p.valid) p.tCrossB = cross(p.t, p.b);
  return p;
}

/// @brief gradientFromUvDerivatives for a prepared frame (same arguments otherwise).
inline Vec3d gradientFromPreparedUvFrame(const PreparedUvFrame& frame, Vec3d normal, Vec2d dhduv,
                                         double minFrameSine) {
  if (!frame.valid) return {};
  // ⟨T̂ × B̂, N⟩: sine of the angle between the derivatives times the cosine to N (scale-free).
  const double det = dot(frame.tCrossB, normal);
  if (!(std::abs(det) >= guardedTolerance(minFrameSine))) return {};
  // Eq. 31 with T = |T|·T̂, B = |B|·B̂: the lengths cancel into the derivatives.
  const double du = dhduv.x / frame.lengthT, dv = dhduv.y / frame.lengthB;
  return finiteOrZero((1 / det) * (du * cross(frame.b, normal) + dv * cross(normal, frame.t)));
}

}  // namespace sgbake::gradient_detail
