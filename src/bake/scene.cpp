/// @file scene.cpp
/// @brief The strict scene-JSON parser (see scene.hpp).
///
/// Parsing walks the document with an ObjectReader per JSON object: it knows the object's place
/// ("outputs[0]"), the keys allowed there, and reads typed, range-checked values. A failure is
/// thrown inside this file as a SceneFailure and becomes one kBadInput line in parseScene; no
/// exception leaves the library.
#include "sgbake/bake/scene.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <system_error>
#include <utility>

#include <nlohmann/json.hpp>

#include "sgbake/bake/planner.hpp"
#include "sgbake/core/text.hpp"
#include "sgbake/gradient/remap.hpp"

namespace sgbake {
namespace {

using nlohmann::json;

/// A parse failure: where (a JSON path such as "outputs[0]", "" for the top level) and what.
struct SceneFailure {
  std::string where;
  std::string what;
};

[[noreturn]] void fail(std::string where, std::string what) {
  throw SceneFailure{std::move(where), std::move(what)};
}

std::string quote(std::string_view text) {
  // (Built with append: `"'" + std::string` trips GCC 12's false -Wrestrict, bug 105651.)
  std::string quoted = "'";
  quoted.append(text).append("'");
  return quoted;
}

/// "a, b or c".
std::string listNames(const std::vector<std::string>& names) {
  std::string text;
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (i > 0) text += i + 1 == names.size() ? " or " : ", ";
    text += names[i];
  }
  return text;
}

/// A JSON value for messages: strings quoted, numbers as written, containers by kind.
std::string describeValue(const json& value) {
  if (value.is_string()) return quote(value.get<std::string>());
  if (value.is_number() || value.is_boolean() || value.is_null()) return value.dump();
  return std::string("an ") + (value.is_array() ? "array" : "object");
}

/// "a string", "an array", ...
std::string describeType(const json& value) {
  const std::string type = value.type_name();
  const bool vowel = type[0] == 'a' || type[0] == 'o';
  return (vowel ? "an " : "a ") + type;
}

std::string appendPath(const std::string& path, std::string_view key) {
  return path.empty() ? std::string(key) : path + "." + std::string(key);
}

/// Message of a range check, shared with validateScene: "size 0 is out of range 1..65536".
std::string rangeMessage(std::string_view name, long long value, long long min, long long max) {
  return std::string(name) + " " + std::to_string(value) + " is out of range " +
         std::to_string(min) + ".." + std::to_string(max);
}

constexpr Named<Filter> kFilters[] = {
    {"bilinear", Filter::kBilinear}, {"bicubic", Filter::kBicubic}, {"hermite", Filter::kHermite}};
constexpr Named<Wrap> kWraps[] = {{"repeat", Wrap::kRepeat}, {"clamp", Wrap::kClamp}};
constexpr Named<NormalSpace> kSpaces[] = {{"tangent", NormalSpace::kTangent},
                                          {"object", NormalSpace::kObject}};
constexpr Named<ImageChannels> kChannels[] = {{"luminance", ImageChannels::kLuminance},
                                              {"r", ImageChannels::kRed},
                                              {"g", ImageChannels::kGreen},
                                              {"b", ImageChannels::kBlue},
                                              {"a", ImageChannels::kAlpha}};
constexpr Named<LayerBase> kBases[] = {{"surface", LayerBase::kSurface},
                                       {"above", LayerBase::kLayersAbove}};
constexpr Named<bool> kHeightSpaces[] = {{"world", false}, {"object", true}};
constexpr Named<NormalMapGreen> kGreens[] = {{"opengl", NormalMapGreen::kOpenGL},
                                             {"directx", NormalMapGreen::kDirectX}};
constexpr Named<ProjectedKind> kKinds[] = {{"height", ProjectedKind::kHeight},
                                           {"tangent-normal", ProjectedKind::kTangentNormal},
                                           {"object-normal", ProjectedKind::kObjectNormal}};
constexpr Named<TriplanarProjection> kProjections[] = {{"blended", TriplanarProjection::kBlended},
                                                       {"box", TriplanarProjection::kBox}};
constexpr Named<MappingType> kMappingTypes[] = {{"point", MappingType::kPoint},
                                                {"texture", MappingType::kTexture},
                                                {"vector", MappingType::kVector}};
constexpr Named<TriplanarProjection> kPlanarProjections[] = {
    {"axis", TriplanarProjection::kBlended},
    {"flat", TriplanarProjection::kFlat},
    {"sphere", TriplanarProjection::kSphere},
    {"tube", TriplanarProjection::kTube}};
constexpr Named<ProjectionAxis> kAxes[] = {
    {"x", ProjectionAxis::kX}, {"y", ProjectionAxis::kY}, {"z", ProjectionAxis::kZ}};
/// The scene name of @p value in @p table.
template <class E, std::size_t N>
std::string nameIn(const Named<E> (&table)[N], E value) {
  for (const Named<E>& entry : table) {
    if (entry.value == value) return entry.name;
  }
  return "?";
}

constexpr Named<VolumeFunction> kFunctions[] = {
    {"sine", VolumeFunction::kSine},
    {"noise", VolumeFunction::kNoise},
    {"blender-noise", VolumeFunction::kBlenderNoise},
    {"blender-musgrave", VolumeFunction::kBlenderMusgrave},
    {"blender-wave", VolumeFunction::kBlenderWave},
    {"blender-voronoi", VolumeFunction::kBlenderVoronoi},
    {"blender-brick", VolumeFunction::kBlenderBrick},
    {"blender-gradient", VolumeFunction::kBlenderGradient},
    {"blender-magic", VolumeFunction::kBlenderMagic}};
constexpr Named<VolumeCoordinates> kVolumeCoordinates[] = {{"object", VolumeCoordinates::kObject},
                                                           {"uv", VolumeCoordinates::kUv}};
constexpr Named<VoronoiMetric> kVoronoiMetrics[] = {{"euclidean", VoronoiMetric::kEuclidean},
                                                    {"manhattan", VoronoiMetric::kManhattan},
                                                    {"chebyshev", VoronoiMetric::kChebyshev},
                                                    {"minkowski", VoronoiMetric::kMinkowski}};
constexpr Named<MusgraveType> kMusgraveTypes[] = {
    {"fbm", MusgraveType::kFbm},
    {"multifractal", MusgraveType::kMultifractal},
    {"ridged-multifractal", MusgraveType::kRidgedMultifractal},
    {"hybrid-multifractal", MusgraveType::kHybridMultifractal},
    {"hetero-terrain", MusgraveType::kHeteroTerrain}};
constexpr Named<VoronoiFeature> kVoronoiFeatures[] = {
    {"f1", VoronoiFeature::kF1},
    {"f2", VoronoiFeature::kF2},
    {"smooth-f1", VoronoiFeature::kSmoothF1},
    {"distance-to-edge", VoronoiFeature::kDistanceToEdge}};
/// The Noise and Musgrave Textures' Dimensions, as Blender names them.
constexpr Named<int> kTextureDimensions[] = {{"1D", 1}, {"2D", 2}, {"3D", 3}, {"4D", 4}};
/// Whether a Noise or Musgrave Texture of @p dimensions reads its W (1D and 4D do).
constexpr bool readsW(int dimensions) { return dimensions == 1 || dimensions == 4; }
constexpr Named<BlenderGradientType> kGradientTypes[] = {
    {"linear", BlenderGradientType::kLinear},
    {"quadratic", BlenderGradientType::kQuadratic},
    {"easing", BlenderGradientType::kEasing},
    {"diagonal", BlenderGradientType::kDiagonal},
    {"spherical", BlenderGradientType::kSpherical},
    {"quadratic-sphere", BlenderGradientType::kQuadraticSphere},
    {"radial", BlenderGradientType::kRadial}};
constexpr Named<WaveType> kWaveTypes[] = {{"bands", WaveType::kBands}, {"rings", WaveType::kRings}};
constexpr Named<WaveDirection> kWaveDirections[] = {{"x", WaveDirection::kX},
                                                    {"y", WaveDirection::kY},
                                                    {"z", WaveDirection::kZ},
                                                    {"diagonal", WaveDirection::kDiagonal},
                                                    {"spherical", WaveDirection::kSpherical}};
constexpr Named<WaveProfile> kWaveProfiles[] = {
    {"sine", WaveProfile::kSine}, {"saw", WaveProfile::kSaw}, {"triangle", WaveProfile::kTriangle}};
constexpr Named<GradientScheme> kSchemes[] = {{"analytic", GradientScheme::kAnalytic},
                                              {"central", GradientScheme::kCentral},
                                              {"tetrahedral", GradientScheme::kTetrahedral}};
constexpr Named<HeightGradient> kHeightGradients[] = {{"analytic", HeightGradient::kAnalytic},
                                                      {"bump-node", HeightGradient::kBumpNode}};
constexpr Named<PaddingMode> kPaddings[] = {{"extend", PaddingMode::kExtend},
                                            {"push-pull", PaddingMode::kPushPull},
                                            {"adjacent-faces", PaddingMode::kAdjacentFaces}};
constexpr Named<SceneLayerType> kLayerTypes[] = {{"height", SceneLayerType::kHeight},
                                                 {"normal", SceneLayerType::kNormal},
                                                 {"volume", SceneLayerType::kVolume},
                                                 {"planar", SceneLayerType::kPlanar},
                                                 {"triplanar", SceneLayerType::kTriplanar}};
constexpr const auto& kUvSmooths = kSubdivisionUvSmoothNames;
constexpr const auto& kBoundaries = kSubdivisionBoundaryNames;

/// The names of an enumeration table, in order.
template <class E, std::size_t N>
std::vector<std::string> namesOf(const Named<E> (&table)[N]) {
  std::vector<std::string> names;
  for (const Named<E>& entry : table) names.emplace_back(entry.name);
  return names;
}

/// The names of every map an output may ask for: the MapKinds and "corners".
std::vector<std::string> outputMapNames() {
  std::vector<std::string> names;
  for (const MapKind kind :
       {MapKind::kTangentNormal, MapKind::kObjectNormal, MapKind::kHeight, MapKind::kDerivative,
        MapKind::kSurfaceGradient, MapKind::kTangent, MapKind::kBitangent, MapKind::kMask}) {
    names.emplace_back(mapKindName(kind));
  }
  names.emplace_back("corners");
  return names;
}

/// "unknown filter 'bicubc' (did you mean 'bicubic'?)" or "... (expected bilinear, ...)".
std::string unknownNameMessage(std::string_view what, std::string_view value,
                               const std::vector<std::string>& names) {
  const std::string suggestion = closestMatch(value, names);
  std::string message = "unknown " + std::string(what) + " " + quote(value);
  if (!suggestion.empty()) return message + " (did you mean " + quote(suggestion) + "?)";
  return message + " (expected " + listNames(names) + ")";
}

/// Keys that are comments: anything starting with '_'.
bool isComment(std::string_view key) { return !key.empty() && key.front() == '_'; }

/// Reads one JSON object of the scene: its allowed keys, typed and range-checked values.
class ObjectReader {
 public:
  /// @param where  the object's JSON path ("outputs[0]"; "" at the top level)
  /// @param what   what the object is, for messages ("a height layer", "an output")
  ObjectReader(const json& object, std::string where, std::string what)
      : object_(object), where_(std::move(where)), what_(std::move(what)) {
    if (!object_.is_object()) {
      fail(where_, "expected an object for " + what_ + ", not " + describeType(object_));
    }
  }

  const std::string& where() const { return where_; }

  /// @brief Fails on the first key not in @p allowed (comments aside). @p elsewhere maps keys
  /// that are valid in a sibling context to a hint naming it ("it is for volume layers").
  void checkKeys(const std::vector<std::string>& allowed,
                 const std::map<std::string, std::string>& elsewhere = {}) const {
    for (const auto& item : object_.items()) {
      const std::string& key = item.key();
      if (isComment(key) || std::find(allowed.begin(), allowed.end(), key) != allowed.end()) {
        continue;
      }
      if (const auto hint = elsewhere.find(key); hint != elsewhere.end()) {
        fail(where_,
             "key " + quote(key) + " does not apply to " + what_ + " (" + hint->second + ")");
      }
      const std::string suggestion = closestMatch(key, allowed);
      if (!suggestion.empty()) {
        fail(where_, "unknown key " + quote(key) + " (did you mean " + quote(suggestion) + "?)");
      }
      fail(where_, "unknown key " + quote(key) + " (expected " + listNames(allowed) + ")");
    }
  }

