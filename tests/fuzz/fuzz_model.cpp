// Fuzz target: the model file (TOML -> parameters, materials, parts, conditions; load_model, which
// does not mesh). The input is written to model.toml in a private folder that also holds a copy of
// models/materials.toml, so that `library = "materials.toml"` resolves as in the shipped models. Any
// input gives a model or an IoError naming the model file (or the library it names); never a crash,
// a hang, an over-allocation or another exception.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <system_error>
#include <unistd.h>

#include "foxi/model/model_file.hpp"
#include "fuzz_util.hpp"

namespace fs = std::filesystem;

namespace {

const fs::path& work_dir() {
  static const fs::path dir = [] {
    const fs::path d = fs::temp_directory_path() / ("foxi-fuzz-model-" + std::to_string(::getpid()));
    fs::create_directories(d);
    fs::copy_file(fs::path(FOXI_MODELS_DIR) / "materials.toml", d / "materials.toml",
                  fs::copy_options::overwrite_existing);
    // Removed at exit (libFuzzer leaves through exit() after its runs).
    std::atexit([] {
      std::error_code ec;
      fs::remove_all(fs::temp_directory_path() / ("foxi-fuzz-model-" + std::to_string(::getpid())), ec);
    });
    return d;
  }();
  return dir;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const fs::path path = work_dir() / "model.toml";
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  try {
    const foxi::Model m = foxi::load_model(path);
    // A model that loads is geometry the mesher can take: finite coordinates, prisms of positive
    // height, surface triangles naming vertices that exist.
    for (const foxi::Part& p : m.parts) {
      FOXI_FUZZ_CHECK(!p.name.empty(), "a part without a name");
      for (const foxi::Prism& q : p.prisms) {
        FOXI_FUZZ_CHECK(q.xy.size() % 2 == 0 && q.xy.size() >= 6, p.name);
        for (double x : q.xy) FOXI_FUZZ_CHECK(std::isfinite(x), p.name);
        FOXI_FUZZ_CHECK(std::isfinite(q.z0) && std::isfinite(q.z1) && q.z0 < q.z1, p.name);
      }
      for (double x : p.surface.xyz) FOXI_FUZZ_CHECK(std::isfinite(x), p.name);
      for (std::uint32_t v : p.surface.tri) FOXI_FUZZ_CHECK(v < p.surface.vertex_count(), p.name);
    }
    for (const foxi::Parameter& q : m.parameters) FOXI_FUZZ_CHECK(std::isfinite(q.value.value), q.name);
  } catch (const foxi::IoError& e) {
    FOXI_FUZZ_CHECK(std::string_view(e.what()).find(e.file()) != std::string_view::npos, e.what());
    FOXI_FUZZ_CHECK(!e.file().empty(), e.what());
  }
  return 0;
}
