/// @file surface_points.hpp
/// @brief Test support: random SurfacePoints on sheared, tilted frames.
#pragma once

#include <random>

#include "sgbake/core/math.hpp"
#include "sgbake/gradient/surface_point.hpp"

namespace sgbake::test {

/// A point with two UV sets on a sheared, tilted frame and a MikkTSpace frame.
inline SurfacePoint samplePoint(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  SurfacePoint p;
  p.position = {u(rng), u(rng), u(rng)};
  const Vec3d dPdu{1 + 0.3 * u(rng), 0.2 * u(rng), 0.3 * u(rng)};
  const Vec3d dPdv{0.2 * u(rng), 1 + 0.3 * u(rng), 0.3 * u(rng)};
  p.normal = normalizeOr(cross(dPdu, dPdv), Vec3d{0, 0, 1});
  p.numUvSets = 2;
  p.uv[0] = {{u(rng), u(rng)}, dPdu, dPdv};
  p.uv[1] = {{u(rng), u(rng)}, 2.0 * dPdv, -0.5 * dPdu};
  p.tangent = normalizeOr(dPdu - dot(dPdu, p.normal) * p.normal, Vec3d{1, 0, 0});
  p.bitangentSign = 1;
  p.hasTangentFrame = true;
  return p;
}

}  // namespace sgbake::test
