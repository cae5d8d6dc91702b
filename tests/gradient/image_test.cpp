// loadImage: bit depths and formats (written here with OpenImageIO, then read back), the
// bottom-up texel orientation, channel selection, and one-line kBadInput errors for bad files.

#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "io/image_check.hpp"
#include "sgbake/gradient/filters.hpp"
#include "sgbake/gradient/image.hpp"

namespace sgbake {
namespace {

namespace fs = std::filesystem;

// A fresh directory for this test's files.
fs::path testDir() {
  const testing::TestInfo* info = testing::UnitTest::GetInstance()->current_test_info();
  const fs::path dir =
      fs::path(testing::TempDir()) /
      (std::string("sgbake_image_") + info->test_suite_name() + "_" + info->name());
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// Writes W×H×C pixels given in file order (top row first) with OpenImageIO.
template <class T>
void writeImage(const fs::path& path, int width, int height, int channels, OIIO::TypeDesc type,
                const std::vector<T>& pixels, bool unassociatedAlpha = false, int tile = 0) {
  ASSERT_EQ(pixels.size(), static_cast<std::size_t>(width * height * channels));
  std::unique_ptr<OIIO::ImageOutput> out = OIIO::ImageOutput::create(path.string());
  ASSERT_TRUE(out) << OIIO::geterror();
  OIIO::ImageSpec spec(width, height, channels, type);
  if (unassociatedAlpha) spec.attribute("oiio:UnassociatedAlpha", 1);
  if (tile > 0) spec.tile_width = spec.tile_height = tile;  // tiled file (EXR, TIFF)
  ASSERT_TRUE(out->open(path.string(), spec)) << out->geterror();
  ASSERT_TRUE(out->write_image(type, pixels.data())) << out->geterror();
  ASSERT_TRUE(out->close());
}

void writeBytes(const fs::path& path, const std::string& bytes) {
  std::ofstream file(path, std::ios::binary);
  file << bytes;
}

// Checks an error: kBadInput, one line, starting with "<path>: <start>".
void expectFileError(const Result<Image>& image, const fs::path& path, const std::string& start) {
  ASSERT_FALSE(image.ok()) << path;
  EXPECT_EQ(image.error().code, ErrorCode::kBadInput);
  EXPECT_EQ(image.error().message.find('\n'), std::string::npos) << image.error().message;
  EXPECT_EQ(image.error().message.rfind(path.string() + ": " + start, 0), 0u)
      << image.error().message;
}

// Pixel value pattern of texel column x, file row r, channel c (distinct everywhere).
int pattern(int x, int r, int c) { return 7 * x + 31 * r + 101 * c; }

TEST(LoadImage, EightBitPngBecomesUnitFloats) {
  const fs::path path = testDir() / "rgb8.png";
  const int w = 5, h = 3, c = 3;
  std::vector<std::uint8_t> pixels;
  for (int r = 0; r < h; ++r) {
    for (int x = 0; x < w; ++x) {
      for (int k = 0; k < c; ++k) pixels.push_back(static_cast<std::uint8_t>(pattern(x, r, k)));
    }
  }
  pixels[0] = 255;  // full scale
  pixels[1] = 0;
  writeImage(path, w, h, c, OIIO::TypeDesc::UINT8, pixels);

  const Result<Image> image = loadImage(path);
  ASSERT_TRUE(image.ok()) << image.error().message;
  ASSERT_EQ(image->width(), w);
  ASSERT_EQ(image->height(), h);
  ASSERT_EQ(image->channels(), c);
  for (int r = 0; r < h; ++r) {
    for (int x = 0; x < w; ++x) {
      for (int k = 0; k < c; ++k) {
        const double expected = pixels[static_cast<std::size_t>((r * w + x) * c + k)] / 255.0;
        EXPECT_NEAR(image->at(x, image->yFromFileRow(r), k), expected, 1e-7);
      }
    }
  }
  EXPECT_EQ(image->at(0, h - 1, 0), 1.0f);
  EXPECT_EQ(image->at(0, h - 1, 1), 0.0f);
}

TEST(LoadImage, SixteenBitPngAndTiffBecomeUnitFloats) {
  const fs::path dir = testDir();
  const int w = 4, h = 3;
  std::vector<std::uint16_t> pixels;
  for (int r = 0; r < h; ++r) {
    for (int x = 0; x < w; ++x) pixels.push_back(static_cast<std::uint16_t>(pattern(x, r, 0) * 97));
  }
  pixels[1] = 65535;
  pixels[2] = 1;  // a value an 8-bit path would lose
  for (const char* name : {"gray16.png", "gray16.tif"}) {
    const fs::path path = dir / name;
    writeImage(path, w, h, 1, OIIO::TypeDesc::UINT16, pixels);
    const Result<Image> image = loadImage(path);
    ASSERT_TRUE(image.ok()) << image.error().message;
    ASSERT_EQ(image->channels(), 1);
    for (int r = 0; r < h; ++r) {
      for (int x = 0; x < w; ++x) {
        const double expected = pixels[static_cast<std::size_t>(r * w + x)] / 65535.0;
        EXPECT_NEAR(image->at(x, image->yFromFileRow(r)), expected, 1e-7) << name;
      }
    }
    EXPECT_EQ(image->at(1, h - 1), 1.0f) << name;
    EXPECT_GT(image->at(2, h - 1), 0.0f) << name;
  }
}

TEST(LoadImage, FloatExrAndTiffAreRaw) {
  const fs::path dir = testDir();
  const int w = 3, h = 2, c = 3;
  // Raw floats: negative, above 1, tiny, large — no normalization, no colour conversion.
  const std::vector<float> pixels = {-1.5f, 0.25f, 3.75f, 1e-20f, 123456.0f, 0.1f,
                                     2.0f,  -0.0f, 0.5f,  0.3f,   0.7f,      -8.0f,
                                     1.0f,  1.25f, 0.0f,  42.0f,  -42.0f,    0.015625f};
  for (const char* name : {"rgb.exr", "rgb_float.tif", "rgb_tiled.exr"}) {
    const fs::path path = dir / name;
    const bool tiled = std::string(name).find("tiled") != std::string::npos;
    writeImage(path, w, h, c, OIIO::TypeDesc::FLOAT, pixels, false, tiled ? 16 : 0);
    const Result<Image> image = loadImage(path);
    ASSERT_TRUE(image.ok()) << image.error().message;
    ASSERT_EQ(image->channels(), c);
    for (int r = 0; r < h; ++r) {
      for (int x = 0; x < w; ++x) {
        for (int k = 0; k < c; ++k) {
          EXPECT_EQ(image->at(x, image->yFromFileRow(r), k),
                    pixels[static_cast<std::size_t>((r * w + x) * c + k)])
              << name;
        }
      }
    }
  }
}

TEST(LoadImage, TopFileRowIsTheTopOfTextureSpace) {
  // File row 0 (the top of the picture) is texel row y = H − 1, whose centre is t = 1 − 0.5/H.
  const fs::path path = testDir() / "rows.png";
  const int w = 4, h = 8;
  std::vector<std::uint8_t> pixels(static_cast<std::size_t>(w * h), 0);
  for (int x = 0; x < w; ++x) pixels[static_cast<std::size_t>(x)] = 255;  // top file row white
  writeImage(path, w, h, 1, OIIO::TypeDesc::UINT8, pixels);

  const Result<Image> image = loadImage(path);
  ASSERT_TRUE(image.ok()) << image.error().message;
  EXPECT_EQ(image->at(2, h - 1), 1.0f);
  EXPECT_EQ(image->at(2, 0), 0.0f);
  EXPECT_DOUBLE_EQ(image->texelCentre(2, h - 1).y, 1.0 - 0.5 / h);

  // Through a texture: white near t = 1, black near t = 0.
  const Result<ImageScalarTexture> texture = ImageScalarTexture::create(*image);
  ASSERT_TRUE(texture.ok());
  EXPECT_EQ(texture->sample({0.3, 1.0 - 0.5 / h}).value, 1.0);
  EXPECT_EQ(texture->sample({0.3, 0.5 / h}).value, 0.0);
  EXPECT_EQ(texture->sample({0.3, 0.5}).value, 0.0);
  // Between the top texel row and the row below, the height rises with t.
  EXPECT_GT(texture->sample({0.3, 1.0 - 1.0 / h}).gradient.y, 0.0);
}

TEST(LoadImage, ChannelSelection) {
  const fs::path dir = testDir();
  const int w = 2, h = 2;
  // RGBA with alpha 0.5 (128): colour must come back unpremultiplied, as stored.
  const std::vector<std::uint8_t> rgba = {200, 100, 50, 128, 10, 20, 30,  128,
                                          255, 0,   0,  128, 0,  0,  255, 128};
  const fs::path rgbaPath = dir / "rgba.png";
  writeImage(rgbaPath, w, h, 4, OIIO::TypeDesc::UINT8, rgba, /*unassociatedAlpha=*/true);

  const Result<Image> all = loadImage(rgbaPath);
  ASSERT_TRUE(all.ok()) << all.error().message;
  ASSERT_EQ(all->channels(), 4);
  EXPECT_NEAR(all->at(0, h - 1, 0), 200 / 255.0, 1e-7);  // not 200·128/255
  EXPECT_NEAR(all->at(0, h - 1, 3), 128 / 255.0, 1e-7);

  const Result<Image> first = loadImage(rgbaPath, {ImageChannels::kFirst});
  ASSERT_TRUE(first.ok());
  ASSERT_EQ(first->channels(), 1);
  EXPECT_NEAR(first->at(1, h - 1), 10 / 255.0, 1e-7);

  const Result<Image> luminance = loadImage(rgbaPath, {ImageChannels::kLuminance});
  ASSERT_TRUE(luminance.ok());
  ASSERT_EQ(luminance->channels(), 1);
  // Cycles' weights (measured from Blender 3.4); the rounded 0.2126, 0.7152, 0.0722 are 3e-5 off.
  EXPECT_NEAR(luminance->at(0, h - 1),
              (0.212672979 * 200 + 0.715152621 * 100 + 0.072175443 * 50) / 255.0, 1e-7);
  EXPECT_NEAR(luminance->at(1, 0), 0.072175443, 1e-7);  // pure blue, bottom-right

  const Result<Image> rgb = loadImage(rgbaPath, {ImageChannels::kRgb});
  ASSERT_TRUE(rgb.ok());
  ASSERT_EQ(rgb->channels(), 3);
  EXPECT_NEAR(rgb->at(0, 0, 0), 1.0, 1e-7);

  // A grey file: luminance is the grey channel; RGB is an error.
  const fs::path grayPath = dir / "gray.png";
  writeImage(grayPath, w, h, 1, OIIO::TypeDesc::UINT8, std::vector<std::uint8_t>{0, 51, 102, 255});
  const Result<Image> grayLuminance = loadImage(grayPath, {ImageChannels::kLuminance});
  ASSERT_TRUE(grayLuminance.ok());
  EXPECT_NEAR(grayLuminance->at(1, h - 1), 0.2, 1e-7);
  expectFileError(loadImage(grayPath, {ImageChannels::kRgb}), grayPath,
                  "image has 1 channel but 3 are needed (RGB)");
}

TEST(LoadImage, BadFilesAreOneLineBadInputErrors) {
  const fs::path dir = testDir();

  const fs::path missing = dir / "missing.png";
  expectFileError(loadImage(missing), missing, "cannot open file");

  const fs::path empty = dir / "empty.png";
  writeBytes(empty, "");
  expectFileError(loadImage(empty), empty, "file is empty");

  const fs::path garbage = dir / "garbage.png";
  writeBytes(garbage, std::string("\x89PNG\r\n\x1a\n this is not a PNG\n\x00\x01\x02", 31));
  expectFileError(loadImage(garbage), garbage, "cannot read image (");

  const fs::path text = dir / "notes.exr";
  writeBytes(text, "hello\nworld\n");
  expectFileError(loadImage(text), text, "cannot read image (");

  const fs::path directory = dir / "folder.png";
  fs::create_directories(directory);
  expectFileError(loadImage(directory), directory, "cannot read file");

  // A valid PNG cut in the middle of its pixel data.
  const fs::path full = dir / "full.png";
  std::vector<std::uint8_t> noise(64 * 64 * 3);
  for (std::size_t i = 0; i < noise.size(); ++i) noise[i] = static_cast<std::uint8_t>(i * 7919);
  writeImage(full, 64, 64, 3, OIIO::TypeDesc::UINT8, noise);
  std::ifstream in(full, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const fs::path truncated = dir / "truncated.png";
  writeBytes(truncated, bytes.substr(0, bytes.size() / 2));
  expectFileError(loadImage(truncated), truncated, "cannot read image (");

  // Headers that claim a zero-size or a too-large image (binary PGM: the pixel data need not
  // follow, the sizes are checked first).
  const fs::path zero = dir / "zero.pgm";
  writeBytes(zero, "P5\n0 4\n255\n");
  expectFileError(loadImage(zero), zero, "image has zero size (0x4, 1 channel)");

  // A header without its pixels: the library gives no reason, the message says what it means.
  const fs::path headerOnly = dir / "header_only.pgm";
  writeBytes(headerOnly, "P5\n4 4\n255\n");
  expectFileError(loadImage(headerOnly), headerOnly,
                  "cannot read image (no reason given: the file may be truncated or damaged)");

  const fs::path huge = dir / "huge.pgm";
  writeBytes(huge, "P5\n70000 2\n255\n");
  expectFileError(loadImage(huge), huge, "image is too large (70000x2; at most 65536 per side)");

  // A header within the sides' limit whose image cannot fit in this machine's memory (a
  // decompression bomb: a few MB of zeros decode to 60000² bytes): refused before any
  // allocation. 65536² grey 16-bit needs ~34 GB as floats plus the decoder's copy.
  const fs::path bomb = dir / "bomb.pgm";
  writeBytes(bomb, "P5\n65536 65536\n65535\n");
  const double memory = static_cast<double>(::sysconf(_SC_PHYS_PAGES)) *
                        static_cast<double>(::sysconf(_SC_PAGE_SIZE));
  if (memory < 65536.0 * 65536.0 * 8) {
    expectFileError(loadImage(bomb), bomb,
                    "image is too large to load on this machine (65536x65536, 1 channel: about "
                    "34.4 GB; the machine has");
  }
}

std::string readBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// The byte offset of @p type's chunk in a PNG file's bytes (its length field).
std::size_t chunkOffset(const std::string& png, const std::string& type) {
  const std::size_t at = png.find(type);
  EXPECT_NE(at, std::string::npos) << type;
  return at - 4;
}

// A 64x64 PNG of noise (so that its IDAT is large), as bytes.
std::string noisePng(const fs::path& dir) {
  std::vector<std::uint8_t> noise(64 * 64 * 3);
  for (std::size_t i = 0; i < noise.size(); ++i) noise[i] = static_cast<std::uint8_t>(i * 7919);
  writeImage(dir / "noise.png", 64, 64, 3, OIIO::TypeDesc::UINT8, noise);
  return readBytes(dir / "noise.png");
}

TEST(PngCheck, Crc32IsTheIsoCrc) {
  const std::string check = "123456789";  // the CRC-32 check value of the catalogue
  const auto* bytes = reinterpret_cast<const unsigned char*>(check.data());
  EXPECT_EQ(io_detail::crc32(0, bytes, check.size()), 0xCBF43926u);
  // Continued over pieces of every length around the 8-byte steps, the same value.
  for (std::size_t split = 0; split <= check.size(); ++split) {
    EXPECT_EQ(
        io_detail::crc32(io_detail::crc32(0, bytes, split), bytes + split, check.size() - split),
        0xCBF43926u)
        << split;
  }
}

// A damaged PNG is refused in one line of sgbake's, and nothing else reaches standard error
// (decoded, libpng would print "libpng error: ..." of its own).
TEST(LoadImage, DamagedPngIsRefusedInOneLineAndNothingElse) {
  const fs::path dir = testDir();
  const std::string png = noisePng(dir);
  const std::size_t idat = chunkOffset(png, "IDAT");
  const std::size_t iend = chunkOffset(png, "IEND");
  ASSERT_TRUE(io_detail::imageDamage(dir / "noise.png").empty());

  struct Case {
    std::string name, bytes, start;
  };
  std::string flipped = png;
  flipped[idat + 8 + 100] = static_cast<char>(flipped[idat + 8 + 100] ^ 0x20);
  const std::vector<Case> cases = {
      {"half.png", png.substr(0, png.size() / 2),
       "cannot read image (truncated PNG: the file ends inside its IDAT chunk (at byte " +
           std::to_string(idat) + "))"},
      {"no_crc.png", png.substr(0, iend - 2),
       "cannot read image (truncated PNG: the file ends inside its IDAT chunk"},
      {"no_end.png", png.substr(0, iend),
       "cannot read image (truncated PNG: the file ends at byte " + std::to_string(iend) +
           ", before its IEND chunk)"},
      {"flipped.png", flipped,
       "cannot read image (corrupt PNG: its IDAT chunk at byte " + std::to_string(idat) +
           " fails its CRC check)"},
  };
  for (const Case& c : cases) {
    const fs::path path = dir / c.name;
    writeBytes(path, c.bytes);
    testing::internal::CaptureStderr();
    const Result<Image> image = loadImage(path);
    const std::string printed = testing::internal::GetCapturedStderr();
    expectFileError(image, path, c.start);
    EXPECT_EQ(printed, "") << c.name;
  }
}

// libjpeg only warns about a JPEG cut short (OpenImageIO returns its rows padded with grey):
// refused, wherever the cut; bytes after EOI and stray bytes before a marker are tolerated,
// as libjpeg tolerates them.
TEST(LoadImage, TruncatedJpegIsRefused) {
  const fs::path dir = testDir();
  std::vector<std::uint8_t> noise(64 * 64 * 3);
  for (std::size_t i = 0; i < noise.size(); ++i) noise[i] = static_cast<std::uint8_t>(i * 7919);
  writeImage(dir / "noise.jpg", 64, 64, 3, OIIO::TypeDesc::UINT8, noise);
  const std::string jpeg = readBytes(dir / "noise.jpg");
  const std::size_t scan = jpeg.find("\xFF\xDA");
  ASSERT_NE(scan, std::string::npos);
  const Result<Image> whole = loadImage(dir / "noise.jpg");
  ASSERT_TRUE(whole.ok()) << whole.error().message;
  for (const auto& [cut, reason] : std::vector<std::pair<std::size_t, std::string>>{
           {jpeg.size() * 9 / 10, "inside its image data, before its EOI marker"},
           {jpeg.size() - 2, "inside its image data, before its EOI marker"},
           {scan + 5, "inside a segment, before its EOI marker"},
           {scan / 2, "inside a segment, before its EOI marker"}}) {
    const fs::path path = dir / ("cut" + std::to_string(cut) + ".jpg");
    writeBytes(path, jpeg.substr(0, cut));
    testing::internal::CaptureStderr();
    expectFileError(loadImage(path), path,
                    "cannot read image (truncated JPEG: the file ends " + reason + ")");
    EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
  }
  const fs::path tail = dir / "tail.jpg";
  writeBytes(tail, jpeg + std::string("\0\0trailing\xFF", 11));
  EXPECT_TRUE(loadImage(tail).ok());
  const fs::path stray = dir / "stray.jpg";
  writeBytes(stray, jpeg.substr(0, scan) + "ab" + jpeg.substr(scan));
  EXPECT_EQ(io_detail::imageDamage(stray), "");
}

// An ancillary chunk with a bad CRC is skipped by libpng (and Blender): the image loads.
TEST(LoadImage, AncillaryChunkWithABadCrcIsTolerated) {
  const fs::path dir = testDir();
  const std::string png = noisePng(dir);
  const std::size_t idat = chunkOffset(png, "IDAT");
  const std::string text = std::string("\0\0\0\4tEXtabcd\0\0\0\0", 16);  // CRC 0: wrong
  const fs::path path = dir / "text.png";
  writeBytes(path, png.substr(0, idat) + text + png.substr(idat));
  EXPECT_TRUE(io_detail::imageDamage(path).empty());
  const Result<Image> image = loadImage(path);
  ASSERT_TRUE(image.ok()) << image.error().message;
  EXPECT_EQ(image->width(), 64);
}

// OpenImageIO's TIFF reader returns success on a file cut short, its missing strips unread:
// refused all the same, for every strip layout.
TEST(LoadImage, TruncatedTiffIsRefused) {
  const fs::path dir = testDir();
  std::vector<float> noise(96 * 96);
  for (std::size_t i = 0; i < noise.size(); ++i) noise[i] = static_cast<float>(i % 97) / 97.0f;
  for (const int tile : {0, 16}) {
    const fs::path full = dir / "full.tif";
    writeImage(full, 96, 96, 1, OIIO::TypeDesc::FLOAT, noise, false, tile);
    ASSERT_TRUE(loadImage(full).ok());
    const std::string bytes = readBytes(full);
    const fs::path cut = dir / "cut.tif";
    writeBytes(cut, bytes.substr(0, bytes.size() / 2));
    expectFileError(loadImage(cut), cut, "cannot read image (");
  }
}

// A WebP file was refused ("Couldn't decode subimage 0"): OpenImageIO's WebP reader cannot read
// after the failed seek that counts subimages, so a file of one image is opened afresh.
TEST(LoadImage, WebpIsRead) {
  const fs::path path = testDir() / "ramp.webp";
  std::vector<unsigned char> pixels(16 * 8 * 3);
  for (std::size_t i = 0; i < pixels.size(); ++i)
    pixels[i] = static_cast<unsigned char>(8 * (i % 24));
  {
    std::unique_ptr<OIIO::ImageOutput> out = OIIO::ImageOutput::create(path.string());
    ASSERT_TRUE(out) << OIIO::geterror();
    OIIO::ImageSpec spec(16, 8, 3, OIIO::TypeDesc::UINT8);
    ASSERT_TRUE(out->open(path.string(), spec)) << out->geterror();
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, pixels.data()));
    ASSERT_TRUE(out->close());
  }
  const Result<Image> image = loadImage(path);
  ASSERT_TRUE(image.ok()) << image.error().message;
  EXPECT_EQ(image->width(), 16);
  EXPECT_NEAR(image->at(1, 0, 0), 24.0f / 255.0f, 0.03f) << "lossy, but the same ramp";
}

// SGI (IRIS) files: OpenImageIO's reader aborts the process on RLE data that overruns its
// scanline (an assertion Debian's build keeps), and reports a truncated file as "Read error"
// once per row. The structure is checked first: every RLE scanline must decode to the width.
TEST(LoadImage, DamagedSgiIsRefused) {
  const fs::path dir = testDir();
  // OpenImageIO writes SGI files verbatim: a 16 x 8 grey RLE file made here. Header: magic
  // 474, RLE, 1 byte per channel, 2 dimensions, 16 x 8 x 1; then the tables of the scanlines'
  // offsets and lengths; each scanline a literal run of its 16 values and the end count 0.
  std::string file(512, '\0');
  const auto put16 = [&](std::size_t at, unsigned v) {
    file[at] = static_cast<char>(v >> 8);
    file[at + 1] = static_cast<char>(v & 0xFFu);
  };
  const auto put32 = [&](std::size_t at, std::uint32_t v) {
    for (std::size_t i = 0; i < 4; ++i) file[at + i] = static_cast<char>(v >> (24 - 8 * i));
  };
  put16(0, 474);
  file[2] = 1;
  file[3] = 1;
  put16(4, 2);
  put16(6, 16);
  put16(8, 8);
  put16(10, 1);
  put32(108, 255);  // pixmax
  file.resize(512 + 2 * 8 * 4);
  for (std::uint32_t row = 0; row < 8; ++row) {
    put32(512 + 4 * row, static_cast<std::uint32_t>(file.size()));
    put32(512 + 32 + 4 * row, 18);
    file += static_cast<char>(0x80 | 16);
    for (int x = 0; x < 16; ++x) file += static_cast<char>(16 * x + row);
    file += '\0';
  }
  const fs::path full = dir / "full.sgi";
  writeBytes(full, file);
  const Result<Image> image = loadImage(full);
  ASSERT_TRUE(image.ok()) << image.error().message;
  EXPECT_EQ(std::lround(image->at(3, 2, 0) * 255.0f) / 16, 3) << "column 3 holds 48 + row";
  const std::string& bytes = file;
  // Scanline 0's first count, made a run of 127 values: more than the 16 of its row.
  const auto loadBig32 = [&](std::size_t at) {
    std::uint32_t v = 0;
    for (std::size_t i = 0; i < 4; ++i) v = v << 8 | static_cast<unsigned char>(bytes[at + i]);
    return v;
  };
  std::string overrun = bytes;
  overrun[loadBig32(512)] = static_cast<char>(0x7F);
  const fs::path corrupt = dir / "overrun.sgi";
  writeBytes(corrupt, overrun);
  expectFileError(loadImage(corrupt), corrupt,
                  "cannot read image (corrupt SGI image: RLE scanline 0 (at byte " +
                      std::to_string(loadBig32(512)) + ") does not decode to 16 values)");
  const fs::path cut = dir / "cut.sgi";
  writeBytes(cut, bytes.substr(0, bytes.size() - 10));
  expectFileError(loadImage(cut), cut,
                  "cannot read image (truncated SGI image: the file ends "
                  "inside RLE scanline ");
}

// A Cineon or DPX file cut short was decoded with its missing pixels zero or garbage (Cineon),
// or refused with no reason given (DPX): their headers' sizes are checked first.
TEST(LoadImage, TruncatedCineonAndDpxAreRefused) {
  const fs::path dir = testDir();
  // An 8 x 8 RGB ramp Blender 3.4 wrote (10 bits, 2048-byte header).
  const fs::path cineon = fs::path(SGBAKE_TEST_DATA) / "corpus" / "images" / "ramp_8x8.cin";
  ASSERT_TRUE(loadImage(cineon).ok());
  const std::string cineonBytes = readBytes(cineon);
  ASSERT_EQ(cineonBytes.size(), 2304u);
  const fs::path cutCineon = dir / "cut.cin";
  writeBytes(cutCineon, cineonBytes.substr(0, 2200));
  expectFileError(loadImage(cutCineon), cutCineon,
                  "cannot read image (truncated Cineon image: the file is 2200 bytes, its "
                  "header says 2304)");
  const fs::path headerOnly = dir / "header.cin";
  writeBytes(headerOnly, cineonBytes.substr(0, 2048));
  expectFileError(loadImage(headerOnly), headerOnly,
                  "cannot read image (truncated Cineon image: the file is 2048 bytes, its "
                  "pixels would start at byte 2048)");

  const fs::path dpx = dir / "full.dpx";
  std::vector<float> ramp(32 * 16 * 3);
  for (std::size_t i = 0; i < ramp.size(); ++i) ramp[i] = static_cast<float>(i % 29) / 29.0f;
  writeImage(dpx, 32, 16, 3, OIIO::TypeDesc::UINT16, ramp);
  ASSERT_TRUE(loadImage(dpx).ok());
  const std::string dpxBytes = readBytes(dpx);
  const fs::path cutDpx = dir / "cut.dpx";
  writeBytes(cutDpx, dpxBytes.substr(0, dpxBytes.size() - 100));
  expectFileError(loadImage(cutDpx), cutDpx,
                  "cannot read image (truncated DPX image: the file is " +
                      std::to_string(dpxBytes.size() - 100) + " bytes, its ");
}

// An EXR chunk whose size field says 0 (its data gone) was read as rows of zeros or of another
// chunk; OpenEXR does not tell. Every chunk the offset table points to must hold data, in
// scanline files and in tiled ones, one level or mipmapped (whose chunks are counted per level).
TEST(LoadImage, ExrChunksWithoutDataAreRefused) {
  const fs::path dir = testDir();
  std::vector<float> noise(64 * 48);
  for (std::size_t i = 0; i < noise.size(); ++i) noise[i] = static_cast<float>(i % 89) / 89.0f;
  struct Layout {
    const char* name;
    int tile;
    const char* levels;  // "" or "mipmap" (a tiled file's levels)
    int roundingMode;
    std::size_t chunks;
  };
  // ZIP: 16 scanlines a chunk. Tiles of 16: 4 x 3 at level 0; mipmaps of 32 x 24, 16 x 12,
  // 8 x 6, 4 x 3, 2 x 1, 1 x 1 (rounded down) or 32 x 24, 16 x 12, 8 x 6, 4 x 3, 2 x 2, 1 x 1
  // (up) add 2 x 2 + 1 + 1 + 1 + 1 + 1 chunks.
  for (const Layout& layout :
       {Layout{"scanlines", 0, "", 0, 3}, Layout{"tiles", 16, "", 0, 12},
        Layout{"mipmap_down", 16, "mipmap", 0, 21}, Layout{"mipmap_up", 16, "mipmap", 1, 21}}) {
    SCOPED_TRACE(layout.name);
    const fs::path full = dir / (std::string(layout.name) + ".exr");
    {
      std::unique_ptr<OIIO::ImageOutput> out = OIIO::ImageOutput::create(full.string());
      ASSERT_TRUE(out);
      OIIO::ImageSpec spec(64, 48, 1, OIIO::TypeDesc::FLOAT);
      spec.attribute("compression", "zip");
      if (layout.tile > 0) spec.tile_width = spec.tile_height = layout.tile;
      const bool mipmap = std::string(layout.levels) == "mipmap";
      if (mipmap) {
        spec.attribute("textureformat", "Plain Texture");  // what makes OpenImageIO mipmap
        spec.attribute("openexr:levelmode", 1);
        spec.attribute("openexr:roundingmode", layout.roundingMode);
      }
      ASSERT_TRUE(out->open(full.string(), spec)) << out->geterror();
      ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, noise.data())) << out->geterror();
      for (int w = 32, h = 24; mipmap;) {
        OIIO::ImageSpec level = spec;
        level.width = level.full_width = w;
        level.height = level.full_height = h;
        ASSERT_TRUE(out->open(full.string(), level, OIIO::ImageOutput::AppendMIPLevel))
            << out->geterror();
        std::vector<float> pixels(static_cast<std::size_t>(w * h), 0.5f);
        ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, pixels.data())) << out->geterror();
        if (w == 1 && h == 1) break;
        w = layout.roundingMode != 0 ? std::max(1, (w + 1) / 2) : std::max(1, w / 2);
        h = layout.roundingMode != 0 ? std::max(1, (h + 1) / 2) : std::max(1, h / 2);
      }
      ASSERT_TRUE(out->close());
    }
    ASSERT_TRUE(loadImage(full).ok()) << "a whole file passes the check";
    std::string bytes = readBytes(full);
    // The offset table is the 8-byte offsets just before the first chunk, which it points to.
    const auto load64 = [&](std::size_t at) {
      std::uint64_t v = 0;
      for (std::size_t i = 8; i-- > 0;) v = v << 8 | static_cast<unsigned char>(bytes[at + i]);
      return v;
    };
    std::size_t table = 0;
    for (std::size_t at = 8; at + 8 <= bytes.size(); ++at) {
      if (load64(at) == at + 8 * layout.chunks) {
        table = at;
        break;
      }
    }
    ASSERT_NE(table, 0u) << "no table of " << layout.chunks << " chunks";
    // The last chunk (of the last level: found only where the levels are counted right).
    const std::size_t k = layout.chunks - 1;
    const std::size_t offset = load64(table + 8 * k);
    const std::size_t sizeField = offset + (layout.tile > 0 ? 16 : 4);
    for (std::size_t i = 0; i < 4; ++i) bytes[sizeField + i] = 0;
    const fs::path emptied = dir / (std::string(layout.name) + "_emptied.exr");
    writeBytes(emptied, bytes);
    expectFileError(loadImage(emptied), emptied,
                    "cannot read image (corrupt EXR: chunk " + std::to_string(k) + " (at byte " +
                        std::to_string(offset) + ") holds no pixel data)");
  }
}

