// convertNormalMap: object ↔ tangent space per texel, with the same raster and per-texel frame
// as bakeMap (raster.hpp, texel_frame.hpp).
#include "sgbake/bake/convert.hpp"

#include <new>
#include <optional>
#include <string>

#include "bake/limit_shader.hpp"
#include "bake/raster.hpp"
#include "bake/texel_frame.hpp"

namespace sgbake {

Result<NormalSpace> parseNormalSpace(std::string_view name) {
  if (name == "object") return NormalSpace::kObject;
  if (name == "tangent") return NormalSpace::kTangent;
  return Error::badInput("unknown normal space '" + std::string(name) +
                         "' (expected object or tangent)");
}

std::string_view normalSpaceName(NormalSpace space) {
  return space == NormalSpace::kObject ? "object" : "tangent";
}

namespace bake_detail {
namespace {

/// Converts the input texel under each covered sample (see convertNormalMap).
struct ConvertShader {
  static constexpr int kChannels = 3;
  const Mesh* mesh = nullptr;
  const CornerTangents* tangents = nullptr;
  const FloatImage* input = nullptr;
  NormalSpace from = NormalSpace::kObject, to = NormalSpace::kTangent;
  /// How the input and the output store a normal: the swizzles, G negated on the tangent side
  /// for a DirectX green (convertShader).
  NormalSwizzle inputChannels = kIdentitySwizzle, outputChannels = kIdentitySwizzle;
  int uvSet = 0;
  ShadingTriangle tri;
  /// With a transform (ConvertSettings::transform): the object-space side's texels to object
  /// normals, M^T M, and back, M^{-1} M^{-T}.
  std::optional<Mat3> objectMapToNormal, normalToObjectMap;

  void beginTriangle(std::uint32_t, const std::array<std::uint32_t, 3>& corners) {
    loadShadingTriangle(*mesh, tangents, corners, uvSet, tri);
  }
  /// Nothing is derived from `tri` (LimitShader calls this after rewriting it).
  void triangleChanged() {}

