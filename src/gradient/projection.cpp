#include "sgbake/gradient/projection.hpp"

#include <algorithm>
#include <cmath>

#include "sgbake/core/math.hpp"

namespace sgbake {
namespace {

constexpr std::array<ProjectionAxis, 3> kAxes{ProjectionAxis::kX, ProjectionAxis::kY,
                                              ProjectionAxis::kZ};

constexpr std::size_t index(ProjectionAxis axis) { return static_cast<std::size_t>(axis); }

/// Slopes (∂h/∂s, ∂h/∂t) per texture unit of a tangent-space texel read in a plane's frame.
Vec2d planeSlopes(const VectorTexture& texture, Vec2d st, const ProjectedNormalOptions& options) {
  return slopesFromTangentNormal(decodeNormalTexel(texture.sample(st), options.green),
                                 options.minNormalZ);
}

/// Γ as computed, or 0 when it overflowed (absurd scales) or met a NaN input.
Vec3d finiteOrZero(Vec3d gamma) { return isFinite(gamma) ? gamma : Vec3d{}; }

}  // namespace

PlaneAxes planeAxes(ProjectionAxis axis) {
  switch (axis) {
    case ProjectionAxis::kX:
      return {{0, 1, 0}, {0, 0, 1}, {1, 0, 0}};
    case ProjectionAxis::kY:
      return {{0, 0, 1}, {1, 0, 0}, {0, 1, 0}};
    case ProjectionAxis::kZ:
      break;
  }
  return {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
}

Vec2d planeCoordinates(Vec3d position, ProjectionAxis axis) {
  switch (axis) {
    case ProjectionAxis::kX:
      return {position.y, position.z};
    case ProjectionAxis::kY:
      return {position.z, position.x};
    case ProjectionAxis::kZ:
      break;
  }
  return {position.x, position.y};
}

Vec2d planarTextureCoordinates(Vec3d position, const PlanarMapping& mapping) {
  return textureCoordinates(planeCoordinates(position, mapping.axis), mapping.tiling,
                            mapping.offset);
}

Vec3d planeVolumeGradient(Vec2d dhdst, const PlanarMapping& mapping, double scale) {
  const PlaneAxes axes = planeAxes(mapping.axis);
  return (scale * mapping.tiling.x * dhdst.x) * axes.s +
         (scale * mapping.tiling.y * dhdst.y) * axes.t;
}

Vec3d planarHeightGradient(const ScalarTexture& texture, const PlanarMapping& mapping, double scale,
                           const SurfacePoint& point) {
  const ScalarSample h = texture.sample(planarTextureCoordinates(point.position, mapping));
  return finiteOrZero(projectOntoTangentPlaneAlong(planeVolumeGradient(h.gradient, mapping, scale),
                                                   point.normal, point.geometricNormal));
}

Vec3d planarTangentNormalGradient(const VectorTexture& texture, const PlanarMapping& mapping,
                                  double strength, const SurfacePoint& point,
                                  const ProjectedNormalOptions& options) {
  const Vec2d slopes =
      planeSlopes(texture, planarTextureCoordinates(point.position, mapping), options);
  return finiteOrZero(
      projectOntoTangentPlane(planeVolumeGradient(slopes, mapping, strength), point.normal));
}

Vec3d planarObjectNormalGradient(const VectorTexture& texture, const PlanarMapping& mapping,
                                 double strength, const SurfacePoint& point,
                                 const ProjectedNormalOptions& options) {
  const Vec3d n =
      decodeNormalTexel(texture.sample(planarTextureCoordinates(point.position, mapping)));
  return finiteOrZero(strength * gradientFromObjectNormal(n, point.normal, options.minCosine));
}

TriplanarWeights triplanarWeights(Vec3d normal, double sharpness, double minWeight) {
  TriplanarWeights result;
  if (!isFinite(normal)) return result;
  const Vec3d a{std::abs(normal.x), std::abs(normal.y), std::abs(normal.z)};
  const double largest = std::max({a.x, a.y, a.z});
  if (!(largest > 0)) return result;
  const double exponent = sharpness > 0 ? sharpness : 0.0;  // NaN → 0
  const double threshold = std::clamp(minWeight > 0 ? minWeight : 0.0, 0.0, 1.0 / 3.0);

  // Ratios to the largest component: the dominant plane gets exactly 1, nothing overflows, and
  // the sum lies in [1, 3], so the division below is safe.
  std::array<double, 3> w{};
  double sum = 0;
  for (std::size_t i = 0; i < 3; ++i) {
    w[i] = std::pow(a[i] / largest, exponent);
    sum += w[i];
  }
  double kept = 0;
  for (std::size_t i = 0; i < 3; ++i) {
    w[i] /= sum;
    if (w[i] < threshold) w[i] = 0;
    kept += w[i];
  }
  for (std::size_t i = 0; i < 3; ++i) {
    result.w[i] = w[i] / kept;  // kept ≥ the dominant weight ≥ 1/3
    if (result.w[i] > 0) ++result.active;
  }
  return result;
}

namespace {

/// Σ over the planes with a nonzero triplanar weight w of plane(mapping, st, w · scale), st being
/// the point's texture coordinates in that plane: the loop the three triplanar kinds share.
/// Planes below the weight threshold are not sampled at all.
template <class PlaneTerm>
Vec3d sumOverPlanes(const TriplanarOptions& options, const SurfacePoint& point,
                    const PlaneTerm& plane) {
  const TriplanarWeights weights =
      triplanarWeights(point.normal, options.sharpness, options.minWeight);
  Vec3d sum{};
  for (const ProjectionAxis axis : kAxes) {
    const double w = weights.w[index(axis)];
    if (w == 0) continue;
    const PlanarMapping mapping{axis, options.tiling, options.offset};
    sum += plane(mapping, planarTextureCoordinates(point.position, mapping), w * options.scale);
  }
  return sum;
}

}  // namespace

Vec3d triplanarHeightGradient(const ScalarTexture& texture, const TriplanarOptions& options,
                              const SurfacePoint& point) {
  const Vec3d volumeGradient = sumOverPlanes(
      options, point, [&](const PlanarMapping& mapping, Vec2d st, double weightedScale) {
        return planeVolumeGradient(texture.sample(st).gradient, mapping, weightedScale);
      });
  return finiteOrZero(
      projectOntoTangentPlaneAlong(volumeGradient, point.normal, point.geometricNormal));
}

Vec3d triplanarTangentNormalGradient(const VectorTexture& texture, const TriplanarOptions& options,
                                     const SurfacePoint& point) {
  const Vec3d volumeGradient = sumOverPlanes(
      options, point, [&](const PlanarMapping& mapping, Vec2d st, double weightedScale) {
        return planeVolumeGradient(planeSlopes(texture, st, options.normal), mapping, weightedScale);
      });
  return finiteOrZero(projectOntoTangentPlane(volumeGradient, point.normal));
}

Vec3d triplanarObjectNormalGradient(const VectorTexture& texture, const TriplanarOptions& options,
                                    const SurfacePoint& point) {
  return finiteOrZero(sumOverPlanes(
      options, point, [&](const PlanarMapping&, Vec2d st, double weightedScale) {
        const Vec3d n = decodeNormalTexel(texture.sample(st));
        return weightedScale * gradientFromObjectNormal(n, point.normal, options.normal.minCosine);
      }));
}

}  // namespace sgbake
