/// @file volume.hpp
/// @brief Procedural height volumes h(P) in object space and their volume gradients ∇h.
///
/// A height volume is a scalar field over object space (seed 001, "Height Maps and Volumes"):
/// every point P has a height h(P). Bumping a surface with it needs the volume gradient ∇h at
/// the surface point, projected onto the tangent plane (seed 001 eq. 30):
///
///     Γ = ∇h − ⟨∇h, N⟩ N.
///
/// ∇h comes either from the field's exact derivative (GradientScheme::kAnalytic) or from finite
/// differences of h (kCentral: 6 taps; kTetrahedral: the 4-tap scheme of seed 002). The finite
/// differences work for any HeightVolume, including ones without an analytic gradient.
///
/// Units: positions and steps are object-space lengths (the mesh's units); heights are in the
/// same length unit (a height of 0.1 displaces by 0.1 along N); gradients are height per length
/// (dimensionless).
///
/// Thread safety: every HeightVolume here is immutable after construction; value() and
/// analyticGradient() may be called from any number of threads at once and return the same bits
/// for the same input, whatever the thread.
#pragma once

#include <array>
#include <cstdint>
#include <limits>

#include "sgbake/core/result.hpp"
#include "sgbake/core/vec.hpp"

namespace sgbake {

/// @brief A height and its gradient at one point.
struct VolumeSample {
  double value = 0;
  Vec3d gradient{};
};

/// @brief A scalar height field over object space.
///
/// @note Contract for implementations: value() and analyticGradient() are thread-safe, do not
/// allocate, and return finite numbers for every finite input (NaN input may give NaN).
/// analyticGradient() is the exact derivative of the function value() implements (not of some
/// idealisation of it), up to floating-point rounding.
class HeightVolume {
 public:
  virtual ~HeightVolume() = default;

  /// @brief h(P): the height at object-space point @p p.
  virtual double value(Vec3d p) const = 0;

  /// @brief ∇h(P) = (∂h/∂x, ∂h/∂y, ∂h/∂z), object space, height per unit length.
  virtual Vec3d analyticGradient(Vec3d p) const = 0;

  /// @brief value() and analyticGradient() at once, the same bits as each: volumes that compute
  /// both together (Blender's textures) override it to evaluate once.
  virtual VolumeSample sample(Vec3d p) const { return {value(p), analyticGradient(p)}; }

 protected:
  HeightVolume() = default;
  HeightVolume(const HeightVolume&) = default;
  HeightVolume(HeightVolume&&) = default;
  HeightVolume& operator=(const HeightVolume&) = default;
  HeightVolume& operator=(HeightVolume&&) = default;
};

/// Largest |height| or |slope| scale a procedural volume accepts at construction. Keeping heights
/// and gradients below 1e300 keeps sums and differences of a few of them finite.
inline constexpr double kMaxVolumeScale = 1e300;

// ------------------------------------------------------------------------------------------------
// Directional sine
// ------------------------------------------------------------------------------------------------

/// @brief Parameters of DirectionalSine::create.
struct DirectionalSineParams {
  double amplitude = 1;      ///< A: peak height, object-space length; any finite value
  double frequency = 1;      ///< f: cycles per object-space unit along d̂; any finite value
  Vec3d direction{1, 0, 0};  ///< d: wave direction, any nonzero finite length (normalized here)
  double phase = 0;          ///< φ: radians
};

/// @brief Plane wave h(P) = A · sin(2π f ⟨d̂, P⟩ + φ), d̂ = d / |d|.
///
/// ∇h(P) = A · 2πf · cos(2π f ⟨d̂, P⟩ + φ) · d̂ — the reference field of the tests: its surface
/// gradient on a sphere has a closed form.
///
/// Far from the origin: once |2πf⟨d̂,P⟩| exceeds kMaxPhase (2^62 rad, where adjacent doubles
/// are already radians apart and the wave is no longer resolved) the phase is clamped, so the
/// field stays finite (constant along d̂ out there) for every finite P.
class DirectionalSine final : public HeightVolume {
 public:
  /// Phase magnitude beyond which 2πf⟨d̂,P⟩ is clamped (see the class note).
  static constexpr double kMaxPhase = 0x1p62;

