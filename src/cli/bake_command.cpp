/// @file bake_command.cpp
/// @brief `sgbake bake SCENE.json` (or the one-map shorthand `sgbake bake --mesh M.obj ... -o
/// OUT`): plans the scene, explains or runs the plan, reports progress and timings.
#include <sys/ioctl.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli.hpp"
#include "sgbake/bake/image_output.hpp"
#include "sgbake/bake/planner.hpp"
#include "sgbake/bake/scene.hpp"
#include "sgbake/gradient/remap.hpp"

namespace sgbake::cli {
namespace {

/// The command line of `sgbake bake`, as CLI11 fills it in.
struct BakeArguments {
  std::string scene;   ///< SCENE.json ("" in the one-map form)
  std::string outDir;  ///< --out-dir
  bool explain = false;
  bool force = false;
  bool noManifest = false;
  int threads = 0;
  bool stats = false;

  // One-map form.
  std::string mesh;
  std::string output;
  std::string map = "tangent-normal";
  int size = kDefaultOutputSize;
  int margin = kDefaultMargin;
  std::string padding = "extend";
  int samples = 1;
  int uvSet = 0;
  std::string green = "opengl";
  std::string swizzle;  ///< empty: +X+Y+Z
  std::string heightImage;
  double heightScale = 1;
  std::string filter = "bilinear";
  std::string heightGradient = "analytic";
  std::string heightSpace = "world";
  std::string heightRemap;  ///< "X:Y,X:Y,…": the points of the height's remap
  std::string normalImage;
  std::string normalSpace = "tangent";
  std::string normalGreen = "opengl";
  int bitDepth = 0;
  bool alpha = false;
  std::optional<std::string> range;  ///< a number, or "auto"
  SubdivisionOptions subdivision;  ///< level 0: none
  bool limitSurface = false;       ///< --subdivide limit
  std::string transform;           ///< --transform: matrix_world, row by row
};

constexpr const char* kFooter =
    "Scene file (JSON; relative paths are relative to the scene file):\n"
    "  { \"mesh\": \"m.obj\", \"uv\": 0,\n"
    "    \"subdivision\": {\"level\": 2 (or \"limit\"), \"uv_smooth\": \"keep-boundaries\", "
    "\"boundary\": \"all\",\n"
    "                    \"use_creases\": true, \"edge_creases\": [[A, B, C], ...], "
    "\"vertex_creases\": [[V, C], ...],\n"
    "                    \"quality\": 3, \"use_limit_surface\": true, \"type\": "
    "\"catmull-clark\", \"auto_smooth\": 30,\n"
    "                    \"sharp_edges\": [[A, B], ...]},\n"
    "    \"transform\": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]],\n"
    "    \"layers\": [\n"
    "      {\"type\": \"height\", \"image\": \"h.png\", \"scale\": 0.1, \"filter\": \"bicubic\"},\n"
    "      {\"type\": \"normal\", \"image\": \"n.png\", \"space\": \"tangent\", \"green\": "
    "\"opengl\"},\n"
    "      {\"type\": \"volume\", \"function\": \"noise\", \"amplitude\": 0.01, \"frequency\": "
    "8},\n"
    "      {\"type\": \"triplanar\", \"image\": \"t.png\", \"kind\": \"height\", \"scale\": "
    "0.05}],\n"
    "    \"outputs\": [\n"
    "      {\"map\": \"tangent-normal\", \"file\": \"out/n.png\", \"size\": 2048, \"margin\": 16}] "
    "}\n"
    "  Layer keys (all layers: type, name, weight = 1, mask = IMAGE or {image, uv, tiling,\n"
    "  offset, filter}, material = INDEX or OBJ usemtl NAME: that material's faces only):\n"
    "    height     image, uv, scale = 1, strength = 1 (Blender's Bump Strength: a blend of\n"
    "               normals), channel = luminance|r|g|b|a (one channel: a packed height),\n"
    "               filter = bilinear|bicubic|hermite, wrap = repeat|clamp,\n"
    "               tiling = 1 (number or [s, t]), offset = [0, 0],\n"
    "               gradient = analytic|bump-node (bump-node: slopes as Blender's Bump\n"
    "               node takes them when Cycles bakes, differences half a texel apart)\n"
    "    normal     image, uv, space = tangent|object, green = opengl|directx, strength = 1,\n"
    "               filter = bilinear|bicubic, wrap, tiling, offset, tangent_uv (tangent\n"
    "               space: the UV set whose tangents decode it, if not uv)\n"
    "    volume     function = sine|noise|blender-noise|blender-musgrave|blender-wave|\n"
    "               blender-voronoi|blender-brick|blender-gradient|blender-magic,\n"
    "               amplitude = 1,\n"
    "               frequency = 1, direction = [1,0,0] and phase = 0 (sine), seed = 0 and\n"
    "               octaves = 1 (noise); blender-noise is Blender's Noise Texture (3D):\n"
    "               frequency its Scale (default 5), detail = 2, roughness = 0.5,\n"
    "               distortion = 0; blender-musgrave is Blender's Musgrave Texture (3D):\n"
    "               frequency its Scale (default 5), musgrave_type = fbm|multifractal|\n"
    "               ridged-multifractal|hybrid-multifractal|hetero-terrain, detail = 2,\n"
    "               dimension = 2, lacunarity = 2, offset = 0 (ridged, hybrid, hetero),\n"
    "               gain = 1 (ridged, hybrid); blender-wave is Blender's Wave Texture:\n"
    "               frequency its Scale (default 5), wave = bands|rings, wave_direction =\n"
    "               x|y|z|diagonal|spherical, profile = sine|saw|triangle, phase = 0,\n"
    "               distortion = 0, detail = 2, detail_scale = 1, detail_roughness = 0.5;\n"
    "               blender-voronoi is Blender's Voronoi Texture (3D, its Distance):\n"
    "               frequency its Scale (default 5), feature = f1|f2|smooth-f1|\n"
    "               distance-to-edge, smoothness = 1 (smooth-f1), randomness = 1, metric =\n"
    "               euclidean|manhattan|chebyshev|minkowski (not distance-to-edge),\n"
    "               exponent = 0.5; blender-brick is Blender's Brick Texture's Fac (the\n"
    "               mortar): frequency its Scale (default 5), mortar_size = 0.02,\n"
    "               mortar_smooth = 0.1, brick_width = 0.5, row_height = 0.25, brick_offset =\n"
    "               0.5, offset_frequency = 2, squash = 1, squash_frequency = 2;\n"
    "               blender-gradient is Blender's Gradient Texture's Fac: gradient_type =\n"
    "               linear|quadratic|easing|diagonal|spherical|quadratic-sphere|radial (no\n"
    "               frequency: the node has no Scale); blender-magic is Blender's Magic\n"
    "               Texture's Fac (its Color's mean): frequency its Scale (default 5),\n"
    "               depth = 2 (0 to 10), distortion = 1; all seven take\n"
    "               mapping (as planar's: the object coordinates mapped first);\n"
    "               coordinates = object|uv (uv: read at (u, v, 0) of the set uv, as a\n"
    "               texture on Blender's Texture Coordinate UV; mapped first too);\n"
    "               gradient = analytic|central|tetrahedral|bump-node (uv: analytic or\n"
    "               bump-node), step (default 2^-20 of the mesh size)\n"
    "    planar     image, kind = height|tangent-normal|object-normal, axis = x|y|z, scale = 1,\n"
    "               tiling, offset, filter, wrap, green, projection = axis|flat|sphere|tube\n"
    "               (Blender's Image Texture projections: flat the (x, y) plane, sphere and\n"
    "               tube wrapped around z of 2 (P - 0.5); tangent-normal decodes in the frames\n"
    "               of tangent_uv, else uv)\n"
    "    triplanar  image, kind, scale = 1, tiling, offset, filter, wrap, green,\n"
    "               projection = blended|box; blended: sharpness = 4, min_weight = 0.001;\n"
    "               box (Blender's Image Texture Box projection; tangent-normal decodes in\n"
    "               the frames of tangent_uv, else uv): box_blend = 0 (Blender's Blend)\n"
    "    planar and triplanar take mapping = {type = point|texture|vector, location,\n"
    "               rotation (radians, XYZ Euler), scale, matrix}: Blender's Mapping node\n"
    "               between the object coordinates and the projection; matrix (3 rows of 4)\n"
    "               maps them first (another object's coordinates, Generated)\n"
    "  Heights (height, volume, planar and triplanar of kind height) take strength = 1 (the\n"
    "  Bump node's), gradient = bump-node (slopes as Cycles' Bump node takes them when it\n"
    "  bakes), height_space = world|object (object: the scale in object units along the\n"
    "  normal, as a Displacement node's in Object space), remap = [[x, y], ...] (the value read\n"
    "  through the piecewise-linear function through these points, constant beyond the ends,\n"
    "  a repeated x a step: levels, clamps, a Color Ramp as Cycles tabulates it) and base =\n"
    "  surface|above: 'above' bumps the normal the layers before it make, as a Bump node whose\n"
    "  Normal input is linked to the node before it (a Normal Map, another Bump); 'surface'\n"
    "  (the default) adds the layer's surface gradient to the others'.\n"
    "  A height, normal or mask image named with '<UDIM>' (h.<UDIM>.exr) reads tile 1001 + u +\n"
    "  10 v where the UVs lie in [u, u+1) x [v, v+1); no tiling or offset; no bump where the\n"
    "  UVs reach no tile file (a warning names the missing files).\n"
    "  Output keys: map (tangent-normal, object-normal, height, derivative, surface-gradient,\n"
    "    tangent, bitangent, mask, or corners for the per-corner CSV table), file (.png, .exr,\n"
    "    .tif; '<UDIM>' in the name bakes every UDIM tile the UV set touches),\n"
    "    size = 1024 (or width and height), margin = 16,\n"
    "    padding = extend|adjacent-faces|push-pull,\n"
    "    samples = 1 (N x N per texel), uv, green = opengl|directx, swizzle = \"+X+Y+Z\"\n"
    "    (normal maps' channels as Blender's bake Swizzle; not with green), tile = 1001,\n"
    "    format = png|exr|tiff, bit_depth = 8|16|32 (default 16; 8 for masks in PNG/TIFF),\n"
    "    alpha = false (coverage as alpha), range = 1 (derivative and surface-gradient maps\n"
    "    in PNG/TIFF integers store v / (2 range) + 0.5; EXR and float TIFF store v;\n"
    "    \"auto\": the largest |v| of the map, rounded up, found by a first pass).\n"
    "  transform: the object's matrix_world (4 rows of 4, or 3 of 3). Unless its 3 x 3 part is\n"
    "    the identity, maps of normals and gradients are shaded in world space as Cycles\n"
    "    shades the placed object: height scales are world distances (a Bump node's\n"
    "    Distance), normal maps are carried to world space as normals, and the result comes\n"
    "    back as Blender's baker brings it (object-space maps through the inverse matrix).\n"
    "  Unknown keys are errors; keys starting with '_' are comments.\n"
    "\n"
    "Incremental:\n"
    "  Each output directory gets a .sgbake-manifest.json with hashes of the inputs, the\n"
    "  parameters and the written files. A re-run bakes only outputs whose inputs, parameters\n"
    "  or files changed (the others print 'up to date'); --force bakes everything.\n"
    "  Files are replaced only once complete: a failed run never leaves partial files.\n"
    "\n"
    "Examples:\n"
    "  sgbake bake meshes/default_scene.json --out-dir out\n"
    "  sgbake bake scene.json --explain\n"
    "  sgbake bake scene.json --force --threads 4 --stats\n"
    "  sgbake bake --mesh suzanne.obj --height bumps.png --height-scale 0.05 \\\n"
    "              --map tangent-normal --size 2048 -o suzanne_normal.png\n"
    "  sgbake bake --mesh m.obj --normal n_os.png --normal-space object --map tangent-normal \\\n"
    "              --size 1024 --margin 0 -o n_ts.exr\n"
    "\n";

/// Options of the one-map form: any of them set means the one-map form.
const char* const kOneMapOptions[] = {"--mesh",
                                      "--output",
                                      "--map",
                                      "--size",
                                      "--margin",
                                      "--padding",
                                      "--samples",
                                      "--uv",
                                      "--green",
                                      "--swizzle",
                                      "--height",
                                      "--height-scale",
                                      "--filter",
                                      "--height-gradient",
                                      "--height-space",
                                      "--height-remap",
                                      "--normal",
                                      "--normal-space",
                                      "--normal-green",
                                      "--bit-depth",
                                      "--alpha",
                                      "--range",
                                      "--subdivide",
                                      "--uv-smooth",
                                      "--boundary-smooth",
                                      "--edge-crease",
                                      "--vertex-crease",
                                      "--no-creases",
                                      "--subdivision-quality",
                                      "--no-limit-surface",
                                      "--subdivision-type",
                                      "--auto-smooth",
                                      "--sharp-edge",
                                      "--transform"};

// ---- Progress bar ------------------------------------------------------------------------------

/// A one-line progress bar on standard error, shown only when standard error is a terminal and
/// the work has lasted longer than kDelay; redrawn by a ticker thread (a single bake gives no
/// intermediate progress, so the elapsed time keeps moving). Cleared when done.
class ProgressBar {
 public:
  static constexpr std::chrono::milliseconds kDelay{500};
  static constexpr std::chrono::milliseconds kTick{100};

