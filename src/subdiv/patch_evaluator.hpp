/// @file patch_evaluator.hpp
/// @brief Private to src/subdiv: the limit surface evaluated the way Blender's Subdivision Surface
/// modifier evaluates it, so that subdivideMesh's floats are Blender's, bit for bit.
///
/// Blender does not use Bfr: it refines the control mesh adaptively to its "Quality" (3 unless set;
/// uniformly to the modifier's level when "Use Limit Surface" is off, then the patches are
/// bilinear quads through the refined points),
/// builds a Far patch table (Gregory-basis end caps, infinitely sharp patches, face-varying
/// patches for the UVs), computes every patch point with Far stencil tables in float, and
/// evaluates one point at a time with Osd's CPU evaluator at a Ptex face's (u, v). The patches
/// only approximate the limit where a face is irregular (at 2^-3 of a face, as Bfr with the same
/// quality does), and they round in float differently from a double evaluation: both matter,
/// because MikkTSpace shares a tangent only between corners whose UVs are identical. This class
/// repeats those steps with the same OpenSubdiv library and options.
#pragma once

#include <opensubdiv/far/patchMap.h>
#include <opensubdiv/far/patchTable.h>
#include <opensubdiv/far/ptexIndices.h>
#include <opensubdiv/osd/cpuPatchTable.h>

#include <memory>
#include <vector>

#include "subdiv/control_mesh.hpp"

namespace sgbake::subdiv_detail {

class PatchEvaluator {
 public:
  /// How the control mesh is refined before its patches are built: Blender's
  /// `SubdivSettings::is_adaptive` and `level`.
  struct Refinement {
    /// true: "Use Limit Surface" (refined adaptively: bicubic patches of the limit surface);
    /// false: refined uniformly, the patches are the bilinear quads of the last level
    bool adaptive = true;
    int level = 3;  ///< adaptive: the "Quality"; uniform: the modifier's "Levels"
  };

  /// The patches of @p control's topology refined as @p refinement says (its refiner is refined
  /// here: Bfr cannot use it afterwards), with the control points and face-varying values of
  /// @p control in float. Throws std::bad_alloc.
  PatchEvaluator(ControlMesh& control, Refinement refinement);
  ~PatchEvaluator();
  PatchEvaluator(const PatchEvaluator&) = delete;
  PatchEvaluator& operator=(const PatchEvaluator&) = delete;

  /// The first Ptex face of coarse face @p face (quads have one, other faces one per corner,
  /// in corner order).
  int ptexFace(int face) const { return ptex_.GetFaceId(face); }

  /// The position at (u, v) ∈ [0,1]² of Ptex face @p ptexFace. Thread-safe.
  /// @return false when no patch covers the point (out is then unchanged)
  bool position(int ptexFace, float u, float v, float out[3]) const;
  /// Face-varying channel @p channel (a UV set) at (u, v) of Ptex face @p ptexFace. Thread-safe.
  /// @return false when no patch covers the point (out is then unchanged)
  bool faceVarying(int channel, int ptexFace, float u, float v, float out[2]) const;

 private:
  bool locate(int ptexFace, float u, float v, osd::Osd::PatchCoord& at) const;

  osd::Far::PtexIndices ptex_;
  std::unique_ptr<const osd::Far::PatchTable> patches_;
  std::unique_ptr<osd::Osd::CpuPatchTable> cpuPatches_;
  std::unique_ptr<osd::Far::PatchMap> map_;
  std::vector<float> points_;                 ///< 3 per control, refined and local point
  std::vector<std::vector<float>> channels_;  ///< per channel: 2 per value, refined and local
};

}  // namespace sgbake::subdiv_detail
