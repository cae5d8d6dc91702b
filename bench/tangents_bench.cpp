/// @file tangents_bench.cpp
/// @brief Google Benchmark timings of sgbake::computeTangents (and, optionally, loadMesh).
///
/// How to run (from a Release build, e.g. `cmake -B build -DCMAKE_BUILD_TYPE=Release`):
///
///     ninja -C build sgbake_bench_tangents
///     build/bench/sgbake_bench_tangents
///     SGBAKE_BENCH_MESH=big.obj build/bench/sgbake_bench_tangents   # also load + tangents of a
///     file build/bench/sgbake_bench_tangents --benchmark_filter=Tangents/torus
///     --benchmark_repetitions=5
///
/// Benchmarks:
///   - `Tangents/torus/threads:1` and `Tangents/torus/threads:N` (N = all cores): computeTangents
///     on a procedural torus of 500 x 250 quads (125k faces, 500k corners) with smooth analytic
///     normals and one UV set with a seam in both directions, built here in memory so the number
///     does not depend on any file or loader.
///   - `Triangulate/<corners>/<waves>`: triangulatePolygon of one n-gon, a circle (waves 0) or a
///     wavy ring whose every other stretch is reflex.
///   - With SGBAKE_BENCH_MESH=PATH: `Load/<file>` (loadMesh) and `Tangents/<file>/threads:*`.
/// Times are wall-clock (UseRealTime), since the work is spread over threads; `items_per_second`
/// is corners per second. Compare with Blender using bench/tangents_vs_blender.py.

#include <benchmark/benchmark.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <numbers>
#include <string>
#include <thread>
#include <vector>

#include "sgbake/frames/tangents.hpp"
#include "sgbake/mesh/io.hpp"
#include "sgbake/mesh/mesh.hpp"
#include "sgbake/mesh/triangulate.hpp"

