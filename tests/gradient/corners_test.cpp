// The per-corner driver: SurfacePoints built from a Mesh (corner triangles, the fallback for
// degenerate corners, MikkTSpace frames), exact constant gradients of linear heights on planar
// meshes, the closed-form sine normal, identical UV sets, thread independence, the table format.

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "sgbake/core/math.hpp"
#include "sgbake/gradient/corners.hpp"
#include "support/analytic_textures.hpp"
#include "support/parametric_mesh.hpp"

namespace sgbake {
namespace {

using test::AnalyticHeight;
using test::maxAbsDiff;

class WavyNormalTexture final : public VectorTexture {
 public:
  Vec3d sample(Vec2d st) const override {
    const Vec3d n =
        normalizeOr(Vec3d{0.4 * std::sin(5 * st.x), 0.3 * std::cos(3 * st.y), 1}, Vec3d{});
    return 0.5 * n + Vec3d{0.5, 0.5, 0.5};
  }
};

/// A mesh from explicit faces; every corner gets @p normal and the UV @p uvOf(position).
template <class UvOf>
Mesh makeMesh(const std::vector<Vec3f>& positions,
              const std::vector<std::vector<std::uint32_t>>& faces, Vec3f normal, UvOf uvOf) {
  Mesh mesh;
  mesh.source = "test";
  mesh.positions = positions;
  UvSet uv{"UVMap", {}};
  for (const auto& face : faces) {
    for (const std::uint32_t v : face) {
      mesh.cornerVertex.push_back(v);
      mesh.cornerNormals.push_back(normal);
      uv.uvs.push_back(uvOf(positions[v]));
    }
    mesh.faceStart.push_back(static_cast<std::uint32_t>(mesh.cornerVertex.size()));
  }
  mesh.uvSets.push_back(std::move(uv));
  return mesh;
}

std::vector<CornerSample> evaluate(const Mesh& mesh, const std::vector<Layer>& layers,
                                   const CornerOptions& options = {}) {
  auto result = evaluateCorners(mesh, layers, options);
  EXPECT_TRUE(result.ok()) << (result.ok() ? "" : result.error().message);
  return result.ok() ? std::move(result).value() : std::vector<CornerSample>{};
}

// ---------------------------------------------------------------------------------------------

// A linear height on a planar grid (UV = (x, y)): Γ is the same exact constant at every corner.
TEST(Corners, LinearHeightOnAPlanarGridIsAnExactConstant) {
  const Mesh mesh = test::gridMesh(test::plane, 4, 3);
  AnalyticHeight h(0.5, -0.25, 0);
  const std::vector<Layer> layers{{UvHeightSource{&h, 0, 0.5, {2, 4}, {0.1, 0.3}}, 1, {}}};
  const auto samples = evaluate(mesh, layers);
  ASSERT_EQ(samples.size(), mesh.numCorners());
  for (const CornerSample& s : samples) {
    EXPECT_EQ(s.gradient, Vec3d(0.5 * 2 * 0.5, 0.5 * 4 * -0.25, 0)) << "corner " << s.corner;
    EXPECT_LT(maxAbsDiff(s.tangent, Vec3d(1, 0, 0)), 1e-6);
    EXPECT_EQ(s.sign, 1.0);
  }
}

// A tilted plane with a sheared parametrization P(u, v) = (2u − v, 2v, u) (all coordinates
// dyadic, so the float mesh is exact): Γ is constant and satisfies eq. 32 exactly.
TEST(Corners, LinearHeightOnATiltedShearedPlaneIsAnExactConstant) {
  std::vector<Vec3f> positions;
  std::vector<std::vector<std::uint32_t>> faces;
  const int n = 4;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const float u = 0.25f * static_cast<float>(i), v = 0.25f * static_cast<float>(j);
      positions.push_back({2 * u - v, 2 * v, u});
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const auto at = [&](int a, int b) { return static_cast<std::uint32_t>(b * (n + 1) + a); };
      if ((i + j) % 2) {
        faces.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)});
      } else {  // triangles too
        faces.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
        faces.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
      }
    }
  const Vec3d dPdu{2, 0, 1}, dPdv{-1, 2, 0};
  const Vec3f normal = cast<float>(normalizeOr(cross(dPdu, dPdv), Vec3d{}));
  const Mesh mesh = makeMesh(positions, faces, normal, [](Vec3f p) {
    return Vec2f{p.z, 0.5f * p.y};  // u = z, v = y/2
  });
  AnalyticHeight h(0.75, -0.5, 0);
  const std::vector<Layer> layers{{UvHeightSource{&h, 0}, 1, {}}};
  const auto samples = evaluate(mesh, layers);
  const Vec3d n0 = cast<double>(normal);
  for (const CornerSample& s : samples) {
    EXPECT_EQ(s.gradient, samples[0].gradient);
    EXPECT_NEAR(dot(s.gradient, dPdu), 0.75, 1e-15);
    EXPECT_NEAR(dot(s.gradient, dPdv), -0.5, 1e-15);
    EXPECT_NEAR(dot(s.gradient, n0), 0.0, 1e-15);
  }
}

