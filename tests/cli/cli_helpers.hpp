// Helpers shared by the application's end-to-end tests: run the lpshoot executable with its
// output captured, read reports and CSV files.
#pragma once

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace lpshoot_cli_test {

namespace fs = std::filesystem;
using json = nlohmann::json;

struct Outcome {
  int code = -1;
  std::string out, err;
};

inline std::string slurp(const fs::path& p) {
  std::ifstream f(p);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

inline fs::path scratch(const std::string& name) {
  const fs::path d = fs::path(::testing::TempDir()) / ("lpshoot_cli_" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

// Runs `lpshoot ARGS` with stdout and stderr captured.
inline Outcome run_cli(const std::string& args, const fs::path& work) {
  const std::string cmd = std::string("'") + LPSHOOT_CLI + "' " + args + " > '" + (work / "stdout").string() + "' 2> '" +
                          (work / "stderr").string() + "'";
  const int rc = std::system(cmd.c_str());
  return {rc == -1 ? -1 : WEXITSTATUS(rc), slurp(work / "stdout"), slurp(work / "stderr")};
}

inline std::string scene(const std::string& name) { return std::string(LPSHOOT_SCENES) + "/" + name + ".json"; }

inline const json* at_path(const json& j, const std::string& dotted) {
  const json* node = &j;
  std::stringstream ss(dotted);
  for (std::string k; std::getline(ss, k, '.');) {
    if (!node->is_object() || !node->contains(k)) return nullptr;
    node = &(*node)[k];
  }
  return node;
}

inline bool gnuplot_available() { return std::system("command -v gnuplot > /dev/null 2>&1") == 0; }

inline bool is_png(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  char magic[8] = {};
  f.read(magic, 8);
  return f && std::string(magic + 1, 3) == "PNG";
}

// Rows of a CSV with a header; empty cells are NaN.
inline std::vector<std::vector<double>> read_csv(const fs::path& p, std::vector<std::string>& header) {
  std::ifstream f(p);
  std::string line;
  std::getline(f, line);
  header.clear();
  std::stringstream hs(line);
  for (std::string c; std::getline(hs, c, ',');) header.push_back(c);
  std::vector<std::vector<double>> rows;
  while (std::getline(f, line)) {
    std::vector<double> row;
    std::stringstream ls(line);
    std::string c;
    for (size_t i = 0; i < header.size(); ++i) {
      std::getline(ls, c, ',');
      row.push_back(c.empty() ? std::nan("") : std::stod(c));
    }
    rows.push_back(row);
  }
  return rows;
}

}  // namespace lpshoot_cli_test
