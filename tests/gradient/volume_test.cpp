/// @file volume_test.cpp
/// @brief Height volumes and their gradients: closed forms on a sphere, convergence orders of the
/// finite-difference schemes, exactness on linear fields, the noise's properties (exact
/// analytic gradient, C² across cells, bound, zeros, seeds, determinism) and extreme inputs.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <thread>
#include <vector>

#include "sgbake/core/math.hpp"
#include "sgbake/gradient/volume.hpp"

namespace sgbake {
namespace {

constexpr double kTwoPi = 2.0 * kPi;
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// ------------------------------------------------------------------------------------------------
// Helpers
// ------------------------------------------------------------------------------------------------

/// Deterministic random numbers: the raw output of mt19937_64 is fixed by the standard (the
/// std distributions are not), mapped to [0, 1) through its top 53 bits.
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : engine_(seed) {}
  double uniform() { return static_cast<double>(engine_() >> 11) * 0x1p-53; }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  Vec3d inBox(double half) {
    return {uniform(-half, half), uniform(-half, half), uniform(-half, half)};
  }
  /// Uniform on the unit sphere (Archimedes: z uniform in [−1, 1], azimuth uniform).
  Vec3d onSphere() {
    const double z = uniform(-1, 1);
    const double phi = uniform(0, kTwoPi);
    const double r = std::sqrt(std::max(0.0, 1 - z * z));
    return {r * std::cos(phi), r * std::sin(phi), z};
  }

 private:
  std::mt19937_64 engine_;
};

std::vector<Vec3d> spherePoints(int count, std::uint64_t seed) {
  Rng rng(seed);
  std::vector<Vec3d> points;
  points.reserve(static_cast<std::size_t>(count));
  for (int i = 0; i < count; ++i) points.push_back(rng.onSphere());
  return points;
}

DirectionalSine makeSine(const DirectionalSineParams& params) {
  Result<DirectionalSine> r = DirectionalSine::create(params);
  EXPECT_TRUE(r.ok());
  return std::move(r).value();
}

GradientNoise makeNoise(const GradientNoiseParams& params) {
  Result<GradientNoise> r = GradientNoise::create(params);
  EXPECT_TRUE(r.ok());
  return std::move(r).value();
}

/// h(P) = ⟨g, P⟩ + c: every scheme must return g up to round-off.
class LinearField final : public HeightVolume {
 public:
  LinearField(Vec3d g, double c) : g_(g), c_(c) {}
  double value(Vec3d p) const override { return dot(g_, p) + c_; }
  Vec3d analyticGradient(Vec3d) const override { return g_; }

