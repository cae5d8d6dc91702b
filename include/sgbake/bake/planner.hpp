/// @file planner.hpp
/// @brief From a Scene to files on disk: a Plan of exactly the work the outputs need, its
/// explanation (`sgbake bake --explain`), the manifest that makes re-runs incremental, and the
/// execution.
///
/// ## What the planner leaves out
/// - Tangent frames, unless an output map is expressed in them (tangent-normal, tangent,
///   bitangent) or a layer an output reads is a tangent-space normal map on UV set 0 (decoded in
///   the MikkTSpace frame). The corner table computes its own.
/// - Layers no output reads: weight 0; every layer for tangent, bitangent and mask maps (they
///   read none); layers without a height (normal maps) for height maps; everything read only by
///   outputs that are up to date.
/// - Images only those layers use. An image file read by several layers is loaded once per
///   channel selection (heights and masks: luminance; normal maps: RGB), and one texture is made
///   per (image, filter, wrap), whatever the number of layers using it.
/// - Outputs that are up to date (see the manifest), unless PlanOptions::force.
/// The kernels skip more on their own: texels outside the UV islands (background, then margin)
/// and triplanar planes whose blend weight is below the layer's min_weight. explainPlan lists
/// all of it under "skipped:".
///
/// ## The manifest
/// `.sgbake-manifest.json` in the directory of each output, one entry per output file name:
/// ```json
/// { "sgbake_manifest": 1,
///   "outputs": {
///     "n.png": { "parameters": { ...canonical parameters... },
///                "inputs": { "/abs/path/m.obj": "fnv1a64:89abcdef01234567", ... },
///                "files": { "n.png": "fnv1a64:0123456789abcdef" } } } }
/// ```
/// - "parameters": everything that determines the output besides file contents — the map and
///   its settings, the mesh's canonical path, the UV set, every layer it reads (with canonical
///   image paths), the subdivision block and the sgbake version — as JSON with sorted keys.
/// - "inputs": canonical path → 64-bit FNV-1a hash of the file's bytes, for the mesh and every
///   image the output reads.
/// - "files": the file name of each written file (one per UDIM tile for `<UDIM>` names) → hash
///   of its bytes as written.
/// An output is up to date when its entry exists, the parameters are equal, every input hash
/// matches the file now, and every written file still exists with the recorded hash. Entries of
/// other outputs in the same directory are kept. A manifest that cannot be read is ignored
/// (everything in that directory is re-baked) and rewritten.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "sgbake/bake/bake.hpp"
#include "sgbake/bake/scene.hpp"
#include "sgbake/core/result.hpp"
#include "sgbake/gradient/image.hpp"
#include "sgbake/mesh/mesh.hpp"

