// foxi movie and foxi render --depth, end to end: numbered PNG frames whose high point equals
// foxi render's picture (another command, same camera defaults) and whose ends are blank, the APNG
// and GIF of the same movie decoded by ffmpeg (when installed) frame for frame against the PNG
// frames (GIF: read back with giflib), MP4 through ffmpeg, and usage errors.
#include <gif_lib.h>
#include <gtest/gtest.h>

#include <string>

#include "foxi/model/mesh_io.hpp"
#include "foxi/viz/png.hpp"
#include "test_util.hpp"
#include "viz/mesh_factory.hpp"

namespace foxi {
namespace {

class MovieCli : public ::testing::Test {
 protected:
  void SetUp() override {
    Mesh m = test::grid_mesh(5, 4, 3, 1, 1, 1, 6);
    test::regions_along_x(m, 2, 3.5);
    mesh_ = dir_ / "grid.vtu";
    write_mesh(m, mesh_);
  }
  int foxi(const std::string& args, std::string* out = nullptr) {
    const int status = test::run("'" + test::cli_path() + "' " + args, dir_ / "log.txt");
    if (out) *out = test::read_text(dir_ / "log.txt");
    return status;
  }
  std::string p(const std::string& name) const { return "'" + (dir_ / name).string() + "'"; }
  test::TempDir dir_;
  std::filesystem::path mesh_;
};

bool same_rgb(const Framebuffer& a, const Framebuffer& b) {
  if (a.width != b.width || a.height != b.height) return false;
  for (std::size_t i = 0; i < a.rgba.size(); ++i)
    if ((a.rgba[i] & 0xFFFFFFu) != (b.rgba[i] & 0xFFFFFFu)) return false;
  return true;
}

TEST_F(MovieCli, FramesApngGifAndMp4AgreeWithRender) {
  const std::string common = p("grid.vtu") + " --size 80x60 --frames 6";
  std::string out;
  ASSERT_EQ(foxi("movie " + common + " -o " + p("frames/f_%03d.png"), &out), 0) << out;
  EXPECT_NE(out.find("6 frames of 80x60"), std::string::npos) << out;
  std::vector<Framebuffer> frames;
  for (int k = 0; k < 6; ++k) {
    char name[32];
    std::snprintf(name, sizeof name, "frames/f_%03d.png", k);
    frames.push_back(read_png(dir_ / name));
  }
  ASSERT_EQ(foxi("render " + p("grid.vtu") + " --size 80x60 -o " + p("full.png"), &out), 0) << out;
  EXPECT_TRUE(same_rgb(frames[3], read_png(dir_ / "full.png"))) << "the high point is the whole picture";
  Framebuffer blank(80, 60);
  EXPECT_TRUE(same_rgb(frames[0], blank));
  EXPECT_FALSE(same_rgb(frames[1], blank));
  EXPECT_FALSE(same_rgb(frames[1], frames[3]));
  EXPECT_TRUE(same_rgb(frames[2], frames[4])) << "undrawing passes the same points";

  ASSERT_EQ(foxi("movie " + common + " -o " + p("m.apng"), &out), 0) << out;
  EXPECT_TRUE(same_rgb(read_png(dir_ / "m.apng"), frames[0]));
  ASSERT_EQ(foxi("movie " + common + " -o " + p("m.gif"), &out), 0) << out;
  int err = 0;
  GifFileType* gif = DGifOpenFileName((dir_ / "m.gif").c_str(), &err);
  ASSERT_NE(gif, nullptr);
  ASSERT_EQ(DGifSlurp(gif), GIF_OK);
  EXPECT_EQ(gif->ImageCount, 6);
  DGifCloseFile(gif, &err);

  if (!test::have_program("ffmpeg")) {
    EXPECT_EQ(foxi("movie " + common + " -o " + p("m.mp4"), &out), 2) << out;
    EXPECT_NE(out.find("ffmpeg"), std::string::npos) << out;
    GTEST_SKIP() << "ffmpeg is not installed: APNG frames and MP4 not decoded";
  }
  ASSERT_EQ(test::run("ffmpeg -v error -y -i " + p("m.apng") + " " + p("dec_%d.png"), dir_ / "ff.log"), 0);
  for (int k = 0; k < 6; ++k)
    EXPECT_TRUE(same_rgb(read_png(dir_ / ("dec_" + std::to_string(k + 1) + ".png")), frames[std::size_t(k)]))
        << "APNG frame " << k;
  ASSERT_EQ(foxi("movie " + common + " --mode rotate -o " + p("m.mp4"), &out), 0) << out;
  ASSERT_EQ(
      test::run(
          "ffprobe -v error -count_frames -show_entries stream=nb_read_frames,width,height -of csv=p=0 " +
              p("m.mp4"),
          dir_ / "probe.txt"),
      0);
  EXPECT_EQ(test::read_text(dir_ / "probe.txt"), "80,60,6\n");
  // A bare file name (the frames' folder beside it in "."): a sweep of the folder's stale
  // temporaries once took the live frames for one ("./bare.mp4.foxi-tmp-..." against the tracked
  // "bare.mp4.foxi-tmp-...") and ffmpeg found none.
  ASSERT_EQ(test::run("cd " + p("") + " && '" + test::cli_path() +
                          "' movie grid.vtu --size 80x60 --frames 6 "
                          "--mode rotate -o bare.mp4",
                      dir_ / "bare.txt"),
            0)
      << test::read_text(dir_ / "bare.txt");
  ASSERT_EQ(test::run("ffprobe -v error -count_frames -show_entries stream=nb_read_frames -of csv=p=0 " +
                          p("bare.mp4"),
                      dir_ / "probe2.txt"),
            0);
  EXPECT_EQ(test::read_text(dir_ / "probe2.txt"), "6\n");
  for (const auto& e : std::filesystem::directory_iterator(dir_.path()))
    EXPECT_EQ(e.path().filename().string().find(".foxi-tmp-"), std::string::npos) << e.path();
}

TEST_F(MovieCli, RenderDepthStops) {
  std::string out;
  ASSERT_EQ(foxi("render " + p("grid.vtu") + " --size 80x60 -o " + p("full.png")), 0);
  ASSERT_EQ(foxi("render " + p("grid.vtu") + " --size 80x60 --depth -1e9 -o " + p("all.png"), &out), 0)
      << out;
  EXPECT_TRUE(same_rgb(read_png(dir_ / "all.png"), read_png(dir_ / "full.png")));
  ASSERT_EQ(foxi("render " + p("grid.vtu") + " --size 80x60 --depth 1e9 -o " + p("none.png"), &out), 0)
      << out;
  EXPECT_NE(out.find("drawn       0 of 360"), std::string::npos) << out;
  ASSERT_EQ(foxi("render " + p("grid.vtu") + " --size 80x60 --depth 12 -o " + p("some.png"), &out), 0) << out;
  EXPECT_NE(out.find("stopped at depth 12"), std::string::npos) << out;
  EXPECT_EQ(foxi("render " + p("grid.vtu") + " --depth abc -o " + p("x.png")), 2);
}

TEST_F(MovieCli, BadOptionsAreUsageErrors) {
  std::string out;
  EXPECT_EQ(foxi("movie " + p("grid.vtu") + " -o " + p("m.xyz"), &out), 2);
  EXPECT_NE(out.find(".gif"), std::string::npos) << out;
  EXPECT_EQ(foxi("movie " + p("grid.vtu") + " -o " + p("f_%s.png"), &out), 2);
  EXPECT_EQ(foxi("movie " + p("grid.vtu") + " --mode spin -o " + p("m.gif"), &out), 2);
  // A GIF's frame delay holds at most 655.35 s (it was clamped in silence); render writes PNG only.
  EXPECT_EQ(foxi("movie " + p("grid.vtu") + " --fps 0.001 -o " + p("m.gif"), &out), 2);
  EXPECT_NE(out.find("655.35 s"), std::string::npos) << out;
  EXPECT_EQ(foxi("render " + p("grid.vtu") + " -o " + p("r.jpg"), &out), 2);
  EXPECT_NE(out.find("writes PNG"), std::string::npos) << out;
  EXPECT_FALSE(std::filesystem::exists(dir_ / "r.jpg"));
  EXPECT_EQ(foxi("movie " + p("grid.vtu") + " --frames 1 -o " + p("m.gif"), &out), 2);
  EXPECT_EQ(foxi("movie " + p("grid.vtu") + " --from 60% --to 40% -o " + p("m.gif"), &out), 2);
  EXPECT_EQ(foxi("movie " + p("missing.vtu") + " -o " + p("m.gif"), &out), 3);
  EXPECT_FALSE(std::filesystem::exists(dir_ / "m.gif"));
  EXPECT_EQ(foxi("movie --help", &out), 0);
  EXPECT_NE(out.find("backforth"), std::string::npos);
}

}  // namespace
}  // namespace foxi