  bool has(std::string_view key) const { return object_.contains(key); }

  const json& at(std::string_view key) const { return object_.at(std::string(key)); }

  void require(std::string_view key) const {
    if (!has(key)) fail(where_, "missing key " + quote(key) + " in " + what_);
  }

  std::string string(std::string_view key) const {
    const json& value = at(key);
    if (!value.is_string()) typeError(key, "a string", value);
    return value.get<std::string>();
  }

  bool boolean(std::string_view key) const {
    const json& value = at(key);
    if (!value.is_boolean()) typeError(key, "true or false", value);
    return value.get<bool>();
  }

  /// A finite number.
  double number(std::string_view key) const { return numberValue(key, at(key)); }

  /// A number >= @p min (finite).
  double numberAtLeast(std::string_view key, double min, bool exclusive) const {
    const double value = number(key);
    if (exclusive ? !(value > min) : !(value >= min)) {
      std::ostringstream bound;
      bound << min;
      fail(where_, std::string(key) + " " + at(key).dump() + " must be " +
                       (exclusive ? "greater than " : "at least ") + bound.str());
    }
    return value;
  }

  /// An integer in [min, max]; integral floats (2048.0) are accepted.
  long long integer(std::string_view key, long long min, long long max) const {
    const json& value = at(key);
    long long result = 0;
    if (value.is_number_integer()) {
      if (value.is_number_unsigned() &&
          value.get<std::uint64_t>() > static_cast<std::uint64_t>(max)) {
        fail(where_, std::string(key) + " " + value.dump() + " is out of range " +
                         std::to_string(min) + ".." + std::to_string(max));
      }
      result = value.get<long long>();
    } else if (value.is_number_float()) {
      const double d = value.get<double>();
      if (!std::isfinite(d) || d != std::floor(d)) typeError(key, "an integer", value);
      if (d < static_cast<double>(min) || d > static_cast<double>(max)) {
        fail(where_, std::string(key) + " " + value.dump() + " is out of range " +
                         std::to_string(min) + ".." + std::to_string(max));
      }
      result = static_cast<long long>(d);
    } else {
      typeError(key, "an integer", value);
    }
    if (result < min || result > max) fail(where_, rangeMessage(key, result, min, max));
    return result;
  }

  int smallInteger(std::string_view key, int min, int max) const {
    return static_cast<int>(integer(key, min, max));
  }

  /// A non-negative integer of up to 64 bits (noise seeds).
  std::uint64_t unsignedInteger(std::string_view key) const {
    const json& value = at(key);
    if (value.is_number_unsigned()) return value.get<std::uint64_t>();
    if (value.is_number_integer()) {
      fail(where_, std::string(key) + " " + value.dump() + " must be at least 0");
    }
    typeError(key, "an integer", value);
  }

  /// A number (both components equal) or an array of two numbers.
  Vec2d vec2(std::string_view key) const {
    const json& value = at(key);
    if (value.is_number()) {
      const double d = numberValue(key, value);
      return {d, d};
    }
    if (!value.is_array() || value.size() != 2) {
      typeError(key, "a number or an array of 2 numbers", value);
    }
    return {numberValue(key, value[0]), numberValue(key, value[1])};
  }

  /// An array of [x, y] pairs of numbers (at least one).
  std::vector<Vec2d> points(std::string_view key) const {
    const json& value = at(key);
    if (!value.is_array() || value.empty()) typeError(key, "an array of [x, y] points", value);
    std::vector<Vec2d> out;
    out.reserve(value.size());
    for (const json& point : value) {
      if (!point.is_array() || point.size() != 2) {
        typeError(key, "an array of [x, y] points", value);
      }
      out.push_back({numberValue(key, point[0]), numberValue(key, point[1])});
    }
    return out;
  }

  /// An array of three numbers.
  Vec3d vec3(std::string_view key) const {
    const json& value = at(key);
    if (!value.is_array() || value.size() != 3) typeError(key, "an array of 3 numbers", value);
    return {numberValue(key, value[0]), numberValue(key, value[1]), numberValue(key, value[2])};
  }

  /// One of the names in @p table.
  template <class E, std::size_t N>
  E name(std::string_view key, const Named<E> (&table)[N]) const {
    const std::string text = string(key);
    for (const Named<E>& entry : table) {
      if (text == entry.name) return entry.value;
    }
    fail(where_, unknownNameMessage(key, text, namesOf(table)));
  }

  /// Reads @p key into @p out when present.
  template <class E, std::size_t N>
  void optionalName(std::string_view key, const Named<E> (&table)[N], E& out) const {
    if (has(key)) out = name(key, table);
  }

 private:
  [[noreturn]] void typeError(std::string_view key, std::string_view expected,
                              const json& value) const {
    fail(where_, quote(key) + " must be " + std::string(expected) + ", not " +
                     (value.is_number() ? describeValue(value) : describeType(value)));
  }

  double numberValue(std::string_view key, const json& value) const {
    if (!value.is_number()) typeError(key, "a number", value);
    const double d = value.get<double>();
    if (!std::isfinite(d)) fail(where_, quote(key) + " must be a finite number");
    return d;
  }

  const json& object_;
  std::string where_;
  std::string what_;
};

/// Resolves a scene path: absolute as is, relative against @p base; lexically normalized.
std::filesystem::path resolvePath(const std::filesystem::path& base, const std::string& text) {
  const std::filesystem::path path(text);
  const std::filesystem::path joined = path.is_absolute() || base.empty() ? path : base / path;
  // ".." after a symbolic link to a directory leads where the link's target is, not back
  // where the text says: such paths are resolved as the system resolves them (their existing
  // part, links included; the result is absolute). Others only lose "." and doubled slashes.
  if (std::any_of(joined.begin(), joined.end(), [](const auto& part) { return part == ".."; })) {
    return canonicalPath(joined);
  }
  return joined.lexically_normal();
}

/// How a scene's input paths are read: resolved against a directory, or, for a scene of an
/// in-memory bake, kept as the names of images given in memory.
struct InputPaths {
  std::filesystem::path base;
  bool names = false;
  std::filesystem::path operator()(const std::string& text) const {
    return names ? std::filesystem::path(text) : resolvePath(base, text);
  }
};

/// A path key: a non-empty string, resolved against @p base.
std::filesystem::path pathValue(const ObjectReader& reader, std::string_view key,
                                const InputPaths& paths) {
  const std::string text = reader.string(key);
  if (text.empty()) fail(reader.where(), quote(key) + " is empty");
  // JSON can spell a NUL ("\u0000"); a file name cannot hold one (the system would cut it).
  if (text.find('\0') != std::string::npos) {
    fail(reader.where(), quote(key) + " holds a NUL character, which no file name can");
  }
  return paths(text);
}

// ---- Keys of each kind of object ---------------------------------------------------------------

const std::vector<std::string> kTopKeys = {"mesh",      "uv",     "subdivision",
                                           "transform", "layers", "outputs"};
const std::vector<std::string> kSubdivisionKeys = {"level",       "uv_smooth",    "boundary",
                                                   "use_creases", "edge_creases", "vertex_creases",
                                                   "quality",     "use_limit_surface",
                                                   "type",        "auto_smooth",
                                                   "sharp_edges"};
const std::vector<std::string> kMaskKeys = {"image", "uv", "tiling", "offset", "filter"};
const std::vector<std::string> kMappingKeys = {"type", "location", "rotation", "scale", "matrix"};
const std::vector<std::string> kLayerCommonKeys = {"type", "name", "weight", "mask", "material"};
const std::vector<std::string> kImageLayerKeys = {"image", "filter", "wrap", "tiling", "offset"};

/// The keys of a layer of @p type beyond kLayerCommonKeys.
std::vector<std::string> layerKeys(SceneLayerType type) {
  std::vector<std::string> keys = kLayerCommonKeys;
  const auto add = [&keys](std::initializer_list<const char*> more) {
    keys.insert(keys.end(), more.begin(), more.end());
  };
  if (type != SceneLayerType::kVolume)
    keys.insert(keys.end(), kImageLayerKeys.begin(), kImageLayerKeys.end());
  switch (type) {
    case SceneLayerType::kHeight:
      add({"uv", "scale", "strength", "base", "channel", "gradient", "height_space", "remap"});
      break;
    case SceneLayerType::kNormal:
      add({"uv", "space", "green", "strength", "tangent_uv"});
      break;
    case SceneLayerType::kVolume:
      add({"function",
           "amplitude",
           "frequency",
           "direction",
           "phase",
           "seed",
           "octaves",
           "detail",
           "roughness",
           "distortion",
           "dimension",
           "lacunarity",
           "dimensions",  // the Noise and Musgrave Textures' Dimensions, and their W
           "w",
           "mortar_size",  // the Brick Texture's
           "mortar_smooth",
           "brick_width",
           "row_height",
           "brick_offset",
           "offset_frequency",
           "squash",
           "squash_frequency",
           "musgrave_type",  // the Musgrave Texture's type, its offset and gain
           "offset",
           "gain",
           "wave",
           "wave_direction",
           "profile",
           "detail_scale",
           "detail_roughness",
           "randomness",
           "metric",
           "exponent",
           "feature",  // the Voronoi Texture's Feature Output and its smoothness
           "smoothness",
           "gradient_type",  // the Gradient Texture's type
           "depth",          // the Magic Texture's
           "mapping",
           "coordinates",
           "uv",
           "gradient",
           "step",
           "base",
           "strength",
           "height_space",
           "remap"});
      break;
    case SceneLayerType::kPlanar:
      add({"kind", "axis", "scale", "mapping", "green", "base", "gradient", "strength",
           "projection", "tangent_uv", "height_space", "remap"});
      break;
    case SceneLayerType::kTriplanar:
      add({"kind", "scale", "mapping", "projection", "sharpness", "min_weight", "box_blend",
           "green", "base", "gradient", "tangent_uv", "strength", "height_space", "remap"});
      break;
  }
  return keys;
}

/// For a layer of @p type: keys that other layer types accept, with a hint naming them.
std::map<std::string, std::string> layerKeysElsewhere(SceneLayerType type) {
  const std::vector<std::string> own = layerKeys(type);
  std::map<std::string, std::vector<std::string>> users;
  for (const Named<SceneLayerType>& other : kLayerTypes) {
    if (other.value == type) continue;
    for (const std::string& key : layerKeys(other.value)) {
      if (std::find(own.begin(), own.end(), key) == own.end()) users[key].push_back(other.name);
    }
  }
  std::map<std::string, std::string> hints;
  for (const auto& [key, types] : users) {
    hints[key] = "it is for " + listNames(types) + " layers";
  }
  return hints;
}

const std::vector<std::string> kMapOutputKeys = {
    "map", "file",  "size",    "width", "height", "margin",    "padding", "samples",
    "uv",  "green", "swizzle", "tile",  "format", "bit_depth", "alpha",   "range"};
const std::vector<std::string> kCornersOutputKeys = {"map", "file"};

// ---- Parsing each part -------------------------------------------------------------------------

/// A vertex index inside a crease entry at @p where.
std::uint32_t creaseVertex(const json& value, const std::string& where) {
  if (value.is_number_unsigned() &&
      value.get<std::uint64_t>() <= std::numeric_limits<std::uint32_t>::max()) {
    return static_cast<std::uint32_t>(value.get<std::uint64_t>());
  }
  if (value.is_number_integer() || (value.is_number_float() && std::isfinite(value.get<double>()) &&
                                    value.get<double>() == std::floor(value.get<double>()))) {
    fail(where, "vertex " + value.dump() + " is out of range (vertices are numbered from 0)");
  }
  fail(where, "a vertex must be an integer, not " +
                  (value.is_number() ? describeValue(value) : describeType(value)));
}

/// The crease value inside a crease entry at @p where: a number in [0, 1].
float creaseValue(const json& value, const std::string& where) {
  if (!value.is_number()) {
    fail(where, "a crease must be a number, not " + describeType(value));
  }
  const double c = value.get<double>();
  if (!(c >= 0.0 && c <= 1.0)) fail(where, "crease " + value.dump() + " is out of range 0..1");
  return static_cast<float>(c);
}

/// The entries of a crease list @p key of @p reader: arrays of @p size elements.
const json& creaseList(const ObjectReader& reader, std::string_view key, std::size_t size,
                       std::string_view shape) {
  const json& list = reader.at(key);
  const std::string where = appendPath(reader.where(), key);
  if (!list.is_array())
    fail(reader.where(), quote(key) + " must be an array, not " + describeType(list));
  for (std::size_t i = 0; i < list.size(); ++i) {
    const json& entry = list[i];
    if (!entry.is_array() || entry.size() != size) {
      fail(where + "[" + std::to_string(i) + "]",
           "expected " + std::string(shape) + ", not " +
               (entry.is_array() ? "an array of " + std::to_string(entry.size())
                                 : describeValue(entry)));
    }
  }
  return list;
}

/// "edge_creases": [[a, b, c], ...], each edge once.
std::vector<EdgeCrease> parseEdgeCreases(const ObjectReader& reader) {
  const json& list = creaseList(reader, "edge_creases", 3,
                                "[a, b, c] (two vertex indices and a crease in [0, 1])");
  std::vector<EdgeCrease> creases;
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::size_t> seen;
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string where =
        appendPath(reader.where(), "edge_creases") + "[" + std::to_string(i) + "]";
    EdgeCrease crease{creaseVertex(list[i][0], where), creaseVertex(list[i][1], where),
                      creaseValue(list[i][2], where)};
    if (crease.v0 == crease.v1) {
      fail(where, "an edge joins two different vertices, not " + std::to_string(crease.v0) +
                      " and itself");
    }
    const auto key = std::minmax(crease.v0, crease.v1);
    if (const auto [it, added] = seen.emplace(key, i); !added) {
      fail(where, "the edge " + std::to_string(key.first) + "-" + std::to_string(key.second) +
                      " is already creased by edge_creases[" + std::to_string(it->second) + "]");
    }
    creases.push_back(crease);
  }
  return creases;
}

