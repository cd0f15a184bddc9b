// Writing results (nlohmann-json stays here and in scene.cpp).
#include "output.hpp"

#include <nlohmann/json.hpp>

#include "interrupt.hpp"
#include "problem.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cerrno>
#include <cstdlib>
#include <filesystem>
#include <fstream>
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

json finite_or_null(double x) { return std::isfinite(x) ? json(x) : json(nullptr); }

// Pretty JSON; text that is not UTF-8 (a file name from the command line) is written with U+FFFD.
std::string dump(const json& j) { return j.dump(2, ' ', false, json::error_handler_t::replace) + "\n"; }

// True when FILE is a whole PNG (it ends with the IEND chunk): a full disk can leave a
// truncated image behind a gnuplot that exits 0.
bool complete_png(const fs::path& file) {
  std::ifstream f(file, std::ios::binary | std::ios::ate);
  if (!f || f.tellg() < 20) return false;
  f.seekg(-8, std::ios::end);
  char tail[8];
  f.read(tail, 8);
  return f && std::string(tail, 4) == "IEND";
}

// Runs gnuplot on plot.gp in the staging directory (which writes the PNGs there). gnuplot runs
// as a child that SIGINT/SIGTERM reach (std::system would make this process ignore them).
void run_gnuplot(OutputDir& out, const std::string& script, const std::vector<std::string>& pngs, Written& w) {
  out.write("plot.gp", script);
  w.files.push_back(out.final_path("plot.gp"));
  const fs::path log = out.staging() / ".gnuplot.log";
  const pid_t pid = fork();
  if (pid == 0) {
    if (chdir(out.staging().c_str()) != 0) _exit(126);
    const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd >= 0) dup2(fd, 1), dup2(fd, 2);
    execlp("gnuplot", "gnuplot", "plot.gp", static_cast<char*>(nullptr));
    _exit(127);
  }
  int status = 0;
  bool waited = pid > 0;
  while (waited && waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) {
      waited = false;
      break;
    }
    if (interrupt_signal()) kill(pid, SIGTERM);  // then reap it
  }
  throw_if_interrupted();
  const int code = !waited ? -1 : WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  std::string first_line;
  {
    std::ifstream f(log);
    std::getline(f, first_line);
  }
  std::error_code ec;
  fs::remove(log, ec);
  if (code != 0) {
    std::string why = code == 127 ? "gnuplot is not installed (apt-get install gnuplot-nox)" : "gnuplot failed";
    if (code != 127 && !first_line.empty()) why += ": " + first_line;
    w.warnings.push_back("plots skipped: " + why + " (script kept in " + out.final_path("plot.gp") + ")");
    for (const auto& p : pngs) fs::remove(out.staging() / p, ec);
    return;
  }
  for (const auto& p : pngs) {
    if (complete_png(out.staging() / p)) {
      w.files.push_back(out.final_path(p));
    } else {
      fs::remove(out.staging() / p, ec);
      w.warnings.push_back("plot " + p + " was not produced in full (disk full?)");
    }
  }
}

