/// @file planner.cpp
/// @brief Planning a scene, explaining the plan, the manifest, and running the plan (see
/// planner.hpp).
#include "sgbake/bake/planner.hpp"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <future>
#include <iterator>
#include <limits>
#include <map>
#include <memory>
#include <new>
#include <set>
#include <span>
#include <string>
#include <system_error>
#include <tuple>
#include <utility>

#include <nlohmann/json.hpp>

#include "bake/prepare.hpp"
#include "bake/raster.hpp"
#include "sgbake/bake/bake.hpp"
#include "sgbake/bake/image_output.hpp"
#include "sgbake/frames/tangents.hpp"
#include "sgbake/gradient/corners.hpp"
#include "sgbake/gradient/filters.hpp"
#include "sgbake/gradient/layers.hpp"
#include "sgbake/gradient/volume.hpp"
#include "sgbake/io/atomic_file.hpp"
#include "sgbake/io/image_io.hpp"
#include "sgbake/mesh/io.hpp"
#include "sgbake/sgbake.h"
#include "sgbake/subdiv/limit_surface.hpp"

namespace sgbake {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

/// Version of the manifest's layout ("sgbake_manifest": 1).
constexpr int kManifestVersion = 1;

using plan_detail::layerLabel;
using plan_detail::outputLabel;
using plan_detail::scenePrefix;
using plan_detail::secondsSince;

/// The directory that holds @p file ("." for a bare name).
fs::path directoryOf(const fs::path& file) {
  const fs::path dir = file.parent_path();
  return dir.empty() ? fs::path(".") : dir;
}

/// Why @p output does not read @p layer, or "" when it does.
std::string whyNotRead(const SceneOutput& output, const SceneLayer& layer) {
  if (layer.weight == 0) return "weight 0";
  if (output.kind == OutputKind::kCorners) return {};
  switch (output.map) {
    case MapKind::kTangent:
    case MapKind::kBitangent:
    case MapKind::kMask:
      return std::string(mapKindName(output.map)) + " maps read no layers";
    case MapKind::kHeight:
      if (!layer.hasHeight())
        return "height maps read only layers with a height (normal maps have none)";
      break;
    default:
      break;
  }
  return {};
}

/// Whether a layer read by a baked map needs MikkTSpace frames: a tangent-space normal map on
/// UV set 0 is decoded in them (TangentFrameChoice::kAuto).
bool layerNeedsTangents(const SceneLayer& layer) { return layer.decodesInUvTangentFrames(); }

std::string describeOutput(const SceneOutput& output) {
  if (output.kind == OutputKind::kCorners) return "the corner table " + output.file.string();
  return "the " + std::string(mapKindName(output.map)) + " map " + output.file.string();
}

// ---- Manifest ----------------------------------------------------------------------------------

/// A manifest as read from disk.
struct ReadManifest {
  json content = json::object();  ///< the manifest, or an empty object
  std::string problem;            ///< why a file at the path was not used; empty when it was
};

/// Whether @p value nests arrays and objects more than @p limit deep (iteratively: a value
/// too deep for recursion is what this guards against).
bool nestsDeeperThan(const json& value, int limit) {
  std::vector<std::pair<const json*, int>> pending{{&value, 0}};
  while (!pending.empty()) {
    const auto [node, depth] = pending.back();
    pending.pop_back();
    if (!node->is_structured()) continue;
    if (depth >= limit) return true;
    for (const json& child : *node) pending.emplace_back(&child, depth + 1);
  }
  return false;
}

/// Whether @p entry is an output's entry as recordInManifests writes it: "parameters" (an
/// object, a few levels deep), "inputs" and "files" (objects of strings), and "udim_reached"
/// (tile numbers) and "input_tiles" (input name → tile number) when the output reads a UDIM
/// image.
bool isManifestEntry(const json& entry) {
  if (!entry.is_object()) return false;
  const auto parameters = entry.find("parameters");
  if (parameters == entry.end() || !parameters->is_object() || nestsDeeperThan(*parameters, 16)) {
    return false;
  }
  for (const char* key : {"inputs", "files"}) {
    const auto strings = entry.find(key);
    if (strings == entry.end() || !strings->is_object()) return false;
    for (const json& value : *strings) {
      if (!value.is_string()) return false;
    }
  }
  if (const auto reached = entry.find("udim_reached"); reached != entry.end()) {
    if (!reached->is_array()) return false;
    for (const json& tile : *reached) {
      if (!tile.is_number_integer()) return false;
    }
  }
  if (const auto tiles = entry.find("input_tiles"); tiles != entry.end()) {
    if (!tiles->is_object()) return false;
    for (const json& tile : *tiles) {
      if (!tile.is_number_integer()) return false;
    }
  }
  return true;
}

/// The manifest at @p path; an empty object when there is none, or when it is not a regular
/// file, not valid JSON or not of this version (everything then re-bakes and writing it
/// replaces it), without the entries that are not what recordInManifests writes (those
/// outputs re-bake); `problem` says what was wrong, for a warning.
ReadManifest readManifest(const fs::path& path) {
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  // Something else at the path is an error before baking (executePlan probes it), not a warning.
  if (ec || !fs::is_regular_file(status)) return {};
  std::ifstream in(path, std::ios::binary);
  json parsed = json::parse(in, nullptr, /*allow_exceptions=*/false);
  if (parsed.is_discarded()) return {json::object(), "not valid JSON"};
  if (!parsed.is_object()) return {json::object(), "not a JSON object"};
  const auto version = parsed.find("sgbake_manifest");
  if (version == parsed.end() || *version != kManifestVersion) {
    return {json::object(),
            "not a version " + std::to_string(kManifestVersion) +
                " sgbake manifest (its \"sgbake_manifest\" is " +
                (version == parsed.end() ? std::string("missing") : version->dump()) + ")"};
  }
  // Entries as recordInManifests writes them; anything else (hand-edited, or a foreign value
  // nested deep enough to exhaust the stack when written back) is dropped with a warning.
  const auto outputs = parsed.find("outputs");
  if (outputs == parsed.end()) return {std::move(parsed), {}};
  if (!outputs->is_object()) return {json::object(), "its \"outputs\" is not an object"};
  std::vector<std::string> malformed;
  for (auto entry = outputs->begin(); entry != outputs->end();) {
    if (isManifestEntry(*entry)) {
      ++entry;
    } else {
      malformed.push_back("'" + entry.key() + "'");
      entry = outputs->erase(entry);
    }
  }
  if (malformed.empty()) return {std::move(parsed), {}};
  std::string names;
  for (const std::string& name : malformed) names += (names.empty() ? "" : ", ") + name;
  return {std::move(parsed), "its entries for " + names + " are not what sgbake writes"};
}

/// The length of the UTF-8 sequence that starts at @p text[i], or 0 when none valid does.
std::size_t utf8SequenceLength(std::string_view text, std::size_t i) {
  const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(text[k]); };
  const unsigned char lead = byte(i);
  if (lead < 0x80) return 1;
  std::size_t length = 0;
  std::uint32_t code = 0;
  if ((lead & 0xE0) == 0xC0) {
    length = 2;
    code = lead & 0x1Fu;
  } else if ((lead & 0xF0) == 0xE0) {
    length = 3;
    code = lead & 0x0Fu;
  } else if ((lead & 0xF8) == 0xF0) {
    length = 4;
    code = lead & 0x07u;
  } else {
    return 0;
  }
  if (i + length > text.size()) return 0;
  for (std::size_t k = 1; k < length; ++k) {
    if ((byte(i + k) & 0xC0) != 0x80) return 0;
    code = code << 6 | (byte(i + k) & 0x3Fu);
  }
  constexpr std::uint32_t kSmallest[5] = {0, 0, 0x80, 0x800, 0x10000};
  if (code < kSmallest[length] || code > 0x10FFFF || (code >= 0xD800 && code <= 0xDFFF)) return 0;
  return length;
}

/// A file name as the manifest (JSON: UTF-8 text) stores it: bytes that are not UTF-8 (a Linux
/// name may hold any) and '%' itself become %HH, so that every name is text and the mapping
/// is reversible (fileNameBytes); a UTF-8 name without '%' is itself.
std::string manifestText(std::string_view name) {
  std::string text;
  for (std::size_t i = 0; i < name.size();) {
    const std::size_t length = name[i] == '%' ? 0 : utf8SequenceLength(name, i);
    if (length > 0) {
      text.append(name.substr(i, length));
      i += length;
      continue;
    }
    static constexpr char kHex[] = "0123456789ABCDEF";
    const auto b = static_cast<unsigned char>(name[i++]);
    text += '%';
    text += kHex[b >> 4];
    text += kHex[b & 0xF];
  }
  return text;
}

/// The bytes of a name manifestText made.
std::string fileNameBytes(std::string_view text) {
  const auto hex = [](char c) -> int {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
  };
  std::string bytes;
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text[i] == '%' && i + 2 < text.size() && hex(text[i + 1]) >= 0 && hex(text[i + 2]) >= 0) {
      bytes += static_cast<char>(hex(text[i + 1]) << 4 | hex(text[i + 2]));
      i += 2;
    } else {
      bytes += text[i];
    }
  }
  return bytes;
}

/// The manifests of the output directories, read once per plan.
class ManifestCache {
 public:
  /// The entry of @p file in its directory's manifest, or null.
  const json* entry(const fs::path& file) {
    const json& manifest = load(directoryOf(file));
    const auto outputs = manifest.find("outputs");
    if (outputs == manifest.end() || !outputs->is_object()) return nullptr;
    const auto found = outputs->find(manifestText(file.filename().string()));
    return found == outputs->end() ? nullptr : &*found;
  }

  /// One line for each manifest read that could not be used.
  std::vector<std::string> warnings() const {
    std::vector<std::string> lines;
    for (const auto& [dir, manifest] : manifests_) {
      if (manifest.problem.empty()) continue;
      lines.push_back((fs::path(dir) / kManifestName).string() + ": " + manifest.problem +
                      "; outputs without a valid record there count as changed, and the file "
                      "is rewritten when outputs are written");
    }
    return lines;
  }

 private:
  const json& load(const fs::path& dir) {
    const std::string key = dir.string();
    if (const auto it = manifests_.find(key); it != manifests_.end()) return it->second.content;
    return manifests_.emplace(key, readManifest(dir / kManifestName)).first->second.content;
  }

  std::map<std::string, ReadManifest> manifests_;
};

