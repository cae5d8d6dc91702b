/// @file image_output.cpp
/// @brief writeImage through the image I/O module into an AtomicFile's temporary (see
/// image_output.hpp).
#include "sgbake/bake/image_output.hpp"

#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <ctime>
#include <deque>
#include <limits>
#include <memory>
#include <mutex>
#include <new>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include "bake/raster.hpp"
#include "io/image_codec.hpp"
#include "sgbake/core/text.hpp"
#include "sgbake/io/atomic_file.hpp"

namespace sgbake {
namespace {

/// SOURCE_DATE_EPOCH (seconds since 1970, UTC) as a TIFF/EXR DateTime ("YYYY:MM:DD hh:mm:ss"),
/// or nothing when it is unset or not a whole number of seconds.
std::optional<std::string> sourceDateTime() {
  const char* epoch = std::getenv("SOURCE_DATE_EPOCH");
  if (epoch == nullptr || *epoch == '\0') return std::nullopt;
  char* end = nullptr;
  errno = 0;
  const long long seconds = std::strtoll(epoch, &end, 10);
  if (errno != 0 || *end != '\0' || seconds < 0) return std::nullopt;
  const std::time_t time = static_cast<std::time_t>(seconds);
  std::tm utc{};
  if (gmtime_r(&time, &utc) == nullptr) return std::nullopt;
  std::array<char, 32> text{};
  if (std::strftime(text.data(), text.size(), "%Y:%m:%d %H:%M:%S", &utc) == 0) return std::nullopt;
  return std::string(text.data());
}

Error fileError(ErrorCode code, const std::filesystem::path& path, std::string_view what) {
  return {code, path.string() + ": " + std::string(what)};
}

/// What this file knows of each format it writes.
struct FormatInfo {
  ImageFormat format;
  std::string_view name;      ///< imageFormatName: "exr", "png", "tiff"
  const char* codecName;      ///< the image codec's name of the format
  std::string_view upper;     ///< display name in messages
  std::string_view depths;    ///< the bit depths it stores, for messages
};

constexpr FormatInfo kFormats[] = {
    {ImageFormat::kExr, "exr", "openexr", "EXR", "16 (half) or 32 (float)"},
    {ImageFormat::kPng, "png", "png", "PNG", "8 or 16"},
    {ImageFormat::kTiff, "tiff", "tiff", "TIFF", "8, 16 or 32 (float)"},
};

/// The entry of @p format, or nullptr for kAuto.
const FormatInfo* formatInfo(ImageFormat format) {
  for (const FormatInfo& info : kFormats)
    if (info.format == format) return &info;
  return nullptr;
}

const char* codecFormatName(ImageFormat format) {
  const FormatInfo* info = formatInfo(format);
  return info ? info->codecName : "";
}
std::string upperName(ImageFormat format) {
  const FormatInfo* info = formatInfo(format);
  return std::string(info ? info->upper : "AUTO");
}
std::string supportedDepths(ImageFormat format) {
  const FormatInfo* info = formatInfo(format);
  return std::string(info ? info->depths : "");
}

using io_detail::PixelType;

/// The file's pixel type for @p bitDepth in @p format (formatSupportsBitDepth holds).
PixelType pixelType(ImageFormat format, int bitDepth) {
  if (format == ImageFormat::kExr) return bitDepth == 32 ? PixelType::kFloat : PixelType::kHalf;
  if (bitDepth == 32) return PixelType::kFloat;
  return bitDepth == 8 ? PixelType::kUint8 : PixelType::kUint16;
}
using io_detail::oneLineReason;

/// Integer code of @p value in [0, 1] scaled to [0, maxCode], rounded to nearest; NaN → 0.
/// value·maxCode is exact in double (24 × 16 significant bits), so adding 0.5 and truncating is
/// lround's round-half-away-from-zero without its library call. Written with selects only (the
/// clamp, then one expression), so that conversion loops vectorize.
template <class T>
T quantize(float value, double maxCode) {
  const double v = static_cast<double>(value);
  const double clamped = v > 0.0 ? (v < 1.0 ? v : 1.0) : 0.0;  // NaN compares false: 0
  return static_cast<T>(clamped * maxCode + 0.5);
}

/// The file's channels: the image's channels (two padded to three for PNG/TIFF) and the
/// coverage as alpha.
struct FileLayout {
  int imageChannels = 0;   ///< channels of the strips given to writeRows
  int colourChannels = 0;  ///< channels taken from the image (padded with zeros)
  int fileChannels = 0;    ///< colourChannels + alpha
  std::vector<std::string> names;
};

FileLayout fileLayout(int imageChannels, ImageFormat format, bool alpha) {
  FileLayout layout;
  layout.imageChannels = imageChannels;
  layout.colourChannels = imageChannels;
  if (imageChannels == 2 && format != ImageFormat::kExr) layout.colourChannels = 3;
  layout.fileChannels = layout.colourChannels + (alpha ? 1 : 0);
  static const char* const kColour[] = {"R", "G", "B"};
  if (layout.colourChannels == 1) {
    layout.names.emplace_back("Y");
  } else {
    for (int c = 0; c < layout.colourChannels; ++c) layout.names.emplace_back(kColour[c]);
  }
  if (alpha) layout.names.emplace_back("A");
  return layout;
}

/// 1 unless @p value is stored as it is in an integer file of codes 0 to @p maxCode: inside
/// [0, 1] to within half a code (quantize's clamp then changes no code). 1 for NaN. Compares
/// floats without branches (`|`, not `||`), so that conversion loops vectorize.
inline unsigned outsideCodes(float value, double maxCode) {
  const float low = static_cast<float>(-0.5 / maxCode),
              high = static_cast<float>(1 + 0.5 / maxCode);
  return static_cast<unsigned>(!(value >= low)) | static_cast<unsigned>(!(value <= high));
}

/// @p value clamped to [−limit, limit], NaN → 0 (for float and half files).
inline float clampFloat(float value, float limit) {
  const float clamped = value > limit ? limit : (value < -limit ? -limit : value);
  return clamped == clamped ? clamped : 0.0f;
}

/// @p value in the file's type T (a float type: float or half files, clamped to ±@p floatLimit).
template <class T>
inline T fileValue(float value, double maxCode, float floatLimit) {
  if constexpr (std::is_same_v<T, float>) {
    return clampFloat(value, floatLimit);
  } else {
    return quantize<T>(value, maxCode);
  }
}

/// 1 when fileValue changes @p value beyond rounding (see ImageFileWriter::clippedValues), else 0.
template <class T>
inline unsigned isClipped(float value, double maxCode, float floatLimit) {
  if constexpr (std::is_same_v<T, float>) {
    return static_cast<unsigned>(!(std::fabs(value) <= floatLimit));  // NaN too
  } else {
    return outsideCodes(value, maxCode);
  }
}

/// Converts @p texels texels (image channels in @p pixels, alpha from @p coverage) to the file's
/// layout and pixel type T at @p out. Integer types are quantized here (clamp, round, NaN → 0)
/// rather than by the codec, so the rule is ours and documented; float types (float and half
/// files) are clamped to ±@p floatLimit, NaN → 0. @return the number of values the file cannot
/// store as they are.
template <class T>
std::uint64_t convertTexels(const float* pixels, const float* coverage, std::size_t texels,
                            const FileLayout& layout, double maxCode, float floatLimit, T* out) {
  unsigned clipped = 0;  // per row of a strip: fewer than 2^32 values
  const std::size_t in = static_cast<std::size_t>(layout.imageChannels);
  if (layout.fileChannels == layout.imageChannels) {  // no alpha, no padding channel: value by value
    const std::size_t values = texels * in;
    // The count is a local of the loop: a reference could alias out (uint8_t aliases anything)
    // and would be stored and reloaded for every value, which stops the loop vectorizing.
    for (std::size_t i = 0; i < values; ++i) {
      clipped += isClipped<T>(pixels[i], maxCode, floatLimit);
      out[i] = fileValue<T>(pixels[i], maxCode, floatLimit);
    }
    return clipped;
  }
  for (std::size_t t = 0; t < texels; ++t) {
    for (int c = 0; c < layout.fileChannels; ++c) {
      float v = 0.0f;  // padding of a two-channel image
      if (c < layout.imageChannels) {
        v = pixels[t * in + static_cast<std::size_t>(c)];
      } else if (c >= layout.colourChannels) {
        v = coverage[t];  // alpha
      }
      clipped += isClipped<T>(v, maxCode, floatLimit);
      *out++ = fileValue<T>(v, maxCode, floatLimit);
    }
  }
  return clipped;
}

/// Checks the image's shape before anything touches the disk.
Status checkShape(int width, int height, int channels, const std::filesystem::path& path) {
  if (width <= 0 || height <= 0) {
    return fileError(ErrorCode::kBadInput, path,
                     "cannot write an empty image (" + std::to_string(width) + "x" +
                         std::to_string(height) + ")");
  }
  if (channels < 1 || channels > 3) {
    return fileError(ErrorCode::kInternal, path,
                     "cannot write an image with " + std::to_string(channels) +
                         " channels (1 to 3 are supported)");
  }
  return Ok{};
}

/// Checks that the image holds the values its shape (checked by ImageFileWriter::open) needs.
Status checkContents(const FloatImage& image, const std::filesystem::path& path, bool alpha) {
  const std::size_t texels =
      static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height);
  if (image.pixels.size() != texels * static_cast<std::size_t>(image.channels)) {
    return fileError(ErrorCode::kInternal, path,
                     "image has " + std::to_string(image.pixels.size()) + " values for its size");
  }
  if (alpha && image.coverage.size() != texels) {
    return fileError(ErrorCode::kInternal, path, "image has no coverage for its alpha channel");
  }
  return Ok{};
}

/// Strips writeRows may queue ahead of the one being written before it waits: two bands of
/// bakeMapRows (256 rows each), so that the bake hands a band over without waiting while the
/// band before is still being written; fewer (but at least kMinQueuedStrips) when they would
/// hold more than kMaxQueuedBytes (wide images: a 16384-wide 16-bit RGB strip is 6.3 MB).
constexpr std::size_t kMaxQueuedStrips = 8;
constexpr std::size_t kMinQueuedStrips = 2;
constexpr std::size_t kMaxQueuedBytes = std::size_t{16} << 20;
/// Rows per strip a task compresses: writeRows splits larger requests, so that converting one
/// strip overlaps compressing the one before.
constexpr int kStripRows = 64;

using Clock = std::chrono::steady_clock;
double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

}  // namespace

