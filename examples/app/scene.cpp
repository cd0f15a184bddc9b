// Scene parsing and validation (nlohmann-json stays in this file and in report.cpp).
#include "scene.hpp"

#include "problem.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <unistd.h>

namespace lpshoot::app {
namespace {

using json = nlohmann::json;

size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diag = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (std::tolower(a[i - 1]) == std::tolower(b[j - 1]) ? 0 : 1)});
      diag = up;
    }
  }
  return row[b.size()];
}

std::string join(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : ", ") + x;
  return s;
}

// A JSON object at a key path; every accessor checks type, size and finiteness and names the key.
class Reader {
 public:
  Reader(const json& j, std::string path, const std::string& file) : j_(j), path_(std::move(path)), file_(file) {
    if (!j_.is_object()) fail(path_.empty() ? "the scene must be a JSON object" : "must be an object");
  }

  [[noreturn]] void fail(const std::string& what, const std::string& key = "") const {
    const std::string at = key.empty() ? path_ : name(key);
    throw SceneError(file_ + ": " + (at.empty() ? "" : at + ": ") + what);
  }
  std::string name(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }

  // Rejects keys outside `allowed`, suggesting the nearest allowed one.
  void allow(const std::vector<std::string>& allowed) const {
    for (auto it = j_.begin(); it != j_.end(); ++it) {
      if (std::find(allowed.begin(), allowed.end(), it.key()) != allowed.end()) continue;
      std::string best;
      size_t best_d = SIZE_MAX;
      for (const auto& a : allowed)
        if (const size_t d = edit_distance(it.key(), a); d < best_d) best_d = d, best = a;
      const std::string hint = best_d <= std::max<size_t>(2, best.size() / 3)
                                   ? "did you mean '" + name(best) + "'?"
                                   : "allowed here: " + join(allowed);
      fail("unknown key (" + hint + ")", it.key());
    }
  }
  bool has(const std::string& key) const { return j_.contains(key) && !j_.at(key).is_null(); }
  void forbid(const std::string& key, const std::string& why) const {
    if (j_.contains(key)) fail(why, key);
  }
  const json& at(const std::string& key) const {
    if (!has(key)) fail("missing (required)", key);
    return j_.at(key);
  }

  double number(const std::string& key) const {
    const json& v = at(key);
    if (!v.is_number()) fail("must be a number, got " + std::string(v.type_name()), key);
    const double x = v.get<double>();
    if (!std::isfinite(x)) fail("must be finite", key);
    return x;
  }
  double number(const std::string& key, double fallback) const { return has(key) ? number(key) : fallback; }
  std::optional<double> optional_number(const std::string& key) const {
    return has(key) ? std::optional<double>(number(key)) : std::nullopt;
  }
  double positive(const std::string& key, double fallback) const {
    const double x = number(key, fallback);
    if (!(x > 0)) fail("must be > 0 (got " + format(x) + ")", key);
    return x;
  }
  int integer(const std::string& key, int fallback) const {
    if (!has(key)) return fallback;
    const json& v = at(key);
    if (!v.is_number_integer() && !(v.is_number_float() && std::floor(v.get<double>()) == v.get<double>()))
      fail("must be an integer, got " + v.dump(), key);
    const double x = v.get<double>();
    if (std::abs(x) > 1e9) fail("is out of range (" + v.dump() + ")", key);
    return static_cast<int>(x);
  }
  bool boolean(const std::string& key, bool fallback) const {
    if (!has(key)) return fallback;
    if (!at(key).is_boolean()) fail("must be true or false, got " + at(key).dump(), key);
    return at(key).get<bool>();
  }
  std::string choice(const std::string& key, const std::vector<std::string>& options, const std::string& fallback) const {
    if (!has(key)) return fallback;
    const json& v = at(key);
    if (!v.is_string() || std::find(options.begin(), options.end(), v.get<std::string>()) == options.end())
      fail("must be one of " + join(options) + " (got " + v.dump() + ")", key);
    return v.get<std::string>();
  }
  std::string string(const std::string& key, const std::string& fallback) const {
    if (!has(key)) return fallback;
    if (!at(key).is_string()) fail("must be a string, got " + at(key).dump(), key);
    return at(key).get<std::string>();
  }
  template <int n>
  Eigen::Matrix<double, n, 1> vector(const std::string& key) const {
    return vector_of<n>(at(key), name(key));
  }
  template <int n>
  Eigen::Matrix<double, n, 1> vector_of(const json& v, const std::string& where) const {
    if (!v.is_array() || v.size() != static_cast<size_t>(n))
      throw SceneError(file_ + ": " + where + ": must be an array of " + std::to_string(n) + " numbers (got " +
                       v.dump() + ")");
    Eigen::Matrix<double, n, 1> x;
    for (int i = 0; i < n; ++i) {
      if (!v[i].is_number() || !std::isfinite(v[i].get<double>()))
        throw SceneError(file_ + ": " + where + "[" + std::to_string(i) + "]: must be a finite number (got " +
                         v[i].dump() + ")");
      x(i) = v[i].get<double>();
    }
    return x;
  }
  std::vector<double> numbers(const std::string& key, size_t n) const {
    const json& v = at(key);
    if (!v.is_array() || v.size() != n)
      fail("must be an array of " + std::to_string(n) + " numbers (got " + v.dump() + ")", key);
    std::vector<double> x(n);
    for (size_t i = 0; i < n; ++i) {
      if (!v[i].is_number() || !std::isfinite(v[i].get<double>()))
        fail("must be a finite number (got " + v[i].dump() + ")", key + "[" + std::to_string(i) + "]");
      x[i] = v[i].get<double>();
    }
    return x;
  }
  Reader object(const std::string& key) const { return Reader(at(key), name(key), file_); }
  std::optional<Reader> optional_object(const std::string& key) const {
    return has(key) ? std::optional<Reader>(object(key)) : std::nullopt;
  }

