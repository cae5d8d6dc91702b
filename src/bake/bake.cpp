// bakeMap: validation, the row-block raster with one of the shaders of shaders.hpp per map kind,
// and the per-triangle data and heights the shaders read.
#include "sgbake/bake/bake.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <limits>
#include <new>
#include <string>
#include <variant>

#include "bake/height.hpp"
#include "bake/limit_shader.hpp"
#include "bake/raster.hpp"
#include "bake/shaders.hpp"
#include "bake/texel_frame.hpp"
#include "gradient/prepared_uv_frame.hpp"
#include "sgbake/core/math.hpp"
#include "sgbake/gradient/projection.hpp"
#include "sgbake/mesh/normals.hpp"

namespace sgbake {

// ---------------------------------------------------------------------------------------------
// Map kinds
// ---------------------------------------------------------------------------------------------

namespace {

struct MapInfo {
  MapKind kind;
  std::string_view name;
  int channels;
  bool needsTangents;
  bool isSigned = false;
};

constexpr std::array<MapInfo, 8> kMaps{{
    {MapKind::kTangentNormal, "tangent-normal", 3, true},
    {MapKind::kObjectNormal, "object-normal", 3, false},
    {MapKind::kHeight, "height", 1, false},
    {MapKind::kDerivative, "derivative", 2, false, true},
    {MapKind::kSurfaceGradient, "surface-gradient", 3, false, true},
    {MapKind::kTangent, "tangent", 3, true},
    {MapKind::kBitangent, "bitangent", 3, true},
    {MapKind::kMask, "mask", 1, false},
}};

const MapInfo& info(MapKind kind) {
  for (const MapInfo& m : kMaps)
    if (m.kind == kind) return m;
  return kMaps[0];  // unreachable for valid enumerators
}

}  // namespace

Result<NormalSwizzle> parseNormalSwizzle(std::string_view text) {
  const auto bad = [&](std::string_view why) {
    return Error::badInput("swizzle '" + std::string(text) + "' " + std::string(why) +
                           " (expected three signed axes, e.g. \"+X+Y+Z\" or \"+X-Y+Z\", or "
                           "Blender's POS_X, NEG_Y, ...)");
  };
  NormalSwizzle swizzle{};
  int found = 0;
  std::size_t i = 0;
  const auto upper = [&](std::size_t k) {
    return k < text.size() ? static_cast<char>(std::toupper(static_cast<unsigned char>(text[k])))
                           : '\0';
  };
  while (i < text.size()) {
    const char c = upper(i);
    if (c == ',' || c == ' ') {
      ++i;
      continue;
    }
    bool negate = false;
    if (c == '+' || c == '-') {
      negate = c == '-';
      ++i;
    } else if (upper(i + 3) == '_' && ((c == 'P' && upper(i + 1) == 'O' && upper(i + 2) == 'S') ||
                                       (c == 'N' && upper(i + 1) == 'E' && upper(i + 2) == 'G'))) {
      negate = c == 'N';
      i += 4;
    } else {
      return bad("has '" + std::string(1, text[i]) + "' where a sign is expected");
    }
    const char axis = upper(i);
    if (axis != 'X' && axis != 'Y' && axis != 'Z')
      return bad("has a sign without an axis X, Y or Z");
    if (found == 3) return bad("has more than three axes");
    swizzle[static_cast<std::size_t>(found++)] = {axis - 'X', negate};
    ++i;
  }
  if (found != 3) return bad("has " + std::to_string(found) + " axes, not three");
  return swizzle;
}

std::vector<std::pair<std::string, std::string>> normalChannelAttributes(
    const NormalSwizzle& stored, bool tangentSpace) {
  std::vector<std::pair<std::string, std::string>> attributes;
  if (tangentSpace && stored[1].axis == 1)
    attributes.emplace_back("sgbake:green", stored[1].negate ? "directx" : "opengl");
  if (stored != kIdentitySwizzle && !(tangentSpace && stored == kDirectXSwizzle))
    attributes.emplace_back("sgbake:swizzle", normalSwizzleName(stored));
  return attributes;
}

std::string normalSwizzleName(const NormalSwizzle& swizzle) {
  std::string name;
  for (const SwizzleAxis& s : swizzle) {
    name += s.negate ? '-' : '+';
    name += static_cast<char>('X' + s.axis);
  }
  return name;
}

Result<MapKind> parseMapKind(std::string_view name) {
  std::string known;
  for (const MapInfo& m : kMaps) {
    if (m.name == name) return m.kind;
    known += known.empty() ? "" : ", ";
    known += m.name;
  }
  return Error::badInput("unknown map '" + std::string(name) + "' (expected one of: " + known + ")");
}

std::string_view mapKindName(MapKind kind) { return info(kind).name; }
int mapChannels(MapKind kind) { return info(kind).channels; }
bool mapNeedsTangents(MapKind kind) { return info(kind).needsTangents; }
bool isSignedMap(MapKind kind) { return info(kind).isSigned; }

// ---------------------------------------------------------------------------------------------
// Per-triangle data and heights
// ---------------------------------------------------------------------------------------------

namespace bake_detail {

void triangleDerivatives(const std::array<Vec3d, 3>& p, const std::array<Vec2d, 3>& uv,
                         Vec3d& dPdu, Vec3d& dPdv) {
  const Vec3d e1 = p[1] - p[0], e2 = p[2] - p[0];
  const Vec2d d1 = uv[1] - uv[0], d2 = uv[2] - uv[0];
  const double det = d1.x * d2.y - d2.x * d1.y;
  const double scale = std::sqrt(lengthSquared(d1) * lengthSquared(d2));
  if (!(std::abs(det) > kMinUvTriangleSine * scale) || !std::isfinite(det)) {
    dPdu = {};
    dPdv = {};
    return;
  }
  // [e1 e2] = [∂P/∂u ∂P/∂v] · [[d1.x d2.x] [d1.y d2.y]], solved by Cramer's rule.
  const double inv = 1 / det;
  dPdu = inv * (d2.y * e1 - d1.y * e2);
  dPdv = inv * (d1.x * e2 - d2.x * e1);
}

void loadShadingTriangle(const Mesh& mesh, const CornerTangents* tangents,
                         const std::array<std::uint32_t, 3>& corners, int bakeUvSet,
                         ShadingTriangle& tri) {
  for (std::size_t i = 0; i < 3; ++i) {
    const std::uint32_t c = corners[i];
    tri.position[i] = cast<double>(mesh.positions[mesh.cornerVertex[c]]);
    tri.normal[i] = cast<double>(mesh.cornerNormals[c]);
    if (tangents != nullptr) {
      tri.tangent[i] = cast<double>(tangents->tangent[c]);
      tri.sign[i] = tangents->sign[c];
    }
  }
  tri.hasTangents = tangents != nullptr;
  tri.faceNormal = normalizeOr(cross(tri.position[1] - tri.position[0], tri.position[2] - tri.position[0]),
                               Vec3d{0, 0, 1});
  tri.flat = tri.polygonFrame = false;
  if (!mesh.faceFlat.empty()) {  // the face of the triangle's corners
    const std::size_t face = faceOfCorner(mesh, corners[0]);
    if (mesh.isFlat(face)) {
      tri.flat = !mesh.autoSmooth;
      tri.polygonFrame = true;
      tri.polygonNormal = normalizeOr(faceNormalDirection(mesh.view(), face), tri.faceNormal);
    }
  }
  tri.numUvSets = static_cast<int>(std::min<std::size_t>(mesh.uvSets.size(), kMaxUvSets));
  for (std::size_t s = 0; s < static_cast<std::size_t>(tri.numUvSets); ++s) {
    for (std::size_t i = 0; i < 3; ++i) tri.uv[s][i] = cast<double>(mesh.uvSets[s].uvs[corners[i]]);
    triangleDerivatives(tri.position, tri.uv[s], tri.dPdu[s], tri.dPdv[s]);
  }
  const std::size_t b = static_cast<std::size_t>(bakeUvSet);
  if (bakeUvSet < tri.numUvSets) {
    tri.bakeDPdu = tri.dPdu[b];
    tri.bakeDPdv = tri.dPdv[b];
  } else {
    const std::vector<Vec2f>& uvs = mesh.uvSets[b].uvs;
    triangleDerivatives(tri.position,
                        {cast<double>(uvs[corners[0]]), cast<double>(uvs[corners[1]]),
                         cast<double>(uvs[corners[2]])},
                        tri.bakeDPdu, tri.bakeDPdv);
  }
}

namespace {

double heightOf(const UvHeightSource& s, const SurfacePoint& p) {
  if (s.texture == nullptr || !hasUvSet(p, s.uvSet)) return 0;
  const Vec2d st = textureCoordinates(p.uv[static_cast<std::size_t>(s.uvSet)].uv, s.tiling, s.offset);
  return s.scale * s.texture->sample(st).value;
}
double heightOf(const VolumeSource& s, const SurfacePoint& p) {
  return s.volume == nullptr
             ? 0
             : s.scale * gradient_detail::unscaledHeightAt(s, p.position, p.seenNormal());
}
template <class Projection>
double heightOf(const Projection& s, const SurfacePoint& p) {
  if (s.kind != ProjectedKind::kHeight || s.height == nullptr) return 0;
  return gradient_detail::heightScale(s) *
         gradient_detail::unscaledHeightAt(s, p.position, p.seenNormal());
}
double heightOf(const TangentNormalSource&, const SurfacePoint&) { return 0; }
double heightOf(const ObjectNormalSource&, const SurfacePoint&) { return 0; }

}  // namespace

double layerHeight(const LayerSource& source, const SurfacePoint& point) {
  const double h = std::visit([&](const auto& s) { return heightOf(s, point); }, source);
  return std::isfinite(h) ? h : 0.0;
}

double compositeHeight(std::span<const Layer> layers, const SurfacePoint& point) {
  double h = 0;
  for (const Layer& layer : layers) {
    if (layer.weight == 0 || !std::isfinite(layer.weight)) continue;
    const double factor = layer.weight * layerMask(layer.mask, point);
    if (factor == 0) continue;
    h += factor * layerHeight(layer.source, point);
  }
  return std::isfinite(h) ? h : 0.0;
}

}  // namespace bake_detail

// ---------------------------------------------------------------------------------------------
// bakeMap
// ---------------------------------------------------------------------------------------------

namespace {

Status validateSettings(const BakeInput& input, const BakeSettings& s) {
  if (input.mesh == nullptr) return Error::badInput("bake: no mesh");
  const Mesh& mesh = *input.mesh;
  const std::string where = mesh.source.empty() ? std::string("bake") : mesh.source;
  if (s.width < 1 || s.height < 1 || s.width > kMaxBakeSide || s.height > kMaxBakeSide) {
    return Error::badInput(where + ": bake size " + std::to_string(s.width) + "x" +
                           std::to_string(s.height) + " is out of range (1 to " +
                           std::to_string(kMaxBakeSide) + " per side)");
  }
  if (s.samples < 1 || s.samples > kMaxBakeSamples) {
    return Error::badInput(where + ": samples " + std::to_string(s.samples) +
                           " is out of range (1 to " + std::to_string(kMaxBakeSamples) + ")");
  }
  if (s.uvSet < 0 || !mesh.hasUvSet(static_cast<std::size_t>(s.uvSet))) {
    return Error::badInput(where + ": the mesh has no UV set " + std::to_string(s.uvSet) + " (it has " +
                           std::to_string(mesh.uvSets.size()) + ")");
  }
  if (s.udimTile < kFirstUdimTile || s.udimTile > kLastUdimTile) {
    return Error::badInput(where + ": UDIM tile " + std::to_string(s.udimTile) +
                           " is out of range (1001 to 2000)");
  }
  if (s.threads < 0) return Error::badInput(where + ": threads must be 0 (all cores) or more");
  for (const SwizzleAxis& axis : s.swizzle) {
    if (axis.axis < 0 || axis.axis > 2) {
      return Error::badInput(where + ": a swizzle axis must be 0 (x), 1 (y) or 2 (z), not " +
                             std::to_string(axis.axis));
    }
  }
  if (input.tangents != nullptr && (input.tangents->tangent.size() != mesh.numCorners() ||
                                    input.tangents->sign.size() != mesh.numCorners())) {
    return Error::badInput(where + ": tangent frames do not match the mesh (" +
                           std::to_string(input.tangents->tangent.size()) + " for " +
                           std::to_string(mesh.numCorners()) + " corners)");
  }
  // (A limit surface gives every sample its own frame: LimitShader.)
  if (mapNeedsTangents(s.map) && input.tangents == nullptr && input.limit == nullptr) {
    return Error::badInput(where + ": the " + std::string(mapKindName(s.map)) +
                           " map needs tangent frames (none given)");
  }
  if (input.limit != nullptr && (input.limitParameters == nullptr ||
                                 !isTessellationOf(mesh, *input.limit, *input.limitParameters))) {
    return Error::badInput(where + ": the mesh is not a tessellation of the limit surface "
                                   "(subdivideMesh with its SurfaceParameters)");
  }
  // loopTriangles cuts every face of k corners into k − 2 triangles (counted, not cut again).
  const std::size_t frames = 3 * (mesh.numCorners() - 2 * mesh.numFaces());
  for (const CornerTangents* given : input.triangleTangents) {
    if (given == nullptr) continue;
    if (given->tangent.size() != frames || given->sign.size() != frames) {
      return Error::badInput(where + ": " + std::to_string(given->tangent.size()) +
                             " loop-triangle tangents for " + std::to_string(frames) +
                             " triangle corners");
    }
  }
  if (input.transform != nullptr) {
    if (Result<WorldSpace> space = WorldSpace::of(*input.transform); !space) {
      return Error::badInput(where + ": " + space.error().message);
    }
  }
  return validateLayers(input.layers, static_cast<int>(mesh.uvSets.size()));
}

/// Rasterizes @p job into @p target with the shader of settings.map. @p blank: the target was
/// just allocated, zero-filled (RasterOutput::blank).
void runBake(const BakeInput& input, const BakeSettings& settings, const bake_detail::RasterJob& job,
             const bake_detail::RasterTarget& target, bool blank) {
  using namespace bake_detail;
  BakeShaderBase base;
  base.mesh = input.mesh;
  base.tangents = input.tangents;
  base.triangleTangents = input.triangleTangents;
  base.layers = input.layers;
  base.uvSet = settings.uvSet;
  // Normal maps: the swizzle, then G negated for DirectX green (tangent-space maps).
  base.channels = storedChannels(settings.swizzle, settings.map == MapKind::kTangentNormal
                                                       ? settings.green
                                                       : NormalMapGreen::kOpenGL);
  // The object's transform (not for height maps, whose heights it does not change): a rotation
  // (or mirror) with a uniform scale s shades as object space with heights divided by s
  // (ObjectTransform::uniformScale) unless the Bump node's offsets are read, which Cycles
  // spreads along its orthonormals of the world Ng (a rotation turns them otherwise than the
  // object); any other is shaded in world space (world_shading.hpp).
  std::vector<Layer> scaledLayers;
  WorldSpace world;
  if (input.transform != nullptr && !input.transform->shadesAsObjectSpace() &&
      settings.map != MapKind::kHeight) {
    const bool bumpOffsets = std::ranges::any_of(input.layers, [](const Layer& layer) {
      return gradient_detail::readsBumpOffsets(layer.source);
    });
    if (const std::optional<double> s = input.transform->objectSpaceScale(bumpOffsets)) {
      // (Heights in object units are s times as high in the world: unchanged.)
      for (const Layer& layer : input.layers)
        scaledLayers.push_back(layer.objectSpaceHeight ? layer : withHeightsScaled(layer, 1 / *s));
      base.layers = scaledLayers;
    } else {
      world = WorldSpace::of(*input.transform).value();  // validateSettings checked it
      base.world = &world;
    }
  }
  // Heights differentiated as the Bump node does read them again half a texel away.
  if (std::ranges::any_of(base.layers, [](const Layer& layer) {
        return gradient_detail::readsBumpOffsets(layer.source);
      })) {
    base.bumpTexel = {1.0 / settings.width, 1.0 / settings.height};
  }
  // Layers of one material: each triangle takes its face's.
  const std::vector<std::vector<Layer>> byMaterial = layersByMaterial(base.layers);
  base.layersByMaterial = byMaterial;
  // The maps of Cycles' normals are shaded on the triangles Cycles reads the texels on; the
  // layers' loop-triangle frames are of Cycles' triangles.
  const bool normalMap =
      settings.map == MapKind::kTangentNormal || settings.map == MapKind::kObjectNormal;
  const bool layerFrames =
      std::ranges::any_of(input.triangleTangents, [](const auto* t) { return t != nullptr; });
  std::vector<std::array<std::uint32_t, 3>> shadingCorners;
  if ((normalMap || layerFrames) && input.limit == nullptr) {
    shadingCorners = cyclesShadingTriangles(*input.mesh, job.triangles);
  }
  if (normalMap) base.shadingCorners = shadingCorners;
  if (layerFrames) base.frameTriangles = shadingCorners.empty() ? job.triangles : shadingCorners;

  // Texels outside the islands of a tangent-space map: the surface's normal, (0, 0, 1), encoded.
  double flatEncoded[3];
  base.putEncoded(0, 0, 1, flatEncoded);
  const float kFlat[3] = {static_cast<float>(flatEncoded[0]), static_cast<float>(flatEncoded[1]),
                          static_cast<float>(flatEncoded[2])};
  static constexpr float kZero[3] = {0, 0, 0};
  RasterOutput output{kZero, false};
  output.blank = blank;
  // On a limit surface every sample is shaded from the surface under it (LimitShader).
  const auto run = [&](auto shader) {
    if (input.limit != nullptr) {
      rasterize(job, LimitShader<decltype(shader)>(shader, input.limit, input.limitParameters),
                output, target);
    } else {
      rasterize(job, shader, output, target);
    }
  };
  switch (settings.map) {
    case MapKind::kTangentNormal:
      output.background = kFlat;
      run(TangentNormalShader{base});
      break;
    case MapKind::kObjectNormal: run(ObjectNormalShader{base}); break;
    case MapKind::kHeight: run(HeightShader{base}); break;
    case MapKind::kDerivative: run(DerivativeShader{base}); break;
    case MapKind::kSurfaceGradient: run(SurfaceGradientShader{base}); break;
    case MapKind::kTangent: run(TangentShader{base}); break;
    case MapKind::kBitangent: run(BitangentShader{base}); break;
    case MapKind::kMask:
      output.valueIsCoverage = true;
      rasterize(job, MaskShader{}, output, target);
      break;
  }
}

Error outOfMemory(const BakeSettings& settings) {
  return Error::internal("bake: out of memory for a " + std::to_string(settings.width) + "x" +
                         std::to_string(settings.height) + " map");
}

}  // namespace

void bake_detail::worldTriangle(const bake_detail::ShadingTriangle& tri, const WorldSpace& space,
                                bake_detail::ShadingTriangle& world) {
  world = tri;
  for (std::size_t i = 0; i < 3; ++i) {
    world.position[i] = space.toWorld * tri.position[i] + space.translation;
    world.normal[i] = normalizeOr(space.normalToWorld * tri.normal[i], tri.normal[i]);
  }
  world.faceNormal = normalizeOr(space.normalToWorld * tri.faceNormal, tri.faceNormal);
  for (std::size_t s = 0; s < static_cast<std::size_t>(tri.numUvSets); ++s) {
    world.dPdu[s] = space.toWorld * tri.dPdu[s];
    world.dPdv[s] = space.toWorld * tri.dPdv[s];
  }
  world.bakeDPdu = space.toWorld * tri.bakeDPdu;
  world.bakeDPdv = space.toWorld * tri.bakeDPdv;
  world.polygonFrame = false;
  world.hasTangents = false;
  world.hasLayerTangents = {};
}

namespace {

/// The unit normal of triangle (p0, p1, p2) as Cycles computes it (Mesh::Triangle::compute_normal,
/// in float, the cross product divided by its length): MikkTSpace welds the
/// corners of a flat quad's two triangles where their normals are equal to the bit, so a normal
/// that rounds otherwise gives some flat quads other tangents.
Vec3f cyclesTriangleNormal(const Vec3f& p0, const Vec3f& p1, const Vec3f& p2) {
  const Vec3f n = cross(p1 - p0, p2 - p0);
  const float length = std::sqrt(n.x * n.x + n.y * n.y + n.z * n.z);
  if (length == 0.0f) return {1.0f, 0.0f, 0.0f};
  return {n.x / length, n.y / length, n.z / length};
}

}  // namespace

Result<CornerTangents> computeLoopTriangleTangents(const Mesh& mesh, int uvSet,
                                                   const TangentOptions& options) {
  if (uvSet < 0 || !mesh.hasUvSet(static_cast<std::size_t>(uvSet))) {
    return Error::badInput("loop-triangle tangents: the mesh has no UV set " +
                           std::to_string(uvSet));
  }
  const std::vector<std::array<std::uint32_t, 3>> triangles = bake_detail::cyclesTriangles(mesh);
  const std::size_t n = 3 * triangles.size();
  std::vector<std::uint32_t> faceStart(triangles.size() + 1), cornerVertex(n);
  std::vector<Vec3f> normals(n);
  std::vector<Vec2f> uvs(n);
  const std::vector<Vec2f>& meshUvs = mesh.uvSets[static_cast<std::size_t>(uvSet)].uvs;
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    faceStart[t + 1] = static_cast<std::uint32_t>(3 * (t + 1));
    const std::array<std::uint32_t, 3>& c = triangles[t];
    // Cycles shades a flat face without Auto Smooth, and gives MikkTSpace, its triangle's normal.
    const bool triangleNormal = !mesh.faceFlat.empty() && !mesh.autoSmooth &&
                                mesh.isFlat(bake_detail::faceOfCorner(mesh, c[0]));
    const Vec3f flat = cyclesTriangleNormal(mesh.positions[mesh.cornerVertex[c[0]]],
                                            mesh.positions[mesh.cornerVertex[c[1]]],
                                            mesh.positions[mesh.cornerVertex[c[2]]]);
    for (std::size_t i = 0; i < 3; ++i) {
      cornerVertex[3 * t + i] = mesh.cornerVertex[c[i]];
      normals[3 * t + i] = triangleNormal ? flat : mesh.cornerNormals[c[i]];
      uvs[3 * t + i] = meshUvs[c[i]];
    }
  }
  const MeshView view{mesh.positions, faceStart, cornerVertex, normals, uvs};
  return computeTangents(view, options);
}

