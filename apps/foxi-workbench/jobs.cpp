// foxi-workbench's jobs: meshing and solving on a worker with progress and Cancel; a job's outcome shown.
#include "workbench.hpp"
#include "workbench_parts.hpp"

#include <QDoubleSpinBox>
#include <QLabel>
#include <QPlainTextEdit>
#include <QProgressBar>
#include <QPushButton>
#include <QSignalBlocker>
#include <QTimer>
#include <QtConcurrent/QtConcurrentRun>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <iterator>
#include <utility>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include "foxi/mesher/mesher.hpp"
#include "foxi/mesher/model_mesh.hpp"
#include "foxi/model/io_error.hpp"
#include "foxi/model/physics.hpp"
#include "foxi/model/progress.hpp"
#include "foxi/model/sweep_values.hpp"

namespace foxi::workbench {

namespace {

using Clock = std::chrono::steady_clock;

// The stages the libraries report (progress.hpp's ProgressFn), numbered for the progress value the
// worker stores in one atomic: stage * 10000 + fraction in permille. 0: unknown.
const char* const kStages[] = {"",          "meshing", "conforming refinement", "assemble",
                               "factorize", "solve",   "meshing (CGAL)",        "ccx"};
int stage_index(std::string_view name) {
  for (int i = 1; i < int(std::size(kStages)); ++i)
    if (name == kStages[i]) return i;
  return 0;
}

// Stores stage * 10000 + fraction (permille): a new stage replaces the value, the same stage only
// moves it forward (the bar never goes back within a stage).
void store_progress(std::atomic<int>& permille, std::string_view stage, double f) {
  const int index = stage_index(stage);
  const int v = index * 10000 + int(std::lround(std::clamp(f, 0.0, 1.0) * 1000));
  int old = permille.load();
  while ((old / 10000 != index || old < v) && !permille.compare_exchange_weak(old, v)) {
  }
}

}  // namespace

bool same_overrides(const std::vector<ParameterOverride>& a, const std::vector<ParameterOverride>& b) {
  return std::equal(a.begin(), a.end(), b.begin(), b.end(),
                    [](const ParameterOverride& x, const ParameterOverride& y) {
                      return x.name == y.name && x.expression == y.expression;
                    });
}

const char* progress_stage(int index) {
  return index > 0 && index < int(std::size(kStages)) ? kStages[index] : "";
}

QString progress_format(const QString& what, int permille, const SolveProgress* solve) {
  QString text = what;
  if (solve && solve->points.load() > 0)
    text += QObject::tr(", point %1 of %2").arg(solve->point.load()).arg(solve->points.load());
  const char* stage = progress_stage(permille / 10000);
  if (*stage) text += QString(" (%1)").arg(stage);
  text += " %p%";
  if (solve && solve->iteration.load() > 0 && permille / 10000 == stage_index("solve"))
    text += QObject::tr(" - iteration %1, residual %2")
                .arg(solve->iteration.load())
                .arg(solve->residual.load(), 0, 'g', 2);
  return text;
}

QString duration_text(double seconds) {
  if (seconds >= 0.1) return QObject::tr("%1 s").arg(seconds, 0, 'f', seconds >= 10 ? 1 : 2);
  return QObject::tr("%1 ms").arg(1000 * seconds, 0, 'g', 3);
}

LinearSolverOptions job_solver_options(LinearSolverKind kind, std::shared_ptr<std::atomic<bool>> cancel,
                                       std::shared_ptr<std::atomic<int>> permille,
                                       std::shared_ptr<SolveProgress> solve) {
  LinearSolverOptions o;
  o.kind = kind;
  o.progress = [cancel, permille](std::string_view stage, double f) {
    store_progress(*permille, stage, f);
    return !cancel->load();
  };
  if (!solve) return o;
  o.iterations = [cancel, solve](const IterationReport& r) {
    solve->residual.store(r.relative_residual);
    solve->iteration.store(long(r.iteration));
    return !cancel->load();
  };
  return o;
}

void Workbench::launch(std::function<std::shared_ptr<Outcome>()> work, const QString& what,
                       std::shared_ptr<std::atomic<bool>> cancel, std::shared_ptr<std::atomic<int>> permille,
                       std::shared_ptr<SolveProgress> solve) {
  job_ = std::make_unique<Job>();
  job_->what = what;
  job_->cancel = std::move(cancel);
  job_->permille = std::move(permille);
  job_->solve = solve;
  if (solve) last_solve_ = std::move(solve);
  connect(&job_->watcher, &QFutureWatcher<std::shared_ptr<Outcome>>::finished, this, &Workbench::on_job_done);
  job_->watcher.setFuture(QtConcurrent::run([work = std::move(work)] {
    // The worker (and the threads it starts: TetGen, the solver's, which inherit it) niced, so
    // that on a machine with few cores the GUI thread still gets the CPU when it needs it.
    setpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid)), 10);
    return work();
  }));
  mesh_button_->setEnabled(false);
  solve_button_->setEnabled(false);
  cancel_button_->setEnabled(true);
  progress_->setValue(0);
  progress_->setFormat(what + " %p%");
  poll_->start();
}