/// Records each (file, entry) of @p entries in its directory's manifest: each manifest is read,
/// given all of its entries and written atomically once (not once per output, which made a run
/// of many outputs in one directory quadratic in their number).
Status recordInManifests(const std::vector<std::pair<fs::path, json>>& entries) {
  std::map<fs::path, std::vector<const std::pair<fs::path, json>*>> byDirectory;
  for (const auto& entry : entries) byDirectory[directoryOf(entry.first)].push_back(&entry);
  for (const auto& [dir, recorded] : byDirectory) {
    const fs::path path = dir / kManifestName;
    json manifest = readManifest(path).content;
    manifest["sgbake_manifest"] = kManifestVersion;
    if (!manifest.contains("outputs") || !manifest["outputs"].is_object()) {
      manifest["outputs"] = json::object();
    }
    for (const auto* entry : recorded) {
      manifest["outputs"][manifestText(entry->first.filename().string())] = entry->second;
    }
    const std::string text = manifest.dump(2, ' ', false, json::error_handler_t::replace) + "\n";
    if (Status ok = writeFileAtomically(path, text); !ok) return ok;
  }
  return Ok{};
}

std::string joinLabels(const std::vector<std::string>& labels) {
  std::string text;
  for (const std::string& label : labels) {
    if (!text.empty()) text += ", ";
    text += label;
  }
  return text;
}

/// How the manifest in @p dir names @p canonical (both canonical): relative to @p dir, in generic
/// form
/// ("h.png", "../textures/h.png"), or absolute where no relative path leads there (another
/// root).
std::string manifestName(const fs::path& canonical, const fs::path& dir) {
  const fs::path relative = canonical.lexically_relative(dir);
  return manifestText(relative.empty() ? canonical.generic_string() : relative.generic_string());
}

/// Whether @p output's values depend on the scene's "transform" (BakeInput::transform): the
/// maps of the shaded normal and Γ, and the corners table.
bool shadedThroughTransform(const SceneOutput& output) {
  if (output.kind == OutputKind::kCorners) return true;
  switch (output.map) {
    case MapKind::kTangentNormal:
    case MapKind::kObjectNormal:
    case MapKind::kDerivative:
    case MapKind::kSurfaceGradient:
      return true;
    default:
      return false;
  }
}

/// ,"transform":[12 numbers] for the manifest's parameters of @p output when the scene's
/// transform shades it (not the identity); nothing otherwise, so that adding an identity
/// transform, or a transform to a scene of height maps, re-bakes nothing.
std::string transformParametersJson(const Scene& scene, const SceneOutput& output) {
  if (!scene.transform || scene.transform->shadesAsObjectSpace() || !shadedThroughTransform(output))
    return {};
  const ObjectTransform& t = *scene.transform;
  json rows = json::array();
  for (int r = 0; r < 3; ++r) {
    const double translation = r == 0   ? t.translation.x
                               : r == 1 ? t.translation.y
                                        : t.translation.z;
    rows.push_back({t.linear(r, 0), t.linear(r, 1), t.linear(r, 2), translation});
  }
  return ",\"transform\":" + rows.dump();
}

/// An input of an output that differs from what its manifest entry recorded.
struct InputDifference {
  enum class Kind { kNew, kChanged, kGone };
  Kind kind;
  std::string name;             ///< as the manifest names it
  std::optional<int> udimTile;  ///< the UDIM tile it is a file of; none: the mesh or a plain image
};

/// The inputs of @p planned that differ from those its manifest entry @p entry records ("inputs",
/// an object): new or changed ones in the planned order, then gone ones. UDIM tiles the mesh's UVs
/// did not reach when it was baked ("udim_reached") are left out: the same mesh (its hash is an
/// input) reaches the same tiles, and a tile no UV reaches changes no texel. The tile of a gone
/// input is the one the entry recorded for it ("input_tiles").
std::vector<InputDifference> inputDifferences(const json& entry, const json& inputs,
                                              const PlannedOutput& planned) {
  using Kind = InputDifference::Kind;
  const auto reached = entry.find("udim_reached");
  std::set<int> reachedTiles;
  if (reached != entry.end()) reachedTiles = reached->get<std::set<int>>();
  std::vector<InputDifference> differences;
  std::set<std::string> compared;
  for (const auto& [path, hash] : planned.inputHashes) {
    const auto tile = planned.udimTileInputs.find(path);
    const bool isTile = tile != planned.udimTileInputs.end();
    if (reached != entry.end() && isTile && !reachedTiles.contains(tile->second)) continue;
    compared.insert(path);
    const auto recorded = inputs.find(path);
    if (recorded != inputs.end() && *recorded == hash) continue;
    differences.push_back({recorded == inputs.end() ? Kind::kNew : Kind::kChanged, path,
                           isTile ? std::optional<int>(tile->second) : std::nullopt});
  }
  const auto tiles = entry.find("input_tiles");
  for (const auto& [path, hash] : inputs.items()) {
    if (compared.contains(path)) continue;
    std::optional<int> tile;
    if (tiles != entry.end() && tiles->contains(path)) tile = (*tiles)[path].get<int>();
    differences.push_back({Kind::kGone, path, tile});
  }
  return differences;
}

/// Why @p planned must be baked, as the manifest entry @p entry of its @p file says (one
/// phrase for explainPlan: the first difference found); empty when nothing changed.
std::string whyBake(const json* entry, const PlannedOutput& planned, const fs::path& file) {
  const std::string manifest = (directoryOf(file) / kManifestName).string();
  if (entry == nullptr || !entry->is_object()) return "it is not in " + manifest + " yet";
  const auto parameters = entry->find("parameters");
  if (parameters == entry->end() || parameters->dump() != planned.parameters) {
    // Name the parts that differ: "output", "layers", "mesh", "subdivision", "sgbake".
    const json now = json::parse(planned.parameters);
    std::vector<std::string> changed;
    for (const auto& [key, value] : now.items()) {
      if (parameters == entry->end() || !parameters->contains(key) || (*parameters)[key] != value) {
        changed.push_back("\"" + key + "\"");
      }
    }
    return "its parameters changed" + (changed.empty() ? "" : ": " + joinLabels(changed));
  }
  const auto inputs = entry->find("inputs");
  if (inputs == entry->end() || !inputs->is_object()) return "its inputs are not in " + manifest;
  if (const std::vector<InputDifference> differences = inputDifferences(*entry, *inputs, planned);
      !differences.empty()) {
    // Inputs are named relative to the manifest's directory: said as full paths.
    const InputDifference& first = differences.front();
    const fs::path full = (canonicalPath(directoryOf(file)) / fileNameBytes(first.name));
    using Kind = InputDifference::Kind;
    return full.lexically_normal().string() + (first.kind == Kind::kNew       ? " is new"
                                               : first.kind == Kind::kChanged ? " changed"
                                                                              : " is gone");
  }
  const auto files = entry->find("files");
  if (files == entry->end() || !files->is_object() || files->empty()) {
    return "its files are not in " + manifest;
  }
  for (const auto& [name, hash] : files->items()) {
    const fs::path path = directoryOf(file) / fileNameBytes(name);
    Result<std::string> now = hashFile(path);
    if (!now) return path.string() + " is missing";
    if (!hash.is_string() || *now != hash.get<std::string>()) {
      return path.string() + " was changed since it was baked";
    }
  }
  return {};
}

/// The file of tile @p tile of @p output (a corners table is one file).
fs::path tileFile(const SceneOutput& output, int tile) {
  return output.kind == OutputKind::kCorners
             ? output.file
             : fs::path(expandUdimToken(output.file.string(), tile));
}

/// Whether every layer @p layers (scene indices) that reads a UDIM image or mask reads, at a
/// texel of tile t of @p output, the image's tile t only: one sampled on the output's UV set
/// (UDIM images are on UV layers, untiled and unshifted: validateScene; a UDIM texture samples
/// the tile its coordinates lie in, and a texel's sample lies inside its tile).
bool readsUdimTileByTile(const Scene& s, const std::vector<std::size_t>& layers,
                         const SceneOutput& output) {
  for (const std::size_t l : layers) {
    const SceneLayer& layer = s.layers[l];
    if (layer.hasImage() && hasUdimToken(layer.image.string()) && layer.uvSet != output.uvSet)
      return false;
    if (layer.mask && hasUdimToken(layer.mask->image.string()) &&
        layer.mask->uvSet != output.uvSet) {
      return false;
    }
  }
  return true;
}

/// The tiles of a UDIM output to bake again and those to keep.
struct TilesToKeep {
  std::set<int> rebaked;  ///< their inputs or their files changed
  std::vector<int> kept;
  std::vector<std::pair<std::string, std::string>> keptFiles;  ///< manifest name → hash
};

/// For a UDIM output that must be baked (whyBake) because some of its tiles changed only: which
/// tiles those are, and the tiles whose files stay (their UDIM image tiles and their files are
/// as the manifest @p entry recorded them, and every layer reads tile by tile). Nothing when
/// the whole output must be baked: its parameters, mesh or a plain image changed, a tile file
/// of an input is gone from a manifest that did not record its tile number, its "range" is
/// "auto" (one range for every tile), or the tile number is in a directory name.
std::optional<TilesToKeep> udimTilesToKeep(const json* entry, const PlannedOutput& planned,
                                           const Scene& s, const SceneOutput& output) {
  if (entry == nullptr || !entry->is_object() || output.kind != OutputKind::kMap ||
      !hasUdimToken(output.file.filename().string()) ||
      (output.rangeAuto && output.storesSignedRange()) ||
      !readsUdimTileByTile(s, planned.layers, output)) {
    return {};
  }
  const auto parameters = entry->find("parameters");
  const auto inputs = entry->find("inputs");
  const auto files = entry->find("files");
  if (parameters == entry->end() || parameters->dump() != planned.parameters ||
      inputs == entry->end() || !inputs->is_object() || files == entry->end() ||
      !files->is_object()) {
    return {};
  }
  TilesToKeep result;
  for (const InputDifference& difference : inputDifferences(*entry, *inputs, planned)) {
    if (!difference.udimTile) return {};  // the mesh, a plain image, or a tile of unknown number
    result.rebaked.insert(*difference.udimTile);
  }
  std::map<std::string, int> tileOfName;
  for (int tile = kFirstUdimTile; tile <= kLastUdimTile; ++tile) {
    tileOfName.emplace(manifestText(tileFile(output, tile).filename().string()), tile);
  }
  for (const auto& [name, hash] : files->items()) {
    const auto tile = tileOfName.find(name);
    if (tile == tileOfName.end() || !hash.is_string()) return {};
    if (result.rebaked.contains(tile->second)) continue;
    const Result<std::string> now = hashFile(directoryOf(output.file) / fileNameBytes(name));
    if (!now || *now != hash.get<std::string>()) {
      result.rebaked.insert(tile->second);
      continue;
    }
    result.kept.push_back(tile->second);
    result.keptFiles.emplace_back(name, hash.get<std::string>());
  }
  if (result.rebaked.empty() || result.kept.empty()) return {};
  return result;
}

