/// @file image_output_test.cpp
/// @brief writeImage: formats, bit depths, orientation, alpha, all-or-nothing files, and the
/// `<UDIM>` token. Files are read back with OpenImageIO directly (not through sgbake).
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>
#include <sys/stat.h>
#include <tbb/task_arena.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <memory>
#include <set>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "support/files.hpp"
#include "sgbake/bake/image_output.hpp"
#include "sgbake/io/atomic_file.hpp"

namespace sgbake {
namespace {

namespace fs = std::filesystem;
using test::listDirectory;
using test::readFile;
using test::writeFile;

/// A fresh, empty directory per test, removed afterwards.
class ImageOutputTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("sgbake_image_output_" + std::string(info->name()) + "_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path dir_;
};

/// A W×H image whose value at (x, row, c) is distinct and in [0, 1]: (x + 10·row + 100·c) / 1000.
FloatImage rampImage(int width, int height, int channels) {
  FloatImage image;
  image.width = width;
  image.height = height;
  image.channels = channels;
  image.pixels.resize(static_cast<std::size_t>(width * height * channels));
  image.coverage.assign(static_cast<std::size_t>(width * height), 1.0f);
  for (int row = 0; row < height; ++row) {
    for (int x = 0; x < width; ++x) {
      for (int c = 0; c < channels; ++c) {
        image.at(x, row, c) = static_cast<float>(x + 10 * row + 100 * c) / 1000.0f;
      }
    }
  }
  return image;
}

/// What OIIO reads from a file: the spec and the pixels as floats (rows top first).
struct ReadBack {
  OIIO::ImageSpec spec;
  std::vector<float> pixels;
  float at(int x, int row, int c) const {
    return pixels[(static_cast<std::size_t>(row) * spec.width + x) * spec.nchannels + c];
  }
};

ReadBack readBack(const fs::path& path) {
  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);  // raw colour, as written
  std::unique_ptr<OIIO::ImageInput> in = OIIO::ImageInput::open(path.string(), &config);
  ReadBack result;
  if (!in) {
    ADD_FAILURE() << "cannot open " << path << ": " << OIIO::geterror();
    return result;
  }
  result.spec = in->spec();
  result.pixels.resize(static_cast<std::size_t>(result.spec.width) * result.spec.height *
                       result.spec.nchannels);
  EXPECT_TRUE(
      in->read_image(0, 0, 0, result.spec.nchannels, OIIO::TypeDesc::FLOAT, result.pixels.data()));
  in->close();
  return result;
}

TEST_F(ImageOutputTest, Png16BitReadsBackTopRowFirst) {
  const FloatImage image = rampImage(5, 3, 3);
  const fs::path path = dir_ / "ramp.png";
  ASSERT_TRUE(writeImage(image, path)) << "default: 16-bit";
  const ReadBack back = readBack(path);
  EXPECT_EQ(back.spec.format, OIIO::TypeDesc::UINT16);
  ASSERT_EQ(back.spec.width, 5);
  ASSERT_EQ(back.spec.height, 3);
  ASSERT_EQ(back.spec.nchannels, 3);
  for (int row = 0; row < 3; ++row) {
    for (int x = 0; x < 5; ++x) {
      for (int c = 0; c < 3; ++c) {
        // 16-bit quantization: within half a code.
        EXPECT_NEAR(back.at(x, row, c), image.at(x, row, c), 0.5 / 65535 + 1e-7)
            << "x " << x << " row " << row << " channel " << c;
      }
    }
  }
  // Orientation spelled out: the file's first row is FloatImage row 0.
  EXPECT_NEAR(back.at(0, 0, 0), 0.0f, 1e-6);
  EXPECT_NEAR(back.at(0, 2, 0), 0.020f, 1e-5);
}

TEST_F(ImageOutputTest, Png8BitIsTheMaskDefault) {
  EXPECT_EQ(defaultBitDepth(ImageFormat::kPng, MapKind::kMask), 8);
  EXPECT_EQ(defaultBitDepth(ImageFormat::kPng, MapKind::kTangentNormal), 16);
  EXPECT_EQ(defaultBitDepth(ImageFormat::kExr, MapKind::kMask), 16);
  ImageWriteOptions options;
  options.bitDepth = 8;
  const FloatImage image = rampImage(4, 4, 1);
  ASSERT_TRUE(writeImage(image, dir_ / "mask.png", options));
  const ReadBack back = readBack(dir_ / "mask.png");
  EXPECT_EQ(back.spec.format, OIIO::TypeDesc::UINT8);
  EXPECT_EQ(back.spec.nchannels, 1);
  EXPECT_NEAR(back.at(3, 2, 0), image.at(3, 2, 0), 0.5 / 255 + 1e-7);
}

TEST_F(ImageOutputTest, IntegerFormatsClampAndWriteNanAsZero) {
  FloatImage image = rampImage(3, 1, 1);
  image.pixels = {-0.5f, 2.0f, std::numeric_limits<float>::quiet_NaN()};
  ASSERT_TRUE(writeImage(image, dir_ / "clamp.png"));
  const ReadBack back = readBack(dir_ / "clamp.png");
  EXPECT_EQ(back.at(0, 0, 0), 0.0f);
  EXPECT_EQ(back.at(1, 0, 0), 1.0f);
  EXPECT_EQ(back.at(2, 0, 0), 0.0f);
}

/// Writes @p values as a one-row, one-channel image through an ImageFileWriter and returns the
/// values it says it clamped (the file is read back by the caller).
std::uint64_t writeAndCountClipped(const std::vector<float>& values, const fs::path& path,
                                   int bitDepth) {
  ImageWriteOptions options;
  options.bitDepth = bitDepth;
  Result<ImageFileWriter> writer =
      ImageFileWriter::open(path, static_cast<int>(values.size()), 1, 1, options);
  if (!writer) {
    ADD_FAILURE() << writer.error().message;
    return 0;
  }
  EXPECT_TRUE(writer->writeRows(0, 1, values, {}));
  EXPECT_TRUE(writer->commit());
  return writer->clippedValues();
}

TEST_F(ImageOutputTest, ValuesTheFileCannotStoreAreClampedAndCounted) {
  const float inf = std::numeric_limits<float>::infinity();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  // Integer files: outside [0, 1] by more than half a code, and NaN. Within half a code of the
  // ends (rounding noise of an encoded unit normal) is stored as it is: not counted.
  const std::vector<float> codes = {
      0.0f, 1.0f, 1.0f + 0.4f / 65535, -0.4f / 65535, 1.0f + 0.6f / 65535, -0.6f / 65535,
      2.0f, nan};
  EXPECT_EQ(writeAndCountClipped(codes, dir_ / "c16.png", 16), 4u);
  const ReadBack png = readBack(dir_ / "c16.png");
  EXPECT_EQ(png.at(4, 0, 0), 1.0f);
  EXPECT_EQ(png.at(5, 0, 0), 0.0f);
  EXPECT_EQ(writeAndCountClipped(codes, dir_ / "c8.png", 8), 2u);  // ±0.6/65535 fit 8 bits

  // Half: beyond ±65504 is clamped to it instead of becoming an infinity.
  const std::vector<float> halves = {65504.0f, -65504.0f, 1e5f, -1e30f, inf, nan, 3.0f};
  EXPECT_EQ(writeAndCountClipped(halves, dir_ / "h.exr", 16), 4u);
  const ReadBack half = readBack(dir_ / "h.exr");
  const std::vector<float> expectedHalf = {65504.0f, -65504.0f, 65504.0f, -65504.0f,
                                           65504.0f, 0.0f,      3.0f};
  for (std::size_t i = 0; i < halves.size(); ++i) {
    EXPECT_EQ(half.at(static_cast<int>(i), 0, 0), expectedHalf[i]) << i;
  }

  // Float: only infinities and NaN.
  const std::vector<float> floats = {1e30f, -1e38f, inf, -inf, nan, 0.5f};
  EXPECT_EQ(writeAndCountClipped(floats, dir_ / "f.exr", 32), 3u);
  const ReadBack full = readBack(dir_ / "f.exr");
  const float max = std::numeric_limits<float>::max();
  const std::vector<float> expectedFloat = {1e30f, -1e38f, max, -max, 0.0f, 0.5f};
  for (std::size_t i = 0; i < floats.size(); ++i) {
    EXPECT_EQ(full.at(static_cast<int>(i), 0, 0), expectedFloat[i]) << i;
  }
}

TEST_F(ImageOutputTest, PngAlphaIsUnassociatedCoverage) {
  FloatImage image = rampImage(2, 2, 3);
  image.coverage = {0.5f, 1.0f, 0.25f, 0.0f};
  ImageWriteOptions options;
  options.alpha = true;
  ASSERT_TRUE(writeImage(image, dir_ / "alpha.png", options));
  const ReadBack back = readBack(dir_ / "alpha.png");
  ASSERT_EQ(back.spec.nchannels, 4);
  EXPECT_EQ(back.spec.alpha_channel, 3);
  EXPECT_NEAR(back.at(0, 0, 3), 0.5f, 1e-4);
  EXPECT_NEAR(back.at(1, 1, 3), 0.0f, 1e-6);
  // Colour kept as baked: not divided by alpha (0.4 would come back as 0.8) nor multiplied.
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(back.at(0, 0, c), image.at(0, 0, c), 1e-4) << c;
    EXPECT_NEAR(back.at(0, 1, c), image.at(0, 1, c), 1e-4) << c;
  }
}

