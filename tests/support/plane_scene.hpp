/// @file plane_scene.hpp
/// @brief The unit-square plane the planner and CLI bake tests build their scenes on.
#pragma once

#include <string>

namespace sgbake::test {

/// A unit square, z = 0, UVs = (x, y), normal +z.
inline constexpr const char* kPlaneObj =
    "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
    "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
    "vn 0 0 1\n"
    "f 1/1/1 2/2/1 3/3/1 4/4/1\n";

/// A valid mesh without texture coordinates.
inline constexpr const char* kNoUvObj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";

/// A height layer reading h.png, scale 0.1.
inline constexpr const char* kHeightLayer =
    R"({"type": "height", "image": "h.png", "scale": 0.1})";

/// A scene of @p mesh with @p layers and @p outputs (JSON array contents).
inline std::string planeScene(const std::string& layers, const std::string& outputs,
                              const std::string& mesh = "plane.obj") {
  return R"({"mesh": ")" + mesh + R"(", "layers": [)" + layers + R"(], "outputs": [)" + outputs +
         "]}";
}

}  // namespace sgbake::test
