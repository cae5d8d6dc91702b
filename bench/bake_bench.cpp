// Timings of the baker: a 4096² map of meshes/suzanne.obj (7872 quads) with one UV height layer,
// for 1 and 2 threads, plus the raster alone (mask) and the padding passes.
//
//   ninja -C build sgbake_bench_bake && build/bench/sgbake_bench_bake
//   SGBAKE_BENCH_MESH=other.obj build/bench/sgbake_bench_bake    # another mesh (needs UVs)
//
// Benchmarks (wall time, milliseconds; the argument is the thread count):
//   - BM_TangentNormal/threads:N — bakeMap(kTangentNormal, 4096², 1 sample) with a bilinear
//     2048² height map: the speed target (Blender's Cycles bake takes 25–35 s);
//   - BM_TangentNormalBumpNode/threads:N — the same map with the height's slopes as Cycles'
//     Bump node takes them ("gradient": "bump-node": three lookups a sample instead of one);
//   - BM_TangentNormalBands/threads:N — the same map by bakeMapRows (bands of rows in a reused
//     ring, what the CLI runs), and BM_TangentNormalBandsMargin16/threads:N with each band's
//     final rows padded in place (extendMarginRowsInPlace, margin 16) as the CLI pads them;
//   - BM_ObjectNormal/threads:N, BM_SurfaceGradient/threads:N — the object-space normal and
//     surface-gradient maps of the same scene (bakeMap);
//   - BM_TangentNormalStretched, BM_ObjectNormalStretched, BM_SurfaceGradientStretched — the
//     same three maps of Suzanne placed with the scale (2, 1, 0.5), shaded in world space as
//     Cycles shades an object whose scale was never applied (BakeInput::transform);
//   - BM_TangentNormalRamp/threads:N, BM_TangentNormalRampBumpNode/threads:N — the same maps with
//     the height read through a remap of 256 points, evenly spaced as Cycles tabulates a Color
//     Ramp, on the line y = x: the same bumps (no more texels bent by the valid-reflection
//     guard), so the difference is the remap's own cost;
//   - BM_TangentNormalNoLayers/threads:N — the frame and encoding alone;
//   - BM_Mask/threads:N — the raster and coverage alone (no shading);
//   - BM_ExtendMargin16/threads:N, BM_PushPull/threads:N — padding of the 4096² tangent map;
//   - BM_TangentNormalLimit/threads:N — the tangent map of Suzanne's exact limit surface
//     ("subdivision": {"level": "limit"}: every sample located on the surface with Bfr), and
//     BM_TangentNormalLevel3/threads:N — the same map of the level-3 mesh its raster walks.
// Setup (loading the mesh, MikkTSpace, building the texture) is not timed; writing files is not
// part of this library.

#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "sgbake/bake/bake.hpp"
#include "sgbake/core/math.hpp"
#include "sgbake/frames/tangents.hpp"
#include "sgbake/gradient/filters.hpp"
#include "sgbake/gradient/image.hpp"
#include "sgbake/gradient/remap.hpp"
#include "sgbake/gradient/world_shading.hpp"
#include "sgbake/mesh/io.hpp"
#include "sgbake/subdiv/limit_surface.hpp"