/// "sharp_edges": [[a, b], ...] (whether each is an edge of the mesh, and listed once, is
/// checked against the mesh: findCreaseIssue).
std::vector<SharpEdge> parseSharpEdges(const ObjectReader& reader) {
  const json& list = creaseList(reader, "sharp_edges", 2, "[a, b] (two vertex indices)");
  std::vector<SharpEdge> edges;
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string where =
        appendPath(reader.where(), "sharp_edges") + "[" + std::to_string(i) + "]";
    edges.push_back({creaseVertex(list[i][0], where), creaseVertex(list[i][1], where)});
  }
  return edges;
}

/// "vertex_creases": [[v, c], ...], each vertex once.
std::vector<VertexCrease> parseVertexCreases(const ObjectReader& reader) {
  const json& list =
      creaseList(reader, "vertex_creases", 2, "[v, c] (a vertex index and a crease in [0, 1])");
  std::vector<VertexCrease> creases;
  std::map<std::uint32_t, std::size_t> seen;
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string where =
        appendPath(reader.where(), "vertex_creases") + "[" + std::to_string(i) + "]";
    VertexCrease crease{creaseVertex(list[i][0], where), creaseValue(list[i][1], where)};
    if (const auto [it, added] = seen.emplace(crease.vertex, i); !added) {
      fail(where, "vertex " + std::to_string(crease.vertex) +
                      " is already creased by vertex_creases[" + std::to_string(it->second) + "]");
    }
    creases.push_back(crease);
  }
  return creases;
}

/// Refuses settings of a subdivision block that do nothing or contradict each other
/// (findSubdivisionConflict: the command line refuses the same, in its flags' words).
void checkSubdivisionConflict(const ObjectReader& reader, const SceneSubdivision& subdivision) {
  const auto unsubdivided = [&](const char* given) {
    fail(reader.where(), std::string(given) +
                             " applies to a subdivided mesh; set \"level\" to 1 or more (at "
                             "\"level\": 0 nothing is subdivided)");
  };
  // Quality is how closely Use Limit Surface approximates the limit: unused without it, and by
  // the exact limit surface.
  if (reader.has("quality") && (subdivision.limit || !subdivision.useLimitSurface)) {
    fail(reader.where(), std::string("\"quality\" applies with Use Limit Surface, not with ") +
                             (subdivision.limit ? "\"level\": \"limit\" (the exact surface)"
                                                : "\"use_limit_surface\": false"));
  }
  switch (findSubdivisionConflict(subdivision.options(), subdivision.limit)) {
    case SubdivisionConflict::kNone:
      return;
    case SubdivisionConflict::kEdgeCreasesUnsubdivided:
      return unsubdivided("\"edge_creases\"");
    case SubdivisionConflict::kVertexCreasesUnsubdivided:
      return unsubdivided("\"vertex_creases\"");
    case SubdivisionConflict::kNoLimitSurfaceUnsubdivided:
      return unsubdivided("\"use_limit_surface\": false");
    case SubdivisionConflict::kSimpleUnsubdivided:
      return unsubdivided("\"type\": \"simple\"");
    case SubdivisionConflict::kSharpEdgesWithoutAutoSmooth:
      fail(reader.where(),
           "\"sharp_edges\" need \"auto_smooth\" (edges marked sharp split the normals only "
           "with Auto Smooth)");
    case SubdivisionConflict::kLimitWithoutLimitSurface:
      fail(reader.where(),
           "\"level\": \"limit\" shades the limit surface itself; it cannot be "
           "combined with \"use_limit_surface\": false");
    case SubdivisionConflict::kLimitSimple:
      fail(reader.where(),
           "\"level\": \"limit\" is the Catmull-Clark limit surface; it cannot "
           "be combined with \"type\": \"simple\"");
    case SubdivisionConflict::kLimitAutoSmooth:
      fail(reader.where(),
           "\"level\": \"limit\" shades the exact surface's own normals; it "
           "cannot be combined with \"auto_smooth\"");
    case SubdivisionConflict::kLimitSharpEdges:
      fail(reader.where(),
           "\"level\": \"limit\" shades the exact surface's own normals; it "
           "cannot be combined with \"sharp_edges\"");
  }
}

/// The top-level "transform": 4 rows of 4 numbers (an affine matrix: last row 0 0 0 1) or 3 rows
/// of 3, finite, with a nonzero determinant.
ObjectTransform parseTransform(const json& value) {
  const auto shape = [&] {
    fail("",
         "'transform' must be 4 rows of 4 numbers (Blender's matrix_world) or 3 rows of 3, "
         "not " +
             (value.is_array() ? std::string("an array of ") + std::to_string(value.size())
                               : describeType(value)));
  };
  if (!value.is_array() || (value.size() != 4 && value.size() != 3)) shape();
  const std::size_t n = value.size();
  double m[4][4] = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}};
  for (std::size_t r = 0; r < n; ++r) {
    const json& row = value[r];
    if (!row.is_array() || row.size() != n) {
      fail("",
           "transform[" + std::to_string(r) + "] must be a row of " + std::to_string(n) +
               " numbers (" + std::to_string(n) + " rows of " + std::to_string(n) + "), not " +
               (row.is_array() ? "an array of " + std::to_string(row.size()) : describeType(row)));
    }
    for (std::size_t c = 0; c < n; ++c) {
      const std::string where = "transform[" + std::to_string(r) + "][" + std::to_string(c) + "]";
      if (!row[c].is_number()) fail("", where + " must be a number, not " + describeType(row[c]));
      m[r][c] = row[c].get<double>();
      if (!std::isfinite(m[r][c])) fail("", where + " is not finite");
    }
  }
  const Result<ObjectTransform> transform =
      objectTransformFromRows({&m[0][0], 16}, static_cast<int>(n) == 3 ? 3 : 4, 4);
  if (!transform) fail("", "'transform' " + transform.error().message);
  return *transform;
}

SceneSubdivision parseSubdivision(const json& value) {
  const ObjectReader reader(value, "subdivision", "the subdivision block");
  reader.checkKeys(kSubdivisionKeys);
  SceneSubdivision subdivision;
  subdivision.present = true;
  if (reader.has("level")) {
    const json& level = reader.at("level");
    if (level.is_string()) {
      if (level.get<std::string>() != "limit") {
        fail(reader.where(), "level " + describeValue(level) + " must be \"limit\" or a number");
      }
      subdivision.limit = true;
    } else {
      subdivision.level = reader.smallInteger("level", 0, 6);
    }
  }
  reader.optionalName("type", kSubdivisionTypeNames, subdivision.type);
  reader.optionalName("uv_smooth", kUvSmooths, subdivision.uvSmooth);
  reader.optionalName("boundary", kBoundaries, subdivision.boundary);
  if (reader.has("use_creases")) subdivision.useCreases = reader.boolean("use_creases");
  if (reader.has("edge_creases")) subdivision.edgeCreases = parseEdgeCreases(reader);
  if (reader.has("sharp_edges")) subdivision.sharpEdges = parseSharpEdges(reader);
  if (reader.has("vertex_creases")) subdivision.vertexCreases = parseVertexCreases(reader);
  if (reader.has("quality")) {
    subdivision.quality =
        reader.smallInteger("quality", kMinSubdivisionQuality, kMaxSubdivisionQuality);
  }
  if (reader.has("auto_smooth")) {
    const double degrees = reader.numberAtLeast("auto_smooth", 0, false);
    if (degrees > 180) {
      fail(reader.where(), "auto_smooth " + reader.at("auto_smooth").dump() +
                               " must be at most 180 (degrees)");
    }
    subdivision.autoSmoothDegrees = degrees;
  }
  if (reader.has("use_limit_surface")) {
    subdivision.useLimitSurface = reader.boolean("use_limit_surface");
  }
  checkSubdivisionConflict(reader, subdivision);
  return subdivision;
}

SceneMask parseMask(const json& value, const std::string& where, const InputPaths& paths,
                    int defaultUv) {
  SceneMask mask;
  mask.uvSet = defaultUv;
  if (value.is_string()) {
    const std::string text = value.get<std::string>();
    if (text.empty()) fail(where, "'mask' is empty");
    if (text.find('\0') != std::string::npos) {
      fail(where, "'mask' holds a NUL character, which no file name can");
    }
    mask.image = paths(text);
    return mask;
  }
  const ObjectReader reader(value, where, "a mask");
  reader.checkKeys(kMaskKeys);
  reader.require("image");
  mask.image = pathValue(reader, "image", paths);
  if (reader.has("uv")) mask.uvSet = reader.smallInteger("uv", 0, kMaxUvSets - 1);
  if (reader.has("tiling")) mask.tiling = reader.vec2("tiling");
  if (reader.has("offset")) mask.offset = reader.vec2("offset");
  reader.optionalName("filter", kFilters, mask.filter);
  return mask;
}