 private:
  Vec3d g_;
  double c_;
};

/// max over the unit-sphere points P (N = P) of |Γ_scheme − Γ_analytic|.
double maxSurfaceGradientError(const HeightVolume& volume, const std::vector<Vec3d>& points,
                               GradientScheme scheme, double step) {
  double worst = 0;
  for (const Vec3d& p : points) {
    const Vec3d exact = surfaceGradientFromVolume(volume.analyticGradient(p), p);
    const Vec3d approx = surfaceGradientFromVolume(volumeGradient(volume, p, scheme, step), p);
    worst = std::max(worst, length(approx - exact));
  }
  return worst;
}

/// Error ratios e(h)/e(h/2) and e(h/2)/e(h/4): ≈ 2^order.
std::array<double, 2> halvingRatios(const HeightVolume& volume, const std::vector<Vec3d>& points,
                                    GradientScheme scheme, double h) {
  const double e0 = maxSurfaceGradientError(volume, points, scheme, h);
  const double e1 = maxSurfaceGradientError(volume, points, scheme, h / 2);
  const double e2 = maxSurfaceGradientError(volume, points, scheme, h / 4);
  return {e0 / e1, e1 / e2};
}

// Allowed band for the ratio of a second-order scheme (4 = 2²) and a first-order one (2 = 2¹).
constexpr double kSecondOrderMinRatio = 3.0;
constexpr double kSecondOrderMaxRatio = 5.0;
constexpr double kFirstOrderMinRatio = 1.6;
constexpr double kFirstOrderMaxRatio = 2.4;

/// The wave of the sphere tests: an oblique direction (so every Hessian entry is nonzero).
const DirectionalSineParams kObliqueWave{0.7, 1.3, {1, 2, 3}, 0.4};

// ------------------------------------------------------------------------------------------------
// surfaceGradientFromVolume
// ------------------------------------------------------------------------------------------------

TEST(SurfaceGradientFromVolume, ProjectsOntoTheTangentPlane) {
  Rng rng(1);
  for (int i = 0; i < 1000; ++i) {
    const Vec3d n = rng.onSphere();
    const Vec3d g = rng.inBox(5);
    const Vec3d gamma = surfaceGradientFromVolume(g, n);
    EXPECT_LE(std::abs(dot(gamma, n)), 1e-14 * length(g));
    // What was removed is parallel to N.
    EXPECT_LE(length(cross(g - gamma, n)), 1e-14 * length(g));
  }
  EXPECT_EQ(surfaceGradientFromVolume({0, 0, 3}, {0, 0, 1}), (Vec3d{0, 0, 0}));
  EXPECT_EQ(surfaceGradientFromVolume({1, 2, 0}, {0, 0, 1}), (Vec3d{1, 2, 0}));
}

// ------------------------------------------------------------------------------------------------
// DirectionalSine
// ------------------------------------------------------------------------------------------------

TEST(DirectionalSine, RejectsInvalidParameters) {
  EXPECT_FALSE(DirectionalSine::create({1, 1, {0, 0, 0}, 0}).ok());
  EXPECT_FALSE(DirectionalSine::create({1, 1, {1e-320, 0, 0}, 0}).ok());  // denormal: zero
  EXPECT_FALSE(DirectionalSine::create({1, 1, {kNaN, 0, 1}, 0}).ok());
  EXPECT_FALSE(DirectionalSine::create({1, 1, {kInf, 0, 1}, 0}).ok());
  EXPECT_FALSE(DirectionalSine::create({kNaN, 1, {1, 0, 0}, 0}).ok());
  EXPECT_FALSE(DirectionalSine::create({1, kInf, {1, 0, 0}, 0}).ok());
  EXPECT_FALSE(DirectionalSine::create({1, 1, {1, 0, 0}, kNaN}).ok());
  EXPECT_FALSE(DirectionalSine::create({1e299, 1e10, {1, 0, 0}, 0}).ok());  // slope > 1e300
  const Result<DirectionalSine> bad = DirectionalSine::create({1, 1, {0, 0, 0}, 0});
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().code, ErrorCode::kBadInput);
  EXPECT_NE(bad.error().message.find("direction"), std::string::npos);
}

TEST(DirectionalSine, NormalizesTheDirection) {
  const DirectionalSine sine = makeSine({2, 0.5, {0, 3, 4}, 0});
  EXPECT_NEAR(length(sine.direction()), 1.0, 1e-15);
  EXPECT_NEAR(sine.direction().y, 0.6, 1e-15);
  EXPECT_NEAR(sine.direction().z, 0.8, 1e-15);
  EXPECT_DOUBLE_EQ(sine.angularFrequency(), kPi);
  // Tiny but normal direction vectors are fine.
  const DirectionalSine tiny = makeSine({1, 1, {1e-300, 0, 0}, 0});
  EXPECT_EQ(tiny.direction(), (Vec3d{1, 0, 0}));
}

TEST(DirectionalSine, SurfaceGradientOnUnitSphereMatchesClosedForm) {
  const DirectionalSine sine = makeSine(kObliqueWave);
  const double A = kObliqueWave.amplitude;
  const double f = kObliqueWave.frequency;
  const Vec3d d = kObliqueWave.direction;
  const Vec3d dHat = (1.0 / length(d)) * d;
  // "Relative" is relative to the gradient scale A·2πf: Γ itself vanishes at some points.
  const double scale = A * kTwoPi * f;
  constexpr double kRelativeTolerance = 1e-12;
  constexpr double kOrthogonalityTolerance = 1e-14;
  for (const Vec3d& p : spherePoints(5000, 2)) {
    const Vec3d n = p;  // unit sphere: N = P
    const Vec3d gamma = surfaceGradientFromVolume(sine.analyticGradient(p), n);
    const double c = A * kTwoPi * f * std::cos(kTwoPi * f * dot(dHat, p) + kObliqueWave.phase);
    const Vec3d closedForm = c * (dHat - dot(dHat, n) * n);
    EXPECT_LE(length(gamma - closedForm), kRelativeTolerance * scale)
        << p.x << " " << p.y << " " << p.z;
    EXPECT_LE(std::abs(dot(gamma, n)), kOrthogonalityTolerance * scale);
    // The value is the formula's, too.
    EXPECT_NEAR(sine.value(p), A * std::sin(kTwoPi * f * dot(dHat, p) + kObliqueWave.phase),
                1e-14 * A);
  }
}

