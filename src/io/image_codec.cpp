// Loading the image I/O module (see image_codec.hpp and sgbake/io/image_io.hpp).
#include "io/image_codec.hpp"

#include <dlfcn.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <future>
#include <mutex>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "sgbake/io/image_io.hpp"

namespace sgbake {
namespace io_detail {
namespace {

constexpr const char* kModuleFileName = "libsgbake_oiio.so";

struct LoadedModule {
  const ImageCodec* codec = nullptr;
  std::string error;  ///< when codec is nullptr
};

LoadedModule loadModule() {
  const std::filesystem::path path = imageIoModulePath();
  const std::string prefix = path.string() + ": cannot load the image I/O module (";
  // Lazy binding: only the data relocations of OpenImageIO's libraries are resolved now.
  void* handle = ::dlopen(path.c_str(), RTLD_LAZY | RTLD_LOCAL);
  if (handle == nullptr) {
    const char* reason = ::dlerror();
    return {nullptr, prefix + oneLineReason(reason ? reason : "") + ")"};
  }
  using Entry = const ImageCodec* (*)(int);
  // The module stays loaded until the process ends: the codec and its objects live in it.
  auto entry = reinterpret_cast<Entry>(::dlsym(handle, kImageCodecEntryPoint));
  if (entry == nullptr) return {nullptr, prefix + "it has no " + kImageCodecEntryPoint + ")"};
  const ImageCodec* codec = entry(kImageCodecVersion);
  if (codec == nullptr) {
    return {nullptr, prefix + "it was built for another version of libsgbake)"};
  }
  return {codec, {}};
}

std::once_flag started;
std::shared_future<LoadedModule> loading;
std::atomic<bool> loadingSet{false};  ///< `loading` holds a started load

/// Starts loadModule on a thread of its own, once; where no thread can be made, the first
/// waiter runs it.
void startLoading() {
  std::call_once(started, [] {
    try {
      loading = std::async(std::launch::async, loadModule).share();
    } catch (const std::system_error&) {
      loading = std::async(std::launch::deferred, loadModule).share();
    }
    loadingSet.store(true, std::memory_order_release);
  });
}

}  // namespace

void finishLoading() {
  if (!loadingSet.load(std::memory_order_acquire)) return;
  // A deferred load (no thread could be made) has not started: waiting would run it.
  if (loading.wait_for(std::chrono::seconds(0)) == std::future_status::deferred) return;
  loading.wait();
}

Result<const ImageCodec*> imageCodec() {
  startLoading();
  const LoadedModule& loaded = loading.get();
  if (loaded.codec == nullptr) return Error::internal(loaded.error);
  return loaded.codec;
}

std::string oneLineReason(std::string text) {
  while (!text.empty() && (text.back() == '\n' || text.back() == '\r' || text.back() == ' ')) {
    text.pop_back();
  }
  // Lines joined by "; ", each said once (a decoder may repeat "Read error" for every row).
  std::string line;
  std::vector<std::string> said;
  std::size_t start = 0;
  while (start <= text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    std::string part;
    for (std::size_t i = start; i < end; ++i) {
      const char c = text[i];
      if (c == '\r') continue;
      part += (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) ? '?' : c;
    }
    start = end + 1;
    if (part.empty() || std::find(said.begin(), said.end(), part) != said.end()) continue;
    if (!line.empty()) line += "; ";
    line += part;
    said.push_back(std::move(part));
  }
  return line.empty() ? std::string("no reason given: the file may be truncated or damaged") : line;
}

}  // namespace io_detail

void preloadImageIo() { io_detail::startLoading(); }

void finishImageIoPreload() { io_detail::finishLoading(); }

std::filesystem::path imageIoModulePath() {
  if (const char* path = std::getenv("SGBAKE_IMAGE_IO_MODULE"); path != nullptr && *path != 0) {
    return path;
  }
  // Beside the file this function was loaded from (libsgbake.so, wherever it is installed).
  Dl_info info{};
  if (::dladdr(reinterpret_cast<const void*>(&imageIoModulePath), &info) != 0 &&
      info.dli_fname != nullptr && *info.dli_fname != 0) {
    return std::filesystem::path(info.dli_fname).parent_path() / io_detail::kModuleFileName;
  }
  return io_detail::kModuleFileName;  // the dynamic loader's search path
}

}  // namespace sgbake