namespace sgbake {

/// File name of the manifest, written in each output directory.
inline constexpr const char* kManifestName = ".sgbake-manifest.json";

/// @brief 64-bit FNV-1a of @p bytes (offset basis 0xcbf29ce484222325, prime 0x100000001b3).
std::uint64_t fnv1a64(std::string_view bytes, std::uint64_t hash = 0xcbf29ce484222325ULL);

/// @brief "fnv1a64:" and the 16 lower-case hex digits of the FNV-1a hash of the file at @p path.
/// @return kBadInput naming the file when it cannot be read.
Result<std::string> hashFile(const std::filesystem::path& path);

/// @brief An image file to read, once.
struct PlannedImage {
  std::filesystem::path path;       ///< as the scene resolved it (for messages)
  std::filesystem::path canonical;  ///< weakly_canonical(path): with channels, the dedupe key
  ImageChannels channels =
      ImageChannels::kLuminance;  ///< kRgb (normal maps), kLuminance or one channel (heights)
  std::vector<std::string> users;                      ///< "layers[0]", "layers[2].mask", ...
};

/// @brief A texture made from a loaded image, shared by every layer with the same settings.
struct PlannedTexture {
  std::size_t image = 0;  ///< index into Plan::images
  bool vector = false;    ///< ImageVectorTexture (normal maps) or ImageScalarTexture
  Filter filter = Filter::kBilinear;
  Wrap wrap = Wrap::kRepeat;
  /// A UDIM image (`<UDIM>` in its name): tile number → index into Plan::textures of the tile's
  /// own texture; `image` is then unused. Empty for a single image.
  std::map<int, std::size_t> udimTiles;
  std::filesystem::path udimImage;  ///< the UDIM image's name, `<UDIM>` in it (for messages)
};

/// @brief A scene layer some output to bake reads.
struct PlannedLayer {
  std::size_t sceneLayer = 0;          ///< index into Scene::layers
  std::optional<std::size_t> texture;  ///< index into Plan::textures (image layers)
  std::optional<std::size_t> mask;     ///< index into Plan::textures (masked layers)
};

/// @brief One scene output.
struct PlannedOutput {
  std::size_t sceneOutput = 0;      ///< index into Scene::outputs
  bool upToDate = false;            ///< the manifest says nothing changed: not baked
  /// Why it is baked, for explainPlan, as a clause after "because" ("of --force", "/d/h_1001.png
  /// changed", "its parameters changed: \"layers\"", "it is not in /d/.sgbake-manifest.json
  /// yet", …); empty when up to date.
  std::string whyBake;
  std::vector<std::size_t> layers;  ///< indices into Plan::layers it reads, in scene order
  std::string parameters;           ///< canonical JSON of its parameters (manifest)
  /// The files it depends on (canonical path → hash): the mesh and its layers' images. Empty
  /// when the manifest is off.
  std::vector<std::pair<std::string, std::string>> inputHashes;
  /// Inputs that are tiles of UDIM images only (canonical path → tile number): the manifest
  /// records, and compares, only the tiles the mesh's UVs reach ("udim_reached"), so that a
  /// tile no UV reaches can be added, changed or removed without a re-bake.
  std::map<std::string, int> udimTileInputs;
  /// A UDIM output of which only some tiles changed (their UDIM image tiles, or their files
  /// since they were baked): the tiles baked before whose files stay as they are. Only when
  /// every layer reads the output's tile of its UDIM images (the same UV set, untiled,
  /// unshifted); empty: every tile the UV set touches is baked.
  std::vector<int> keptTiles;
  /// The manifest's records (file name → hash) of the kept tiles' files, carried over.
  std::vector<std::pair<std::string, std::string>> keptFiles;
};

/// @brief One line of the plan: what is done and why.
struct PlanStep {
  std::string what;
  std::string why;
};

/// @brief Options of makePlan.
struct PlanOptions {
  bool force = false;       ///< bake every output, up to date or not
  bool useManifest = true;  ///< read and write the manifest (false: always bake, write none)
  /// An in-memory scene's image names (the C ABI's sgbake_image::name): where a layer's
  /// "image" holds `<UDIM>`, the names with a tile number (1001 …) in its place are its tiles.
  std::set<std::string> imageNames = {};
};

/// @brief The work a scene needs, decided before any of it is done.
struct Plan {
  Scene scene;
  PlanOptions options;
  bool loadMesh = false;         ///< false when every output is up to date
  bool computeTangents = false;  ///< MikkTSpace frames of UV set 0 for the baker
  std::vector<PlannedImage> images;
  std::vector<PlannedTexture> textures;
  std::vector<PlannedLayer> layers;
  std::vector<PlannedOutput> outputs;  ///< one per scene output, in scene order
  std::vector<PlanStep> steps;         ///< in execution order
  std::vector<PlanStep> skipped;       ///< work left out, and why
  /// What the user may not expect, one line each (e.g. a manifest that is not valid JSON and
  /// will be replaced)
  std::vector<std::string> warnings;
  double planSeconds = 0;              ///< time makePlan took (mostly hashing files)

