/// @file main.cpp
/// @brief `sgbake`: the command-line tool. Parses the command line, dispatches to a subcommand
/// from the table below, and turns errors into one line on stderr and an exit code.
#include <malloc.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <exception>
#include <new>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>
#include <tbb/global_control.h>

#include "cli.hpp"
#include "sgbake/io/image_io.hpp"
#include "sgbake/sgbake.h"

namespace sgbake::cli {

// (These two belong in cli.hpp next to defineTangentsCommand.)
/// `sgbake bake`: bake the maps of a scene, or one map (bake_command.cpp).
CommandAction defineBakeCommand(CLI::App& app);
/// `sgbake convert`: a normal map between object and tangent space (convert_command.cpp).
CommandAction defineConvertCommand(CLI::App& app);

namespace {

/// Every subcommand, in the order `sgbake --help` lists them. A new subcommand (`bake`,
/// `convert`, ...) is one define function and one row here.
constexpr CommandSpec kCommands[] = {
    {"tangents", "Compute MikkTSpace tangent frames per face corner and write them as CSV",
     defineTangentsCommand},
    {"bake", "Bake normal, height, mask and other maps of a scene (or one map) to images",
     defineBakeCommand},
    {"convert", "Convert a normal map between object space and tangent space",
     defineConvertCommand},
};

constexpr const char* kDescription =
    "sgbake: Blender-compatible tangent frames and surface-gradient baking";

constexpr const char* kFooter =
    "Run 'sgbake COMMAND --help' for the options of a command.\n"
    "\n"
    "Examples:\n"
    "  sgbake tangents mesh.obj -o tangents.csv\n"
    "  sgbake tangents mesh.obj --uv 1 --threads 4 --stats > tangents.csv\n"
    "  sgbake bake meshes/default_scene.json --out-dir out\n"
    "  sgbake convert --mesh mesh.obj --from object --to tangent n_os.exr -o n_ts.exr\n"
    "\n";

/// The names of all subcommands, for messages: "tangents, bake".
std::string commandNames() {
  std::string names;
  for (const CommandSpec& spec : kCommands) {
    if (!names.empty()) names += ", ";
    names += spec.name;
  }
  return names;
}

/// CLI11's messages start like sentences ("The following argument..."); ours continue a line
/// after "sgbake: error: tangents: ". Leaves words in capitals ("MESH is required") alone.
std::string sentenceCase(std::string message) {
  if (message.size() >= 2 && std::isupper(static_cast<unsigned char>(message[0])) &&
      std::islower(static_cast<unsigned char>(message[1]))) {
    message[0] = static_cast<char>(std::tolower(static_cast<unsigned char>(message[0])));
  }
  return message;
}

/// Reports a command-line error as one line and returns the exit code; help and version
/// requests (which CLI11 also raises as exceptions) print to stdout and succeed.
int handleParseError(const CLI::App& app, const CLI::ParseError& e) {
  if (dynamic_cast<const CLI::Success*>(&e) != nullptr) {
    const int code = app.exit(e);
    // Help or a version nobody could read (a full disk, a closed pipe) is not a success.
    if (std::fflush(stdout) != 0 || std::ferror(stdout) != 0) {
      printError("cannot write to standard output: " + std::generic_category().message(errno));
      return kExitInternal;
    }
    return code;
  }

  const std::vector<CLI::App*> chosen = app.get_subcommands();
  if (!chosen.empty()) {
    const std::string name = chosen.front()->get_name();
    printError(name + ": " + sentenceCase(e.what()) + " (see 'sgbake " + name + " --help')");
    return kExitBadInput;
  }
  // No subcommand recognised: the first stray word is an unknown command or option.
  const std::vector<std::string> stray = app.remaining();
  const std::string commands = " (commands: " + commandNames() + "; see 'sgbake --help')";
  if (stray.empty()) {
    printError("no command given" + commands);
  } else if (stray.front().starts_with("-")) {
    printError("unknown option '" + stray.front() + "'" + commands);
  } else {
    printError("unknown command '" + stray.front() + "'" + commands);
  }
  return kExitBadInput;
}

int run(int argc, char** argv) {
  installSignalCleanup();

  CLI::App app(kDescription, "sgbake");
  app.set_version_flag("--version", std::string("sgbake ") + sgbake_version(),
                       "Print the version and exit");
  app.set_help_flag("-h,--help", "Print this help and exit");
  app.require_subcommand(1);
  app.footer(std::string(kFooter) + kExitCodeHelp);
  app.get_formatter()->column_width(28);
  app.get_formatter()->label("SUBCOMMAND", "COMMAND");

  std::vector<std::pair<CLI::App*, CommandAction>> commands;
  for (const CommandSpec& spec : kCommands) {
    CLI::App* sub = app.add_subcommand(spec.name, spec.summary);
    sub->group("Commands");
    sub->set_help_flag("-h,--help", "Print this help and exit");
    commands.emplace_back(sub, spec.define(*sub));
  }

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return handleParseError(app, e);
  }

  for (const auto& [sub, action] : commands) {
    if (!sub->parsed()) continue;
    // An option given an empty value ("--height-scale ''", from a script's unset variable) would
    // read as 0 or as not given at all: refused, whatever the option.
    for (const CLI::Option* option : sub->get_options()) {
      const std::vector<std::string>& values = option->results();
      if (std::find(values.begin(), values.end(), std::string()) != values.end()) {
        printError(sub->get_name() + ": " + option->get_name() +
                   " is given an empty value (see 'sgbake " + sub->get_name() + " --help')");
        return kExitBadInput;
      }
    }
    const Status status = action();
    if (status) return kExitOk;
    printError(status.error().message);
    return exitCodeFor(status.error().code);
  }
  printError("no command given (see 'sgbake --help')");  // unreachable: require_subcommand(1)
  return kExitBadInput;
}

}  // namespace
}  // namespace sgbake::cli

namespace {

/// sgbake::cli::run, where nothing may escape as a crash with a multi-line message: anything
/// thrown is an internal error (the library reports bad input as values, never by throwing).
int runCatchingEverything(int argc, char** argv) {
  try {
    return sgbake::cli::run(argc, argv);
  } catch (const std::bad_alloc&) {
    sgbake::cli::printError("out of memory");
  } catch (const std::exception& e) {
    sgbake::cli::printError(std::string("internal error: ") + e.what());
  } catch (...) {
    sgbake::cli::printError("internal error: unknown exception");
  }
  return sgbake::cli::kExitInternal;
}

}  // namespace

int main(int argc, char** argv) {
  // Keep freed memory for reuse instead of returning it to the kernel: a run allocates and frees
  // hundreds of MB phase after phase (mesh parsing, tangents, images), and every fresh page
  // costs a page fault and a zeroing in the kernel.
  ::mallopt(M_MMAP_THRESHOLD, 1 << 30);
  ::mallopt(M_TRIM_THRESHOLD, 1 << 30);
  // TBB's worker threads are joined before the process exits (below), so that it ends with one
  // thread: exit handlers (and leak checkers, which stop every thread to scan their stacks) never
  // run while workers are still being torn down.
  tbb::task_scheduler_handle scheduler{tbb::attach{}};
  const int code = runCatchingEverything(argc, argv);
  // A bad-input error can end a run while the image module is still loading (preloadImageIo):
  // the process must not exit while that thread is inside dlopen.
  sgbake::finishImageIoPreload();
  tbb::finalize(scheduler, std::nothrow);  // false (nothing joined) is harmless
  return code;
}