SceneMapping parseMapping(const json& value, const std::string& where) {
  const ObjectReader reader(value, where, "a mapping");
  reader.checkKeys(kMappingKeys);
  SceneMapping mapping;
  reader.optionalName("type", kMappingTypes, mapping.type);
  if (reader.has("location")) mapping.location = reader.vec3("location");
  if (reader.has("rotation")) mapping.rotation = reader.vec3("rotation");
  if (reader.has("scale")) mapping.scale = reader.vec3("scale");
  if (reader.has("matrix")) {
    const json& rows = reader.at("matrix");
    const auto bad = [&](const std::string& why) { fail(where, "matrix " + why); };
    if (!rows.is_array() || (rows.size() != 3 && rows.size() != 4)) {
      bad("must be 3 rows of 4 numbers (or 4, the last [0, 0, 0, 1])");
    }
    double m[4][4] = {};
    for (std::size_t r = 0; r < rows.size(); ++r) {
      if (!rows[r].is_array() || rows[r].size() != 4) {
        bad("row " + std::to_string(r) + " must be 4 numbers");
      }
      for (std::size_t c = 0; c < 4; ++c) {
        if (!rows[r][c].is_number() || !std::isfinite(rows[r][c].get<double>())) {
          bad("[" + std::to_string(r) + "][" + std::to_string(c) + "] must be a finite number");
        }
        m[r][c] = rows[r][c].get<double>();
      }
    }
    if (rows.size() == 4 && (m[3][0] != 0 || m[3][1] != 0 || m[3][2] != 0 || m[3][3] != 1)) {
      bad("row 3 must be [0, 0, 0, 1] (an affine map)");
    }
    mapping.matrix = Mat3::fromColumns({m[0][0], m[1][0], m[2][0]}, {m[0][1], m[1][1], m[2][1]},
                                       {m[0][2], m[1][2], m[2][2]});
    mapping.matrixTranslation = {m[0][3], m[1][3], m[2][3]};
  }
  return mapping;
}

SceneLayer parseLayer(const json& value, const std::string& where, const InputPaths& paths,
                      int defaultUv) {
  SceneLayer layer;
  {
    const ObjectReader probe(value, where, "a layer");
    probe.require("type");
    layer.type = probe.name("type", kLayerTypes);
  }
  const std::string what = "a " + std::string(sceneLayerTypeName(layer.type)) + " layer";
  const ObjectReader reader(value, where, what);
  reader.checkKeys(layerKeys(layer.type), layerKeysElsewhere(layer.type));

  layer.uvSet = defaultUv;
  if (reader.has("name")) layer.name = reader.string("name");
  if (reader.has("weight")) layer.weight = reader.number("weight");
  if (reader.has("material")) {
    const json& material = reader.at("material");
    if (material.is_string()) {
      layer.materialName = material.get<std::string>();
    } else {
      layer.material = static_cast<int>(reader.integer("material", 0, kMaxMaterialIndex));
    }
  }

  if (layer.hasImage()) {
    reader.require("image");
    layer.image = pathValue(reader, "image", paths);
    reader.optionalName("filter", kFilters, layer.filter);
    reader.optionalName("wrap", kWraps, layer.wrap);
    if (reader.has("tiling")) layer.tiling = reader.vec2("tiling");
    if (reader.has("offset")) layer.offset = reader.vec2("offset");
  }
  if (reader.has("uv")) layer.uvSet = reader.smallInteger("uv", 0, kMaxUvSets - 1);
  if (reader.has("mask")) {
    // The mask is looked up on the layer's UV set unless it names its own.
    layer.mask = parseMask(reader.at("mask"), appendPath(where, "mask"), paths, layer.uvSet);
  }
  if (reader.has("scale")) layer.scale = reader.number("scale");
  reader.optionalName("green", kGreens, layer.green);
  reader.optionalName("space", kSpaces, layer.space);
  reader.optionalName("kind", kKinds, layer.kind);
  if (reader.has("strength")) {
    // A normal map's Strength is its only factor (held as its scale); a height's is the Bump
    // node's, beside its scale (the Bump node's Distance).
    if (layer.projected() && !layer.hasHeight()) {
      fail(where,
           "key 'strength' applies to heights (a projected normal map's strength is its "
           "'scale')");
    }
    (layer.hasHeight() ? layer.strength : layer.scale) = reader.number("strength");
  }
  reader.optionalName("axis", kAxes, layer.axis);
  reader.optionalName("base", kBases, layer.base);
  reader.optionalName("height_space", kHeightSpaces, layer.objectSpaceHeight);
  reader.optionalName("channel", kChannels, layer.channel);
  if (layer.type == SceneLayerType::kHeight || layer.projected()) {
    reader.optionalName("gradient", kHeightGradients, layer.heightGradient);
  }
  if (reader.has("tangent_uv"))
    layer.tangentUvSet = reader.smallInteger("tangent_uv", 0, kMaxUvSets - 1);
  if (reader.has("sharpness")) layer.sharpness = reader.numberAtLeast("sharpness", 0, false);
  if (reader.has("min_weight")) layer.minWeight = reader.numberAtLeast("min_weight", 0, false);
  if (layer.type == SceneLayerType::kPlanar) {
    reader.optionalName("projection", kPlanarProjections, layer.projection);
  } else {
    reader.optionalName("projection", kProjections, layer.projection);
  }
  if (reader.has("mapping"))
    layer.mapping = parseMapping(reader.at("mapping"), appendPath(where, "mapping"));
  if (reader.has("box_blend")) layer.boxBlend = reader.numberAtLeast("box_blend", 0, false);

  if (layer.type == SceneLayerType::kVolume) {
    reader.optionalName("function", kFunctions, layer.function);
    const bool sine = layer.function == VolumeFunction::kSine;
    const bool noise = layer.function == VolumeFunction::kBlenderNoise;
    const bool musgrave = layer.function == VolumeFunction::kBlenderMusgrave;
    const bool wave = layer.function == VolumeFunction::kBlenderWave;
    const bool voronoi = layer.function == VolumeFunction::kBlenderVoronoi;
    const bool brick = layer.function == VolumeFunction::kBlenderBrick;
    const bool gradientTexture = layer.function == VolumeFunction::kBlenderGradient;
    const bool magic = layer.function == VolumeFunction::kBlenderMagic;
    const bool blender = noise || musgrave || wave || voronoi || brick || gradientTexture || magic;
    const std::string function = nameIn(kFunctions, layer.function);
    const auto onlyFor = [&](std::initializer_list<const char*> keys, bool applies,
                             const char* owner) {
      for (const char* key : keys) {
        if (!applies && reader.has(key)) {
          fail(where, "key " + quote(key) + " does not apply to a " + function +
                          " volume (it is for " + owner + ")");
        }
      }
    };
    onlyFor({"direction"}, sine, "sine");
    onlyFor({"phase"}, sine || wave, "sine and blender-wave");
    onlyFor({"seed", "octaves"}, layer.function == VolumeFunction::kNoise, "noise");
    onlyFor({"detail"}, noise || musgrave || wave,
            "blender-noise, blender-musgrave and blender-wave");
    onlyFor({"distortion"}, noise || wave || magic,
            "blender-noise, blender-wave and blender-magic");
    onlyFor({"frequency"}, !gradientTexture,
            "the other functions: the Gradient Texture has no Scale");
    onlyFor({"gradient_type"}, gradientTexture, "blender-gradient");
    onlyFor({"depth"}, magic, "blender-magic");
    onlyFor({"roughness"}, noise, "blender-noise");
    onlyFor({"wave", "wave_direction", "profile", "detail_scale", "detail_roughness"}, wave,
            "blender-wave");
    onlyFor({"randomness", "metric", "exponent", "feature", "smoothness"}, voronoi,
            "blender-voronoi");
    onlyFor({"mortar_size", "mortar_smooth", "brick_width", "row_height", "brick_offset",
             "offset_frequency", "squash", "squash_frequency"},
            brick, "blender-brick");
    onlyFor({"dimension", "lacunarity", "musgrave_type", "offset", "gain"}, musgrave,
            "blender-musgrave");
    onlyFor({"dimensions"}, noise || musgrave, "blender-noise and blender-musgrave");
    reader.optionalName("dimensions", kTextureDimensions, layer.textureDimensions);
    if (reader.has("w")) {
      if (!readsW(layer.textureDimensions)) {
        fail(where, "key " + quote("w") + " does not apply to a " +
                        (noise || musgrave
                             ? nameIn(kTextureDimensions, layer.textureDimensions) + " " + function
                             : function) +
                        " volume (W is read by blender-noise and blender-musgrave of "
                        "dimensions 1D and 4D)");
      }
      layer.textureW = reader.number("w");
    }
    if (reader.has("amplitude")) layer.amplitude = reader.number("amplitude");
    if (blender && !gradientTexture) layer.frequency = 5;  // Blender's textures' default Scale
    if (reader.has("frequency")) {
      layer.frequency = sine || blender ? reader.number("frequency")
                                        : reader.numberAtLeast("frequency", 0, /*exclusive=*/true);
    }
    if (reader.has("detail")) layer.noiseDetail = reader.number("detail");
    if (reader.has("roughness")) layer.noiseRoughness = reader.number("roughness");
    if (magic) layer.noiseDistortion = 1;  // the Magic Texture's default Distortion
    if (reader.has("distortion")) layer.noiseDistortion = reader.number("distortion");
    reader.optionalName("gradient_type", kGradientTypes, layer.gradientType);
    if (reader.has("depth"))
      layer.magicDepth = reader.smallInteger("depth", 0, kBlenderMagicMaxDepth);
    if (reader.has("dimension")) layer.noiseDimension = reader.number("dimension");
    if (reader.has("lacunarity")) layer.noiseLacunarity = reader.number("lacunarity");
    reader.optionalName("musgrave_type", kMusgraveTypes, layer.musgraveType);
    if (musgrave) {
      // Offset is for the ridged, hybrid and hetero terrain types, gain for ridged and hybrid.
      const MusgraveType type = layer.musgraveType;
      const bool ridgedOrHybrid =
          type == MusgraveType::kRidgedMultifractal || type == MusgraveType::kHybridMultifractal;
      const auto onlyForTypes = [&](const char* key, bool applies, const char* owner) {
        if (!applies && reader.has(key)) {
          fail(where, "key " + quote(key) + " does not apply to a blender-musgrave volume of " +
                          "musgrave_type " + quote(nameIn(kMusgraveTypes, type)) + " (it is for " +
                          owner + ")");
        }
      };
      onlyForTypes("offset", ridgedOrHybrid || type == MusgraveType::kHeteroTerrain,
                   "ridged-multifractal, hybrid-multifractal and hetero-terrain");
      onlyForTypes("gain", ridgedOrHybrid, "ridged-multifractal and hybrid-multifractal");
    }
    if (reader.has("offset")) layer.musgraveOffset = reader.number("offset");
    if (reader.has("gain")) layer.musgraveGain = reader.number("gain");
    if (brick) {
      BlenderBrickParams& b = layer.brick;
      if (reader.has("mortar_size")) b.mortarSize = reader.number("mortar_size");
      if (reader.has("mortar_smooth")) b.mortarSmooth = reader.number("mortar_smooth");
      if (reader.has("brick_width"))
        b.brickWidth = reader.numberAtLeast("brick_width", 0, /*exclusive=*/true);
      if (reader.has("row_height"))
        b.rowHeight = reader.numberAtLeast("row_height", 0, /*exclusive=*/true);
      if (reader.has("brick_offset")) b.offset = reader.number("brick_offset");
      if (reader.has("offset_frequency"))
        b.offsetFrequency = reader.smallInteger("offset_frequency", 0, 99);
      if (reader.has("squash")) b.squash = reader.numberAtLeast("squash", 0, /*exclusive=*/true);
      if (reader.has("squash_frequency"))
        b.squashFrequency = reader.smallInteger("squash_frequency", 0, 99);
    }
    if (reader.has("randomness")) layer.voronoiRandomness = reader.number("randomness");
    reader.optionalName("metric", kVoronoiMetrics, layer.voronoiMetric);
    if (reader.has("exponent")) layer.voronoiExponent = reader.number("exponent");
    reader.optionalName("feature", kVoronoiFeatures, layer.voronoiFeature);
    if (voronoi && layer.voronoiFeature != VoronoiFeature::kSmoothF1 && reader.has("smoothness")) {
      fail(where, "key 'smoothness' does not apply to a blender-voronoi volume of feature " +
                      quote(nameIn(kVoronoiFeatures, layer.voronoiFeature)) +
                      " (it is for smooth-f1)");
    }
    if (reader.has("smoothness")) layer.voronoiSmoothness = reader.number("smoothness");
    reader.optionalName("wave", kWaveTypes, layer.waveType);
    reader.optionalName("wave_direction", kWaveDirections, layer.waveDirection);
    reader.optionalName("profile", kWaveProfiles, layer.waveProfile);
    if (reader.has("detail_scale")) layer.noiseDetailScale = reader.number("detail_scale");
    if (reader.has("detail_roughness")) {
      layer.noiseDetailRoughness = reader.number("detail_roughness");
    }
    if (wave && layer.waveDirection == WaveDirection::kDiagonal &&
        layer.waveType != WaveType::kBands) {
      fail(where, "'wave_direction': 'diagonal' applies to 'wave': 'bands' only");
    }
    if (wave && layer.waveDirection == WaveDirection::kSpherical &&
        layer.waveType != WaveType::kRings) {
      fail(where, "'wave_direction': 'spherical' applies to 'wave': 'rings' only");
    }
    if (reader.has("direction")) layer.direction = reader.vec3("direction");
    if (reader.has("phase")) layer.phase = reader.number("phase");
    if (reader.has("seed")) layer.seed = reader.unsignedInteger("seed");
    if (reader.has("octaves")) layer.octaves = reader.smallInteger("octaves", 1, kMaxNoiseOctaves);
    // A scheme, or "bump-node": differenced as the Bump node does, analytic where a point has
    // no bake texel (per-corner tables).
    constexpr Named<int> kVolumeGradients[] = {
        {"analytic", 0}, {"central", 1}, {"tetrahedral", 2}, {"bump-node", 3}};
    int gradient = 0;
    reader.optionalName("gradient", kVolumeGradients, gradient);
    layer.gradient = gradient == 1   ? GradientScheme::kCentral
                     : gradient == 2 ? GradientScheme::kTetrahedral
                                     : GradientScheme::kAnalytic;
    if (gradient == 3) layer.heightGradient = HeightGradient::kBumpNode;
    if (reader.has("step")) layer.step = reader.numberAtLeast("step", 0, /*exclusive=*/true);
    reader.optionalName("coordinates", kVolumeCoordinates, layer.coordinates);
    if (layer.coordinates == VolumeCoordinates::kObject && reader.has("uv")) {
      fail(where,
           "key 'uv' applies to a volume on 'coordinates': 'uv' (this one is read at the "
           "object's positions)");
    }
    if (layer.coordinates == VolumeCoordinates::kUv && (gradient == 1 || gradient == 2)) {
      fail(where, "'gradient': '" + std::string(nameIn(kVolumeGradients, gradient)) +
                      "' applies to volumes on 'coordinates': 'object' (one on UV coordinates "
                      "takes its slopes 'analytic' or 'bump-node')");
    }
    if (layer.coordinates == VolumeCoordinates::kUv && reader.has("step")) {
      fail(where,
           "key 'step' applies to volumes on 'coordinates': 'object' (one on UV "
           "coordinates takes no finite differences)");
    }
  }

  // Combinations the keys alone do not rule out.
  if (layer.readsNormals() && layer.filter == Filter::kHermite) {
    fail(where, "filter 'hermite' is only available for height images (use bilinear or bicubic)");
  }
  const bool objectSpace =
      (layer.type == SceneLayerType::kNormal && layer.space == NormalSpace::kObject) ||
      (layer.projected() && layer.kind != ProjectedKind::kTangentNormal);
  if (objectSpace && reader.has("green")) {
    fail(where, "key 'green' applies only to tangent-space normal maps");
  }
  if (layer.projected() && layer.kind != ProjectedKind::kHeight && reader.has("gradient")) {
    fail(where, "key 'gradient' applies only to projected heights (kind 'height')");
  }
  const bool box = layer.projection == TriplanarProjection::kBox;
  for (const char* key : {"sharpness", "min_weight"}) {
    if (box && reader.has(key)) {
      fail(where, "key " + quote(key) +
                      " applies only to 'projection': 'blended' (Blender's Box projection "
                      "blends by 'box_blend')");
    }
  }
  if (!box && reader.has("box_blend")) {
    fail(where, "key 'box_blend' applies only to 'projection': 'box'");
  }
  if (layer.base == LayerBase::kLayersAbove && layer.readsNormals()) {
    fail(where,
         "'base': 'above' applies only to heights (a normal map has no normal to start from)");
  }
  if (reader.has("remap")) {
    if (layer.readsNormals()) {
      fail(where, "key 'remap' applies only to heights (a normal map's colour is not remapped)");
    }
    Result<HeightRemap> remap = HeightRemap::create(reader.points("remap"));
    if (!remap) fail(where, "'remap': " + remap.error().message);
    layer.remap.assign(remap->points().begin(), remap->points().end());
  }
  if (layer.readsNormals() && reader.has("height_space")) {
    fail(where, "key 'height_space' applies only to heights (a normal map has no height)");
  }
  return layer;
}

