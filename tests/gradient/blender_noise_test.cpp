/// @file blender_noise_test.cpp
/// @brief Blender's Noise Texture as a volume: its invariants and its exact gradient. (Its values
/// against Cycles' own are checked by BlenderBakeOracle's noise cases.)
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>

#include "sgbake/gradient/blender_noise.hpp"
#include "sgbake/gradient/remap.hpp"
#include "support/analytic_textures.hpp"

namespace sgbake {
namespace {

using test::centralGradient;
using test::maxAbsDiff;

BlenderNoise makeNoise(const BlenderNoiseParams& params) {
  Result<BlenderNoise> made = BlenderNoise::create(params);
  EXPECT_TRUE(made) << made.error().message;
  return std::move(made).value();
}

// Perlin noise is 0 at every lattice point, so without distortion each octave there reads ½:
// Fac = ½ wherever scale · P is integer, whatever the detail and roughness.
TEST(BlenderNoise, IsOneHalfAtLatticePoints) {
  const BlenderNoise noise =
      makeNoise({.amplitude = 1, .scale = 4, .detail = 3.5, .roughness = 0.7});
  for (const Vec3d lattice : {Vec3d{0, 0, 0}, Vec3d{1, -2, 3}, Vec3d{-7, 5, 11}}) {
    EXPECT_NEAR(noise.value((1.0 / 4) * lattice), 0.5, 1e-15) << lattice.x;
    EXPECT_EQ(blenderSignedNoise(lattice, nullptr), 0.0);
  }
}

// Cycles scales Perlin noise by 0.982 so that the Fac of the node stays within [0, 1]: so does
// sgbake's, with distortion and many octaves, at 5000 points.
TEST(BlenderNoise, FacStaysWithinZeroAndOne) {
  const BlenderNoise noise = makeNoise({.detail = 4, .roughness = 0.9, .distortion = 1.5});
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> along(-20, 20);
  for (int i = 0; i < 5000; ++i) {
    const double v = noise.value({along(rng), along(rng), along(rng)});
    EXPECT_GE(v, 0.0);
    EXPECT_LE(v, 1.0);
  }
}

// The gradient is exact: central differences agree to their own error, with distortion, a
// fractional detail (the extra octave's blend) and an amplitude.
TEST(BlenderNoise, AnalyticGradientIsTheDerivativeOfTheValue) {
  for (const BlenderNoiseParams params :
       {BlenderNoiseParams{.amplitude = 0.3, .scale = 5, .detail = 2, .roughness = 0.5},
        BlenderNoiseParams{
            .amplitude = -1.2, .scale = 2.5, .detail = 3.4, .roughness = 0.8, .distortion = 0.9},
        BlenderNoiseParams{.amplitude = 1, .scale = 1.5, .detail = 0, .roughness = 1.7}}) {
    const BlenderNoise noise = makeNoise(params);
    std::mt19937_64 rng(9);
    std::uniform_real_distribution<double> along(-3, 3);
    for (int i = 0; i < 300; ++i) {
      const Vec3d p{along(rng), along(rng), along(rng)};
      const Vec3d exact = noise.analyticGradient(p);
      const Vec3d central = centralGradient([&](Vec3d q) { return noise.value(q); }, p, 1e-6);
      EXPECT_LT(maxAbsDiff(exact, central), 2e-6 * (1 + std::abs(params.amplitude) * 100))
          << params.detail << " at " << p.x << ", " << p.y << ", " << p.z;
    }
  }
}

// The signed noise's gradient, on its own.
TEST(BlenderNoise, SignedNoiseGradientIsItsDerivative) {
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> along(-50, 50);
  for (int i = 0; i < 500; ++i) {
    const Vec3d p{along(rng), along(rng), along(rng)};
    Vec3d exact;
    blenderSignedNoise(p, &exact);
    const Vec3d central =
        centralGradient([](Vec3d q) { return blenderSignedNoise(q, nullptr); }, p, 1e-6);
    EXPECT_LT(maxAbsDiff(exact, central), 1e-7);
  }
}

// Dimensions 2D read (x, y) alone and 4D (x, y, z, W): Fac is ½ at their lattice points, 2D's does
// not change along z (its gradient's z is 0), 4D's changes with W, and the gradient of each is
// exact, with distortion and a fractional detail. 1D reads W alone: one Fac over the whole
// surface, no slopes, changing with W.
TEST(BlenderNoise, OtherDimensionsReadTheirAxesAndTheirGradientsAreTheDerivatives) {
  const auto noiseOf = [](int dimensions, double w, double distortion) {
    return makeNoise({.amplitude = 0.7, .scale = 2, .detail = 2.6, .roughness = 0.6,
                      .distortion = distortion, .dimensions = dimensions, .w = w});
  };
  for (const int dimensions : {2, 4}) {
    const BlenderNoise plain = noiseOf(dimensions, 1.5, 0);  // scaled W: 3, on the lattice
    EXPECT_NEAR(plain.value({0.5, -1.5, 2.5}), 0.7 * 0.5, 1e-15) << dimensions;
    EXPECT_NE(plain.value({0.5, -1.5, 2.5}), plain.value({0.6, -1.5, 2.5})) << dimensions;
    for (const double distortion : {0.0, 0.8}) {
      const BlenderNoise noise = noiseOf(dimensions, 0.37, distortion);
      std::mt19937_64 rng(static_cast<std::uint64_t>(11 + dimensions));
      std::uniform_real_distribution<double> along(-3, 3);
      for (int i = 0; i < 200; ++i) {
        const Vec3d p{along(rng), along(rng), along(rng)};
        const Vec3d exact = noise.analyticGradient(p);
        const Vec3d central = centralGradient([&](Vec3d q) { return noise.value(q); }, p, 1e-6);
        EXPECT_LT(maxAbsDiff(exact, central), 2e-5) << dimensions << "D at " << p.x;
        if (dimensions == 2) {
          EXPECT_EQ(noise.value(p), noise.value({p.x, p.y, p.z + 1.3}));
          EXPECT_EQ(exact.z, 0.0);
        }
      }
    }
    const bool wMatters = noiseOf(dimensions, 0.37, 0).value({0.3, 0.2, 0.1}) !=
                          noiseOf(dimensions, 0.41, 0).value({0.3, 0.2, 0.1});
    EXPECT_EQ(wMatters, dimensions == 4) << dimensions << "D";
  }
  const BlenderNoise line = noiseOf(1, 0.37, 0.8);
  const double fac = line.value({0.1, 0.2, 0.3});
  EXPECT_EQ(line.value({-2.5, 1.0, 7.0}), fac);
  EXPECT_EQ(line.analyticGradient({0.1, 0.2, 0.3}), (Vec3d{0, 0, 0}));
  EXPECT_NE(noiseOf(1, 0.41, 0.8).value({0.1, 0.2, 0.3}), fac);
  EXPECT_GT(fac, 0.0);
  EXPECT_LT(fac, 0.7);
}

// The Musgrave Texture of Dimensions 1D, 2D and 4D reads the same points as the Noise Texture's:
// 1D one value over the surface, 2D none of z; its gradient is exact (fBM, multifractal). A
// Dimensions beyond 4D is refused.
TEST(BlenderMusgrave, OtherDimensionsReadTheirAxesAndTheirGradientsAreTheDerivatives) {
  for (const MusgraveType type : {MusgraveType::kFbm, MusgraveType::kMultifractal}) {
    for (const int dimensions : {1, 2, 4}) {
      Result<BlenderMusgrave> made =
          BlenderMusgrave::create({.amplitude = 0.4, .scale = 1.5, .type = type, .detail = 2.5,
                                   .offset = 1, .gain = 1, .dimensions = dimensions, .w = 0.8});
      ASSERT_TRUE(made) << made.error().message;
      const BlenderMusgrave& musgrave = made.value();
      std::mt19937_64 rng(static_cast<std::uint64_t>(5 + dimensions));
      std::uniform_real_distribution<double> along(-3, 3);
      for (int i = 0; i < 100; ++i) {
        const Vec3d p{along(rng), along(rng), along(rng)};
        const Vec3d exact = musgrave.analyticGradient(p);
        const Vec3d central =
            centralGradient([&](Vec3d q) { return musgrave.value(q); }, p, 1e-6);
        EXPECT_LT(maxAbsDiff(exact, central), 2e-5) << dimensions << "D at " << p.x;
        if (dimensions < 3) {
          EXPECT_EQ(exact.z, 0.0);
        }
        if (dimensions == 1) {
          EXPECT_EQ(musgrave.value(p), musgrave.value({0, 0, 0}));
        }
      }
    }
  }
  Result<BlenderMusgrave> bad = BlenderMusgrave::create({.dimensions = 5});
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().message, "a Musgrave Texture's Dimensions must be 1, 2, 3 or 4, not 5");
}

// Musgrave fBM: the signed noise summed over octaves at Lⁱ p weighted L^(−iH), a fractional
// Detail adding part of one more; its gradient exact.
TEST(BlenderMusgrave, SumsTheOctavesAndItsGradientIsTheDerivative) {
  Result<BlenderMusgrave> made = BlenderMusgrave::create(
      {.amplitude = 0.4, .scale = 2.5, .detail = 2.5, .dimension = 1.5, .lacunarity = 2.3});
  ASSERT_TRUE(made) << made.error().message;
  std::mt19937_64 rng(12);
  std::uniform_real_distribution<double> along(-3, 3);
  for (int i = 0; i < 300; ++i) {
    const Vec3d p{along(rng), along(rng), along(rng)};
    const Vec3d q = 2.5 * p;
    const double w = std::pow(2.3, -1.5);
    const double expected = blenderSignedNoise(q, nullptr) +
                            w * blenderSignedNoise(2.3 * q, nullptr) +
                            0.5 * w * w * blenderSignedNoise(2.3 * 2.3 * q, nullptr);
    EXPECT_NEAR(made->value(p), 0.4 * expected, 1e-15);
    const Vec3d central = centralGradient([&](Vec3d r) { return made->value(r); }, p, 1e-6);
    EXPECT_LT(maxAbsDiff(made->analyticGradient(p), central), 1e-6);
  }
}

/// Cycles 3.4's Musgrave types written out plainly, octave by octave (value only): the reference
/// the library's values are checked against.
double musgraveReference(MusgraveType type, Vec3d q, double detail, double h, double l,
                         double offset, double gain) {
  const int n = static_cast<int>(detail);
  const double rest = detail - n;
  const auto s = [&](int i) { return blenderSignedNoise(std::pow(l, i) * q, nullptr); };
  const auto w = [&](int i) { return std::pow(l, -h * i); };
  double value = 0;
  switch (type) {
    case MusgraveType::kMultifractal:
      value = 1;
      for (int i = 0; i < n; ++i) value *= w(i) * s(i) + 1;
      if (rest != 0) value *= rest * w(n) * s(n) + 1;
      break;
    case MusgraveType::kHeteroTerrain: {
      value = offset + s(0);
      int i = 1;
      for (; i < n; ++i) value += (s(i) + offset) * w(i) * value;
      if (rest != 0) value += rest * (s(i) + offset) * w(i) * value;
      break;
    }
    case MusgraveType::kHybridMultifractal: {
      double weight = 1;
      int i = 0;
      for (; weight > 0.001f && i < n; ++i) {
        weight = std::min(weight, 1.0);
        const double signal = (s(i) + offset) * w(i);
        value += weight * signal;
        weight *= gain * signal;
      }
      if (rest != 0 && weight > 0.001f)
        value += rest * std::min(weight, 1.0) * (s(i) + offset) * w(i);
      break;
    }
    case MusgraveType::kRidgedMultifractal: {
      double signal = (offset - std::abs(s(0))) * (offset - std::abs(s(0)));
      value = signal;
      for (int i = 1; i < n; ++i) {
        const double weight = std::clamp(signal * gain, 0.0, 1.0);
        signal = (offset - std::abs(s(i))) * (offset - std::abs(s(i))) * weight;
        value += signal * w(i);
      }
      break;
    }
    default:
      break;
  }
  return value;
}

// The other Musgrave types: each Fac is the reference's (octave 0 whole, a fractional Detail's
// extra octave as Cycles reads it, ridged ignoring the fraction) and the gradient the derivative,
// at points where no kink (|s| = 0, a weight reaching its clamp, the hybrid's stop) lies within
// the central difference's step: there its one-sided differences disagree and the point is
// skipped.
TEST(BlenderMusgrave, OtherTypesAreCyclesAndTheirGradientsAreTheDerivatives) {
  int checked = 0;
  for (const MusgraveType type :
       {MusgraveType::kMultifractal, MusgraveType::kRidgedMultifractal,
        MusgraveType::kHybridMultifractal, MusgraveType::kHeteroTerrain}) {
    // Ridged: signals (1 − |s|)² in [0, 1] times Gain 3 clamp at 1 at about half of the points;
    // hybrid: weights 1.8 (s + 0.7) too.
    const bool ridged = type == MusgraveType::kRidgedMultifractal;
    const double offset = ridged ? 1.0 : 0.7, gain = ridged ? 3.0 : 1.8;
    for (const double detail : {0.5, 1.0, 2.5, 4.0}) {
      const BlenderMusgraveParams params{.amplitude = 0.4,
                                         .scale = 2.5,
                                         .type = type,
                                         .detail = detail,
                                         .dimension = 0.8,
                                         .lacunarity = 2.3,
                                         .offset = offset,
                                         .gain = gain};
      Result<BlenderMusgrave> made = BlenderMusgrave::create(params);
      ASSERT_TRUE(made) << made.error().message;
      std::mt19937_64 rng(31);
      std::uniform_real_distribution<double> along(-3, 3);
      for (int i = 0; i < 200; ++i) {
        const Vec3d p{along(rng), along(rng), along(rng)};
        const double expected = musgraveReference(type, 2.5 * p, detail, 0.8, 2.3, offset, gain);
        EXPECT_NEAR(made->value(p), 0.4 * expected, 1e-13) << int(type) << ' ' << detail;
        const auto f = [&](Vec3d r) { return made->value(r); };
        const double step = 1e-6;
        const Vec3d central = centralGradient(f, p, step);
        const Vec3d forward = centralGradient(f, p + Vec3d{step, step, step} * 0.5, step * 0.5);
        const Vec3d backward = centralGradient(f, p - Vec3d{step, step, step} * 0.5, step * 0.5);
        if (maxAbsDiff(forward, backward) > 1e-3) continue;  // a kink within the step
        ++checked;
        EXPECT_LT(maxAbsDiff(made->analyticGradient(p), central), 1e-6)
            << int(type) << ' ' << detail;
      }
    }
  }
  EXPECT_GT(checked, 3150);  // of 3200
}

// Special cases: one octave of multifractal is 1 + s₀; ridged with Detail 1 is (offset − |s₀|)²,
// and its fraction is ignored (Detail 2.9 reads as 2); hetero terrain's first octave is whole
// (Detail 0 is offset + s₀); fBM is unchanged by offset and gain.
TEST(BlenderMusgrave, OtherTypesSpecialCases) {
  const auto fac = [](BlenderMusgraveParams params, Vec3d p) {
    params.scale = 1;
    return BlenderMusgrave::create(params).value().value(p);
  };
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> along(-4, 4);
  for (int i = 0; i < 100; ++i) {
    const Vec3d p{along(rng), along(rng), along(rng)};
    const double s = blenderSignedNoise(p, nullptr);
    EXPECT_NEAR(fac({.type = MusgraveType::kMultifractal, .detail = 1}, p), 1 + s, 1e-15);
    EXPECT_NEAR(fac({.type = MusgraveType::kRidgedMultifractal, .detail = 1, .offset = 1}, p),
                (1 - std::abs(s)) * (1 - std::abs(s)), 1e-15);
    EXPECT_EQ(fac({.type = MusgraveType::kRidgedMultifractal, .detail = 2.9, .gain = 3}, p),
              fac({.type = MusgraveType::kRidgedMultifractal, .detail = 2, .gain = 3}, p));
    EXPECT_NEAR(fac({.type = MusgraveType::kHeteroTerrain, .detail = 0, .offset = 0.3}, p), 0.3 + s,
                1e-15);
    EXPECT_EQ(fac({.detail = 3.5, .offset = 0.6, .gain = 2}, p), fac({.detail = 3.5}, p));
  }
}

// The Wave Texture's gradient, every type and profile, distorted or not, away from the saw's and
// triangle's corners (where the value jumps or folds: skipped when the central difference's two
// sides would straddle one).
TEST(BlenderWave, AnalyticGradientIsTheDerivativeOfTheValue) {
  std::mt19937_64 rng(21);
  std::uniform_real_distribution<double> along(-1, 1);
  int checked = 0;
  for (const WaveType type : {WaveType::kBands, WaveType::kRings}) {
    for (const WaveDirection direction :
         {WaveDirection::kX, WaveDirection::kZ,
          type == WaveType::kBands ? WaveDirection::kDiagonal : WaveDirection::kSpherical}) {
      for (const WaveProfile profile :
           {WaveProfile::kSine, WaveProfile::kSaw, WaveProfile::kTriangle}) {
        for (const double distortion : {0.0, 1.3}) {
          Result<BlenderWave> made = BlenderWave::create({.amplitude = 0.7,
                                                          .scale = 1.7,
                                                          .type = type,
                                                          .direction = direction,
                                                          .profile = profile,
                                                          .distortion = distortion,
                                                          .detail = 2.5,
                                                          .detailScale = 1.5,
                                                          .detailRoughness = 0.6,
                                                          .phase = 0.4});
          ASSERT_TRUE(made) << made.error().message;
          for (int i = 0; i < 40; ++i) {
            const Vec3d p{along(rng), along(rng), along(rng)};
            const double h = 1e-6;
            const Vec3d central = centralGradient([&](Vec3d q) { return made->value(q); }, p, h);
            const Vec3d exact = made->analyticGradient(p);
            // A corner between the two sides: the difference quotient is far from any slope.
            if (std::abs(central.x) + std::abs(central.y) + std::abs(central.z) > 1e3) continue;
            EXPECT_LT(maxAbsDiff(exact, central),
                      1e-5 * (1 + std::abs(exact.x) + std::abs(exact.y) + std::abs(exact.z)))
                << static_cast<int>(type) << static_cast<int>(direction)
                << static_cast<int>(profile) << " " << distortion;
            ++checked;
          }
        }
      }
    }
  }
  EXPECT_GT(checked, 1300);
}

// With Randomness 0 every cell's point is its corner: Distance is the metric's distance to the
// nearest lattice point, per axis min(f, 1 − f).
TEST(BlenderVoronoi, WithoutRandomnessMeasuresToTheNearestLatticePoint) {
  std::mt19937_64 rng(31);
  std::uniform_real_distribution<double> along(-4, 4);
  for (const VoronoiMetric metric : {VoronoiMetric::kEuclidean, VoronoiMetric::kManhattan,
                                     VoronoiMetric::kChebyshev, VoronoiMetric::kMinkowski}) {
    Result<BlenderVoronoi> made =
        BlenderVoronoi::create({.scale = 2, .randomness = 0, .metric = metric, .exponent = 1.5});
    ASSERT_TRUE(made) << made.error().message;
    for (int i = 0; i < 200; ++i) {
      const Vec3d p{along(rng), along(rng), along(rng)};
      const auto nearest = [](double v) {
        const double f = v - std::floor(v);
        return std::min(f, 1 - f);
      };
      const Vec3d a{nearest(2 * p.x), nearest(2 * p.y), nearest(2 * p.z)};
      const double expected =
          metric == VoronoiMetric::kEuclidean   ? std::sqrt(dot(a, a))
          : metric == VoronoiMetric::kManhattan ? a.x + a.y + a.z
          : metric == VoronoiMetric::kChebyshev
              ? std::max({a.x, a.y, a.z})
              : std::pow(std::pow(a.x, 1.5) + std::pow(a.y, 1.5) + std::pow(a.z, 1.5), 1 / 1.5);
      EXPECT_NEAR(made->value(p), expected, 1e-12) << static_cast<int>(metric);
    }
  }
}

// Away from the borders between cells' points the Distance's gradient is the metric's.
TEST(BlenderVoronoi, AnalyticGradientIsTheDerivativeOfTheValue) {
  std::mt19937_64 rng(32);
  std::uniform_real_distribution<double> along(-2, 2);
  int checked = 0;
  for (const VoronoiMetric metric : {VoronoiMetric::kEuclidean, VoronoiMetric::kManhattan,
                                     VoronoiMetric::kChebyshev, VoronoiMetric::kMinkowski}) {
    Result<BlenderVoronoi> made = BlenderVoronoi::create(
        {.amplitude = 0.3, .scale = 3, .randomness = 0.9, .metric = metric, .exponent = 1.7});
    ASSERT_TRUE(made) << made.error().message;
    for (int i = 0; i < 300; ++i) {
      const Vec3d p{along(rng), along(rng), along(rng)};
      const Vec3d central = centralGradient([&](Vec3d q) { return made->value(q); }, p, 1e-7);
      const Vec3d exact = made->analyticGradient(p);
      if (maxAbsDiff(exact, central) > 1e-3) continue;  // a border between the two sides
      EXPECT_LT(maxAbsDiff(exact, central), 1e-6) << static_cast<int>(metric);
      ++checked;
    }
  }
  EXPECT_GT(checked, 1150);  // borders are rare at this step
}

// With Randomness 0, F2 is the distance to the second-nearest lattice point: the nearest with the
// axis farthest from its lattice plane flipped to the other side (a → 1 − a).
TEST(BlenderVoronoi, F2WithoutRandomnessMeasuresToTheSecondNearestLatticePoint) {
  std::mt19937_64 rng(33);
  std::uniform_real_distribution<double> along(-4, 4);
  for (const VoronoiMetric metric : {VoronoiMetric::kEuclidean, VoronoiMetric::kManhattan,
                                     VoronoiMetric::kChebyshev, VoronoiMetric::kMinkowski}) {
    Result<BlenderVoronoi> made = BlenderVoronoi::create({.scale = 2,
                                                          .randomness = 0,
                                                          .metric = metric,
                                                          .exponent = 1.5,
                                                          .feature = VoronoiFeature::kF2});
    ASSERT_TRUE(made) << made.error().message;
    for (int i = 0; i < 200; ++i) {
      const Vec3d p{along(rng), along(rng), along(rng)};
      const auto nearest = [](double v) {
        const double f = v - std::floor(v);
        return std::min(f, 1 - f);
      };
      std::array<double, 3> a{nearest(2 * p.x), nearest(2 * p.y), nearest(2 * p.z)};
      std::sort(a.begin(), a.end());
      a[2] = 1 - a[2];
      const double expected =
          metric == VoronoiMetric::kEuclidean   ? std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])
          : metric == VoronoiMetric::kManhattan ? a[0] + a[1] + a[2]
          : metric == VoronoiMetric::kChebyshev
              ? a[2]
              : std::pow(std::pow(a[0], 1.5) + std::pow(a[1], 1.5) + std::pow(a[2], 1.5), 1 / 1.5);
      EXPECT_NEAR(made->value(p), expected, 1e-12) << static_cast<int>(metric);
    }
  }
}

