/// @file sources_bench.cpp
/// @brief Google Benchmark timings of each surface-gradient source, per evaluated point.
///
/// How to run (Release build):
///
///     ninja -C build sgbake_bench_sources && build/bench/sgbake_bench_sources
///
/// Every benchmark evaluates one source (or a composite) at 4096 precomputed surface points on a
/// tilted, sheared frame with a MikkTSpace tangent, one thread; `items_per_second` is points per
/// second, so 1e9 / items_per_second is nanoseconds per point. Textures are small analytic
/// classes with exact derivatives (a sine height, its tangent-space normal map, a varying
/// object-space normal map) so the numbers measure the framework, not image filtering.
///
/// Benchmarks:
///   - `UvHeight`: UvHeightSource (one texture sample, eq. 31)
///   - `TangentNormal/mikk`, `TangentNormal/uvframe`: TangentNormalSource in the MikkTSpace frame /
///     the UV-derivative frame (UV set 1)
///   - `ObjectNormal`: ObjectNormalSource (eq. 38)
///   - `TriplanarHeight/planes:N`: triplanar heights with normals chosen so that N = 1, 2 or 3
///     planes pass the weight threshold (the others are not sampled)
///   - `TriplanarBoxHeight/planes:N`: the same with Blender's Box projection (Blend 0.3), normals
///     in its one-, two- and three-plane zones; `TriplanarBoxHeight/mapped` three planes after a
///     Mapping node (CoordinateMapping)
///   - `ProjectedTangentNormal/box:N`, `ProjectedTangentNormal/flat`, `/sphere`, `/tube`: the
///     tangent-space map read by Blender's Box projection (normals in its N-plane zone) or its
///     Flat, Sphere or Tube projection and decoded in the MikkTSpace frame
///     (TangentNormalSource::projection), against `TangentNormal/mikk`
///   - `PlanarHeight/flat`, `/sphere`, `/tube`: a height read by those single lookups (a planar
///     layer; the wrapped ones with their exact slopes, wrappedCoordinateGradients)
///   - `Composite3`: UV height + tangent-space map + triplanar height (all 3 planes) together,
///     resolved to the perturbed normal (perturbedNormal)

#include <benchmark/benchmark.h>

#include <cmath>
#include <random>
#include <vector>

#include "sgbake/core/math.hpp"
#include "sgbake/gradient/layers.hpp"

namespace {

using namespace sgbake;

class SineHeight final : public ScalarTexture {
 public:
  ScalarSample sample(Vec2d st) const override {
    const double w = 2 * kPi;
    const double ss = std::sin(w * st.x), cs = std::cos(w * st.x);
    const double st_ = std::sin(w * st.y), ct = std::cos(w * st.y);
    return {0.1 * ss * ct, {0.1 * w * cs * ct, -0.1 * w * ss * st_}};
  }
};

class SineNormalMap final : public VectorTexture {
 public:
  Vec3d sample(Vec2d st) const override {
    const Vec2d g = height_.sample(st).gradient;
    const Vec3d n = normalizeOr(Vec3d{-g.x, -g.y, 1}, Vec3d{0, 0, 1});
    return 0.5 * n + Vec3d{0.5, 0.5, 0.5};
  }

