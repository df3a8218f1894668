// foxi-workbench's main window: a model file's parameters edited with units (checked by the model
// library's own load_model), the model meshed (mesh_model) and solved (thermal, electrostatic, DC
// current or thermal stress from the model's conditions: the results record and balance checks) on worker
// threads with a progress bar and Cancel, the result shown on the foxi::qt view with a field, a colour map
// and a legend, and a history of the runs. Every operation that can take long runs on a worker
// (QtConcurrent); the GUI thread only presents, and the previous mesh and picture stay shown until a new one
// is ready.
#pragma once

#include <QFuture>
#include <QImage>
#include <QMainWindow>
#include <QString>
#include <QStringList>
#include <atomic>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "foxi/mesher/model_mesh.hpp"
#include "foxi/model/mesh.hpp"
#include "foxi/model/model_file.hpp"
#include "foxi/model/physics.hpp"
#include "foxi/qt/view_widget.hpp"
#include "foxi/solver/results.hpp"
#include "foxi/solver/solver.hpp"
#include "foxi/viz/camera.hpp"
#include "foxi/viz/field_paint.hpp"
#include "foxi/viz/field_selection.hpp"

class QCheckBox;
class QComboBox;
class QDoubleSpinBox;
class QHBoxLayout;
class QLabel;
class QLineEdit;
class QListWidget;
class QProgressBar;
class QPushButton;
class QSlider;
class QTableWidget;
class QPlainTextEdit;
class QTimer;

namespace foxi::workbench {

// The deformed shape (foxi render --deform NAME:SCALE): each node moved by scale x the node vector
// field (a thermal stress solve's displacement).
struct Deform {
  std::string field = "displacement";
  double scale = 1;
};

// How the field is coloured: the map, flat or graded, the automatic range or the user's (display unit);
// and what is drawn: the regions hidden, the deformed shape.
struct Colouring {
  std::string cmap = "viridis";
  bool graded = false;
  std::optional<std::pair<double, double>> range;
  std::vector<std::int32_t> hidden;  // regions hidden
  std::optional<Deform> deform;
  // The unit values are shown in, the legend's and the results table's alike: the engineer's (°C,
  // MPa, µm, mV: default_display_unit) or SI (K, Pa, m, V).
  bool si_units = false;
};

// Which solver Solve runs: foxi's own (its linear solver: automatic, direct, CG) or CalculiX (ccx,
// a child process: thermal and thermal stress, as foxi solve --physics thermal|thermoelastic --with ccx
// takes them).
struct SolverChoice {
  bool calculix = false;
  LinearSolverKind linear = LinearSolverKind::automatic;
};

// The mesh panel's choices (mesh_panel.cpp), given to mesh_model's options (model_mesh.hpp) by every
// mesh job. Lengths in metres; unset or empty: the model's [mesh] table.
struct MeshSettings {
  Mesher mesher = Mesher::tetgen;
  std::optional<double> max_size;
  std::vector<PartSize> part_sizes;  // by part name: replace the model's size of that part
  std::optional<double> quality;     // radius-edge bound (TetGen: 0 or >= 1.414; CGAL: its cell bound)
  std::vector<RefinementBox> boxes;  // added to the model's [[mesh.refine]] boxes (either mesher)
  // Refine from the current result: the next mesh's sizes from the Zienkiewicz-Zhu error of the
  // result's node field `refine_field` (empty: the field shown, else the first), for this relative
  // gradient error. TetGen only; a mesh job without a solved result then fails with the reason.
  bool refine_from_result = false;
  std::string refine_field;
  double target_error = 0.1;
};

// One row of the run history.
struct HistoryRow {
  std::vector<ParameterOverride> parameters;  // the overrides of that run
  std::size_t mesh = 0;  // which mesh (1, 2, ... in the session): a solve completes its mesh's row
  std::size_t tets = 0;
  RunResults results;  // status failed with no values: meshed only
  double seconds = 0;  // mesh + solve wall time
  // The mesh panel's settings that made the row's mesh (none: a project saved before rows kept them).
  std::optional<MeshSettings> mesh_settings;
};

// What a worker hands back (mesh, solve or a new field paint).
struct Outcome;
struct MeshControls;  // the mesh panel's widgets (workbench_parts.hpp)
struct ProjectSnapshot;
struct SolveProgress;

class Workbench : public QMainWindow {
  Q_OBJECT