// ---- Planning ----------------------------------------------------------------------------------

/// Checks that an input file exists and is a regular file.
Status checkInputFile(const Scene& scene, const std::string& user, std::string_view what,
                      const fs::path& path) {
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (ec || !fs::exists(status)) {
    return Error::badInput(scenePrefix(scene) + user + ": " + std::string(what) + " " +
                           path.string() + " does not exist");
  }
  if (!fs::is_regular_file(status)) {
    return Error::badInput(scenePrefix(scene) + user + ": " + std::string(what) + " " +
                           path.string() + " is not a file");
  }
  return Ok{};
}

/// The tile files of UDIM image names (`<UDIM>` in the file name) that exist, looked for once
/// per name and plan (a name means 1,000 candidate files).
class UdimTileFinder {
 public:
  /// In memory (@p inMemory), tiles are among @p imageNames instead of files.
  UdimTileFinder(bool inMemory, const std::set<std::string>& imageNames)
      : inMemory_(inMemory), imageNames_(imageNames) {}

  /// Tile → file (or image name), for the tiles of @p pattern that exist.
  const std::map<int, fs::path>& tiles(const fs::path& pattern) { return find(pattern).tiles; }

  /// Why a tile of @p pattern cannot be read: something at a tile's name that is not a
  /// regular file (a directory, a link to nothing, a pipe); empty when there is none.
  const std::string& problem(const fs::path& pattern) { return find(pattern).problem; }

 private:
  struct Found {
    std::map<int, fs::path> tiles;
    std::string problem;
  };

  const Found& find(const fs::path& pattern) {
    const std::string text = pattern.string();
    if (const auto it = found_.find(text); it != found_.end()) return it->second;
    Found found;
    for (int tile = kFirstUdimTile; tile <= kLastUdimTile; ++tile) {
      std::string name = expandUdimToken(text, tile);
      if (inMemory_) {
        if (imageNames_.contains(name)) found.tiles.emplace(tile, std::move(name));
        continue;
      }
      std::error_code ec;
      const fs::file_status link = fs::symlink_status(name, ec);
      if (ec || !fs::exists(link)) continue;  // no tile
      const fs::file_status target = fs::status(name, ec);  // of the file a link points to
      if (!ec && fs::is_regular_file(target)) {
        found.tiles.emplace(tile, std::move(name));
      } else if (found.problem.empty()) {
        found.problem = "tile file " + name + " is not a regular file" +
                        (fs::is_directory(target) ? " (a directory)"
                         : fs::is_symlink(link)   ? " (a link to nothing?)"
                                                  : "");
      }
    }
    return found_.emplace(text, std::move(found)).first->second;
  }

  bool inMemory_;
  const std::set<std::string>& imageNames_;
  std::map<std::string, Found> found_;
};

/// Builds the plan's image, texture and layer lists for the layers in @p used.
void planLayers(Plan& plan, const std::set<std::size_t>& used, UdimTileFinder& udimTiles) {
  std::map<std::pair<std::string, int>, std::size_t> imageIndex;
  std::map<std::tuple<std::size_t, bool, int, int>, std::size_t> textureIndex;
  const auto addTexture = [&](const fs::path& path, bool vector, Filter filter, Wrap wrap,
                              const std::string& user, ImageChannels scalarChannel) {
    const ImageChannels channels = vector ? ImageChannels::kRgb : scalarChannel;
    const fs::path canonical = plan.scene.inMemory ? path : canonicalPath(path);
    const auto imageKey = std::make_pair(canonical.string(), static_cast<int>(channels));
    auto [image, newImage] = imageIndex.emplace(imageKey, plan.images.size());
    if (newImage) plan.images.push_back({path, canonical, channels, {}});
    plan.images[image->second].users.push_back(user);
    const auto textureKey =
        std::make_tuple(image->second, vector, static_cast<int>(filter), static_cast<int>(wrap));
    auto [texture, newTexture] = textureIndex.emplace(textureKey, plan.textures.size());
    if (newTexture) plan.textures.push_back({image->second, vector, filter, wrap, {}, {}});
    return texture->second;
  };
  // A UDIM image: a texture per tile file, and one that picks among them by UV.
  std::map<std::tuple<std::string, bool, int, int, int>, std::size_t> udimIndex;
  const auto addImageTexture = [&](const fs::path& path, bool vector, Filter filter, Wrap wrap,
                                   const std::string& user, ImageChannels scalarChannel) {
    if (!hasUdimToken(path.string())) {
      return addTexture(path, vector, filter, wrap, user, scalarChannel);
    }
    const auto key = std::make_tuple((plan.scene.inMemory ? path : canonicalPath(path)).string(),
                                     vector, static_cast<int>(filter), static_cast<int>(wrap),
                                     static_cast<int>(scalarChannel));
    if (const auto it = udimIndex.find(key); it != udimIndex.end()) {
      for (const auto& [tile, t] : plan.textures[it->second].udimTiles) {
        plan.images[plan.textures[t].image].users.push_back(user);
      }
      return it->second;
    }
    PlannedTexture udim{std::numeric_limits<std::size_t>::max(), vector, filter, wrap, {}, path};
    for (const auto& [tile, file] : udimTiles.tiles(path)) {  // not empty: makePlan checked
      udim.udimTiles.emplace(tile, addTexture(file, vector, filter, wrap, user, scalarChannel));
    }
    plan.textures.push_back(std::move(udim));
    udimIndex.emplace(key, plan.textures.size() - 1);
    return plan.textures.size() - 1;
  };
  for (const std::size_t i : used) {
    const SceneLayer& layer = plan.scene.layers[i];
    PlannedLayer planned;
    planned.sceneLayer = i;
    if (layer.hasImage()) {
      planned.texture = addImageTexture(layer.image, layer.readsNormals(), layer.filter, layer.wrap,
                                        layerLabel(i), layer.channel);
    }
    if (layer.mask) {
      planned.mask = addImageTexture(layer.mask->image, false, layer.mask->filter, Wrap::kRepeat,
                                     layerLabel(i) + ".mask", ImageChannels::kLuminance);
    }
    plan.layers.push_back(planned);
  }
}

/// A number in its shortest "%g" form (0.001, not 0.001000).
std::string formatNumber(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", value);
  return text;
}

std::string channelsName(ImageChannels channels) {
  switch (channels) {
    case ImageChannels::kRgb:
      return "RGB";
    case ImageChannels::kRed:
      return "R";
    case ImageChannels::kGreen:
      return "G";
    case ImageChannels::kBlue:
      return "B";
    case ImageChannels::kAlpha:
      return "alpha";
    default:
      return "luminance";
  }
}

