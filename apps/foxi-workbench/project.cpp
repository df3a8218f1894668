// foxi-workbench's projects: save and reopen the whole state as a folder, recent projects, autosave.
#include "workbench.hpp"
#include "workbench_parts.hpp"

#include <QCheckBox>
#include <QDateTime>
#include <QComboBox>
#include <QDoubleSpinBox>
#include <QDir>
#include <QFile>
#include <QFileDialog>
#include <QFileInfo>
#include <QHBoxLayout>
#include <QJsonArray>
#include <QJsonDocument>
#include <QJsonObject>
#include <QMenu>
#include <QMessageBox>
#include <QProgressBar>
#include <QPushButton>
#include <QSettings>
#include <QSignalBlocker>
#include <QTimer>
#include <QtConcurrent/QtConcurrentRun>
#include <algorithm>
#include <cmath>
#include <filesystem>

#include "foxi/model/durable_file.hpp"
#include "foxi/model/mesh_io.hpp"
#include "foxi/model/model_save.hpp"

namespace foxi::workbench {

QHBoxLayout* Workbench::build_project_row() {
  // Projects: save and reopen the whole state; the folder is then autosaved; the recent ones listed.
  auto* projects = new QHBoxLayout;
  auto* save_p = new QPushButton(tr("Save project..."));
  auto* open_p = new QPushButton(tr("Open project..."));
  auto* recent = new QPushButton(tr("Recent"));
  auto* recent_menu = new QMenu(recent);
  recent->setMenu(recent_menu);
  // After a save or an open of `folder`: it heads the recent list (QSettings) and is autosaved.
  auto adopt = [this](bool ok, const QString& folder, const QString& why) {
    if (!ok) {
      show_error(why);
      return;
    }
    QSettings settings;
    QStringList list = settings.value("recent_projects").toStringList();
    list.removeAll(folder);
    list.prepend(folder);
    while (list.size() > 8) list.removeLast();
    settings.setValue("recent_projects", list);
    set_autosave_folder(folder);
  };
  auto open_folder = [this, adopt](const QString& folder) {
    QString why;
    adopt(open_project(folder, &why), folder, why);
  };
  connect(save_p, &QPushButton::clicked, this, [this, adopt] {
    const QString f = QFileDialog::getExistingDirectory(this, tr("Save the project into a folder"));
    if (f.isEmpty()) return;
    QString why;
    adopt(save_project(f, &why), f, why);
  });
  connect(open_p, &QPushButton::clicked, this, [this, open_folder] {
    const QString f = QFileDialog::getExistingDirectory(this, tr("Open a project folder"));
    if (!f.isEmpty()) open_folder(f);
  });
  connect(recent_menu, &QMenu::aboutToShow, this, [recent_menu, open_folder] {
    recent_menu->clear();
    for (const QString& f : QSettings().value("recent_projects").toStringList())
      recent_menu->addAction(f, [open_folder, f] { open_folder(f); });
  });
  projects->addWidget(save_p);
  projects->addWidget(open_p);
  projects->addWidget(recent);
  return projects;
}

namespace {

QJsonArray numbers(const double* v, int n) {
  QJsonArray a;
  for (int i = 0; i < n; ++i) a.append(v[i]);
  return a;
}

void read_numbers(const QJsonValue& v, double* out, int n) {
  const QJsonArray a = v.toArray();
  if (a.size() != n)
    throw std::runtime_error("a camera vector of " + std::to_string(n) + " numbers expected");
  for (int i = 0; i < n; ++i) out[i] = a[i].toDouble();
}

// A clip or slice plane: its point, then its normal.
QJsonArray plane_json(const Plane& plane) {
  QJsonArray a = numbers(plane.p, 3);
  for (int k = 0; k < 3; ++k) a.append(plane.n[k]);
  return a;
}

Plane read_plane(const QJsonValue& v) {
  const QJsonArray a = v.toArray();
  if (a.size() != 6) throw std::runtime_error("a plane of 6 numbers (point, normal) expected");
  Plane plane;
  for (int k = 0; k < 3; ++k) plane.p[k] = a[k].toDouble(), plane.n[k] = a[k + 3].toDouble();
  return plane;
}

QJsonArray overrides_json(const std::vector<ParameterOverride>& ov) {
  QJsonArray a;
  for (const ParameterOverride& o : ov)
    a.append(QJsonArray{QString::fromStdString(o.name), QString::fromStdString(o.expression)});
  return a;
}

std::vector<ParameterOverride> overrides_of(const QJsonValue& v) {
  std::vector<ParameterOverride> ov;
  for (const QJsonValue& e : v.toArray())
    ov.push_back({e.toArray().at(0).toString().toStdString(), e.toArray().at(1).toString().toStdString()});
  return ov;
}

// The mesh panel's settings (MeshSettings) as project.json keeps them: lengths in metres, each
// optional value only when set.
QJsonObject mesh_settings_json(const MeshSettings& s) {
  QJsonObject o;
  o["mesher"] = s.mesher == Mesher::cgal ? "cgal" : "tetgen";
  if (s.max_size) o["max_size"] = *s.max_size;
  QJsonArray parts;
  for (const PartSize& p : s.part_sizes)
    parts.append(QJsonObject{{"part", QString::fromStdString(p.part)}, {"max_size", p.max_size}});
  o["part_sizes"] = parts;
  if (s.quality) o["quality"] = *s.quality;
  QJsonArray boxes;
  for (const RefinementBox& b : s.boxes)
    boxes.append(QJsonObject{{"lo", numbers(b.lo, 3)}, {"hi", numbers(b.hi, 3)}, {"size", b.size}});
  o["boxes"] = boxes;
  o["refine_from_result"] = s.refine_from_result;
  o["refine_field"] = QString::fromStdString(s.refine_field);
  o["target_error"] = s.target_error;
  return o;
}

// The settings back from mesh_settings_json's object; `where` ("FILE: mesh_settings") heads the
// reason of a malformed entry (a wrong type, an unknown key, a mesher foxi does not have). Entries
// left out keep their defaults. The values' ranges are set_mesh_settings' to check (mesh_model's
// own check_mesh_options, the parts of the model).
MeshSettings mesh_settings_of(const QJsonValue& v, const std::string& where) {
  auto bad = [&](const std::string& why) { return std::runtime_error(where + ": " + why); };
  if (!v.isObject()) throw bad("an object expected");
  const QJsonObject o = v.toObject();
  static const char* const kKeys[] = {"mesher", "max_size",           "part_sizes",   "quality",
                                      "boxes",  "refine_from_result", "refine_field", "target_error"};
  for (const QString& key : o.keys())
    if (std::none_of(std::begin(kKeys), std::end(kKeys), [&](const char* k) { return key == k; }))
      throw bad("unknown entry '" + key.toStdString() + "'");
  auto number = [&](const QJsonValue& x, const std::string& what) {
    if (!x.isDouble() || !std::isfinite(x.toDouble())) throw bad(what + " is not a number");
    return x.toDouble();
  };
  auto corner = [&](const QJsonValue& x, double* out, const std::string& what) {
    const QJsonArray a = x.toArray();
    if (!x.isArray() || a.size() != 3) throw bad(what + " is not 3 numbers");
    for (int k = 0; k < 3; ++k) out[k] = number(a[k], what);
  };
  MeshSettings s;
  if (o.contains("mesher")) {
    const QString m = o["mesher"].toString();
    if (!o["mesher"].isString()) throw bad("the mesher is not a name (tetgen or cgal)");
    if (m == "cgal")
      s.mesher = Mesher::cgal;
    else if (m != "tetgen")
      throw bad("the mesher is tetgen or cgal, not '" + m.toStdString() + "'");
  }
  if (o.contains("max_size")) s.max_size = number(o["max_size"], "max_size");
  if (o.contains("quality")) s.quality = number(o["quality"], "quality");
  if (o.contains("part_sizes") && !o["part_sizes"].isArray()) throw bad("part_sizes is not a list");
  for (const QJsonValue& e : o["part_sizes"].toArray()) {
    const std::string what = "part size " + std::to_string(s.part_sizes.size() + 1);
    const QJsonObject p = e.toObject();
    if (!e.isObject() || !p["part"].isString() || p["part"].toString().isEmpty())
      throw bad(what + ": a part name and its max_size expected");
    s.part_sizes.push_back({.part = p["part"].toString().toStdString(),
                            .max_size = number(p["max_size"], what + "'s max_size")});
  }
  if (o.contains("boxes") && !o["boxes"].isArray()) throw bad("boxes is not a list");
  for (const QJsonValue& e : o["boxes"].toArray()) {
    const std::string what = "refinement box " + std::to_string(s.boxes.size() + 1);
    if (!e.isObject()) throw bad(what + ": lo, hi and size expected");
    RefinementBox b;
    corner(e.toObject()["lo"], b.lo, what + "'s lo");
    corner(e.toObject()["hi"], b.hi, what + "'s hi");
    b.size = number(e.toObject()["size"], what + "'s size");
    s.boxes.push_back(b);
  }
  if (o.contains("refine_from_result")) {
    if (!o["refine_from_result"].isBool()) throw bad("refine_from_result is not true or false");
    s.refine_from_result = o["refine_from_result"].toBool();
  }
  if (o.contains("refine_field")) {
    if (!o["refine_field"].isString()) throw bad("refine_field is not a field name");
    s.refine_field = o["refine_field"].toString().toStdString();
  }
  if (o.contains("target_error")) s.target_error = number(o["target_error"], "target_error");
  return s;
}

}  // namespace

namespace {

// What the model copy of an autosave into `folder` is of: the model file, its last change and the values.
QString model_key(const QString& folder, const QString& model, const std::vector<ParameterOverride>& values) {
  QString key = folder + "\n" + QFileInfo(model).absoluteFilePath() + "\n" +
                QFileInfo(model).lastModified().toString(Qt::ISODateWithMs);
  for (const ParameterOverride& o : values) key += "\n" + QString::fromStdString(o.name + "=" + o.expression);
  return key;
}

}  // namespace

// What a save writes, taken on the GUI thread (the state may change meanwhile) and written on any thread.
struct ProjectSnapshot {
  std::filesystem::path dir;
  QJsonObject json;
  std::shared_ptr<const Mesh> mesh;
  // The mesh file of the folder's project.json that already holds `mesh` (written by the last
  // autosave of the same mesh object), kept instead of written again; empty: write the mesh.
  std::string mesh_written;
  // The model: its file and values, saved as a copy (save_model, the referenced files copied beside
  // it) named `model_name` in the folder, unless `model_written` (the last autosave wrote that copy).
  std::filesystem::path model_source;
  std::vector<ParameterOverride> model_values;
  std::string model_name;
  bool model_written = false;
};

namespace {

// Writes the mesh under a new name, then project.json naming it (both DurableFile: each whole or
// not at all), then removes the mesh file the previous project.json named. A mesh the folder holds
// already (snap.mesh_written, still named by project.json) is not written again. Returns the mesh
// file project.json names ("" for none).
std::string write_project(ProjectSnapshot snap) {
  const std::filesystem::path& dir = snap.dir;
  std::filesystem::create_directories(dir);
  // The model first: the copy project.json names, its material library and STL files beside it, so
  // the folder needs nothing outside it (moved, or on another machine). A refused copy writes no
  // project.json.
  if (!snap.model_written || !std::filesystem::exists(dir / snap.model_name)) {
    std::filesystem::create_directories((dir / snap.model_name).parent_path());
    save_model(snap.model_source, dir / snap.model_name, snap.model_values, {.copy_references = true});
  }
  snap.json["model"] = QString::fromStdString(snap.model_name);
  std::filesystem::path old_mesh;
  if (std::filesystem::exists(dir / "project.json")) {
    QFile f(QString::fromStdString((dir / "project.json").string()));
    if (f.open(QIODevice::ReadOnly)) {
      const QString m = QJsonDocument::fromJson(f.readAll()).object()["mesh"].toString();
      if (!m.isEmpty()) old_mesh = dir / m.toStdString();
    }
  }
  if (snap.mesh && !snap.mesh_written.empty() && dir / snap.mesh_written == old_mesh &&
      std::filesystem::exists(old_mesh)) {
    snap.json["mesh"] = QString::fromStdString(snap.mesh_written);  // unchanged since it was written
  } else if (snap.mesh) {
    // A new name each save: the previous project.json names a whole mesh until the new one is in.
    std::string name;
    for (int i = 1;; ++i) {
      name = "mesh-" + std::to_string(i) + ".vtu";
      if (!std::filesystem::exists(dir / name) && dir / name != old_mesh) break;
    }
    write_mesh(*snap.mesh, dir / name);
    snap.json["mesh"] = QString::fromStdString(name);
  }
  DurableFile out(dir / "project.json");
  out.write(QJsonDocument(snap.json).toJson().toStdString());
  out.commit();
  if (!old_mesh.empty() && old_mesh.filename().string() != snap.json["mesh"].toString().toStdString() &&
      old_mesh.filename().string().rfind("mesh-", 0) == 0)
    std::filesystem::remove(old_mesh);
  return snap.json["mesh"].toString().toStdString();
}

}  // namespace

ProjectSnapshot Workbench::project_snapshot(const QString& folder) const {
  if (model_path_.isEmpty()) throw std::runtime_error("no model to save");
  ProjectSnapshot snap;
  snap.dir = folder.toStdString();
  snap.mesh = mesh_;
  QJsonObject& p = snap.json;
  p["format"] = "foxi-workbench project 1";
  // the model as a copy in the folder's model/ (write_project), with the values: project.json names it
  // relatively. The overrides are kept too: reapplied to the copy (the same values), they stay the
  // edits the history, undo and the shown mesh's parameters compare with.
  snap.model_source = QFileInfo(model_path_).absoluteFilePath().toStdString();
  snap.model_values = overrides();
  snap.model_name = "model/" + QFileInfo(model_path_).fileName().toStdString();
  p["overrides"] = overrides_json(overrides());
  p["field"] = field_;
  p["color_map"] = color_map_;
  p["graded"] = graded_;
  if (range_) p["range"] = QJsonArray{range_->first, range_->second};
  QJsonArray hidden;
  for (std::int32_t r : hidden_) hidden.append(r);
  p["hidden_regions"] = hidden;
  p["shrink"] = shrink_;
  p["physics"] = physics_name(physics_);
  p["si_units"] = si_units_;
  p["solver"] = solver_.calculix ? -1 : int(solver_.linear);
  // The mesh panel's settings (the next mesh's) and those the shown mesh was made with: reopened,
  // a Solve remeshes exactly when it would have before the save.
  p["mesh_settings"] = mesh_settings_json(mesh_settings_);
  if (mesh_) p["meshed_settings"] = mesh_settings_json(meshed_settings_);
  if (deform_)
    p["deform"] = QJsonObject{{"field", QString::fromStdString(deform_->field)}, {"scale", deform_->scale}};
  if (const Camera* c = view_->camera()) {
    QJsonObject cam;
    cam["perspective"] = c->perspective;
    cam["eye"] = numbers(c->eye, 3);
    cam["at"] = numbers(c->at, 3);
    cam["up"] = numbers(c->up, 3);
    cam["fov_deg"] = c->fov_deg;
    cam["ortho_height"] = c->ortho_height;
    p["camera"] = cam;
  }
  QJsonArray history;
  for (const HistoryRow& h : history_) {
    QJsonObject row;
    row["parameters"] = overrides_json(h.parameters);
    row["mesh"] = double(h.mesh);
    row["tets"] = double(h.tets);
    row["seconds"] = h.seconds;
    row["results"] = QString::fromStdString(results_json(h.results));
    if (h.mesh_settings) row["mesh_settings"] = mesh_settings_json(*h.mesh_settings);
    history.append(row);
  }
  p["history"] = history;
  if (has_results_) p["results"] = QString::fromStdString(results_json(results_));
  p["mesh_overrides"] = overrides_json(meshed_overrides_);
  if (selection_.any()) {
    QJsonObject sel;
    QJsonArray iso;
    for (double v : selection_.iso) iso.append(v);
    sel["iso"] = iso;
    sel["iso_only"] = selection_.iso_only;
    if (selection_.threshold)
      sel["threshold"] = QJsonArray{selection_.threshold->first, selection_.threshold->second};
    if (selection_.clip) sel["clip"] = plane_json(*selection_.clip);
    if (selection_.slice) sel["slice"] = plane_json(*selection_.slice);
    p["selection"] = sel;
  }
  return snap;
}

bool Workbench::save_project(const QString& folder, QString* error) {
  try {
    if (busy()) throw std::runtime_error("a job is running: save when it ends");
    if (autosaving_.isRunning()) autosaving_.waitForFinished();
    write_project(project_snapshot(folder));
    return true;
  } catch (const std::exception& e) {
    if (error) *error = QString::fromStdString(e.what());
    return false;
  }
}

void Workbench::set_autosave_delay(int milliseconds) {
  autosave_timer_->setInterval(std::max(0, milliseconds));
}

void Workbench::set_autosave_folder(const QString& folder) {
  autosave_folder_ = folder;
  if (folder.isEmpty()) autosave_timer_->stop();
}

void Workbench::changed() {
  if (!autosave_folder_.isEmpty() && !model_path_.isEmpty() && !autosave_timer_->isActive())
    autosave_timer_->start();
}

void Workbench::autosave() {
  // Not while a job runs (its result is the next change) or the previous autosave still writes.
  if (busy() || autosaving_.isRunning()) {
    autosave_timer_->start();
    return;
  }
  try {
    ProjectSnapshot snap = project_snapshot(autosave_folder_);
    // The mesh (with its fields: the results) only when it changed since the last autosave wrote it
    if (const auto written = autosaved_mesh_.lock();
        written && written == mesh_ && autosaved_folder_ == autosave_folder_)
      snap.mesh_written = autosaved_mesh_name_;
    // The model copy only when the model file (its last change) or the values changed since
    snap.model_written = model_key(autosave_folder_, model_path_, snap.model_values) == autosaved_model_key_;
    autosaved_model_key_.clear();  // set again once this one is written
    autosaved_mesh_.reset();
    autosaved_folder_ = autosave_folder_;
    autosaving_ = QtConcurrent::run(
        [this, snap = std::move(snap), folder = autosave_folder_, model = model_path_]() -> QString {
          try {
            const std::string name = write_project(snap);
            // after the write: a reopened project's model is its copy, which the write just changed;
            // read by the GUI thread only after this future finished
            autosaved_model_key_ = model_key(folder, model, snap.model_values);
            if (snap.model_written) ++model_writes_saved_;
            // read by the GUI thread only after this future finished (autosave() waits for it)
            autosaved_mesh_name_ = name;
            autosaved_mesh_ = snap.mesh;
            if (!snap.mesh_written.empty() && name == snap.mesh_written) ++mesh_writes_saved_;
            return {};
          } catch (const std::exception& e) {
            return QString::fromStdString(e.what());
          }
        });
    ++autosaves_;
  } catch (const std::exception& e) {
    progress_->setFormat(tr("autosave: %1").arg(QString::fromStdString(e.what())));
  }
}

void Workbench::wait_autosave() {
  if (autosaving_.isRunning()) autosaving_.waitForFinished();
}

bool Workbench::autosave_found(const QString& folder) {
  return !folder.isEmpty() && QFileInfo(QDir(folder).filePath("project.json")).isFile();
}

bool Workbench::restore_autosave(const QString& folder, bool ask, QString* error) {
  if (!autosave_found(folder)) return false;
  if (ask && QMessageBox::question(
                 this, tr("Restore unsaved work?"),
                 tr("The last session left unsaved work (autosaved in %1). Restore it?").arg(folder)) !=
                 QMessageBox::Yes)
    return false;
  return open_project(folder, error);
}

bool Workbench::open_project(const QString& folder, QString* error) {
  try {
    if (busy()) throw std::runtime_error("a job is running");
    const std::filesystem::path dir = folder.toStdString();
    QFile f(QString::fromStdString((dir / "project.json").string()));
    if (!f.open(QIODevice::ReadOnly))
      throw std::runtime_error((dir / "project.json").string() + ": cannot read");
    QJsonParseError perr;
    const QJsonDocument doc = QJsonDocument::fromJson(f.readAll(), &perr);
    if (doc.isNull())
      throw std::runtime_error((dir / "project.json").string() + ": " + perr.errorString().toStdString());
    const QJsonObject p = doc.object();
    if (p["format"].toString() != "foxi-workbench project 1")
      throw std::runtime_error((dir / "project.json").string() + ": not a foxi-workbench project");
    // The mesh settings read before anything changes (a malformed entry leaves the window as it was);
    // a project without them (saved before they were kept) meshes with the defaults.
    const std::string file = (dir / "project.json").string();
    const MeshSettings settings = p.contains("mesh_settings")
                                      ? mesh_settings_of(p["mesh_settings"], file + ": mesh_settings")
                                      : MeshSettings{};
    const MeshSettings meshed = p.contains("meshed_settings")
                                    ? mesh_settings_of(p["meshed_settings"], file + ": meshed_settings")
                                    : settings;
    // The history too (each row's mesh settings: none in a project saved before rows kept them).
    std::vector<HistoryRow> history;
    for (const QJsonValue& v : p["history"].toArray()) {
      const QJsonObject o = v.toObject();
      HistoryRow h;
      h.parameters = overrides_of(o["parameters"]);
      h.mesh = std::size_t(o["mesh"].toDouble());
      h.tets = std::size_t(o["tets"].toDouble());
      h.seconds = o["seconds"].toDouble();
      h.results = parse_results_json(o["results"].toString().toStdString());
      if (o.contains("mesh_settings"))
        h.mesh_settings =
            mesh_settings_of(o["mesh_settings"], file + ": history row " +
                                                     std::to_string(history.size() + 1) + ": mesh_settings");
      history.push_back(std::move(h));
    }
    // The folder's copy of the model (a project of an earlier version names the model file itself,
    // absolutely: opened where it is)
    QString why;
    const QString model = p["model"].toString();
    if (model.isEmpty()) throw std::runtime_error(file + ": no model named");
    const QString model_file =
        QFileInfo(model).isAbsolute() ? model : QString::fromStdString((dir / model.toStdString()).string());
    if (!open_model(model_file, &why)) throw std::runtime_error(why.toStdString());
    std::map<std::string, std::string> trial;
    for (const ParameterOverride& o : overrides_of(p["overrides"])) trial[o.name] = o.expression;
    if (!apply_overrides(trial, &why)) throw std::runtime_error(why.toStdString());
    // Their values as the panel checks them (mesh_model's check, the model's parts).
    if (!set_mesh_settings(settings, &why))
      throw std::runtime_error(file + ": mesh_settings: " + why.toStdString());
    field_ = p["field"].toString();
    color_map_ = p["color_map"].toString("viridis");
    graded_ = p["graded"].toBool();
    range_.reset();
    if (p.contains("range"))
      range_ = std::pair(p["range"].toArray().at(0).toDouble(), p["range"].toArray().at(1).toDouble());
    hidden_.clear();
    for (const QJsonValue& v : p["hidden_regions"].toArray()) hidden_.push_back(v.toInt());
    shrink_ = p["shrink"].toDouble(1);
    set_physics(physics_of(p["physics"].toString("thermal").toStdString()).value_or(Physics::thermal));
    si_units_ = p["si_units"].toBool(false);
    {
      const QSignalBlocker quiet(units_box_);
      units_box_->setCurrentIndex(si_units_ ? 1 : 0);
    }
    SolverChoice solver;
    const int kind = p["solver"].toInt(0);
    solver.calculix = kind < 0;
    if (kind > 0 && kind <= int(LinearSolverKind::cg_amg)) solver.linear = LinearSolverKind(kind);
    set_solver(solver);
    // The deformed shape shown, as saved (its display below: refused, it goes and the mesh shows plain).
    deform_.reset();
    if (p.contains("deform")) {
      const QJsonObject d = p["deform"].toObject();
      const double scale = d["scale"].toDouble(NAN);
      if (!std::isfinite(scale))
        throw std::runtime_error((dir / "project.json").string() +
                                 ": the deformed shape's scale is not a number");
      deform_ = Deform{d["field"].toString("displacement").toStdString(), scale};
    }
    history_ = std::move(history);
    has_results_ = p.contains("results");
    if (has_results_) results_ = parse_results_json(p["results"].toString().toStdString());
    if (!p["mesh"].toString().isEmpty()) {
      mesh_ = std::make_shared<const Mesh>(read_mesh(dir / p["mesh"].toString().toStdString()));
      meshed_model_ = model_;
      meshed_path_ = model_path_;
      meshed_overrides_ = overrides_of(p["mesh_overrides"]);
      meshed_settings_ = meshed;
      mesh_serial_ = 1;
      for (const HistoryRow& h : history_) mesh_serial_ = std::max(mesh_serial_, h.mesh);
    }
    if (p.contains("camera")) {
      const QJsonObject c = p["camera"].toObject();
      Camera cam;
      cam.perspective = c["perspective"].toBool(true);
      read_numbers(c["eye"], cam.eye, 3);
      read_numbers(c["at"], cam.at, 3);
      read_numbers(c["up"], cam.up, 3);
      cam.fov_deg = c["fov_deg"].toDouble(30);
      cam.ortho_height = c["ortho_height"].toDouble(1);
      pending_camera_ = cam;
    }
    selection_ = {};
    if (p.contains("selection")) {
      const QJsonObject sel = p["selection"].toObject();
      for (const QJsonValue& v : sel["iso"].toArray()) selection_.iso.push_back(v.toDouble());
      selection_.iso_only = sel["iso_only"].toBool();
      if (sel.contains("threshold"))
        selection_.threshold = std::pair(sel["threshold"].toArray().at(0).toDouble(),
                                         sel["threshold"].toArray().at(1).toDouble());
      // A project saved before the slice was kept has none: the slice off.
      if (sel.contains("clip")) selection_.clip = read_plane(sel["clip"]);
      if (sel.contains("slice")) selection_.slice = read_plane(sel["slice"]);
    }
    selection_field_ = field_;  // the display that follows applies it
    {
      const QSignalBlocker q1(graded_box_), q2(range_on_), q3(range_lo_), q4(range_hi_), q5(shrink_box_);
      graded_box_->setChecked(graded_);
      range_on_->setChecked(range_.has_value());
      if (range_) range_lo_->setValue(range_->first), range_hi_->setValue(range_->second);
      shrink_box_->setValue(shrink_);
    }
    if (has_results_) show_results();
    refresh_history();
    refresh_mesh_controls();  // the reopened result's fields to refine from
    if (mesh_ && set_field(field_, color_map_) && deform_)
      deform_before_ = std::optional<Deform>{};  // a refused shape: the undeformed one
    return true;
  } catch (const std::exception& e) {
    if (error) *error = QString::fromStdString(e.what());
    return false;
  }
}

}  // namespace foxi::workbench