namespace {

using namespace sgbake;

constexpr int kBakeSize = 4096;
constexpr int kHeightMapSize = 2048;

struct Scene {
  Mesh mesh;
  CornerTangents tangents;
  std::optional<ImageScalarTexture> height;
  std::vector<Layer> layers;
  std::vector<Layer> bumpNodeLayers;  ///< the same height, slopes as Cycles' Bump node takes them
  std::optional<RemappedScalarTexture> ramp;          ///< the height through 256 points
  std::vector<Layer> rampLayers, rampBumpNodeLayers;  ///< layers and bumpNodeLayers through it
};

/// Loaded once: the mesh, its tangents and a 2048² height map of a few summed sines.
const Scene& scene() {
  static const std::unique_ptr<Scene> s = [] {
    auto out = std::make_unique<Scene>();
    const char* env = std::getenv("SGBAKE_BENCH_MESH");
    // meshes/ next to bench/ (CMake passes this file's absolute path).
    const std::filesystem::path path =
        env ? std::filesystem::path(env)
            : std::filesystem::path(__FILE__).parent_path().parent_path() / "meshes" / "suzanne.obj";
    Result<Mesh> mesh = loadMesh(path, {.requireUvs = true});
    if (!mesh) {
      std::fprintf(stderr, "%s\n", mesh.error().message.c_str());
      std::exit(1);
    }
    out->mesh = std::move(*mesh);
    Result<CornerTangents> tangents = computeTangents(out->mesh.view(0));
    if (!tangents) std::exit(1);
    out->tangents = std::move(*tangents);
    Image image(kHeightMapSize, kHeightMapSize, 1);
    for (int y = 0; y < kHeightMapSize; ++y)
      for (int x = 0; x < kHeightMapSize; ++x) {
        const double a = 2 * kPi * x / kHeightMapSize, b = 2 * kPi * y / kHeightMapSize;
        image.at(x, y) = static_cast<float>(0.5 + 0.25 * std::sin(17 * a) * std::cos(23 * b) +
                                            0.1 * std::sin(101 * a + 37 * b));
      }
    Result<ImageScalarTexture> texture = ImageScalarTexture::create(image);
    if (!texture) std::exit(1);
    out->height.emplace(std::move(*texture));
    out->layers.push_back(Layer{UvHeightSource{&*out->height, 0, 0.02}, 1.0, {}});
    UvHeightSource bumpNode{&*out->height, 0, 0.02};
    bumpNode.gradient = HeightGradient::kBumpNode;
    out->bumpNodeLayers.push_back(Layer{bumpNode, 1.0, {}});
    // A Color Ramp's 256 entries, on y = x (the heights lie in [0.15, 0.85]).
    std::vector<Vec2d> table;
    for (int i = 0; i < 256; ++i) table.push_back({i / 255.0, i / 255.0});
    Result<HeightRemap> remap = HeightRemap::create(std::move(table));
    if (!remap) std::exit(1);
    out->ramp.emplace(*out->height, std::move(*remap));
    out->rampLayers.push_back(Layer{UvHeightSource{&*out->ramp, 0, 0.02}, 1.0, {}});
    bumpNode.texture = &*out->ramp;
    out->rampBumpNodeLayers.push_back(Layer{bumpNode, 1.0, {}});
    return out;
  }();
  return *s;
}

/// The stretched placement of the *Stretched benchmarks: Suzanne scaled (2, 1, 0.5), an object
/// whose scale was never applied.
const ObjectTransform kStretched{Mat3::diagonal({2, 1, 0.5}), {}};

void bake(benchmark::State& state, MapKind kind, bool withLayers,
          const ObjectTransform* transform = nullptr, bool bumpNode = false, bool ramp = false) {
  const Scene& s = scene();
  BakeSettings settings;
  settings.map = kind;
  settings.width = settings.height = kBakeSize;
  settings.threads = static_cast<int>(state.range(0));
  const std::span<const Layer> layers = ramp ? (bumpNode ? s.rampBumpNodeLayers : s.rampLayers)
                                             : (bumpNode ? s.bumpNodeLayers : s.layers);
  BakeInput input{&s.mesh, &s.tangents, withLayers ? layers : std::span<const Layer>()};
  input.transform = transform;
  for (auto _ : state) {
    Result<FloatImage> image = bakeMap(input, settings);
    if (!image) state.SkipWithError(image.error().message.c_str());
    benchmark::DoNotOptimize(image);
  }
  state.counters["texels"] = double(kBakeSize) * kBakeSize;
}

/// Suzanne's limit surface (Blender's default options) and its level-3 tessellation with that
/// mesh's MikkTSpace frames, made once.
struct LimitScene {
  LimitTessellation limit;
  CornerTangents tangents;
};
const LimitScene& limitScene() {
  static const std::unique_ptr<LimitScene> s = [] {
    Result<LimitTessellation> limit = tessellateLimitSurface(scene().mesh, {});
    if (!limit) std::exit(1);
    Result<CornerTangents> tangents = computeTangents(limit->mesh.view(0));
    if (!tangents) std::exit(1);
    return std::make_unique<LimitScene>(LimitScene{std::move(*limit), std::move(*tangents)});
  }();
  return *s;
}

/// The tangent map of the limit surface (@p exact) or of its tessellation as a mesh.
void bakeSubdivided(benchmark::State& state, bool exact) {
  const LimitScene& l = limitScene();
  BakeSettings settings;
  settings.map = MapKind::kTangentNormal;
  settings.width = settings.height = kBakeSize;
  settings.threads = static_cast<int>(state.range(0));
  BakeInput input{&l.limit.mesh, exact ? nullptr : &l.tangents, scene().layers};
  if (exact) {
    input.limit = &l.limit.surface;
    input.limitParameters = &l.limit.parameters;
  }
  for (auto _ : state) {
    Result<FloatImage> image = bakeMap(input, settings);
    if (!image) state.SkipWithError(image.error().message.c_str());
    benchmark::DoNotOptimize(image);
  }
  state.counters["texels"] = double(kBakeSize) * kBakeSize;
}

void BM_TangentNormal(benchmark::State& state) { bake(state, MapKind::kTangentNormal, true); }
void BM_TangentNormalLimit(benchmark::State& state) { bakeSubdivided(state, true); }
void BM_TangentNormalLevel3(benchmark::State& state) { bakeSubdivided(state, false); }
void BM_TangentNormalBumpNode(benchmark::State& state) {
  bake(state, MapKind::kTangentNormal, true, nullptr, true);
}
void BM_TangentNormalRamp(benchmark::State& state) {
  bake(state, MapKind::kTangentNormal, true, nullptr, false, true);
}
void BM_TangentNormalRampBumpNode(benchmark::State& state) {
  bake(state, MapKind::kTangentNormal, true, nullptr, true, true);
}
void BM_ObjectNormal(benchmark::State& state) { bake(state, MapKind::kObjectNormal, true); }
void BM_TangentNormalStretched(benchmark::State& state) {
  bake(state, MapKind::kTangentNormal, true, &kStretched);
}
void BM_ObjectNormalStretched(benchmark::State& state) {
  bake(state, MapKind::kObjectNormal, true, &kStretched);
}
void BM_SurfaceGradientStretched(benchmark::State& state) {
  bake(state, MapKind::kSurfaceGradient, true, &kStretched);
}
void BM_SurfaceGradient(benchmark::State& state) { bake(state, MapKind::kSurfaceGradient, true); }
void BM_TangentNormalNoLayers(benchmark::State& state) { bake(state, MapKind::kTangentNormal, false); }
void BM_Mask(benchmark::State& state) { bake(state, MapKind::kMask, false); }

/// bakeMapRows of the tangent-normal map; with @p margin > 0 each band's final rows are padded.
void bakeBands(benchmark::State& state, int margin) {
  const Scene& s = scene();
  BakeSettings settings;
  settings.width = settings.height = kBakeSize;
  settings.threads = static_cast<int>(state.range(0));
  const BakeInput input{&s.mesh, &s.tangents, s.layers};
  for (auto _ : state) {
    int rowsPadded = 0;
    const Status done = bakeMapRows(input, settings, 2 * margin, [&](const MutableImageRows& rows) {
      const int ready = rows.end == rows.height ? rows.height : rows.end - margin;
      if (margin > 0 && ready > rowsPadded) {
        extendMarginRowsInPlace(rows, margin, rowsPadded, ready, settings.threads);
        rowsPadded = ready;
      }
      benchmark::DoNotOptimize(rows.pixelRow(rows.begin));
      return Status{Ok{}};
    });
    if (!done) state.SkipWithError(done.error().message.c_str());
  }
  state.counters["texels"] = double(kBakeSize) * kBakeSize;
}

void BM_TangentNormalBands(benchmark::State& state) { bakeBands(state, 0); }
void BM_TangentNormalBandsMargin16(benchmark::State& state) { bakeBands(state, 16); }

const FloatImage& tangentMap() {
  static const FloatImage map = [] {
    const Scene& s = scene();
    BakeSettings settings;
    settings.width = settings.height = kBakeSize;
    return std::move(*bakeMap({&s.mesh, &s.tangents, s.layers}, settings));
  }();
  return map;
}

void BM_ExtendMargin16(benchmark::State& state) {
  for (auto _ : state) {
    state.PauseTiming();
    FloatImage image = tangentMap();
    state.ResumeTiming();
    extendMargin(image, 16, static_cast<int>(state.range(0)));
    benchmark::DoNotOptimize(image);
  }
}

void BM_PushPull(benchmark::State& state) {
  for (auto _ : state) {
    state.PauseTiming();
    FloatImage image = tangentMap();
    state.ResumeTiming();
    pushPullFill(image, static_cast<int>(state.range(0)));
    benchmark::DoNotOptimize(image);
  }
}

void threadArgs(benchmark::internal::Benchmark* b) {
  b->ArgName("threads")->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);
}

}  // namespace

