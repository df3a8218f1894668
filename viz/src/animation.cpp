#include "foxi/viz/animation.hpp"

#include <gif_lib.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "foxi/model/durable_file.hpp"
#include "foxi/viz/png.hpp"

namespace foxi {

namespace {

void check_params(const std::filesystem::path& path, const AnimationParams& p) {
  if (p.width < 1 || p.height < 1 || p.width > 65535 || p.height > 65535)
    throw std::runtime_error(path.string() + ": frame size must be 1..65535 pixels");
  if (!(p.fps > 0 && p.fps <= 1000)) throw std::runtime_error(path.string() + ": fps must be in (0, 1000]");
  if (p.loops < 0 || p.loops > 65535) throw std::runtime_error(path.string() + ": loops must be 0..65535");
}

void check_frame(const std::filesystem::path& path, const AnimationParams& p, const Framebuffer& fb) {
  if (fb.width != p.width || fb.height != p.height ||
      fb.rgba.size() != std::size_t(fb.width) * std::size_t(fb.height))
    throw std::runtime_error(path.string() + ": frame of " + std::to_string(fb.width) + "x" +
                             std::to_string(fb.height) + " pixels in an animation of " +
                             std::to_string(p.width) + "x" + std::to_string(p.height));
}

void put32(std::string& s, std::uint32_t v) {
  s += char(v >> 24);
  s += char(v >> 16 & 255);
  s += char(v >> 8 & 255);
  s += char(v & 255);
}

void put16(std::string& s, std::uint32_t v) {
  s += char(v >> 8 & 255);
  s += char(v & 255);
}

class ApngWriter final : public AnimationWriter {
 public:
  ApngWriter(const std::filesystem::path& path, const AnimationParams& params)
      : path_(path), p_(params), file_((check_params(path, params), path)) {
    file_.write("\x89PNG\r\n\x1a\n", 8);
    std::string ihdr;
    put32(ihdr, std::uint32_t(p_.width));
    put32(ihdr, std::uint32_t(p_.height));
    ihdr += char(8);               // bit depth
    ihdr += char(2);               // colour type: RGB
    ihdr += std::string(3, '\0');  // compression, filter, interlace
    chunk("IHDR", ihdr);
    actl_at_ = file_.size();
    std::string actl;
    put32(actl, 0);  // frame count, patched by finish()
    put32(actl, std::uint32_t(p_.loops));
    chunk("acTL", actl);
    // Delay as a fraction: fps rounded to 1/1000.
    delay_num_ = 1000;
    delay_den_ = std::uint32_t(std::max(1.0, std::round(p_.fps * 1000)));
    if (delay_den_ > 65535) {
      delay_num_ = 1;
      delay_den_ = std::uint32_t(std::round(p_.fps));
    }
  }

  void add(const Framebuffer& fb) override {
    check_frame(path_, p_, fb);
    // The rectangle that differs from the previous frame (the whole frame first).
    int x0 = 0, y0 = 0, x1 = p_.width - 1, y1 = p_.height - 1;
    if (frames_ > 0) {
      x0 = p_.width;
      y0 = p_.height;
      x1 = y1 = -1;
      for (int y = 0; y < p_.height; ++y)
        for (int x = 0; x < p_.width; ++x) {
          const std::size_t i = fb.index(x, y);
          if (((fb.rgba[i] ^ previous_[i]) & 0xFFFFFFu) == 0) continue;
          x0 = std::min(x0, x);
          x1 = std::max(x1, x);
          y0 = std::min(y0, y);
          y1 = std::max(y1, y);
        }
      if (x1 < 0) x0 = x1 = y0 = y1 = 0;  // unchanged: one pixel, rewritten as it is
    }
    std::string fctl;
    put32(fctl, sequence_++);
    put32(fctl, std::uint32_t(x1 - x0 + 1));
    put32(fctl, std::uint32_t(y1 - y0 + 1));
    put32(fctl, std::uint32_t(x0));
    put32(fctl, std::uint32_t(y0));
    put16(fctl, delay_num_);
    put16(fctl, delay_den_);
    fctl += char(0);  // dispose: none
    fctl += char(0);  // blend: source
    chunk("fcTL", fctl);
    const std::string data = compress_rect(fb, x0, y0, x1, y1);
    if (frames_ == 0) {
      chunk("IDAT", data);
    } else {
      std::string fdat;
      put32(fdat, sequence_++);
      fdat += data;
      chunk("fdAT", fdat);
    }
    previous_ = fb.rgba;
    ++frames_;
  }

  void finish() override {
    if (frames_ == 0) throw std::runtime_error(path_.string() + ": an animation needs at least one frame");
    chunk("IEND", "");
    // Patch the frame count into acTL (its CRC covers it, so rewrite the whole chunk).
    std::string actl;
    put32(actl, std::uint32_t(frames_));
    put32(actl, std::uint32_t(p_.loops));
    file_.overwrite(actl_at_, chunk_bytes("acTL", actl));
    file_.commit();
  }
  int frames() const override { return frames_; }

