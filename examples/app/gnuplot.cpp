// gnuplot for the output writers (gnuplot.hpp).
#include "gnuplot.hpp"

#include "interrupt.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace lpshoot::app {
namespace {

namespace fs = std::filesystem;

// True when FILE is a whole PNG (it ends with the IEND chunk): a full disk can leave a
// truncated image behind a gnuplot that exits 0.
bool complete_png(const fs::path& file) {
  std::ifstream f(file, std::ios::binary | std::ios::ate);
  if (!f || f.tellg() < 20) return false;
  f.seekg(-8, std::ios::end);
  char tail[8];
  f.read(tail, 8);
  return f && std::string(tail, 4) == "IEND";
}

}  // namespace

// Runs gnuplot on plot.gp in the staging directory (which writes the PNGs there). gnuplot runs
// as a child that SIGINT/SIGTERM reach (std::system would make this process ignore them).
void run_gnuplot(OutputDir& out, const std::string& script, const std::vector<std::string>& pngs, Written& w) {
  out.write("plot.gp", script);
  w.files.push_back(out.final_path("plot.gp"));
  const fs::path log = out.staging() / ".gnuplot.log";
  const pid_t pid = fork();
  if (pid == 0) {
    if (chdir(out.staging().c_str()) != 0) _exit(126);
    const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd >= 0) dup2(fd, 1), dup2(fd, 2);
    execlp("gnuplot", "gnuplot", "plot.gp", static_cast<char*>(nullptr));
    _exit(127);
  }
  int status = 0;
  bool waited = pid > 0;
  while (waited && waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) {
      waited = false;
      break;
    }
    if (interrupt_signal()) kill(pid, SIGTERM);  // then reap it
  }
  throw_if_interrupted();
  const int code = !waited ? -1 : WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  std::string first_line;
  {
    std::ifstream f(log);
    std::getline(f, first_line);
  }
  std::error_code ec;
  fs::remove(log, ec);
  if (code != 0) {
    std::string why = code == 127 ? "gnuplot is not installed (apt-get install gnuplot-nox)" : "gnuplot failed";
    if (code != 127 && !first_line.empty()) why += ": " + first_line;
    w.warnings.push_back("plots skipped: " + why + " (script kept in " + out.final_path("plot.gp") + ")");
    for (const auto& p : pngs) fs::remove(out.staging() / p, ec);
    return;
  }
  for (const auto& p : pngs) {
    if (complete_png(out.staging() / p)) {
      w.files.push_back(out.final_path(p));
    } else {
      fs::remove(out.staging() / p, ec);
      w.warnings.push_back("plot " + p + " was not produced in full (disk full?)");
    }
  }
}

std::string gp_header(const std::string& out, int width, int height) {
  std::ostringstream s;
  s << "set terminal pngcairo size " << width << "," << height << " font ',10'\n"
    << "set output '" << out << "'\n";
  return s.str();
}

}  // namespace lpshoot::app
