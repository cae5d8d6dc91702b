// sgbake_bench_runtime_vs_error: what each accuracy setting of a bake costs and buys, measured
// against closed-form references in one run, printed as a Markdown report
// (docs/runtime-vs-error.md is its output on the development machine).
//
//   ninja -C build sgbake_bench_runtime_vs_error && build/bench/sgbake_bench_runtime_vs_error
//   ninja -C build bench_runtime_vs_error      # the same, written to build/bench/runtime_vs_error.md
//   ... [--runs N] [--size N] [--threads N] [--quick]
//
// Every row is one bakeMap (in memory, no file I/O) timed best of --runs (after one untimed
// warm-up), and its error against
// an exact reference at every fully covered texel: the median, 99th percentile and maximum angle
// (degrees) between the baked normal and the exact one. Times are also given as a ratio to the
// first row of their table, measured in the same run (absolute times vary from machine to
// machine and run to run; ratios much less).
//
// 1. Height-map filters: a plane with UV = (x, y) and the height map of
//    h(s, t) = A·sin(2π·3s)·sin(2π·2t), sampled at texel centres at several resolutions, baked as
//    object-space normals (equal to tangent-space ones on this plane); exact normal
//    normalize(−∂h/∂s, −∂h/∂t, 1).
// 2. Supersampling: the same plane and filter, samples 1…4 per texel side; the exact value is the
//    texel's box average of the encoded analytic normal (16×16 points), which is what a
//    supersampled bake estimates.
// 3. Height-volume gradients: a UV sphere with 4-octave gradient noise, the analytic gradient
//    against central and tetrahedral differences at 0.1×, 1× and 10× the default step; the
//    exact normal is the analytic-gradient bake of the same mesh.
// 4. Subdivision: a regular torus grid whose limit surface is a bicubic B-spline (closed form),
//    baked from meshes subdivided 1…4 levels and from the limit surface itself; the time
//    includes subdividing or setting up the limit surface.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "sgbake/bake/bake.hpp"
#include "sgbake/bake/scene.hpp"
#include "sgbake/core/math.hpp"
#include "sgbake/gradient/filters.hpp"
#include "sgbake/gradient/image.hpp"
#include "sgbake/gradient/layers.hpp"
#include "sgbake/gradient/volume.hpp"
#include "sgbake/subdiv/limit_surface.hpp"
#include "sgbake/subdiv/subdivide.hpp"
#include "support/bspline_torus.hpp"
#include "support/parametric_mesh.hpp"

