// Problems of one's own from one C++ file (issue 10): the application builds a plugin from a
// source file, runs solve, sweep, check and problems on it, takes it from its cache the second
// time, rebuilds a cached library that carries another build stamp, and fails cleanly, naming
// the file, on bad plugins. The oscillator's optimum is known in
// closed form, so the trajectory and the cost are checked against a reference computed here.
#include "cli_helpers.hpp"

#include <Eigen/Dense>

#include <iterator>
#include <regex>

using namespace lpshoot_cli_test;

namespace {

const std::string oscillator_source = std::string(LPSHOOT_EXAMPLE_PLUGINS) + "/oscillator.cpp";
const std::string oscillator_scene = std::string(LPSHOOT_EXAMPLE_PLUGINS) + "/oscillator.json";

std::string plugin(const std::string& name) { return std::string(LPSHOOT_TEST_PLUGINS) + "/" + name + ".cpp"; }

// The optimal motion of ℓ = ½|x'' + ω²x|² between two states: (d²/dt² + ω²)² x = 0, so
// x(t) = (a + b t) cos ωt + (c + d t) sin ωt, the four coefficients from the four end values.
struct ExactOscillator {
  double w;
  Eigen::Vector4d coef;  // a, b, c, d
  ExactOscillator(double omega, double T, double x0, double v0, double xT, double vT) : w(omega) {
    auto row = [&](double t, bool derivative) {
      const double c = std::cos(w * t), s = std::sin(w * t);
      if (!derivative) return Eigen::RowVector4d(c, t * c, s, t * s);
      return Eigen::RowVector4d(-w * s, c - w * t * s, w * c, s + w * t * c);
    };
    Eigen::Matrix4d A;
    A << row(0, false), row(0, true), row(T, false), row(T, true);
    coef = A.partialPivLu().solve(Eigen::Vector4d(x0, v0, xT, vT));
  }
  double x(double t) const {
    return (coef(0) + coef(1) * t) * std::cos(w * t) + (coef(2) + coef(3) * t) * std::sin(w * t);
  }
  // u = x'' + ω² x = 2ω (d cos ωt − b sin ωt).
  double u(double t) const { return 2 * w * (coef(3) * std::cos(w * t) - coef(1) * std::sin(w * t)); }
};

int column(const std::vector<std::string>& header, const std::string& name) {
  const auto it = std::find(header.begin(), header.end(), name);
  EXPECT_NE(it, header.end()) << "no column " << name;
  return static_cast<int>(it - header.begin());
}

bool cache_is_empty(const fs::path& cache) { return !fs::exists(cache) || fs::is_empty(cache); }

}  // namespace

