// The image I/O module (sgbake/io/image_io.hpp): not loaded until an image is read or written,
// then found beside libsgbake and loaded once. This executable does not link OpenImageIO, so
// what /proc/self/maps shows is what libsgbake loaded.
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <string>

#include "sgbake/bake/image_output.hpp"
#include "sgbake/gradient/image.hpp"
#include "sgbake/io/image_io.hpp"
#include "support/files.hpp"

namespace sgbake {
namespace {

namespace fs = std::filesystem;

bool mapped(const std::string& fileName) {
  return test::readFile("/proc/self/maps").find(fileName) != std::string::npos;
}

// One test: the module can be loaded only once per process, and the test needs the "before".
TEST(ImageIo, LoadsTheModuleBesideTheLibraryOnlyWhenAnImageIsUsed) {
  ASSERT_EQ(std::getenv("SGBAKE_IMAGE_IO_MODULE"), nullptr);
  EXPECT_EQ(imageIoModulePath().filename(), "libsgbake_oiio.so");
  EXPECT_TRUE(fs::exists(imageIoModulePath())) << imageIoModulePath();
  EXPECT_FALSE(mapped("libOpenImageIO")) << "OpenImageIO is loaded before any image is used";
  EXPECT_FALSE(mapped("libsgbake_oiio.so"));

  finishImageIoPreload();  // nothing was started: it must not load the module itself
  EXPECT_FALSE(mapped("libsgbake_oiio.so"));

  preloadImageIo();
  preloadImageIo();  // a second call does nothing
  finishImageIoPreload();  // returns once the module is in the process
  EXPECT_TRUE(mapped("libsgbake_oiio.so"));
  EXPECT_TRUE(mapped("libOpenImageIO"));

  // A round trip through the module: EXR float keeps every value.
  const fs::path path = fs::temp_directory_path() /
                        ("sgbake_image_io_" + std::to_string(::getpid()) + ".exr");
  FloatImage image;
  image.width = 3;
  image.height = 2;
  image.channels = 1;
  image.pixels = {0.125f, -2.0f, 1e-3f, 4.0f, 0.0f, 65504.0f};
  image.coverage.assign(6, 1.0f);
  ImageWriteOptions options;
  options.bitDepth = 32;
  ASSERT_TRUE(writeImage(image, path, options));
  Result<Image> read = loadImage(path);
  fs::remove(path);
  ASSERT_TRUE(read) << read.error().message;
  ASSERT_EQ(read->width(), 3);
  ASSERT_EQ(read->height(), 2);
  // FloatImage rows are top first; Image rows bottom first (y up).
  for (int r = 0; r < 2; ++r)
    for (int x = 0; x < 3; ++x)
      EXPECT_EQ(read->at(x, 1 - r), image.pixels[static_cast<std::size_t>(r * 3 + x)]);

  EXPECT_TRUE(mapped("libsgbake_oiio.so"));
  EXPECT_TRUE(mapped("libOpenImageIO"));
}

}  // namespace
}  // namespace sgbake
