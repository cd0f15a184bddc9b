// lpshoot._core: the Python module's C++ half, thin over the application's own code (scene.hpp,
// run.hpp, sweep.hpp, report.hpp, output.hpp, describe.hpp, plugin.hpp). The Python API is
// lpshoot/__init__.py; pybind11 stays in this file.
//
// Threads: scenes are read and plugins loaded with the GIL held (they touch the problem
// registry); runs, sweeps and writing results release it, so Python threads solve in parallel.
// A run takes the GIL back only at its progress checkpoints (once per solver iteration), to let
// Ctrl-C (KeyboardInterrupt) and the caller's progress function in.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <lpshoot/app/describe.hpp>
#include <lpshoot/app/output.hpp>
#include <lpshoot/app/plugin.hpp>
#include <lpshoot/app/report.hpp>
#include <lpshoot/app/scene.hpp>

#include <nlohmann/json.hpp>

namespace py = pybind11;
using namespace lpshoot;
using namespace lpshoot::app;

namespace {

// A scene from a path, or from JSON text (the Python side dumps a dict), with --set overrides;
// checked by counting as `lpshoot check` does. Throws SceneError.
Scene read_scene(const std::string& source, bool is_text, const std::vector<std::string>& overrides) {
  Scene s = is_text ? load_scene_text(source, "scene", overrides) : load_scene(source, overrides);
  if (const std::string why = check_boundary(s); !why.empty()) throw SceneError(s.file + ": boundary: " + why);
  return s;
}

// The progress function handed to a run (called with the GIL released). `callback` outlives
// the run: it belongs to the binding's frame. A pending signal or a raising callback becomes the
// Python exception the run ends with.
Progress checkpoint(const py::object* callback) {
  return [callback](const std::string& line) {
    py::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    if (!line.empty() && !callback->is_none()) (*callback)(line);
  };
}

py::object from_json(const nlohmann::ordered_json& j) {
  return py::module_::import("json").attr("loads")(j.dump());
}

// Columns as float64 arrays in their order (t first); NaN where a column has no value at a node.
py::dict arrays(const Table& t) {
  py::dict d;
  for (size_t c = 0; c < t.names.size(); ++c)
    d[py::str(t.names[c])] = py::array_t<double>(static_cast<py::ssize_t>(t.columns[c].size()), t.columns[c].data());
  return d;
}

struct Run {
  Scene scene;
  RunRecord record;
};

struct Sweep {
  Scene scene;
  SweepRecord record;
};

template <class Write>
std::vector<std::string> write_to(const std::string& dir, Write&& write) {
  py::gil_scoped_release release;
  OutputDir out(dir);
  return write(out).files;
}

Run run(const std::string& command, const std::string& source, bool is_text, const std::vector<std::string>& overrides,
        const py::object& progress) {
  Run r{read_scene(source, is_text, overrides), {}};
  const Progress p = checkpoint(&progress);
  py::gil_scoped_release release;
  r.record = run_scene(command, r.scene, p);
  return r;
}

Sweep sweep(const std::string& source, bool is_text, const std::vector<std::string>& overrides, const std::vector<int>& N,
            const std::vector<std::string>& schemes, const std::vector<std::string>& methods,
            const std::vector<std::string>& backends, int steps_per_segment, bool use_exact, const py::object& progress) {
  Sweep s{read_scene(source, is_text, overrides), {}};
  SweepOptions o;
  o.N = N;
  o.schemes = schemes;
  for (const auto& m : methods) {
    if (m != "single" && m != "multiple") throw SceneError("methods: unknown method \"" + m + "\" (single, multiple)");
    o.methods.push_back(m == "multiple" ? ShootingMethod::Multiple : ShootingMethod::Single);
  }
  for (const auto& b : backends) {
    if (b != "kinsol" && b != "nlopt") throw SceneError("backends: unknown backend \"" + b + "\" (kinsol, nlopt)");
    o.backends.push_back(b == "nlopt" ? Backend::Nlopt : Backend::Kinsol);
  }
  if (steps_per_segment < 0) throw SceneError("steps_per_segment: must be > 0 (got " + std::to_string(steps_per_segment) + ")");
  if (!s.scene.is_optimal_control() && (!o.methods.empty() || !o.backends.empty() || !o.schemes.empty() || steps_per_segment > 0))
    throw SceneError("schemes/methods/backends/steps_per_segment: a " + s.scene.problem_name +
                     " simulation has no scheme or shooting solver to choose");
  o.steps_per_segment = steps_per_segment;
  o.use_exact = use_exact;
  const Progress p = checkpoint(&progress);
  const std::string command = s.scene.is_optimal_control() ? "solve" : "simulate";
  py::gil_scoped_release release;
  s.record = run_sweep(s.scene, command, o, p);
  return s;
}

py::dict check(const std::string& source, bool is_text, const std::vector<std::string>& overrides) {
  const Scene s = read_scene(source, is_text, overrides);
  py::dict d;
  d["file"] = s.file;
  d["problem"] = s.problem_name;
  d["command"] = s.is_optimal_control() ? "solve" : "simulate";
  d["N"] = s.N;
  d["T"] = s.T;
  d["h"] = s.h();
  d["scene"] = py::module_::import("json").attr("loads")(s.effective_json);
  return d;
}

// Builds (minutes the first time) and loads with the GIL released, so that other Python threads
// run meanwhile; the notification takes it back.
py::dict load_problem(const std::string& file, const std::string& cache_dir, const py::object& notify) {
  PluginOptions o;
  o.cache_dir = cache_dir;
  if (!notify.is_none())
    o.notify = [&notify](const std::string& what) {
      py::gil_scoped_acquire gil;
      notify(what);
    };
  LoadedPlugin p;
  {
    py::gil_scoped_release release;
    p = load_problem_file(file, o);
  }
  py::dict d;
  d["source"] = p.source;
  d["library"] = p.library;
  d["built"] = p.built;
  d["build_seconds"] = p.build_seconds;
  d["problems"] = p.problems;
  return d;
}

}  // namespace