 private:
  void chunk(const char* type, const std::string& data) { file_.write(chunk_bytes(type, data)); }
  static std::string chunk_bytes(const char* type, const std::string& data) {
    std::string c;
    put32(c, std::uint32_t(data.size()));
    c += type;
    c += data;
    const uLong crc =
        crc32(crc32(0, nullptr, 0), reinterpret_cast<const Bytef*>(c.data() + 4), uInt(c.size() - 4));
    put32(c, std::uint32_t(crc));
    return c;
  }

  // Scanlines of the rectangle, each with PNG filter "Up" (1 byte + 3 per pixel), deflated.
  std::string compress_rect(const Framebuffer& fb, int x0, int y0, int x1, int y1) const {
    const std::size_t w = std::size_t(x1 - x0 + 1), stride = 1 + 3 * w;
    std::vector<unsigned char> raw(stride * std::size_t(y1 - y0 + 1));
    std::vector<unsigned char> row(3 * w), above(3 * w, 0);
    for (int y = y0; y <= y1; ++y) {
      for (std::size_t i = 0; i < w; ++i) {
        const std::uint32_t c = fb.rgba[fb.index(x0 + int(i), y)];
        row[3 * i] = static_cast<unsigned char>(c & 255u);
        row[3 * i + 1] = static_cast<unsigned char>(c >> 8 & 255u);
        row[3 * i + 2] = static_cast<unsigned char>(c >> 16 & 255u);
      }
      unsigned char* r = &raw[std::size_t(y - y0) * stride];
      r[0] = 2;  // Up
      for (std::size_t i = 0; i < 3 * w; ++i) r[1 + i] = static_cast<unsigned char>(row[i] - above[i]);
      std::swap(row, above);
    }
    uLongf size = compressBound(uLong(raw.size()));
    std::string out(size, '\0');
    if (compress2(reinterpret_cast<Bytef*>(out.data()), &size, raw.data(), uLong(raw.size()), 6) != Z_OK)
      throw std::runtime_error(path_.string() + ": zlib compression failed");
    out.resize(size);
    return out;
  }

  std::filesystem::path path_;
  AnimationParams p_;
  DurableFile file_;  // complete or absent, durable (foxi/model/durable_file.hpp)
  std::uint64_t actl_at_ = 0;
  std::uint32_t delay_num_ = 1, delay_den_ = 12, sequence_ = 0;
  int frames_ = 0;
  std::vector<std::uint32_t> previous_;
};

class GifWriter final : public AnimationWriter {
 public:
  GifWriter(const std::filesystem::path& path, const AnimationParams& params)
      : path_(path), p_(params), file_((check_params(path, params), path)) {
    int err = 0;
    // A copy of the DurableFile's descriptor (giflib closes the one it is given), rather than a file
    // giflib creates, which would be readable by its owner only.
    const int fd = ::dup(file_.fd());
    if (fd < 0) throw std::runtime_error(path.string() + ": cannot write: " + std::strerror(errno));
    gif_ = EGifOpenFileHandle(fd, &err);
    if (!gif_) {
      ::close(fd);
      fail(err);
    }
    EGifSetGifVersion(gif_, true);
    if (EGifPutScreenDesc(gif_, p_.width, p_.height, 8, 0, nullptr) == GIF_ERROR) fail(gif_->Error);
    // NETSCAPE2.0: loop count.
    unsigned char loop[3] = {1, static_cast<unsigned char>(p_.loops & 255),
                             static_cast<unsigned char>(p_.loops >> 8)};
    if (EGifPutExtensionLeader(gif_, APPLICATION_EXT_FUNC_CODE) == GIF_ERROR ||
        EGifPutExtensionBlock(gif_, 11, "NETSCAPE2.0") == GIF_ERROR ||
        EGifPutExtensionBlock(gif_, 3, loop) == GIF_ERROR || EGifPutExtensionTrailer(gif_) == GIF_ERROR)
      fail(gif_->Error);
    delay_cs_ = std::clamp(int(std::lround(100 / p_.fps)), 1, 65535);
  }
  ~GifWriter() override {
    if (gif_) {
      int err = 0;
      EGifCloseFile(gif_, &err);
    }
  }

