// Loading a problem of one's own (plugin.hpp): find or build the library, load it, check its
// stamp, take its problems into the application's registry.
#include "plugin.hpp"

#include <lpshoot/version.hpp>

#include <dlfcn.h>

#include <chrono>
#include <filesystem>
#include <mutex>

namespace lpshoot::app {
namespace {

namespace fs = std::filesystem;

struct Library {
  void* handle = nullptr;
  std::string stamp;
  const PluginContents* contents = nullptr;
};

// Loads the library; throws PluginError naming `source` when it is not a loadable lpshoot plugin.
Library open_library(const std::string& source, const std::string& path) {
  Library lib;
  lib.handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!lib.handle) throw PluginError(source + ": the built plugin cannot be loaded: " + dlerror());
  auto stamp = reinterpret_cast<const char* (*)()>(dlsym(lib.handle, "lpshoot_plugin_stamp"));
  auto contents = reinterpret_cast<const PluginContents* (*)()>(dlsym(lib.handle, "lpshoot_plugin_contents"));
  if (!stamp || !contents)
    throw PluginError(source + ": " + path + " is not an lpshoot plugin (no lpshoot_plugin_stamp / lpshoot_plugin_contents)");
  lib.stamp = stamp();
  // Only a library built against these very headers may be asked for its contents (their layout).
  if (lib.stamp == LPSHOOT_BUILD_STAMP) lib.contents = contents();
  return lib;
}

}  // namespace

LoadedPlugin load_problem_file(const std::string& source, const PluginOptions& options) {
  namespace pd = plugin_detail;
  std::error_code ec;
  if (!fs::is_regular_file(source, ec))
    throw PluginError(source + ": no such file (--problem names a C++ source file with a problem of one's own)");
  const std::string cache = pd::cache_directory(options.cache_dir);
  const std::string key = pd::cache_key(source);
  LoadedPlugin loaded;
  loaded.source = source;
  loaded.library = (fs::path(cache) / key / "problem.so").string();
  Library lib;
  if (fs::exists(loaded.library, ec)) lib = open_library(source, loaded.library);
  if (!lib.contents) {
    // Not built yet, or built against other headers (another lpshoot build in the same cache
    // entry): build it afresh.
    const bool stale = lib.handle != nullptr;
    if (stale) {  // its contents were never taken, so nothing refers to its code
      dlclose(lib.handle);
      fs::remove_all(fs::path(cache) / key, ec);
    }
    if (options.notify) options.notify("building " + source + " (once; cached in " + cache + ")");
    const auto started = std::chrono::steady_clock::now();
    loaded.library = pd::build(source, cache, key);
    loaded.built = true;
    loaded.build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    // dlclose does not unmap a library with STB_GNU_UNIQUE symbols (C++ inline statics), and
    // dlopen matches loaded libraries by the path string first: the stale image would come back.
    // Another spelling of the path makes dlopen compare the file itself, which is new.
    const fs::path fresh = fs::path(loaded.library).parent_path() / "." / fs::path(loaded.library).filename();
    lib = open_library(source, stale ? fresh.string() : loaded.library);
    if (!lib.contents)
      throw PluginError(source + ": the plugin was built against lpshoot " + lib.stamp + ", not this lpshoot (" +
                        LPSHOOT_BUILD_STAMP + "): check that lpshoot's package directory is this build's");
  }
  const PluginContents& c = *lib.contents;
  if (!c.errors.empty()) {
    std::string why = source + ": ";
    for (size_t i = 0; i < c.errors.size(); ++i) why += (i ? "; " : "") + c.errors[i];
    throw PluginError(why);
  }
  if (c.problems.empty())
    throw PluginError(source + ": the file registers no problem: give it a descriptor and a problem object, and "
                               "register it with LPSHOOT_REGISTER_PROBLEM(object) (README, \"A problem of your own\")");
  // The same library loaded again (dlopen returns the same handle, so the same objects): its
  // problems are registered already, and loading it is a no-op (a Python session re-running a cell).
  // Checked and registered as one (threads of a Python session may load files at once).
  static std::mutex registering;
  const std::lock_guard<std::mutex> lock(registering);
  for (const Problem* p : c.problems) {
    const std::string& name = p->descriptor().name;
    if (const Problem* known = find_problem(name); known && known != p)
      throw PluginError(source + ": problem \"" + name + "\" is already registered (a built-in problem or another "
                                 "--problem file has that name): rename it in the descriptor");
  }
  for (const Problem* p : c.problems) {
    if (!find_problem(p->descriptor().name)) register_problem(*p);
    loaded.problems.push_back(p->descriptor().name);
  }
  return loaded;
}

}  // namespace lpshoot::app
