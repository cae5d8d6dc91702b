// Float images and loading them through the image I/O module (see image.hpp for the conventions).

#include "sgbake/gradient/image.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <new>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>

#include "gradient/parallel_rows.hpp"
#include "io/image_check.hpp"
#include "io/image_codec.hpp"

namespace sgbake {

Image::Image(int width, int height, int channels)
    : width_(width), height_(height), channels_(channels) {
  assert(width >= 1 && height >= 1 && channels >= 1);
  data_.assign(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) *
                   static_cast<std::size_t>(channels),
               0.0f);
}

namespace {

using gradient_detail::forEachRow;
using gradient_detail::kRowGrain;

/// The exponent bits of a float: all set (kExponentBits) exactly when it is NaN or ±infinity.
constexpr std::uint32_t kExponentBits = 0x7f800000u;
inline std::uint32_t exponentBits(float v) {
  return std::bit_cast<std::uint32_t>(v) & kExponentBits;
}

// The luminance Cycles takes of a colour in a float socket (`rgb_to_y`): the Y row of Blender's
// scene-linear to XYZ matrix (Rec. 709 primaries, D65), as Cycles 3.4 computes it, measured by
// an Emission bake of pure R, G and B through a Math node. (The config's rounded 0.2126, 0.7152,
// 0.0722 move a height by up to 7e-5 of its value.)
constexpr double kLumaR = 0.212672979;
constexpr double kLumaG = 0.715152621;
constexpr double kLumaB = 0.072175443;

std::string channelsText(int n) { return std::to_string(n) + (n == 1 ? " channel" : " channels"); }

Error fileError(const std::filesystem::path& path, std::string_view what) {
  return Error::badInput(printableText(path.string()) + ": " + std::string(what));
}

/// The machine's physical memory in bytes (0 when unknown).
double physicalMemoryBytes() {
  const long pages = ::sysconf(_SC_PHYS_PAGES), pageSize = ::sysconf(_SC_PAGE_SIZE);
  return pages > 0 && pageSize > 0 ? static_cast<double>(pages) * static_cast<double>(pageSize)
                                   : 0.0;
}

/// @p bytes in GB with one decimal, e.g. "28.8".
std::string gigabytes(double bytes) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f", bytes / 1e9);
  return text;
}

}  // namespace

