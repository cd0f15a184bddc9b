// gnuplot for the output writers: plot.gp run in an output's staging directory.
#pragma once

#include "output.hpp"

#include <string>
#include <vector>

namespace lpshoot::app {

// Writes `script` as plot.gp into OUT's staging directory and runs gnuplot there (it writes the
// PNGs). gnuplot missing or failing, or a PNG left incomplete, becomes a warning in `w`; the PNGs
// made in full are added to w.files. Throws Interrupted when a signal arrives meanwhile.
void run_gnuplot(OutputDir& out, const std::string& script, const std::vector<std::string>& pngs, Written& w);

// "set terminal pngcairo ... set output 'OUT'".
std::string gp_header(const std::string& out, int width, int height);

}  // namespace lpshoot::app