/// Everything an ImageFileWriter owns. Queued strips are written by tasks enqueued in the task
/// arena open() was called in (see writeRows), which hold the state by a shared_ptr, and the
/// state holds that arena, so that the arena a task runs in outlives a temporary task_arena
/// that made it. finish (or the writer's destruction) waits until every task enqueued for the
/// strips has started: none holds the state past the writer (a task that starts once the
/// strips are written finds the queue empty and returns).
struct ImageFileWriter::State : std::enable_shared_from_this<ImageFileWriter::State> {
  std::filesystem::path path;
  AtomicFile file;
  std::unique_ptr<io_detail::ImageWriter> out;
  FileLayout layout;
  /// Pixel type of the strips' data: the file's integer type, or float for float and half files
  /// (the codec converts float to half, rounding to nearest even).
  PixelType stripType = PixelType::kFloat;
  int width = 0, height = 0, threads = 0;
  int nextRow = 0;  ///< first row writeRows expects next

  struct Strip {
    int row = 0, rows = 0;
    std::vector<std::byte> data;
  };
  std::mutex mutex;
  std::condition_variable changed;  ///< a strip was written, or writing stopped
  std::deque<Strip> queue;
  std::size_t queuedBytes = 0;                ///< of the strips in `queue`
  std::vector<std::vector<std::byte>> spare;  ///< written strips' buffers, for reuse
  /// Strips are handed to tasks (threads != 1); else writeRows writes each one itself.
  bool tasks = false;
  bool writing = false;    ///< a thread is writing strips (one at a time, in order)
  bool scheduled = false;  ///< a task is enqueued and has not started yet
  bool failed = false;     ///< a strip failed to write (the rest are dropped)
  bool abandoned = false;  ///< the writer is destroyed uncommitted: queued strips are dropped
  std::string failure;     ///< the codec's reason, one line
  double fileSeconds = 0;  ///< time inside the codec (guarded by mutex)
  double waitSeconds = 0;  ///< caller's time waiting for the queue, or writing itself
  /// Largest magnitude a float strip value keeps: ±65504 (the largest half) or FLT_MAX
  float floatLimit = std::numeric_limits<float>::max();
  std::uint64_t clipped = 0;  ///< values the file cannot store as they are (see clippedValues)
  /// The caller's arena at open(), where the tasks are enqueued (kept alive by this handle).
  tbb::task_arena arena{tbb::task_arena::attach()};