SceneOutput parseOutput(const json& value, const std::string& where,
                        const std::filesystem::path& outputBase, int defaultUv, bool inMemory) {
  SceneOutput output;
  output.uvSet = defaultUv;
  {
    const ObjectReader probe(value, where, "an output");
    probe.require("map");
    const std::string map = probe.string("map");
    if (map == "corners") {
      output.kind = OutputKind::kCorners;
    } else {
      Result<MapKind> kind = parseMapKind(map);
      if (!kind) fail(where, unknownNameMessage("map", map, outputMapNames()));
      output.map = *kind;
    }
  }
  const bool corners = output.kind == OutputKind::kCorners;
  const ObjectReader reader(value, where, corners ? "a corners output" : "an output");
  if (corners) {
    std::map<std::string, std::string> imageOnly;
    for (const std::string& key : kMapOutputKeys) imageOnly[key] = "it is for image maps";
    reader.checkKeys(kCornersOutputKeys, imageOnly);
  } else {
    reader.checkKeys(kMapOutputKeys);
  }
  if (inMemory) {
    if (corners) fail(where, "a corners table cannot be baked in memory (it is written as a file)");
    for (const char* key : {"file", "format", "bit_depth"}) {
      if (reader.has(key)) {
        fail(where, "key " + quote(key) + " is not used in memory (the map is returned as pixels)");
      }
    }
  } else {
    reader.require("file");
    output.file = pathValue(reader, "file", InputPaths{outputBase});
  }
  if (corners) return output;

  if (reader.has("size") && (reader.has("width") || reader.has("height"))) {
    fail(where, "give either 'size' or 'width'/'height', not both");
  }
  if (reader.has("size")) {
    output.width = output.height = reader.smallInteger("size", 1, kMaxBakeSide);
  }
  if (reader.has("width")) output.width = reader.smallInteger("width", 1, kMaxBakeSide);
  if (reader.has("height")) output.height = reader.smallInteger("height", 1, kMaxBakeSide);
  if (reader.has("margin")) output.margin = reader.smallInteger("margin", 0, kMaxBakeSide);
  reader.optionalName("padding", kPaddings, output.padding);
  if (reader.has("samples")) output.samples = reader.smallInteger("samples", 1, kMaxBakeSamples);
  if (reader.has("uv")) output.uvSet = reader.smallInteger("uv", 0, kMaxUvSets - 1);
  reader.optionalName("green", kGreens, output.green);
  if (reader.has("swizzle")) {
    // "+X-Y+Z", or ["+X", "-Y", "+Z"] (Blender's POS_X, NEG_Y, ... too).
    const json& given = reader.at("swizzle");
    std::string text;
    if (given.is_array() && given.size() == 3 &&
        std::ranges::all_of(given, [](const json& v) { return v.is_string(); })) {
      for (const json& axis : given) text += axis.get<std::string>() + ",";
    } else if (given.is_string()) {
      text = given.get<std::string>();
    } else {
      fail(where, "swizzle " + given.dump() +
                      " must be a string such as \"+X-Y+Z\" or three strings such as "
                      "[\"+X\", \"-Y\", \"+Z\"]");
    }
    Result<NormalSwizzle> swizzle = parseNormalSwizzle(text);
    if (!swizzle) fail(where, swizzle.error().message);
    output.swizzle = *swizzle;
  }
  if (reader.has("tile")) {
    output.tile = reader.smallInteger("tile", kFirstUdimTile, kLastUdimTile);
  }
  if (reader.has("format")) {
    Result<ImageFormat> format = parseImageFormat(reader.string("format"));
    if (!format) fail(where, format.error().message);
    output.format = *format;
  }
  if (reader.has("bit_depth")) {
    const json& depth = reader.at("bit_depth");
    if (depth.is_string() && (depth == "half" || depth == "float")) {
      output.bitDepth = depth == "half" ? 16 : 32;
    } else {
      output.bitDepth = reader.smallInteger("bit_depth", 8, 32);
    }
  }
  if (reader.has("alpha")) output.alpha = reader.boolean("alpha");
  if (reader.has("range")) {
    const json& range = reader.at("range");
    if (range == "auto") {
      output.rangeAuto = true;
    } else if (range.is_string()) {
      fail(where, "range " + range.dump() + " must be a positive number or \"auto\"");
    } else {
      output.range = reader.numberAtLeast("range", 0, true);
    }
  }
  if (reader.has("margin") && output.margin > 0 && output.padding == PaddingMode::kPushPull) {
    fail(where,
         "key 'margin' applies to padding \"extend\" and \"adjacent-faces\"; "
         "\"push-pull\" fills every texel outside the UV islands");
  }
  if (reader.has("green") && output.map != MapKind::kTangentNormal) {
    fail(where, "key 'green' applies only to tangent-normal maps");
  }
  if (reader.has("swizzle") && output.map != MapKind::kTangentNormal &&
      output.map != MapKind::kObjectNormal) {
    fail(where, "key 'swizzle' applies only to tangent-normal and object-normal maps");
  }
  if (reader.has("swizzle") && reader.has("green")) {
    fail(where,
         "give the green channel's direction either with 'green' or in 'swizzle' (its "
         "second axis: +Y OpenGL, -Y DirectX), not both");
  }
  if (reader.has("range") && !isSignedMap(output.map)) {
    fail(where, "key 'range' applies only to derivative and surface-gradient maps");
  }
  if (reader.has("range") && !inMemory && !output.storesSignedRange()) {
    fail(where,
         "key 'range' applies to integer files (PNG, 8- and 16-bit TIFF); this " +
             std::string(output.resolvedFormat() == ImageFormat::kExr ? "EXR" : "float TIFF") +
             " stores the values themselves");
  }
  return output;
}

Scene parseDocument(const json& document, const SceneParseOptions& options) {
  const ObjectReader top(document, "", "the scene");
  top.checkKeys(kTopKeys);
  const std::filesystem::path outputBase =
      options.outputDir.empty() ? options.baseDir : options.outputDir;

  Scene scene;
  if (options.inMemory) {
    if (top.has("mesh")) fail("", "key 'mesh' is not used in memory (the mesh is given as arrays)");
    scene.inMemory = true;
    scene.mesh = kInMemoryMeshName;
  } else {
    top.require("mesh");
    scene.mesh = pathValue(top, "mesh", InputPaths{options.baseDir});
  }
  const InputPaths inputPaths{options.baseDir, options.inMemory};
  if (top.has("uv")) scene.uvSet = top.smallInteger("uv", 0, kMaxUvSets - 1);
  if (top.has("subdivision")) scene.subdivision = parseSubdivision(top.at("subdivision"));
  if (top.has("transform")) scene.transform = parseTransform(top.at("transform"));

  if (top.has("layers")) {
    const json& layers = top.at("layers");
    if (!layers.is_array()) fail("", "'layers' must be an array, not " + describeType(layers));
    for (std::size_t i = 0; i < layers.size(); ++i) {
      scene.layers.push_back(
          parseLayer(layers[i], "layers[" + std::to_string(i) + "]", inputPaths, scene.uvSet));
    }
  }

  top.require("outputs");
  const json& outputs = top.at("outputs");
  if (!outputs.is_array()) fail("", "'outputs' must be an array, not " + describeType(outputs));
  if (outputs.empty()) fail("", "'outputs' is empty: nothing to bake");
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    scene.outputs.push_back(
        parseOutput(outputs[i], "outputs[" + std::to_string(i) + "]", outputBase, scene.uvSet,
                    options.inMemory));
  }
  return scene;
}

