// Building a problem of one's own (plugin.hpp): the cache key, the cache directory, and the
// CMake project that compiles the file against this lpshoot's package with the compiler and
// flags lpshoot was built with.
#include "plugin.hpp"

#include <lpshoot/version.hpp>

#include <boost/uuid/detail/sha1.hpp>
#include <dlfcn.h>
#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>

extern char** environ;

namespace lpshoot::app::plugin_detail {
namespace {

namespace fs = std::filesystem;

std::string read_file(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  if (!f) throw PluginError(p.string() + ": cannot read the file");
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

// The file and, recursively, the files it includes with "..." that exist next to their includer:
// a change to a header of one's own rebuilds the plugin as a change to the file does.
void collect_sources(const fs::path& file, std::set<fs::path>& seen, std::string& digest_input) {
  const fs::path canonical = fs::weakly_canonical(file);
  if (!seen.insert(canonical).second) return;
  const std::string text = read_file(canonical);
  digest_input += canonical.string() + '\n' + std::to_string(text.size()) + '\n' + text;
  static const std::regex include(R"re(^\s*#\s*include\s*"([^"]+)")re");
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    std::smatch m;
    if (!std::regex_search(line, m, include)) continue;
    const fs::path included = canonical.parent_path() / m[1].str();
    std::error_code ec;
    if (fs::is_regular_file(included, ec)) collect_sources(included, seen, digest_input);
  }
}

std::string sha1_hex(const std::string& data) {
  boost::uuids::detail::sha1 h;
  h.process_bytes(data.data(), data.size());
  boost::uuids::detail::sha1::digest_type d;
  h.get_digest(d);
  char hex[41];
  for (int i = 0; i < 5; ++i) std::snprintf(hex + 8 * i, 9, "%08x", static_cast<unsigned>(d[i]));
  return hex;
}

// The lpshoot package a plugin is built against: the installed one next to the binary holding
// this code (executable or Python module), else the build tree this code was built in, else the
// configured install prefix's.
std::string package_directory() {
  std::vector<fs::path> candidates;
  Dl_info info{};
  if (dladdr(reinterpret_cast<void*>(&package_directory), &info) && info.dli_fname) {
    std::error_code ec;
    const fs::path binary = fs::weakly_canonical(info.dli_fname, ec);
    if (!ec) candidates.push_back(binary.parent_path().parent_path() / LPSHOOT_INSTALL_PACKAGE_DIR);
  }
  candidates.emplace_back(LPSHOOT_BUILD_PACKAGE_DIR);
  candidates.push_back(fs::path(LPSHOOT_INSTALL_PREFIX) / LPSHOOT_INSTALL_PACKAGE_DIR);
  std::string tried;
  for (const auto& c : candidates) {
    std::error_code ec;
    if (fs::is_regular_file(c / "lpshootConfig.cmake", ec)) return c.string();
    tried += (tried.empty() ? "" : ", ") + c.string();
  }
  throw PluginError("cannot build a problem of one's own: lpshoot's CMake package (lpshootConfig.cmake) is in none of " +
                    tried + " (install lpshoot with `cmake --install`, or run it from its build tree)");
}

// Runs argv with stdout and stderr appended to `log` (after the command line itself); the exit
// status (-1: could not start).
int run(const std::vector<std::string>& argv, const std::string& log) {
  {
    std::ofstream l(log, std::ios::app);
    l << "$";
    for (const auto& a : argv) l << " " << a;
    l << "\n";
  }
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  pid_t pid = 0;
  const int rc = posix_spawnp(&pid, args[0], &actions, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0) return -1;
  int status = 0;
  while (waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) return -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
}

// The compiler's and linker's messages from a failed build's log: the error lines with the
// source lines and carets the compiler prints under them (at most 40 lines), else the log's end.
std::string diagnostics(const std::string& log) {
  std::istringstream in(read_file(log));
  std::vector<std::string> lines;
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  static const std::regex error(R"((error|Error):|undefined reference|cannot find -l)");
  static const std::regex context(R"(^\s+(\d+\s+)?\|)");
  std::string out;
  int shown = 0;
  for (size_t i = 0; i < lines.size() && shown < 40; ++i) {
    if (!std::regex_search(lines[i], error)) continue;
    out += "  " + lines[i] + "\n", ++shown;
    for (size_t j = i + 1; j < lines.size() && shown < 40 && std::regex_search(lines[j], context); ++j)
      out += "  " + lines[j] + "\n", ++shown;
  }
  if (!out.empty()) return out;
  for (size_t i = lines.size() > 20 ? lines.size() - 20 : 0; i < lines.size(); ++i) out += "  " + lines[i] + "\n";
  return out;
}

std::string cmake_quote(const std::string& s) {
  std::string q = "\"";
  for (char c : s) q += (c == '"' || c == '\\' || c == '$') ? std::string("\\") + c : std::string(1, c);
  return q + "\"";
}

std::string cmake_command() {
  std::error_code ec;
  return fs::exists(LPSHOOT_CMAKE_COMMAND, ec) ? LPSHOOT_CMAKE_COMMAND : "cmake";
}

}  // namespace

std::string cache_directory(const std::string& configured) {
  fs::path dir;
  if (!configured.empty()) dir = configured;
  else if (const char* c = std::getenv("LPSHOOT_PLUGIN_CACHE"); c && *c) dir = c;
  else if (const char* x = std::getenv("XDG_CACHE_HOME"); x && *x) dir = fs::path(x) / "lpshoot" / "plugins";
  else if (const char* h = std::getenv("HOME"); h && *h) dir = fs::path(h) / ".cache" / "lpshoot" / "plugins";
  else throw PluginError("no plugin cache directory: set LPSHOOT_PLUGIN_CACHE (or HOME)");
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir))
    throw PluginError("plugin cache " + dir.string() + ": cannot create it: " +
                      (ec ? ec.message() : std::string("not a directory")) + " (set LPSHOOT_PLUGIN_CACHE elsewhere)");
  return fs::absolute(dir).string();
}

std::string cache_key(const std::string& source) {
  std::set<fs::path> seen;
  std::string input = std::string(LPSHOOT_BUILD_STAMP) + '\n';
  collect_sources(source, seen, input);
  std::string stem = fs::path(source).stem().string();
  for (char& c : stem)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_' && c != '-') c = '_';
  return stem + "-" + sha1_hex(input).substr(0, 20);
}

std::string build(const std::string& source, const std::string& cache, const std::string& key) {
  static std::atomic<int> counter{0};
  const fs::path final_dir = fs::path(cache) / key;
  const fs::path work = fs::path(cache) / (key + ".building-" + std::to_string(getpid()) + "-" + std::to_string(counter++));
  const std::string package = package_directory();
  std::error_code ec;
  fs::remove_all(work, ec);
  fs::create_directories(work / "project", ec);
  if (ec) throw PluginError("plugin cache " + cache + ": cannot write in it: " + ec.message());
  struct Cleanup {  // nothing half-built stays behind, whatever happens
    fs::path dir;
    ~Cleanup() {
      std::error_code e;
      if (!dir.empty()) fs::remove_all(dir, e);
    }
  } cleanup{work};

  const std::string file = fs::weakly_canonical(source).string();
  {
    std::ofstream cm(work / "project" / "CMakeLists.txt");
    cm << "# Generated by lpshoot for " << file << "\n"
       << "cmake_minimum_required(VERSION 3.20)\nproject(lpshoot_plugin LANGUAGES CXX)\n"
       << "find_package(lpshoot REQUIRED CONFIG)\n"
       << "add_library(problem MODULE " << cmake_quote(file) << ")\n"
       << "target_link_libraries(problem PRIVATE lpshoot::plugin)\n"
       << "# its own copy of the application library, bound to itself; every symbol resolved at link time\n"
       << "target_link_options(problem PRIVATE -Wl,-Bsymbolic -Wl,-z,defs)\n"
       << "set_target_properties(problem PROPERTIES PREFIX \"\" SUFFIX \".so\" LIBRARY_OUTPUT_DIRECTORY "
       << cmake_quote(work.string()) << ")\n";
    if (!cm) throw PluginError("plugin cache " + cache + ": cannot write in it");
  }
  const std::string log = (work / "build.log").string();
  const std::string cmake = cmake_command();
  const int configured = run({cmake, "-S", (work / "project").string(), "-B", (work / "build").string(),
                              "-DCMAKE_BUILD_TYPE=" LPSHOOT_PLUGIN_BUILD_TYPE,
                              "-DCMAKE_CXX_COMPILER=" LPSHOOT_PLUGIN_CXX_COMPILER,
                              "-DCMAKE_CXX_FLAGS=" LPSHOOT_PLUGIN_CXX_FLAGS, "-Dlpshoot_DIR=" + package},
                             log);
  if (configured == -1) throw PluginError(source + ": cannot build it: cmake (" + cmake + ") cannot be run (apt-get install cmake)");
  if (configured != 0)
    throw PluginError(source + ": cannot build it: configuring its CMake project against " + package + " failed:\n" +
                      diagnostics(log));
  if (run({cmake, "--build", (work / "build").string()}, log) != 0)
    throw PluginError(source + ": does not compile (" LPSHOOT_PLUGIN_CXX_COMPILER "):\n" + diagnostics(log));
  fs::remove_all(work / "build", ec);  // the objects: only the library and the log are kept
  fs::rename(work, final_dir, ec);
  if (ec && !fs::exists(final_dir / "problem.so"))  // (else another process built it first: use theirs)
    throw PluginError("plugin cache " + cache + ": cannot store the built plugin: " + ec.message());
  if (!ec) cleanup.dir.clear();
  return (final_dir / "problem.so").string();
}

}  // namespace lpshoot::app::plugin_detail
