/// @file scene.hpp
/// @brief Bake scenes: which mesh, which bump layers, which maps to write — parsed strictly from
/// the scene JSON that `sgbake bake SCENE.json` reads.
///
/// ## The scene file
/// ```json
/// { "mesh": "m.obj", "uv": 0,
///   "subdivision": {"level": "limit" | 2, "uv_smooth": "keep-boundaries", "boundary": "all",
///                   "use_creases": true, "edge_creases": [[0, 1, 0.5]],
///                   "vertex_creases": [[3, 1]]},
///   "layers": [
///     {"type": "height", "image": "h.exr", "scale": 0.1, "filter": "bicubic", "uv": 0},
///     {"type": "normal", "image": "n.png", "space": "tangent", "green": "opengl"},
///     {"type": "volume", "function": "sine", "amplitude": 1, "frequency": 1,
///      "direction": [1,0,0], "phase": 0, "gradient": "analytic", "step": 0.001},
///     {"type": "triplanar", "image": "t.png", "kind": "height", "scale": 0.1, "tiling": 1,
///      "sharpness": 4} ],
///   "outputs": [ {"map": "tangent-normal", "file": "out/n.png", "size": 2048, "margin": 16,
///                 "samples": 1, "green": "opengl"} ] }
/// ```
/// `sgbake bake --help` lists every key. The rules:
/// - Relative paths (mesh, images, masks, output files) are relative to the scene file's
///   directory (output files: to SceneParseOptions::outputDir when given).
/// - Strict: an unknown key is an error naming it, its place and the closest known key
///   (`outputs[0]: unknown key 'sise' (did you mean 'size'?)`); so are wrong types, values out of
///   range and unknown names. Keys starting with `_` are comments and are ignored.
/// - Defaults: top-level "uv" (default 0) is the UV set of every layer and output that does not
///   give its own; size 1024, margin 16, padding "extend", samples 1, green "opengl", weight 1,
///   filter "bilinear", tiling 1, offset 0, scale/strength 1, triplanar sharpness 4, base
///   "surface".
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "sgbake/bake/bake.hpp"
#include "sgbake/bake/convert.hpp"
#include "sgbake/bake/image_output.hpp"
#include "sgbake/core/result.hpp"
#include "sgbake/core/vec.hpp"
#include "sgbake/gradient/blender_noise.hpp"
#include "sgbake/gradient/filters.hpp"
#include "sgbake/gradient/layers.hpp"
#include "sgbake/gradient/projection.hpp"
#include "sgbake/gradient/volume.hpp"
#include "sgbake/subdiv/subdivide.hpp"

