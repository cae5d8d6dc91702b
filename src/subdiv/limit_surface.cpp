/// @file limit_surface.cpp
/// @brief LimitSurface: Bfr surfaces of a face (positions and every UV set), evaluated in
/// normalized sub-face coordinates, and Newton's method to find where the UVs take a value.
#include "sgbake/subdiv/limit_surface.hpp"

#include <opensubdiv/bfr/surface.h>

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "subdiv/control_mesh.hpp"

namespace sgbake {

using namespace subdiv_detail;

struct LimitSurface::Data {
  ControlMesh control;
};

LimitSurface::LimitSurface(std::unique_ptr<Data> data) : data_(std::move(data)) {}
LimitSurface::LimitSurface(LimitSurface&&) noexcept = default;
LimitSurface& LimitSurface::operator=(LimitSurface&&) noexcept = default;
LimitSurface::~LimitSurface() = default;

Result<LimitSurface> LimitSurface::create(const Mesh& coarse, const SubdivisionOptions& options) {
  Result<ControlMesh> control = buildControlMesh(coarse, options);
  if (!control) return control.error();
  auto data = std::make_unique<Data>();
  data->control = std::move(*control);
  return LimitSurface(std::move(data));
}

std::size_t LimitSurface::numFaces() const { return data_->control.faceSizes.size(); }
int LimitSurface::numUvSets() const {
  return std::min(static_cast<int>(data_->control.channels.size()), LimitPoint::kMaxUvSets);
}

struct LimitSurface::Evaluator::State {
  explicit State(const Data& d)
      : data(&d), factory(*d.control.refiner, surfaceFactoryOptions()) {}
  const Data* data;
  SurfaceFactory factory;
  long face = -1;  ///< the face whose surfaces are set up, or -1
  osd::Bfr::Surface<double> vertex;
  std::vector<double> vertexPatch;
  std::vector<osd::Bfr::Surface<double>> uvs;
  std::vector<std::vector<double>> uvPatches;

  /// Sets up the surfaces of @p f; false when Bfr has none.
  bool setUp(std::uint32_t f) {
    if (face == static_cast<long>(f)) return true;
    face = -1;
    const ControlMesh& control = data->control;
    if (f >= control.faceSizes.size()) return false;
    const int index = static_cast<int>(f);
    if (!factory.InitVertexSurface(index, &vertex)) return false;
    const osd::Bfr::Surface<double>::PointDescriptor xyz(3), st(2);
    vertexPatch.resize(static_cast<std::size_t>(vertex.GetNumPatchPoints()) * 3);
    vertex.PreparePatchPoints(control.points.data(), xyz, vertexPatch.data(), xyz);
    const std::size_t sets = static_cast<std::size_t>(
        std::min(static_cast<int>(control.channels.size()), LimitPoint::kMaxUvSets));
    uvs.resize(sets);
    uvPatches.resize(sets);
    for (std::size_t s = 0; s < sets; ++s) {
      if (!factory.InitFaceVaryingSurface(index, &uvs[s], static_cast<int>(s))) return false;
      uvPatches[s].resize(static_cast<std::size_t>(uvs[s].GetNumPatchPoints()) * 2);
      uvs[s].PreparePatchPoints(control.channels[s].values.data(), st, uvPatches[s].data(), st);
    }
    face = index;
    return true;
  }

  /// Bfr's coordinates of normalized (s, t) on sub-face @p subFace, and their derivatives.
  bool coordinates(std::uint32_t subFace, Vec2d st, double uv[2], Vec2d& dds, Vec2d& ddt) const {
    const int corners = data->control.faceSizes[static_cast<std::size_t>(face)];
    if (corners == 4) {
      if (subFace != 0) return false;
      uv[0] = st.x;
      uv[1] = st.y;
      dds = {1, 0};
      ddt = {0, 1};
      return true;
    }
    if (subFace >= static_cast<std::uint32_t>(corners)) return false;
    // The normalized sub-face maps affinely into the face's coordinates.
    const osd::Bfr::Parameterization param = vertex.GetParameterization();
    const int k = static_cast<int>(subFace);
    const double zero[2] = {0, 0}, s1[2] = {1, 0}, t1[2] = {0, 1}, at[2] = {st.x, st.y};
    double o[2], a[2], b[2];
    param.ConvertNormalizedSubFaceToCoord(k, zero, o);
    param.ConvertNormalizedSubFaceToCoord(k, s1, a);
    param.ConvertNormalizedSubFaceToCoord(k, t1, b);
    param.ConvertNormalizedSubFaceToCoord(k, at, uv);
    dds = {a[0] - o[0], a[1] - o[1]};
    ddt = {b[0] - o[0], b[1] - o[1]};
    return true;
  }

  /// UV set @p set alone at (s, t) (what each Newton step of locate needs): the values
  /// evaluate() gives it, bit for bit.
  bool evaluateUv(std::uint32_t f, std::uint32_t subFace, Vec2d st, std::size_t set, Vec2d& uv,
                  Vec2d& dUVds, Vec2d& dUVdt) {
    if (!setUp(f) || set >= uvs.size()) return false;
    double at[2];
    Vec2d dds, ddt;
    if (!coordinates(subFace, st, at, dds, ddt)) return false;
    const osd::Bfr::Surface<double>::PointDescriptor two(2);
    double T[2], Tu[2], Tv[2];
    uvs[set].Evaluate(at, uvPatches[set].data(), two, T, Tu, Tv);
    const Vec2d tu{Tu[0], Tu[1]}, tv{Tv[0], Tv[1]};
    uv = {T[0], T[1]};
    dUVds = dds.x * tu + dds.y * tv;
    dUVdt = ddt.x * tu + ddt.y * tv;
    return true;
  }

