// sgbake_bench_write IMAGE [RUNS]: the time OpenImageIO alone needs to write IMAGE (already in
// memory, in the file's own pixel type) with the settings sgbake writes that format with — the
// baseline of bench_bake_vs_cycles' total/write target. Best and median of RUNS (default 5)
// writes to a temporary file beside IMAGE; prints one JSON line.
// sgbake_bench_write --start-only: exits at once, so that timing the whole process gives what a
// program writing with OpenImageIO pays before its first write (start-up, loading the ~260
// libraries Debian's OpenImageIO links); bench_bake_vs_cycles adds it to write_s for a
// process-to-process comparison.
#include <OpenImageIO/imageio.h>

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "sgbake/bake/image_output.hpp"

namespace {

int fail(const std::string& message) {
  std::fprintf(stderr, "sgbake_bench_write: %s\n", message.c_str());
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 2 && std::string(argv[1]) == "--start-only") {
    std::printf("{\"oiio_version\": %d}\n", OIIO::openimageio_version());
    return 0;
  }
  if (argc < 2 || argc > 3) return fail("usage: sgbake_bench_write IMAGE [RUNS] | --start-only");
  const std::filesystem::path path = argv[1];
  const int runs = argc == 3 ? std::atoi(argv[2]) : 5;
  if (runs < 1) return fail("RUNS must be at least 1");
  std::unique_ptr<OIIO::ImageInput> in = OIIO::ImageInput::open(path.string());
  if (!in) return fail(path.string() + ": " + OIIO::geterror());
  const OIIO::ImageSpec fileSpec = in->spec();
  const OIIO::TypeDesc type = fileSpec.format;
  std::vector<unsigned char> pixels(fileSpec.image_bytes());
  if (!in->read_image(0, 0, 0, fileSpec.nchannels, type, pixels.data())) {
    return fail(path.string() + ": " + in->geterror());
  }
  in->close();

  // The attributes ImageFileWriter (src/bake/image_output.cpp) gives each format.
  const std::string format = in->format_name();
  OIIO::ImageSpec spec(fileSpec.width, fileSpec.height, fileSpec.nchannels, type);
  spec.channelnames = fileSpec.channelnames;
  spec.alpha_channel = fileSpec.alpha_channel;
  if (format == "png") {
    spec.attribute("png:compressionLevel", sgbake::kPngCompressionLevel);
    spec.attribute("png:filter", sgbake::kPngFilters);
  } else {
    spec.attribute("compression", "zip");
  }
  const std::filesystem::path out =
      path.parent_path() / (".write-bench-" + std::to_string(::getpid()) + path.extension().string());
  std::vector<double> seconds;
  for (int run = 0; run < runs; ++run) {
    const auto start = std::chrono::steady_clock::now();
    std::unique_ptr<OIIO::ImageOutput> writer = OIIO::ImageOutput::create(format);
    if (!writer || !writer->open(out.string(), spec) ||
        !writer->write_image(type, pixels.data()) || !writer->close()) {
      std::filesystem::remove(out);
      return fail(out.string() + ": cannot write (" + OIIO::geterror() + ")");
    }
    seconds.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  const auto bytes = std::filesystem::file_size(out);
  std::filesystem::remove(out);
  std::sort(seconds.begin(), seconds.end());
  std::printf("{\"write_s\": %.6f, \"median_s\": %.6f, \"runs\": %d, \"bytes\": %ju}\n",
              seconds.front(), seconds[seconds.size() / 2], runs, static_cast<std::uintmax_t>(bytes));
  return 0;
}
