// foxi-workbench's solve panel: the physics a solve runs (the model's conditions and loads of it, as
// foxi solve MODEL --physics NAME takes them), and the derived quantities and balance checks of the
// last solve.
#include "workbench.hpp"
#include "workbench_parts.hpp"

#include <QComboBox>
#include <QDoubleSpinBox>
#include <QDockWidget>
#include <QHBoxLayout>
#include <QHeaderView>
#include <QLabel>
#include <QPushButton>
#include <QSignalBlocker>
#include <QTableWidget>
#include <QVBoxLayout>
#include <cmath>

#include "foxi/model/io_error.hpp"
#include "foxi/solver/calculix.hpp"
#include "foxi/solver/electric.hpp"
#include "foxi/solver/model_problem.hpp"
#include "foxi/solver/thermal.hpp"
#include "foxi/solver/thermoelastic.hpp"

namespace foxi::workbench {

namespace {

constexpr Physics kPhysics[] = {Physics::thermal, Physics::electrostatic, Physics::current,
                                Physics::thermal_stress};

}  // namespace

bool calculix_solves(Physics physics) {
  return physics == Physics::thermal || physics == Physics::thermal_stress;
}

std::optional<Physics> physics_of(const std::string& name) {
  for (Physics p : kPhysics)
    if (name == physics_name(p)) return p;
  return std::nullopt;
}

std::optional<SolverChoice> solver_of(const std::string& name) {
  if (name == "auto") return SolverChoice{false, LinearSolverKind::automatic};
  if (name == "direct") return SolverChoice{false, LinearSolverKind::direct};
  if (name == "amg") return SolverChoice{false, LinearSolverKind::cg_amg};
  if (name == "ichol") return SolverChoice{false, LinearSolverKind::cg_ichol};
  if (name == "ccx") return SolverChoice{true, LinearSolverKind::automatic};
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
                               const LinearSolverOptions& solver, bool calculix) {
  if (calculix && physics != Physics::thermal && physics != Physics::thermal_stress)
    throw SolverError(std::string("CalculiX solves the thermal and thermal stress problems here, not ") +
                      physics_name(physics));
  // foxi solve MODEL --with ccx: ccx's results with foxi's report of them (its checks); Cancel kills ccx.
  CalculixRunOptions ccx;
  ccx.progress = solver.progress;
  // Each branch takes from the model what foxi solve MODEL --physics NAME takes (cmd_solve.cpp,
  // cmd_solve_thermoelastic.cpp) with no other option, so that the results are the CLI's.
  switch (physics) {
    case Physics::electrostatic: {
      ElectrostaticParams ep;
      ep.solver = solver;
      ep.conductors = electrostatic_params_from_model(model, mesh).conductors;
      return electrostatic_results(mesh, solve_electrostatic(mesh, ep));
    }
    case Physics::current: {
      CurrentParams cp;
      cp.solver = solver;
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
      tp.solver = solver;
      if (calculix) return thermoelastic_results(mesh, solve_thermoelastic_calculix(mesh, tp, ccx).report);
      return thermoelastic_results(mesh, solve_thermoelastic(mesh, tp));
    }
    case Physics::thermal:
      break;
  }
  ThermalParams params = thermal_params_from_model(model, mesh);
  params.solver = solver;
  if (calculix) return thermal_results(mesh, solve_thermal_calculix(mesh, params, ccx).report);
  return thermal_results(mesh, solve_thermal(mesh, params));
}

DisplayUnit Workbench::shown_unit(const std::string& si_unit, double max_abs) const {
  return unit_for(si_unit, max_abs, si_units_);
}

DisplayUnit unit_for(const std::string& si_unit, double max_abs, bool si) {
  return si ? DisplayUnit{si_unit, 1, 0} : default_display_unit(si_unit, max_abs);
}

bool Workbench::set_solver(const SolverChoice& choice) {
  if (busy() || (choice.calculix && !calculix_solves(physics_))) return false;
  solver_ = choice;
  const QSignalBlocker quiet(solver_box_);
  const int want = choice.calculix ? -1 : int(choice.linear);
  solver_box_->setCurrentIndex(std::max(0, solver_box_->findData(want)));
  return true;
}

bool Workbench::set_si_units(bool si) {
  if (busy()) return false;
  // A colour range of the user's is in the unit shown: the same values in the new one.
  const Field* f = mesh_ && range_ ? mesh_->find_field(field_.toStdString()) : nullptr;
  if (f && si != si_units_) {
    const DisplayUnit to = unit_for(f->unit, std::max(std::abs(field_lo_), std::abs(field_hi_)), si);
    range_ = std::pair(to.to_display(unit_.to_si(range_->first)), to.to_display(unit_.to_si(range_->second)));
    const QSignalBlocker q1(range_lo_), q2(range_hi_);
    range_lo_->setValue(range_->first);
    range_hi_->setValue(range_->second);
  }
  si_units_ = si;
  {
    const QSignalBlocker quiet(units_box_);
    units_box_->setCurrentIndex(si ? 1 : 0);
  }
  if (has_results_) show_results();
  refresh_history();
  changed();
  return !mesh_ || field_.isEmpty() || set_field(field_, color_map_);
}

bool Workbench::set_physics(Physics physics) {
  if (busy()) return false;
  physics_ = physics;
  if (!calculix_solves(physics) && solver_.calculix) set_solver({});  // ccx: heat and thermal stress only
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
  // The solver: foxi's own (its linear solver as foxi solve --solver names it) or CalculiX.
  auto* row2 = new QHBoxLayout;
  solver_box_ = new QComboBox;
  solver_box_->setObjectName("solver");
  solver_box_->addItem(tr("built-in (auto)"), int(LinearSolverKind::automatic));
  solver_box_->addItem(tr("built-in, direct"), int(LinearSolverKind::direct));
  solver_box_->addItem(tr("built-in, CG + AMG"), int(LinearSolverKind::cg_amg));
  solver_box_->addItem(tr("built-in, CG + IC"), int(LinearSolverKind::cg_ichol));
  solver_box_->addItem(tr("CalculiX (ccx)"), -1);
  // Narrower than its longest entry when the window is (a laptop screen): the list shows them whole.
  solver_box_->setMinimumContentsLength(8);
  solver_box_->setSizeAdjustPolicy(QComboBox::AdjustToMinimumContentsLengthWithIcon);
  solver_box_->setToolTip(
      tr("foxi's solver (foxi solve --solver) or CalculiX, thermal and thermal_stress (foxi solve "
         "--with ccx: a ccx child process, killed by Cancel)"));
  connect(solver_box_, qOverload<int>(&QComboBox::currentIndexChanged), this, [this] {
    const int v = solver_box_->currentData().toInt();
    SolverChoice c;
    c.calculix = v < 0;
    if (v >= 0) c.linear = LinearSolverKind(v);
    if (!set_solver(c)) {
      show_error(tr("CalculiX solves the thermal and thermal stress problems only"));
      set_solver(solver_);
    }
  });
  units_box_ = new QComboBox;
  units_box_->setObjectName("units");
  units_box_->addItem(tr("°C, MPa, µm"));
  units_box_->addItem(tr("SI: K, Pa, m"));
  units_box_->setToolTip(tr("the unit of the values shown: the legend's, the results' and the history's"));
  connect(units_box_, qOverload<int>(&QComboBox::currentIndexChanged), this,
          [this](int i) { set_si_units(i == 1); });
  row2->addWidget(new QLabel(tr("solver")));
  row2->addWidget(solver_box_, 1);
  row2->addWidget(units_box_);
  sv->addLayout(row2);
  results_table_ = new QTableWidget(0, 3);
  results_table_->setObjectName("results");
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
  // Values in the unit the legend uses (°C, MPa, ...; or SI): one unit everywhere.
  for (const ResultValue& v : r.values) {
    const DisplayUnit u = shown_unit(v.unit, std::abs(v.value));
    add(QString::fromStdString(v.name) + (v.key ? " *" : ""), QString::number(u.to_display(v.value), 'g', 6),
        QString::fromStdString(u.symbol));
  }
  for (const BalanceCheck& c : r.checks)
    add(tr("check ") + QString::fromStdString(c.name), QString::number(c.figure, 'g', 3),
        (c.passed ? tr("ok, tolerance ") : tr("FAILED, tolerance ")) + QString::number(c.tolerance, 'g', 3));
}

}  // namespace foxi::workbench
