/// @file atomic_file.hpp
/// @brief Output files written all-or-nothing: a reader sees either the old file or the whole new
/// one, never a partial file, whatever happens to the writer.
///
/// The data goes to a temporary file in the target's directory (same filesystem, so the final
/// rename(2) is atomic) and is renamed over the target only when the writer commits. A writer that
/// is destroyed, fails or is discarded before committing removes its temporary file and leaves an
/// existing target byte-identical.
#pragma once

#include <filesystem>
#include <string_view>
#include <vector>

#include "sgbake/core/result.hpp"

namespace sgbake {

/// @brief Options for AtomicFile.
struct AtomicFileOptions {
  /// fsync(2) the data before the rename and the directory after it, so that the new content
  /// also survives a power loss. Off by default: it can cost more than producing the data, and
  /// the all-or-nothing guarantee towards other processes holds without it.
  bool durable = false;
};

/// @brief A file being written under a temporary name, renamed over its target by commit().
///
/// The temporary is `<target>.tmp-<pid>-<random hex>` in the target's directory, created
/// exclusively (O_EXCL) with mode 0666 minus the umask like any new file, or with the permission
/// bits of the file it will replace. A symbolic link at the target is replaced, not followed.
/// Code that must write a path itself (an image library, say) can write to tempPath() and then
/// call commit().
///
/// Errors: a target that cannot be created (missing directory, no permission, a directory in its
/// place, or a device, pipe or socket — or a link to one — that the rename would replace) is
/// ErrorCode::kBadInput; a failing write, sync or rename (disk full, I/O error) is
/// ErrorCode::kInternal. Messages name the target path.
///
/// @note Not thread-safe: one writer per thread. Move-only.
class AtomicFile {
 public:
  /// @brief Creates the temporary file next to @p target.
  static Result<AtomicFile> create(const std::filesystem::path& target,
                                   const AtomicFileOptions& options = {});

  AtomicFile(AtomicFile&& other) noexcept;
  AtomicFile& operator=(AtomicFile&& other) noexcept;
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  /// @brief Removes the temporary file unless commit() succeeded.
  ~AtomicFile();

  /// @brief Appends @p bytes to the temporary file (retrying short and interrupted writes).
  /// @note After a failed write the writer is discarded; later calls fail too.
  Status write(std::string_view bytes);

  /// @brief Closes the temporary file (syncing it when durable) without renaming it: the file
  /// is complete, and commit() will only rename it. So several files can all be written before
  /// any replaces its target. After a failure the temporary is removed. Idempotent.
  Status finish();

  /// @brief Closes the temporary file (finish(), unless done) and renames it over the target.
  /// After a failure the temporary file is removed and the target is untouched.
  Status commit();

  /// @brief Abandons the file: closes and removes the temporary. Idempotent.
  void discard() noexcept;

  /// @brief True until finish(), commit() or discard() (or a failure) ends the writer.
  bool isOpen() const { return fd_ >= 0; }

  const std::filesystem::path& target() const { return target_; }
  const std::filesystem::path& tempPath() const { return temp_; }

 private:
  /// @p slot: temp's entry in the table removeTemporaryFiles reads (made before the file was).
  AtomicFile(std::filesystem::path target, std::filesystem::path temp, int fd, bool durable,
             int slot);
  void forgetTemporary() noexcept;

  std::filesystem::path target_;
  std::filesystem::path temp_;
  int fd_ = -1;  ///< open descriptor of temp_, or -1 once finished, committed or discarded
  bool finished_ = false;  ///< temp_ is complete and closed, not yet renamed
  bool durable_ = false;
  int slot_ = -1;  ///< temp_'s entry in the table removeTemporaryFiles reads, or -1
};

/// @brief Removes the temporary file of every AtomicFile that is neither committed nor discarded
/// (in any thread), then every directory noted by trackCreatedDirectory that is left empty.
/// Async-signal-safe: meant for a handler of SIGINT/SIGTERM, which cannot run destructors, so
/// that an interrupted program leaves no temporaries, and no directories it made for them,
/// behind. The AtomicFiles themselves stay as they are (their commits will fail).
/// @note Up to 64 temporaries and directories in all, of paths up to 4095 bytes, are tracked;
/// others are not removed.
void removeTemporaryFiles() noexcept;

/// @brief Notes @p dir, a directory just made to hold outputs, for removeTemporaryFiles (which
/// removes it again if it is then empty) until forgetCreatedDirectory.
/// @return the handle forgetCreatedDirectory takes, or -1 when it could not be noted
int trackCreatedDirectory(const std::filesystem::path& dir);

/// @brief Ends what trackCreatedDirectory(…) = @p handle began (nothing for -1): the directory
/// stays, or was removed by its owner.
void forgetCreatedDirectory(int handle) noexcept;

/// @brief The temporaries of @p target (`<target>.tmp-<pid>-<hex>`) whose process no longer
/// runs on this machine: left by a run that was killed outright (SIGKILL, a crash, a power
/// loss), which nothing removes. Reported, not removed: on a shared network directory the
/// process may be another machine's.
std::vector<std::filesystem::path> staleTemporaries(const std::filesystem::path& target);

/// @brief Writes @p bytes to @p target all-or-nothing (AtomicFile::create, write, commit).
Status writeFileAtomically(const std::filesystem::path& target, std::string_view bytes,
                           const AtomicFileOptions& options = {});

}  // namespace sgbake
