/// @file remap_test.cpp
/// @brief Piecewise-linear height remaps: the function itself against hand-computed values, and
/// textures, volumes and layers read through one against the chain rule.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "sgbake/gradient/blender_noise.hpp"
#include "sgbake/gradient/layers.hpp"
#include "sgbake/gradient/remap.hpp"
#include "support/analytic_textures.hpp"
#include "support/surface_points.hpp"

namespace sgbake {
namespace {

using test::AnalyticHeight;
using test::maxAbsDiff;
using test::samplePoint;

HeightRemap makeRemap(std::vector<Vec2d> points) {
  Result<HeightRemap> made = HeightRemap::create(std::move(points));
  EXPECT_TRUE(made) << made.error().message;
  return std::move(made).value();
}

/// A clamp to [0, 1] of 2x − 0.5, then a step down at x = 0.9: levels, a clamp and a Constant
/// ramp's kind of jump in one.
HeightRemap levelsWithAStep() { return makeRemap({{0.25, 0}, {0.75, 1}, {0.9, 1}, {0.9, 0.2}}); }

TEST(HeightRemap, IsLinearBetweenPointsAndConstantBeyondThem) {
  const HeightRemap g = levelsWithAStep();
  EXPECT_EQ(g.value(-3), 0);
  EXPECT_EQ(g.slope(-3), 0);
  EXPECT_DOUBLE_EQ(g.value(0.5), 0.5);
  EXPECT_DOUBLE_EQ(g.slope(0.5), 2);
  EXPECT_DOUBLE_EQ(g.value(0.375), 0.25);
  EXPECT_EQ(g.value(0.8), 1);
  EXPECT_EQ(g.slope(0.8), 0);
  EXPECT_EQ(g.value(7), 0.2);
  EXPECT_EQ(g.slope(7), 0);
  EXPECT_TRUE(std::isnan(g.value(std::numeric_limits<double>::quiet_NaN())));
}

TEST(HeightRemap, TakesTheSegmentToTheRightAtAPointAndTheSecondValueAtAStep) {
  const HeightRemap g = levelsWithAStep();
  EXPECT_EQ(g.value(0.25), 0);
  EXPECT_DOUBLE_EQ(g.slope(0.25), 2);  // the segment starting there
  EXPECT_EQ(g.value(0.75), 1);
  EXPECT_EQ(g.slope(0.75), 0);
  EXPECT_EQ(g.value(0.9), 0.2);  // continuous from the right
  EXPECT_EQ(g.value(std::nextafter(0.9, 0.0)), 1);
  // A Constant Color Ramp's table read as Cycles reads it: the entry at or below the value.
  const HeightRemap constant = makeRemap({{0, 0.1}, {0.5, 0.1}, {0.5, 0.7}, {1, 0.7}});
  EXPECT_EQ(constant.value(0.49), 0.1);
  EXPECT_EQ(constant.value(0.5), 0.7);
  EXPECT_EQ(constant.slope(0.3), 0);
}

// Uneven points, steps and points crowded into one cell of the lookup grid (seven in [1, 1.06]:
// found by bisection): every value is the one the segment whose start is the last point at or
// left of x gives.
TEST(HeightRemap, FindsTheSegmentOfEveryValueAsBisectionDoes) {
  const std::vector<Vec2d> points{{-1, 0},   {-0.999, 1}, {-0.998, 0}, {0.3, 2},   {0.3, -1},
                                  {0.31, 0}, {0.75, 3},   {0.75, 1},   {0.751, 2}, {1, 0},
                                  {1.01, 1}, {1.02, 0},   {1.03, 1},   {1.04, 0},  {1.05, 1},
                                  {1.06, 0}, {5, 0}};
  const HeightRemap g = makeRemap(points);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> along(-1.5, 5.5);
  std::vector<double> xs;
  for (const Vec2d& p : points) xs.insert(xs.end(), {p.x, std::nextafter(p.x, -10.0)});
  for (int i = 0; i < 2000; ++i) xs.push_back(along(rng));
  for (const double x : xs) {
    std::size_t right = 0;
    while (right < points.size() && points[right].x <= x) ++right;
    double value = points.back().y, slope = 0;
    if (right == 0) {
      value = points.front().y;
    } else if (right < points.size()) {
      const Vec2d a = points[right - 1], b = points[right];
      slope = (b.y - a.y) / (b.x - a.x);
      value = a.y + (x - a.x) * slope;
    }
    EXPECT_EQ(g.value(x), value) << x;
    EXPECT_EQ(g.slope(x), slope) << x;
  }
}

TEST(HeightRemap, RejectsWhatIsNotAFunction) {
  const auto message = [](std::vector<Vec2d> points) {
    Result<HeightRemap> made = HeightRemap::create(std::move(points));
    return made ? std::string("accepted") : made.error().message;
  };
  EXPECT_EQ(message({{0, 1}}), "a remap needs 2 to 65536 points, not 1");
  EXPECT_EQ(message({{0, 0}, {1, 1}, {0.5, 2}}),
            "remap point 2 has a smaller x than the point before it");
  EXPECT_EQ(message({{0, 0}, {0, 1}, {0, 2}}),
            "remap point 2 is the third of one x (a step takes two)");
  EXPECT_EQ(message({{0, 0}, {1, std::numeric_limits<double>::infinity()}}),
            "remap point 1 is not finite");
  EXPECT_EQ(message({{0, 0}, {1e-320, 1e10}}),
            "remap point 1 is too close to the point before it for a finite slope");
  EXPECT_EQ(message({{0, 0}, {0, 1}}), "accepted");  // a single step is a function
}

// Away from its points, a remapped texture's gradient is the derivative of its value.
TEST(RemappedScalarTexture, IsTheRemapOfTheValueWithTheChainRulesGradient) {
  const AnalyticHeight h(0.3, -0.2, 0.25);
  const HeightRemap g = makeRemap({{-0.2, 0.4}, {0.1, -0.3}, {0.35, 0.9}, {0.6, 0.9}});
  const RemappedScalarTexture remapped(h, g);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> unit(0, 1);
  const double step = 1e-6;
  int checked = 0;
  for (int i = 0; i < 400; ++i) {
    const Vec2d st{unit(rng), unit(rng)};
    const ScalarSample inner = h.sample(st), outer = remapped.sample(st);
    EXPECT_EQ(outer.value, g.value(inner.value));
    bool nearPoint = false;
    for (const Vec2d& p : g.points()) nearPoint |= std::abs(inner.value - p.x) < 1e-3;
    if (nearPoint) continue;
    const Vec2d central{
        (remapped.sample(st + Vec2d{step, 0}).value - remapped.sample(st - Vec2d{step, 0}).value) /
            (2 * step),
        (remapped.sample(st + Vec2d{0, step}).value - remapped.sample(st - Vec2d{0, step}).value) /
            (2 * step)};
    EXPECT_LT(maxAbsDiff(outer.gradient, central), 1e-7) << st.x << ", " << st.y;
    ++checked;
  }
  EXPECT_GT(checked, 200);  // most points are on a segment, not next to a point
}

TEST(RemappedScalarTexture, SamplesABatchAsItSamplesOnePoint) {
  const AnalyticHeight h(0.3, -0.2, 0.25);
  const RemappedScalarTexture remapped(h, levelsWithAStep());
  std::vector<Vec2d> st;
  for (int i = 0; i < 37; ++i) st.push_back({0.03 * i, 0.7 - 0.02 * i});
  std::vector<ScalarSample> many(st.size());
  remapped.sampleMany(st, many);
  for (std::size_t i = 0; i < st.size(); ++i) {
    const ScalarSample one = remapped.sample(st[i]);
    EXPECT_EQ(many[i].value, one.value);
    EXPECT_EQ(many[i].gradient, one.gradient);
  }
}

/// h(P) = ⟨(0.7, −0.4, 0.2), P⟩ + 0.1.
class PlaneVolume final : public HeightVolume {
 public:
  double value(Vec3d p) const override { return dot(Vec3d{0.7, -0.4, 0.2}, p) + 0.1; }
  Vec3d analyticGradient(Vec3d) const override { return {0.7, -0.4, 0.2}; }
};

TEST(RemappedHeightVolume, ScalesTheGradientByTheSlopeAtTheValue) {
  const PlaneVolume plane;
  const RemappedHeightVolume remapped(plane, levelsWithAStep());
  const Vec3d on{0.5, 0, 0};  // h = 0.45: slope 2
  EXPECT_DOUBLE_EQ(remapped.value(on), 0.4);
  EXPECT_LT(maxAbsDiff(remapped.analyticGradient(on), Vec3d{1.4, -0.8, 0.4}), 1e-15);
  const Vec3d flat{1.2, 0, 0};  // h = 0.94: beyond the step, flat
  EXPECT_EQ(remapped.value(flat), 0.2);
  EXPECT_EQ(remapped.analyticGradient(flat), Vec3d{});
}

// The views evaluate value and gradient together (HeightVolume::sample) with the same bits as
// value() and analyticGradient() apart, over a Blender texture whose sample() is one evaluation.
TEST(HeightVolumeViews, SampleAtOnceGivesTheSameBitsAsValueAndGradientApart) {
  Result<BlenderNoise> noise = BlenderNoise::create({.amplitude = 0.3, .scale = 2.5});
  ASSERT_TRUE(noise) << noise.error().message;
  const MappedHeightVolume mapped(
      *noise, CoordinateMapping::fromMappingNode({0.2, -1, 0.5}, {0.3, 0, 1.1}, {2, 1, 0.5},
                                                 MappingType::kPoint));
  const RemappedHeightVolume remapped(mapped, levelsWithAStep());
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> coordinate(-3, 3);
  for (int i = 0; i < 100; ++i) {
    const Vec3d p{coordinate(rng), coordinate(rng), coordinate(rng)};
    for (const HeightVolume* volume :
         {static_cast<const HeightVolume*>(&*noise), static_cast<const HeightVolume*>(&mapped),
          static_cast<const HeightVolume*>(&remapped)}) {
      const VolumeSample s = volume->sample(p);
      EXPECT_EQ(s.value, volume->value(p));
      EXPECT_EQ(s.gradient, volume->analyticGradient(p));
    }
  }
}

// A volume read on UV coordinates is the volume at (s, t, 0), its slopes the gradient's x and y
// there (a Mapping node before it, a MappedHeightVolume, included).
TEST(VolumeOnUvTexture, IsTheVolumeOnThePlaneZeroAndItsSlopes) {
  const PlaneVolume plane;
  const VolumeOnUvTexture flat(plane);
  const ScalarSample at = flat.sample({0.5, 2});
  EXPECT_DOUBLE_EQ(at.value, 0.35 - 0.8 + 0.1);
  EXPECT_EQ(at.gradient, (Vec2d{0.7, -0.4}));
  Result<BlenderNoise> noise = BlenderNoise::create({.scale = 3, .detail = 1.5});
  ASSERT_TRUE(noise) << noise.error().message;
  const MappedHeightVolume mapped(
      *noise, CoordinateMapping::fromMappingNode({0, 0.25, 0.1}, {0, 0, 0.6}, {2, 1, 1},
                                                 MappingType::kPoint));
  const VolumeOnUvTexture onUv(mapped);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> coordinate(-2, 2);
  for (int i = 0; i < 100; ++i) {
    const Vec2d st{coordinate(rng), coordinate(rng)};
    const ScalarSample s = onUv.sample(st);
    EXPECT_EQ(s.value, mapped.value({st.x, st.y, 0}));
    const double h = 1e-6;
    const double dx =
        (mapped.value({st.x + h, st.y, 0}) - mapped.value({st.x - h, st.y, 0})) / (2 * h);
    const double dy =
        (mapped.value({st.x, st.y + h, 0}) - mapped.value({st.x, st.y - h, 0})) / (2 * h);
    EXPECT_NEAR(s.gradient.x, dx, 1e-6 * (1 + std::abs(dx)));
    EXPECT_NEAR(s.gradient.y, dy, 1e-6 * (1 + std::abs(dy)));
  }
}

// Every kind of height layer reads a remapped texture as a height G(h): its Γ is G′(h) times the
// layer's Γ of h (for a UV height, exactly; the point's h known from the texture).
TEST(RemappedScalarTexture, BumpsALayerByTheRemapsSlopeTimesItsGamma) {
  const AnalyticHeight h(0.3, -0.2, 0.25);
  const HeightRemap g = makeRemap({{-1, 2}, {0, 0}, {0.2, 0.5}, {2, -1}});
  const RemappedScalarTexture remapped(h, g);
  std::mt19937_64 rng(11);
  for (int i = 0; i < 200; ++i) {
    const SurfacePoint p = samplePoint(rng);
    const UvHeightSource plain{&h, 0, 0.8, {1.5, 0.5}, {0.1, 0}};
    UvHeightSource through = plain;
    through.texture = &remapped;
    const Vec2d st = textureCoordinates(p.uv[0].uv, plain.tiling, plain.offset);
    const double slope = g.slope(h.sample(st).value);
    EXPECT_LT(maxAbsDiff(layerGradient(through, p), slope * layerGradient(plain, p)), 1e-13);
  }
}

}  // namespace
}  // namespace sgbake