 public:
  explicit Workbench(QWidget* parent = nullptr);
  ~Workbench() override;

  // The window's size and panels as the user left them (QSettings: ~/.config/foxi/foxi-workbench.conf;
  // saved on close). Not in headless runs, whose pictures must not depend on a user's settings.
  void restore_settings();

  // Loads the model file; false with the error (file:line: reason) in `error` and shown.
  bool open_model(const QString& path, QString* error = nullptr);
  // Sets parameter `name` to `expression` ("5 mm", "2 * die_w"), checked by loading the model with
  // it: false (nothing changes) with the library's message (file:line: reason) for an unknown name,
  // a unit of another dimension, a bad expression.
  bool set_parameter(const QString& name, const QString& expression, QString* error = nullptr);
  // Undo / redo of parameter edits (Ctrl+Z, Ctrl+Shift+Z); false when there is nothing to undo or
  // redo (or the model file no longer loads with those values).
  bool undo();
  bool redo();
  // Writes the open model file with the current parameter values to `path` (empty: over the open
  // file) by save_model (foxi/model/model_save.hpp: only the values' text changes, references stay
  // valid, refused unless it loads back equal); the workbench then works on the saved file with no
  // overrides. False (nothing written) with the reason (file:line: reason) in `error` and shown.
  bool save_model_file(const QString& path = {}, QString* error = nullptr);
  // The model panel's exploded parts picture: foxi model show's (the same coarse mesh, drawing and
  // colours, draw_model_picture) of `model` with `overrides`, width x height. A null image with the
  // reason in `error` when the model does not mesh. Static: the panel runs it on a worker.
  static QImage parts_picture(const QString& model, const std::vector<ParameterOverride>& overrides,
                              int width, int height, QString* error = nullptr);
  // The picture the panel shows now (null until the worker has drawn it); parts_pictures(): drawn so far.
  QImage shown_parts_picture() const { return parts_image_; }
  int parts_pictures() const { return parts_pictures_; }

  // The current overrides (name=expression), and the model as loaded with them.
  std::vector<ParameterOverride> overrides() const;
  const Model* model() const { return model_.get(); }

  // Starts meshing / solving on a worker; false if busy or nothing to do. finished() comes after.
  // A solve meshes first when the parameters changed since the shown mesh was made.
  bool start_mesh();
  bool start_solve();
  // The physics Solve runs (foxi solve MODEL --physics NAME): thermal, electrostatic, current or
  // thermal stress (thermoelastic: the model's temperature_change load), with the model's conditions
  // and loads of it; the field shown after the solve is its temperature, potential or von Mises
  // stress. False while a job runs.
  bool set_physics(Physics physics);
  Physics physics() const { return physics_; }
  // The mesh panel's settings (mesher, sizes, quality bound, boxes, refine from the result), used by
  // the next mesh job; a solve remeshes first when they changed since the shown mesh. False (nothing
  // changes) with the reason for values mesh_model refuses (check_mesh_options, an unknown part) or
  // while a job runs. The panel's controls follow.
  bool set_mesh_settings(const MeshSettings& settings, QString* error = nullptr);
  const MeshSettings& mesh_settings() const { return mesh_settings_; }
  // The solver Solve runs (the solve panel's choice); false while a job runs, or CalculiX for a physics
  // other than thermal and thermal_stress. A CalculiX run is a child process (killed by Cancel, its
  // work folder removed), its temperatures or displacements read back (with the stress and von Mises
  // foxi derives from them, ccx's nodal stress as stress_nodal) and reported with the balance checks
  // as foxi solve --with ccx reports them (solve_thermal_calculix, solve_thermoelastic_calculix).
  bool set_solver(const SolverChoice& choice);
  const SolverChoice& solver() const { return solver_; }
  // The progress bar: the stage, the iterative solver's iteration and residual while it runs.
  QProgressBar* progress_bar() const { return progress_; }
  // The iterations the running (or last) iterative solve reported so far, and its relative residual.
  long solve_iterations() const;
  double solve_residual() const;
  // Asks the running job to stop; the previous mesh and picture stay.
  void cancel();
  bool busy() const { return job_ != nullptr; }

