// Study files, their points, and one point's row (study.hpp).
#include "study.hpp"

#include "interrupt.hpp"
#include "sweep.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <new>
#include <random>
#include <sstream>

namespace lpshoot::app {
namespace {

using json = nlohmann::ordered_json;
namespace fs = std::filesystem;

constexpr size_t max_points = 10'000'000;

std::string read_text(const std::string& path, const std::string& what) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) throw SceneError(path + ": cannot read the " + what + ": no such file");
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  if (!in) throw SceneError(path + ": cannot read the " + what + ": unreadable");
  return s.str();
}

json parse(const std::string& text, const std::string& where) {
  try {
    return json::parse(text);
  } catch (const json::exception& e) {
    std::string what = e.what();
    const size_t at = what.find("] ");
    throw SceneError(where + ": invalid JSON: " + (at == std::string::npos ? what : what.substr(at + 2)));
  }
}

double finite_number(const json& v, const std::string& where) {
  if (!v.is_number() || !std::isfinite(v.get<double>())) throw SceneError(where + ": must be a finite number, got " + v.dump());
  return v.get<double>();
}

int count_of(const json& axis, const std::string& where) {
  if (!axis.contains("count")) throw SceneError(where + ".count: missing (required)");
  const json& c = axis["count"];
  if (!c.is_number_integer() || c.get<long long>() < 1 || c.get<long long>() > 1'000'000)
    throw SceneError(where + ".count: must be an integer from 1 to 1000000, got " + c.dump());
  return c.get<int>();
}

// `prefix` is what goes before an unknown key in the message ("FILE: " or "FILE: axes.KEY.").
void allow_only(const json& o, const std::vector<std::string>& keys, const std::string& prefix) {
  for (auto it = o.begin(); it != o.end(); ++it)
    if (std::find(keys.begin(), keys.end(), it.key()) == keys.end()) {
      std::string allowed;
      for (const auto& k : keys) allowed += (allowed.empty() ? "" : ", ") + k;
      throw SceneError(prefix + it.key() + ": unknown key (allowed here: " + allowed + ")");
    }
}

// One axis's values: a list, an evenly spaced range (linear or geometric), or seeded uniform draws.
std::vector<std::string> axis_values(const json& v, const std::string& where) {
  std::vector<std::string> out;
  if (v.is_array()) {
    if (v.empty()) throw SceneError(where + ": an empty list of values");
    for (const auto& x : v) out.push_back(x.is_number_float() ? number_text(x.get<double>()) : x.dump());
    return out;
  }
  const std::string forms = "must be a list of values, {\"from\": a, \"to\": b, \"count\": n[, \"log\": true]}, or "
                            "{\"random\": {\"uniform\": [a, b]}, \"count\": n, \"seed\": s}";
  if (!v.is_object()) throw SceneError(where + ": " + forms + " (got " + v.dump() + ")");
  if (v.contains("random")) {
    allow_only(v, {"random", "count", "seed"}, where + ".");
    const json& r = v["random"];
    if (!r.is_object() || r.size() != 1 || !r.contains("uniform") || !r["uniform"].is_array() || r["uniform"].size() != 2)
      throw SceneError(where + ".random: must be {\"uniform\": [a, b]} (got " + r.dump() + ")");
    const double a = finite_number(r["uniform"][0], where + ".random.uniform[0]");
    const double b = finite_number(r["uniform"][1], where + ".random.uniform[1]");
    const int n = count_of(v, where);
    const json seed = v.value("seed", json(0));
    if (!seed.is_number_unsigned()) throw SceneError(where + ".seed: must be a non-negative integer, got " + seed.dump());
    std::mt19937_64 gen(seed.get<unsigned long long>());
    for (int i = 0; i < n; ++i) {  // 53 random bits: the same draws on every platform
      const double u = static_cast<double>(gen() >> 11) * 0x1.0p-53;
      out.push_back(number_text(a + (b - a) * u));
    }
    return out;
  }
  if (v.contains("from") || v.contains("to")) {
    allow_only(v, {"from", "to", "count", "log"}, where + ".");
    if (!v.contains("from") || !v.contains("to")) throw SceneError(where + ": a range needs both \"from\" and \"to\"");
    const double a = finite_number(v["from"], where + ".from"), b = finite_number(v["to"], where + ".to");
    const int n = count_of(v, where);
    const json log = v.value("log", json(false));
    if (!log.is_boolean()) throw SceneError(where + ".log: must be true or false, got " + log.dump());
    if (log.get<bool>() && !(a > 0 && b > 0)) throw SceneError(where + ": a geometric (log) range needs from, to > 0");
    for (int i = 0; i < n; ++i) {
      const double s = n == 1 ? 0.0 : static_cast<double>(i) / (n - 1);
      const double x = i == n - 1 ? b : log.get<bool>() ? a * std::pow(b / a, s) : a + (b - a) * s;
      out.push_back(number_text(x));
    }
    return out;
  }
  throw SceneError(where + ": " + forms + " (got " + v.dump() + ")");
}

