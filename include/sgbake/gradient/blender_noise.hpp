/// @file blender_noise.hpp
/// @brief Blender's Noise Texture (Cycles 3.4) as a height volume, with its exact gradient.
///
/// The most common procedural bump in Blender is a Noise Texture's Fac into a Bump node. To bake
/// it as Cycles does, sgbake evaluates the same function (in double precision; Cycles in float):
///
///     Fac(P) = fbm(p + distortion · (snoise(p + o₀), snoise(p + o₁), snoise(p + o₂))),  p = scale
///     · P
///
/// - snoise(x) = 0.982 · perlin(x): Perlin's improved noise with the quintic fade
///   6t⁵ − 15t⁴ + 10t³, trilinear over the 8 corners of the unit cell, each corner's gradient
///   chosen by Perlin's 12-direction rule from the low 4 bits of a hash of the corner's integer
///   coordinates (Bob Jenkins' lookup3 final mix of the three 32-bit words). noise = ½ snoise + ½.
/// - fbm: octaves i = 0 … ⌊detail⌋ of noise(2ⁱ p) weighted roughnessⁱ (roughness clamped to
///   [0, 1]), divided by the sum of the weights; a fractional detail blends in one more octave
///   linearly. detail is clamped to [0, 15].
/// - oₖ: the offsets Cycles seeds the distortion with, 100 + 100 · hash(k) per axis.
///
/// The gradient is exact for this function: the fade's and the corner terms' derivatives, the
/// octaves' chain-rule factors 2ⁱ, and the distortion's Jacobian I + distortion · ∇snoise(p + oₖ).
///
/// Dimensions other than 3D (the Noise and Musgrave Textures') read other points: 1D the node's
/// W alone (a constant over the surface: no slopes), 2D (x, y), 4D (x, y, z, W), W scaled by
/// Scale as the Vector. Their perlin is the same multilinear blend over 2ᴺ corners with Cycles'
/// rules for N: the corner's hash is lookup3's of its N words; its gradient is g = 1 … 8 of
/// either sign in 1D, ±d_u ± 2 d_v in 2D, ±d_u ± d_v ± d_s in 4D (32 directions); snoise scales
/// perlin by 0.25, 0.6616, 0.982 or 0.8344. The distortion moves each of the N axes, seeded per
/// axis (1D: 100 + 100 · hash(0); else the offsets above, of N components). W holds still, so
/// the gradient with respect to P is the N-dimensional one's x, y, z part, pulled back.
#pragma once

#include <array>

#include "sgbake/core/result.hpp"
#include "sgbake/core/vec.hpp"
#include "sgbake/gradient/volume.hpp"

namespace sgbake {

/// @brief What Blender's procedural textures share as height volumes: the height is amplitude
/// times the node's output (Fac, or the Voronoi's Distance), its gradient that of the output.
template <class Params>
class BlenderTextureVolume : public HeightVolume {
 public:
  double value(Vec3d p) const final { return params_.amplitude * output(p, nullptr); }
  Vec3d analyticGradient(Vec3d p) const final { return sample(p).gradient; }
  VolumeSample sample(Vec3d p) const final {
    Vec3d g;
    const double fac = output(p, &g);
    return {params_.amplitude * fac, params_.amplitude * g};
  }
  /// The node's output at @p p (object space, before the amplitude), and its gradient.
  virtual double output(Vec3d p, Vec3d* gradient) const = 0;
  const Params& params() const { return params_; }