  explicit State(AtomicFile f) : file(std::move(f)) {}

  /// Writes the queued strips in order, unless another thread is writing them already; returns
  /// when the queue is empty. Called with @p lock held, returns it held.
  void drain(std::unique_lock<std::mutex>& lock) {
    if (writing) return;
    writing = true;
    while (!queue.empty()) {
      Strip strip = std::move(queue.front());
      queue.pop_front();
      queuedBytes -= strip.data.size();
      const bool skip = failed || abandoned;
      lock.unlock();
      changed.notify_all();  // room in the queue
      bool ok = true;
      const Clock::time_point start = Clock::now();
      if (!skip)
        ok = out->writeRows(strip.row, strip.row + strip.rows, stripType, strip.data.data());
      const double seconds = secondsSince(start);
      lock.lock();
      fileSeconds += seconds;
      spare.push_back(std::move(strip.data));
      if (!ok && !failed) {
        failed = true;
        failure = oneLineReason(out->error());
      }
    }
    writing = false;
    changed.notify_all();
  }

  /// Whether writeRows must wait before it queues another strip (kMaxQueuedStrips).
  bool full() const {
    return queue.size() >= kMaxQueuedStrips ||
           (queue.size() >= kMinQueuedStrips && queuedBytes >= kMaxQueuedBytes);
  }

