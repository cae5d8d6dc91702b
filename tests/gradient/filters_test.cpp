// Image filters against analytic references: polynomial reproduction (bilinear: affine,
// Catmull-Rom: biquadratic, Hermite: bicubic), C1 continuity across cell edges, convergence
// orders on a smooth periodic field, derivatives versus finite differences of the filter's own
// value, seamless repeat wrapping, clamping, and the equivalence of Hermite with
// central-difference derivatives and Catmull-Rom.
//
// Polynomial fields are written in texel units (u = s·W − 0.5, v = t·H − 0.5) with integer
// coefficients, so that every texel value and supplied derivative is an exactly representable
// float and the only error left is the filter's own arithmetic (double).

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "sgbake/core/math.hpp"
#include "sgbake/gradient/filters.hpp"
#include "sgbake/gradient/image.hpp"

namespace sgbake {
namespace {

// Relative tolerance of exact-reproduction checks: double round-off of a few dozen operations on
// values up to ~1e7.
constexpr double kExactTolerance = 1e-9;
// Relative tolerance where per-texel derivatives went through float storage (estimated ones).
constexpr double kFloatStorageTolerance = 2e-6;

// A polynomial p(u, v) = Σ c[a][b] u^a v^b in texel units, degree ≤ 3 in each variable.
struct Poly {
  std::array<std::array<double, 4>, 4> c{};

  // Value and derivatives w.r.t. u, v and the mixed one, at (u, v).
  double value(double u, double v) const { return eval(u, v, 0, 0); }
  double du(double u, double v) const { return eval(u, v, 1, 0); }
  double dv(double u, double v) const { return eval(u, v, 0, 1); }
  double duv(double u, double v) const { return eval(u, v, 1, 1); }

 private:
  // ∂^(i+j) p / ∂u^i ∂v^j for i, j ∈ {0, 1}.
  double eval(double u, double v, int i, int j) const {
    double sum = 0;
    for (int a = 0; a < 4; ++a) {
      for (int b = 0; b < 4; ++b) {
        if (a < i || b < j) continue;
        const double fu = (i == 1 ? a : 1) * std::pow(u, a - i);
        const double fv = (j == 1 ? b : 1) * std::pow(v, b - j);
        sum += c[a][b] * fu * fv;
      }
    }
    return sum;
  }
};

// Coefficients with every term up to the given degrees (small integers, mixed signs).
Poly makePoly(int maxDegreeU, int maxDegreeV, bool withU3V3 = true) {
  Poly p;
  const std::array<double, 16> coefficients = {3, -2, 1,  2,  -1, 2,  -3, 1,
                                               2, 1,  -2, -1, 1,  -1, 2,  1};
  for (int a = 0; a <= maxDegreeU; ++a) {
    for (int b = 0; b <= maxDegreeV; ++b) p.c[a][b] = coefficients[a * 4 + b];
  }
  if (!withU3V3) p.c[3][3] = 0;
  return p;
}

// An image whose texel (x, y) holds f(x, y) (texel units) in every channel c as f + c.
Image imageOf(int width, int height, int channels, const std::function<double(int, int)>& f) {
  Image image(width, height, channels);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      for (int c = 0; c < channels; ++c) image.at(x, y, c) = static_cast<float>(f(x, y) + c);
    }
  }
  return image;
}

Image polyImage(const Poly& p, int width, int height) {
  return imageOf(width, height, 1, [&](int x, int y) { return p.value(x, y); });
}

// Supplied derivatives of p in texture units: [∂p/∂s, ∂p/∂t (, ∂²p/∂s∂t)].
Image polyDerivatives(const Poly& p, int width, int height, int channels) {
  Image d(width, height, channels);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      d.at(x, y, 0) = static_cast<float>(width * p.du(x, y));
      d.at(x, y, 1) = static_cast<float>(height * p.dv(x, y));
      if (channels > 2) d.at(x, y, 2) = static_cast<float>(width * height * p.duv(x, y));
    }
  }
  return d;
}

// Uniformly random texel data in [0, 1] (a periodic "worst case" with no smoothness at all).
Image randomImage(int width, int height, int channels, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
  Image image(width, height, channels);
  for (float& value : image.pixels()) value = uniform(rng);
  return image;
}

// Deterministic points (s, t) with u ∈ [u0, u1], v ∈ [v0, v1] (texel units).
std::vector<Vec2d> pointsInTexelBox(int width, int height, double u0, double u1, double v0,
                                    double v1, int count, unsigned seed = 7) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::vector<Vec2d> points;
  for (int i = 0; i < count; ++i) {
    const double u = u0 + (u1 - u0) * uniform(rng);
    const double v = v0 + (v1 - v0) * uniform(rng);
    points.push_back({(u + 0.5) / width, (v + 0.5) / height});
  }
  return points;
}

