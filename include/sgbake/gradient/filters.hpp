/// @file filters.hpp
/// @brief Images as textures: filtered values with the exact derivatives of the filtered
/// (interpolated) function, for height maps (ScalarTexture) and normal maps (VectorTexture).
///
/// ## Geometry of a filter
/// Texture space is (s, t), s right, t up, one image repeat per unit (image.hpp). Texel (x, y)
/// has its centre at ((x + 0.5)/W, (y + 0.5)/H). Every filter works in *texel units*
/// `u = s·W − 0.5`, `v = t·H − 0.5`, in which texel centres sit on the integer lattice. The
/// lattice square with lower-left corner (x, y) is **cell (x, y)**; its corners are the centres
/// of texels (x, y), (x+1, y), (x, y+1), (x+1, y+1), and inside it the filtered function is one
/// polynomial of the fractional position (fx, fy) = (u − x, v − y) ∈ [0, 1]². Derivatives are
/// those of that polynomial, carried to texture space by the chain rule:
/// `∂h/∂s = W · ∂h/∂u`, `∂h/∂t = H · ∂h/∂v`.
///
/// ## Filters
/// - **kBilinear**: the tensor product of linear interpolation (Blender's "Linear"). C0: inside
///   a cell ∂h/∂s depends on fy only and ∂h/∂t on fx only (constant along their own axis, as in
///   1D), and both jump across cell edges. Reproduces affine fields exactly.
/// - **kBicubic**: the tensor product of the **Catmull-Rom** cubic (Keys' kernel, a = −1/2),
///   4×4 texels. C1; *interpolating* (a sample at a texel centre returns that texel), reproduces
///   every polynomial of degree ≤ 2 in each of s and t (biquadratics) exactly, error O(h³).
///   Why not Blender's "Cubic": Cycles and EEVEE use the cubic **B-spline**, which is C2 but
///   *approximating*: it smooths the map (texel values are not reproduced; a period-4-texel
///   sine loses a third of its amplitude), so a baked height would no longer match its texels.
///   Catmull-Rom is also exactly Hermite interpolation with central-difference derivatives (see
///   DerivativeStencil::kCentral2), which keeps the three filters one family.
/// - **kHermite**: first-order Hermite interpolation (seed 004): in each cell the bicubic
///   Hermite patch of the four corner texels' values h, first derivatives h_u, h_v and cross
///   derivative h_uv (the "twist", 16 coefficients). C1 across cells, 2×2 texels per sample
///   (the derivatives are precomputed per texel). Reproduces every bicubic polynomial (degree
///   ≤ 3 in each of s and t) exactly when the per-texel derivatives are exact. The derivatives
///   are either supplied with the map (ImageScalarTexture::createWithDerivatives) or estimated
///   from it by finite differences (DerivativeStencil).
///
/// ## Wrap modes
/// - **kRepeat** (default, Blender's "Repeat"): the image tiles the plane; s and t are reduced
///   to [0, 1) and taps wrap around. Seamless: the value and derivative are as smooth across
///   s = 0 / s = 1 as anywhere else.
/// - **kClamp** (Blender's "Extend"): the position is clamped to the centres of the border
///   texels (u ∈ [0, W−1], v ∈ [0, H−1]); beyond them the texture is constant along that axis,
///   whose derivative is then 0. Taps and stencils past the border read the border texel.
///
/// ## Performance and threads
/// sample() does no allocation and no virtual call past its own; a texture is immutable after
/// creation, so sample() may be called from any number of threads. Textures copy the channels
/// they need at creation (float32); the Image may be destroyed afterwards.
#pragma once

#include <span>
#include <vector>

#include "sgbake/core/result.hpp"
#include "sgbake/core/vec.hpp"
#include "sgbake/gradient/image.hpp"
#include "sgbake/gradient/texture.hpp"