// With Randomness 0 the cells' points make a cubic lattice, whose nearest bisector plane is the
// one across the axis farthest from the nearest point: Distance to Edge is ½ − that distance,
// whatever the metric.
TEST(BlenderVoronoi, DistanceToEdgeWithoutRandomnessIsToTheNearestCubeFace) {
  std::mt19937_64 rng(34);
  std::uniform_real_distribution<double> along(-4, 4);
  for (const VoronoiMetric metric : {VoronoiMetric::kEuclidean, VoronoiMetric::kManhattan}) {
    Result<BlenderVoronoi> made =
        BlenderVoronoi::create({.scale = 2,
                                .randomness = 0,
                                .metric = metric,
                                .exponent = -1,  // not used
                                .feature = VoronoiFeature::kDistanceToEdge});
    ASSERT_TRUE(made) << made.error().message;
    for (int i = 0; i < 200; ++i) {
      const Vec3d p{along(rng), along(rng), along(rng)};
      const auto nearest = [](double v) {
        const double f = v - std::floor(v);
        return std::min(f, 1 - f);
      };
      const double farthest = std::max({nearest(2 * p.x), nearest(2 * p.y), nearest(2 * p.z)});
      EXPECT_NEAR(made->value(p), 0.5 - farthest, 1e-12);
    }
  }
}