TEST_F(ImageOutputTest, TwoChannelsArePaddedToRgbInPng) {
  const FloatImage image = rampImage(2, 2, 2);
  ASSERT_TRUE(writeImage(image, dir_ / "rg.png"));
  const ReadBack back = readBack(dir_ / "rg.png");
  ASSERT_EQ(back.spec.nchannels, 3);
  EXPECT_NEAR(back.at(1, 1, 1), image.at(1, 1, 1), 1e-4);
  EXPECT_EQ(back.at(1, 1, 2), 0.0f);
  // EXR keeps two named channels.
  ASSERT_TRUE(writeImage(image, dir_ / "rg.exr"));
  const ReadBack exr = readBack(dir_ / "rg.exr");
  ASSERT_EQ(exr.spec.nchannels, 2);
  EXPECT_EQ(exr.spec.channelnames[0], "R");
  EXPECT_EQ(exr.spec.channelnames[1], "G");
}

TEST_F(ImageOutputTest, ExrHalfByDefaultAndFloatOnRequest) {
  FloatImage image = rampImage(3, 2, 3);
  image.pixels[0] = -3.25f;       // signed values survive (surface gradients)
  image.pixels[1] = 1.0f / 3.0f;  // not representable in half
  image.pixels[2] = 1000.5f;      // beyond [0, 1]
  ASSERT_TRUE(writeImage(image, dir_ / "half.exr"));
  const ReadBack half = readBack(dir_ / "half.exr");
  EXPECT_EQ(half.spec.format, OIIO::TypeDesc::HALF);
  EXPECT_EQ(half.at(0, 0, 0), -3.25f);
  EXPECT_NEAR(half.at(0, 0, 1), 1.0f / 3.0f, 1.0f / 2048);
  EXPECT_NE(half.at(0, 0, 1), 1.0f / 3.0f);
  EXPECT_EQ(half.at(0, 0, 2), 1000.5f);
  EXPECT_EQ(half.spec.get_string_attribute("compression"), "zip");

  ImageWriteOptions options;
  options.bitDepth = 32;
  ASSERT_TRUE(writeImage(image, dir_ / "float.exr", options));
  const ReadBack full = readBack(dir_ / "float.exr");
  EXPECT_EQ(full.spec.format, OIIO::TypeDesc::FLOAT);
  ASSERT_EQ(full.pixels.size(), image.pixels.size());
  for (std::size_t i = 0; i < image.pixels.size(); ++i) {
    EXPECT_EQ(full.pixels[i], image.pixels[i]) << i;  // bit-exact
  }
}