  ProgressBar() : enabled_(::isatty(STDERR_FILENO) == 1) {
    if (enabled_) ticker_ = std::thread([this] { run(); });
  }
  ProgressBar(const ProgressBar&) = delete;
  ProgressBar& operator=(const ProgressBar&) = delete;
  ~ProgressBar() { stop(); }

  /// The callback for ExecuteOptions::progress.
  void update(const BakeProgress& progress) {
    if (!enabled_) return;
    const std::lock_guard<std::mutex> lock(mutex_);
    done_ = progress.done;
    total_ = progress.total;
    what_ = std::string(progress.what);
  }

  /// Stops the ticker and erases the bar (idempotent).
  void stop() {
    if (!ticker_.joinable()) return;
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      stopping_ = true;
    }
    wake_.notify_all();
    ticker_.join();
    if (shown_) std::fputs("\r\033[K", stderr);
    std::fflush(stderr);
  }

 private:
  void run() {
    std::unique_lock<std::mutex> lock(mutex_);
    while (!wake_.wait_for(lock, kTick, [this] { return stopping_; })) {
      if (std::chrono::steady_clock::now() - start_ < kDelay) continue;
      draw();
    }
  }

  /// Draws the bar; called with mutex_ held.
  void draw() {
    constexpr int kBarWidth = 24;
    static const char kSpinner[] = "|/-\\";
    int columns = 80;
    winsize size{};
    if (::ioctl(STDERR_FILENO, TIOCGWINSZ, &size) == 0 && size.ws_col > 20) columns = size.ws_col;
    const double fraction =
        total_ == 0 ? 0.0 : static_cast<double>(done_) / static_cast<double>(total_);
    const int filled = static_cast<int>(fraction * kBarWidth);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    char head[128];
    std::snprintf(head, sizeof head, "\r[%-*s] %zu/%zu %c %.1fs ", kBarWidth,
                  std::string(static_cast<std::size_t>(filled), '#').c_str(), done_, total_,
                  kSpinner[ticks_++ % 4], seconds);
    std::string line = head + what_;
    const auto maxChars = static_cast<std::size_t>(columns - 1) + 1;  // +1 for the '\r'
    if (line.size() > maxChars) line.resize(maxChars);
    line += "\033[K";
    std::fputs(line.c_str(), stderr);
    std::fflush(stderr);
    shown_ = true;
  }