  void shade(const Vec3d& b, int x, int y, double* out) const {
    const int row = input->height - 1 - y;
    // Channel k holds ±n[axis]/2 + 0.5: back to n/2 + 0.5 first.
    Vec3d c;
    for (std::size_t k = 0; k < 3; ++k) {
      const double v = input->at(x, row, static_cast<int>(k));
      const SwizzleAxis& s = inputChannels[k];
      c[static_cast<std::size_t>(s.axis)] = s.negate ? 1.0 - v : v;
    }
    const Vec3d n = decodeNormalTexel(c);
    const TexelFrame f = texelFrame(tri, b);
    Vec3d result;
    if (from == to) {
      result = normalizeOr(n, to == NormalSpace::kTangent ? Vec3d{0, 0, 1} : unitNormal(tri, f));
    } else if (to == NormalSpace::kTangent) {
      result = objectToTangent(f, objectMapToNormal ? *objectMapToNormal * n : n);
    } else {
      result = tangentToObject(tri, f, n);
      if (normalToObjectMap) {
        result = normalizeOr(*normalToObjectMap * result, unitNormal(tri, f));
      }
    }
    for (std::size_t k = 0; k < 3; ++k) {
      const SwizzleAxis& s = outputChannels[k];
      out[k] = 0.5 * ((s.negate ? -1.0 : 1.0) * result[static_cast<std::size_t>(s.axis)]) + 0.5;
    }
  }
};

}  // namespace
}  // namespace bake_detail

namespace {

/// How messages name a conversion: the mesh's file, or "convert".
std::string convertWhere(const Mesh& mesh) {
  return mesh.source.empty() ? std::string("convert") : mesh.source;
}

/// The checks convertNormalMap and convertNormalMapRows share (see convertNormalMap).
Status validateConvert(const Mesh& mesh, const CornerTangents& tangents, const FloatImage& input,
                       const ConvertSettings& settings) {
  const std::string where = convertWhere(mesh);
  if (input.width < 1 || input.height < 1 || input.width > kMaxBakeSide ||
      input.height > kMaxBakeSide) {
    return Error::badInput(where + ": the normal map is empty or too large (" +
                           std::to_string(input.width) + "x" + std::to_string(input.height) + ")");
  }
  if (input.channels < 3) {
    return Error::badInput(where + ": the normal map has " + std::to_string(input.channels) +
                           " channels but 3 are needed (RGB)");
  }
  const std::size_t texels = static_cast<std::size_t>(input.width) * input.height;
  if (input.pixels.size() != texels * static_cast<std::size_t>(input.channels)) {
    return Error::badInput(where + ": the normal map's pixels do not match its size");
  }
  if (settings.uvSet < 0 || !mesh.hasUvSet(static_cast<std::size_t>(settings.uvSet))) {
    return Error::badInput(where + ": the mesh has no UV set " + std::to_string(settings.uvSet) +
                           " (it has " + std::to_string(mesh.uvSets.size()) + ")");
  }
  // On a limit surface no frames may be given: every sample has the surface's own (LimitShader).
  const bool none = tangents.tangent.empty() && tangents.sign.empty() && settings.limit != nullptr;
  if (!none &&
      (tangents.tangent.size() != mesh.numCorners() || tangents.sign.size() != mesh.numCorners())) {
    return Error::badInput(where + ": tangent frames do not match the mesh (" +
                           std::to_string(tangents.tangent.size()) + " for " +
                           std::to_string(mesh.numCorners()) + " corners)");
  }
  if (settings.udimTile < kFirstUdimTile || settings.udimTile > kLastUdimTile) {
    return Error::badInput(where + ": UDIM tile " + std::to_string(settings.udimTile) +
                           " is out of range (1001 to 2000)");
  }
  if (settings.samples < 1 || settings.samples > kMaxBakeSamples) {
    return Error::badInput(where + ": samples " + std::to_string(settings.samples) +
                           " is out of range (1 to " + std::to_string(kMaxBakeSamples) + ")");
  }
  if (settings.threads < 0) return Error::badInput(where + ": threads must be 0 (all cores) or more");
  const auto axis = [](const SwizzleAxis& s) { return s.axis; };
  for (const NormalSwizzle& channels : {settings.inputSwizzle, settings.outputSwizzle}) {
    if (!std::ranges::all_of(channels,
                             [&](const SwizzleAxis& s) { return axis(s) >= 0 && axis(s) <= 2; })) {
      return Error::badInput(where + ": a swizzle axis must be 0 (x), 1 (y) or 2 (z)");
    }
  }
  const NormalSwizzle& in = settings.inputSwizzle;
  if (in[0].axis == in[1].axis || in[0].axis == in[2].axis || in[1].axis == in[2].axis) {
    return Error::badInput(where + ": the input's swizzle " + normalSwizzleName(in) +
                           " names an axis twice: its channels cannot be read back");
  }
  if (settings.limit != nullptr &&
      (settings.limitParameters == nullptr ||
       !isTessellationOf(mesh, *settings.limit, *settings.limitParameters))) {
    return Error::badInput(where + ": the mesh is not a tessellation of the limit surface "
                                   "(tessellateLimitSurface)");
  }
  if (settings.transform != nullptr) {
    if (Result<WorldSpace> space = WorldSpace::of(*settings.transform); !space) {
      return Error::badInput(where + ": " + space.error().message);
    }
  }
  return Ok{};
}

/// The shader of a conversion from @p from to @p to.
bake_detail::ConvertShader convertShader(const Mesh& mesh, const CornerTangents& tangents,
                                         const FloatImage& input, NormalSpace from, NormalSpace to,
                                         const ConvertSettings& settings) {
  bake_detail::ConvertShader shader;
  shader.mesh = &mesh;
  shader.tangents = tangents.tangent.empty() ? nullptr : &tangents;  // none: the limit's frames
  shader.input = &input;
  shader.from = from;
  shader.to = to;
  // The swizzles, G negated on the tangent-space side for a DirectX green.
  const auto green = [&](NormalSpace space) {
    return space == NormalSpace::kTangent ? settings.green : NormalMapGreen::kOpenGL;
  };
  shader.inputChannels = storedChannels(settings.inputSwizzle, green(from));
  shader.outputChannels = storedChannels(settings.outputSwizzle, green(to));
  shader.uvSet = settings.uvSet;
  if (settings.transform != nullptr && !settings.transform->shadesAsObjectSpace()) {
    const WorldSpace space = WorldSpace::of(*settings.transform).value();  // validateConvert
    shader.objectMapToNormal = space.normalToObject * space.toWorld;
    shader.normalToObjectMap = space.directionToObject * space.normalToWorld;
  }
  return shader;
}

/// Rasterizes a conversion: on the mesh, or on the limit surface it tessellates (LimitShader).
void rasterizeConversion(const bake_detail::RasterJob& job, const bake_detail::ConvertShader& shader,
                         const ConvertSettings& settings, const bake_detail::RasterOutput& output,
                         const bake_detail::RasterTarget& target) {
  if (settings.limit != nullptr) {
    bake_detail::rasterize(
        job, bake_detail::LimitShader(shader, settings.limit, settings.limitParameters), output,
        target);
  } else {
    bake_detail::rasterize(job, shader, output, target);
  }
}

Error convertOutOfMemory(const Mesh& mesh, const FloatImage& input) {
  return Error::internal(convertWhere(mesh) + ": out of memory converting a " +
                         std::to_string(input.width) + "x" + std::to_string(input.height) +
                         " normal map");
}

}  // namespace

Result<FloatImage> convertNormalMap(const Mesh& mesh, const CornerTangents& tangents,
                                    const FloatImage& input, NormalSpace from, NormalSpace to,
                                    const ConvertSettings& settings) {
  if (Status valid = validateConvert(mesh, tangents, input, settings); !valid) return valid.error();
  const std::size_t texels = static_cast<std::size_t>(input.width) * input.height;
  try {
    const std::vector<std::array<std::uint32_t, 3>> triangles = loopTriangles(mesh);
    FloatImage output;
    output.width = input.width;
    output.height = input.height;
    output.channels = input.channels;
    bake_detail::runWithThreads(settings.threads, [&] {
      tbb::parallel_invoke(
          [&] { output.pixels = input.pixels; },  // uncovered texels and extra channels keep the input
          [&] { output.coverage.resize(texels); });
    });

    const bake_detail::RasterJob job =
        bake_detail::rasterJobFor(mesh, triangles, settings, input.width, input.height);

    bake_detail::RasterOutput rasterOutput;
    rasterOutput.keepUncovered = true;
    rasterOutput.blank = true;  // the coverage was just zero-filled
    rasterizeConversion(job, convertShader(mesh, tangents, input, from, to, settings), settings,
                        rasterOutput, bake_detail::RasterTarget::of(output));
    return output;
  } catch (const std::bad_alloc&) {
    return convertOutOfMemory(mesh, input);
  }
}

Status convertNormalMapRows(const Mesh& mesh, const CornerTangents& tangents,
                            const FloatImage& input, NormalSpace from, NormalSpace to,
                            const ConvertSettings& settings, const BakedRowsSink& sink) {
  if (Status valid = validateConvert(mesh, tangents, input, settings); !valid) return valid;
  if (!sink) return Error::badInput(convertWhere(mesh) + ": no sink for the converted rows");
  Status result = Ok{};
  try {
    const std::vector<std::array<std::uint32_t, 3>> triangles = loopTriangles(mesh);
    const int W = input.width, H = input.height, C = input.channels;
    const int ringRows = bakeRingRows(H, 0);
    const std::size_t ringTexels = static_cast<std::size_t>(ringRows) * static_cast<std::size_t>(W);
    std::vector<float> pixels(ringTexels * static_cast<std::size_t>(C));
    std::vector<float> coverage(ringTexels);
    const bake_detail::RasterTarget target{pixels.data(), coverage.data(), C, ringRows};

    bake_detail::RasterJob job = bake_detail::rasterJobFor(mesh, triangles, settings, W, H);
    int previousEnd = 0;
    job.onRowsFinal = [&](int rowsFinal) {
      const MutableImageRows rows{W, H, C, previousEnd, rowsFinal, ringRows,
                                  pixels.data(), coverage.data()};
      previousEnd = rowsFinal;
      result = sink(rows);
      return result.ok();
    };
    bake_detail::RasterOutput rasterOutput;
    rasterOutput.keepUncovered = true;
    rasterOutput.initialPixels = input.pixels.data();  // each band's rows start from the input
    rasterizeConversion(job, convertShader(mesh, tangents, input, from, to, settings), settings,
                        rasterOutput, target);
  } catch (const std::bad_alloc&) {
    return convertOutOfMemory(mesh, input);
  }
  return result;
}

}  // namespace sgbake
