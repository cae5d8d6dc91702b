/// @file image.hpp
/// @brief Float images in texture space, and reading them from files (PNG, TIFF, EXR, … via
/// OpenImageIO).
///
/// Orientation (CONVENTIONS.md, "Texture space"): texel (x, y) has its centre at
/// `s = (x + 0.5) / W`, `t = (y + 0.5) / H`, with x to the right and **y up**. Rows are stored
/// **bottom-up**: row y = 0 is the bottom of the picture (t near 0), which is the *last* row of
/// the file. A texel in file row r (0 = the top row of the file) therefore has `y = H - 1 - r`
/// and `t = 1 - (r + 0.5) / H`. (Blender's `Image.pixels` uses the same bottom-up order.)
#pragma once

#include <cassert>
#include <cstddef>
#include <filesystem>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "sgbake/core/result.hpp"
#include "sgbake/core/vec.hpp"

namespace sgbake {

/// Largest width or height loadImage accepts, in texels.
inline constexpr int kMaxImageSide = 65536;

/// @brief A W×H image of C float32 channels, in texture space (see the file comment).
///
/// Storage: `pixels()[(y * W + x) * C + c]`, rows bottom-up (y = 0 is the bottom row, t ≈ 0),
/// channels interleaved. Values are whatever the source held: integer file formats map to
/// [0, 1], float formats are kept raw; no colour-space conversion is ever applied (images are
/// data, like Blender's "Non-Color").
///
/// An Image is a plain value (copyable, movable). A default-constructed Image is empty (0×0×0).
class Image {
 public:
  Image() = default;

  /// @brief A zero-filled image.
  /// @param[in] width    W, texels (≥ 1)
  /// @param[in] height   H, texels (≥ 1)
  /// @param[in] channels C (≥ 1)
  /// @note Preconditions: all three ≥ 1 (asserted); W·H·C must fit in memory.
  Image(int width, int height, int channels);

  int width() const { return width_; }        ///< W, texels
  int height() const { return height_; }      ///< H, texels
  int channels() const { return channels_; }  ///< C
  bool empty() const { return data_.empty(); }

  /// @brief Channel @p c of texel (x, y), y counted from the bottom row.
  /// @note Preconditions: 0 ≤ x < W, 0 ≤ y < H, 0 ≤ c < C (asserted in debug builds).
  float at(int x, int y, int c = 0) const { return data_[index(x, y, c)]; }
  float& at(int x, int y, int c = 0) { return data_[index(x, y, c)]; }

  /// @brief All W·H·C values, bottom row first, channels interleaved.
  std::span<const float> pixels() const { return data_; }
  std::span<float> pixels() { return data_; }

  /// @brief Moves the W·H·C values out (as pixels() lays them out), leaving the image empty
  /// (0×0×0).
  std::vector<float> takePixels() {
    width_ = height_ = channels_ = 0;
    return std::exchange(data_, {});
  }

  /// @brief Texture coordinates (s, t) of the centre of texel (x, y): ((x+0.5)/W, (y+0.5)/H).
  Vec2d texelCentre(int x, int y) const { return {(x + 0.5) / width_, (y + 0.5) / height_}; }

  /// @brief The y of file row @p fileRow (0 = top row of the file): H - 1 - fileRow.
  int yFromFileRow(int fileRow) const { return height_ - 1 - fileRow; }

 private:
  std::size_t index(int x, int y, int c) const {
    assert(x >= 0 && x < width_ && y >= 0 && y < height_ && c >= 0 && c < channels_);
    return (static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) +
            static_cast<std::size_t>(x)) *
               static_cast<std::size_t>(channels_) +
           static_cast<std::size_t>(c);
  }

  int width_ = 0;
  int height_ = 0;
  int channels_ = 0;
  std::vector<float> data_;
};