TEST_F(ImageOutputTest, TiffIntegerAndFloat) {
  const FloatImage image = rampImage(4, 3, 1);
  ImageWriteOptions options;
  options.bitDepth = 32;
  ASSERT_TRUE(writeImage(image, dir_ / "h.tif", options));
  const ReadBack full = readBack(dir_ / "h.tif");
  EXPECT_EQ(full.spec.format, OIIO::TypeDesc::FLOAT);
  EXPECT_EQ(full.at(3, 2, 0), image.at(3, 2, 0));
  options.bitDepth = 16;
  ASSERT_TRUE(writeImage(image, dir_ / "h16.TIFF", options));  // extension case-insensitive
  EXPECT_EQ(readBack(dir_ / "h16.TIFF").spec.format, OIIO::TypeDesc::UINT16);
}

TEST_F(ImageOutputTest, FormatOptionOverridesTheExtension) {
  ImageWriteOptions options;
  options.format = ImageFormat::kExr;
  ASSERT_TRUE(writeImage(rampImage(2, 2, 1), dir_ / "data.bin", options));
  const ReadBack back = readBack(dir_ / "data.bin");
  EXPECT_EQ(back.spec.format, OIIO::TypeDesc::HALF);
}

TEST_F(ImageOutputTest, FormatNames) {
  EXPECT_EQ(*imageFormatFromPath("a/b.EXR"), ImageFormat::kExr);
  EXPECT_EQ(*imageFormatFromPath("b.tif"), ImageFormat::kTiff);
  EXPECT_EQ(*parseImageFormat("TIFF"), ImageFormat::kTiff);
  EXPECT_FALSE(parseImageFormat("jpeg"));
  EXPECT_FALSE(imageFormatFromPath("noextension"));
  EXPECT_TRUE(formatSupportsBitDepth(ImageFormat::kTiff, 32));
  EXPECT_FALSE(formatSupportsBitDepth(ImageFormat::kPng, 32));
  EXPECT_FALSE(formatSupportsBitDepth(ImageFormat::kExr, 8));
}

