// Running, resuming and merging studies, and their files (study_run.hpp).
#include "study_run.hpp"

#include "gnuplot.hpp"
#include "interrupt.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <fstream>
#include <map>
#include <mutex>
#include <sstream>
#include <system_error>
#include <thread>

namespace lpshoot::app {
namespace {

using json = nlohmann::ordered_json;
namespace fs = std::filesystem;

// What the rows of a directory belong to: the base scene and the axes (not the shard).
json spec_json(const Study& s) {
  json axes = json::array();
  for (const auto& a : s.axes) axes.push_back({{"key", a.key}, {"values", a.values}});
  return {{"scene_name", s.scene_name}, {"scene_text", s.scene_text}, {"axes", axes}};
}

Study study_from_spec(const json& j, const std::string& file) {
  Study s;
  s.file = file;
  s.scene_name = j.at("scene_name").get<std::string>();
  s.scene_text = j.at("scene_text").get<std::string>();
  for (const auto& a : j.at("axes")) s.axes.push_back({a.at("key").get<std::string>(), a.at("values").get<std::vector<std::string>>()});
  return s;
}

// The rows in DIR/study.jsonl by point index (a point's last row wins). A line cut short by a kill
// and a rank_lost row are dropped (their points run again); a row of another study is an error.
std::map<size_t, StudyRow> read_rows(const Study& study, const fs::path& dir) {
  std::map<size_t, StudyRow> rows;
  std::ifstream in(dir / "study.jsonl");
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    if (line.empty() || line.back() != '}') continue;  // a partial last line
    try {
      StudyRow r = row_from_json(study, line);
      if (r.status == "rank_lost") rows.erase(r.index);  // not solved: a rerun solves it
      else rows.insert_or_assign(r.index, std::move(r));  // the last row of a point wins
    } catch (const SceneError& e) {
      throw OutputError((dir / "study.jsonl").string() + ":" + std::to_string(n) + ": " + e.what() +
                        " (the directory holds another study's rows: choose another --out)");
    }
  }
  return rows;
}

// Refuses a directory whose rows belong to another study; creates it otherwise.
void claim_directory(const Study& study, const fs::path& dir) {
  std::error_code ec;
  const fs::path spec = dir / "study_spec.json";
  if (fs::exists(spec, ec)) {
    std::ifstream in(spec);
    json j;
    try {
      j = json::parse(in);
    } catch (const json::exception&) {
      throw OutputError(spec.string() + ": unreadable; remove the directory or choose another --out");
    }
    if (j != spec_json(study))
      throw OutputError(dir.string() + ": holds the rows of another study (its scene or axes differ); choose another --out");
    return;
  }
  if (fs::exists(dir / "study.jsonl", ec))
    throw OutputError(dir.string() + ": holds rows without a study_spec.json; choose another --out");
  fs::create_directories(dir, ec);
  std::ofstream out(spec);
  out << spec_json(study).dump(2) << "\n";
  if (!out) throw OutputError(spec.string() + ": cannot be written");
}

std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c == '\n' ? ' ' : c);
  return q + "\"";
}

std::string csv_number(double x) { return std::isfinite(x) ? number_text(x) : std::string(); }  // empty: none

std::string study_csv(const Study& st, const std::vector<StudyRow>& rows) {
  std::string s = "index";
  for (const auto& a : st.axes) s += "," + csv_field(a.key);
  s += ",status,message,scheme_name,N,h,cost,error,error_kind,iterations,residual_norm,wall_time_s\n";
  for (const auto& r : rows) {
    s += std::to_string(r.index);
    for (const auto& v : r.values) {
      const json j = json::parse(v);
      s += "," + csv_field(j.is_string() ? j.get<std::string>() : v);
    }
    s += "," + r.status + "," + csv_field(r.message) + "," + r.scheme + "," + std::to_string(r.N) + "," + csv_number(r.h) +
         "," + csv_number(r.cost) + "," + csv_number(r.error) + "," + r.error_kind + "," + std::to_string(r.iterations) +
         "," + csv_number(r.residual_norm) + "," + csv_number(r.wall_time_s) + "\n";
  }
  return s;
}

// Error against wall time, one series per scheme (inline data blocks: no CSV quoting issues).
std::string pareto_script(const std::vector<StudyRow>& rows) {
  std::map<std::string, std::string> data;
  for (const auto& r : rows)
    if (r.status == "converged" && std::isfinite(r.error) && r.error > 0 && r.wall_time_s > 0)
      data[r.scheme] += csv_number(r.wall_time_s) + " " + csv_number(r.error) + "\n";
  if (data.empty()) return "";
  std::ostringstream g;
  int i = 0;
  for (const auto& [scheme, d] : data) g << "$s" << i++ << " << EOD\n" << d << "EOD\n";
  g << gp_header("study_pareto.png", 900, 600) << "set logscale xy\nset grid\nset format y '10^{%L}'\n"
    << "set xlabel 'wall time per point [s]'\nset ylabel 'error (exact, or estimated)'\n"
    << "set title 'error against cost, by scheme'\nset key top right\nplot ";
  i = 0;
  for (const auto& entry : data)
    g << (i ? ", " : "") << "$s" << i << " using 1:2 with points pt 7 ps 1.2 title '" << entry.first << "'", ++i;
  g << "\nset output\n";
  return g.str();
}

