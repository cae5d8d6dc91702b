// libsgbake_oiio.so: the image I/O module, OpenImageIO behind the interface of image_codec.hpp.
// Nothing else in sgbake includes OpenImageIO.
#include <OpenImageIO/imageio.h>

#include <memory>
#include <string>
#include <utility>

#include "io/image_codec.hpp"

namespace sgbake::io_detail {
namespace {

OIIO::TypeDesc oiioType(PixelType type) {
  switch (type) {
    case PixelType::kUint8:
      return OIIO::TypeDesc::UINT8;
    case PixelType::kUint16:
      return OIIO::TypeDesc::UINT16;
    case PixelType::kHalf:
      return OIIO::TypeDesc::HALF;
    case PixelType::kFloat:
      return OIIO::TypeDesc::FLOAT;
  }
  return OIIO::TypeDesc::UNKNOWN;
}

class OiioReader final : public ImageReader {
 public:
  explicit OiioReader(std::unique_ptr<OIIO::ImageInput> in) : in_(std::move(in)) {}
  ~OiioReader() override { in_->close(); }

  ImageHeader header() const override {
    const OIIO::ImageSpec& spec = in_->spec();
    return {spec.width, spec.height, spec.depth, spec.nchannels};
  }
  bool readFloat(int channels, float* first, std::ptrdiff_t pixelStride,
                 std::ptrdiff_t rowStride) override {
    return in_->read_image(0, 0, 0, channels, OIIO::TypeDesc::FLOAT, first, pixelStride,
                           rowStride);
  }
  std::string error() override { return in_->geterror(); }

 private:
  std::unique_ptr<OIIO::ImageInput> in_;
};

class OiioWriter final : public ImageWriter {
 public:
  explicit OiioWriter(std::unique_ptr<OIIO::ImageOutput> out) : out_(std::move(out)) {}
  ~OiioWriter() override {
    if (!closed_) out_->close();
  }

  bool writeRows(int begin, int end, PixelType type, const void* data) override {
    return out_->write_scanlines(begin, end, 0, oiioType(type), data);
  }
  bool close() override {
    closed_ = true;
    return out_->close();
  }
  std::string error() override { return out_->geterror(); }

 private:
  std::unique_ptr<OIIO::ImageOutput> out_;
  bool closed_ = false;
};

class OiioCodec final : public ImageCodec {
 public:
  std::unique_ptr<ImageReader> openReader(const std::filesystem::path& path,
                                          std::string& error) const override {
    // Keep unassociated alpha as stored: by default OIIO premultiplies colour by alpha on read,
    // which would change the heights/normals of any texel with alpha < 1.
    OIIO::ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);
    std::unique_ptr<OIIO::ImageInput> in = OIIO::ImageInput::open(path.string(), &config);
    if (!in) {
      error = OIIO::geterror();
      return nullptr;
    }
    return std::make_unique<OiioReader>(std::move(in));
  }

  std::unique_ptr<ImageWriter> openWriter(const std::filesystem::path& path,
                                          const ImageWriteSpec& spec,
                                          std::string& error) const override {
    OIIO::ImageSpec oiioSpec(spec.width, spec.height, spec.channels, oiioType(spec.type));
    oiioSpec.channelnames = spec.channelNames;
    oiioSpec.alpha_channel = spec.alphaChannel;
    if (spec.alphaChannel >= 0) oiioSpec.attribute("oiio:UnassociatedAlpha", 1);
    if (spec.zipCompression) oiioSpec.attribute("compression", "zip");
    if (spec.pngCompressionLevel >= 0) {
      oiioSpec.attribute("png:compressionLevel", spec.pngCompressionLevel);
    }
    if (spec.pngFilters >= 0) oiioSpec.attribute("png:filter", spec.pngFilters);
    if (!spec.software.empty()) oiioSpec.attribute("Software", spec.software);

    std::unique_ptr<OIIO::ImageOutput> out = OIIO::ImageOutput::create(spec.format);
    if (!out) {
      error = OIIO::geterror();
      return nullptr;
    }
    if (!out->open(path.string(), oiioSpec)) {
      error = out->geterror();
      return nullptr;
    }
    return std::make_unique<OiioWriter>(std::move(out));
  }
};

}  // namespace
}  // namespace sgbake::io_detail

extern "C" __attribute__((visibility("default"))) const sgbake::io_detail::ImageCodec*
sgbake_image_codec(int version) {
  static const sgbake::io_detail::OiioCodec codec;
  return version == sgbake::io_detail::kImageCodecVersion ? &codec : nullptr;
}