  // The field shown ("" for regions) and its colour map; rebuilds the picture on a worker.
  bool set_field(const QString& field, const QString& color_map = "viridis");

  // Graded colouring (foxi render --graded) and a colour range in the field's display unit (--range
  // a,b; nullopt: the values' own); recolours on a worker. False for a range without low < high.
  bool set_colouring(bool graded, std::optional<std::pair<double, double>> range);
  Colouring colouring() const;
  // The regions not shown (by id; foxi render --regions shows the others); redraws on a worker.
  bool set_hidden_regions(std::vector<std::int32_t> hidden);
  // Every region of material `material` (an index into the mesh's materials) shown or hidden, the
  // others as they were: set_hidden_regions with that set (the region boxes and the material boxes
  // follow, both ways). False without a mesh or for a material no region has.
  bool set_material_shown(std::uint32_t material, bool shown);

  // The deformed shape (nullopt: undeformed): the view shows a moved copy of the mesh, checked and
  // repaired as foxi render --deform does (folded tets re-oriented); in general it is not Delaunay and
  // is drawn in MPVO order with the depth buffer, which the status line says. A new mesh or solve
  // shows the undeformed shape again. Redraws on a worker; false while a job runs, without a mesh or
  // for a scale that is not finite.
  bool set_deform(std::optional<Deform> deform);
  const std::optional<Deform>& deform() const { return deform_; }

  // Each tet drawn scaled about its centroid by `shrink` in (0, 1] (foxi render --shrink); false
  // for a value outside or while a job runs.
  bool set_shrink(double shrink);

  // Values in SI units (K, Pa, m, V) or the engineer's (°C, MPa, µm, mV), in the legend, the probe, the
  // field tools, the results table and the history alike; redraws on a worker.
  bool set_si_units(bool si);
  bool si_units() const { return si_units_; }
  // The unit a value of SI unit `si_unit` (largest magnitude `max_abs`) is shown in now.
  DisplayUnit shown_unit(const std::string& si_unit, double max_abs) const;

  // The view's field tools (field_selection.hpp, SI values): an isosurface (the solid above it, or the
  // surface only), a threshold on the tets' values, a clip plane and a slice, by the field shown. The
  // controls follow. False (nothing changes) with the reason: no field shown, a slice with isovalues, a zero
  // clip or slice normal, what the x-ray or the volume does not draw with (ViewWidget::set_selection).
  bool set_selection(const FieldSelection& selection, QString* error = nullptr);
  // The field shown's display unit (the legend's, the probe's) and its corner values' range, SI: the
  // range the isovalue slider spans.
  const DisplayUnit& display_unit() const { return unit_; }
  double field_lo() const { return field_lo_; }
  double field_hi() const { return field_hi_; }
  // The isovalue slider (0 .. 1000 over [field_lo, field_hi]): moving it moves the isosurface; the
  // box of more isovalues (display unit, comma-separated) drawn with it (foxi render --iso a,b,...).
  QSlider* iso_slider() const { return iso_slider_; }
  QLineEdit* more_isovalues() const { return iso_more_; }
  const FieldSelection& selection() const { return selection_; }

  // A movie of the view: foxi movie --mode rotate --frames N with the view's camera, size and what it
  // draws (the field's colours, regions shown, threshold or clip, x-ray or volume; not an isosurface
  // or slice), the camera turned 360 degrees about its up axis, written to `path` (.gif, .apng, or
  // numbered PNG frames like DIR/frame_%04d.png, the folder existing) on a worker with progress and
  // Cancel (cancel_movie); movie_finished follows. A file appears whole or not at all. False (nothing
  // started) with the reason: no view, a movie running, iso drawing, a bad name, frames < 2.
  bool save_movie(const QString& path, int frames = 48, QString* error = nullptr);
  void cancel_movie();
  bool movie_running() const { return movie_ != nullptr; }