// Cost over the first axis (numeric), one line per value of the second axis.
std::string cost_script(const Study& st, const std::vector<StudyRow>& rows) {
  if (st.axes.empty()) return "";
  std::map<std::string, std::string> data;  // second-axis value -> "x cost" lines
  for (const auto& r : rows) {
    const json x = json::parse(r.values[0]);
    if (r.status != "converged" || !x.is_number() || !std::isfinite(r.cost)) continue;
    data[st.axes.size() > 1 ? r.values[1] : ""] += csv_number(x.get<double>()) + " " + csv_number(r.cost) + "\n";
  }
  if (data.empty() || data.size() > 12) return "";
  std::ostringstream g;
  int i = 0;
  for (const auto& [v, d] : data) g << "$c" << i++ << " << EOD\n" << d << "EOD\n";
  g << gp_header("study_cost.png", 900, 600) << "set grid\nset xlabel '" << st.axes[0].key << "'\nset ylabel 'cost'\n"
    << "set title 'cost over " << st.axes[0].key << "'\nset key outside right\nplot ";
  i = 0;
  for (const auto& entry : data) {
    std::string title = st.axes.size() > 1 ? st.axes[1].key + " = " + entry.first : "cost";
    std::replace(title.begin(), title.end(), '\'', '"');
    g << (i ? ", " : "") << "$c" << i << " using 1:2 with linespoints lw 2 pt 7 title '" << title << "'", ++i;
  }
  g << "\nset output\n";
  return g.str();
}

// Writes the study's files for `rows` (sorted) and commits OUT.
Written write_study(const Study& st, const std::vector<StudyRow>& rows, size_t points, const std::string& shard,
                    double elapsed_s, const std::string& out_dir, bool plot) {
  OutputDir out(out_dir);
  Written w;
  std::string jsonl;
  for (const auto& r : rows) jsonl += row_json(st, r) + "\n";
  out.write("study.jsonl", jsonl);
  out.write("study_spec.json", spec_json(st).dump(2) + "\n");
  out.write("study.csv", study_csv(st, rows));
  for (const char* f : {"study.jsonl", "study.csv"}) w.files.push_back(out.final_path(f));
  if (plot) {
    const std::string pareto = pareto_script(rows), cost = cost_script(st, rows);
    std::vector<std::string> pngs;
    if (!pareto.empty()) pngs.push_back("study_pareto.png");
    if (!cost.empty()) pngs.push_back("study_cost.png");
    if (!pngs.empty()) run_gnuplot(out, "# lpshoot study plots: `gnuplot plot.gp` redraws them.\n" + pareto + cost, pngs, w);
  }
  json j;
  j["lpshoot_version"] = "0.1.0";
  j["command"] = "study";
  j["study_file"] = st.file;
  j["scene"] = st.scene_name;
  json axes = json::object();
  for (const auto& a : st.axes) {
    axes[a.key] = json::array();
    for (const auto& v : a.values) axes[a.key].push_back(json::parse(v));
  }
  j["axes"] = axes;
  j["points_in_study"] = st.points();
  j["shard"] = shard;
  j["points"] = points;
  j["rows"] = rows.size();
  json by_status = json::object();
  size_t failures = 0;
  double solve_time = 0;
  for (const auto& r : rows) {
    by_status[r.status] = by_status.value(r.status, 0) + 1;
    failures += r.status != "converged";
    solve_time += r.wall_time_s;
  }
  j["status"] = rows.size() == points ? (failures ? "completed_with_failures" : "completed") : "incomplete";
  j["by_status"] = by_status;
  j["failures"] = failures;
  j["solve_time_s"] = solve_time;
  j["elapsed_s"] = elapsed_s;
  w.files.insert(w.files.begin(), out.final_path("study.json"));
  j["files"] = w.files;
  j["warnings"] = w.warnings;
  out.write("study.json", j.dump(2, ' ', false, json::error_handler_t::replace) + "\n");
  out.commit();
  return w;
}

size_t failures_in(const std::vector<StudyRow>& rows) {
  return static_cast<size_t>(std::count_if(rows.begin(), rows.end(), [](const StudyRow& r) { return r.status != "converged"; }));
}

}  // namespace

