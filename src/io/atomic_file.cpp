/// @file atomic_file.cpp
/// @brief AtomicFile on POSIX: open(O_EXCL) a sibling temporary, write(2), rename(2).
#include "sgbake/io/atomic_file.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <system_error>
#include <utility>

namespace sgbake {
namespace {

/// How many random temporary names to try before giving up (each collision is ~2^-64 likely,
/// so more than one attempt only matters when something else is creating files with our names).
constexpr int kMaxNameAttempts = 16;

std::string describeErrno(int err) { return std::generic_category().message(err); }

/// `<target>: <what>: <strerror>` — the one-line message format of every failure here.
Error ioError(ErrorCode code, const std::filesystem::path& target, std::string_view what,
              int err) {
  return {code, target.string() + ": " + std::string(what) + ": " + describeErrno(err)};
}

/// `<filename>.tmp-<pid>-<16 hex digits>` next to @p target.
std::filesystem::path makeTempName(const std::filesystem::path& target, std::mt19937_64& rng) {
  char suffix[64];
  std::snprintf(suffix, sizeof suffix, ".tmp-%ld-%016llx", static_cast<long>(::getpid()),
                static_cast<unsigned long long>(rng()));
  std::filesystem::path temp = target;
  temp += suffix;
  return temp;
}

/// The directory that holds @p target ("." for a bare file name).
std::filesystem::path parentDirectory(const std::filesystem::path& target) {
  std::filesystem::path dir = target.parent_path();
  return dir.empty() ? std::filesystem::path(".") : dir;
}

/// A file that replaces @p target keeps its permission bits (best effort: the new file simply
/// keeps the umask's mode when that fails).
void keepPermissionsOf(const std::filesystem::path& target, int fd) {
  struct stat existing {};
  if (::stat(target.c_str(), &existing) == 0 && S_ISREG(existing.st_mode)) {
    ::fchmod(fd, existing.st_mode & 07777);
  }
}

/// fsync(2) of a directory, so that a rename inside it is durable.
int syncDirectory(const std::filesystem::path& dir) {
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return errno;
  const int err = ::fsync(fd) == 0 ? 0 : errno;
  ::close(fd);
  return err;
}

// ---- The temporaries removeTemporaryFiles() removes --------------------------------------------
//
// A fixed table a signal handler may read: a slot is claimed (free → busy), filled, then
// published (busy → holds a path); the handler only reads published slots and calls unlink(2),
// which is async-signal-safe. Lock-free atomics keep the claiming safe across threads.

constexpr std::size_t kMaxTrackedTemporaries = 64;
constexpr std::size_t kMaxTrackedPathBytes = 4096;

enum SlotState : int { kFree = 0, kBusy = 1, kHoldsPath = 2, kHoldsDirectory = 3 };

struct TrackedTemporary {
  std::atomic<int> state{kFree};
  char path[kMaxTrackedPathBytes] = {};
};
static_assert(std::atomic<int>::is_always_lock_free, "the signal handler needs lock-free atomics");

TrackedTemporary g_tracked[kMaxTrackedTemporaries];

/// @return the slot now holding @p path as @p kind (a temporary file, or a directory), or -1
/// when the table is full or the path too long
int trackPath(const std::filesystem::path& path, SlotState kind) {
  const std::string& text = path.native();
  if (text.size() >= kMaxTrackedPathBytes) return -1;
  for (std::size_t i = 0; i < kMaxTrackedTemporaries; ++i) {
    int expected = kFree;
    if (!g_tracked[i].state.compare_exchange_strong(expected, kBusy)) continue;
    std::memcpy(g_tracked[i].path, text.c_str(), text.size() + 1);
    g_tracked[i].state.store(kind, std::memory_order_release);
    return static_cast<int>(i);
  }
  return -1;
}

int trackTemporary(const std::filesystem::path& path) { return trackPath(path, kHoldsPath); }

/// Frees slot @p slot of trackTemporary (nothing for -1).
void untrackTemporary(int slot) noexcept {
  if (slot >= 0) g_tracked[slot].state.store(kFree, std::memory_order_release);
}

}  // namespace

void removeTemporaryFiles() noexcept {
  std::size_t directories = 0;
  for (TrackedTemporary& tracked : g_tracked) {
    const int state = tracked.state.load(std::memory_order_acquire);
    if (state == kHoldsPath) ::unlink(tracked.path);
    directories += state == kHoldsDirectory;
  }
  // Then the directories, those left empty only: a directory inside another goes first, and a
  // slot's place in the table says nothing of that, so as many passes as there are directories.
  for (std::size_t pass = 0; pass < directories; ++pass) {
    for (TrackedTemporary& tracked : g_tracked) {
      if (tracked.state.load(std::memory_order_acquire) == kHoldsDirectory) ::rmdir(tracked.path);
    }
  }
}

int trackCreatedDirectory(const std::filesystem::path& dir) {
  return trackPath(dir, kHoldsDirectory);
}

void forgetCreatedDirectory(int handle) noexcept { untrackTemporary(handle); }

AtomicFile::AtomicFile(std::filesystem::path target, std::filesystem::path temp, int fd,
                       bool durable, int slot)
    : target_(std::move(target)), temp_(std::move(temp)), fd_(fd), durable_(durable), slot_(slot) {}

void AtomicFile::forgetTemporary() noexcept {
  untrackTemporary(slot_);
  slot_ = -1;
}

Result<AtomicFile> AtomicFile::create(const std::filesystem::path& target,
                                      const AtomicFileOptions& options) {
  if (target.empty() || !target.has_filename()) {
    // (Built with append: `"'" + std::string` trips GCC 12's false -Wrestrict, bug 105651.)
    std::string message = "'";
    message.append(target.string()).append("': not a file name");
    return Error::badInput(std::move(message));
  }
  std::error_code ec;
  if (std::filesystem::is_directory(target, ec)) {
    return Error::badInput(target.string() + ": is a directory");
  }
  // A device, pipe or socket (or a link to one, such as /dev/stdout) would be replaced by a
  // regular file: refused. (A link to a regular file is replaced like one.)
  const std::filesystem::file_status status = std::filesystem::status(target, ec);
  if (std::filesystem::exists(status) && !std::filesystem::is_regular_file(status)) {
    return Error::badInput(target.string() +
                           ": is not a regular file (a device, pipe or socket); sgbake writes "
                           "files by replacing them");
  }

  // Seeded per call from the OS: two processes (or two writers in one) never share a sequence.
  std::random_device entropy;
  std::mt19937_64 rng((static_cast<std::uint64_t>(entropy()) << 32) ^ entropy());
  for (int attempt = 0; attempt < kMaxNameAttempts; ++attempt) {
    std::filesystem::path temp = makeTempName(target, rng);
    // Tracked before it exists, so that a signal from the moment it is created removes it.
    const int slot = trackTemporary(temp);
    const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd >= 0) {
      keepPermissionsOf(target, fd);
      return AtomicFile(target, std::move(temp), fd, options.durable, slot);
    }
    const int err = errno;
    untrackTemporary(slot);
    if (err != EEXIST) return ioError(ErrorCode::kBadInput, target, "cannot create file", err);
  }
  return ioError(ErrorCode::kInternal, target, "cannot create a unique temporary file", EEXIST);
}