// A sine height on the plane z = 0 with UV = (x, y): at every corner the perturbed normal is the
// closed form normalize(−∂h/∂x, −∂h/∂y, 1).
TEST(Corners, SineHeightOnAPlaneGivesTheClosedFormNormal) {
  const Mesh mesh = test::gridMesh(test::plane, 16, 16);
  AnalyticHeight h(0, 0, 0.2);
  const Vec2d tiling{1.5, 2}, offset{0.1, 0.2};
  const std::vector<Layer> layers{{UvHeightSource{&h, 0, 0.8, tiling, offset}, 1, {}}};
  double worst = 0;
  for (const CornerSample& s : evaluate(mesh, layers)) {
    const Vec2d g =
        h.sample(textureCoordinates({s.position.x, s.position.y}, tiling, offset)).gradient;
    const Vec3d expected =
        normalizeOr(Vec3d{-0.8 * tiling.x * g.x, -0.8 * tiling.y * g.y, 1}, Vec3d{});
    worst = std::max(worst, maxAbsDiff(s.perturbed, expected));
  }
  EXPECT_LT(worst, 1e-12);
}

// A tangent-space map on a second UV set identical to the first equals the map on the first: the
// MikkTSpace frame of a plane is the UV-derivative frame (up to MikkTSpace's float tangents).
TEST(Corners, TangentNormalOnASecondIdenticalUvSetEqualsTheFirst) {
  Mesh mesh = test::gridMesh(test::plane, 6, 5);
  mesh.uvSets.push_back(mesh.uvSets[0]);
  WavyNormalTexture ts;
  const auto first = evaluate(mesh, {{TangentNormalSource{&ts, 0, {}}, 1, {}}});
  const auto second = evaluate(mesh, {{TangentNormalSource{&ts, 1, {}}, 1, {}}});
  ASSERT_EQ(first.size(), second.size());
  for (std::size_t c = 0; c < first.size(); ++c) {
    EXPECT_LT(maxAbsDiff(first[c].gradient, second[c].gradient), 1e-6) << c;
    EXPECT_GT(length(first[c].gradient), 0.01);
  }
}