  /// @brief Number of outputs that will be baked.
  std::size_t outputsToBake() const;
};

/// @brief Plans @p scene: checks that the files it reads exist, decides what each output reads,
/// and (with the manifest) which outputs are up to date. An in-memory scene (Scene::inMemory)
/// has no files: nothing is checked on disk and the manifest is never used.
/// @return kBadInput for a missing mesh or image (naming the file and the layer), or a scene
/// validateScene rejects.
Result<Plan> makePlan(Scene scene, const PlanOptions& options = {});

/// @brief The plan as text: a header, one numbered line per step (what: why), and a "skipped:"
/// list with reasons. Every line ends with '\n'.
std::string explainPlan(const Plan& plan);

/// @brief Progress of executePlan: @p done of @p total units of work are finished, and the
/// one that starts now is @p what.
struct BakeProgress {
  std::size_t done = 0;
  std::size_t total = 0;
  std::string_view what;
};

/// @brief Options of executePlan.
struct ExecuteOptions {
  int threads = 0;  ///< maximum threads of every kernel; 0 = all cores
  /// Called before each unit of work (loading, tangents, each output tile) and once at the end
  /// with done == total; may be empty.
  std::function<void(const BakeProgress&)> progress;
};

/// @brief What happened to one output.
struct OutputReport {
  std::filesystem::path file;                ///< the scene's file name (may contain `<UDIM>`)
  bool baked = false;                        ///< false: up to date, not touched
  std::vector<std::filesystem::path> files;  ///< files written (one per UDIM tile)
  /// UDIM tile files left as they were, their inputs unchanged (PlannedOutput::keptTiles)
  std::vector<std::filesystem::path> kept;
  /// The range a `"range": "auto"` output was stored with (0: none was chosen)
  double autoRange = 0;
};

/// @brief The range a `"range": "auto"` output is stored with when the largest |v| of its
/// covered texels is @p largest: @p largest rounded up to 3 significant digits, so that the
/// number a file records ("sgbake:range") is short and every value fits; 1 when @p largest is 0
/// (or not a positive finite number).
double roundRangeUp(double largest);

/// @brief Timings (seconds) and counts of an execution.
struct ExecuteReport {
  std::vector<OutputReport> outputs;  ///< one per scene output, in scene order
  /// What the user may not expect, in one line each (e.g. a map no UV triangle reaches)
  std::vector<std::string> warnings;
  std::size_t imagesLoaded = 0;
  std::size_t texturesCreated = 0;
  bool tangentsComputed = false;
  std::size_t tilesBaked = 0;
  double loadSeconds = 0;      ///< mesh, images, textures, volumes
  double tangentsSeconds = 0;  ///< MikkTSpace frames
  double bakeSeconds = 0;      ///< bakeMap and the corner table
  double padSeconds = 0;       ///< margins
  double convertSeconds = 0;   ///< converting pixels to the files' types
  /// Image files inside OpenImageIO (compressing, writing; between the bake's tasks, while the
  /// next rows are baked), CSV files, output hashes, manifests
  double writeSeconds = 0;
  /// The part of the image writing the bake waited for (not overlapped with baking)
  double writeWaitSeconds = 0;
};

/// @brief Runs @p plan: loads the mesh (it must have UVs) and images, computes tangents if
/// needed, bakes each output that is not up to date (every UDIM tile of a `<UDIM>` file name,
/// else its tile), pads it, writes it all or nothing, and records it in the manifest. An image
/// is padded and written strip by strip while its lower rows are still baked (push-pull
/// padding, which needs the whole image, waits for the bake).
///
/// Everything is loaded and checked before the first file is written, so bad input (an
/// unreadable image, a mesh without UVs or without a UV set an output or layer names) leaves
/// every output untouched. Output directories are created when missing.
Result<ExecuteReport> executePlan(const Plan& plan, const ExecuteOptions& options = {});

/// @brief What an in-memory plan bakes from instead of files (bakeOutputInMemory).
struct MemoryInputs {
  /// The mesh, before the scene's subdivision. It must have the UV sets the scene uses.
  const Mesh* mesh = nullptr;
  /// The image a scene's "image" key names (PlannedImage::path), with the plan's channels
  /// (PlannedImage::channels); kBadInput naming it when there is none.
  std::function<Result<Image>(const PlannedImage& image)> image;
};

/// @brief Bakes output @p output of a plan of an in-memory scene (SceneParseOptions::inMemory)
/// and pads it as executePlan pads a file, without writing anything.
///
/// The planner's decisions hold as for files: only the layers the output reads are built, and
/// tangent frames only when the output or a layer needs them. The result is the one a float
/// file of the same output holds (executePlan and this give the same values): rows top first,
/// normal maps encoded, signed maps raw (no "range" remapping).
/// @param[in] threads maximum threads; 0 = all cores (the result does not depend on it)
/// @param[in] progress called as the bake goes (bakeMap's BakeProgressCallback); may stop it
/// @return the image, or kBadInput for a missing image, a UV set the mesh lacks, a bad layer;
/// kCancelled when @p progress stopped the bake
Result<FloatImage> bakeOutputInMemory(const Plan& plan, std::size_t output,
                                      const MemoryInputs& inputs, int threads = 0,
                                      const BakeProgressCallback& progress = {});

}  // namespace sgbake