ImageScalarTexture makeTexture(const Image& image, Filter filter, Wrap wrap = Wrap::kRepeat,
                               DerivativeStencil stencil = DerivativeStencil::kCentral4) {
  ScalarTextureOptions options;
  options.filter = filter;
  options.wrap = wrap;
  options.stencil = stencil;
  Result<ImageScalarTexture> texture = ImageScalarTexture::create(image, options);
  EXPECT_TRUE(texture.ok()) << (texture.ok() ? "" : texture.error().message);
  return std::move(texture).value();
}

ImageScalarTexture makeHermite(const Image& image, const Image& derivatives,
                               HermiteTwist twist = HermiteTwist::kEstimate,
                               Wrap wrap = Wrap::kRepeat) {
  ScalarTextureOptions options;
  options.wrap = wrap;
  options.twist = twist;
  Result<ImageScalarTexture> texture =
      ImageScalarTexture::createWithDerivatives(image, derivatives, options);
  EXPECT_TRUE(texture.ok()) << (texture.ok() ? "" : texture.error().message);
  return std::move(texture).value();
}

// Checks a texture against p on points whose texel-unit box keeps every tap inside the image.
void expectReproduces(const ImageScalarTexture& texture, const Poly& p, double u0, double u1,
                      double v0, double v1, double tolerance, const std::string& what) {
  const int w = texture.width();
  const int h = texture.height();
  const std::vector<Vec2d> points = pointsInTexelBox(w, h, u0, u1, v0, v1, 400);
  // Scales: the largest reference magnitudes over the points.
  double valueScale = 0, gradientScale = 0;
  for (const Vec2d st : points) {
    const double u = st.x * w - 0.5, v = st.y * h - 0.5;
    valueScale = std::max(valueScale, std::abs(p.value(u, v)));
    gradientScale = std::max({gradientScale, std::abs(w * p.du(u, v)), std::abs(h * p.dv(u, v))});
  }
  for (const Vec2d st : points) {
    const double u = st.x * w - 0.5, v = st.y * h - 0.5;
    const ScalarSample sample = texture.sample(st);
    EXPECT_NEAR(sample.value, p.value(u, v), tolerance * valueScale)
        << what << " at u=" << u << " v=" << v;
    EXPECT_NEAR(sample.gradient.x, w * p.du(u, v), tolerance * gradientScale)
        << what << " d/ds at u=" << u << " v=" << v;
    EXPECT_NEAR(sample.gradient.y, h * p.dv(u, v), tolerance * gradientScale)
        << what << " d/dt at u=" << u << " v=" << v;
  }
}

// Largest |error| of value and gradient against p over a texel box (for "does not reproduce").
double maxError(const ImageScalarTexture& texture, const Poly& p, double u0, double u1, double v0,
                double v1) {
  const int w = texture.width();
  const int h = texture.height();
  double worst = 0;
  for (const Vec2d st : pointsInTexelBox(w, h, u0, u1, v0, v1, 400)) {
    const double u = st.x * w - 0.5, v = st.y * h - 0.5;
    const ScalarSample sample = texture.sample(st);
    worst = std::max({worst, std::abs(sample.value - p.value(u, v)),
                      std::abs(sample.gradient.x - w * p.du(u, v)) / w,
                      std::abs(sample.gradient.y - h * p.dv(u, v)) / h});
  }
  return worst;
}

// ---------------------------------------------------------------------------------------------
// Polynomial reproduction

TEST(ImageFilters, BilinearReproducesAffineFields) {
  const Poly p = makePoly(1, 1);
  Poly affine = p;
  affine.c[1][1] = 0;  // bilinear reproduces u·v too, but "affine" is the contract to test
  const int w = 16, h = 8;
  const Image image = polyImage(affine, w, h);
  for (Wrap wrap : {Wrap::kRepeat, Wrap::kClamp}) {
    const ImageScalarTexture texture = makeTexture(image, Filter::kBilinear, wrap);
    // Away from the seam: the cell between texel W−1 and texel 0 wraps and is not affine.
    expectReproduces(texture, affine, 0, w - 1, 0, h - 1, kExactTolerance, "bilinear affine");
    // Gradient: exactly the constant (∂p/∂s, ∂p/∂t) = (W·c10, H·c01) everywhere inside.
    const ScalarSample sample = texture.sample({0.37, 0.61});
    EXPECT_NEAR(sample.gradient.x, w * affine.c[1][0], kExactTolerance * w);
    EXPECT_NEAR(sample.gradient.y, h * affine.c[0][1], kExactTolerance * h);
  }
}

TEST(ImageFilters, BilinearReturnsTexelsAtTexelCentres) {
  const Image image = randomImage(7, 5, 1, 11);
  const ImageScalarTexture texture = makeTexture(image, Filter::kBilinear);
  for (int y = 0; y < 5; ++y) {
    for (int x = 0; x < 7; ++x) {
      EXPECT_EQ(texture.sample(image.texelCentre(x, y)).value, image.at(x, y));
    }
  }
}