namespace sgbake {

/// @brief Reconstruction filter of an image texture (see the file comment).
enum class Filter { kBilinear, kBicubic, kHermite };

/// @brief What lies outside [0, 1)² (see the file comment).
enum class Wrap { kRepeat, kClamp };

/// @brief How Filter::kHermite estimates per-texel derivatives from the map when none are
/// supplied. Stencils wrap like the sampler (kRepeat: periodic; kClamp: border texel repeated).
enum class DerivativeStencil {
  /// Second-order central differences in texel units: h_u = (h[x+1] − h[x−1]) / 2, likewise h_v,
  /// and h_uv = (h[x+1,y+1] − h[x−1,y+1] − h[x+1,y−1] + h[x−1,y−1]) / 4 — which is also the
  /// Adini twist (seed 004 §6.1, below) of these h_u, h_v. The resulting Hermite surface is
  /// *identical* to Catmull-Rom (Filter::kBicubic). Error O(h³) in value, O(h²) in derivative.
  kCentral2,
  /// Fourth-order central differences, D = (h[x−2] − 8h[x−1] + 8h[x+1] − h[x+2]) / 12 along
  /// each axis, and h_uv = D_u D_v h (5×5 stencil). Exact for polynomials of degree ≤ 4, so the
  /// Hermite surface reproduces bicubics exactly. Error O(h⁴) in value, O(h³) in derivative.
  kCentral4,
};

/// @brief Where Filter::kHermite takes the twist h_uv from when the data has none
/// (estimated derivatives, or supplied derivatives with two channels).
enum class HermiteTwist {
  /// Estimated. Estimated derivatives: the stencil applied along both axes (DerivativeStencil).
  /// Two supplied channels: the Adini twist of seed 004 §6.1 in two dimensions — the cross
  /// derivative at the texel of the Coons patch fitted to its four neighbouring cells — which in
  /// texel units is
  /// `h_uv = (h_u[x,y+1] − h_u[x,y−1])/2 + (h_v[x+1,y] − h_v[x−1,y])/2
  ///        − (h[x+1,y+1] − h[x+1,y−1] − h[x−1,y+1] + h[x−1,y−1])/4`.
  /// It is exact for every bicubic term except s³t³.
  kEstimate,
  /// Zero twist (Ferguson patches, seed 004 §6.1): cheaper to reason about, shows flat spots.
  kZero,
};

/// @brief Options for ImageScalarTexture.
struct ScalarTextureOptions {
  Filter filter = Filter::kBilinear;
  Wrap wrap = Wrap::kRepeat;
  int channel = 0;  ///< which channel of the image is the height
  DerivativeStencil stencil = DerivativeStencil::kCentral4;  ///< kHermite, estimated derivatives
  HermiteTwist twist = HermiteTwist::kEstimate;  ///< kHermite without a supplied twist channel
};

/// @brief Options for ImageVectorTexture.
struct VectorTextureOptions {
  Filter filter = Filter::kBilinear;  ///< kBilinear or kBicubic
  Wrap wrap = Wrap::kRepeat;
  int firstChannel = 0;  ///< channels firstChannel .. firstChannel+2 are the vector
};

/// @brief A filtered three-channel value and its exact derivatives w.r.t. s and t.
struct VectorSample {
  Vec3d value{};
  Vec3d dds{};  ///< ∂value/∂s, per channel
  Vec3d ddt{};  ///< ∂value/∂t, per channel
};

/// @brief One channel of an Image as a ScalarTexture (height maps).
class ImageScalarTexture final : public ScalarTexture {
 public:
  /// @brief A texture over channel options.channel of @p image.
  ///
  /// With Filter::kHermite the per-texel derivatives are estimated (options.stencil,
  /// options.twist).
  /// @return kBadInput when the image is empty, the channel does not exist or a value is not
  /// finite.
  static Result<ImageScalarTexture> create(const Image& image,
                                           const ScalarTextureOptions& options = {});

  /// @brief A Filter::kHermite texture whose per-texel derivatives are supplied (this is how
  /// derivatives are attached to a map; options.filter and options.stencil are ignored).
  ///
  /// @param[in] image       the height map (channel options.channel)
  /// @param[in] derivatives same W×H as @p image, 2 or 3 channels, in **texture units** (per
  ///   unit of s and t, as ScalarSample::gradient): channel 0 = ∂h/∂s, 1 = ∂h/∂t and, when
  ///   present, 2 = ∂²h/∂s∂t. Without channel 2 the twist follows options.twist. Rows bottom-up
  ///   like every Image (loadImage gives that order).
  /// @return kBadInput when the sizes differ, the channel counts are wrong or a value is not
  ///   finite.
  static Result<ImageScalarTexture> createWithDerivatives(const Image& image,
                                                          const Image& derivatives,
                                                          const ScalarTextureOptions& options = {});