TEST_F(ImageOutputTest, UnknownExtensionIsBadInputNamingTheFile) {
  const fs::path path = dir_ / "normal.jpg";
  const Status status = writeImage(rampImage(2, 2, 3), path);
  ASSERT_FALSE(status);
  EXPECT_EQ(status.error().code, ErrorCode::kBadInput);
  EXPECT_NE(status.error().message.find(path.string()), std::string::npos)
      << status.error().message;
  EXPECT_NE(status.error().message.find("'.jpg'"), std::string::npos) << status.error().message;
  EXPECT_TRUE(listDirectory(dir_).empty());
}

TEST_F(ImageOutputTest, BitDepthTheFormatCannotStoreIsBadInput) {
  ImageWriteOptions options;
  options.bitDepth = 32;
  const Status png = writeImage(rampImage(2, 2, 3), dir_ / "n.png", options);
  ASSERT_FALSE(png);
  EXPECT_EQ(png.error().code, ErrorCode::kBadInput);
  EXPECT_NE(png.error().message.find("PNG cannot store 32-bit channels"), std::string::npos)
      << png.error().message;
  options.bitDepth = 8;
  const Status exr = writeImage(rampImage(2, 2, 3), dir_ / "n.exr", options);
  ASSERT_FALSE(exr);
  EXPECT_NE(exr.error().message.find("EXR cannot store 8-bit"), std::string::npos);
  EXPECT_TRUE(listDirectory(dir_).empty());
}

TEST_F(ImageOutputTest, MissingDirectoryIsBadInputNamingTheFile) {
  const fs::path path = dir_ / "missing" / "n.png";
  const Status status = writeImage(rampImage(2, 2, 3), path);
  ASSERT_FALSE(status);
  EXPECT_EQ(status.error().code, ErrorCode::kBadInput);
  EXPECT_TRUE(status.error().message.starts_with(path.string() + ": cannot create file"))
      << status.error().message;
  EXPECT_EQ(status.error().message.find('\n'), std::string::npos);
}

TEST_F(ImageOutputTest, FailedWriteLeavesTheExistingFileAndNoTemporary) {
  const fs::path path = dir_ / "n.png";
  {
    std::ofstream out(path, std::ios::binary);
    out << "previous content";
  }
  FloatImage broken = rampImage(2, 2, 3);
  broken.pixels.resize(3);  // inconsistent with its size: rejected
  EXPECT_FALSE(writeImage(broken, path));
  FloatImage empty;
  EXPECT_FALSE(writeImage(empty, path));
  EXPECT_EQ(readFile(path), "previous content");
  EXPECT_EQ(listDirectory(dir_), std::set<std::string>{"n.png"});
}