  const bool enabled_;
  const std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
  std::mutex mutex_;
  std::condition_variable wake_;
  std::thread ticker_;
  bool stopping_ = false;
  bool shown_ = false;
  std::size_t done_ = 0, total_ = 0, ticks_ = 0;
  std::string what_;
};

// ---- The command -------------------------------------------------------------------------------

/// @p message (about the scene oneMapScene builds) in the words of the one-map flags: the scene's
/// "outputs[0]: bit_depth 8 …" is "--bit-depth 8 …", "layers[0]: scale …" is
/// "--height-scale …", and the layers and the output are named by their flags.
std::string inFlagWords(std::string message, const BakeArguments& args) {
  const auto replaceAll = [&message](const std::string& from, const std::string& to) {
    for (std::size_t at = message.find(from); at != std::string::npos;
         at = message.find(from, at + to.size())) {
      message.replace(at, from.size(), to);
    }
  };
  // The layers in the order oneMapScene adds them.
  std::vector<std::pair<std::string, std::string>> layers;  // flag, the flag of its scale
  if (!args.heightImage.empty()) layers.emplace_back("--height", "--height-scale");
  if (!args.normalImage.empty()) layers.emplace_back("--normal", "--normal");
  for (std::size_t l = 0; l < layers.size(); ++l) {
    const std::string label = "layers[" + std::to_string(l) + "]";
    replaceAll(label + ": scale ", layers[l].second + " ");
    replaceAll(label + ": filter ", "--filter ");
    replaceAll(label + ": ", layers[l].first + ": ");
    replaceAll(label, "the " + layers[l].first + " image");
  }
  for (const auto& [key, flag] : {std::pair<const char*, const char*>{"bit_depth", "--bit-depth"},
                                  {"size", "--size"},
                                  {"margin", "--margin"},
                                  {"samples", "--samples"},
                                  {"uv", "--uv"},
                                  {"range", "--range"},
                                  {"file", "-o"}}) {
    replaceAll(std::string("outputs[0]: ") + key + " ", std::string(flag) + " ");
  }
  replaceAll("outputs[0]: ", "-o " + args.output + ": ");
  replaceAll("outputs[0]", "the map (-o " + args.output + ")");
  return message;
}

/// The scene of the one-map form: one output and the layers its options name.
/// The points of --height-remap "X:Y,X:Y,…", checked as a HeightRemap checks them.
Result<std::vector<Vec2d>> parseRemapPoints(const std::string& text) {
  const std::string where = "bake: --height-remap: ";
  std::vector<Vec2d> points;
  std::size_t i = 0;
  while (i <= text.size()) {
    const std::size_t end = std::min(text.find(',', i), text.size());
    const std::string pair = text.substr(i, end - i);
    const std::size_t colon = pair.find(':');
    const std::optional<double> x =
        colon == std::string::npos ? std::nullopt : parseFiniteNumber(pair.substr(0, colon));
    const std::optional<double> y =
        colon == std::string::npos ? std::nullopt : parseFiniteNumber(pair.substr(colon + 1));
    if (!x || !y) return Error::badInput(where + "'" + pair + "' is not X:Y (two finite numbers)");
    points.push_back({*x, *y});
    i = end + 1;
  }
  if (Result<HeightRemap> remap = HeightRemap::create(points); !remap) {
    return Error::badInput(where + remap.error().message);
  }
  return points;
}

Result<Scene> oneMapScene(const BakeArguments& args) {
  if (args.mesh.empty()) return Error::badInput("bake: --mesh is required without a SCENE file");
  if (args.output.empty()) return Error::badInput("bake: -o/--output is required with --mesh");
  const auto parseName = [](const std::string& option, const std::string& value,
                            std::initializer_list<const char*> names) -> Status {
    for (const char* name : names) {
      if (value == name) return Ok{};
    }
    std::vector<std::string> list(names.begin(), names.end());
    std::string message = "bake: " + option + ": unknown value '" + value + "'";
    const std::string suggestion = closestMatch(value, list);
    message += suggestion.empty() ? " (expected " : " (did you mean '" + suggestion + "'?; ";
    if (!suggestion.empty()) message += "expected ";
    for (std::size_t i = 0; i < list.size(); ++i) message += (i ? ", " : "") + list[i];
    return Error::badInput(message + ")");
  };

  Scene scene;
  scene.mesh = args.mesh;
  scene.uvSet = args.uvSet;
  scene.subdivision = SceneSubdivision::of(args.subdivision, args.limitSurface);
  if (!args.heightImage.empty()) {
    if (Status ok = parseName("--filter", args.filter, {"bilinear", "bicubic", "hermite"}); !ok) {
      return ok.error();
    }
    if (Status ok = parseName("--height-gradient", args.heightGradient, {"analytic", "bump-node"});
        !ok) {
      return ok.error();
    }
    if (Status ok = parseName("--height-space", args.heightSpace, {"world", "object"}); !ok) {
      return ok.error();
    }
    SceneLayer height;
    height.type = SceneLayerType::kHeight;
    height.objectSpaceHeight = args.heightSpace == "object";
    if (!args.heightRemap.empty()) {
      Result<std::vector<Vec2d>> points = parseRemapPoints(args.heightRemap);
      if (!points) return points.error();
      height.remap = std::move(*points);
    }
    height.heightGradient =
        args.heightGradient == "bump-node" ? HeightGradient::kBumpNode : HeightGradient::kAnalytic;
    height.image = args.heightImage;
    height.scale = args.heightScale;
    height.uvSet = args.uvSet;
    height.filter = args.filter == "bicubic"   ? Filter::kBicubic
                    : args.filter == "hermite" ? Filter::kHermite
                                               : Filter::kBilinear;
    scene.layers.push_back(height);
  }
  if (!args.normalImage.empty()) {
    if (Status ok = parseName("--normal-space", args.normalSpace, {"tangent", "object"}); !ok) {
      return ok.error();
    }
    if (Status ok = parseName("--normal-green", args.normalGreen, {"opengl", "directx"}); !ok) {
      return ok.error();
    }
    SceneLayer normal;
    normal.type = SceneLayerType::kNormal;
    normal.image = args.normalImage;
    normal.uvSet = args.uvSet;
    normal.space = args.normalSpace == "object" ? NormalSpace::kObject : NormalSpace::kTangent;
    normal.green =
        args.normalGreen == "directx" ? NormalMapGreen::kDirectX : NormalMapGreen::kOpenGL;
    normal.filter = args.filter == "bicubic" ? Filter::kBicubic : Filter::kBilinear;
    scene.layers.push_back(normal);
  }

  SceneOutput output;
  output.file = args.output;
  if (args.map == "corners") {
    output.kind = OutputKind::kCorners;
  } else {
    Result<MapKind> map = parseMapKind(args.map);
    if (!map) return Error::badInput("bake: --map: " + map.error().message);
    output.map = *map;
    Result<ImageFormat> format = imageFormatFromPath(output.file);
    if (!format) return Error::badInput("bake: -o: " + format.error().message);
  }
  if (Status ok = parseName("--padding", args.padding, {"extend", "adjacent-faces", "push-pull"});
      !ok) {
    return ok.error();
  }
  if (Status ok = parseName("--green", args.green, {"opengl", "directx"}); !ok) return ok.error();
  output.width = output.height = args.size;
  output.margin = args.margin;
  output.padding = *parsePaddingMode(args.padding);  // (a name parseName accepted)
  output.samples = args.samples;
  output.uvSet = args.uvSet;
  output.green = args.green == "directx" ? NormalMapGreen::kDirectX : NormalMapGreen::kOpenGL;
  if (!args.swizzle.empty()) {
    Result<NormalSwizzle> swizzle = parseNormalSwizzle(args.swizzle);
    if (!swizzle) return Error::badInput("bake: --swizzle: " + swizzle.error().message);
    output.swizzle = *swizzle;
  }
  output.bitDepth = args.bitDepth;
  output.alpha = args.alpha;
  if (args.range) {
    if (!isSignedMap(output.map)) {
      return Error::badInput("bake: --range applies only to derivative and surface-gradient maps");
    }
    if (!output.storesSignedRange()) {
      return Error::badInput(
          "bake: --range applies to integer files (PNG, 8- and 16-bit TIFF); -o " + args.output +
          " stores the values themselves");
    }
    if (*args.range == "auto") {
      output.rangeAuto = true;
    } else {
      const std::optional<double> range = parseFiniteNumber(*args.range);
      if (!range || !(*range > 0)) {
        return Error::badInput("bake: --range " + *args.range +
                               " must be a positive number or 'auto'");
      }
      output.range = *range;
    }
  }
  scene.outputs.push_back(output);
  Result<std::optional<ObjectTransform>> transform = parseTransformOption("bake", args.transform);
  if (!transform) return transform.error();
  scene.transform = *transform;
  if (Status valid = validateScene(scene); !valid) {
    return Error::badInput("bake: " + valid.error().message);
  }
  return scene;
}

/// Prints what happened to each output on standard output.
Status printOutcome(const ExecuteReport& report) {
  std::string text;
  for (const OutputReport& output : report.outputs) {
    if (!output.baked) {
      text += "up to date: " + output.file.string() + "\n";
      continue;
    }
    // The range "range": "auto" chose: what a shader decoding the files needs.
    std::string range;
    if (output.autoRange > 0) {
      char number[32];
      std::snprintf(number, sizeof number, "%g", output.autoRange);
      range = std::string(" (range ±") + number + ")";
    }
    for (const std::filesystem::path& file : output.files) {
      text += "wrote " + file.string() + range + "\n";
    }
    for (const std::filesystem::path& file : output.kept) {
      text += "up to date: " + file.string() + "\n";
    }
  }
  return writeStandardOutput(text);
}

Status runBake(const BakeArguments& args, const CLI::App& app) {
  Stopwatch total;
  const ThreadLimit threadLimit(args.threads);

  bool oneMap = false;
  for (const char* option : kOneMapOptions) {
    if (app.count(option) > 0) oneMap = true;
  }
  if (oneMap && !args.scene.empty()) {
    return Error::badInput(
        "bake: give either a SCENE file or the one-map options (--mesh, "
        "--map, -o, ...), not both");
  }
  if (!oneMap && args.scene.empty()) {
    return Error::badInput(
        "bake: give a SCENE file, or --mesh and -o for one map (see 'sgbake "
        "bake --help')");
  }
  if (oneMap && !args.outDir.empty()) {
    return Error::badInput("bake: --out-dir applies to scene files only");
  }
  if (Status ok = checkSubdivisionOptions("bake", args.subdivision, args.limitSurface, app); !ok) {
    return ok;
  }
  // Layer and output options that would change nothing, as a scene's keys would be refused.
  const bool height = !args.heightImage.empty(), normal = !args.normalImage.empty();
  for (const auto& [option, applies, needs] :
       {std::tuple{"--height-scale", height, "--height"},
        {"--height-gradient", height, "--height"},
        {"--height-space", height, "--height"},
        {"--height-remap", height, "--height"},
        {"--filter", height || normal, "--height or --normal"},
        {"--normal-space", normal, "--normal"},
        {"--normal-green", normal, "--normal"},
        {"--green", args.map == "tangent-normal", "--map tangent-normal"},
        {"--swizzle", args.map == "tangent-normal" || args.map == "object-normal",
         "--map tangent-normal or object-normal"}}) {
    if (!applies && app.count(option) > 0) {
      return Error::badInput(std::string("bake: ") + option + " applies only with " + needs);
    }
  }
  if (app.count("--green") > 0 && app.count("--swizzle") > 0) {
    return Error::badInput(
        "bake: give the green channel's direction either with --green or in --swizzle (its "
        "second axis: +Y OpenGL, -Y DirectX), not both");
  }
  // A margin or padding that would be ignored (0 and extend, the defaults, may be said).
  if (args.padding == "push-pull" && app.count("--margin") > 0 && args.margin > 0) {
    return Error::badInput(
        "bake: --margin is the width of --padding extend or adjacent-faces; push-pull fills "
        "every texel outside the UV islands");
  }
  if (args.map == "mask" && ((app.count("--margin") > 0 && args.margin > 0) ||
                             (app.count("--padding") > 0 && args.padding != "extend"))) {
    return Error::badInput(
        std::string("bake: ") +
        (app.count("--padding") > 0 && args.padding != "extend" ? "--padding" : "--margin") +
        " does not apply to --map mask: a mask shows the coverage and is "
        "never padded");
  }
  if (args.map == "corners") {  // a CSV table of the mesh's corners: no image options
    for (const char* option :
         {"--size", "--margin", "--samples", "--padding", "--bit-depth", "--alpha", "--range"}) {
      if (app.count(option) > 0) {
        return Error::badInput(std::string("bake: ") + option +
                               " applies to images, not to --map corners (a CSV table)");
      }
    }
  }
  if (normal && args.filter == "hermite") {  // Hermite interpolates heights
    return Error::badInput(
        "bake: --filter hermite applies only to height images; --normal takes bilinear or "
        "bicubic");
  }

  // The one-map flags build a scene: its messages are said in the flags' words.
  const auto inWords = [&](Error error) {
    if (oneMap) error.message = inFlagWords(error.message, args);
    return error;
  };
  Result<Scene> scene = oneMap ? oneMapScene(args) : loadScene(args.scene, args.outDir);
  if (!scene) return inWords(scene.error());

  PlanOptions planOptions;
  planOptions.force = args.force;
  planOptions.useManifest = !args.noManifest;
  Result<Plan> plan = makePlan(std::move(*scene), planOptions);
  if (!plan) return inWords(plan.error());
  for (const std::string& warning : plan->warnings) {
    std::fprintf(stderr, "sgbake: warning: %s\n", warning.c_str());
  }
  if (args.explain) {
    const std::string text = explainPlan(*plan);
    return writeStandardOutput(text);
  }

  ProgressBar bar;
  ExecuteOptions executeOptions;
  executeOptions.threads = args.threads;
  executeOptions.progress = [&bar](const BakeProgress& progress) { bar.update(progress); };
  Result<ExecuteReport> report = executePlan(*plan, executeOptions);
  bar.stop();
  if (!report) return inWords(report.error());
  for (const std::string& warning : report->warnings) {
    std::fprintf(stderr, "sgbake: warning: %s\n", warning.c_str());
  }
  if (Status ok = printOutcome(*report); !ok) return ok;

  if (args.stats) {
    std::size_t baked = 0;
    for (const OutputReport& output : report->outputs) baked += output.baked ? 1 : 0;
    const nlohmann::json stats = {
        {"command", "bake"},
        {"scene", oneMap ? std::string("-") : args.scene},
        {"outputs", report->outputs.size()},
        {"baked", baked},
        {"up_to_date", report->outputs.size() - baked},
        {"tiles", report->tilesBaked},
        {"images_loaded", report->imagesLoaded},
        {"textures", report->texturesCreated},
        {"tangents", report->tangentsComputed},
        {"threads", threadLimit.effectiveThreads()},
        {"plan_s", plan->planSeconds},
        {"load_s", report->loadSeconds},
        {"tangents_s", report->tangentsSeconds},
        {"bake_s", report->bakeSeconds},
        {"pad_s", report->padSeconds},
        {"convert_s", report->convertSeconds},
        {"write_s", report->writeSeconds},
        {"write_wait_s", report->writeWaitSeconds},
        {"total_s", total.seconds()},
    };
    printStats(stats);
  }
  return Ok{};
}

}  // namespace

