#pragma once
// The calibration report's pictures: the best cost against evaluations, and for each experiment
// every compared channel, measured against simulated before and after calibration. Drawn with
// Qwt offscreen (no display needed); absent when Caliper is built without the GUI.

#include <string>
#include <vector>

namespace caliper::calibration {

struct Curve {
  std::string name;
  std::vector<double> x, y;
};

/// One plot: a title, axis titles and curves.
struct Plot {
  std::string title, x_title, y_title;
  std::vector<Curve> curves;
  bool log_y = false;
};

/// Writes `plots` stacked into one PNG of width x (height per plot) pixels; returns "" when
/// written, else why not (no GUI build, a write error).
std::string WritePng(const std::string& path, const std::vector<Plot>& plots, int width = 900,
                     int height_per_plot = 260);

}  // namespace caliper::calibration
