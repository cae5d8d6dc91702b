// Heights differenced as Blender's Bump node does when Cycles bakes (HeightGradient::kBumpNode):
// the offsets a bake texel gives, exactness on affine heights, first-order convergence to the
// exact surface gradient, and the exact gradient where a point has no offsets.

#include "gradient/bump_node.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "sgbake/core/math.hpp"
#include "sgbake/gradient/layers.hpp"
#include "sgbake/gradient/volume.hpp"
#include "support/analytic_textures.hpp"
#include "support/surface_points.hpp"

namespace sgbake {
namespace {

using gradient_detail::bakeBumpOffsets;
using test::AnalyticHeight;
using test::maxAbsDiff;
using test::samplePoint;

template <class Source>
Vec3d heightGradient(const Source& s, const SurfacePoint& p) {
  return layerGradient(LayerSource{s}, p);
}

TEST(BumpNode, OffsetsAreCyclesOrthonormalsOfNgSpanningHalfATexel) {
  // Ng = ẑ: Cycles' first orthonormal is (1, 1, 1) × ẑ normalized, the second ẑ × that.
  const Vec3d dPdu{4, 0, 0}, dPdv{0, 2, 0};
  const BumpOffsets flat = bakeBumpOffsets({0, 0, 1}, dPdu, dPdv, {1.0 / 64, 1.0 / 32});
  // r = ½ (½·4/64 + ½·2/32) = 1/32.
  const double r = 1.0 / 32, h = r / std::sqrt(2.0);
  EXPECT_LT(maxAbsDiff(flat.dx, {h, -h, 0}), 1e-15);
  EXPECT_LT(maxAbsDiff(flat.dy, {h, h, 0}), 1e-15);

  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int i = 0; i < 100; ++i) {
    const Vec3d a{u(rng), u(rng), u(rng)}, b{u(rng), u(rng), u(rng)};
    const Vec3d ng = normalizeOr(cross(a, b), Vec3d{0, 0, 1});
    const BumpOffsets o = bakeBumpOffsets(ng, a, b, {1.0 / 512, 1.0 / 256});
    const double expected = 0.5 * (0.5 * length(a) / 512 + 0.5 * length(b) / 256);
    EXPECT_NEAR(length(o.dx), expected, 1e-15);
    EXPECT_NEAR(length(o.dy), expected, 1e-15);
    EXPECT_NEAR(dot(o.dx, ng), 0, 1e-15);
    EXPECT_NEAR(dot(o.dy, ng), 0, 1e-15);
    EXPECT_NEAR(dot(o.dx, o.dy), 0, 1e-15);
    EXPECT_GT(dot(cross(o.dx, o.dy), ng), 0);  // (dx, dy, Ng) right-handed, as Cycles' are
  }
  // All components equal: the other axis, still orthogonal.
  const Vec3d diagonal = normalizeOr(Vec3d{1, 1, 1}, Vec3d{});
  const BumpOffsets d = bakeBumpOffsets(diagonal, {1, 0, 0}, {0, 1, 0}, {0.5, 0.5});
  EXPECT_GT(length(d.dx), 0);
  EXPECT_NEAR(dot(d.dx, diagonal), 0, 1e-15);
  // A collapsed UV map: no offsets.
  EXPECT_TRUE(bakeBumpOffsets({0, 0, 1}, {0, 0, 0}, {0, 0, 0}, {0.5, 0.5}).empty());
}

TEST(BumpNode, AffineHeightsAreDifferencedExactly) {
  std::mt19937_64 rng(11);
  const AnalyticHeight affine(0.7, -0.4, 0);
  for (int i = 0; i < 50; ++i) {
    SurfacePoint p = samplePoint(rng);
    UvHeightSource s{&affine, i % 2, 0.3, {1.5, 0.5}, {0.1, 0}};
    const Vec3d exact = heightGradient(s, p);
    p.bump = bakeBumpOffsets(p.normal, p.uv[0].dPdu, p.uv[0].dPdv, {1.0 / 64, 1.0 / 64});
    s.gradient = HeightGradient::kBumpNode;
    EXPECT_LT(maxAbsDiff(heightGradient(s, p), exact), 1e-12 * (1 + length(exact)));
    // Seen from behind it reads the heights on the other side: still exact.
    EXPECT_LT(maxAbsDiff(heightGradient(s, gradient_detail::seenFromBehind(p)), exact),
              1e-12 * (1 + length(exact)));
  }
}

TEST(BumpNode, CurvedHeightsConvergeToTheExactGradientToFirstOrder) {
  std::mt19937_64 rng(3);
  const AnalyticHeight curved(0.2, 0.1, 0.05);
  for (int i = 0; i < 50; ++i) {
    SurfacePoint p = samplePoint(rng);
    UvHeightSource s{&curved, 0, 0.5};
    const Vec3d exact = heightGradient(s, p);
    s.gradient = HeightGradient::kBumpNode;
    double error[2];
    for (const int k : {0, 1}) {
      const double texel = k == 0 ? 1.0 / 128 : 1.0 / 2048;
      p.bump = bakeBumpOffsets(p.normal, p.uv[0].dPdu, p.uv[0].dPdv, {texel, texel});
      error[k] = length(heightGradient(s, p) - exact);
    }
    // 16 times smaller steps: about 16 times smaller errors (forward differences).
    EXPECT_LT(error[1], error[0] / 8 + 1e-12) << i;
    EXPECT_LT(error[1], 1e-3) << i;  // |Γ| is ~0.1 here
  }
}

// Heights read at positions: a planar projection of an affine height is differenced exactly,
// on triangles whose N leans from Ng too (the node's slopes along the triangle's plane), and
// from behind; a volume converges to its exact Γ to first order.
TEST(BumpNode, HeightsReadAtPositionsAreDifferencedAlongTheTrianglesPlane) {
  std::mt19937_64 rng(13);
  std::uniform_real_distribution<double> u(-1, 1);
  const AnalyticHeight affine(0.7, -0.4, 0);
  auto sine = DirectionalSine::create({0.2, 1.5, {1, 2, 3}, 0.3});
  ASSERT_TRUE(sine.ok());
  for (int i = 0; i < 50; ++i) {
    SurfacePoint p = samplePoint(rng);
    const Vec3d ng = p.normal;
    p.geometricNormal = ng;
    p.normal = normalizeOr(ng + 0.5 * Vec3d{u(rng), u(rng), u(rng)}, ng);
    PlanarSource planar;
    planar.height = &affine;
    planar.mapping = {ProjectionAxis::kY, {1.5, 0.5}, {0.1, 0}};
    planar.scale = 0.3;
    const Vec3d exact = heightGradient(planar, p);
    planar.gradient = HeightGradient::kBumpNode;
    p.bump = bakeBumpOffsets(ng, p.uv[0].dPdu, p.uv[0].dPdv, {1.0 / 64, 1.0 / 64});
    EXPECT_LT(maxAbsDiff(heightGradient(planar, p), exact), 1e-12 * (1 + length(exact))) << i;
    // From behind it reads at −dx, +dy; on an affine height that changes nothing.
    EXPECT_LT(maxAbsDiff(heightGradient(planar, gradient_detail::seenFromBehind(p)), exact),
              1e-12 * (1 + length(exact)))
        << i;

    VolumeSource volume{&*sine, GradientScheme::kAnalytic, 0, 0.5};
    const Vec3d volumeExact = heightGradient(volume, p);
    volume.gradient = HeightGradient::kBumpNode;
    double error[2];
    for (const int k : {0, 1}) {
      const double texel = k == 0 ? 1.0 / 128 : 1.0 / 2048;
      p.bump = bakeBumpOffsets(ng, p.uv[0].dPdu, p.uv[0].dPdv, {texel, texel});
      error[k] = length(heightGradient(volume, p) - volumeExact);
    }
    EXPECT_LT(error[1], error[0] / 8 + 1e-12) << i;
  }
}

TEST(BumpNode, APointWithoutOffsetsIsDifferentiatedExactly) {
  std::mt19937_64 rng(5);
  const AnalyticHeight curved(0.2, 0.1, 0.05);
  const SurfacePoint p = samplePoint(rng);
  ASSERT_TRUE(p.bump.empty());
  UvHeightSource s{&curved, 1, 0.5};
  const Vec3d exact = heightGradient(s, p);
  s.gradient = HeightGradient::kBumpNode;
  const Vec3d same = heightGradient(s, p);
  EXPECT_EQ(same.x, exact.x);
  EXPECT_EQ(same.y, exact.y);
  EXPECT_EQ(same.z, exact.z);
}

}  // namespace
}  // namespace sgbake