 protected:
  explicit BlenderTextureVolume(const Params& params) : params_(params) {}
  Params params_;
};

/// @brief The Noise Texture node's settings and the height's scale.
struct BlenderNoiseParams {
  double amplitude = 1;    ///< height per unit of Fac (a Bump node's Distance)
  double scale = 5;        ///< the node's Scale: P is multiplied by it
  double detail = 2;       ///< the node's Detail (clamped to [0, 15] as Cycles clamps it)
  double roughness = 0.5;  ///< the node's Roughness (clamped to [0, 1] as Cycles clamps it)
  double distortion = 0;   ///< the node's Distortion
  int dimensions = 3;      ///< the node's Dimensions: 1 (W only), 2 (x, y), 3, 4 (x, y, z, W)
  double w = 0;            ///< the node's W (read in 1D and 4D), scaled by Scale as the Vector
};

/// @brief Blender's Noise Texture Fac, times an amplitude: a HeightVolume.
class BlenderNoise final : public BlenderTextureVolume<BlenderNoiseParams> {
 public:
  /// @return kBadInput for a non-finite setting, or slopes beyond kMaxVolumeScale
  /// (|amplitude| · |scale| · (1 + |distortion|) · 2^detail).
  static Result<BlenderNoise> create(const BlenderNoiseParams& params);

  /// The node's Fac.
  double output(Vec3d p, Vec3d* gradient) const override;

 private:
  explicit BlenderNoise(const BlenderNoiseParams& params);
  std::array<std::array<double, 4>, 4> distortionOffsets_{};  ///< [axis][component]
};

/// The Musgrave Texture's Type (Blender's FBM, MULTIFRACTAL, RIDGED_MULTIFRACTAL,
/// HYBRID_MULTIFRACTAL, HETERO_TERRAIN).
enum class MusgraveType {
  kFbm,
  kMultifractal,
  kRidgedMultifractal,
  kHybridMultifractal,
  kHeteroTerrain
};

/// @brief The Musgrave Texture node's settings and the height's scale.
struct BlenderMusgraveParams {
  double amplitude = 1;  ///< height per unit of Fac
  double scale = 5;      ///< the node's Scale
  MusgraveType type = MusgraveType::kFbm;
  double detail = 2;      ///< the node's Detail: octaves (clamped to [0, 15])
  double dimension = 2;   ///< the node's Dimension H (at least 1e-5)
  double lacunarity = 2;  ///< the node's Lacunarity L (at least 1e-5)
  double offset = 0;      ///< the node's Offset (ridged, hybrid, hetero terrain)
  double gain = 1;        ///< the node's Gain (ridged, hybrid)
  int dimensions = 3;     ///< the node's Dimensions: 1 (W only), 2 (x, y), 3, 4 (x, y, z, W)
  double w = 0;           ///< the node's W (read in 1D and 4D), scaled by Scale as the Vector
};

/// @brief Blender's Musgrave Texture, times an amplitude: a HeightVolume.
///
/// With p = scale · P (the point its Dimensions read, as BlenderNoise's), sᵢ = snoise(Lⁱ p)
/// (BlenderNoise's, unnormalized: Fac is signed), wᵢ =
/// L^(−iH), n = ⌊detail⌋ and r = detail − n (detail clamped to [0, 15]), Cycles 3.4's types:
///
/// - fBM: Fac = Σ_{i < n} wᵢ sᵢ + r wₙ sₙ.
/// - Multifractal: Fac = Π_{i < n} (1 + wᵢ sᵢ) · (1 + r wₙ sₙ) (the last factor only if r ≠ 0).
/// - Hetero Terrain: V₀ = offset + s₀, then Vᵢ = Vᵢ₋₁ · (1 + (sᵢ + offset) wᵢ) for 0 < i < n;
///   Fac = Vₖ₋₁ · (1 + r (sₖ + offset) wₖ), k = max(n, 1) (octave 0 is always whole: with
///   detail < 1 the fraction reads octave 1).
/// - Hybrid Multifractal: weights ω₀ = 1 and, for i < n, the signal σᵢ = (sᵢ + offset) wᵢ adds
///   min(ωᵢ, 1) σᵢ and ωᵢ₊₁ = min(ωᵢ, 1) · gain · σᵢ; if r ≠ 0 the fraction adds
///   r min(ωₙ, 1) σₙ. The sum stops (the fraction too) at the first ωᵢ ≤ 0.001 (Cycles' float
///   0.001).
/// - Ridged Multifractal: σ₀ = (offset − |s₀|)², σᵢ = (offset − |sᵢ|)² · clamp(gain σᵢ₋₁, 0, 1)
///   for 0 < i < n; Fac = Σ wᵢ σᵢ over i < max(n, 1). The fraction r is not used (Cycles
///   ignores it).
///
/// The gradient is exact: the octaves' chain-rule factors Lⁱ, the product rule over the
/// multifractal's and hetero terrain's factors, and the weights' gradients where they are not
/// clamped (0 where min(ω, 1) or clamp(…, 0, 1) holds them at a bound). Where it is not
/// differentiable it takes one side: |sᵢ| has the gradient sign(sᵢ) ∇sᵢ (+ at sᵢ = 0, the
/// ridge), a clamped weight at its bound counts as clamped, and the hybrid's jump where a weight
/// crosses 0.001 is not seen.
class BlenderMusgrave final : public BlenderTextureVolume<BlenderMusgraveParams> {
 public:
  /// @return kBadInput for a non-finite setting, or slopes beyond kMaxVolumeScale (a bound per
  /// type, growing with detail, 1 + |offset|, |gain| and L^(−H), L^(1−H): see create()).
  static Result<BlenderMusgrave> create(const BlenderMusgraveParams& params);
  /// The node's Fac.
  double output(Vec3d p, Vec3d* gradient) const override;

