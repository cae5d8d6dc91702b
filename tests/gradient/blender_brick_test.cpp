/// @file blender_brick_test.cpp
/// @brief Blender's Brick Texture's Fac as a volume: the layout of rows, offsets and squashed
/// rows, the mortar's smoothstep, and its exact gradient. (Its values against Cycles' own are
/// checked by BlenderBakeOracle's brick case.)
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "sgbake/gradient/blender_noise.hpp"

namespace sgbake {
namespace {

BlenderBrick makeBrick(const BlenderBrickParams& params) {
  Result<BlenderBrick> made = BlenderBrick::create(params);
  EXPECT_TRUE(made) << made.error().message;
  return std::move(made).value();
}

/// Blender's defaults at Scale 1: bricks 0.5 × 0.25, rows 0, ±2, … moved by 0.25, mortar 0.02
/// smoothed over its inner tenth.
constexpr BlenderBrickParams kDefaults{.scale = 1};

// At a distance d from the brick's nearest edge the Fac is 1 inside the mortar's unsmoothed
// part, 0 beyond it, and 3t² − 2t³ of t = (1 − d / 0.02) / 0.1 between; rows whose number is a
// multiple of 2 (below zero too, as C's remainder has it) are moved by half a brick.
TEST(BlenderBrick, IsTheMortarAtTheDistanceToTheBricksEdge) {
  const BlenderBrick brick = makeBrick(kDefaults);
  const auto fac = [&](double x, double y) { return brick.output({x, y, 0.7}, nullptr); };
  const double smooth = 0.25 * 0.25 * (3 - 2 * 0.25);  // d = 0.0195: t = 0.25
  // Row 0 (y in [0, 0.25)) is moved by 0.25: its edges lie at x = 0.25 + 0.5 k.
  EXPECT_EQ(fac(0.26, 0.125), 1);  // d = 0.01
  EXPECT_EQ(fac(0.30, 0.125), 0);  // d = 0.05
  EXPECT_NEAR(fac(0.2695, 0.125), smooth, 1e-12);
  EXPECT_NEAR(fac(0.2305, 0.125), smooth, 1e-12);  // the other side of that edge
  // Row 1 is not moved: its edges lie at x = 0.5 k.
  EXPECT_NEAR(fac(0.0195, 0.375), smooth, 1e-12);
  EXPECT_EQ(fac(0.2695, 0.375), 0);
  // Row −1 is not moved, row −2 is.
  EXPECT_NEAR(fac(0.5195, -0.125), smooth, 1e-12);
  EXPECT_NEAR(fac(0.2695, -0.375), smooth, 1e-12);
  // The rows' own edges: y = 0.25 k.
  EXPECT_NEAR(fac(0.4, 0.2695), smooth, 1e-12);
  // Scale multiplies P; the Fac is the mortar's, whatever the z.
  const BlenderBrick scaled = makeBrick({.scale = 2});
  EXPECT_NEAR(scaled.output({0.0195 / 2, 0.375 / 2, -3}, nullptr), smooth, 1e-12);
  // Without smoothing the mortar is 1 throughout; the amplitude scales the height.
  EXPECT_EQ(makeBrick({.scale = 1, .mortarSmooth = 0}).output({0.0195, 0.375, 0}, nullptr), 1);
  EXPECT_NEAR(makeBrick({.amplitude = 0.3, .scale = 1}).value({0.0195, 0.375, 0}), 0.3 * smooth,
              1e-12);
}

// Squash widens the bricks of the rows whose number is a multiple of its frequency, and the
// offset of such a row is in those wider bricks; a zero frequency turns both off.
TEST(BlenderBrick, SquashedRowsHaveWiderBricks) {
  const BlenderBrick squashed = makeBrick({.scale = 1, .squash = 2, .squashFrequency = 3});
  const auto fac = [&](const BlenderBrick& b, double x, double y) {
    return b.output({x, y, 0}, nullptr);
  };
  // Row 0: multiple of 3 and of 2: bricks 1 wide, moved by 0.5: edges at x = 0.5 + k.
  EXPECT_EQ(fac(squashed, 0.51, 0.125), 1);
  EXPECT_EQ(fac(squashed, 0.01, 0.125), 0);
  // Row 3 (y in [0.75, 1)): squashed, not moved: edges at x = k.
  EXPECT_EQ(fac(squashed, 1.01, 0.875), 1);
  EXPECT_EQ(fac(squashed, 0.51, 0.875), 0);
  // Row 2: moved by 0.25, bricks 0.5 wide.
  EXPECT_EQ(fac(squashed, 0.26, 0.625), 1);
  const BlenderBrick plain = makeBrick({.scale = 1, .offsetFrequency = 0, .squash = 2});
  EXPECT_EQ(fac(plain, 0.51, 0.125), 1);  // row 0 neither moved nor squashed
  EXPECT_EQ(fac(plain, 0.26, 0.125), 0);
}

// The gradient is the Fac's derivative: along the nearest edge's normal inside the smoothed
// mortar, zero elsewhere (points near a brick's corner or the mortar's borders are left out).
TEST(BlenderBrick, ItsGradientIsTheDerivativeOfTheFac) {
  const BlenderBrick brick =
      makeBrick({.scale = 3, .mortarSize = 0.05, .mortarSmooth = 0.8, .squash = 1.4});
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> coordinate(-2, 2);
  const double h = 1e-7;
  int smoothed = 0;
  for (int i = 0; i < 4000; ++i) {
    const Vec3d p{coordinate(rng), coordinate(rng), coordinate(rng)};
    Vec3d g;
    const double fac = brick.output(p, &g);
    const auto at = [&](Vec3d q) { return brick.output(q, nullptr); };
    const Vec3d numeric{(at(p + Vec3d{h, 0, 0}) - at(p - Vec3d{h, 0, 0})) / (2 * h),
                        (at(p + Vec3d{0, h, 0}) - at(p - Vec3d{0, h, 0})) / (2 * h),
                        (at(p + Vec3d{0, 0, h}) - at(p - Vec3d{0, 0, h})) / (2 * h)};
    // Skip kinks: the differences straddle a corner or a border when the two sides disagree.
    const double forward = (at(p + Vec3d{h, 0, 0}) - fac) / h;
    const double backward = (fac - at(p - Vec3d{h, 0, 0})) / h;
    const double up = (at(p + Vec3d{0, h, 0}) - fac) / h;
    const double down = (fac - at(p - Vec3d{0, h, 0})) / h;
    if (std::abs(forward - backward) > 1e-3 || std::abs(up - down) > 1e-3) continue;
    if (fac > 0 && fac < 1) ++smoothed;
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(g[c], numeric[c], 1e-5 * (1 + std::abs(numeric[c]))) << i << " axis " << c;
    }
  }
  EXPECT_GT(smoothed, 100) << "points inside the smoothed mortar";
}

TEST(BlenderBrick, RefusesSettingsItCannotLayOut) {
  EXPECT_FALSE(BlenderBrick::create({.brickWidth = 0}));
  EXPECT_FALSE(BlenderBrick::create({.rowHeight = -1}));
  EXPECT_FALSE(BlenderBrick::create({.offsetFrequency = -1}));
  EXPECT_FALSE(BlenderBrick::create({.squash = 0}));
  EXPECT_TRUE(BlenderBrick::create({.squash = 0, .squashFrequency = 0}));  // squash unused
  EXPECT_FALSE(BlenderBrick::create({.mortarSize = std::nan("")}));
  Result<BlenderBrick> steep = BlenderBrick::create({.mortarSize = 1e-160, .mortarSmooth = 1e-160});
  ASSERT_FALSE(steep);
  EXPECT_EQ(steep.error().message,
            "Brick Texture slopes beyond 1e300 (amplitude × scale × 1.5 / (mortar size × mortar "
            "smooth))");
}

}  // namespace
}  // namespace sgbake
