// What foxi-workbench's source files share (not installed, not a public header): the outcome a
// worker hands back, the running job, and the helpers one panel's file defines and another calls.
// The files: workbench.cpp (the window, its status bar and keys), model_panel.cpp (model and
// parameters), mesh_panel.cpp (mesh settings and quality report), solve_panel.cpp (results table),
// view_panel.cpp (the view and its field tools), jobs.cpp (mesh/solve workers, progress, Cancel, results
// shown), project.cpp (save/open/autosave), history.cpp (run history).
#pragma once

#include <QFutureWatcher>
#include <QPixmap>
#include <QString>
#include <QTimer>
#include <atomic>
#include <exception>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "foxi/mesher/model_mesh.hpp"
#include "foxi/mesher/quality_report.hpp"
#include "foxi/model/physics.hpp"
#include "foxi/model/progress.hpp"
#include "foxi/solver/results.hpp"
#include "foxi/solver/solver.hpp"
#include "foxi/viz/camera.hpp"
#include "foxi/viz/colormap.hpp"
#include "foxi/viz/interactive_view.hpp"
#include "workbench.hpp"

namespace foxi::workbench {

struct Outcome {
  bool ok = false, cancelled = false;
  bool bad_input = false;  // the error is the model's (IoError: file, line, reason)
  QString error;
  bool meshed = false, solved = false;
  std::string path;  // the model file (meshed: the mesh's)
  std::shared_ptr<const Mesh> mesh;
  std::shared_ptr<const Mesh> view_mesh;  // the deformed copy the view shows (null: `mesh`)
  std::shared_ptr<const Model> model;
  std::vector<ParameterOverride> overrides;
  std::unique_ptr<InteractiveView> view;
  std::vector<double> probe;  // per tet, display unit
  QString probe_unit, field_label;
  ColorScale scale;
  // The volume's scale: the automatic range of the corner values (a volume shows the field between
  // the nodes, foxi render's rule), else `scale`.
  ColorScale volume_scale;
  DisplayUnit unit;
  bool has_scale = false;
  std::vector<std::uint32_t> base;    // the tets of the regions shown (empty: all)
  std::optional<FieldChoice> choice;  // the field shown, for the field tools
  std::size_t step = 0;
  std::shared_ptr<IsoCache> iso_cache;  // built here, on the worker: the tools then only query
  double corner_lo = 0, corner_hi = 0;  // the corner values' range, SI
  RunResults results;
  double seconds = 0;                        // meshing; a recolour's: building the picture
  double solve_seconds = 0;                  // the solve
  std::optional<MeshQualityReport> quality;  // a new mesh's
  QString mesher_summary;                    // and which mesher made it (mesh_panel.cpp)
  MeshSettings mesh_settings;                // the mesh settings it was made with
  bool sweep = false;                        // a sweep's: its points' rows, nothing shown
  std::vector<HistoryRow> sweep_rows;
};

// What a worker reports beside the stage: the iterative solve's iteration and relative residual, a
// sweep's point (1-based) of how many. Written by the worker, read by the GUI thread's poll.
struct SolveProgress {
  std::atomic<long> iteration{0};
  std::atomic<double> residual{0};
  std::atomic<int> point{0}, points{0};
};

struct Workbench::Job {
  std::shared_ptr<std::atomic<bool>> cancel;
  std::shared_ptr<std::atomic<int>> permille;
  std::shared_ptr<SolveProgress> solve;  // null: a job without a solve
  QFutureWatcher<std::shared_ptr<Outcome>> watcher;
  QString what;
};

// Whether two override lists are the same, name and expression, in order (jobs.cpp).
bool same_overrides(const std::vector<ParameterOverride>& a, const std::vector<ParameterOverride>& b);
struct Workbench::MovieJob {
  std::shared_ptr<std::atomic<bool>> cancel = std::make_shared<std::atomic<bool>>(false);
  std::shared_ptr<std::atomic<int>> permille = std::make_shared<std::atomic<int>>(0);
  QFutureWatcher<QString> watcher;  // the worker's result: empty when written, else the reason
  QTimer poll;
  ~MovieJob() {
    cancel->store(true);
    watcher.waitForFinished();
  }
};

// The stage (1, 2, ...) of a progress value stage * 10000 + permille; "" for 0 (jobs.cpp).
const char* progress_stage(int index);
// The progress bar's text for the running job: what, the stage, %p%, the iteration and residual of an
// iterative solve, a sweep's point k of n (jobs.cpp).
QString progress_format(const QString& what, int permille, const SolveProgress* solve);
// A job's duration as the progress bar says it: "1.25 s", under 0.1 s in milliseconds ("3.14 ms"), so a
// quick recolour does not read "0.00 s" (jobs.cpp).
QString duration_text(double seconds);

// The display of `mesh` on the worker: the field's paint, flat or graded, on the automatic scale or
// the user's range (as foxi render --field NAME --cmap MAP [--graded] [--range a,b] draws it) and the
// view, built with `camera` (null: the default) (view_panel.cpp).
void build_display(Outcome& out, const Mesh& mesh, const std::string& field, const Colouring& colouring,
                   double shrink, int w, int h, const Camera* camera);

// The unit a value of SI unit `si_unit` is shown in: SI itself (`si`) or the engineer's
// (default_display_unit, by the largest magnitude shown) (solve_panel.cpp).
DisplayUnit unit_for(const std::string& si_unit, double max_abs, bool si);

// A colour bar with ticks in the field's display unit (view_panel.cpp).
QPixmap legend_pixmap(const ColorScale& s, const DisplayUnit& unit, const QString& label, int height);

// The minimum dihedral angle histogram of the quality report as a bar chart (mesh_panel.cpp).
QPixmap histogram_pixmap(const MeshQualityReport& q);

// The mesh panel's widgets (mesh_panel.cpp).
struct MeshControls {
  QComboBox* mesher = nullptr;
  QLineEdit *max_size = nullptr, *quality = nullptr, *target_error = nullptr;
  QTableWidget *parts = nullptr, *boxes = nullptr;
  QCheckBox* refine = nullptr;
  QComboBox* refine_field = nullptr;
  QLabel* error = nullptr;
};

// mesh_model's options (model_mesh.hpp) with the mesh panel's settings; `result` is the solved mesh
// to refine from (null: none; then refine_from_result fails with the reason), `shown_field` the
// field the view shows (refined from when the settings name none) (mesh_panel.cpp).
void apply_mesh_settings(ModelMeshOptions& options, const MeshSettings& settings, const Mesh* result,
                         const std::string& shown_field);
// The first line of the quality report: which mesher made the mesh, and for CGAL the region volumes
// against the PLC's (mesh_panel.cpp).
QString mesher_summary(const MeshedModel& m);
// The same settings (mesh_panel.cpp): a solve remeshes first when they differ from the shown mesh's.
bool same_mesh_settings(const MeshSettings& a, const MeshSettings& b);
// The settings in words, lengths in the model's unit (`scale` metres, named `unit`): a history row's
// tooltip, one item a line.
QString mesh_settings_text(const MeshSettings& s, double scale, const std::string& unit);

// Whether CalculiX solves `physics` here (thermal, thermal_stress) (solve_panel.cpp).
bool calculix_solves(Physics physics);
// The physics named as foxi solve --physics names it (physics_name), or nullopt (solve_panel.cpp).
std::optional<Physics> physics_of(const std::string& name);
// The solve panel's solver by the name foxi solve --solver gives it (auto, direct, amg, ichol) or
// ccx for CalculiX (foxi solve --with ccx), or nullopt (solve_panel.cpp).
std::optional<SolverChoice> solver_of(const std::string& name);
// The field a solve of `physics` is shown by: temperature, potential, von_mises (solve_panel.cpp).
const char* solved_field(Physics physics);
// Solves `physics` on `mesh` (its fields written there) with the model's conditions and loads, as
// foxi solve MODEL --physics NAME does (with `solver.kind` as its --solver); the results record with
// its checks. With `calculix`: a thermal or thermal stress solve by ccx, as foxi solve MODEL --physics
// thermal|thermoelastic --with ccx does (SolverError for another physics; Cancel kills ccx). `solver`'s
// progress and iterations report and cancel. Errors: IoError on the model file (`path`) for what the model
// lacks, SolverError, Cancelled when a callback says stop.
RunResults solve_model_physics(const std::string& path, const Model& model, Mesh& mesh, Physics physics,
                               const LinearSolverOptions& solver, bool calculix = false);
// The progress callbacks of a job's solve: the stage and its permille into `permille` (stage * 10000 +
// permille, never back within a stage), the iterations into `solve`; all false once `cancel` is set.
LinearSolverOptions job_solver_options(LinearSolverKind kind, std::shared_ptr<std::atomic<bool>> cancel,
                                       std::shared_ptr<std::atomic<int>> permille,
                                       std::shared_ptr<SolveProgress> solve);

inline QString what_of(const std::exception& e) { return QString::fromStdString(e.what()); }

}  // namespace foxi::workbench