 private:
  using BlenderTextureVolume::BlenderTextureVolume;
};

/// @brief The Brick Texture node's settings that shape its Fac (the mortar), and the height's
/// scale. (Its colours and Bias tint the bricks only.)
struct BlenderBrickParams {
  double amplitude = 1;       ///< height per unit of Fac
  double scale = 5;           ///< the node's Scale
  double mortarSize = 0.02;   ///< Mortar Size
  double mortarSmooth = 0.1;  ///< Mortar Smooth
  double brickWidth = 0.5;    ///< Brick Width (greater than 0)
  double rowHeight = 0.25;    ///< Row Height (greater than 0)
  double offset = 0.5;        ///< Offset: of every offsetFrequency-th row, in brick widths
  int offsetFrequency = 2;    ///< its Frequency (0: no offset and no squash)
  double squash = 1;          ///< Squash: brick width factor of every squashFrequency-th row
  int squashFrequency = 2;    ///< its Frequency (0: no offset and no squash)
};

/// @brief Blender's Brick Texture's Fac (1 in the mortar, 0 in the bricks), times an amplitude:
/// a HeightVolume.
///
/// p = scale · P, only its x and y read. Row r = ⌊y / h⌋ (h the Row Height); when both
/// frequencies are non-zero a row whose r is a multiple of the squash frequency has bricks
/// Squash times as wide (w), and one whose r is a multiple of the offset frequency is moved by
/// Offset · w (rows below zero too). Brick b = ⌊(x + offset) / w⌋, and in
/// it x′ = x + offset − b w, y′ = y − r h; d = min(x′, y′, w − x′, h − y′), the distance to the
/// brick's edge. Fac = 0 where d ≥ Mortar Size, else 1 without smoothing, else
/// smoothstep(t) = 3t² − 2t³ of t = (1 − d / Mortar Size) / Mortar Smooth while t < 1, else
/// 1. Its gradient is exact but where d's nearest edge changes (the bricks' corners) and at
/// the mortar's borders.
class BlenderBrick final : public BlenderTextureVolume<BlenderBrickParams> {
 public:
  /// @return kBadInput for a non-finite setting, a Brick Width or Row Height not greater than 0,
  /// a negative frequency, or slopes beyond kMaxVolumeScale.
  static Result<BlenderBrick> create(const BlenderBrickParams& params);
  /// The node's Fac.
  double output(Vec3d p, Vec3d* gradient) const override;