  /// @brief Filtered height and its exact gradient (∂h/∂s, ∂h/∂t) at @p st.
  /// @note Non-finite @p st gives a NaN value and gradient.
  ScalarSample sample(Vec2d st) const override;

  /// @brief sample() at every point of @p st into @p out (the same size), bit for bit: one
  /// dispatch on the filter for the whole batch instead of a virtual call and a switch per point
  /// (the baker samples a batch of texels at once).
  void sampleMany(std::span<const Vec2d> st, std::span<ScalarSample> out) const override;

  /// @brief The polynomial piece of cell (cellX, cellY) at fractional position @p fraction.
  ///
  /// sample() is sampleCell() of the cell containing the point. Evaluating two neighbouring
  /// cells on their shared edge (fraction 1 in one, 0 in the other) gives the one-sided limits
  /// there, e.g. to check continuity. Cell indices wrap (kRepeat) or clamp (kClamp).
  /// @param[in] cellX,cellY the cell's lower-left texel
  /// @param[in] fraction    (fx, fy), texel units, normally in [0, 1]²
  /// @return value and gradient in texture units (∂/∂s = W·∂/∂fx, ∂/∂t = H·∂/∂fy)
  ScalarSample sampleCell(int cellX, int cellY, Vec2d fraction) const;

  int width() const { return width_; }
  int height() const { return height_; }
  Filter filter() const { return filter_; }
  Wrap wrap() const { return wrap_; }

  /// Per-texel Hermite data in texel units (∂/∂u, ∂/∂v with u = s·W − 0.5, v = t·H − 0.5).
  struct HermiteTexel {
    float h, hu, hv, huv;
  };

 private:
  ImageScalarTexture() = default;
  // The piece of cell (cellX, cellY) at (fx, fy); scaleX/scaleY = du/ds, dv/dt (W and H, or 0
  // where kClamp holds the position at the border).
  ScalarSample evaluate(int cellX, double fx, double scaleX, int cellY, double fy,
                        double scaleY) const;
  // Calls body(kernel) with kernel(cellX, fx, cellY, fy) the filter's piece of a cell (one
  // switch on the filter per call; defined and instantiated in filters.cpp only).
  template <class Body>
  void withKernel(const Body& body) const;

  int width_ = 0;
  int height_ = 0;
  Filter filter_ = Filter::kBilinear;
  Wrap wrap_ = Wrap::kRepeat;
  std::vector<float> plane_;           ///< kBilinear, kBicubic: W×H heights, bottom row first
  std::vector<HermiteTexel> hermite_;  ///< kHermite: W×H texels, bottom row first
};

/// @brief Three channels of an Image as a VectorTexture (normal maps), bilinear or bicubic.
class ImageVectorTexture final : public VectorTexture {
 public:
  /// @return kBadInput when the image is empty, has fewer than firstChannel + 3 channels,
  /// a value is not finite, or options.filter is kHermite (not offered for vectors).
  static Result<ImageVectorTexture> create(const Image& image,
                                           const VectorTextureOptions& options = {});
  /// @brief create() from an image that is not needed afterwards: a three-channel image's
  /// pixels become the texture's (no copy, half the memory at the peak); @p image is left
  /// empty on success.
  static Result<ImageVectorTexture> create(Image&& image, const VectorTextureOptions& options = {});

  /// @brief The filtered channels at @p st, as stored (no decoding, no normalization).
  Vec3d sample(Vec2d st) const override;

  /// @brief The filtered channels and their exact derivatives w.r.t. s and t.
  VectorSample sampleWithDerivatives(Vec2d st) const;

  /// @brief The polynomial piece of cell (cellX, cellY) at @p fraction (as
  /// ImageScalarTexture::sampleCell).
  VectorSample sampleCell(int cellX, int cellY, Vec2d fraction) const;

  int width() const { return width_; }
  int height() const { return height_; }
  Filter filter() const { return filter_; }
  Wrap wrap() const { return wrap_; }

 private:
  ImageVectorTexture() = default;
  VectorSample evaluate(int cellX, double fx, double scaleX, int cellY, double fy,
                        double scaleY) const;

  int width_ = 0;
  int height_ = 0;
  Filter filter_ = Filter::kBilinear;
  Wrap wrap_ = Wrap::kRepeat;
  std::vector<float> texels_;  ///< W×H×3, bottom row first, channels interleaved
};

}  // namespace sgbake
