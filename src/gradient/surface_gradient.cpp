#include "sgbake/gradient/surface_gradient.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "gradient/prepared_uv_frame.hpp"
#include "sgbake/core/math.hpp"

namespace sgbake {
using gradient_detail::finiteOrZero;
using gradient_detail::guardedTolerance;
using gradient_detail::unitAndLength;

double determinant(const Mat3& m) { return dot(cross(m.col[0], m.col[1]), m.col[2]); }

Mat3 cofactor(const Mat3& m) {
  return Mat3::fromColumns(cross(m.col[1], m.col[2]), cross(m.col[2], m.col[0]),
                           cross(m.col[0], m.col[1]));
}

Vec3d gradientFromUvDerivatives(const UvFrame& frame, Vec3d normal, Vec2d dhduv,
                                double minFrameSine) {
  return gradient_detail::gradientFromPreparedUvFrame(gradient_detail::prepareUvFrame(frame), normal,
                                                      dhduv, minFrameSine);
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

namespace {

/// The frame gradientFromTangentNormal decodes in (see there): T/L and B of the MikkTSpace frame
/// of the UV set, or of set 0, or the UV-derivative frame. False when there is none.
bool tangentNormalFrame(const SurfacePoint& point, int uvSet, const TangentNormalOptions& options,
                        Vec3d& tangent, Vec3d& bitangent) {
  // The MikkTSpace frame of the map's UV set, if the point has one (set 0's is point.tangent);
  // kMikkTSpace falls back on set 0's.
  const Vec3d* mikkTangent = nullptr;
  double mikkSign = 1;
  if (options.frame != TangentFrameChoice::kUvDerivatives) {
    if (uvSet > 0 && uvSet < kMaxUvSets &&
        point.hasUvTangentFrame[static_cast<std::size_t>(uvSet)]) {
      mikkTangent = &point.uvTangent[static_cast<std::size_t>(uvSet)];
      mikkSign = point.uvBitangentSign[static_cast<std::size_t>(uvSet)];
    } else if (point.hasTangentFrame &&
               (uvSet == 0 || options.frame == TangentFrameChoice::kMikkTSpace)) {
      mikkTangent = &point.tangent;
      mikkSign = point.bitangentSign;
    }
  }
  if (mikkTangent != nullptr) {
    // Blender's Normal Map node: normalize(x·T + y·B_i + z·N_i) with the unnormalized
    // interpolated normal N_i = L·N and B_i = sign · N_i × T (sign = interpolated sign < 0 ?
    // −1 : +1). Divided by L: x·T/L + y·B + z·N with B = sign · N × T, so T/L decodes.
    const double sign = mikkSign < 0 ? -1.0 : 1.0;
    bitangent = sign * cross(point.normal, *mikkTangent);
    tangent = (1 / point.normalLength) * *mikkTangent;
    return true;
  }
  if (uvSet < 0 || uvSet >= point.numUvSets || uvSet >= kMaxUvSets) return false;
  return uvDerivativeTangentFrame(point.uv[static_cast<std::size_t>(uvSet)], point.normal, tangent,
                                  bitangent, options.minFrameSine);
}

}  // namespace

Vec3d gradientFromTangentNormal(Vec3d n, const SurfacePoint& point, int uvSet,
                                const TangentNormalOptions& options) {
  // Tiling repeats the map without steepening it: Blender's Normal Map node decodes the texel
  // in the frame of the untiled UVs (a Mapping node only moves the lookup), and so does every
  // engine. (A height map's tiling does steepen its slopes: the heights are squeezed.)
  const Vec2d slopes = slopesFromTangentNormal(n, options.minNormalZ);
  Vec3d tangent, bitangent;
  if (!tangentNormalFrame(point, uvSet, options, tangent, bitangent)) return {};
  return withNormalMapStrength(finiteOrZero(gradientFromTangentFrame(slopes, tangent, bitangent)),
                               point.normal, options.strength);
}

Vec3d decodeTangentNormal(Vec3d n, const SurfacePoint& point, int uvSet,
                          const TangentNormalOptions& options) {
  Vec3d tangent, bitangent;
  if (!isFinite(n) || !tangentNormalFrame(point, uvSet, options, tangent, bitangent)) return {};
  return finiteOrZero(n.x * tangent + n.y * bitangent + n.z * point.normal);
}

Vec3d withNormalMapStrength(Vec3d gamma, Vec3d normal, double strength) {
  if (strength == 1) return gamma;
  if (!(strength > 0)) return {};  // Blender clamps Strength at 0 (and NaN is no bump)
  // n' = normalize(N − Γ) has a positive N component (Γ is tangent), so the blend has too.
  const Vec3d decoded = normalizeOr(normal - gamma, normal);
  const Vec3d blended = normal + strength * (decoded - normal);
  return finiteOrZero(gradientFromObjectNormal(blended, normal));
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
