// Edge padding: Blender's "Extend" margin (ring by ring, L1 metric) and push-pull hole filling.
// See bake.hpp for the exact rules.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <type_traits>
#include <vector>

#include "bake/raster.hpp"
#include "sgbake/bake/bake.hpp"

namespace sgbake {
namespace {

/// Weights of IMB_filter_extend: 2 for the four edge neighbours, 1 for the four diagonal ones.
constexpr double kEdgeNeighbourWeight = 2;
constexpr double kDiagonalNeighbourWeight = 1;
/// Rows per parallel work item of the image-wide scans.
constexpr int kScanRows = 16;

bool imageIsValid(const FloatImage& image) {
  const std::size_t texels = static_cast<std::size_t>(std::max(image.width, 0)) *
                             static_cast<std::size_t>(std::max(image.height, 0));
  return texels > 0 && image.channels > 0 &&
         image.pixels.size() == texels * static_cast<std::size_t>(image.channels) &&
         image.coverage.size() == texels;
}

/// Runs body(rowBegin, rowEnd) over [0, rows) in fixed blocks of kScanRows, in parallel.
template <class Body>
void forRowBlocks(int rows, int threads, const Body& body) {
  const int blocks = (rows + kScanRows - 1) / kScanRows;
  bake_detail::runWithThreads(threads, [&] {
    tbb::parallel_for(tbb::blocked_range<int>(0, blocks, 1), [&](const tbb::blocked_range<int>& r) {
      for (int b = r.begin(); b != r.end(); ++b)
        body(b * kScanRows, std::min(rows, (b + 1) * kScanRows));
    });
  });
}

/// Rows 0 … height−1 of the image extendMarginIn pads, wherever they are stored.
struct PaddedRows {
  int width = 0, height = 0, channels = 0;
  std::vector<float*> pixels;          ///< row r's width·channels values
  std::vector<const float*> coverage;  ///< row r's width coverage values
};

/// The rows [begin, end) of @p rows (which must hold them) as PaddedRows.
PaddedRows paddedRows(const MutableImageRows& rows, int begin, int end) {
  PaddedRows out;
  out.width = rows.width;
  out.height = end - begin;
  out.channels = rows.channels;
  for (int r = begin; r < end; ++r) {
    out.pixels.push_back(rows.pixelRow(r));
    out.coverage.push_back(rows.coverageRow(r));
  }
  return out;
}

/// extendMargin of the image @p image's rows make up (see bake.hpp). Reads the pixels of filled
/// texels only: the values uncovered texels start with never matter.
void extendMarginIn(const PaddedRows& image, int margin, int threads) {
  const int W = image.width, H = image.height, C = image.channels;
  const std::size_t stride = static_cast<std::size_t>(C);
  std::vector<std::uint8_t> filled(static_cast<std::size_t>(W) * static_cast<std::size_t>(H));
  forRowBlocks(H, threads, [&](int r0, int r1) {
    for (int r = r0; r < r1; ++r) {
      // Raw pointers: a store through uint8_t* may alias anything, which would make the
      // compiler reload the vectors' pointers every iteration instead of vectorizing.
      const float* coverage = image.coverage[static_cast<std::size_t>(r)];
      std::uint8_t* out = filled.data() + static_cast<std::size_t>(r) * W;
      for (int x = 0; x < W; ++x) out[x] = coverage[x] > 0 ? 1 : 0;
    }
  });

  auto isFilled = [&](int x, int r) {
    return x >= 0 && x < W && r >= 0 && r < H && filled[static_cast<std::size_t>(r) * W + x] != 0;
  };

  // Ring 1: every unfilled texel with a filled 4-neighbour, found by a parallel scan whose
  // per-block lists are concatenated in row order. Per row, a branch-free (vectorized) pass
  // marks the ring's texels, and a second one collects the marks eight bytes at a time (most
  // of an image is either inside an island or far from one).
  const int scanBlocks = (H + kScanRows - 1) / kScanRows;
  std::vector<std::vector<std::uint32_t>> found(static_cast<std::size_t>(scanBlocks));
  const std::vector<std::uint8_t> emptyRow(static_cast<std::size_t>(W), 0);
  forRowBlocks(H, threads, [&](int r0, int r1) {
    std::vector<std::uint32_t>& list = found[static_cast<std::size_t>(r0 / kScanRows)];
    std::vector<std::uint8_t> mark(static_cast<std::size_t>(W) + 8, 0);  // + 8: whole words
    for (int r = r0; r < r1; ++r) {
      const std::uint8_t* self = filled.data() + static_cast<std::size_t>(r) * W;
      const std::uint8_t* up = r > 0 ? self - W : emptyRow.data();
      const std::uint8_t* down = r + 1 < H ? self + W : emptyRow.data();
      auto ringMark = [&](int x, std::uint8_t left, std::uint8_t right) {
        return static_cast<std::uint8_t>((left | right | up[x] | down[x]) & (self[x] ^ 1));
      };
      mark[0] = ringMark(0, 0, W > 1 ? self[1] : 0);
      for (int x = 1; x < W - 1; ++x) mark[static_cast<std::size_t>(x)] = ringMark(x, self[x - 1], self[x + 1]);
      if (W > 1) mark[static_cast<std::size_t>(W - 1)] = ringMark(W - 1, self[W - 2], 0);
      const std::size_t rowStart = static_cast<std::size_t>(r) * W;
      for (int x = 0; x < W; x += 8) {
        std::uint64_t word = 0;
        std::memcpy(&word, mark.data() + x, sizeof word);
        if (word == 0) continue;
        for (int k = x; k < std::min(W, x + 8); ++k)
          if (mark[static_cast<std::size_t>(k)] != 0) list.push_back(static_cast<std::uint32_t>(rowStart + k));
      }
    }
  });
  std::vector<std::uint32_t> ring;
  for (const std::vector<std::uint32_t>& list : found) ring.insert(ring.end(), list.begin(), list.end());

  std::vector<float> values;
  std::vector<std::uint8_t> queued(filled.size(), 0);
  for (int pass = 0; pass < margin && !ring.empty(); ++pass) {
    // Values of this ring from the state before it (the ring's own texels are not filled yet).
    values.resize(ring.size() * stride);
    bake_detail::runWithThreads(threads, [&] {
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, ring.size(), 1024),
                        [&](const tbb::blocked_range<std::size_t>& range) {
        // The channel count as a constant for the usual 1–4 channels, so acc lives in registers.
        auto run = [&]<int kC>(std::integral_constant<int, kC>) {
          const std::size_t channels = kC > 0 ? static_cast<std::size_t>(kC) : stride;
          std::array<double, 4> fixedAcc{};
          std::vector<double> dynamicAcc(kC > 0 ? 0 : stride);
          double* acc = kC > 0 ? fixedAcc.data() : dynamicAcc.data();
          for (std::size_t k = range.begin(); k != range.end(); ++k) {
            const int x = static_cast<int>(ring[k] % static_cast<std::uint32_t>(W));
            const int r = static_cast<int>(ring[k] / static_cast<std::uint32_t>(W));
            for (std::size_t c = 0; c < channels; ++c) acc[c] = 0.0;
            double weightSum = 0;
            for (int dr = -1; dr <= 1; ++dr) {
              for (int dx = -1; dx <= 1; ++dx) {
                if ((dx == 0 && dr == 0) || !isFilled(x + dx, r + dr)) continue;
                const double w = (dx == 0 || dr == 0) ? kEdgeNeighbourWeight : kDiagonalNeighbourWeight;
                const float* p = image.pixels[static_cast<std::size_t>(r + dr)] + static_cast<std::size_t>(x + dx) * stride;
                for (std::size_t c = 0; c < channels; ++c) acc[c] += w * p[c];
                weightSum += w;
              }
            }
            for (std::size_t c = 0; c < channels; ++c)
              values[k * stride + c] = static_cast<float>(acc[c] / weightSum);
          }
        };
        switch (C) {
          case 1: run(std::integral_constant<int, 1>{}); break;
          case 2: run(std::integral_constant<int, 2>{}); break;
          case 3: run(std::integral_constant<int, 3>{}); break;
          case 4: run(std::integral_constant<int, 4>{}); break;
          default: run(std::integral_constant<int, 0>{}); break;
        }
      });
    });
    for (std::size_t k = 0; k < ring.size(); ++k) {
      const std::size_t x = ring[k] % static_cast<std::uint32_t>(W), r = ring[k] / static_cast<std::uint32_t>(W);
      std::copy_n(values.begin() + static_cast<std::ptrdiff_t>(k * stride), stride, image.pixels[r] + x * stride);
      filled[ring[k]] = 1;
    }
    if (pass + 1 == margin) break;
    // Next ring: unfilled 4-neighbours of this ring (each queued once).
    std::vector<std::uint32_t> next;
    for (const std::uint32_t index : ring) {
      const int x = static_cast<int>(index % static_cast<std::uint32_t>(W));
      const int r = static_cast<int>(index / static_cast<std::uint32_t>(W));
      const int nx[4] = {x - 1, x + 1, x, x};
      const int nr[4] = {r, r, r - 1, r + 1};
      for (int k = 0; k < 4; ++k) {
        if (nx[k] < 0 || nx[k] >= W || nr[k] < 0 || nr[k] >= H) continue;
        const std::uint32_t n = static_cast<std::uint32_t>(static_cast<std::size_t>(nr[k]) * W + nx[k]);
        if (filled[n] || queued[n]) continue;
        queued[n] = 1;
        next.push_back(n);
      }
    }
    ring = std::move(next);
  }
}

}  // namespace