PYBIND11_MODULE(_core, m) {
  m.doc() = "lpshoot's C++ half; use the lpshoot package";
  py::register_exception<SceneError>(m, "SceneError", PyExc_ValueError);
  py::register_exception<OutputError>(m, "OutputError", PyExc_OSError);
  py::register_exception<PluginError>(m, "PluginError", PyExc_RuntimeError);

  py::class_<Run>(m, "Run")
      .def_property_readonly("report", [](const Run& r) { return from_json(run_report(r.scene, r.record)); })
      .def_property_readonly("trajectory", [](const Run& r) { return arrays(r.record.trajectory); })
      .def_property_readonly("momentum", [](const Run& r) { return arrays(r.record.momentum); })
      .def_property_readonly("extrapolated",
                             [](const Run& r) {
                               const auto& e = r.record.error_estimate;
                               return e && e->extrapolation_order > 0 ? arrays(e->extrapolated) : py::dict();
                             })
      .def_property_readonly("state_columns", [](const Run& r) { return r.record.state_columns; })
      .def_property_readonly("out_dir", [](const Run& r) { return r.scene.out_dir; })
      .def_property_readonly("plot", [](const Run& r) { return r.scene.plot; })
      .def("write", [](const Run& r, const std::string& dir, bool plot) {
        return write_to(dir, [&](OutputDir& out) { return write_run(r.scene, r.record, out, plot); });
      });
  py::class_<Sweep>(m, "Sweep")
      .def_property_readonly("report", [](const Sweep& s) { return from_json(sweep_report(s.scene, s.record)); })
      .def_property_readonly("out_dir", [](const Sweep& s) { return s.scene.out_dir; })
      .def_property_readonly("plot", [](const Sweep& s) { return s.scene.plot; })
      .def("write", [](const Sweep& s, const std::string& dir, bool plot) {
        return write_to(dir, [&](OutputDir& out) { return write_sweep(s.scene, s.record, out, plot); });
      });

  m.def("run", &run);
  m.def("sweep", &sweep);
  m.def("check", &check);
  m.def("problems_json", [] { return problems_json(registered_problems()); });
  m.def("load_problem", &load_problem);
  m.def("registration_errors", &registration_errors);
}