BENCHMARK(BM_TangentNormal)->Apply(threadArgs);
BENCHMARK(BM_TangentNormalBumpNode)->Apply(threadArgs);
BENCHMARK(BM_TangentNormalRamp)->Apply(threadArgs);
BENCHMARK(BM_TangentNormalRampBumpNode)->Apply(threadArgs);
BENCHMARK(BM_TangentNormalBands)->Apply(threadArgs);
BENCHMARK(BM_TangentNormalBandsMargin16)->Apply(threadArgs);
BENCHMARK(BM_ObjectNormal)->Apply(threadArgs);
BENCHMARK(BM_SurfaceGradient)->Apply(threadArgs);
BENCHMARK(BM_TangentNormalStretched)->Apply(threadArgs);
BENCHMARK(BM_ObjectNormalStretched)->Apply(threadArgs);
BENCHMARK(BM_SurfaceGradientStretched)->Apply(threadArgs);
BENCHMARK(BM_TangentNormalNoLayers)->Apply(threadArgs);
BENCHMARK(BM_Mask)->Apply(threadArgs);
BENCHMARK(BM_ExtendMargin16)->Apply(threadArgs);
BENCHMARK(BM_PushPull)->Apply(threadArgs);
BENCHMARK(BM_TangentNormalLevel3)->Apply(threadArgs);
BENCHMARK(BM_TangentNormalLimit)->Apply(threadArgs);

BENCHMARK_MAIN();
