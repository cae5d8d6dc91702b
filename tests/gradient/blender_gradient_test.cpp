/// @file blender_gradient_test.cpp
/// @brief Blender's Gradient Texture's Fac as a volume: its seven types, Cycles' clamps, the
/// points where it is not differentiable, and its exact gradient. (Its values against Cycles'
/// own are checked by BlenderTextureFacOracle.)
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "sgbake/core/math.hpp"
#include "sgbake/gradient/blender_noise.hpp"
#include "support/analytic_textures.hpp"

namespace sgbake {
namespace {

using test::centralGradient;
using test::maxAbsDiff;
using Type = BlenderGradientType;

constexpr Type kTypes[] = {Type::kLinear,    Type::kQuadratic,       Type::kEasing, Type::kDiagonal,
                           Type::kSpherical, Type::kQuadraticSphere, Type::kRadial};

BlenderGradient makeGradient(Type type, double amplitude = 1) {
  return test::created(BlenderGradient::create({.amplitude = amplitude, .type = type}));
}

double fac(Type type, Vec3d p) { return makeGradient(type).output(p, nullptr); }
Vec3d slope(Type type, Vec3d p) {
  Vec3d g;
  makeGradient(type).output(p, &g);
  return g;
}

// Each type's formula, inside its clamps and beyond them.
TEST(BlenderGradient, IsEachTypesFormulaClampedToZeroAndOne) {
  const double nudge = 0.999999f;  // Cycles' float
  EXPECT_EQ(fac(Type::kLinear, {0.3, 5, -7}), 0.3);
  EXPECT_EQ(fac(Type::kLinear, {-0.5, 0, 0}), 0);
  EXPECT_EQ(fac(Type::kLinear, {1.7, 0, 0}), 1);
  EXPECT_EQ(fac(Type::kQuadratic, {0.5, 2, 0}), 0.25);
  EXPECT_EQ(fac(Type::kQuadratic, {-0.5, 0, 0}), 0);
  EXPECT_EQ(fac(Type::kQuadratic, {1.2, 0, 0}), 1);
  EXPECT_EQ(fac(Type::kEasing, {0.5, 0, 0}), 0.5);
  EXPECT_NEAR(fac(Type::kEasing, {0.25, 0, 0}), 3 * 0.0625 - 2 * 0.015625, 1e-15);
  EXPECT_EQ(fac(Type::kEasing, {1.5, 0, 0}), 1);
  EXPECT_NEAR(fac(Type::kDiagonal, {0.2, 0.4, 9}), 0.3, 1e-15);
  EXPECT_EQ(fac(Type::kDiagonal, {1.2, 1.4, 0}), 1);
  EXPECT_NEAR(fac(Type::kSpherical, {0.3, 0.4, 0}), nudge - 0.5, 1e-15);
  EXPECT_NEAR(fac(Type::kQuadraticSphere, {0, 0.3, 0.4}), (nudge - 0.5) * (nudge - 0.5), 1e-15);
  EXPECT_EQ(fac(Type::kSpherical, {1, 0, 0}), 0);  // the nudge: exactly 0 on the unit sphere
  EXPECT_EQ(fac(Type::kQuadraticSphere, {0.8, 0.8, 0}), 0);
  EXPECT_EQ(fac(Type::kRadial, {1, 0, 3}), 0.5);
  EXPECT_NEAR(fac(Type::kRadial, {0, 2, 0}), 0.75, 1e-15);
  EXPECT_NEAR(fac(Type::kRadial, {0, -2, 0}), 0.25, 1e-15);
  // Its cut: atan2 is π on the half-plane y = +0, x < 0, and −π just below it.
  EXPECT_EQ(fac(Type::kRadial, {-1, 0, 0}), 1);
  EXPECT_EQ(fac(Type::kRadial, {-1, -0.0, 0}), 0);
  EXPECT_NEAR(fac(Type::kRadial, {-1, -1e-9, 0}), 0, 1e-9);
  // The amplitude scales the height.
  EXPECT_NEAR(makeGradient(Type::kLinear, -0.4).value({0.3, 0, 0}), -0.12, 1e-15);
}

// Where a clamp holds the Fac (its bounds included) the gradient is 0; so it is at the
// spheres' centre (their apex) and on Radial's axis, where the Fac is ½ (atan2(0, 0) = 0).
TEST(BlenderGradient, ItsGradientIsZeroWhereClampedAndAtDegeneratePoints) {
  const Vec3d zero{};
  EXPECT_EQ(slope(Type::kLinear, {-0.3, 0, 0}), zero);
  EXPECT_EQ(slope(Type::kLinear, {1.3, 0, 0}), zero);
  EXPECT_EQ(slope(Type::kLinear, {0, 0.5, 0}), zero);  // on the bound: clamped
  EXPECT_EQ(slope(Type::kLinear, {1, 0.5, 0}), zero);
  EXPECT_EQ(slope(Type::kLinear, {0.5, 0.5, 0}), (Vec3d{1, 0, 0}));
  EXPECT_EQ(slope(Type::kQuadratic, {1.5, 0, 0}), zero);
  EXPECT_EQ(slope(Type::kQuadratic, {-1.5, 0, 0}), zero);
  EXPECT_EQ(slope(Type::kEasing, {2, 0, 0}), zero);
  EXPECT_EQ(slope(Type::kDiagonal, {1, 1.5, 0}), zero);
  EXPECT_EQ(slope(Type::kDiagonal, {0.5, 0.3, 0}), (Vec3d{0.5, 0.5, 0}));
  EXPECT_EQ(slope(Type::kSpherical, {1, 1, 0}), zero);
  EXPECT_EQ(slope(Type::kQuadraticSphere, {0, 0, -2}), zero);
  EXPECT_EQ(slope(Type::kSpherical, zero), zero);
  EXPECT_EQ(slope(Type::kQuadraticSphere, zero), zero);
  EXPECT_NEAR(fac(Type::kSpherical, zero), 0.999999f, 0);
  for (const double z : {0.0, 2.0}) {
    EXPECT_EQ(fac(Type::kRadial, {0, 0, z}), 0.5);
    EXPECT_EQ(slope(Type::kRadial, {0, 0, z}), zero);
    EXPECT_EQ(slope(Type::kRadial, {1e-200, -1e-200, z}), zero);  // x² + y² underflows
  }
  // Radial's slope near its axis, 1 / (2π r) around it.
  const Vec3d near = slope(Type::kRadial, {1e-6, 0, 0});
  EXPECT_NEAR(near.y, 1 / (2 * kPi * 1e-6), 1e-3);
  EXPECT_EQ(near.x, 0);
}

// The gradient is the derivative of the Fac: central differences agree at random points, but
// for those whose differences straddle a clamp's bound, a sphere's apex or Radial's cut.
TEST(BlenderGradient, ItsGradientIsTheDerivativeOfTheFac) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> along(-1.5, 1.5);
  const double h = 1e-6;
  for (const Type type : kTypes) {
    const BlenderGradient gradient = makeGradient(type, 0.7);
    const auto height = [&](Vec3d q) { return gradient.value(q); };
    int sloped = 0;
    for (int i = 0; i < 3000; ++i) {
      const Vec3d p{along(rng), along(rng), along(rng)};
      const Vec3d exact = gradient.analyticGradient(p);
      // Away from kinks: one-sided differences along each axis agree.
      bool kink = false;
      for (int c = 0; c < 3; ++c) {
        Vec3d e{};
        (c == 0 ? e.x : c == 1 ? e.y : e.z) = h;
        const double forward = (height(p + e) - height(p)) / h;
        const double backward = (height(p) - height(p - e)) / h;
        kink = kink || std::abs(forward - backward) > 1e-3;
      }
      if (kink) continue;
      if (exact != Vec3d{}) ++sloped;
      // (Radial's differences lose to its curvature, ~|gradient|³ h², near its axis.)
      const double size = 1 + maxAbsDiff(exact, Vec3d{});
      EXPECT_LT(maxAbsDiff(exact, centralGradient(height, p, h)), 1e-7 * size * size * size)
          << int(type) << " at " << p.x << ", " << p.y << ", " << p.z;
    }
    EXPECT_GT(sloped, 300) << int(type) << ": points where the Fac is not clamped";
  }
}

// The height alone and with its gradient (HeightVolume::sample) are the same bits.
TEST(BlenderGradient, SampleIsTheValueBitForBit) {
  std::mt19937_64 rng(12);
  std::uniform_real_distribution<double> along(-1.5, 1.5);
  for (const Type type : kTypes) {
    const BlenderGradient gradient = makeGradient(type, -1.3);
    for (int i = 0; i < 500; ++i) {
      const Vec3d p{along(rng), along(rng), along(rng)};
      const VolumeSample both = gradient.sample(p);
      EXPECT_EQ(both.value, gradient.value(p)) << int(type);
      EXPECT_EQ(both.gradient, gradient.analyticGradient(p)) << int(type);
    }
  }
}

TEST(BlenderGradient, RefusesSettingsItCannotBake) {
  Result<BlenderGradient> nan = BlenderGradient::create({.amplitude = std::nan("")});
  ASSERT_FALSE(nan);
  EXPECT_EQ(nan.error().message, "a Gradient Texture setting is not finite");
  Result<BlenderGradient> unknown = BlenderGradient::create({.type = static_cast<Type>(7)});
  ASSERT_FALSE(unknown);
  EXPECT_EQ(unknown.error().message, "a Gradient Texture's type is not one of Blender's seven");
  Result<BlenderGradient> steep = BlenderGradient::create({.amplitude = 1e300});
  ASSERT_FALSE(steep);
  EXPECT_EQ(steep.error().message, "Gradient Texture slopes beyond 1e300 (amplitude × 2)");
  EXPECT_TRUE(BlenderGradient::create({.amplitude = -1e299, .type = Type::kRadial}));
}

}  // namespace
}  // namespace sgbake