void extendMargin(FloatImage& image, int margin, int threads) {
  if (margin <= 0 || !imageIsValid(image)) return;
  const MutableImageRows rows = MutableImageRows::of(image);
  extendMarginIn(paddedRows(rows, 0, image.height), margin, threads);
}

namespace {

/// Rows a strip [rowBegin, rowEnd) of an image's padding depends on: [rowBegin − margin, rowEnd +
/// margin) clipped to the image (whose edges the window then shares, so the padding there is
/// the same too); held when the view can read all of them.
struct StripWindow {
  int rowBegin = 0, rowEnd = 0;  ///< the strip, clamped to the image
  int begin = 0, end = 0;        ///< the rows it depends on
  bool held = false;
};

template <class T>
StripWindow stripWindow(const BasicImageRows<T>& rows, int margin, int rowBegin, int rowEnd) {
  const int H = std::max(rows.height, 0);
  StripWindow w;
  w.rowBegin = std::clamp(rowBegin, 0, H);
  w.rowEnd = std::clamp(rowEnd, w.rowBegin, H);
  margin = std::max(margin, 0);
  w.begin = std::max(0, w.rowBegin - margin);
  w.end = std::min(H, w.rowEnd + margin);
  w.held = rows.width > 0 && rows.channels > 0 && w.begin >= rows.begin && w.end <= rows.end;
  return w;
}

}  // namespace