Result<Image> loadImage(const std::filesystem::path& path, const LoadImageOptions& options) {
  // Existence and kind first: OIIO's messages for these are vague.
  std::error_code ec;
  const std::filesystem::file_status status = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(status)) {
    return fileError(path, "cannot open file (no such file)");
  }
  if (std::filesystem::is_directory(status)) {
    return fileError(path, "cannot read file (it is a directory)");
  }
  // A device or pipe: decoders seek, and one (OpenImageIO's IFF reader on /dev/zero) never
  // returns.
  if (!std::filesystem::is_regular_file(status)) {
    return fileError(path, "cannot read file (it is not a regular file: a device, pipe or socket)");
  }
  if (const std::uintmax_t size = std::filesystem::file_size(path, ec); !ec && size == 0) {
    return fileError(path, "file is empty");
  }
  // A damaged PNG or JPEG is told here: decoded, it prints a line of its own (libpng) or comes
  // back padded with grey (libjpeg).
  if (const std::string damage = io_detail::imageDamage(path); !damage.empty()) {
    return fileError(path, "cannot read image (" + damage + ")");
  }

  Result<const io_detail::ImageCodec*> codec = io_detail::imageCodec();
  if (!codec) return codec.error();
  std::string reason;
  std::unique_ptr<io_detail::ImageReader> in = (*codec)->openReader(path, reason);
  if (!in) return fileError(path, "cannot read image (" + io_detail::oneLineReason(reason) + ")");
  const io_detail::ImageHeader spec = in->header();
  if (options.attributes != nullptr) *options.attributes = spec.attributes;
  if (spec.width <= 0 || spec.height <= 0 || spec.channels <= 0) {
    return fileError(path, "image has zero size (" + std::to_string(spec.width) + "x" +
                               std::to_string(spec.height) + ", " + channelsText(spec.channels) +
                               ")");
  }
  if (spec.depth > 1) return fileError(path, "volume images are not supported");
  if (spec.uintChannels) {
    return fileError(path,
                     "holds 32-bit unsigned integer channels (an ID or count pass), not "
                     "heights or normals");
  }
  // Channels are read by position: say so when none of the names tells which holds what (an
  // EXR of layer.pass channels, say, "baz" and "foo.bar").
  const auto colourName = [](const std::string& name) {
    const std::string last = name.substr(name.rfind('.') + 1);
    return last == "R" || last == "G" || last == "B" || last == "Y";
  };
  if (spec.channelNames.size() > 1 && options.warnings != nullptr &&
      std::none_of(spec.channelNames.begin(), spec.channelNames.end(), colourName)) {
    std::string names;
    for (const std::string& name : spec.channelNames)
      names += (names.empty() ? "'" : ", '") + name + "'";
    const int read = std::max(1, channelsToRead(options.channels, spec.channels));
    options.warnings->push_back(
        path.string() + ": no channel is named R, G, B or Y (" + names + "); the first " +
        (read == 1 ? std::string("one is") : std::to_string(read) + " are") + " read");
  }
  if (spec.subimages > 1 && options.warnings != nullptr) {
    const std::string first =
        spec.subimageName.empty() ? "the first" : "the first ('" + spec.subimageName + "')";
    options.warnings->push_back(path.string() + ": holds " + std::to_string(spec.subimages) +
                                " images (EXR parts or pages); only " + first + " is read");
  }
  if (spec.width > kMaxImageSide || spec.height > kMaxImageSide) {
    return fileError(path, "image is too large (" + std::to_string(spec.width) + "x" +
                               std::to_string(spec.height) + "; at most " +
                               std::to_string(kMaxImageSide) + " per side)");
  }
  const int readChannels = channelsToRead(options.channels, spec.channels);
  if (readChannels < 0) {
    return fileError(path, "image has " + channelsText(spec.channels) + " but " +
                               channelsNeeded(options.channels));
  }

  const int width = spec.width;
  const int height = spec.height;
  // A small compressed file can hold a huge image: refuse one that cannot be loaded here
  // before allocating it, rather than swap until the system kills the process. Loading
  // holds the floats read and, at most, the decoder's copy of the file's channels (counted
  // at 4 bytes each).
  const double texels = static_cast<double>(width) * static_cast<double>(height);
  const double needed = texels * (readChannels + spec.channels) * sizeof(float);
  if (const double memory = physicalMemoryBytes(); memory > 0 && needed > memory) {
    return fileError(path, "image is too large to load on this machine (" + std::to_string(width) +
                               "x" + std::to_string(height) + ", " + channelsText(spec.channels) +
                               ": about " + gigabytes(needed) + " GB; the machine has " +
                               gigabytes(memory) + " GB)");
  }
  Image read;
  try {
    read = Image(width, height, readChannels);
  } catch (const std::bad_alloc&) {
    return fileError(path, "image is too large to fit in memory (" + std::to_string(width) + "x" +
                               std::to_string(height) + ")");
  }

  // Read straight into bottom-up order: start at the last stored row (the file's top row) and
  // step backwards one row per scanline.
  const auto pixelBytes = static_cast<std::ptrdiff_t>(sizeof(float)) * readChannels;
  const std::ptrdiff_t rowBytes = pixelBytes * width;
  float* topRow = &read.at(0, height - 1, 0);
  if (!in->readFloat(readChannels, topRow, pixelBytes, -rowBytes)) {
    return fileError(path, "cannot read image (" + io_detail::oneLineReason(in->error()) + ")");
  }
  in.reset();

  // Non-finite values (possible in float formats) would poison every filtered sample.
  if (const std::ptrdiff_t bad = findNonFinite(read); bad >= 0) {
    const auto i = static_cast<std::size_t>(bad);
    const std::size_t texel = i / static_cast<std::size_t>(readChannels);
    const auto x = static_cast<int>(texel % static_cast<std::size_t>(width));
    const auto y = static_cast<int>(texel / static_cast<std::size_t>(width));
    return fileError(path, "pixel at column " + std::to_string(x) + ", row " +
                               std::to_string(read.yFromFileRow(y)) + " (from the top), channel " +
                               std::to_string(i % static_cast<std::size_t>(readChannels)) +
                               " is not a finite number");
  }

  // The file's channels were read as the selection needs them; only luminance is left to do.
  return selectImageChannels(std::move(read), options.channels);
}

int channelsToRead(ImageChannels selection, int channels) {
  switch (selection) {
    case ImageChannels::kAll:
      return channels;
    case ImageChannels::kFirst:
    case ImageChannels::kRed:
      return 1;
    case ImageChannels::kLuminance:
      return channels >= 3 ? 3 : 1;
    case ImageChannels::kRgb:
      return channels >= 3 ? 3 : -1;
    case ImageChannels::kGreen:
      return channels >= 2 ? 2 : -1;
    case ImageChannels::kBlue:
      return channels >= 3 ? 3 : -1;
    case ImageChannels::kAlpha:
      return channels == 2 || channels == 4 ? channels : -1;
  }
  return -1;
}