  static std::string format_exact(double x) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.17g", x);
    return buf;
  }
  static std::string format(double x) {
    std::ostringstream s;
    s << x;
    return s.str();
  }

 private:
  const json& j_;
  std::string path_;
  const std::string& file_;
};

// The deepest nesting a scene may have: real scenes need 4 levels; a limit keeps a hostile file
// (10^5 levels) from exhausting memory or the stack while it is read.
constexpr int max_json_depth = 64;

// A SAX pass before the document is built: rejects nesting deeper than max_json_depth and
// duplicate keys in one object (nlohmann keeps the last one silently). Throws SceneError;
// returns false on a syntax error, which the DOM parse then describes.
class JsonPrecheck : public nlohmann::json_sax<json> {
 public:
  explicit JsonPrecheck(std::string where) : where_(std::move(where)) {}
  bool null() override { return true; }
  bool boolean(bool) override { return true; }
  bool number_integer(number_integer_t) override { return true; }
  bool number_unsigned(number_unsigned_t) override { return true; }
  bool number_float(number_float_t, const string_t&) override { return true; }
  bool string(string_t&) override { return true; }
  bool binary(binary_t&) override { return true; }
  bool start_object(std::size_t) override { return open(true); }
  bool end_object() override { return close(); }
  bool start_array(std::size_t) override { return open(false); }
  bool end_array() override { return close(); }
  bool key(string_t& k) override {
    auto& keys = stack_.back().keys;
    if (std::find(keys.begin(), keys.end(), k) != keys.end())
      throw SceneError(where_ + ": duplicate key \"" + k + "\" in one object" + at() + " (JSON keeps only one; remove the other)");
    keys.push_back(k);
    return true;
  }
  bool parse_error(std::size_t, const std::string&, const nlohmann::detail::exception&) override { return false; }

 private:
  struct Level {
    bool object;
    std::vector<std::string> keys;
  };
  bool open(bool object) {
    if (static_cast<int>(stack_.size()) >= max_json_depth)
      throw SceneError(where_ + ": nested more than " + std::to_string(max_json_depth) +
                       " levels deep; a scene needs a handful");
    stack_.push_back({object, {}});
    return true;
  }
  bool close() {
    stack_.pop_back();
    return true;
  }
  std::string at() const {  // the enclosing keys, e.g. " (at boundary.initial)"
    std::string path;
    for (size_t i = 0; i + 1 < stack_.size(); ++i)
      if (stack_[i].object && !stack_[i].keys.empty()) path += (path.empty() ? "" : ".") + stack_[i].keys.back();
    return path.empty() ? "" : " (at " + path + ")";
  }
  std::string where_;
  std::vector<Level> stack_;
};