json value_or_null(double x) { return std::isfinite(x) ? json(x) : json(nullptr); }
double number_or_nan(const json& v) { return v.is_number() ? v.get<double>() : nan(); }

}  // namespace

std::string number_text(double x) {
  if (std::floor(x) == x && std::abs(x) < 9e15) return std::to_string(static_cast<long long>(x));
  char buf[32];
  for (int precision = 15; precision <= 17; ++precision) {
    std::snprintf(buf, sizeof buf, "%.*g", precision, x);
    if (std::strtod(buf, nullptr) == x) break;
  }
  return buf;
}

size_t Study::points() const {
  size_t n = 1;
  for (const auto& a : axes) n *= a.values.size();
  return n;
}

std::vector<std::string> Study::point(size_t i) const {
  std::vector<std::string> v(axes.size());
  for (size_t k = axes.size(); k-- > 0;) {  // the last axis fastest
    v[k] = axes[k].values[i % axes[k].values.size()];
    i /= axes[k].values.size();
  }
  return v;
}

Study load_study(const std::string& path) {
  Study st;
  st.file = path;
  st.name = fs::path(path).stem().string();
  const json j = parse(read_text(path, "study file"), path);
  if (!j.is_object()) throw SceneError(path + ": a study is a JSON object with \"scene\" and \"axes\"");
  allow_only(j, {"scene", "axes", "description"}, path + ": ");
  if (!j.contains("scene")) throw SceneError(path + ": scene: missing (required): a scene object, or the path of a scene file");
  const json& scene = j["scene"];
  if (scene.is_string()) {
    fs::path p = scene.get<std::string>();
    if (p.is_relative()) p = fs::path(path).parent_path() / p;
    st.scene_name = p.lexically_normal().string();
    st.scene_text = read_text(st.scene_name, "study's scene (key \"scene\" of " + path + ")");
  } else if (scene.is_object()) {
    st.scene_name = path + ": scene";
    st.scene_text = scene.dump();
  } else {
    throw SceneError(path + ": scene: must be a scene object or a path (got " + scene.dump() + ")");
  }
  const json axes = j.value("axes", json::object());
  if (!axes.is_object()) throw SceneError(path + ": axes: must be an object from scene key paths to values");
  size_t n = 1;
  for (auto it = axes.begin(); it != axes.end(); ++it) {
    const std::string where = path + ": axes." + it.key();
    if (it.key().empty() || it.key().front() == '.' || it.key().back() == '.' || it.key().find("..") != std::string::npos)
      throw SceneError(path + ": axes: \"" + it.key() + "\" is not a scene key path (such as horizon.N)");
    st.axes.push_back({it.key(), axis_values(it.value(), where)});
    n *= st.axes.back().values.size();
    if (n > max_points) throw SceneError(path + ": axes: more than 10^7 points; split the study");
  }
  return st;
}

