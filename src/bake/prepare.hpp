/// @file prepare.hpp
/// @brief Private: the steps of running a plan that do not depend on where its inputs come from
/// (files for executePlan, arrays for bakeOutputInMemory): the surface to bake on, textures,
/// layers, tangent frames, and the BakeInput / BakeSettings of an output.
#pragma once

#include <chrono>
#include <cstddef>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "sgbake/bake/bake.hpp"
#include "sgbake/bake/planner.hpp"
#include "sgbake/bake/scene.hpp"
#include "sgbake/frames/tangents.hpp"
#include "sgbake/gradient/image.hpp"
#include "sgbake/gradient/layers.hpp"
#include "sgbake/gradient/texture.hpp"
#include "sgbake/gradient/volume.hpp"
#include "sgbake/mesh/mesh.hpp"
#include "sgbake/subdiv/limit_surface.hpp"
#include "sgbake/subdiv/subdivide.hpp"

namespace sgbake::plan_detail {

/// Seconds since @p start.
inline double secondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

/// "scene.json: " for scenes read from a file, "" for scenes built in code.
inline std::string scenePrefix(const Scene& scene) {
  return scene.source.empty() ? std::string() : scene.source.string() + ": ";
}

inline std::string layerLabel(std::size_t i) { return "layers[" + std::to_string(i) + "]"; }
inline std::string outputLabel(std::size_t i) { return "outputs[" + std::to_string(i) + "]"; }

/// How an image output is padded: masks not at all (padding would overwrite the coverage they
/// show), else push-pull, or Extend or Adjacent Faces by `margin` texels.
struct OutputPadding {
  PaddingMode mode = PaddingMode::kExtend;
  int margin = 0;  ///< texels of Extend or Adjacent Faces; 0 for push-pull and masks
  /// Whether the padding needs the whole baked image (push-pull, and Adjacent Faces, which
  /// reads across seams anywhere in it); Extend pads band by band.
  bool wholeImage() const {
    return mode == PaddingMode::kPushPull || (mode == PaddingMode::kAdjacentFaces && margin > 0);
  }
  /// Rows the banded (Extend) padding keeps above a band: 2·margin.
  int bandHalo() const { return mode == PaddingMode::kExtend ? 2 * margin : 0; }
};
OutputPadding outputPadding(const SceneOutput& output);
/// Pads @p image, bakeMap's whole image of @p input and @p settings, as @p padding says.
void padImage(FloatImage& image, const OutputPadding& padding, const BakeInput& input,
              const BakeSettings& settings);

/// Everything loaded for a run; layers point into the textures and volumes held here.
struct Loaded {
  Mesh mesh;  ///< as read, subdivided, or the tessellation of the limit surface
  std::optional<LimitSurface> limit;  ///< "level": "limit": the surface the samples are shaded on
  SurfaceParameters limitParameters;  ///< where mesh's corners lie on it
  /// Per plan texture (or null: the other kind, or a UDIM tile's, owned by its UDIM texture)
  std::vector<std::unique_ptr<ScalarTexture>> scalar;
  std::vector<std::unique_ptr<VectorTexture>> vector;  ///< per plan texture, as scalar
  std::vector<std::unique_ptr<HeightVolume>> volumes;  ///< remapped ones after what they read
  /// A layer's view of its texture or volume as the texture it reads (RemappedScalarTexture,
  /// VolumeOnUvTexture), per such layer
  std::vector<std::unique_ptr<ScalarTexture>> textureViews;
  std::vector<Layer> layers;  ///< per plan layer
  std::optional<CornerTangents> tangents;
  /// computeLoopTriangleTangents per UV set a tangent-space layer decodes on (MikkTSpace frame)
  std::array<std::optional<CornerTangents>, kMaxUvSets> triangleTangents;
  /// The scene's "transform" when it shades in world space (not the identity), and its matrices.
  std::optional<ObjectTransform> transform;
  std::optional<WorldSpace> world;
  std::vector<std::string> warnings;  ///< about the inputs, for ExecuteReport::warnings
};

/// Calls the progress callback, if any.
class ProgressReporter {
 public:
  ProgressReporter(const ExecuteOptions& options, std::size_t total)
      : callback_(options.progress), total_(total) {}
  void start(std::string_view what) {
    if (callback_) callback_({done_, total_, what});
  }
  void finishOne() { ++done_; }
  void addWork(std::size_t units) { total_ += units; }
  void finishAll() {
    if (callback_) callback_({total_, total_, "done"});
  }

 private:
  const std::function<void(const BakeProgress&)>& callback_;
  std::size_t total_;
  std::size_t done_ = 0;
};

/// @brief Sets loaded.mesh (and the limit surface) from the mesh as read, @p coarse: subdivided
/// as the scene asks, or, for "level": "limit", the limit surface and its level-3 tessellation.
/// A crease that does not fit the mesh is kBadInput naming the scene and its key.
Status setSurface(const Scene& scene, Mesh coarse, Loaded& loaded);

/// Where the images of a plan come from: the image of a PlannedImage, with its channels.
using ImageSource = std::function<Result<Image>(const PlannedImage&)>;

/// The UDIM tiles UV set `uvSet` of a mesh touches (udimTiles), ascending.
using TouchedTiles = std::function<const std::vector<int>&(int uvSet)>;

/// @brief The UDIM tiles any layer or mask of a bake of @p mesh can sample, on any UV set: those
/// a triangle overlaps (@p touched), and with @p cornerTable (a corners output is baked) those
/// a corner lies in. One flag per tile number, 0 … kLastUdimTile.
std::vector<bool> reachedUdimTiles(const Mesh& mesh, const TouchedTiles& touched, bool cornerTable);

/// @brief Which images of the plan a bake reads: all but the UDIM tiles not in @p reached
/// (reachedUdimTiles) that no layer reads directly.
std::vector<bool> imagesToLoad(const Plan& plan, const std::vector<bool>& reached);

/// @brief Gets the images of the plan from @p source (those @p load marks; all when it is
/// empty) and makes the plan's textures of them; a UDIM texture gets the tiles loaded.
Status loadTextures(const Plan& plan, const ImageSource& source, Loaded& loaded,
                    ProgressReporter& progress, ExecuteReport& report,
                    const std::vector<bool>& load = {});

/// @brief With the surface and textures loaded: checks the UV sets the outputs and layers use,
/// makes the layers (and their volumes) and, if the plan needs them, the tangent frames.
Status prepareLayers(const Plan& plan, int threads, Loaded& loaded, ProgressReporter& progress,
                     ExecuteReport& report);

/// The library Layers an output reads (PlannedOutput::layers), in scene order.
std::vector<Layer> outputLayers(const PlannedOutput& planned, const Loaded& loaded);

/// @brief What bakeMap reads for an output of layers @p layers (which must outlive it).
BakeInput bakeInputFor(const Loaded& loaded, std::span<const Layer> layers);

/// @brief The BakeSettings of an image output's UDIM tile @p tile.
BakeSettings bakeSettingsFor(const SceneOutput& output, int tile, int threads);

}  // namespace sgbake::plan_detail
