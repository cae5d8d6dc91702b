/// @file cli.hpp
/// @brief What every `sgbake` subcommand shares: the subcommand table entry, exit codes, error
/// reporting, timing, the thread cap and the output sink.
///
/// The CLI is a thin skin over the library: subcommands parse options, call the library, and
/// turn its sgbake::Error values into one-line messages and exit codes. Adding a subcommand is
/// one `define...Command` function and one row in the table in main.cpp.
#pragma once

#include <chrono>
#include <functional>
#include <optional>
#include <string>
#include <string_view>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <tbb/global_control.h>

#include "sgbake/core/result.hpp"
#include "sgbake/gradient/world_shading.hpp"
#include "sgbake/io/atomic_file.hpp"
#include "sgbake/subdiv/subdivide.hpp"

namespace sgbake::cli {

/// @brief Process exit codes, the same numbers as the C ABI's status codes.
enum ExitCode : int {
  kExitOk = 0,        ///< success
  kExitInternal = 1,  ///< a bug or a resource failure (out of memory, disk full)
  kExitBadInput = 2,  ///< bad usage or bad input (unreadable, invalid or unsuitable file)
};

/// @brief The exit code that reports an Error of kind @p code.
ExitCode exitCodeFor(ErrorCode code);

/// @brief Prints `sgbake: error: <message>` as exactly one line on stderr (line breaks in
/// @p message become spaces).
void printError(std::string_view message);

/// Prints @p stats as one line of JSON on standard error (--stats). Paths need not be UTF-8:
/// invalid bytes are replaced rather than thrown on.
void printStats(const nlohmann::json& stats);

/// @brief What a subcommand does once its command line has been parsed.
using CommandAction = std::function<Status()>;

/// @brief One row of the subcommand table: `sgbake <name> ...`.
struct CommandSpec {
  const char* name;
  const char* summary;  ///< one line: shown by `sgbake --help` and atop `sgbake <name> --help`
  /// Adds the subcommand's options, positionals and help footer to @p app and returns the action
  /// that runs it; the action reads the variables the options were bound to.
  CommandAction (*define)(CLI::App& app);
};

/// @brief `sgbake tangents`: MikkTSpace frames per face corner as CSV (tangents_command.cpp).
CommandAction defineTangentsCommand(CLI::App& app);

/// @brief The help-text block that ends every `--help`: what the exit codes mean.
extern const char* const kExitCodeHelp;

/// @brief CLI11 validator for options that take a count or an index: an integer >= 0 that fits
/// in an int.
extern const CLI::Validator kNonNegativeInteger;

/// @brief A CLI11 check: the value is a whole integer (no trailing text, no exponent) in
/// [@p min, @p max]; otherwise "'VALUE' is not an integer from MIN to MAX".
CLI::Validator integerIn(long long min, long long max);

/// @brief Adds --subdivide N, --uv-smooth NAME and --boundary-smooth NAME (Blender's
/// Subdivision Surface modifier, see subdivideMesh), and --edge-crease A,B,C, --vertex-crease
/// V,C (each repeatable) and --no-creases (the mesh's creases, the modifier's "Use Creases"),
/// bound to @p options; level 0 (the default) means no subdivision. Non-empty @p group files
/// them under that heading of --help. With @p limit, --subdivide also takes "limit", which sets
/// *limit (and level 0).
void addSubdivisionOptions(CLI::App& app, SubdivisionOptions& options,
                           const std::string& group = {}, bool* limit = nullptr);

/// @brief What addSubdivisionOptions cannot check while parsing, bad input reported for
/// @p command: --no-limit-surface, --subdivision-type simple or --auto-smooth with --subdivide
/// limit (@p limit); creases, sharp edges without --auto-smooth, --no-limit-surface,
/// --subdivision-type simple without any --subdivide; --uv-smooth, --boundary-smooth,
/// --subdivision-quality or --no-creases given on @p app without a --subdivide option.
Status checkSubdivisionOptions(const std::string& command, const SubdivisionOptions& options,
                               bool limit, const CLI::App& app);

/// @brief Adds --transform M (the object's matrix_world, see parseTransformOption) bound to
/// @p text, filed under @p group of --help when non-empty.
void addTransformOption(CLI::App& app, std::string& text, const std::string& group = {});

/// @brief @p word as a number when the whole of it is one and finite (strtod's syntax), else
/// none (an empty word too).
std::optional<double> parseFiniteNumber(const std::string& word);

/// @brief The object transform --transform gave @p command: 16, 12 or 9 numbers separated by
/// commas (or spaces), row by row (Blender's matrix_world: 4 rows of 4, the last 0 0 0 1; or 3
/// rows of 4 without it; or the 3 × 3 linear part). Empty @p text: none.
/// @return kBadInput naming the option and what is wrong (count, a non-number, the last row,
///         a singular matrix)
Result<std::optional<ObjectTransform>> parseTransformOption(const std::string& command,
                                                            const std::string& text);

/// @brief Measures wall-clock seconds since construction or the last lap().
class Stopwatch {
 public:
  double seconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }
  /// @brief The seconds so far; the watch restarts from now.
  double lap() {
    const auto now = std::chrono::steady_clock::now();
    const double s = std::chrono::duration<double>(now - start_).count();
    start_ = now;
    return s;
  }

 private:
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

/// @brief Caps the parallelism of everything TBB runs in this process (library kernels and the
/// CLI's own loops) while it is alive: the `--threads` option.
class ThreadLimit {
 public:
  /// @param threads the most threads to use; 0 = no cap (all cores)
  explicit ThreadLimit(int threads);
  /// @brief The number of threads TBB will actually use under this cap.
  int effectiveThreads() const;

 private:
  std::optional<tbb::global_control> control_;
};

/// @brief Installs handlers for SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGPIPE, SIGUSR1/2, SIGALRM,
/// SIGVTALRM, SIGPROF and SIGXCPU that remove the temporary files of every unfinished AtomicFile
/// (Outputs and the images the library writes) before the process dies of the signal, and
/// ignores SIGXFSZ, so that a write past a file-size limit is an error like a full disk. Call
/// once, early in main.
void installSignalCleanup();

/// @brief Writes @p bytes to standard output (unbuffered, after whatever stdio holds).
/// @return kInternal "cannot write to standard output: ..." when it fails (a closed pipe with
/// SIGPIPE ignored, a full disk, /dev/full)
Status writeStandardOutput(std::string_view bytes);

/// @brief Where a command writes its main result: standard output, or a file that appears
/// complete on finish() or not at all (AtomicFile), even when the command fails or is
/// interrupted.
class Output {
 public:
  /// @brief Standard output when @p path is "-", otherwise a new AtomicFile (an empty path is
  /// bad input, not standard output: it is usually an unset variable in a script).
  /// Opening a file creates its temporary right away, so an unwritable destination is reported
  /// before any work is done.
  static Result<Output> open(const std::string& path);

  Output(Output&& other) noexcept;
  Output& operator=(Output&&) = delete;
  Output(const Output&) = delete;
  Output& operator=(const Output&) = delete;
  ~Output();

  /// @brief Appends @p bytes.
  Status write(std::string_view bytes);
  /// @brief Publishes the output: renames the file into place, or checks standard output.
  Status finish();

  /// @brief How messages name this output: the path, or "-" for standard output.
  std::string name() const;

 private:
  explicit Output(std::optional<AtomicFile> file);

  std::optional<AtomicFile> file_;  ///< empty: standard output
};

}  // namespace sgbake::cli
