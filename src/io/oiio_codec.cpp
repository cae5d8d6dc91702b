// libsgbake_oiio.so: the image I/O module, OpenImageIO behind the interface of image_codec.hpp.
// Nothing else in sgbake includes OpenImageIO.
#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

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
  /// @p subimages: how many the file has (countSubimages), @p in at the first.
  OiioReader(std::unique_ptr<OIIO::ImageInput> in, int subimages)
      : in_(std::move(in)), subimages_(subimages) {}
  ~OiioReader() override { in_->close(); }

  ImageHeader header() const override {
    const OIIO::ImageSpec& spec = in_->spec();
    ImageHeader header;
    header.width = spec.width;
    header.height = spec.height;
    header.depth = spec.depth;
    header.channels = spec.nchannels;
    for (const OIIO::ParamValue& p : spec.extra_attribs) {
      const std::string name = p.name().string();
      if (name.starts_with("sgbake:") && p.type() == OIIO::TypeDesc::STRING) {
        header.attributes.emplace_back(name, p.get_string());
      }
    }
    header.subimages = subimages_;
    header.subimageName = spec.get_string_attribute("name");
    header.channelNames = spec.channelnames;
    if (std::string_view(in_->format_name()) == "openexr") {
      for (int c = 0; c < spec.nchannels; ++c) {
        if (spec.channelformat(c) == OIIO::TypeDesc::UINT) header.uintChannels = true;
      }
    }
    return header;
  }
  bool readFloat(int channels, float* first, std::ptrdiff_t pixelStride,
                 std::ptrdiff_t rowStride) override {
    const bool read =
        in_->read_image(0, 0, 0, channels, OIIO::TypeDesc::FLOAT, first, pixelStride, rowStride);
    // OpenImageIO's TIFF reader reports a strip it could not read (a truncated file) only in
    // geterror() and returns true, its pixels left unread: the text decides.
    error_ = in_->geterror();
    return read && error_.empty();
  }
  std::string error() override { return error_.empty() ? in_->geterror() : error_; }

 private:
  std::unique_ptr<OIIO::ImageInput> in_;
  int subimages_ = 1;
  std::string error_;  ///< of the last readFloat
};

/// An output file that remembers the first failed write. OpenImageIO's PNG writer writes
/// through stdio and does not check fclose, so a full disk or a file-size limit there leaves a
/// truncated file behind a successful close(); written through this proxy, the failure is
/// seen. Writes go through a buffer (libpng writes in small pieces); seek, pwrite and close
/// flush it first.
class CheckedFileProxy final : public OIIO::Filesystem::IOProxy {
 public:
  explicit CheckedFileProxy(const std::string& path) : IOProxy(path, Write) {
    fd_ = ::open(path.c_str(), O_WRONLY | O_TRUNC | O_CLOEXEC);
    if (fd_ < 0) fail(errno);
  }
  ~CheckedFileProxy() override { close(); }

  const char* proxytype() const override { return "sgbake-checked-file"; }
  void close() override {
    if (fd_ < 0) return;
    flushBuffer();
    if (::close(fd_) != 0) fail(errno);
    fd_ = -1;
    m_mode = Closed;
  }
  bool seek(int64_t offset) override {
    if (offset < 0) return false;
    m_pos = offset;
    return true;
  }
  size_t write(const void* data, size_t size) override {
    if (fd_ < 0) return 0;
    if (m_pos != bufferStart_ + static_cast<int64_t>(buffer_.size())) {  // not where it ends
      flushBuffer();
      bufferStart_ = m_pos;
    }
    const char* bytes = static_cast<const char*>(data);
    buffer_.insert(buffer_.end(), bytes, bytes + size);
    m_pos += static_cast<int64_t>(size);
    if (buffer_.size() >= kBufferBytes) flushBuffer();
    return failed() ? 0 : size;
  }
  size_t pwrite(const void* data, size_t size, int64_t offset) override {
    flushBuffer();
    return writeAt(static_cast<const char*>(data), size, offset) ? size : 0;
  }
  size_t read(void*, size_t) override { return 0; }  // write only
  size_t pread(void*, size_t, int64_t) override { return 0; }
  size_t size() const override {
    struct stat st {};
    const int64_t onDisk = fd_ >= 0 && ::fstat(fd_, &st) == 0 ? st.st_size : 0;
    return static_cast<size_t>(
        std::max(onDisk, bufferStart_ + static_cast<int64_t>(buffer_.size())));
  }