CommandAction defineBakeCommand(CLI::App& app) {
  auto args = std::make_shared<BakeArguments>();
  app.footer(std::string(kFooter) + kExitCodeHelp);
  app.add_option("SCENE", args->scene, "Scene file (JSON) listing the mesh, layers and outputs")
      ->type_name("FILE");
  app.add_flag("--explain", args->explain,
               "Print the plan (steps with reasons, and what is skipped) and exit without baking");
  app.add_flag("--force", args->force, "Bake every output, even those that are up to date");
  app.add_flag("--no-manifest", args->noManifest,
               "Neither read nor write .sgbake-manifest.json (always bake)");
  app.add_option("--out-dir", args->outDir,
                 "Resolve relative output files against DIR instead of the scene's directory")
      ->type_name("DIR");
  app.add_option("--threads", args->threads, "Maximum number of threads, 0 = all cores")
      ->type_name("N")
      ->check(kNonNegativeInteger)
      ->capture_default_str();
  app.add_flag("--stats", args->stats,
               "Print timings and counts as one line of JSON on standard error");

  const std::string oneMap = "One map without a scene file";
  app.add_option("--mesh", args->mesh, "Mesh with UVs (.obj, .ply, .off)")
      ->type_name("FILE")
      ->group(oneMap);
  app.add_option("-o,--output", args->output, "Output file (.png, .exr, .tif; '<UDIM>' allowed)")
      ->type_name("FILE")
      ->group(oneMap);
  addSubdivisionOptions(app, args->subdivision, oneMap, &args->limitSurface);
  addTransformOption(app, args->transform, oneMap);
  app.add_option("--map", args->map,
                 "tangent-normal, object-normal, height, derivative, surface-gradient, tangent, "
                 "bitangent, mask or corners")
      ->type_name("MAP")
      ->capture_default_str()
      ->group(oneMap);
  app.add_option("--size", args->size, "Width and height of the map, texels (1 to 65536)")
      ->type_name("N")
      ->check(integerIn(1, kMaxBakeSide))
      ->capture_default_str()
      ->group(oneMap);
  app.add_option("--margin", args->margin, "Texels of edge padding around the UV islands")
      ->type_name("N")
      ->check(integerIn(0, kMaxBakeSide))
      ->capture_default_str()
      ->group(oneMap);
  app.add_option("--padding", args->padding,
                 "extend or adjacent-faces (by --margin), or push-pull (fill all)")
      ->type_name("MODE")
      ->capture_default_str()
      ->group(oneMap);
  app.add_option("--samples", args->samples, "N: N x N samples per texel (1 to 16)")
      ->type_name("N")
      ->check(integerIn(1, kMaxBakeSamples))
      ->capture_default_str()
      ->group(oneMap);
  app.add_option("--uv", args->uvSet, "UV set of the map and its layers (0 = the first)")
      ->type_name("N")
      ->check(integerIn(0, kMaxUvSets - 1))
      ->capture_default_str()
      ->group(oneMap);
  app.add_option("--green", args->green, "Green channel of a tangent-normal map: opengl or directx")
      ->type_name("CONVENTION")
      ->capture_default_str()
      ->group(oneMap);
  app.add_option("--swizzle", args->swizzle,
                 "Channels of a normal map as Blender's bake Swizzle: three signed axes for R, G, "
                 "B, e.g. +X-Y+Z (default +X+Y+Z; not with --green)")
      ->type_name("AXES")
      ->group(oneMap);
  app.add_option("--height", args->heightImage, "Height image layer")
      ->type_name("IMAGE")
      ->group(oneMap);
  app.add_option("--height-scale", args->heightScale,
                 "Object units of height per unit of image value")
      ->type_name("S")
      ->capture_default_str()
      ->group(oneMap);
  app.add_option("--filter", args->filter,
                 "Image filter: bilinear, bicubic or hermite (heights only)")
      ->type_name("FILTER")
      ->capture_default_str()
      ->group(oneMap);
  app.add_option("--height-gradient", args->heightGradient,
                 "Slopes of --height: analytic (exact), or bump-node (Blender's Bump node as "
                 "Cycles bakes it: differences half a texel apart)")
      ->type_name("MODE")
      ->capture_default_str()
      ->group(oneMap);
  app.add_option("--height-space", args->heightSpace,
                 "Units of --height-scale: world (as a Bump node's Distance), or object (as a "
                 "Displacement node's Scale in Object space: grown along the normal by "
                 "--transform)")
      ->type_name("SPACE")
      ->capture_default_str()
      ->group(oneMap);
  app.add_option("--height-remap", args->heightRemap,
                 "Read --height through the piecewise-linear function through these points, "
                 "constant beyond the ends (a repeated X: a step), e.g. 0.2:0,0.6:1 for levels")
      ->type_name("X:Y,...")
      ->group(oneMap);
  app.add_option("--normal", args->normalImage, "Normal-map layer")
      ->type_name("IMAGE")
      ->group(oneMap);
  app.add_option("--normal-space", args->normalSpace, "Space of --normal: tangent or object")
      ->type_name("SPACE")
      ->capture_default_str()
      ->group(oneMap);
  app.add_option("--normal-green", args->normalGreen,
                 "Green channel of --normal: opengl or directx")
      ->type_name("CONVENTION")
      ->capture_default_str()
      ->group(oneMap);
  app.add_option("--bit-depth", args->bitDepth,
                 "8, 16 or 32 bits per channel (0 = 16; 8 for masks in PNG/TIFF)")
      ->type_name("N")
      ->check(CLI::IsMember({0, 8, 16, 32}).description(""))
      ->capture_default_str()
      ->group(oneMap);
  app.add_flag("--alpha", args->alpha, "Write the coverage as an alpha channel")->group(oneMap);
  app.add_option("--range", args->range,
                 "Derivative/surface-gradient maps in PNG/TIFF store v / (2 R) + 0.5 (default 1; "
                 "auto: the map's largest |v|, rounded up)")
      ->type_name("R")
      ->group(oneMap);

  return [args, &app] { return runBake(*args, app); };
}

}  // namespace sgbake::cli