  /// @brief Validates @p params and builds the field.
  /// @return kBadInput when the direction is zero (or denormal), or any parameter is not finite,
  /// or |A| or |A·2πf| exceeds kMaxVolumeScale.
  static Result<DirectionalSine> create(const DirectionalSineParams& params);

  double value(Vec3d p) const override;
  Vec3d analyticGradient(Vec3d p) const override;

  double amplitude() const { return amplitude_; }
  /// ω = 2πf, radians per object-space unit.
  double angularFrequency() const { return angularFrequency_; }
  /// d̂, unit length.
  Vec3d direction() const { return direction_; }
  double phase() const { return phase_; }

 private:
  DirectionalSine(double amplitude, double angularFrequency, Vec3d unitDirection, double phase)
      : amplitude_(amplitude),
        angularFrequency_(angularFrequency),
        direction_(unitDirection),
        phase_(phase) {}

  /// The sine's argument ω⟨d̂,P⟩ + φ, clamped as described in the class note.
  double argument(Vec3d p) const;

  double amplitude_;
  double angularFrequency_;
  Vec3d direction_;
  double phase_;
};

// ------------------------------------------------------------------------------------------------
// Gradient noise
// ------------------------------------------------------------------------------------------------

/// Most octaves GradientNoise accepts.
inline constexpr int kMaxNoiseOctaves = 16;
/// Frequency ratio between successive fBm octaves.
inline constexpr double kNoiseLacunarity = 2.0;
/// Amplitude ratio between successive fBm octaves.
inline constexpr double kNoiseGain = 0.5;
/// Bound on |n(x)| for one octave of unit-amplitude lattice noise: √3/2 (proof at GradientNoise).
inline constexpr double kNoiseOctaveBound = 0.86602540378443864676;

/// @brief Parameters of GradientNoise::create.
struct GradientNoiseParams {
  double amplitude = 1;    ///< A: height scale of the first octave, object-space length
  double frequency = 1;    ///< F > 0: lattice cells per object-space unit of the first octave
  std::uint64_t seed = 0;  ///< selects the field; every seed gives a different lattice
  int octaves = 1;         ///< 1 .. kMaxNoiseOctaves
};

/// @brief Perlin-style gradient noise with optional fBm octaves.
///
/// h(P) = Σ_{o<octaves} A·g^o · n_o(F·λ^o · P), λ = kNoiseLacunarity = 2, g = kNoiseGain = 0.5,
/// where each octave n_o is lattice gradient noise with its own key (derived from the seed and
/// o, so octaves are uncorrelated):
///
///     n(x) = Σ_{c ∈ {0,1}³} W_c(t) · ⟨G(i + c), t − c⟩,   i = ⌊x⌋, t = x − i ∈ [0,1)³,
///     W_c(t) = Π_axes (c_a ? s(t_a) : 1 − s(t_a)),   s(t) = 6t⁵ − 15t⁴ + 10t³.
///
/// - **Fade** s: quintic, s(0)=0, s(1)=1, s' and s'' vanish at 0 and 1, so n is C² across cell
///   faces (a cubic fade would only give C¹).
/// - **Gradients** G(i): unit vectors, one of 256 directions spread over the sphere (a spherical
///   Fibonacci set computed at compile time), picked by the top 8 bits of a 64-bit hash of the
///   integer cell coordinates and the octave key — no permutation table. The hash feeds each
///   coordinate (as a 64-bit two's-complement integer) through a bijective xor-shift/multiply
///   avalanche mixer, nested x → y → z so neighbouring corners share work:
///   `H = mix(mix(mix(key ^ ix) ^ iy) ^ iz)`; `key_o = mix(seed + (o+1)·0x9E3779B97F4A7C15)`.
///   `mix` is the well-known 64-bit finalizer shape (xor-shift 30/27/31, multiply by two odd
///   constants; the constants of Stafford's "Mix13"), written here from that description.
/// - **Zero at lattice points**: at integer x, t = 0, so the corner term ⟨G, 0⟩ = 0 and all other
///   corners have weight 0: n = 0 exactly. For fBm every first-octave lattice point (P with F·P
///   integer) is a lattice point of all octaves, so h = 0 there as well.
/// - **Bound**: |n| ≤ Σ W_c |t − c| ≤ (Σ W_c |t − c|²)^½ (Jensen; W_c ≥ 0, Σ W_c = 1)
///   = (Σ_a φ(t_a))^½ with φ(t) = t² + s(t)(1 − 2t) = ¼ + u² − 2u(s(t) − ½), u = t − ½; since
///   s(t) − ½ ≥ u for t ≥ ½ (and symmetrically below), φ ≤ ¼, so |n| ≤ √3/2 = kNoiseOctaveBound.
///   Hence |h| ≤ valueBound() = |A| · √3/2 · Σ g^o < |A|·√3.
/// - **Analytic gradient**: the product rule on the formula above (∂W_c/∂t_a uses
///   s'(t) = 30t²(t − 1)²) plus Σ W_c G(i + c), times the chain-rule factor F·λ^o per octave:
///   exact for the implemented function.
/// - **Far from the origin**: lattice coordinates are clamped to ±2^62 cells so the integer
///   conversion is defined for every finite P; beyond 2^52 cells every double is a lattice point,
///   the value there is 0 and the gradient is Σ_o A·g^o·F·λ^o·G_o of that point (finite).
///
/// Cost: one octave of value() is 14 hash mixes, 8 table reads and 8 dot products, no allocation.
class GradientNoise final : public HeightVolume {
 public:
  /// Lattice coordinates are clamped to ±kMaxLatticeCoordinate before the integer conversion.
  static constexpr double kMaxLatticeCoordinate = 0x1p62;

