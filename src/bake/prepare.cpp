/// @file prepare.cpp
/// @brief The input-independent steps of running a plan (see prepare.hpp).
#include "bake/prepare.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <utility>
#include <vector>

#include "sgbake/gradient/blender_noise.hpp"
#include "sgbake/gradient/filters.hpp"
#include "sgbake/gradient/remap.hpp"
#include "sgbake/gradient/udim.hpp"

namespace sgbake::plan_detail {

OutputPadding outputPadding(const SceneOutput& output) {
  if (output.map == MapKind::kMask) return {PaddingMode::kExtend, 0};
  if (output.padding == PaddingMode::kPushPull) return {PaddingMode::kPushPull, 0};
  return {output.padding, std::max(output.margin, 0)};
}

void padImage(FloatImage& image, const OutputPadding& padding, const BakeInput& input,
              const BakeSettings& settings) {
  sgbake::padImage(image, padding.mode, padding.margin, *input.mesh, settings.uvSet,
                   settings.udimTile, settings.samples, settings.threads);
}

namespace {

/// Above this many faces at one vertex, subdividing is slow enough to say so beforehand.
constexpr std::uint32_t kSlowSubdivisionValence = 100;

struct VertexValence {
  std::uint32_t vertex = 0;
  std::uint32_t corners = 0;  ///< how many face corners lie on it
};

/// The vertex that is a corner of the most faces (the first such).
VertexValence largestValence(const Mesh& mesh) {
  std::vector<std::uint32_t> corners(mesh.positions.size());
  for (const std::uint32_t v : mesh.cornerVertex) ++corners[v];
  VertexValence busiest;
  for (std::uint32_t v = 0; v < corners.size(); ++v)
    if (corners[v] > busiest.corners) busiest = {v, corners[v]};
  return busiest;
}

}  // namespace

Status setSurface(const Scene& scene, Mesh coarse, Loaded& loaded) {
  if (scene.transform && !scene.transform->shadesAsObjectSpace()) {
    Result<WorldSpace> world = WorldSpace::of(*scene.transform);
    if (!world) return world.error();
    loaded.transform = scene.transform;
    loaded.world = *world;
  }
  const SceneSubdivision& subdivision = scene.subdivision;
  if (!subdivision.requested()) {
    loaded.mesh = std::move(coarse);
    return Ok{};
  }
  // Creases that do not fit the mesh are the scene's mistake: name its key, or the option of a
  // scene made from the command line.
  if (const std::optional<CreaseIssue> issue = findCreaseIssue(coarse, subdivision.options())) {
    if (scene.source.empty() && !scene.inMemory) {
      return Error::badInput(scene.mesh.string() + ": " + issue->flag() + " #" +
                             std::to_string(issue->index + 1) + ": " + issue->what);
    }
    return Error::badInput(scenePrefix(scene) + "subdivision." + issue->key() + "[" +
                           std::to_string(issue->index) + "]: " + issue->what +
                           (scene.inMemory ? std::string() : " (" + scene.mesh.string() + ")"));
  }
  // An OBJ's normals can show that Auto Smooth split them (normalsShowAutoSmooth), not at
  // which angle: the subdivided mesh, which Blender splits again by that angle, cannot be.
  if (coarse.autoSmooth && !subdivision.options().autoSmoothDegrees) {
    loaded.warnings.push_back(
        scene.mesh.string() + ": its normals are split at sharp edges (Auto Smooth), but " +
        (subdivision.limitSurface()
             ? std::string("the exact limit surface is shaded with its own smooth normals")
             : std::string("the subdivided mesh is shaded smooth: give \"auto_smooth\" "
                           "(--auto-smooth DEG) with the object's Auto Smooth angle to split its "
                           "normals as Blender does")));
  }
  // Subdividing around a vertex of many faces takes time growing as the cube of their number
  // (OpenSubdiv's end caps, in Blender too: docs/subdivision.md): say so before it starts.
  if (const VertexValence busiest = largestValence(coarse);
      busiest.corners > kSlowSubdivisionValence) {
    loaded.warnings.push_back(scene.mesh.string() + ": vertex " +
                              std::to_string(busiest.vertex + 1) + " is a corner of " +
                              std::to_string(busiest.corners) +
                              " faces: subdividing around it is slow (about 2 s at 128 faces, "
                              "2 minutes at 400; Blender's modifier too)");
  }
  if (!subdivision.limitSurface()) {
    Result<Mesh> subdivided = subdivideMesh(coarse, subdivision.options());
    if (!subdivided) return subdivided.error();
    loaded.mesh = std::move(*subdivided);
    return Ok{};
  }
  // The limit surface, and the tessellation the raster walks to find it.
  Result<LimitTessellation> limit = tessellateLimitSurface(coarse, subdivision.options());
  if (!limit) return limit.error();
  loaded.limit = std::move(limit->surface);
  loaded.mesh = std::move(limit->mesh);
  loaded.limitParameters = std::move(limit->parameters);
  return Ok{};
}

namespace {

/// The length of the mesh's bounding-box diagonal (the scale of volume gradient steps).
double boundingBoxDiagonal(const Mesh& mesh) {
  if (mesh.positions.empty()) return 1;
  Vec3d lo{mesh.positions[0].x, mesh.positions[0].y, mesh.positions[0].z};
  Vec3d hi = lo;
  for (const Vec3f& p : mesh.positions) {
    lo = {std::min<double>(lo.x, p.x), std::min<double>(lo.y, p.y), std::min<double>(lo.z, p.z)};
    hi = {std::max<double>(hi.x, p.x), std::max<double>(hi.y, p.y), std::max<double>(hi.z, p.z)};
  }
  const Vec3d d = hi - lo;
  return std::sqrt(dot(d, d));
}

/// The UV set check: every UV set an output bakes on or a layer reads must exist.
Status checkUvSets(const Plan& plan, const Mesh& mesh) {
  const Scene& s = plan.scene;
  const auto missing = [&](const std::string& user, int uvSet) {
    return Error::badInput(s.mesh.string() + ": has " + std::to_string(mesh.uvSets.size()) +
                           " UV set(s) but " + user + " uses UV set " + std::to_string(uvSet) +
                           " (UV sets are numbered from 0)");
  };
  for (const PlannedOutput& output : plan.outputs) {
    const SceneOutput& out = s.outputs[output.sceneOutput];
    if (!output.upToDate && out.kind == OutputKind::kMap &&
        !mesh.hasUvSet(static_cast<std::size_t>(out.uvSet))) {
      return missing(outputLabel(output.sceneOutput), out.uvSet);
    }
  }
  for (const PlannedLayer& planned : plan.layers) {
    const SceneLayer& layer = s.layers[planned.sceneLayer];
    const bool uvLayer =
        layer.type == SceneLayerType::kHeight || layer.type == SceneLayerType::kNormal;
    if (uvLayer && !mesh.hasUvSet(static_cast<std::size_t>(layer.uvSet))) {
      return missing(layerLabel(planned.sceneLayer), layer.uvSet);
    }
    if (layer.decodesInUvTangentFrames() &&
        !mesh.hasUvSet(static_cast<std::size_t>(layer.frameUvSet()))) {
      return missing(layerLabel(planned.sceneLayer) + "'s tangent frames", layer.frameUvSet());
    }
    if (layer.mask && !mesh.hasUvSet(static_cast<std::size_t>(layer.mask->uvSet))) {
      return missing(layerLabel(planned.sceneLayer) + ".mask", layer.mask->uvSet);
    }
  }
  return Ok{};
}

}  // namespace

std::vector<bool> reachedUdimTiles(const Mesh& mesh, const TouchedTiles& touched,
                                   bool cornerTable) {
  // A corner on a tile's left or bottom edge samples that tile in the corner table (a UV of
  // exactly 1 samples the tile to the right); texels sample inside the triangles only.
  // One flag per tile number (0: outside the tiles), not a tree insertion per corner.
  std::vector<bool> reached(static_cast<std::size_t>(kLastUdimTile) + 1, false);
  const auto reach = [&reached](int tile) {
    if (tile <= kLastUdimTile) reached[static_cast<std::size_t>(tile)] = true;
  };
  for (std::size_t uv = 0; uv < mesh.uvSets.size(); ++uv) {
    for (const int tile : touched(static_cast<int>(uv))) reach(tile);
    if (!cornerTable) continue;
    for (const Vec2f& corner : mesh.uvSets[uv].uvs) {
      Vec2d within;
      reach(udimTileOf({corner.x, corner.y}, within));
    }
  }
  return reached;
}

std::vector<bool> imagesToLoad(const Plan& plan, const std::vector<bool>& reached) {
  std::vector<bool> tileOnly(plan.textures.size(), false), load(plan.images.size(), false);
  for (const PlannedTexture& texture : plan.textures) {
    for (const auto& [tile, t] : texture.udimTiles) tileOnly[t] = true;
  }
  for (const PlannedLayer& layer : plan.layers) {  // used directly: needed whatever the tiles
    for (const std::optional<std::size_t>& t : {layer.texture, layer.mask}) {
      if (t) tileOnly[*t] = false;
    }
  }
  for (std::size_t t = 0; t < plan.textures.size(); ++t) {
    const PlannedTexture& texture = plan.textures[t];
    if (!texture.udimTiles.empty()) {
      for (const auto& [tile, tileTexture] : texture.udimTiles) {
        if (reached[static_cast<std::size_t>(tile)]) load[plan.textures[tileTexture].image] = true;
      }
    } else if (!tileOnly[t]) {
      load[texture.image] = true;
    }
  }
  return load;
}

Status loadTextures(const Plan& plan, const ImageSource& source, Loaded& loaded,
                    ProgressReporter& progress, ExecuteReport& report,
                    const std::vector<bool>& load) {
  loaded.scalar.resize(plan.textures.size());
  loaded.vector.resize(plan.textures.size());
  for (std::size_t i = 0; i < plan.images.size(); ++i) {
    const PlannedImage& planned = plan.images[i];
    if (!load.empty() && !load[i]) {  // a UDIM tile no UV reaches
      progress.finishOne();
      continue;
    }
    progress.start("loading " + planned.path.string());
    Result<Image> image = source(planned);
    if (!image) return image.error();
    ++report.imagesLoaded;
    std::size_t lastUser = 0;  // the last texture made of this image may take its pixels
    for (std::size_t t = 0; t < plan.textures.size(); ++t) {
      if (plan.textures[t].image == i) lastUser = t;
    }
    for (std::size_t t = 0; t < plan.textures.size(); ++t) {
      const PlannedTexture& texture = plan.textures[t];
      if (texture.image != i) continue;
      if (texture.vector) {
        VectorTextureOptions textureOptions;
        textureOptions.filter = texture.filter;
        textureOptions.wrap = texture.wrap;
        Result<ImageVectorTexture> made =
            t == lastUser ? ImageVectorTexture::create(std::move(*image), textureOptions)
                          : ImageVectorTexture::create(*image, textureOptions);
        if (!made)
          return Error{made.error().code, planned.path.string() + ": " + made.error().message};
        loaded.vector[t] = std::make_unique<ImageVectorTexture>(std::move(*made));
      } else {
        ScalarTextureOptions textureOptions;
        textureOptions.filter = texture.filter;
        textureOptions.wrap = texture.wrap;
        Result<ImageScalarTexture> made = ImageScalarTexture::create(*image, textureOptions);
        if (!made)
          return Error{made.error().code, planned.path.string() + ": " + made.error().message};
        loaded.scalar[t] = std::make_unique<ImageScalarTexture>(std::move(*made));
      }
      ++report.texturesCreated;
    }
    progress.finishOne();  // the Image is released here (scalar textures keep their own copy)
  }
  // UDIM textures take over their tiles' textures.
  for (std::size_t t = 0; t < plan.textures.size(); ++t) {
    const PlannedTexture& texture = plan.textures[t];
    if (texture.udimTiles.empty()) continue;
    if (texture.vector) {
      std::map<int, std::unique_ptr<VectorTexture>> tiles;
      for (const auto& [tile, index] : texture.udimTiles) {  // the tiles loaded
        if (loaded.vector[index]) tiles.emplace(tile, std::move(loaded.vector[index]));
      }
      loaded.vector[t] = std::make_unique<UdimVectorTexture>(std::move(tiles));
    } else {
      std::map<int, std::unique_ptr<ScalarTexture>> tiles;
      for (const auto& [tile, index] : texture.udimTiles) {  // the tiles loaded
        if (loaded.scalar[index]) tiles.emplace(tile, std::move(loaded.scalar[index]));
      }
      loaded.scalar[t] = std::make_unique<UdimScalarTexture>(std::move(tiles));
    }
    ++report.texturesCreated;
  }
  return Ok{};
}

namespace {

/// A volume made by its create(), owned.
template <class V>
Result<std::unique_ptr<HeightVolume>> owned(Result<V> made) {
  if (!made) return made.error();
  return std::unique_ptr<HeightVolume>(std::make_unique<V>(std::move(*made)));
}

/// Builds the volume of a volume layer.
Result<std::unique_ptr<HeightVolume>> makeVolume(const SceneLayer& layer) {
  switch (layer.function) {
    case VolumeFunction::kSine:
      return owned(DirectionalSine::create({.amplitude = layer.amplitude,
                                            .frequency = layer.frequency,
                                            .direction = layer.direction,
                                            .phase = layer.phase}));
    case VolumeFunction::kBlenderNoise:
      return owned(BlenderNoise::create({.amplitude = layer.amplitude,
                                         .scale = layer.frequency,
                                         .detail = layer.noiseDetail,
                                         .roughness = layer.noiseRoughness,
                                         .distortion = layer.noiseDistortion,
                                         .dimensions = layer.textureDimensions,
                                         .w = layer.textureW}));
    case VolumeFunction::kBlenderMusgrave:
      return owned(BlenderMusgrave::create({.amplitude = layer.amplitude,
                                            .scale = layer.frequency,
                                            .type = layer.musgraveType,
                                            .detail = layer.noiseDetail,
                                            .dimension = layer.noiseDimension,
                                            .lacunarity = layer.noiseLacunarity,
                                            .offset = layer.musgraveOffset,
                                            .gain = layer.musgraveGain,
                                            .dimensions = layer.textureDimensions,
                                            .w = layer.textureW}));
    case VolumeFunction::kBlenderWave:
      return owned(BlenderWave::create({.amplitude = layer.amplitude,
                                        .scale = layer.frequency,
                                        .type = layer.waveType,
                                        .direction = layer.waveDirection,
                                        .profile = layer.waveProfile,
                                        .distortion = layer.noiseDistortion,
                                        .detail = layer.noiseDetail,
                                        .detailScale = layer.noiseDetailScale,
                                        .detailRoughness = layer.noiseDetailRoughness,
                                        .phase = layer.phase}));
    case VolumeFunction::kBlenderVoronoi:
      return owned(BlenderVoronoi::create({.amplitude = layer.amplitude,
                                           .scale = layer.frequency,
                                           .randomness = layer.voronoiRandomness,
                                           .metric = layer.voronoiMetric,
                                           .exponent = layer.voronoiExponent,
                                           .feature = layer.voronoiFeature,
                                           .smoothness = layer.voronoiSmoothness}));
    case VolumeFunction::kBlenderBrick: {
      BlenderBrickParams params = layer.brick;
      params.amplitude = layer.amplitude;
      params.scale = layer.frequency;
      return owned(BlenderBrick::create(params));
    }
    case VolumeFunction::kBlenderGradient:
      return owned(
          BlenderGradient::create({.amplitude = layer.amplitude, .type = layer.gradientType}));
    case VolumeFunction::kBlenderMagic:
      return owned(BlenderMagic::create({.amplitude = layer.amplitude,
                                         .scale = layer.frequency,
                                         .depth = layer.magicDepth,
                                         .distortion = layer.noiseDistortion}));
    case VolumeFunction::kNoise:
      break;
  }
  return owned(GradientNoise::create({.amplitude = layer.amplitude,
                                      .frequency = layer.frequency,
                                      .seed = layer.seed,
                                      .octaves = layer.octaves}));
}

/// The material index of scene layer @p index (Layer::material: −1 for every face): its
/// "material" index, or the index of its OBJ `usemtl` name in the mesh. A name the mesh does
/// not have is bad input; an index no face has, a warning (the layer bakes nothing).
Result<int> layerMaterial(const Scene& scene, std::size_t index, Loaded& loaded) {
  const SceneLayer& layer = scene.layers[index];
  const Mesh& mesh = loaded.mesh;
  const std::string where = scenePrefix(scene) + layerLabel(index) + ": ";
  if (layer.materialName) {
    const std::vector<std::string>& names = mesh.materialNames;
    const auto found = std::find(names.begin(), names.end(), *layer.materialName);
    if (found != names.end()) return static_cast<int>(found - names.begin());
    std::string known;
    for (const std::string& name : names) known += (known.empty() ? "'" : ", '") + name + "'";
    return Error::badInput(where + "material '" + *layer.materialName + "' is not in " +
                           scene.mesh.string() +
                           (names.empty() ? " (it names no material: no usemtl; give an index)"
                                          : " (its materials: " + known + ")"));
  }
  if (!layer.material) return -1;
  const std::uint32_t material = static_cast<std::uint32_t>(*layer.material);
  const bool used = mesh.faceMaterial.empty()
                        ? material == 0
                        : std::find(mesh.faceMaterial.begin(), mesh.faceMaterial.end(), material) !=
                              mesh.faceMaterial.end();
  if (!used) {
    loaded.warnings.push_back(where + "no face of " + scene.mesh.string() + " has material " +
                              std::to_string(material) + ": the layer bakes nothing");
  }
  return *layer.material;
}

/// The object coordinates a projection layer reads (its "mapping", or P itself).
CoordinateMapping coordinateMapping(const SceneLayer& layer) {
  if (!layer.mapping) return {};
  const SceneMapping& m = *layer.mapping;
  const CoordinateMapping node =
      CoordinateMapping::fromMappingNode(m.location, m.rotation, m.scale, m.type);
  if (!m.matrix) return node;
  return node.after(CoordinateMapping::affine(*m.matrix, m.matrixTranslation));
}

/// A projected layer's options (those of Blender's projections too).
TriplanarOptions triplanarOptions(const SceneLayer& layer) {
  TriplanarOptions options;
  options.tiling = layer.tiling;
  options.offset = layer.offset;
  options.scale = layer.scale;
  options.sharpness = layer.sharpness;
  options.minWeight = layer.minWeight;
  options.projection = layer.projection;
  options.boxBlend = layer.boxBlend;
  options.coordinates = coordinateMapping(layer);
  options.normal.green = layer.green;
  return options;
}

/// A normal-map layer projected by one of Blender's projections (Box, Flat, Sphere, Tube): what
/// Cycles bakes, a Normal Map node (Strength = the layer's scale) decoding the colour an Image
/// Texture's projection reads. The normal-map source with its texels read by that projection
/// (TangentNormalSource::projection): Strength, guards and normals below the surface as a UV
/// normal map's.
LayerSource projectedNormalSource(const SceneLayer& layer, const VectorTexture* texture) {
  if (layer.kind == ProjectedKind::kTangentNormal) {
    TangentNormalSource source;
    source.texture = texture;
    source.uvSet = layer.frameUvSet();
    source.options.green = layer.green;
    source.options.strength = layer.scale;
    source.projection = triplanarOptions(layer);
    return source;
  }
  ObjectNormalSource source;
  source.texture = texture;
  source.strength = layer.scale;
  source.projection = triplanarOptions(layer);
  return source;
}

/// The library Layer of a planned layer (textures and volumes must be loaded).
Result<Layer> makeLayer(const Plan& plan, const PlannedLayer& planned, Loaded& loaded,
                        double objectSize) {
  const SceneLayer& layer = plan.scene.layers[planned.sceneLayer];
  const ScalarTexture* scalar = planned.texture ? loaded.scalar[*planned.texture].get() : nullptr;
  const VectorTexture* vector = planned.texture ? loaded.vector[*planned.texture].get() : nullptr;
  // A remapped height reads its texture through the remap (the texture itself is shared).
  std::optional<HeightRemap> remap;
  if (!layer.remap.empty()) {
    Result<HeightRemap> made = HeightRemap::create(layer.remap);
    if (!made) {
      return Error::badInput(scenePrefix(plan.scene) + layerLabel(planned.sceneLayer) + ": " +
                             made.error().message);
    }
    remap = std::move(*made);
    if (scalar != nullptr) {
      loaded.textureViews.push_back(std::make_unique<RemappedScalarTexture>(*scalar, *remap));
      scalar = loaded.textureViews.back().get();
    }
  }
  Layer result;
  result.weight = layer.weight;
  if (layer.mask && planned.mask) {
    result.mask.texture = loaded.scalar[*planned.mask].get();
    result.mask.uvSet = layer.mask->uvSet;
    result.mask.tiling = layer.mask->tiling;
    result.mask.offset = layer.mask->offset;
  }
  result.base = layer.base;
  result.objectSpaceHeight = layer.objectSpaceHeight;
  Result<int> material = layerMaterial(plan.scene, planned.sceneLayer, loaded);
  if (!material) return material.error();
  result.material = *material;
  ProjectedNormalOptions projected;
  projected.green = layer.green;
  switch (layer.type) {
    case SceneLayerType::kHeight: {
      UvHeightSource source;
      source.texture = scalar;
      source.uvSet = layer.uvSet;
      source.scale = layer.scale;
      source.strength = layer.strength;
      source.tiling = layer.tiling;
      source.offset = layer.offset;
      source.gradient = layer.heightGradient;
      result.source = source;
      break;
    }
    case SceneLayerType::kNormal:
      if (layer.space == NormalSpace::kTangent) {
        TangentNormalSource source;
        source.texture = vector;
        source.uvSet = layer.uvSet;
        source.options.green = layer.green;
        source.options.strength = layer.scale;
        source.options.tiling = layer.tiling;
        source.options.offset = layer.offset;
        if (layer.tangentUvSet) source.tangentUvSet = *layer.tangentUvSet;
        result.source = source;
      } else {
        ObjectNormalSource source;
        source.texture = vector;
        source.uvSet = layer.uvSet;
        source.tiling = layer.tiling;
        source.offset = layer.offset;
        source.strength = layer.scale;
        result.source = source;
      }
      break;
    case SceneLayerType::kVolume: {
      Result<std::unique_ptr<HeightVolume>> volume = makeVolume(layer);
      if (!volume) {
        return Error::badInput(scenePrefix(plan.scene) + layerLabel(planned.sceneLayer) + ": " +
                               volume.error().message);
      }
      loaded.volumes.push_back(std::move(*volume));
      if (layer.mapping) {  // a Mapping node, or other coordinates, before the texture
        loaded.volumes.push_back(
            std::make_unique<MappedHeightVolume>(*loaded.volumes.back(), coordinateMapping(layer)));
      }
      if (remap) {
        loaded.volumes.push_back(
            std::make_unique<RemappedHeightVolume>(*loaded.volumes.back(), std::move(*remap)));
      }
      if (layer.coordinates == VolumeCoordinates::kUv) {  // read at (u, v, 0): a UV height
        loaded.textureViews.push_back(std::make_unique<VolumeOnUvTexture>(*loaded.volumes.back()));
        UvHeightSource source;
        source.texture = loaded.textureViews.back().get();
        source.uvSet = layer.uvSet;
        source.strength = layer.strength;
        source.gradient = layer.heightGradient;
        result.source = source;
        break;
      }
      VolumeSource source;
      source.volume = loaded.volumes.back().get();
      source.scheme = layer.gradient;
      source.gradient = layer.heightGradient;
      source.step = layer.step ? *layer.step : defaultStep(objectSize);
      source.strength = layer.strength;
      result.source = source;
      break;
    }
    case SceneLayerType::kPlanar: {
      if (layer.projectedByBlender() && layer.readsNormals()) {
        result.source = projectedNormalSource(layer, vector);
        break;
      }
      PlanarSource source;
      source.kind = layer.kind;
      source.height = scalar;
      source.normals = vector;
      source.mapping = isSingleLookup(layer.projection)
                           ? singleLookupMapping(layer.projection, layer.tiling, layer.offset)
                           : PlanarMapping{layer.axis, layer.tiling, layer.offset};
      source.coordinates = coordinateMapping(layer);
      source.scale = layer.scale;
      source.normal = projected;
      source.gradient = layer.heightGradient;
      source.strength = layer.strength;
      result.source = source;
      break;
    }
    case SceneLayerType::kTriplanar: {
      if (layer.projectedByBlender() && layer.readsNormals()) {
        result.source = projectedNormalSource(layer, vector);
        break;
      }
      TriplanarSource source;
      source.kind = layer.kind;
      source.height = scalar;
      source.normals = vector;
      source.options = triplanarOptions(layer);
      source.gradient = layer.heightGradient;
      source.strength = layer.strength;
      result.source = source;
      break;
    }
  }
  return result;
}

}  // namespace

Status prepareLayers(const Plan& plan, int threads, Loaded& loaded, ProgressReporter& progress,
                     ExecuteReport& report) {
  const Scene& s = plan.scene;
  if (Status ok = checkUvSets(plan, loaded.mesh); !ok) return ok.error();
  const double objectSize = boundingBoxDiagonal(loaded.mesh);
  for (const PlannedLayer& planned : plan.layers) {
    Result<Layer> layer = makeLayer(plan, planned, loaded, objectSize);
    if (!layer) return layer.error();
    loaded.layers.push_back(std::move(*layer));
  }
  const int numUvSets =
      static_cast<int>(std::min<std::size_t>(loaded.mesh.uvSets.size(), kMaxUvSets));
  if (Status valid = validateLayers(loaded.layers, numUvSets); !valid) {
    return Error{valid.error().code, scenePrefix(s) + valid.error().message};
  }
  if (!plan.computeTangents) return Ok{};
  const auto start = std::chrono::steady_clock::now();
  progress.start("computing tangent frames");
  TangentOptions tangentOptions;
  tangentOptions.threads = threads;
  Result<CornerTangents> tangents = computeTangents(loaded.mesh.view(0), tangentOptions);
  if (!tangents) {
    return Error{tangents.error().code, s.mesh.string() + ": " + tangents.error().message};
  }
  if (std::string warning = missingTangentsWarning(*tangents, s.mesh.string()); !warning.empty()) {
    report.warnings.push_back(std::move(warning));
  }
  loaded.tangents = std::move(*tangents);
  // Cycles' Normal Map node decodes with MikkTSpace of its triangulated mesh, on the UV map it
  // names: a tangent-space layer in the MikkTSpace frame gets those of its UV set, not the
  // polygon mesh's. (On a limit surface the frames are the surface's own.)
  for (const Layer& layer : loaded.layers) {
    const auto* normal = std::get_if<TangentNormalSource>(&layer.source);
    if (normal == nullptr || normal->options.frame == TangentFrameChoice::kUvDerivatives ||
        loaded.limit || normal->frameUvSet() < 0 || normal->frameUvSet() >= kMaxUvSets ||
        !loaded.mesh.hasUvSet(static_cast<std::size_t>(normal->frameUvSet())) ||
        loaded.triangleTangents[static_cast<std::size_t>(normal->frameUvSet())]) {
      continue;
    }
    Result<CornerTangents> triangles =
        computeLoopTriangleTangents(loaded.mesh, normal->frameUvSet(), tangentOptions);
    if (!triangles) {
      return Error{triangles.error().code, s.mesh.string() + ": " + triangles.error().message};
    }
    loaded.triangleTangents[static_cast<std::size_t>(normal->frameUvSet())] = std::move(*triangles);
  }
  report.tangentsComputed = true;
  progress.finishOne();
  report.tangentsSeconds = secondsSince(start);
  return Ok{};
}

std::vector<Layer> outputLayers(const PlannedOutput& planned, const Loaded& loaded) {
  std::vector<Layer> layers;
  for (const std::size_t l : planned.layers) layers.push_back(loaded.layers[l]);
  return layers;
}

BakeInput bakeInputFor(const Loaded& loaded, std::span<const Layer> layers) {
  BakeInput input;
  input.mesh = &loaded.mesh;
  input.tangents = loaded.tangents ? &*loaded.tangents : nullptr;
  for (std::size_t s = 0; s < kMaxUvSets; ++s) {
    if (loaded.triangleTangents[s]) input.triangleTangents[s] = &*loaded.triangleTangents[s];
  }
  input.layers = layers;
  if (loaded.transform) input.transform = &*loaded.transform;
  if (loaded.limit) {
    input.limit = &*loaded.limit;
    input.limitParameters = &loaded.limitParameters;
  }
  return input;
}

BakeSettings bakeSettingsFor(const SceneOutput& output, int tile, int threads) {
  BakeSettings settings;
  settings.map = output.map;
  settings.width = output.width;
  settings.height = output.height;
  settings.samples = output.samples;
  settings.uvSet = output.uvSet;
  settings.udimTile = tile;
  settings.green = output.green;
  settings.swizzle = output.swizzle;
  settings.threads = threads;
  return settings;
}

}  // namespace sgbake::plan_detail