// Smooth F1 with Smoothness 0 is F1 (but for the rounding of D + (d − D)); with Smoothness it is
// a smooth minimum: never above F1, below it where another point is within the blend's reach.
TEST(BlenderVoronoi, SmoothF1IsASmoothMinimumBelowF1) {
  std::mt19937_64 rng(35);
  std::uniform_real_distribution<double> along(-3, 3);
  Result<BlenderVoronoi> f1 = BlenderVoronoi::create({.scale = 2, .randomness = 0});
  Result<BlenderVoronoi> sharp = BlenderVoronoi::create(
      {.scale = 2, .randomness = 0, .feature = VoronoiFeature::kSmoothF1, .smoothness = 0});
  Result<BlenderVoronoi> f1Random = BlenderVoronoi::create({.scale = 2, .randomness = 0.8});
  Result<BlenderVoronoi> smooth = BlenderVoronoi::create(
      {.scale = 2, .randomness = 0.8, .feature = VoronoiFeature::kSmoothF1, .smoothness = 0.6});
  ASSERT_TRUE(f1 && sharp && f1Random && smooth);
  int below = 0;
  for (int i = 0; i < 200; ++i) {
    const Vec3d p{along(rng), along(rng), along(rng)};
    EXPECT_NEAR(sharp->value(p), f1->value(p), 1e-15);
    EXPECT_LE(smooth->value(p), f1Random->value(p) + 1e-15);
    if (smooth->value(p) < f1Random->value(p) - 1e-3) ++below;
  }
  EXPECT_GT(below, 100);
}

