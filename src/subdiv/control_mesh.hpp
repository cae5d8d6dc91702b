/// @file control_mesh.hpp
/// @brief Private to src/subdiv: a sgbake Mesh as OpenSubdiv's control mesh (Far topology with
/// Blender's options, one face-varying channel per UV set), shared by subdivideMesh and
/// LimitSurface.
#pragma once

#include <opensubdiv/bfr/refinerSurfaceFactory.h>
#include <opensubdiv/far/topologyRefiner.h>

#include <memory>
#include <string>
#include <vector>

#include "sgbake/core/result.hpp"
#include "sgbake/mesh/mesh.hpp"
#include "sgbake/subdiv/subdivide.hpp"

namespace sgbake::subdiv_detail {

namespace osd = OpenSubdiv;
using Refiner = osd::Far::TopologyRefiner;
using SurfaceFactory = osd::Bfr::RefinerSurfaceFactory<>;

/// One UV set as an OpenSubdiv face-varying channel: an index per corner into distinct values.
struct FVarChannel {
  std::vector<int> cornerValue;  ///< #C
  std::vector<double> values;    ///< 2 per value
};

/// The coarse mesh as OpenSubdiv sees it.
struct ControlMesh {
  std::unique_ptr<Refiner> refiner;  ///< base level only (Bfr needs no refinement)
  std::vector<FVarChannel> channels;  ///< one per UV set, in order
  std::vector<int> faceSizes;         ///< #F
  std::vector<double> points;         ///< 3 per vertex, the positions in double
};

/// kBadInput naming coarse.source and the entry for the first crease or sharp edge of
/// @p options that does not fit @p coarse (findCreaseIssue).
Status checkCreases(const Mesh& coarse, const SubdivisionOptions& options);

/// The Far topology of @p coarse with Blender's options (see shared/CONVENTIONS.md).
/// @return kBadInput naming coarse.source for a face that uses a vertex twice or a topology
///         OpenSubdiv rejects
Result<ControlMesh> buildControlMesh(const Mesh& coarse, const SubdivisionOptions& options);

/// The options of every Bfr factory: irregular regions approximated to Blender's Quality.
SurfaceFactory::Options surfaceFactoryOptions();

}  // namespace sgbake::subdiv_detail