 private:
  using BlenderTextureVolume::BlenderTextureVolume;
};

/// The Gradient Texture's Gradient Type (Blender's LINEAR, QUADRATIC, EASING, DIAGONAL,
/// SPHERICAL, QUADRATIC_SPHERE, RADIAL).
enum class BlenderGradientType {
  kLinear,
  kQuadratic,
  kEasing,
  kDiagonal,
  kSpherical,
  kQuadraticSphere,
  kRadial
};

/// @brief The Gradient Texture node's type and the height's scale (the node has no Scale: a
/// Mapping node in front of it scales P).
struct BlenderGradientParams {
  double amplitude = 1;  ///< height per unit of Fac
  BlenderGradientType type = BlenderGradientType::kLinear;
};

/// @brief Blender's Gradient Texture's Fac (its Color is (Fac, Fac, Fac)), times an amplitude: a
/// HeightVolume.
///
/// Of P = (x, y, z), Cycles 3.4's `svm_gradient`, its result clamped to [0, 1]:
/// - Linear x; Quadratic max(x, 0)²; Easing 3r² − 2r³ of r = clamp(x, 0, 1); Diagonal (x + y) / 2;
/// - Spherical s = max(k − |P|, 0) and Quadratic Sphere s², k = 0.999999 (Cycles' float
///   0.999999f, its nudge for unit vectors);
/// - Radial atan2(y, x) / 2π + ½.
///
/// The gradient is exact where the Fac is not clamped, and 0 where it is (a point on a clamp's
/// bound counts as clamped). Where it is not differentiable: Spherical's and Quadratic Sphere's
/// apex P = 0 takes the gradient 0; Radial's is (−y, x) / (2π (x² + y²)), singular on the z axis,
/// where it is taken as 0 (x² + y² = 0, underflow included; atan2(0, 0) = 0 gives the Fac ½), and
/// across the half-plane y = 0, x < 0 the Fac jumps from 1 (y = +0) to 0 (y < 0): the gradient
/// there is the smooth one of either side, the jump not seen.
class BlenderGradient final : public BlenderTextureVolume<BlenderGradientParams> {
 public:
  /// @return kBadInput for a non-finite amplitude, an unknown type, or slopes beyond
  /// kMaxVolumeScale.
  static Result<BlenderGradient> create(const BlenderGradientParams& params);
  /// The node's Fac.
  double output(Vec3d p, Vec3d* gradient) const override;

 private:
  using BlenderTextureVolume::BlenderTextureVolume;
};

/// The Magic Texture's Depth: 0 to this (Blender's range).
inline constexpr int kBlenderMagicMaxDepth = 10;

/// @brief The Magic Texture node's settings and the height's scale.
struct BlenderMagicParams {
  double amplitude = 1;   ///< height per unit of Fac
  double scale = 5;       ///< the node's Scale
  int depth = 2;          ///< the node's Depth, 0 to kBlenderMagicMaxDepth
  double distortion = 1;  ///< the node's Distortion
};

/// @brief Blender's Magic Texture's Fac, the mean of its Color's three channels (Cycles 3.4's
/// `svm_node_tex_magic` writes Fac as average(color)), times an amplitude: a HeightVolume.
///
/// With p = scale · P and a = 5 (pₓ + p_y + p_z), b = 5 (−pₓ + p_y − p_z), c = 5 (−pₓ − p_y + p_z):
/// x = sin a, y = cos b, z = −cos c. With Depth n > 0, each of x, y, z is times the Distortion
/// d, then n of Cycles' ten steps follow in order, each setting one of x, y, z to d times a sine
/// or cosine (signed) of ±x ± y ± z of the current values (Cycles' `svm_magic`: y = −cos(x − y +
/// z), x = cos(x − y − z), z = sin(−x − y − z), x = −cos(−x + y − z), y = −sin(−x + y + z), y =
/// −cos(−x + y + z), x = cos(x + y + z), z = sin(x + y − z), x = −cos(−x − y + z), y = −sin(x − y
/// + z)). Where d ≠ 0, x, y, z are divided by 2d (at Depth 0 too). Color = ½ − (x, y, z); Fac =
/// its mean. The gradient is exact: the chain rule through every sine and cosine.
class BlenderMagic final : public BlenderTextureVolume<BlenderMagicParams> {
 public:
  /// @return kBadInput for a non-finite setting, a Depth out of [0, kBlenderMagicMaxDepth], or
  /// slopes beyond kMaxVolumeScale (|amplitude| · |scale| · 5√3 · max(1, 3|d|)^n, divided by 2|d|
  /// at Depth 0).
  static Result<BlenderMagic> create(const BlenderMagicParams& params);
  /// The node's Fac.
  double output(Vec3d p, Vec3d* gradient) const override;

