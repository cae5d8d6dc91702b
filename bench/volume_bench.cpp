/// @file volume_bench.cpp
/// @brief Google Benchmark timings of height volumes and their gradient schemes.
///
/// How to run (from a Release build):
///
///     ninja -C build sgbake_bench_volume && build/bench/sgbake_bench_volume
///
/// Benchmarks (time is per batch of kNumPoints points; `time_per_point` is the CPU time per point,
/// in seconds):
///   - `Volume/<field>/<what>`: value(), and volumeGradient with kAnalytic, kCentral and
///     kTetrahedral (at the default step), for the directional sine, 1- and 4-octave noise, and
///     Blender's Noise Texture at Blender's defaults (Scale 5, Detail 2: three octaves) and
///     with Distortion 0.5 (three more noises and their gradients), and Blender's Musgrave
///     (fBM), Wave (bands, distorted: its fbm) and Voronoi (F1, Euclidean) Textures at their
///     defaults, and the Musgrave's Ridged (Offset 1) and Hybrid Multifractal (Offset 0.5).
///   - `EqualError/<scheme>/target:<t>`: on the 1-octave noise, the step at which each finite
///     difference scheme reaches a max error of t (relative to the RMS analytic gradient
///     magnitude over a fixed point set, measured against the analytic gradient in the setup),
///     then the gradient timed at that step. Counters: `step`, `error` (achieved, relative),
///     `reached` (1 when some step met the target), `time_per_point`.
///
/// Central differences are second order and tetrahedral ones first order (volume.hpp), so the
/// tetrahedral scheme needs a much smaller step for the same error; with 4 taps instead of 6 it
/// is still cheaper per point while that step stays well above round-off.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "sgbake/core/vec.hpp"
#include "sgbake/gradient/blender_noise.hpp"
#include "sgbake/gradient/volume.hpp"

