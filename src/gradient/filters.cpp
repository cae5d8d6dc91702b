// Image textures: bilinear, Catmull-Rom bicubic and first-order Hermite filtering with the exact
// derivatives of the filtered function (see filters.hpp for the definitions).
//
// Everything is computed in double from float texels. Positions are reduced per axis to
// (cell, fraction, du/ds); the kernels then evaluate the polynomial piece of that cell. The
// kernels are templates over the channel count so that height maps (1 channel) and normal maps
// (3 interleaved channels) share one implementation.

#include "sgbake/gradient/filters.hpp"

#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <string>

#include "gradient/parallel_rows.hpp"

namespace sgbake {
namespace {

using gradient_detail::forEachRow;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// ---------------------------------------------------------------------------------------------
// Positions and indices

// A coordinate reduced to one axis of the texel lattice.
struct AxisPosition {
  int cell;      // lower lattice point of the cell (texel index before wrapping)
  double frac;   // position inside the cell, [0, 1]
  double scale;  // du/ds: the axis size n, or 0 where kClamp holds the position at the border
};

// s (texture units) → cell and fraction along an axis of n texels (u = s·n − 0.5).
// @note Precondition: s is finite.
[[gnu::always_inline]] inline AxisPosition locate(double s, int n, Wrap wrap) {
  const double size = n;
  if (wrap == Wrap::kRepeat) {
    // s − floor(s) is exact; it may round up to 1.0 for tiny negative s, which is the same
    // point as 0 on the torus. u ∈ [−0.5, n − 0.5], so cell ∈ [−1, n − 1].
    const double u = (s - std::floor(s)) * size - 0.5;
    const double cell = std::floor(u);
    return {static_cast<int>(cell), u - cell, size};
  }
  // kClamp: hold u at the border texel centres; the texture is constant beyond them.
  const double last = size - 1;
  double u = s * size - 0.5;
  double scale = size;
  if (u < 0) {
    u = 0;
    scale = 0;
  } else if (u > last) {
    u = last;
    scale = 0;
  }
  double cell = std::floor(u);
  // At u == n − 1 stay in the last cell (fraction 1) so the derivative is the inside one.
  if (n >= 2 && cell > last - 1) cell = last - 1;
  return {static_cast<int>(cell), u - cell, scale};
}

// Texel index i on an axis of n texels, periodic.
inline int wrapRepeat(int i, int n) {
  if (i >= 0 && i < n) return i;
  const int r = i % n;
  return r < 0 ? r + n : r;
}

// Texel index i on an axis of n texels, clamped to the border.
inline int clampIndex(int i, int n) { return i < 0 ? 0 : (i >= n ? n - 1 : i); }

inline int resolveIndex(int i, int n, Wrap wrap) {
  return wrap == Wrap::kRepeat ? wrapRepeat(i, n) : clampIndex(i, n);
}

inline std::size_t texelOffset(int x, int y, int width) {
  return static_cast<std::size_t>(y) * static_cast<std::size_t>(width) +
         static_cast<std::size_t>(x);
}

// ---------------------------------------------------------------------------------------------
// Kernels. Each returns the value and the derivatives w.r.t. the fractions (texel units).

template <int N>
struct Filtered {
  std::array<double, N> value{};
  std::array<double, N> du{};
  std::array<double, N> dv{};
};

// Bilinear: taps (x0, x1) × (y0, y1). Always inlined, like locate(): as calls returning their
// result through memory they cost a 4096² tangent-normal bake ~8 % (BM_TangentNormalBands:
// 378–384 → 350 ms on one thread, 194–201 → 179–180 ms on two; the same bits).
template <int N>
[[gnu::always_inline]] inline Filtered<N> bilinear(const float* texels, int width, int height,
                                                   Wrap wrap, int cellX, double fx, int cellY,
                                                   double fy) {
  const int x0 = resolveIndex(cellX, width, wrap);
  const int x1 = resolveIndex(cellX + 1, width, wrap);
  const int y0 = resolveIndex(cellY, height, wrap);
  const int y1 = resolveIndex(cellY + 1, height, wrap);
  const float* p00 = texels + texelOffset(x0, y0, width) * N;
  const float* p10 = texels + texelOffset(x1, y0, width) * N;
  const float* p01 = texels + texelOffset(x0, y1, width) * N;
  const float* p11 = texels + texelOffset(x1, y1, width) * N;
  Filtered<N> out;
  for (int c = 0; c < N; ++c) {
    const double f00 = p00[c], f10 = p10[c], f01 = p01[c], f11 = p11[c];
    const double slopeBottom = f10 - f00;
    const double slopeTop = f11 - f01;
    const double bottom = f00 + fx * slopeBottom;
    const double top = f01 + fx * slopeTop;
    out.value[c] = bottom + fy * (top - bottom);
    out.du[c] = slopeBottom + fy * (slopeTop - slopeBottom);
    out.dv[c] = top - bottom;
  }
  return out;
}

// Catmull-Rom weights of the taps at offsets −1, 0, 1, 2 from the cell's lower corner, and their
// derivatives, at fraction x ∈ [0, 1]. Keys' cubic convolution kernel with a = −1/2:
//   w₋₁ = (−x³ + 2x² − x)/2,  w₀ = (3x³ − 5x² + 2)/2,  w₁ = (−3x³ + 4x² + x)/2,  w₂ = (x³ − x²)/2.
// At x = 0 the weights are exactly (0, 1, 0, 0): the filter interpolates the texels.
struct CubicWeights {
  std::array<double, 4> w;
  std::array<double, 4> dw;
};

inline CubicWeights catmullRom(double x) {
  const double x2 = x * x;
  const double x3 = x2 * x;
  CubicWeights k;
  k.w = {0.5 * (-x3 + 2 * x2 - x), 0.5 * (3 * x3 - 5 * x2 + 2), 0.5 * (-3 * x3 + 4 * x2 + x),
         0.5 * (x3 - x2)};
  k.dw = {0.5 * (-3 * x2 + 4 * x - 1), 0.5 * (9 * x2 - 10 * x), 0.5 * (-9 * x2 + 8 * x + 1),
          0.5 * (3 * x2 - 2 * x)};
  return k;
}

// Bicubic (Catmull-Rom): taps cellX−1 .. cellX+2 × cellY−1 .. cellY+2.
template <int N>
Filtered<N> bicubic(const float* texels, int width, int height, Wrap wrap, int cellX, double fx,
                    int cellY, double fy) {
  const CubicWeights kx = catmullRom(fx);
  const CubicWeights ky = catmullRom(fy);
  std::array<std::size_t, 4> column{};
  for (int k = 0; k < 4; ++k) {
    column[k] = static_cast<std::size_t>(resolveIndex(cellX - 1 + k, width, wrap)) * N;
  }
  Filtered<N> out;
  for (int j = 0; j < 4; ++j) {
    const int y = resolveIndex(cellY - 1 + j, height, wrap);
    const float* row = texels + texelOffset(0, y, width) * N;
    for (int c = 0; c < N; ++c) {
      double rowValue = 0;
      double rowDu = 0;
      for (int k = 0; k < 4; ++k) {
        const double f = row[column[k] + c];
        rowValue += kx.w[k] * f;
        rowDu += kx.dw[k] * f;
      }
      out.value[c] += ky.w[j] * rowValue;
      out.du[c] += ky.w[j] * rowDu;
      out.dv[c] += ky.dw[j] * rowValue;
    }
  }
  return out;
}

// Cubic Hermite basis on [0, 1] (seed 004 §3.2, order 1) and its derivatives:
//   h0 = 1 − 3x² + 2x³ (value at 0), h1 = 3x² − 2x³ (value at 1),
//   g0 = x − 2x² + x³ (slope at 0),  g1 = x³ − x² (slope at 1).
struct HermiteBasis {
  double h0, h1, g0, g1;
  double dh0, dh1, dg0, dg1;
};

inline HermiteBasis hermiteBasis(double x) {
  const double x2 = x * x;
  const double x3 = x2 * x;
  HermiteBasis b;
  b.h1 = 3 * x2 - 2 * x3;
  b.h0 = 1 - b.h1;
  b.g0 = x - 2 * x2 + x3;
  b.g1 = x3 - x2;
  b.dh1 = 6 * x - 6 * x2;
  b.dh0 = -b.dh1;
  b.dg0 = 1 - 4 * x + 3 * x2;
  b.dg1 = 3 * x2 - 2 * x;
  return b;
}

// Bicubic Hermite patch of the cell from its four corner texels (tensor product of the 1D
// basis: 16 coefficients h, h_u, h_v, h_uv at the corners).
Filtered<1> hermite(const ImageScalarTexture::HermiteTexel* texels, int width, int height,
                    Wrap wrap, int cellX, double fx, int cellY, double fy) {
  using Texel = ImageScalarTexture::HermiteTexel;
  const int x0 = resolveIndex(cellX, width, wrap);
  const int x1 = resolveIndex(cellX + 1, width, wrap);
  const int y0 = resolveIndex(cellY, height, wrap);
  const int y1 = resolveIndex(cellY + 1, height, wrap);
  const HermiteBasis bx = hermiteBasis(fx);
  const HermiteBasis by = hermiteBasis(fy);

  // Along u on the cell's bottom (b = 0) and top (b = 1) edges: the height (a) and its v-slope
  // (s), with their u-derivatives.
  auto edge = [&](const Texel& left, const Texel& right, double& a, double& da, double& s,
                  double& ds) {
    a = bx.h0 * left.h + bx.h1 * right.h + bx.g0 * left.hu + bx.g1 * right.hu;
    da = bx.dh0 * left.h + bx.dh1 * right.h + bx.dg0 * left.hu + bx.dg1 * right.hu;
    s = bx.h0 * left.hv + bx.h1 * right.hv + bx.g0 * left.huv + bx.g1 * right.huv;
    ds = bx.dh0 * left.hv + bx.dh1 * right.hv + bx.dg0 * left.huv + bx.dg1 * right.huv;
  };
  double a0, da0, s0, ds0, a1, da1, s1, ds1;
  edge(texels[texelOffset(x0, y0, width)], texels[texelOffset(x1, y0, width)], a0, da0, s0, ds0);
  edge(texels[texelOffset(x0, y1, width)], texels[texelOffset(x1, y1, width)], a1, da1, s1, ds1);

  Filtered<1> out;
  out.value[0] = by.h0 * a0 + by.h1 * a1 + by.g0 * s0 + by.g1 * s1;
  out.du[0] = by.h0 * da0 + by.h1 * da1 + by.g0 * ds0 + by.g1 * ds1;
  out.dv[0] = by.dh0 * a0 + by.dh1 * a1 + by.dg0 * s0 + by.dg1 * s1;
  return out;
}

// ---------------------------------------------------------------------------------------------
// Hermite derivative data

// A height plane with wrapped reads.
struct Plane {
  const std::vector<float>& h;
  int width, height;
  Wrap wrap;
  double at(int x, int y) const {
    return h[texelOffset(resolveIndex(x, width, wrap), resolveIndex(y, height, wrap), width)];
  }
};

// Central-difference weights at offsets −2 .. 2 (texel units).
constexpr std::array<double, 5> kCentral2Weights = {0.0, -0.5, 0.0, 0.5, 0.0};
constexpr std::array<double, 5> kCentral4Weights = {1.0 / 12, -8.0 / 12, 0.0, 8.0 / 12, -1.0 / 12};

std::vector<ImageScalarTexture::HermiteTexel> estimateHermite(const Plane& plane,
                                                              DerivativeStencil stencil,
                                                              HermiteTwist twist) {
  const std::array<double, 5>& d =
      stencil == DerivativeStencil::kCentral2 ? kCentral2Weights : kCentral4Weights;
  std::vector<ImageScalarTexture::HermiteTexel> out(plane.h.size());
  forEachRow(plane.height, [&](int y) {
    for (int x = 0; x < plane.width; ++x) {
      double hu = 0, hv = 0, huv = 0;
      for (int k = 0; k < 5; ++k) {
        if (d[k] == 0) continue;
        hu += d[k] * plane.at(x + k - 2, y);
        hv += d[k] * plane.at(x, y + k - 2);
        if (twist == HermiteTwist::kEstimate) {
          double column = 0;  // D_u h on row y + k − 2
          for (int i = 0; i < 5; ++i) {
            if (d[i] != 0) column += d[i] * plane.at(x + i - 2, y + k - 2);
          }
          huv += d[k] * column;
        }
      }
      out[texelOffset(x, y, plane.width)] = {static_cast<float>(plane.at(x, y)),
                                             static_cast<float>(hu), static_cast<float>(hv),
                                             static_cast<float>(huv)};
    }
  });
  return out;
}

std::vector<ImageScalarTexture::HermiteTexel> suppliedHermite(const Plane& plane,
                                                              const Image& derivatives,
                                                              HermiteTwist twist) {
  // Texture units → texel units: ∂/∂u = ∂/∂s / W, ∂/∂v = ∂/∂t / H.
  const double perU = 1.0 / plane.width;
  const double perV = 1.0 / plane.height;
  const bool hasTwist = derivatives.channels() >= 3;
  auto hu = [&](int x, int y) {
    return perU * derivatives.at(resolveIndex(x, plane.width, plane.wrap),
                                 resolveIndex(y, plane.height, plane.wrap), 0);
  };
  auto hv = [&](int x, int y) {
    return perV * derivatives.at(resolveIndex(x, plane.width, plane.wrap),
                                 resolveIndex(y, plane.height, plane.wrap), 1);
  };
  std::vector<ImageScalarTexture::HermiteTexel> out(plane.h.size());
  forEachRow(plane.height, [&](int y) {
    for (int x = 0; x < plane.width; ++x) {
      double huv = 0;
      if (hasTwist) {
        huv = perU * perV * derivatives.at(x, y, 2);
      } else if (twist == HermiteTwist::kEstimate) {
        // Adini twist (seed 004 §6.1 in 2D): ∂²/∂u∂v at the centre of the Coons patch over the
        // four cells around the texel, whose edges are the Hermite curves through the texel's
        // row and column.
        huv = 0.5 * (hu(x, y + 1) - hu(x, y - 1)) + 0.5 * (hv(x + 1, y) - hv(x - 1, y)) -
              0.25 * (plane.at(x + 1, y + 1) - plane.at(x + 1, y - 1) - plane.at(x - 1, y + 1) +
                      plane.at(x - 1, y - 1));
      }
      out[texelOffset(x, y, plane.width)] = {static_cast<float>(plane.at(x, y)),
                                             static_cast<float>(hu(x, y)),
                                             static_cast<float>(hv(x, y)), static_cast<float>(huv)};
    }
  });
  return out;
}

// ---------------------------------------------------------------------------------------------
// Validation

std::string channelsText(int n) { return std::to_string(n) + (n == 1 ? " channel" : " channels"); }

// The first non-finite value of channels [first, first + count) of @p image, as an error.
Status checkFinite(const Image& image, int first, int count, const char* what) {
  const std::ptrdiff_t bad = findNonFinite(image, first, count);
  if (bad < 0) return Ok{};
  const auto texel = static_cast<std::size_t>(bad) / static_cast<std::size_t>(image.channels());
  const auto width = static_cast<std::size_t>(image.width());
  return Error::badInput(std::string(what) + ": texel (" + std::to_string(texel % width) + ", " +
                         std::to_string(texel / width) + ") channel " +
                         std::to_string(bad % image.channels()) + " is not a finite number");
}

Status checkScalarSource(const Image& image, const ScalarTextureOptions& options) {
  if (image.empty()) return Error::badInput("height texture: the image is empty");
  if (options.channel < 0 || options.channel >= image.channels()) {
    return Error::badInput("height texture: channel " + std::to_string(options.channel) +
                           " does not exist (the image has " + channelsText(image.channels()) +
                           ")");
  }
  return checkFinite(image, options.channel, 1, "height texture");
}

std::vector<float> extractChannel(const Image& image, int channel) {
  const auto width = static_cast<std::size_t>(image.width());
  std::vector<float> plane(width * static_cast<std::size_t>(image.height()));
  const float* pixels = image.pixels().data();
  const auto stride = static_cast<std::size_t>(image.channels());
  forEachRow(image.height(), [&](int y) {
    const std::size_t row = static_cast<std::size_t>(y) * width;
    for (std::size_t x = row; x < row + width; ++x) {
      plane[x] = pixels[x * stride + static_cast<std::size_t>(channel)];
    }
  });
  return plane;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// ImageScalarTexture

Result<ImageScalarTexture> ImageScalarTexture::create(const Image& image,
                                                      const ScalarTextureOptions& options) {
  if (Status ok = checkScalarSource(image, options); !ok) return ok.error();
  ImageScalarTexture texture;
  texture.width_ = image.width();
  texture.height_ = image.height();
  texture.filter_ = options.filter;
  texture.wrap_ = options.wrap;
  std::vector<float> plane = extractChannel(image, options.channel);
  if (options.filter == Filter::kHermite) {
    const Plane view{plane, texture.width_, texture.height_, texture.wrap_};
    texture.hermite_ = estimateHermite(view, options.stencil, options.twist);
  } else {
    texture.plane_ = std::move(plane);
  }
  return texture;
}

Result<ImageScalarTexture> ImageScalarTexture::createWithDerivatives(
    const Image& image, const Image& derivatives, const ScalarTextureOptions& options) {
  if (Status ok = checkScalarSource(image, options); !ok) return ok.error();
  if (derivatives.width() != image.width() || derivatives.height() != image.height()) {
    return Error::badInput("height texture: the derivative image is " +
                           std::to_string(derivatives.width()) + "x" +
                           std::to_string(derivatives.height()) + " but the height image is " +
                           std::to_string(image.width()) + "x" + std::to_string(image.height()));
  }
  if (derivatives.channels() != 2 && derivatives.channels() != 3) {
    return Error::badInput("height texture: the derivative image has " +
                           channelsText(derivatives.channels()) +
                           "; 2 (dh/ds, dh/dt) or 3 (and d2h/dsdt) are needed");
  }
  if (Status ok = checkFinite(derivatives, 0, derivatives.channels(), "height derivatives"); !ok) {
    return ok.error();
  }
  ImageScalarTexture texture;
  texture.width_ = image.width();
  texture.height_ = image.height();
  texture.filter_ = Filter::kHermite;
  texture.wrap_ = options.wrap;
  const std::vector<float> plane = extractChannel(image, options.channel);
  const Plane view{plane, texture.width_, texture.height_, texture.wrap_};
  texture.hermite_ = suppliedHermite(view, derivatives, options.twist);
  return texture;
}

template <class Body>
void ImageScalarTexture::withKernel(const Body& body) const {
  switch (filter_) {
    case Filter::kBilinear:
      body([this](int cellX, double fx, int cellY, double fy) {
        return bilinear<1>(plane_.data(), width_, height_, wrap_, cellX, fx, cellY, fy);
      });
      break;
    case Filter::kBicubic:
      body([this](int cellX, double fx, int cellY, double fy) {
        return bicubic<1>(plane_.data(), width_, height_, wrap_, cellX, fx, cellY, fy);
      });
      break;
    case Filter::kHermite:
      body([this](int cellX, double fx, int cellY, double fy) {
        return hermite(hermite_.data(), width_, height_, wrap_, cellX, fx, cellY, fy);
      });
      break;
  }
}

ScalarSample ImageScalarTexture::evaluate(int cellX, double fx, double scaleX, int cellY, double fy,
                                          double scaleY) const {
  Filtered<1> f;
  withKernel([&](const auto& kernel) { f = kernel(cellX, fx, cellY, fy); });
  return {f.value[0], {f.du[0] * scaleX, f.dv[0] * scaleY}};
}

ScalarSample ImageScalarTexture::sample(Vec2d st) const {
  ScalarSample out;
  sampleMany({&st, 1}, {&out, 1});
  return out;
}

void ImageScalarTexture::sampleMany(std::span<const Vec2d> st, std::span<ScalarSample> out) const {
  withKernel([&](const auto& kernel) {
    for (std::size_t i = 0; i < st.size() && i < out.size(); ++i) {
      if (!std::isfinite(st[i].x) || !std::isfinite(st[i].y)) {
        out[i] = {kNaN, {kNaN, kNaN}};
        continue;
      }
      const AxisPosition px = locate(st[i].x, width_, wrap_);
      const AxisPosition py = locate(st[i].y, height_, wrap_);
      const Filtered<1> f = kernel(px.cell, px.frac, py.cell, py.frac);
      out[i] = {f.value[0], {f.du[0] * px.scale, f.dv[0] * py.scale}};
    }
  });
}

ScalarSample ImageScalarTexture::sampleCell(int cellX, int cellY, Vec2d fraction) const {
  return evaluate(cellX, fraction.x, width_, cellY, fraction.y, height_);
}

// ---------------------------------------------------------------------------------------------
// ImageVectorTexture

namespace {

/// What makes @p image unusable as a vector texture with @p options (create's errors).
Status checkVectorSource(const Image& image, const VectorTextureOptions& options) {
  if (image.empty()) return Error::badInput("vector texture: the image is empty");
  if (options.firstChannel < 0 || options.firstChannel + 3 > image.channels()) {
    return Error::badInput("vector texture: channels " + std::to_string(options.firstChannel) +
                           " to " + std::to_string(options.firstChannel + 2) +
                           " do not exist (the image has " + channelsText(image.channels()) + ")");
  }
  if (options.filter == Filter::kHermite) {
    return Error::badInput("vector texture: the Hermite filter is offered for height maps only");
  }
  return checkFinite(image, options.firstChannel, 3, "vector texture");
}

}  // namespace

Result<ImageVectorTexture> ImageVectorTexture::create(const Image& image,
                                                      const VectorTextureOptions& options) {
  if (Status ok = checkVectorSource(image, options); !ok) return ok.error();
  ImageVectorTexture texture;
  texture.width_ = image.width();
  texture.height_ = image.height();
  texture.filter_ = options.filter;
  texture.wrap_ = options.wrap;
  const std::size_t count =
      static_cast<std::size_t>(image.width()) * static_cast<std::size_t>(image.height());
  texture.texels_.resize(count * 3);
  const std::span<const float> pixels = image.pixels();
  const auto stride = static_cast<std::size_t>(image.channels());
  const auto first = static_cast<std::size_t>(options.firstChannel);
  for (std::size_t i = 0; i < count; ++i) {
    for (std::size_t c = 0; c < 3; ++c) texture.texels_[i * 3 + c] = pixels[i * stride + first + c];
  }
  return texture;
}

Result<ImageVectorTexture> ImageVectorTexture::create(Image&& image,
                                                      const VectorTextureOptions& options) {
  if (image.channels() != 3 || options.firstChannel != 0) {
    return create(static_cast<const Image&>(image), options);
  }
  if (Status ok = checkVectorSource(image, options); !ok) return ok.error();
  ImageVectorTexture texture;  // its texels are the image's own values
  texture.filter_ = options.filter;
  texture.wrap_ = options.wrap;
  texture.width_ = image.width();
  texture.height_ = image.height();
  texture.texels_ = image.takePixels();
  return texture;
}

VectorSample ImageVectorTexture::evaluate(int cellX, double fx, double scaleX, int cellY, double fy,
                                          double scaleY) const {
  const Filtered<3> f =
      filter_ == Filter::kBicubic
          ? bicubic<3>(texels_.data(), width_, height_, wrap_, cellX, fx, cellY, fy)
          : bilinear<3>(texels_.data(), width_, height_, wrap_, cellX, fx, cellY, fy);
  VectorSample out;
  for (std::size_t c = 0; c < 3; ++c) {
    out.value[c] = f.value[c];
    out.dds[c] = f.du[c] * scaleX;
    out.ddt[c] = f.dv[c] * scaleY;
  }
  return out;
}

VectorSample ImageVectorTexture::sampleWithDerivatives(Vec2d st) const {
  if (!std::isfinite(st.x) || !std::isfinite(st.y)) {
    return {{kNaN, kNaN, kNaN}, {kNaN, kNaN, kNaN}, {kNaN, kNaN, kNaN}};
  }
  const AxisPosition px = locate(st.x, width_, wrap_);
  const AxisPosition py = locate(st.y, height_, wrap_);
  return evaluate(px.cell, px.frac, px.scale, py.cell, py.frac, py.scale);
}

Vec3d ImageVectorTexture::sample(Vec2d st) const { return sampleWithDerivatives(st).value; }

VectorSample ImageVectorTexture::sampleCell(int cellX, int cellY, Vec2d fraction) const {
  return evaluate(cellX, fraction.x, width_, cellY, fraction.y, height_);
}

}  // namespace sgbake
