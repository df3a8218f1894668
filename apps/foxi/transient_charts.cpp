// See transient_charts.hpp.
#include "transient_charts.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "foxi/model/durable_file.hpp"
#include "foxi/solver/structure_function.hpp"
#include "foxi/viz/chart.hpp"
#include "foxi/viz/png.hpp"

namespace foxi::cli {

namespace {

constexpr int kChartWidth = 820, kChartHeight = 440;
constexpr double kFitTolerance = 0.01;    // the Foster fit's largest error against Zth(end)
constexpr double kMomentTolerance = 0.1;  // the fit's first moment against the body's

std::string number(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

}  // namespace

void write_transient_charts(const std::string& stem, const std::vector<double>& times,
                            const std::vector<JunctionCurve>& junctions, const TextRenderer& text,
                            const std::string& shown) {
  Chart zth, tj;
  zth.title = "Thermal impedance Zth(t) = (Tj(t) - Tj(0)) / P";
  zth.x = {"time", "s", true};
  zth.y = {"Zth", "K/W"};
  tj.title = "Junction temperature";
  tj.x = {"time", "s"};
  tj.y = {"Tj (max over the region)", "K"};
  std::vector<const JunctionCurve*> stepped;
  for (std::size_t j = 0; j < junctions.size(); ++j) {
    const JunctionCurve& c = junctions[j];
    tj.series.push_back({c.name, times, c.tj, chart_color(j)});
    if (c.waveform == "step" && c.step_power != 0) {
      ChartSeries s{c.name, {}, {}, chart_color(j)};
      for (std::size_t i = 1; i < times.size(); ++i) {  // t = 0 has no place on a log axis
        s.x.push_back(times[i]);
        s.y.push_back((c.tj[i] - c.tj[0]) / c.step_power);
      }
      zth.series.push_back(std::move(s));
      stepped.push_back(&c);
    } else {
      std::printf("Zth(t) of %s: not computed: Zth is defined for a step of power, and its power is %s\n",
                  c.name.c_str(), c.waveform == "step" ? "zero" : ("a " + c.waveform).c_str());
    }
  }
  const bool with_zth = !zth.series.empty();
  const std::string picture = stem + (with_zth ? "_zth.png" : "_tj.png");
  {
    Framebuffer fb(kChartWidth, with_zth ? 2 * kChartHeight : kChartHeight);
    int top = 0;
    if (with_zth) {
      draw_chart(fb, text, zth, PixelRect{0, 0, kChartWidth - 1, kChartHeight - 1});
      top = kChartHeight;
    }
    draw_chart(fb, text, tj, PixelRect{0, top, kChartWidth - 1, top + kChartHeight - 1});
    write_png(picture, fb);
  }
  std::printf("wrote %s (%s)\n", (shown + (with_zth ? "_zth.png" : "_tj.png")).c_str(),
              with_zth ? "Zth against log time, Tj against time" : "Tj against time");

  if (stepped.empty()) return;
  if (junctions.size() != 1) {
    std::printf(
        "structure function: not computed: %zu regions are powered (it describes the heat path of "
        "one source; each heats the others' junctions)\n",
        junctions.size());
    return;
  }
  const JunctionCurve& c = *stepped.front();
  std::vector<double> t, z;
  for (std::size_t i = 1; i < times.size(); ++i) {
    t.push_back(times[i]);
    z.push_back((c.tj[i] - c.tj[0]) / c.step_power);
  }
  if (t.size() < 3) {
    std::printf("structure function: not computed: %zu time steps (at least 3 are needed)\n", t.size());
    return;
  }
  const StructureFunction sf = structure_function(t, z);
  const double zend = std::abs(z.back());
  const double fit_error = zend > 0 ? sf.fit.max_error / zend : NAN;
  // The structure function is only as good as the fit it comes from: refused past 1 % of Zth(end).
  if (!(fit_error <= kFitTolerance)) {
    // A step response is monotone; a discrete one that falls somewhere is the time stepping's
    // (BDF2 overshoots at steps long against the time constants), which no sum of rising
    // exponentials fits.
    double peak = z.front(), drop = 0, drop_at = 0;
    for (std::size_t i = 0; i < z.size(); ++i) {
      if (peak - z[i] > drop) drop = peak - z[i], drop_at = t[i];
      peak = std::max(peak, z[i]);
    }
    std::string why = std::to_string(t.size()) + " time steps do not resolve it; use more --steps";
    if (drop > 0) {
      char buf[200];
      std::snprintf(buf, sizeof buf,
                    "Zth(t) falls by %.3g K/W by t = %.4g s, which a step response does not (the time "
                    "stepping's overshoot: use more --steps, or --scheme euler)",
                    drop, drop_at);
      why = buf;
    }
    std::printf(
        "structure function of %s: not written: the Foster fit misses Zth(t) by %.3g K/W, %.2g %% of "
        "Zth(end) (more than %g %%): %s\n",
        c.name.c_str(), sf.fit.max_error, 100 * fit_error, 100 * kFitTolerance, why.c_str());
    return;
  }
  // The fit's first moment against the body's (at the steady state only: before it, the body's is
  // not the moment). A first step long against the body's time constants gives a discrete Zth whose
  // time constants are the stepping's: 1e6 s in 100 steps put C 92 J/K at the junction of a body of
  // 1 J/K, the fit within 0.07 % (an outside probe); its moment was 93 times the body's.
  double fit_moment = 0;
  for (const FosterTerm& f : sf.fit.terms) fit_moment += f.r * f.tau;
  if (sf.settled <= 0.01 && std::isfinite(c.moment) && c.moment > 0 &&
      !(std::abs(fit_moment / c.moment - 1) <= kMomentTolerance)) {
    std::printf(
        "structure function of %s: not written: the fit's first moment, sum R tau = %.4g K s/W, is %.3g "
        "times the body's, sum m (dT / P)^2 = %.4g K s/W (more than %g %% off): the first step (%.3g s) "
        "is too long for the body's time constants; use more --steps\n",
        c.name.c_str(), fit_moment, fit_moment / c.moment, c.moment, 100 * kMomentTolerance, t.front());
    return;
  }
  {
    std::string csv = "stage,R_K/W,C_J/K,cumulative_R_K/W,cumulative_C_J/K\n";
    for (std::size_t i = 0; i < sf.cauer.size(); ++i)
      csv += std::to_string(i + 1) + ',' + number(sf.cauer[i].r) + ',' + number(sf.cauer[i].c) + ',' +
             number(sf.cumulative_r[i]) + ',' + number(sf.cumulative_c[i]) + '\n';
    DurableFile f(stem + "_structure.csv");
    f.write(csv);
    f.commit();
  }
  {
    // The staircase: C_sum(R) is cumulative_c[i] on [cumulative_r[i-1], cumulative_r[i]).
    Chart s;
    s.title = "Cumulative structure function of " + c.name;
    s.x = {"cumulative thermal resistance", "K/W"};
    s.y = {"cumulative thermal capacitance", "J/K", true};
    ChartSeries st{"", {}, {}, chart_color(0)};
    for (std::size_t i = 0; i < sf.cumulative_r.size(); ++i) {
      st.x.push_back(i == 0 ? 0.0 : sf.cumulative_r[i - 1]);
      st.y.push_back(sf.cumulative_c[i]);
      st.x.push_back(sf.cumulative_r[i]);
      st.y.push_back(sf.cumulative_c[i]);
    }
    s.series.push_back(std::move(st));
    Framebuffer fb(kChartWidth, kChartHeight + 60);
    draw_chart(fb, text, s, PixelRect{0, 0, kChartWidth - 1, kChartHeight + 59});
    write_png(stem + "_structure.png", fb);
  }
  std::printf(
      "structure function of %s: %zu Cauer stages from %zu Foster terms (time constants %.3g s to "
      "%.3g s), total R %.6g K/W against Zth(end) %.6g K/W, C at the junction %.4g J/K; Foster fit "
      "error %.3g K/W at most (%.2g %% of Zth(end), within %g %%)\n",
      c.name.c_str(), sf.cauer.size(), sf.fit.terms.size(),
      sf.fit.terms.empty() ? NAN : sf.fit.terms.front().tau,
      sf.fit.terms.empty() ? NAN : sf.fit.terms.back().tau,
      sf.cumulative_r.empty() ? NAN : sf.cumulative_r.back(), z.back(),
      sf.cauer.empty() ? NAN : sf.cauer.front().c, sf.fit.max_error, 100 * fit_error, 100 * kFitTolerance);
  if (sf.settled > 0.01)
    std::printf(
        "note: Zth still rose %.1f %% over the last tenth of the log time: the heat has not reached the "
        "ambient, so the structure function ends early (its last stages stand for what is beyond); "
        "run longer (--time) for the whole path\n",
        100 * sf.settled);
  std::printf("wrote %s_structure.csv and %s_structure.png (cumulative C against cumulative R)\n",
              shown.c_str(), shown.c_str());
  return;
}

}  // namespace foxi::cli