CornerTangents loopTriangleFramesAtCorners(const Mesh& mesh, const CornerTangents& triangleFrames) {
  CornerTangents frames;
  frames.tangent.assign(mesh.numCorners(), Vec3f{});
  frames.sign.assign(mesh.numCorners(), 1.0f);
  std::vector<bool> found(mesh.numCorners(), false);
  const std::vector<std::array<std::uint32_t, 3>> triangles = bake_detail::cyclesTriangles(mesh);
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    for (std::size_t i = 0; i < 3; ++i) {
      const std::uint32_t c = triangles[t][i];
      const std::size_t k = 3 * t + i;
      if (found[c] || k >= triangleFrames.tangent.size()) continue;
      found[c] = true;
      frames.tangent[c] = triangleFrames.tangent[k];
      frames.sign[c] = triangleFrames.sign[k];
    }
  }
  return frames;
}

Result<FloatImage> bakeMap(const BakeInput& input, const BakeSettings& settings) {
  return bakeMap(input, settings, {});
}

Result<FloatImage> bakeMap(const BakeInput& input, const BakeSettings& settings,
                           const BakeProgressCallback& progress) {
  if (Status s = validateSettings(input, settings); !s) return s.error();
  try {
    const std::vector<std::array<std::uint32_t, 3>> triangles = loopTriangles(*input.mesh);
    FloatImage image;
    bake_detail::allocateImage(image, settings.width, settings.height, mapChannels(settings.map),
                               settings.threads);
    bake_detail::RasterJob job =
        bake_detail::rasterJobFor(*input.mesh, triangles, settings, settings.width, settings.height);
    bool stopped = false;
    if (progress) {  // bands of the whole image: it holds every row they read
      job.onRowsFinal = [&](int rowsFinal) {
        stopped = !progress(rowsFinal, settings.height);
        return !stopped;
      };
    }
    runBake(input, settings, job, bake_detail::RasterTarget::of(image), /*blank=*/true);
    if (stopped) return Error{ErrorCode::kCancelled, "bake: cancelled"};
    return image;
  } catch (const std::bad_alloc&) {
    return outOfMemory(settings);
  }
}