// The step range of the order tests: ε·ω ≤ 0.08, so the next Taylor term changes the ratios by
// well under 10%, and the truncation error (≥ 1e-7 · scale) is orders of magnitude above the
// round-off error (≈ 1e-16 / ε ≈ 1e-13).
constexpr double kOrderTestStep = 1e-2;

TEST(DirectionalSine, CentralDifferencesAreSecondOrder) {
  const DirectionalSine sine = makeSine(kObliqueWave);
  const std::vector<Vec3d> points = spherePoints(2000, 3);
  const auto ratios = halvingRatios(sine, points, GradientScheme::kCentral, kOrderTestStep);
  for (double r : ratios) {
    EXPECT_GE(r, kSecondOrderMinRatio);
    EXPECT_LE(r, kSecondOrderMaxRatio);
  }
}

// Seed 002's tetrahedral scheme is first order for a general field: the error's leading term is
// ε·(h_yz, h_xz, h_xy) (see GradientScheme::kTetrahedral). Halving the step halves the error.
TEST(DirectionalSine, TetrahedralDifferencesAreFirstOrderInGeneral) {
  const DirectionalSine sine = makeSine(kObliqueWave);
  const std::vector<Vec3d> points = spherePoints(2000, 3);
  const auto ratios = halvingRatios(sine, points, GradientScheme::kTetrahedral, kOrderTestStep);
  for (double r : ratios) {
    EXPECT_GE(r, kFirstOrderMinRatio);
    EXPECT_LE(r, kFirstOrderMaxRatio);
  }
}

// With the wave along a coordinate axis the Hessian is diagonal, the first-order term vanishes
// and the tetrahedral scheme is second order, like the central one.
TEST(DirectionalSine, TetrahedralDifferencesAreSecondOrderForDiagonalHessian) {
  for (const Vec3d axis : {Vec3d{1, 0, 0}, Vec3d{0, 1, 0}, Vec3d{0, 0, 1}}) {
    const DirectionalSine sine = makeSine({0.7, 1.3, axis, 0.4});
    const std::vector<Vec3d> points = spherePoints(2000, 4);
    for (GradientScheme scheme : {GradientScheme::kCentral, GradientScheme::kTetrahedral}) {
      const auto ratios = halvingRatios(sine, points, scheme, kOrderTestStep);
      for (double r : ratios) {
        EXPECT_GE(r, kSecondOrderMinRatio);
        EXPECT_LE(r, kSecondOrderMaxRatio);
      }
    }
  }
}

// The tetrahedral error is ε·(h_yz, h_xz, h_xy) to leading order; for the sine
// H = −A ω² sin(θ) d̂ d̂ᵀ. This pins the scheme's constant 1/(4ε) and its orientation.
TEST(DirectionalSine, TetrahedralErrorHasThePredictedLeadingTerm) {
  const DirectionalSine sine = makeSine(kObliqueWave);
  const Vec3d d = sine.direction();
  const double A = sine.amplitude();
  const double w = sine.angularFrequency();
  constexpr double kStep = 1e-5;
  // Next term: O(ε² A ω³) ≈ 1e-3 of the leading one at this step; round-off ≈ 1e-11.
  constexpr double kTolerance = 1e-3;
  for (const Vec3d& p : spherePoints(500, 5)) {
    const double hessianScale = -A * w * w * std::sin(w * dot(d, p) + sine.phase());
    const Vec3d predicted = kStep * hessianScale * Vec3d{d.y * d.z, d.x * d.z, d.x * d.y};
    const Vec3d error =
        volumeGradient(sine, p, GradientScheme::kTetrahedral, kStep) - sine.analyticGradient(p);
    EXPECT_LE(length(error - predicted), kTolerance * kStep * A * w * w);
  }
}