/// The plan's steps and skipped list, for explainPlan.
void describePlan(Plan& plan, const std::vector<std::string>& tangentReasons) {
  const Scene& scene = plan.scene;
  std::vector<std::string> toBake;
  for (const PlannedOutput& output : plan.outputs) {
    if (!output.upToDate) toBake.push_back(scene.outputs[output.sceneOutput].file.string());
  }

  // Steps, in execution order.
  if (plan.loadMesh) {
    plan.steps.push_back({"load mesh " + scene.mesh.string() + ", UVs required",
                          "read by every output to bake: " + joinLabels(toBake)});
    if (scene.subdivision.limitSurface()) {
      plan.steps.push_back(
          {"subdivide the mesh " + describeSubdivision(scene.subdivision) +
               ": every sample is shaded on the exact surface, found through a level-" +
               std::to_string(kLimitTessellationLevel) + " tessellation",
           "the scene's \"subdivision\": {\"level\": \"limit\"}"});
    } else if (scene.subdivision.requested() && scene.subdivision.level == 0) {
      plan.steps.push_back({"split the mesh's normals by Auto Smooth at " +
                                describeAutoSmooth(scene.subdivision) + " (not subdivided)",
                            "the scene's \"subdivision\": {\"level\": 0, \"auto_smooth\": ...}"});
    } else if (scene.subdivision.requested()) {
      plan.steps.push_back({"subdivide the mesh " + describeSubdivision(scene.subdivision),
                            "the scene's \"subdivision\" block (Blender's Subdivision Surface "
                            "modifier)"});
    }
  }
  for (const PlannedImage& image : plan.images) {
    plan.steps.push_back(
        {"load image " + image.path.string() + " as " + channelsName(image.channels),
         "read by " + joinLabels(image.users)});
  }
  std::map<std::size_t, std::string> tileOf;  // a UDIM tile's texture → what samples it
  for (const PlannedTexture& texture : plan.textures) {
    for (const auto& [tile, t] : texture.udimTiles) {
      tileOf[t] = "tile " + std::to_string(tile) + " of " + texture.udimImage.string();
    }
  }
  // A layer that reads its height through a remap (one view of the shared texture each).
  const auto remapNote = [&scene](std::size_t sceneLayer) {
    const std::size_t points = scene.layers[sceneLayer].remap.size();
    return points == 0 ? std::string()
                       : " through a remap of " + std::to_string(points) + " points";
  };
  for (std::size_t t = 0; t < plan.textures.size(); ++t) {
    const PlannedTexture& texture = plan.textures[t];
    std::vector<std::string> users;
    for (const PlannedLayer& layer : plan.layers) {
      if (layer.texture == t)
        users.push_back(layerLabel(layer.sceneLayer) + remapNote(layer.sceneLayer));
      if (layer.mask == t) users.push_back(layerLabel(layer.sceneLayer) + ".mask");
    }
    const std::string kind = texture.vector ? "vector" : "scalar";
    if (!texture.udimTiles.empty()) {
      std::vector<std::string> tiles;
      for (const auto& entry : texture.udimTiles) tiles.push_back(std::to_string(entry.first));
      plan.steps.push_back(
          {"make UDIM " + kind + " texture " + texture.udimImage.string() + " of tiles " +
               joinLabels(tiles) +
               (texture.vector ? " (the zero normal, no bump, where the UVs reach no tile)"
                               : " (0 where the UVs reach no tile)"),
           "sampled by " + joinLabels(users)});
      continue;
    }
    const auto tile = tileOf.find(t);
    plan.steps.push_back(
        {"make " + kind + " texture " + plan.images[texture.image].path.string() + ", " +
             std::string(filterName(texture.filter)) + ", " +
             (texture.wrap == Wrap::kRepeat ? "repeat" : "clamp"),
         tile != tileOf.end() && users.empty() ? tile->second : "sampled by " + joinLabels(users)});
  }
  for (const PlannedLayer& layer : plan.layers) {
    if (scene.layers[layer.sceneLayer].type == SceneLayerType::kVolume) {
      const SceneLayer& volume = scene.layers[layer.sceneLayer];
      plan.steps.push_back({"make " + describeLayer(volume) + " for " +
                                layerLabel(layer.sceneLayer) + remapNote(layer.sceneLayer),
                            volume.coordinates == VolumeCoordinates::kUv
                                ? "read as a UV height: slopes through the UV map"
                            : volume.step
                                ? "gradient step " + formatNumber(*volume.step)
                                : "gradient step: 2^-20 of the mesh's bounding-box diagonal"});
    }
  }
  if (plan.computeTangents) {
    plan.steps.push_back({"compute MikkTSpace tangent frames", joinLabels(tangentReasons)});
  }
  if (scene.transform && !scene.transform->shadesAsObjectSpace()) {
    std::vector<std::string> shaded;
    for (const PlannedOutput& output : plan.outputs) {
      const SceneOutput& o = scene.outputs[output.sceneOutput];
      if (!output.upToDate && shadedThroughTransform(o)) shaded.push_back(o.file.string());
    }
    if (!shaded.empty()) {
      // A rotation (or mirror) with a uniform scale shades as object space (runBake), unless
      // a height is differenced as the Bump node does (its offsets turn with the world).
      const bool bumpNode = std::ranges::any_of(scene.layers, [](const SceneLayer& layer) {
        return layer.hasHeight() && layer.heightGradient == HeightGradient::kBumpNode;
      });
      const std::optional<double> uniform = scene.transform->objectSpaceScale(bumpNode);
      plan.steps.push_back(
          {uniform ? "shade in object space with heights in world units divided by the "
                     "object's uniform scale " +
                         formatNumber(*uniform) + " (as Cycles shades it in world space)"
                   : std::string("shade in world space through the object transform, as Cycles "
                                 "does (heights in world units)"),
           "the scene's \"transform\", for " + joinLabels(shaded)});
    }
  }
  for (const PlannedOutput& planned : plan.outputs) {
    if (planned.upToDate) continue;
    const SceneOutput& output = scene.outputs[planned.sceneOutput];
    std::vector<std::string> read;
    for (const std::size_t l : planned.layers)
      read.push_back(layerLabel(plan.layers[l].sceneLayer));
    const std::string reads = read.empty() ? "reads no layers" : "reads " + joinLabels(read);
    if (output.kind == OutputKind::kCorners) {
      plan.steps.push_back({"evaluate the corner table " + output.file.string(),
                            "because " + planned.whyBake + "; " + reads +
                                "; MikkTSpace frames of UV set 0 computed with it"});
      plan.steps.push_back({"write " + output.file.string() + " as CSV", "all or nothing"});
      continue;
    }
    const bool udim = hasUdimToken(output.file.string());
    // Memory of the pixels (float values and coverage): bakeImageTile's ring of bands, or the
    // whole image for push-pull (with its pyramid of halved images, a third more) and Adjacent
    // Faces (with each texel's face and distance, 8 bytes, and the margin's lists, ~4 more;
    // measured at 4096² RGB: 21 and 28 bytes per texel against 16 for the image).
    const plan_detail::OutputPadding padding = plan_detail::outputPadding(output);
    const int rowsHeld =
        padding.wholeImage() ? output.height : bakeRingRows(output.height, padding.bandHalo());
    const double pixelBytes = (mapChannels(output.map) + 1) * sizeof(float);
    const double texelBytes = padding.mode == PaddingMode::kPushPull ? pixelBytes * 4 / 3
                              : padding.wholeImage()                 ? pixelBytes + 12
                                                                     : pixelBytes;
    const double bytes = static_cast<double>(rowsHeld) * output.width * texelBytes;
    char megabytes[32];  // one decimal below 10 MB
    std::snprintf(megabytes, sizeof megabytes, bytes < 1e7 ? "%.1f MB" : "%.0f MB", bytes / 1e6);
    const std::string memory =
        padding.wholeImage()
            ? "; the whole image in memory for " +
                  std::string(padding.mode == PaddingMode::kPushPull ? "push-pull"
                                                                     : "adjacent-faces") +
                  " (" + megabytes + ")"
            : "; in bands of " + std::to_string(kBakeBandRows) + " rows, " +
                  std::to_string(rowsHeld) + " rows (" + megabytes + ") in memory at a time";
    if (output.rangeAuto && output.storesSignedRange()) {
      plan.steps.push_back({"find the range of " + output.file.string() +
                                ": bake it once for its largest |value|" +
                                (udim ? " over every tile" : ""),
                            "\"range\": \"auto\" (a second bake of the map)"});
    }
    plan.steps.push_back(
        {"bake " + output.file.string() + ": " + std::string(mapKindName(output.map)) + " " +
             std::to_string(output.width) + "x" + std::to_string(output.height) + ", " +
             std::to_string(output.samples) + "x" + std::to_string(output.samples) +
             " samples per texel, UV set " + std::to_string(output.uvSet) + ", " +
             (!udim                       ? "UDIM tile " + std::to_string(output.tile)
              : planned.keptTiles.empty() ? "every UDIM tile the UV set touches"
                                          : "the UDIM tiles the UV set touches but those kept"),
         "because " + planned.whyBake + "; " + reads + memory});
    if (padding.mode == PaddingMode::kPushPull) {  // (masks are never padded: outputPadding)
      plan.steps.push_back({"pad " + output.file.string() + " by push-pull",
                            "fills every texel outside the UV islands"});
    } else if (padding.margin > 0 && padding.mode == PaddingMode::kAdjacentFaces) {
      plan.steps.push_back({"pad " + output.file.string() + ": adjacent faces, " +
                                std::to_string(padding.margin) + " texels",
                            "each margin texel takes the surface's value across the UV seam it "
                            "faces (Blender's default margin)"});
    } else if (padding.margin > 0) {
      plan.steps.push_back(
          {"pad " + output.file.string() + ": extend " + std::to_string(padding.margin) + " texels",
           "margin against bleeding at UV seams under filtering and mipmaps"});
    }
    const ImageFormat format = output.resolvedFormat();
    std::string formatText(imageFormatName(format));
    for (char& c : formatText) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    const int depth = output.resolvedBitDepth();
    const std::string depthText = format == ImageFormat::kExr ? (depth == 32 ? "float" : "half")
                                  : depth == 32               ? "32-bit float"
                                                              : std::to_string(depth) + "-bit";
    plan.steps.push_back({"write " + output.file.string() + " as " + depthText + " " + formatText +
                              (output.alpha ? " with alpha = coverage" : ""),
                          "all or nothing: temporary file, then rename"});
  }
  if (plan.options.useManifest && !toBake.empty()) {
    plan.steps.push_back({"record the outputs in " + std::string(kManifestName),
                          "the next run re-bakes only what changed"});
  }

  // Skipped work.
  for (const PlannedOutput& planned : plan.outputs) {
    if (planned.upToDate) {
      const SceneOutput& output = scene.outputs[planned.sceneOutput];
      plan.skipped.push_back(
          {output.file.string(), "up to date (inputs, parameters and file match " +
                                     (directoryOf(output.file) / kManifestName).string() +
                                     "; --force re-bakes)"});
    }
  }
  if (!plan.loadMesh) {
    plan.skipped.push_back({"load mesh " + scene.mesh.string(), "every output is up to date"});
  }
  std::set<std::size_t> planned;
  for (const PlannedLayer& layer : plan.layers) planned.insert(layer.sceneLayer);
  for (std::size_t i = 0; i < scene.layers.size(); ++i) {
    const SceneLayer& layer = scene.layers[i];
    const std::string what = layerLabel(i) + " (" + describeLayer(layer) + ")";
    if (planned.count(i) == 0) {
      std::set<std::string> reasons;
      for (const PlannedOutput& output : plan.outputs) {
        const std::string why = whyNotRead(scene.outputs[output.sceneOutput], layer);
        if (!why.empty()) {
          reasons.insert(why);
        } else if (output.upToDate) {
          reasons.insert("the outputs that read it are up to date");
        }
      }
      std::vector<std::string> list(reasons.begin(), reasons.end());
      plan.skipped.push_back({what + (layer.hasImage() ? " and its image" : ""),
                              "no output to bake reads it: " + joinLabels(list)});
      continue;
    }
    for (const PlannedOutput& output : plan.outputs) {
      if (output.upToDate) continue;
      const std::string why = whyNotRead(scene.outputs[output.sceneOutput], layer);
      if (!why.empty()) {
        plan.skipped.push_back(
            {what + " for " + scene.outputs[output.sceneOutput].file.string(), why});
      }
    }
  }
  if (!plan.computeTangents && plan.loadMesh) {
    plan.skipped.push_back(
        {"tangent frames (MikkTSpace)",
         scene.subdivision.limitSurface()
             ? "the exact limit surface gives every sample its own frame (T = dP/du made "
               "orthogonal to N, the sign from dP/dv)"
             : "no map to bake is tangent-normal, tangent or bitangent, and no layer it reads "
               "is a tangent-space normal map on UV set 0"});
  }
  bool images = false;
  for (const PlannedOutput& output : plan.outputs) {
    if (!output.upToDate && scene.outputs[output.sceneOutput].kind == OutputKind::kMap)
      images = true;
  }
  if (images) {
    plan.skipped.push_back({"texels outside the UV islands",
                            "not shaded by the baker (background value, then margin or padding)"});
  }
  for (const PlannedLayer& layer : plan.layers) {
    const SceneLayer& source = scene.layers[layer.sceneLayer];
    if (source.type == SceneLayerType::kTriplanar &&
        source.projection == TriplanarProjection::kBox) {
      plan.skipped.push_back({"Box planes of " + layerLabel(layer.sceneLayer) +
                                  " outside their blend (box_blend " +
                                  formatNumber(source.boxBlend) + ")",
                              "not sampled by the kernel (weight 0, as in Cycles)"});
    } else if (source.type == SceneLayerType::kTriplanar) {
      plan.skipped.push_back({"triplanar planes of " + layerLabel(layer.sceneLayer) +
                                  " with blend weight below " + formatNumber(source.minWeight),
                              "not sampled by the kernel (the other planes are renormalized)"});
    }
    if (source.mask) {
      plan.skipped.push_back(
          {layerLabel(layer.sceneLayer) + " where its mask is 0", "not sampled by the kernel"});
    }
  }
}

}  // namespace

