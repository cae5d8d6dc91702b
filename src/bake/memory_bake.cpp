/// @file memory_bake.cpp
/// @brief bakeOutputInMemory (planner.hpp): a plan run on a mesh and images held in memory.
#include <string>
#include <utility>
#include <vector>

#include "bake/prepare.hpp"
#include "sgbake/bake/planner.hpp"
#include "sgbake/mesh/normals.hpp"

namespace sgbake {

Result<FloatImage> bakeOutputInMemory(const Plan& plan, std::size_t output,
                                      const MemoryInputs& inputs, int threads,
                                      const BakeProgressCallback& progress) {
  const Scene& s = plan.scene;
  if (!s.inMemory) return Error::internal("bakeOutputInMemory: the scene is not an in-memory one");
  if (output >= plan.outputs.size()) {
    return Error::internal("bakeOutputInMemory: the plan has no output " + std::to_string(output));
  }
  if (inputs.mesh == nullptr || !inputs.image) {
    return Error::internal("bakeOutputInMemory: no mesh or no image source");
  }
  const PlannedOutput& planned = plan.outputs[output];
  const SceneOutput& out = s.outputs[planned.sceneOutput];
  if (out.kind != OutputKind::kMap) {
    return Error::badInput(plan_detail::outputLabel(output) + ": only image maps bake in memory");
  }
  if (Status valid = validate(*inputs.mesh); !valid) return valid.error();

  ExecuteOptions silent;
  plan_detail::ProgressReporter steps(silent, 0);
  ExecuteReport report;
  plan_detail::Loaded loaded;
  if (Status ok = plan_detail::setSurface(s, *inputs.mesh, loaded); !ok) {
    return Error{ok.error().code, s.mesh.string() + ": " + ok.error().message};
  }
  if (Status ok = plan_detail::loadTextures(plan, inputs.image, loaded, steps, report); !ok) {
    return ok.error();
  }
  if (Status ok = plan_detail::prepareLayers(plan, threads, loaded, steps, report); !ok) {
    return ok.error();
  }

  const std::vector<Layer> layers = plan_detail::outputLayers(planned, loaded);
  const BakeInput input = plan_detail::bakeInputFor(loaded, layers);
  const BakeSettings settings = plan_detail::bakeSettingsFor(out, out.tile, threads);
  Result<FloatImage> image = bakeMap(input, settings, progress);
  if (!image) return image.error();
  plan_detail::padImage(*image, plan_detail::outputPadding(out), input, settings);
  return image;
}

}  // namespace sgbake
