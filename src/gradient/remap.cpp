/// @file remap.cpp
/// @brief Piecewise-linear height remaps (remap.hpp).
#include "sgbake/gradient/remap.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace sgbake {

Result<HeightRemap> HeightRemap::create(std::vector<Vec2d> points) {
  if (points.size() < 2 || points.size() > kMaxRemapPoints) {
    return Error::badInput("a remap needs 2 to " + std::to_string(kMaxRemapPoints) +
                           " points, not " + std::to_string(points.size()));
  }
  for (std::size_t i = 0; i < points.size(); ++i) {
    const std::string which = "remap point " + std::to_string(i);
    if (!std::isfinite(points[i].x) || !std::isfinite(points[i].y))
      return Error::badInput(which + " is not finite");
    if (i == 0) continue;
    if (points[i].x < points[i - 1].x)
      return Error::badInput(which + " has a smaller x than the point before it");
    if (i >= 2 && points[i].x == points[i - 2].x)
      return Error::badInput(which + " is the third of one x (a step takes two)");
    const double dx = points[i].x - points[i - 1].x;
    if (dx > 0 && !std::isfinite((points[i].y - points[i - 1].y) / dx))
      return Error::badInput(which + " is too close to the point before it for a finite slope");
  }
  return HeightRemap(std::move(points));
}

HeightRemap::HeightRemap(std::vector<Vec2d> points) : points_(std::move(points)) {
  slopes_.assign(points_.size(), 0.0);
  for (std::size_t i = 0; i + 1 < points_.size(); ++i) {
    const Vec2d a = points_[i], b = points_[i + 1];
    if (b.x > a.x) slopes_[i] = (b.y - a.y) / (b.x - a.x);
  }
  const double first = points_.front().x, width = points_.back().x - first;
  // A single step (width 0) has every x beyond an end; an overflowing width is bisected.
  if (!(width > 0) || !std::isfinite(width)) return;
  // One cell per segment: evenly spaced points (a Color Ramp's table) start a cell each, and the
  // cell of x is then its segment but where rounding puts x in the cell beside it.
  const std::size_t count = points_.size() - 1;
  cellsPerUnit_ = static_cast<double>(count) / width;
  if (!std::isfinite(cellsPerUnit_)) {
    cellsPerUnit_ = 0;
    return;
  }
  cells_.resize(count);
  std::size_t point = 0;
  for (std::size_t c = 0; c < count; ++c) {
    const double start = first + static_cast<double>(c) / cellsPerUnit_;
    while (point + 1 < points_.size() && points_[point + 1].x <= start) ++point;
    cells_[c] = static_cast<std::uint32_t>(point);
  }
}

std::size_t HeightRemap::searchLeft(double x) const {
  return static_cast<std::size_t>(
      std::upper_bound(points_.begin(), points_.end(), x,
                       [](double v, const Vec2d& p) { return v < p.x; }) -
      points_.begin() - 1);
}

double HeightRemap::value(double x) const {
  double v, s;
  evaluate(x, v, s);
  return v;
}

double HeightRemap::slope(double x) const {
  double v, s;
  evaluate(x, v, s);
  return s;
}

namespace {

ScalarSample remapped(const HeightRemap& remap, const ScalarSample& h) {
  ScalarSample out;
  double slope;
  remap.evaluate(h.value, out.value, slope);
  out.gradient = slope * h.gradient;
  return out;
}

}  // namespace

ScalarSample RemappedScalarTexture::sample(Vec2d st) const {
  return remapped(remap_, texture_->sample(st));
}

void RemappedScalarTexture::sampleMany(std::span<const Vec2d> st,
                                       std::span<ScalarSample> out) const {
  texture_->sampleMany(st, out);
  for (ScalarSample& h : out) h = remapped(remap_, h);
}

double RemappedHeightVolume::value(Vec3d p) const { return remap_.value(volume_->value(p)); }

VolumeSample RemappedHeightVolume::sample(Vec3d p) const {
  const VolumeSample s = volume_->sample(p);
  return {remap_.value(s.value), s.gradient * remap_.slope(s.value)};
}

}  // namespace sgbake