/// Parses JSON text, rejecting duplicate keys (nlohmann would keep the last silently).
json parseJson(std::string_view text) {
  std::vector<std::set<std::string>> keysPerObject;
  std::string duplicate;
  const json::parser_callback_t callback = [&](int /*depth*/, json::parse_event_t event,
                                               json& parsed) {
    switch (event) {
      case json::parse_event_t::object_start:
        keysPerObject.emplace_back();
        break;
      case json::parse_event_t::object_end:
        if (!keysPerObject.empty()) keysPerObject.pop_back();
        break;
      case json::parse_event_t::key:
        if (!keysPerObject.empty() &&
            !keysPerObject.back().insert(parsed.get<std::string>()).second && duplicate.empty()) {
          duplicate = parsed.get<std::string>();
        }
        break;
      default:
        break;
    }
    return true;
  };
  // nlohmann's parser takes a NUL byte for the end of the text: one anywhere is refused here,
  // so that nothing after it is ignored.
  if (const std::size_t nul = text.find('\0'); nul != std::string_view::npos) {
    const std::string_view before = text.substr(0, nul);
    const std::size_t line =
        1 + static_cast<std::size_t>(std::count(before.begin(), before.end(), '\n'));
    const std::size_t lineStart = before.rfind('\n');
    const std::size_t column = nul - (lineStart == std::string_view::npos ? 0 : lineStart + 1) + 1;
    fail("", "invalid JSON: a NUL byte at line " + std::to_string(line) + ", column " +
                 std::to_string(column) + " (JSON text holds none; write \\u0000 in a string)");
  }
  json document;
  try {
    document = json::parse(text.begin(), text.end(), callback);
  } catch (const json::exception& e) {
    // "[json.exception.parse_error.101] parse error at line 3, column 5: ..." → keep the part
    // after the bracketed id. (A number too large for a double, 1e400, is an out_of_range
    // error of the parse: bad input too.)
    std::string message = e.what();
    if (const std::size_t end = message.find("] "); end != std::string::npos) {
      message = message.substr(end + 2);
    }
    fail("", "invalid JSON: " + message);
  }
  if (!duplicate.empty()) fail("", "duplicate key " + quote(duplicate));
  return document;
}

// ---- Value checks shared by parseScene and validateScene ---------------------------------------

/// Why @p value is not finite, or "".
std::string checkFinite(std::string_view name, double value) {
  return std::isfinite(value) ? std::string() : std::string(name) + " must be a finite number";
}

std::string checkLayer(const SceneLayer& layer, bool inMemory) {
  for (const auto& [name, value] : {std::pair<const char*, double>{"weight", layer.weight},
                                    {"scale", layer.scale},
                                    {"tiling", layer.tiling.x},
                                    {"tiling", layer.tiling.y},
                                    {"offset", layer.offset.x},
                                    {"offset", layer.offset.y},
                                    {"amplitude", layer.amplitude},
                                    {"frequency", layer.frequency},
                                    {"phase", layer.phase}}) {
    if (std::string why = checkFinite(name, value); !why.empty()) return why;
  }
  if (layer.hasImage() && layer.image.empty()) return "missing key 'image'";
  if (layer.uvSet < 0 || layer.uvSet >= kMaxUvSets) {
    return rangeMessage("uv", layer.uvSet, 0, kMaxUvSets - 1);
  }
  if (!(layer.sharpness >= 0) || !std::isfinite(layer.sharpness)) {
    return "sharpness must be a finite number >= 0";
  }
  if (!(layer.boxBlend >= 0 && layer.boxBlend <= 1)) {
    return "box_blend must be a number from 0 to 1 (Blender's Blend)";
  }
  if (layer.type == SceneLayerType::kPlanar && isSingleLookup(layer.projection) &&
      layer.axis != ProjectionAxis::kZ) {
    switch (layer.projection) {
      case TriplanarProjection::kSphere:
        return "'projection': 'sphere' wraps the image around the z axis, as Blender's Sphere "
               "projection does: 'axis' must be z";
      case TriplanarProjection::kTube:
        return "'projection': 'tube' wraps the image around the z axis, as Blender's Tube "
               "projection does: 'axis' must be z";
      default:
        return "'projection': 'flat' reads the (x, y) plane, as Blender's Flat projection does: "
               "'axis' must be z";
    }
  }
  if (layer.tangentUvSet && !layer.decodesInUvTangentFrames()) {
    return "key 'tangent_uv' applies only to tangent-space normal maps (normal layers, and "
           "projected ones with 'projection': 'box', 'flat', 'sphere' or 'tube')";
  }
  if (layer.step && !(*layer.step > 0 && std::isfinite(*layer.step))) {
    return "step must be a finite number > 0";
  }
  if (!layer.remap.empty()) {
    if (layer.readsNormals()) return "key 'remap' applies only to heights";
    if (Result<HeightRemap> remap = HeightRemap::create(layer.remap); !remap) {
      return "'remap': " + remap.error().message;
    }
  }
  if (layer.type != SceneLayerType::kVolume && layer.coordinates != VolumeCoordinates::kObject) {
    return "key 'coordinates' applies only to volumes";
  }
  if (layer.coordinates == VolumeCoordinates::kUv && layer.gradient != GradientScheme::kAnalytic) {
    return "a volume on UV coordinates takes its slopes 'analytic' or 'bump-node' (no finite "
           "differences)";
  }
  if (layer.type == SceneLayerType::kVolume && layer.function == VolumeFunction::kNoise) {
    if (!(layer.frequency > 0)) return "frequency must be greater than 0";
    if (layer.octaves < 1 || layer.octaves > kMaxNoiseOctaves) {
      return rangeMessage("octaves", layer.octaves, 1, kMaxNoiseOctaves);
    }
  }
  if (layer.mask && layer.mask->image.empty()) return "mask has no image";
  // UDIM images: tile 1001 + u + 10·v is read where the layer's UV set lies in [u, u+1)×[v, v+1).
  const auto udimProblem = [&](const std::filesystem::path& image, const char* what, Vec2d tiling,
                               Vec2d offset) -> std::string {
    if (!hasUdimToken(image.string())) return {};
    const std::string name = std::string(what) + " '" + image.string() + "'";
    if (!inMemory && hasUdimToken(image.parent_path().string())) {
      return name + ": " + std::string(kUdimToken) + " must be in the file name, not a directory";
    }
    if (tiling != Vec2d{1, 1} || offset != Vec2d{0, 0}) {
      return name +
             " is a UDIM image: its tiles lie where the UVs do, so tiling and offset "
             "cannot apply";
    }
    return {};
  };
  if (layer.hasImage()) {
    const bool uvLayer =
        layer.type == SceneLayerType::kHeight || layer.type == SceneLayerType::kNormal;
    if (!uvLayer && hasUdimToken(layer.image.string())) {
      return "image '" + layer.image.string() + "': " + std::string(kUdimToken) +
             " images are for UV layers (height, normal), not projections";
    }
    if (std::string why = udimProblem(layer.image, "image", layer.tiling, layer.offset);
        !why.empty()) {
      return why;
    }
  }
  if (layer.mask) {
    if (std::string why =
            udimProblem(layer.mask->image, "mask", layer.mask->tiling, layer.mask->offset);
        !why.empty()) {
      return why;
    }
  }
  return {};
}

std::string checkOutput(const SceneOutput& output, bool inMemory) {
  if (output.file.empty() && !inMemory) return "missing key 'file'";
  if (!inMemory && output.file.filename() == kManifestName) {
    return "file '" + output.file.string() +
           "' has the name of the manifest sgbake keeps beside its outputs";
  }
  if (!inMemory && hasUdimToken(output.file.parent_path().string())) {
    return "file '" + output.file.string() + "': " + std::string(kUdimToken) +
           " goes in the file's name, not in a directory (every tile's file, and the manifest, "
           "are in one directory)";
  }
  if (output.kind == OutputKind::kCorners) {
    if (inMemory) return {};
    if (toLowerAscii(output.file.extension().string()) != ".csv") {
      return "file '" + output.file.string() +
             "': the corners map is a CSV table, its file must end in .csv";
    }
    if (hasUdimToken(output.file.string())) {
      return "file '" + output.file.string() +
             "': the corners map is one table for the whole mesh, its file cannot hold " +
             std::string(kUdimToken);
    }
    return {};
  }
  if (output.width == output.height && (output.width < 1 || output.width > kMaxBakeSide)) {
    return rangeMessage("size", output.width, 1, kMaxBakeSide);
  }
  if (output.width < 1 || output.width > kMaxBakeSide) {
    return rangeMessage("width", output.width, 1, kMaxBakeSide);
  }
  if (output.height < 1 || output.height > kMaxBakeSide) {
    return rangeMessage("height", output.height, 1, kMaxBakeSide);
  }
  if (output.margin < 0 || output.margin > kMaxBakeSide) {
    return rangeMessage("margin", output.margin, 0, kMaxBakeSide);
  }
  if (!(output.range > 0) || !std::isfinite(output.range)) {
    return "range must be a positive number";
  }
  if (output.samples < 1 || output.samples > kMaxBakeSamples) {
    return rangeMessage("samples", output.samples, 1, kMaxBakeSamples);
  }
  if (output.uvSet < 0 || output.uvSet >= kMaxUvSets) {
    return rangeMessage("uv", output.uvSet, 0, kMaxUvSets - 1);
  }
  if (!inMemory && hasUdimToken(output.file.string()) && output.tile != kFirstUdimTile) {
    return "key 'tile' applies only to a file without " + std::string(kUdimToken) +
           " (which bakes every tile the UV set touches)";
  }
  if (output.tile < kFirstUdimTile || output.tile > kLastUdimTile) {
    return rangeMessage("tile", output.tile, kFirstUdimTile, kLastUdimTile);
  }
  if (inMemory) return {};  // no file: no format, no bit depth
  ImageFormat format = output.format;
  Result<ImageFormat> fromPath = imageFormatFromPath(output.file);
  if (format == ImageFormat::kAuto) {
    if (!fromPath) return fromPath.error().message;
    format = *fromPath;
  } else if (fromPath && *fromPath != format) {  // "format" is for names without a known one
    return "format '" + std::string(imageFormatName(format)) + "' contradicts the extension of '" +
           output.file.string() + "' (" + std::string(imageFormatName(*fromPath)) + ")";
  }
  const int depth = output.resolvedBitDepth();
  if (!formatSupportsBitDepth(format, depth)) {
    std::string name(imageFormatName(format));
    for (char& c : name) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    return "bit_depth " + std::to_string(depth) + " is not available in " + name +
           (format == ImageFormat::kExr   ? " (16 = half or 32 = float)"
            : format == ImageFormat::kPng ? " (8 or 16)"
                                          : " (8, 16 or 32)");
  }
  return {};
}

/// Levenshtein distance, case-insensitive.
std::size_t editDistance(std::string_view a, std::string_view b) {
  const auto lower = [](char c) { return std::tolower(static_cast<unsigned char>(c)); };
  std::vector<std::size_t> previous(b.size() + 1);
  std::vector<std::size_t> current(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) previous[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    current[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t substitute = previous[j - 1] + (lower(a[i - 1]) == lower(b[j - 1]) ? 0 : 1);
      current[j] = std::min({previous[j] + 1, current[j - 1] + 1, substitute});
    }
    std::swap(previous, current);
  }
  return previous[b.size()];
}

}  // namespace

// ---- Public API --------------------------------------------------------------------------------

Result<PaddingMode> parsePaddingMode(std::string_view name) {
  for (const Named<PaddingMode>& entry : kPaddings) {
    if (entry.name == name) return entry.value;
  }
  return Error::badInput("unknown padding '" + std::string(name) + "'");
}

std::string_view sceneLayerTypeName(SceneLayerType type) {
  for (const Named<SceneLayerType>& entry : kLayerTypes) {
    if (entry.value == type) return entry.name;
  }
  return "layer";
}

bool SceneLayer::readsNormals() const {
  switch (type) {
    case SceneLayerType::kNormal:
      return true;
    case SceneLayerType::kPlanar:
    case SceneLayerType::kTriplanar:
      return kind != ProjectedKind::kHeight;
    case SceneLayerType::kHeight:
    case SceneLayerType::kVolume:
      break;
  }
  return false;
}