std::string channelsNeeded(ImageChannels selection) {
  switch (selection) {
    case ImageChannels::kRgb:
      return "3 are needed (RGB)";
    case ImageChannels::kGreen:
      return "a green channel is needed (2 or more channels)";
    case ImageChannels::kBlue:
      return "a blue channel is needed (3 or more channels)";
    case ImageChannels::kAlpha:
      return "an alpha channel is needed (grey + alpha, or RGBA)";
    default:
      return "1 is needed";
  }
}

Image selectImageChannels(Image image, ImageChannels selection) {
  const int have = image.channels();
  const int keep = selection == ImageChannels::kAll     ? have
                   : selection == ImageChannels::kRgb && have >= 3 ? 3
                                                                   : 1;
  if (keep == have) return image;
  // The first channel kept: one channel of a packed map, else channel 0.
  const std::size_t first = selection == ImageChannels::kAlpha   ? static_cast<std::size_t>(have - 1)
                            : selection == ImageChannels::kBlue  ? 2
                            : selection == ImageChannels::kGreen ? 1
                                                                 : 0;
  const bool luminance = selection == ImageChannels::kLuminance && have >= 3;
  Image selected(image.width(), image.height(), keep);
  const std::size_t width = static_cast<std::size_t>(image.width());
  const std::size_t from = static_cast<std::size_t>(have);
  const std::size_t to = static_cast<std::size_t>(keep);
  const float* source = image.pixels().data();
  float* target = selected.pixels().data();
  forEachRow(image.height(), [&](int y) {
    const std::size_t row = static_cast<std::size_t>(y) * width;
    const float* in = source + row * from;
    float* out = target + row * to;
    for (std::size_t x = 0; x < width; ++x) {
      if (luminance) {
        const double luma =
            kLumaR * in[x * from] + kLumaG * in[x * from + 1] + kLumaB * in[x * from + 2];
        out[x] = static_cast<float>(luma);
      } else {
        for (std::size_t c = 0; c < to; ++c) out[x * to + c] = in[x * from + first + c];
      }
    }
  });
  return selected;
}

std::ptrdiff_t findNonFinite(const Image& image, int first, int count) {
  const int channels = image.channels();
  if (count < 0) count = channels - first;
  assert(first >= 0 && count >= 0 && first + count <= channels);
  if (image.empty() || count == 0) return -1;
  const std::size_t rowValues =
      static_cast<std::size_t>(image.width()) * static_cast<std::size_t>(channels);
  const float* pixels = image.pixels().data();
  const auto stride = static_cast<std::size_t>(channels);
  const auto c0 = static_cast<std::size_t>(first);
  const auto cn = static_cast<std::size_t>(count);
  // Whether value i of a row is tested; with every channel tested, a plain run of values.
  const bool allChannels = count == channels;
  auto tested = [&](std::size_t i) { return i % stride - c0 < cn; };
  constexpr std::ptrdiff_t kNone = -1;
  auto earlier = [](std::ptrdiff_t a, std::ptrdiff_t b) {
    return a < 0 ? b : b < 0 ? a : std::min(a, b);
  };
  return tbb::parallel_reduce(
      tbb::blocked_range<int>(0, image.height(), kRowGrain), kNone,
      [&](const tbb::blocked_range<int>& rows, std::ptrdiff_t found) {
        for (int y = rows.begin(); y != rows.end() && found < 0; ++y) {
          const float* row = pixels + static_cast<std::size_t>(y) * rowValues;
          // One pass without branches (a vectorized maximum); the exact place only when the
          // largest exponent field of the row is all ones.
          std::uint32_t largest = 0;
          if (allChannels) {
            for (std::size_t i = 0; i < rowValues; ++i) {
              largest = std::max(largest, exponentBits(row[i]));
            }
          } else {
            for (std::size_t i = 0; i < rowValues; ++i) {
              largest = std::max(largest, tested(i) ? exponentBits(row[i]) : 0u);
            }
          }
          const bool any = largest == kExponentBits;
          if (!any) continue;
          for (std::size_t i = 0; i < rowValues; ++i) {
            if (tested(i) && exponentBits(row[i]) == kExponentBits) {
              found = static_cast<std::ptrdiff_t>(static_cast<std::size_t>(y) * rowValues + i);
              break;
            }
          }
        }
        return found;
      },
      earlier);
}

}  // namespace sgbake