// ------------------------------------------------------------------------------------------------
// Linear fields: every scheme is exact
// ------------------------------------------------------------------------------------------------

TEST(VolumeGradient, LinearFieldIsExactForAllSchemes) {
  Rng rng(6);
  for (int i = 0; i < 200; ++i) {
    const Vec3d g = rng.inBox(3);
    const double c = rng.uniform(-10, 10);
    const LinearField field(g, c);
    const Vec3d p = rng.inBox(10);
    EXPECT_EQ(volumeGradient(field, p, GradientScheme::kAnalytic, 0.1), g);
    for (double step : {1e-6, 1e-3, 0.25, 1.0, 1e3}) {
      // Round-off: the taps' values carry ≈ u·(|g|(|P| + √3ε) + |c|); dividing by ε amplifies it.
      const double magnitude = length(g) * (length(p) + 2 * step) + std::abs(c);
      const double tolerance = 16 * DBL_EPSILON * (magnitude / step + length(g));
      for (GradientScheme scheme : {GradientScheme::kCentral, GradientScheme::kTetrahedral}) {
        const Vec3d approx = volumeGradient(field, p, scheme, step);
        EXPECT_LE(length(approx - g), tolerance) << "step " << step;
      }
    }
  }
}

TEST(VolumeGradient, SignOfTheStepDoesNotMatterForCentral) {
  const DirectionalSine sine = makeSine(kObliqueWave);
  const Vec3d p{0.3, -0.2, 0.9};
  EXPECT_EQ(volumeGradient(sine, p, GradientScheme::kCentral, 1e-3),
            volumeGradient(sine, p, GradientScheme::kCentral, -1e-3));
  EXPECT_EQ(volumeGradient(sine, p, GradientScheme::kTetrahedral, 1e-3),
            volumeGradient(sine, p, GradientScheme::kTetrahedral, -1e-3));
}

// ------------------------------------------------------------------------------------------------
// GradientNoise
// ------------------------------------------------------------------------------------------------

TEST(GradientNoise, RejectsInvalidParameters) {
  EXPECT_FALSE(GradientNoise::create({1, 0, 0, 1}).ok());
  EXPECT_FALSE(GradientNoise::create({1, -2, 0, 1}).ok());
  EXPECT_FALSE(GradientNoise::create({1, kInf, 0, 1}).ok());
  EXPECT_FALSE(GradientNoise::create({kNaN, 1, 0, 1}).ok());
  EXPECT_FALSE(GradientNoise::create({1, 1, 0, 0}).ok());
  EXPECT_FALSE(GradientNoise::create({1, 1, 0, kMaxNoiseOctaves + 1}).ok());
  EXPECT_FALSE(GradientNoise::create({1e299, 1e5, 0, 1}).ok());
  EXPECT_TRUE(GradientNoise::create({1, 1, 0, kMaxNoiseOctaves}).ok());
}

/// Points that stress the cell structure for lattice frequency @p baseFrequency: random ones, on
/// cell faces, edges and corners (integer lattice coordinates), and points just off them.
std::vector<Vec3d> noiseTestPoints(double baseFrequency, std::uint64_t seed) {
  Rng rng(seed);
  std::vector<Vec3d> points;
  for (int i = 0; i < 300; ++i) points.push_back(rng.inBox(5));
  for (int i = 0; i < 300; ++i) {
    Vec3d lattice{std::round(rng.uniform(-20, 20)), std::round(rng.uniform(-20, 20)),
                  std::round(rng.uniform(-20, 20))};
    Vec3d p = (1.0 / baseFrequency) * lattice;  // a corner (all three coordinates on the lattice)
    points.push_back(p);
    for (std::size_t a = 0; a < 3; ++a) {
      Vec3d face = p;  // two coordinates off the lattice: on a face of axis a
      face[(a + 1) % 3] += rng.uniform(0, 1) / baseFrequency;
      face[(a + 2) % 3] += rng.uniform(0, 1) / baseFrequency;
      points.push_back(face);
      Vec3d edge = p;  // one coordinate off the lattice: on an edge
      edge[a] += rng.uniform(0, 1) / baseFrequency;
      points.push_back(edge);
      Vec3d nearFace = face;
      nearFace[a] += 1e-9 / baseFrequency;
      points.push_back(nearFace);
    }
  }
  return points;
}

