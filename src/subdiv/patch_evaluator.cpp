/// @file patch_evaluator.cpp
/// @brief PatchEvaluator: Far adaptive refinement, stencils and patch tables, and Osd's CPU
/// patch evaluation, with the options Blender 3.4's modifier uses (see patch_evaluator.hpp).
#include "subdiv/patch_evaluator.hpp"

#include <opensubdiv/far/patchTableFactory.h>
#include <opensubdiv/far/stencilTable.h>
#include <opensubdiv/far/stencilTableFactory.h>
#include <opensubdiv/osd/bufferDescriptor.h>
#include <opensubdiv/osd/cpuEvaluator.h>

#include <cstddef>

namespace sgbake::subdiv_detail {
namespace {

// The float tables themselves (StencilTableReal<float>): Far's StencilTable and
// StencilTableFactory are wrappers that downcast every table they hand out to a type it is not.
using StencilTable = osd::Far::StencilTableReal<float>;
using StencilTableFactory = osd::Far::StencilTableFactoryReal<float>;

/// Owns a stencil table Far hands out by pointer.
using StencilPtr = std::unique_ptr<const StencilTable>;

/// The stencils of every refined vertex (or face-varying value of @p channel, when not -1),
/// each relative to the control mesh, as Blender builds them.
StencilPtr refinedStencils(const Refiner& refiner, bool adaptive, int channel) {
  StencilTableFactory::Options options;
  options.generateOffsets = true;
  // Uniform patches index the control points and the last level only.
  options.generateIntermediateLevels = adaptive;
  if (channel >= 0) {
    options.interpolationMode = StencilTableFactory::INTERPOLATE_FACE_VARYING;
    options.fvarChannel = static_cast<unsigned>(channel);
  }
  return StencilPtr(StencilTableFactory::Create(refiner, options));
}

/// Applies @p stencils to the first @p coarse elements of @p data (each @p width floats) and
/// appends their results: Osd's CPU kernel, on one buffer, as Blender's evaluator refines.
void applyStencils(const StencilTable* stencils, int coarse, int width, std::vector<float>& data) {
  const int count = stencils == nullptr ? 0 : stencils->GetNumStencils();
  data.resize(static_cast<std::size_t>(coarse + count) * static_cast<std::size_t>(width));
  if (count == 0) return;
  const osd::Osd::BufferDescriptor source(0, width, width);
  const osd::Osd::BufferDescriptor target(coarse * width, width, width);
  osd::Osd::CpuEvaluator::EvalStencils(data.data(), source, data.data(), target,
                                       &stencils->GetSizes()[0], &stencils->GetOffsets()[0],
                                       &stencils->GetControlIndices()[0],
                                       &stencils->GetWeights()[0], 0, count);
}

}  // namespace

PatchEvaluator::PatchEvaluator(ControlMesh& control, Refinement refinement)
    : ptex_(*control.refiner) {
  Refiner& refiner = *control.refiner;
  const int numChannels = refiner.GetNumFVarChannels();
  const int level = refinement.level;
  if (refinement.adaptive) {
    Refiner::AdaptiveOptions adaptive(level);
    adaptive.considerFVarChannels = numChannels > 0;
    adaptive.useInfSharpPatch = true;
    refiner.RefineAdaptive(adaptive);
  } else {
    refiner.RefineUniform(Refiner::UniformOptions(level));
  }

  StencilPtr vertexStencils = refinedStencils(refiner, refinement.adaptive, -1);
  std::vector<StencilPtr> channelStencils;
  for (int c = 0; c < numChannels; ++c) {
    channelStencils.push_back(refinedStencils(refiner, refinement.adaptive, c));
  }

  osd::Far::PatchTableFactory::Options options(level);
  options.SetEndCapType(osd::Far::PatchTableFactory::Options::ENDCAP_GREGORY_BASIS);
  options.useInfSharpPatch = true;
  options.generateFVarTables = numChannels > 0;
  options.generateFVarLegacyLinearPatches = false;
  // Uniform patches: face-varying indices count the control values too, as vertex ones do
  // (the values are stored control first, then the last level's).
  options.includeFVarBaseLevelIndices = !refinement.adaptive;
  patches_.reset(osd::Far::PatchTableFactory::Create(refiner, options));

  // Local points (the end caps' control points) after the refined ones.
  if (const StencilTable* local = patches_->GetLocalPointStencilTable<float>(); local != nullptr) {
    vertexStencils.reset(
        StencilTableFactory::AppendLocalPointStencilTable(refiner, vertexStencils.get(), local));
  }
  for (int c = 0; c < numChannels; ++c) {
    const StencilTable* local = patches_->GetLocalPointFaceVaryingStencilTable<float>(c);
    if (const StencilTable* all = StencilTableFactory::AppendLocalPointStencilTableFaceVarying(
            refiner, channelStencils[static_cast<std::size_t>(c)].get(), local, c);
        all != nullptr) {
      channelStencils[static_cast<std::size_t>(c)].reset(all);
    }
  }

  // Control points in float (the mesh's floats: control.points holds them exactly), then
  // every refined and local point.
  const int numVertices = refiner.GetLevel(0).GetNumVertices();
  points_.assign(control.points.begin(), control.points.end());
  applyStencils(vertexStencils.get(), numVertices, 3, points_);
  channels_.resize(static_cast<std::size_t>(numChannels));
  for (int c = 0; c < numChannels; ++c) {
    const std::vector<double>& values = control.channels[static_cast<std::size_t>(c)].values;
    std::vector<float>& data = channels_[static_cast<std::size_t>(c)];
    data.assign(values.begin(), values.end());
    applyStencils(channelStencils[static_cast<std::size_t>(c)].get(),
                  static_cast<int>(values.size() / 2), 2, data);
  }
  cpuPatches_.reset(osd::Osd::CpuPatchTable::Create(patches_.get()));
  map_ = std::make_unique<osd::Far::PatchMap>(*patches_);
}

PatchEvaluator::~PatchEvaluator() = default;

bool PatchEvaluator::locate(int ptexFace, float u, float v, osd::Osd::PatchCoord& at) const {
  const osd::Far::PatchTable::PatchHandle* handle = map_->FindPatch(ptexFace, u, v);
  if (handle == nullptr) return false;
  at = osd::Osd::PatchCoord(*handle, u, v);
  return true;
}

bool PatchEvaluator::position(int ptexFace, float u, float v, float out[3]) const {
  osd::Osd::PatchCoord at;
  if (!locate(ptexFace, u, v, at)) return false;
  const osd::Osd::BufferDescriptor source(0, 3, 3), target(0, 3, 3);
  osd::Osd::CpuEvaluator::EvalPatches(points_.data(), source, out, target, 1, &at,
                                      cpuPatches_->GetPatchArrayBuffer(),
                                      cpuPatches_->GetPatchIndexBuffer(),
                                      cpuPatches_->GetPatchParamBuffer());
  return true;
}

bool PatchEvaluator::faceVarying(int channel, int ptexFace, float u, float v,
                                 float out[2]) const {
  osd::Osd::PatchCoord at;
  if (!locate(ptexFace, u, v, at)) return false;
  const osd::Osd::BufferDescriptor source(0, 2, 2), target(0, 2, 2);
  osd::Osd::CpuEvaluator::EvalPatches(channels_[static_cast<std::size_t>(channel)].data(), source,
                                      out, target, 1, &at,
                                      cpuPatches_->GetFVarPatchArrayBuffer(channel),
                                      cpuPatches_->GetFVarPatchIndexBuffer(channel),
                                      cpuPatches_->GetFVarPatchParamBuffer(channel));
  return true;
}

}  // namespace sgbake::subdiv_detail
