// Writing results: the files of a run or a sweep (their JSON comes from report.cpp).
#include "output.hpp"

#include "gnuplot.hpp"
#include "report.hpp"

#include <nlohmann/json.hpp>

#include "problem.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>

namespace lpshoot::app {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::ordered_json;

std::string number(double x) {  // full precision; empty for "no value"
  if (!std::isfinite(x)) return "";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  return buf;
}

std::string csv(const Table& t) {
  std::string s;
  for (size_t c = 0; c < t.names.size(); ++c) s += (c ? "," : "") + t.names[c];
  s += "\n";
  for (size_t r = 0; r < t.rows(); ++r) {
    for (size_t c = 0; c < t.columns.size(); ++c) s += (c ? "," : "") + number(t.columns[c][r]);
    s += "\n";
  }
  return s;
}

// Pretty JSON; text that is not UTF-8 (a file name from the command line) is written with U+FFFD.
std::string dump(const json& j) { return j.dump(2, ' ', false, json::error_handler_t::replace) + "\n"; }

std::string lines(const std::string& file, const std::string& x, const std::string& y, const std::string& title) {
  return "'" + file + "' using '" + x + "':'" + y + "' with lines lw 2 title '" + title + "'";
}

// The panels of trajectory.png: the descriptor's, or its shape, group coordinates and outputs
// against t.
std::vector<PlotPanel> plot_panels(const Scene& scene) {
  const ProblemDescriptor& d = scene.problem->descriptor();
  if (!d.plots.empty()) return d.plots;
  std::vector<PlotPanel> panels = {{"shape", "t", d.shape, false}};
  if (!d.group.empty()) panels.push_back({"group coordinates", "t", d.group, false});
  if (!d.outputs.empty()) panels.push_back({"outputs", "t", d.outputs, false});
  return panels;
}

std::string run_plot_script(const Scene& scene, const RunRecord& r, bool momentum_plot) {
  std::ostringstream s;
  s << "# lpshoot plots: run `gnuplot plot.gp` in this directory to redraw.\n"
    << "set datafile separator ','\nset key autotitle columnhead\nset grid\n";
  s << gp_header("trajectory.png", 1500, 450);
  char title[200];
  std::snprintf(title, sizeof title, "%s (%s): N = %d, h = %.4g%s", r.problem.c_str(), r.command.c_str(), r.N, r.h,
                r.has_cost ? (", cost " + number(r.cost).substr(0, 10)).c_str() : "");
  const std::vector<PlotPanel> panels = plot_panels(scene);
  s << "set multiplot layout 1," << panels.size() << " title \"" << title << "\"\n";
  const std::string f = "trajectory.csv";
  for (const PlotPanel& panel : panels) {
    s << "set title '" << panel.title << "'\nset xlabel '" << panel.x << "'\nset ylabel '"
      << (panel.equal_axes && panel.y.size() == 1 ? panel.y.front() : "") << "'\n"
      << (panel.equal_axes ? "set size ratio -1\n" : "");
    s << "plot ";
    for (size_t i = 0; i < panel.y.size(); ++i)
      s << (i ? ", " : "")
        << lines(f, panel.x, panel.y[i], panel.equal_axes ? "(" + panel.x + ", " + panel.y[i] + ")" : panel.y[i]);
    s << "\n" << (panel.equal_axes ? "set size noratio\n" : "");
  }
  s << "unset multiplot\nset output\n";
  if (momentum_plot) {
    s << gp_header("momentum.png", 800, 500) << "set title 'spatial momentum drift max_i |J_n - J_0|_i'\n"
      << "set xlabel 't'\nset ylabel ''\nset size noratio\n";
    const bool P = r.has_physical_momentum;
    if (r.momentum_drift > 0 || (P && r.physical_momentum_drift > 0)) {
      s << "set logscale y\nset format y '10^{%L}'\n"
        << "plot 'momentum.csv' using 't':(column('J_drift') > 0 ? column('J_drift') : NaN) with points pt 7 ps 0.4 "
           "title '" << (P ? "optimal-control momentum " : "") << "|J_n - J_0| (zeros not shown)'";
      if (P)
        s << ", '' using 't':(column('P_drift') > 0 ? column('P_drift') : NaN) with points pt 7 ps 0.4 "
             "title 'mechanical momentum |P_n - P_0|'";
      s << "\n";
    } else {
      s << "set yrange [-1:1]\nplot 'momentum.csv' using 't':'J_drift' with lines lw 2 title '|J_n - J_0| (exactly 0)'\n";
    }
    s << "set output\n";
  }
  return s.str();
}

}  // namespace

