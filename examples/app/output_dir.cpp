#include "output_dir.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <vector>

namespace lpshoot::app {
namespace fs = std::filesystem;

namespace {

// The staging directory's name: .TARGET.lpshoot-PID-XXXXXX beside the target.
std::string staging_prefix(const fs::path& target) { return "." + target.filename().string() + ".lpshoot-"; }

// Staging directories of processes that no longer exist (killed runs).
void remove_abandoned(const fs::path& parent, const std::string& prefix) {
  std::error_code ec;
  for (fs::directory_iterator it(parent, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.rfind(prefix, 0) != 0) continue;
    const long pid = std::strtol(name.c_str() + prefix.size(), nullptr, 10);
    if (pid > 0 && kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH) {
      std::error_code ignored;
      fs::remove_all(it->path(), ignored);
    }
  }
}

}  // namespace

bool is_lpshoot_output(const std::string& name) {
  static const std::array<const char*, 16> names = {
      "report.json", "trajectory.csv", "trajectory_extrapolated.csv", "momentum.csv",    "trajectory.png", "momentum.png",
      "plot.gp",     "sweep.json",     "sweep.csv",                   "sweep_error_time.png", "study.json", "study.jsonl",
      "study.csv",   "study_spec.json", "study_pareto.png",           "study_cost.png"};
  if (std::find_if(names.begin(), names.end(), [&](const char* n) { return name == n; }) != names.end()) return true;
  // Temporary files of lpshoot versions that wrote file by file.
  return name == ".gnuplot.log" || (name.size() > 5 && name[0] == '.' && name.compare(name.size() - 4, 4, ".tmp") == 0);
}

OutputDir::OutputDir(const std::string& target) {
  if (target.empty()) throw OutputError("the output directory is empty: give a directory name");
  std::error_code ec;
  target_ = fs::weakly_canonical(fs::absolute(target, ec), ec);
  if (ec || target_.filename().empty() || target_ == target_.root_path())
    throw OutputError(target + ": cannot be used as the output directory");
  if (fs::exists(target_, ec)) {
    if (!fs::is_directory(target_, ec)) throw OutputError(target + ": exists and is not a directory");
    for (fs::directory_iterator it(target_, ec), end; !ec && it != end; it.increment(ec))
      if (!is_lpshoot_output(it->path().filename().string()))
        throw OutputError(target + ": holds files lpshoot did not write (e.g. " + it->path().filename().string() +
                          "); lpshoot replaces its output directory as a whole, so choose a new or empty directory");
    if (ec) throw OutputError(target + ": cannot be read: " + ec.message());
  }
  const fs::path parent = target_.parent_path();
  fs::create_directories(parent, ec);
  if (ec || !fs::is_directory(parent)) throw OutputError(parent.string() + ": cannot create the directory" + (ec ? ": " + ec.message() : ""));
  const std::string prefix = staging_prefix(target_);
  remove_abandoned(parent, prefix);
  std::string tmpl = (parent / (prefix + std::to_string(getpid()) + "-XXXXXX")).string();
  std::vector<char> buf(tmpl.begin(), tmpl.end());
  buf.push_back('\0');
  if (!mkdtemp(buf.data()))
    throw OutputError(parent.string() + ": cannot write there (" + std::strerror(errno) + ")");
  staging_ = buf.data();
  const mode_t mask = umask(0);  // mkdtemp makes 0700; give the result the usual directory mode
  umask(mask);
  chmod(staging_.c_str(), 0777 & ~mask);
}

OutputDir::~OutputDir() {
  if (committed_ || staging_.empty()) return;
  std::error_code ec;
  fs::remove_all(staging_, ec);
}

void OutputDir::write(const std::string& name, const std::string& content) const {
  const fs::path file = staging_ / name;
  const int fd = ::open(file.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw OutputError(final_path(name) + ": could not write: " + std::strerror(errno));
  const char* p = content.data();
  size_t left = content.size();
  while (left > 0) {
    const ssize_t n = ::write(fd, p, left);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const int err = errno;
      ::close(fd);
      throw OutputError(final_path(name) + ": could not write: " + std::strerror(n < 0 ? err : ENOSPC));
    }
    p += n;
    left -= static_cast<size_t>(n);
  }
  if (::fsync(fd) != 0 || ::close(fd) != 0)  // a full disk may only show here
    throw OutputError(final_path(name) + ": could not write: " + std::strerror(errno));
}

void OutputDir::commit() {
  // A new target appears atomically (RENAME_NOREPLACE); an existing one is exchanged with the
  // staging directory, which then holds the old contents and is removed.
  if (renameat2(AT_FDCWD, staging_.c_str(), AT_FDCWD, target_.c_str(), RENAME_NOREPLACE) == 0) {
    committed_ = true;
    return;
  }
  if (errno == EEXIST || errno == ENOTEMPTY) {
    if (renameat2(AT_FDCWD, staging_.c_str(), AT_FDCWD, target_.c_str(), RENAME_EXCHANGE) == 0) {
      std::error_code ec;
      fs::remove_all(staging_, ec);  // the previous result
      committed_ = true;
      return;
    }
  }
  if (errno != EINVAL && errno != ENOSYS && errno != EEXIST)
    throw OutputError(target_.string() + ": could not move the results into place: " + std::strerror(errno));
  // A file system without renameat2's flags: move the old directory aside, then rename (a reader
  // may briefly find no directory, never a mixed one).
  const fs::path old = staging_.string() + ".old";
  std::error_code ec;
  const bool had_target = fs::exists(target_, ec);
  if (had_target) fs::rename(target_, old, ec);
  if (!ec) fs::rename(staging_, target_, ec);
  if (ec) throw OutputError(target_.string() + ": could not move the results into place: " + ec.message());
  if (had_target) fs::remove_all(old, ec);
  committed_ = true;
}

}  // namespace lpshoot::app