// F2's, Distance to Edge's and Smooth F1's gradients are their values' derivatives (away from the
// borders where F2's order or Distance to Edge's plane changes; Smooth F1 has none with the
// Euclidean metric).
TEST(BlenderVoronoi, OtherFeaturesGradientsAreTheDerivativesOfTheValues) {
  std::mt19937_64 rng(36);
  std::uniform_real_distribution<double> along(-2, 2);
  for (const VoronoiFeature feature :
       {VoronoiFeature::kF2, VoronoiFeature::kDistanceToEdge, VoronoiFeature::kSmoothF1}) {
    for (const VoronoiMetric metric : {VoronoiMetric::kEuclidean, VoronoiMetric::kManhattan,
                                       VoronoiMetric::kChebyshev, VoronoiMetric::kMinkowski}) {
      Result<BlenderVoronoi> made = BlenderVoronoi::create({.amplitude = 0.3,
                                                            .scale = 3,
                                                            .randomness = 0.9,
                                                            .metric = metric,
                                                            .exponent = 1.7,
                                                            .feature = feature,
                                                            .smoothness = 0.7});
      ASSERT_TRUE(made) << made.error().message;
      const bool everywhere =
          feature == VoronoiFeature::kSmoothF1 && metric == VoronoiMetric::kEuclidean;
      int checked = 0;
      for (int i = 0; i < 300; ++i) {
        const Vec3d p{along(rng), along(rng), along(rng)};
        const Vec3d central = centralGradient([&](Vec3d q) { return made->value(q); }, p, 1e-7);
        const Vec3d exact = made->analyticGradient(p);
        if (!everywhere && maxAbsDiff(exact, central) > 1e-3) continue;  // a border
        EXPECT_LT(maxAbsDiff(exact, central), 1e-6)
            << static_cast<int>(feature) << ' ' << static_cast<int>(metric);
        ++checked;
      }
      EXPECT_GT(checked, 270) << static_cast<int>(feature) << ' ' << static_cast<int>(metric);
    }
  }
}

