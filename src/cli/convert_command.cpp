/// @file convert_command.cpp
/// @brief `sgbake convert IN --mesh M.obj --from object --to tangent -o OUT`: re-expresses a
/// normal map between object and tangent space with Blender's per-texel frame.
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli.hpp"
#include "sgbake/bake/bake.hpp"
#include "sgbake/bake/convert.hpp"
#include "sgbake/bake/image_output.hpp"
#include "sgbake/bake/scene.hpp"
#include "sgbake/frames/tangents.hpp"
#include "sgbake/gradient/image.hpp"
#include "sgbake/io/atomic_file.hpp"
#include "sgbake/io/image_io.hpp"
#include "sgbake/mesh/io.hpp"
#include "sgbake/sgbake.h"
#include "sgbake/subdiv/limit_surface.hpp"

namespace sgbake::cli {
namespace {

/// The command line of `sgbake convert`, as CLI11 fills it in.
struct ConvertArguments {
  std::string input;
  std::string mesh;
  std::string output;
  std::string from;
  std::string to;
  int uvSet = 0;
  std::string green = "opengl";
  std::string swizzle;       ///< the output's channels; empty: +X+Y+Z
  std::string inputSwizzle;  ///< the input's channels; empty: its sgbake:swizzle, else +X+Y+Z
  int tile = kFirstUdimTile;
  int samples = 1;
  int bitDepth = 0;
  std::string padding = "keep";  ///< keep, or a PaddingMode's name
  int margin = 16;
  int threads = 0;
  bool stats = false;
  SubdivisionOptions subdivision;  ///< level 0: none
  bool limitSurface = false;       ///< --subdivide limit: convert on the exact limit surface
  std::string transform;           ///< --transform: matrix_world, row by row
};

constexpr const char* kFooter =
    "What it does:\n"
    "  Every texel the mesh covers (in the UV set; tile 1001 unless --tile, or the tile a map\n"
    "  sgbake wrote says it is, sgbake:udim_tile; its sgbake:green is --green's default, its\n"
    "  sgbake:swizzle --input-swizzle's, and its sgbake:map must agree with --from) is decoded\n"
    "  as n = 2c - 1 (the input's channels in --input-swizzle's order, the output's in\n"
    "  --swizzle's: Blender's bake Swizzle, default +X+Y+Z) and re-expressed in the per-texel "
    "MikkTSpace frame Blender's baker uses:\n"
    "  object -> tangent applies inverse([T B N]); tangent -> object applies x T + y B + z N.\n"
    "  Texels outside the UV islands keep their input values (--padding keep), or are padded\n"
    "  from the converted islands as `sgbake bake` pads (--padding extend or adjacent-faces by\n"
    "  --margin texels, or push-pull): a map padded in the other space holds that space's\n"
    "  normals there. The output has the input's size;\n"
    "  an alpha channel is kept (unassociated), further channels are dropped. The file is\n"
    "  replaced only once complete.\n"
    "  With --subdivide limit, the frame is the exact limit surface's at each sample, as\n"
    "  `sgbake bake` uses from \"level\": \"limit\" (T = dP/du made orthogonal to N).\n"
    "  With --transform (the object's matrix_world), the object-space side is the map Blender\n"
    "  bakes for the placed object, whose normals it brings back from world space through the\n"
    "  inverse matrix: n stands for the object normal M^T M n.\n"
    "\n"
    "Examples:\n"
    "  sgbake convert --mesh suzanne.obj --from object --to tangent n_os.exr -o n_ts.exr\n"
    "  sgbake convert --mesh suzanne.obj --from tangent --to object --green directx \\\n"
    "                 n_ts.png -o n_os.png\n"
    "  sgbake convert --mesh suzanne.obj --from object --to tangent --padding adjacent-faces \\\n"
    "                 --margin 16 n_os.exr -o n_ts.exr\n"
    "  sgbake convert --mesh cage.obj --subdivide limit --from object --to tangent \\\n"
    "                 n_os.exr -o n_ts.exr\n"
    "\n";

/// The FloatImage (rows top first) of an Image (rows bottom-up), at most three colour channels;
/// a fourth channel becomes the coverage, to be written back as alpha.
FloatImage toFloatImage(const Image& image, bool& hasAlpha) {
  FloatImage out;
  out.width = image.width();
  out.height = image.height();
  out.channels = image.channels();
  hasAlpha = image.channels() >= 4;
  out.pixels.resize(static_cast<std::size_t>(out.width) * static_cast<std::size_t>(out.height) *
                    static_cast<std::size_t>(out.channels));
  out.coverage.assign(static_cast<std::size_t>(out.width) * static_cast<std::size_t>(out.height),
                      1.0f);
  for (int row = 0; row < out.height; ++row) {
    const int y = image.yFromFileRow(row);
    for (int x = 0; x < out.width; ++x) {
      for (int c = 0; c < out.channels; ++c) out.at(x, row, c) = image.at(x, y, c);
    }
  }
  return out;
}

Status runConvert(const ConvertArguments& args, const CLI::App& app) {
  Stopwatch total;
  const ThreadLimit threadLimit(args.threads);
  preloadImageIo();  // the image codec loads while the arguments are checked and the mesh read

  if (Status ok = checkSubdivisionOptions("convert", args.subdivision, args.limitSurface, app);
      !ok) {
    return ok;
  }
  Result<NormalSpace> from = parseNormalSpace(args.from);
  if (!from) return Error::badInput("convert: --from: " + from.error().message);
  Result<NormalSpace> to = parseNormalSpace(args.to);
  if (!to) return Error::badInput("convert: --to: " + to.error().message);
  if (*from == *to) {
    return Error::badInput("convert: --from and --to are both " + args.from +
                           ": there is nothing to convert");
  }
  Result<std::optional<ObjectTransform>> parsedTransform =
      parseTransformOption("convert", args.transform);
  if (!parsedTransform) return parsedTransform.error();
  const std::optional<ObjectTransform> transform = *parsedTransform;
  std::optional<PaddingMode> padding;  // none: keep the input's values
  if (args.padding != "keep") {
    Result<PaddingMode> mode = parsePaddingMode(args.padding);
    if (!mode) {
      return Error::badInput("convert: --padding: unknown value '" + args.padding +
                             "' (expected keep, extend, adjacent-faces or push-pull)");
    }
    padding = *mode;
  }
  if (app.count("--margin") != 0 && args.margin > 0 && padding != PaddingMode::kExtend &&
      padding != PaddingMode::kAdjacentFaces) {
    return Error::badInput(
        "convert: --margin is the width of --padding extend or "
        "adjacent-faces; with --padding " +
        args.padding + " it would change nothing");
  }
  if (args.green != "opengl" && args.green != "directx") {
    return Error::badInput("convert: --green: unknown value '" + args.green +
                           "' (expected opengl or directx)");
  }
  // --green is the tangent-space side's: its swizzle says G's direction as well.
  for (const auto& [option, side] :
       {std::pair{"--swizzle", args.to}, {"--input-swizzle", args.from}}) {
    if (side == "tangent" && app.count("--green") > 0 && app.count(option) > 0) {
      return Error::badInput(std::string("convert: give the tangent-space side's green either with "
                                         "--green or in ") +
                             option + " (its second axis: +Y OpenGL, -Y DirectX), not both");
    }
  }
  for (const auto& [input, what] : {std::pair{args.input, "the image"}, {args.mesh, "the mesh"}}) {
    if (mayBeSameFile(args.output, input)) {
      return Error::badInput("convert: -o " + args.output + " is " + what +
                             " it reads (write it elsewhere)");
    }
  }
  Result<ImageFormat> format = imageFormatFromPath(args.output);
  if (!format) return format.error();
  const int bitDepth =
      args.bitDepth != 0 ? args.bitDepth : defaultBitDepth(*format, MapKind::kTangentNormal);
  if (!formatSupportsBitDepth(*format, bitDepth)) {
    return Error::badInput(args.output + ": --bit-depth " + std::to_string(bitDepth) +
                           " is not available in this format");
  }
  // An unwritable destination is reported before any work is done.
  {
    Result<AtomicFile> probe = AtomicFile::create(args.output);
    if (!probe) return probe.error();
  }

  Stopwatch step;
  LoadOptions meshOptions;
  meshOptions.requireUvs = true;
  if (!args.limitSurface) meshOptions.subdivision = args.subdivision;
  Result<Mesh> mesh = loadMesh(args.mesh, meshOptions);
  if (!mesh) return mesh.error();
  // --subdivide limit: the frames are the limit surface's, found through its tessellation.
  std::optional<LimitTessellation> limit;
  if (args.limitSurface) {
    Result<LimitTessellation> tessellated = tessellateLimitSurface(*mesh, args.subdivision);
    if (!tessellated) return tessellated.error();
    limit.emplace(std::move(*tessellated));
    mesh = std::move(limit->mesh);
  }
  if (!mesh->hasUvSet(static_cast<std::size_t>(args.uvSet))) {
    return Error::badInput(args.mesh + ": has " + std::to_string(mesh->uvSets.size()) +
                           " UV set(s); --uv " + std::to_string(args.uvSet) +
                           " does not exist (UV sets are numbered from 0)");
  }
  std::vector<std::pair<std::string, std::string>> said;  // the input's sgbake:… attributes
  LoadImageOptions imageOptions;
  imageOptions.attributes = &said;
  Result<Image> image = loadImage(args.input, imageOptions);
  if (!image) return image.error();
  // A map sgbake wrote says what it holds: its space must be --from, and its UDIM tile and
  // green convention are what --tile and --green default to.
  const auto saidOf = [&said](std::string_view key) {
    for (const auto& [name, value] : said) {
      if (name == key) return value;
    }
    return std::string();
  };
  const std::string map = saidOf("sgbake:map");
  if ((map == "object-normal" || map == "tangent-normal") &&
      map != std::string(normalSpaceName(*from)) + "-normal") {
    return Error::badInput(
        args.input + ": the file says it is " + (map == "object-normal" ? "an " : "a ") + map +
        " map (sgbake:map); --from " + std::string(normalSpaceName(*from)) + " would misread it");
  }
  int tile = args.tile;
  const std::string saidTile = saidOf("sgbake:udim_tile");
  if (!saidTile.empty() && saidTile != std::to_string(args.tile)) {
    char* end = nullptr;
    const long number = std::strtol(saidTile.c_str(), &end, 10);
    const bool valid = *end == '\0' && number >= kFirstUdimTile && number <= kLastUdimTile;
    if (valid && app.count("--tile") == 0) {
      tile = static_cast<int>(number);
    } else if (valid) {
      std::fprintf(stderr,
                   "sgbake: warning: %s: the file says it is UDIM tile %s (sgbake:udim_tile); "
                   "converted as tile %d, as --tile says\n",
                   args.input.c_str(), saidTile.c_str(), args.tile);
    }
  }
  std::string green = args.green;
  const std::string saidGreen = saidOf("sgbake:green");
  if (*from == NormalSpace::kTangent && app.count("--green") == 0 &&
      (saidGreen == "opengl" || saidGreen == "directx")) {
    green = saidGreen;
  }
  // The channels: the flags', else (the input) what the file says it stores. sgbake:swizzle is
  // the stored order, its DirectX green included, which sgbake:green says again: the green is
  // taken out, as --green applies it.
  NormalSwizzle inputSwizzle = kIdentitySwizzle, outputSwizzle = kIdentitySwizzle;
  if (!args.inputSwizzle.empty()) {
    Result<NormalSwizzle> parsed = parseNormalSwizzle(args.inputSwizzle);
    if (!parsed) return Error::badInput("convert: --input-swizzle: " + parsed.error().message);
    inputSwizzle = *parsed;
  } else if (const std::string saidSwizzle = saidOf("sgbake:swizzle"); !saidSwizzle.empty()) {
    Result<NormalSwizzle> parsed = parseNormalSwizzle(saidSwizzle);
    if (!parsed) {
      return Error::badInput(args.input + ": sgbake:swizzle: " + parsed.error().message);
    }
    // (storedChannels negates G back: a second negation of it is its own inverse.)
    inputSwizzle = storedChannels(*parsed, *from == NormalSpace::kTangent && green == "directx"
                                               ? NormalMapGreen::kDirectX
                                               : NormalMapGreen::kOpenGL);
  }
  if (!args.swizzle.empty()) {
    Result<NormalSwizzle> parsed = parseNormalSwizzle(args.swizzle);
    if (!parsed) return Error::badInput("convert: --swizzle: " + parsed.error().message);
    outputSwizzle = *parsed;
  }
  if (image->channels() < 3) {
    return Error::badInput(args.input + ": image has " + std::to_string(image->channels()) +
                           " channel(s) but a normal map needs 3 (RGB)");
  }
  bool hasAlpha = false;
  const FloatImage input = toFloatImage(*image, hasAlpha);
  { const Image decoded = std::move(*image); }  // freed now: the conversion reads `input`
  const double loadSeconds = step.lap();

  // MikkTSpace frames of the mesh; none on the exact limit surface, which has its own.
  Result<CornerTangents> tangents = CornerTangents{};
  if (!limit) {
    TangentOptions tangentOptions;
    tangentOptions.threads = args.threads;
    tangents = computeTangents(mesh->view(0), tangentOptions);
  }
  if (!tangents) {
    return Error{tangents.error().code, args.mesh + ": " + tangents.error().message};
  }
  if (const std::string warning = missingTangentsWarning(*tangents, args.mesh); !warning.empty()) {
    std::fprintf(stderr, "sgbake: warning: %s\n", warning.c_str());
  }
  const double tangentSeconds = step.lap();

  ConvertSettings settings;
  settings.uvSet = args.uvSet;
  settings.udimTile = tile;
  settings.green = green == "directx" ? NormalMapGreen::kDirectX : NormalMapGreen::kOpenGL;
  settings.inputSwizzle = inputSwizzle;
  settings.outputSwizzle = outputSwizzle;
  settings.samples = args.samples;
  settings.threads = args.threads;
  if (limit) {
    settings.limit = &limit->surface;
    settings.limitParameters = &limit->parameters;
  }
  if (transform) settings.transform = &*transform;

  // Converted band by band; each band's rows go to the writer, whose tasks compress and write
  // them while the next band is converted. The output image never exists whole.
  ImageWriteOptions writeOptions;
  writeOptions.format = *format;
  writeOptions.bitDepth = bitDepth;
  writeOptions.alpha = hasAlpha;
  writeOptions.threads = args.threads;
  // The output says what it holds, as a baked map does (texels outside the UV islands are the
  // input's, whatever they were).
  const bool toTangent = *to == NormalSpace::kTangent;
  writeOptions.attributes = {{"sgbake:map", toTangent ? "tangent-normal" : "object-normal"},
                             {"sgbake:encoding", "n/2+0.5"},
                             {"sgbake:uv", std::to_string(args.uvSet)},
                             {"sgbake:udim_tile", std::to_string(tile)},
                             {"sgbake:version", sgbake_version()}};
  // Its channels, as a baked map says them.
  const NormalSwizzle stored =
      storedChannels(outputSwizzle, toTangent ? settings.green : NormalMapGreen::kOpenGL);
  for (auto& attribute : normalChannelAttributes(stored, toTangent))
    writeOptions.attributes.push_back(std::move(attribute));
  Result<ImageFileWriter> writer =
      ImageFileWriter::open(args.output, input.width, input.height, 3, writeOptions);
  if (!writer) return writer.error();
  std::vector<float> strip, alpha;  // RGB and alpha of rows with more than three channels
  bool writeFailed = false;
  const auto writeRows = [&](const MutableImageRows& rows) -> Status {
    Status ok = Ok{};
    for (int row = rows.begin; row < rows.end && ok;) {
      const int run = std::min(rows.contiguousRows(row), rows.end - row);
      const std::size_t texels = static_cast<std::size_t>(run) * rows.width;
      if (rows.channels == 3) {
        ok = writer->writeRows(row, run, {rows.pixelRow(row), 3 * texels}, {});
      } else {  // channel 3 is alpha (kept, as coverage); further channels are dropped
        strip.resize(3 * texels);
        alpha.resize(texels);
        const float* in = rows.pixelRow(row);
        for (std::size_t t = 0; t < texels; ++t, in += rows.channels) {
          std::copy(in, in + 3, strip.begin() + static_cast<std::ptrdiff_t>(3 * t));
          alpha[t] = in[3];
        }
        ok = writer->writeRows(row, run, strip, alpha);
      }
      row += run;
    }
    writeFailed = !ok;
    return ok;
  };
  double padSeconds = 0;
  Status converted = Ok{};
  if (!padding) {
    converted = convertNormalMapRows(*mesh, *tangents, input, *from, *to, settings, writeRows);
  } else {  // padding reads the whole converted image
    Result<FloatImage> whole = convertNormalMap(*mesh, *tangents, input, *from, *to, settings);
    if (!whole) {
      converted = whole.error();
    } else {
      Stopwatch pad;
      padImage(*whole, *padding, args.margin, *mesh, args.uvSet, tile, args.samples, args.threads);
      padSeconds = pad.seconds();
      converted = writeRows(MutableImageRows::of(*whole));
    }
  }
  if (!converted) {
    if (writeFailed) return converted.error();  // the writer's errors name the file already
    return Error{converted.error().code, args.input + ": " + converted.error().message};
  }
  const double convertSeconds = step.lap() - writer->waitSeconds() - padSeconds;
  const double queueWaits = writer->waitSeconds();
  if (Status ok = writer->commit(); !ok) return ok;
  const double commitSeconds = step.lap();
  // A tile no UV triangle reaches converts nothing: said, as `bake` says it of its maps.
  const std::vector<int> touched = udimTiles(*mesh, args.uvSet);
  if (std::find(touched.begin(), touched.end(), tile) == touched.end()) {
    std::fprintf(stderr,
                 "sgbake: warning: %s: no triangle of UV set %d lies in %s; every texel keeps "
                 "the input's value\n",
                 args.output.c_str(), args.uvSet, describeUdimTile(tile).c_str());
  }
  if (const std::uint64_t clipped = writer->clippedValues(); clipped != 0) {
    const std::string warning = describeClippedValues(
        args.output, clipped,
        static_cast<std::uint64_t>(input.width) * input.height * (hasAlpha ? 4 : 3), *format,
        bitDepth);
    std::fprintf(stderr, "sgbake: warning: %s\n", warning.c_str());
  }

  if (args.stats) {
    const nlohmann::json stats = {
        {"command", "convert"},
        {"input", args.input},
        {"mesh", args.mesh},
        {"output", args.output},
        {"width", input.width},
        {"height", input.height},
        {"from", normalSpaceName(*from)},
        {"to", normalSpaceName(*to)},
        {"threads", threadLimit.effectiveThreads()},
        {"load_s", loadSeconds},
        {"tangents_s", tangentSeconds},
        {"convert_s", convertSeconds},
        {"pad_s", padSeconds},
        {"write_s", writer->fileSeconds()},
        {"write_wait_s", queueWaits + commitSeconds},
        {"total_s", total.seconds()},
    };
    printStats(stats);
  }
  return Ok{};
}

}  // namespace

CommandAction defineConvertCommand(CLI::App& app) {
  auto args = std::make_shared<ConvertArguments>();
  app.footer(std::string(kFooter) + kExitCodeHelp);
  app.add_option("IN", args->input, "Normal map to convert (.png, .exr, .tif, ...)")
      ->required()
      ->type_name("IMAGE");
  app.add_option("--mesh", args->mesh, "Mesh with UVs the map was baked for")
      ->required()
      ->type_name("FILE");
  addSubdivisionOptions(app, args->subdivision, {}, &args->limitSurface);
  addTransformOption(app, args->transform);
  app.add_option("-o,--output", args->output, "Output file (.png, .exr, .tif); same size as IN")
      ->required()
      ->type_name("FILE");
  app.add_option("--from", args->from, "Space of IN: object or tangent")
      ->required()
      ->type_name("SPACE");
  app.add_option("--to", args->to, "Space of the output: object or tangent")
      ->required()
      ->type_name("SPACE");
  app.add_option("--uv", args->uvSet, "UV set that places the mesh in the image")
      ->type_name("N")
      ->check(kNonNegativeInteger)
      ->capture_default_str();
  app.add_option("--green", args->green,
                 "Green channel of the tangent-space side: opengl (Y+) or directx (Y-)")
      ->type_name("CONVENTION")
      ->capture_default_str();
  app.add_option("--swizzle", args->swizzle,
                 "Channels of the output as Blender's bake Swizzle: three signed axes for R, G, B, "
                 "e.g. -Y+X+Z (default +X+Y+Z; a tangent-space side's G is negated after it by "
                 "--green directx)")
      ->type_name("AXES");
  app.add_option("--input-swizzle", args->inputSwizzle,
                 "Channels of the input, as --swizzle, each axis once (default: what the file's "
                 "sgbake:swizzle says, else +X+Y+Z)")
      ->type_name("AXES");
  app.add_option("--tile", args->tile, "UDIM tile the image covers (1001 to 2000)")
      ->type_name("N")
      ->check(CLI::Range(kFirstUdimTile, kLastUdimTile).description(""))
      ->capture_default_str();
  app.add_option("--samples", args->samples, "N: N x N frames per texel, averaged (1 to 16)")
      ->type_name("N")
      ->check(CLI::Range(1, kMaxBakeSamples).description(""))
      ->capture_default_str();
  app.add_option("--padding", args->padding,
                 "keep (IN's values outside the UV islands), extend or adjacent-faces (by "
                 "--margin), or push-pull (every texel)")
      ->type_name("MODE")
      ->capture_default_str();
  app.add_option("--margin", args->margin, "Texels of extend or adjacent-faces padding")
      ->type_name("N")
      ->check(integerIn(0, kMaxBakeSide))
      ->capture_default_str();
  app.add_option("--bit-depth", args->bitDepth, "8, 16 or 32 bits per channel (0 = 16)")
      ->type_name("N")
      ->check(CLI::IsMember({0, 8, 16, 32}).description(""))
      ->capture_default_str();
  app.add_option("--threads", args->threads, "Maximum number of threads, 0 = all cores")
      ->type_name("N")
      ->check(kNonNegativeInteger)
      ->capture_default_str();
  app.add_flag("--stats", args->stats,
               "Print timings and sizes as one line of JSON on standard error");
  return [args, &app] { return runConvert(*args, app); };
}

}  // namespace sgbake::cli