std::string gp_header(const std::string& out, int width, int height) {
  std::ostringstream s;
  s << "set terminal pngcairo size " << width << "," << height << " font ',10'\n"
    << "set output '" << out << "'\n";
  return s.str();
}

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

  json j;
  j["lpshoot_version"] = "0.1.0";
  j["command"] = r.command;
  j["status"] = r.status;
  j["converged"] = r.converged;
  j["message"] = r.message;
  if (!r.detail.empty()) j["detail"] = r.detail;
  j["problem"] = r.problem;
  j["scene_file"] = scene.file;
  j["T"] = r.T;
  j["N"] = r.N;
  j["h"] = r.h;
  if (!r.method.empty()) {
    j["method"] = r.method;
    j["segments"] = r.segments;
    if (r.segments > 1) j["segment_starts"] = r.propagated_starts ? "forward sweep" : "guess";
    j["backend"] = r.backend;
    j["scheme"] = r.scheme;
    if (!r.closure.empty()) j["closure"] = r.closure;
  } else {
    j["method"] = "discrete flow (Newton per step)";
    j["backend"] = "lpshoot step Newton";
  }
  if (!r.constraints.empty()) j["constraints"] = r.constraints;
  j["tolerance"] = r.tolerance;
  if (r.error_estimate) {
    const auto& e = *r.error_estimate;
    if (!e.failure.empty())
      j["error_estimate"] = {{"value", nullptr}, {"failure", e.failure}};
    else
      j["error_estimate"] = {{"value", e.value},
                             {"observed_order", e.order_observed ? json(e.observed_order) : json(nullptr)},
                             {"grids", {r.N, r.N / 2, r.N / 4}},
                             {"differences", {e.d_fine, e.d_coarse}},
                             {"columns", r.state_columns},
                             {"extrapolation_order", e.extrapolation_order},
                             {"wall_time_s", e.wall_time_s}};
  }
  if (!r.continuation_parameter.empty())
    j["continuation"] = {{"parameter", "parameters." + r.continuation_parameter},
                         {"path", r.continuation_path},
                         {"solves", r.continuation_solves}};
  j["cost"] = r.has_cost ? finite_or_null(r.cost) : json(nullptr);
  j["action"] = finite_or_null(r.action);
  j["iterations"] = r.iterations;
  j["residual_norm"] = finite_or_null(r.residual_norm);
  if (r.command == "solve") {
    j["raw_residual_norm"] = finite_or_null(r.raw_residual_norm);
    j["residual_history"] = json::array();
    for (double x : r.residual_history) j["residual_history"].push_back(finite_or_null(x));
    j["condition"] = finite_or_null(r.condition);
    j["rank"] = r.rank >= 0 ? json(r.rank) : json(nullptr);
    j["unknowns"] = r.unknowns;
    if (!r.dependent_conditions.empty()) j["dependent_conditions"] = r.dependent_conditions;
  } else {
    j["condition"] = finite_or_null(r.condition);  // the largest per-step Newton condition number
  }
  if (r.has_momentum) {
    j["momentum_drift"] = r.momentum_drift;
    j["momentum_drift_relative"] = r.momentum_drift_relative;
    j["momentum_initial"] = r.momentum_initial;
    if (r.has_physical_momentum) {
      j["physical_momentum_drift"] = r.physical_momentum_drift;
      j["physical_momentum_initial"] = r.physical_momentum_initial;
    }
  } else {
    j["momentum_drift"] = r.converged && r.problem == "electron" ? json(0.0) : json(nullptr);
    j["momentum_note"] = r.problem == "electron" ? "the symmetry group is trivial: no momentum map to conserve"
                                                 : "no trajectory";
  }
  j["wall_time_s"] = r.wall_time_s;
  json fin = json::object();
  for (const auto& [k, v] : r.final_state) fin[k] = finite_or_null(v);
  j["final_state"] = fin;
  w.files.insert(w.files.begin(), out.final_path("report.json"));
  j["files"] = w.files;
  j["warnings"] = w.warnings;
  j["scene"] = json::parse(scene.effective_json);
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
  json j;
  j["lpshoot_version"] = "0.1.0";
  j["command"] = "sweep";
  j["status"] = sw.all_converged ? "converged" : "not_converged";
  j["message"] = sw.message;
  j["problem"] = sw.problem;
  j["reference"] = sw.reference;
  j["error_columns"] = sw.error_columns;
  j["runs"] = json::array();
  for (const auto& r : sw.runs) {
    json x;
    x["N"] = r.N;
    x["h"] = r.h;
    if (!r.method.empty())
      x["scheme"] = r.scheme, x["method"] = r.method, x["backend"] = r.backend, x["segments"] = r.segments;
    x["status"] = r.status;
    x["converged"] = r.converged;
    if (!r.converged) x["message"] = r.message;
    x["error"] = finite_or_null(r.error);
    x["order"] = finite_or_null(r.order);
    x["cost"] = finite_or_null(r.cost);
    x["cost_error"] = finite_or_null(r.cost_error);
    x["wall_time_s"] = r.wall_time_s;
    x["iterations"] = r.iterations;
    x["momentum_drift"] = r.momentum_drift;
    j["runs"].push_back(x);
  }
  w.files.insert(w.files.begin(), out.final_path("sweep.json"));
  j["files"] = w.files;
  j["warnings"] = w.warnings;
  j["scene"] = json::parse(scene.effective_json);
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