TEST_F(ImageOutputTest, SuccessfulWriteReplacesTheFileAndLeavesNoTemporary) {
  const fs::path path = dir_ / "n.exr";
  {
    std::ofstream out(path, std::ios::binary);
    out << "previous content";
  }
  ASSERT_TRUE(writeImage(rampImage(3, 3, 3), path));
  EXPECT_NE(readFile(path), "previous content");
  EXPECT_EQ(readBack(path).spec.width, 3);
  EXPECT_EQ(listDirectory(dir_), std::set<std::string>{"n.exr"});
}

TEST_F(ImageOutputTest, IntegerCodesRoundHalfAwayFromZero) {
  // Codes are lround(v · (2^bits − 1)): check the values next to every rounding boundary of
  // 8-bit codes and a sweep of 16-bit ones.
  FloatImage image;
  image.width = 0;
  image.height = 1;
  image.channels = 1;
  for (int code = 0; code < 255; ++code) {
    const float boundary = static_cast<float>((code + 0.5) / 255.0);
    for (const float v : {std::nextafter(boundary, 0.0f), boundary, std::nextafter(boundary, 1.0f)})
      image.pixels.push_back(v);
  }
  for (int k = 0; k <= 1000; ++k) image.pixels.push_back(static_cast<float>(k) / 1000.0f);
  image.width = static_cast<int>(image.pixels.size());
  image.coverage.assign(image.pixels.size(), 1.0f);
  for (const int bits : {8, 16}) {
    const fs::path path = dir_ / ("codes" + std::to_string(bits) + ".png");
    ImageWriteOptions options;
    options.bitDepth = bits;
    ASSERT_TRUE(writeImage(image, path, options));
    std::unique_ptr<OIIO::ImageInput> in = OIIO::ImageInput::open(path.string());
    ASSERT_TRUE(in);
    std::vector<std::uint16_t> codes(image.pixels.size());
    ASSERT_TRUE(in->read_image(0, 0, 0, 1, OIIO::TypeDesc::UINT16, codes.data()));
    const double maxCode = bits == 8 ? 255.0 : 65535.0;
    const double scale = 65535.0 / maxCode;  // OIIO reads an 8-bit code c as 257·c
    for (std::size_t i = 0; i < codes.size(); ++i) {
      const long expected = std::lround(static_cast<double>(image.pixels[i]) * maxCode);
      ASSERT_EQ(codes[i], static_cast<std::uint16_t>(static_cast<double>(expected) * scale)) << bits << " bits, value " << image.pixels[i];
    }
  }
}

// With the strips written by tasks of the caller's arena (threads 0) and without them (threads 1:
// each strip written by writeRows itself, before it returns).
TEST_F(ImageOutputTest, StripsWrittenInTurnEqualTheWholeImage) {
  const FloatImage image = rampImage(7, 9, 3);
  ASSERT_TRUE(writeImage(image, dir_ / "whole.png"));
  const ReadBack whole = readBack(dir_ / "whole.png");
  for (const int threads : {0, 1}) {
    SCOPED_TRACE("threads " + std::to_string(threads));
    const fs::path path = dir_ / ("strips" + std::to_string(threads) + ".png");
    ImageWriteOptions options;
    options.alpha = true;
    options.threads = threads;
    Result<ImageFileWriter> writer = ImageFileWriter::open(path, 7, 9, 3, options);
    ASSERT_TRUE(writer.ok());
    EXPECT_EQ(listDirectory(dir_).count(path.filename().string()), 0u);  // nothing there yet
    const std::span<const float> pixels(image.pixels), coverage(image.coverage);
    int row = 0;
    for (const int rows : {2, 0, 4, 3}) {
      ASSERT_TRUE(writer->writeRows(row, rows,
                                    pixels.subspan(std::size_t(row) * 21, std::size_t(rows) * 21),
                                    coverage.subspan(std::size_t(row) * 7, std::size_t(rows) * 7)));
      row += rows;
      if (threads == 1) {
        EXPECT_GT(writer->fileSeconds(), 0.0);  // written already
      }
    }
    ASSERT_TRUE(writer->commit());
    EXPECT_GE(writer->fileSeconds(), 0.0);
    const ReadBack strips = readBack(path);
    ASSERT_EQ(strips.spec.nchannels, 4);
    for (int r = 0; r < 9; ++r)
      for (int x = 0; x < 7; ++x)
        for (int c = 0; c < 3; ++c)
          ASSERT_EQ(strips.at(x, r, c), whole.at(x, r, c)) << x << "," << r;
  }
}

