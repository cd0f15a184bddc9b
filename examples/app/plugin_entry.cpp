// Compiled into every plugin (lpshoot::plugin's interface source): the entry points the loader
// calls (plugin.hpp). The plugin links its own copy of the application library, so its problems
// registered themselves into its own registry while the library was loaded; the loader takes
// them from here and checks the stamp of the headers the plugin was compiled against.
#include <lpshoot/app/plugin.hpp>
#include <lpshoot/version.hpp>

extern "C" {

const char* lpshoot_plugin_stamp() { return LPSHOOT_BUILD_STAMP; }

const lpshoot::app::PluginContents* lpshoot_plugin_contents() {
  static const lpshoot::app::PluginContents contents{lpshoot::app::registered_problems(),
                                                     lpshoot::app::registration_errors()};
  return &contents;
}

}  // extern "C"
