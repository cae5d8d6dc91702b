/// @file obj_writer.cpp
/// @brief formatObj: a Mesh as OBJ text that reads back bit for bit.
#include <algorithm>
#include <array>
#include <charconv>

#include "sgbake/mesh/io.hpp"

namespace sgbake {
namespace {

/// Appends " x" per value, each float in its shortest round-trip form.
template <std::size_t N>
void appendFloats(std::string& out, const char* tag, const std::array<float, N>& values) {
  out += tag;
  char text[32];
  for (const float value : values) {
    out += ' ';
    const auto result = std::to_chars(text, text + sizeof text, value);
    out.append(text, result.ptr);
  }
  out += '\n';
}

}  // namespace

std::string formatObj(const Mesh& mesh, std::size_t uvSet) {
  std::string out;
  out.reserve(48 * (mesh.numVertices() + 2 * mesh.numCorners()) + 24 * mesh.numCorners());
  for (const Vec3f& p : mesh.positions) appendFloats(out, "v", std::array{p.x, p.y, p.z});
  const bool uvs = mesh.hasUvSet(uvSet);
  if (uvs) {
    for (const Vec2f& t : mesh.uvSets[uvSet].uvs) appendFloats(out, "vt", std::array{t.x, t.y});
  }
  for (const Vec3f& n : mesh.cornerNormals) appendFloats(out, "vn", std::array{n.x, n.y, n.z});
  // Flat faces as Blender's exporter marks them: `s 0` before a run of flat faces, `s 1`
  // before a run of smooth ones (nothing when the mesh does not say: every face smooth).
  int smoothing = -1;
  // Materials as `usemtl` before each run of faces of one material (names: the file's, else
  // "material_N"). A reader numbers them in order of first appearance, so every one is named
  // once first, in index order: the indices read back are these.
  const auto materialName = [&mesh](std::size_t m) {
    const bool named = m < mesh.materialNames.size() && !mesh.materialNames[m].empty();
    return named ? mesh.materialNames[m] : "material_" + std::to_string(m);
  };
  if (!mesh.faceMaterial.empty()) {
    const std::uint32_t highest =
        *std::max_element(mesh.faceMaterial.begin(), mesh.faceMaterial.end());
    for (std::size_t m = 0; m <= highest; ++m) out += "usemtl " + materialName(m) + "\n";
  }
  std::size_t material = static_cast<std::size_t>(-1);
  for (std::size_t f = 0; f < mesh.numFaces(); ++f) {
    if (!mesh.faceMaterial.empty() && material != mesh.material(f)) {
      material = mesh.material(f);
      out += "usemtl " + materialName(material) + "\n";
    }
    if (!mesh.faceFlat.empty() && smoothing != (mesh.isFlat(f) ? 0 : 1)) {
      smoothing = mesh.isFlat(f) ? 0 : 1;
      out += smoothing == 0 ? "s 0\n" : "s 1\n";
    }
    out += 'f';
    for (std::uint32_t c = mesh.faceStart[f]; c < mesh.faceStart[f + 1]; ++c) {
      const std::string vertex = std::to_string(mesh.cornerVertex[c] + 1);
      const std::string corner = std::to_string(c + 1);
      out += ' ';
      out += vertex;
      out += '/';
      if (uvs) out += corner;
      out += '/';
      out += corner;
    }
    out += '\n';
  }
  return out;
}

}  // namespace sgbake