// Parses JSON text; `where` names the file or option in messages. Throws SceneError.
json parse_json_text(const std::string& text, const std::string& where) {
  JsonPrecheck check(where);
  json::sax_parse(text, &check);  // throws on depth or duplicates; syntax errors are described below
  try {
    return json::parse(text);
  } catch (const json::exception& e) {  // parse errors, invalid UTF-8, numbers out of range (1e999)
    std::string what = e.what();  // "[json.exception.parse_error.101] parse error at line 3, column 5: ..."
    const size_t at = what.find("] ");
    throw SceneError(where + ": invalid JSON: " + (at == std::string::npos ? what : what.substr(at + 2)));
  }
}

// The whole scene file, or a SceneError saying why it cannot be read.
std::string read_scene_file(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (ec || !fs::exists(st)) throw SceneError(path + ": cannot read the scene file: no such file");
  if (fs::is_directory(st)) throw SceneError(path + ": cannot read the scene file: it is a directory");
  if (!fs::is_regular_file(st)) throw SceneError(path + ": cannot read the scene file: not a regular file");
  constexpr std::uintmax_t max_bytes = 16u << 20;
  if (const std::uintmax_t size = fs::file_size(path, ec); !ec && size > max_bytes)
    throw SceneError(path + ": cannot read the scene file: " + std::to_string(size >> 20) + " MB is too large for a scene");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw SceneError(path + ": cannot read the scene file: permission denied or unreadable");
  std::string text;
  char buf[65536];
  while (in.read(buf, sizeof buf) || in.gcount() > 0) {
    text.append(buf, static_cast<size_t>(in.gcount()));
    if (text.size() > max_bytes) throw SceneError(path + ": cannot read the scene file: too large for a scene");
  }
  if (in.bad()) throw SceneError(path + ": cannot read the scene file: a read error occurred");
  return text;
}

// ---------------------------------------------------------------- --set overrides

// A key path component as an array index: digits only, at most 9 of them; nullopt otherwise.
std::optional<size_t> array_index(const std::string& k) {
  if (k.empty() || k.size() > 9 || k.find_first_not_of("0123456789") != std::string::npos) return std::nullopt;
  return static_cast<size_t>(std::stoul(k));
}

// Well-formed UTF-8 (no overlongs, surrogates or code points past U+10FFFF): what JSON text may hold.
bool valid_utf8(const std::string& s) {
  const auto* p = reinterpret_cast<const unsigned char*>(s.data());
  const size_t n = s.size();
  for (size_t i = 0; i < n;) {
    const unsigned c = p[i];
    int len = c < 0x80 ? 1 : (c >> 5) == 0x6 ? 2 : (c >> 4) == 0xE ? 3 : (c >> 3) == 0x1E ? 4 : 0;
    if (len == 0 || i + len > n) return false;
    unsigned cp = len == 1 ? c : c & (0x7F >> len);
    for (int j = 1; j < len; ++j) {
      if ((p[i + j] & 0xC0) != 0x80) return false;
      cp = (cp << 6) | (p[i + j] & 0x3F);
    }
    if ((len == 2 && cp < 0x80) || (len == 3 && cp < 0x800) || (len == 4 && cp < 0x10000) || cp > 0x10FFFF ||
        (cp >= 0xD800 && cp <= 0xDFFF))
      return false;
    i += len;
  }
  return true;
}

void apply_override(json& scene, const std::string& assignment) {
  if (!valid_utf8(assignment)) throw SceneError("--set: the argument is not valid UTF-8 text");
  const size_t eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0)
    throw SceneError("--set '" + assignment + "': expected key.path=value (e.g. horizon.N=400)");
  const std::string path = assignment.substr(0, eq), text = assignment.substr(eq + 1);
  json value;
  if (json::accept(text)) {
    value = parse_json_text(text, "--set " + path);  // depth and duplicate keys checked
  } else {
    value = text;  // a bare word: a string
  }
  std::vector<std::string> keys;
  std::stringstream ss(path);
  for (std::string k; std::getline(ss, k, '.');) {
    if (k.empty()) throw SceneError("--set '" + assignment + "': empty component in the key path '" + path + "'");
    keys.push_back(k);
  }
  json* node = &scene;
  for (size_t i = 0; i < keys.size(); ++i) {
    const std::string& k = keys[i];
    const bool last = i + 1 == keys.size();
    if (node->is_array()) {  // numeric component: an array element
      const std::optional<size_t> index = array_index(k);
      if (!index) throw SceneError("--set '" + assignment + "': '" + k + "' must be an index into the array at that point");
      const size_t idx = *index;
      if (idx >= node->size())
        throw SceneError("--set '" + assignment + "': index " + k + " is past the end of an array of " +
                         std::to_string(node->size()));
      node = &(*node)[idx];
    } else {
      if (node->is_null()) *node = json::object();
      if (!node->is_object())
        throw SceneError("--set '" + assignment + "': " +
                         (i == 0 ? std::string("the scene is not a JSON object") : "'" + keys[i - 1] + "' is not an object"));
      if (last && value.is_null()) {
        node->erase(k);  // "null" makes the entry free / default
        return;
      }
      node = &(*node)[k];
    }
    if (last) *node = value;
  }
}