// A multi-part EXR is read from its first part, which a warning names, as are channels that are
// not named R, G, B or Y (read by position); an EXR of 32-bit
// unsigned integers (an ID pass), which the codec would scale by 2^-32, is refused.
TEST(LoadImage, MultiPartOddlyNamedAndIntegerExrsAreSaid) {
  const fs::path dir = testDir();
  const fs::path parts = dir / "parts.exr";
  {
    OIIO::ImageSpec specs[2] = {OIIO::ImageSpec(4, 4, 1, OIIO::TypeDesc::FLOAT),
                                OIIO::ImageSpec(4, 4, 1, OIIO::TypeDesc::FLOAT)};
    specs[0].attribute("name", "preview");
    specs[1].attribute("name", "height");
    std::unique_ptr<OIIO::ImageOutput> out = OIIO::ImageOutput::create(parts.string());
    ASSERT_TRUE(out && out->supports("multiimage"));
    ASSERT_TRUE(out->open(parts.string(), 2, specs)) << out->geterror();
    const std::vector<float> zeros(16, 0.0f), ones(16, 1.0f);
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, zeros.data()));
    ASSERT_TRUE(out->open(parts.string(), specs[1], OIIO::ImageOutput::AppendSubimage));
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, ones.data()));
    ASSERT_TRUE(out->close());
  }
  std::vector<std::string> warnings;
  LoadImageOptions options;
  options.warnings = &warnings;
  const Result<Image> image = loadImage(parts, options);
  ASSERT_TRUE(image.ok()) << image.error().message;
  EXPECT_EQ(image->at(0, 0, 0), 0.0f);  // the first part's
  EXPECT_EQ(warnings, std::vector<std::string>{parts.string() +
                                               ": holds 2 images (EXR parts or pages); only the "
                                               "first ('preview') is read"});
  warnings.clear();
  writeImage(dir / "one.exr", 2, 2, 1, OIIO::TypeDesc::FLOAT, std::vector<float>(4, 0.5f));
  ASSERT_TRUE(loadImage(dir / "one.exr", options).ok());
  EXPECT_TRUE(warnings.empty());

  // Channels read by position, none named R, G, B or Y: said.
  const fs::path odd = dir / "odd.exr";
  {
    OIIO::ImageSpec spec(2, 2, 2, OIIO::TypeDesc::FLOAT);
    spec.channelnames = {"baz", "foo.bar"};
    std::unique_ptr<OIIO::ImageOutput> out = OIIO::ImageOutput::create(odd.string());
    ASSERT_TRUE(out && out->open(odd.string(), spec)) << OIIO::geterror();
    const std::vector<float> values(8, 0.25f);
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, values.data()));
    ASSERT_TRUE(out->close());
  }
  options.channels = ImageChannels::kFirst;
  ASSERT_TRUE(loadImage(odd, options).ok());
  EXPECT_EQ(warnings,
            std::vector<std::string>{odd.string() + ": no channel is named R, G, B or Y ('baz', "
                                                    "'foo.bar'); the first one is read"});
  warnings.clear();
  writeImage(dir / "rgb.exr", 2, 2, 3, OIIO::TypeDesc::FLOAT, std::vector<float>(12, 0.5f));
  ASSERT_TRUE(loadImage(dir / "rgb.exr", options).ok());
  EXPECT_TRUE(warnings.empty());

  const fs::path ids = dir / "ids.exr";
  writeImage(ids, 2, 2, 1, OIIO::TypeDesc::UINT, std::vector<std::uint32_t>{1, 2, 3, 945});
  expectFileError(loadImage(ids), ids,
                  "holds 32-bit unsigned integer channels (an ID or count pass), not heights or "
                  "normals");
}