TEST(GradientNoise, AnalyticGradientMatchesTinyStepCentralDifferences) {
  for (const GradientNoiseParams params :
       {GradientNoiseParams{1, 1, 0, 1}, GradientNoiseParams{0.3, 4, 17, 1},
        GradientNoiseParams{2, 0.5, 99, 4}, GradientNoiseParams{1, 3.7, 5, 3}}) {
    const GradientNoise noise = makeNoise(params);
    const double finest = std::ldexp(params.frequency, params.octaves - 1);
    // ε = 1e-5 of the finest cell: truncation ≈ (1e-5)²·|h'''|/6 ≪ 1e-6, round-off ≈ 1e-11.
    const double step = 1e-5 / finest;
    // Relative to max(|∇h|, A·F): where ∇h happens to vanish, A·F is the gradient scale.
    const double scale = std::abs(params.amplitude) * params.frequency;
    constexpr double kRelativeTolerance = 1e-6;
    for (const Vec3d& p : noiseTestPoints(params.frequency, 7)) {
      const Vec3d analytic = noise.analyticGradient(p);
      const Vec3d numeric = volumeGradient(noise, p, GradientScheme::kCentral, step);
      EXPECT_LE(length(numeric - analytic), kRelativeTolerance * std::max(length(analytic), scale))
          << "F=" << params.frequency << " octaves=" << params.octaves << " at " << p.x << ","
          << p.y << "," << p.z;
    }
  }
}

TEST(GradientNoise, ZeroAtLatticePoints) {
  // Power-of-two frequencies, so k/F is exact and F·(k/F) is the integer k.
  for (const GradientNoiseParams params :
       {GradientNoiseParams{1, 1, 0, 1}, GradientNoiseParams{3, 4, 8, 1},
        GradientNoiseParams{1, 0.25, 21, 5}}) {
    const GradientNoise noise = makeNoise(params);
    Rng rng(8);
    for (int i = 0; i < 2000; ++i) {
      const Vec3d k{std::round(rng.uniform(-1000, 1000)), std::round(rng.uniform(-1000, 1000)),
                    std::round(rng.uniform(-1000, 1000))};
      EXPECT_EQ(noise.value((1.0 / params.frequency) * k), 0.0);
    }
  }
}

// C0, C1 and C2 across the cell faces x_a = k/F: one-sided limits of h and ∇h agree, and so do
// the one-sided second differences (a cubic fade 3t² − 2t³ would fail the last check by O(1)).
TEST(GradientNoise, SmoothAcrossCellFaces) {
  const GradientNoiseParams params{1.5, 2, 31, 1};
  const GradientNoise noise = makeNoise(params);
  const double F = params.frequency;
  const double A = params.amplitude;
  Rng rng(9);
  constexpr double kValueDelta = 1e-12;   // in cells
  constexpr double kHessianDelta = 1e-5;  // in cells
  for (int i = 0; i < 500; ++i) {
    for (std::size_t a = 0; a < 3; ++a) {
      Vec3d b = rng.inBox(10);
      b[a] = std::round(b[a] * F) / F;  // on a face of axis a
      Vec3d e{};
      e[a] = 1;
      // C0 and C1: h and ∇h just below, at and just above the face.
      const double dv = kValueDelta / F;
      EXPECT_LE(std::abs(noise.value(b + dv * e) - noise.value(b - dv * e)), 1e-10 * A);
      EXPECT_LE(length(noise.analyticGradient(b + dv * e) - noise.analyticGradient(b - dv * e)),
                1e-9 * A * F);
      // C2: ∂∇h/∂x_a from the cell below and from the cell above.
      const double dh = kHessianDelta / F;
      const Vec3d g0 = noise.analyticGradient(b);
      const Vec3d above = (1.0 / dh) * (noise.analyticGradient(b + dh * e) - g0);
      const Vec3d below = (1.0 / dh) * (g0 - noise.analyticGradient(b - dh * e));
      // Agreement to O(δ·h''') ≈ 1e-5·(tens)·A·F²; a jump in h'' would be O(A·F²).
      EXPECT_LE(length(above - below), 5e-3 * A * F * F);
    }
  }
}

