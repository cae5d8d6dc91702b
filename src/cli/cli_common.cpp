/// @file cli_common.cpp
/// @brief The helpers every subcommand shares (see cli.hpp).
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include <tbb/info.h>

#include "cli.hpp"
#include "sgbake/core/text.hpp"

namespace sgbake::cli {

const char* const kExitCodeHelp =
    "Exit codes:\n"
    "  0  success\n"
    "  1  internal error (a bug in sgbake, out of memory, disk full)\n"
    "  2  bad usage or bad input (unknown option, unreadable or invalid file)\n";

CLI::Validator integerIn(long long min, long long max) {
  return CLI::Validator(
      [min, max](std::string& value) -> std::string {
        std::size_t used = 0;
        long long number = 0;
        try {
          number = std::stoll(value, &used);
        } catch (const std::exception&) {
          used = 0;  // not a number, or beyond long long: reported below
        }
        if (used > 0 && used == value.size() && number >= min && number <= max) return {};
        return "'" + value + "' is not an integer from " + std::to_string(min) + " to " +
               std::to_string(max);
      },
      /*validator_desc=*/"");
}

const CLI::Validator kNonNegativeInteger = integerIn(0, std::numeric_limits<int>::max());

namespace {

/// CLI11's name → value map of a Named table.
template <class E, std::size_t N>
std::map<std::string, E> nameMap(const Named<E> (&table)[N]) {
  std::map<std::string, E> names;
  for (const Named<E>& entry : table) names.emplace(entry.name, entry.value);
  return names;
}

/// Splits "a,b,c" at its commas.
std::vector<std::string> splitCommas(const std::string& text) {
  std::vector<std::string> parts(1);
  for (const char ch : text) {
    if (ch == ',') {
      parts.emplace_back();
    } else {
      parts.back() += ch;
    }
  }
  return parts;
}

/// A vertex index of a crease option, or nullopt.
std::optional<std::uint32_t> creaseVertex(const std::string& text) {
  try {
    std::size_t used = 0;
    if (text.empty() || text[0] == '-') return std::nullopt;
    const unsigned long long v = std::stoull(text, &used);
    if (used != text.size() || v > std::numeric_limits<std::uint32_t>::max()) return std::nullopt;
    return static_cast<std::uint32_t>(v);
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

/// A crease value of a crease option (a number in [0, 1]), or nullopt.
std::optional<float> creaseValue(const std::string& text) {
  try {
    std::size_t used = 0;
    const double c = std::stod(text, &used);
    if (used != text.size() || !(c >= 0.0 && c <= 1.0)) return std::nullopt;
    return static_cast<float>(c);
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

/// "A,B,C" of --edge-crease.
std::optional<EdgeCrease> parseEdgeCrease(const std::string& text) {
  const std::vector<std::string> parts = splitCommas(text);
  if (parts.size() != 3) return std::nullopt;
  const auto v0 = creaseVertex(parts[0]), v1 = creaseVertex(parts[1]);
  const auto c = creaseValue(parts[2]);
  if (!v0 || !v1 || !c) return std::nullopt;
  return EdgeCrease{*v0, *v1, *c};
}

/// "V,C" of --vertex-crease.
std::optional<VertexCrease> parseVertexCrease(const std::string& text) {
  const std::vector<std::string> parts = splitCommas(text);
  if (parts.size() != 2) return std::nullopt;
  const auto v = creaseVertex(parts[0]);
  const auto c = creaseValue(parts[1]);
  if (!v || !c) return std::nullopt;
  return VertexCrease{*v, *c};
}

/// "A,B" of --sharp-edge.
std::optional<SharpEdge> parseSharpEdge(const std::string& text) {
  const std::vector<std::string> parts = splitCommas(text);
  if (parts.size() != 2) return std::nullopt;
  const auto v0 = creaseVertex(parts[0]), v1 = creaseVertex(parts[1]);
  if (!v0 || !v1) return std::nullopt;
  return SharpEdge{*v0, *v1};
}

/// An option taking one of @p names (any case) into @p target, shown as NAME with the default
/// @p defaultName.
template <class Enum, std::size_t N>
CLI::Option* addNamedOption(CLI::App& app, const std::string& name, Enum& target,
                            const Named<Enum> (&names)[N], const std::string& help,
                            const std::string& defaultName) {
  std::string expected;
  for (std::size_t i = 0; i < N; ++i) {
    expected += (i == 0 ? "" : i + 1 == N ? " or " : ", ") + std::string(names[i].name);
  }
  // The name becomes the enumerator's number, which CLI11 then stores (names only: numbers are
  // not part of the interface).
  return app.add_option(name, target, help)
      ->type_name("NAME")
      ->transform(CLI::Validator(
          [map = nameMap(names), expected](std::string& value) -> std::string {
            const auto found = map.find(toLowerAscii(value));
            if (found == map.end())
              return "unknown value '" + value + "' (expected " + expected + ")";
            value = std::to_string(static_cast<long long>(found->second));
            return {};
          },
          /*validator_desc=*/""))
      ->default_str(defaultName);
}

/// A repeatable option whose every value @p parse reads into one more entry of @p list (each
/// checked first: a value it refuses is "'VALUE' is not @p expected").
template <class Crease>
CLI::Option* addCreaseOption(CLI::App& app, const std::string& name, std::vector<Crease>& list,
                             std::optional<Crease> (*parse)(const std::string&),
                             const std::string& help, const std::string& typeName,
                             const std::string& expected) {
  return app
      .add_option_function<std::vector<std::string>>(
          name,
          [&list, parse](const std::vector<std::string>& values) {
            for (const std::string& value : values) list.push_back(*parse(value));
          },
          help)
      ->type_name(typeName)
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll)
      ->check(CLI::Validator(
          [parse, expected](std::string& value) -> std::string {
            if (parse(value)) return {};
            return "'" + value + "' is not " + expected;
          },
          ""));
}

}  // namespace

void addSubdivisionOptions(CLI::App& app, SubdivisionOptions& options, const std::string& group,
                           bool* limit) {
  options.level = 0;
  CLI::Option* level = nullptr;
  if (limit == nullptr) {
    level = app.add_option("--subdivide", options.level,
                           "Subdivide the mesh first, as Blender's Subdivision Surface modifier "
                           "with this many levels (0 = not at all)")
                ->type_name("N")
                ->check(CLI::Range(0, kMaxSubdivisionLevel))
                ->capture_default_str();
  } else {
    *limit = false;
    level = app.add_option_function<std::string>(
                   "--subdivide",
                   [&options, limit](const std::string& value) {
                     *limit = value == "limit";
                     options.level = *limit ? 0 : std::stoi(value);
                   },
                   "Subdivide the mesh first, as Blender's Subdivision Surface modifier with "
                   "this many levels (0 = not at all), or bake from its exact limit surface "
                   "('limit')")
                ->type_name("N|limit")
                ->check(CLI::Validator(
                    [](std::string& value) -> std::string {
                      if (value == "limit") return {};
                      try {
                        std::size_t used = 0;
                        const int n = std::stoi(value, &used);
                        if (used == value.size() && n >= 0 && n <= kMaxSubdivisionLevel) return {};
                      } catch (const std::exception&) {
                        // Not a number: reported below.
                      }
                      return "'" + value + "' is neither a level 0 to " +
                             std::to_string(kMaxSubdivisionLevel) + " nor 'limit'";
                    },
                    ""))
                ->default_str("0");
  }
  CLI::Option* const uvSmooth = addNamedOption(
      app, "--uv-smooth", options.uvSmooth, kSubdivisionUvSmoothNames,
      "The modifier's UV Smooth: none, keep-corners, keep-corners-junctions, "
      "keep-corners-junctions-concave, keep-boundaries, all",
      "keep-boundaries");
  CLI::Option* const boundary =
      addNamedOption(app, "--boundary-smooth", options.boundary, kSubdivisionBoundaryNames,
                     "The modifier's Boundary Smooth: all, keep-corners", "all");
  options.useCreases = true;
  options.edgeCreases.clear();
  options.vertexCreases.clear();
  CLI::Option* const edgeCrease = addCreaseOption(
      app, "--edge-crease", options.edgeCreases, parseEdgeCrease,
      "Crease of the edge between vertices A and B (0-based, in the file's order), "
      "C in [0, 1] as Blender's Edge Crease; repeatable",
      "A,B,C", "A,B,C (two vertex indices >= 0, a crease in [0, 1])");
  CLI::Option* const vertexCrease = addCreaseOption(
      app, "--vertex-crease", options.vertexCreases, parseVertexCrease,
      "Crease of vertex V (0-based), C in [0, 1] as Blender's Vertex Crease; repeatable", "V,C",
      "V,C (a vertex index >= 0, a crease in [0, 1])");
  CLI::Option* const noCreases = app.add_flag_callback(
      "--no-creases", [&options] { options.useCreases = false; },
      "Ignore the creases (the modifier's Use Creases off)");
  CLI::Option* const quality =
      app.add_option("--subdivision-quality", options.quality,
                     "The modifier's Quality: the refinement level its patches isolate "
                     "irregular and semi-sharp features to")
          ->type_name("N")
          ->check(integerIn(kMinSubdivisionQuality, kMaxSubdivisionQuality))
          ->capture_default_str();
  CLI::Option* const type =
      addNamedOption(app, "--subdivision-type", options.type, kSubdivisionTypeNames,
                     "The modifier's type: catmull-clark, simple (faces split, shape kept)",
                     "catmull-clark");
  options.autoSmoothDegrees.reset();
  CLI::Option* const autoSmooth =
      app.add_option_function<double>(
             "--auto-smooth", [&options](double degrees) { options.autoSmoothDegrees = degrees; },
             "The mesh's Auto Smooth angle in degrees: the normals of the mesh (subdivided or "
             "not) are split where its faces meet at more than this, replacing any the file "
             "gives (default: Auto Smooth off)")
          ->type_name("DEG")
          // (Range lets NaN through: every comparison with it is false.)
          ->check(CLI::Validator(
              [](std::string& text) {
                char* end = nullptr;
                const double degrees = std::strtod(text.c_str(), &end);
                return degrees >= 0.0 && degrees <= 180.0 ? std::string()
                                                          : "'" + text +
                                                                "' is not an angle "
                                                                "from 0 to 180 degrees";
              },
              "", ""));
  options.sharpEdges.clear();
  CLI::Option* const sharpEdge = addCreaseOption(
      app, "--sharp-edge", options.sharpEdges, parseSharpEdge,
      "Mark the edge between vertices A and B (0-based) sharp, as Blender's Mark Sharp: with "
      "--auto-smooth, the normals split along it; repeatable",
      "A,B", "A,B (two vertex indices >= 0)");
  options.useLimitSurface = true;
  CLI::Option* const noLimitSurface = app.add_flag_callback(
      "--no-limit-surface", [&options] { options.useLimitSurface = false; },
      "Stop at the refined cage, its points not moved to the limit surface (the modifier's "
      "Use Limit Surface off; --subdivision-quality is then unused)");
  if (!group.empty()) {  // CLI11 hides options of the empty group
    for (CLI::Option* option : {level, uvSmooth, boundary, edgeCrease, vertexCrease, noCreases,
                                quality, noLimitSurface, type, autoSmooth, sharpEdge}) {
      option->group(group);
    }
  }
}

void addTransformOption(CLI::App& app, std::string& text, const std::string& group) {
  CLI::Option* option = app.add_option(
      "--transform", text,
      "The object's matrix_world, row by row (16 numbers, or 12 without the last row 0 0 0 1, "
      "or the 3 x 3 part): shade in world space as Cycles does, heights in world units");
  if (!group.empty()) option->group(group);
}

std::optional<double> parseFiniteNumber(const std::string& word) {
  char* stop = nullptr;
  const double value = std::strtod(word.c_str(), &stop);
  if (word.empty() || *stop != '\0' || !std::isfinite(value)) return std::nullopt;
  return value;
}

Result<std::optional<ObjectTransform>> parseTransformOption(const std::string& command,
                                                            const std::string& text) {
  if (text.empty()) return std::optional<ObjectTransform>{};
  const std::string where = command + ": --transform: ";
  std::vector<double> numbers;
  std::size_t i = 0;
  while (i < text.size()) {
    if (text[i] == ',' || text[i] == ' ') {
      ++i;
      continue;
    }
    const std::size_t end = text.find_first_of(", ", i);
    const std::string word = text.substr(i, end == std::string::npos ? end : end - i);
    const std::optional<double> value = parseFiniteNumber(word);
    if (!value) return Error::badInput(where + "'" + word + "' is not a finite number");
    numbers.push_back(*value);
    i = end == std::string::npos ? text.size() : end;
  }
  const std::size_t n = numbers.size();
  if (n != 16 && n != 12 && n != 9) {
    return Error::badInput(where + "expected 16, 12 or 9 numbers (matrix_world row by row), not " +
                           std::to_string(n));
  }
  const int columns = n == 9 ? 3 : 4;
  Result<ObjectTransform> transform =
      objectTransformFromRows(numbers, static_cast<int>(n) / columns, columns);
  if (!transform) return Error::badInput(where + "the matrix " + transform.error().message);
  return std::optional<ObjectTransform>{*transform};
}

Status checkSubdivisionOptions(const std::string& command, const SubdivisionOptions& options,
                               bool limit, const CLI::App& app) {
  // Options that only shape a subdivision, given without one: a forgotten --subdivide.
  // (--auto-smooth shades the mesh as it is too; --sharp-edge then marks its edges.)
  const auto unsubdivided = [&](const char* given) {
    return Error::badInput(command + ": " + given +
                           " applies to a subdivided mesh; add --subdivide N");
  };
  // Those whose values cannot tell they were given, without any --subdivide (an explicit
  // --subdivide 0 may come with a script's copy of a modifier's settings, as Blender takes).
  if (options.level == 0 && !limit && app.count("--subdivide") == 0) {
    for (const char* option :
         {"--uv-smooth", "--boundary-smooth", "--subdivision-quality", "--no-creases"}) {
      if (app.count(option) > 0) return unsubdivided(option);
    }
  }
  // Quality is how closely Use Limit Surface approximates the limit: unused without it, and by
  // the exact limit surface.
  if (app.count("--subdivision-quality") > 0 && (limit || !options.useLimitSurface)) {
    return Error::badInput(
        command +
        ": --subdivision-quality applies with Use Limit Surface, "
        "not with " +
        (limit ? "--subdivide limit (the exact surface)" : "--no-limit-surface"));
  }
  switch (findSubdivisionConflict(options, limit)) {
    case SubdivisionConflict::kNone:
      return Ok{};
    case SubdivisionConflict::kEdgeCreasesUnsubdivided:
      return unsubdivided("--edge-crease");
    case SubdivisionConflict::kVertexCreasesUnsubdivided:
      return unsubdivided("--vertex-crease");
    case SubdivisionConflict::kNoLimitSurfaceUnsubdivided:
      return unsubdivided("--no-limit-surface");
    case SubdivisionConflict::kSimpleUnsubdivided:
      return unsubdivided("--subdivision-type simple");
    case SubdivisionConflict::kSharpEdgesWithoutAutoSmooth:
      return Error::badInput(command +
                             ": --sharp-edge needs --auto-smooth DEG (edges marked sharp split "
                             "the normals only with Auto Smooth)");
    case SubdivisionConflict::kLimitWithoutLimitSurface:
      return Error::badInput(command +
                             ": --no-limit-surface cannot be combined with --subdivide limit, "
                             "which shades the limit surface itself");
    case SubdivisionConflict::kLimitSimple:
      return Error::badInput(command +
                             ": --subdivision-type simple cannot be combined with --subdivide "
                             "limit, the Catmull-Clark limit surface");
    case SubdivisionConflict::kLimitAutoSmooth:
      return Error::badInput(command +
                             ": --auto-smooth cannot be combined with --subdivide limit, which "
                             "shades the exact surface's own normals");
    case SubdivisionConflict::kLimitSharpEdges:
      return Error::badInput(command +
                             ": --sharp-edge cannot be combined with --subdivide limit, which "
                             "shades the exact surface's own normals");
  }
  return Ok{};
}

ExitCode exitCodeFor(ErrorCode code) {
  return code == ErrorCode::kBadInput ? kExitBadInput : kExitInternal;  // (never kCancelled)
}

void printError(std::string_view message) {
  std::string line = "sgbake: error: ";
  line.append(message);
  std::replace_if(line.begin(), line.end(), [](char ch) { return ch == '\n' || ch == '\r'; },
                  ' ');
  // A NUL the message quotes (from a scene's string) would end the line for fputs: said as \0.
  for (std::size_t at = line.find('\0'); at != std::string::npos; at = line.find('\0', at + 2)) {
    line.replace(at, 1, "\\0");
  }
  line += '\n';
  std::fwrite(line.data(), 1, line.size(), stderr);
  std::fflush(stderr);
}

void printStats(const nlohmann::json& stats) {
  const std::string line =
      stats.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
  std::fputs(line.c_str(), stderr);
}

// ---- Thread cap -------------------------------------------------------------------------------

ThreadLimit::ThreadLimit(int threads) {
  if (threads > 0) {
    control_.emplace(tbb::global_control::max_allowed_parallelism,
                     static_cast<std::size_t>(threads));
  }
}

int ThreadLimit::effectiveThreads() const {
  const auto cap =
      tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism);
  return static_cast<int>(std::min<std::size_t>(
      cap, static_cast<std::size_t>(std::max(1, tbb::info::default_concurrency()))));
}

// ---- Removing temporary files when a signal ends the process ---------------------------------

namespace {

extern "C" void removeTemporariesAndDie(int signal) {
  removeTemporaryFiles();  // every unfinished AtomicFile's, the library's included
  // The handler was installed with SA_RESETHAND: re-raising runs the default action (the
  // process dies of this signal, as the parent expects) once the handler returns.
  ::raise(signal);
}

}  // namespace

void installSignalCleanup() {
  struct sigaction action {};
  action.sa_handler = removeTemporariesAndDie;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESETHAND;
  // Every signal whose default action ends the process and that a user, a shell or a job
  // scheduler sends to a running job (the crash signals, SEGV and the like, are left alone).
  for (const int signal : {SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGPIPE, SIGUSR1, SIGUSR2, SIGALRM,
                           SIGVTALRM, SIGPROF, SIGXCPU}) {
    ::sigaction(signal, &action, nullptr);
  }
  // Past a file-size limit (ulimit -f) a write fails with EFBIG instead of killing the
  // process: the error names the file, and the temporaries are removed as for any failure.
  ::signal(SIGXFSZ, SIG_IGN);
}

// ---- Output -----------------------------------------------------------------------------------

Output::Output(std::optional<AtomicFile> file) : file_(std::move(file)) {}

Output::Output(Output&& other) noexcept : file_(std::exchange(other.file_, std::nullopt)) {}

Output::~Output() {
  if (file_) file_->discard();
}

Result<Output> Output::open(const std::string& path) {
  if (path == "-") return Output(std::nullopt);
  Result<AtomicFile> file = AtomicFile::create(path);
  if (!file) return file.error();
  return Output(std::move(file.value()));
}

std::string Output::name() const { return file_ ? file_->target().string() : "-"; }

Status Output::write(std::string_view bytes) {
  if (file_) return file_->write(bytes);
  return writeStandardOutput(bytes);
}

Status writeStandardOutput(std::string_view bytes) {
  std::fflush(stdout);  // whatever stdio holds goes first
  while (!bytes.empty()) {
    const ssize_t n = ::write(STDOUT_FILENO, bytes.data(), bytes.size());
    if (n < 0) {
      if (errno == EINTR) continue;
      return Error::internal("cannot write to standard output: " +
                             std::generic_category().message(errno));
    }
    bytes.remove_prefix(static_cast<std::size_t>(n));
  }
  return Ok{};
}

Status Output::finish() {
  if (!file_) return Ok{};
  return file_->commit();
}

}  // namespace sgbake::cli