namespace sgbake {

/// Default output size (Blender's default bake image) and margin (Blender's default), texels.
/// Sizes and margins go up to kMaxBakeSide, samples to kMaxBakeSamples, tiles from
/// kFirstUdimTile to kLastUdimTile (bake.hpp).
inline constexpr int kDefaultOutputSize = 1024;
inline constexpr int kDefaultMargin = 16;

/// @brief The "type" of a scene layer.
enum class SceneLayerType {
  kHeight,     ///< "height": a height image on a UV set (UvHeightSource)
  kNormal,     ///< "normal": a tangent- or object-space normal map on a UV set
  kVolume,     ///< "volume": a procedural height volume (VolumeSource)
  kPlanar,     ///< "planar": an image projected along one axis (PlanarSource)
  kTriplanar,  ///< "triplanar": an image projected on the three axis planes (TriplanarSource)
};

/// @brief The scene name of @p type ("height", ...).
std::string_view sceneLayerTypeName(SceneLayerType type);

/// @brief "coordinates" of a volume layer: where it is read.
enum class VolumeCoordinates {
  kObject,  ///< "object": at the object position P (through its "mapping")
  /// "uv": at (u, v, 0) of its "uv" set (through its "mapping"), as a procedural texture on
  /// Blender's Texture Coordinate UV or a UV Map node: a UV height (VolumeOnUvTexture)
  kUv,
};

/// @brief "function" of a volume layer.
enum class VolumeFunction {
  kSine,             ///< DirectionalSine
  kNoise,            ///< GradientNoise
  kBlenderNoise,     ///< "blender-noise": BlenderNoise, Blender's Noise Texture (3D)
  kBlenderMusgrave,  ///< "blender-musgrave": BlenderMusgrave, Blender's Musgrave Texture (3D)
  kBlenderWave,      ///< "blender-wave": BlenderWave, Blender's Wave Texture
  kBlenderVoronoi,   ///< "blender-voronoi": BlenderVoronoi, Blender's Voronoi Texture (3D)
  kBlenderBrick,     ///< "blender-brick": BlenderBrick, Blender's Brick Texture's Fac
  kBlenderGradient,  ///< "blender-gradient": BlenderGradient, Blender's Gradient Texture
  kBlenderMagic,     ///< "blender-magic": BlenderMagic, Blender's Magic Texture's Fac
};

/// @brief The scene's "subdivision" block: Blender's Subdivision Surface modifier on the mesh
/// (subdivideMesh) before anything is baked, or with "level": "limit" the exact limit surface
/// under every sample (LimitSurface, BakeInput::limit).
struct SceneSubdivision {
  bool present = false;  ///< the scene has a "subdivision" block
  bool limit = false;    ///< "level": "limit" — the limit surface
  int level = 0;         ///< "level": N — N uniform levels (0 = none)
  SubdivisionUvSmooth uvSmooth = SubdivisionUvSmooth::kKeepBoundaries;
  SubdivisionBoundary boundary = SubdivisionBoundary::kAll;
  bool useCreases = true;                   ///< "use_creases"
  std::vector<EdgeCrease> edgeCreases;      ///< "edge_creases": [[a, b, c], ...]
  std::vector<VertexCrease> vertexCreases;  ///< "vertex_creases": [[v, c], ...]
  int quality = 3;                          ///< "quality": Blender's Quality, 1 … 10
  bool useLimitSurface = true;  ///< "use_limit_surface": Blender's "Use Limit Surface"
  SubdivisionType type = SubdivisionType::kCatmullClark;  ///< "type": "catmull-clark" | "simple"
  std::optional<double> autoSmoothDegrees;  ///< "auto_smooth": the mesh's Auto Smooth angle
  std::vector<SharpEdge> sharpEdges;        ///< "sharp_edges": [[a, b], ...]
  /// @brief Whether the block changes the mesh: a subdivision (level > 0 or the limit surface),
  /// or Auto Smooth at level 0.
  bool requested() const { return present && (limit || options().changesMesh()); }
  /// @brief Whether the samples are shaded on the exact limit surface ("level": "limit").
  bool limitSurface() const { return present && limit; }
  /// @brief The options of subdivideMesh this block stands for (a number of levels).
  SubdivisionOptions options() const {
    return {level,   uvSmooth,        boundary, useCreases,        edgeCreases, vertexCreases,
            quality, useLimitSurface, type,     autoSmoothDegrees, sharpEdges};
  }
  /// @brief The block of @p options (a number of levels), or of the limit surface under them
  /// when @p limitSurface: options()'s inverse. Present when it changes the mesh (requested()).
  static SceneSubdivision of(const SubdivisionOptions& options, bool limitSurface) {
    return {options.changesMesh() || limitSurface, limitSurface, options.level, options.uvSmooth,
            options.boundary, options.useCreases, options.edgeCreases, options.vertexCreases,
            options.quality, options.useLimitSurface, options.type, options.autoSmoothDegrees,
            options.sharpEdges};
  }
};

/// @brief A projection's optional "mapping": Blender's Mapping node between a Texture
/// Coordinate node's Object output and the Image Texture: of type "point" (the default) the
/// projection reads R · (scale ∘ P) + location, of type "texture" its inverse, of type "vector"
/// R · (scale ∘ P) (CoordinateMapping, MappingType). {"type", "location", "rotation" (radians,
/// XYZ Euler), "scale", "matrix"}, each optional. "matrix" (3 rows of 4 numbers, or 4 with the last
/// [0, 0, 0, 1]) moves P first: the coordinates Blender's Texture Coordinate node gives instead
/// of the object's own (Object with another object named: inverse(its matrix_world) ·
/// matrix_world; Generated: the texture space).
struct SceneMapping {
  MappingType type = MappingType::kPoint;  ///< "type": "point" | "texture" | "vector"
  Vec3d location{};
  Vec3d rotation{};
  Vec3d scale{1, 1, 1};
  std::optional<Mat3> matrix;  ///< "matrix"'s 3 × 3 part
  Vec3d matrixTranslation{};   ///< "matrix"'s last column
};

/// @brief A layer's optional "mask": a scalar image on a UV set that scales its Γ (LayerMask).
/// Written either as a file name or as {"image", "uv", "tiling", "offset", "filter"}.
struct SceneMask {
  std::filesystem::path image;  ///< resolved against the scene's directory
  int uvSet = 0;  ///< "uv"; default: the layer's UV set (the scene's for volumes, projections)
  Vec2d tiling{1, 1};
  Vec2d offset{0, 0};
  Filter filter = Filter::kBilinear;
};

/// @brief One entry of "layers". Only the members of its type are meaningful.
struct SceneLayer {
  SceneLayerType type = SceneLayerType::kHeight;
  std::string name;   ///< optional "name", for messages and --explain
  double weight = 1;  ///< "weight": any finite value; 0 disables the layer
  std::optional<SceneMask> mask;