  // A project folder: project.json (the model file's absolute path, so its material library and STL
  // references stay valid; the parameter overrides, the colouring, the camera, the history, the
  // results) and the mesh with its fields as mesh-N.vtu. Each file is written to a temporary and
  // renamed (DurableFile); project.json last, naming the new mesh file, so a save killed half way
  // leaves the previous project whole. False with the reason in `error`.
  bool save_project(const QString& folder, QString* error = nullptr);
  // Reopens a saved project: the model with its overrides, the mesh and results as saved, the view
  // with the saved camera and colouring (drawn on a worker: finished() follows). False with the reason.
  bool open_project(const QString& folder, QString* error = nullptr);

  // Autosave into `folder` (a project folder; empty: off) within 5 s of a change (2 s after the
  // first change of a burst, written on a worker as save_project writes). autosaves(): started so far.
  void set_autosave_folder(const QString& folder);
  // The wait between a change and its autosave (2 s: a burst of edits is one save; tests shorten it).
  void set_autosave_delay(int milliseconds);
  int autosaves() const { return autosaves_; }
  // Autosaves that kept the mesh file already written (the mesh and results unchanged since).
  int autosaves_without_mesh() const { return mesh_writes_saved_; }
  // Autosaves that kept the model copy already written (the model and its values unchanged since).
  int autosaves_without_model() const { return model_writes_saved_; }
  void wait_autosave();  // the running autosave written (for tests and quitting)
  // Whether `folder` holds an autosaved project (its project.json), which a session left.
  static bool autosave_found(const QString& folder);
  // On start, before anything is autosaved again: when `folder` holds an autosave, asks "restore
  // the unsaved work?" (ask; else restores without asking) and opens it (open_project). False when
  // there is none, the user declined, or it does not open (the reason in `error`).
  bool restore_autosave(const QString& folder, bool ask, QString* error = nullptr);

  // A sweep from the history: `parameter` set to each of `values` in turn ("2 mm", ...: expressions as
  // the parameter table takes them), each point meshed and solved (the physics and solver chosen) on
  // the worker, one history row per point (a failed point: a row with its error; the sweep goes on);
  // progress "point k of n"; Cancel stops it, the rows so far stay. The other parameters are the
  // current ones. False with the reason when busy, no model, no values, or the parameter or a value
  // does not load. finished() comes after.
  bool start_sweep(const QString& parameter, const QStringList& values, QString* error = nullptr);
  // The values of a range: `count` values evenly from `lo` to `hi` in lo's unit ("2 mm", "8 mm", 4 ->
  // 2mm, 4mm, 6mm, 8mm), as foxi sweep --vary NAME=LO:HI:N writes them; empty with the reason in `error`.
  static QStringList sweep_values(const QString& lo, const QString& hi, int count, QString* error = nullptr);

  std::shared_ptr<const Mesh> mesh() const { return mesh_; }
  const RunResults* results() const { return has_results_ ? &results_ : nullptr; }
  const std::vector<HistoryRow>& history() const { return history_; }
  foxi::qt::ViewWidget* view_widget() const { return view_; }
  QString last_error() const { return last_error_; }
  // The last job failed on the model itself (its file, a parameter, missing conditions): the
  // message names the file and line; a headless run exits with status 3 then.
  bool last_error_bad_input() const { return last_error_bad_input_; }

 signals:
  // A job ended: ok false with last_error() (cancelled: "cancelled").
  void finished(bool ok);
  // A movie ended: ok, or the reason ("cancelled" when cancelled).
  void movie_finished(bool ok, const QString& message);

 protected:
  void closeEvent(QCloseEvent* event) override;