  void add(const Framebuffer& fb) override {
    check_frame(path_, p_, fb);
    const std::size_t n = fb.rgba.size();
    std::vector<GifByteType> r(n), g(n), b(n), index(n);
    for (std::size_t i = 0; i < n; ++i) {
      r[i] = static_cast<GifByteType>(fb.rgba[i] & 255u);
      g[i] = static_cast<GifByteType>(fb.rgba[i] >> 8 & 255u);
      b[i] = static_cast<GifByteType>(fb.rgba[i] >> 16 & 255u);
    }
    int colours = 256;
    GifColorType palette[256] = {};
    if (GifQuantizeBuffer(unsigned(p_.width), unsigned(p_.height), &colours, r.data(), g.data(), b.data(),
                          index.data(), palette) == GIF_ERROR)
      throw std::runtime_error(path_.string() + ": GIF colour quantization failed");
    // Each palette entry becomes the mean of the colours mapped to it (the median cut works on
    // 5-bit colours: this gives back exact colours where a box holds one, e.g. the background).
    std::vector<std::uint64_t> sum(4 * 256, 0);
    for (std::size_t i = 0; i < n; ++i) {
      std::uint64_t* e = &sum[4 * std::size_t(index[i])];
      e[0] += r[i];
      e[1] += g[i];
      e[2] += b[i];
      ++e[3];
    }
    for (int k = 0; k < 256; ++k) {
      const std::uint64_t* e = &sum[4 * std::size_t(k)];
      if (e[3] == 0) continue;
      palette[k].Red = static_cast<GifByteType>((e[0] + e[3] / 2) / e[3]);
      palette[k].Green = static_cast<GifByteType>((e[1] + e[3] / 2) / e[3]);
      palette[k].Blue = static_cast<GifByteType>((e[2] + e[3] / 2) / e[3]);
    }
    GraphicsControlBlock gcb{};
    gcb.DisposalMode = DISPOSAL_UNSPECIFIED;
    gcb.UserInputFlag = false;
    gcb.DelayTime = delay_cs_;
    gcb.TransparentColor = NO_TRANSPARENT_COLOR;
    GifByteType ext[4];
    EGifGCBToExtension(&gcb, ext);
    if (EGifPutExtension(gif_, GRAPHICS_EXT_FUNC_CODE, 4, ext) == GIF_ERROR) fail(gif_->Error);
    ColorMapObject* map = GifMakeMapObject(256, palette);
    if (!map) throw std::runtime_error(path_.string() + ": out of memory");
    const int put = EGifPutImageDesc(gif_, 0, 0, p_.width, p_.height, false, map);
    GifFreeMapObject(map);
    if (put == GIF_ERROR) fail(gif_->Error);
    for (int y = 0; y < p_.height; ++y)
      if (EGifPutLine(gif_, &index[std::size_t(y) * std::size_t(p_.width)], p_.width) == GIF_ERROR)
        fail(gif_->Error);
    ++frames_;
  }

  void finish() override {
    if (frames_ == 0) throw std::runtime_error(path_.string() + ": an animation needs at least one frame");
    int err = 0;
    const int closed = EGifCloseFile(gif_, &err);
    gif_ = nullptr;
    if (closed == GIF_ERROR) fail(err);
    file_.commit();
  }
  int frames() const override { return frames_; }

 private:
  [[noreturn]] void fail(int err) const {
    const char* why = GifErrorString(err);
    throw std::runtime_error(path_.string() + ": " + (why ? why : "GIF error " + std::to_string(err)));
  }

  std::filesystem::path path_;
  AnimationParams p_;
  DurableFile file_;  // complete or absent, durable (foxi/model/durable_file.hpp)
  GifFileType* gif_ = nullptr;
  int delay_cs_ = 8, frames_ = 0;
};

class PngFramesWriter : public AnimationWriter {
 public:
  PngFramesWriter(std::string pattern, const AnimationParams& p) : pattern_(std::move(pattern)), p_(p) {
    if (!frame_pattern(pattern_))
      throw std::runtime_error(pattern_ + ": a frame name needs one %d or %0Nd and no other %");
    check_params(pattern_, p_);
  }
  void add(const Framebuffer& fb) override {
    const std::filesystem::path path = frame_name(pattern_, files_.size());
    check_frame(path, p_, fb);
    files_.emplace_back(path, false);
    write_png(files_.back(), fb);
  }
  void finish() override {
    if (files_.empty()) throw std::runtime_error(pattern_ + ": no frames to write");
    commit_together(files_);
  }
  int frames() const override { return int(files_.size()); }

 private:
  std::string pattern_;
  AnimationParams p_;
  std::vector<DurableFile> files_;  // removed unless committed
};

}  // namespace

bool frame_pattern(const std::string& pattern) {
  int conversions = 0;
  for (std::size_t i = 0; i < pattern.size(); ++i) {
    if (pattern[i] != '%') continue;
    std::size_t j = i + 1;
    if (j < pattern.size() && pattern[j] == '0') ++j;
    while (j < pattern.size() && pattern[j] >= '0' && pattern[j] <= '9') ++j;
    if (j >= pattern.size() || pattern[j] != 'd' || j - i > 4) return false;
    ++conversions;
    i = j;
  }
  return conversions == 1;
}

std::string frame_name(const std::string& pattern, std::size_t k) {
  char buf[4096];
  std::snprintf(buf, sizeof buf, pattern.c_str(), int(k));  // checked by frame_pattern
  return buf;
}

std::unique_ptr<AnimationWriter> open_png_frames(const std::string& pattern, const AnimationParams& params) {
  return std::make_unique<PngFramesWriter>(pattern, params);
}

std::unique_ptr<AnimationWriter> open_apng(const std::filesystem::path& path, const AnimationParams& params) {
  return std::make_unique<ApngWriter>(path, params);
}

std::unique_ptr<AnimationWriter> open_gif(const std::filesystem::path& path, const AnimationParams& params) {
  return std::make_unique<GifWriter>(path, params);
}

}  // namespace foxi