bool SceneLayer::decodesInUvTangentFrames() const {
  if (type == SceneLayerType::kNormal) return space == NormalSpace::kTangent;
  return projectedByBlender() && kind == ProjectedKind::kTangentNormal;
}

bool SceneLayer::projectedByBlender() const {
  return (type == SceneLayerType::kTriplanar && projection == TriplanarProjection::kBox) ||
         (type == SceneLayerType::kPlanar && isSingleLookup(projection));
}

bool SceneLayer::hasHeight() const {
  return type == SceneLayerType::kHeight || type == SceneLayerType::kVolume ||
         (projected() && kind == ProjectedKind::kHeight);
}

bool SceneLayer::projected() const {
  return type == SceneLayerType::kPlanar || type == SceneLayerType::kTriplanar;
}

ImageFormat SceneOutput::resolvedFormat() const {
  if (format != ImageFormat::kAuto) return format;
  Result<ImageFormat> fromPath = imageFormatFromPath(file);
  return fromPath ? *fromPath : ImageFormat::kAuto;
}

int SceneOutput::resolvedBitDepth() const {
  return bitDepth != 0 ? bitDepth : defaultBitDepth(resolvedFormat(), map);
}

bool SceneOutput::storesSignedRange() const {
  if (kind != OutputKind::kMap || !isSignedMap(map)) return false;
  const ImageFormat f = resolvedFormat();
  return f == ImageFormat::kPng || (f == ImageFormat::kTiff && resolvedBitDepth() != 32);
}

std::string_view filterName(Filter filter) {
  for (const Named<Filter>& entry : kFilters) {
    if (entry.value == filter) return entry.name;
  }
  return "?";
}

std::filesystem::path canonicalPath(const std::filesystem::path& path) {
  std::error_code ec;
  // Absolute first: weakly_canonical leaves a relative path relative when none of it exists
  // (a bare "h_<UDIM>.png"), and it would then not compare equal to its tiles' paths.
  const std::filesystem::path absolute = std::filesystem::absolute(path, ec);
  if (ec) return path.lexically_normal();
  std::filesystem::path canonical = std::filesystem::weakly_canonical(absolute, ec);
  return ec ? absolute.lexically_normal() : canonical;
}

namespace {

/// The canonical paths of the files a path names (itself, or each of its UDIM tiles), sorted;
/// each path's list is made once.
class NamedFiles {
 public:
  const std::vector<std::filesystem::path>& of(const std::filesystem::path& path) {
    const std::string text = path.string();
    if (const auto it = named_.find(text); it != named_.end()) return it->second;
    std::vector<std::filesystem::path> files;
    if (!hasUdimToken(text)) {
      files.push_back(canonicalPath(path));
    } else if (!hasUdimToken(path.parent_path().string())) {
      // The token in the name: the directory is made canonical once, and only the tiles that
      // are links need resolving (one lstat each, not a canonicalPath per tile).
      const std::filesystem::path dir = canonicalPath(path).parent_path();
      const std::string name = path.filename().string();
      for (int tile = kFirstUdimTile; tile <= kLastUdimTile; ++tile) {
        std::filesystem::path file = dir / expandUdimToken(name, tile);
        // A link, even one to a file not there yet (an output's): where it points.
        std::error_code ec;
        for (int hops = 0; hops < 8 && std::filesystem::is_symlink(file, ec); ++hops) {
          const std::filesystem::path target = std::filesystem::read_symlink(file, ec);
          if (ec) break;
          file = canonicalPath(file.parent_path() / target);
        }
        files.push_back(std::move(file));
      }
    } else {
      for (int tile = kFirstUdimTile; tile <= kLastUdimTile; ++tile) {
        files.push_back(canonicalPath(expandUdimToken(text, tile)));
      }
    }
    std::sort(files.begin(), files.end());
    return named_.emplace(text, std::move(files)).first->second;
  }

  /// Whether @p a and @p b name a file in common.
  bool share(const std::filesystem::path& a, const std::filesystem::path& b) {
    const std::vector<std::filesystem::path>& as = of(a);
    const std::vector<std::filesystem::path>& bs = of(b);
    for (auto i = as.begin(), j = bs.begin(); i != as.end() && j != bs.end();) {
      if (*i == *j) return true;
      if (*i < *j) {
        ++i;
      } else {
        ++j;
      }
    }
    return false;
  }

 private:
  std::map<std::string, std::vector<std::filesystem::path>> named_;
};

}  // namespace

bool mayBeSameFile(const std::filesystem::path& a, const std::filesystem::path& b) {
  // Every file each names, canonical (links resolved as far as they exist): two UDIM names
  // may share a file under different tile numbers (x<UDIM>1.png and x1<UDIM>.png both name
  // x11001.png), and a tile may be a link to the other's file.
  return NamedFiles().share(a, b);
}

std::string describeLayer(const SceneLayer& layer) {
  std::string text;
  switch (layer.type) {
    case SceneLayerType::kHeight:
      text = "height image " + layer.image.string();
      break;
    case SceneLayerType::kNormal:
      text = std::string(layer.space == NormalSpace::kTangent ? "tangent" : "object") +
             "-space normal map " + layer.image.string();
      break;
    case SceneLayerType::kVolume:
      text = "volume " + nameIn(kFunctions, layer.function);
      if (layer.textureDimensions != 3)
        text += " " + nameIn(kTextureDimensions, layer.textureDimensions);
      if (layer.coordinates == VolumeCoordinates::kUv) {
        text += " on UV set " + std::to_string(layer.uvSet) + "'s coordinates";
      }
      break;
    case SceneLayerType::kPlanar:
    case SceneLayerType::kTriplanar:
      text = std::string(sceneLayerTypeName(layer.type)) + " " + nameIn(kKinds, layer.kind) + " " +
             layer.image.string();
      break;
  }
  return layer.name.empty() ? text : "'" + layer.name + "', " + text;
}

/// A Noise or Musgrave Texture's Dimensions and W, written only when not 3D (so the manifests
/// of scenes before them stay valid).
void writeTextureDimensions(const SceneLayer& layer, json& j) {
  if (layer.textureDimensions == 3) return;
  j["dimensions"] = nameIn(kTextureDimensions, layer.textureDimensions);
  if (readsW(layer.textureDimensions)) j["w"] = layer.textureW;
}

std::string layerParametersJson(const SceneLayer& layer, const PathNamer& namer) {
  const auto name = [&namer](const std::filesystem::path& path) {
    return namer ? namer(path) : canonicalPath(path).string();
  };
  json j;
  j["type"] = sceneLayerTypeName(layer.type);
  j["weight"] = layer.weight;
  if (layer.base != LayerBase::kSurface) j["base"] = nameIn(kBases, layer.base);
  if (layer.objectSpaceHeight) j["height_space"] = "object";
  if (layer.material) j["material"] = *layer.material;
  if (layer.materialName) j["material"] = *layer.materialName;
  if (layer.mask) {
    j["mask"] = {{"image", name(layer.mask->image)},
                 {"uv", layer.mask->uvSet},
                 {"tiling", {layer.mask->tiling.x, layer.mask->tiling.y}},
                 {"offset", {layer.mask->offset.x, layer.mask->offset.y}},
                 {"filter", filterName(layer.mask->filter)}};
  }
  if (layer.hasImage()) {
    j["image"] = name(layer.image);
    j["filter"] = filterName(layer.filter);
    j["wrap"] = nameIn(kWraps, layer.wrap);
    j["tiling"] = {layer.tiling.x, layer.tiling.y};
    j["offset"] = {layer.offset.x, layer.offset.y};
    j["scale"] = layer.scale;
  }
  const bool tangentNormals =
      (layer.type == SceneLayerType::kNormal && layer.space == NormalSpace::kTangent) ||
      (layer.projected() && layer.kind == ProjectedKind::kTangentNormal);
  if (tangentNormals) j["green"] = nameIn(kGreens, layer.green);
  if (layer.tangentUvSet) j["tangent_uv"] = *layer.tangentUvSet;
  if (layer.decodesInUvTangentFrames() && layer.projected()) j["uv"] = layer.uvSet;
  // A height's Bump Strength (written always for UV heights, as before; else when not 1).
  if (layer.type == SceneLayerType::kHeight || (layer.hasHeight() && layer.strength != 1))
    j["strength"] = layer.strength;
  if (!layer.remap.empty()) {
    json points = json::array();
    for (const Vec2d& p : layer.remap) points.push_back({p.x, p.y});
    j["remap"] = std::move(points);
  }
  switch (layer.type) {
    case SceneLayerType::kHeight:
      j["uv"] = layer.uvSet;
      if (layer.channel != ImageChannels::kLuminance)
        j["channel"] = nameIn(kChannels, layer.channel);
      if (layer.heightGradient != HeightGradient::kAnalytic)
        j["gradient"] = nameIn(kHeightGradients, layer.heightGradient);
      break;
    case SceneLayerType::kNormal:
      j["uv"] = layer.uvSet;
      j["space"] = nameIn(kSpaces, layer.space);
      break;
    case SceneLayerType::kVolume:
      j["function"] = nameIn(kFunctions, layer.function);
      j["amplitude"] = layer.amplitude;
      // (the Gradient Texture has no Scale)
      if (layer.function != VolumeFunction::kBlenderGradient) j["frequency"] = layer.frequency;
      if (layer.function == VolumeFunction::kSine) {
        j["direction"] = {layer.direction.x, layer.direction.y, layer.direction.z};
        j["phase"] = layer.phase;
      } else if (layer.function == VolumeFunction::kNoise) {
        j["seed"] = layer.seed;
        j["octaves"] = layer.octaves;
      } else if (layer.function == VolumeFunction::kBlenderNoise) {
        j["detail"] = layer.noiseDetail;
        j["roughness"] = layer.noiseRoughness;
        j["distortion"] = layer.noiseDistortion;
        writeTextureDimensions(layer, j);
      } else if (layer.function == VolumeFunction::kBlenderMusgrave) {
        writeTextureDimensions(layer, j);
        j["detail"] = layer.noiseDetail;
        j["dimension"] = layer.noiseDimension;
        j["lacunarity"] = layer.noiseLacunarity;
        const MusgraveType type = layer.musgraveType;
        // (no "musgrave_type" key for fBM: the manifests of scenes before it stay valid)
        if (type != MusgraveType::kFbm) j["musgrave_type"] = nameIn(kMusgraveTypes, type);
        if (type != MusgraveType::kFbm && type != MusgraveType::kMultifractal) {
          j["offset"] = layer.musgraveOffset;
        }
        if (type == MusgraveType::kRidgedMultifractal ||
            type == MusgraveType::kHybridMultifractal) {
          j["gain"] = layer.musgraveGain;
        }
      } else if (layer.function == VolumeFunction::kBlenderBrick) {
        const BlenderBrickParams& b = layer.brick;
        j["mortar_size"] = b.mortarSize;
        j["mortar_smooth"] = b.mortarSmooth;
        j["brick_width"] = b.brickWidth;
        j["row_height"] = b.rowHeight;
        j["brick_offset"] = b.offset;
        j["offset_frequency"] = b.offsetFrequency;
        j["squash"] = b.squash;
        j["squash_frequency"] = b.squashFrequency;
      } else if (layer.function == VolumeFunction::kBlenderGradient) {
        j["gradient_type"] = nameIn(kGradientTypes, layer.gradientType);
      } else if (layer.function == VolumeFunction::kBlenderMagic) {
        j["depth"] = layer.magicDepth;
        j["distortion"] = layer.noiseDistortion;
      } else if (layer.function == VolumeFunction::kBlenderVoronoi) {
        j["randomness"] = layer.voronoiRandomness;
        j["metric"] = nameIn(kVoronoiMetrics, layer.voronoiMetric);
        j["exponent"] = layer.voronoiExponent;
        // (no "feature" key for F1: the manifests of scenes before it stay valid)
        const VoronoiFeature feature = layer.voronoiFeature;
        if (feature != VoronoiFeature::kF1) j["feature"] = nameIn(kVoronoiFeatures, feature);
        if (feature == VoronoiFeature::kSmoothF1) j["smoothness"] = layer.voronoiSmoothness;
      } else {
        j["wave"] = nameIn(kWaveTypes, layer.waveType);
        j["wave_direction"] = nameIn(kWaveDirections, layer.waveDirection);
        j["profile"] = nameIn(kWaveProfiles, layer.waveProfile);
        j["phase"] = layer.phase;
        j["distortion"] = layer.noiseDistortion;
        j["detail"] = layer.noiseDetail;
        j["detail_scale"] = layer.noiseDetailScale;
        j["detail_roughness"] = layer.noiseDetailRoughness;
      }
      j["gradient"] = layer.heightGradient == HeightGradient::kBumpNode
                          ? nameIn(kHeightGradients, layer.heightGradient)
                          : nameIn(kSchemes, layer.gradient);
      j["step"] = layer.step ? json(*layer.step) : json("default");
      // (no "coordinates" key on object coordinates: the manifests of scenes before it stay
      // valid)
      if (layer.coordinates == VolumeCoordinates::kUv) {
        j["coordinates"] = nameIn(kVolumeCoordinates, layer.coordinates);
        j["uv"] = layer.uvSet;
      }
      break;
    case SceneLayerType::kPlanar:
      j["kind"] = nameIn(kKinds, layer.kind);
      j["axis"] = nameIn(kAxes, layer.axis);
      if (layer.projection != TriplanarProjection::kBlended)
        j["projection"] = nameIn(kPlanarProjections, layer.projection);
      break;
    case SceneLayerType::kTriplanar:
      j["kind"] = nameIn(kKinds, layer.kind);
      if (layer.projection == TriplanarProjection::kBox) {
        j["projection"] = nameIn(kProjections, layer.projection);
        j["box_blend"] = layer.boxBlend;
      } else {  // (no "projection" key: the manifests of scenes before it stay valid)
        j["sharpness"] = layer.sharpness;
        j["min_weight"] = layer.minWeight;
      }
      break;
  }
  if (layer.mapping) {
    const auto triple = [](const Vec3d& v) { return json::array({v.x, v.y, v.z}); };
    j["mapping"] = {{"location", triple(layer.mapping->location)},
                    {"rotation", triple(layer.mapping->rotation)},
                    {"scale", triple(layer.mapping->scale)}};
    if (layer.mapping->type != MappingType::kPoint) {
      j["mapping"]["type"] = nameIn(kMappingTypes, layer.mapping->type);
    }
    if (const std::optional<Mat3>& a = layer.mapping->matrix) {
      const Vec3d& t = layer.mapping->matrixTranslation;
      j["mapping"]["matrix"] = {{(*a)(0, 0), (*a)(0, 1), (*a)(0, 2), t.x},
                                {(*a)(1, 0), (*a)(1, 1), (*a)(1, 2), t.y},
                                {(*a)(2, 0), (*a)(2, 1), (*a)(2, 2), t.z}};
    }
  }
  if (layer.heightGradient != HeightGradient::kAnalytic && layer.projected()) {
    j["gradient"] = nameIn(kHeightGradients, layer.heightGradient);
  }
  return j.dump();
}