TEST(GradientNoise, ValueIsBoundedAndNotTrivial) {
  for (const GradientNoiseParams params :
       {GradientNoiseParams{1, 1, 0, 1}, GradientNoiseParams{2.5, 3, 4, 3}}) {
    const GradientNoise noise = makeNoise(params);
    const double bound = noise.valueBound();
    EXPECT_DOUBLE_EQ(bound, std::abs(params.amplitude) * kNoiseOctaveBound *
                                (2.0 - std::ldexp(2.0, -params.octaves)));
    Rng rng(10);
    double largest = 0;
    double sum = 0;
    constexpr int kSamples = 200000;
    for (int i = 0; i < kSamples; ++i) {
      const double v = noise.value(rng.inBox(50));
      ASSERT_LE(std::abs(v), bound);
      largest = std::max(largest, std::abs(v));
      sum += v;
    }
    // The field uses a good part of its range and averages to about zero.
    EXPECT_GE(largest, 0.4 * bound);
    EXPECT_LE(std::abs(sum / kSamples), 0.02 * bound);
  }
}

TEST(GradientNoise, SeedsChangeTheField) {
  const std::array<std::uint64_t, 4> seeds{0, 1, 2, 0xFFFFFFFFFFFFFFFFull};
  Rng rng(11);
  std::vector<Vec3d> points;
  for (int i = 0; i < 1000; ++i) points.push_back(rng.inBox(8));
  for (std::size_t i = 0; i < seeds.size(); ++i) {
    for (std::size_t j = i + 1; j < seeds.size(); ++j) {
      const GradientNoise a = makeNoise({1, 1, seeds[i], 2});
      const GradientNoise b = makeNoise({1, 1, seeds[j], 2});
      int different = 0;
      for (const Vec3d& p : points) different += a.value(p) != b.value(p) ? 1 : 0;
      EXPECT_GE(different, 990) << seeds[i] << " vs " << seeds[j];
    }
  }
}

TEST(GradientNoise, DeterministicAcrossCallsInstancesAndThreads) {
  const GradientNoiseParams params{1, 2.5, 1234, 4};
  const GradientNoise noise = makeNoise(params);
  Rng rng(12);
  std::vector<Vec3d> points;
  for (int i = 0; i < 20000; ++i) points.push_back(rng.inBox(30));

  std::vector<double> values;
  std::vector<Vec3d> gradients;
  for (const Vec3d& p : points) {
    values.push_back(noise.value(p));
    gradients.push_back(noise.analyticGradient(p));
  }

  const GradientNoise twin = makeNoise(params);
  constexpr int kThreads = 4;
  std::vector<int> mismatches(kThreads, 0);
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&, t] {
      const HeightVolume& volume = (t % 2 == 0) ? static_cast<const HeightVolume&>(noise) : twin;
      // Each thread walks the points in its own order.
      for (std::size_t k = 0; k < points.size(); ++k) {
        const std::size_t i = (k * static_cast<std::size_t>(2 * t + 1)) % points.size();
        if (volume.value(points[i]) != values[i] ||
            !(volume.analyticGradient(points[i]) == gradients[i])) {
          ++mismatches[static_cast<std::size_t>(t)];
        }
      }
    });
  }
  for (std::thread& th : threads) th.join();
  for (int m : mismatches) EXPECT_EQ(m, 0);
}