// More strips at once than the queue holds (writeRows splits 300 rows into strips of 64): the
// caller waits for the task writing them, or writes them itself when no thread is; in an arena
// of two threads, of one, and in the caller's. The file is the whole image, row for row.
TEST_F(ImageOutputTest, MoreStripsThanTheQueueHoldsAreWrittenInOrder) {
  const int width = 5, height = 1000;
  const FloatImage image = rampImage(width, height, 3);
  const std::span<const float> pixels(image.pixels);
  ImageWriteOptions options;
  options.bitDepth = 32;  // float EXR: every ramp value exactly
  const auto writeAll = [&](const fs::path& path, int threads) {
    options.threads = threads;
    Result<ImageFileWriter> writer = ImageFileWriter::open(path, width, height, 3, options);
    ASSERT_TRUE(writer.ok());
    const auto rowValues = static_cast<std::size_t>(width * 3);
    for (int row = 0; row < height; row += 300) {
      const int rows = std::min(300, height - row);
      ASSERT_TRUE(writer->writeRows(
          row, rows, pixels.subspan(std::size_t(row) * rowValues, std::size_t(rows) * rowValues),
          {}));
    }
    ASSERT_TRUE(writer->commit());
  };
  const std::vector<std::pair<int, int>> cases = {{0, 0}, {2, 2}, {1, 2}, {2, 1}};
  for (const auto& [arenaThreads, threads] : cases) {
    SCOPED_TRACE("arena " + std::to_string(arenaThreads) + ", threads " + std::to_string(threads));
    const fs::path path =
        dir_ / ("many" + std::to_string(arenaThreads) + std::to_string(threads) + ".exr");
    if (arenaThreads == 0) {
      writeAll(path, threads);
    } else {
      tbb::task_arena(arenaThreads).execute([&] { writeAll(path, threads); });
    }
    const ReadBack back = readBack(path);
    ASSERT_EQ(back.spec.height, height);
    for (int r = 0; r < height; ++r)
      for (int x = 0; x < width; ++x)
        for (int c = 0; c < 3; ++c) ASSERT_EQ(back.at(x, r, c), image.at(x, r, c)) << x << "," << r;
  }
  // Abandoned with strips queued: nothing is left, at once (not when a late task lets go).
  const std::set<std::string> before = listDirectory(dir_);
  {
    options.threads = 0;
    Result<ImageFileWriter> abandoned =
        ImageFileWriter::open(dir_ / "abandoned.exr", width, height, 3, options);
    ASSERT_TRUE(abandoned.ok());
    ASSERT_TRUE(abandoned->writeRows(0, height, pixels, {}));
  }
  EXPECT_EQ(listDirectory(dir_), before);
}

TEST_F(ImageOutputTest, StripWriterRejectsGapsAndLeavesNothingWhenUnfinished) {
  const fs::path path = dir_ / "n.png";
  {
    std::ofstream out(path, std::ios::binary);
    out << "previous content";
  }
  const FloatImage image = rampImage(4, 4, 1);
  const std::span<const float> pixels(image.pixels);
  for (const int threads : {0, 1}) {  // strips written by tasks, or by writeRows (see above)
    SCOPED_TRACE("threads " + std::to_string(threads));
    ImageWriteOptions options;
    options.threads = threads;
    Result<ImageFileWriter> writer = ImageFileWriter::open(path, 4, 4, 1, options);
    ASSERT_TRUE(writer.ok());
    ASSERT_TRUE(writer->writeRows(0, 1, pixels.subspan(0, 4), {}));
    const Status gap = writer->writeRows(2, 1, pixels.subspan(8, 4), {});  // row 1 skipped
    ASSERT_FALSE(gap);
    EXPECT_EQ(gap.error().code, ErrorCode::kInternal);
    EXPECT_FALSE(writer->writeRows(1, 1, pixels.subspan(0, 3), {}));  // wrong size
    const Status incomplete = writer->commit();  // rows 1 to 3 missing
    ASSERT_FALSE(incomplete);
    EXPECT_TRUE(incomplete.error().message.starts_with(path.string() + ": ")) << incomplete.error().message;
  }
  for (const int threads : {0, 1}) {
    ImageWriteOptions options;
    options.threads = threads;
    Result<ImageFileWriter> abandoned = ImageFileWriter::open(path, 4, 4, 1, options);
    ASSERT_TRUE(abandoned.ok());
    ASSERT_TRUE(abandoned->writeRows(0, 4, pixels, {}));
  }  // each destroyed without commit
  EXPECT_EQ(readFile(path), "previous content");
  EXPECT_EQ(listDirectory(dir_), std::set<std::string>{"n.png"});
}