TEST(LoadImage, NonFiniteTexelsAreNamedFromTheTop) {
  const fs::path dir = testDir();
  // 5×4 RGB float EXR: bad values at column 3, file row 1, channel 2 and at column 0 of file
  // row 3, channel 0.
  const int w = 5, h = 4;
  for (const float bad :
       {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity(),
        -std::numeric_limits<float>::infinity()}) {
    std::vector<float> pixels(static_cast<std::size_t>(w * h * 3), 0.25f);
    pixels[static_cast<std::size_t>((1 * w + 3) * 3 + 2)] = bad;
    pixels[static_cast<std::size_t>((3 * w + 0) * 3 + 0)] = bad;
    const fs::path path = dir / "bad.exr";
    writeImage(path, w, h, 3, OIIO::TypeDesc::FLOAT, pixels);
    // Rows are stored bottom-up: file row 3 is searched first, so its texel is the one named.
    expectFileError(loadImage(path), path,
                    "pixel at column 0, row 3 (from the top), channel 0 is not a finite number");
    pixels[static_cast<std::size_t>((3 * w + 0) * 3 + 0)] = 0.5f;
    writeImage(path, w, h, 3, OIIO::TypeDesc::FLOAT, pixels);
    expectFileError(loadImage(path), path,
                    "pixel at column 3, row 1 (from the top), channel 2 is not a finite number");
  }
}

