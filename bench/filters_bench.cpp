// Samples per second of each image filter on a 2048² height map (and a 2048² RGB map).
//
//   ninja -C build sgbake_bench_filters && build/bench/sgbake_bench_filters
//
// Each iteration samples one point through the ScalarTexture / VectorTexture interface (a
// virtual call, as the gradient sources use it). The points are fixed pseudo-random positions
// over the whole map, so most samples miss the cache as a bake of a large mesh would;
// BM_*Coherent walks a texel row instead (neighbouring samples share texels).

#include <benchmark/benchmark.h>

#include <memory>
#include <random>
#include <vector>

#include "sgbake/gradient/filters.hpp"
#include "sgbake/gradient/image.hpp"

namespace {

using sgbake::Filter;
using sgbake::Image;
using sgbake::ImageScalarTexture;
using sgbake::ImageVectorTexture;
using sgbake::ScalarSample;
using sgbake::ScalarTexture;
using sgbake::Vec2d;
using sgbake::Vec3d;
using sgbake::VectorTexture;

constexpr int kMapSize = 2048;
constexpr std::size_t kPointCount = 1 << 16;

const Image& randomMap(int channels) {
  static std::vector<std::unique_ptr<Image>> maps(4);
  std::unique_ptr<Image>& map = maps[static_cast<std::size_t>(channels)];
  if (!map) {
    map = std::make_unique<Image>(kMapSize, kMapSize, channels);
    std::mt19937 rng(1);
    std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
    for (float& v : map->pixels()) v = uniform(rng);
  }
  return *map;
}

const std::vector<Vec2d>& randomPoints() {
  static const std::vector<Vec2d> points = [] {
    std::mt19937 rng(2);
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    std::vector<Vec2d> p(kPointCount);
    for (Vec2d& st : p) st = {uniform(rng), uniform(rng)};
    return p;
  }();
  return points;
}

std::unique_ptr<ScalarTexture> scalarTexture(Filter filter) {
  sgbake::ScalarTextureOptions options;
  options.filter = filter;
  return std::make_unique<ImageScalarTexture>(
      ImageScalarTexture::create(randomMap(1), options).value());
}

void runScalar(benchmark::State& state, const ScalarTexture& texture,
               const std::vector<Vec2d>& points) {
  std::size_t i = 0;
  for (auto _ : state) {
    const ScalarSample sample = texture.sample(points[i]);
    benchmark::DoNotOptimize(sample);
    i = (i + 1) & (kPointCount - 1);
  }
  state.SetItemsProcessed(state.iterations());
}

void BM_Scalar(benchmark::State& state) {
  const auto filter = static_cast<Filter>(state.range(0));
  const std::unique_ptr<ScalarTexture> texture = scalarTexture(filter);
  runScalar(state, *texture, randomPoints());
}

void BM_ScalarCoherent(benchmark::State& state) {
  const auto filter = static_cast<Filter>(state.range(0));
  const std::unique_ptr<ScalarTexture> texture = scalarTexture(filter);
  // Consecutive samples a third of a texel apart along s.
  std::vector<Vec2d> points(kPointCount);
  for (std::size_t k = 0; k < kPointCount; ++k) {
    points[k] = {static_cast<double>(k) / (3.0 * kMapSize), 0.37};
  }
  runScalar(state, *texture, points);
}

void BM_Vector(benchmark::State& state) {
  sgbake::VectorTextureOptions options;
  options.filter = static_cast<Filter>(state.range(0));
  const std::unique_ptr<VectorTexture> texture = std::make_unique<ImageVectorTexture>(
      ImageVectorTexture::create(randomMap(3), options).value());
  const std::vector<Vec2d>& points = randomPoints();
  std::size_t i = 0;
  for (auto _ : state) {
    const Vec3d value = texture->sample(points[i]);
    benchmark::DoNotOptimize(value);
    i = (i + 1) & (kPointCount - 1);
  }
  state.SetItemsProcessed(state.iterations());
}

// Creating a Hermite texture estimates the derivatives of every texel (parallel over rows).
void BM_CreateHermite(benchmark::State& state) {
  const Image& map = randomMap(1);
  sgbake::ScalarTextureOptions options;
  options.filter = Filter::kHermite;
  for (auto _ : state) {
    auto texture = ImageScalarTexture::create(map, options);
    benchmark::DoNotOptimize(texture);
  }
  state.SetItemsProcessed(state.iterations() * kMapSize * kMapSize);
}

void filterArgs(benchmark::internal::Benchmark* b) {
  b->ArgName("filter");
  for (Filter f : {Filter::kBilinear, Filter::kBicubic, Filter::kHermite}) {
    b->Arg(static_cast<int>(f));
  }
}

BENCHMARK(BM_Scalar)->Apply(filterArgs);
BENCHMARK(BM_ScalarCoherent)->Apply(filterArgs);
BENCHMARK(BM_Vector)
    ->ArgName("filter")
    ->Arg(static_cast<int>(Filter::kBilinear))
    ->Arg(static_cast<int>(Filter::kBicubic));
BENCHMARK(BM_CreateHermite)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