AtomicFile::AtomicFile(AtomicFile&& other) noexcept
    : target_(std::move(other.target_)),
      temp_(std::move(other.temp_)),
      fd_(std::exchange(other.fd_, -1)),
      finished_(std::exchange(other.finished_, false)),
      durable_(other.durable_),
      slot_(std::exchange(other.slot_, -1)) {}

AtomicFile& AtomicFile::operator=(AtomicFile&& other) noexcept {
  if (this != &other) {
    discard();
    target_ = std::move(other.target_);
    temp_ = std::move(other.temp_);
    fd_ = std::exchange(other.fd_, -1);
    finished_ = std::exchange(other.finished_, false);
    durable_ = other.durable_;
    slot_ = std::exchange(other.slot_, -1);
  }
  return *this;
}

AtomicFile::~AtomicFile() { discard(); }

void AtomicFile::discard() noexcept {
  if (fd_ < 0 && !finished_) return;
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  finished_ = false;
  ::unlink(temp_.c_str());
  forgetTemporary();
}

Status AtomicFile::write(std::string_view bytes) {
  if (fd_ < 0) return Error::internal(target_.string() + ": write after the file was closed");
  while (!bytes.empty()) {
    const ssize_t n = ::write(fd_, bytes.data(), bytes.size());
    if (n < 0) {
      if (errno == EINTR) continue;
      const int err = errno;
      discard();
      return ioError(ErrorCode::kInternal, target_, "cannot write", err);
    }
    bytes.remove_prefix(static_cast<std::size_t>(n));
  }
  return Ok{};
}

