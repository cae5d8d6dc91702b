/// @file raster.hpp
/// @brief Private: the texel raster shared by bakeMap and convertNormalMap (see bake.hpp, "Texels
/// and coverage", for the conventions it implements).
///
/// rasterize() walks the texels of one UDIM tile, finds the triangle that claims each sample and
/// hands (triangle, barycentrics) to a Shader, a small class with a compile-time channel count:
///
///     struct Shader {
///       static constexpr int kChannels = 3;
///       // Called once per (row block, triangle) before its samples: `triangle` is its index in
///       // RasterJob::triangles, `corners` its global corner indices.
///       void beginTriangle(std::uint32_t triangle, const std::array<std::uint32_t, 3>& corners);
///       // One covered sample; writes kChannels values to out. x, y: texel, y up.
///       void shade(const Vec3d& bary, int x, int y, double* out);
///     };
///
/// Each row block gets its own copy of the shader (so shaders may keep per-triangle state), and
/// no shader call is virtual: the per-sample path is inlined into the raster loop.
///
/// A shader may also shade samples in batches (BatchShader): it then gets up to
/// SampleBatch::kMax covered samples of one triangle at a time, in the order shade() would have
/// seen them, and must give each the values shade() gives it, bit for bit (a batch is only a
/// way to let the compiler compute several samples with one vector instruction).
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/task_arena.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "sgbake/bake/bake.hpp"
#include "sgbake/core/vec.hpp"
#include "sgbake/mesh/mesh.hpp"

namespace sgbake::bake_detail {

/// Rows of texels per parallel work item. Fixed (not derived from the thread count), so the
/// partition of the work, and therefore every result bit, is the same for any number of threads.
inline constexpr int kRowsPerBlock = 8;

/// @brief One edge of a triangle as an affine function of the texel-space point p:
/// E(p) = a·p.x + b·p.y + c, positive inside the triangle, zero on the edge.
struct EdgeFunction {
  double a = 0, b = 0, c = 0;
  /// Whether samples exactly on the edge (E == 0) belong to this triangle (the nudge rule).
  bool claimsTies = false;