// ---------------------------------------------------------------- sections

ShootingMethod read_method(const std::string& s) { return s == "multiple" ? ShootingMethod::Multiple : ShootingMethod::Single; }

void read_solver(const Reader& r, Scene& s) {
  if (!s.is_optimal_control()) {  // a simulation: only the per-step Newton is tuned
    r.allow({"tolerance", "max_iterations"});
    s.shooting.step.step_tolerance = r.positive("tolerance", s.shooting.step.step_tolerance);
    // A relative Newton correction per step: above 1e-6 a step is not solved to an accuracy worth
    // reporting (the run would "converge" on a first guess).
    if (s.shooting.step.step_tolerance < 1e-15 || s.shooting.step.step_tolerance > 1e-6)
      r.fail("must be between 1e-15 and 1e-6, a relative Newton correction per step (got " +
                 Reader::format(s.shooting.step.step_tolerance) + ")",
             "tolerance");
    s.shooting.step.max_iterations = r.integer("max_iterations", s.shooting.step.max_iterations);
    if (s.shooting.step.max_iterations < 1) r.fail("must be >= 1", "max_iterations");
    return;
  }
  r.allow({"method", "segments", "backend", "tolerance", "max_iterations", "threads", "continuation"});
  s.shooting.method = read_method(r.choice("method", {"single", "multiple"}, "single"));
  const int max_segments = s.max_segments(s.N);
  s.auto_segments = !r.has("segments") || r.at("segments").is_string();
  if (s.auto_segments) {
    if (r.has("segments") && r.at("segments").get<std::string>() != "auto")
      r.fail("must be an integer or \"auto\" (got " + r.at("segments").dump() + ")", "segments");
    s.shooting.segments = s.default_segments(s.N);
  } else {
    s.shooting.segments = r.integer("segments", 1);
  }
  if (s.shooting.segments < 1 || s.shooting.segments > max_segments)
    r.fail("must be between 1 and " + std::string(s.galerkin() ? "N = " : "N - 2k + 1 = ") + std::to_string(max_segments) + " (got " +
               std::to_string(s.shooting.segments) + ")",
           "segments");
  if (s.shooting.method == ShootingMethod::Single) s.shooting.segments = 1;  // segments: multiple shooting only
  // "auto" also doubles the segments, twice at most, when Newton does not converge (shooting.hpp);
  // a count the scene gives is kept.
  s.shooting.segment_doublings = s.auto_segments ? auto_segment_doublings : 0;
  s.shooting.solver.backend = r.choice("backend", {"kinsol", "nlopt"}, "kinsol") == "nlopt" ? Backend::Nlopt : Backend::Kinsol;
  s.shooting.solver.tolerance = r.positive("tolerance", 1e-10);
  if (s.shooting.solver.tolerance < 1e-14 || s.shooting.solver.tolerance > 1)
    r.fail("must be between 1e-14 (double precision roundoff) and 1 (got " + Reader::format(s.shooting.solver.tolerance) + ")",
           "tolerance");
  s.shooting.solver.max_iterations = r.integer("max_iterations", 50);
  if (s.shooting.solver.max_iterations < 1) r.fail("must be >= 1", "max_iterations");
  s.shooting.threads = r.integer("threads", 0);
  if (s.shooting.threads < 0) r.fail("must be >= 0 (0: one per core)", "threads");
}

// ---------------------------------------------------------------- the problem's own sections