double roundRangeUp(double largest) {
  if (!(largest > 0) || !std::isfinite(largest)) return 1;
  const double step = std::pow(10.0, std::floor(std::log10(largest)) - 2);  // 3 digits
  double range = std::ceil(largest / step) * step;
  range = std::strtod(formatNumber(range).c_str(), nullptr);  // exactly the number recorded
  if (range < largest) range = std::strtod(formatNumber(range + step).c_str(), nullptr);
  return range;
}

// ---- Hashing -----------------------------------------------------------------------------------

std::uint64_t fnv1a64(std::string_view bytes, std::uint64_t hash) {
  constexpr std::uint64_t kPrime = 0x100000001b3ULL;
  for (const char c : bytes) {
    hash ^= static_cast<unsigned char>(c);
    hash *= kPrime;
  }
  return hash;
}

Result<std::string> hashFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Error::badInput(path.string() + ": cannot read file");
  std::uint64_t hash = 0xcbf29ce484222325ULL;
  std::vector<char> buffer(1 << 16);
  while (in) {
    in.read(buffer.data(), static_cast<std::streamsize>(buffer.size()));
    const auto n = static_cast<std::size_t>(in.gcount());
    hash = fnv1a64(std::string_view(buffer.data(), n), hash);
  }
  if (in.bad()) return Error::badInput(path.string() + ": cannot read file");
  char text[32];
  std::snprintf(text, sizeof text, "fnv1a64:%016" PRIx64, hash);
  return std::string(text);
}

// ---- makePlan ----------------------------------------------------------------------------------

std::size_t Plan::outputsToBake() const {
  return static_cast<std::size_t>(std::count_if(
      outputs.begin(), outputs.end(), [](const PlannedOutput& o) { return !o.upToDate; }));
}

Result<Plan> makePlan(Scene scene, const PlanOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  const std::string prefix = scenePrefix(scene);
  if (Status valid = validateScene(scene); !valid) {
    return Error::badInput(prefix + valid.error().message);
  }
  // In memory there are no files to check, hash or record.
  if (!scene.inMemory) {
    if (Status ok = checkInputFile(scene, "mesh", "file", scene.mesh); !ok) return ok.error();
  }

  Plan plan;
  plan.options = options;
  plan.options.useManifest = options.useManifest && !scene.inMemory;
  plan.scene = std::move(scene);
  const Scene& s = plan.scene;

  // Which layers each output reads; the files each output depends on. Every output names and
  // hashes its inputs: each path is made canonical once (a UDIM image has up to 1000 tiles).
  std::map<std::string, fs::path> canonicalPaths;  // path as given → canonical
  const auto canonicalOf = [&canonicalPaths](const fs::path& path) -> const fs::path& {
    auto [it, added] = canonicalPaths.try_emplace(path.string());
    if (added) it->second = canonicalPath(path);
    return it->second;
  };
  std::map<std::string, std::string> hashes;  // canonical path → hash
  const auto hashOf = [&](const fs::path& path, const std::string& user,
                          std::string_view what) -> Result<std::string> {
    const std::string canonical = canonicalOf(path).string();
    if (const auto it = hashes.find(canonical); it != hashes.end()) return it->second;
    if (Status ok = checkInputFile(s, user, what, path); !ok) return ok.error();
    Result<std::string> hash = hashFile(path);
    if (!hash) return Error::badInput(prefix + user + ": " + hash.error().message);
    hashes.emplace(canonical, *hash);
    return hash;
  };

  ManifestCache manifests;
  UdimTileFinder udimTiles(s.inMemory, options.imageNames);
  for (std::size_t o = 0; o < s.outputs.size(); ++o) {
    const SceneOutput& output = s.outputs[o];
    PlannedOutput planned;
    planned.sceneOutput = o;
    // Files are named relative to the manifest's directory (manifestName), so that a project
    // moved or checked out elsewhere as a whole is still up to date.
    const fs::path manifestDir = canonicalPath(directoryOf(output.file));
    const PathNamer name = [&](const fs::path& path) {
      return s.inMemory ? manifestText(path.string())
                        : manifestName(canonicalOf(path), manifestDir);
    };
    const std::string common = std::string("{\"sgbake\":\"") + sgbake_version() +
                               "\",\"subdivision\":" + subdivisionParametersJson(s.subdivision) +
                               transformParametersJson(s, output) +
                               ",\"mesh\":" + json(name(s.mesh)).dump();
    std::string layersJson;
    std::vector<fs::path> inputs{s.mesh};
    std::vector<std::string> users{"mesh"};
    std::set<std::string> directInputs;  // images read as they are (not as a UDIM tile)
    for (std::size_t l = 0; l < s.layers.size(); ++l) {
      const SceneLayer& layer = s.layers[l];
      if (!whyNotRead(output, layer).empty()) continue;
      planned.layers.push_back(l);  // scene index for now; remapped below
      layersJson += (layersJson.empty() ? "" : ",") + layerParametersJson(layer, name);
      // A UDIM image's inputs are its tile files; it needs one at least.
      const auto addInput = [&](const fs::path& image, const std::string& user) -> Status {
        if (!hasUdimToken(image.string())) {
          inputs.push_back(image);
          users.push_back(user);
          directInputs.insert(name(image));
          return Ok{};
        }
        if (const std::string& problem = udimTiles.problem(image); !problem.empty()) {
          return Error::badInput(prefix + user + ": UDIM image " + image.string() + ": " + problem);
        }
        const std::map<int, fs::path>& tiles = udimTiles.tiles(image);
        if (tiles.empty()) {
          return Error::badInput(prefix + user + ": no tile of the UDIM image " + image.string() +
                                 (s.inMemory ? " is among the images given (names " : " exists (") +
                                 expandUdimToken(image.string(), kFirstUdimTile) + " to " +
                                 expandUdimToken(image.string(), kLastUdimTile) + ")");
        }
        for (const auto& [tile, file] : tiles) {
          inputs.push_back(file);
          users.push_back(user);
          planned.udimTileInputs[name(file)] = tile;
        }
        return Ok{};
      };
      if (layer.hasImage()) {
        if (Status ok = addInput(layer.image, layerLabel(l)); !ok) return ok.error();
      }
      if (layer.mask) {
        if (Status ok = addInput(layer.mask->image, layerLabel(l) + ".mask"); !ok) {
          return ok.error();
        }
      }
    }
    // A file read directly too is an input whatever the UVs reach.
    for (const std::string& path : directInputs) planned.udimTileInputs.erase(path);
    planned.parameters = common + ",\"output\":" + outputParametersJson(output) + ",\"layers\":[" +
                         layersJson + "]}";
    planned.parameters = json::parse(planned.parameters).dump();  // canonical key order
    if (plan.options.useManifest) {
      for (std::size_t i = 0; i < inputs.size(); ++i) {
        Result<std::string> hash =
            hashOf(inputs[i], users[i],
                   i == 0 ? "file" : (users[i].ends_with(".mask") ? "mask image" : "image"));
        if (!hash) return hash.error();
        planned.inputHashes.emplace_back(name(inputs[i]), *hash);
      }
      std::sort(planned.inputHashes.begin(), planned.inputHashes.end());
      planned.inputHashes.erase(std::unique(planned.inputHashes.begin(), planned.inputHashes.end()),
                                planned.inputHashes.end());
      const json* entry = manifests.entry(output.file);  // read with --force too, for warnings
      planned.whyBake = options.force ? "of --force" : whyBake(entry, planned, output.file);
      planned.upToDate = planned.whyBake.empty();
      if (!planned.upToDate && !options.force) {
        if (std::optional<TilesToKeep> keep = udimTilesToKeep(entry, planned, s, output)) {
          std::vector<std::string> rebaked, kept;
          for (const int tile : keep->rebaked) rebaked.push_back(std::to_string(tile));
          for (const int tile : keep->kept) kept.push_back(std::to_string(tile));
          planned.whyBake = "tile(s) " + joinLabels(rebaked) + " changed (" + planned.whyBake +
                            "); tile(s) " + joinLabels(kept) + " are kept as they are";
          planned.keptTiles = std::move(keep->kept);
          planned.keptFiles = std::move(keep->keptFiles);
        }
      }
    } else {
      planned.whyBake =
          s.inMemory ? "it is baked in memory" : "the manifest is off (--no-manifest)";
    }
    plan.outputs.push_back(std::move(planned));
  }
  plan.warnings = manifests.warnings();

  // The layers, images and textures of the outputs to bake.
  std::set<std::size_t> used;
  std::vector<std::string> tangentReasons;
  // On the exact limit surface every sample gets the surface's own frame (LimitShader).
  const bool limitFrames = s.subdivision.limitSurface();
  for (const PlannedOutput& output : plan.outputs) {
    if (output.upToDate) continue;
    const SceneOutput& out = s.outputs[output.sceneOutput];
    plan.loadMesh = true;
    if (out.kind == OutputKind::kMap && mapNeedsTangents(out.map) && !limitFrames) {
      tangentReasons.push_back(describeOutput(out) + " is expressed in them");
    }
    for (const std::size_t l : output.layers) {
      used.insert(l);
      if (out.kind == OutputKind::kMap && layerNeedsTangents(s.layers[l]) && !limitFrames) {
        tangentReasons.push_back(layerLabel(l) + ", a tangent-space normal map, is decoded in " +
                                 "those of UV set " + std::to_string(s.layers[l].frameUvSet()) +
                                 " (of the loop triangles) for " + out.file.string());
      }
    }
  }
  plan.computeTangents = !tangentReasons.empty();
  planLayers(plan, used, udimTiles);
  // Output layer lists: scene indices → indices into plan.layers (up-to-date outputs: none).
  for (PlannedOutput& output : plan.outputs) {
    std::vector<std::size_t> mapped;
    if (!output.upToDate) {
      for (const std::size_t l : output.layers) {
        for (std::size_t p = 0; p < plan.layers.size(); ++p) {
          if (plan.layers[p].sceneLayer == l) mapped.push_back(p);
        }
      }
    }
    output.layers = std::move(mapped);
  }
  // Every image to load must exist (checked here so no output is touched on bad input).
  for (const PlannedImage& image : plan.images) {
    if (s.inMemory) continue;  // images in memory are looked up when they are loaded
    if (Status ok = checkInputFile(s, image.users.front(), "image", image.path); !ok) {
      return ok.error();
    }
  }
  describePlan(plan, tangentReasons);
  plan.planSeconds = secondsSince(start);
  return plan;
}