TEST(Plugins, OscillatorFromItsOwnFileMatchesTheExactOptimum) {
  const fs::path work = scratch("plugin_oscillator");
  const std::string cache = " --plugin-cache '" + (work / "cache").string() + "'";
  const std::string problem = " --problem '" + oscillator_source + "'" + cache;

  // First run: built (and said so), solved.
  const Outcome first = run_cli("solve" + problem + " '" + oscillator_scene + "' --no-plot --out '" +
                                    (work / "solve").string() + "'",
                                work);
  ASSERT_EQ(first.code, 0) << first.out << first.err;
  EXPECT_NE(first.err.find("building"), std::string::npos) << first.err;
  const json report = json::parse(std::ifstream(work / "solve" / "report.json"));
  EXPECT_EQ(report["status"], "converged");
  EXPECT_EQ(report["problem"], "oscillator");

  // The trajectory and the control against the closed form (Galerkin order 6, h = 0.075: the
  // sweep below measures the error near 1e-10).
  const json scene_json = json::parse(std::ifstream(oscillator_scene));
  const double w = scene_json["parameters"]["omega"], T = scene_json["horizon"]["T"];
  const json& b = scene_json["boundary"];
  std::vector<ExactOscillator> exact;
  for (int i = 0; i < 2; ++i)
    exact.emplace_back(w, T, b["initial"]["position"][i], b["initial"]["velocity"][i], b["final"]["position"][i],
                       b["final"]["velocity"][i]);
  std::vector<std::string> header;
  const auto rows = read_csv(work / "solve" / "trajectory.csv", header);
  ASSERT_EQ(rows.size(), scene_json["horizon"]["N"].get<size_t>() + 1);
  const int x1 = column(header, "x1"), x2 = column(header, "x2"), u1 = column(header, "u1"), u2 = column(header, "u2");
  double err_x = 0, err_u = 0;
  for (const auto& r : rows) {
    err_x = std::max({err_x, std::abs(r[x1] - exact[0].x(r[0])), std::abs(r[x2] - exact[1].x(r[0]))});
    err_u = std::max({err_u, std::abs(r[u1] - exact[0].u(r[0])), std::abs(r[u2] - exact[1].u(r[0]))});
  }
  EXPECT_LT(err_x, 1e-8);
  EXPECT_LT(err_u, 1e-6);
  // The cost ∫ ½|u|² dt by Simpson's rule on the exact control.
  const int M = 4000;
  double cost = 0;
  for (int k = 0; k <= M; ++k) {
    const double t = T * k / M, weight = (k == 0 || k == M) ? 1 : (k % 2 ? 4 : 2);
    cost += weight * 0.5 * (std::pow(exact[0].u(t), 2) + std::pow(exact[1].u(t), 2));
  }
  cost *= T / M / 3;
  EXPECT_NEAR(report["cost"].get<double>(), cost, 1e-8 * cost);

  // Second run: from the cache (no build), the same answer.
  const Outcome second = run_cli("solve" + problem + " '" + oscillator_scene + "' --no-plot --out '" +
                                     (work / "again").string() + "'",
                                 work);
  ASSERT_EQ(second.code, 0) << second.err;
  EXPECT_EQ(second.err.find("building"), std::string::npos) << second.err;
  EXPECT_EQ(json::parse(std::ifstream(work / "again" / "report.json"))["cost"], report["cost"]);

  // A library built against another lpshoot is rebuilt, not loaded: give the cached one another
  // build stamp (every "VERSION+<40 hex>" in it, same length), then run again.
  {
    fs::path library;
    for (const auto& entry : fs::recursive_directory_iterator(work / "cache"))
      if (entry.path().filename() == "problem.so") library = entry.path();
    ASSERT_FALSE(library.empty()) << "no cached plugin library";
    std::string bytes;
    {
      std::ifstream in(library, std::ios::binary);
      bytes.assign(std::istreambuf_iterator<char>(in), {});
    }
    const std::regex stamp("0\\.1\\.0\\+[0-9a-f]{40}");
    size_t patched = 0;
    for (auto it = std::sregex_iterator(bytes.begin(), bytes.end(), stamp); it != std::sregex_iterator(); ++it, ++patched)
      bytes.replace(static_cast<size_t>(it->position()) + 6, 40, std::string(40, '0'));
    ASSERT_GT(patched, 0u) << "no build stamp found in " << library;
    std::ofstream(library, std::ios::binary | std::ios::trunc) << bytes;
    const Outcome other = run_cli("solve" + problem + " '" + oscillator_scene + "' --no-plot --out '" +
                                      (work / "rebuilt").string() + "'",
                                  work);
    ASSERT_EQ(other.code, 0) << other.err;
    EXPECT_NE(other.err.find("building"), std::string::npos) << "a foreign build stamp must trigger a rebuild: " << other.err;
    EXPECT_EQ(json::parse(std::ifstream(work / "rebuilt" / "report.json"))["cost"], report["cost"]);
  }

  // Sweep: the schemes' orders 4 and 6 on the plugin's problem.
  const Outcome sw = run_cli("sweep" + problem + " '" + oscillator_scene + "' --N 10,20,40,80 --scheme galerkin4,galerkin6 --no-plot --out '" +
                                 (work / "sweep").string() + "'",
                             work);
  ASSERT_EQ(sw.code, 0) << sw.out << sw.err;
  const json sweep = json::parse(std::ifstream(work / "sweep" / "sweep.json"));
  std::map<std::string, std::vector<double>> orders;
  for (const auto& r : sweep["runs"])
    if (r["order"].is_number()) orders[r["scheme"].get<std::string>()].push_back(r["order"].get<double>());
  ASSERT_EQ(orders["galerkin4"].size(), 2u) << sw.out;
  ASSERT_EQ(orders["galerkin6"].size(), 2u) << sw.out;
  for (double p : orders["galerkin4"]) EXPECT_NEAR(p, 4.0, 0.25);
  for (double p : orders["galerkin6"]) EXPECT_NEAR(p, 6.0, 0.25);

  // The paper's nodal windows derived from the plugin's model (core/paper_windows.hpp), with the
  // second-order closure: second order against the exact optimum, positions and control.
  // Measured: x 2.13, 2.07; u 1.93, 1.97 (N = 40 -> 80 is still 2.22).
  std::vector<double> paper_x, paper_u;
  for (int N : {80, 160, 320}) {
    const fs::path out = work / ("paper" + std::to_string(N));
    const Outcome pr = run_cli("solve" + problem + " '" + oscillator_scene + "' --set 'scheme={\"discretization\": \"paper\"}' --set horizon.N=" +
                                   std::to_string(N) + " --no-plot --out '" + out.string() + "'",
                               work);
    ASSERT_EQ(pr.code, 0) << pr.out << pr.err;
    std::vector<std::string> ph;
    const auto prow = read_csv(out / "trajectory.csv", ph);
    ASSERT_EQ(prow.size(), static_cast<size_t>(N + 1));
    const int px1 = column(ph, "x1"), px2 = column(ph, "x2"), pu1 = column(ph, "u1"), pu2 = column(ph, "u2");
    double ex = 0, eu = 0;
    for (size_t n = 0; n < prow.size(); ++n) {
      const auto& r = prow[n];
      ex = std::max({ex, std::abs(r[px1] - exact[0].x(r[0])), std::abs(r[px2] - exact[1].x(r[0]))});
      if (n == 0 || n + 1 == prow.size()) continue;  // the control lives on windows: nodes 1 .. N-1
      eu = std::max({eu, std::abs(r[pu1] - exact[0].u(r[0])), std::abs(r[pu2] - exact[1].u(r[0]))});
    }
    std::printf("oscillator, derived paper windows, N = %d: x error %.3e, u error %.3e\n", N, ex, eu);
    paper_x.push_back(ex);
    paper_u.push_back(eu);
    const json pj = json::parse(std::ifstream(out / "report.json"));
    EXPECT_EQ(pj["scheme"], "paper");
    EXPECT_EQ(pj["outputs_from"], "window_jets");
  }
  for (size_t i = 1; i < paper_x.size(); ++i) {
    EXPECT_NEAR(std::log2(paper_x[i - 1] / paper_x[i]), 2.0, 0.15) << "x, halving " << i;
    EXPECT_NEAR(std::log2(paper_u[i - 1] / paper_u[i]), 2.0, 0.15) << "u, halving " << i;
  }

  // check, and the problem listed with its descriptor.
  const Outcome ck = run_cli("check" + problem + " '" + oscillator_scene + "'", work);
  EXPECT_EQ(ck.code, 0) << ck.err;
  EXPECT_NE(ck.out.find("valid oscillator scene"), std::string::npos) << ck.out;
  const Outcome listed = run_cli("problems --json" + problem, work);
  ASSERT_EQ(listed.code, 0) << listed.err;
  bool found = false;
  for (const auto& p : json::parse(listed.out))
    if (p["name"] == "oscillator") {
      found = true;
      EXPECT_EQ(p["parameters"][0]["key"], "omega");
      EXPECT_EQ(p["parameters"][0]["default"], 1.0);
      EXPECT_EQ(p["columns"]["shape"], json({"x1", "x2"}));
    }
  EXPECT_TRUE(found) << listed.out;

  // Bad scene input for a plugin's problem is rejected naming the key, as for a built-in one.
  const Outcome typo = run_cli("check" + problem + " '" + oscillator_scene + "' --set parameters.omgea=2", work);
  EXPECT_EQ(typo.code, 2);
  EXPECT_NE(typo.err.find("parameters.omgea"), std::string::npos) << typo.err;
  EXPECT_NE(typo.err.find("parameters.omega"), std::string::npos) << typo.err;
  const Outcome range = run_cli("check" + problem + " '" + oscillator_scene + "' --set parameters.omega=-1", work);
  EXPECT_EQ(range.code, 2);
  EXPECT_NE(range.err.find("parameters.omega"), std::string::npos) << range.err;
  const Outcome size = run_cli("check" + problem + " '" + oscillator_scene + "' --set boundary.final.velocity=[1]", work);
  EXPECT_EQ(size.code, 2);
  EXPECT_NE(size.err.find("boundary.final.velocity"), std::string::npos) << size.err;
  // The derived paper windows: a velocity without its position cannot go through the paper's
  // first-order closure (node 1 = x(0) + h v(0)); the message names both and the fix, and the
  // second-order closure takes the same data.
  const std::string no_position = " --set boundary.initial.position=null";
  const Outcome closure = run_cli("check" + problem + " '" + oscillator_scene +
                                      "' --set 'scheme={\"discretization\": \"paper\", \"closure\": \"paper\"}'" + no_position,
                                  work);
  EXPECT_EQ(closure.code, 2);
  EXPECT_NE(closure.err.find("initial v1 is given without initial x1"), std::string::npos) << closure.err;
  EXPECT_NE(closure.err.find("scheme.closure \"second_order\""), std::string::npos) << closure.err;
  const Outcome second_order = run_cli("check" + problem + " '" + oscillator_scene + "' --set 'scheme={\"discretization\": \"paper\"}'" +
                                     no_position,
                                 work);
  EXPECT_EQ(second_order.code, 0) << second_order.err;
  // Without --problem, the scene's problem is unknown, and the message says how to load it.
  const Outcome missing = run_cli("check '" + oscillator_scene + "'", work);
  EXPECT_EQ(missing.code, 2);
  EXPECT_NE(missing.err.find("--problem"), std::string::npos) << missing.err;
}