  bool evaluate(std::uint32_t f, std::uint32_t subFace, Vec2d st, LimitPoint& out) {
    if (!setUp(f)) return false;
    double uv[2];
    Vec2d dds, ddt;
    if (!coordinates(subFace, st, uv, dds, ddt)) return false;
    const osd::Bfr::Surface<double>::PointDescriptor xyz(3), two(2);
    double P[3], Du[3], Dv[3];
    vertex.Evaluate(uv, vertexPatch.data(), xyz, P, Du, Dv);
    const Vec3d du{Du[0], Du[1], Du[2]}, dv{Dv[0], Dv[1], Dv[2]};
    out.position = {P[0], P[1], P[2]};
    out.dPds = dds.x * du + dds.y * dv;
    out.dPdt = ddt.x * du + ddt.y * dv;
    out.numUvSets = static_cast<int>(uvs.size());
    for (std::size_t s = 0; s < uvs.size(); ++s) {
      double T[2], Tu[2], Tv[2];
      uvs[s].Evaluate(uv, uvPatches[s].data(), two, T, Tu, Tv);
      const Vec2d tu{Tu[0], Tu[1]}, tv{Tv[0], Tv[1]};
      out.uv[s] = {T[0], T[1]};
      out.dUVds[s] = dds.x * tu + dds.y * tv;
      out.dUVdt[s] = ddt.x * tu + ddt.y * tv;
    }
    return true;
  }
};

LimitSurface::Evaluator::Evaluator(const LimitSurface& surface)
    : state_(std::make_unique<State>(*surface.data_)) {}
LimitSurface::Evaluator::Evaluator(Evaluator&&) noexcept = default;
LimitSurface::Evaluator& LimitSurface::Evaluator::operator=(Evaluator&&) noexcept = default;
LimitSurface::Evaluator::~Evaluator() = default;

bool LimitSurface::Evaluator::evaluate(std::uint32_t face, std::uint32_t subFace, Vec2d st,
                                       LimitPoint& out) {
  return state_->evaluate(face, subFace, st, out);
}

bool LimitSurface::Evaluator::locate(std::uint32_t face, std::uint32_t subFace, Vec2d start,
                                     int uvSet, Vec2d target, LimitPoint& out) {
  constexpr int kMaxSteps = 8;
  if (uvSet < 0 || uvSet >= LimitPoint::kMaxUvSets) return false;
  const std::size_t k = static_cast<std::size_t>(uvSet);
  // Newton's steps read UV set k only; the whole point is evaluated once, where they end.
  Vec2d st{std::clamp(start.x, 0.0, 1.0), std::clamp(start.y, 0.0, 1.0)};
  Vec2d uv, a, b;
  if (!state_->evaluateUv(face, subFace, st, k, uv, a, b)) return false;
  const double tolerance = 1e-12 * std::max(1.0, std::max(std::abs(target.x), std::abs(target.y)));
  double previous = 0;  // the residual before the last step (0: no step yet)
  for (int step = 0; step < kMaxSteps; ++step) {
    const Vec2d r = target - uv;
    const double residual = std::max(std::abs(r.x), std::abs(r.y));
    if (residual <= tolerance) break;
    // Solve [dUV/ds dUV/dt] · Δ = r.
    const double det = a.x * b.y - a.y * b.x;
    if (!(std::abs(det) > 0) || !std::isfinite(det)) break;
    const Vec2d delta{(r.x * b.y - r.y * b.x) / det, (a.x * r.y - a.y * r.x) / det};
    const Vec2d free{st.x + delta.x, st.y + delta.y};
    const Vec2d next{std::clamp(free.x, 0.0, 1.0), std::clamp(free.y, 0.0, 1.0)};
    if (next == st) break;  // pinned at the border of the sub-face
    st = next;
    // Newton's method converges quadratically, r' ≈ c·r², with c ≈ r / previous² as measured
    // on the step before. When the residual so predicted after this step is far below the
    // tolerance, the step is not checked: the point is evaluated where it lands (a UV
    // evaluation fewer per sample, a quarter of what locating costs). A step the clamp
    // shortened is checked.
    if (previous > 0 && next == free &&
        residual * residual * residual <= 1e-3 * tolerance * previous * previous) {
      break;
    }
    previous = residual;
    state_->evaluateUv(face, subFace, st, k, uv, a, b);
  }
  return state_->evaluate(face, subFace, st, out);
}

Result<LimitTessellation> tessellateLimitSurface(const Mesh& coarse,
                                                 const SubdivisionOptions& options) {
  SubdivisionOptions tessellation = options;
  tessellation.level = kLimitTessellationLevel;
  Result<LimitSurface> surface = LimitSurface::create(coarse, tessellation);
  if (!surface) return surface.error();
  SurfaceParameters parameters;
  Result<Mesh> mesh = subdivideMesh(coarse, tessellation, &parameters);
  if (!mesh) return mesh.error();
  return LimitTessellation{std::move(*surface), std::move(*mesh), std::move(parameters)};
}

bool isTessellationOf(const Mesh& mesh, const LimitSurface& surface,
                      const SurfaceParameters& parameters) {
  for (std::size_t f = 0; f < mesh.faceStart.size(); ++f) {
    if (mesh.faceStart[f] != 4 * f) return false;
  }
  return parameters.faceOrigin.size() == mesh.numFaces() &&
         parameters.cornerSubFace.size() == mesh.numCorners() &&
         parameters.cornerCoord.size() == mesh.numCorners() &&
         std::none_of(parameters.faceOrigin.begin(), parameters.faceOrigin.end(),
                      [&](std::uint32_t f) { return f >= surface.numFaces(); });
}

}  // namespace sgbake
