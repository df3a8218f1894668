#include "foxi/viz/png.hpp"

#include <png.h>

#include <cstdint>
#include <cstdio>
#include <random>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

namespace foxi {

void write_png(const std::filesystem::path& path, const Framebuffer& fb) {
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
  std::random_device rd;
  std::filesystem::path tmp = path;
  tmp += ".tmp" + std::to_string(rd());
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  image.width = png_uint_32(fb.width);
  image.height = png_uint_32(fb.height);
  image.format = PNG_FORMAT_RGBA;
  if (png_image_write_to_file(&image, tmp.c_str(), 0, bytes.data(), png_int_32(4 * fb.width), nullptr) == 0) {
    std::string why = image.message;
    png_image_free(&image);
    std::error_code ec;
    std::filesystem::remove(tmp, ec);
    throw std::runtime_error("cannot write " + path.string() + ": " + why);
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::filesystem::remove(tmp, ec);
    throw std::runtime_error("cannot write " + path.string() + ": rename failed");
  }
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
