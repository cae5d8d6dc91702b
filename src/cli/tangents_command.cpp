/// @file tangents_command.cpp
/// @brief `sgbake tangents MESH`: MikkTSpace tangent frames per face corner, written as CSV.
#include <algorithm>
#include <charconv>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <tbb/parallel_for.h>

#include "cli.hpp"
#include "float_format.hpp"
#include "sgbake/bake/scene.hpp"
#include "sgbake/core/text.hpp"
#include "sgbake/frames/tangents.hpp"
#include "sgbake/io/atomic_file.hpp"
#include "sgbake/mesh/io.hpp"
#include "sgbake/subdiv/subdivide.hpp"

namespace sgbake::cli {
namespace {

/// The command line of `sgbake tangents`, as CLI11 fills it in.
struct TangentsArguments {
  std::string mesh;
  std::string output = "-";  ///< "-": standard output
  int uvSet = 0;
  int threads = 0;
  bool stats = false;
  SubdivisionOptions subdivision;  ///< level 0: none
  std::string meshOut;             ///< --mesh-out: the (subdivided) mesh as OBJ, or empty
};

constexpr const char* kFooter =
    "Output:\n"
    "  CSV with the header face,corner,tx,ty,tz,sign and one row per face corner: faces in\n"
    "  file order, each face's corners in winding order; 'corner' is the corner's index within\n"
    "  its face (0-based). tx,ty,tz is the unit tangent in object space, with 9 significant\n"
    "  digits (enough to read the float back exactly); sign is 1 or -1, and the bitangent is\n"
    "  sign * cross(normal, tangent). Normals come from the file, or are smooth angle-weighted\n"
    "  normals when it has none.\n"
    "  With --subdivide, the rows are the corners of the subdivided mesh (Blender's modifier\n"
    "  applied): --mesh-out writes that mesh as OBJ, its corners in the rows' order.\n"
    "  With -o, the file is replaced only once everything has succeeded: never left partial.\n"
    "\n"
    "Examples:\n"
    "  sgbake tangents suzanne.obj -o suzanne_tangents.csv\n"
    "  sgbake tangents suzanne.obj --subdivide 2 --mesh-out suzanne_l2.obj -o l2_tangents.csv\n"
    "  sgbake tangents scan.ply --uv 1 --threads 4 --stats > tangents.csv\n"
    "\n";

constexpr const char* kCsvHeader = "face,corner,tx,ty,tz,sign\n";

/// Rows are formatted in parallel in blocks of about this many corners, and written in order.
constexpr std::size_t kCornersPerBlock = 32 * 1024;
/// Blocks formatted before they are written: bounds the memory held by formatted text.
constexpr std::size_t kBlocksPerBatch = 32;
/// The longest row: face and corner indices (20 and 10 digits), three `%.9g` floats, the sign,
/// five commas and a newline.
constexpr std::size_t kMaxRowChars = 20 + 10 + 3 * kMaxFloatG9Chars + 2 + 5 + 1;

char* appendUnsigned(char* out, char* end, std::uint64_t value) {
  return std::to_chars(out, end, value).ptr;
}


/// Appends the CSV rows of faces [faceBegin, faceEnd) to @p out.
void appendRows(const Mesh& mesh, const CornerTangents& frames, std::size_t faceBegin,
                std::size_t faceEnd, std::string& out) {
  const std::size_t rows = mesh.faceStart[faceEnd] - mesh.faceStart[faceBegin];
  const std::size_t used = out.size();
  out.resize(used + rows * kMaxRowChars);
  char* p = out.data() + used;
  char* const end = out.data() + out.size();
  for (std::size_t f = faceBegin; f < faceEnd; ++f) {
    const std::uint32_t first = mesh.faceStart[f];
    for (std::uint32_t c = first; c < mesh.faceStart[f + 1]; ++c) {
      const Vec3f t = frames.tangent[c];
      p = appendUnsigned(p, end, f);
      *p++ = ',';
      p = appendUnsigned(p, end, c - first);
      *p++ = ',';
      p = formatFloatG9(p, t.x);
      *p++ = ',';
      p = formatFloatG9(p, t.y);
      *p++ = ',';
      p = formatFloatG9(p, t.z);
      *p++ = ',';
      if (frames.sign[c] < 0.0f) *p++ = '-';
      *p++ = '1';
      *p++ = '\n';
    }
  }
  out.resize(static_cast<std::size_t>(p - out.data()));
}

/// Splits the faces into consecutive blocks of about kCornersPerBlock corners; returns the
/// first face of every block followed by #F.
std::vector<std::size_t> splitIntoBlocks(std::span<const std::uint32_t> faceStart) {
  const std::size_t numFaces = faceStart.size() - 1;
  std::vector<std::size_t> bounds{0};
  while (bounds.back() < numFaces) {
    const std::uint64_t wanted = std::uint64_t{faceStart[bounds.back()]} + kCornersPerBlock;
    // The first face starting at or after `wanted` (at least one face per block).
    const auto next = std::lower_bound(faceStart.begin() + bounds.back() + 1,
                                       faceStart.begin() + numFaces, wanted);
    bounds.push_back(static_cast<std::size_t>(next - faceStart.begin()));
  }
  return bounds;
}

/// Writes the whole CSV to @p output (formatting blocks in parallel, writing them in order).
Status writeCsv(const Mesh& mesh, const CornerTangents& frames, Output& output) {
  if (Status s = output.write(kCsvHeader); !s) return s;
  const std::vector<std::size_t> bounds = splitIntoBlocks(mesh.faceStart);
  const std::size_t numBlocks = bounds.size() - 1;
  std::vector<std::string> text(std::min(numBlocks, kBlocksPerBatch));
  for (std::size_t batch = 0; batch < numBlocks; batch += kBlocksPerBatch) {
    const std::size_t count = std::min(kBlocksPerBatch, numBlocks - batch);
    const auto format = [&](std::size_t i) {
      text[i].clear();
      appendRows(mesh, frames, bounds[batch + i], bounds[batch + i + 1], text[i]);
    };
    if (count == 1) {
      format(0);  // small outputs: not worth waking the thread pool
    } else {
      tbb::parallel_for(std::size_t{0}, count, format);
    }
    for (std::size_t i = 0; i < count; ++i) {
      if (Status s = output.write(text[i]); !s) return s;
    }
  }
  return output.finish();
}

Status runTangents(const TangentsArguments& args, const CLI::App& app) {
  Stopwatch total;
  const ThreadLimit threadLimit(args.threads);
  if (Status ok = checkSubdivisionOptions("tangents", args.subdivision, false, app); !ok) return ok;
  if (args.output != "-" && mayBeSameFile(args.output, args.mesh)) {
    return Error::badInput("tangents: -o " + args.output + " is the mesh it reads");
  }
  // As a scene's corners table: a CSV under another name (say an image's) would replace it.
  if (args.output != "-" &&
      toLowerAscii(std::filesystem::path(args.output).extension().string()) != ".csv") {
    return Error::badInput("tangents: -o " + args.output +
                           ": the table is written as CSV, its file must end in .csv (or - for "
                           "standard output)");
  }
  if (!args.meshOut.empty()) {
    if (toLowerAscii(std::filesystem::path(args.meshOut).extension().string()) != ".obj") {
      return Error::badInput("tangents: --mesh-out " + args.meshOut +
                             ": the mesh is written as OBJ, its file must end in .obj");
    }
    if (mayBeSameFile(args.meshOut, args.mesh)) {
      return Error::badInput("tangents: --mesh-out " + args.meshOut + " is the mesh it reads");
    }
    if (args.output != "-" && mayBeSameFile(args.meshOut, args.output)) {
      return Error::badInput("tangents: --mesh-out and -o name the same file, " + args.output);
    }
  }

  // Open the output first: an unwritable destination is reported before any work is done.
  Result<Output> output = Output::open(args.output);
  if (!output) return output.error();

  Stopwatch step;
  LoadOptions loadOptions;
  loadOptions.requireUvs = true;
  Result<Mesh> mesh = loadMesh(args.mesh, loadOptions);
  if (!mesh) return mesh.error();
  const double loadSeconds = step.lap();
  if (args.subdivision.changesMesh()) {  // timed on its own (--stats)
    mesh = subdivideMesh(*mesh, args.subdivision);
    if (!mesh) return mesh.error();
  }
  const double subdivideSeconds = step.lap();


  const auto uvSet = static_cast<std::size_t>(args.uvSet);
  if (!mesh->hasUvSet(uvSet)) {
    return Error::badInput(args.mesh + ": has " + std::to_string(mesh->uvSets.size()) +
                           " UV set(s); --uv " + std::to_string(uvSet) +
                           " does not exist (UV sets are numbered from 0)");
  }

  TangentOptions tangentOptions;
  tangentOptions.threads = args.threads;
  Result<CornerTangents> frames = computeTangents(mesh->view(uvSet), tangentOptions);
  if (!frames) {
    // The kernel sees arrays, not files: name the file here.
    return Error{frames.error().code, args.mesh + ": " + frames.error().message};
  }
  if (frames->tangent.size() != mesh->numCorners() || frames->sign.size() != mesh->numCorners()) {
    return Error::internal(args.mesh + ": computeTangents returned " +
                           std::to_string(frames->tangent.size()) + " tangents for " +
                           std::to_string(mesh->numCorners()) + " corners");
  }
  const double tangentSeconds = step.lap();
  if (const std::string warning = missingTangentsWarning(*frames, args.mesh); !warning.empty()) {
    std::fprintf(stderr, "sgbake: warning: %s\n", warning.c_str());
  }

  if (!args.meshOut.empty()) {
    if (Status written = writeFileAtomically(args.meshOut, formatObj(*mesh, uvSet)); !written) {
      return written;
    }
  }
  if (Status written = writeCsv(*mesh, *frames, *output); !written) return written;
  const double writeSeconds = step.lap();

  if (args.stats) {
    const nlohmann::json stats = {
        {"command", "tangents"},
        {"mesh", args.mesh},
        {"output", output->name()},
        {"vertices", mesh->numVertices()},
        {"faces", mesh->numFaces()},
        {"corners", mesh->numCorners()},
        {"uv_set", uvSet},
        {"threads", threadLimit.effectiveThreads()},
        {"subdivision_level", args.subdivision.level},
        {"load_s", loadSeconds},
        {"subdivide_s", subdivideSeconds},
        {"tangents_s", tangentSeconds},
        {"write_s", writeSeconds},
        {"total_s", total.seconds()},
    };
    printStats(stats);
  }
  return Ok{};
}

}  // namespace

CommandAction defineTangentsCommand(CLI::App& app) {
  auto args = std::make_shared<TangentsArguments>();
  app.footer(std::string(kFooter) + kExitCodeHelp);
  app.add_option("MESH", args->mesh, "Mesh file with UVs: .obj, .ply or .off")
      ->required()
      ->type_name("FILE");
  app.add_option("-o,--output", args->output,
                 "Write the CSV to FILE (ending in .csv) instead of standard output ('-')")
      ->type_name("FILE");
  app.add_option("--uv", args->uvSet, "UV set (0 = the first one in the file)")
      ->type_name("N")
      ->check(kNonNegativeInteger)
      ->capture_default_str();
  app.add_option("--threads", args->threads, "Maximum number of threads, 0 = all cores")
      ->type_name("N")
      ->check(kNonNegativeInteger)
      ->capture_default_str();
  addSubdivisionOptions(app, args->subdivision);
  app.add_option("--mesh-out", args->meshOut,
                 "Also write the mesh the tangents are of (subdivided, with its normals) as OBJ")
      ->type_name("FILE");
  app.add_flag("--stats", args->stats,
               "Print timings and sizes as one line of JSON on standard error");
  return [args, &app] { return runTangents(*args, app); };
}

}  // namespace sgbake::cli