/// @brief Which channels loadImage keeps.
enum class ImageChannels {
  kAll,    ///< every channel of the file, in the file's order (OIIO puts R, G, B, A first)
  kFirst,  ///< channel 0 only (grey, or R): the usual height-map channel → C = 1
  /// Rec. 709 luminance `0.212672979 R + 0.715152621 G + 0.072175443 B` of channels 0–2 when
  /// the file has at least three channels, else channel 0 → C = 1. These are the weights Cycles
  /// uses when a colour is plugged into a float socket (e.g. an RGB image into the Bump node's
  /// Height): the Y row of Blender's scene-linear to XYZ matrix, measured from Cycles 3.4 (not
  /// the config's rounded 0.2126, 0.7152, 0.0722); the values are not linearised (Non-Color).
  kLuminance,
  kRgb,  ///< channels 0, 1, 2 (normal maps) → C = 3; files with fewer channels fail
  /// One channel as it is stored → C = 1 (a height packed into a channel of another map):
  /// R, G, B = channel 0, 1, 2; A = the last channel of a grey+alpha or RGBA image. Files
  /// without it fail.
  kRed,
  kGreen,
  kBlue,
  kAlpha,
};

/// @brief How many leading channels of an image of @p channels channels @p selection reads,
/// or −1 when the image lacks what it needs (kRgb with fewer than 3, kAlpha without 2 or 4…).
int channelsToRead(ImageChannels selection, int channels);

/// @brief What @p selection needs, for messages after "image has 2 channels but ": "3 are
/// needed (RGB)", "an alpha channel is needed (grey + alpha, or RGBA)", …
std::string channelsNeeded(ImageChannels selection);

/// @brief Options for loadImage.
struct LoadImageOptions {
  ImageChannels channels = ImageChannels::kAll;
  /// When not null, set to the file's "sgbake:…" string attributes (name, value): how a file
  /// sgbake wrote says it is encoded (sgbake:map, sgbake:udim_tile, sgbake:green, …).
  std::vector<std::pair<std::string, std::string>>* attributes = nullptr;
  /// When not null, gets one line (naming the file) per thing the file holds that is not read
  /// or read by guess: the images after the first of a multi-part EXR or a multi-page TIFF, and
  /// channels read by position because none is named R, G, B or Y.
  std::vector<std::string>* warnings = nullptr;
};

/// @brief Reads the first subimage (full resolution) of an image file through OpenImageIO (in
/// the image I/O module, loaded on first use: sgbake/io/image_io.hpp).
///
/// Any bit depth: integer formats (8- and 16-bit PNG/TIFF, …) become floats in [0, 1]
/// (value / (2^bits - 1)); half and float formats (EXR, float TIFF) are kept raw. Alpha is read
/// as stored (never premultiplied into colour: PNG's unassociated alpha is kept as is). The data
/// window is read; an EXR display window is ignored. Rows are flipped to the bottom-up order of
/// Image.
///
/// Errors are ErrorCode::kBadInput with one line starting with the path:
/// `<path>: cannot open file (no such file)`, `<path>: cannot read image (<reason>)`,
/// `<path>: image has zero size`, `<path>: image is too large (W×H; at most 65536 per side)`,
/// `<path>: image has N channels but 3 are needed (RGB)`, `<path>: volume images are not
/// supported`, ... A missing or broken image I/O module is ErrorCode::kInternal naming the
/// module's file.
///
/// @param[in] path    the image file
/// @param[in] options which channels to keep (ImageChannels)
/// @return the image, W×H×C with C as selected by @p options
Result<Image> loadImage(const std::filesystem::path& path, const LoadImageOptions& options = {});

/// @brief The channels @p selection keeps of an image already in memory, as loadImage keeps
/// them of a file: kAll all of them, kFirst channel 0, kLuminance the Rec. 709 luminance of
/// channels 0–2 (channel 0 when there are fewer than three), kRgb channels 0–2, kRed … kAlpha
/// that one channel.
/// @note Precondition: channelsToRead(selection, image.channels()) ≥ 0 (callers check and
/// report it).
Image selectImageChannels(Image image, ImageChannels selection);

/// @brief The first value that is not a finite number (NaN or ±infinity) among channels
/// [first, first + count) of @p image, in the order of pixels() (bottom row first).
///
/// Rows are searched in parallel with a branch-free test that the compiler vectorizes: a
/// 2048² RGB image takes a few milliseconds instead of tens.
/// @param[in] image the image
/// @param[in] first the first channel to test (0 ≤ first < C)
/// @param[in] count how many channels from @p first (first + count ≤ C); -1: all the rest
/// @return the value's index in pixels(), or -1 when every tested value is finite
std::ptrdiff_t findNonFinite(const Image& image, int first = 0, int count = -1);

}  // namespace sgbake
