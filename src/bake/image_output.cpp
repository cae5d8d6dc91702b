/// @file image_output.cpp
/// @brief writeImage through OpenImageIO into an AtomicFile's temporary (see image_output.hpp).
#include "sgbake/bake/image_output.hpp"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <memory>
#include <new>
#include <string>
#include <vector>

#include "sgbake/io/atomic_file.hpp"

namespace sgbake {
namespace {

std::string toLower(std::string_view text) {
  std::string lower(text);
  for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return lower;
}

/// An OIIO error text (possibly several lines) as one line.
std::string oneLineReason(std::string text) {
  std::replace_if(
      text.begin(), text.end(), [](char c) { return c == '\n' || c == '\r'; }, ' ');
  while (!text.empty() && text.back() == ' ') text.pop_back();
  return text.empty() ? std::string("unknown error") : text;
}

Error fileError(ErrorCode code, const std::filesystem::path& path, std::string_view what) {
  return {code, path.string() + ": " + std::string(what)};
}

/// The name ImageOutput::create knows the format by.
const char* oiioFormatName(ImageFormat format) {
  switch (format) {
    case ImageFormat::kExr:
      return "openexr";
    case ImageFormat::kPng:
      return "png";
    case ImageFormat::kTiff:
      return "tiff";
    case ImageFormat::kAuto:
      break;
  }
  return "";
}

/// Display name in messages: "EXR", "PNG", "TIFF".
std::string upperName(ImageFormat format) {
  std::string name(imageFormatName(format));
  for (char& c : name) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return name;
}

std::string supportedDepths(ImageFormat format) {
  switch (format) {
    case ImageFormat::kExr:
      return "16 (half) or 32 (float)";
    case ImageFormat::kPng:
      return "8 or 16";
    case ImageFormat::kTiff:
      return "8, 16 or 32 (float)";
    case ImageFormat::kAuto:
      break;
  }
  return "";
}

/// OIIO's pixel type for @p bitDepth in @p format (formatSupportsBitDepth holds).
OIIO::TypeDesc pixelType(ImageFormat format, int bitDepth) {
  if (format == ImageFormat::kExr) {
    return bitDepth == 32 ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::HALF;
  }
  if (bitDepth == 32) return OIIO::TypeDesc::FLOAT;
  return bitDepth == 8 ? OIIO::TypeDesc::UINT8 : OIIO::TypeDesc::UINT16;
}

/// Integer code of @p value in [0, 1] scaled to [0, maxCode], rounded to nearest; NaN → 0.
template <class T>
T quantize(float value, float maxCode) {
  if (!(value > 0.0f)) return 0;  // also NaN
  if (value >= 1.0f) return static_cast<T>(maxCode);
  return static_cast<T>(std::lround(static_cast<double>(value) * maxCode));
}

/// The file's channels, interleaved, as floats: the image's channels (two padded to three for
/// PNG/TIFF) and the coverage as alpha.
struct FileLayout {
  int colourChannels = 0;  ///< channels taken from the image (padded with zeros)
  int fileChannels = 0;    ///< colourChannels + alpha
  std::vector<std::string> names;
};

FileLayout fileLayout(const FloatImage& image, ImageFormat format, bool alpha) {
  FileLayout layout;
  layout.colourChannels = image.channels;
  if (image.channels == 2 && format != ImageFormat::kExr) layout.colourChannels = 3;
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

/// The value of file channel @p c at texel @p texel.
float fileValue(const FloatImage& image, const FileLayout& layout, std::size_t texel, int c) {
  if (c < image.channels) {
    return image
        .pixels[texel * static_cast<std::size_t>(image.channels) + static_cast<std::size_t>(c)];
  }
  if (c < layout.colourChannels) return 0.0f;  // padding of a two-channel image
  return image.coverage[texel];                // alpha
}

/// Converts the image to the file's layout and pixel type. Integer types are quantized here
/// (clamp, round, NaN → 0) rather than by OIIO, so the rule is ours and documented.
template <class T>
std::vector<T> convertPixels(const FloatImage& image, const FileLayout& layout, float maxCode) {
  const std::size_t texels =
      static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height);
  std::vector<T> out(texels * static_cast<std::size_t>(layout.fileChannels));
  std::size_t i = 0;
  for (std::size_t t = 0; t < texels; ++t) {
    for (int c = 0; c < layout.fileChannels; ++c) {
      const float v = fileValue(image, layout, t, c);
      if constexpr (std::is_same_v<T, float>) {
        out[i++] = v;
      } else {
        out[i++] = quantize<T>(v, maxCode);
      }
    }
  }
  return out;
}

/// Checks the image's shape before anything touches the disk.
Status checkImage(const FloatImage& image, const std::filesystem::path& path, bool alpha) {
  if (image.width <= 0 || image.height <= 0) {
    return fileError(ErrorCode::kBadInput, path,
                     "cannot write an empty image (" + std::to_string(image.width) + "x" +
                         std::to_string(image.height) + ")");
  }
  if (image.channels < 1 || image.channels > 3) {
    return fileError(ErrorCode::kInternal, path,
                     "cannot write an image with " + std::to_string(image.channels) +
                         " channels (1 to 3 are supported)");
  }
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

}  // namespace

Result<ImageFormat> parseImageFormat(std::string_view name) {
  const std::string lower = toLower(name);
  if (lower == "exr" || lower == "openexr") return ImageFormat::kExr;
  if (lower == "png") return ImageFormat::kPng;
  if (lower == "tif" || lower == "tiff") return ImageFormat::kTiff;
  return Error::badInput("unknown image format '" + std::string(name) + "' (use exr, png or tiff)");
}

std::string_view imageFormatName(ImageFormat format) {
  switch (format) {
    case ImageFormat::kExr:
      return "exr";
    case ImageFormat::kPng:
      return "png";
    case ImageFormat::kTiff:
      return "tiff";
    case ImageFormat::kAuto:
      break;
  }
  return "auto";
}

Result<ImageFormat> imageFormatFromPath(const std::filesystem::path& path) {
  const std::string extension = toLower(path.extension().string());
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
  if (Status ok = checkImage(image, path, options.alpha); !ok) return ok;

  // The temporary file first: an unwritable destination fails before any conversion work.
  Result<AtomicFile> file = AtomicFile::create(path);
  if (!file) return file.error();

  const FileLayout layout = fileLayout(image, format, options.alpha);
  const OIIO::TypeDesc type = pixelType(format, bitDepth);
  OIIO::ImageSpec spec(image.width, image.height, layout.fileChannels, type);
  spec.channelnames = layout.names;
  spec.alpha_channel = options.alpha ? layout.fileChannels - 1 : -1;
  if (options.alpha) spec.attribute("oiio:UnassociatedAlpha", 1);
  if (format != ImageFormat::kPng) spec.attribute("compression", "zip");
  // Blender's default PNG compression ("15%") is zlib level 1: several times faster to write
  // than zlib's default 6, for files about 10-20% larger.
  if (format == ImageFormat::kPng) spec.attribute("png:compressionLevel", kPngCompressionLevel);
  spec.attribute("Software", "sgbake");

  std::unique_ptr<OIIO::ImageOutput> out = OIIO::ImageOutput::create(oiioFormatName(format));
  if (!out) {
    return fileError(ErrorCode::kInternal, path,
                     "OpenImageIO cannot write " + upperName(format) + " (" +
                         oneLineReason(OIIO::geterror()) + ")");
  }
  // OIIO opens the temporary by name (truncating the empty file AtomicFile created); the
  // format is chosen above, so the temporary's odd extension does not matter.
  if (!out->open(file->tempPath().string(), spec)) {
    return fileError(ErrorCode::kInternal, path,
                     "cannot write image (" + oneLineReason(out->geterror()) + ")");
  }
  bool written = false;
  try {
    if (type == OIIO::TypeDesc::UINT8) {
      const std::vector<std::uint8_t> data = convertPixels<std::uint8_t>(image, layout, 255.0f);
      written = out->write_image(OIIO::TypeDesc::UINT8, data.data());
    } else if (type == OIIO::TypeDesc::UINT16) {
      const std::vector<std::uint16_t> data = convertPixels<std::uint16_t>(image, layout, 65535.0f);
      written = out->write_image(OIIO::TypeDesc::UINT16, data.data());
    } else {
      // OIIO converts float to half (round to nearest even).
      const std::vector<float> data = convertPixels<float>(image, layout, 1.0f);
      written = out->write_image(OIIO::TypeDesc::FLOAT, data.data());
    }
  } catch (const std::bad_alloc&) {
    out->close();
    return fileError(ErrorCode::kInternal, path, "out of memory while converting the image");
  }
  const bool closed = out->close();
  if (!written || !closed) {
    return fileError(ErrorCode::kInternal, path,
                     "cannot write image (" + oneLineReason(out->geterror()) + ")");
  }
  return file->commit();  // on failure the temporary is removed and the target untouched
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