TEST(Corners, CornerTrianglesFollowANonPlanarQuad) {
  const Mesh mesh = makeMesh({{0, 0, 0}, {1, 0, 0}, {1, 1, 1}, {0, 1, 0}}, {{0, 1, 2, 3}},
                             Vec3f{0, 0, 1}, [](Vec3f p) {
                               return Vec2f{p.x, p.y};
                             });
  const SurfacePoint c0 = cornerSurfacePoint(mesh, nullptr, 0, 0);
  EXPECT_EQ(c0.uv[0].dPdu, Vec3d(1, 0, 0));
  EXPECT_EQ(c0.uv[0].dPdv, Vec3d(0, 1, 0));
  const SurfacePoint c2 = cornerSurfacePoint(mesh, nullptr, 0, 2);  // triangle (1, 2, 3)
  EXPECT_EQ(c2.uv[0].dPdu, Vec3d(1, 0, 1));
  EXPECT_EQ(c2.uv[0].dPdv, Vec3d(0, 1, 1));
  EXPECT_EQ(c2.uv[0].uv, Vec2d(1, 1));
  EXPECT_FALSE(c2.hasTangentFrame);
  EXPECT_EQ(c2.numUvSets, 1);
}

// A pentagon with a corner on a straight edge: that corner's own triangle is flat, so it takes
// the best triangle of the face's triangulation through it, which has the face's exact frame.
TEST(Corners, DegenerateCornerTrianglesFallBackToTheTriangulation) {
  const Mesh mesh = makeMesh({{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {2, 2, 0}, {0, 2, 0}},
                             {{0, 1, 2, 3, 4}}, Vec3f{0, 0, 1}, [](Vec3f p) {
                               return Vec2f{0.5f * p.x, 0.5f * p.y};
                             });
  for (std::uint32_t c = 0; c < 5; ++c) {
    const SurfacePoint p = cornerSurfacePoint(mesh, nullptr, 0, c);
    EXPECT_EQ(p.uv[0].dPdu, Vec3d(2, 0, 0)) << c;
    EXPECT_EQ(p.uv[0].dPdv, Vec3d(0, 2, 0)) << c;
  }
}

// Collapsed UVs: no usable triangle, ∂P/∂u = ∂P/∂v = 0, Γ = 0, N' = N — finite everywhere.
TEST(Corners, CollapsedUvsGiveTheUnperturbedNormal) {
  const Mesh mesh = makeMesh({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}},
                             {{0, 1, 2, 3}, {0, 2, 3}}, Vec3f{0, 0, 1}, [](Vec3f) {
                               return Vec2f{0.5f, 0.5f};
                             });
  AnalyticHeight h(1, 1, 0.3);
  WavyNormalTexture ts;
  const auto samples = evaluate(
      mesh, {{UvHeightSource{&h, 0}, 1, {}},
             {TangentNormalSource{&ts,
                                  0,
                                  {TangentNormalOptions{NormalMapGreen::kOpenGL,
                                                        TangentFrameChoice::kUvDerivatives}}},
              1,
              {}}});
  for (const CornerSample& s : samples) {
    EXPECT_EQ(s.gradient, Vec3d{});
    EXPECT_EQ(s.perturbed, Vec3d(0, 0, 1));
    EXPECT_TRUE(isFinite(s.tangent));
  }
}

TEST(Corners, ResultDoesNotDependOnTheThreadCount) {
  const Mesh mesh = test::gridMesh(test::torus, 40, 20);
  AnalyticHeight h(0.1, 0.2, 0.05);
  WavyNormalTexture ts;
  TriplanarSource tri;
  tri.height = &h;
  const std::vector<Layer> layers{{UvHeightSource{&h, 0, 0.3, {4, 2}}, 1, {}},
                                  {TangentNormalSource{&ts, 0, {}}, 0.5, {}},
                                  {tri, 0.2, {}}};
  const std::string one = formatCornerTable(evaluate(mesh, layers, {1}));
  const std::string many = formatCornerTable(evaluate(mesh, layers, {4}));
  const std::string all = formatCornerTable(evaluate(mesh, layers, {0}));
  EXPECT_EQ(one, many);
  EXPECT_EQ(one, all);
}