namespace {

using sgbake::GradientScheme;
using sgbake::HeightVolume;
using sgbake::Vec3d;
using sgbake::VolumeSample;

/// Points per timed batch (fits in L1 with the values; large enough to hide loop overhead).
constexpr int kNumPoints = 1024;
/// Points of the error measurement in the equal-error setup.
constexpr int kNumErrorPoints = 4096;
/// Object size of the benchmark scene (points in a cube of this edge).
constexpr double kObjectSize = 2.0;

/// Uniform points in the cube [−S/2, S/2]³, reproducible (raw mt19937_64 bits).
std::vector<Vec3d> makePoints(int count, std::uint64_t seed) {
  std::mt19937_64 engine(seed);
  auto uniform = [&] {
    return (static_cast<double>(engine() >> 11) * 0x1p-53 - 0.5) * kObjectSize;
  };
  std::vector<Vec3d> points(static_cast<std::size_t>(count));
  for (Vec3d& p : points) p = {uniform(), uniform(), uniform()};
  return points;
}

const sgbake::DirectionalSine& sineField() {
  static const sgbake::DirectionalSine sine =
      sgbake::DirectionalSine::create({0.05, 3.0, {1, 2, 3}, 0.4}).value();
  return sine;
}

/// Noise with cells an eighth of the object (frequency 4 on a size-2 object).
const sgbake::GradientNoise& noiseField(int octaves) {
  static const sgbake::GradientNoise one = sgbake::GradientNoise::create({0.05, 4.0, 7, 1}).value();
  static const sgbake::GradientNoise four =
      sgbake::GradientNoise::create({0.05, 4.0, 7, 4}).value();
  return octaves == 1 ? one : four;
}

/// Blender's Noise Texture at its defaults, or with Distortion 0.5.
const sgbake::BlenderNoise& blenderNoiseField(bool distorted) {
  static const sgbake::BlenderNoise plain =
      sgbake::BlenderNoise::create({.amplitude = 0.05}).value();
  static const sgbake::BlenderNoise twisted =
      sgbake::BlenderNoise::create({.amplitude = 0.05, .distortion = 0.5}).value();
  return distorted ? twisted : plain;
}

const HeightVolume& blenderField(int which) {
  static const sgbake::BlenderMusgrave musgrave =
      sgbake::BlenderMusgrave::create({.amplitude = 0.05}).value();
  static const sgbake::BlenderWave wave =
      sgbake::BlenderWave::create({.amplitude = 0.05, .distortion = 1}).value();
  static const sgbake::BlenderVoronoi voronoi =
      sgbake::BlenderVoronoi::create({.amplitude = 0.05}).value();
  static const sgbake::BlenderMusgrave ridged =
      sgbake::BlenderMusgrave::create(
          {.amplitude = 0.05, .type = sgbake::MusgraveType::kRidgedMultifractal, .offset = 1})
          .value();
  static const sgbake::BlenderMusgrave hybrid =
      sgbake::BlenderMusgrave::create(
          {.amplitude = 0.05, .type = sgbake::MusgraveType::kHybridMultifractal, .offset = 0.5})
          .value();
  switch (which) {
    case 0:
      return musgrave;
    case 1:
      return wave;
    case 2:
      return voronoi;
    case 3:
      return ridged;
    default:
      return hybrid;
  }
}

constexpr int kNumFields = 10;

const HeightVolume& field(int which) {
  switch (which) {
    case 0:
      return sineField();
    case 1:
      return noiseField(1);
    case 2:
      return noiseField(4);
    case 3:
      return blenderNoiseField(false);
    case 4:
      return blenderNoiseField(true);
    default:
      return blenderField(which - 5);
  }
}

const char* fieldName(int which) {
  switch (which) {
    case 0:
      return "sine";
    case 1:
      return "noise1";
    case 2:
      return "noise4";
    case 3:
      return "blender-noise";
    case 4:
      return "blender-noise-distorted";
    case 5:
      return "blender-musgrave";
    case 6:
      return "blender-wave-distorted";
    case 7:
      return "blender-voronoi";
    case 8:
      return "blender-musgrave-ridged";
    default:
      return "blender-musgrave-hybrid";
  }
}

void setPerPointCounters(benchmark::State& state, int pointsPerIteration) {
  const auto points = static_cast<double>(state.iterations()) * pointsPerIteration;
  state.SetItemsProcessed(static_cast<std::int64_t>(points));
  // Seconds per point (printed with an SI prefix, e.g. 37.1n = 37.1 ns).
  state.counters["time_per_point"] =
      benchmark::Counter(points, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

void benchValue(benchmark::State& state, int which) {
  const HeightVolume& volume = field(which);
  const std::vector<Vec3d> points = makePoints(kNumPoints, 1);
  for (auto _ : state) {
    double sum = 0;
    for (const Vec3d& p : points) sum += volume.value(p);
    benchmark::DoNotOptimize(sum);
  }
  setPerPointCounters(state, kNumPoints);
}

void benchGradient(benchmark::State& state, int which, GradientScheme scheme, double step) {
  const HeightVolume& volume = field(which);
  const std::vector<Vec3d> points = makePoints(kNumPoints, 1);
  for (auto _ : state) {
    Vec3d sum{};
    for (const Vec3d& p : points) sum += sgbake::volumeGradient(volume, p, scheme, step);
    benchmark::DoNotOptimize(sum);
  }
  setPerPointCounters(state, kNumPoints);
}

/// Value and gradient together, as a volume read on UV coordinates needs them
/// (VolumeOnUvTexture): HeightVolume::sample, or (@p apart) value() and analyticGradient().
void benchValueAndGradient(benchmark::State& state, int which, bool apart) {
  const HeightVolume& volume = field(which);
  const std::vector<Vec3d> points = makePoints(kNumPoints, 1);
  for (auto _ : state) {
    VolumeSample sum;
    for (const Vec3d& p : points) {
      const VolumeSample s =
          apart ? VolumeSample{volume.value(p), volume.analyticGradient(p)} : volume.sample(p);
      sum.value += s.value;
      sum.gradient += s.gradient;
    }
    benchmark::DoNotOptimize(sum);
  }
  setPerPointCounters(state, kNumPoints);
}

// ------------------------------------------------------------------------------------------------
// Equal error
// ------------------------------------------------------------------------------------------------

/// Max over the point set of |∇h_scheme − ∇h_analytic|, relative to the RMS |∇h_analytic|.
double relativeMaxError(const HeightVolume& volume, const std::vector<Vec3d>& points,
                        const std::vector<Vec3d>& exact, double exactRms, GradientScheme scheme,
                        double step) {
  double worst = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    worst = std::max(
        worst, sgbake::length(sgbake::volumeGradient(volume, points[i], scheme, step) - exact[i]));
  }
  return worst / exactRms;
}

struct StepChoice {
  double step = 0;
  double error = 0;
  bool reached = false;
};

/// The largest step whose relative max error is ≤ @p target: halve from a quarter cell until the
/// target is met (or round-off wins), then bisect (geometrically) between the last failing and
/// the first passing step. Where no step meets the target, the step of the smallest error.
StepChoice findStep(const HeightVolume& volume, GradientScheme scheme, double cellSize,
                    double target) {
  constexpr int kMaxHalvings = 60;
  constexpr int kBisections = 30;
  const std::vector<Vec3d> points = makePoints(kNumErrorPoints, 2);
  std::vector<Vec3d> exact;
  double sumSquares = 0;
  for (const Vec3d& p : points) {
    exact.push_back(volume.analyticGradient(p));
    sumSquares += sgbake::lengthSquared(exact.back());
  }
  const double rms = std::sqrt(sumSquares / static_cast<double>(points.size()));
  auto error = [&](double step) {
    return relativeMaxError(volume, points, exact, rms, scheme, step);
  };

  StepChoice best{0, HUGE_VAL, false};
  double failing = 0.25 * cellSize;
  if (const double e0 = error(failing); e0 <= target) return {failing, e0, true};
  for (int i = 0; i < kMaxHalvings; ++i) {
    const double step = failing / 2;
    const double e = error(step);
    if (e < best.error) best = {step, e, false};
    if (e <= target) {
      // Bisect in log space between failing (error > target) and step (error ≤ target).
      double passing = step;
      double passingError = e;
      for (int k = 0; k < kBisections; ++k) {
        const double mid = std::sqrt(failing * passing);
        const double em = error(mid);
        if (em <= target) {
          passing = mid;
          passingError = em;
        } else {
          failing = mid;
        }
      }
      return {passing, passingError, true};
    }
    if (e > 4 * best.error) break;  // round-off dominates from here on: the error grows again
    failing = step;
  }
  return best;
}

void benchEqualError(benchmark::State& state, GradientScheme scheme, double target) {
  const HeightVolume& volume = noiseField(1);
  const double cellSize = 1.0 / noiseField(1).params().frequency;
  const StepChoice choice = findStep(volume, scheme, cellSize, target);
  const std::vector<Vec3d> points = makePoints(kNumPoints, 1);
  for (auto _ : state) {
    Vec3d sum{};
    for (const Vec3d& p : points) sum += sgbake::volumeGradient(volume, p, scheme, choice.step);
    benchmark::DoNotOptimize(sum);
  }
  setPerPointCounters(state, kNumPoints);
  state.counters["step"] = choice.step;
  state.counters["error"] = choice.error;
  state.counters["reached"] = choice.reached ? 1 : 0;
}

void registerAll() {
  const double step = sgbake::defaultStep(kObjectSize);
  for (int which = 0; which < kNumFields; ++which) {
    const std::string base = std::string("Volume/") + fieldName(which);
    benchmark::RegisterBenchmark((base + "/value").c_str(),
                                 [which](benchmark::State& s) { benchValue(s, which); });
    benchmark::RegisterBenchmark((base + "/analytic").c_str(), [which](benchmark::State& s) {
      benchGradient(s, which, GradientScheme::kAnalytic, 0);
    });
    benchmark::RegisterBenchmark((base + "/sample").c_str(), [which](benchmark::State& s) {
      benchValueAndGradient(s, which, false);
    });
    benchmark::RegisterBenchmark((base + "/value+analytic").c_str(), [which](benchmark::State& s) {
      benchValueAndGradient(s, which, true);
    });
    benchmark::RegisterBenchmark((base + "/central").c_str(), [which, step](benchmark::State& s) {
      benchGradient(s, which, GradientScheme::kCentral, step);
    });
    benchmark::RegisterBenchmark((base + "/tetrahedral").c_str(),
                                 [which, step](benchmark::State& s) {
                                   benchGradient(s, which, GradientScheme::kTetrahedral, step);
                                 });
  }
  for (double target : {1e-4, 1e-7}) {
    char suffix[32];
    std::snprintf(suffix, sizeof suffix, "/target:%g", target);
    benchmark::RegisterBenchmark(
        (std::string("EqualError/central") + suffix).c_str(),
        [target](benchmark::State& s) { benchEqualError(s, GradientScheme::kCentral, target); });
    benchmark::RegisterBenchmark((std::string("EqualError/tetrahedral") + suffix).c_str(),
                                 [target](benchmark::State& s) {
                                   benchEqualError(s, GradientScheme::kTetrahedral, target);
                                 });
  }
}

}  // namespace

int main(int argc, char** argv) {
  registerAll();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
