#include "sgbake/gradient/surface_gradient.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "sgbake/core/math.hpp"

namespace sgbake {
namespace {

/// Smallest tolerance any relative guard is allowed to take: a caller passing 0 (or a negative
/// or NaN value) gets machine epsilon, so divisions by the guarded quantity stay finite.
constexpr double kToleranceFloor = std::numeric_limits<double>::epsilon();

double guardedTolerance(double tolerance) {
  return tolerance > kToleranceFloor ? tolerance : kToleranceFloor;  // NaN → floor
}

/// Length of @p a and its unit direction, without overflow or underflow for any finite input
/// (the vector is scaled by its largest component first). Returns 0 (and a zero unit vector)
/// for a zero or non-finite vector.
double unitAndLength(Vec3d a, Vec3d& unit) {
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
Vec3d finiteOrZero(Vec3d gamma) { return isFinite(gamma) ? gamma : Vec3d{}; }

}  // namespace

double determinant(const Mat3& m) { return dot(cross(m.col[0], m.col[1]), m.col[2]); }

Mat3 cofactor(const Mat3& m) {
  return Mat3::fromColumns(cross(m.col[1], m.col[2]), cross(m.col[2], m.col[0]),
                           cross(m.col[0], m.col[1]));
}

Vec3d gradientFromUvDerivatives(const UvFrame& frame, Vec3d normal, Vec2d dhduv,
                                double minFrameSine) {
  Vec3d t, b;
  const double lengthT = unitAndLength(frame.dPdu, t);
  const double lengthB = unitAndLength(frame.dPdv, b);
  if (lengthT == 0 || lengthB == 0) return {};
  // ⟨T̂ × B̂, N⟩: sine of the angle between the derivatives times the cosine to N (scale-free).
  const double det = dot(cross(t, b), normal);
  if (!(std::abs(det) >= guardedTolerance(minFrameSine))) return {};
  // Eq. 31 with T = |T|·T̂, B = |B|·B̂: the lengths cancel into the derivatives.
  const double du = dhduv.x / lengthT, dv = dhduv.y / lengthB;
  return finiteOrZero((1 / det) * (du * cross(b, normal) + dv * cross(normal, t)));
}

Vec2d slopesFromTangentNormal(Vec3d n, double minNormalZ) {
  if (!isFinite(n)) return {};
  Vec3d unit;
  const double len = unitAndLength(n, unit);
  if (len == 0) return {};
  // Work on the unit vector: the clamp is relative, and the slopes do not depend on the length.
  const double z = std::max(unit.z, std::min(guardedTolerance(minNormalZ), 1.0));
  return {-unit.x / z, -unit.y / z};
}

bool uvDerivativeTangentFrame(const UvFrame& frame, Vec3d normal, Vec3d& tangent, Vec3d& bitangent,
                              double minFrameSine) {
  tangent = {};
  bitangent = {};
  Vec3d t, b;
  if (unitAndLength(frame.dPdu, t) == 0 || unitAndLength(frame.dPdv, b) == 0) return false;
  const double det = dot(cross(t, b), normal);
  if (!(std::abs(det) >= guardedTolerance(minFrameSine))) return false;
  // |T̂ − ⟨T̂,N⟩N| ≥ |⟨T̂ × B̂, N⟩| ≥ minFrameSine > 0, so this normalization is safe.
  Vec3d projected;
  if (unitAndLength(t - dot(t, normal) * normal, projected) == 0) return false;
  tangent = projected;
  bitangent = (det < 0 ? -1.0 : 1.0) * cross(normal, projected);
  return true;
}

Vec3d gradientFromTangentNormal(Vec3d n, const SurfacePoint& point, int uvSet,
                                const TangentNormalOptions& options) {
  const Vec2d s = slopesFromTangentNormal(n, options.minNormalZ);
  const Vec2d slopes{options.strength * options.tiling.x * s.x,
                     options.strength * options.tiling.y * s.y};

  const bool mikk =
      point.hasTangentFrame && (options.frame == TangentFrameChoice::kMikkTSpace ||
                                (options.frame == TangentFrameChoice::kAuto && uvSet == 0));
  if (mikk) {
    // Blender: B = sign · N × T with sign = (interpolated sign < 0 ? −1 : +1).
    const double sign = point.bitangentSign < 0 ? -1.0 : 1.0;
    const Vec3d bitangent = sign * cross(point.normal, point.tangent);
    return finiteOrZero(gradientFromTangentFrame(slopes, point.tangent, bitangent));
  }
  if (uvSet < 0 || uvSet >= point.numUvSets || uvSet >= kMaxUvSets) return {};
  Vec3d tangent, bitangent;
  if (!uvDerivativeTangentFrame(point.uv[static_cast<std::size_t>(uvSet)], point.normal, tangent,
                                bitangent, options.minFrameSine)) {
    return {};
  }
  return finiteOrZero(gradientFromTangentFrame(slopes, tangent, bitangent));
}

Vec3d gradientFromObjectNormal(Vec3d objectNormal, Vec3d normal, double minCosine) {
  if (!isFinite(objectNormal)) return {};
  Vec3d v;
  if (unitAndLength(objectNormal, v) == 0) return {};
  const double k = dot(v, normal);
  const double divisor = std::max(std::abs(k), std::min(guardedTolerance(minCosine), 1.0));
  return (1 / divisor) * (k * normal - v);
}

Vec3d resolveNormal(Vec3d normal, Vec3d gamma, const Mat3& objectScaleCofactor) {
  const Vec3d unperturbed = normalizeOr(objectScaleCofactor * normal, normal);
  return normalizeOr(objectScaleCofactor * (normal - gamma), unperturbed);
}

}  // namespace sgbake
