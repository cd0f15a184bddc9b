// Problems of one's own from one C++ file (issue 10): `lpshoot solve --problem my_problem.cpp`.
// The file is compiled once, against this lpshoot's installed (or build-tree) package, into a
// shared library under a cache directory keyed by a hash of the file (and of the files it
// includes with "...") and of lpshoot's build stamp (lpshoot/version.hpp); later runs load it at
// once. The library registers its problems exactly as a built-in problem file does.
#pragma once

#include "problem.hpp"

#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

namespace lpshoot::app {

// A plugin that cannot be built or loaded; the message names the file and says why (for a
// compile error: the compiler's own messages with file and line).
struct PluginError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct PluginOptions {
  // Where built plugins are kept; empty: $LPSHOOT_PLUGIN_CACHE, else $XDG_CACHE_HOME/lpshoot/plugins,
  // else $HOME/.cache/lpshoot/plugins.
  std::string cache_dir;
  // Told before a build starts (it takes a while), e.g. to print "building ...".
  std::function<void(const std::string&)> notify;
};

struct LoadedPlugin {
  std::string source;    // the file as given
  std::string library;   // the shared library loaded
  bool built = false;    // false: taken from the cache
  double build_seconds = 0;
  std::vector<std::string> problems;  // the names it registered
};

// Builds (or finds in the cache) and loads the plugin, then registers its problems with the
// application's registry. Throws PluginError.
LoadedPlugin load_problem_file(const std::string& source, const PluginOptions& options = {});

// What a plugin library exports (plugin_entry.cpp) for the loader: its build stamp, and the
// problems and registration errors of its own registry.
struct PluginContents {
  std::vector<const Problem*> problems;
  std::vector<std::string> errors;
};

namespace plugin_detail {  // plugin_build.cpp, for plugin.cpp
std::string cache_directory(const std::string& configured);
std::string cache_key(const std::string& source);  // throws PluginError if a file cannot be read
// Builds the plugin into cache/key/ (atomically: a half-built one never appears there) and
// returns the library's path. Throws PluginError with the compiler's messages.
std::string build(const std::string& source, const std::string& cache, const std::string& key);
}  // namespace plugin_detail

}  // namespace lpshoot::app

// The entry points a plugin exports (plugin_entry.cpp).
extern "C" {
const char* lpshoot_plugin_stamp();
const lpshoot::app::PluginContents* lpshoot_plugin_contents();
}
