// SIGINT and SIGTERM: the first one asks the run to stop at its next checkpoint (a solver
// iteration, a sweep's next run, the end of plotting), which then reports "interrupted"; a
// second one ends the process at once.
#pragma once

#include <stdexcept>
#include <string>

namespace lpshoot::app {

struct Interrupted : std::runtime_error {
  explicit Interrupted(int signal);
  int signal;
};

void install_interrupt_handlers();
int interrupt_signal();       // 0, or the signal received
void throw_if_interrupted();  // throws Interrupted after a signal

}  // namespace lpshoot::app