 private:
  using BlenderTextureVolume::BlenderTextureVolume;
};

/// The Wave Texture's Wave Type.
enum class WaveType { kBands, kRings };
/// Its Bands Direction (x, y, z, diagonal) or Rings Direction (x, y, z: around that axis;
/// spherical).
enum class WaveDirection { kX, kY, kZ, kDiagonal, kSpherical };
/// Its Wave Profile.
enum class WaveProfile { kSine, kSaw, kTriangle };

/// @brief The Wave Texture node's settings and the height's scale.
struct BlenderWaveParams {
  double amplitude = 1;  ///< height per unit of Fac
  double scale = 5;      ///< the node's Scale
  WaveType type = WaveType::kBands;
  WaveDirection direction = WaveDirection::kX;  ///< diagonal for bands, spherical for rings only
  WaveProfile profile = WaveProfile::kSine;
  double distortion = 0;         ///< the node's Distortion
  double detail = 2;             ///< Detail of the distortion's noise (clamped to [0, 15])
  double detailScale = 1;        ///< its Detail Scale
  double detailRoughness = 0.5;  ///< its Detail Roughness (clamped to [0, 1])
  double phase = 0;              ///< Phase Offset, radians
};

/// @brief Blender's Wave Texture, times an amplitude: a HeightVolume.
///
/// p = (scale · P + 10⁻⁶) · 0.999999 (Cycles' nudge off the lattice); n = 20 p_axis (bands;
/// diagonal 10 (x + y + z)) or 20 |p without the axis| (rings; spherical 20 |p|), plus the phase
/// and Distortion · (2 fbm(Detail Scale · p) − 1) with BlenderNoise's fbm; Fac = ½ + ½ sin(n −
/// π/2), the fraction of n / 2π (saw) or twice its distance to the nearest integer (triangle). The
/// gradient is exact away from the saw's and triangle's corners (and the rings' axis).
class BlenderWave final : public BlenderTextureVolume<BlenderWaveParams> {
 public:
  /// @return kBadInput for a non-finite setting, a direction the type has not (diagonal rings,
  /// spherical bands), or slopes beyond kMaxVolumeScale.
  static Result<BlenderWave> create(const BlenderWaveParams& params);
  /// The node's Fac.
  double output(Vec3d p, Vec3d* gradient) const override;