// ---- explainPlan -------------------------------------------------------------------------------

std::string explainPlan(const Plan& plan) {
  const Scene& scene = plan.scene;
  std::string text =
      "plan for " +
      (scene.source.empty() ? std::string("the command line") : scene.source.string()) + ": " +
      std::to_string(plan.outputsToBake()) + " of " + std::to_string(scene.outputs.size()) +
      " output" + (scene.outputs.size() == 1 ? "" : "s") + " to bake";
  // Images are loaded once however many layers read them (and UDIM tiles the UVs do not
  // reach not at all, once the mesh is read).
  std::size_t uses = 0;
  for (const PlannedImage& image : plan.images) uses += image.users.size();
  text += ", " + std::to_string(plan.images.size()) + " image" +
          (plan.images.size() == 1 ? "" : "s") + " to load";
  if (uses > plan.images.size()) text += " for " + std::to_string(uses) + " layer inputs";
  text += "\n";
  if (plan.steps.empty())
    text += "steps: none\n";
  else
    text += "steps:\n";
  for (std::size_t i = 0; i < plan.steps.size(); ++i) {
    text +=
        "  " + std::to_string(i + 1) + ". " + plan.steps[i].what + " (" + plan.steps[i].why + ")\n";
  }
  text += "skipped:";
  text += plan.skipped.empty() ? " nothing\n" : "\n";
  for (const PlanStep& skipped : plan.skipped) {
    text += "  - " + skipped.what + ": " + skipped.why + "\n";
  }
  return text;
}

// ---- executePlan -------------------------------------------------------------------------------

namespace {

using plan_detail::Loaded;
using plan_detail::ProgressReporter;

/// What a baked image file says about itself (ImageWriteOptions::attributes), so that a tool
/// reading it knows how to decode it: the map, how its values are stored, the range of a
/// signed map in an integer file, the green convention and any other swizzle of a normal map's
/// channels, the UV set and the UDIM tile.
std::vector<std::pair<std::string, std::string>> bakedFileAttributes(const SceneOutput& output,
                                                                     const BakeSettings& settings) {
  const MapKind map = settings.map;
  std::string encoding = "value";
  if (map == MapKind::kTangentNormal || map == MapKind::kObjectNormal || map == MapKind::kTangent ||
      map == MapKind::kBitangent) {
    encoding = "n/2+0.5";
  } else if (output.storesSignedRange()) {
    encoding = "value/(2*range)+0.5";
  }
  std::vector<std::pair<std::string, std::string>> attributes = {
      {"sgbake:map", std::string(mapKindName(map))},
      {"sgbake:encoding", encoding},
      {"sgbake:uv", std::to_string(settings.uvSet)},
      {"sgbake:udim_tile", std::to_string(settings.udimTile)},
      {"sgbake:version", sgbake_version()}};
  if (output.storesSignedRange())
    attributes.emplace_back("sgbake:range", formatNumber(output.range));
  if (map == MapKind::kTangentNormal || map == MapKind::kObjectNormal) {
    const bool tangentSpace = map == MapKind::kTangentNormal;
    const NormalSwizzle stored =
        storedChannels(settings.swizzle, tangentSpace ? settings.green : NormalMapGreen::kOpenGL);
    for (auto& attribute : normalChannelAttributes(stored, tangentSpace))
      attributes.push_back(std::move(attribute));
  }
  return attributes;
}

/// The largest finite |v| of the texels covered in the tiles @p tiles of a signed map: the first
/// pass of a `"range": "auto"` output, band by band as the bake itself (bakeMapRows, no halo).
Result<double> largestMagnitude(const BakeInput& input, const SceneOutput& output,
                                std::span<const int> tiles, int threads) {
  float largest = 0;
  for (const int tile : tiles) {
    const BakeSettings settings = plan_detail::bakeSettingsFor(output, tile, threads);
    const Status baked = bakeMapRows(input, settings, 0, [&](const MutableImageRows& rows) {
      const auto channels = static_cast<std::size_t>(rows.channels);
      for (int row = rows.begin; row < rows.end; ++row) {
        const float* pixels = rows.pixelRow(row);
        const float* coverage = rows.coverageRow(row);
        for (std::size_t x = 0; x < static_cast<std::size_t>(rows.width); ++x) {
          if (coverage[x] == 0) continue;
          for (std::size_t c = 0; c < channels; ++c) {
            const float magnitude = std::fabs(pixels[x * channels + c]);
            if (magnitude > largest && std::isfinite(magnitude)) largest = magnitude;
          }
        }
      }
      return Status{Ok{}};
    });
    if (!baked) return baked.error();
  }
  return static_cast<double>(largest);
}

/// Bakes one image tile into @p file and adds its timings to @p report. The image is baked band
/// by band into a small ring of rows (bakeMapRows), and each band's final rows are padded and
/// handed to an ImageFileWriter, so the file is compressed and written while the rest is baked
/// and the whole image never exists. Extend padding of a strip, done in the ring
/// (extendMarginRowsInPlace; a copy for signed maps, whose remapped values must not reach the
/// next strip), needs `margin` rows below it and above it: the rows above are kept in the ring,
/// and the last `margin` rows of each band wait for the next one. Push-pull and Adjacent Faces need
/// the whole image, which is then baked, padded and written in one piece. Masks are not padded
/// (padding would overwrite the coverage they show). The complete file is left under its temporary
/// name in
/// @p pending, renamed over @p file once every output of the run is written.
Status bakeImageTile(const BakeInput& input, const BakeSettings& settings,
                     const SceneOutput& output, const fs::path& file, ExecuteReport& report,
                     std::vector<AtomicFile>& pending) {
  using Clock = std::chrono::steady_clock;
  const int threads = settings.threads;
  ImageWriteOptions writeOptions;
  writeOptions.format = output.resolvedFormat();
  writeOptions.bitDepth = output.resolvedBitDepth();
  writeOptions.alpha = output.alpha;
  writeOptions.threads = threads;
  writeOptions.attributes = bakedFileAttributes(output, settings);
  Result<ImageFileWriter> writer = ImageFileWriter::open(file, settings.width, settings.height,
                                                        mapChannels(settings.map), writeOptions);
  if (!writer) return writer.error();

  const plan_detail::OutputPadding padding = plan_detail::outputPadding(output);
  // Extend rings padded band by band here; a whole-image padding is done before.
  const int margin = padding.wholeImage() ? 0 : padding.margin;
  const bool signedRange = output.storesSignedRange();
  int rowsWritten = 0;
  double padSeconds = 0, convertSeconds = 0;
  FloatImage window;  // padded rows and their halo, reused from strip to strip
  // Pads and queues the rows whose padding is final: all of them once the image is complete.
  auto writeFinalRows = [&](const MutableImageRows& rows) -> Status {
    const int ready = rows.end == rows.height ? rows.height : rows.end - margin;
    if (ready <= rowsWritten) return Ok{};
    const std::size_t rowTexels = static_cast<std::size_t>(rows.width);
    const std::size_t rowValues = rows.rowValues();
    Status ok = Ok{};
    if (signedRange) {  // from a padded and remapped copy of the rows
      Clock::time_point start = Clock::now();
      const auto first = static_cast<std::size_t>(
          extendMarginRows(rows, margin, rowsWritten, ready, window, threads));
      const auto count = static_cast<std::size_t>(ready - rowsWritten);
      padSeconds += secondsSince(start);
      start = Clock::now();
      const double scale = 0.5 / output.range;  // [−range, range] → [0, 1] for the integer file
      for (std::size_t i = first * rowValues; i < (first + count) * rowValues; ++i)
        window.pixels[i] = static_cast<float>(scale * window.pixels[i] + 0.5);
      ok = writer->writeRows(
          rowsWritten, ready - rowsWritten,
          std::span<const float>(window.pixels).subspan(first * rowValues, count * rowValues),
          std::span<const float>(window.coverage).subspan(first * rowTexels, count * rowTexels));
      convertSeconds += secondsSince(start);
    } else {  // padded in place, written run by run of rows contiguous in their ring
      Clock::time_point start = Clock::now();
      extendMarginRowsInPlace(rows, margin, rowsWritten, ready, threads);
      padSeconds += secondsSince(start);
      start = Clock::now();
      for (int row = rowsWritten; row < ready && ok;) {
        const int run = std::min(rows.contiguousRows(row), ready - row);
        const auto count = static_cast<std::size_t>(run);
        ok = writer->writeRows(row, run, {rows.pixelRow(row), count * rowValues},
                               {rows.coverageRow(row), count * rowTexels});
        row += run;
      }
      convertSeconds += secondsSince(start);
    }
    rowsWritten = ready;
    return ok;
  };

  const Clock::time_point start = Clock::now();
  if (padding.wholeImage()) {
    Result<FloatImage> image = bakeMap(input, settings);
    if (!image) return Error{image.error().code, file.string() + ": " + image.error().message};
    report.bakeSeconds += secondsSince(start);
    const Clock::time_point padStart = Clock::now();
    plan_detail::padImage(*image, padding, input, settings);
    padSeconds += secondsSince(padStart);
    if (Status ok = writeFinalRows(MutableImageRows::of(*image)); !ok) return ok;
  } else {
    // A strip's padding reads `margin` rows above it, which are `margin` rows above the last
    // rows written: 2·margin rows above the new band.
    bool writeFailed = false;
    const Status baked = bakeMapRows(input, settings, 2 * margin, [&](const MutableImageRows& rows) {
      Status ok = writeFinalRows(rows);
      writeFailed = !ok;
      return ok;
    });
    if (!baked) {
      if (writeFailed) return baked.error();  // the writer's errors name the file already
      return Error{baked.error().code, file.string() + ": " + baked.error().message};
    }
    report.bakeSeconds += secondsSince(start) - padSeconds - convertSeconds;
  }
  const double queueWaits = writer->waitSeconds();  // inside writeRows: the queue was full
  const Clock::time_point commitStart = Clock::now();
  Result<AtomicFile> written = writer->finish();
  if (!written) return written.error();
  pending.push_back(std::move(*written));
  if (const std::uint64_t clipped = writer->clippedValues(); clipped != 0) {
    const std::uint64_t values = static_cast<std::uint64_t>(settings.width) *
                                 static_cast<std::uint64_t>(settings.height) *
                                 static_cast<std::uint64_t>(mapChannels(settings.map));
    // With "range": "auto" only infinities and NaN lie beyond the range found.
    const std::string range =
        output.storesSignedRange() && output.rangeAuto
            ? "were infinite or NaN (a layer's scale or strength too large?) and were clamped "
              "to the range ±" +
                  formatNumber(output.range) + " (NaN to 0)"
        : output.storesSignedRange()
            ? "were beyond the stored range ±" + formatNumber(output.range) +
                  " and were clamped to it: a larger \"range\" (--range), \"range\": \"auto\" "
                  "(--range auto) or an EXR keeps them"
            : std::string();
    report.warnings.push_back(describeClippedValues(file, clipped, values, writeOptions.format,
                                                    writeOptions.bitDepth, range));
  }
  const double finalWait = writer->waitSeconds() - queueWaits;  // commit waiting for the queue
  const double closeSeconds = secondsSince(commitStart) - finalWait;
  report.padSeconds += padSeconds;
  report.convertSeconds += convertSeconds - queueWaits;
  report.writeSeconds += writer->fileSeconds() + closeSeconds;
  report.writeWaitSeconds += queueWaits + finalWait;
  return Ok{};
}

/// Creates the directory of @p file when it is missing.
/// Directories a run created, removed again (when still empty, deepest first) unless the run
/// succeeds: a failed bake leaves the file system as it found it.
class CreatedDirectories {
 public:
  CreatedDirectories() = default;
  CreatedDirectories(const CreatedDirectories&) = delete;
  CreatedDirectories& operator=(const CreatedDirectories&) = delete;
  ~CreatedDirectories() {
    std::error_code ec;
    for (auto dir = created_.rbegin(); dir != created_.rend(); ++dir) fs::remove(*dir, ec);
    forgetAll();  // only now: a signal while they are removed still finds them
  }
  /// The run succeeded: the directories stay.
  void keep() { forgetAll(); }
  /// Creates the directory of @p file and the missing ones above it, noting each.
  Status ensureFor(const fs::path& file) {
    const fs::path dir = file.parent_path();
    if (dir.empty()) return Ok{};
    std::error_code ec;
    if (fs::is_directory(dir, ec)) return Ok{};
    std::vector<fs::path> missing;  // dir and its missing ancestors, deepest first
    for (fs::path d = dir; !d.empty() && !fs::exists(d, ec); d = d.parent_path()) {
      missing.push_back(d);
      if (d == d.parent_path()) break;
    }
    for (auto d = missing.rbegin(); d != missing.rend(); ++d) {
      // Noted before it exists, so that a signal from the moment it is made removes it (and
      // forgotten when it was there already: someone else's).
      const int handle = trackCreatedDirectory(*d);
      if (fs::create_directory(*d, ec)) {
        created_.push_back(*d);
        tracked_.push_back(handle);
      } else {
        forgetCreatedDirectory(handle);
      }
      if (ec) {
        return Error::badInput(file.string() + ": cannot create directory " + d->string() + ": " +
                               ec.message());
      }
    }
    if (!fs::is_directory(dir, ec)) {
      return Error::badInput(file.string() + ": cannot create directory " + dir.string() + ": " +
                             (ec ? ec.message() : std::string("Not a directory")));
    }
    return Ok{};
  }