TEST(Corners, TableHasTheHeaderAndOneRowOfTwentyFieldsPerCorner) {
  const Mesh mesh = makeMesh({{0.1f, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}, {{0, 1, 2, 3}},
                             Vec3f{0, 0, 1}, [](Vec3f p) {
                               return Vec2f{p.x, p.y};
                             });
  AnalyticHeight h(1.0 / 3.0, 0, 0);
  const auto samples = evaluate(mesh, {{UvHeightSource{&h, 0}, 1, {}}});
  std::ostringstream out;
  writeCornerTable(out, samples);
  EXPECT_EQ(out.str(), formatCornerTable(samples));
  std::istringstream in(out.str());
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "face,corner,px,py,pz,nx,ny,nz,tx,ty,tz,sign,u,v,gx,gy,gz,mx,my,mz");
  int rows = 0;
  while (std::getline(in, line)) {
    std::vector<std::string> fields;
    std::stringstream ss(line);
    for (std::string f; std::getline(ss, f, ',');) fields.push_back(f);
    ASSERT_EQ(fields.size(), 20u) << line;
    EXPECT_EQ(fields[0], "0");
    EXPECT_EQ(fields[1], std::to_string(rows));
    for (const std::string& f : fields) {
      EXPECT_NE(f, "-0");
      EXPECT_EQ(f.find("nan"), std::string::npos);
      std::size_t digits = 0;
      for (char ch : f.substr(0, f.find('e'))) digits += (ch >= '0' && ch <= '9');
      EXPECT_LE(digits, 10u) << f;  // 9 significant digits (+ a leading "0." zero)
    }
    ++rows;
  }
  EXPECT_EQ(rows, 4);
  // Corner 0 sits at x = 0.1f = 0.100000001490116...: 9 significant digits.
  EXPECT_NE(out.str().find("\n0,0,0.100000001,0,0,0,0,1,"), std::string::npos) << out.str();
  // gx = 1/3 at every corner (a linear height on a unit-UV quad).
  EXPECT_NE(out.str().find(",0.333333333,0,0,"), std::string::npos);
}

TEST(Corners, MeshesWithoutUvsStillEvaluateSpatialLayers) {
  Mesh mesh = test::gridMesh(test::sphere, 12, 6);
  mesh.uvSets.clear();
  auto sine = DirectionalSine::create({0.1, 2, {0, 0, 1}, 0});
  ASSERT_TRUE(sine.ok());
  const auto samples = evaluate(mesh, {{VolumeSource{&*sine}, 1, {}}});
  ASSERT_EQ(samples.size(), mesh.numCorners());
  for (const CornerSample& s : samples) {
    EXPECT_EQ(s.tangent, Vec3d{});
    EXPECT_EQ(s.sign, 1.0);
    EXPECT_EQ(s.uv, Vec2d{});
    const Vec3d g = sine->analyticGradient(s.position);
    EXPECT_LT(maxAbsDiff(s.gradient, g - dot(g, s.normal) * s.normal), 1e-15);
  }
}

TEST(Corners, InvalidInputIsAnError) {
  const Mesh mesh = test::gridMesh(test::plane, 2, 2);
  AnalyticHeight h(1, 0, 0);
  const std::vector<Layer> missingSet{{UvHeightSource{&h, 1}, 1, {}}};
  auto result = evaluateCorners(mesh, missingSet);
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.error().code, ErrorCode::kBadInput);
  Mesh broken = mesh;
  broken.cornerNormals.pop_back();
  EXPECT_FALSE(evaluateCorners(broken, {}).ok());
}

// A non-uniform object scale resolves every corner with cof(M) (eq. 33); Γ stays object space.
TEST(Corners, ObjectScaleCofactorAppliesToThePerturbedNormalOnly) {
  const Mesh mesh = test::gridMesh(test::cylinder, 12, 4);
  AnalyticHeight h(0.2, 0.1, 0.05);
  const std::vector<Layer> layers{{UvHeightSource{&h, 0}, 1, {}}};
  CornerOptions scaled;
  scaled.objectScaleCofactor = cofactor(Mat3::diagonal({1e8, 1, 1e-8}));
  const auto plain = evaluate(mesh, layers);
  const auto withScale = evaluate(mesh, layers, scaled);
  for (std::size_t c = 0; c < plain.size(); ++c) {
    EXPECT_EQ(plain[c].gradient, withScale[c].gradient);
    const Vec3d expected =
        resolveNormal(plain[c].normal, plain[c].gradient, scaled.objectScaleCofactor);
    EXPECT_EQ(withScale[c].perturbed, expected);
    EXPECT_NEAR(length(withScale[c].perturbed), 1.0, 1e-14);
  }
}

