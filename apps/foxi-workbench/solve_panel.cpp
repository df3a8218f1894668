// foxi-workbench's solve panel: the physics a solve runs (the model's conditions and loads of it, as
// foxi solve MODEL --physics NAME takes them), and the derived quantities and balance checks of the
// last solve.
#include "workbench.hpp"
#include "workbench_parts.hpp"

#include <QComboBox>
#include <QDockWidget>
#include <QHBoxLayout>
#include <QHeaderView>
#include <QLabel>
#include <QPushButton>
#include <QSignalBlocker>
#include <QTableWidget>
#include <QVBoxLayout>

#include "foxi/model/io_error.hpp"
#include "foxi/solver/electric.hpp"
#include "foxi/solver/model_problem.hpp"
#include "foxi/solver/thermal.hpp"
#include "foxi/solver/thermoelastic.hpp"

namespace foxi::workbench {

namespace {

constexpr Physics kPhysics[] = {Physics::thermal, Physics::electrostatic, Physics::current,
                                Physics::thermal_stress};

}  // namespace

std::optional<Physics> physics_of(const std::string& name) {
  for (Physics p : kPhysics)
    if (name == physics_name(p)) return p;
  return std::nullopt;
}

const char* solved_field(Physics physics) {
  switch (physics) {
    case Physics::electrostatic:
    case Physics::current:
      return "potential";
    case Physics::thermal_stress:
      return "von_mises";
    case Physics::thermal:
      break;
  }
  return "temperature";
}

RunResults solve_model_physics(const std::string& path, const Model& model, Mesh& mesh, Physics physics,
                               const ProgressFn& progress) {
  // Each branch takes from the model what foxi solve MODEL --physics NAME takes (cmd_solve.cpp,
  // cmd_solve_thermoelastic.cpp) with no other option, so that the results are the CLI's.
  switch (physics) {
    case Physics::electrostatic: {
      ElectrostaticParams ep;
      ep.solver.progress = progress;
      ep.conductors = electrostatic_params_from_model(model, mesh).conductors;
      return electrostatic_results(mesh, solve_electrostatic(mesh, ep));
    }
    case Physics::current: {
      CurrentParams cp;
      cp.solver.progress = progress;
      cp.terminals = current_params_from_model(model, mesh).terminals;
      return current_results(mesh, solve_current(mesh, cp));
    }
    case Physics::thermal_stress: {
      bool has_load = false;
      for (const Load& l : model.loads) has_load = has_load || l.kind == LoadKind::temperature_change;
      if (!has_load)
        throw IoError(path, 0, 0,
                      "no temperature_change load: a thermal stress solve needs one (foxi solve "
                      "--physics thermoelastic --dT or --temperature-from-thermal on the command line)");
      ThermoelasticParams tp;
      const ThermoelasticParams mp = thermoelastic_params_from_model(model, mesh);
      tp.materials = mp.materials, tp.fixed = mp.fixed, tp.sliding = mp.sliding, tp.delta_t = mp.delta_t;
      tp.solver.progress = progress;
      return thermoelastic_results(mesh, solve_thermoelastic(mesh, tp));
    }
    case Physics::thermal:
      break;
  }
  ThermalParams params = thermal_params_from_model(model, mesh);
  params.solver.progress = progress;
  return thermal_results(mesh, solve_thermal(mesh, params));
}

bool Workbench::set_physics(Physics physics) {
  if (busy()) return false;
  physics_ = physics;
  const QSignalBlocker quiet(physics_box_);
  physics_box_->setCurrentIndex(physics_box_->findData(int(physics)));
  solve_button_->setText(tr("Solve (%1)").arg(physics_name(physics)));
  return true;
}

void Workbench::build_results_panel() {
  // The physics solved (Solve, Ctrl+R) and the results of the last solve.
  auto* panel = new QWidget;
  auto* sv = new QVBoxLayout(panel);
  auto* row = new QHBoxLayout;
  physics_box_ = new QComboBox;
  for (Physics p : kPhysics) physics_box_->addItem(physics_name(p), int(p));
  physics_box_->setToolTip(
      tr("the model's conditions and loads of this physics are solved (foxi solve MODEL --physics NAME)"));
  connect(physics_box_, qOverload<int>(&QComboBox::currentIndexChanged), this, [this] {
    if (!set_physics(Physics(physics_box_->currentData().toInt()))) set_physics(physics_);
  });
  row->addWidget(new QLabel(tr("physics")));
  row->addWidget(physics_box_, 1);
  sv->addLayout(row);
  results_table_ = new QTableWidget(0, 3);
  results_table_->setHorizontalHeaderLabels({tr("result"), tr("value"), tr("unit / check")});
  results_table_->horizontalHeader()->setSectionResizeMode(QHeaderView::ResizeToContents);
  results_table_->setMinimumWidth(330);
  results_table_->verticalHeader()->hide();
  results_table_->setEditTriggers(QAbstractItemView::NoEditTriggers);
  sv->addWidget(results_table_, 1);
  auto* results_dock = new QDockWidget(tr("Solve and results"));
  results_dock->setObjectName("results");
  results_dock->setWidget(panel);
  addDockWidget(Qt::RightDockWidgetArea, results_dock);
}

void Workbench::show_results() {
  const RunResults& r = results_;
  results_table_->setRowCount(0);
  auto add = [&](const QString& a, const QString& b, const QString& c) {
    const int row = results_table_->rowCount();
    results_table_->insertRow(row);
    results_table_->setItem(row, 0, new QTableWidgetItem(a));
    results_table_->setItem(row, 1, new QTableWidgetItem(b));
    results_table_->setItem(row, 2, new QTableWidgetItem(c));
  };
  add(tr("status"), run_status_name(r.status), QString::fromStdString(r.error));
  add(tr("nodes / tets"), QString("%1 / %2").arg(r.nodes).arg(r.tets), {});
  for (const ResultValue& v : r.values)
    add(QString::fromStdString(v.name) + (v.key ? " *" : ""), QString::number(v.value, 'g', 6),
        QString::fromStdString(v.unit));
  for (const BalanceCheck& c : r.checks)
    add(tr("check ") + QString::fromStdString(c.name), QString::number(c.figure, 'g', 3),
        (c.passed ? tr("ok, tolerance ") : tr("FAILED, tolerance ")) + QString::number(c.tolerance, 'g', 3));
}

}  // namespace foxi::workbench