  bool failed() const { return errno_ != 0; }
  /// @brief Why the first write failed, e.g. "No space left on device".
  std::string failure() const { return std::strerror(errno_); }

 private:
  static constexpr size_t kBufferBytes = 1 << 20;

  void fail(int error) {
    if (errno_ == 0) errno_ = error != 0 ? error : EIO;
  }
  bool writeAt(const char* data, size_t size, int64_t offset) {
    while (size > 0 && fd_ >= 0 && !failed()) {
      const ssize_t n = ::pwrite(fd_, data, size, offset);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) {
        fail(n < 0 ? errno : EIO);
        return false;
      }
      data += n;
      size -= static_cast<size_t>(n);
      offset += n;
    }
    return !failed();
  }
  void flushBuffer() {
    if (!buffer_.empty()) writeAt(buffer_.data(), buffer_.size(), bufferStart_);
    buffer_.clear();
  }

  int fd_ = -1;
  int errno_ = 0;
  std::vector<char> buffer_;
  int64_t bufferStart_ = 0;  ///< file offset of buffer_[0]
};

class OiioWriter final : public ImageWriter {
 public:
  OiioWriter(std::unique_ptr<OIIO::ImageOutput> out, std::unique_ptr<CheckedFileProxy> proxy)
      : proxy_(std::move(proxy)), out_(std::move(out)) {}
  ~OiioWriter() override {
    if (!closed_) out_->close();
  }

  bool writeRows(int begin, int end, PixelType type, const void* data) override {
    return out_->write_scanlines(begin, end, 0, oiioType(type), data) && !proxyFailed();
  }
  bool close() override {
    closed_ = true;
    const bool closed = out_->close();
    if (proxy_) proxy_->close();
    return closed && !proxyFailed();
  }
  std::string error() override {
    std::string error = out_->geterror();  // (read either way: it clears OpenImageIO's text)
    // The file's own failure says it all; OpenImageIO then adds one "Write error at position
    // …" per later write that went nowhere.
    if (proxyFailed()) return proxy_->failure();
    return error;
  }

 private:
  bool proxyFailed() const { return proxy_ && proxy_->failed(); }

  // The proxy outlives the output that writes through it (members die in reverse order).
  std::unique_ptr<CheckedFileProxy> proxy_;  ///< the file PNG output goes through, else null
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
    // How many subimages there are (EXR parts, TIFF pages): seeking past the last fails.
    int subimages = 1;
    while (subimages < 64 && in->seek_subimage(subimages, 0)) ++subimages;
    (void)in->geterror();  // the failed seek's text
    if (subimages > 1) {
      in->seek_subimage(0, 0);
    } else {
      // A reader may not read again after a failed seek (WebP's says "Couldn't decode
      // subimage 0"): a file of one image is opened afresh.
      in = OIIO::ImageInput::open(path.string(), &config);
      if (!in) {
        error = OIIO::geterror();
        return nullptr;
      }
    }
    return std::make_unique<OiioReader>(std::move(in), subimages);
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
    for (const auto& [name, value] : spec.attributes) oiioSpec.attribute(name, value);

    std::unique_ptr<OIIO::ImageOutput> out = OIIO::ImageOutput::create(spec.format);
    if (!out) {
      error = OIIO::geterror();
      return nullptr;
    }
    // PNG through CheckedFileProxy (OpenImageIO's OpenEXR and TIFF writers report failed
    // writes themselves).
    std::unique_ptr<CheckedFileProxy> proxy;
    if (spec.format == "png" && out->supports("ioproxy")) {
      proxy = std::make_unique<CheckedFileProxy>(path.string());
      if (proxy->failed()) {
        error = proxy->failure();
        return nullptr;
      }
      out->set_ioproxy(proxy.get());
    }
    if (!out->open(path.string(), oiioSpec)) {
      error = out->geterror();
      return nullptr;
    }
    return std::make_unique<OiioWriter>(std::move(out), std::move(proxy));
  }
};

}  // namespace
}  // namespace sgbake::io_detail

extern "C" __attribute__((visibility("default"))) const sgbake::io_detail::ImageCodec*
sgbake_image_codec(int version) {
  static const sgbake::io_detail::OiioCodec codec;
  return version == sgbake::io_detail::kImageCodecVersion ? &codec : nullptr;
}