  /// Has a task of the caller's arena drain the queue, unless one is about to or a thread is
  /// writing (it takes the new strip before it stops). Called with mutex held.
  void schedule() {
    if (writing || scheduled) return;
    scheduled = true;
    arena.enqueue([self = shared_from_this()] {
      std::unique_lock lock(self->mutex);
      self->scheduled = false;
      self->changed.notify_all();  // flush() may wait for this start
      self->drain(lock);
    });
  }

  /// Waits until every queued strip is written (writing them itself when no thread is), and
  /// until a task enqueued for them has started: it finds nothing left to write, and no task
  /// holds the state past the writer (a task never run would keep it, and its arena, forever).
  void flush() {
    const Clock::time_point start = Clock::now();
    std::unique_lock lock(mutex);
    for (;;) {
      drain(lock);
      if (writing) {
        changed.wait(lock, [&] { return !writing; });
      } else if (scheduled) {
        changed.wait(lock, [&] { return !scheduled; });  // enqueue: a thread will run it
      } else {
        break;
      }
    }
    std::vector<std::vector<std::byte>>().swap(spare);  // not kept until a late task lets go
    waitSeconds += secondsSince(start);
  }

  /// Converts rows [row, row + rows) (in parallel) and queues them for the thread, waiting
  /// while the queue is full.
  Status queueStrip(int row, int rows, std::span<const float> pixels,
                    std::span<const float> coverage);

  Error writeFailure() const {
    return fileError(ErrorCode::kInternal, path, "cannot write image (" + failure + ")");
  }
};

ImageFileWriter::ImageFileWriter(std::shared_ptr<State> state) : state_(std::move(state)) {}
ImageFileWriter::ImageFileWriter(ImageFileWriter&&) noexcept = default;
ImageFileWriter& ImageFileWriter::operator=(ImageFileWriter&&) noexcept = default;

ImageFileWriter::~ImageFileWriter() {
  if (!state_) return;
  {
    std::lock_guard lock(state_->mutex);
    state_->abandoned = true;  // no use compressing strips of a file that will be removed
  }
  state_->flush();
  if (state_->out) state_->out->close();
  // Now, not when a task that is still enqueued lets the state go: the temporary goes, the
  // target stays.
  state_->out.reset();
  state_->file.discard();
}