// What a mesh or solve job needs, copied from the GUI thread's state when it starts.
struct JobInput {
  std::string path;
  std::vector<ParameterOverride> overrides;
  bool mesh = true, solve = false;
  Physics physics = Physics::thermal;      // of the solve
  SolverChoice solver;                     // and its solver
  std::shared_ptr<const Mesh> old_mesh;    // solve only: the mesh to solve on
  std::shared_ptr<const Model> old_model;  // and the model it came from
  MeshSettings mesh_settings;              // the mesh panel's (mesh_panel.cpp)
  std::shared_ptr<const Mesh> result;      // the solved mesh to refine from (null: none)
  std::string shown_field;
  int width = 1, height = 1;
  std::optional<Camera> camera;  // the view's camera stays across a remesh (compare before and after)
  Colouring colouring;
  double shrink = 1;
  std::shared_ptr<std::atomic<bool>> cancel;
  std::shared_ptr<std::atomic<int>> permille;
  std::shared_ptr<SolveProgress> solve_progress;
  bool display = true;  // the new picture's view built (not for a sweep's points)
};

namespace {

// The worker's part: mesh (mesh_model) and/or solve (thermal) and the new picture's view.
std::shared_ptr<Outcome> run_job(const JobInput& in) {
  auto out = std::make_shared<Outcome>();
  const auto t0 = Clock::now();
  const LinearSolverOptions solver =
      job_solver_options(in.solver.linear, in.cancel, in.permille, in.solve_progress);
  const ProgressFn& progress = solver.progress;
  // Cancel pressed after the last progress call (a direct solve may not call it at all) still
  // discards the result: the previous state stays.
  auto cancelled = [&] {
    if (!in.cancel->load()) return false;
    out->cancelled = true;
    out->error = "cancelled";
    return true;
  };
  try {
    std::shared_ptr<Mesh> mesh;
    std::shared_ptr<const Model> model = in.old_model;
    if (in.mesh) {
      ModelMeshOptions options;
      options.override_origin = "the parameter table";
      options.progress = progress;
      // A solve to follow: the model's conditions and materials checked before meshing, as foxi solve does.
      if (in.solve) options.physics = in.physics;
      MeshSettings settings = in.mesh_settings;
      if (settings.refine_from_result && !in.result) {
        if (!in.solve)
          throw MesherError(
              MesherFailure::bad_input,
              "refine from the result: there is no solved result of these parameters yet (solve first)");
        settings.refine_from_result = false;  // a solve's first mesh: the next Mesh refines from its result
      }
      apply_mesh_settings(options, settings, in.result.get(), in.shown_field);
      MeshedModel mm = mesh_model(in.path, in.overrides, options);
      if (cancelled()) return out;
      out->mesher_summary = mesher_summary(mm);
      out->mesh_settings = in.mesh_settings;
      mesh = std::make_shared<Mesh>(std::move(mm.mesh));
      out->quality = mesh_quality_report(*mesh, mm.conforming);
      model = std::make_shared<const Model>(std::move(mm.model));
      out->meshed = true;
      out->seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    } else {
      // The shown mesh stays as it is: the solve writes its fields into a copy.
      mesh = std::make_shared<Mesh>(*in.old_mesh);
    }
    const auto t1 = Clock::now();
    if (in.solve) {
      if (!in.mesh) check_physics(*model, in.physics);
      out->results = solve_model_physics(in.path, *model, *mesh, in.physics, solver, in.solver.calculix);
      if (cancelled()) return out;
      out->results.model = in.path;
      for (const ParameterOverride& o : in.overrides)
        out->results.parameters.push_back({o.name, o.expression});
      out->solve_seconds = std::chrono::duration<double>(Clock::now() - t1).count();
      out->solved = true;
    }
    if (in.display)
      build_display(*out, *mesh, in.solve ? solved_field(in.physics) : "", in.colouring, in.shrink, in.width,
                    in.height, in.camera ? &*in.camera : nullptr);
    if (cancelled()) return out;  // Cancel while the picture was built: the job's result goes too
    out->mesh = std::move(mesh);
    out->model = std::move(model);
    out->overrides = in.overrides;
    out->path = in.path;
    out->ok = true;
  } catch (const Cancelled&) {
    out->cancelled = true;
    out->error = "cancelled";
  } catch (const IoError& e) {
    out->bad_input = true;
    out->error = what_of(e);
  } catch (const std::exception& e) {
    out->error = what_of(e);
  }
  return out;
}

// A sweep's points on the worker: each meshed and solved as Solve does (run_job), one history row
// each; a failed point is a row with its error and the sweep goes on; Cancel ends it (the rows so far
// come back).
std::shared_ptr<Outcome> run_sweep(JobInput in, const std::string& parameter,
                                   const std::vector<std::string>& values) {
  auto out = std::make_shared<Outcome>();
  out->sweep = true;
  in.solve_progress->points.store(int(values.size()));
  const std::vector<ParameterOverride> base = in.overrides;
  for (std::size_t k = 0; k < values.size(); ++k) {
    in.solve_progress->point.store(int(k + 1));
    in.solve_progress->iteration.store(0);
    in.overrides = base;
    std::erase_if(in.overrides, [&](const ParameterOverride& o) { return o.name == parameter; });
    in.overrides.push_back({parameter, values[k]});
    std::sort(in.overrides.begin(), in.overrides.end(),
              [](const ParameterOverride& a, const ParameterOverride& b) { return a.name < b.name; });
    const auto t0 = Clock::now();
    std::shared_ptr<Outcome> point = run_job(in);
    if (point->cancelled || in.cancel->load()) {
      out->cancelled = true;
      out->error = "cancelled";
      return out;
    }
    HistoryRow row;
    row.parameters = in.overrides;
    row.mesh_settings = in.mesh_settings;
    row.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    if (point->ok) {
      row.tets = point->mesh->tet_count();
      row.results = std::move(point->results);
      row.results.mesh_seconds = point->seconds;
      row.results.solve_seconds = point->solve_seconds;
    } else {
      row.results.status = RunStatus::failed;
      row.results.error = point->error.toStdString();
      row.results.model = in.path;
      row.results.physics = physics_name(in.physics);
      for (const ParameterOverride& o : in.overrides)
        row.results.parameters.push_back({o.name, o.expression});
    }
    out->sweep_rows.push_back(std::move(row));
  }
  out->ok = true;
  return out;
}

}  // namespace