 private:
  void build_ui();  // workbench.cpp: the panels put together, the status bar, the keys
  // The panels, each built in its own file.
  QPushButton* build_view_panel();   // view_panel.cpp: the view and its tools; its Save picture button
  QPushButton* build_model_panel();  // model_panel.cpp: its Open model button
  QHBoxLayout* build_project_row();  // project.cpp: save, open, recent projects
  void build_mesh_panel();           // mesh_panel.cpp
  void refresh_mesh_controls();      // mesh_panel.cpp: the controls from mesh_settings_ and the model
  void on_mesh_controls_edited();    // mesh_panel.cpp: the controls to mesh_settings_
  void build_results_panel();        // solve_panel.cpp
  void build_history_panel();        // history.cpp
  void run_sweep_dialog();           // history.cpp: the sweep's parameter and values asked
  // model_file.cpp: Save model, Save model as; the exploded parts picture, redrawn on a worker
  QHBoxLayout* build_model_file_row();
  QLabel* build_parts_picture();
  void refresh_parts_picture();
  void refresh_model_panel();
  void on_parameter_edited(int row, int column);
  bool start_job(bool mesh, bool solve);
  bool apply_overrides(std::map<std::string, std::string> trial, QString* error);
  void launch(std::function<std::shared_ptr<Outcome>()> work, const QString& what,
              std::shared_ptr<std::atomic<bool>> cancel, std::shared_ptr<std::atomic<int>> permille,
              std::shared_ptr<SolveProgress> solve = nullptr);
  void on_job_done();
  void finish_sweep(Outcome& out, const QString& what);  // jobs.cpp: a sweep's rows into the history
  void show_results();
  void add_history(double seconds);
  void fill_history_row(int i, const HistoryRow& row);
  void refresh_history();
  void refresh_fields();
  void show_region_boxes();  // the region and material boxes checked as hidden_ says
  void show_error(const QString& text);
  void changed();  // something a project holds changed: autosave soon
  void autosave();
  ProjectSnapshot project_snapshot(const QString& folder) const;
  void apply_field_tools();  // the controls' selection to the view
  void show_selection();     // the controls to the selection
  void show_legend();        // legend_scale_'s, the volume's scale while the view draws the volume

  QString model_path_;
  std::map<std::string, std::string> overrides_;
  std::vector<std::map<std::string, std::string>> undo_, redo_;  // the overrides before each edit
  std::shared_ptr<const Model> model_;                           // as loaded with the overrides
  std::shared_ptr<const Model> meshed_model_;                    // the model the shown mesh came from
  QString meshed_path_;                                          // its file
  std::vector<ParameterOverride> meshed_overrides_;
  MeshSettings mesh_settings_;    // the mesh panel's
  MeshSettings meshed_settings_;  // those the shown mesh was made with
  QString mesh_settings_model_;   // the model file they were made for (another one resets them)
  std::unique_ptr<MeshControls> mesh_ui_;
  std::shared_ptr<const Mesh> mesh_;
  RunResults results_;
  bool has_results_ = false;
  Physics physics_ = Physics::thermal;
  SolverChoice solver_;
  bool si_units_ = false;
  double mesh_seconds_ = 0;
  std::size_t mesh_serial_ = 0;
  std::vector<HistoryRow> history_;
  QString field_, color_map_ = "viridis";
  double shrink_ = 1;
  bool graded_ = false;
  std::optional<std::pair<double, double>> range_;
  std::vector<std::int32_t> hidden_;
  std::optional<Deform> deform_;
  std::optional<std::optional<Deform>> deform_before_;  // set_deform's job running: the shape before it
  std::optional<Camera> pending_camera_;
  QString autosave_folder_;
  QTimer* autosave_timer_ = nullptr;
  QFuture<QString> autosaving_;
  int autosaves_ = 0;  // a reopened project's, for the next display
  // The mesh the last autosave wrote (set on its worker, read after it finished) and its file
  std::weak_ptr<const Mesh> autosaved_mesh_;
  std::string autosaved_mesh_name_;
  QString autosaved_folder_;
  std::atomic<int> mesh_writes_saved_{0};
  // The model copy the last autosave wrote: its source file, last change and values (the key), and name
  QString autosaved_model_key_;
  std::atomic<int> model_writes_saved_{0};
  FieldSelection selection_;  // of selection_field_ (SI)
  QString selection_field_;
  DisplayUnit unit_;
  double field_lo_ = 0, field_hi_ = 0;
  double bounds_lo_[3] = {0, 0, 0}, bounds_hi_[3] = {0, 0, 0};  // the mesh's, for the clip slider
  QString last_error_;
  bool last_error_bad_input_ = false;

