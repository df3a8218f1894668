// foxi: the command-line program. Subcommands are plain functions in cmd_*.cpp.
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "cli.hpp"
#include "exit_codes.hpp"
#include "model_run.hpp"
#include "foxi/mesher/model_mesh.hpp"
#include "foxi/solver/solver.hpp"
#include "foxi/model/io_error.hpp"
#include "foxi/viz/view_options.hpp"
#include "foxi/model/progress.hpp"
#include "foxi/model/units.hpp"
#include "foxi/version.hpp"
#include "signals.hpp"

namespace {

const char* kUsage =
    "foxi - finite-element pre/post-processor (meshes, fields, Delaunay visibility ordering)\n"
    "\n"
    "usage: foxi COMMAND [options]\n"
    "\n"
    "commands:\n"
    "  model check|plc|show MODEL.toml  parametrized structure: report it, write its PLC (-o OUT.poly)\n"
    "                 or a picture of its parts (-o OUT.png)\n"
    "  demo [MODEL]   one model end to end: mesh, certificate, steady heat, pictures (-o DIR)\n"
    "  mesh MODEL.toml|PLC.poly  certified conforming Delaunay tets (-o OUT, --max-size, --quality,\n"
    "                 --refine-box, --refine-from), with a quality report\n"
    "  info MESH      counts, bounding box, regions, boundaries, fields and their ranges, volume,\n"
    "                 tet quality, validation; --json for machine-readable output; --check-delaunay\n"
    "  convert IN OUT convert between mesh formats (format from the extension)\n"
    "  order MESH     visibility order for views (--eye, --dir, --views N), with violation counts\n"
    "  solve MESH|MODEL.toml  --physics thermal: temperatures, heat per boundary; electrostatic: the\n"
    "                 capacitance matrix; current: resistance, Joule heat; thermoelastic:\n"
    "                 thermal stress, max von Mises and where; -o OUT.vtu; --json: the figures\n"
    "                 as JSON; --convergence K: the solve on K finer meshes, observed order\n"
    "  sweep MODEL.toml  the model solved over a grid of parameter values (--vary die_w=2mm:8mm:7),\n"
    "                 in parallel, one CSV row per run with its key results (-o SWEEP.csv)\n"
    "  render MESH    a PNG picture of the interior (painter, visibility order); -o OUT.png;\n"
    "                 --field NAME colours it by a field (flat or --graded) with a legend\n"
    "  probe RESULT   a field's value at points (--field NAME --at x,y,z): tet, region, value, units\n"
    "  plot RESULT    a field along a segment (--field NAME --line A:B -o PLOT.csv)\n"
    "  movie MESH     draw/undraw back and forth, or turn the view: -o OUT.gif|.apng|.mp4|frames\n"
    "\n"
    "mesh formats: .msh (Gmsh 2.2/4.1, ASCII/binary), .vtu (VTK XML), .vtk (VTK legacy),\n"
    "              .node/.ele/.face (TetGen), .mesh (Medit)\n"
    "\n"
    "'foxi COMMAND --help' describes a command.\n"
    "\n"
    "exit status: 0 ok, 1 failure, 2 usage error, 3 bad input (file, model, parameter),\n"
    "             4 a result that failed its own checks, 130 SIGINT, 143 SIGTERM\n";

}  // namespace

int main(int argc, char** argv) {
  using namespace foxi::cli;
  // Line by line into a file or pipe as on a terminal: a run stopped by a signal (which exits
  // without flushing) or one that fails keeps the report lines it printed before.
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty() || args[0] == "--help" || args[0] == "-h" || args[0] == "help") {
    std::fputs(kUsage, stdout);
    return args.empty() ? kExitUsage : kExitOk;
  }
  if (args[0] == "--version") {
    std::puts("foxi " FOXI_VERSION_STRING);
    return kExitOk;
  }
  std::string command = args[0];
  foxi::cli::handle_stop_signals("foxi " + command);  // SIGINT/SIGTERM: exit 130/143, nothing partial left
  foxi::cli::Args rest(std::vector<std::string>(args.begin() + 1, args.end()));
  try {
    if (command == "info") return foxi::cli::cmd_info(std::move(rest));
    if (command == "convert") return foxi::cli::cmd_convert(std::move(rest));
    if (command == "order") return foxi::cli::cmd_order(std::move(rest));
    if (command == "mesh") return foxi::cli::cmd_mesh(std::move(rest));
    if (command == "render") return foxi::cli::cmd_render(std::move(rest));
    if (command == "movie") return foxi::cli::cmd_movie(std::move(rest));
    if (command == "solve") return foxi::cli::cmd_solve(std::move(rest));
    if (command == "model") return foxi::cli::cmd_model(std::move(rest));
    if (command == "demo") return foxi::cli::cmd_demo(std::move(rest));
    if (command == "sweep") return foxi::cli::cmd_sweep(std::move(rest));
    if (command == "fields") return foxi::cli::cmd_fields(std::move(rest));
    if (command == "probe") return foxi::cli::cmd_probe(std::move(rest));
    if (command == "plot") return foxi::cli::cmd_plot(std::move(rest));
    if (command == "export-ccx") return foxi::cli::cmd_export_ccx(std::move(rest));
    std::fprintf(stderr, "foxi: unknown command '%s'\n\n%s", command.c_str(), kUsage);
    return kExitUsage;
  } catch (const UsageError& e) {
    std::fprintf(stderr, "foxi %s: %s\n", command.c_str(), e.what());
    return kExitUsage;
  } catch (const foxi::OptionError& e) {  // a malformed picture option (view_options.hpp)
    std::fprintf(stderr, "foxi %s: %s\n", command.c_str(), e.what());
    return kExitUsage;
  } catch (const InputError& e) {
    std::fprintf(stderr, "foxi %s: error: %s\n", command.c_str(), e.what());
    return kExitBadInput;
  } catch (const foxi::TetLimitError& e) {  // a mesh estimated past --max-tets, refused before meshing
    std::fprintf(stderr, "foxi %s: error: %s\n", command.c_str(), tet_limit_message(e).c_str());
    return kExitBadInput;
  } catch (const foxi::WriteError& e) {  // a full disk, an I/O error: the work failed, not the input
    std::fprintf(stderr, "foxi %s: error: %s\n", command.c_str(), e.what());
    return kExitFailure;
  } catch (const foxi::IoError& e) {
    // Files that cannot be read or are not what they claim, model files and their parameters.
    std::fprintf(stderr, "foxi %s: error: %s\n", command.c_str(), e.what());
    return kExitBadInput;
  } catch (const foxi::ExpressionError& e) {
    std::fprintf(stderr, "foxi %s: error: %s\n", command.c_str(), e.what());
    return kExitBadInput;
  } catch (const foxi::SolverInputError& e) {  // the problem as given (coefficients, conditions, tags)
    std::fprintf(stderr, "foxi %s: error: %s\n", command.c_str(), e.what());
    return kExitBadInput;
  } catch (const foxi::Cancelled& c) {  // a progress function said stop (an interrupt), in any library
    const auto* e = dynamic_cast<const std::exception*>(&c);
    std::fprintf(stderr, "foxi %s: %s\n", command.c_str(), e ? e->what() : "cancelled");
    return kExitInterrupted;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "foxi %s: error: out of memory\n", command.c_str());
    return kExitFailure;
  } catch (const std::exception& e) {  // the mesher, the solver, a writer, ...
    std::fprintf(stderr, "foxi %s: error: %s\n", command.c_str(), e.what());
    return kExitFailure;
  }
}