// The range a parameter's value must lie in, as a message, or "" when it does.
std::string out_of_range(const ParameterSpec& p, double x) {
  const bool above = p.min_exclusive ? x > p.min : x >= p.min;
  if (above && x <= p.max) return "";
  const std::string got = " (got " + Reader::format(x) + ")";
  if (std::isfinite(p.min) && std::isfinite(p.max))
    return "must be between " + Reader::format(p.min) + " and " + Reader::format(p.max) + got;
  if (std::isfinite(p.max)) return "must be <= " + Reader::format(p.max) + got;
  return std::string("must be ") + (p.min_exclusive ? "> " : ">= ") + Reader::format(p.min) + got;
}

// The descriptor's parameters under `prefix` (a dotted key path, "" at the top) from the object
// `r`; nested objects follow the keys' dots. Missing entries take their defaults.
void read_parameter_object(const Reader* r, const std::string& prefix, const std::vector<ParameterSpec>& specs,
                           ParameterValues& v) {
  std::vector<std::string> children;  // the names directly under prefix, in the descriptor's order
  for (const auto& p : specs) {
    if (p.key.compare(0, prefix.size(), prefix) != 0) continue;
    const std::string rest = p.key.substr(prefix.size());
    const std::string child = rest.substr(0, rest.find('.'));
    if (std::find(children.begin(), children.end(), child) == children.end()) children.push_back(child);
  }
  if (r) r->allow(children);
  for (const auto& child : children) {
    const std::string key = prefix + child;
    const auto leaf = std::find_if(specs.begin(), specs.end(), [&](const ParameterSpec& p) { return p.key == key; });
    if (leaf == specs.end()) {  // a nested object
      if (r && r->has(child)) {
        const Reader sub = r->object(child);
        read_parameter_object(&sub, key + ".", specs, v);
      } else {
        read_parameter_object(nullptr, key + ".", specs, v);
      }
      continue;
    }
    const ParameterSpec& p = *leaf;
    const bool given = r && r->has(child);
    if (given) v.given.push_back(key);
    switch (p.kind) {
      case ParameterSpec::Kind::Choice:
        v.words[key] = r ? r->choice(child, p.choices, p.choices.front()) : p.choices.front();
        break;
      case ParameterSpec::Kind::Number: {
        const double x = given ? r->number(child) : p.value.front();
        if (const std::string why = out_of_range(p, x); given && !why.empty()) r->fail(why, child);
        v.numbers[key] = {x};
        break;
      }
      case ParameterSpec::Kind::Array: {
        const std::vector<double> x = given ? r->numbers(child, p.value.size()) : p.value;
        for (size_t i = 0; given && i < x.size(); ++i)
          if (const std::string why = out_of_range(p, x[i]); !why.empty()) r->fail(why, child + "[" + std::to_string(i) + "]");
        v.numbers[key] = x;
        break;
      }
    }
  }
}

void read_parameters(const Reader& root, const Problem& problem, Scene& s) {
  s.parameters = {};
  const auto par = root.optional_object("parameters");
  read_parameter_object(par ? &*par : nullptr, "", problem.descriptor().parameters, s.parameters);
  if (const auto bad = problem.check_parameters(s.parameters))
    root.fail(bad->second, "parameters." + bad->first);
}

// boundary.initial / boundary.final: the descriptor's entries; a missing one is free.
void read_boundary(const Reader& root, const ProblemDescriptor& d, Scene& s) {
  s.start = s.end = {};
  if (!root.has("boundary")) return;
  const Reader bd = root.object("boundary");
  bd.allow({"initial", "final"});
  std::vector<std::string> keys;
  for (const auto& b : d.boundary) keys.push_back(b.key);
  for (const char* side : {"initial", "final"}) {
    BoundaryValues& values = std::string(side) == "initial" ? s.start : s.end;
    const std::optional<Reader> e = bd.optional_object(side);
    if (!e) continue;
    e->allow(keys);
    for (const auto& b : d.boundary) {
      if (!e->has(b.key)) continue;
      if (!b.requires.empty() && !e->has(b.requires)) e->fail(b.requires_message, b.key);
      values.given[b.key] = b.array ? e->numbers(b.key, b.size) : std::vector<double>{e->number(b.key)};
    }
  }
}

