// The charts and the structure function of foxi solve --physics transient (issue 18): Zth(t) on a
// log time axis and Tj(t) as OUT_zth.png, and, for one junction heated by a step of power, the
// cumulative structure function (foxi/solver/structure_function.hpp) as OUT_structure.csv and
// OUT_structure.png.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include "foxi/solver/solver.hpp"
#include "foxi/viz/text.hpp"

namespace foxi::cli {

struct JunctionCurve {
  std::string name;        // the region
  std::string waveform;    // "step", "pulse", "table"
  double step_power = 0;   // W, for a step (else 0)
  std::vector<double> tj;  // K at each time
  // K s/W: the body's first moment of Zth, TransientReport::capacity_moment / P^2 (NaN: not known)
  double moment = std::numeric_limits<double>::quiet_NaN();
};

// Zth is (Tj(t) - Tj(0)) / P for a step of P != 0 only: a junction with another waveform gets no
// Zth (a line says so) and, when no junction has a step, the picture is OUT_tj.png with Tj(t) alone.
// The structure function needs exactly one powered junction with a step (several sources heat each
// other's junctions, so no single path is described; a line says so), and a Foster fit within 1 %
// of Zth(end) (else a line says it is not written and why: too few steps) whose first moment, sum R
// tau, is within 10 % of the body's (`moment`, where the run reached the steady state: steps long
// against the body's time constants make a discrete Zth with other time constants, which the fit
// follows). Prints what it wrote.
// `shown`: the stem the printed lines name (the files may be written elsewhere first: a series'
// staging folder).
void write_transient_charts(const std::string& stem, const std::vector<double>& times,
                            const std::vector<JunctionCurve>& junctions, const TextRenderer& text,
                            const std::string& shown);

}  // namespace foxi::cli