QStringList Workbench::sweep_values(const QString& lo, const QString& hi, int count, QString* error) {
  try {
    QStringList out;
    for (const std::string& t : sweep_range(lo.toStdString(), hi.toStdString(), count).texts)
      out << QString::fromStdString(t);
    return out;
  } catch (const std::exception& e) {
    if (error) *error = what_of(e);
    return {};
  }
}

bool Workbench::start_sweep(const QString& parameter, const QStringList& values, QString* error) {
  auto refuse = [&](const QString& why) {
    if (error) *error = why;
    show_error(why);
    return false;
  };
  if (busy()) return refuse(tr("a job is running"));
  if (model_path_.isEmpty()) return refuse(tr("open a model first"));
  if (values.isEmpty()) return refuse(tr("no values to sweep"));
  std::vector<std::string> texts;
  for (const QString& v : values) texts.push_back(v.trimmed().toStdString());
  // As foxi sweep checks before its runs: a mistyped name or unit fails at once (no value loads); a
  // value only the geometry refuses is that point's failed row.
  std::string first_error;
  bool loads = false;
  for (const std::string& t : texts) {
    std::vector<ParameterOverride> ov = overrides();
    std::erase_if(ov, [&](const ParameterOverride& o) { return o.name == parameter.toStdString(); });
    ov.push_back({parameter.toStdString(), t});
    try {
      (void)load_model(model_path_.toStdString(), ov, "the sweep");
      loads = true;
      break;
    } catch (const std::exception& e) {
      if (first_error.empty()) first_error = e.what();
    }
  }
  if (!loads) return refuse(QString::fromStdString(first_error));
  JobInput in;
  in.path = model_path_.toStdString();
  in.overrides = overrides();
  in.mesh = true;
  in.solve = true;
  in.display = false;
  in.physics = physics_;
  in.solver = solver_;
  in.mesh_settings = mesh_settings_;  // the mesh panel's (refine from the result: none for new values)
  in.cancel = std::make_shared<std::atomic<bool>>(false);
  in.permille = std::make_shared<std::atomic<int>>(0);
  in.solve_progress = std::make_shared<SolveProgress>();
  auto cancel = in.cancel;
  auto permille = in.permille;
  auto progress = in.solve_progress;
  launch([in = std::move(in), p = parameter.toStdString(), texts] { return run_sweep(in, p, texts); },
         tr("sweep of %1").arg(parameter), cancel, permille, progress);
  return true;
}