 private:
  using BlenderTextureVolume::BlenderTextureVolume;
};

/// The Voronoi Texture's Distance Metric.
enum class VoronoiMetric { kEuclidean, kManhattan, kChebyshev, kMinkowski };

/// The Voronoi Texture's Feature Output (of those with a Distance output).
enum class VoronoiFeature { kF1, kF2, kSmoothF1, kDistanceToEdge };

/// @brief The Voronoi Texture node's settings (3D: its Distance output) and the height's scale.
struct BlenderVoronoiParams {
  double amplitude = 1;   ///< height per unit of Distance
  double scale = 5;       ///< the node's Scale
  double randomness = 1;  ///< the node's Randomness (clamped to [0, 1])
  VoronoiMetric metric = VoronoiMetric::kEuclidean;  ///< (ignored by Distance to Edge)
  double exponent = 0.5;  ///< the node's Exponent (Minkowski)
  VoronoiFeature feature = VoronoiFeature::kF1;  ///< the node's Feature Output
  double smoothness = 1;  ///< the node's Smoothness (Smooth F1; clamped to [0, 1])
};

/// @brief Blender's Voronoi Texture (3D), its Distance output, times an amplitude: a
/// HeightVolume.
///
/// p = scale · P, c = ⌊p⌋, l = p − c; the cell at integer offset o from c holds one point
/// qₒ = o + r · h(c + o), r the randomness clamped to [0, 1], h a hash of the cell's coordinates
/// (three lookup3 hashes of the coordinates' float bits, the second and third with a fourth word
/// 1 and 2, as Cycles hashes them); d(a, b) is the metric's distance. Cells are visited in z, y, x
/// order (o from −1 to 1 in each, or −2 to 2 for Smooth F1):
/// - F1: Distance = min over the 27 cells of d(qₒ, l), the first of equals kept. Gradient: the
///   metric's gradient at the nearest point, exact but where the nearest point changes.
/// - F2: the second-smallest d(qₒ, l) of the 27, kept as Cycles keeps it (a distance strictly
///   below F1 pushes F1 down to F2; else one strictly below F2 replaces F2). Gradient: the
///   metric's at the second point, exact but where the order changes.
/// - Distance to Edge (Euclidean whatever the metric, as in Cycles): first the vector
///   v = qₙ − l to the nearest point by squared distance (the first of equals); then over the
///   same 27 cells, for each point with |vₒ − v|² > 10⁻⁴ (vₒ = qₒ − l; so not the nearest),
///   the distance to the bisector plane, ((v + vₒ) / 2) · (vₒ − v) / |vₒ − v|; Distance is the
///   minimum (8 if none). Gradient: −(vₒ − v) / |vₒ − v| of the minimising plane (the unit normal
///   pointing away from the edge, into the nearest point's cell), exact but at ties.
/// - Smooth F1: s = clamp(smoothness / 2, 0, ½); starting from D = 8, for each of the 125 cells
///   of the 5×5×5 neighbourhood, with dₒ = d(qₒ, l): h = smoothstep(0, 1, ½ + ½ (D − dₒ) / s)
///   (3t² − 2t³ on [0, 1), 0 below, 1 from 1 on), D ← D + h (dₒ − D) − s h (1 − h). With s = 0,
///   h = 1 where D > dₒ, else 0 (where Cycles' 0 / 0 gives NaN, at D = dₒ). Gradient: the chain
///   rule through every step, with dh = 6t(1 − t) · ½ (dD − ddₒ) / s inside (0, 1), 0 outside.
/// Every feature's gradient is then times scale.
class BlenderVoronoi final : public BlenderTextureVolume<BlenderVoronoiParams> {
 public:
  /// @return kBadInput for a non-finite setting, an exponent ≤ 0 with Minkowski (but for
  /// Distance to Edge, which has no metric), or slopes beyond kMaxVolumeScale.
  static Result<BlenderVoronoi> create(const BlenderVoronoiParams& params);

  /// The node's Distance.
  double output(Vec3d p, Vec3d* gradient) const override;

 private:
  using BlenderTextureVolume::BlenderTextureVolume;
};

/// @brief The Noise Texture's fBm of @p p (no Scale, no distortion): octaves of ½ snoise + ½, as
/// described above, and its gradient with respect to p.
double blenderFractalNoise(Vec3d p, double detail, double roughness, Vec3d* gradient);

/// @brief Cycles' signed Perlin noise snoise(x) = 0.982 · perlin(x) at @p x, and its gradient
/// (exposed for tests).
double blenderSignedNoise(Vec3d x, Vec3d* gradient);

}  // namespace sgbake