void extendMarginRowsInPlace(const MutableImageRows& rows, int margin, int rowBegin, int rowEnd,
                             int threads) {
  const StripWindow w = stripWindow(rows, margin, rowBegin, rowEnd);
  if (margin <= 0 || w.rowBegin == w.rowEnd || !w.held) return;
  extendMarginIn(paddedRows(rows, w.begin, w.end), margin, threads);
}

int extendMarginRows(const ImageRows& rows, int margin, int rowBegin, int rowEnd,
                     FloatImage& window, int threads) {
  const StripWindow w = stripWindow(rows, margin, rowBegin, rowEnd);
  const int windowBegin = w.begin, windowEnd = w.end;
  window.width = rows.width;
  window.height = windowEnd - windowBegin;
  window.channels = rows.channels;
  if (!w.held || window.height == 0) {
    window.height = 0;
    window.pixels.clear();
    window.coverage.clear();
    return w.rowBegin - windowBegin;
  }
  const std::size_t rowValues = rows.rowValues();
  const std::size_t rowTexels = static_cast<std::size_t>(rows.width);
  window.pixels.resize(static_cast<std::size_t>(window.height) * rowValues);
  window.coverage.resize(static_cast<std::size_t>(window.height) * rowTexels);
  for (int r = windowBegin; r < windowEnd;) {  // runs of rows contiguous in the ring
    const int run = std::min(rows.contiguousRows(r), windowEnd - r);
    const std::size_t at = static_cast<std::size_t>(r - windowBegin);
    std::copy_n(rows.pixelRow(r), static_cast<std::size_t>(run) * rowValues,
                window.pixels.begin() + static_cast<std::ptrdiff_t>(at * rowValues));
    std::copy_n(rows.coverageRow(r), static_cast<std::size_t>(run) * rowTexels,
                window.coverage.begin() + static_cast<std::ptrdiff_t>(at * rowTexels));
    r += run;
  }
  extendMargin(window, margin, threads);
  return w.rowBegin - windowBegin;
}

