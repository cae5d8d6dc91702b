/// @file image_output.hpp
/// @brief Writing baked maps to image files (EXR, PNG, TIFF through OpenImageIO, in the image I/O
/// module loaded on first use: sgbake/io/image_io.hpp), all or nothing, and the `<UDIM>` token
/// of output file names.
///
/// Every file is written to a temporary file in the target's directory and renamed over the
/// target only once it is complete (sgbake/io/atomic_file.hpp): a failed or interrupted write
/// never leaves a partial image and never touches an existing file at the target.
///
/// Orientation: FloatImage rows are top first, like every image file, so row r of the image is
/// row r of the file (CONVENTIONS.md, "Texture space"). Values are written as they are (data,
/// no colour transform); integer formats clamp to [0, 1] and round to the nearest code.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "sgbake/bake/bake.hpp"
#include "sgbake/core/result.hpp"
#include "sgbake/io/atomic_file.hpp"

namespace sgbake {

/// @brief Image file formats writeImage can produce.
enum class ImageFormat {
  kAuto,  ///< from the file name's extension (.exr, .png, .tif/.tiff; case-insensitive)
  kExr,   ///< OpenEXR, zip-compressed; half (16) or float (32) channels
  kPng,   ///< PNG, 8- or 16-bit unsigned integers
  kTiff,  ///< TIFF, zip-compressed; 8- or 16-bit unsigned integers or 32-bit float
};

/// @brief Parses a format name: "exr", "png", "tif"/"tiff" (case-insensitive).
/// @return kBadInput naming the format and listing the known ones.
Result<ImageFormat> parseImageFormat(std::string_view name);

/// @brief The lower-case name of @p format ("exr", "png", "tiff"; "auto" for kAuto).
std::string_view imageFormatName(ImageFormat format);

/// @brief The format writeImage picks for @p path with ImageFormat::kAuto.
/// @return kBadInput naming the file when the extension is missing or unknown.
Result<ImageFormat> imageFormatFromPath(const std::filesystem::path& path);

/// @brief The bit depth used when ImageWriteOptions::bitDepth is 0: 16 (EXR half, 16-bit PNG and
/// TIFF) for every map but the mask, which gets 8 bits in PNG and TIFF (its values are coverage
/// fractions; 8 bits resolve 1/255, finer than any supersampling grid up to 15×15).
int defaultBitDepth(ImageFormat format, MapKind map);

/// @brief Whether @p format can store @p bitDepth-bit channels (EXR 16/32, PNG 8/16, TIFF 8/16/32).
bool formatSupportsBitDepth(ImageFormat format, int bitDepth);

/// @brief Options of writeImage.
/// zlib level of PNG files: Blender's default PNG compression ("15%") is level 1.
inline constexpr int kPngCompressionLevel = 1;
/// libpng row filters PNG files may use (PNG_FILTER_SUB | PNG_FILTER_UP; libpng picks one per
/// row): measured on a 4096² baked normal map, files as small as or smaller than with all five
/// filters (8-bit 4.27 against 4.33 MB, 16-bit 29.2 against 31.1 MB) and written 1.4–1.6× faster.
inline constexpr int kPngFilters = 0x10 | 0x20;

struct ImageWriteOptions {
  ImageFormat format = ImageFormat::kAuto;  ///< kAuto: from the file name's extension
  /// Bits per channel: 8, 16 or 32; 0 = 16. EXR: 16 = half, 32 = float; PNG: 8 or 16-bit
  /// integers; TIFF: 8/16-bit integers or 32-bit float.
  int bitDepth = 0;
  /// Append FloatImage::coverage as an alpha channel (unassociated: colour is not divided or
  /// multiplied by it; PNG gets `oiio:UnassociatedAlpha = 1`).
  bool alpha = false;
  /// String attributes stored in the file (name, value): header attributes in EXR, text
  /// chunks in PNG (TIFF has no place for them). Names are conventionally "sgbake:...".
  std::vector<std::pair<std::string, std::string>> attributes = {};
  /// Most threads converting pixels to the file's type (0 = all cores). The file itself is
  /// written by one thread of its own (see ImageFileWriter), except with 1: then writeRows
  /// writes each strip itself, so that one thread means one busy thread.
  int threads = 0;
};

/// @brief Writes @p image to @p path, all or nothing.
///
/// Channels: 1 → grey ("Y"), 2 → R, G (plus a zero B channel in PNG and TIFF, which have no
/// two-channel colour layout: two channels would be read as grey + alpha), 3 → R, G, B; plus A
/// when options.alpha. Integer formats: each value is clamped to [0, 1] and rounded to the
/// nearest of 2^bits − 1 codes; NaN is written as 0. Float formats keep values as they are,
/// except that half (16-bit EXR) rounds to nearest even and clamps to ±65504, the largest half
/// (rather than turning larger values into infinities), float clamps infinities to ±FLT_MAX,
/// and NaN is written as 0. ImageFileWriter::clippedValues counts the values so changed.
///
/// Errors name the file, in one line: an extension writeImage does not know
/// (`out/n.jpg: unknown image format '.jpg' (use .exr, .png, .tif or .tiff)`), a bit depth the
/// format cannot store (`out/n.png: PNG cannot store 32-bit channels (use 8 or 16)`), an empty or
/// inconsistent image, and a missing or unwritable directory (`out/n.png: cannot create file: No
/// such file or directory`) are kBadInput; a failure while writing (disk full) is kInternal.
/// On any failure the target is left as it was and no temporary file remains.
Status writeImage(const FloatImage& image, const std::filesystem::path& path,
                  const ImageWriteOptions& options = {});

/// @brief An image file written strip by strip while the caller computes the next strips, all or
/// nothing (the rules, formats and errors of writeImage, which is built on it).
///
/// writeRows converts a strip of rows to the file's pixel type (in parallel) and queues it; a
/// task enqueued in the task arena open() was called in (task_arena::attach, then enqueue)
/// compresses and writes the queued strips in order (PNG's zlib, for one, is serial). So a caller
/// that bakes strip k+1 in the same arena while strip k is written overlaps the two on the arena's
/// threads, without a thread more: one of them writes between the bake's tasks, the others bake. At
/// most a few strips wait in the queue: while it is full, writeRows waits for the task, or writes
/// the queued strips itself when no thread is writing (so a writer never waits on a task that has
/// not started). With ImageWriteOptions::threads 1 there are no tasks: writeRows writes each strip
/// before it returns. commit() writes or waits for what is queued, closes the file and renames
/// it over the target; a writer destroyed without a successful commit removes its temporary at
/// once and leaves the target as it was.
///
///     Result<ImageFileWriter> out = ImageFileWriter::open("n.png", 4096, 4096, 3, options);
///     for (each strip of rows, top first) out->writeRows(row, rows, pixels, coverage);
///     Status done = out->commit();
class ImageFileWriter {
 public:
  /// @brief Creates the temporary file and opens it for a width × height image whose strips have
  /// @p channels channels (1 to 3, laid out as in writeImage).
  /// @return the errors of writeImage for the format, bit depth, size and directory
  static Result<ImageFileWriter> open(const std::filesystem::path& path, int width, int height,
                                      int channels, const ImageWriteOptions& options = {});