Result<ImageFileWriter> ImageFileWriter::open(const std::filesystem::path& path, int width,
                                              int height, int channels,
                                              const ImageWriteOptions& options) {
  ImageFormat format = options.format;
  if (format == ImageFormat::kAuto) {
    Result<ImageFormat> fromPath = imageFormatFromPath(path);
    if (!fromPath) return fromPath.error();
    format = *fromPath;
  }
  const int bitDepth = options.bitDepth == 0 ? 16 : options.bitDepth;
  if (!formatSupportsBitDepth(format, bitDepth)) {
    return fileError(ErrorCode::kBadInput, path,
                     upperName(format) + " cannot store " + std::to_string(bitDepth) +
                         "-bit channels (use " + supportedDepths(format) + ")");
  }
  if (Status ok = checkShape(width, height, channels, path); !ok) return ok.error();

  // The temporary file first: an unwritable destination fails before any conversion work.
  Result<AtomicFile> file = AtomicFile::create(path);
  if (!file) return file.error();
  auto state = std::make_shared<State>(std::move(*file));
  state->path = path;
  state->width = width;
  state->height = height;
  state->threads = options.threads;
  state->layout = fileLayout(channels, format, options.alpha);
  const PixelType fileType = pixelType(format, bitDepth);
  state->stripType = fileType == PixelType::kHalf ? PixelType::kFloat : fileType;
  if (fileType == PixelType::kHalf) state->floatLimit = 65504.0f;
  const FileLayout& layout = state->layout;

  io_detail::ImageWriteSpec spec;
  spec.format = codecFormatName(format);
  spec.width = width;
  spec.height = height;
  spec.channels = layout.fileChannels;
  spec.type = fileType;
  spec.channelNames = layout.names;
  spec.alphaChannel = options.alpha ? layout.fileChannels - 1 : -1;
  spec.zipCompression = format != ImageFormat::kPng;
  // Blender's default PNG compression ("15%") is zlib level 1: several times faster to write
  // than zlib's default 6, for files about 10-20% larger.
  if (format == ImageFormat::kPng) {
    spec.pngCompressionLevel = kPngCompressionLevel;
    spec.pngFilters = kPngFilters;
  }
  spec.software = "sgbake";
  spec.attributes = options.attributes;
  // OpenImageIO's EXR and TIFF writers stamp the time of writing (DateTime, EXR capDate), so
  // two identical bakes differ in those bytes: with SOURCE_DATE_EPOCH set (the
  // reproducible-builds convention) the stamp is that time, and the files are identical.
  if (const std::optional<std::string> stamp = sourceDateTime()) {
    spec.attributes.emplace_back("DateTime", *stamp);
  }

  Result<const io_detail::ImageCodec*> codec = io_detail::imageCodec();
  if (!codec) return codec.error();
  // The codec opens the temporary by name (truncating the empty file AtomicFile created); the
  // format is chosen above, so the temporary's odd extension does not matter.
  std::string reason;
  state->out = (*codec)->openWriter(state->file.tempPath(), spec, reason);
  if (!state->out) {
    return fileError(ErrorCode::kInternal, path,
                     "cannot write " + upperName(format) + " image (" + oneLineReason(reason) + ")");
  }
  // One thread asked for, or only one to be had: writeRows writes each strip itself.
  state->tasks =
      options.threads != 1 && state->arena.max_concurrency() > 1 &&
      tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism) > 1;
  return ImageFileWriter(std::move(state));
}

Status ImageFileWriter::writeRows(int row, int rows, std::span<const float> pixels,
                                  std::span<const float> coverage) {
  State& s = *state_;
  const FileLayout& layout = s.layout;
  const std::size_t width = static_cast<std::size_t>(s.width);
  const std::size_t texels = static_cast<std::size_t>(std::max(rows, 0)) * width;
  const bool alpha = layout.fileChannels > layout.colourChannels;
  if (row != s.nextRow || rows < 0 || row + rows > s.height ||
      pixels.size() != texels * static_cast<std::size_t>(layout.imageChannels) ||
      (alpha && coverage.size() != texels)) {
    return fileError(ErrorCode::kInternal, s.path,
                     "rows " + std::to_string(row) + " to " + std::to_string(row + rows) +
                         " do not continue the image or have the wrong size");
  }
  s.nextRow = row + rows;
  const std::size_t imageRowValues = width * static_cast<std::size_t>(layout.imageChannels);
  for (int first = row; first < row + rows; first += kStripRows) {
    const int count = std::min(kStripRows, row + rows - first);
    const std::size_t skipped = static_cast<std::size_t>(first - row);
    const std::span<const float> stripCoverage =
        alpha ? coverage.subspan(skipped * width, static_cast<std::size_t>(count) * width)
              : std::span<const float>{};
    if (Status ok = s.queueStrip(first, count,
                                 pixels.subspan(skipped * imageRowValues,
                                                static_cast<std::size_t>(count) * imageRowValues),
                                 stripCoverage);
        !ok) {
      return ok;
    }
  }
  return Ok{};
}