std::string outputParametersJson(const SceneOutput& output) {
  json j;
  if (output.kind == OutputKind::kCorners) {
    j["map"] = "corners";
    return j.dump();
  }
  j["map"] = mapKindName(output.map);
  j["width"] = output.width;
  j["height"] = output.height;
  j["samples"] = output.samples;
  j["uv"] = output.uvSet;
  j["margin"] = output.margin;
  j["padding"] = nameIn(kPaddings, output.padding);
  if (output.map == MapKind::kTangentNormal) j["green"] = nameIn(kGreens, output.green);
  if (output.swizzle != kIdentitySwizzle) j["swizzle"] = normalSwizzleName(output.swizzle);
  if (!hasUdimToken(output.file.string())) j["tile"] = output.tile;
  j["format"] = imageFormatName(output.resolvedFormat());
  j["bit_depth"] = output.resolvedBitDepth();
  j["alpha"] = output.alpha;
  if (output.storesSignedRange()) {
    j["range"] = output.rangeAuto ? json("auto") : json(output.range);
  }
  return j.dump();
}

std::string describeAutoSmooth(const SceneSubdivision& subdivision) {
  std::ostringstream text;
  text << *subdivision.autoSmoothDegrees << " deg";
  if (!subdivision.sharpEdges.empty()) {
    text << " and " << subdivision.sharpEdges.size() << " sharp edge(s)";
  }
  return text.str();
}

std::string describeSubdivision(const SceneSubdivision& subdivision) {
  const std::string level = subdivision.limit ? std::string("the limit surface")
                                              : "level " + std::to_string(subdivision.level);
  std::string creases;
  if (!subdivision.edgeCreases.empty() || !subdivision.vertexCreases.empty()) {
    creases = ", " + std::to_string(subdivision.edgeCreases.size()) + " edge and " +
              std::to_string(subdivision.vertexCreases.size()) + " vertex crease(s)" +
              (subdivision.useCreases ? "" : ", not used");
  }
  const std::string quality =
      subdivision.quality == SubdivisionOptions{}.quality
          ? std::string()
          : ", quality " + std::to_string(subdivision.quality);
  const std::string refinement =
      std::string(subdivision.useLimitSurface ? "" : ", without the limit surface") +
      (subdivision.type == SubdivisionType::kSimple ? ", simple" : "");
  const std::string autoSmooth = subdivision.autoSmoothDegrees
                                     ? ", auto smooth " + describeAutoSmooth(subdivision)
                                     : std::string();
  return "to " + level + " (uv_smooth " + nameIn(kUvSmooths, subdivision.uvSmooth) + ", boundary " +
         nameIn(kBoundaries, subdivision.boundary) + creases + quality + refinement + autoSmooth +
         ")";
}

std::string subdivisionParametersJson(const SceneSubdivision& subdivision) {
  // A block that changes nothing ("level": 0 alone, a script's copy of an unused modifier) is
  // the same bake as no block: the manifest must not re-bake for it.
  if (!subdivision.requested()) return "null";
  json j;
  j["level"] = subdivision.limit ? json("limit") : json(subdivision.level);
  j["uv_smooth"] = nameIn(kUvSmooths, subdivision.uvSmooth);
  j["boundary"] = nameIn(kBoundaries, subdivision.boundary);
  // Creases only when there are any, so that the text (and the manifest hash) of a scene
  // without creases stays what it was before creases were read.
  if (!subdivision.edgeCreases.empty() || !subdivision.vertexCreases.empty()) {
    j["use_creases"] = subdivision.useCreases;
    json edges = json::array(), vertices = json::array();
    for (const EdgeCrease& e : subdivision.edgeCreases) edges.push_back({e.v0, e.v1, e.crease});
    for (const VertexCrease& v : subdivision.vertexCreases)
      vertices.push_back({v.vertex, v.crease});
    j["edge_creases"] = std::move(edges);
    j["vertex_creases"] = std::move(vertices);
  }
  // Likewise the quality, unless it is not the default.
  if (subdivision.quality != SubdivisionOptions{}.quality) j["quality"] = subdivision.quality;
  if (!subdivision.useLimitSurface) j["use_limit_surface"] = false;
  if (subdivision.type != SubdivisionType::kCatmullClark) {
    j["type"] = nameIn(kSubdivisionTypeNames, subdivision.type);
  }
  if (subdivision.autoSmoothDegrees) j["auto_smooth"] = *subdivision.autoSmoothDegrees;
  if (!subdivision.sharpEdges.empty()) {
    json edges = json::array();
    for (const SharpEdge& e : subdivision.sharpEdges) edges.push_back({e.v0, e.v1});
    j["sharp_edges"] = std::move(edges);
  }
  return j.dump();
}

std::string closestMatch(std::string_view word, const std::vector<std::string>& candidates) {
  std::string best;
  std::size_t bestDistance = std::numeric_limits<std::size_t>::max();
  for (const std::string& candidate : candidates) {
    const std::size_t d = editDistance(word, candidate);
    if (d < bestDistance) {
      bestDistance = d;
      best = candidate;
    }
  }
  const std::size_t limit = std::min<std::size_t>(2, (word.size() + 1) / 2);
  return bestDistance <= limit ? best : std::string();
}

namespace {

/// The files a scene reads, each with how messages name it.
std::vector<std::pair<std::filesystem::path, std::string>> sceneInputs(const Scene& scene) {
  std::vector<std::pair<std::filesystem::path, std::string>> inputs;
  if (!scene.source.empty()) inputs.emplace_back(scene.source, "the scene file");
  inputs.emplace_back(scene.mesh, "the mesh");
  for (std::size_t k = 0; k < scene.layers.size(); ++k) {
    const SceneLayer& layer = scene.layers[k];
    const std::string name = "layers[" + std::to_string(k) + "]";
    if (!layer.image.empty()) inputs.emplace_back(layer.image, "the image of " + name);
    if (layer.mask) inputs.emplace_back(layer.mask->image, "the mask of " + name);
  }
  return inputs;
}

}  // namespace

Status validateScene(const Scene& scene) {
  const auto where = [](const char* list, std::size_t i) {
    return std::string(list) + "[" + std::to_string(i) + "]: ";
  };
  if (scene.mesh.empty()) return Error::badInput("missing key 'mesh'");
  if (scene.uvSet < 0 || scene.uvSet >= kMaxUvSets) {
    return Error::badInput(rangeMessage("uv", scene.uvSet, 0, kMaxUvSets - 1));
  }
  for (std::size_t i = 0; i < scene.layers.size(); ++i) {
    if (std::string why = checkLayer(scene.layers[i], scene.inMemory); !why.empty()) {
      return Error::badInput(where("layers", i) + why);
    }
  }
  if (scene.outputs.empty()) return Error::badInput("'outputs' is empty: nothing to bake");
  NamedFiles named;  // each path's files found once
  for (std::size_t i = 0; i < scene.outputs.size(); ++i) {
    if (std::string why = checkOutput(scene.outputs[i], scene.inMemory); !why.empty()) {
      return Error::badInput(where("outputs", i) + why);
    }
    if (scene.inMemory) continue;
    const std::filesystem::path& file = scene.outputs[i].file;
    for (std::size_t j = 0; j < i; ++j) {
      if (named.share(scene.outputs[j].file, file)) {
        return Error::badInput(where("outputs", i) + "file '" + file.string() +
                               "' is also written by outputs[" + std::to_string(j) + "]");
      }
    }
    for (const auto& [input, what] : sceneInputs(scene)) {
      if (named.share(file, input)) {
        return Error::badInput(where("outputs", i) + "file '" + file.string() + "' is " + what +
                               ", which the bake reads (write it elsewhere)");
      }
    }
  }
  return Ok{};
}

Result<Scene> parseScene(std::string_view text, const SceneParseOptions& options) {
  const std::string prefix = options.name + ": ";
  try {
    Scene scene = parseDocument(parseJson(text), options);
    if (Status valid = validateScene(scene); !valid) {
      return Error::badInput(prefix + valid.error().message);
    }
    return scene;
  } catch (const SceneFailure& failure) {
    return Error::badInput(prefix + (failure.where.empty() ? "" : failure.where + ": ") +
                           failure.what);
  } catch (const json::exception& e) {
    // Every access above checks types first; this is a bug, not bad input.
    return Error::internal(prefix + "unexpected JSON error: " + e.what());
  }
}

Result<Scene> loadScene(const std::filesystem::path& path, const std::filesystem::path& outputDir) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) {
    return Error::badInput(path.string() + ": cannot open scene (no such file)");
  }
  if (std::filesystem::is_directory(path, ec)) {
    return Error::badInput(path.string() + ": cannot read scene (it is a directory)");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) return Error::badInput(path.string() + ": cannot open scene (permission denied?)");
  const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  if (in.bad()) return Error::badInput(path.string() + ": cannot read scene");

  SceneParseOptions options;
  options.baseDir = path.parent_path();
  options.outputDir = outputDir;
  options.name = path.string();
  Result<Scene> scene = parseScene(text, options);
  if (scene) scene->source = path;
  return scene;
}

}  // namespace sgbake
