/// @file udim_test.cpp
/// @brief UDIM textures: the tile a texture coordinate lies in, and sampling within it.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>
#include <memory>

#include "sgbake/gradient/udim.hpp"

namespace sgbake {
namespace {

/// h(s, t) = a + s + 2·t: a tile's own texture, told apart by a.
class AffineTexture : public ScalarTexture {
 public:
  explicit AffineTexture(double a) : a_(a) {}
  ScalarSample sample(Vec2d st) const override { return {a_ + st.x + 2 * st.y, {1, 2}}; }

 private:
  double a_;
};

class ConstantVector : public VectorTexture {
 public:
  explicit ConstantVector(Vec3d v) : v_(v) {}
  Vec3d sample(Vec2d) const override { return v_; }

 private:
  Vec3d v_;
};

TEST(Udim, TileNumbersAndCoordinatesWithinTheTile) {
  Vec2d within;
  EXPECT_EQ(udimTileOf({0.25, 0.5}, within), 1001);
  EXPECT_EQ(within, (Vec2d{0.25, 0.5}));
  EXPECT_EQ(udimTileOf({1.25, 0.5}, within), 1002);
  EXPECT_EQ(within, (Vec2d{0.25, 0.5}));
  EXPECT_EQ(udimTileOf({9.5, 2.75}, within), 1030);  // the last column of the third row
  EXPECT_EQ(within, (Vec2d{0.5, 0.75}));
  EXPECT_EQ(udimTileOf({1.0, 1.0}, within), 1012);  // edges belong to the tile above/right
  // Outside the ten columns and below the first row there is no tile.
  EXPECT_EQ(udimTileOf({-0.25, 0.5}, within), 0);
  EXPECT_EQ(udimTileOf({10.0, 0.5}, within), 0);
  EXPECT_EQ(udimTileOf({0.5, -1e-9}, within), 0);
  EXPECT_EQ(udimTileOf({std::numeric_limits<double>::quiet_NaN(), 0.5}, within), 0);
}

TEST(Udim, SamplesTheTileAtCoordinatesWithinIt) {
  std::map<int, std::unique_ptr<ScalarTexture>> tiles;
  tiles.emplace(1001, std::make_unique<AffineTexture>(10));
  tiles.emplace(1012, std::make_unique<AffineTexture>(20));
  const UdimScalarTexture udim(std::move(tiles));
  const ScalarSample first = udim.sample({0.25, 0.5});
  EXPECT_DOUBLE_EQ(first.value, 10 + 0.25 + 1.0);
  EXPECT_EQ(first.gradient, (Vec2d{1, 2}));  // a tile spans one unit: derivatives unscaled
  EXPECT_DOUBLE_EQ(udim.sample({1.5, 1.25}).value, 20 + 0.5 + 0.5);
  // Tile 1002 is missing: no bump there.
  const ScalarSample missing = udim.sample({1.5, 0.5});
  EXPECT_EQ(missing.value, 0.0);
  EXPECT_EQ(missing.gradient, (Vec2d{0, 0}));

  std::map<int, std::unique_ptr<VectorTexture>> normals;
  normals.emplace(1002, std::make_unique<ConstantVector>(Vec3d{0.1, 0.2, 0.3}));
  const UdimVectorTexture normalUdim(std::move(normals));
  EXPECT_EQ(normalUdim.sample({1.5, 0.5}), (Vec3d{0.1, 0.2, 0.3}));
  EXPECT_EQ(normalUdim.sample({0.5, 0.5}), (Vec3d{0.5, 0.5, 0.5}));  // encoded (0, 0, 0)
}

}  // namespace
}  // namespace sgbake