TEST(BlenderWave, RefusesADirectionItsTypeHasNot) {
  Result<BlenderWave> rings =
      BlenderWave::create({.type = WaveType::kRings, .direction = WaveDirection::kDiagonal});
  ASSERT_FALSE(rings);
  EXPECT_EQ(rings.error().message,
            "a Wave Texture's direction is diagonal for bands only, spherical for rings only");
  EXPECT_FALSE(
      BlenderWave::create({.type = WaveType::kBands, .direction = WaveDirection::kSpherical}));
  EXPECT_TRUE(
      BlenderWave::create({.type = WaveType::kRings, .direction = WaveDirection::kSpherical}));
}

// Octave i's slopes grow as (L^(1−H))ⁱ: a Lacunarity below 1 with a large Dimension grows them as
// surely as a large Lacunarity does, and both are refused before they overflow.
TEST(BlenderMusgrave, RefusesSlopesThatWouldOverflow) {
  EXPECT_FALSE(BlenderMusgrave::create({.detail = 15, .dimension = 200, .lacunarity = 0.5}));
  EXPECT_FALSE(BlenderMusgrave::create({.detail = 15, .dimension = 0, .lacunarity = 1e30}));
  EXPECT_TRUE(BlenderMusgrave::create({.detail = 15, .dimension = 2, .lacunarity = 0.5}));
  Result<BlenderMusgrave> made =
      BlenderMusgrave::create({.detail = 15, .dimension = 200, .lacunarity = 0.5});
  ASSERT_FALSE(made);
  EXPECT_EQ(made.error().message,
            "Musgrave Texture slopes beyond 1e300 (amplitude × scale × (1 + detail) × "
            "lacunarity^((1 − dimension) · detail))");
}