// Each bad plugin: exit 2, a message naming the file and saying what is wrong, no output
// directory, and nothing half-built in the cache. One test per plugin, so ctest runs the builds
// in parallel.
struct BadPlugin {
  std::string name, expected;
  bool leaves_nothing;  // a file that does not compile (or does not exist) leaves nothing in the cache
};

void PrintTo(const BadPlugin& b, std::ostream* os) { *os << b.name; }

class BadPlugins : public ::testing::TestWithParam<BadPlugin> {};

TEST_P(BadPlugins, FailCleanlyNamingTheFile) {
  const BadPlugin& c = GetParam();
  const std::string file = plugin(c.name);
  const fs::path work = scratch("plugin_bad_" + c.name);
  const Outcome o = run_cli("solve --problem '" + file + "' --plugin-cache '" + (work / "cache").string() + "' '" +
                                oscillator_scene + "' --out '" + (work / "out").string() + "'",
                            work);
  EXPECT_EQ(o.code, 2) << o.err;
  EXPECT_NE(o.err.find(c.name + ".cpp"), std::string::npos) << o.err;
  EXPECT_NE(o.err.find(c.expected), std::string::npos) << o.err;
  EXPECT_FALSE(fs::exists(work / "out"));
  if (c.leaves_nothing) {
    EXPECT_TRUE(cache_is_empty(work / "cache"));
  }
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(work / "cache", ec))
    EXPECT_EQ(entry.path().string().find(".building-"), std::string::npos) << entry.path();
}

INSTANTIATE_TEST_SUITE_P(Plugins, BadPlugins,
                         ::testing::Values(BadPlugin{"syntax_error", "syntax_error.cpp:9:", true},
                                           BadPlugin{"no_problem", "registers no problem", false},
                                           BadPlugin{"wrong_dimensions", "the descriptor names 2 shape", false},
                                           BadPlugin{"name_taken", "\"electron\" is already registered", false},
                                           BadPlugin{"does_not_exist", "no such file", true}),
                         [](const ::testing::TestParamInfo<BadPlugin>& info) { return info.param.name; });