namespace sgbake {
namespace {

struct Settings {
  int runs = 5;
  int size = 1024;  ///< bake size, texels per side
  int threads = 0;
  bool quick = false;
};

/// Angle statistics (degrees) over the covered texels.
struct ErrorStats {
  double median = 0, p99 = 0, max = 0;
  std::size_t texels = 0;
};

ErrorStats statsOf(std::vector<double> angles) {
  ErrorStats stats;
  stats.texels = angles.size();
  if (angles.empty()) return stats;
  std::sort(angles.begin(), angles.end());
  const auto at = [&](double q) {
    const auto index = static_cast<std::size_t>(q * static_cast<double>(angles.size()));
    return angles[std::min(angles.size() - 1, index)];
  };
  stats.median = at(0.5);
  stats.p99 = at(0.99);
  stats.max = angles.back();
  return stats;
}

/// The unit vector an encoded normal-map texel holds.
Vec3d decoded(const FloatImage& image, int x, int row) {
  return normalizeOr(Vec3d{2.0 * image.at(x, row, 0) - 1, 2.0 * image.at(x, row, 1) - 1,
                           2.0 * image.at(x, row, 2) - 1},
                     Vec3d{0, 0, 1});
}

/// Angles between @p image and @p exact(x, y) (texel x, y counted up) at fully covered texels.
ErrorStats compare(const FloatImage& image, const std::function<Vec3d(int x, int y)>& exact) {
  std::vector<double> angles;
  for (int row = 0; row < image.height; ++row) {
    for (int x = 0; x < image.width; ++x) {
      if (image.coverage[static_cast<std::size_t>(row) * image.width + x] != 1.0f) continue;
      const int y = image.height - 1 - row;
      angles.push_back(angleBetween(decoded(image, x, row), exact(x, y)) * 180 / kPi);
    }
  }
  return statsOf(std::move(angles));
}

/// Best wall time of @p runs calls of @p work after one untimed warm-up call (first-touch page
/// faults, thread start-up), seconds; @p work keeps its last result itself.
double bestOf(int runs, const std::function<void()>& work) {
  work();
  double best = 1e300;
  for (int run = 0; run < runs; ++run) {
    const auto start = std::chrono::steady_clock::now();
    work();
    best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  return best;
}

/// One Markdown table; rows print as they are measured.
class Table {
 public:
  Table(const std::string& title, const std::string& intro, const std::string& firstColumn) {
    std::printf("\n## %s\n\n%s\n\n| %s | time (ms) | time ratio | median (°) | p99 (°) | max (°) |\n"
                "|---|---:|---:|---:|---:|---:|\n",
                title.c_str(), intro.c_str(), firstColumn.c_str());
  }
  void row(const std::string& label, double seconds, const ErrorStats& error) {
    if (baseline_ == 0) baseline_ = seconds;
    std::printf("| %s | %.1f | %.2f | %.2e | %.2e | %.2e |\n", label.c_str(), seconds * 1e3,
                seconds / baseline_, error.median, error.p99, error.max);
    std::fflush(stdout);
  }

 private:
  double baseline_ = 0;
};

BakeSettings objectNormals(const Settings& settings, int samples = 1) {
  BakeSettings bake;
  bake.map = MapKind::kObjectNormal;
  bake.width = bake.height = settings.size;
  bake.samples = samples;
  bake.threads = settings.threads;
  return bake;
}

/// Bakes, exiting with a message on failure (a benchmark has no one to report to).
FloatImage bake(const BakeInput& input, const BakeSettings& settings) {
  Result<FloatImage> image = bakeMap(input, settings);
  if (!image) {
    std::fprintf(stderr, "sgbake_bench_runtime_vs_error: %s\n", image.error().message.c_str());
    std::exit(1);
  }
  return std::move(*image);
}

// ---- 1 and 2: height maps on a plane -----------------------------------------------------------

constexpr double kWaveAmplitude = 0.01;  ///< A, object units (the plane is 1 unit wide)

/// The exact height's gradient (∂h/∂s, ∂h/∂t).
Vec2d waveGradient(double s, double t) {
  const double a = 2 * kPi * 3, b = 2 * kPi * 2;
  return {kWaveAmplitude * a * std::cos(a * s) * std::sin(b * t),
          kWaveAmplitude * b * std::sin(a * s) * std::cos(b * t)};
}

Vec3d waveNormal(double s, double t) {
  const Vec2d g = waveGradient(s, t);
  return normalizeOr(Vec3d{-g.x, -g.y, 1}, Vec3d{0, 0, 1});
}

/// The height map of the wave: r × r texels sampled at their centres (scale 1 in the layer).
Image waveImage(int r) {
  Image image(r, r, 1);
  for (int y = 0; y < r; ++y) {
    for (int x = 0; x < r; ++x) {
      const double s = (x + 0.5) / r, t = (y + 0.5) / r;
      image.at(x, y) = static_cast<float>(kWaveAmplitude * std::sin(2 * kPi * 3 * s) *
                                          std::sin(2 * kPi * 2 * t));
    }
  }
  return image;
}

std::unique_ptr<ImageScalarTexture> waveTexture(int r, Filter filter) {
  ScalarTextureOptions options;
  options.filter = filter;
  Result<ImageScalarTexture> texture = ImageScalarTexture::create(waveImage(r), options);
  if (!texture) std::exit(1);
  return std::make_unique<ImageScalarTexture>(std::move(*texture));
}

void heightFilters(const Settings& settings) {
  Table table(
      "Height-map filters",
      "A plane, UV = (x, y), the height map of A·sin(2π·3s)·sin(2π·2t) (A = 0.01; steepest "
      "slope 21°) sampled at R² texel centres, baked to " +
          std::to_string(settings.size) +
          "² object-space normals, 1 sample per texel. "
          "Error: against the exact normal of the continuous height where each texel is sampled.",
      "filter, R");
  const Mesh plane = test::gridMesh(test::plane, 4, 4);
  const std::vector<int> resolutions =
      settings.quick ? std::vector<int>{64, 256} : std::vector<int>{32, 64, 128, 256, 512};
  for (const Filter filter : {Filter::kBilinear, Filter::kBicubic, Filter::kHermite}) {
    for (const int r : resolutions) {
      const std::unique_ptr<ImageScalarTexture> texture = waveTexture(r, filter);
      const Layer layers[] = {{UvHeightSource{texture.get(), 0, 1.0}}};
      FloatImage image;
      const double seconds = bestOf(settings.runs, [&] {
        image = bake({&plane, nullptr, layers}, objectNormals(settings));
      });
      const ErrorStats error = compare(image, [&](int x, int y) {
        const Vec2d uv = bakeSampleUv(x + 0.5, y + 0.5, settings.size, settings.size);
        return waveNormal(uv.x, uv.y);
      });
      table.row(std::string(filterName(filter)) + ", " + std::to_string(r), seconds, error);
    }
  }
  std::printf(
      "\nBilinear slopes are constant across each map texel in their own direction (first "
      "order: the error halves when R doubles); Catmull-Rom (bicubic) slopes are second order "
      "and Hermite's (from fourth-order derivative estimates) third order.\n");
}

void supersampling(const Settings& settings) {
  Table table("Supersampling",
              "The plane and wave of the previous table (bicubic, R = 512), N×N samples per texel. "
              "Error: against the texel's box average of the exact encoded normal (16×16 points), "
              "the value a supersampled bake estimates.",
              "samples");
  const Mesh plane = test::gridMesh(test::plane, 4, 4);
  const std::unique_ptr<ImageScalarTexture> texture = waveTexture(512, Filter::kBicubic);
  const Layer layers[] = {{UvHeightSource{texture.get(), 0, 1.0}}};
  const int size = settings.size;
  const auto boxAverage = [size](int x, int y) {
    constexpr int kPoints = 16;
    Vec3d sum{0, 0, 0};
    for (int j = 0; j < kPoints; ++j) {
      for (int i = 0; i < kPoints; ++i) {
        const Vec2d uv = bakeSampleUv(x + (i + 0.5) / kPoints, y + (j + 0.5) / kPoints, size, size);
        sum = sum + waveNormal(uv.x, uv.y);
      }
    }
    return normalizeOr(sum, Vec3d{0, 0, 1});  // the mean encoded colour decodes to this direction
  };
  for (int samples = 1; samples <= (settings.quick ? 2 : 4); ++samples) {
    FloatImage image;
    const double seconds = bestOf(settings.runs, [&] {
      image = bake({&plane, nullptr, layers}, objectNormals(settings, samples));
    });
    table.row(std::to_string(samples) + "×" + std::to_string(samples), seconds,
              compare(image, boxAverage));
  }
}

// ---- 3: height volumes ------------------------------------------------------------------------

void volumeGradients(const Settings& settings) {
  Table table("Height-volume gradients",
              "A UV sphere (64 × 32 quads, radius 1) bumped by 4-octave gradient noise (amplitude "
              "0.02, frequency 4), baked to " + std::to_string(settings.size) +
                  "² object-space normals. Error: against the analytic-gradient bake (first row).",
              "scheme, step");
  const Mesh sphere = test::gridMesh(test::sphere, 64, 32);
  Result<GradientNoise> noise = GradientNoise::create({0.02, 4, 7, 4});
  if (!noise) std::exit(1);
  const double step = defaultStep(2 * std::sqrt(3.0));  // the sphere's bounding-box diagonal
  FloatImage exact;
  const auto run = [&](GradientScheme scheme, double h, const std::string& label) {
    const Layer layers[] = {{VolumeSource{&*noise, scheme, h, 1.0}}};
    FloatImage image;
    const double seconds = bestOf(settings.runs, [&] {
      image = bake({&sphere, nullptr, layers}, objectNormals(settings));
    });
    if (exact.pixels.empty()) exact = image;
    table.row(label, seconds, compare(image, [&](int x, int y) {
                return decoded(exact, x, exact.height - 1 - y);
              }));
  };
  run(GradientScheme::kAnalytic, 0, "analytic");
  for (const auto& [scheme, name] : {std::pair{GradientScheme::kCentral, "central"},
                                     std::pair{GradientScheme::kTetrahedral, "tetrahedral"}}) {
    for (const double factor : {0.1, 1.0, 10.0}) {
      char label[64];
      std::snprintf(label, sizeof label, "%s, %g× default (%.1e)", name, factor, factor * step);
      run(scheme, factor * step, label);
    }
  }
}

// ---- 4: subdivision ---------------------------------------------------------------------------

void subdivision(const Settings& settings) {
  constexpr int kNu = 8, kNv = 6;
  Table table("Subdivision",
              "A closed torus grid of 8 × 6 quads, every vertex of valence 4, so its Catmull-Clark "
              "limit is a bicubic B-spline with a closed form; UV Smooth none. Baked to " +
                  std::to_string(settings.size) + "² object-space normals from the mesh "
                  "subdivided N levels (interpolated vertex normals, as Blender's modifier) and from "
                  "the limit surface itself. Time: subdividing (or building the limit surface and "
                  "its tessellation) plus the bake. Error: against the closed-form limit normal.",
              "surface");
  const Mesh coarse = test::torusGridWithUvs(kNu, kNv);
  const int size = settings.size;
  const auto exact = [&](int x, int y) {
    const Vec2d uv = bakeSampleUv(x + 0.5, y + 0.5, size, size);
    const double u = uv.x * kNu, v = uv.y * kNv;
    const int i = std::min(kNu - 1, static_cast<int>(u)), j = std::min(kNv - 1, static_cast<int>(v));
    Vec3d P, Ps, Pt;
    test::torusGridLimit(coarse, kNu, kNv, i, j, u - i, v - j, P, Ps, Pt);
    return normalizeOr(cross(Ps, Pt), Vec3d{0, 0, 1});
  };
  for (int level = 1; level <= (settings.quick ? 2 : 4); ++level) {
    FloatImage image;
    const double seconds = bestOf(settings.runs, [&] {
      Result<Mesh> fine = subdivideMesh(coarse, {level, SubdivisionUvSmooth::kNone});
      if (!fine) std::exit(1);
      image = bake({&*fine, nullptr, {}}, objectNormals(settings));
    });
    table.row("level " + std::to_string(level), seconds, compare(image, exact));
  }
  FloatImage image;
  const double seconds = bestOf(settings.runs, [&] {
    Result<LimitTessellation> limit =
        tessellateLimitSurface(coarse, {kLimitTessellationLevel, SubdivisionUvSmooth::kNone});
    if (!limit) std::exit(1);
    image = bake({&limit->mesh, nullptr, {}, &limit->surface, &limit->parameters},
                 objectNormals(settings));
  });
  table.row("limit surface", seconds, compare(image, exact));
}

int usage(const char* message) {
  std::fprintf(stderr,
               "sgbake_bench_runtime_vs_error: %s\n"
               "usage: sgbake_bench_runtime_vs_error [--runs N] [--size N] [--threads N] [--quick]\n",
               message);
  return 2;
}

}  // namespace
}  // namespace sgbake

int main(int argc, char** argv) {
  sgbake::Settings settings;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const auto number = [&](int& target, int minimum) {
      if (i + 1 >= argc) return false;
      char* end = nullptr;
      const long value = std::strtol(argv[++i], &end, 10);
      if (*end != '\0' || value < minimum || value > 8192) return false;
      target = static_cast<int>(value);
      return true;
    };
    if (arg == "--quick") {
      settings.quick = true;
    } else if (arg == "--runs") {
      if (!number(settings.runs, 1)) return sgbake::usage("--runs needs a number >= 1");
    } else if (arg == "--size") {
      if (!number(settings.size, 16)) return sgbake::usage("--size needs a number >= 16");
    } else if (arg == "--threads") {
      if (!number(settings.threads, 0)) return sgbake::usage("--threads needs a number >= 0");
    } else {
      return sgbake::usage(("unknown argument " + arg).c_str());
    }
  }
  std::printf("# Run time against error\n\nGenerated by `sgbake_bench_runtime_vs_error --size %d "
              "--runs %d%s` (bench/runtime_vs_error.cpp): each time is the best of %d in-memory "
              "bakes (%s) after a warm-up, its ratio to the first row of its table measured in the same run; "
              "errors are angles between baked and exact normals over the fully covered texels.\n",
              settings.size, settings.runs, settings.quick ? " --quick" : "", settings.runs,
              settings.threads == 0 ? "all cores" : (std::to_string(settings.threads) + " threads").c_str());
  sgbake::heightFilters(settings);
  sgbake::supersampling(settings);
  sgbake::volumeGradients(settings);
  sgbake::subdivision(settings);
  return 0;
}