  /// @brief Validates @p params and builds the field.
  /// @return kBadInput when the frequency is not finite and positive, the amplitude is not
  /// finite, octaves is outside 1..kMaxNoiseOctaves, or the finest octave's slope scale
  /// |A|·F·λ^(octaves−1) exceeds kMaxVolumeScale.
  static Result<GradientNoise> create(const GradientNoiseParams& params);

  double value(Vec3d p) const override;
  Vec3d analyticGradient(Vec3d p) const override;

  /// @brief Bound on |value(p)| over all p: |A| · kNoiseOctaveBound · Σ_{o<octaves} g^o.
  double valueBound() const;

  const GradientNoiseParams& params() const { return params_; }

 private:
  explicit GradientNoise(const GradientNoiseParams& params);

  GradientNoiseParams params_;
  std::array<std::uint64_t, kMaxNoiseOctaves> octaveKeys_{};
};

// ------------------------------------------------------------------------------------------------
// Gradients of any volume
// ------------------------------------------------------------------------------------------------

/// @brief How volumeGradient obtains ∇h.
enum class GradientScheme {
  /// HeightVolume::analyticGradient (step ignored): exact.
  kAnalytic,
  /// 6 taps, (h(P + εe_i) − h(P − εe_i)) / (2ε) per axis. Error ε²/6 · ∂³h/∂x_i³ + O(ε⁴):
  /// second order.
  kCentral,
  /// 4 taps at the vertices k ∈ {(1,−1,−1), (−1,−1,1), (−1,1,−1), (1,1,1)} of a tetrahedron
  /// (seed 002): ∇h ≈ Σ k h(P + εk) / (4ε). The 4 is Σ k kᵀ = 4I (seed 002's "gradient scaled
  /// by a factor of 4"); Σ k = 0 cancels h(P). The taps sit ε√3 from P.
  /// @note Only **first order** in general: the tetrahedron is not point-symmetric. The Taylor
  /// term ε²/2 · kᵀHk leaves Σ k (kᵀHk) ε/8, and while Σ k k_a² = Σ k = 0, the mixed sums do not
  /// vanish (Σ k k_x k_y = (0, 0, 4), as k_x k_y k_z = 1 at all four vertices), so the error is
  /// ε · (h_yz, h_xz, h_xy) + O(ε²). It is second order only where the Hessian's off-diagonal
  /// terms vanish (e.g. a wave along a coordinate axis). Exact for linear fields, like kCentral.
  kTetrahedral,
};

/// Smallest step volumeGradient uses: the smallest normal double (smaller |step| is raised to it).
inline constexpr double kMinGradientStep = std::numeric_limits<double>::min();
/// Largest step volumeGradient uses (larger |step| is lowered to it), so 4·step stays finite.
inline constexpr double kMaxGradientStep = 1e300;

/// @brief The default finite-difference step relative to the object's size: 2^-20 ≈ 9.5e-7.
///
/// Why: the relative error of the central scheme is about
///     (ε/ℓ)²/6          (truncation; ℓ = length scale of the height's features, h''' ≈ h'/ℓ²,
///                        e.g. ℓ = 1/(2πf) for a sine of frequency f)
///   + u · S/ε           (round-off; u = 2^-53, S = object size ≥ |P|: P ± ε is rounded to
///                        u·|P|, and h itself to u·|h| ≲ u·|∇h|·ℓ).
/// With ε = 2^-20·S the round-off part is ≈ 1.2e-10 whatever the field, and the truncation part
/// stays below 1e-5 for features down to ℓ ≈ S/8000, i.e. wavelengths down to ≈ S/1300
/// (≈ 1.5e-13 for ℓ = S). The optimum for ℓ = S, ε = (3u)^⅓·S ≈ 7e-6·S, would cost accuracy on
/// fine detail, which is what bump maps have.
/// A power of two keeps ε·k, 2ε and 4ε exact. For kTetrahedral the error is first order,
/// ≈ ε/ℓ ≈ 1e-6·S/ℓ: 1e-4 for ℓ = S/100.
inline constexpr double kDefaultRelativeStep = 0x1p-20;

/// @brief A finite-difference step for an object of size @p objectSize: kDefaultRelativeStep ×
/// objectSize (an absolute object-space length, what volumeGradient takes).
///
/// @param[in] objectSize  a length that bounds the coordinates, e.g. the bounding-box diagonal
/// (or the largest |coordinate|). Non-positive or non-finite sizes are treated as 1.
/// @return a step in [kMinGradientStep, kMaxGradientStep].
double defaultStep(double objectSize);

/// @brief ∇h of @p volume at @p p with @p scheme.
///
/// @param[in] volume  the height field
/// @param[in] p       object-space point
/// @param[in] scheme  kAnalytic, kCentral (6 value() calls) or kTetrahedral (4 value() calls)
/// @param[in] step    ε: absolute object-space distance of the taps along each axis (the
///   tetrahedral taps are ε√3 from P); see defaultStep. Ignored by kAnalytic.
/// @return ∇h, object space, height per unit length.
///
/// @note Degenerate policy: the sign of @p step is ignored; |step| is clamped to
/// [kMinGradientStep, kMaxGradientStep]; tap positions beyond ±DBL_MAX are clamped to ±DBL_MAX.
/// A step below the resolution of P (|step| < ½ ulp(P)) makes the taps coincide with P and
/// returns 0 on those axes — no information, but no NaN. The result is finite for every finite
/// @p p and non-NaN @p step (given a volume that honours the HeightVolume contract); a NaN step
/// or NaN coordinate gives NaN.
Vec3d volumeGradient(const HeightVolume& volume, Vec3d p, GradientScheme scheme, double step);

/// @brief The surface gradient of a height volume (seed 001 eq. 30): Γ = ∇h − ⟨∇h, N⟩ N.
///
/// @param[in] gradH  the volume gradient ∇h at the surface point, object space
/// @param[in] N      the unit surface normal there, object space
/// @return Γ, in the tangent plane of N (⟨Γ, N⟩ = 0 up to rounding when |N| = 1).
/// @note Precondition: |N| = 1. A non-unit N projects incorrectly (no renormalisation here).
Vec3d surfaceGradientFromVolume(Vec3d gradH, Vec3d N);

}  // namespace sgbake