// The other types multiply octaves: a large Offset or Gain, or an octave weight L^(−H) above 1,
// raised to powers growing with Detail, would overflow; Blender's ranges of them do not.
TEST(BlenderMusgrave, OtherTypesRefuseSlopesThatWouldOverflow) {
  using enum MusgraveType;
  for (const MusgraveType type :
       {kMultifractal, kRidgedMultifractal, kHybridMultifractal, kHeteroTerrain}) {
    // Blender's extremes: Detail 15, Dimension 0, Lacunarity 1000, Offset ±1000, Gain 1000.
    EXPECT_TRUE(BlenderMusgrave::create({.type = type, .detail = 15}));
    EXPECT_TRUE(BlenderMusgrave::create({.type = type,
                                         .detail = 15,
                                         .dimension = 0,
                                         .lacunarity = 1000,
                                         .offset = -1000,
                                         .gain = 1000}));
    EXPECT_TRUE(BlenderMusgrave::create(
        {.type = type, .detail = 15, .dimension = 2, .lacunarity = 0.5, .offset = 3, .gain = 4}));
    // Octave weights 0.5^(−200) as the fBM's, and here multiplied.
    EXPECT_FALSE(
        BlenderMusgrave::create({.type = type, .detail = 15, .dimension = 200, .lacunarity = 0.5}))
        << int(type);
    // Octave weights (1e-5)^(−2) = 1e10: the products of 16 of them overflow, the ridged's sum
    // (and fBM's) does not.
    EXPECT_EQ(bool(BlenderMusgrave::create({.type = type, .detail = 15, .lacunarity = 1e-5})),
              type == kRidgedMultifractal)
        << int(type);
  }
  EXPECT_TRUE(BlenderMusgrave::create({.detail = 15, .lacunarity = 1e-5}));
  // Offset and gain grow the octaves the types multiply or weight.
  EXPECT_FALSE(BlenderMusgrave::create({.type = kHeteroTerrain, .detail = 15, .offset = 1e20}));
  EXPECT_FALSE(BlenderMusgrave::create({.type = kHybridMultifractal, .detail = 15, .gain = 1e20}));
  EXPECT_FALSE(
      BlenderMusgrave::create({.type = kRidgedMultifractal, .detail = 15, .offset = 1e10}));
  EXPECT_FALSE(BlenderMusgrave::create({.type = kRidgedMultifractal, .detail = 15, .gain = 1e21}));
  // Offset does not enter the multifractal, which does not refuse it.
  EXPECT_TRUE(BlenderMusgrave::create({.type = kMultifractal, .detail = 15, .offset = 1e20}));
  Result<BlenderMusgrave> made =
      BlenderMusgrave::create({.type = kHeteroTerrain, .detail = 15, .offset = 1e20});
  ASSERT_FALSE(made);
  EXPECT_EQ(made.error().message,
            "Musgrave Texture slopes beyond 1e300 (amplitude × scale × the type's octaves "
            "multiplied: (1 + offset), gain and lacunarity^(−dimension) to powers growing with "
            "detail)");
  EXPECT_EQ(
      BlenderMusgrave::create({.type = kRidgedMultifractal, .gain = std::nan("")}).error().message,
      "a Musgrave Texture setting is not finite");
}

