/// @file remap.hpp
/// @brief A piecewise-linear remap of a height's value, and textures and volumes read through it.
///
/// A height is often reshaped before it bumps: levels and clamps (Blender's Math node with Clamp,
/// Map Range with Clamp, the Clamp node), or a Color Ramp. Each is a piecewise-linear function G
/// of the value; the remapped height is G(h) and its slopes, by the chain rule, G′(h) ∇h. The
/// Bump node's differences read G at each of their heights, so wrapping the texture (or volume)
/// serves every way a layer takes its slopes.
///
/// Cycles tabulates a Color Ramp at 256 evenly spaced values, ramp(i / 255), and reads the table
/// with the value clamped to [0, 1]: linearly between entries, or the entry at or below it when
/// the ramp's interpolation is Constant. Both are HeightRemap points: (i / 255, table[i]), and
/// for Constant a step at every entry.
///
/// MappedHeightVolume is the same kind of view of a volume's position: a Mapping node (or another
/// affine map of the coordinates) between Texture Coordinate Object and a procedural texture.
/// VolumeOnUvTexture reads a volume on a UV map's coordinates (u, v, 0) instead.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "sgbake/core/result.hpp"
#include "sgbake/core/vec.hpp"
#include "sgbake/gradient/projection.hpp"
#include "sgbake/gradient/texture.hpp"
#include "sgbake/gradient/volume.hpp"

namespace sgbake {

/// Most points a HeightRemap takes (a Color Ramp table with a step at each entry has 512).
inline constexpr std::size_t kMaxRemapPoints = 65536;

/// @brief G: a piecewise-linear function through points (x, y) in order of x, constant beyond the
/// first and the last point. Two points of one x make a step, G taking the second's y there
/// (continuous from the right).
class HeightRemap {
 public:
  /// @return kBadInput for fewer than two points or more than kMaxRemapPoints, a non-finite
  /// coordinate, an x smaller than the one before, or three points of one x.
  static Result<HeightRemap> create(std::vector<Vec2d> points);

  /// G(x). A NaN x gives NaN.
  double value(double x) const;
  /// G′(x): the slope of the segment x lies on (of the one to its right at a point); 0 beyond the
  /// ends and on a step.
  double slope(double x) const;
  /// G(x) and G′(x) together.
  void evaluate(double x, double& value, double& slope) const {
    if (std::isnan(x)) {
      value = slope = std::numeric_limits<double>::quiet_NaN();
      return;
    }
    if (x < points_.front().x || x >= points_.back().x) {
      value = x < points_.front().x ? points_.front().y : points_.back().y;
      slope = 0;
      return;
    }
    const std::size_t left = segmentOf(x);
    slope = slopes_[left];
    value = points_[left].y + (x - points_[left].x) * slope;
  }

  std::span<const Vec2d> points() const { return points_; }

 private:
  explicit HeightRemap(std::vector<Vec2d> points);
  /// The last point at or left of @p x, for points.front().x <= x < points.back().x: x lies on
  /// the segment that starts there. Its cell gives a point at or left of x; a few steps find it
  /// (none for evenly spaced points), bisection where the cell is crowded.
  std::size_t segmentOf(double x) const {
    if (cells_.empty()) return searchLeft(x);
    const auto cell = static_cast<std::int64_t>((x - points_.front().x) * cellsPerUnit_);
    std::size_t left = cells_[std::min(static_cast<std::size_t>(cell), cells_.size() - 1)];
    while (left > 0 && points_[left].x > x) --left;  // rounding in the cell's start
    for (int step = 0; step < 4; ++step, ++left) {   // x < the last point's x: stops there
      if (points_[left + 1].x > x) return left;
    }
    return searchLeft(x);
  }
  std::size_t searchLeft(double x) const;  ///< segmentOf by bisection
  std::vector<Vec2d> points_;
  /// Where to start looking: one cell of equal width per segment over [first x, last x], each
  /// holding the last point at or left of the cell's start (evenly spaced points: its own).
  std::vector<std::uint32_t> cells_;
  std::vector<double> slopes_;  ///< of the segment starting at each point (0 at a step, the last)
  double cellsPerUnit_ = 0;
};

/// @brief A ScalarTexture read through a HeightRemap: value G(h), gradient G′(h) ∇h.
///
/// The texture is **not owned**; it must outlive this one. Thread-safe as the texture is.
class RemappedScalarTexture final : public ScalarTexture {
 public:
  RemappedScalarTexture(const ScalarTexture& texture, HeightRemap remap)
      : texture_(&texture), remap_(std::move(remap)) {}
  ScalarSample sample(Vec2d st) const override;
  /// The texture's sampleMany, then the remap, point by point.
  void sampleMany(std::span<const Vec2d> st, std::span<ScalarSample> out) const override;
  const HeightRemap& remap() const { return remap_; }

 private:
  const ScalarTexture* texture_;
  HeightRemap remap_;
};

/// @brief A HeightVolume read through a HeightRemap: value G(h), gradient G′(h) ∇h (exact where
/// G is differentiable; finite-difference schemes read value() and see the kinks as they are).
///
/// The volume is **not owned**; it must outlive this one.
class RemappedHeightVolume final : public HeightVolume {
 public:
  RemappedHeightVolume(const HeightVolume& volume, HeightRemap remap)
      : volume_(&volume), remap_(std::move(remap)) {}
  double value(Vec3d p) const override;
  Vec3d analyticGradient(Vec3d p) const override { return sample(p).gradient; }
  VolumeSample sample(Vec3d p) const override;

 private:
  const HeightVolume* volume_;
  HeightRemap remap_;
};

/// @brief A HeightVolume read at mapped coordinates: value h(P′), P′ = mapping.apply(P), gradient
/// mappingᵀ ∇h(P′) (CoordinateMapping::pullBack).
///
/// The volume is **not owned**; it must outlive this one.
class MappedHeightVolume final : public HeightVolume {
 public:
  MappedHeightVolume(const HeightVolume& volume, const CoordinateMapping& mapping)
      : volume_(&volume), mapping_(mapping) {}
  double value(Vec3d p) const override { return volume_->value(mapping_.apply(p)); }
  Vec3d analyticGradient(Vec3d p) const override {
    return mapping_.pullBack(volume_->analyticGradient(mapping_.apply(p)));
  }
  VolumeSample sample(Vec3d p) const override {
    const VolumeSample s = volume_->sample(mapping_.apply(p));
    return {s.value, mapping_.pullBack(s.gradient)};
  }

 private:
  const HeightVolume* volume_;
  CoordinateMapping mapping_;
};

/// @brief A HeightVolume read as a texture on the plane z = 0 of its coordinates:
/// h(s, t) = volume((s, t, 0)), slopes (∂h/∂x, ∂h/∂y) there. A procedural texture on a UV map's
/// coordinates is this: Blender's Texture Coordinate UV (and the UV Map node) give (u, v, 0),
/// and a Mapping node between them is a MappedHeightVolume under this view.
///
/// The volume is **not owned**; it must outlive this one. Thread-safe as the volume is.
class VolumeOnUvTexture final : public ScalarTexture {
 public:
  explicit VolumeOnUvTexture(const HeightVolume& volume) : volume_(&volume) {}
  ScalarSample sample(Vec2d st) const override {
    const VolumeSample s = volume_->sample({st.x, st.y, 0});
    return {s.value, {s.gradient.x, s.gradient.y}};
  }

 private:
  const HeightVolume* volume_;
};

}  // namespace sgbake