  // The running job: its cancel flag and progress, polled by a timer (no event per progress call).
  struct Job;
  std::unique_ptr<Job> job_;
  std::shared_ptr<SolveProgress> last_solve_;  // the running or last solve's iterations
  struct MovieJob;  // view_panel.cpp: the movie being written (cancelled and waited for when it goes)
  std::unique_ptr<MovieJob> movie_;
  QPushButton* movie_button_ = nullptr;
  QProgressBar* movie_progress_ = nullptr;
  QTimer* poll_ = nullptr;

  foxi::qt::ViewWidget* view_ = nullptr;
  QTableWidget* params_ = nullptr;
  QLabel* param_error_ = nullptr;
  QPlainTextEdit* model_text_ = nullptr;
  QPlainTextEdit* quality_text_ = nullptr;
  QLabel* histogram_ = nullptr;
  QLabel* parts_label_ = nullptr;
  QImage parts_image_;
  int parts_pictures_ = 0;
  std::size_t parts_serial_ = 0;  // the latest request: an older worker's picture is dropped
  QString parts_key_;             // the model and overrides it was requested for
  QPushButton *mesh_button_ = nullptr, *solve_button_ = nullptr, *cancel_button_ = nullptr;
  QProgressBar* progress_ = nullptr;
  QTableWidget* results_table_ = nullptr;
  QComboBox* physics_box_ = nullptr;
  QComboBox* solver_box_ = nullptr;
  QComboBox* units_box_ = nullptr;
  QTableWidget* history_table_ = nullptr;
  QComboBox *field_box_ = nullptr, *cmap_box_ = nullptr;
  QDoubleSpinBox* shrink_box_ = nullptr;
  QCheckBox* deform_on_ = nullptr;
  QDoubleSpinBox* deform_scale_ = nullptr;
  QCheckBox *graded_box_ = nullptr, *range_on_ = nullptr;
  QDoubleSpinBox *range_lo_ = nullptr, *range_hi_ = nullptr;
  QLabel* legend_ = nullptr;
  // The field shown's scales (the picture's, the volume's), unit and label: the legend's.
  struct LegendScales {
    ColorScale scale, volume_scale;
    DisplayUnit unit;
    QString label;
  };
  std::optional<LegendScales> legend_scale_;
  QSlider* fraction_ = nullptr;
  QCheckBox *iso_on_ = nullptr, *iso_only_ = nullptr, *threshold_on_ = nullptr, *clip_on_ = nullptr;
  QSlider *iso_slider_ = nullptr, *clip_slider_ = nullptr;
  QLabel* iso_value_ = nullptr;
  QLineEdit* iso_more_ = nullptr;  // more isovalues (display unit), drawn with the slider's
  QDoubleSpinBox *threshold_lo_ = nullptr, *threshold_hi_ = nullptr;
  QComboBox* clip_axis_ = nullptr;
  // The slice (foxi render --slice): an axis plane through the slider's position, coloured by the field.
  QCheckBox* slice_on_ = nullptr;
  QComboBox* slice_axis_ = nullptr;
  QSlider* slice_slider_ = nullptr;
  QCheckBox *xray_box_ = nullptr, *volume_box_ = nullptr;
  QListWidget* regions_ = nullptr;
  QListWidget* materials_ = nullptr;  // a box per material: all its regions shown, none, or some
  QLabel *status_ = nullptr, *probe_ = nullptr;
  bool filling_ = false;  // the tables being filled by the program, not edited
};

}  // namespace foxi::workbench