Status ImageFileWriter::State::queueStrip(int row, int rows, std::span<const float> pixels,
                                          std::span<const float> coverage) {
  const std::size_t rowTexels = static_cast<std::size_t>(width);
  const std::size_t texels = static_cast<std::size_t>(rows) * rowTexels;
  const bool alpha = layout.fileChannels > layout.colourChannels;
  Strip strip;
  strip.row = row;
  strip.rows = rows;
  const std::size_t values = texels * static_cast<std::size_t>(layout.fileChannels);
  {
    std::lock_guard lock(mutex);  // a buffer the thread is done with: no fresh pages to fault in
    if (!spare.empty()) {
      strip.data = std::move(spare.back());
      spare.pop_back();
    }
  }
  try {
    strip.data.resize(values * io_detail::pixelTypeSize(stripType));
  } catch (const std::bad_alloc&) {
    return fileError(ErrorCode::kInternal, path, "out of memory while converting the image");
  }
  // Convert row by row in parallel (the file's thread meanwhile compresses earlier strips).
  const std::size_t fileRowValues = rowTexels * static_cast<std::size_t>(layout.fileChannels);
  const std::size_t imageRowValues = rowTexels * static_cast<std::size_t>(layout.imageChannels);
  auto convertRow = [&](std::size_t r) -> std::uint64_t {
    const float* in = pixels.data() + r * imageRowValues;
    const float* cov = alpha ? coverage.data() + r * rowTexels : nullptr;
    std::byte* to = strip.data.data() + r * fileRowValues * io_detail::pixelTypeSize(stripType);
    if (stripType == PixelType::kUint8) {
      return convertTexels(in, cov, rowTexels, layout, 255.0, 0.0f,
                           reinterpret_cast<std::uint8_t*>(to));
    }
    if (stripType == PixelType::kUint16) {
      return convertTexels(in, cov, rowTexels, layout, 65535.0, 0.0f,
                           reinterpret_cast<std::uint16_t*>(to));
    }
    return convertTexels(in, cov, rowTexels, layout, 1.0, floatLimit, reinterpret_cast<float*>(to));
  };
  std::atomic<std::uint64_t> stripClipped{0};
  bake_detail::runWithThreads(threads, [&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, static_cast<std::size_t>(rows), 4),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                        std::uint64_t count = 0;
                        for (std::size_t r = range.begin(); r != range.end(); ++r) {
                          count += convertRow(r);
                        }
                        if (count != 0) stripClipped.fetch_add(count, std::memory_order_relaxed);
                      });
  });
  clipped += stripClipped.load(std::memory_order_relaxed);
  const Clock::time_point start = Clock::now();
  std::unique_lock lock(mutex);
  if (!tasks) {  // threads == 1: write the strip here
    queuedBytes += strip.data.size();
    queue.push_back(std::move(strip));
    drain(lock);
    waitSeconds += secondsSince(start);  // the caller is held up by the file, as by a wait
    return failed ? Status{writeFailure()} : Status{Ok{}};
  }
  // A full queue: the task writing is behind; wait for it, or write when none is.
  while (!failed && full()) {
    if (!writing) {
      drain(lock);
    } else {
      changed.wait(lock, [&] { return failed || !writing || !full(); });
    }
  }
  waitSeconds += secondsSince(start);
  if (failed) return writeFailure();
  queuedBytes += strip.data.size();
  queue.push_back(std::move(strip));
  schedule();
  return Ok{};
}

Result<AtomicFile> ImageFileWriter::finish() {
  State& s = *state_;
  s.flush();
  if (s.failed) return s.writeFailure();
  if (s.nextRow != s.height) {
    return fileError(ErrorCode::kInternal, s.path,
                     "only " + std::to_string(s.nextRow) + " of " + std::to_string(s.height) +
                         " rows were written");
  }
  const bool closed = s.out->close();
  if (!closed) {
    return fileError(ErrorCode::kInternal, s.path,
                     "cannot write image (" + oneLineReason(s.out->error()) + ")");
  }
  if (Status finished = s.file.finish(); !finished) return finished.error();
  return std::move(s.file);
}

std::uint64_t ImageFileWriter::clippedValues() const { return state_->clipped; }