  double operator()(double x, double y) const { return a * x + b * y + c; }
  bool inside(double e) const { return e > 0 || (e == 0 && claimsTies); }
};

/// @brief A triangle set up for rasterization in texel space (x right, y up, units of texels,
/// origin at the tile's lower-left corner).
struct RasterTriangle {
  std::array<EdgeFunction, 3> edge;  ///< edge[i] is opposite corner i: E_i ∝ barycentric b_i
  int x0 = 0, x1 = -1, y0 = 0, y1 = -1;  ///< inclusive texel bounding box, clipped to the tile
};

/// @brief Sets up @p triangle from its corners' texel-space positions.
///
/// Edge functions are computed with the edge's endpoints in lexicographic (x, then y) order and
/// negated as needed, so a neighbour sharing the edge gets bitwise the opposite function; ties go
/// to the triangle into which the nudge direction ε·(1, 2) + ε²·(1, 0) points.
/// @return false when the triangle has zero area (it covers nothing) or is outside the tile
bool setupRasterTriangle(const std::array<Vec2d, 3>& texel, int width, int height,
                         RasterTriangle& triangle);

/// @brief Where the samples of a texel sit, as offsets from its lower-left corner: sample
/// (i, j) of an N × N bake is at (x[i], y[j]), ((i + 0.5)/N, (j + 0.5)/N) + kBakeSampleNudge
/// (bake.hpp, "Where a texel is sampled").
struct SampleOffsets {
  std::vector<double> x, y;
  explicit SampleOffsets(int samples);
};

/// @brief The texels [first, last] of row @p y (within the triangle's bounding box) that may
/// hold a sample inside @p tri, the samples being at x + offsets.x[i], y + offsets.y[j]:
/// rasterize() still tests every sample exactly, this only skips texels
/// where no sample can be inside. The bounds come from solving E(px) = 0 per edge, widened by a
/// texel plus the rounding error of evaluating E, so no sample the exact test would accept is
/// ever skipped.
void rowSpan(const RasterTriangle& tri, int y, const SampleOffsets& offsets, int& first, int& last);

/// @brief The corners Cycles shades each loop triangle of @p triangles (loopTriangles(mesh))
/// with; empty when those are the triangles' own everywhere.
///
/// Blender's baker splits a quad by its fast test (the one loopTriangles reproduces), and
/// Cycles its own copy of the mesh by the test that uses the polygon normal; on a near-tie
/// (Suzanne's concave quads 162 and 163) they choose different diagonals, and the baker hands
/// Cycles its triangle k with barycentrics that Cycles reads on its own triangle k of the
/// other split: a texel there shows the other triangle's normal and point (measured: all 48
/// texels of flat Suzanne's two quads, 28–115° off before). The texel's frame stays the
/// baker's.
std::vector<std::array<std::uint32_t, 3>> cyclesShadingTriangles(
    const Mesh& mesh, std::span<const std::array<std::uint32_t, 3>> triangles);

/// @brief Cycles' triangles of @p mesh, in loop-triangle order: loopTriangles(mesh) with the
/// quads Cycles splits on the other diagonal cut as Cycles cuts them (cyclesShadingTriangles).
/// Cycles' MikkTSpace, which its Normal Map node decodes in, runs on these.
std::vector<std::array<std::uint32_t, 3>> cyclesTriangles(const Mesh& mesh);

/// @brief Texel-space position of UV @p uv in a width × height bake of tile @p udimTile.
inline Vec2d uvToTexel(Vec2f uv, int udimTile, int width, int height) {
  const int index = udimTile - kFirstUdimTile;
  return {(static_cast<double>(uv.x) - static_cast<double>(index % 10)) * width,
          (static_cast<double>(uv.y) - static_cast<double>(index / 10)) * height};
}

/// @brief Covered samples of one triangle, handed to a BatchShader together: barycentrics and
/// texel per sample, as separate arrays (so that loops over the samples vectorize).
struct SampleBatch {
  static constexpr int kMax = 64;
  int count = 0;
  std::array<double, kMax> b0, b1, b2;
  std::array<int, kMax> x, y;
};

/// @brief A shader that also has shadeBatch(batch, out): the kChannels values of sample i to
/// out[i·kChannels …], equal to shade(bary_i, x_i, y_i, …).
template <class S>
concept BatchShader = requires(S& shader, const SampleBatch& batch, double* out) {
  shader.shadeBatch(batch, out);
};

/// @brief What to rasterize: the triangles, where their corners sit in the image, and how.
struct RasterJob {
  std::span<const std::array<std::uint32_t, 3>> triangles;  ///< global corner indices
  std::span<const Vec2f> uvs;  ///< #C corner UVs of the UV set that places the texels
  int width = 0, height = 0, samples = 1, udimTile = kFirstUdimTile, threads = 0;
  /// Optional: rasterize() then works in bands of kBlocksPerBand row blocks from the top of the
  /// image down and calls it after each band with the number of final rows from the top, while
  /// it bakes the next band (one call at a time, in order, on one of the bake's threads); it
  /// returns whether to go on (bakeMapRows). The target must hold two bands and what the
  /// call reads above them.
  std::function<bool(int rowsFinal)> onRowsFinal;
};

/// Row blocks per band when RasterJob::onRowsFinal is set: kBakeBandRows rows, so a 4096² bake
/// reports 16 times (each band ends with a wait for its slowest block, so bands are not made
/// smaller).
inline constexpr int kBlocksPerBand = kBakeBandRows / kRowsPerBlock;
static_assert(kBlocksPerBand * kRowsPerBlock == kBakeBandRows);

/// @brief The RasterJob of a bake or a conversion (BakeSettings, ConvertSettings): @p triangles
/// (loopTriangles(mesh), which must outlive the job) placed by UV set settings.uvSet in a
/// @p width × @p height image of UDIM tile settings.udimTile.
template <class Settings>
RasterJob rasterJobFor(const Mesh& mesh, std::span<const std::array<std::uint32_t, 3>> triangles,
                       const Settings& settings, int width, int height) {
  RasterJob job;
  job.triangles = triangles;
  job.uvs = mesh.uvSets[static_cast<std::size_t>(settings.uvSet)].uvs;
  job.width = width;
  job.height = height;
  job.samples = settings.samples;
  job.udimTile = settings.udimTile;
  job.threads = settings.threads;
  return job;
}

/// @brief Triangles overlapping each block of kRowsPerBlock rows, in ascending triangle order
/// (compressed rows: the triangles of block k are index[start[k] .. start[k+1])).
struct TriangleBins {
  std::vector<std::uint32_t> start;
  std::vector<std::uint32_t> index;
};

/// @brief Bins the job's triangles by row block (serial; a few ns per triangle).
TriangleBins binTriangles(const RasterJob& job);

/// @brief Runs @p work() in a task arena of at most @p threads threads (0: the caller's arena,
/// i.e. all cores by default). A caller already in an arena of that many threads runs @p work
/// there: nested calls share the arena, and with it the tasks ImageFileWriter enqueues in it.
template <class Work>
void runWithThreads(int threads, const Work& work) {
  const int wanted = std::min(threads, tbb::info::default_concurrency());
  if (threads > 0 && tbb::this_task_arena::max_concurrency() != wanted) {
    tbb::task_arena arena(wanted);
    arena.execute(work);
  } else {
    work();
  }
}

/// @brief Maps the pages of [data, data + bytes) writable now, in @p pieces concurrent parts
/// (Linux MADV_POPULATE_WRITE; elsewhere, or when the kernel refuses, nothing happens and the
/// pages fault in on first touch as usual). One system call per piece instead of one page fault
/// per 4 KiB page, spread over the threads: a 4096² bake allocates ~270 MB.
void prefaultPages(void* data, std::size_t bytes, int pieces);

/// @brief Sizes @p image (width × height × channels, coverage width × height), zero-filled. The
/// pages are mapped first, in parallel (prefaultPages), and the two buffers are zero-filled
/// concurrently: first-touching hundreds of MB is a serial cost that limits scaling.
inline void allocateImage(FloatImage& image, int width, int height, int channels, int threads) {
  image.width = width;
  image.height = height;
  image.channels = channels;
  const std::size_t texels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  const std::size_t values = texels * static_cast<std::size_t>(channels);
  image.pixels.reserve(values);
  image.coverage.reserve(texels);
  runWithThreads(threads, [&] {
    const int pieces = std::max(1, tbb::this_task_arena::max_concurrency());
    tbb::parallel_invoke([&] { prefaultPages(image.pixels.data(), values * sizeof(float), pieces); },
                         [&] { prefaultPages(image.coverage.data(), texels * sizeof(float), pieces); });
    tbb::parallel_invoke([&] { image.pixels.resize(values); }, [&] { image.coverage.resize(texels); });
  });
}

/// @brief Where rasterize() writes: file row r (top first) of the image at slot r % ringRows of
/// the buffers (ringRows == height: a whole image; fewer: bakeMapRows' reused band ring, whose
/// slots are reset before a band is baked into them).
struct RasterTarget {
  float* pixels = nullptr;    ///< ringRows·width·channels
  float* coverage = nullptr;  ///< ringRows·width
  int channels = 0;           ///< ≥ Shader::kChannels
  int ringRows = 0;