// A free motion's initial data (descriptor.configuration names its components).
void read_initial_data(const Reader& root, const ProblemDescriptor& d, Scene& s) {
  const size_t n = d.configuration.size();
  std::string q = "[";
  for (size_t i = 0; i < n; ++i) q += (i ? ", " : "") + d.configuration[i];
  q += "]";
  const Reader bd = root.object("boundary");
  bd.allow({"initial", "final"});
  bd.forbid("final", "a simulation (" + d.name + ") starts from initial data only; remove boundary.final");
  const Reader init = bd.object("initial");
  init.allow({"configurations", "position", "velocity"});
  auto as_vector = [](const std::vector<double>& x) { return Eigen::Map<const Eigen::VectorXd>(x.data(), x.size()).eval(); };
  s.initial = {};
  if (init.has("configurations")) {
    if (init.has("position") || init.has("velocity"))
      init.fail("give either configurations or position and velocity, not both", "configurations");
    const json& c = init.at("configurations");
    if (!c.is_array() || c.size() != 2) init.fail("must be [" + q + ", " + q + "] (q_0 and q_1)", "configurations");
    const json rows{{"configurations[0]", c[0]}, {"configurations[1]", c[1]}};  // named as the scene's entries
    const Reader r(rows, bd.name("initial"), s.file);
    s.initial.configurations =
        std::array<Eigen::VectorXd, 2>{as_vector(r.numbers("configurations[0]", n)), as_vector(r.numbers("configurations[1]", n))};
  } else {
    if (!init.has("position")) init.fail("missing (required): " + q + ", or give configurations", "position");
    if (!init.has("velocity")) init.fail("missing (required): the rates of " + q, "velocity");
    s.initial.position = as_vector(init.numbers("position", n));
    s.initial.velocity = as_vector(init.numbers("velocity", n));
  }
}

Scene parse_scene(const json& j, const std::string& path);

void read_continuation(const Reader& so, const json& scene, Scene& s) {
  if (!so.has("continuation")) return;
  const Reader c = so.object("continuation");
  c.allow({"parameter", "from", "initial_step"});
  Scene::Continuation cont;
  cont.parameter = c.string("parameter", "");
  if (cont.parameter.empty()) c.fail("missing (required): a key under parameters, e.g. \"potential.amplitude\"", "parameter");
  const json* node = scene.contains("parameters") ? &scene.at("parameters") : nullptr;
  std::stringstream ss(cont.parameter);
  for (std::string k; node && std::getline(ss, k, '.');) {
    if (node->is_object() && node->contains(k))
      node = &(*node)[k];
    else if (const std::optional<size_t> i = array_index(k); node->is_array() && i && *i < node->size())
      node = &(*node)[*i];
    else
      node = nullptr;
  }
  if (!node || !node->is_number())
    c.fail("parameters." + cont.parameter + " must be a number given in the scene's parameters", "parameter");
  cont.to = node->get<double>();
  cont.from = c.number("from");
  cont.initial_step = c.positive("initial_step", 0.25);
  if (cont.initial_step > 1) c.fail("must be in (0, 1], a fraction of |to - from|", "initial_step");
  json start = scene;
  start["solver"].erase("continuation");
  apply_override(start["parameters"], cont.parameter + "=" + Reader::format_exact(cont.from));
  try {
    parse_scene(start, s.file);
  } catch (const SceneError& e) {
    std::string why = e.what();
    if (why.rfind(s.file + ": ", 0) == 0) why = why.substr(s.file.size() + 2);
    c.fail("the scene is not valid at the start value " + Reader::format(cont.from) + " (" + why + ")", "from");
  }
  s.continuation = cont;
}

}  // namespace

Scene load_scene(const std::string& path, const std::vector<std::string>& overrides) {
  return load_scene_text(read_scene_file(path), path, overrides);
}

Scene load_scene_text(const std::string& text, const std::string& name, const std::vector<std::string>& overrides) {
  json j = parse_json_text(text, name);
  for (const auto& o : overrides) apply_override(j, o);
  return parse_scene(j, name);
}

Scene with_parameter(const Scene& s, const std::string& parameter, double value) {
  json j = parse_json_text(s.effective_json, s.file);
  if (j.contains("solver") && j["solver"].is_object()) j["solver"].erase("continuation");
  apply_override(j["parameters"], parameter + "=" + Reader::format_exact(value));
  return parse_scene(j, s.file);
}