TEST(ImageFilters, CatmullRomReproducesBiquadraticsButNotCubics) {
  // Keys' kernel with a = −1/2 reproduces polynomials of degree ≤ 2 per axis: for the taps
  // f(i) = i² at offsets −1..2 the weights sum to x² exactly, while i³ gives 3x³ − 3x² + x.
  const int w = 12, h = 10;
  const Poly biquadratic = makePoly(2, 2);
  const ImageScalarTexture texture = makeTexture(polyImage(biquadratic, w, h), Filter::kBicubic);
  // Every tap inside the image: cells 1 .. W−3, i.e. u ∈ [1, W−2].
  expectReproduces(texture, biquadratic, 1, w - 2, 1, h - 2, kExactTolerance,
                   "Catmull-Rom biquadratic");

  Poly cubic;
  cubic.c[3][0] = 1;  // u³
  const ImageScalarTexture cubicTexture = makeTexture(polyImage(cubic, w, h), Filter::kBicubic);
  EXPECT_GT(maxError(cubicTexture, cubic, 1, w - 2, 1, h - 2), 0.01);
}

TEST(ImageFilters, HermiteWithExactDerivativesReproducesBicubics) {
  const int w = 8, h = 6;
  const Poly bicubic = makePoly(3, 3);
  const Image image = polyImage(bicubic, w, h);
  const ImageScalarTexture texture = makeHermite(image, polyDerivatives(bicubic, w, h, 3));
  // Hermite reads only the corners of a cell: every cell that does not cross the seam.
  expectReproduces(texture, bicubic, 0, w - 1, 0, h - 1, kExactTolerance, "Hermite bicubic");

  // It interpolates the supplied data: at a texel centre the value and gradient are the texel's.
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      // (t = (y + 0.5)/6 is rounded, so v is y only to ~1e-16.)
      const ScalarSample sample = texture.sample(image.texelCentre(x, y));
      EXPECT_NEAR(sample.value, bicubic.value(x, y), 1e-12 * 1e5);
      EXPECT_NEAR(sample.gradient.x, w * bicubic.du(x, y), 1e-12 * 1e6);
      EXPECT_NEAR(sample.gradient.y, h * bicubic.dv(x, y), 1e-12 * 1e6);
    }
  }
}

TEST(ImageFilters, HermiteAdiniTwistIsExactForBicubicsWithoutTheTopTerm) {
  // Two supplied channels: the twist is the 2D Adini twist (seed 004 §6.1), exact for every
  // term u^a v^b with a, b ≤ 3 except u³v³ (for which it is off by −∂⁶p/∂u³∂v³ / 36).
  const int w = 9, h = 8;
  const Poly p = makePoly(3, 3, /*withU3V3=*/false);
  const ImageScalarTexture texture =
      makeHermite(polyImage(p, w, h), polyDerivatives(p, w, h, 2), HermiteTwist::kEstimate);
  // The twist of a texel reads its four neighbours: texels 1 .. W−2 only.
  expectReproduces(texture, p, 1, w - 2, 1, h - 2, kExactTolerance, "Hermite Adini");

  Poly top;
  top.c[3][3] = 1;
  const ImageScalarTexture topTexture =
      makeHermite(polyImage(top, w, h), polyDerivatives(top, w, h, 2), HermiteTwist::kEstimate);
  EXPECT_GT(maxError(topTexture, top, 1, w - 2, 1, h - 2), 1e-3);

  // A zero twist (Ferguson) does not reproduce even u·v.
  Poly uv;
  uv.c[1][1] = 1;
  const ImageScalarTexture ferguson =
      makeHermite(polyImage(uv, w, h), polyDerivatives(uv, w, h, 2), HermiteTwist::kZero);
  EXPECT_GT(maxError(ferguson, uv, 1, w - 2, 1, h - 2), 1e-3);
}

TEST(ImageFilters, HermiteWithFourthOrderEstimatesReproducesBicubics) {
  // D = (h[−2] − 8h[−1] + 8h[1] − h[2]) / 12 is exact up to degree 4, and D_u D_v for the twist.
  const int w = 12, h = 11;
  const Poly bicubic = makePoly(3, 3);
  const ImageScalarTexture texture = makeTexture(polyImage(bicubic, w, h), Filter::kHermite,
                                                 Wrap::kRepeat, DerivativeStencil::kCentral4);
  // Stencils reach two texels: texels 2 .. W−3.
  expectReproduces(texture, bicubic, 2, w - 3, 2, h - 3, kFloatStorageTolerance,
                   "Hermite, estimated (4th order)");
}