  static RasterTarget of(FloatImage& image) {
    return {image.pixels.data(), image.coverage.data(), image.channels, image.height};
  }
};

/// @brief How rasterize() finishes a texel.
struct RasterOutput {
  std::span<const float> background;  ///< kChannels values of texels no sample covers
  bool valueIsCoverage = false;       ///< kMask: the value is the coverage fraction itself
  /// Leave the pixels of uncovered texels as they are (convertNormalMap) instead of writing the
  /// background (their coverage is still set to 0).
  bool keepUncovered = false;
  /// With keepUncovered: the whole image's starting values (height rows of width·channels
  /// values, file rows top first, the target's channels), copied into each row of the target
  /// before the row is rasterized; the uncovered texels keep them (convertNormalMapRows, whose
  /// ring of rows holds another band before). Null: the target's rows already hold them.
  const float* initialPixels = nullptr;
  /// The image was just allocated: its coverage is all +0, and so are its pixels unless
  /// keepUncovered, so rasterize() writes neither again (one pass over hundreds of MB less) and
  /// the background only when it is not zero.
  bool blank = false;
};

/// @brief Rasterizes @p job into @p target (a width × height image of target.channels ≥
/// Shader::kChannels channels, or a ring of its rows) with @p prototype copied once per row
/// block. Only channels 0 … kChannels−1 are written.
///
/// Texels with covered samples get the mean of the shader's values over those samples and
/// coverage = covered / N²; others get @p output.background and coverage 0.
template <class Shader>
void rasterize(const RasterJob& job, const Shader& prototype, const RasterOutput& output,
               const RasterTarget& target) {
  constexpr int kC = Shader::kChannels;
  const int W = job.width, H = job.height, N = job.samples;
  const std::size_t stride = static_cast<std::size_t>(target.channels);
  const TriangleBins bins = binTriangles(job);
  const int numBlocks = (H + kRowsPerBlock - 1) / kRowsPerBlock;

  // +0 only: a blank image holds +0, and −0 must still be written. (keepUncovered jobs have no
  // background.)
  const bool backgroundIsZero =
      !output.keepUncovered &&
      std::all_of(output.background.begin(), output.background.begin() + kC,
                  [](float v) { return v == 0 && !std::signbit(v); });
  const SampleOffsets offsets(N);
  // A row of background texels, copied whole into each row to reset when the shader fills
  // every channel (texel by texel, channel by channel, the reset cost a sixth of the raster).
  std::vector<float> backgroundRow;
  if (!output.keepUncovered && stride == static_cast<std::size_t>(kC)) {
    backgroundRow.resize(static_cast<std::size_t>(W) * stride);
    for (std::size_t i = 0; i < backgroundRow.size(); ++i) {
      backgroundRow[i] = output.background[i % stride];
    }
  }

  // Per-thread scratch for N > 1: per-texel sums (double) and sample counts of one block.
  tbb::enumerable_thread_specific<std::vector<double>> sumsTls;
  tbb::enumerable_thread_specific<std::vector<int>> countsTls;
  // ... and which of its samples a triangle has claimed (overlapping UVs: see below).
  tbb::enumerable_thread_specific<std::vector<std::uint8_t>> claimedTls;
  const std::size_t samplesPerTexel = static_cast<std::size_t>(N) * static_cast<std::size_t>(N);

  auto processBlock = [&](int block) {
    const int yBegin = block * kRowsPerBlock;
    const int yEnd = std::min(H, yBegin + kRowsPerBlock);
    const std::size_t blockTexels = static_cast<std::size_t>(yEnd - yBegin) * W;
    // The block's rows in the target (file row H − 1 − y; a ring wraps between rows).
    std::array<float*, kRowsPerBlock> pixelRows{}, coverageRows{};
    for (int y = yBegin; y < yEnd; ++y) {
      const std::size_t slot = static_cast<std::size_t>((H - 1 - y) % target.ringRows);
      pixelRows[static_cast<std::size_t>(y - yBegin)] = target.pixels + slot * W * stride;
      coverageRows[static_cast<std::size_t>(y - yBegin)] = target.coverage + slot * W;
    }
    auto pixelAt = [&](int x, int y) {
      return pixelRows[static_cast<std::size_t>(y - yBegin)] + static_cast<std::size_t>(x) * stride;
    };
    auto coverageAt = [&](int x, int y) -> float& {
      return coverageRows[static_cast<std::size_t>(y - yBegin)][x];
    };

    // Start from "nothing covered": background (unless kept) and coverage 0.
    const bool writeCoverage = !output.blank;
    const bool writeBackground = !output.keepUncovered && !(output.blank && backgroundIsZero);
    if (output.keepUncovered && output.initialPixels != nullptr) {
      const std::size_t rowValues = static_cast<std::size_t>(W) * stride;
      for (int y = yBegin; y < yEnd; ++y) {
        const float* from = output.initialPixels + static_cast<std::size_t>(H - 1 - y) * rowValues;
        std::copy(from, from + rowValues, pixelRows[static_cast<std::size_t>(y - yBegin)]);
      }
    }
    for (int y = yBegin; y < yEnd && (writeCoverage || writeBackground); ++y) {
      if (writeCoverage) std::fill_n(&coverageAt(0, y), W, 0.0f);
      if (writeBackground && !backgroundRow.empty()) {
        std::copy(backgroundRow.begin(), backgroundRow.end(), pixelAt(0, y));
      } else if (writeBackground) {
        for (int x = 0; x < W; ++x) {
          float* pixel = pixelAt(x, y);
          for (int c = 0; c < kC; ++c) pixel[c] = output.background[static_cast<std::size_t>(c)];
        }
      }
    }
    std::vector<double>* sums = nullptr;
    std::vector<int>* counts = nullptr;
    std::uint8_t* claimed = nullptr;
    if (N > 1) {
      sums = &sumsTls.local();
      counts = &countsTls.local();
      sums->assign(blockTexels * kC, 0.0);
      counts->assign(blockTexels, 0);
      std::vector<std::uint8_t>& claims = claimedTls.local();
      claims.assign(blockTexels * samplesPerTexel, 0);
      claimed = claims.data();
    }

    Shader shader = prototype;
    // A covered sample's values into the image (one sample per texel) or the block's sums.
    auto store = [&](int x, int y, const double* v) {
      if (N == 1) {  // each texel has one sample, claimed once: store it
        float* pixel = pixelAt(x, y);
        for (int c = 0; c < kC; ++c) pixel[c] = static_cast<float>(v[c]);
        coverageAt(x, y) = 1;
      } else {
        const std::size_t local = static_cast<std::size_t>(y - yBegin) * W + x;
        for (int c = 0; c < kC; ++c) (*sums)[local * kC + c] += v[c];
        ++(*counts)[local];
      }
    };
    constexpr bool kBatched = BatchShader<Shader>;
    SampleBatch batch;
    std::array<double, kBatched ? SampleBatch::kMax * kC : 1> batchValues;
    auto flush = [&] {
      if constexpr (kBatched) {
        if (batch.count == 0) return;
        shader.shadeBatch(batch, batchValues.data());
        for (int i = 0; i < batch.count; ++i)
          store(batch.x[static_cast<std::size_t>(i)], batch.y[static_cast<std::size_t>(i)],
                batchValues.data() + static_cast<std::size_t>(i) * kC);
        batch.count = 0;
      }
    };
    // Where UV islands overlap, a sample belongs to the last triangle that covers it, as a
    // pixel does in Blender's baker. One sample per texel: triangles in order, each overwriting
    // the texel. Several: triangles in reverse order, each sample kept by the first that claims
    // it (a texel's sums must not count a sample twice); the same owners.
    const std::uint32_t first = bins.start[block], end = bins.start[block + 1];
    for (std::uint32_t n = 0; n < end - first; ++n) {
      const std::uint32_t k = N == 1 ? first + n : end - 1 - n;
      const std::array<std::uint32_t, 3>& corners = job.triangles[bins.index[k]];
      RasterTriangle tri;
      const std::array<Vec2d, 3> texel{uvToTexel(job.uvs[corners[0]], job.udimTile, W, H),
                                       uvToTexel(job.uvs[corners[1]], job.udimTile, W, H),
                                       uvToTexel(job.uvs[corners[2]], job.udimTile, W, H)};
      if (!setupRasterTriangle(texel, W, H, tri)) continue;
      const int ya = std::max(tri.y0, yBegin), yb = std::min(tri.y1, yEnd - 1);
      if (ya > yb) continue;
      bool begun = false;  // load the shading data only if a sample is inside
      for (int y = ya; y <= yb; ++y) {
        int xFirst = 0, xLast = -1;
        rowSpan(tri, y, offsets, xFirst, xLast);
        for (int x = xFirst; x <= xLast; ++x) {
          for (int j = 0; j < N; ++j) {
            const double py = y + offsets.y[static_cast<std::size_t>(j)];
            for (int i = 0; i < N; ++i) {
              const double px = x + offsets.x[static_cast<std::size_t>(i)];
              const double e0 = tri.edge[0](px, py);
              if (!tri.edge[0].inside(e0)) continue;
              const double e1 = tri.edge[1](px, py);
              if (!tri.edge[1].inside(e1)) continue;
              const double e2 = tri.edge[2](px, py);
              if (!tri.edge[2].inside(e2)) continue;
              if (claimed != nullptr) {
                std::uint8_t& owner =
                    claimed[(static_cast<std::size_t>(y - yBegin) * static_cast<std::size_t>(W) +
                             static_cast<std::size_t>(x)) * samplesPerTexel +
                            static_cast<std::size_t>(j * N + i)];
                if (owner) continue;  // a later triangle has it
                owner = 1;
              }
              if (!begun) {
                shader.beginTriangle(bins.index[k], corners);
                begun = true;
              }
              // Barycentrics from the edge functions; all three are ≥ 0 here.
              const double sum = e0 + e1 + e2;
              const double inv = sum > 0 ? 1 / sum : 0;
              const Vec3d bary = sum > 0 ? Vec3d{e0 * inv, e1 * inv, e2 * inv}
                                         : Vec3d{1.0 / 3, 1.0 / 3, 1.0 / 3};
              if constexpr (kBatched) {
                const std::size_t lane = static_cast<std::size_t>(batch.count++);
                batch.b0[lane] = bary.x;
                batch.b1[lane] = bary.y;
                batch.b2[lane] = bary.z;
                batch.x[lane] = x;
                batch.y[lane] = y;
                if (batch.count == SampleBatch::kMax) flush();
              } else {
                double value[kC];
                shader.shade(bary, x, y, value);
                store(x, y, value);
              }
            }
          }
        }
      }
      flush();  // the rest of this triangle's samples, before the next triangle begins
    }

    if (N > 1) {  // mean of the covered samples, coverage = covered / N²
      for (int y = yBegin; y < yEnd; ++y) {
        for (int x = 0; x < W; ++x) {
          const std::size_t local = static_cast<std::size_t>(y - yBegin) * W + x;
          const int count = (*counts)[local];
          if (count == 0) continue;
          float* pixel = pixelAt(x, y);
          const double* sum = sums->data() + local * kC;
          for (int c = 0; c < kC; ++c) pixel[c] = static_cast<float>(sum[c] / count);
          coverageAt(x, y) = static_cast<float>(count) / static_cast<float>(N * N);
        }
      }
    }
    if (output.valueIsCoverage) {
      for (int y = yBegin; y < yEnd; ++y)
        for (int x = 0; x < W; ++x)
          if (coverageAt(x, y) > 0)
            for (int c = 0; c < kC; ++c) pixelAt(x, y)[c] = coverageAt(x, y);
    }
  };

  auto processBlocks = [&](int first, int end) {
    tbb::parallel_for(tbb::blocked_range<int>(first, end, 1), [&](const tbb::blocked_range<int>& r) {
      for (int b = r.begin(); b != r.end(); ++b) processBlock(b);
    });
  };
  runWithThreads(job.threads, [&] {
    if (!job.onRowsFinal) {
      processBlocks(0, numBlocks);
      return;
    }
    // Bands from the top of the image (the highest blocks: y is up, rows are top first) down.
    // Each band's rows go to onRowsFinal in a task of their own while the next band is baked,
    // so its serial parts (and its waits for a writer) overlap the baking; one call at a time,
    // in order, and never while the band it reads is still being baked.
    tbb::task_group reporting;
    bool goOn = true;  // the last call's answer, read once it is done
    for (int end = numBlocks; end > 0; end -= kBlocksPerBand) {
      const int first = std::max(0, end - kBlocksPerBand);
      processBlocks(first, end);
      reporting.wait();
      if (!goOn) return;
      const int rowsFinal = H - first * kRowsPerBlock;
      reporting.run([&job, &goOn, rowsFinal] { goOn = job.onRowsFinal(rowsFinal); });
    }
    reporting.wait();
  });
}

}  // namespace sgbake::bake_detail