 private:
  /// Neither this object nor the signal handler removes them any more.
  void forgetAll() {
    created_.clear();
    for (const int handle : tracked_) forgetCreatedDirectory(handle);
    tracked_.clear();
  }

  std::vector<fs::path> created_;
  std::vector<int> tracked_;  ///< their trackCreatedDirectory handles (removed on a signal)
};

}  // namespace

Result<ExecuteReport> executePlan(const Plan& plan, const ExecuteOptions& options) {
  const Scene& s = plan.scene;
  ExecuteReport report;
  for (const PlannedOutput& output : plan.outputs) {
    OutputReport entry;
    entry.file = s.outputs[output.sceneOutput].file;
    report.outputs.push_back(std::move(entry));
  }
  if (plan.outputsToBake() == 0) return report;
  CreatedDirectories directories;  // removed again if the run fails

  bool readsOrWritesImages = !plan.images.empty();
  for (const PlannedOutput& output : plan.outputs) {
    if (!output.upToDate && s.outputs[output.sceneOutput].kind == OutputKind::kMap) {
      readsOrWritesImages = true;
    }
  }

  using Clock = std::chrono::steady_clock;
  ProgressReporter progress(options, 1 + plan.images.size() + (plan.computeTangents ? 1 : 0));
  Loaded loaded;

  // 1. Everything is loaded and checked before the first output is written.
  auto start = Clock::now();
  progress.start("loading " + s.mesh.string());
  // The mesh is parsed on a thread of its own while the images are decoded here: the two are
  // independent, and each is mostly serial. A bad mesh is still reported before a bad image.
  std::future<Status> meshLoad = std::async(std::launch::async, [&s, &loaded]() -> Status {
    LoadOptions meshOptions;
    meshOptions.requireUvs = true;
    Result<Mesh> mesh = loadMesh(s.mesh, meshOptions);
    if (!mesh) return mesh.error();
    return plan_detail::setSurface(s, std::move(*mesh), loaded);
  });
  // The image codec loads on a thread of its own while the mesh is parsed (image_io.hpp),
  // started after the mesh's thread: a thread created while dlopen runs can wait for the
  // dynamic loader's lock until the whole module is loaded (seen in 1 run of 10 of the Cycles
  // benchmark, the mesh then parsed during the image's decoding instead of beside the load).
  if (readsOrWritesImages) preloadImageIo();
  std::vector<std::string> imageWarnings;  // images are loaded here, on this thread
  const plan_detail::ImageSource imageFiles = [&imageWarnings](const PlannedImage& image) {
    LoadImageOptions imageOptions;
    imageOptions.channels = image.channels;
    imageOptions.warnings = &imageWarnings;
    return loadImage(image.path, imageOptions);
  };
  // With UDIM images the mesh comes first: only the tiles its UVs reach are loaded.
  const bool udim = std::any_of(plan.textures.begin(), plan.textures.end(),
                                [](const PlannedTexture& t) { return !t.udimTiles.empty(); });
  // The UDIM tiles each UV set touches, and its triangles in no tile: found once per set (a
  // pass over every triangle), for the tiles to load and for every output on the set.
  struct UvSetTiles {
    std::vector<int> tiles;
    std::size_t outside = 0;
  };
  // Sized once the mesh is loaded; the last entry stands for every set the mesh lacks (none).
  std::vector<std::optional<UvSetTiles>> tilesBySet;
  const auto uvSetTiles = [&](int uvSet) -> const UvSetTiles& {
    if (tilesBySet.empty()) tilesBySet.resize(loaded.mesh.uvSets.size() + 1);
    std::optional<UvSetTiles>& entry =
        tilesBySet[std::min(static_cast<std::size_t>(uvSet), tilesBySet.size() - 1)];
    if (!entry) {
      entry.emplace();
      entry->tiles = udimTiles(loaded.mesh, uvSet, &entry->outside);
    }
    return *entry;
  };
  std::optional<Status> mesh;
  std::vector<bool> load, reached;  // reached: flags by tile number
  if (udim) {
    mesh = meshLoad.get();
    if (!*mesh) return mesh->error();
    const bool cornerTable =
        std::any_of(plan.outputs.begin(), plan.outputs.end(), [&](const PlannedOutput& o) {
          return !o.upToDate && s.outputs[o.sceneOutput].kind == OutputKind::kCorners;
        });
    reached = plan_detail::reachedUdimTiles(
        loaded.mesh, [&](int uvSet) -> const std::vector<int>& { return uvSetTiles(uvSet).tiles; },
        cornerTable);
    // A tile every output to bake keeps (PlannedOutput::keptTiles) is not read: its image
    // tiles are not loaded.
    std::vector<bool> read = reached;
    for (std::size_t tile = 0; tile < read.size(); ++tile) {
      read[tile] =
          read[tile] &&
          std::any_of(plan.outputs.begin(), plan.outputs.end(), [&](const PlannedOutput& o) {
            return !o.upToDate && std::find(o.keptTiles.begin(), o.keptTiles.end(),
                                            static_cast<int>(tile)) == o.keptTiles.end();
          });
    }
    load = plan_detail::imagesToLoad(plan, read);
    // A tile the UVs reach without a file is read as no bump (documented), but is more often a
    // file forgotten or misnamed: said once per UDIM image and UV set.
    std::set<std::pair<std::size_t, int>> told;
    for (const PlannedLayer& layer : plan.layers) {
      const SceneLayer& scene = s.layers[layer.sceneLayer];
      const auto tell = [&](std::optional<std::size_t> t, int uvSet) {
        if (!t || plan.textures[*t].udimTiles.empty() || !told.insert({*t, uvSet}).second) return;
        const PlannedTexture& texture = plan.textures[*t];
        std::vector<std::string> missing;
        for (const int tile : uvSetTiles(uvSet).tiles) {
          if (!texture.udimTiles.contains(tile)) {
            missing.push_back(expandUdimToken(texture.udimImage.string(), tile));
          }
        }
        if (missing.empty()) return;
        report.warnings.push_back(texture.udimImage.string() + ": UV set " + std::to_string(uvSet) +
                                  " reaches tiles without a file (" + joinLabels(missing) +
                                  "): no bump there");
      };
      tell(layer.texture, scene.uvSet);
      if (scene.mask) tell(layer.mask, scene.mask->uvSet);
    }
  }
  std::set<int> reachedTiles;  // for the manifest
  for (int tile = kFirstUdimTile; tile < static_cast<int>(reached.size()); ++tile) {
    if (reached[static_cast<std::size_t>(tile)]) reachedTiles.insert(tile);
  }
  const Status textures =
      plan_detail::loadTextures(plan, imageFiles, loaded, progress, report, load);
  if (!mesh) mesh = meshLoad.get();
  if (!*mesh) return mesh->error();
  report.warnings.insert(report.warnings.end(), loaded.warnings.begin(), loaded.warnings.end());
  report.warnings.insert(report.warnings.end(), imageWarnings.begin(), imageWarnings.end());
  progress.finishOne();
  if (!textures) return textures.error();
  // Layers, and tangent frames if the plan needs them (timed apart from the loading).
  const std::size_t loadWarnings = loaded.warnings.size();
  if (Status ok = plan_detail::prepareLayers(plan, options.threads, loaded, progress, report); !ok) {
    return ok.error();
  }
  report.warnings.insert(report.warnings.end(),
                         loaded.warnings.begin() + static_cast<std::ptrdiff_t>(loadWarnings),
                         loaded.warnings.end());  // about the layers (layerMaterial)
  report.loadSeconds = secondsSince(start) - report.tangentsSeconds;

  // 2. The tiles of every output to bake (known now that the mesh is loaded).
  std::vector<std::vector<int>> tiles(plan.outputs.size());
  for (std::size_t o = 0; o < plan.outputs.size(); ++o) {
    const PlannedOutput& planned = plan.outputs[o];
    if (planned.upToDate) continue;
    const SceneOutput& output = s.outputs[planned.sceneOutput];
    if (output.kind == OutputKind::kCorners) {
      tiles[o] = {0};
    } else {
      // A map no UV triangle reaches holds only its background: said, not an error (a UV
      // set still being laid out, say).
      const std::vector<int>& touched = uvSetTiles(output.uvSet).tiles;
      const std::size_t outside = uvSetTiles(output.uvSet).outside;
      const std::string uvSet = "UV set " + std::to_string(output.uvSet);
      if (hasUdimToken(output.file.string())) {
        if (outside > 0 && !touched.empty()) {  // (none in a tile: said below)
          report.warnings.push_back(
              output.file.string() + ": " + std::to_string(outside) + " triangle(s) of " + uvSet +
              " lie outside UDIM tiles 1001 to 2000 (negative u or v, u ≥ 10 or v ≥ 100) and are "
              "not baked");
        }
        tiles[o] = touched.empty() ? std::vector<int>{kFirstUdimTile} : touched;
        if (touched.empty()) {
          report.warnings.push_back(output.file.string() + ": no triangle of " + uvSet +
                                    " with a non-zero UV area lies in a UDIM tile (1001 to "
                                    "2000); tile 1001 holds "
                                    "only the background");
        }
        // Tiles of an earlier bake the UVs no longer reach stay as they were: said, so that
        // a tool loading the whole set does not mix old tiles with new ones unawares.
        std::vector<std::string> stale;
        for (int tile = kFirstUdimTile; tile <= kLastUdimTile; ++tile) {
          std::error_code ec;
          if (!std::binary_search(tiles[o].begin(), tiles[o].end(), tile) &&
              fs::exists(tileFile(output, tile), ec)) {
            stale.push_back(std::to_string(tile));
          }
        }
        if (!stale.empty()) {
          report.warnings.push_back(output.file.string() + ": tile(s) " + joinLabels(stale) +
                                    " of an earlier bake are left as they were (no triangle of " +
                                    uvSet + " lies there now)");
        }
        // Tiles whose inputs and files are unchanged (PlannedOutput::keptTiles) stay.
        std::erase_if(tiles[o], [&](int tile) {
          const bool kept = std::find(planned.keptTiles.begin(), planned.keptTiles.end(), tile) !=
                            planned.keptTiles.end();
          if (kept) report.outputs[o].kept.push_back(tileFile(output, tile));
          return kept;
        });
      } else {
        tiles[o] = {output.tile};
        if (std::find(touched.begin(), touched.end(), output.tile) == touched.end()) {
          report.warnings.push_back(output.file.string() + ": no triangle of " + uvSet +
                                    " with a non-zero UV area lies in " +
                                    describeUdimTile(output.tile) +
                                    "; the map holds only the background");
        }
      }
    }
    progress.addWork(tiles[o].size());
  }

  // Every output directory (of every tile: "<UDIM>/n.png" has one per tile) must exist
  // (created here) and be writable before the long work.
  for (std::size_t o = 0; o < plan.outputs.size(); ++o) {
    if (plan.outputs[o].upToDate) continue;
    const SceneOutput& output = s.outputs[plan.outputs[o].sceneOutput];
    for (const int tile : tiles[o]) {
      const fs::path file = tileFile(output, tile);
      if (Status ok = directories.ensureFor(file); !ok) return ok.error();
      Result<AtomicFile> probe = AtomicFile::create(file);  // removed when it goes out of scope
      if (!probe) return probe.error();
    }
    if (plan.options.useManifest) {  // and so must its manifest
      Result<AtomicFile> probe = AtomicFile::create(directoryOf(output.file) / kManifestName);
      if (!probe) return probe.error();
    }
  }

  // 3. Bake, pad and write each output into a temporary file; they replace the outputs only
  // once all are written (a run that fails or is interrupted changes no output), then the
  // manifests record them.
  std::vector<AtomicFile> pending;
  std::vector<std::pair<fs::path, json>> manifestEntries;
  for (std::size_t o = 0; o < plan.outputs.size(); ++o) {
    const PlannedOutput& planned = plan.outputs[o];
    if (planned.upToDate) continue;
    const SceneOutput& output = s.outputs[planned.sceneOutput];
    const std::vector<Layer> layers = plan_detail::outputLayers(planned, loaded);
    OutputReport& outputReport = report.outputs[o];
    json files = json::object();
    for (const auto& [name, hash] : planned.keptFiles) files[name] = hash;
    // A "range": "auto" output is stored with one range for all its tiles, found first.
    SceneOutput stored = output;
    if (output.rangeAuto && output.storesSignedRange()) {
      start = Clock::now();
      progress.start("finding the range of " + output.file.string());
      Result<double> largest = largestMagnitude(plan_detail::bakeInputFor(loaded, layers), output,
                                                tiles[o], options.threads);
      if (!largest)
        return Error{largest.error().code, output.file.string() + ": " + largest.error().message};
      stored.range = roundRangeUp(*largest);
      outputReport.autoRange = stored.range;
      report.bakeSeconds += secondsSince(start);
    }

    for (const int tile : tiles[o]) {
      const fs::path file = tileFile(output, tile);
      progress.start("baking " + file.string());
      start = Clock::now();
      if (output.kind == OutputKind::kCorners) {
        CornerOptions cornerOptions;
        cornerOptions.threads = options.threads;
        if (loaded.world) cornerOptions.world = &*loaded.world;
        // Tangent-space layers decode with the loop triangles' frames, as in a baked map.
        std::array<CornerTangents, kMaxUvSets> cornerFrames;
        for (std::size_t set = 0; set < kMaxUvSets; ++set) {
          if (!loaded.triangleTangents[set]) continue;
          cornerFrames[set] =
              loopTriangleFramesAtCorners(loaded.mesh, *loaded.triangleTangents[set]);
          cornerOptions.layerTangents[set] = &cornerFrames[set];
        }
        Result<std::vector<CornerSample>> corners =
            evaluateCorners(loaded.mesh, layers, cornerOptions);
        if (!corners) {
          return Error{corners.error().code, s.mesh.string() + ": " + corners.error().message};
        }
        const std::string table = formatCornerTable(*corners);
        report.bakeSeconds += secondsSince(start);
        start = Clock::now();
        Result<AtomicFile> csv = AtomicFile::create(file);
        if (!csv) return csv.error();
        if (Status ok = csv->write(table); !ok) return ok.error();
        if (Status ok = csv->finish(); !ok) return ok.error();
        pending.push_back(std::move(*csv));
        report.writeSeconds += secondsSince(start);
      } else {
        const BakeInput input = plan_detail::bakeInputFor(loaded, layers);
        const BakeSettings settings = plan_detail::bakeSettingsFor(output, tile, options.threads);
        // One arena for the bake and the writer's tasks: writing takes turns with baking on
        // the `threads` threads instead of running beside them.
        Status baked = Ok{};
        bake_detail::runWithThreads(settings.threads, [&] {
          baked = bakeImageTile(input, settings, stored, file, report, pending);
        });
        if (!baked) return baked.error();
      }
      outputReport.files.push_back(file);
      for (const fs::path& stale : staleTemporaries(file)) {
        report.warnings.push_back(stale.string() +
                                  ": a temporary left by a run that was killed (its process is "
                                  "gone); remove it");
      }
      ++report.tilesBaked;
      start = Clock::now();
      if (plan.options.useManifest) {
        Result<std::string> hash = hashFile(pending.back().tempPath());
        if (!hash) return Error::internal(hash.error().message);
        files[manifestText(file.filename().string())] = *hash;
      }
      report.writeSeconds += secondsSince(start);
      progress.finishOne();
    }
    outputReport.baked = true;

    if (plan.options.useManifest) {
      start = Clock::now();
      // UDIM tiles no UV reaches are left out (whyBake): changing them changes no texel.
      // A UDIM tile's number is recorded too, for the day its file is gone (udimTilesToKeep).
      json inputs = json::object();
      json inputTiles = json::object();
      for (const auto& [path, hash] : planned.inputHashes) {
        const auto tile = planned.udimTileInputs.find(path);
        if (tile == planned.udimTileInputs.end()) {
          inputs[path] = hash;
        } else if (reachedTiles.contains(tile->second)) {
          inputs[path] = hash;
          inputTiles[path] = tile->second;
        }
      }
      json entry = {{"parameters", json::parse(planned.parameters)},
                    {"inputs", std::move(inputs)},
                    {"files", std::move(files)}};
      if (!planned.udimTileInputs.empty()) {
        entry["udim_reached"] = reachedTiles;
        entry["input_tiles"] = std::move(inputTiles);
      }
      manifestEntries.emplace_back(output.file, std::move(entry));
      report.writeSeconds += secondsSince(start);
    }
  }

  // 4. Every output is written: replace the files, then record them.
  start = Clock::now();
  for (AtomicFile& file : pending) {
    if (Status ok = file.commit(); !ok) return ok.error();
  }
  if (Status ok = recordInManifests(manifestEntries); !ok) return ok.error();
  report.writeSeconds += secondsSince(start);
  progress.finishAll();
  directories.keep();
  return report;
}

}  // namespace sgbake
