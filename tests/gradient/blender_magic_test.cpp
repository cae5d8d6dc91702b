/// @file blender_magic_test.cpp
/// @brief Blender's Magic Texture's Fac as a volume: Cycles' steps at each Depth, the mean of
/// its Color, and its exact gradient through every sine and cosine. (Its values against Cycles'
/// own are checked by BlenderTextureFacOracle.)
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "sgbake/gradient/blender_noise.hpp"
#include "support/analytic_textures.hpp"

namespace sgbake {
namespace {

using test::centralGradient;
using test::maxAbsDiff;

BlenderMagic makeMagic(const BlenderMagicParams& params) {
  return test::created(BlenderMagic::create(params));
}

// Depth 0 is the three waves, divided by 2d when d ≠ 0; Depth 1 and 2 take Cycles' first
// steps. Fac = the mean of Color = ½ − (x, y, z).
TEST(BlenderMagic, IsTheMeanOfCyclesColourAtEachDepth) {
  const Vec3d P{0.31, -0.12, 0.27};
  const double s = 1.5;
  const double a = 5 * s * (P.x + P.y + P.z), b = 5 * s * (-P.x + P.y - P.z),
               c = 5 * s * (-P.x - P.y + P.z);
  const double x0 = std::sin(a), y0 = std::cos(b), z0 = -std::cos(c);
  const auto fac = [](double x, double y, double z) {
    return ((0.5 - x) + (0.5 - y) + (0.5 - z)) / 3;
  };
  const auto magic = [&](int depth, double d) {
    return makeMagic({.scale = s, .depth = depth, .distortion = d}).output(P, nullptr);
  };
  EXPECT_NEAR(magic(0, 0), fac(x0, y0, z0), 1e-15);
  EXPECT_NEAR(magic(0, 2), fac(x0 / 4, y0 / 4, z0 / 4), 1e-15);
  const double d = 1.7;
  double x = d * x0, y = d * y0, z = d * z0;
  y = -std::cos(x - y + z) * d;
  EXPECT_NEAR(magic(1, d), fac(x / (2 * d), y / (2 * d), z / (2 * d)), 1e-15);
  x = std::cos(x - y - z) * d;
  EXPECT_NEAR(magic(2, d), fac(x / (2 * d), y / (2 * d), z / (2 * d)), 1e-15);
  // Without distortion any step zeroes x, y and z: Fac ½, flat.
  Vec3d g;
  EXPECT_EQ(makeMagic({.depth = 3, .distortion = 0}).output(P, &g), 0.5);
  EXPECT_EQ(g, Vec3d{});
  EXPECT_NEAR(makeMagic({.amplitude = -2, .scale = s, .depth = 0, .distortion = 0}).value(P),
              -2 * fac(x0, y0, z0), 1e-15);
}

// The gradient is the chain rule through every step: central differences agree at every
// Depth with a Distortion below, at and above 1, of either sign. (Each step multiplies the
// curvature too: the differences are extrapolated, (4 D(h / 2) − D(h)) / 3, and their step
// shrinks as the slopes grow.)
TEST(BlenderMagic, ItsGradientIsTheDerivativeOfTheFacAtEveryDepth) {
  std::mt19937_64 rng(13);
  std::uniform_real_distribution<double> along(-1.5, 1.5);
  for (int depth = 0; depth <= kBlenderMagicMaxDepth; ++depth) {
    for (const double d : {0.6, 1.0, 2.3, -1.4}) {
      const BlenderMagic magic =
          makeMagic({.amplitude = 0.8, .scale = 1.3, .depth = depth, .distortion = d});
      const auto height = [&](Vec3d q) { return magic.value(q); };
      for (int i = 0; i < 200; ++i) {
        const Vec3d p{along(rng), along(rng), along(rng)};
        const Vec3d exact = magic.analyticGradient(p);
        const double size = 1 + maxAbsDiff(exact, Vec3d{});
        const double h = 1e-5 / size;
        const Vec3d extrapolated = (4.0 / 3) * centralGradient(height, p, h / 2) -
                                   (1.0 / 3) * centralGradient(height, p, h);
        EXPECT_LT(maxAbsDiff(exact, extrapolated), 1e-6 * size)
            << "depth " << depth << ", distortion " << d << " at " << p.x << ", " << p.y << ", "
            << p.z;
      }
    }
  }
}

// The height alone and with its gradient (HeightVolume::sample) are the same bits.
TEST(BlenderMagic, SampleIsTheValueBitForBit) {
  std::mt19937_64 rng(14);
  std::uniform_real_distribution<double> along(-3, 3);
  for (int depth = 0; depth <= kBlenderMagicMaxDepth; ++depth) {
    const BlenderMagic magic = makeMagic({.amplitude = 1.1, .depth = depth, .distortion = 1.9});
    for (int i = 0; i < 100; ++i) {
      const Vec3d p{along(rng), along(rng), along(rng)};
      const VolumeSample both = magic.sample(p);
      EXPECT_EQ(both.value, magic.value(p)) << depth;
      EXPECT_EQ(both.gradient, magic.analyticGradient(p)) << depth;
    }
  }
}

TEST(BlenderMagic, RefusesSettingsItCannotBake) {
  for (const int depth : {-1, 11}) {
    Result<BlenderMagic> made = BlenderMagic::create({.depth = depth});
    ASSERT_FALSE(made) << depth;
    EXPECT_EQ(made.error().message, "a Magic Texture's Depth must be an integer from 0 to 10");
  }
  EXPECT_TRUE(BlenderMagic::create({.depth = 0}));
  EXPECT_TRUE(BlenderMagic::create({.depth = 10, .distortion = -1000}));
  Result<BlenderMagic> nan = BlenderMagic::create({.distortion = std::nan("")});
  ASSERT_FALSE(nan);
  EXPECT_EQ(nan.error().message, "a Magic Texture setting is not finite");
  EXPECT_FALSE(BlenderMagic::create({.scale = INFINITY}));
  Result<BlenderMagic> steep = BlenderMagic::create({.scale = 1e299});
  ASSERT_FALSE(steep);
  EXPECT_EQ(steep.error().message,
            "Magic Texture slopes beyond 1e300 (amplitude × scale × 5√3 × max(1, 3 "
            "|distortion|)^depth, / 2 |distortion| at depth 0)");
  // At Depth 0 a tiny Distortion divides the waves: their slopes grow as 1 / 2d.
  EXPECT_FALSE(BlenderMagic::create({.depth = 0, .distortion = 1e-300}));
  EXPECT_TRUE(BlenderMagic::create({.depth = 1, .distortion = 1e-300}));
}

}  // namespace
}  // namespace sgbake