namespace {

// scheme: the discretization and its options. closure and constraints belong to the paper's
// nodal windows; order to Galerkin (METHOD.md §9).
void read_scheme(const Reader& sc, Scene& s) {
  if (!s.is_optimal_control()) {
    sc.allow({});
    return;
  }
  const ProblemDescriptor& d = s.problem->descriptor();
  std::vector<std::string> keys = {"discretization", "order", "closure", "error_estimate"};
  for (const auto& o : d.paper_options) keys.push_back(o.key);
  sc.allow(keys);
  s.error_estimate = sc.boolean("error_estimate", false);
  s.discretization = sc.choice("discretization", {"paper", "galerkin"}, s.galerkin() ? "galerkin" : "paper") == "galerkin"
                         ? Discretization::Galerkin
                         : Discretization::Paper;
  if (!s.galerkin() && d.paper_order == 0)
    sc.fail("problem \"" + d.name + "\" has only its continuous form, for the \"galerkin\" discretization", "discretization");
  if (s.galerkin()) {
    std::vector<std::string> paper_only = {"closure"};
    for (const auto& o : d.paper_options) paper_only.push_back(o.key);
    for (const auto& key : paper_only)
      if (sc.has(key))
        sc.fail("applies to the paper's discretization only (Galerkin imposes node positions and velocities exactly "
                "and the continuous constraints at its Gauss points); remove it",
                key);
    s.galerkin_order = sc.integer("order", 4);
    if (s.galerkin_order != 4 && s.galerkin_order != 6 && s.galerkin_order != 8)
      sc.fail("must be 4, 6 or 8 (cubic, quartic or quintic Galerkin; got " + std::to_string(s.galerkin_order) + ")",
              "order");
    if (s.galerkin_order > d.galerkin_max_order)
      sc.fail("order " + std::to_string(s.galerkin_order) + " is not compiled into problem \"" + d.name +
                  "\" (its highest is " + std::to_string(d.galerkin_max_order) +
                  "; a problem of one's own gets order 8 as ModelProblem<Model, 8>)",
              "order");
    return;
  }
  if (sc.has("order"))
    sc.fail("applies to the galerkin discretization only (the paper's order follows from its closure); remove it or set "
            "scheme.discretization = \"galerkin\"",
            "order");
  s.closure = sc.choice("closure", {"paper", "second_order"}, "second_order") == "paper" ? Closure::Paper : Closure::SecondOrder;
  for (const auto& o : d.paper_options) s.scheme_options[o.key] = sc.choice(o.key, o.choices, o.choices.front());
}

Scene parse_scene(const json& j, const std::string& path) {
  Scene s;
  s.file = path;
  s.effective_json = j.dump(2);

  const Reader root(j, "", path);
  root.allow({"problem", "description", "parameters", "horizon", "boundary", "scheme", "solver", "output"});
  std::vector<std::string> names;
  for (const Problem* p : registered_problems()) names.push_back(p->descriptor().name);
  if (!root.has("problem")) root.fail("missing (required): one of " + join(names), "problem");
  if (const json& p = root.at("problem"); p.is_string() && std::find(names.begin(), names.end(), p) == names.end())
    root.fail("unknown problem " + p.dump() + ": the registered problems are " + join(names) +
                  "; a problem of one's own is loaded from its C++ file with --problem FILE.cpp",
              "problem");
  s.problem_name = root.choice("problem", names, "");
  s.problem = find_problem(s.problem_name);
  s.k = s.problem->descriptor().paper_order;
  root.string("description", "");

  const Reader hz = root.object("horizon");
  hz.allow({"T", "N"});
  s.T = hz.number("T");
  if (!(s.T > 0)) hz.fail("must be > 0 (got " + Reader::format(s.T) + ")", "T");
  if (!hz.has("N")) hz.fail("missing (required)", "N");
  s.N = hz.integer("N", 0);

  read_parameters(root, *s.problem, s);
  if (s.is_optimal_control()) {
    read_boundary(root, s.problem->descriptor(), s);
    if (s.problem->descriptor().paper_order == 0 || s.problem->descriptor().paper_derived)
      s.discretization = Discretization::Galerkin;
    for (const auto& o : s.problem->descriptor().paper_options) s.scheme_options[o.key] = o.choices.front();
  } else {
    read_initial_data(root, s.problem->descriptor(), s);
  }

  const auto sc = root.optional_object("scheme");
  if (sc) read_scheme(*sc, s);
  const int k = s.order();
  if (s.N < s.min_N()) {
    if (s.galerkin()) hz.fail("must be at least 2 for the galerkin discretization (got " + std::to_string(s.N) + ")", "N");
    hz.fail("must be at least 2k + 1 = " + std::to_string(2 * k + 1) + " for " + s.problem_name + " (order k = " +
                std::to_string(k) + "; got " + std::to_string(s.N) + ")",
            "N");
  }
  if (s.error_estimate && (s.N % 4 != 0 || s.N / 4 < s.min_N()))
    sc->fail("needs N divisible by 4 with N/4 >= " + std::to_string(s.min_N()) +
                 " (the estimate solves on N/2 and N/4 too; N = " + std::to_string(s.N) + ")",
             "error_estimate");
  if (const auto so = root.optional_object("solver")) {
    read_solver(*so, s);
    read_continuation(*so, j, s);
  } else
    read_solver(Reader(json::object(), "solver", path), s);
  if (const std::string why = resource_problem(s); !why.empty()) hz.fail(why, "N");

  const std::string stem = std::filesystem::path(path).stem().string();
  s.out_dir = "lpshoot-out/" + stem;
  if (const auto out = root.optional_object("output")) {
    out->allow({"dir", "plot"});
    s.out_dir = out->string("dir", s.out_dir);
    if (s.out_dir.empty()) out->fail("must not be empty", "dir");
    s.plot = out->boolean("plot", true);
  }
  return s;
}

}  // namespace

