// The surface-gradient core (seed 001): eq. 31 on arbitrary UV frames, tiling (eq. 13),
// tangent-space maps (eq. 14-15) in the MikkTSpace and UV-derivative frames, object-space normals
// (eq. 38), cofactors and resolving (eq. 20, 33). References are closed forms: linear heights give
// exact constant gradients, a sine height gives the closed-form normal, Blender's forward decode
// normalize(x·T + y·B + z·N), the normal of an explicitly displaced and scaled surface.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "sgbake/core/math.hpp"
#include "sgbake/gradient/surface_gradient.hpp"

namespace sgbake {
namespace {

// ---------------------------------------------------------------------------------------------
// helpers

double maxAbsDiff(Vec3d a, Vec3d b) {
  return std::max({std::abs(a.x - b.x), std::abs(a.y - b.y), std::abs(a.z - b.z)});
}

class Random {
 public:
  explicit Random(std::uint64_t seed) : engine_(seed) {}
  double uniform(double lo, double hi) {
    return std::uniform_real_distribution<double>(lo, hi)(engine_);
  }
  Vec3d vector(double lo = -1, double hi = 1) {
    return {uniform(lo, hi), uniform(lo, hi), uniform(lo, hi)};
  }
  Vec3d unit() {
    for (;;) {
      const Vec3d v = vector();
      const double l = length(v);
      if (l > 0.1 && l <= 1) return (1 / l) * v;
    }
  }
  /// A random rotation (columns: an orthonormal right-handed frame).
  Mat3 rotation() {
    const Vec3d a = unit();
    const Vec3d b = normalizeOr(cross(a, unit()), Vec3d{0, 0, 1});
    return Mat3::fromColumns(a, b, cross(a, b));
  }

 private:
  std::mt19937_64 engine_;
};

// A texture-free sine height on the plane: h(x, y) = A sin(2π s) cos(2π t),
// (s, t) = tiling ∘ (x/Lx, y/Ly) + offset, with exact derivatives.
struct SineHeight {
  double amplitude = 0.3;
  Vec2d tiling{3, 2}, offset{0.1, 0.2};
  double lx = 1.5, ly = 0.75;

