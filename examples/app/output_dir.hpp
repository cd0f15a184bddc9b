// An output directory replaced as a whole: a run writes every file into a fresh staging
// directory beside the target and, once all are written, swaps it into place in one atomic
// rename (renameat2 RENAME_EXCHANGE). Readers, concurrent runs and interrupted runs therefore
// see either the complete earlier result or the complete new one, never a mix.
#pragma once

#include <filesystem>
#include <stdexcept>
#include <string>

namespace lpshoot::app {

struct OutputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

class OutputDir {
 public:
  // Checks the target (a new directory, or one holding only lpshoot's own files) and creates the
  // staging directory, so that an unwritable location is reported before any work starts.
  // Removes staging directories left by runs that were killed. Throws OutputError.
  explicit OutputDir(const std::string& target);
  ~OutputDir();  // removes the staging directory unless it was committed
  OutputDir(const OutputDir&) = delete;
  OutputDir& operator=(const OutputDir&) = delete;

  const std::filesystem::path& target() const { return target_; }
  const std::filesystem::path& staging() const { return staging_; }
  // The path a file will have once committed (what reports list).
  std::string final_path(const std::string& name) const { return (target_ / name).string(); }
  // Writes NAME in the staging directory; throws OutputError when it cannot be written in full.
  void write(const std::string& name, const std::string& content) const;
  // Swaps the staging directory into place (the previous contents are removed).
  void commit();

 private:
  std::filesystem::path target_, staging_;
  bool committed_ = false;
};

// The names lpshoot writes into an output directory.
bool is_lpshoot_output(const std::string& name);

}  // namespace lpshoot::app