TEST_F(ImageOutputTest, RemoveTemporaryFilesTakesOnlyUnfinishedTemporaries) {
  // What a signal handler calls: the temporaries of open AtomicFiles (the CLI's and an image
  // writer's) go; committed files stay.
  Result<AtomicFile> open = AtomicFile::create(dir_ / "open.txt");
  ASSERT_TRUE(open.ok());
  ASSERT_TRUE(writeFileAtomically(dir_ / "done.txt", "done"));
  Result<ImageFileWriter> image = ImageFileWriter::open(dir_ / "n.png", 4, 4, 1);
  ASSERT_TRUE(image.ok());
  EXPECT_EQ(listDirectory(dir_).size(), 3u);  // done.txt and two temporaries
  removeTemporaryFiles();
  EXPECT_EQ(listDirectory(dir_), std::set<std::string>{"done.txt"});
  EXPECT_EQ(readFile(dir_ / "done.txt"), "done");
  EXPECT_FALSE(open->commit());  // its temporary is gone: nothing appears at the target
  EXPECT_EQ(listDirectory(dir_), std::set<std::string>{"done.txt"});
}

TEST_F(ImageOutputTest, PipesAndLinksToThemAreRefusedAndLinksToFilesReplaced) {
  // A FIFO (like a device) would be replaced by the rename: refused, and left as it is; so is
  // a link to one (as /dev/stdout is). A link to a regular file is replaced by the new file.
  const fs::path fifo = dir_ / "pipe.csv";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  Result<AtomicFile> refused = AtomicFile::create(fifo);
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().code, ErrorCode::kBadInput);
  EXPECT_NE(refused.error().message.find("pipe.csv: is not a regular file"), std::string::npos)
      << refused.error().message;
  fs::create_symlink("pipe.csv", dir_ / "to_pipe.csv");
  EXPECT_FALSE(writeFileAtomically(dir_ / "to_pipe.csv", "x"));
  EXPECT_TRUE(fs::is_fifo(fs::symlink_status(fifo)));
  EXPECT_TRUE(fs::is_symlink(fs::symlink_status(dir_ / "to_pipe.csv")));

  writeFile(dir_ / "kept.csv", "old");
  fs::create_symlink("kept.csv", dir_ / "to_file.csv");
  ASSERT_TRUE(writeFileAtomically(dir_ / "to_file.csv", "new"));
  EXPECT_FALSE(fs::is_symlink(fs::symlink_status(dir_ / "to_file.csv")));
  EXPECT_EQ(readFile(dir_ / "to_file.csv"), "new");
  EXPECT_EQ(readFile(dir_ / "kept.csv"), "old");
  EXPECT_EQ(listDirectory(dir_),
            (std::set<std::string>{"kept.csv", "pipe.csv", "to_file.csv", "to_pipe.csv"}));
}

TEST(UdimToken, Expansion) {
  EXPECT_EQ(expandUdimToken("out/n.<UDIM>.png", 1002), "out/n.1002.png");
  EXPECT_EQ(expandUdimToken("<UDIM>/n_<UDIM>.exr", 1011), "1011/n_1011.exr");
  EXPECT_EQ(expandUdimToken("out/n.png", 1002), "out/n.png");
  EXPECT_EQ(expandUdimToken("out/n.<udim>.png", 1002), "out/n.<udim>.png");  // case matters
  EXPECT_TRUE(hasUdimToken("a.<UDIM>.png"));
  EXPECT_FALSE(hasUdimToken("a.<UDIM.png"));
}

}  // namespace
}  // namespace sgbake
