// `lpshoot study`: one base scene over the product of axes (scene key paths and their values),
// one solve (or simulate) per point, one row per point. The study file:
//   { "scene": "beanie.json" | { ...a scene... },
//     "axes": { "horizon.N": [50, 100, 200],
//               "parameters.I1": {"from": 0.5, "to": 2, "count": 4, "log": true},
//               "parameters.m": {"random": {"uniform": [0.5, 1.5]}, "count": 3, "seed": 1} } }
// The points are the product of the axes in the file's order, the last axis fastest. A point
// whose scene is invalid is a row with its error; the study goes on.
#pragma once

#include "run.hpp"

#include <functional>
#include <string>
#include <vector>

namespace lpshoot::app {

struct StudyAxis {
  std::string key;                  // a --set key path, e.g. "horizon.N"
  std::vector<std::string> values;  // each a JSON text
};

struct Study {
  std::string file;             // the study file (messages)
  std::string name;             // its stem: the default output directory lpshoot-out/NAME
  std::string scene_text;       // the base scene's JSON text
  std::string scene_name;       // its file, or "FILE: scene" when inline
  std::vector<StudyAxis> axes;
  size_t points() const;        // the product of the axes' lengths (1 without axes)
  // The values of point i, one JSON text per axis.
  std::vector<std::string> point(size_t i) const;
};

// The shortest text that reads back as x; integral values as integers (so "horizon.N" takes them).
std::string number_text(double x);

// Reads and checks a study file (not its points' scenes). Throws SceneError naming the key.
Study load_study(const std::string& path);

// One point's row. Axis values are JSON texts; numbers NaN when not available.
struct StudyRow {
  size_t index = 0;
  std::vector<std::string> values;
  std::string status, message;
  std::string scheme;  // Scene::scheme_name() ("galerkin4", ...), "flow" for a simulation; column scheme_name
  int N = 0, iterations = 0;
  double h = nan(), cost = nan(), error = nan(), residual_norm = nan(), wall_time_s = 0;
  std::string error_kind;  // "exact" (against the problem's exact solution), "estimate" (Richardson), or ""
};

// Solves (or simulates) point i on one thread (solver.threads = 1 unless an axis sets it).
// Never throws for the point's own failure: an invalid scene, a failed run or a fault is its row
// (status invalid_scene, the run's status, out_of_memory, error); throws Interrupted only.
StudyRow run_study_point(const Study& study, size_t i, const Progress& checkpoint);

// A row as one line of JSON (study.jsonl) and back (throws SceneError on a malformed line).
std::string row_json(const Study& study, const StudyRow& row);
StudyRow row_from_json(const Study& study, const std::string& line);

}  // namespace lpshoot::app