  // Image layers (height, normal, planar, triplanar).
  std::filesystem::path image;        ///< "image", resolved against the scene's directory
  Filter filter = Filter::kBilinear;  ///< "filter": bilinear | bicubic | hermite (heights only)
  Wrap wrap = Wrap::kRepeat;          ///< "wrap": repeat | clamp
  int uvSet = 0;  ///< "uv" (height, normal, and a volume on "coordinates": "uv")
  Vec2d tiling{1, 1};                 ///< "tiling": a number or [s, t]
  Vec2d offset{0, 0};                 ///< "offset": [s, t]
  /// "scale" (height, planar, triplanar: object units per unit of value; strength for projected
  /// normal maps) or "strength" (normal).
  double scale = 1;
  /// "strength" of a height (height layers, volumes, projected heights): the Bump node's (a
  /// blend of normals)
  double strength = 1;
  /// "channel" of a height layer: luminance (Rec. 709 of RGB, as a colour into the Bump node's
  /// Height), or one channel: r, g, b, a (a height packed into another map, or the Image
  /// Texture's Alpha output)
  ImageChannels channel = ImageChannels::kLuminance;
  /// "gradient" of a height layer: "analytic" (exact), or "bump-node": the forward differences
  /// half a texel apart that Blender's Bump node takes when Cycles bakes (HeightGradient)
  HeightGradient heightGradient = HeightGradient::kAnalytic;
  /// "remap" (heights): [[x, y], …], the points of a piecewise-linear function the value is read
  /// through before the scale (HeightRemap: levels, clamps, a Color Ramp's table); empty: none
  std::vector<Vec2d> remap;
  NormalSpace space = NormalSpace::kTangent;       ///< "space" (normal; convert.hpp)
  /// "tangent_uv" (tangent-space normal layers, and those Blender's projections read): the UV
  /// set whose tangent frames decode the map, when not its "uv"
  /// (TangentNormalSource::tangentUvSet)
  std::optional<int> tangentUvSet;
  NormalMapGreen green = NormalMapGreen::kOpenGL;  ///< "green" (normal maps, all projections)
  ProjectedKind kind = ProjectedKind::kHeight;     ///< "kind" (planar, triplanar)
  ProjectionAxis axis = ProjectionAxis::kZ;        ///< "axis" (planar)
  double sharpness = kDefaultTriplanarSharpness;   ///< "sharpness" (triplanar)
  double minWeight = kDefaultMinTriplanarWeight;   ///< "min_weight" (triplanar)
  /// "projection": sgbake's own (kBlended: a triplanar layer's "blended", seed 003's planes and
  /// weights; a planar layer's "axis", along its axis, normal kinds in the plane's frame), the
  /// default, or Blender's Image Texture projections: a triplanar layer's "box" (kBox), a planar
  /// layer's "flat" (kFlat, the (x, y) plane), "sphere" (kSphere) or "tube" (kTube), the last
  /// two wrapped around the z axis of 2 · (P' − ½). Blender's decode normal kinds as a Normal
  /// Map node decodes the colour they read.
  TriplanarProjection projection = TriplanarProjection::kBlended;
  double boxBlend = kDefaultBoxBlend;  ///< "box_blend" (triplanar box): Blender's Blend, 0 … 1
  std::optional<SceneMapping> mapping;  ///< "mapping" (planar, triplanar)
  /// "base" (heights): "surface" (N, the default) or "above" (the normal the layers above make,
  /// as a Bump node whose Normal input is linked to them; LayerBase::kLayersAbove)
  LayerBase base = LayerBase::kSurface;
  /// "height_space" (heights): "world" (the default: the scale in world units, as a Bump
  /// node's Distance or a Displacement node in World space) or "object" (in object units along
  /// the normal, as a Displacement node in Object space: Layer::objectSpaceHeight)
  bool objectSpaceHeight = false;
  /// "material": the faces the layer applies to, those of one material: an index (Blender's
  /// material slot; Mesh::faceMaterial) or an OBJ `usemtl` name (materialName). Neither: every
  /// face.
  std::optional<int> material;
  std::optional<std::string> materialName;