namespace {

/// @brief A torus of @p majorSegments x @p minorSegments quads around the z axis.
///
/// Vertex (i, j) sits at angle 2πi/majorSegments around the ring and 2πj/minorSegments around
/// the tube. Face (i, j) has corners (i, j), (i+1, j), (i+1, j+1), (i, j+1), counter-clockwise
/// seen from outside. UVs are (i/majorSegments, j/minorSegments) per corner; the faces of the last
/// row and column use u = 1 or v = 1 where their vertex wraps to index 0, so the UV map has a seam
/// in both directions exactly like Blender's torus primitive.
sgbake::Mesh makeTorus(std::uint32_t majorSegments, std::uint32_t minorSegments) {
  constexpr double kMajorRadius = 1.0;
  constexpr double kMinorRadius = 0.25;
  constexpr double kTwoPi = 2.0 * std::numbers::pi;

  sgbake::Mesh mesh;
  mesh.source = "procedural torus";
  const std::size_t numVertices = std::size_t{majorSegments} * minorSegments;
  const std::size_t numCorners = 4 * numVertices;
  mesh.positions.reserve(numVertices);
  std::vector<sgbake::Vec3f> vertexNormals;
  vertexNormals.reserve(numVertices);
  for (std::uint32_t i = 0; i < majorSegments; ++i) {
    const double phi = kTwoPi * i / majorSegments;
    for (std::uint32_t j = 0; j < minorSegments; ++j) {
      const double theta = kTwoPi * j / minorSegments;
      const double ring = kMajorRadius + kMinorRadius * std::cos(theta);
      mesh.positions.push_back(sgbake::cast<float>(sgbake::Vec3d{
          ring * std::cos(phi), ring * std::sin(phi), kMinorRadius * std::sin(theta)}));
      vertexNormals.push_back(sgbake::cast<float>(sgbake::Vec3d{
          std::cos(theta) * std::cos(phi), std::cos(theta) * std::sin(phi), std::sin(theta)}));
    }
  }

  mesh.faceStart.reserve(numVertices + 1);
  mesh.cornerVertex.reserve(numCorners);
  mesh.cornerNormals.reserve(numCorners);
  sgbake::UvSet uvs{"UVMap", {}};
  uvs.uvs.reserve(numCorners);
  for (std::uint32_t i = 0; i < majorSegments; ++i) {
    for (std::uint32_t j = 0; j < minorSegments; ++j) {
      // (di, dj) walks the face's corners counter-clockwise.
      constexpr std::uint32_t kCornerOffsets[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
      for (const auto& offset : kCornerOffsets) {
        const std::uint32_t ci = i + offset[0];  // may equal majorSegments: u = 1 on the seam
        const std::uint32_t cj = j + offset[1];
        const std::uint32_t vertex = (ci % majorSegments) * minorSegments + cj % minorSegments;
        mesh.cornerVertex.push_back(vertex);
        mesh.cornerNormals.push_back(vertexNormals[vertex]);
        uvs.uvs.push_back({static_cast<float>(static_cast<double>(ci) / majorSegments),
                           static_cast<float>(static_cast<double>(cj) / minorSegments)});
      }
      mesh.faceStart.push_back(static_cast<std::uint32_t>(mesh.cornerVertex.size()));
    }
  }
  mesh.uvSets.push_back(std::move(uvs));
  return mesh;
}

/// @brief Times computeTangents on @p mesh with at most @p threads threads.
void benchTangents(benchmark::State& state, const sgbake::Mesh& mesh, int threads) {
  const sgbake::MeshView view = mesh.view();
  for (auto _ : state) {
    auto result = sgbake::computeTangents(view, sgbake::TangentOptions{threads});
    if (!result) {
      state.SkipWithError(result.error().message.c_str());
      break;
    }
    benchmark::DoNotOptimize(result->tangent.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(mesh.numCorners()));
  state.counters["corners"] = static_cast<double>(mesh.numCorners());
  state.counters["threads"] = threads;
}

/// @brief Times loadMesh on @p path.
void benchLoad(benchmark::State& state, const std::filesystem::path& path) {
  std::size_t corners = 0;
  for (auto _ : state) {
    auto mesh = sgbake::loadMesh(path);
    if (!mesh) {
      state.SkipWithError(mesh.error().message.c_str());
      break;
    }
    corners = mesh->numCorners();
    benchmark::DoNotOptimize(mesh->positions.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(corners));
  state.counters["corners"] = static_cast<double>(corners);
}

/// @brief Registers Tangents/<label>/threads:1 and, on a multi-core machine, threads:<all>.
void registerTangents(const std::string& label, const sgbake::Mesh& mesh) {
  std::vector<int> threadCounts{1};
  const int cores = static_cast<int>(std::thread::hardware_concurrency());
  if (cores > 1) threadCounts.push_back(cores);
  for (const int threads : threadCounts) {
    const std::string name = "Tangents/" + label + "/threads:" + std::to_string(threads);
    benchmark::RegisterBenchmark(name.c_str(), benchTangents, std::cref(mesh), threads)
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
  }
}

/// @brief Times triangulatePolygon on one ring of state.range(0) corners: a circle (every corner
/// convex, or straight in float) when state.range(1) is 0, else a ring with that many waves
/// (half its corners reflex).
void benchTriangulate(benchmark::State& state) {
  const auto k = static_cast<std::size_t>(state.range(0));
  const double waves = static_cast<double>(state.range(1));
  std::vector<sgbake::Vec3f> points(k);
  for (std::size_t i = 0; i < k; ++i) {
    const double a = 2 * std::numbers::pi * static_cast<double>(i) / static_cast<double>(k);
    const double r = 1 + 0.3 * std::sin(waves * a);
    points[i] = {static_cast<float>(r * std::cos(a)), static_cast<float>(r * std::sin(a)), 0.0f};
  }
  std::vector<std::array<std::uint32_t, 3>> triangles;
  for (auto _ : state) {
    sgbake::triangulatePolygon(points, triangles);
    benchmark::DoNotOptimize(triangles.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(k));
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;

  // The meshes live until the benchmarks have run; the registered closures refer to them.
  const sgbake::Mesh torus = makeTorus(500, 250);  // 125000 quads, 500000 corners
  registerTangents("torus", torus);
  benchmark::RegisterBenchmark("Triangulate", benchTriangulate)
      ->Args({1000, 0})
      ->Args({100000, 0})
      ->Args({1000, 20})
      ->Args({100000, 200})
      ->Unit(benchmark::kMillisecond);

  sgbake::Mesh fileMesh;
  const char* meshPath = std::getenv("SGBAKE_BENCH_MESH");
  if (meshPath != nullptr && *meshPath != '\0') {
    const std::filesystem::path path(meshPath);
    const std::string label = path.filename().string();
    benchmark::RegisterBenchmark(("Load/" + label).c_str(), benchLoad, path)
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
    if (auto loaded = sgbake::loadMesh(path)) {
      fileMesh = std::move(*loaded);
      registerTangents(label, fileMesh);
    } else {
      std::fprintf(stderr, "SGBAKE_BENCH_MESH: %s\n", loaded.error().message.c_str());
    }
  }

  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