// Shaded through a transform (CornerOptions::world) and by material, as the bake shades texels:
// the plane z = 0 of an object scaled (2, 0.5, 1.5) with a ramp h = 0.3·u on material 1 only.
// Material 1's corners get the world bump brought back to object space, Γ = (0.3/1.5, 0, 0)
// (only the scale across the plane matters; the maps test has the derivation), material 0's
// none.
TEST(Corners, WorldShadingAndMaterialsAsTheBakeDoes) {
  Mesh mesh = test::gridMesh(test::plane, 4, 2);
  mesh.faceMaterial.resize(mesh.numFaces());
  for (std::size_t f = 0; f < mesh.numFaces(); ++f) mesh.faceMaterial[f] = f % 2 == 0 ? 1 : 0;
  const AnalyticHeight ramp(0.3, 0, 0);  // h = 0.3·s
  Layer layer{UvHeightSource{&ramp, 0}, 1, {}};
  layer.material = 1;
  const Result<WorldSpace> space = WorldSpace::of({Mat3::diagonal({2, 0.5, 1.5}), {1, 2, 3}});
  ASSERT_TRUE(space.ok());
  CornerOptions options;
  options.world = &*space;
  const auto corners = evaluate(mesh, {layer}, options);
  ASSERT_EQ(corners.size(), mesh.numCorners());
  for (const CornerSample& s : corners) {
    const bool bumped = mesh.material(s.face) == 1;
    const Vec3d expected = bumped ? Vec3d{0.3 / 1.5, 0, 0} : Vec3d{};
    EXPECT_LT(maxAbsDiff(s.gradient, expected), 1e-12) << "corner " << s.corner;
    EXPECT_LT(maxAbsDiff(s.perturbed, resolveNormal(s.normal, expected)), 1e-12);
  }
}

// Every source kind on curved meshes with seams and poles: finite, unit perturbed normals.
TEST(Corners, CurvedMeshesWithEverySourceAreFinite) {
  AnalyticHeight h(0.1, 0.2, 0.05);
  WavyNormalTexture ts;
  auto noise = GradientNoise::create({0.05, 3, 7, 2});
  ASSERT_TRUE(noise.ok());
  TriplanarSource triTs, triOs;
  triTs.kind = ProjectedKind::kTangentNormal;
  triTs.normals = &ts;
  triOs.kind = ProjectedKind::kObjectNormal;
  triOs.normals = &ts;
  const std::vector<Layer> layers{{UvHeightSource{&h, 0, 0.3, {4, 2}}, 1, {}},
                                  {TangentNormalSource{&ts, 0, {}}, 0.5, {}},
                                  {ObjectNormalSource{&ts, 0}, 0.3, {}},
                                  {VolumeSource{&*noise, GradientScheme::kCentral, 1e-5, 1}, 1, {}},
                                  {triTs, 0.2, {}},
                                  {triOs, 0.2, {&h, 0}}};
  for (const test::Surface& surface :
       {test::Surface(test::sphere), test::Surface(test::torus), test::Surface(test::cylinder)}) {
    const Mesh mesh = test::gridMesh(surface, 24, 12);
    for (const CornerSample& s : evaluate(mesh, layers)) {
      ASSERT_TRUE(isFinite(s.gradient));
      ASSERT_TRUE(isFinite(s.perturbed));
      EXPECT_NEAR(length(s.perturbed), 1.0, 1e-12);
    }
  }
}

}  // namespace
}  // namespace sgbake
