/// @file blender_noise.cpp
/// @brief Blender's Noise Texture (blender_noise.hpp), written from its description: Perlin's
/// improved noise on a hashed lattice, fBm octaves, distortion.
#include "sgbake/gradient/blender_noise.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <limits>
#include <string>
#include <string_view>

#include "sgbake/core/math.hpp"

namespace sgbake {
namespace {

constexpr std::uint32_t rotate(std::uint32_t x, int k) { return (x << k) | (x >> (32 - k)); }

/// Bob Jenkins' lookup3 `final` mix of (a, b, c); returns c. Seven steps x ^= y, x −= y rotated
/// left by k, round the words c ← b, a ← c, b ← a, …
constexpr std::uint32_t finalMix(std::uint32_t a, std::uint32_t b, std::uint32_t c) {
  const auto step = [](std::uint32_t& x, std::uint32_t y, int k) {
    x ^= y;
    x -= rotate(y, k);
  };
  step(c, b, 14);
  step(a, c, 11);
  step(b, a, 25);
  step(c, b, 16);
  step(a, c, 4);
  step(b, a, 14);
  step(c, b, 24);
  return c;
}

/// lookup3's hash of three words (Cycles' hash_uint3): the initial value 0xdeadbeef + (3 << 2) +
/// 13 in a, b and c, the words added, then the final mix.
constexpr std::uint32_t hashWords(std::uint32_t x, std::uint32_t y, std::uint32_t z) {
  constexpr std::uint32_t init = 0xdeadbeefu + (3u << 2) + 13u;
  return finalMix(init + x, init + y, init + z);
}

/// lookup3's `mix` of (a, b, c): six rounds of x −= z, x ^= z rotated left by k, z += y, round the
/// words.
constexpr void mixWords(std::uint32_t& a, std::uint32_t& b, std::uint32_t& c) {
  const auto round = [](std::uint32_t& x, std::uint32_t& y, std::uint32_t& z, int k) {
    x -= z;
    x ^= rotate(z, k);
    z += y;
  };
  round(a, b, c, 4);
  round(b, c, a, 6);
  round(c, a, b, 8);
  round(a, b, c, 16);
  round(b, c, a, 19);
  round(c, a, b, 4);
}

/// lookup3's hash of four words (Cycles' hash_uint4): three words mixed in, then the fourth
/// added to a and the final mix.
constexpr std::uint32_t hashWords(std::uint32_t x, std::uint32_t y, std::uint32_t z,
                                  std::uint32_t w) {
  constexpr std::uint32_t init = 0xdeadbeefu + (4u << 2) + 13u;
  std::uint32_t a = init + x, b = init + y, c = init + z;
  mixWords(a, b, c);
  return finalMix(a + w, b, c);
}

/// A hash as Cycles maps it into [0, 1]: in float, divided by 2³² − 1.
inline float unitFloat(std::uint32_t h) {
  return static_cast<float>(h) / static_cast<float>(0xFFFFFFFFu);
}

/// Of two words (Cycles' hash_uint2), the third word not added.
constexpr std::uint32_t hashWords(std::uint32_t x, std::uint32_t y) {
  constexpr std::uint32_t init = 0xdeadbeefu + (2u << 2) + 13u;
  return finalMix(init + x, init + y, init);
}

/// Component @p axis of the offset Cycles adds to seed noise number @p seed (its
/// random_float3_offset): 100 + 100 · hash(seed, axis) / (2³² − 1), the two floats' bits hashed,
/// in float as Cycles computes it.
float seedOffset(int seed, int axis) {
  const std::uint32_t h = hashWords(std::bit_cast<std::uint32_t>(float(seed)),
                                    std::bit_cast<std::uint32_t>(float(axis)));
  return 100.0f + unitFloat(h) * 100.0f;
}

inline constexpr double fade(double t) { return t * t * t * (t * (t * 6 - 15) + 10); }
inline constexpr double fadeSlope(double t) { return 30 * t * t * (t - 1) * (t - 1); }

/// A point (or a gradient) of Blender's noise of N = 1 … 4 dimensions.
template <int N>
struct NoiseVec {
  std::array<double, N> c{};
  friend NoiseVec operator+(NoiseVec a, const NoiseVec& b) {
    for (int i = 0; i < N; ++i) a.c[i] += b.c[i];
    return a;
  }
  friend NoiseVec operator*(double s, NoiseVec a) {
    for (int i = 0; i < N; ++i) a.c[i] = s * a.c[i];
    return a;
  }
};

inline NoiseVec<3> toNoiseVec(Vec3d v) { return {{v.x, v.y, v.z}}; }
inline Vec3d toVec3(const NoiseVec<3>& v) { return {v.c[0], v.c[1], v.c[2]}; }

/// lookup3's hash of one word (Cycles' hash_uint): a, b and c all start at 0xdeadbeef + (1 << 2)
/// + 13, the word is added to a, then the final mix.
constexpr std::uint32_t hashWord(std::uint32_t x) {
  constexpr std::uint32_t init = 0xdeadbeefu + (1u << 2) + 13u;
  return finalMix(init + x, init, init);
}

/// The hash of a lattice corner's N integer coordinates (Cycles' hash_uint … hash_uint4).
template <int N>
std::uint32_t latticeHash(const std::uint32_t (&w)[N]) {
  if constexpr (N == 1) return hashWord(w[0]);
  if constexpr (N == 2) return hashWords(w[0], w[1]);
  if constexpr (N == 3) return hashWords(w[0], w[1], w[2]);
  if constexpr (N == 4) return hashWords(w[0], w[1], w[2], w[3]);
}

/// Cycles' gradient rule of N-dimensional Perlin noise: corner hash @p hash picks the corner's
/// gradient g, and the corner's term is g · d, d the offset from the corner; with @p direction,
/// g itself (the term's gradient with respect to d). Of the hash's low bits:
/// - 1D (grad1): g = ±(1 + (h & 7)) of the low 4 bits, negative if bit 8 is set;
/// - 2D (grad2): of the low 3 bits, ±e_u ± 2 e_v, (u, v) = (x, y) for h < 4, else (y, x);
/// - 3D (grad3): of the low 4 bits, ±e_u ± e_v, u = x for h < 8, else y; v = y for h < 4, x for
///   12 and 14, else z: Perlin's 12 directions of his improved noise, 4 of them twice;
/// - 4D (grad4): of the low 5 bits, ±e_u ± e_v ± e_s, u = x for h < 24, else y; v = y for
///   h < 16, else z; s = z for h < 8, else w.
/// The signs are bits 1, 2 (and 4) of the hash.
template <int N, bool kDirection>
inline double cornerTerm(std::uint32_t hash, const double (&d)[N], double (&direction)[N]) {
  const auto sign = [hash](std::uint32_t bit) { return (hash & bit) ? -1.0 : 1.0; };
  if constexpr (kDirection) {
    for (int a = 0; a < N; ++a) direction[a] = 0;
  }
  if constexpr (N == 1) {
    const double g = sign(8u) * (1.0 + double(hash & 7u));
    if constexpr (kDirection) direction[0] = g;
    return g * d[0];
  } else {
    const std::uint32_t h = hash & (N == 2 ? 7u : N == 3 ? 15u : 31u);
    int u, v;
    double su = sign(1u), sv = sign(2u);
    if constexpr (N == 2) {
      u = h < 4 ? 0 : 1;
      v = 1 - u;
      sv *= 2;
    } else if constexpr (N == 3) {
      u = h < 8 ? 0 : 1;
      v = h < 4 ? 1 : (h == 12 || h == 14) ? 0 : 2;
    } else {
      u = h < 24 ? 0 : 1;
      v = h < 16 ? 1 : 2;
    }
    if constexpr (kDirection) {
      direction[u] += su;
      direction[v] += sv;
    }
    double term = su * d[u] + sv * d[v];
    if constexpr (N == 4) {
      const int s = h < 8 ? 2 : 3;
      const double ss = sign(4u);
      if constexpr (kDirection) direction[s] += ss;
      term += ss * d[s];
    }
    return term;
  }
}

/// The integer cell coordinate of x as Cycles casts it to a word (floor, two's complement),
/// clamped to the int range for coordinates beyond it.
inline std::uint32_t cellWord(double floored) {
  const double clamped = std::clamp(floored, -2147483648.0, 2147483647.0);
  return static_cast<std::uint32_t>(static_cast<std::int32_t>(clamped));
}

/// perlin(x) in N dimensions, and with kGradient its gradient: the 2ᴺ corners' terms blended
/// multilinearly by the faded fractions (x first, then y, z and w).
template <int N, bool kGradient>
double perlin(const NoiseVec<N>& x, NoiseVec<N>* gradient) {
  constexpr int kCorners = 1 << N;
  double f[N], s[N], ds[N];
  std::uint32_t cell[N];
  for (int a = 0; a < N; ++a) {
    const double floored = std::floor(x.c[a]);
    f[a] = x.c[a] - floored;
    cell[a] = cellWord(floored);
    s[a] = fade(f[a]);
    ds[a] = fadeSlope(f[a]);
  }
  double term[kCorners], dir[kCorners][N];
  for (int c = 0; c < kCorners; ++c) {
    double d[N];
    std::uint32_t corner[N];
    for (int a = 0; a < N; ++a) {
      const std::uint32_t bit = (c >> a) & 1u;
      d[a] = f[a] - bit;
      corner[a] = cell[a] + bit;
    }
    term[c] = cornerTerm<N, kGradient>(latticeHash<N>(corner), d, dir[c]);
  }
  // Blend along x (pairs of corners 2k, 2k + 1), then along y the results, and so on.
  const auto lerp = [](double a, double b, double t) { return a + t * (b - a); };
  double blend[kCorners];
  for (int c = 0; c < kCorners; ++c) blend[c] = term[c];
  for (int a = 0; a < N; ++a) {
    for (int k = 0; k < (kCorners >> (a + 1)); ++k) {
      blend[k] = lerp(blend[2 * k], blend[2 * k + 1], s[a]);
    }
  }
  if constexpr (kGradient) {
    // Each corner: its weight Π w_a times its direction, plus its term times the derivative
    // of its weight along each axis (±fade′ times the other axes' weights).
    NoiseVec<N> g;
    for (int c = 0; c < kCorners; ++c) {
      double w[N];
      double weight = 1;
      for (int a = 0; a < N; ++a) {
        w[a] = ((c >> a) & 1) ? s[a] : 1 - s[a];
        weight *= w[a];
      }
      for (int a = 0; a < N; ++a) {
        double along = term[c] * (((c >> a) & 1) ? 1.0 : -1.0) * ds[a];
        for (int b = 0; b < N; ++b) {
          if (b != a) along *= w[b];
        }
        g.c[a] += weight * dir[c][a] + along;
      }
    }
    *gradient = g;
  }
  return blend[0];
}

/// Cycles' noise_scale1 … noise_scale4: snoise = scale · perlin in N dimensions.
template <int N>
constexpr double kNoiseScale = N == 1 ? 0.2500 : N == 2 ? 0.6616 : N == 3 ? 0.9820 : 0.8344;

/// Cycles' snoise in N dimensions at @p x, and its gradient if asked.
template <int N>
double signedNoise(const NoiseVec<N>& x, NoiseVec<N>* gradient) {
  if (gradient == nullptr) return kNoiseScale<N> * perlin<N, false>(x, nullptr);
  const double value = perlin<N, true>(x, gradient);
  *gradient = kNoiseScale<N> * *gradient;
  return kNoiseScale<N> * value;
}

/// The Noise Texture's fBm in N dimensions (blenderFractalNoise), and its gradient if asked.
template <int N>
double fractalNoise(const NoiseVec<N>& p, double detail, double roughness,
                    NoiseVec<N>* gradient) {
  detail = std::clamp(detail, 0.0, 15.0);
  roughness = std::clamp(roughness, 0.0, 1.0);
  const int octaves = static_cast<int>(detail);
  double frequency = 1, amplitude = 1, weights = 0, sum = 0;
  NoiseVec<N> slope{};
  const auto octave = [&](double& value, NoiseVec<N>& g) {  // ½ snoise + ½ of p · frequency
    value = 0.5 * signedNoise<N>(frequency * p, gradient ? &g : nullptr) + 0.5;
    g = (0.5 * frequency) * g;
  };
  for (int i = 0; i <= octaves; ++i) {
    double t;
    NoiseVec<N> g{};
    octave(t, g);
    sum += t * amplitude;
    slope = slope + amplitude * g;
    weights += amplitude;
    amplitude *= roughness;
    frequency *= 2;
  }
  double value = sum / weights;
  NoiseVec<N> valueSlope = (1 / weights) * slope;
  const double rest = detail - std::floor(detail);
  if (rest != 0) {  // one more octave, blended in by the fraction
    double t;
    NoiseVec<N> g{};
    octave(t, g);
    const double more = (sum + t * amplitude) / (weights + amplitude);
    const NoiseVec<N> moreSlope = (1 / (weights + amplitude)) * (slope + amplitude * g);
    value = (1 - rest) * value + rest * more;
    valueSlope = (1 - rest) * valueSlope + rest * moreSlope;
  }
  if (gradient != nullptr) *gradient = valueSlope;
  return value;
}

/// The point a node of Dimensions N reads of its scaled Vector @p p and W @p w: (w) in 1D,
/// (x, y) in 2D, (x, y, z) in 3D, (x, y, z, w) in 4D.
template <int N>
NoiseVec<N> nodePoint(Vec3d p, double w) {
  if constexpr (N == 1) return {{w}};
  if constexpr (N == 2) return {{p.x, p.y}};
  if constexpr (N == 3) return {{p.x, p.y, p.z}};
  if constexpr (N == 4) return {{p.x, p.y, p.z, w}};
}

/// The derivative of nodePoint's axis @p a with respect to the Vector: e_a for x, y and z, 0
/// for W.
template <int N>
Vec3d nodeAxis(int a) {
  if (N == 1 || a == 3) return {};
  return {a == 0 ? 1.0 : 0.0, a == 1 ? 1.0 : 0.0, a == 2 ? 1.0 : 0.0};
}

/// A gradient @p g with respect to nodePoint, pulled back to the Vector (W held).
template <int N>
Vec3d vectorSlope(const NoiseVec<N>& g) {
  Vec3d v{};
  for (int a = 0; a < N; ++a) v = v + g.c[a] * nodeAxis<N>(a);
  return v;
}

/// @p at's `operator()<N>()` for N = @p dimensions (create() has checked it is 1 … 4).
template <class At>
double withDimensions(int dimensions, const At& at) {
  switch (dimensions) {
    case 1:
      return at.template operator()<1>();
    case 2:
      return at.template operator()<2>();
    case 4:
      return at.template operator()<4>();
    default:
      return at.template operator()<3>();
  }
}

/// snoise of a node of Dimensions @p dimensions at its scaled Vector @p p and W @p w, and its
/// gradient with respect to the Vector.
double signedNoiseOf(int dimensions, Vec3d p, double w, Vec3d* gradient) {
  return withDimensions(dimensions, [&]<int N>() {
    NoiseVec<N> g;
    const double value = signedNoise<N>(nodePoint<N>(p, w), gradient ? &g : nullptr);
    if (gradient != nullptr) *gradient = vectorSlope<N>(g);
    return value;
  });
}

/// The bits of @p v as the float Cycles hashes.
inline std::uint32_t floatBits(double v) {
  return std::bit_cast<std::uint32_t>(static_cast<float>(v));
}

/// The offset of the point in the Voronoi cell at integer coordinates @p cell, in [0, 1)³ before
/// the randomness: Cycles' hash_float3_to_float3 of the cell's coordinates.
Vec3d voronoiCellPoint(Vec3d cell) {
  const std::uint32_t x = floatBits(cell.x), y = floatBits(cell.y), z = floatBits(cell.z);
  return {unitFloat(hashWords(x, y, z)), unitFloat(hashWords(x, y, z, floatBits(1.0))),
          unitFloat(hashWords(x, y, z, floatBits(2.0)))};
}

/// The check every texture's create() starts with: "a <texture> setting is not finite".
Status finiteSettings(std::string_view texture, std::initializer_list<double> settings) {
  for (const double v : settings) {
    if (!std::isfinite(v)) {
      return Error::badInput("a " + std::string(texture) + " setting is not finite");
    }
  }
  return Ok{};
}

/// The check of a node's Dimensions: "a <texture>'s Dimensions must be 1, 2, 3 or 4".
Status validDimensions(std::string_view texture, int dimensions) {
  if (dimensions >= 1 && dimensions <= 4) return Ok{};
  return Error::badInput("a " + std::string(texture) + "'s Dimensions must be 1, 2, 3 or 4, not " +
                         std::to_string(dimensions));
}

/// The bound every texture's create() puts on its slopes' scale @p slopes (kMaxVolumeScale), the
/// message naming the @p formula it was computed by (if any).
Status boundedSlopes(std::string_view texture, double slopes, std::string_view formula) {
  if (slopes <= kMaxVolumeScale) return Ok{};
  std::string message(texture);
  message += " slopes beyond 1e300";
  if (!formula.empty()) {
    message += ' ';
    message += formula;
  }
  return Error::badInput(std::move(message));
}

}  // namespace

double blenderSignedNoise(Vec3d x, Vec3d* gradient) {
  NoiseVec<3> g;
  const double value = signedNoise<3>(toNoiseVec(x), gradient ? &g : nullptr);
  if (gradient != nullptr) *gradient = toVec3(g);
  return value;
}

double blenderFractalNoise(Vec3d p, double detail, double roughness, Vec3d* gradient) {
  NoiseVec<3> g;
  const double value = fractalNoise<3>(toNoiseVec(p), detail, roughness, gradient ? &g : nullptr);
  if (gradient != nullptr) *gradient = toVec3(g);
  return value;
}

namespace {

/// The offset Cycles adds to seed the 1D distortion (its random_float_offset(0)): 100 + 100 ·
/// hash(the bits of 0.0f) / (2³² − 1).
float seedOffset1D(int seed) {
  return 100.0f + unitFloat(hashWord(std::bit_cast<std::uint32_t>(float(seed)))) * 100.0f;
}

/// The Noise Texture's Fac in N dimensions at the object-space @p position, and its gradient
/// with respect to it: the distortion moves each of the N axes of the node's point by snoise
/// seeded with that axis's offset, and the gradient is pulled back through that map's Jacobian.
template <int N>
double noiseTexture(const BlenderNoiseParams& params,
                    const std::array<std::array<double, 4>, 4>& offsets, Vec3d position,
                    Vec3d* gradient) {
  const double scale = params.scale;
  const NoiseVec<N> p = nodePoint<N>(scale * position, scale * params.w);
  // Row a: the derivative of the (moved) point's axis a with respect to the scaled Vector.
  std::array<Vec3d, N> rows;
  for (int a = 0; a < N; ++a) rows[static_cast<std::size_t>(a)] = nodeAxis<N>(a);
  NoiseVec<N> moved = p;
  if (params.distortion != 0) {
    for (int k = 0; k < N; ++k) {
      NoiseVec<N> seeded = p;
      for (int a = 0; a < N; ++a) {
        seeded.c[a] += offsets[static_cast<std::size_t>(k)][static_cast<std::size_t>(a)];
      }
      NoiseVec<N> g;
      moved.c[k] += signedNoise<N>(seeded, gradient ? &g : nullptr) * params.distortion;
      if (gradient != nullptr) {
        rows[static_cast<std::size_t>(k)] =
            rows[static_cast<std::size_t>(k)] + params.distortion * vectorSlope<N>(g);
      }
    }
  }
  NoiseVec<N> valueSlope;
  const double value =
      fractalNoise<N>(moved, params.detail, params.roughness, gradient ? &valueSlope : nullptr);
  if (gradient != nullptr) {
    // d Fac / d position = scale · Jᵀ · ∇fbm.
    Vec3d pulled{};
    for (int a = 0; a < N; ++a) pulled = pulled + valueSlope.c[a] * rows[static_cast<std::size_t>(a)];
    *gradient = scale * pulled;
  }
  return value;
}

}  // namespace

Result<BlenderNoise> BlenderNoise::create(const BlenderNoiseParams& params) {
  if (Status finite = finiteSettings("Noise Texture",
                                     {params.amplitude, params.scale, params.detail,
                                      params.roughness, params.distortion, params.w});
      !finite)
    return finite.error();
  if (Status dimensions = validDimensions("Noise Texture", params.dimensions); !dimensions)
    return dimensions.error();
  const double detail = std::clamp(params.detail, 0.0, 15.0);
  const double slopes = std::abs(params.amplitude) * std::abs(params.scale) *
                        (1 + std::abs(params.distortion)) * std::exp2(std::ceil(detail));
  if (Status bounded = boundedSlopes("Noise Texture", slopes,
                                     "(amplitude × scale × (1 + distortion) × 2^detail)");
      !bounded)
    return bounded.error();
  return BlenderNoise(params);
}

BlenderNoise::BlenderNoise(const BlenderNoiseParams& params) : BlenderTextureVolume(params) {
  // The distortion of axis k reads noise seeded k: random_float_offset(0) in 1D, else
  // random_floatN_offset(k).
  for (std::size_t k = 0; k < 4; ++k) {
    for (std::size_t a = 0; a < 4; ++a) {
      distortionOffsets_[k][a] = params.dimensions == 1
                                     ? seedOffset1D(static_cast<int>(k))
                                     : seedOffset(static_cast<int>(k), static_cast<int>(a));
    }
  }
}

double BlenderNoise::output(Vec3d position, Vec3d* gradient) const {
  return withDimensions(params_.dimensions, [&]<int N>() {
    return noiseTexture<N>(params_, distortionOffsets_, position, gradient);
  });
}

Result<BlenderMusgrave> BlenderMusgrave::create(const BlenderMusgraveParams& params) {
  if (Status finite = finiteSettings(
          "Musgrave Texture", {params.amplitude, params.scale, params.detail, params.dimension,
                               params.lacunarity, params.offset, params.gain, params.w});
      !finite)
    return finite.error();
  if (Status dimensions = validDimensions("Musgrave Texture", params.dimensions); !dimensions)
    return dimensions.error();
  const double detail = std::clamp(params.detail, 0.0, 15.0);
  const double lacunarity = std::max(params.lacunarity, 1e-5);
  const double h = std::max(params.dimension, 1e-5);
  const double n = std::ceil(detail);
  const double scale = std::abs(params.amplitude) * std::abs(params.scale);
  // Octave i's slopes are scaled by its weight times its frequency, L^(−iH) · Lⁱ = (L^(1−H))ⁱ:
  // at most qⁿ, q = max(1, L^(1−H)), with n = ⌈detail⌉.
  const double q = std::max(1.0, std::pow(lacunarity, 1 - h));
  if (params.type == MusgraveType::kFbm) {
    // The n + 1 octaves at most (n + 1) · qⁿ.
    const double slopes = scale * (1 + n) * std::pow(q, n);
    if (Status bounded = boundedSlopes(
            "Musgrave Texture", slopes,
            "(amplitude × scale × (1 + detail) × lacunarity^((1 − dimension) · detail))");
        !bounded)
      return bounded.error();
    return BlenderMusgrave(params);
  }
  // The other types multiply octaves (or weight them by earlier ones): with m = max(1, L^(−H))
  // bounding an octave's weight, a = 1 + |offset| an offset signal and g = max(1, |gain|), the
  // product of the n + 1 factors (1 + a wᵢ) is at most (2a)ⁿ⁺¹ · m^(n(n+1)/2), and the product
  // rule's n + 1 terms each take one factor's slopes, at most qⁿ. The hybrid's weights multiply
  // in g and their own slopes, (n + 1) more terms; the ridged's signals are squares (a²) whose
  // weights multiply in g, read at frequencies at most max(1, L)ⁿ, weighted at most mⁿ.
  const double a = 1 + std::abs(params.offset);
  const double g = std::max(1.0, std::abs(params.gain));
  const double m = std::max(1.0, std::pow(lacunarity, -h));
  const double products = std::pow(m, n * (n + 1) / 2) * std::pow(q, n);
  double slopes = 0;
  switch (params.type) {
    case MusgraveType::kMultifractal:
      slopes = (1 + n) * std::pow(2.0, n + 1) * products;
      break;
    case MusgraveType::kHeteroTerrain:
      slopes = (1 + n) * std::pow(2 * a, n + 1) * products;
      break;
    case MusgraveType::kHybridMultifractal:
      slopes = (1 + n) * (1 + n) * std::pow(2 * a * g, n + 1) * products;
      break;
    default:  // ridged
      slopes = (1 + n) * (1 + n) * 2 * a * std::pow(a * a * g * m * std::max(1.0, lacunarity), n);
      break;
  }
  if (Status bounded = boundedSlopes(
          "Musgrave Texture", scale * slopes,
          "(amplitude × scale × the type's octaves multiplied: (1 + offset), gain and "
          "lacunarity^(−dimension) to powers growing with detail)");
      !bounded)
    return bounded.error();
  return BlenderMusgrave(params);
}

namespace {

/// Cycles' threshold on the hybrid multifractal's weight, its float 0.001.
constexpr double kHybridThreshold = static_cast<double>(0.001f);

/// The octaves of a Musgrave Texture at p: octave i reads snoise(Lⁱ p), and its gradient with
/// respect to p (times Lⁱ) if asked.
struct MusgraveOctaves {
  int dimensions;
  Vec3d p;
  double w;
  double lacunarity;
  bool gradient;
  double frequency = 1;
  /// snoise at the current frequency, its gradient in @p g; then the next octave.
  double next(Vec3d& g) {
    const double s =
        signedNoiseOf(dimensions, frequency * p, frequency * w, gradient ? &g : nullptr);
    if (gradient) g = frequency * g;
    frequency *= lacunarity;
    return s;
  }
};

/// Multifractal: the product of the factors 1 + wᵢ sᵢ (the fraction's 1 + r wₙ sₙ), the
/// gradient by the product rule.
double musgraveMultifractal(MusgraveOctaves octaves, int n, double rest, double weightStep,
                            Vec3d& slope) {
  double value = 1, weight = 1;
  const auto multiply = [&](double factor) {
    Vec3d g{};
    const double s = octaves.next(g);
    const double f = 1 + factor * weight * s;
    slope = f * slope + (value * factor * weight) * g;
    value *= f;
  };
  for (int i = 0; i < n; ++i) {
    multiply(1);
    weight *= weightStep;
  }
  if (rest != 0) multiply(rest);
  return value;
}

/// Hetero Terrain: V₀ = offset + s₀, each later octave adding (sᵢ + offset) wᵢ V.
double musgraveHeteroTerrain(MusgraveOctaves octaves, int n, double rest, double weightStep,
                             double offset, Vec3d& slope) {
  Vec3d g{};
  double value = offset + octaves.next(g);
  slope = g;
  double weight = weightStep;
  const auto add = [&](double factor) {
    const double s = octaves.next(g) + offset;
    const double increment = s * weight * value;
    slope = slope + (factor * weight) * (value * g + s * slope);
    value += factor * increment;
  };
  for (int i = 1; i < n; ++i) {
    add(1);
    weight *= weightStep;
  }
  if (rest != 0) add(rest);
  return value;
}

/// Hybrid Multifractal: each signal (sᵢ + offset) wᵢ added times a weight, min(1, …) of the
/// previous weight times gain times the previous signal; stops once the weight is ≤ 0.001.
double musgraveHybrid(MusgraveOctaves octaves, int n, double rest, double weightStep, double offset,
                      double gain, Vec3d& slope) {
  double value = 0, power = 1, weight = 1;
  Vec3d weightSlope{};
  const auto add = [&](double factor) {
    if (weight > 1) {  // clamped: its gradient is 0
      weight = 1;
      weightSlope = {};
    }
    Vec3d g{};
    const double signal = (octaves.next(g) + offset) * power;
    const Vec3d signalSlope = power * g;
    const Vec3d termSlope = signal * weightSlope + weight * signalSlope;
    value += factor * weight * signal;
    slope = slope + factor * termSlope;
    weightSlope = gain * termSlope;
    weight *= gain * signal;
    power *= weightStep;
  };
  for (int i = 0; weight > kHybridThreshold && i < n; ++i) add(1);
  if (rest != 0 && weight > kHybridThreshold) add(rest);
  return value;
}

/// Ridged Multifractal: signals (offset − |sᵢ|)², each after the first times clamp(gain · the
/// previous signal, 0, 1), summed weighted wᵢ. |s|'s gradient is sign(s) ∇s, + at s = 0.
double musgraveRidged(MusgraveOctaves octaves, int n, double weightStep, double offset, double gain,
                      Vec3d& slope) {
  double value = 0, power = 1, signal = 0;
  Vec3d signalSlope{};
  for (int i = 0; i < std::max(n, 1); ++i) {
    double weight = 1;
    Vec3d weightSlope{};
    if (i > 0) {
      const double t = signal * gain;
      weight = std::clamp(t, 0.0, 1.0);
      if (t > 0 && t < 1) weightSlope = gain * signalSlope;  // else clamped: 0
    }
    Vec3d g{};
    const double s = octaves.next(g);
    const double ridge = offset - std::abs(s);
    const Vec3d ridgeSlope = (s < 0 ? 1.0 : -1.0) * g;
    signal = ridge * ridge * weight;
    signalSlope = (2 * ridge * weight) * ridgeSlope + (ridge * ridge) * weightSlope;
    value += signal * power;
    slope = slope + power * signalSlope;
    power *= weightStep;
  }
  return value;
}

}  // namespace

double BlenderMusgrave::output(Vec3d position, Vec3d* gradient) const {
  const double detail = std::clamp(params_.detail, 0.0, 15.0);
  const double h = std::max(params_.dimension, 1e-5);
  const double lacunarity = std::max(params_.lacunarity, 1e-5);
  const double weightStep = std::pow(lacunarity, -h);
  const Vec3d p = params_.scale * position;
  const int octaves = static_cast<int>(detail);
  const double rest = detail - std::floor(detail);
  if (params_.type != MusgraveType::kFbm) {
    const MusgraveOctaves at{.dimensions = params_.dimensions,
                             .p = p,
                             .w = params_.scale * params_.w,
                             .lacunarity = lacunarity,
                             .gradient = gradient != nullptr};
    Vec3d slope{};
    double value = 0;
    switch (params_.type) {
      case MusgraveType::kMultifractal:
        value = musgraveMultifractal(at, octaves, rest, weightStep, slope);
        break;
      case MusgraveType::kHeteroTerrain:
        value = musgraveHeteroTerrain(at, octaves, rest, weightStep, params_.offset, slope);
        break;
      case MusgraveType::kHybridMultifractal:
        value = musgraveHybrid(at, octaves, rest, weightStep, params_.offset, params_.gain, slope);
        break;
      default:
        value = musgraveRidged(at, octaves, weightStep, params_.offset, params_.gain, slope);
        break;
    }
    if (gradient != nullptr) *gradient = params_.scale * slope;
    return value;
  }
  const double w = params_.scale * params_.w;
  double value = 0, weight = 1, frequency = 1;
  Vec3d slope{};
  const auto add = [&](double factor) {
    Vec3d g;
    value += factor * weight *
             signedNoiseOf(params_.dimensions, frequency * p, frequency * w, gradient ? &g : nullptr);
    if (gradient != nullptr) slope = slope + (factor * weight * frequency) * g;
  };
  for (int i = 0; i < octaves; ++i) {
    add(1);
    weight *= weightStep;
    frequency *= lacunarity;
  }
  if (rest != 0) add(rest);
  if (gradient != nullptr) *gradient = params_.scale * slope;
  return value;
}

namespace {

/// Voronoi's Distance to Edge at @p local (within its cell), the points of the cells at offsets
/// o ∈ {−1, 0, 1}³ given by @p pointAt(o); if @p gradient, its gradient times @p scale.
template <class PointAt>
double voronoiDistanceToEdge(Vec3d local, const PointAt& pointAt, double scale, Vec3d* gradient) {
  const auto each = [](const auto& visit) {
    for (int k = -1; k <= 1; ++k) {
      for (int j = -1; j <= 1; ++j) {
        for (int i = -1; i <= 1; ++i) visit(Vec3d{double(i), double(j), double(k)});
      }
    }
  };
  Vec3d toNearest{};
  double nearest = 8;  // Cycles' start, a squared distance
  each([&](Vec3d offset) {
    const Vec3d v = pointAt(offset) - local;
    const double d = dot(v, v);
    if (d < nearest) {
      nearest = d;
      toNearest = v;
    }
  });
  double best = 8;
  Vec3d normal{};
  each([&](Vec3d offset) {
    const Vec3d v = pointAt(offset) - local;
    const Vec3d across = v - toNearest;
    const double length2 = dot(across, across);
    if (length2 > 1e-4) {
      const Vec3d n = (1 / std::sqrt(length2)) * across;
      const double d = dot(0.5 * (toNearest + v), n);
      if (d < best) {
        best = d;
        normal = n;
      }
    }
  });
  if (gradient != nullptr) *gradient = -scale * normal;
  return best;
}

}  // namespace

Result<BlenderVoronoi> BlenderVoronoi::create(const BlenderVoronoiParams& params) {
  if (Status finite = finiteSettings(
          "Voronoi Texture",
          {params.amplitude, params.scale, params.randomness, params.exponent, params.smoothness});
      !finite)
    return finite.error();
  if (params.metric == VoronoiMetric::kMinkowski &&
      params.feature != VoronoiFeature::kDistanceToEdge && !(params.exponent > 0)) {
    return Error::badInput("a Voronoi Texture's Minkowski exponent must be greater than 0");
  }
  if (Status bounded = boundedSlopes("Voronoi Texture",
                                     std::abs(params.amplitude) * std::abs(params.scale) * 2, "");
      !bounded)
    return bounded.error();
  return BlenderVoronoi(params);
}

double BlenderVoronoi::output(Vec3d position, Vec3d* gradient) const {
  const Vec3d p = params_.scale * position;
  const Vec3d cell{std::floor(p.x), std::floor(p.y), std::floor(p.z)};
  const Vec3d local = p - cell;
  const double randomness = std::clamp(params_.randomness, 0.0, 1.0);
  const double e = params_.exponent;
  // The metric's distance of d = local − point, and its gradient with respect to local.
  const auto measure = [&](Vec3d d, Vec3d* slope) {
    const Vec3d a{std::abs(d.x), std::abs(d.y), std::abs(d.z)};
    const Vec3d sign{d.x < 0 ? -1.0 : 1.0, d.y < 0 ? -1.0 : 1.0, d.z < 0 ? -1.0 : 1.0};
    switch (params_.metric) {
      case VoronoiMetric::kManhattan:
        if (slope) *slope = sign;
        return a.x + a.y + a.z;
      case VoronoiMetric::kChebyshev: {
        const double m = std::max({a.x, a.y, a.z});
        if (slope) {
          *slope = a.x == m   ? Vec3d{sign.x, 0, 0}
                   : a.y == m ? Vec3d{0, sign.y, 0}
                              : Vec3d{0, 0, sign.z};
        }
        return m;
      }
      case VoronoiMetric::kMinkowski: {
        const double sum = std::pow(a.x, e) + std::pow(a.y, e) + std::pow(a.z, e);
        const double r = std::pow(sum, 1 / e);
        if (slope) {
          const auto part = [&](double v, double s) {
            return v > 0 ? s * std::pow(v, e - 1) * std::pow(sum, 1 / e - 1) : 0.0;
          };
          *slope = {part(a.x, sign.x), part(a.y, sign.y), part(a.z, sign.z)};
        }
        return r;
      }
      default: {
        const double r = std::sqrt(dot(d, d));
        if (slope) *slope = r > 0 ? (1 / r) * d : Vec3d{};
        return r;
      }
    }
  };
  const auto pointAt = [&](const Vec3d& offset) {
    return offset + randomness * voronoiCellPoint(cell + offset);
  };
  if (params_.feature == VoronoiFeature::kDistanceToEdge) {
    return voronoiDistanceToEdge(local, pointAt, gradient ? params_.scale : 0.0, gradient);
  }
  if (params_.feature == VoronoiFeature::kSmoothF1) {
    const double s = std::clamp(params_.smoothness / 2, 0.0, 0.5);
    double smooth = 8;  // Cycles' start
    Vec3d smoothSlope{};
    for (int k = -2; k <= 2; ++k) {
      for (int j = -2; j <= 2; ++j) {
        for (int i = -2; i <= 2; ++i) {
          Vec3d slope;
          const double d = measure(local - pointAt({double(i), double(j), double(k)}),
                                   gradient ? &slope : nullptr);
          double h, dh = 0;  // h and ∂h/∂(D − d)
          if (s == 0) {
            h = smooth > d ? 1 : 0;
          } else {
            const double t = 0.5 + 0.5 * (smooth - d) / s;
            h = t < 0 ? 0 : t >= 1 ? 1 : (3 - 2 * t) * (t * t);
            if (t > 0 && t < 1) dh = 6 * t * (1 - t) * 0.5 / s;
          }
          if (gradient != nullptr) {
            const Vec3d hSlope = dh * (smoothSlope - slope);
            smoothSlope = smoothSlope + (d - smooth) * hSlope + h * (slope - smoothSlope) -
                          (s * (1 - 2 * h)) * hSlope;
          }
          smooth = smooth + h * (d - smooth) - s * h * (1 - h);
        }
      }
    }
    if (gradient != nullptr) *gradient = params_.scale * smoothSlope;
    return smooth;
  }
  const bool second = params_.feature == VoronoiFeature::kF2;
  double best = 8;  // Cycles' start: farther than any point of the 27 cells
  double next = 8;  // F2's
  Vec3d bestOffset{}, nextOffset{};
  for (int k = -1; k <= 1; ++k) {
    for (int j = -1; j <= 1; ++j) {
      for (int i = -1; i <= 1; ++i) {
        const Vec3d point = pointAt({double(i), double(j), double(k)});
        const double d = measure(local - point, nullptr);
        if (d < best) {
          next = best;
          nextOffset = bestOffset;
          best = d;
          bestOffset = point;
        } else if (second && d < next) {
          next = d;
          nextOffset = point;
        }
      }
    }
  }
  if (gradient != nullptr) {
    Vec3d slope;
    measure(local - (second ? nextOffset : bestOffset), &slope);
    *gradient = params_.scale * slope;
  }
  return second ? next : best;
}

Result<BlenderWave> BlenderWave::create(const BlenderWaveParams& params) {
  if (Status finite = finiteSettings(
          "Wave Texture", {params.amplitude, params.scale, params.distortion, params.detail,
                           params.detailScale, params.detailRoughness, params.phase});
      !finite)
    return finite.error();
  if ((params.direction == WaveDirection::kDiagonal && params.type != WaveType::kBands) ||
      (params.direction == WaveDirection::kSpherical && params.type != WaveType::kRings)) {
    return Error::badInput(
        "a Wave Texture's direction is diagonal for bands only, spherical "
        "for rings only");
  }
  const double slopes = std::abs(params.amplitude) * std::abs(params.scale) *
                        (20 + std::abs(params.distortion) * std::abs(params.detailScale) *
                                  std::exp2(std::ceil(std::clamp(params.detail, 0.0, 15.0))));
  if (Status bounded = boundedSlopes("Wave Texture", slopes, ""); !bounded) return bounded.error();
  return BlenderWave(params);
}

double BlenderWave::output(Vec3d position, Vec3d* gradient) const {
  // Cycles nudges the scaled coordinates off the unit lattice: p = (scale P + 1e-6) · 0.999999.
  constexpr double kNudge = 0.999999;
  const Vec3d p = kNudge * (params_.scale * position + Vec3d{1e-6, 1e-6, 1e-6});
  double n;
  Vec3d dn;  // ∂n/∂p
  if (params_.type == WaveType::kBands) {
    switch (params_.direction) {
      case WaveDirection::kX:
        n = 20 * p.x, dn = {20, 0, 0};
        break;
      case WaveDirection::kY:
        n = 20 * p.y, dn = {0, 20, 0};
        break;
      case WaveDirection::kZ:
        n = 20 * p.z, dn = {0, 0, 20};
        break;
      default:
        n = 10 * (p.x + p.y + p.z), dn = {10, 10, 10};
        break;  // diagonal
    }
  } else {  // rings around an axis (its coordinate dropped), or spherical
    const Vec3d r{params_.direction == WaveDirection::kX ? 0 : p.x,
                  params_.direction == WaveDirection::kY ? 0 : p.y,
                  params_.direction == WaveDirection::kZ ? 0 : p.z};
    const double length = std::sqrt(dot(r, r));
    n = 20 * length;
    dn = length > 0 ? (20 / length) * r : Vec3d{};
  }
  n += params_.phase;
  if (params_.distortion != 0) {
    Vec3d g;
    const double fbm = blenderFractalNoise(params_.detailScale * p, params_.detail,
                                           params_.detailRoughness, gradient ? &g : nullptr);
    n += params_.distortion * (2 * fbm - 1);
    dn = dn + (2 * params_.distortion * params_.detailScale) * g;
  }
  double value, slope;
  constexpr double kTwoPi = 2 * kPi;
  switch (params_.profile) {
    case WaveProfile::kSine:
      value = 0.5 + 0.5 * std::sin(n - kPi / 2);
      slope = 0.5 * std::cos(n - kPi / 2);
      break;
    case WaveProfile::kSaw: {
      const double t = n / kTwoPi;
      value = t - std::floor(t);
      slope = 1 / kTwoPi;
      break;
    }
    default: {  // triangle: |t − round(t)| · 2
      const double t = n / kTwoPi;
      const double d = t - std::floor(t + 0.5);
      value = std::abs(d) * 2;
      slope = (d < 0 ? -2 : 2) / kTwoPi;
      break;
    }
  }
  if (gradient != nullptr) *gradient = (slope * kNudge * params_.scale) * dn;
  return value;
}

Result<BlenderBrick> BlenderBrick::create(const BlenderBrickParams& params) {
  if (Status finite = finiteSettings(
          "Brick Texture", {params.amplitude, params.scale, params.mortarSize, params.mortarSmooth,
                            params.brickWidth, params.rowHeight, params.offset, params.squash});
      !finite)
    return finite.error();
  if (!(params.brickWidth > 0) || !(params.rowHeight > 0)) {
    return Error::badInput("a Brick Texture's Brick Width and Row Height must be greater than 0");
  }
  if (params.offsetFrequency < 0 || params.squashFrequency < 0) {
    return Error::badInput("a Brick Texture's frequencies must be 0 or more");
  }
  if (params.offsetFrequency != 0 && params.squashFrequency != 0 && !(params.squash > 0)) {
    return Error::badInput("a Brick Texture's Squash must be greater than 0");
  }
  // The smoothstep's steepest slope, 1.5 / (Mortar Size · Mortar Smooth), per unit of p.
  const double smoothing = std::abs(params.mortarSize * params.mortarSmooth);
  const double steepest = smoothing > 0 ? 1.5 / smoothing : 0;
  if (Status bounded = boundedSlopes("Brick Texture",
                                     std::abs(params.amplitude) * std::abs(params.scale) * steepest,
                                     "(amplitude × scale × 1.5 / (mortar size × mortar smooth))");
      !bounded)
    return bounded.error();
  return BlenderBrick(params);
}

double BlenderBrick::output(Vec3d position, Vec3d* gradient) const {
  const BlenderBrickParams& b = params_;
  const double px = b.scale * position.x, py = b.scale * position.y;
  const double row = std::floor(py / b.rowHeight);
  double width = b.brickWidth, offset = 0;
  if (b.offsetFrequency != 0 && b.squashFrequency != 0) {
    // (Rows below zero too: −2 is a multiple of 2.)
    const auto multiple = [row](int frequency) { return std::fmod(row, frequency) == 0; };
    if (multiple(b.squashFrequency)) width *= b.squash;
    if (multiple(b.offsetFrequency)) offset = width * b.offset;
  }
  const double brick = std::floor((px + offset) / width);
  const double x = px + offset - width * brick, y = py - b.rowHeight * row;
  // d, the distance to the brick's nearest edge, and its slope along p's x and y.
  double d = x;
  double dx = 1, dy = 0;
  const auto nearer = [&](double candidate, double cx, double cy) {
    if (candidate < d) d = candidate, dx = cx, dy = cy;
  };
  nearer(y, 0, 1);
  nearer(width - x, -1, 0);
  nearer(b.rowHeight - y, 0, -1);
  double fac = 0, slope = 0;  // slope: dFac / dd
  if (d >= b.mortarSize) {
    fac = 0;
  } else if (b.mortarSmooth == 0) {
    fac = 1;
  } else {
    const double t = (1 - d / b.mortarSize) / b.mortarSmooth;
    if (t < 1) {
      fac = t * t * (3 - 2 * t);
      slope = 6 * t * (1 - t) * (-1 / (b.mortarSize * b.mortarSmooth));
    } else {
      fac = 1;
    }
  }
  if (gradient != nullptr) *gradient = Vec3d{slope * dx, slope * dy, 0} * b.scale;
  return fac;
}

Result<BlenderGradient> BlenderGradient::create(const BlenderGradientParams& params) {
  if (Status finite = finiteSettings("Gradient Texture", {params.amplitude}); !finite)
    return finite.error();
  if (params.type < BlenderGradientType::kLinear || params.type > BlenderGradientType::kRadial) {
    return Error::badInput("a Gradient Texture's type is not one of Blender's seven");
  }
  // The steepest slope per unit of P is 2 (Quadratic, Quadratic Sphere) but Radial's, which
  // grows without bound toward its axis: a point's, not the settings'.
  if (Status bounded =
          boundedSlopes("Gradient Texture", 2 * std::abs(params.amplitude), "(amplitude × 2)");
      !bounded)
    return bounded.error();
  return BlenderGradient(params);
}

double BlenderGradient::output(Vec3d p, Vec3d* gradient) const {
  // Cycles' value before its clamp to [0, 1], and its gradient.
  double value = 0;
  Vec3d slope{};
  switch (params_.type) {
    case BlenderGradientType::kLinear:
      value = p.x, slope = {1, 0, 0};
      break;
    case BlenderGradientType::kQuadratic: {
      const double r = std::max(p.x, 0.0);
      value = r * r, slope = {2 * r, 0, 0};
      break;
    }
    case BlenderGradientType::kEasing: {
      const double r = std::clamp(p.x, 0.0, 1.0);
      value = r * r * (3 - 2 * r), slope = {6 * r * (1 - r), 0, 0};
      break;
    }
    case BlenderGradientType::kDiagonal:
      value = (p.x + p.y) * 0.5, slope = {0.5, 0.5, 0};
      break;
    case BlenderGradientType::kRadial: {
      value = std::atan2(p.y, p.x) / (2 * kPi) + 0.5;
      const double r2 = p.x * p.x + p.y * p.y;
      if (r2 > 0) slope = Vec3d{-p.y, p.x, 0} * (1 / (2 * kPi * r2));
      break;
    }
    case BlenderGradientType::kSpherical:
    case BlenderGradientType::kQuadraticSphere: {
      constexpr double kUnitNudge = 0.999999f;  // Cycles' float, for unit vectors to give 0
      const double length = std::sqrt(p.x * p.x + p.y * p.y + p.z * p.z);
      const double s = std::max(kUnitNudge - length, 0.0);
      // d s / d P = −P / |P| inside the sphere, 0 beyond it and at its centre.
      const Vec3d ds = s > 0 && length > 0 ? p * (-1 / length) : Vec3d{};
      const bool quadratic = params_.type == BlenderGradientType::kQuadraticSphere;
      value = quadratic ? s * s : s;
      slope = quadratic ? ds * (2 * s) : ds;
      break;
    }
  }
  // Cycles' saturate; where it holds the Fac at a bound the gradient is 0.
  const bool clamped = !(value > 0 && value < 1);
  if (gradient != nullptr) *gradient = clamped ? Vec3d{} : slope;
  return std::clamp(value, 0.0, 1.0);
}

Result<BlenderMagic> BlenderMagic::create(const BlenderMagicParams& params) {
  if (Status finite =
          finiteSettings("Magic Texture", {params.amplitude, params.scale, params.distortion});
      !finite)
    return finite.error();
  if (params.depth < 0 || params.depth > kBlenderMagicMaxDepth) {
    return Error::badInput("a Magic Texture's Depth must be an integer from 0 to " +
                           std::to_string(kBlenderMagicMaxDepth));
  }
  // Each step's sine or cosine of three values, each d times a sine or cosine: 3|d| times its
  // inputs' slopes; at Depth 0 the division by 2d is not balanced by a product.
  const double d = std::abs(params.distortion);
  double slopes = std::abs(params.amplitude) * std::abs(params.scale) * 5 * std::sqrt(3.0) *
                  std::pow(std::max(1.0, 3 * d), params.depth);
  if (params.depth == 0 && d != 0) slopes /= 2 * d;
  if (Status bounded = boundedSlopes(
          "Magic Texture", slopes,
          "(amplitude × scale × 5√3 × max(1, 3 |distortion|)^depth, / 2 |distortion| at depth 0)");
      !bounded)
    return bounded.error();
  return BlenderMagic(params);
}

namespace {

/// A value and its gradient with respect to P, carried through the Magic Texture's steps.
struct MagicTerm {
  double value;
  Vec3d slope;
};

/// One of the Magic Texture's steps: component `target` (0 x, 1 y, 2 z) becomes `sign` times the
/// sine (else the cosine) of Σ signs[k] · (x, y, z)[k].
struct MagicStep {
  int target;
  double sign;
  bool sine;
  double signs[3];
};

/// Cycles 3.4's ten steps, in order; Depth n takes the first n.
constexpr MagicStep kMagicSteps[kBlenderMagicMaxDepth] = {
    {1, -1, false, {1, -1, 1}},  {0, 1, false, {1, -1, -1}}, {2, 1, true, {-1, -1, -1}},
    {0, -1, false, {-1, 1, -1}}, {1, -1, true, {-1, 1, 1}},  {1, -1, false, {-1, 1, 1}},
    {0, 1, false, {1, 1, 1}},    {2, 1, true, {1, 1, -1}},   {0, -1, false, {-1, -1, 1}},
    {1, -1, true, {1, -1, 1}}};

/// sign · sin(a) (else sign · cos(a)) of a term a, with its gradient.
MagicTerm magicWave(double sign, bool sine, const MagicTerm& a) {
  const double s = std::sin(a.value), c = std::cos(a.value);
  return sine ? MagicTerm{sign * s, a.slope * (sign * c)}
              : MagicTerm{sign * c, a.slope * (-sign * s)};
}

}  // namespace

double BlenderMagic::output(Vec3d position, Vec3d* gradient) const {
  const BlenderMagicParams& m = params_;
  const Vec3d p = position * m.scale;
  const double k = 5 * m.scale;  // d(5 p) / dP
  MagicTerm t[3] = {magicWave(1, true, {5 * (p.x + p.y + p.z), Vec3d{1, 1, 1} * k}),
                    magicWave(1, false, {5 * (-p.x + p.y - p.z), Vec3d{-1, 1, -1} * k}),
                    magicWave(-1, false, {5 * (-p.x - p.y + p.z), Vec3d{-1, -1, 1} * k})};
  const double d = m.distortion;
  const auto distort = [d](MagicTerm& term) {
    term.value *= d;
    term.slope = term.slope * d;
  };
  if (m.depth > 0) {
    for (MagicTerm& term : t) distort(term);
  }
  for (int i = 0; i < m.depth; ++i) {
    const MagicStep& step = kMagicSteps[i];
    MagicTerm argument{0, Vec3d{}};
    for (int c = 0; c < 3; ++c) {
      argument.value += step.signs[c] * t[c].value;
      argument.slope = argument.slope + t[c].slope * step.signs[c];
    }
    t[step.target] = magicWave(step.sign, step.sine, argument);
    distort(t[step.target]);
  }
  // Color = ½ − (x, y, z) / 2d (d ≠ 0), Fac its mean.
  const double divisor = d != 0 ? 3 * (2 * d) : 3;
  const double sum = t[0].value + t[1].value + t[2].value;
  if (gradient != nullptr) *gradient = (t[0].slope + t[1].slope + t[2].slope) * (-1 / divisor);
  return 0.5 - sum / divisor;
}

}  // namespace sgbake