Written write_run(const Scene& scene, const RunRecord& r, OutputDir& out, bool plot) {
  Written w;
  if (r.converged) {  // a failed run writes its report only
    out.write("trajectory.csv", csv(r.trajectory));
    w.files.push_back(out.final_path("trajectory.csv"));
    if (r.error_estimate && r.error_estimate->extrapolation_order > 0) {
      out.write("trajectory_extrapolated.csv", csv(r.error_estimate->extrapolated));
      w.files.push_back(out.final_path("trajectory_extrapolated.csv"));
    }
    if (r.has_momentum) {
      out.write("momentum.csv", csv(r.momentum));
      w.files.push_back(out.final_path("momentum.csv"));
    }
    if (plot) {
      std::vector<std::string> pngs = {"trajectory.png"};
      if (r.has_momentum) pngs.push_back("momentum.png");
      run_gnuplot(out, run_plot_script(scene, r, r.has_momentum), pngs, w);
    }
  }

  json j = run_report(scene, r);
  w.files.insert(w.files.begin(), out.final_path("report.json"));
  j["files"] = w.files;
  j["warnings"] = w.warnings;
  out.write("report.json", dump(j));
  out.commit();
  return w;
}

Written write_sweep(const Scene& scene, const SweepRecord& sw, OutputDir& out, bool plot) {
  Written w;
  // The CSV carries the solver as text columns; build it by hand.
  std::string s = "N,h,scheme,method,backend,segments,converged,error,order,cost,cost_error,wall_time_s,iterations,"
                  "momentum_drift\n";
  for (size_t i = 0; i < sw.runs.size(); ++i) {
    const auto& r = sw.runs[i];
    s += std::to_string(r.N) + "," + number(r.h) + "," + r.scheme + "," + r.method + "," + r.backend + "," +
         std::to_string(r.segments) + "," + (r.converged ? "1" : "0") + "," + number(r.error) + "," + number(r.order) + "," +
         number(r.cost) + "," + number(r.cost_error) + "," + number(r.wall_time_s) + "," + std::to_string(r.iterations) +
         "," + number(r.momentum_drift) + "\n";
  }
  out.write("sweep.csv", s);
  w.files.push_back(out.final_path("sweep.csv"));
  if (plot) {
    std::ostringstream g;
    g << "# lpshoot sweep plot: run `gnuplot plot.gp` in this directory to redraw.\n"
      << "set datafile separator ','\nset grid\nset logscale xy\nset format y '10^{%L}'\n"
      << gp_header("sweep_error_time.png", 900, 600) << "set xlabel 'wall time [s]'\nset ylabel 'max error vs "
      << (sw.reference.rfind("exact", 0) == 0 ? "exact solution" : "finest grid") << "'\n"
      << "set title '" << sw.problem << ": error against cost (labels: N)'\nset key top right\n";
    // One line per scheme and solver: columns 3-5 (scheme, method, backend), error 8, time 12.
    std::vector<std::string> lines;
    for (const auto& r : sw.runs)
      if (const std::string key = r.scheme + "," + r.method + "," + r.backend;
          std::find(lines.begin(), lines.end(), key) == lines.end())
        lines.push_back(key);
    g << "plot ";
    for (size_t i = 0; i < lines.size(); ++i) {
      const std::string sel = "(strcol(3).','.strcol(4).','.strcol(5) eq '" + lines[i] + "' ? column(8) : NaN)";
      std::string name = lines[i] == ",," ? "discrete flow" : lines[i];
      std::replace(name.begin(), name.end(), ',', ' ');
      g << (i ? ", " : "") << "'sweep.csv' skip 1 using 12:" << sel << " with linespoints lw 2 pt 7 title '" << name
        << "', '' skip 1 using 12:" << sel << ":1 with labels offset 0,1 notitle";
    }
    g << "\nset output\n";
    run_gnuplot(out, g.str(), {"sweep_error_time.png"}, w);
  }
  json j = sweep_report(scene, sw);
  w.files.insert(w.files.begin(), out.final_path("sweep.json"));
  j["files"] = w.files;
  j["warnings"] = w.warnings;
  out.write("sweep.json", dump(j));
  out.commit();
  return w;
}

Written write_interrupted(const Scene& scene, const std::string& command, OutputDir& out, const std::string& why,
                          double wall_time_s) {
  Written w;
  json j;
  j["lpshoot_version"] = "0.1.0";
  j["command"] = command;
  j["status"] = "interrupted";
  j["converged"] = false;
  j["message"] = why + " before the run finished; no results were kept";
  j["problem"] = scene.problem_name;
  j["scene_file"] = scene.file;
  j["wall_time_s"] = wall_time_s;
  const std::string name = command == "sweep" ? "sweep.json" : "report.json";
  w.files.push_back(out.final_path(name));
  j["files"] = w.files;
  j["scene"] = json::parse(scene.effective_json);
  out.write(name, dump(j));
  out.commit();
  return w;
}

}  // namespace lpshoot::app