void Workbench::finish_sweep(Outcome& out, const QString& what) {
  // The rows so far (all, or those before a Cancel) join the history; the shown mesh and results stay.
  for (HistoryRow& row : out.sweep_rows) history_.push_back(std::move(row));
  refresh_history();
  std::size_t failed = 0;
  for (const HistoryRow& row : out.sweep_rows) failed += row.results.status == RunStatus::failed;
  if (out.cancelled) {
    last_error_ = "cancelled";
    progress_->setFormat(what + tr(": cancelled after %1 points").arg(out.sweep_rows.size()));
  } else {
    last_error_.clear();
    progress_->setFormat(what + tr(": %1 points, %2 failed").arg(out.sweep_rows.size()).arg(failed));
  }
  last_error_bad_input_ = false;
  if (!out.sweep_rows.empty()) changed();
  emit finished(!out.cancelled);
}

bool Workbench::start_job(bool mesh, bool solve) {
  if (busy() || model_path_.isEmpty()) return false;
  JobInput in;
  in.path = model_path_.toStdString();
  in.overrides = overrides();
  // Only what changed reruns: a solve remeshes first when the model file, the parameters or the mesh
  // settings changed since the mesh (a Save model that wrote the mesh's values into the file changes
  // none of them: see save_model_file).
  const bool stale = !mesh_ || !meshed_model_ || meshed_path_ != model_path_ ||
                     !same_overrides(in.overrides, meshed_overrides_) ||
                     !same_mesh_settings(mesh_settings_, meshed_settings_);
  in.mesh = mesh || stale;
  in.solve = solve;
  in.physics = physics_;
  in.solver = solver_;
  in.old_mesh = mesh_;
  in.old_model = meshed_model_;
  in.mesh_settings = mesh_settings_;
  // Refining from the result takes the solved mesh as its background: only one of these parameters
  // (a result of other ones covers another shape).
  if (has_results_ && same_overrides(in.overrides, meshed_overrides_)) in.result = mesh_;
  in.shown_field = field_.toStdString();
  in.width = view_->width();
  in.height = view_->height();
  if (view_->camera()) in.camera = *view_->camera();
  in.colouring = colouring();
  in.colouring.deform.reset();  // a new mesh or result: the undeformed shape (deform_ reset when it lands)
  in.shrink = shrink_;
  in.cancel = std::make_shared<std::atomic<bool>>(false);
  in.permille = std::make_shared<std::atomic<int>>(0);
  if (solve) in.solve_progress = std::make_shared<SolveProgress>();
  const QString what = in.mesh && in.solve ? tr("meshing and solving")
                       : in.mesh           ? tr("meshing")
                                           : tr("solving");
  auto cancel = in.cancel;
  auto permille = in.permille;
  auto progress = in.solve_progress;
  launch([in = std::move(in)] { return run_job(in); }, what, cancel, permille, progress);
  return true;
}

bool Workbench::start_mesh() { return start_job(true, false); }

long Workbench::solve_iterations() const { return last_solve_ ? last_solve_->iteration.load() : 0; }
double Workbench::solve_residual() const { return last_solve_ ? last_solve_->residual.load() : 0; }
bool Workbench::start_solve() { return start_job(false, true); }