  ScalarSample sample(Vec2d st) const {
    const double w = 2 * kPi;
    return {amplitude * std::sin(w * st.x) * std::cos(w * st.y),
            {amplitude * w * std::cos(w * st.x) * std::cos(w * st.y),
             -amplitude * w * std::sin(w * st.x) * std::sin(w * st.y)}};
  }
  /// (∂h/∂x, ∂h/∂y) in object space at (x, y).
  Vec2d slope(double x, double y) const {
    const ScalarSample s = sample(textureCoordinates({x / lx, y / ly}, tiling, offset));
    return {s.gradient.x * tiling.x / lx, s.gradient.y * tiling.y / ly};
  }
};

// ---------------------------------------------------------------------------------------------
// Mat3 and cofactors

TEST(Cofactor, IsDeterminantTimesInverseTranspose) {
  Random rng(1);
  for (int i = 0; i < 100; ++i) {
    const Mat3 m = Mat3::fromColumns(rng.vector(-3, 3), rng.vector(-3, 3), rng.vector(-3, 3));
    const Mat3 c = cofactor(m);
    const double det = determinant(m);
    // cof(M)ᵀ · M = det · I  ⇔  ⟨cof column i, M column j⟩ = det δ_ij.
    for (std::size_t r = 0; r < 3; ++r)
      for (std::size_t k = 0; k < 3; ++k)
        EXPECT_NEAR(dot(c.col[r], m.col[k]), r == k ? det : 0.0, 1e-12 * (1 + std::abs(det)));
    // (M a) × (M b) = cof(M) (a × b)  (eq. 20)
    const Vec3d a = rng.vector(), b = rng.vector();
    EXPECT_LT(maxAbsDiff(cross(m * a, m * b), c * cross(a, b)), 1e-12);
  }
}

TEST(Cofactor, OfADiagonalScaleIsTheProductOfTheOtherTwo) {
  const Mat3 c = cofactor(Mat3::diagonal({2, 3, 5}));
  EXPECT_EQ(c * Vec3d(1, 0, 0), Vec3d(15, 0, 0));
  EXPECT_EQ(c * Vec3d(0, 1, 0), Vec3d(0, 10, 0));
  EXPECT_EQ(c * Vec3d(0, 0, 1), Vec3d(0, 0, 6));
  EXPECT_EQ(determinant(Mat3::diagonal({2, 3, 5})), 30.0);
}

// ---------------------------------------------------------------------------------------------
// eq. 31: linear heights give exact constant gradients

TEST(GradientFromUvDerivatives, LinearHeightOnAnAxisAlignedPlaneIsExact) {
  const UvFrame frame{{0.3, 0.7}, {2, 0, 0}, {0, 4, 0}};
  // h = a u + b v ⇒ Γ = (a/2, b/4, 0): u grows 1 per 2 object units, v 1 per 4.
  for (const Vec2d ab : {Vec2d{1, 0}, Vec2d{0, 1}, Vec2d{-3, 5}, Vec2d{0.25, -0.125}}) {
    const Vec3d gamma = gradientFromUvDerivatives(frame, {0, 0, 1}, ab);
    EXPECT_EQ(gamma, Vec3d(ab.x / 2, ab.y / 4, 0));
  }
}

// A linear height h(P) = ⟨g, P⟩ with g in the tangent plane, seen through any tilted, sheared,
// non-unit or mirrored parametrization: ∂h/∂u = ⟨g, ∂P/∂u⟩, ∂h/∂v = ⟨g, ∂P/∂v⟩, and Γ = g.
TEST(GradientFromUvDerivatives, LinearHeightOnTiltedShearedFramesGivesTheExactGradient) {
  Random rng(2);
  for (int i = 0; i < 1000; ++i) {
    const Mat3 r = rng.rotation();
    const Vec3d n = r * Vec3d{0, 0, 1};
    Vec3d dPdu = r * Vec3d{rng.uniform(0.1, 3), rng.uniform(-2, 2), 0};
    Vec3d dPdv = r * Vec3d{rng.uniform(-2, 2), rng.uniform(0.1, 3), 0};
    if (i % 2) std::swap(dPdu, dPdv);  // mirrored UVs: ⟨T × B, N⟩ < 0
    const Vec3d g = r * Vec3d{rng.uniform(-2, 2), rng.uniform(-2, 2), 0};
    const Vec3d gamma =
        gradientFromUvDerivatives({{}, dPdu, dPdv}, n, {dot(g, dPdu), dot(g, dPdv)});
    // Round-off grows with the frame's condition number 1 / sin∠(∂P/∂u, ∂P/∂v).
    const double sine = length(cross(dPdu, dPdv)) / (length(dPdu) * length(dPdv));
    EXPECT_LT(maxAbsDiff(gamma, g), 1e-14 * (1 + length(g)) / sine) << "frame " << i;
  }
}

// Eq. 32 for a shading normal that is not the frame's geometric normal: ⟨Γ, T⟩ = ∂h/∂u,
// ⟨Γ, B⟩ = ∂h/∂v, ⟨Γ, N⟩ = 0.
TEST(GradientFromUvDerivatives, SatisfiesEquation32ForAnyShadingNormal) {
  Random rng(3);
  for (int i = 0; i < 1000; ++i) {
    const Vec3d dPdu = rng.vector(-2, 2), dPdv = rng.vector(-2, 2);
    const Vec3d geometric = normalizeOr(cross(dPdu, dPdv), Vec3d{0, 0, 1});
    const Vec3d n = normalizeOr(geometric + 0.5 * rng.unit(), geometric);
    if (std::abs(dot(cross(dPdu, dPdv), n)) < 0.05 * length(dPdu) * length(dPdv)) continue;
    const Vec2d d{rng.uniform(-3, 3), rng.uniform(-3, 3)};
    const Vec3d gamma = gradientFromUvDerivatives({{}, dPdu, dPdv}, n, d);
    const double scale = 1e-11 * (1 + length(gamma) * (length(dPdu) + length(dPdv)));
    EXPECT_NEAR(dot(gamma, dPdu), d.x, scale);
    EXPECT_NEAR(dot(gamma, dPdv), d.y, scale);
    EXPECT_NEAR(dot(gamma, n), 0.0, scale);
  }
}

TEST(GradientFromUvDerivatives, IsLinearInTheDerivatives) {
  Random rng(4);
  for (int i = 0; i < 200; ++i) {
    const UvFrame frame{{}, rng.vector(), rng.vector()};
    const Vec3d n = normalizeOr(cross(frame.dPdu, frame.dPdv), Vec3d{0, 0, 1});
    const Vec2d d1{rng.uniform(-1, 1), rng.uniform(-1, 1)},
        d2{rng.uniform(-1, 1), rng.uniform(-1, 1)};
    const double alpha = rng.uniform(-3, 3), beta = rng.uniform(-3, 3);
    const Vec3d combined = gradientFromUvDerivatives(frame, n, alpha * d1 + beta * d2);
    const Vec3d separate = alpha * gradientFromUvDerivatives(frame, n, d1) +
                           beta * gradientFromUvDerivatives(frame, n, d2);
    EXPECT_LT(maxAbsDiff(combined, separate), 1e-11 * (1 + length(combined)));
  }
}

// Scaling the mesh by k scales Γ by 1/k; scaling the UVs by k changes nothing (derivatives
// w.r.t. u shrink with ∂P/∂u). 1e±8 and beyond: nothing changes but scale.
TEST(GradientFromUvDerivatives, ScalesExactlyWithTheMeshAndIgnoresUvScale) {
  const UvFrame frame{{}, {0.8, 0.1, 0.3}, {-0.2, 0.9, 0.1}};
  const Vec3d n = normalizeOr(cross(frame.dPdu, frame.dPdv), Vec3d{0, 0, 1});
  const Vec2d d{0.7, -0.4};
  const Vec3d reference = gradientFromUvDerivatives(frame, n, d);
  for (const double k : {1e-8, 1e-4, 1e4, 1e8, 1e-150, 1e150}) {
    const Vec3d meshScaled = gradientFromUvDerivatives({{}, k * frame.dPdu, k * frame.dPdv}, n, d);
    EXPECT_LT(maxAbsDiff(k * meshScaled, reference), 1e-14) << k;
    // UV scaled by k: ∂P/∂u' = ∂P/∂u / k and ∂h/∂u' = ∂h/∂u / k.
    const Vec3d uvScaled =
        gradientFromUvDerivatives({{}, (1 / k) * frame.dPdu, (1 / k) * frame.dPdv}, n, (1 / k) * d);
    EXPECT_LT(maxAbsDiff(uvScaled, reference), 1e-14) << k;
  }
}

TEST(GradientFromUvDerivatives, DegenerateFramesGiveZero) {
  const Vec3d n{0, 0, 1};
  const Vec2d d{1, 1};
  EXPECT_EQ(gradientFromUvDerivatives({{}, {0, 0, 0}, {0, 1, 0}}, n, d), Vec3d{});  // zero ∂P/∂u
  EXPECT_EQ(gradientFromUvDerivatives({{}, {1, 0, 0}, {0, 0, 0}}, n, d), Vec3d{});  // zero ∂P/∂v
  EXPECT_EQ(gradientFromUvDerivatives({{}, {1, 0, 0}, {2, 0, 0}}, n, d), Vec3d{});  // parallel
  EXPECT_EQ(gradientFromUvDerivatives({{}, {1, 0, 0}, {0, 0, 1}}, n, d),
            Vec3d{});  // N in the plane
  EXPECT_EQ(gradientFromUvDerivatives({{}, {1, 0, 0}, {1, 1e-12, 0}}, n, d),
            Vec3d{});  // sine 1e-12
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_EQ(gradientFromUvDerivatives({{}, {inf, 0, 0}, {0, 1, 0}}, n, d), Vec3d{});
  EXPECT_EQ(gradientFromUvDerivatives({{}, {std::nan(""), 0, 0}, {0, 1, 0}}, n, d), Vec3d{});
  // Just above the threshold the frame is used.
  EXPECT_NE(gradientFromUvDerivatives({{}, {1, 0, 0}, {1, 1e-8, 0}}, n, d), Vec3d{});
}

TEST(UvDerivativesFromTexture, AppliesTilingAndScaleButNotOffset) {
  const ScalarSample s{0.5, {0.25, -2}};
  const Vec2d d = uvDerivativesFromTexture(s, {2, -3}, 0.5);
  EXPECT_EQ(d, Vec2d(0.25, 3));
  EXPECT_EQ(textureCoordinates({0.5, 0.25}, {2, 4}, {0.1, -1}), Vec2d(1.1, 0));
}

// A sine height on the plane z = 0 (UV = (x/Lx, y/Ly), tiled and offset): the perturbed normal is
// the closed form normalize(−∂h/∂x, −∂h/∂y, 1) to round-off.
TEST(GradientFromUvDerivatives, SineHeightOnAPlaneGivesTheClosedFormNormal) {
  const SineHeight h;
  const UvFrame base{{}, {h.lx, 0, 0}, {0, h.ly, 0}};
  Random rng(5);
  double worst = 0;
  for (int i = 0; i < 2000; ++i) {
    const double x = rng.uniform(-2, 2), y = rng.uniform(-2, 2);
    UvFrame frame = base;
    frame.uv = {x / h.lx, y / h.ly};
    const ScalarSample s = h.sample(textureCoordinates(frame.uv, h.tiling, h.offset));
    const Vec3d gamma =
        gradientFromUvDerivatives(frame, {0, 0, 1}, uvDerivativesFromTexture(s, h.tiling, 1));
    const Vec2d slope = h.slope(x, y);
    const Vec3d expected = normalizeOr(Vec3d{-slope.x, -slope.y, 1}, Vec3d{});
    worst = std::max(worst, maxAbsDiff(resolveNormal({0, 0, 1}, gamma), expected));
  }
  EXPECT_LT(worst, 1e-12);
}

// ---------------------------------------------------------------------------------------------
// tangent-space normal maps

TEST(DecodeNormalTexel, FollowsTheBlenderEncodingAndFlipsGreenForDirectX) {
  EXPECT_EQ(decodeNormalTexel({0.5, 0.5, 1}), Vec3d(0, 0, 1));
  EXPECT_EQ(decodeNormalTexel({1, 0.75, 0.5}), Vec3d(1, 0.5, 0));
  EXPECT_EQ(decodeNormalTexel({1, 0.75, 0.5}, NormalMapGreen::kDirectX), Vec3d(1, -0.5, 0));
  EXPECT_EQ(decodeNormalTexel({0, 0, 0}), Vec3d(-1, -1, -1));
}

TEST(SlopesFromTangentNormal, IsMinusXYOverZForAnyLength) {
  const Vec2d expected{-0.3 / 0.9, 0.2 / 0.9};
  for (const double len : {1e-8, 0.5, 1.0, 3.0, 1e8}) {
    const Vec2d s = slopesFromTangentNormal(len * Vec3d{0.3, -0.2, 0.9});
    EXPECT_NEAR(s.x, expected.x, 1e-15);
    EXPECT_NEAR(s.y, expected.y, 1e-15);
  }
  EXPECT_EQ(slopesFromTangentNormal({0, 0, 1}), Vec2d(0, 0));
}

// The documented n_z guard: n_z is raised to minNormalZ·|n|: finite, bounded by 1/minNormalZ,
// continuous through the threshold, n_z < 0 leans towards (n_x, n_y) like the clamped texel and
// fades to flat at (0, 0, -1); zero and NaN are flat.
TEST(SlopesFromTangentNormal, GuardsGrazingAndBelowHorizonTexels) {
  const double m = kMinTangentNormalZ;
  for (int i = 0; i <= 2000; ++i) {
    const double angle = kPi * i / 2000;  // from straight up (0) to straight down (π)
    const Vec3d n{std::sin(angle), 0, std::cos(angle)};
    const Vec2d s = slopesFromTangentNormal(n);
    ASSERT_TRUE(isFinite(s)) << angle;
    EXPECT_LE(std::abs(s.x), 1 / m + 1e-9);
    EXPECT_EQ(s.y, 0.0);
    EXPECT_LE(s.x, 0.0);  // always leaning towards +x: N' tilts towards the texel's x
    if (n.z <= m) {
      EXPECT_NEAR(s.x, -n.x / m, 1e-9) << angle;  // the clamped texel
    }
  }
  // Continuous through the threshold n_z = m (steep there: ∂s/∂θ ≈ 1/m²).
  const double threshold = std::acos(m);
  for (const double delta : {1e-6, 1e-9}) {
    const Vec2d above =
        slopesFromTangentNormal({std::sin(threshold - delta), 0, std::cos(threshold - delta)});
    const Vec2d below =
        slopesFromTangentNormal({std::sin(threshold + delta), 0, std::cos(threshold + delta)});
    EXPECT_LT(std::abs(above.x - below.x), 2 * delta / (m * m));
  }
  EXPECT_EQ(slopesFromTangentNormal({0, 0, -1}), Vec2d(0, 0));  // straight down: flat
  EXPECT_EQ(slopesFromTangentNormal({0, 0, 0}), Vec2d(0, 0));
  EXPECT_EQ(slopesFromTangentNormal({std::nan(""), 0, 1}), Vec2d(0, 0));
  // A texel exactly at the horizon: slope 1/m towards it.
  EXPECT_NEAR(slopesFromTangentNormal({0, 1, 0}).y, -1 / m, 1e-9);
  // A zero guard is raised to machine epsilon: still finite.
  EXPECT_TRUE(isFinite(slopesFromTangentNormal({1, 0, 0}, 0.0)));
}

// The MikkTSpace form reproduces Blender's forward decode normalize(x·T + y·B + z·N) exactly,
// for unit and non-unit tangents, tangents not orthogonal to N, both signs, and any tiling = 1.
/// A point with a random MikkTSpace frame for sample @p i: its tangent orthogonal to N and of
/// unit length every third sample (every sample with @p orthonormal), arbitrary otherwise; both
/// bitangent signs. False when the tangent lies too near N.
bool randomMikkTSpacePoint(Random& rng, int i, bool orthonormal, SurfacePoint& p) {
  p.normal = rng.unit();
  const Vec3d t = rng.unit();
  p.tangent = orthonormal || i % 3 == 0 ? normalizeOr(t - dot(t, p.normal) * p.normal, Vec3d{})
                                        : rng.uniform(0.5, 1.5) * t;
  p.bitangentSign = i % 2 ? 1.0 : -1.0;
  p.hasTangentFrame = true;
  return length(cross(p.normal, p.tangent)) >= 0.2;
}

TEST(GradientFromTangentNormal, MikkTSpaceFrameMatchesBlendersForwardDecode) {
  Random rng(6);
  double worst = 0;
  for (int i = 0; i < 2000; ++i) {
    SurfacePoint p;
    if (!randomMikkTSpacePoint(rng, i, false, p)) continue;
    Vec3d n = rng.unit();
    if (n.z < 0.05) n.z = std::abs(n.z) + 0.05;  // a valid texel, above the guard
    n = rng.uniform(0.8, 1.2) * n;               // and not of unit length
    const Vec3d b = p.bitangentSign * cross(p.normal, p.tangent);
    const Vec3d blender = normalizeOr(n.x * p.tangent + n.y * b + n.z * p.normal, Vec3d{});
    const Vec3d ours = resolveNormal(p.normal, gradientFromTangentNormal(n, p, 0));
    worst = std::max(worst, maxAbsDiff(ours, blender));
  }
  EXPECT_LT(worst, 1e-12);
}

// decodeTangentNormal is Blender's forward decode x·T + y·B + z·N itself, for every texel: a
// positive multiple of N − Γ above the horizon, below the tangent plane where z < 0 (where Γ only
// clamps it).
TEST(DecodeTangentNormal, IsBlendersForwardDecodeAboveAndBelowTheHorizon) {
  Random rng(16);
  int below = 0;
  for (int i = 0; i < 2000; ++i) {
    SurfacePoint p;
    if (!randomMikkTSpacePoint(rng, i, true, p)) continue;
    const Vec3d n = rng.uniform(0.8, 1.2) * rng.unit();
    const Vec3d b = p.bitangentSign * cross(p.normal, p.tangent);
    const Vec3d decoded = decodeTangentNormal(n, p, 0);
    EXPECT_LT(maxAbsDiff(decoded, n.x * p.tangent + n.y * b + n.z * p.normal), 1e-15);
    if (n.z > 0.05 * length(n)) {
      EXPECT_LT(maxAbsDiff(normalizeOr(decoded, Vec3d{}),
                           resolveNormal(p.normal, gradientFromTangentNormal(n, p, 0))),
                1e-12);
    } else if (n.z < 0) {
      ++below;
      EXPECT_LT(dot(decoded, p.normal), 0);
    }
  }
  EXPECT_GT(below, 500);
  SurfacePoint frameless;  // no MikkTSpace frame, no UV set: no decode
  EXPECT_EQ(decodeTangentNormal({0.1, 0.2, 0.9}, frameless, 0), (Vec3d{0, 0, 0}));
}

// Without precomputed tangents the frame is built from ∂P/∂u like the JCGT framework; it equals
// the MikkTSpace form whenever the MikkTSpace frame is that same frame.
TEST(GradientFromTangentNormal, UvDerivativeFrameEqualsMikkTSpaceWhenTheFramesAgree) {
  Random rng(7);
  for (int i = 0; i < 1000; ++i) {
    SurfacePoint p;
    p.normal = rng.unit();
    p.numUvSets = 2;
    p.uv[1] = {{0.2, 0.3}, rng.vector(), rng.vector()};
    Vec3d t, b;
    if (!uvDerivativeTangentFrame(p.uv[1], p.normal, t, b)) continue;
    EXPECT_NEAR(length(t), 1.0, 1e-14);
    EXPECT_NEAR(dot(t, p.normal), 0.0, 1e-14);
    p.uv[0] = p.uv[1];
    p.tangent = t;
    p.bitangentSign = dot(cross(p.uv[1].dPdu, p.uv[1].dPdv), p.normal) < 0 ? -1 : 1;
    p.hasTangentFrame = true;
    const Vec3d n = normalizeOr(Vec3d{rng.uniform(-1, 1), rng.uniform(-1, 1), 1}, Vec3d{});
    const TangentNormalOptions options{
        NormalMapGreen::kOpenGL, TangentFrameChoice::kAuto, 1.5, {2, 0.5}, {0, 0}};
    const Vec3d mikk = gradientFromTangentNormal(n, p, 0, options);  // kAuto + set 0: MikkTSpace
    const Vec3d uv1 = gradientFromTangentNormal(n, p, 1, options);   // set 1: UV derivatives
    TangentNormalOptions forced = options;
    forced.frame = TangentFrameChoice::kUvDerivatives;
    const Vec3d uv0 = gradientFromTangentNormal(n, p, 0, forced);
    EXPECT_LT(maxAbsDiff(mikk, uv1), 1e-12);
    EXPECT_LT(maxAbsDiff(mikk, uv0), 1e-12);
  }
}

Vec3d unit(const Vec3d& v) { return (1 / std::sqrt(dot(v, v))) * v; }

// Tiling repeats a normal map without steepening it, as in Blender (a Mapping node before the
// Image Texture only moves the Normal Map node's lookup): the slopes are the texel's own.
TEST(GradientFromTangentNormal, TilingRepeatsTheMapWithoutSteepeningIt) {
  SurfacePoint p;
  p.hasTangentFrame = true;  // T = +x, B = +y, N = +z
  const Vec3d n{0.2, -0.1, 0.8};
  TangentNormalOptions o;
  o.tiling = {2, 3};
  const Vec3d gamma = gradientFromTangentNormal(n, p, 0, o);
  EXPECT_NEAR(gamma.x, -0.2 / 0.8, 1e-15);
  EXPECT_NEAR(gamma.y, 0.1 / 0.8, 1e-15);
  EXPECT_EQ(gamma.z, 0.0);
}

// Strength is Blender's Normal Map node's: the decoded normal n' is blended with N as
// unit(N + s·(n' − N)), not a scaled height (which would give unit(s·x, s·y, z)).
TEST(GradientFromTangentNormal, StrengthBlendsNormalsAsBlenderDoes) {
  SurfacePoint p;
  p.hasTangentFrame = true;  // T = +x, B = +y, N = +z
  const Vec3d n{0.3, -0.4, 0.6};
  const Vec3d decoded = unit(n);
  for (const double s : {0.0, 0.25, 0.5, 2.0, 3.0}) {
    TangentNormalOptions o;
    o.strength = s;
    const Vec3d gamma = gradientFromTangentNormal(n, p, 0, o);
    const Vec3d expected = unit(p.normal + s * (decoded - p.normal));
    EXPECT_LT(maxAbsDiff(unit(p.normal - gamma), expected), 1e-14) << s;
    EXPECT_NEAR(dot(gamma, p.normal), 0.0, 1e-15) << s;
  }
  TangentNormalOptions negative;
  negative.strength = -1;  // Blender clamps Strength at 0: no bump
  EXPECT_EQ(gradientFromTangentNormal(n, p, 0, negative), Vec3d{});
  // Strength 1 is the decode itself, bit for bit.
  TangentNormalOptions one;
  EXPECT_EQ(withNormalMapStrength(gradientFromTangentNormal(n, p, 0, one), p.normal, 1),
            gradientFromTangentNormal(n, p, 0, one));
}

// Blender's Normal Map node decodes with the interpolated normal before it is renormalized,
// N_i = L·N: unit(x·T + y·sign·(N_i × T) + z·N_i). SurfacePoint::normalLength carries L.
TEST(GradientFromTangentNormal, DecodesWithTheUnnormalizedInterpolatedNormal) {
  SurfacePoint p;
  p.hasTangentFrame = true;
  p.normal = unit(Vec3d{0.1, 0.2, 1});
  p.tangent = Vec3d{0.9, 0.05, -0.1};  // interpolated: not unit, not orthogonal to N
  p.bitangentSign = -1;
  const Vec3d n{0.35, 0.2, 0.8};
  for (const double length : {1.0, 0.93, 0.7}) {
    p.normalLength = length;
    const Vec3d gamma = gradientFromTangentNormal(n, p, 0);
    const Vec3d interpolated = length * p.normal;
    const Vec3d expected =
        unit(n.x * p.tangent + n.y * -1.0 * cross(interpolated, p.tangent) + n.z * interpolated);
    EXPECT_LT(maxAbsDiff(unit(p.normal - gamma), expected), 1e-14) << length;
  }
}

TEST(GradientFromTangentNormal, DegenerateFramesAndMissingUvSetsGiveZero) {
  SurfacePoint p;
  p.numUvSets = 1;
  p.uv[0] = {{}, {1, 0, 0}, {2, 0, 0}};  // degenerate UV frame, no MikkTSpace frame
  const Vec3d n{0.3, 0.3, 0.9};
  EXPECT_EQ(gradientFromTangentNormal(n, p, 0), Vec3d{});
  EXPECT_EQ(gradientFromTangentNormal(n, p, 3), Vec3d{});  // set out of range
  EXPECT_EQ(gradientFromTangentNormal(n, p, -1), Vec3d{});
  p.hasTangentFrame = true;
  p.tangent = {};  // a zero MikkTSpace tangent: flat
  EXPECT_EQ(gradientFromTangentNormal(n, p, 0), Vec3d{});
}

// ---------------------------------------------------------------------------------------------
// object-space normals (eq. 38, JCGT form)

TEST(GradientFromObjectNormal, ResolvesBackToTheObjectNormalOrItsMirror) {
  Random rng(8);
  const double eps = kMinObjectNormalCosine;
  int positive = 0, negative = 0, grazing = 0;
  for (int i = 0; i < 5000; ++i) {
    const Vec3d n = rng.unit();
    const Vec3d no = rng.unit();
    const double len = rng.uniform(0.2, 5);  // non-unit N_o: same result
    const Vec3d gamma = gradientFromObjectNormal(len * no, n);
    ASSERT_TRUE(isFinite(gamma));
    EXPECT_NEAR(dot(gamma, n), 0.0, 1e-12 * (1 + length(gamma)));
    EXPECT_LE(length(gamma), 1 / eps + 1e-9);
    const Vec3d resolved = resolveNormal(n, gamma);
    const double k = dot(no, n);
    if (k >= eps) {
      ++positive;
      EXPECT_LT(maxAbsDiff(resolved, no), 1e-12);
    } else if (k <= -eps) {
      ++negative;
      const Vec3d mirrored = no - 2 * k * n;  // reflected across the tangent plane
      EXPECT_LT(maxAbsDiff(resolved, mirrored), 1e-12);
    } else {
      ++grazing;
    }
    // Always on the front side, leaning the way N_o's tangential part points.
    EXPECT_GT(dot(resolved, n), 0.0);
    const Vec3d tangential = no - k * n;
    EXPECT_GE(dot(resolved, tangential), -1e-12);
  }
  EXPECT_GT(positive, 1000);
  EXPECT_GT(negative, 1000);
}

TEST(GradientFromObjectNormal, GrazingZeroAndNanInputsAreFinite) {
  const Vec3d n{0, 0, 1};
  const double eps = kMinObjectNormalCosine;
  // Exactly in the tangent plane: leans towards it at elevation ≈ asin(ε).
  const Vec3d horizon = resolveNormal(n, gradientFromObjectNormal({1, 0, 0}, n));
  EXPECT_NEAR(horizon.z, eps / std::sqrt(1 + eps * eps), 1e-15);
  EXPECT_GT(horizon.x, 0.99);
  EXPECT_EQ(gradientFromObjectNormal({0, 0, 0}, n), Vec3d{});
  EXPECT_EQ(gradientFromObjectNormal({std::nan(""), 0, 1}, n), Vec3d{});
  EXPECT_EQ(gradientFromObjectNormal({0, 0, -1}, n), Vec3d{});  // straight down: mirrored to up
  EXPECT_EQ(gradientFromObjectNormal({0, 0, 5}, n), Vec3d{});
  EXPECT_TRUE(isFinite(gradientFromObjectNormal({1, 0, 0}, n, 0.0)));
}

// ---------------------------------------------------------------------------------------------
// resolving (eq. 33) with an object scale

// The perturbed normal of the explicitly displaced and transformed surface
// P(u,v) = M (S(u,v) + h(u,v) N) with a linear h: T_p = M(T + h_u N), B_p = M(B + h_v N),
// N_p = unit(T_p × B_p) (eq. 17-19), equals resolveNormal(N, Γ, cof(M)).
TEST(ResolveNormal, MatchesTheExplicitlyDisplacedAndScaledSurface) {
  Random rng(9);
  double worst = 0;
  for (int i = 0; i < 1000; ++i) {
    const Vec3d dPdu = rng.vector(), dPdv = rng.vector();
    const Vec3d n = normalizeOr(cross(dPdu, dPdv), Vec3d{});  // ⟨T×B, N⟩ > 0
    if (length(cross(dPdu, dPdv)) < 0.05) continue;
    const Vec2d d{rng.uniform(-2, 2), rng.uniform(-2, 2)};
    Mat3 m = Mat3::diagonal({rng.uniform(0.1, 10), rng.uniform(0.1, 10), rng.uniform(0.1, 10)});
    if (i % 2) m = rng.rotation() * m;
    if (i % 4 == 3) m = m * Mat3::diagonal({-1, 1, 1});  // a mirroring transform, det < 0
    const Vec3d tp = m * (dPdu + d.x * n), bp = m * (dPdv + d.y * n);
    const Vec3d expected = normalizeOr(cross(tp, bp), Vec3d{});
    const Vec3d ours =
        resolveNormal(n, gradientFromUvDerivatives({{}, dPdu, dPdv}, n, d), cofactor(m));
    worst = std::max(worst, maxAbsDiff(ours, expected));
  }
  EXPECT_LT(worst, 1e-12);
}

TEST(ResolveNormal, ZeroLengthResultsFallBackToTheUnperturbedNormal) {
  const Vec3d n{0, 0, 1};
  EXPECT_EQ(resolveNormal(n, n), n);  // N − Γ = 0
  const Mat3 scale = cofactor(Mat3::diagonal({2, 2, 2}));
  EXPECT_EQ(resolveNormal(n, n, scale), n);
  // Singular transform (flattened along z): cof = diag(0, 0, 1); a normal along x vanishes.
  const Mat3 flat = cofactor(Mat3::diagonal({1, 1, 0}));
  EXPECT_EQ(resolveNormal({1, 0, 0}, {}, flat), Vec3d(1, 0, 0));
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_EQ(resolveNormal(n, {inf, 0, 0}), n);
}

// Scaling the object by 1e±8 uniformly changes nothing; non-uniform 1e±8 scales stay finite and
// unit.
TEST(ResolveNormal, ExtremeObjectScalesAreFiniteAndUnit) {
  Random rng(10);
  for (const double s : {1e-8, 1.0, 1e8}) {
    for (int i = 0; i < 200; ++i) {
      const Vec3d n = rng.unit();
      const Vec3d gamma = 3 * rng.vector();
      const Vec3d uniform = resolveNormal(n, gamma, cofactor(Mat3::diagonal({s, s, s})));
      EXPECT_LT(maxAbsDiff(uniform, resolveNormal(n, gamma)), 1e-14);
      const Vec3d skewed = resolveNormal(n, gamma, cofactor(Mat3::diagonal({s, 1 / s, 1})));
      ASSERT_TRUE(isFinite(skewed));
      EXPECT_NEAR(length(skewed), 1.0, 1e-14);
    }
  }
}

// ---------------------------------------------------------------------------------------------
// no NaN anywhere: a sweep over extreme inputs of every kernel

TEST(SurfaceGradientKernels, NoNanForExtremeInputs) {
  Random rng(11);
  const double scales[] = {0.0, 1e-300, 1e-8, 1e-3, 1.0, 1e3, 1e8, 1e300};
  int checked = 0;
  for (int i = 0; i < 4000; ++i) {
    const double s1 = scales[i % 8], s2 = scales[(i / 8) % 8];
    SurfacePoint p;
    p.normal = rng.unit();
    p.numUvSets = 1;
    p.uv[0] = {{rng.uniform(-10, 10), rng.uniform(-10, 10)}, s1 * rng.vector(), s2 * rng.vector()};
    if (i % 5 == 0) p.uv[0].dPdv = 2 * p.uv[0].dPdu;  // degenerate
    if (i % 7 == 0) p.uv[0].dPdu = p.normal;          // ∂P/∂u along N
    p.tangent = (i % 3 == 0) ? Vec3d{} : rng.unit();
    p.hasTangentFrame = i % 2;
    p.bitangentSign = i % 4 < 2 ? 1 : -1;
    const Vec2d d{rng.uniform(-1, 1) * scales[(i / 3) % 8], rng.uniform(-1, 1)};
    const Vec3d texel = (i % 11 == 0) ? Vec3d{0, 0, 0} : rng.vector();  // includes n_z < 0
    const Vec3d gammas[] = {
        gradientFromUvDerivatives(p.uv[0], p.normal, d),
        gradientFromTangentNormal(texel, p, 0),
        gradientFromTangentNormal(texel, p, 0,
                                  {NormalMapGreen::kDirectX, TangentFrameChoice::kUvDerivatives}),
        gradientFromObjectNormal(texel, p.normal),
    };
    for (const Vec3d& g : gammas) {
      // Finite whenever the result is representable: huge frames give tiny Γ, tiny frames with
      // O(1) derivatives give huge but finite Γ up to 1e300 · 1e8.
      ASSERT_TRUE(isFinite(g)) << "case " << i;
      const Mat3 cof = cofactor(Mat3::diagonal({s1 + 1e-8, 1, s2 + 1e-8}));
      const Vec3d resolved = resolveNormal(p.normal, g, cof);
      ASSERT_TRUE(isFinite(resolved)) << "case " << i;
      EXPECT_NEAR(length(resolved), 1.0, 1e-12);
      ++checked;
    }
  }
  EXPECT_GT(checked, 10000);
}

}  // namespace
}  // namespace sgbake