  // Volume layers.
  VolumeFunction function = VolumeFunction::kSine;      ///< "function"
  double amplitude = 1;                                 ///< "amplitude"
  double frequency = 1;                                 ///< "frequency"
  Vec3d direction{1, 0, 0};                             ///< "direction" (sine)
  double phase = 0;                                     ///< "phase" (sine), radians
  std::uint64_t seed = 0;                               ///< "seed" (noise)
  int octaves = 1;                                      ///< "octaves" (noise)
  /// "detail" (blender-noise, blender-musgrave), "roughness", "distortion" (blender-noise),
  /// "dimension", "lacunarity" (blender-musgrave): the node's inputs; its Scale is "frequency",
  /// 5 unless given, as Blender's defaults
  double noiseDetail = 2;
  double noiseRoughness = 0.5;
  double noiseDistortion = 0;
  double noiseDimension = 2;
  double noiseLacunarity = 2;
  /// blender-musgrave: "musgrave_type" (fbm | multifractal | ridged-multifractal |
  /// hybrid-multifractal | hetero-terrain), "offset" (ridged, hybrid, hetero terrain) and "gain"
  /// (ridged, hybrid): the node's Type and inputs, Blender's defaults
  MusgraveType musgraveType = MusgraveType::kFbm;
  /// blender-noise, blender-musgrave: "dimensions" ("1D" | "2D" | "3D" | "4D": the node's
  /// Dimensions, which read W, (x, y), (x, y, z) or (x, y, z, W)) and "w" (the node's W, 1D
  /// and 4D only)
  int textureDimensions = 3;
  double textureW = 0;
  double musgraveOffset = 0;
  double musgraveGain = 1;
  /// blender-wave: "wave" (bands | rings), "wave_direction" (x | y | z | diagonal (bands) |
  /// spherical (rings)), "profile" (sine | saw | triangle), "detail_scale", "detail_roughness"
  /// (of its distortion's noise; also "distortion", "detail", and "phase": the Phase Offset)
  WaveType waveType = WaveType::kBands;
  WaveDirection waveDirection = WaveDirection::kX;
  WaveProfile waveProfile = WaveProfile::kSine;
  double noiseDetailScale = 1;
  double noiseDetailRoughness = 0.5;
  /// blender-voronoi: "randomness", "metric" (euclidean | manhattan | chebyshev | minkowski),
  /// "exponent" (Minkowski's), "feature" (f1 | f2 | smooth-f1 | distance-to-edge: the Feature
  /// Output, whose Distance is the height; distance-to-edge ignores the metric, as Cycles does),
  /// "smoothness" (smooth-f1's)
  double voronoiRandomness = 1;
  VoronoiMetric voronoiMetric = VoronoiMetric::kEuclidean;
  double voronoiExponent = 0.5;
  VoronoiFeature voronoiFeature = VoronoiFeature::kF1;
  double voronoiSmoothness = 1;
  /// blender-brick: "mortar_size", "mortar_smooth", "brick_width", "row_height",
  /// "brick_offset", "offset_frequency", "squash", "squash_frequency": the node's inputs and
  /// properties, Blender's defaults (its amplitude and scale are the layer's)
  BlenderBrickParams brick{};
  /// blender-gradient: "gradient_type" (linear | quadratic | easing | diagonal | spherical |
  /// quadratic-sphere | radial), the node's Gradient Type (it has no Scale: no "frequency")
  BlenderGradientType gradientType = BlenderGradientType::kLinear;
  /// blender-magic: "depth" (0 to 10), the node's Depth (also "distortion", 1 unless given, and
  /// "frequency", its Scale)
  int magicDepth = 2;
  GradientScheme gradient = GradientScheme::kAnalytic;  ///< "gradient"
  std::optional<double> step;  ///< "step"; default defaultStep(mesh bounding-box diagonal)
  VolumeCoordinates coordinates = VolumeCoordinates::kObject;  ///< "coordinates" (with "uv")

