// The animation writers against readers: APNG parsed here chunk by chunk (CRCs, sequence numbers,
// acTL frame count, frames inflated with zlib, un-filtered and composed over their rectangles),
// libpng (an APNG is a PNG whose picture is the first frame), and ffmpeg when it is installed (all
// frames decoded, compared exactly); GIF read back with giflib's decoder and ffmpeg. Failures leave
// no file behind.
#include "foxi/viz/animation.hpp"

#include <gif_lib.h>
#include <gtest/gtest.h>
#include <zlib.h>

#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "foxi/viz/png.hpp"
#include "test_util.hpp"

namespace foxi {
namespace {

// Frames with rectangles of a few colours moving about (flat areas, like the painter's pictures).
std::vector<Framebuffer> test_frames(int w, int h, int n, int colours, unsigned seed) {
  std::mt19937 rng(seed);
  std::vector<std::uint32_t> palette;
  for (int i = 0; i < colours; ++i)  // distinct in their top 5 bits, so GIF keeps them exactly
    palette.push_back(pack_rgba(std::uint32_t(8 * (rng() % 32) + 3), std::uint32_t(8 * (rng() % 32) + 4),
                                std::uint32_t(8 * (rng() % 32) + 5)));
  std::vector<Framebuffer> frames;
  Framebuffer fb(w, h);
  for (int f = 0; f < n; ++f) {
    if (f != 2) {  // frame 2 repeats frame 1
      for (int r = 0; r < 3; ++r) {
        const int x0 = int(rng() % unsigned(w)), y0 = int(rng() % unsigned(h));
        const int x1 = std::min(w - 1, x0 + int(rng() % 20)), y1 = std::min(h - 1, y0 + int(rng() % 15));
        const std::uint32_t c = palette[rng() % palette.size()];
        for (int y = y0; y <= y1; ++y)
          for (int x = x0; x <= x1; ++x) fb.rgba[fb.index(x, y)] = c;
      }
    }
    frames.push_back(fb);
  }
  return frames;
}

std::uint32_t be32(const std::string& s, std::size_t at) {
  return std::uint32_t(std::uint8_t(s[at])) << 24 | std::uint32_t(std::uint8_t(s[at + 1])) << 16 |
         std::uint32_t(std::uint8_t(s[at + 2])) << 8 | std::uint32_t(std::uint8_t(s[at + 3]));
}

// A small APNG reader (8-bit RGB, any PNG filter, dispose none, blend source).
std::vector<Framebuffer> read_apng(const std::filesystem::path& path, std::uint32_t* plays) {
  const std::string f = test::read_text(path);
  EXPECT_EQ(f.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  std::size_t at = 8;
  int w = 0, h = 0;
  std::uint32_t declared = 0, next_sequence = 0;
  std::vector<Framebuffer> frames;
  Framebuffer canvas;
  int fx = 0, fy = 0, fw = 0, fh = 0;
  std::string data;
  auto flush = [&]() {
    if (data.empty()) return;
    const std::size_t stride = 1 + 3 * std::size_t(fw);
    std::vector<unsigned char> raw(stride * std::size_t(fh));
    uLongf size = uLongf(raw.size());
    EXPECT_EQ(uncompress(raw.data(), &size, reinterpret_cast<const Bytef*>(data.data()), uLong(data.size())),
              Z_OK);
    EXPECT_EQ(size, raw.size());
    std::vector<unsigned char> prev(3 * std::size_t(fw), 0), cur(3 * std::size_t(fw));
    for (int y = 0; y < fh; ++y) {
      const unsigned char* r = &raw[std::size_t(y) * stride];
      for (std::size_t i = 0; i < cur.size(); ++i) {
        const int a = i >= 3 ? cur[i - 3] : 0, b = prev[i], c = i >= 3 ? prev[i - 3] : 0;
        int pred = 0;
        switch (r[0]) {
          case 0:
            pred = 0;
            break;
          case 1:
            pred = a;
            break;
          case 2:
            pred = b;
            break;
          case 3:
            pred = (a + b) / 2;
            break;
          case 4: {
            const int p = a + b - c, pa = std::abs(p - a), pb = std::abs(p - b), pc = std::abs(p - c);
            pred = pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
            break;
          }
          default:
            ADD_FAILURE() << "bad filter " << int(r[0]);
        }
        cur[i] = static_cast<unsigned char>(r[1 + i] + pred);
      }
      for (int x = 0; x < fw; ++x)
        canvas.rgba[canvas.index(fx + x, fy + y)] =
            pack_rgba(cur[3 * std::size_t(x)], cur[3 * std::size_t(x) + 1], cur[3 * std::size_t(x) + 2]);
      std::swap(prev, cur);
    }
    frames.push_back(canvas);
    data.clear();
  };
  while (at + 12 <= f.size()) {
    const std::uint32_t len = be32(f, at);
    const std::string type = f.substr(at + 4, 4), body = f.substr(at + 8, len);
    const uLong crc =
        crc32(crc32(0, nullptr, 0), reinterpret_cast<const Bytef*>(f.data() + at + 4), uInt(len + 4));
    EXPECT_EQ(be32(f, at + 8 + len), std::uint32_t(crc)) << type << " CRC";
    at += 12 + len;
    if (type == "IHDR") {
      w = int(be32(body, 0));
      h = int(be32(body, 4));
      EXPECT_EQ(body[8], 8);
      EXPECT_EQ(body[9], 2);
      canvas = Framebuffer(w, h);
    } else if (type == "acTL") {
      declared = be32(body, 0);
      *plays = be32(body, 4);
    } else if (type == "fcTL") {
      flush();
      EXPECT_EQ(be32(body, 0), next_sequence++);
      fw = int(be32(body, 4));
      fh = int(be32(body, 8));
      fx = int(be32(body, 12));
      fy = int(be32(body, 16));
      EXPECT_LE(fx + fw, w);
      EXPECT_LE(fy + fh, h);
      EXPECT_EQ(body[24], 0);  // dispose none
      EXPECT_EQ(body[25], 0);  // blend source
    } else if (type == "IDAT") {
      data += body;
    } else if (type == "fdAT") {
      EXPECT_EQ(be32(body, 0), next_sequence++);
      data += body.substr(4);
    } else if (type == "IEND") {
      flush();
      EXPECT_EQ(at, f.size());
    }
  }
  EXPECT_EQ(declared, frames.size());
  return frames;
}

bool same_rgb(const Framebuffer& a, const Framebuffer& b) {
  if (a.rgba.size() != b.rgba.size()) return false;
  for (std::size_t i = 0; i < a.rgba.size(); ++i)
    if ((a.rgba[i] & 0xFFFFFFu) != (b.rgba[i] & 0xFFFFFFu)) return false;
  return true;
}

// All frames as ffmpeg decodes them (rgb24), or empty if ffmpeg is not installed.
std::vector<Framebuffer> ffmpeg_frames(const test::TempDir& dir, const std::filesystem::path& file, int w,
                                       int h) {
  std::vector<Framebuffer> out;
  if (!test::have_program("ffmpeg")) return out;
  const auto raw = dir / "frames.rgb";
  EXPECT_EQ(test::run("ffmpeg -v error -y -i '" + file.string() + "' -f rawvideo -pix_fmt rgb24 '" +
                          raw.string() + "'",
                      dir / "ffmpeg.log"),
            0);
  const std::string bytes = test::read_text(raw);
  const std::size_t size = 3 * std::size_t(w) * std::size_t(h);
  for (std::size_t at = 0; at + size <= bytes.size(); at += size) {
    Framebuffer fb(w, h);
    for (std::size_t i = 0; i < fb.rgba.size(); ++i)
      fb.rgba[i] = pack_rgba(std::uint8_t(bytes[at + 3 * i]), std::uint8_t(bytes[at + 3 * i + 1]),
                             std::uint8_t(bytes[at + 3 * i + 2]));
    out.push_back(std::move(fb));
  }
  EXPECT_EQ(bytes.size() % size, 0u);
  return out;
}

TEST(Animation, ApngFramesReadBackExactly) {
  test::TempDir dir;
  const int w = 57, h = 31;
  const auto frames = test_frames(w, h, 7, 6, 1);
  AnimationParams p;
  p.width = w;
  p.height = h;
  p.fps = 10;
  p.loops = 3;
  auto writer = open_apng(dir / "a.apng", p);
  for (const Framebuffer& fb : frames) writer->add(fb);
  EXPECT_FALSE(std::filesystem::exists(dir / "a.apng")) << "nothing in place before finish";
  writer->finish();
  std::uint32_t plays = 0;
  const auto back = read_apng(dir / "a.apng", &plays);
  EXPECT_EQ(plays, 3u);
  ASSERT_EQ(back.size(), frames.size());
  for (std::size_t i = 0; i < frames.size(); ++i) EXPECT_TRUE(same_rgb(back[i], frames[i])) << "frame " << i;
  EXPECT_TRUE(same_rgb(read_png(dir / "a.apng"), frames[0])) << "libpng sees the first frame";
  const auto ff = ffmpeg_frames(dir, dir / "a.apng", w, h);
  if (!ff.empty()) {
    ASSERT_EQ(ff.size(), frames.size());
    for (std::size_t i = 0; i < frames.size(); ++i)
      EXPECT_TRUE(same_rgb(ff[i], frames[i])) << "ffmpeg frame " << i;
  }
}

TEST(Animation, GifFramesReadBack) {
  test::TempDir dir;
  const int w = 64, h = 40;
  const auto frames = test_frames(w, h, 5, 20, 2);
  AnimationParams p;
  p.width = w;
  p.height = h;
  p.fps = 25;
  auto writer = open_gif(dir / "a.gif", p);
  for (const Framebuffer& fb : frames) writer->add(fb);
  writer->finish();
  int err = 0;
  GifFileType* gif = DGifOpenFileName((dir / "a.gif").c_str(), &err);
  ASSERT_NE(gif, nullptr);
  ASSERT_EQ(DGifSlurp(gif), GIF_OK);
  EXPECT_EQ(gif->SWidth, w);
  EXPECT_EQ(gif->SHeight, h);
  ASSERT_EQ(gif->ImageCount, int(frames.size()));
  for (int i = 0; i < gif->ImageCount; ++i) {
    const SavedImage& im = gif->SavedImages[i];
    GraphicsControlBlock gcb;
    ASSERT_EQ(DGifSavedExtensionToGCB(gif, i, &gcb), GIF_OK);
    EXPECT_EQ(gcb.DelayTime, 4);
    const ColorMapObject* map = im.ImageDesc.ColorMap ? im.ImageDesc.ColorMap : gif->SColorMap;
    ASSERT_NE(map, nullptr);
    std::size_t differ = 0;
    for (std::size_t k = 0; k < frames[std::size_t(i)].rgba.size(); ++k) {
      const GifColorType c = map->Colors[im.RasterBits[k]];
      differ += pack_rgba(c.Red, c.Green, c.Blue) != frames[std::size_t(i)].rgba[k];
    }
    EXPECT_EQ(differ, 0u) << "frame " << i << ": fewer than 256 colours are kept exactly";
  }
  DGifCloseFile(gif, &err);
  const auto ff = ffmpeg_frames(dir, dir / "a.gif", w, h);
  if (!ff.empty()) {
    EXPECT_EQ(ff.size(), frames.size());
  }
}

TEST(Animation, BadUseLeavesNoFile) {
  test::TempDir dir;
  AnimationParams p;
  p.width = 10;
  p.height = 10;
  for (const char* name : {"x.apng", "x.gif"}) {
    const auto path = dir / name;
    {
      auto writer = std::string(name).ends_with(".gif") ? open_gif(path, p) : open_apng(path, p);
      EXPECT_THROW(writer->add(Framebuffer(11, 10)), std::runtime_error);
      EXPECT_THROW(writer->finish(), std::runtime_error);  // no frame
    }
    EXPECT_FALSE(std::filesystem::exists(path));
    EXPECT_TRUE(std::filesystem::is_empty(dir.path())) << name;
  }
  p.width = 0;
  EXPECT_THROW(open_apng(dir / "y.apng", p), std::runtime_error);
  p.width = 10;
  EXPECT_THROW(open_gif(dir / "no/such/dir/y.gif", p), std::runtime_error);
}

// Numbered PNG frames: each frame read back by libpng equals the one added, named by the pattern;
// none in place before finish(); a writer dropped without finish() leaves nothing; bad patterns refused.
TEST(Animation, PngFramesReadBackExactlyAndAppearTogether) {
  test::TempDir dir;
  const int w = 33, h = 21;
  const auto frames = test_frames(w, h, 4, 5, 3);
  AnimationParams p;
  p.width = w;
  p.height = h;
  const std::string pattern = (dir / "f_%03d.png").string();
  auto writer = open_png_frames(pattern, p);
  for (const Framebuffer& fb : frames) writer->add(fb);
  EXPECT_EQ(writer->frames(), 4);
  EXPECT_FALSE(std::filesystem::exists(dir / "f_000.png")) << "nothing in place before finish";
  writer->finish();
  for (std::size_t i = 0; i < frames.size(); ++i) {
    EXPECT_EQ(frame_name(pattern, i), (dir / ("f_00" + std::to_string(i) + ".png")).string());
    EXPECT_TRUE(same_rgb(read_png(frame_name(pattern, i)), frames[i])) << "frame " << i;
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "f_004.png"));
  {
    auto dropped = open_png_frames((dir / "g_%d.png").string(), p);
    dropped->add(frames[0]);
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "g_0.png"));
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()), {}), 4) << "no temporaries left";
  for (const char* bad : {"f.png", "f_%d_%d.png", "f_%s.png", "f_%0123d.png", "50%.png"})
    EXPECT_FALSE(frame_pattern(bad)) << bad;
  EXPECT_TRUE(frame_pattern("frame_%04d.png"));
  EXPECT_THROW(open_png_frames((dir / "f.png").string(), p), std::runtime_error);
}

}  // namespace
}  // namespace foxi