Status bakeMapRows(const BakeInput& input, const BakeSettings& settings, int keepRows,
                   const BakedRowsSink& sink) {
  if (Status s = validateSettings(input, settings); !s) return s;
  if (keepRows < 0) return Error::badInput("bake: rows to keep must be 0 or more");
  if (!sink) return Error::badInput("bake: no sink for the baked rows");
  Status result = Ok{};
  try {
    const std::vector<std::array<std::uint32_t, 3>> triangles = loopTriangles(*input.mesh);
    const int W = settings.width, H = settings.height, C = mapChannels(settings.map);
    // Bands are at most kBakeBandRows rows, and a call may read keepRows rows above its band.
    const int ringRows = bakeRingRows(H, keepRows);
    const std::size_t ringTexels = static_cast<std::size_t>(ringRows) * static_cast<std::size_t>(W);
    std::vector<float> pixels(ringTexels * static_cast<std::size_t>(C));
    std::vector<float> coverage(ringTexels);
    const bake_detail::RasterTarget target{pixels.data(), coverage.data(), C, ringRows};

    bake_detail::RasterJob job = bake_detail::rasterJobFor(*input.mesh, triangles, settings, W, H);
    int previousEnd = 0;
    job.onRowsFinal = [&](int rowsFinal) {
      const MutableImageRows rows{W, H, C, std::max(0, previousEnd - keepRows), rowsFinal, ringRows,
                           pixels.data(), coverage.data()};
      previousEnd = rowsFinal;
      result = sink(rows);
      return result.ok();
    };
    // Not blank: every band's slots still hold the band before, and are reset block by block.
    runBake(input, settings, job, target, /*blank=*/false);
  } catch (const std::bad_alloc&) {
    return outOfMemory(settings);
  }
  return result;
}

}  // namespace sgbake
