// foxi movie MESH: the painter's movies (seed paper, section 6.1): back-and-forth (draw back to
// front, undraw front to back) or a rotating view, as numbered PNG frames, an animated PNG, a GIF,
// or an MP4 (through the ffmpeg program, when it is installed).
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <system_error>
#include <vector>

#include "cli.hpp"
#include "exit_codes.hpp"
#include "field_options.hpp"
#include "mesh_input.hpp"
#include "foxi/model/cleanup.hpp"
#include "foxi/model/durable_file.hpp"
#include "foxi/model/mesh_io.hpp"
#include "foxi/viz/animation.hpp"
#include "foxi/viz/movie.hpp"
#include "foxi/viz/png.hpp"
#include "foxi/viz/spheres.hpp"
#include "render_options.hpp"
#include "signals.hpp"

namespace foxi::cli {

namespace {

const std::string kMovieUsage = std::string(
    "foxi movie MESH [camera and picture options] [--mode backforth|rotate] [--frames N]\n"
    "                [--cycles C] [--from P%] [--to P%] [--turn deg] [--fps F]\n"
    "                [--field NAME[:C] [--graded] [--cmap M] [--range a,b] [--log] [--units U] [--step k]\n"
    "                [--legend on|off]]\n"
    "                -o OUT.gif|OUT.apng|OUT.mp4|DIR/frame_%04d.png\n"
    "  A movie of the painter. backforth (the default): the tets drawn back to front in the\n"
    "  visibility order from --from to --to percent of the order (default 0% to 100%), then\n"
    "  undrawn front to back (the seed paper's undraw: back faces repainted as the neighbour's\n"
    "  front face, or restored from saved pixels), N frames per cycle, looping seamlessly.\n"
    "  rotate: the camera turned --turn degrees (default 360) about its up axis through --at over\n"
    "  N frames, each frame the first --to percent of its own order.\n") +
    kPictureOptionsHelp + kFieldOptionsHelp +
    "  (--size defaults to 640x480; with --field the colour range is the same in every frame)\n"
    "  --frames N      frames per cycle (default 48), --cycles C cycles (default 1)\n"
    "  --fps F         frames per second of the animated file (default 12)\n"
    "  -o              .gif (giflib, 256 colours per frame), .apng (animated PNG), .mp4 (needs the\n"
    "                  ffmpeg program), or a name with a printf number, e.g. out/frame_%04d.png:\n"
    "                  numbered PNG frames (the folder is created)\n"
    "  Meshes that fail the Delaunay certificate have no visibility order and are refused (exit\n"
    "  status 3), as are unusable ones (see foxi info); inverted tets are re-oriented (a note says so).";

double percent(const std::string& s, const char* what, double fallback) {
  if (s.empty()) return fallback;
  std::string v = s;
  if (v.back() == '%') v.pop_back();
  char* end = nullptr;
  const double p = std::strtod(v.c_str(), &end);
  if (v.empty() || *end != 0 || !(p >= 0 && p <= 100))
    throw UsageError(std::string(what) + " takes a percentage 0..100, e.g. 40%");
  return p / 100;
}

long whole(const std::string& s, const char* what, long fallback, long lo, long hi) {
  if (s.empty()) return fallback;
  char* end = nullptr;
  const long v = std::strtol(s.c_str(), &end, 10);
  if (*end != 0 || v < lo || v > hi)
    throw UsageError(std::string(what) + " takes a whole number in " + std::to_string(lo) + ".." + std::to_string(hi));
  return v;
}

// True if `pattern` holds exactly one printf integer conversion (%d or %0Nd) and no other '%'.
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

// Looked up in PATH here rather than by a shell: a child process foxi does not track could outlive a stop.
bool have_ffmpeg() {
  const char* path = std::getenv("PATH");
  std::string dirs = path ? path : "/usr/bin:/bin";
  std::size_t at = 0;
  while (at <= dirs.size()) {
    const std::size_t colon = std::min(dirs.find(':', at), dirs.size());
    const std::string dir = dirs.substr(at, colon - at);
    const std::string exe = (dir.empty() ? std::string(".") : dir) + "/ffmpeg";
    if (::access(exe.c_str(), X_OK) == 0 && !std::filesystem::is_directory(exe)) return true;
    at = colon + 1;
  }
  return false;
}

}  // namespace

int cmd_movie(Args args) {
  if (args.flag("--help") || args.flag("-h")) {
    std::puts(kMovieUsage.c_str());
    return kExitOk;
  }
  const std::string mode = args.option("--mode", "backforth");
  const std::string frames_s = args.option("--frames"), cycles_s = args.option("--cycles");
  const std::string from_s = args.option("--from"), to_s = args.option("--to"), turn_s = args.option("--turn");
  const std::string fps_s = args.option("--fps", "12");
  std::string out = args.option("-o");
  if (out.empty()) out = args.option("--output");
  PictureOptions options = take_picture_options(args, "640x480");
  const FieldOptions field_options = take_field_options(args);
  if (field_options.markers) throw UsageError("--markers marks a picture: foxi render takes it, foxi movie does not");
  const std::string path = args.positional(1, 1, kMovieUsage)[0];
  if (out.empty()) throw UsageError("give the output with -o OUT.gif|OUT.apng|OUT.mp4|DIR/frame_%04d.png");
  if (mode != "backforth" && mode != "rotate") throw UsageError("--mode takes backforth or rotate");
  MovieParams mp;
  mp.rotate = mode == "rotate";
  mp.frames = int(whole(frames_s, "--frames", 48, 2, 100000));
  mp.cycles = int(whole(cycles_s, "--cycles", 1, 1, 1000));
  mp.from = percent(from_s, "--from", 0);
  mp.to = percent(to_s, "--to", 1);
  if (mp.from > mp.to) throw UsageError("--from must not exceed --to");
  if (!turn_s.empty()) {
    char* end = nullptr;
    mp.turn_deg = std::strtod(turn_s.c_str(), &end);
    if (*end != 0 || !std::isfinite(mp.turn_deg)) throw UsageError("--turn takes degrees");
  }
  char* fps_end = nullptr;
  const double fps = std::strtod(fps_s.c_str(), &fps_end);
  if (*fps_end != 0 || !(fps > 0 && fps <= 100)) throw UsageError("--fps takes a rate in (0, 100]");

  enum class Kind { frames, gif, apng, mp4 } kind;
  const std::string ext = std::filesystem::path(out).extension().string();
  if (out.find('%') != std::string::npos) {
    if (!frame_pattern(out)) throw UsageError("-o " + out + ": a frame name needs one %d or %0Nd and no other %");
    kind = Kind::frames;
  } else if (ext == ".gif") {
    kind = Kind::gif;
  } else if (ext == ".apng") {
    kind = Kind::apng;
  } else if (ext == ".mp4") {
    kind = Kind::mp4;
    if (!have_ffmpeg())
      throw UsageError("-o " + out + ": MP4 needs the ffmpeg program, which is not installed (write .gif, .apng or frames)");
  } else {
    throw UsageError("-o " + out + ": give .gif, .apng, .mp4 or a numbered frame name like dir/frame_%04d.png");
  }
  if (kind != Kind::frames) check_output_path(out);  // before the work (frames: once their folder is made)

  const Mesh mesh = read_usable_mesh(path, "movie");
  Picture picture = resolve_picture(options, mesh);
  // Colour by a field: one paint (one range) for the whole movie; the legend drawn once into a frame
  // whose left part each movie frame fills.
  FieldPicture field;
  Framebuffer framed;
  if (!field_options.spec.empty()) {
    field = resolve_field(field_options, mesh, picture.subset, path);
    options.params.field = field.paint;
    if (field_options.legend) {
      const TextRenderer text(find_font_file());
      const int panel = legend_panel(text, field, options.width, options.height);
      framed = with_legend(Framebuffer(options.width - panel, options.height), text, field, panel);
      options.width -= panel;
      picture = resolve_picture(options, mesh);
    }
  }
  mp.render = options.params;
  const SphereTable table = compute_spheres(mesh);

  AnimationParams ap;
  ap.width = framed.width > 0 ? framed.width : options.width;
  ap.height = options.height;
  ap.fps = fps;
  std::unique_ptr<AnimationWriter> writer;
  // Numbered frames (and the mp4's frames for ffmpeg) are written as DurableFile temporaries and
  // committed together at the end: a stopped or failed movie leaves no frame behind.
  std::vector<DurableFile> frames;
  std::filesystem::path frame_dir;  // mp4: the PNG frames for ffmpeg, a tracked temporary folder
  std::string pattern = out;
  if (kind == Kind::gif) writer = open_gif(out, ap);
  if (kind == Kind::apng) writer = open_apng(out, ap);
  if (kind == Kind::mp4) {
    frame_dir = std::filesystem::path(out + ".foxi-tmp-" + std::to_string(::getpid()) + "-frames");
    cleanup::with_lock([&] {
      cleanup::track(frame_dir, true);
      std::filesystem::create_directories(frame_dir);
    });
    pattern = (frame_dir / "frame_%06d.png").string();
  }
  std::filesystem::path created;  // the first folder of the frames' path that this run created
  if (kind == Kind::frames) {
    const std::filesystem::path parent = std::filesystem::path(frame_name(pattern, 0)).parent_path();
    if (!parent.empty()) {
      for (std::filesystem::path p = parent; !p.empty() && !std::filesystem::exists(p); p = p.parent_path()) {
        created = p;
        if (p == p.parent_path()) break;
      }
      cleanup::with_lock([&] {
        if (!created.empty()) cleanup::track(created, true);
        std::filesystem::create_directories(parent);
      });
    }
    check_output_path(frame_name(pattern, 0));
    // Once for the folder rather than once per frame (each a reading of the whole folder).
    remove_stale_temporaries_in(std::filesystem::path(frame_name(pattern, 0)).parent_path().empty()
                                    ? std::filesystem::path(".")
                                    : std::filesystem::path(frame_name(pattern, 0)).parent_path());
  }
  struct Forget {
    std::filesystem::path dir;
    bool remove;
    ~Forget() {
      std::error_code ec;
      if (!dir.empty() && remove) std::filesystem::remove_all(dir, ec);
      if (!dir.empty()) cleanup::untrack(dir);
    }
  } forget_frames{frame_dir, true}, forget_created{created, true};

  std::size_t index = 0;
  const auto t0 = std::chrono::steady_clock::now();
  MovieStats stats;
  try {
    stats = make_movie(mesh, table, picture.camera, options.width, options.height, picture.subset, mp,
                                      [&](const Framebuffer& scene) {
                                        const Framebuffer* fb = &scene;
                                        if (framed.width > 0) {  // the scene beside the legend
                                          for (int y = 0; y < scene.height; ++y)
                                            std::copy_n(scene.rgba.begin() + std::ptrdiff_t(scene.index(0, y)),
                                                        scene.width,
                                                        framed.rgba.begin() + std::ptrdiff_t(framed.index(0, y)));
                                          fb = &framed;
                                        }
                                        if (writer) {
                                          writer->add(*fb);
                                        } else {
                                          frames.emplace_back(frame_name(pattern, index), false);
                                          write_png(frames.back(), *fb);
                                        }
                                        ++index;
                                      });
  } catch (const UncertifiedMeshError&) {  // thrown before the first frame: nothing written
    throw InputError(path + " fails the Delaunay certificate: it has no visibility order to make a "
                            "movie with (foxi render --zbuffer draws it)");
  }
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  if (writer) writer->finish();
  if (!writer) commit_together(frames);  // numbered frames, or ffmpeg's input
  if (kind == Kind::frames) forget_created.remove = false;  // the frames are in it now
  if (kind == Kind::mp4) {
    DurableFile video(out);
    const std::vector<std::string> ffmpeg = {
        "ffmpeg", "-y", "-loglevel", "error", "-framerate", std::to_string(fps), "-i",
        (frame_dir / "frame_%06d.png").string(), "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2", "-pix_fmt", "yuv420p",
        "-c:v", "libx264", "-f", "mp4", video.temp().string()};
    if (run_program(ffmpeg) != 0) throw std::runtime_error(out + ": ffmpeg failed to encode the frames");
    video.commit();
  }
  std::printf("mesh        %s: %zu tets, %zu shown\n", path.c_str(), mesh.tet_count(),
              picture.subset.empty() ? mesh.tet_count() : picture.subset.size());
  std::printf("movie       %s, %zu frames of %dx%d, %.1f ms per frame (frames written included)\n", mode.c_str(),
              stats.frames, ap.width, options.height, ms / double(std::max<std::size_t>(1, stats.frames)));
  std::printf("painter     %zu tets drawn, %zu undrawn, undraw memory at most %.1f MB\n", stats.tets_drawn,
              stats.tets_undrawn, double(stats.max_undo_bytes) / 1e6);
  if (field.paint) {
    const DisplayUnit& u = field.legend.unit;
    std::printf("field       %s, step %zu, %s, %s%s, colours %.6g to %.6g%s%s in every frame%s\n",
                field.legend.title.c_str(), field.step, field_options.graded ? "graded facets" : "flat per tet",
                color_map_name(field.legend.scale.map), field.legend.scale.log ? " log" : "",
                u.to_display(field.legend.scale.lo), u.to_display(field.legend.scale.hi), u.symbol.empty() ? "" : " ",
                u.symbol.c_str(), framed.width > 0 ? ", legend at the right" : "");
  }
  std::printf("wrote       %s\n", out.c_str());
  return kExitOk;
}

}  // namespace foxi::cli