std::string resource_problem(const Scene& s) {
  // Measured peak memory is 0.4-1.3 kB per step (trajectory, step sensitivities, CSV columns;
  // the beanie on Galerkin 4 at N = 10^5: 1.2 kB). Multiple shooting also holds its Jacobian:
  // with KINSOL sparse (block bidiagonal, about 2 x 22 non-zeros per row for the largest state,
  // the beanie's on Galerkin 6; the matrix, KLU's factors and the diagnosis' copies: ~4 copies
  // of 12 bytes each), with NLopt's SLSQP dense (4 copies of the square matrix).
  const double per_step = 1024.0;
  const double unknowns = s.shooting.method == ShootingMethod::Multiple ? 22.0 * s.shooting.segments : 0.0;
  const bool dense = s.shooting.solver.backend == Backend::Nlopt;
  const double jacobian = dense ? 4 * 8.0 * unknowns * unknowns : 4 * 12.0 * 44.0 * unknowns;
  const double bytes = per_step * s.N + jacobian;
  const double available = 0.75 * double(sysconf(_SC_PHYS_PAGES)) * double(sysconf(_SC_PAGE_SIZE));
  if (!(available > 0) || bytes <= available) return "";
  char buf[400];
  if (dense && jacobian > per_step * s.N)
    std::snprintf(buf, sizeof buf,
                  "%d steps in %d multiple-shooting segments need an estimated %.3g GB (NLopt's dense Jacobian of "
                  "about %.0f unknowns), more than 3/4 of this machine's %.3g GB; use fewer segments "
                  "(solver.segments), the kinsol backend, or a smaller N",
                  s.N, s.shooting.segments, bytes / 1e9, unknowns, available / 0.75 / 1e9);
  else
    std::snprintf(buf, sizeof buf,
                  "%d steps need an estimated %.3g GB of memory (about 1 kB per step), more than 3/4 of this "
                  "machine's %.3g GB; use a smaller N",
                  s.N, bytes / 1e9, available / 0.75 / 1e9);
  return buf;
}

std::vector<std::string> scheme_names(const ProblemDescriptor& d) {
  if (!d.optimal_control) return {"paper"};  // a free motion: the paper's windows only
  std::vector<std::string> s;
  if (d.paper_order > 0) s.push_back("paper");
  for (int order = 4; order <= d.galerkin_max_order; order += 2) s.push_back("galerkin" + std::to_string(order));
  return s;
}

bool set_scheme(Scene& s, const std::string& name) {
  if (name == "paper") {
    s.discretization = Discretization::Paper;
    return true;
  }
  for (int order : {4, 6, 8})
    if (name == "galerkin" + std::to_string(order)) {
      if (s.problem && order > s.problem->descriptor().galerkin_max_order) return false;
      s.discretization = Discretization::Galerkin;
      s.galerkin_order = order;
      return true;
    }
  return false;
}

bool Scene::is_optimal_control() const { return !problem || problem->descriptor().optimal_control; }

const char* closure_name(Closure c) { return c == Closure::Paper ? "paper" : "second_order"; }
const char* method_name(ShootingMethod m) { return m == ShootingMethod::Multiple ? "multiple" : "single"; }

}  // namespace lpshoot::app
