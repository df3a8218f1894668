#include "foxi/viz/png.hpp"

#include <png.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

#include "foxi/model/durable_file.hpp"

namespace foxi {

void write_png(const std::filesystem::path& path, const Framebuffer& fb) {
  DurableFile file(path);
  write_png(file, fb);
  file.commit();
}

void write_png(DurableFile& file, const Framebuffer& fb) {
  const std::filesystem::path& path = file.target();
  if (fb.width < 1 || fb.height < 1 || fb.rgba.size() != std::size_t(fb.width) * std::size_t(fb.height))
    throw std::runtime_error("write_png: empty or inconsistent framebuffer");
  std::vector<std::uint8_t> bytes(fb.rgba.size() * 4);
  for (std::size_t i = 0; i < fb.rgba.size(); ++i) {
    const std::uint32_t p = fb.rgba[i];
    bytes[4 * i + 0] = std::uint8_t(p & 255u);
    bytes[4 * i + 1] = std::uint8_t((p >> 8) & 255u);
    bytes[4 * i + 2] = std::uint8_t((p >> 16) & 255u);
    bytes[4 * i + 3] = std::uint8_t((p >> 24) & 255u);
  }
  std::FILE* f = nullptr;
  const int fd = ::dup(file.fd());  // fclose closes the copy; the DurableFile keeps its own
  if (fd >= 0) f = ::fdopen(fd, "wb");
  if (f == nullptr) {
    if (fd >= 0) ::close(fd);
    throw std::runtime_error("cannot write " + path.string() + ": " + std::strerror(errno));
  }
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  image.width = png_uint_32(fb.width);
  image.height = png_uint_32(fb.height);
  image.format = PNG_FORMAT_RGBA;
  const int written = png_image_write_to_stdio(&image, f, 0, bytes.data(), png_int_32(4 * fb.width), nullptr);
  const bool closed = std::fclose(f) == 0;
  if (written == 0 || !closed) {
    std::string why = written == 0 ? image.message : "write failed (disk full?)";
    png_image_free(&image);
    throw std::runtime_error("cannot write " + path.string() + ": " + why);
  }
  file.finish();
}

Framebuffer read_png(const std::filesystem::path& path) {
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  if (png_image_begin_read_from_file(&image, path.c_str()) == 0)
    throw std::runtime_error("cannot read " + path.string() + ": " + image.message);
  image.format = PNG_FORMAT_RGBA;
  std::vector<std::uint8_t> bytes(PNG_IMAGE_SIZE(image));
  if (png_image_finish_read(&image, nullptr, bytes.data(), 0, nullptr) == 0) {
    std::string why = image.message;
    png_image_free(&image);
    throw std::runtime_error("cannot read " + path.string() + ": " + why);
  }
  Framebuffer fb(int(image.width), int(image.height));
  for (std::size_t i = 0; i < fb.rgba.size(); ++i)
    fb.rgba[i] = pack_rgba(bytes[4 * i], bytes[4 * i + 1], bytes[4 * i + 2], bytes[4 * i + 3]);
  return fb;
}

}  // namespace foxi