std::string describeClippedValues(const std::filesystem::path& file, std::uint64_t clipped,
                                  std::uint64_t values, ImageFormat format, int bitDepth,
                                  std::string_view integerWhat) {
  const int depth = bitDepth == 0 ? 16 : bitDepth;  // as ImageFileWriter::open resolves it
  const bool floatFile = format == ImageFormat::kExr || depth == 32;
  std::string what;
  if (floatFile && depth != 32) {
    what =
        "were beyond ±65504, the largest half float, and were clamped to it: a 32-bit EXR "
        "(\"bit_depth\": 32, --bit-depth 32) keeps them";
  } else if (floatFile) {
    what = "were infinite or NaN (a layer's scale or strength too large?) and were clamped";
  } else if (!integerWhat.empty()) {
    what = integerWhat;
  } else {
    what =
        "were outside [0, 1], all an integer file stores, and were clamped to it: an EXR or "
        "a 32-bit TIFF keeps them";
  }
  return file.string() + ": " + std::to_string(clipped) + " of " + std::to_string(values) +
         " values " + what;
}

Status ImageFileWriter::commit() {
  Result<AtomicFile> file = finish();
  if (!file) return file.error();
  return file->commit();  // on failure the temporary is removed and the target untouched
}

double ImageFileWriter::fileSeconds() const {
  std::lock_guard lock(state_->mutex);
  return state_->fileSeconds;
}

double ImageFileWriter::waitSeconds() const { return state_->waitSeconds; }

Result<ImageFormat> parseImageFormat(std::string_view name) {
  const std::string lower = toLowerAscii(name);
  if (lower == "exr" || lower == "openexr") return ImageFormat::kExr;
  if (lower == "png") return ImageFormat::kPng;
  if (lower == "tif" || lower == "tiff") return ImageFormat::kTiff;
  return Error::badInput("unknown image format '" + std::string(name) + "' (use exr, png or tiff)");
}

std::string_view imageFormatName(ImageFormat format) {
  const FormatInfo* info = formatInfo(format);
  return info ? info->name : "auto";
}

Result<ImageFormat> imageFormatFromPath(const std::filesystem::path& path) {
  const std::string extension = toLowerAscii(path.extension().string());
  if (extension == ".exr") return ImageFormat::kExr;
  if (extension == ".png") return ImageFormat::kPng;
  if (extension == ".tif" || extension == ".tiff") return ImageFormat::kTiff;
  const std::string what = extension.empty()
                               ? std::string("file name has no extension")
                               : "unknown image format '" + path.extension().string() + "'";
  return fileError(ErrorCode::kBadInput, path, what + " (use .exr, .png, .tif or .tiff)");
}

int defaultBitDepth(ImageFormat format, MapKind map) {
  if (map == MapKind::kMask && (format == ImageFormat::kPng || format == ImageFormat::kTiff)) {
    return 8;
  }
  return 16;
}

bool formatSupportsBitDepth(ImageFormat format, int bitDepth) {
  switch (format) {
    case ImageFormat::kExr:
      return bitDepth == 16 || bitDepth == 32;
    case ImageFormat::kPng:
      return bitDepth == 8 || bitDepth == 16;
    case ImageFormat::kTiff:
      return bitDepth == 8 || bitDepth == 16 || bitDepth == 32;
    case ImageFormat::kAuto:
      break;
  }
  return false;
}

Status writeImage(const FloatImage& image, const std::filesystem::path& path,
                  const ImageWriteOptions& options) {
  // Format, depth and shape first (by open), then the image's contents, as documented.
  Result<ImageFileWriter> writer =
      ImageFileWriter::open(path, image.width, image.height, image.channels, options);
  if (!writer) return writer.error();
  if (Status ok = checkContents(image, path, options.alpha); !ok) return ok;
  const std::span<const float> coverage =
      options.alpha ? std::span<const float>(image.coverage) : std::span<const float>{};
  if (Status ok = writer->writeRows(0, image.height, image.pixels, coverage); !ok) return ok;
  return writer->commit();
}

bool hasUdimToken(std::string_view path) { return path.find(kUdimToken) != std::string_view::npos; }

std::string expandUdimToken(std::string_view path, int tile) {
  const std::string number = std::to_string(tile);
  std::string out;
  out.reserve(path.size());
  std::size_t start = 0;
  for (std::size_t at = path.find(kUdimToken); at != std::string_view::npos;
       at = path.find(kUdimToken, start)) {
    out.append(path.substr(start, at - start)).append(number);
    start = at + kUdimToken.size();
  }
  out.append(path.substr(start));
  return out;
}

}  // namespace sgbake