StudyExecutor thread_pool_executor(int threads) {
  return [threads](const Study& study, const std::vector<size_t>& todo, const StudyRecorder& record,
                   const Progress& checkpoint) {
    std::atomic<size_t> next{0};
    std::atomic<bool> stop{false};
    const Progress check = [&](const std::string& line) {
      if (stop) throw Interrupted(interrupt_signal());
      if (checkpoint) checkpoint(line);
    };
    auto worker = [&] {
      for (size_t k; !stop && (k = next++) < todo.size();) {
        try {
          record(run_study_point(study, todo[k], check));
        } catch (const Interrupted&) {
          stop = true;
          return;
        }
      }
    };
    const int n = std::max(1, std::min<int>(threads > 0 ? threads : static_cast<int>(std::thread::hardware_concurrency()),
                                            static_cast<int>(std::max<size_t>(todo.size(), 1))));
    std::vector<std::thread> pool;
    for (int t = 1; t < n; ++t) {
      try {
        pool.emplace_back(worker);
      } catch (const std::system_error&) {  // no more threads: the ones running finish the work
        break;
      }
    }
    worker();
    for (auto& t : pool) t.join();
    if (stop) throw Interrupted(interrupt_signal());
  };
}

StudyOutcome run_study(const Study& study, const StudyOptions& o, const std::function<void(const StudyProgress&)>& progress,
                       const StudyExecutor& executor) {
  const auto started = std::chrono::steady_clock::now();
  const fs::path dir = o.out;
  { OutputDir check(o.out); }  // a place that cannot be written, or holds other files, fails now
  claim_directory(study, dir);
  std::map<size_t, StudyRow> done = read_rows(study, dir);

  StudyOutcome outcome;
  std::vector<size_t> todo;
  for (size_t i = static_cast<size_t>(o.shard); i < study.points(); i += static_cast<size_t>(o.shards)) {
    ++outcome.points;
    if (done.count(i)) ++outcome.skipped;
    else todo.push_back(i);
  }
  // Rows of other shards in this directory (a merged study run again as a shard) are dropped.
  for (auto it = done.begin(); it != done.end();)
    it = it->first % static_cast<size_t>(o.shards) == static_cast<size_t>(o.shard) ? std::next(it) : done.erase(it);

  std::ofstream log(dir / "study.jsonl", std::ios::app);
  if (!log) throw OutputError((dir / "study.jsonl").string() + ": cannot be written");
  std::mutex m;
  StudyProgress p;
  p.total = todo.size();
  const StudyRecorder record = [&](StudyRow row) {
    const std::lock_guard<std::mutex> lock(m);
    log << row_json(study, row) << "\n" << std::flush;
    ++p.done;
    p.failures += row.status != "converged";
    p.elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    p.remaining_s = p.done < p.total ? p.elapsed_s / static_cast<double>(p.done) * static_cast<double>(p.total - p.done) : 0;
    // A point's later row wins (a rank declared lost that answers after all replaces rank_lost).
    if (const auto it = done.find(row.index); it == done.end() || it->second.status == "rank_lost")
      done.insert_or_assign(row.index, std::move(row));
    if (progress) progress(p);
  };
  const Progress checkpoint = [](const std::string&) { throw_if_interrupted(); };
  (executor ? executor : thread_pool_executor(o.threads))(study, todo, record, checkpoint);
  log.close();
  throw_if_interrupted();

  std::vector<StudyRow> rows;
  for (auto& [i, r] : done) rows.push_back(std::move(r));
  outcome.run = p.done;
  outcome.failures = failures_in(rows);
  const std::string shard = o.shards > 1 ? std::to_string(o.shard) + "/" + std::to_string(o.shards) : "";
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  outcome.written = write_study(study, rows, outcome.points, shard, elapsed, o.out, o.plot);
  return outcome;
}

StudyOutcome merge_studies(const std::vector<std::string>& dirs, const std::string& out, bool plot) {
  if (dirs.empty()) throw SceneError("study merge: give the shard directories to merge");
  Study study;
  std::map<size_t, StudyRow> rows;
  for (size_t d = 0; d < dirs.size(); ++d) {
    const fs::path spec = fs::path(dirs[d]) / "study_spec.json";
    std::ifstream in(spec);
    if (!in) throw SceneError(dirs[d] + ": not a study directory (no study_spec.json)");
    json j;
    try {
      j = json::parse(in);
      const Study s = study_from_spec(j, spec.string());
      if (d > 0 && spec_json(s) != spec_json(study))
        throw SceneError(dirs[d] + ": the rows of another study than " + dirs[0] + "'s (the scene or axes differ)");
      if (d == 0) study = s;
    } catch (const json::exception& e) {
      throw SceneError(spec.string() + ": unreadable (" + std::string(e.what()) + ")");
    }
    try {
      for (auto& [i, r] : read_rows(study, dirs[d])) rows.emplace(i, std::move(r));
    } catch (const OutputError& e) {
      throw SceneError(e.what());
    }
  }
  study.file = dirs[0];
  StudyOutcome outcome;
  outcome.points = study.points();
  outcome.skipped = rows.size();
  std::vector<StudyRow> list;
  for (auto& [i, r] : rows) list.push_back(std::move(r));
  outcome.failures = failures_in(list);
  outcome.written = write_study(study, list, outcome.points, "", 0.0, out, plot);
  return outcome;
}

}  // namespace lpshoot::app