TEST(LoadImage, ControlCharactersInTheNameStayOnOneLine) {
  const fs::path path = testDir() / "evil\nname.png";
  const Result<Image> image = loadImage(path);
  ASSERT_FALSE(image.ok());
  EXPECT_EQ(image.error().message.find('\n'), std::string::npos) << image.error().message;
}

TEST(Image, StorageIsBottomUpAndInterleaved) {
  Image image(3, 2, 2);
  image.at(2, 1, 1) = 5.0f;  // last texel of the top row, second channel
  EXPECT_EQ(image.pixels().back(), 5.0f);
  image.at(0, 0, 0) = 7.0f;  // bottom-left texel
  EXPECT_EQ(image.pixels().front(), 7.0f);
  EXPECT_EQ(image.yFromFileRow(0), 1);
  EXPECT_EQ(image.texelCentre(0, 0), (Vec2d{0.5 / 3, 0.25}));
}

// findNonFinite against a plain scan with std::isfinite: random bad values in an image tall
// enough to be searched by several tasks, for every channel range.
TEST(Image, FindNonFiniteIsTheFirstBadValueInStorageOrder) {
  const float kBad[] = {std::numeric_limits<float>::quiet_NaN(),
                        std::numeric_limits<float>::infinity(),
                        -std::numeric_limits<float>::infinity()};
  // Finite extremes must pass: the largest float, a subnormal, −0.
  const float kFinite[] = {std::numeric_limits<float>::max(), -std::numeric_limits<float>::max(),
                           std::numeric_limits<float>::denorm_min(), -0.0f, 1.0f};
  std::mt19937 random(7);
  for (int trial = 0; trial < 40; ++trial) {
    const int channels = 1 + trial % 4;
    Image image(13, 150, channels);
    std::span<float> values = image.pixels();
    for (std::size_t i = 0; i < values.size(); ++i) values[i] = kFinite[random() % 5];
    const int bads = trial % 5;  // 0: all finite
    for (int b = 0; b < bads; ++b) values[random() % values.size()] = kBad[random() % 3];
    for (int first = 0; first < channels; ++first) {
      for (int count = 0; first + count <= channels; ++count) {
        std::ptrdiff_t expected = -1;
        for (std::size_t i = 0; i < values.size() && expected < 0; ++i) {
          const int c = static_cast<int>(i % static_cast<std::size_t>(channels));
          if (c >= first && c < first + count && !std::isfinite(values[i])) {
            expected = static_cast<std::ptrdiff_t>(i);
          }
        }
        EXPECT_EQ(findNonFinite(image, first, count), expected)
            << "trial " << trial << ", channels [" << first << ", " << first + count << ")";
      }
    }
    std::ptrdiff_t all = -1;
    for (std::size_t i = 0; i < values.size() && all < 0; ++i) {
      if (!std::isfinite(values[i])) all = static_cast<std::ptrdiff_t>(i);
    }
    EXPECT_EQ(findNonFinite(image), all) << "trial " << trial;
  }
  EXPECT_EQ(findNonFinite(Image()), -1);
}

}  // namespace
}  // namespace sgbake
