/// @file volume.cpp
/// @brief Procedural height volumes (directional sine, gradient noise) and finite-difference
/// volume gradients. See volume.hpp for the definitions and error analysis.
#include "sgbake/gradient/volume.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <string>

#include "sgbake/core/math.hpp"

namespace sgbake {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kMaxFinite = std::numeric_limits<double>::max();

bool hasNaN(Vec3d p) { return std::isnan(p.x) || std::isnan(p.y) || std::isnan(p.z); }

// ------------------------------------------------------------------------------------------------
// Hash
// ------------------------------------------------------------------------------------------------

/// Odd 64-bit constant ⌊2^64/φ⌋ (golden ratio), the usual Weyl-sequence increment: spaces the
/// per-octave inputs of the key derivation far apart.
constexpr std::uint64_t kGoldenGamma = 0x9E3779B97F4A7C15ull;

/// @brief Bijective 64-bit avalanche mixer: two rounds of xor-shift-right then multiply by an
/// odd constant, and a final xor-shift (shifts 30/27/31 and the multipliers of Stafford's
/// "Mix13" finalizer). Every input bit affects every output bit; being a bijection, distinct
/// inputs never collide.
constexpr std::uint64_t mix64(std::uint64_t z) {
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

/// Key of octave @p octave for @p seed (see GradientNoise: key_o = mix(seed + (o+1)·γ)).
constexpr std::uint64_t octaveKey(std::uint64_t seed, int octave) {
  return mix64(seed + static_cast<std::uint64_t>(octave + 1) * kGoldenGamma);
}

// ------------------------------------------------------------------------------------------------
// Gradient directions: a spherical Fibonacci set, built at compile time
// ------------------------------------------------------------------------------------------------

/// Number of lattice gradient directions (the hash's top kGradientIndexBits bits pick one).
constexpr int kGradientIndexBits = 8;
constexpr std::size_t kNumGradients = std::size_t{1} << kGradientIndexBits;

/// sqrt by Newton's iteration from above (compile-time only; x ≥ 0).
constexpr double constexprSqrt(double x) {
  if (!(x > 0)) return 0;
  double r = x > 1 ? x : 1;  // ≥ sqrt(x): the iteration then decreases monotonically
  for (int i = 0; i < 2000; ++i) {
    const double next = 0.5 * (r + x / r);
    if (!(next < r)) break;
    r = next;
  }
  return r;
}

/// sin and cos of @p a ∈ [−π, π] by their Taylor series (compile-time only; the largest term
/// is π³/6 ≈ 5, so the absolute error is a few 1e-16).
constexpr void constexprSinCos(double a, double& s, double& c) {
  constexpr int kTerms = 40;  // π^40/40! ≈ 1e-28
  s = 0;
  c = 0;
  double term = 1;  // a^n / n!
  for (int n = 0; n < kTerms; ++n) {
    switch (n % 4) {
      case 0:
        c += term;
        break;
      case 1:
        s += term;
        break;
      case 2:
        c -= term;
        break;
      default:
        s -= term;
        break;
    }
    term *= a / (n + 1);
  }
}

/// Direction k of the spherical Fibonacci set of @p n points: z evenly spaced in (−1, 1),
/// azimuth advancing by the golden fraction of a turn. Nearly uniform over the sphere, with no
/// preferred axis (unlike the 12 cube-edge directions of Perlin's improved noise).
constexpr std::array<Vec3d, kNumGradients> makeGradientTable() {
  constexpr double kPiLocal = 3.14159265358979323846;
  const double goldenFraction = (constexprSqrt(5.0) - 1.0) / 2.0;  // 1/φ
  std::array<Vec3d, kNumGradients> table{};
  for (std::size_t k = 0; k < kNumGradients; ++k) {
    const double kd = static_cast<double>(k);
    const double z = 1.0 - (2.0 * kd + 1.0) / static_cast<double>(kNumGradients);
    const double r = constexprSqrt(1.0 - z * z);
    const double turns = kd * goldenFraction;
    const double fraction = turns - static_cast<double>(static_cast<std::uint64_t>(turns));
    double s = 0, c = 0;
    constexprSinCos(2.0 * kPiLocal * fraction - kPiLocal, s, c);
    const Vec3d g{r * c, r * s, z};
    table[k] = (1.0 / constexprSqrt(dot(g, g))) * g;
  }
  return table;
}

constexpr std::array<Vec3d, kNumGradients> kGradientTable = makeGradientTable();

constexpr bool gradientsAreUnit() {
  for (const Vec3d& g : kGradientTable) {
    const double len2 = dot(g, g);
    if (len2 < 1.0 - 1e-14 || len2 > 1.0 + 1e-14) return false;
  }
  return true;
}
static_assert(gradientsAreUnit(),
              "lattice gradients must be unit vectors (the bound relies on it)");

// ------------------------------------------------------------------------------------------------
// One octave of lattice noise
// ------------------------------------------------------------------------------------------------

/// Quintic fade s(t) = 6t⁵ − 15t⁴ + 10t³ (Horner form).
constexpr double fade(double t) { return t * t * t * (t * (t * 6.0 - 15.0) + 10.0); }

/// s'(t) = 30t⁴ − 60t³ + 30t² = 30 t² (t − 1)².
constexpr double fadeDerivative(double t) {
  const double tm1 = t - 1.0;
  return 30.0 * t * t * tm1 * tm1;
}

/// Value and gradient (w.r.t. lattice coordinates x) of one octave.
struct LatticeSample {
  double value = 0;
  Vec3d gradient{};
};

/// @brief n(x) of one octave with key @p key; with @p kWithGradient also ∇ₓn (exact).
/// @note Precondition: x has no NaN component (infinite ones are clamped).
template <bool kWithGradient>
LatticeSample latticeNoise(Vec3d x, std::uint64_t key) {
  std::array<std::uint64_t, 3> cell{};  // ⌊x⌋ as two's-complement bits
  Vec3d t{};                            // x − ⌊x⌋ ∈ [0, 1]
  for (std::size_t a = 0; a < 3; ++a) {
    const double xc = std::clamp(x[a], -GradientNoise::kMaxLatticeCoordinate,
                                 GradientNoise::kMaxLatticeCoordinate);
    const double floorX = std::floor(xc);
    cell[a] = static_cast<std::uint64_t>(static_cast<std::int64_t>(floorX));
    // Exact for x ≥ 0 (Sterbenz); for x < 0 it may round, up to 1.0 for x = −tiny, which is
    // harmless: t = 1 in cell i is the same point as t = 0 in cell i + 1, and n is C² there.
    t[a] = xc - floorX;
  }

  // Per axis a and corner side c ∈ {0, 1}: weight w[a][c] and its derivative dw[a][c].
  double w[3][2];
  double dw[3][2];
  for (std::size_t a = 0; a < 3; ++a) {
    const double s = fade(t[a]);
    const double ds = fadeDerivative(t[a]);
    w[a][0] = 1.0 - s;
    w[a][1] = s;
    dw[a][0] = -ds;
    dw[a][1] = ds;
  }

  LatticeSample out;
  for (std::uint64_t cx = 0; cx < 2; ++cx) {
    const std::uint64_t hx = mix64(key ^ (cell[0] + cx));
    for (std::uint64_t cy = 0; cy < 2; ++cy) {
      const std::uint64_t hxy = mix64(hx ^ (cell[1] + cy));
      for (std::uint64_t cz = 0; cz < 2; ++cz) {
        const std::uint64_t h = mix64(hxy ^ (cell[2] + cz));
        const Vec3d& g = kGradientTable[h >> (64 - kGradientIndexBits)];
        const Vec3d d{t.x - static_cast<double>(cx), t.y - static_cast<double>(cy),
                      t.z - static_cast<double>(cz)};
        const double ramp = dot(g, d);  // the corner's linear function ⟨G, t − c⟩
        const double wx = w[0][cx], wy = w[1][cy], wz = w[2][cz];
        const double weight = wx * wy * wz;
        out.value += weight * ramp;
        if constexpr (kWithGradient) {
          // ∇(W·ramp) = W·G + ramp·∇W, ∇W = (w'x wy wz, wx w'y wz, wx wy w'z).
          out.gradient += weight * g;
          out.gradient +=
              ramp * Vec3d{dw[0][cx] * wy * wz, wx * dw[1][cy] * wz, wx * wy * dw[2][cz]};
        }
      }
    }
  }
  return out;
}

/// A tap coordinate clamped into the finite range: only matters within a step of ±DBL_MAX, so
/// that a finite P never hands ±inf to a volume. (NaN never gets here: volumeGradient returns
/// early for NaN input, since fmin/fmax would turn NaN into a bound.)
inline double finiteCoordinate(double v) {
  return std::fmin(std::fmax(v, -kMaxFinite), kMaxFinite);
}

/// Tetrahedron vertices k_1 … k_4 of seed 002.
constexpr std::array<Vec3d, 4> kTetrahedron{{{1, -1, -1}, {-1, -1, 1}, {-1, 1, -1}, {1, 1, 1}}};
/// Σ k kᵀ = kTetrahedralNorm · I: the divisor of the tetrahedral scheme (seed 002's factor 4).
constexpr double kTetrahedralNorm = 4.0;

/// Checks the two identities the tetrahedral scheme rests on: Σ k = 0 (h(P) cancels) and
/// Σ k kᵀ = kTetrahedralNorm · I (the first-order terms give kTetrahedralNorm · ∇h).
constexpr bool tetrahedronIdentitiesHold() {
  for (std::size_t a = 0; a < 3; ++a) {
    double sum = 0;
    for (const Vec3d& k : kTetrahedron) sum += k[a];
    if (sum != 0) return false;
    for (std::size_t b = 0; b < 3; ++b) {
      double outer = 0;
      for (const Vec3d& k : kTetrahedron) outer += k[a] * k[b];
      if (outer != (a == b ? kTetrahedralNorm : 0.0)) return false;
    }
  }
  return true;
}
static_assert(tetrahedronIdentitiesHold(), "Σk = 0 and Σk kᵀ = 4I");

// The taps are written out rather than looped over: a loop that patched one component of a
// Vec3d copy per tap measured up to twice as slow here (perf put the time on reloading the
// stack-passed Vec3d in value()).

Vec3d centralGradient(const HeightVolume& volume, Vec3d p, double step) {
  const double xp = finiteCoordinate(p.x + step), xm = finiteCoordinate(p.x - step);
  const double yp = finiteCoordinate(p.y + step), ym = finiteCoordinate(p.y - step);
  const double zp = finiteCoordinate(p.z + step), zm = finiteCoordinate(p.z - step);
  const double dx = volume.value({xp, p.y, p.z}) - volume.value({xm, p.y, p.z});
  const double dy = volume.value({p.x, yp, p.z}) - volume.value({p.x, ym, p.z});
  const double dz = volume.value({p.x, p.y, zp}) - volume.value({p.x, p.y, zm});
  const double span = 2.0 * step;
  return {dx / span, dy / span, dz / span};
}

Vec3d tetrahedralGradient(const HeightVolume& volume, Vec3d p, double step) {
  const double xp = finiteCoordinate(p.x + step), xm = finiteCoordinate(p.x - step);
  const double yp = finiteCoordinate(p.y + step), ym = finiteCoordinate(p.y - step);
  const double zp = finiteCoordinate(p.z + step), zm = finiteCoordinate(p.z - step);
  const double h1 = volume.value({xp, ym, zm});  // k_1 = ( 1, −1, −1)
  const double h2 = volume.value({xm, ym, zp});  // k_2 = (−1, −1,  1)
  const double h3 = volume.value({xm, yp, zm});  // k_3 = (−1,  1, −1)
  const double h4 = volume.value({xp, yp, zp});  // k_4 = ( 1,  1,  1)
  // Σ k_i h_i, component by component.
  const double sx = (h1 - h2) + (h4 - h3);
  const double sy = (h3 - h1) + (h4 - h2);
  const double sz = (h2 - h1) + (h4 - h3);
  const double denominator = kTetrahedralNorm * step;
  return {sx / denominator, sy / denominator, sz / denominator};
}

}  // namespace

// ------------------------------------------------------------------------------------------------
// DirectionalSine
// ------------------------------------------------------------------------------------------------

Result<DirectionalSine> DirectionalSine::create(const DirectionalSineParams& params) {
  if (!std::isfinite(params.amplitude) || !std::isfinite(params.frequency) ||
      !std::isfinite(params.phase)) {
    return Error::badInput("directional sine: amplitude, frequency and phase must be finite");
  }
  if (!isFinite(params.direction) || !notZero(params.direction)) {
    return Error::badInput("directional sine: direction must be a finite, nonzero vector");
  }
  const double angularFrequency = 2.0 * kPi * params.frequency;
  if (!(std::abs(params.amplitude) <= kMaxVolumeScale) ||
      !(std::abs(params.amplitude * angularFrequency) <= kMaxVolumeScale)) {
    return Error::badInput("directional sine: amplitude or amplitude*2*pi*frequency exceeds 1e300");
  }
  const Vec3d unit = normalizeOr(params.direction, Vec3d{});
  return DirectionalSine(params.amplitude, angularFrequency, unit, params.phase);
}

double DirectionalSine::argument(Vec3d p) const {
  // ⟨d̂,P⟩ may overflow to ±inf for finite P (|⟨d̂,P⟩| ≤ √3·DBL_MAX), and 0·inf would be NaN
  // when f = 0: clamp it to the finite range first. ω·⟨d̂,P⟩ may still overflow to ±inf, which
  // the phase clamp (kMaxPhase) turns back into a finite argument.
  const double along = std::clamp(dot(direction_, p), -kMaxFinite, kMaxFinite);
  return std::clamp(angularFrequency_ * along, -kMaxPhase, kMaxPhase) + phase_;
}

double DirectionalSine::value(Vec3d p) const { return amplitude_ * std::sin(argument(p)); }

Vec3d DirectionalSine::analyticGradient(Vec3d p) const {
  return (amplitude_ * angularFrequency_ * std::cos(argument(p))) * direction_;
}

// ------------------------------------------------------------------------------------------------
// GradientNoise
// ------------------------------------------------------------------------------------------------

GradientNoise::GradientNoise(const GradientNoiseParams& params) : params_(params) {
  for (int o = 0; o < params.octaves; ++o) {
    octaveKeys_[static_cast<std::size_t>(o)] = octaveKey(params.seed, o);
  }
}

Result<GradientNoise> GradientNoise::create(const GradientNoiseParams& params) {
  if (!std::isfinite(params.amplitude)) {
    return Error::badInput("gradient noise: amplitude must be finite");
  }
  if (!(params.frequency > 0) || !std::isfinite(params.frequency)) {
    return Error::badInput("gradient noise: frequency must be finite and positive");
  }
  if (params.octaves < 1 || params.octaves > kMaxNoiseOctaves) {
    return Error::badInput("gradient noise: octaves must be in 1.." +
                           std::to_string(kMaxNoiseOctaves));
  }
  const double finestFrequency = std::ldexp(params.frequency, params.octaves - 1);
  if (!(std::abs(params.amplitude) * finestFrequency <= kMaxVolumeScale) ||
      !(std::abs(params.amplitude) <= kMaxVolumeScale)) {
    return Error::badInput("gradient noise: amplitude*frequency*2^(octaves-1) exceeds 1e300");
  }
  return GradientNoise(params);
}

double GradientNoise::value(Vec3d p) const {
  if (hasNaN(p)) return kNaN;
  double sum = 0;
  double frequency = params_.frequency;
  double amplitude = params_.amplitude;
  for (int o = 0; o < params_.octaves; ++o) {
    sum += amplitude *
           latticeNoise<false>(frequency * p, octaveKeys_[static_cast<std::size_t>(o)]).value;
    frequency *= kNoiseLacunarity;
    amplitude *= kNoiseGain;
  }
  return sum;
}

Vec3d GradientNoise::analyticGradient(Vec3d p) const {
  if (hasNaN(p)) return {kNaN, kNaN, kNaN};
  Vec3d sum{};
  double frequency = params_.frequency;
  double amplitude = params_.amplitude;
  for (int o = 0; o < params_.octaves; ++o) {
    const LatticeSample s =
        latticeNoise<true>(frequency * p, octaveKeys_[static_cast<std::size_t>(o)]);
    sum += (amplitude * frequency) * s.gradient;  // chain rule: ∂x/∂P = frequency
    frequency *= kNoiseLacunarity;
    amplitude *= kNoiseGain;
  }
  return sum;
}

double GradientNoise::valueBound() const {
  double octaveSum = 0;
  double gain = 1;
  for (int o = 0; o < params_.octaves; ++o) {
    octaveSum += gain;
    gain *= kNoiseGain;
  }
  return std::abs(params_.amplitude) * kNoiseOctaveBound * octaveSum;
}

// ------------------------------------------------------------------------------------------------
// Gradients
// ------------------------------------------------------------------------------------------------

double defaultStep(double objectSize) {
  const double size = (objectSize > 0 && std::isfinite(objectSize)) ? objectSize : 1.0;
  return std::clamp(kDefaultRelativeStep * size, kMinGradientStep, kMaxGradientStep);
}

Vec3d volumeGradient(const HeightVolume& volume, Vec3d p, GradientScheme scheme, double step) {
  if (scheme == GradientScheme::kAnalytic) return volume.analyticGradient(p);
  if (std::isnan(step) || hasNaN(p)) return {kNaN, kNaN, kNaN};
  const double e = std::clamp(std::abs(step), kMinGradientStep, kMaxGradientStep);
  return scheme == GradientScheme::kCentral ? centralGradient(volume, p, e)
                                            : tetrahedralGradient(volume, p, e);
}

Vec3d surfaceGradientFromVolume(Vec3d gradH, Vec3d N) { return gradH - dot(gradH, N) * N; }

}  // namespace sgbake