 private:
  SineHeight height_;
};

class WavyObjectNormals final : public VectorTexture {
 public:
  Vec3d sample(Vec2d st) const override {
    const Vec3d n =
        normalizeOr(Vec3d{0.3 * std::sin(3 * st.x), 0.3 * std::cos(2 * st.y), 1}, Vec3d{0, 0, 1});
    return 0.5 * n + Vec3d{0.5, 0.5, 0.5};
  }
};

/// 4096 points; @p normalOf picks the normal (to control how many triplanar planes are active).
template <class NormalOf>
std::vector<SurfacePoint> makePoints(NormalOf normalOf) {
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<SurfacePoint> points(4096);
  for (SurfacePoint& p : points) {
    const Vec3d dPdu{1 + 0.2 * u(rng), 0.1 * u(rng), 0.2 * u(rng)};
    const Vec3d dPdv{0.1 * u(rng), 1 + 0.2 * u(rng), 0.2 * u(rng)};
    p.position = {u(rng), u(rng), u(rng)};
    p.normal = normalizeOr(normalOf(cross(dPdu, dPdv), rng), Vec3d{0, 0, 1});
    p.numUvSets = 2;
    p.uv[0] = {{u(rng), u(rng)}, dPdu, dPdv};
    p.uv[1] = p.uv[0];
    p.tangent = normalizeOr(dPdu - dot(dPdu, p.normal) * p.normal, Vec3d{1, 0, 0});
    p.bitangentSign = 1;
    p.hasTangentFrame = true;
  }
  return points;
}

std::vector<SurfacePoint> defaultPoints() {
  return makePoints([](Vec3d geometric, std::mt19937_64&) { return geometric; });
}

void runLayers(benchmark::State& state, const std::vector<Layer>& layers,
               const std::vector<SurfacePoint>& points) {
  for (auto _ : state) {
    for (const SurfacePoint& p : points) benchmark::DoNotOptimize(compositeGradient(layers, p));
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(points.size()));
}

const SineHeight kHeight;
const SineNormalMap kTangentMap;
const WavyObjectNormals kObjectMap;

void UvHeight(benchmark::State& state) {
  runLayers(state, {{UvHeightSource{&kHeight, 0, 0.5, {2, 2}}, 1, {}}}, defaultPoints());
}
BENCHMARK(UvHeight);

void TangentNormalMikk(benchmark::State& state) {
  runLayers(state, {{TangentNormalSource{&kTangentMap, 0, {}}, 1, {}}}, defaultPoints());
}
BENCHMARK(TangentNormalMikk)->Name("TangentNormal/mikk");

void TangentNormalUvFrame(benchmark::State& state) {
  runLayers(state, {{TangentNormalSource{&kTangentMap, 1, {}}, 1, {}}}, defaultPoints());
}
BENCHMARK(TangentNormalUvFrame)->Name("TangentNormal/uvframe");

void ObjectNormal(benchmark::State& state) {
  runLayers(state, {{ObjectNormalSource{&kObjectMap, 0}, 1, {}}}, defaultPoints());
}
BENCHMARK(ObjectNormal);

/// Normals with exactly `planes` triplanar planes above the default threshold.
std::vector<SurfacePoint> triplanarPoints(int planes) {
  return makePoints([planes](Vec3d, std::mt19937_64& rng) {
    std::uniform_real_distribution<double> u(0.5, 1);
    const Vec3d n{u(rng), planes >= 2 ? u(rng) : 0.0, planes >= 3 ? u(rng) : 0.0};
    return n;
  });
}

void TriplanarHeight(benchmark::State& state) {
  const int planes = static_cast<int>(state.range(0));
  const std::vector<SurfacePoint> points = triplanarPoints(planes);
  int active = 0;
  for (const SurfacePoint& p : points) active += triplanarWeights(p.normal).active;
  if (active != planes * static_cast<int>(points.size())) state.SkipWithError("wrong plane count");
  TriplanarSource tri;
  tri.height = &kHeight;
  tri.options.tiling = {2, 2};
  runLayers(state, {{tri, 1, {}}}, points);
}
BENCHMARK(TriplanarHeight)->ArgName("planes")->Arg(1)->Arg(2)->Arg(3);

/// Normals in the zone of Blender's Box projection (Blend 0.3) with `planes` planes.
std::vector<SurfacePoint> boxPoints(int planes) {
  return makePoints([planes](Vec3d, std::mt19937_64& rng) {
    std::uniform_real_distribution<double> u(0.95, 1.05);
    return Vec3d{u(rng), planes >= 2 ? u(rng) : 0.0, planes >= 3 ? u(rng) : 0.0};
  });
}

void runBox(benchmark::State& state, int planes, const CoordinateMapping& coordinates) {
  TriplanarSource tri;
  tri.height = &kHeight;
  tri.options.tiling = {2, 2};
  tri.options.projection = TriplanarProjection::kBox;
  tri.options.boxBlend = 0.3;
  tri.options.coordinates = coordinates;
  const std::vector<SurfacePoint> points = boxPoints(planes);
  int active = 0;
  for (const SurfacePoint& p : points) active += boxProjectionWeights(p.normal, 0.3).active;
  if (active != planes * static_cast<int>(points.size())) state.SkipWithError("wrong plane count");
  runLayers(state, {{tri, 1, {}}}, points);
}

/// The tangent-space map read by a projection of Blender's (kBox: Blend 0.3, normals in the
/// zone of `planes` planes; kFlat).
void runProjectedTangentNormal(benchmark::State& state, TriplanarProjection projection,
                               int planes) {
  TangentNormalSource source{&kTangentMap, 0, {}};
  source.projection = TriplanarOptions{};
  source.projection->projection = projection;
  source.projection->boxBlend = 0.3;
  source.projection->tiling = {2, 2};
  runLayers(state, {{source, 1, {}}}, boxPoints(planes));
}

void ProjectedTangentNormalBox(benchmark::State& state) {
  runProjectedTangentNormal(state, TriplanarProjection::kBox, static_cast<int>(state.range(0)));
}
BENCHMARK(ProjectedTangentNormalBox)
    ->Name("ProjectedTangentNormal")
    ->ArgName("box")
    ->Arg(1)
    ->Arg(2)
    ->Arg(3);

void ProjectedTangentNormalFlat(benchmark::State& state) {
  runProjectedTangentNormal(state, TriplanarProjection::kFlat, 3);
}
BENCHMARK(ProjectedTangentNormalFlat)->Name("ProjectedTangentNormal/flat");

void ProjectedTangentNormalSphere(benchmark::State& state) {
  runProjectedTangentNormal(state, TriplanarProjection::kSphere, 3);
}
BENCHMARK(ProjectedTangentNormalSphere)->Name("ProjectedTangentNormal/sphere");

void ProjectedTangentNormalTube(benchmark::State& state) {
  runProjectedTangentNormal(state, TriplanarProjection::kTube, 3);
}
BENCHMARK(ProjectedTangentNormalTube)->Name("ProjectedTangentNormal/tube");

/// A height read by one of Blender's single lookups (kFlat, kSphere, kTube): a planar layer.
void runSingleLookupHeight(benchmark::State& state, TriplanarProjection projection) {
  PlanarSource planar;
  planar.height = &kHeight;
  planar.mapping = singleLookupMapping(projection, {2, 2});
  runLayers(state, {{planar, 1, {}}}, defaultPoints());
}

void PlanarHeightFlat(benchmark::State& state) {
  runSingleLookupHeight(state, TriplanarProjection::kFlat);
}
BENCHMARK(PlanarHeightFlat)->Name("PlanarHeight/flat");

void PlanarHeightSphere(benchmark::State& state) {
  runSingleLookupHeight(state, TriplanarProjection::kSphere);
}
BENCHMARK(PlanarHeightSphere)->Name("PlanarHeight/sphere");

void PlanarHeightTube(benchmark::State& state) {
  runSingleLookupHeight(state, TriplanarProjection::kTube);
}
BENCHMARK(PlanarHeightTube)->Name("PlanarHeight/tube");

void TriplanarBoxHeight(benchmark::State& state) {
  runBox(state, static_cast<int>(state.range(0)), {});
}
BENCHMARK(TriplanarBoxHeight)->ArgName("planes")->Arg(1)->Arg(2)->Arg(3);

void TriplanarBoxHeightMapped(benchmark::State& state) {
  runBox(state, 3,
         CoordinateMapping::fromMappingNode({0.3, -0.2, 0.1}, {0.4, 0.2, 0.7}, {1.5, 0.8, 1.2}));
}
BENCHMARK(TriplanarBoxHeightMapped)->Name("TriplanarBoxHeight/mapped");

void Composite3(benchmark::State& state) {
  const std::vector<SurfacePoint> points = triplanarPoints(3);
  TriplanarSource tri;
  tri.height = &kHeight;
  const std::vector<Layer> layers{{UvHeightSource{&kHeight, 0, 0.5, {2, 2}}, 1, {}},
                                  {TangentNormalSource{&kTangentMap, 0, {}}, 0.5, {}},
                                  {tri, 0.25, {}}};
  for (auto _ : state) {
    for (const SurfacePoint& p : points) benchmark::DoNotOptimize(perturbedNormal(p, layers));
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(points.size()));
}
BENCHMARK(Composite3);

}  // namespace

BENCHMARK_MAIN();