int extendMarginRows(const FloatImage& image, int margin, int rowBegin, int rowEnd,
                     FloatImage& window, int threads) {
  ImageRows rows = ImageRows::of(image);
  if (!imageIsValid(image)) rows.end = 0;  // nothing to read: an empty window
  return extendMarginRows(rows, margin, rowBegin, rowEnd, window, threads);
}

namespace {

/// One coarse level of the push-pull pyramid (level 0 is the image itself, with weight 1 where
/// coverage > 0 and 0 elsewhere).
struct Level {
  int width = 0, height = 0;
  std::vector<float> value;   ///< width·height·C, the weighted mean of the sources below
  std::vector<float> weight;  ///< width·height, min(1, Σ weights of the 2×2 texels below)
};

/// Push: @p coarse = 2×2 weighted means of the fine level (@p fineValue, weights @p fineWeight(i)).
template <class WeightFn>
void push(const float* fineValue, const WeightFn& fineWeight, int fineWidth, int fineHeight,
          std::size_t stride, int threads, Level& coarse) {
  coarse.width = (fineWidth + 1) / 2;
  coarse.height = (fineHeight + 1) / 2;
  coarse.value.assign(static_cast<std::size_t>(coarse.width) * coarse.height * stride, 0.0f);
  coarse.weight.assign(static_cast<std::size_t>(coarse.width) * coarse.height, 0.0f);
  forRowBlocks(coarse.height, threads, [&](int r0, int r1) {
    std::vector<double> acc(stride);
    for (int r = r0; r < r1; ++r) {
      for (int x = 0; x < coarse.width; ++x) {
        std::fill(acc.begin(), acc.end(), 0.0);
        double weightSum = 0;
        for (int fr = 2 * r; fr < std::min(2 * r + 2, fineHeight); ++fr) {
          for (int fx = 2 * x; fx < std::min(2 * x + 2, fineWidth); ++fx) {
            const std::size_t f = static_cast<std::size_t>(fr) * fineWidth + fx;
            const double w = fineWeight(f);
            if (w == 0) continue;
            for (std::size_t c = 0; c < stride; ++c) acc[c] += w * fineValue[f * stride + c];
            weightSum += w;
          }
        }
        const std::size_t o = static_cast<std::size_t>(r) * coarse.width + x;
        if (weightSum > 0) {
          for (std::size_t c = 0; c < stride; ++c)
            coarse.value[o * stride + c] = static_cast<float>(acc[c] / weightSum);
        }
        coarse.weight[o] = static_cast<float>(std::min(1.0, weightSum));
      }
    }
  });
}

/// Pull: every fine texel with weight w < 1 becomes w·own + (1 − w)·(bilinear interpolation of the
/// complete @p coarse level); @p value is the fine level's values, updated in place.
template <class WeightFn>
void pull(float* value, const WeightFn& weight, int width, int height, std::size_t stride,
          const Level& coarse, int threads) {
  forRowBlocks(height, threads, [&](int r0, int r1) {
    for (int r = r0; r < r1; ++r) {
      // Fine texel centre r + 0.5 sits at coarse coordinate (r + 0.5)/2 − 0.5.
      const double cy = 0.5 * r - 0.25;
      const int y0 = static_cast<int>(std::floor(cy));
      const double fy = cy - y0;
      const int ya = std::clamp(y0, 0, coarse.height - 1), yb = std::clamp(y0 + 1, 0, coarse.height - 1);
      for (int x = 0; x < width; ++x) {
        const std::size_t f = static_cast<std::size_t>(r) * width + x;
        const double w = weight(f);
        if (w >= 1) continue;  // a source (level 0) or fully supported: unchanged
        const double cx = 0.5 * x - 0.25;
        const int x0 = static_cast<int>(std::floor(cx));
        const double fx = cx - x0;
        const int xa = std::clamp(x0, 0, coarse.width - 1), xb = std::clamp(x0 + 1, 0, coarse.width - 1);
        const std::size_t i00 = (static_cast<std::size_t>(ya) * coarse.width + xa) * stride;
        const std::size_t i01 = (static_cast<std::size_t>(ya) * coarse.width + xb) * stride;
        const std::size_t i10 = (static_cast<std::size_t>(yb) * coarse.width + xa) * stride;
        const std::size_t i11 = (static_cast<std::size_t>(yb) * coarse.width + xb) * stride;
        for (std::size_t c = 0; c < stride; ++c) {
          const double top = (1 - fx) * coarse.value[i00 + c] + fx * coarse.value[i01 + c];
          const double bottom = (1 - fx) * coarse.value[i10 + c] + fx * coarse.value[i11 + c];
          const double interpolated = (1 - fy) * top + fy * bottom;
          const double own = w > 0 ? static_cast<double>(value[f * stride + c]) : 0.0;
          value[f * stride + c] = static_cast<float>(w * own + (1 - w) * interpolated);
        }
      }
    }
  });
}

}  // namespace