void Workbench::cancel() {
  if (job_) job_->cancel->store(true);
}

void Workbench::on_job_done() {
  std::shared_ptr<Outcome> out = job_->watcher.result();
  const QString what = job_->what;
  job_.reset();
  poll_->stop();
  mesh_button_->setEnabled(true);
  solve_button_->setEnabled(true);
  cancel_button_->setEnabled(false);
  progress_->setValue(out && out->ok ? 1000 : 0);
  if (out && out->sweep) {
    finish_sweep(*out, what);
    return;
  }
  const auto deform_before = std::exchange(deform_before_, std::nullopt);
  if (!out || !out->ok) {
    if (deform_before) {  // the deformed shape refused: the one shown stays, and its controls
      deform_ = *deform_before;
      refresh_fields();
    }
    const QString why = out ? out->error : tr("no result");
    last_error_ = why;
    last_error_bad_input_ = out && out->bad_input;
    progress_->setFormat(what + ": " + why);
    if (!out || !out->cancelled) param_error_->setText(why);
    emit finished(false);
    return;
  }
  last_error_.clear();
  last_error_bad_input_ = false;
  progress_->setFormat(what + tr(": done in %1").arg(duration_text(out->seconds + out->solve_seconds)));
  if (out->meshed) {
    mesh_ = out->mesh;
    meshed_model_ = out->model;
    meshed_path_ = QString::fromStdString(out->path);
    meshed_overrides_ = out->overrides;
    meshed_settings_ = out->mesh_settings;
    mesh_seconds_ = out->seconds;
    ++mesh_serial_;
    if (out->quality) {
      quality_text_->setPlainText(out->mesher_summary + "\n" +
                                  QString::fromStdString(format_quality_report(*out->quality)));
      histogram_->setPixmap(histogram_pixmap(*out->quality));
    }
    has_results_ = false;
    field_.clear();
  }
  if (out->solved) {
    mesh_ = out->mesh;
    results_ = out->results;
    results_.mesh_seconds = mesh_seconds_;
    results_.solve_seconds = out->solve_seconds;
    has_results_ = true;
    field_ = solved_field(physics_of(out->results.physics).value_or(Physics::thermal));
  }
  if (out->meshed || out->solved) deform_.reset();
  if (!out->meshed && !out->solved) mesh_ = out->mesh;
  const std::shared_ptr<const Mesh> shown = out->view_mesh ? out->view_mesh : out->mesh;
  view_->set_view(shown, std::move(out->view));
  view_->set_probe_values(std::move(out->probe), out->probe_unit);
  mesh_bounds(*shown, bounds_lo_, bounds_hi_);
  view_->set_base(std::move(out->base));
  if (out->has_scale && out->choice) {
    view_->set_field_source(*out->choice, out->step, out->scale, out->iso_cache, out->volume_scale);
    if (!range_) {  // the range boxes start from the automatic range
      const QSignalBlocker q1(range_lo_), q2(range_hi_);
      range_lo_->setValue(out->unit.to_display(out->scale.lo));
      range_hi_->setValue(out->unit.to_display(out->scale.hi));
    }
    unit_ = out->unit;
    field_lo_ = out->corner_lo;
    field_hi_ = out->corner_hi;
    // The same field (a new colour map, shrink or solve): its tools stay; another field: they go.
    if (selection_field_ != field_) selection_ = {};
    selection_field_ = field_;
    QString why;
    if (selection_.any() && !view_->set_selection(selection_, &why)) selection_ = {};
  } else {
    selection_ = {};
    selection_field_.clear();
  }
  show_selection();
  legend_scale_.reset();
  if (out->has_scale) {
    legend_scale_ = LegendScales{out->scale, out->volume_scale, out->unit, out->field_label};
    show_legend();
  } else {
    legend_->clear();
  }
  refresh_fields();
  if (out->meshed && !out->solved) add_history(out->seconds);
  if (out->solved) {
    show_results();
    add_history(mesh_seconds_ + out->solve_seconds);  // the mesh's row gets the results
  }
  refresh_mesh_controls();  // the result's fields to refine from
  changed();
  emit finished(true);
}

}  // namespace foxi::workbench