TEST(GradientNoise, CentralIsSecondOrderTetrahedralFirstOrder) {
  const GradientNoise noise = makeNoise({1, 1, 3, 1});
  // Points on a sphere of radius 3: several cells, N = P/3.
  std::vector<Vec3d> points = spherePoints(2000, 13);
  auto maxError = [&](GradientScheme scheme, double step) {
    double worst = 0;
    for (const Vec3d& n : points) {
      const Vec3d p = 3.0 * n;
      const Vec3d exact = surfaceGradientFromVolume(noise.analyticGradient(p), n);
      const Vec3d approx = surfaceGradientFromVolume(volumeGradient(noise, p, scheme, step), n);
      worst = std::max(worst, length(approx - exact));
    }
    return worst;
  };
  constexpr double kStep = 1e-2;  // a hundredth of a cell
  const double c0 = maxError(GradientScheme::kCentral, kStep);
  const double c1 = maxError(GradientScheme::kCentral, kStep / 2);
  const double c2 = maxError(GradientScheme::kCentral, kStep / 4);
  EXPECT_GE(c0 / c1, kSecondOrderMinRatio);
  EXPECT_LE(c0 / c1, kSecondOrderMaxRatio);
  EXPECT_GE(c1 / c2, kSecondOrderMinRatio);
  EXPECT_LE(c1 / c2, kSecondOrderMaxRatio);
  const double t0 = maxError(GradientScheme::kTetrahedral, kStep);
  const double t1 = maxError(GradientScheme::kTetrahedral, kStep / 2);
  const double t2 = maxError(GradientScheme::kTetrahedral, kStep / 4);
  EXPECT_GE(t0 / t1, kFirstOrderMinRatio);
  EXPECT_LE(t0 / t1, kFirstOrderMaxRatio);
  EXPECT_GE(t1 / t2, kFirstOrderMinRatio);
  EXPECT_LE(t1 / t2, kFirstOrderMaxRatio);
}

// ------------------------------------------------------------------------------------------------
// Steps, scales and extreme inputs
// ------------------------------------------------------------------------------------------------

TEST(DefaultStep, IsTheRelativeFactorTimesTheSize) {
  EXPECT_EQ(defaultStep(1), kDefaultRelativeStep);
  EXPECT_EQ(defaultStep(2), 0x1p-19);
  EXPECT_EQ(defaultStep(1e6), kDefaultRelativeStep * 1e6);
  // Meaningless sizes fall back to 1.
  EXPECT_EQ(defaultStep(0), kDefaultRelativeStep);
  EXPECT_EQ(defaultStep(-3), kDefaultRelativeStep);
  EXPECT_EQ(defaultStep(kNaN), kDefaultRelativeStep);
  EXPECT_EQ(defaultStep(kInf), kDefaultRelativeStep);
  // Always a usable step.
  EXPECT_EQ(defaultStep(1e-320), kMinGradientStep);
  EXPECT_EQ(defaultStep(DBL_MAX), kMaxGradientStep);
}

// The default step on a unit-size object with detail an eighth of its size: central is accurate
// to ~1e-9 of the gradient scale, tetrahedral (first order) to ~1e-5.
TEST(DefaultStep, GivesAccurateGradientsOnAUnitObject) {
  const GradientNoise noise = makeNoise({1, 8, 5, 1});
  const double step = defaultStep(2.0);  // unit sphere: bounding-box size 2
  const double scale = 8.0;              // A·F
  double central = 0;
  double tetrahedral = 0;
  for (const Vec3d& p : spherePoints(2000, 14)) {
    const Vec3d exact = noise.analyticGradient(p);
    central =
        std::max(central, length(volumeGradient(noise, p, GradientScheme::kCentral, step) - exact));
    tetrahedral = std::max(
        tetrahedral, length(volumeGradient(noise, p, GradientScheme::kTetrahedral, step) - exact));
  }
  EXPECT_LE(central, 1e-8 * scale);
  EXPECT_LE(tetrahedral, 1e-4 * scale);
}

// Scaling the object by s (positions, feature size and step all by s) scales gradients by 1/s
// and changes nothing else, down to 1e-8 and up to 1e8.
TEST(VolumeGradient, ScaleInvariantFrom1em8To1e8) {
  const DirectionalSineParams sineParams = kObliqueWave;
  const GradientNoiseParams noiseParams{0.8, 2, 77, 3};
  const DirectionalSine sine = makeSine(sineParams);
  const GradientNoise noise = makeNoise(noiseParams);
  constexpr double kStep = 1e-4;
  const std::vector<Vec3d> points = spherePoints(300, 15);
  for (double s : {1e-8, 1e8}) {
    DirectionalSineParams sp = sineParams;
    sp.amplitude *= s;  // heights scale with the object too: gradients are then unchanged
    sp.frequency /= s;
    GradientNoiseParams np = noiseParams;
    np.amplitude *= s;
    np.frequency /= s;
    const DirectionalSine scaledSine = makeSine(sp);
    const GradientNoise scaledNoise = makeNoise(np);
    for (const Vec3d& p : points) {
      for (GradientScheme scheme :
           {GradientScheme::kAnalytic, GradientScheme::kCentral, GradientScheme::kTetrahedral}) {
        const Vec3d a = volumeGradient(sine, p, scheme, kStep);
        const Vec3d b = volumeGradient(scaledSine, s * p, scheme, s * kStep);
        EXPECT_LE(length(a - b), 1e-9 * sine.amplitude() * sine.angularFrequency());
        const Vec3d c = volumeGradient(noise, p, scheme, kStep);
        const Vec3d d = volumeGradient(scaledNoise, s * p, scheme, s * kStep);
        EXPECT_LE(length(c - d), 1e-9 * noiseParams.amplitude * 8 * noiseParams.frequency);
      }
    }
  }
}