void pushPullFill(FloatImage& image, int threads) {
  if (!imageIsValid(image)) return;
  const std::size_t stride = static_cast<std::size_t>(image.channels);
  bool anySource = false, anyHole = false;
  for (const float c : image.coverage) {
    anySource = anySource || c > 0;
    anyHole = anyHole || !(c > 0);
  }
  if (!anySource || !anyHole) return;

  const std::vector<float>& coverage = image.coverage;
  auto sourceWeight = [&](std::size_t i) { return coverage[i] > 0 ? 1.0 : 0.0; };
  // Push: 2×2 weighted means down to 1×1 (whose weight is > 0: there is a source).
  std::vector<Level> levels(1);
  push(image.pixels.data(), sourceWeight, image.width, image.height, stride, threads, levels[0]);
  while (levels.back().width > 1 || levels.back().height > 1) {
    Level coarse;
    const Level& fine = levels.back();
    push(fine.value.data(), [&](std::size_t i) { return static_cast<double>(fine.weight[i]); },
         fine.width, fine.height, stride, threads, coarse);
    levels.push_back(std::move(coarse));
  }
  // Pull from the coarsest level up to the image.
  for (std::size_t l = levels.size() - 1; l-- > 0;) {
    Level& fine = levels[l];
    pull(fine.value.data(), [&](std::size_t i) { return static_cast<double>(fine.weight[i]); },
         fine.width, fine.height, stride, levels[l + 1], threads);
  }
  pull(image.pixels.data(), sourceWeight, image.width, image.height, stride, levels[0], threads);
}

void padImage(FloatImage& image, PaddingMode mode, int margin, const Mesh& mesh, int uvSet,
              int udimTile, int samples, int threads) {
  switch (mode) {
    case PaddingMode::kPushPull:
      pushPullFill(image, threads);
      break;
    case PaddingMode::kAdjacentFaces:
      adjacentFacesMargin(image, mesh, uvSet, udimTile, samples, margin, threads);
      break;
    case PaddingMode::kExtend:
      extendMargin(image, margin, threads);
      break;
  }
}

}  // namespace sgbake
