#pragma once
// The calibration report's pictures and page: the best cost against evaluations, for each
// experiment every compared channel (measured, initial, fitted), the parameters with their 95 %
// intervals, the correlation matrix as a picture and the warnings. The PNG (every plot stacked)
// and a self-contained HTML page (the same plots embedded as PNG data, tables and warnings as
// text). Drawn with Qwt offscreen (no display needed); without the GUI build the page has the
// tables only and no PNG is written.

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

/// One row of the report's parameter table; values in the parameter's unit.
struct ReportParameter {
  std::string id, unit;
  double initial = 0, fitted = 0, lower = 0, upper = 0;  // lower/upper: the search bounds
  double sigma = 0, lower95 = 0, upper95 = 0;            // +-inf when not determined
  bool determined = true;
};

struct ReportNoise {
  std::string experiment, column, unit;
  double sigma = 0;
  size_t samples = 0;
};

struct HtmlReport {
  std::string title;                                         // e.g. the calibration file
  std::vector<std::pair<std::string, std::string>> summary;  // (label, value) rows, in order
  std::vector<std::string> warnings;
  std::vector<ReportParameter> parameters;
  std::vector<std::vector<double>> correlation;  // n x n, NaN where not determined
  std::vector<ReportNoise> noise;
  std::vector<Plot> cost;      // the cost curve(s): global search and refinement
  std::vector<Plot> fitted;    // channels of the fitted experiments
  std::vector<Plot> held_out;  // channels of the held-out experiments (may be empty)
};

/// Writes the page to `path` (beside and renamed: whole or nothing); "" when written, else why
/// not.
std::string WriteHtml(const std::string& path, const HtmlReport& report);

}  // namespace caliper::calibration