TEST(ImageFilters, HermiteWithCentralDifferencesIsCatmullRom) {
  // Catmull-Rom is cubic Hermite interpolation with tangents (f[i+1] − f[i−1]) / 2; in 2D the
  // tensor product also takes the cross difference as the twist.
  const int w = 10, h = 7;
  const Image image = randomImage(w, h, 1, 3);
  for (Wrap wrap : {Wrap::kRepeat, Wrap::kClamp}) {
    const ImageScalarTexture hermite =
        makeTexture(image, Filter::kHermite, wrap, DerivativeStencil::kCentral2);
    const ImageScalarTexture catmullRom = makeTexture(image, Filter::kBicubic, wrap);
    for (const Vec2d st : pointsInTexelBox(w, h, -2, w + 1, -2, h + 1, 500)) {
      const ScalarSample a = hermite.sample(st);
      const ScalarSample b = catmullRom.sample(st);
      EXPECT_NEAR(a.value, b.value, kFloatStorageTolerance);
      EXPECT_NEAR(a.gradient.x, b.gradient.x, kFloatStorageTolerance * w);
      EXPECT_NEAR(a.gradient.y, b.gradient.y, kFloatStorageTolerance * h);
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Continuity

struct EdgeJumps {
  double value = 0;     // largest |Δvalue| across an edge
  double gradient = 0;  // largest |Δgradient| across an edge
};

// Compares the one-sided limits of neighbouring cells on every cell edge, including the edges
// that wrap around the image (cell W−1 against cell W ≡ 0).
EdgeJumps edgeJumps(const ImageScalarTexture& texture) {
  EdgeJumps jumps;
  const int w = texture.width();
  const int h = texture.height();
  for (int y = -1; y < h; ++y) {
    for (int x = -1; x < w; ++x) {
      for (double f : {0.0, 0.3, 0.77, 1.0}) {
        // Vertical edge between cells (x, y) and (x+1, y) at fraction f along it.
        const ScalarSample left = texture.sampleCell(x, y, {1.0, f});
        const ScalarSample right = texture.sampleCell(x + 1, y, {0.0, f});
        // Horizontal edge between cells (x, y) and (x, y+1).
        const ScalarSample below = texture.sampleCell(x, y, {f, 1.0});
        const ScalarSample above = texture.sampleCell(x, y + 1, {f, 0.0});
        jumps.value = std::max(
            {jumps.value, std::abs(left.value - right.value), std::abs(below.value - above.value)});
        jumps.gradient = std::max({jumps.gradient, std::abs(left.gradient.x - right.gradient.x) / w,
                                   std::abs(left.gradient.y - right.gradient.y) / h,
                                   std::abs(below.gradient.x - above.gradient.x) / w,
                                   std::abs(below.gradient.y - above.gradient.y) / h});
      }
    }
  }
  return jumps;
}

TEST(ImageFilters, HermiteAndCatmullRomAreC1AcrossCellEdges) {
  const int w = 8, h = 6;
  const Image image = randomImage(w, h, 1, 5);
  const Image derivatives = randomImage(w, h, 3, 6);  // any derivatives: C1 holds regardless
  const Image twoChannels = randomImage(w, h, 2, 7);
  // Data of unit size: gradients are compared in texel units, so 1e-9 is relative.
  const double tolerance = 1e-9;
  struct Case {
    std::string name;
    ImageScalarTexture texture;
  };
  std::vector<Case> cases;
  cases.push_back(
      {"Hermite, 4th-order estimates",
       makeTexture(image, Filter::kHermite, Wrap::kRepeat, DerivativeStencil::kCentral4)});
  cases.push_back(
      {"Hermite, central differences",
       makeTexture(image, Filter::kHermite, Wrap::kRepeat, DerivativeStencil::kCentral2)});
  cases.push_back({"Hermite, supplied with twist", makeHermite(image, derivatives)});
  cases.push_back({"Hermite, supplied, Adini twist", makeHermite(image, twoChannels)});
  cases.push_back(
      {"Hermite, supplied, zero twist", makeHermite(image, twoChannels, HermiteTwist::kZero)});
  cases.push_back({"Catmull-Rom", makeTexture(image, Filter::kBicubic)});
  for (const Case& c : cases) {
    const EdgeJumps jumps = edgeJumps(c.texture);
    EXPECT_LT(jumps.value, tolerance) << c.name;
    EXPECT_LT(jumps.gradient, tolerance) << c.name;
  }
}

TEST(ImageFilters, BilinearIsC0ButItsGradientJumps) {
  // The same check must see bilinear's derivative discontinuities (so it can fail).
  const ImageScalarTexture texture = makeTexture(randomImage(8, 6, 1, 5), Filter::kBilinear);
  const EdgeJumps jumps = edgeJumps(texture);
  EXPECT_LT(jumps.value, 1e-12);
  EXPECT_GT(jumps.gradient, 0.05);
}

TEST(ImageFilters, SampleIsTheCellPolynomialOfItsCell) {
  const int w = 8, h = 6;
  const Image image = randomImage(w, h, 1, 9);
  for (Filter filter : {Filter::kBilinear, Filter::kBicubic, Filter::kHermite}) {
    const ImageScalarTexture texture = makeTexture(image, filter);
    for (const Vec2d st : pointsInTexelBox(w, h, -0.5, w - 0.5, -0.5, h - 0.5, 100)) {
      const double u = st.x * w - 0.5, v = st.y * h - 0.5;
      const int x = static_cast<int>(std::floor(u)), y = static_cast<int>(std::floor(v));
      const ScalarSample a = texture.sample(st);
      const ScalarSample b = texture.sampleCell(x, y, {u - x, v - y});
      EXPECT_NEAR(a.value, b.value, 1e-12);
      EXPECT_NEAR(a.gradient.x, b.gradient.x, 1e-12 * w);
      EXPECT_NEAR(a.gradient.y, b.gradient.y, 1e-12 * h);
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Convergence on a smooth periodic field

// f(s, t) = sin(2πs)·cos(2πt) + 0.5·sin(2π(s + 2t)): smooth and periodic in s and t.
double smoothValue(double s, double t) {
  const double a = 2 * kPi * s, b = 2 * kPi * t;
  return std::sin(a) * std::cos(b) + 0.5 * std::sin(a + 2 * b);
}
Vec2d smoothGradient(double s, double t) {
  const double a = 2 * kPi * s, b = 2 * kPi * t;
  return {2 * kPi * (std::cos(a) * std::cos(b) + 0.5 * std::cos(a + 2 * b)),
          2 * kPi * (-std::sin(a) * std::sin(b) + std::cos(a + 2 * b))};
}

struct Errors {
  double value = 0;
  double gradient = 0;
};

// Largest errors of a filter of the N×N sampled field over a fixed set of points.
Errors convergenceErrors(int n, const ScalarTextureOptions& options) {
  Image image(n, n, 1);
  for (int y = 0; y < n; ++y) {
    for (int x = 0; x < n; ++x) {
      const Vec2d st = image.texelCentre(x, y);
      image.at(x, y) = static_cast<float>(smoothValue(st.x, st.y));
    }
  }
  const Result<ImageScalarTexture> texture = ImageScalarTexture::create(image, options);
  EXPECT_TRUE(texture.ok());
  Errors errors;
  // The same 2000 points (in texture units) for every resolution.
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  for (int i = 0; i < 2000; ++i) {
    const Vec2d st{uniform(rng), uniform(rng)};
    const ScalarSample sample = texture->sample(st);
    const Vec2d g = smoothGradient(st.x, st.y);
    errors.value = std::max(errors.value, std::abs(sample.value - smoothValue(st.x, st.y)));
    errors.gradient = std::max(
        {errors.gradient, std::abs(sample.gradient.x - g.x), std::abs(sample.gradient.y - g.y)});
  }
  return errors;
}

TEST(ImageFilters, ErrorsShrinkAtTheExpectedOrder) {
  // Observed order = log2(err(N) / err(2N)) of the largest error over fixed points. It must lie
  // in [lowest, highest] ± kOrderSlack. Hermite with 4th-order estimates has a range: its
  // interpolation error is O(h⁴) in value and O(h³) in gradient, but the error of the estimated
  // derivatives (O(h⁴) in gradient, O(h⁵) in value) dominates at these resolutions, so the
  // observed orders sit between the two; above N ≈ 128 float storage (~6e-8 per texel) takes
  // over, which is why each case uses resolutions where the discretization error dominates.
  struct Case {
    std::string name;
    ScalarTextureOptions options;
    std::vector<int> resolutions;
    double valueLowest, valueHighest, gradientLowest, gradientHighest;
  };
  auto options = [](Filter filter, DerivativeStencil stencil) {
    ScalarTextureOptions o;
    o.filter = filter;
    o.stencil = stencil;
    return o;
  };
  const std::vector<Case> cases = {
      {"bilinear",
       options(Filter::kBilinear, DerivativeStencil::kCentral4),
       {32, 64, 128},
       2,
       2,
       1,
       1},
      {"Catmull-Rom",
       options(Filter::kBicubic, DerivativeStencil::kCentral4),
       {32, 64, 128},
       3,
       3,
       2,
       2},
      {"Hermite, central differences",
       options(Filter::kHermite, DerivativeStencil::kCentral2),
       {32, 64, 128},
       3,
       3,
       2,
       2},
      {"Hermite, 4th-order estimates",
       options(Filter::kHermite, DerivativeStencil::kCentral4),
       {16, 32, 64},
       4,
       5,
       3,
       4},
  };
  constexpr double kOrderSlack = 0.4;
  for (const Case& c : cases) {
    std::vector<Errors> errors;
    for (int n : c.resolutions) errors.push_back(convergenceErrors(n, c.options));
    for (std::size_t i = 0; i + 1 < errors.size(); ++i) {
      const double valueOrder = std::log2(errors[i].value / errors[i + 1].value);
      const double gradientOrder = std::log2(errors[i].gradient / errors[i + 1].gradient);
      const std::string where = c.name + ", N=" + std::to_string(c.resolutions[i]);
      EXPECT_GT(valueOrder, c.valueLowest - kOrderSlack) << where;
      EXPECT_LT(valueOrder, c.valueHighest + kOrderSlack) << where;
      EXPECT_GT(gradientOrder, c.gradientLowest - kOrderSlack) << where;
      EXPECT_LT(gradientOrder, c.gradientHighest + kOrderSlack) << where;
    }
  }
  // And the point of 4th-order estimates: at N = 64 Hermite beats Catmull-Rom by far.
  const Errors catmullRom = convergenceErrors(64, cases[1].options);
  const Errors hermite = convergenceErrors(64, cases[3].options);
  EXPECT_LT(hermite.value, catmullRom.value / 10);
  EXPECT_LT(hermite.gradient, catmullRom.gradient / 10);
}

// ---------------------------------------------------------------------------------------------
// Derivatives versus finite differences of the filter's own value

// Step of the central differences (texture units) and the tolerance relative to W, H: the
// truncation error is ~δ²·W³ for unit data, the cancellation error ~1e-16/δ.
constexpr double kFdStep = 1e-6;
constexpr double kFdTolerance = 1e-6;

TEST(ImageFilters, DerivativesMatchFiniteDifferencesOfTheValue) {
  const int w = 16, h = 12;
  const Image image = randomImage(w, h, 1, 21);
  const Image derivatives = randomImage(w, h, 3, 22);
  std::vector<std::pair<std::string, ImageScalarTexture>> textures;
  for (Wrap wrap : {Wrap::kRepeat, Wrap::kClamp}) {
    const std::string suffix = wrap == Wrap::kRepeat ? " (repeat)" : " (clamp)";
    textures.emplace_back("bilinear" + suffix, makeTexture(image, Filter::kBilinear, wrap));
    textures.emplace_back("bicubic" + suffix, makeTexture(image, Filter::kBicubic, wrap));
    textures.emplace_back("Hermite" + suffix, makeTexture(image, Filter::kHermite, wrap));
    textures.emplace_back("Hermite supplied" + suffix,
                          makeHermite(image, derivatives, HermiteTwist::kEstimate, wrap));
  }
  // Points anywhere, including around the seam and outside [0, 1), but not within 2δ of a cell
  // edge or (clamp) of the border texel centres, where the one-sided derivatives differ.
  std::vector<Vec2d> points = pointsInTexelBox(w, h, -3, w + 2, -3, h + 2, 600);
  points.push_back({2e-7, 0.3});   // straddling s = 0
  points.push_back({0.7, -3e-7});  // straddling t = 0
  auto nearEdge = [&](double coordinate, int n) {
    const double u = coordinate * n - 0.5;
    return std::abs(u - std::round(u)) < 2 * kFdStep * n;
  };
  for (const auto& [name, texture] : textures) {
    for (const Vec2d st : points) {
      if (nearEdge(st.x, w) || nearEdge(st.y, h)) continue;
      const ScalarSample sample = texture.sample(st);
      const double ds = (texture.sample({st.x + kFdStep, st.y}).value -
                         texture.sample({st.x - kFdStep, st.y}).value) /
                        (2 * kFdStep);
      const double dt = (texture.sample({st.x, st.y + kFdStep}).value -
                         texture.sample({st.x, st.y - kFdStep}).value) /
                        (2 * kFdStep);
      EXPECT_NEAR(sample.gradient.x, ds, kFdTolerance * w)
          << name << " at " << st.x << ", " << st.y;
      EXPECT_NEAR(sample.gradient.y, dt, kFdTolerance * h)
          << name << " at " << st.x << ", " << st.y;
    }
  }
}

TEST(ImageFilters, VectorDerivativesMatchFiniteDifferences) {
  const int w = 10, h = 14;
  const Image image = randomImage(w, h, 4, 31);
  for (Filter filter : {Filter::kBilinear, Filter::kBicubic}) {
    VectorTextureOptions options;
    options.filter = filter;
    options.firstChannel = 1;
    const Result<ImageVectorTexture> texture = ImageVectorTexture::create(image, options);
    ASSERT_TRUE(texture.ok()) << texture.error().message;
    for (const Vec2d st : pointsInTexelBox(w, h, 0.01, w - 1.01, 0.01, h - 1.01, 200)) {
      const double u = st.x * w - 0.5, v = st.y * h - 0.5;
      if (std::abs(u - std::round(u)) < 1e-4 || std::abs(v - std::round(v)) < 1e-4) continue;
      const VectorSample sample = texture->sampleWithDerivatives(st);
      const Vec3d plusS = texture->sample({st.x + kFdStep, st.y});
      const Vec3d minusS = texture->sample({st.x - kFdStep, st.y});
      const Vec3d plusT = texture->sample({st.x, st.y + kFdStep});
      const Vec3d minusT = texture->sample({st.x, st.y - kFdStep});
      for (std::size_t c = 0; c < 3; ++c) {
        EXPECT_NEAR(sample.dds[c], (plusS[c] - minusS[c]) / (2 * kFdStep), kFdTolerance * w);
        EXPECT_NEAR(sample.ddt[c], (plusT[c] - minusT[c]) / (2 * kFdStep), kFdTolerance * h);
      }
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Wrapping

TEST(ImageFilters, RepeatIsPeriodicAndSeamless) {
  const int w = 6, h = 5;
  const Image image = randomImage(w, h, 1, 41);
  for (Filter filter : {Filter::kBilinear, Filter::kBicubic, Filter::kHermite}) {
    const ImageScalarTexture texture = makeTexture(image, filter);
    // Periodic: shifting by whole repeats changes nothing (up to the rounding of s + k).
    for (const Vec2d st : pointsInTexelBox(w, h, -0.5, w - 0.5, -0.5, h - 0.5, 100)) {
      const ScalarSample a = texture.sample(st);
      for (const Vec2d shift : {Vec2d{1, 0}, Vec2d{-3, 2}, Vec2d{17, -5}}) {
        const ScalarSample b = texture.sample(st + shift);
        EXPECT_NEAR(a.value, b.value, 1e-12);
        EXPECT_NEAR(a.gradient.x, b.gradient.x, 1e-12 * w * w);
        EXPECT_NEAR(a.gradient.y, b.gradient.y, 1e-12 * h * h);
      }
    }
    // Seamless: the cell that straddles s = 0 (between texel W−1 and texel 0) is one polynomial,
    // so approaching 0 from below (s → 1⁻) and from above agree in value and gradient.
    for (double t : {0.13, 0.5, 0.91}) {
      const ScalarSample below = texture.sample({1.0 - 1e-12, t});
      const ScalarSample above = texture.sample({1e-12, t});
      EXPECT_NEAR(below.value, above.value, 1e-9);
      EXPECT_NEAR(below.gradient.x, above.gradient.x, 1e-9 * w);
      EXPECT_NEAR(below.gradient.y, above.gradient.y, 1e-9 * h);
    }
  }
}

TEST(ImageFilters, ClampHoldsTheBorderTexelsAndZeroesTheDerivativeBeyond) {
  const int w = 6, h = 5;
  const Image image = randomImage(w, h, 1, 43);
  for (Filter filter : {Filter::kBilinear, Filter::kBicubic, Filter::kHermite}) {
    const ImageScalarTexture texture = makeTexture(image, filter, Wrap::kClamp);
    for (double t : {0.3, 0.55}) {
      // Left of the first texel centre: the value at the centre, ∂/∂s = 0.
      const ScalarSample edge = texture.sample({0.5 / w, t});
      for (double s : {0.2 / w, -0.4, -7.0}) {
        const ScalarSample outside = texture.sample({s, t});
        EXPECT_NEAR(outside.value, edge.value, 1e-12);
        EXPECT_EQ(outside.gradient.x, 0.0);
        EXPECT_NEAR(outside.gradient.y, edge.gradient.y, 1e-9 * h);
      }
      // Right of the last texel centre: the same on that side.
      const ScalarSample last = texture.sample({1 - 0.5 / w, t});
      const ScalarSample beyond = texture.sample({3.0, t});
      EXPECT_NEAR(beyond.value, last.value, 1e-12);
      EXPECT_EQ(beyond.gradient.x, 0.0);
    }
    // At the border texel centres the value is the texel.
    EXPECT_NEAR(texture.sample({-1, -1}).value, image.at(0, 0), 1e-7);
    EXPECT_NEAR(texture.sample({2, 2}).value, image.at(w - 1, h - 1), 1e-7);
  }
}

// ---------------------------------------------------------------------------------------------
// Vector textures and invalid input

TEST(ImageFilters, VectorTextureReproducesPolynomialsPerChannel) {
  const int w = 12, h = 9;
  const Poly biquadratic = makePoly(2, 2);
  // Channel c holds p + c.
  const Image image = imageOf(w, h, 3, [&](int x, int y) { return biquadratic.value(x, y); });
  for (Filter filter : {Filter::kBilinear, Filter::kBicubic}) {
    VectorTextureOptions options;
    options.filter = filter;
    const Result<ImageVectorTexture> texture = ImageVectorTexture::create(image, options);
    ASSERT_TRUE(texture.ok()) << texture.error().message;
    for (const Vec2d st : pointsInTexelBox(w, h, 1, w - 2, 1, h - 2, 100)) {
      const double u = st.x * w - 0.5, v = st.y * h - 0.5;
      const VectorSample sample = texture->sampleWithDerivatives(st);
      if (filter == Filter::kBicubic) {
        for (std::size_t c = 0; c < 3; ++c) {
          const double scale = 1e4;  // values up to ~1e3, gradients up to ~1e4
          EXPECT_NEAR(sample.value[c], biquadratic.value(u, v) + static_cast<double>(c),
                      kExactTolerance * scale);
          EXPECT_NEAR(sample.dds[c], w * biquadratic.du(u, v), kExactTolerance * scale);
          EXPECT_NEAR(sample.ddt[c], h * biquadratic.dv(u, v), kExactTolerance * scale);
        }
      }
      // The three channels differ by constants: equal derivatives, offset values.
      EXPECT_NEAR(sample.value[2] - sample.value[0], 2.0, 1e-9);
      EXPECT_NEAR(sample.dds[1], sample.dds[0], 1e-9 * w);
      EXPECT_EQ(texture->sample(st), sample.value);
    }
  }
}

// A texture made from an image that is not needed afterwards takes its pixels: it samples as
// the copy does, the image is left empty, and a bad image is refused as the copy refuses it
// (and kept).
TEST(ImageFilters, VectorTextureTakesTheImagesPixels) {
  for (const int channels : {3, 4}) {
    Image image = randomImage(6, 5, channels, 7);
    for (Filter filter : {Filter::kBilinear, Filter::kBicubic}) {
      VectorTextureOptions options;
      options.filter = filter;
      options.wrap = Wrap::kClamp;
      const Result<ImageVectorTexture> copied = ImageVectorTexture::create(image, options);
      Image moved = image;
      const Result<ImageVectorTexture> taken =
          ImageVectorTexture::create(std::move(moved), options);
      ASSERT_TRUE(copied.ok() && taken.ok());
      EXPECT_EQ(moved.empty(), channels == 3) << "only a three-channel image's pixels are taken";
      for (const Vec2d st : pointsInTexelBox(6, 5, -1, 7, -1, 6, 50)) {
        EXPECT_EQ(taken->sampleWithDerivatives(st).value, copied->sampleWithDerivatives(st).value);
        EXPECT_EQ(taken->sampleWithDerivatives(st).dds, copied->sampleWithDerivatives(st).dds);
      }
    }
  }
  Image bad = randomImage(4, 4, 3, 1);
  bad.at(1, 2, 1) = std::numeric_limits<float>::quiet_NaN();
  Image kept = bad;
  const Result<ImageVectorTexture> refused = ImageVectorTexture::create(std::move(kept));
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.error().message, ImageVectorTexture::create(bad).error().message);
  EXPECT_FALSE(kept.empty());
  VectorTextureOptions hermite;
  hermite.filter = Filter::kHermite;
  EXPECT_FALSE(ImageVectorTexture::create(randomImage(4, 4, 3, 1), hermite).ok());
}

TEST(ImageFilters, InvalidInputIsReported) {
  const Image empty;
  EXPECT_EQ(ImageScalarTexture::create(empty).error().code, ErrorCode::kBadInput);
  EXPECT_EQ(ImageVectorTexture::create(empty).error().code, ErrorCode::kBadInput);

  const Image gray = randomImage(4, 4, 1, 1);
  ScalarTextureOptions channel2;
  channel2.channel = 2;
  const Result<ImageScalarTexture> noChannel = ImageScalarTexture::create(gray, channel2);
  ASSERT_FALSE(noChannel.ok());
  EXPECT_NE(noChannel.error().message.find("channel 2 does not exist"), std::string::npos)
      << noChannel.error().message;
  EXPECT_FALSE(ImageVectorTexture::create(gray).ok());
  VectorTextureOptions hermiteVector;
  hermiteVector.filter = Filter::kHermite;
  EXPECT_FALSE(ImageVectorTexture::create(randomImage(4, 4, 3, 1), hermiteVector).ok());

  // Supplied derivatives: same size, 2 or 3 channels, finite.
  EXPECT_FALSE(ImageScalarTexture::createWithDerivatives(gray, randomImage(4, 5, 3, 2)).ok());
  for (int channels : {1, 4}) {
    const Result<ImageScalarTexture> bad =
        ImageScalarTexture::createWithDerivatives(gray, randomImage(4, 4, channels, 2));
    ASSERT_FALSE(bad.ok());
    EXPECT_EQ(bad.error().code, ErrorCode::kBadInput);
    EXPECT_EQ(bad.error().message.find('\n'), std::string::npos);
  }
  Image nan = randomImage(4, 4, 1, 3);
  nan.at(2, 1) = std::numeric_limits<float>::quiet_NaN();
  const Result<ImageScalarTexture> notFinite = ImageScalarTexture::create(nan);
  ASSERT_FALSE(notFinite.ok());
  EXPECT_NE(notFinite.error().message.find("texel (2, 1)"), std::string::npos)
      << notFinite.error().message;

  // Non-finite coordinates give NaN, not a crash.
  const ImageScalarTexture texture = makeTexture(gray, Filter::kBicubic);
  EXPECT_TRUE(std::isnan(texture.sample({std::nan(""), 0.5}).value));
  EXPECT_TRUE(std::isnan(texture.sample({0.5, INFINITY}).gradient.x));
}

TEST(ImageFilters, TinyImagesWrap) {
  // 1×1 and 2×1 images: every tap wraps several times; the value stays finite and periodic.
  for (int w : {1, 2, 3}) {
    const Image image = randomImage(w, 1, 1, 50 + static_cast<unsigned>(w));
    for (Filter filter : {Filter::kBilinear, Filter::kBicubic, Filter::kHermite}) {
      const ImageScalarTexture texture = makeTexture(image, filter);
      for (double s : {-1.3, 0.0, 0.25, 0.9, 4.2}) {
        const ScalarSample a = texture.sample({s, 0.4});
        const ScalarSample b = texture.sample({s + 2, 0.4});
        EXPECT_TRUE(std::isfinite(a.value));
        EXPECT_NEAR(a.value, b.value, 1e-12);
        EXPECT_NEAR(a.gradient.y, 0.0, 1e-12);  // one row: constant along t
      }
    }
  }
}

}  // namespace
}  // namespace sgbake