StudyRow run_study_point(const Study& study, size_t i, const Progress& checkpoint) {
  StudyRow row;
  row.index = i;
  row.values = study.point(i);
  std::vector<std::string> sets;
  bool threads_given = false;
  for (size_t k = 0; k < study.axes.size(); ++k) {
    sets.push_back(study.axes[k].key + "=" + row.values[k]);
    threads_given = threads_given || study.axes[k].key == "solver.threads";
  }
  if (!threads_given) sets.push_back("solver.threads=1");  // the points run in parallel, not their segments
  Scene s;
  try {
    s = load_scene_text(study.scene_text, study.scene_name, sets);
    if (const std::string why = check_boundary(s); !why.empty()) throw SceneError(s.file + ": boundary: " + why);
  } catch (const SceneError& e) {
    row.status = "invalid_scene";
    row.message = e.what();
    return row;
  }
  row.N = s.N;
  row.h = s.h();
  row.scheme = s.is_optimal_control() ? s.scheme_name() : "flow";
  try {
    const RunRecord r = run_scene(s.is_optimal_control() ? "solve" : "simulate", s, checkpoint);
    row.status = r.status;
    row.message = r.message;
    row.iterations = r.iterations;
    row.residual_norm = r.residual_norm;
    row.wall_time_s = r.wall_time_s;
    if (!r.converged) return row;
    if (r.has_cost) row.cost = r.cost;
    if (const ExactReference exact = exact_reference(s, r.trajectory.columns.front()); exact.available) {
      row.error = max_error(r.trajectory, exact.table, r.state_columns);
      row.error_kind = "exact";
    } else if (r.error_estimate && r.error_estimate->failure.empty()) {
      row.error = r.error_estimate->value;
      row.error_kind = "estimate";
    }
  } catch (const SceneError& e) {
    row.status = "invalid_scene";
    row.message = e.what();
  } catch (const Interrupted&) {
    throw;
  } catch (const std::bad_alloc&) {
    row.status = "out_of_memory";
    row.message = "out of memory: the point is too large for this machine";
  } catch (const std::exception& e) {  // a fault in one point is that point's row, not the study's end
    row.status = "error";
    row.message = std::string("internal error: ") + e.what();
  }
  return row;
}

std::string row_json(const Study& study, const StudyRow& r) {
  json j;
  j["index"] = r.index;
  for (size_t k = 0; k < study.axes.size(); ++k) j[study.axes[k].key] = json::parse(r.values[k]);
  j["status"] = r.status;
  j["message"] = r.message;
  j["scheme_name"] = r.scheme;
  j["N"] = r.N;
  j["h"] = value_or_null(r.h);
  j["cost"] = value_or_null(r.cost);
  j["error"] = value_or_null(r.error);
  j["error_kind"] = r.error_kind;
  j["iterations"] = r.iterations;
  j["residual_norm"] = value_or_null(r.residual_norm);
  j["wall_time_s"] = r.wall_time_s;
  return j.dump(-1, ' ', false, json::error_handler_t::replace);
}

StudyRow row_from_json(const Study& study, const std::string& line) {
  json j;
  try {
    j = json::parse(line);
  } catch (const json::exception&) {
    throw SceneError("not a row: " + line.substr(0, 80));
  }
  StudyRow r;
  if (!j.is_object() || !j.contains("index") || !j["index"].is_number_unsigned() || j["index"].get<size_t>() >= study.points())
    throw SceneError("a row without a valid point index: " + line.substr(0, 80));
  r.index = j["index"].get<size_t>();
  r.values = study.point(r.index);
  for (size_t k = 0; k < study.axes.size(); ++k)
    if (!j.contains(study.axes[k].key) || j[study.axes[k].key] != json::parse(r.values[k]))
      throw SceneError("row " + std::to_string(r.index) + " has other values of " + study.axes[k].key +
                       " than this study's point " + std::to_string(r.index));
  r.status = j.value("status", "");
  r.message = j.value("message", "");
  r.scheme = j.value("scheme_name", "");
  r.N = j.value("N", 0);
  r.h = number_or_nan(j.value("h", json(nullptr)));
  r.cost = number_or_nan(j.value("cost", json(nullptr)));
  r.error = number_or_nan(j.value("error", json(nullptr)));
  r.error_kind = j.value("error_kind", "");
  r.iterations = j.value("iterations", 0);
  r.residual_norm = number_or_nan(j.value("residual_norm", json(nullptr)));
  r.wall_time_s = j.value("wall_time_s", 0.0);
  return r;
}

}  // namespace lpshoot::app