Status AtomicFile::finish() {
  if (finished_) return Ok{};
  if (fd_ < 0) return Error::internal(target_.string() + ": finish after the file was closed");
  if (durable_ && ::fsync(fd_) != 0) {
    const int err = errno;
    discard();
    return ioError(ErrorCode::kInternal, target_, "cannot sync", err);
  }
  // close() can report a deferred write error (NFS, quotas): the data is not safe to publish.
  const int closeResult = ::close(std::exchange(fd_, -1));
  if (closeResult != 0 && errno != EINTR) {
    const int err = errno;
    ::unlink(temp_.c_str());
    forgetTemporary();
    return ioError(ErrorCode::kInternal, target_, "cannot write", err);
  }
  finished_ = true;
  return Ok{};
}

Status AtomicFile::commit() {
  if (fd_ < 0 && !finished_) {
    return Error::internal(target_.string() + ": commit after the file was closed");
  }
  if (Status finished = finish(); !finished) return finished;
  finished_ = false;
  const int renamed = ::rename(temp_.c_str(), target_.c_str());
  const int renameError = errno;
  if (renamed != 0) ::unlink(temp_.c_str());
  // Only now: a signal before the rename must still find the temporary to remove.
  forgetTemporary();
  if (renamed != 0) return ioError(ErrorCode::kInternal, target_, "cannot replace file", renameError);
  if (durable_) {
    if (const int err = syncDirectory(parentDirectory(target_)); err != 0) {
      return ioError(ErrorCode::kInternal, target_, "cannot sync directory", err);
    }
  }
  return Ok{};
}

std::vector<std::filesystem::path> staleTemporaries(const std::filesystem::path& target) {
  std::vector<std::filesystem::path> stale;
  const std::string prefix = target.filename().string() + ".tmp-";
  std::filesystem::path dir = target.parent_path();
  if (dir.empty()) dir = ".";
  std::error_code ec;
  for (std::filesystem::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.size() <= prefix.size() || name.compare(0, prefix.size(), prefix) != 0) continue;
    // <pid>-<16 hex digits>, as makeTempName writes them
    const std::string rest = name.substr(prefix.size());
    const std::size_t dash = rest.find('-');
    if (dash == 0 || dash == std::string::npos || rest.size() - dash - 1 != 16 ||
        rest.find_first_not_of("0123456789") != dash ||
        rest.find_first_not_of("0123456789abcdef", dash + 1) != std::string::npos) {
      continue;
    }
    const long pid = std::strtol(rest.c_str(), nullptr, 10);
    if (pid <= 0 || pid == static_cast<long>(::getpid())) continue;
    if (::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH) {
      stale.push_back(target.parent_path() / name);
    }
  }
  std::sort(stale.begin(), stale.end());
  return stale;
}

Status writeFileAtomically(const std::filesystem::path& target, std::string_view bytes,
                           const AtomicFileOptions& options) {
  Result<AtomicFile> file = AtomicFile::create(target, options);
  if (!file) return file.error();
  if (Status s = file->write(bytes); !s) return s;
  return file->commit();
}

}  // namespace sgbake
