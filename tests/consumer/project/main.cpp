// The C++ side of the consumer: the same triangle through sgbake's C++ API and through its C
// ABI (c_abi.c); both must agree, bit for bit, and give the obvious frame.
#include <unistd.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include <sgbake/bake/image_output.hpp>
#include <sgbake/frames/tangents.hpp>
#include <sgbake/gradient/image.hpp>
#include <sgbake/mesh/mesh.hpp>
#include <sgbake/sgbake.h>

extern "C" int consumer_c_tangents(float out_tangents[9], float out_signs[3], char* error,
                                   size_t size);
extern "C" int consumer_c_bake(float out_rgba[64], char* error, size_t size);

namespace {

int failures = 0;

void check(bool ok, const char* what) {
  if (!ok) {
    std::fprintf(stderr, "consumer: FAILED: %s\n", what);
    ++failures;
  }
}

}  // namespace

int main() {
  check(std::strcmp(sgbake_version(), SGBAKE_VERSION_STRING) == 0,
        "sgbake_version() matches the installed header");
  check(std::strcmp(sgbake_version(), SGBAKE_PACKAGE_VERSION) == 0,
        "sgbake_version() matches the CMake package version");

  const std::vector<sgbake::Vec3f> positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  const std::vector<std::uint32_t> faceStart = {0, 3};
  const std::vector<std::uint32_t> cornerVertex = {0, 1, 2};
  const std::vector<sgbake::Vec3f> normals(3, sgbake::Vec3f{0, 0, 1});
  const std::vector<sgbake::Vec2f> uvs = {{0, 0}, {1, 0}, {0, 1}};
  const sgbake::MeshView mesh{positions, faceStart, cornerVertex, normals, uvs};
  const sgbake::Result<sgbake::CornerTangents> cpp = sgbake::computeTangents(mesh);
  check(cpp.ok(), "C++ computeTangents succeeds");
  if (!cpp.ok()) {
    std::fprintf(stderr, "consumer: %s\n", cpp.error().message.c_str());
    return 1;
  }

  float tangents[9] = {};
  float signs[3] = {};
  char error[256] = "";
  const int status = consumer_c_tangents(tangents, signs, error, sizeof error);
  check(status == SGBAKE_OK, "C sgbake_compute_tangents succeeds");
  if (status != SGBAKE_OK) {
    std::fprintf(stderr, "consumer: %s\n", error);
    return 1;
  }

  float rgba[64] = {};
  const int baked = consumer_c_bake(rgba, error, sizeof error);
  check(baked == SGBAKE_OK, "C sgbake_bake_map succeeds");
  if (baked != SGBAKE_OK) std::fprintf(stderr, "consumer: %s\n", error);
  // Texel (0, 0) (bottom left, the triangle's right-angle corner) is +z, alpha 1.
  check(rgba[0] == 0.5f && rgba[1] == 0.5f && rgba[2] == 1.0f && rgba[3] == 1.0f,
        "C bake of the triangle is the encoded +z normal");

  for (int c = 0; c < 3; ++c) {
    const sgbake::Vec3f t = cpp->tangent[c];
    check(t.x == tangents[3 * c] && t.y == tangents[3 * c + 1] && t.z == tangents[3 * c + 2],
          "C and C++ tangents are identical");
    check(cpp->sign[c] == signs[c], "C and C++ signs are identical");
    check(t.x > 0.999999f && t.y == 0.0f && t.z == 0.0f && signs[c] == 1.0f,
          "tangent is +x with sign +1");
  }

  // Image files go through the installed image I/O module (found beside the installed library).
  const std::filesystem::path file = std::filesystem::temp_directory_path() /
                                     ("sgbake_consumer_" + std::to_string(::getpid()) + ".png");
  sgbake::FloatImage image;
  image.width = 2;
  image.height = 1;
  image.channels = 1;
  image.pixels = {0.0f, 1.0f};
  image.coverage = {1.0f, 1.0f};
  const sgbake::Status written = sgbake::writeImage(image, file);
  check(written.ok(), "writeImage succeeds through the installed module");
  if (!written.ok()) std::fprintf(stderr, "consumer: %s\n", written.error().message.c_str());
  const sgbake::Result<sgbake::Image> read = sgbake::loadImage(file);
  std::filesystem::remove(file);
  check(read.ok() && read->width() == 2 && read->at(0, 0) == 0.0f && read->at(1, 0) == 1.0f,
        "loadImage reads the written PNG back");

  if (failures != 0) return 1;
  std::printf("consumer: sgbake %s: C++ API and C ABI agree; images round-trip\n",
              sgbake_version());
  return 0;
}