  /// @brief Whether the layer reads an image ("image" key): every type but volume.
  bool hasImage() const { return type != SceneLayerType::kVolume; }
  /// @brief Whether its image is a normal map (three channels) rather than heights.
  bool readsNormals() const;
  /// @brief Whether the layer has a height (a height map can bake it): height, volume, and
  /// planar/triplanar of kind height. Normal maps have slopes only.
  bool hasHeight() const;
  /// @brief Whether the layer projects its image at positions: planar or triplanar.
  bool projected() const;
  /// @brief Whether the layer projects its image as one of Blender's Image Texture projections:
  /// a triplanar layer's "box", a planar layer's "flat", "sphere" or "tube".
  bool projectedByBlender() const;
  /// @brief Whether the layer decodes a tangent-space normal map in the MikkTSpace frames of a
  /// UV set (frameUvSet): a tangent-space normal layer, or a projected one of Blender's
  /// projections (projectedByBlender: a Normal Map node decoding the colour an Image Texture's
  /// projection reads). sgbake's own projections decode in each plane's own frame instead.
  bool decodesInUvTangentFrames() const;
  /// @brief The UV set whose frames decode its tangent-space normals: "tangent_uv", else "uv".
  int frameUvSet() const { return tangentUvSet.value_or(uvSet); }
};

/// @brief What an output writes.
enum class OutputKind {
  kMap,      ///< a baked map (MapKind), written as an image
  kCorners,  ///< "map": "corners": the per-corner table (corners.hpp) as CSV
};

/// @brief One entry of "outputs".
struct SceneOutput {
  OutputKind kind = OutputKind::kMap;
  MapKind map = MapKind::kTangentNormal;  ///< for kMap
  /// "file", resolved against the output directory; may contain `<UDIM>` (one file per tile
  /// the UV set touches).
  std::filesystem::path file;
  int width = kDefaultOutputSize;                  ///< "size" or "width"
  int height = kDefaultOutputSize;                 ///< "size" or "height"
  int margin = kDefaultMargin;                     ///< "margin", texels
  PaddingMode padding = PaddingMode::kExtend;      ///< "padding"
  int samples = 1;                                 ///< "samples": N×N per texel
  int uvSet = 0;                                   ///< "uv"
  NormalMapGreen green = NormalMapGreen::kOpenGL;  ///< "green" (normal maps)
  /// "swizzle" (tangent- and object-normal maps): "+X-Y+Z" or ["+X", "-Y", "+Z"], Blender's
  /// bake Swizzle; not with "green"
  NormalSwizzle swizzle = kIdentitySwizzle;
  int tile = kFirstUdimTile;  ///< "tile": the UDIM tile when the file has no `<UDIM>` token
  ImageFormat format = ImageFormat::kAuto;  ///< "format": exr | png | tiff (default: extension)
  int bitDepth = 0;                         ///< "bit_depth": 8, 16 or 32; 0 = defaultBitDepth
  bool alpha = false;                       ///< "alpha": write the coverage as alpha
  /// "range": signed maps (derivative, surface-gradient) in integer files (PNG, TIFF 8/16)
  /// store v / (2·range) + 0.5, so [−range, range] fills the codes; float files store v.
  double range = 1;
  /// "range": "auto": the range is the largest |v| of the covered texels of all the output's
  /// tiles, rounded up to 3 significant digits (autoRange), found by a first pass over the map.
  bool rangeAuto = false;

  /// @brief Whether the file stores this output's values remapped by range (see above).
  bool storesSignedRange() const;

