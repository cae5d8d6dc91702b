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
  }
  return HeightRemap(std::move(points));
}

void HeightRemap::evaluate(double x, double& value, double& slope) const {
  if (std::isnan(x)) {
    value = slope = std::numeric_limits<double>::quiet_NaN();
    return;
  }
  // The first point right of x: x lies on the segment that ends there.
  const auto right = std::upper_bound(points_.begin(), points_.end(), x,
                                      [](double v, const Vec2d& p) { return v < p.x; });
  if (right == points_.begin() || right == points_.end()) {
    value = right == points_.begin() ? points_.front().y : points_.back().y;
    slope = 0;
    return;
  }
  const Vec2d a = *(right - 1), b = *right;  // a.x <= x < b.x, so b.x > a.x
  slope = (b.y - a.y) / (b.x - a.x);
  value = a.y + (x - a.x) * slope;
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

Vec3d RemappedHeightVolume::analyticGradient(Vec3d p) const {
  return volume_->analyticGradient(p) * remap_.slope(volume_->value(p));
}

}  // namespace sgbake