// A Mapping node before the texture: the value at the mapped point, the gradient pulled back.
TEST(MappedHeightVolume, ReadsTheMappedPointAndPullsTheGradientBack) {
  const BlenderNoise noise = makeNoise({.scale = 3, .detail = 1});
  const CoordinateMapping mapping =
      CoordinateMapping::fromMappingNode({0.2, -1, 0.5}, {0.3, 0.1, -0.7}, {2, 0.5, 1.5});
  const MappedHeightVolume mapped(noise, mapping);
  std::mt19937_64 rng(8);
  std::uniform_real_distribution<double> along(-2, 2);
  for (int i = 0; i < 200; ++i) {
    const Vec3d p{along(rng), along(rng), along(rng)};
    EXPECT_EQ(mapped.value(p), noise.value(mapping.apply(p)));
    const Vec3d central = centralGradient([&](Vec3d q) { return mapped.value(q); }, p, 1e-6);
    EXPECT_LT(maxAbsDiff(mapped.analyticGradient(p), central), 1e-6);
  }
}

TEST(BlenderNoise, RejectsSettingsThatAreNotFinite) {
  BlenderNoiseParams params;
  params.distortion = std::nan("");
  Result<BlenderNoise> made = BlenderNoise::create(params);
  ASSERT_FALSE(made);
  EXPECT_EQ(made.error().message, "a Noise Texture setting is not finite");
  params.distortion = 0;
  params.amplitude = 1e300;
  EXPECT_FALSE(BlenderNoise::create(params));
}

}  // namespace
}  // namespace sgbake