// No NaN for finite input: every combination of extreme positions and steps gives finite values
// and gradients, for every scheme.
TEST(VolumeGradient, FiniteForEveryFiniteInput) {
  const DirectionalSine sine = makeSine(kObliqueWave);
  const DirectionalSine flat = makeSine({1, 0, {1, 1, 1}, 0.5});  // f = 0: constant
  const GradientNoise noise = makeNoise({1, 3, 42, 6});
  const std::array<const HeightVolume*, 3> volumes{&sine, &flat, &noise};
  const double magnitudes[] = {0.0, 5e-324, 1e-300, 1e-8, 1.0, 1e8, 1e15, 1e300, DBL_MAX};
  const Vec3d signs[] = {{1, 1, 1}, {1, -1, 0.5}, {-1, -1, -1}};
  const double steps[] = {0.0, 5e-324, 1e-300, 1e-12, 1e-3, 1.0, 1e8, 1e300, DBL_MAX, kInf, -1e-3};
  for (const HeightVolume* volume : volumes) {
    for (double m : magnitudes) {
      for (const Vec3d& sign : signs) {
        const Vec3d p = m * sign;
        ASSERT_TRUE(std::isfinite(volume->value(p))) << m;
        ASSERT_TRUE(isFinite(volume->analyticGradient(p))) << m;
        for (double step : steps) {
          for (GradientScheme scheme : {GradientScheme::kCentral, GradientScheme::kTetrahedral}) {
            const Vec3d g = volumeGradient(*volume, p, scheme, step);
            ASSERT_TRUE(isFinite(g)) << "|P| " << m << " step " << step;
          }
        }
      }
    }
  }
}

TEST(VolumeGradient, StepBelowTheResolutionOfPGivesZero) {
  const DirectionalSine sine = makeSine(kObliqueWave);
  const Vec3d p{1e8, -1e8, 1e8};  // ulp(1e8) ≈ 1.5e-8
  EXPECT_EQ(volumeGradient(sine, p, GradientScheme::kCentral, 1e-12), (Vec3d{0, 0, 0}));
  EXPECT_EQ(volumeGradient(sine, p, GradientScheme::kTetrahedral, 1e-12), (Vec3d{0, 0, 0}));
}

TEST(VolumeGradient, NaNInGivesNaNOut) {
  const GradientNoise noise = makeNoise({1, 1, 0, 2});
  const DirectionalSine sine = makeSine(kObliqueWave);
  EXPECT_TRUE(std::isnan(noise.value({kNaN, 0, 0})));
  EXPECT_FALSE(isFinite(noise.analyticGradient({0, kNaN, 0})));
  EXPECT_TRUE(std::isnan(sine.value({0, 0, kNaN})));
  EXPECT_FALSE(isFinite(volumeGradient(sine, {0, 0, 0}, GradientScheme::kCentral, kNaN)));
  EXPECT_FALSE(isFinite(volumeGradient(noise, {0, 0, 0}, GradientScheme::kTetrahedral, kNaN)));
  for (GradientScheme scheme :
       {GradientScheme::kAnalytic, GradientScheme::kCentral, GradientScheme::kTetrahedral}) {
    EXPECT_FALSE(isFinite(volumeGradient(sine, {kNaN, 1, 2}, scheme, 1e-3)));
    EXPECT_FALSE(isFinite(volumeGradient(noise, {1, 2, kNaN}, scheme, 1e-3)));
  }
}

}  // namespace
}  // namespace sgbake
