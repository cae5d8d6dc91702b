/// @file image_codec.hpp
/// @brief Private: the interface between libsgbake and its image I/O module.
///
/// Decoding and encoding image files is done by OpenImageIO, which on Debian pulls in ~260
/// shared libraries (GDAL, OpenVDB, FFmpeg, …) whose loading costs ~0.2 s of symbol resolution
/// before a program linked to it reaches main. libsgbake therefore does not link OpenImageIO:
/// the few calls it needs live in a module, libsgbake_oiio.so (oiio_codec.cpp), beside
/// libsgbake.so, opened with dlopen the first time an image is read or written, or earlier on a
/// thread of its own (preloadImageIo, sgbake/io/image_io.hpp) while the caller parses a mesh.
/// Programs that never touch an image file (tangents, the C ABI's users such as the Blender
/// add-on) never load it.
///
/// Both sides are built together from this header, so the interface is plain C++ (virtual
/// calls, std::string); the module's entry point checks kImageCodecVersion against the one
/// libsgbake was built with. Errors are OpenImageIO's text, unformatted: libsgbake turns them
/// into one-line messages naming the file (oneLineReason).
#pragma once

#include <cstddef>
#include <filesystem>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "sgbake/core/result.hpp"

namespace sgbake::io_detail {

/// Bumped whenever anything in this header changes.
inline constexpr int kImageCodecVersion = 3;
/// The module's entry point: `const ImageCodec* sgbake_image_codec(int version)`, nullptr when
/// @p version is not the module's.
inline constexpr const char* kImageCodecEntryPoint = "sgbake_image_codec";

/// Pixel types of data handed to or read from the codec.
enum class PixelType { kUint8, kUint16, kHalf, kFloat };

/// Bytes per channel value of @p type.
constexpr std::size_t pixelTypeSize(PixelType type) {
  switch (type) {
    case PixelType::kUint8:
      return 1;
    case PixelType::kUint16:
    case PixelType::kHalf:
      return 2;
    case PixelType::kFloat:
      return 4;
  }
  return 0;
}

/// What an image file holds (its first subimage at full resolution).
struct ImageHeader {
  int width = 0, height = 0, depth = 1, channels = 0;
  /// The file's string attributes named "sgbake:…" (name, value), as baked files carry them
  std::vector<std::pair<std::string, std::string>> attributes;
  int subimages = 1;         ///< images (EXR parts, TIFF pages, …) in the file; the first is read
  std::string subimageName;  ///< the first's name, when it has one (an EXR part's)
  std::vector<std::string> channelNames;
  /// A floating-point format (EXR) holding 32-bit unsigned integer channels, which the codec
  /// would scale by 1/(2^32 − 1) as if they were colour (ID or count passes, not heights).
  bool uintChannels = false;
};

/// An image file opened for reading.
class ImageReader {
 public:
  virtual ~ImageReader() = default;
  virtual ImageHeader header() const = 0;
  /// Reads channels [0, channels) of every texel as float: the file's row r (top first), texel x
  /// goes to `first + r·rowStride + x·pixelStride` (strides in bytes, possibly negative).
  virtual bool readFloat(int channels, float* first, std::ptrdiff_t pixelStride,
                         std::ptrdiff_t rowStride) = 0;
  /// The reason of the last failure (possibly several lines).
  virtual std::string error() = 0;
};

/// How a file is to be written.
struct ImageWriteSpec {
  std::string format;  ///< the codec's name of the format: "openexr", "png", "tiff"
  int width = 0, height = 0, channels = 0;
  PixelType type = PixelType::kUint8;  ///< the file's pixel type
  std::vector<std::string> channelNames;
  int alphaChannel = -1;      ///< unassociated alpha, or −1
  bool zipCompression = false;
  int pngCompressionLevel = -1;  ///< zlib level of PNG files (−1: the codec's default)
  int pngFilters = -1;           ///< libpng filter mask of PNG files (−1: the codec's default)
  std::string software;
  /// Further string attributes (name, value): EXR header attributes, PNG text chunks
  std::vector<std::pair<std::string, std::string>> attributes;
};

/// An image file being written, rows top first.
class ImageWriter {
 public:
  virtual ~ImageWriter() = default;
  /// Writes rows [begin, end) from @p data (contiguous, spec.channels values per texel of type
  /// @p type; the codec converts to the file's type).
  virtual bool writeRows(int begin, int end, PixelType type, const void* data) = 0;
  /// Finishes the file.
  virtual bool close() = 0;
  virtual std::string error() = 0;
};

/// The codec: opens files for reading and writing.
class ImageCodec {
 public:
  /// nullptr and @p error on failure. Unassociated alpha is kept as stored.
  virtual std::unique_ptr<ImageReader> openReader(const std::filesystem::path& path,
                                                  std::string& error) const = 0;
  /// Creates (truncates) @p path. nullptr and @p error on failure.
  virtual std::unique_ptr<ImageWriter> openWriter(const std::filesystem::path& path,
                                                  const ImageWriteSpec& spec,
                                                  std::string& error) const = 0;

 protected:
  ~ImageCodec() = default;
};

/// The codec, loading the module on first use (or waiting for preloadImageIo's thread).
/// @return kInternal naming the module's file when it cannot be loaded.
Result<const ImageCodec*> imageCodec();

/// Waits for a load startLoading began (finishImageIoPreload, sgbake/io/image_io.hpp).
void finishLoading();

/// A codec error as one line: its lines joined by "; ", each said once, control characters '?',
/// trailing blanks gone; when empty, that no reason was given and the file may be truncated or
/// damaged.
std::string oneLineReason(std::string text);

}  // namespace sgbake::io_detail