  ImageFileWriter(ImageFileWriter&&) noexcept;
  ImageFileWriter& operator=(ImageFileWriter&&) noexcept;
  ImageFileWriter(const ImageFileWriter&) = delete;
  ImageFileWriter& operator=(const ImageFileWriter&) = delete;
  ~ImageFileWriter();

  /// @brief Queues file rows [row, row + rows) (top first; strips must follow each other without
  /// gaps). @p pixels has rows·width·channels values, @p coverage rows·width (read only for the
  /// alpha channel; may be empty otherwise).
  /// @return an earlier write failure (kInternal, naming the file), or kInternal for a strip out
  /// of order or of the wrong size
  Status writeRows(int row, int rows, std::span<const float> pixels,
                   std::span<const float> coverage);

  /// @brief Waits for the queued strips, closes the file and renames it over the target.
  /// @return kInternal naming the file when a strip failed to write, rows are missing or the
  /// rename fails; the target is then untouched
  Status commit();

  /// @brief commit() without the rename: the complete file, closed, still under its temporary
  /// name, for the caller to commit() once every file of a run is written.
  /// @return the errors of commit() before its rename
  Result<AtomicFile> finish();

  /// Values given to writeRows so far that the file cannot store as they are, and that were
  /// clamped into its range (see writeImage): in integer files, values outside [0, 1] by more
  /// than half a code; in half files, beyond ±65504; in float files, infinities; in all, NaN.
  std::uint64_t clippedValues() const;

  /// Seconds spent inside OpenImageIO (compressing and writing), by whichever thread wrote, so
  /// far.
  double fileSeconds() const;
  /// Seconds writeRows and commit spent waiting for the strips to be written, or writing them
  /// themselves, so far: how long the caller was held up by the file.
  double waitSeconds() const;

 private:
  struct State;
  explicit ImageFileWriter(std::shared_ptr<State> state);
  std::shared_ptr<State> state_;
};

/// @brief One line (without "warning:") saying that @p clipped of the @p values values written
/// to @p file were clamped (ImageFileWriter::clippedValues) and what would keep them, for the
/// file's @p format (not kAuto) and @p bitDepth (0 = the format's default). @p integerWhat
/// replaces the words after "values" for integer files (e.g. a signed map's range); empty: the
/// [0, 1] clamp.
std::string describeClippedValues(const std::filesystem::path& file, std::uint64_t clipped,
                                  std::uint64_t values, ImageFormat format, int bitDepth,
                                  std::string_view integerWhat = {});

/// The token an output file name carries to be baked once per UDIM tile.
inline constexpr std::string_view kUdimToken = "<UDIM>";

/// @brief Whether @p path contains kUdimToken.
bool hasUdimToken(std::string_view path);

/// @brief @p path with every kUdimToken replaced by the tile number ("n.<UDIM>.png", 1002 →
/// "n.1002.png"). Paths without the token are returned unchanged.
std::string expandUdimToken(std::string_view path, int tile);

}  // namespace sgbake