  /// @brief The image format the file is written in (format, else from the extension).
  ImageFormat resolvedFormat() const;
  /// @brief The bit depth written (bitDepth, else defaultBitDepth).
  int resolvedBitDepth() const;
};

/// What Scene::mesh is for a scene of an in-memory bake (messages name the mesh so).
inline constexpr const char* kInMemoryMeshName = "mesh";

/// @brief A parsed scene: every path resolved, every value validated.
struct Scene {
  std::filesystem::path source;  ///< the scene file ("" for scenes built in code)
  std::filesystem::path mesh;    ///< resolved; kInMemoryMeshName in memory
  /// The scene of an in-memory bake (SceneParseOptions::inMemory): the mesh and the images are
  /// given as arrays, "image" keys are their names, and outputs have no file.
  bool inMemory = false;
  int uvSet = 0;                 ///< top-level "uv": default UV set of layers and outputs
  SceneSubdivision subdivision;
  /// Top-level "transform": the object's matrix_world, 4 rows of 4 numbers (the last row
  /// 0 0 0 1) or 3 rows of 3. When its linear part is not the identity, normal-map, derivative,
  /// surface-gradient and corners outputs are shaded in world space as Cycles shades the object
  /// (BakeInput::transform; height scales are then world distances).
  std::optional<ObjectTransform> transform;
  std::vector<SceneLayer> layers;
  std::vector<SceneOutput> outputs;
};

/// @brief Where parseScene resolves relative paths and how it names the scene in messages.
struct SceneParseOptions {
  std::filesystem::path baseDir;    ///< relative mesh/image paths start here ("" = cwd)
  std::filesystem::path outputDir;  ///< relative output files start here ("" = baseDir)
  std::string name = "scene";       ///< prefix of every message ("scene.json: ...")
  /// For a bake in memory (bakeOutputInMemory, the C ABI's sgbake_bake_map): no "mesh" key,
  /// "image" keys are names of images given in memory (kept verbatim), and outputs have no
  /// "file", "format" or "bit_depth" and are not corners tables.
  bool inMemory = false;
};

/// @brief Parses and validates a scene from JSON text.
///
/// Checks syntax, every key and type, and every value's range; resolves paths. Does not touch
/// the files it names (the planner checks them).
/// @return kBadInput with one line `<name>: <where>: <what>`, e.g.
///   `scene.json: outputs[0]: unknown key 'sise' (did you mean 'size'?)`,
///   `scene.json: outputs[0]: size 100000 is out of range 1..65536`,
///   `scene.json: outputs[1]: unknown map 'tangent-normals' (did you mean 'tangent-normal'?)`.
Result<Scene> parseScene(std::string_view json, const SceneParseOptions& options);

/// @brief Reads @p path and parses it, relative paths against its directory.
/// @param[in] outputDir relative output files start here ("" = the scene's directory)
Result<Scene> loadScene(const std::filesystem::path& path,
                        const std::filesystem::path& outputDir = {});

/// @brief Checks a scene built in code with the same rules parseScene applies to values
/// (ranges, finite numbers, formats and bit depths, duplicate output files, at least one output).
/// @return kBadInput naming the layer or output (`outputs[0]: size 0 is out of range 1..65536`).
Status validateScene(const Scene& scene);

/// @brief The scene name of @p filter ("bilinear", "bicubic", "hermite").
std::string_view filterName(Filter filter);

/// @brief The padding a scene's "padding" (and the CLI's --padding) names: "extend",
/// "push-pull" or "adjacent-faces"; kBadInput for any other name.
Result<PaddingMode> parsePaddingMode(std::string_view name);

/// @brief A short description of @p layer for messages and --explain, e.g.
/// `height image meshes/h.png`, `tangent-space normal map n.png`, `volume noise`,
/// `triplanar height t.png`; prefixed with the layer's "name" when it has one.
std::string describeLayer(const SceneLayer& layer);

/// How the parameters name a file (layerParametersJson).
using PathNamer = std::function<std::string(const std::filesystem::path&)>;

/// @brief The parameters of @p layer as canonical JSON text: sorted keys, every default filled
/// in, image paths as @p name gives them (default: canonical, i.e. absolute with symbolic links
/// resolved; the manifest names them relative to its directory) — equal text means an equal
/// layer. For the manifest.
std::string layerParametersJson(const SceneLayer& layer, const PathNamer& name = {});

/// @brief The parameters of @p output as canonical JSON text (like layerParametersJson; the
/// file itself is not included, the resolved format and bit depth are).
std::string outputParametersJson(const SceneOutput& output);

/// @brief The subdivision block as canonical JSON text ("null" when the scene has none).
std::string subdivisionParametersJson(const SceneSubdivision& subdivision);

/// @brief The block in words, for --explain: "to level 2 (uv_smooth keep-boundaries, boundary
/// all)".
std::string describeSubdivision(const SceneSubdivision& subdivision);

/// @brief The block's Auto Smooth in words, for --explain: "30 deg and 2 sharp edge(s)".
/// @note Precondition: autoSmoothDegrees is set.
std::string describeAutoSmooth(const SceneSubdivision& subdivision);

/// @brief @p path made absolute and canonical as far as it exists (weakly_canonical); the
/// lexically normal absolute path when that fails.
std::filesystem::path canonicalPath(const std::filesystem::path& path);

/// @brief Whether writing @p a may write the file @p b is: the same canonicalPath, or, for a
/// path with kUdimToken, that of any of its tiles.
bool mayBeSameFile(const std::filesystem::path& a, const std::filesystem::path& b);

/// @brief The closest of @p candidates to @p word (edit distance at most 2 and less than half
/// its length), or "" — for "did you mean" suggestions.
std::string closestMatch(std::string_view word, const std::vector<std::string>& candidates);

}  // namespace sgbake
