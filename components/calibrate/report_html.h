#pragma once
// The report page's text, shared by the Qwt build and the build without a GUI: each hands in how
// it draws the pictures (or that it draws none).

#include <functional>
#include <string>
#include <vector>

#include "report.h"

namespace caliper::calibration {

/// How a build draws the page's pictures. Each drawing returns a PNG as base64 text (the payload
/// of a data: URI), "" when it could not draw it.
struct PagePictures {
  /// Draws plots stacked into one PNG; empty in a build without pictures.
  std::function<std::string(const std::vector<Plot>&)> plots;
  /// Draws the correlation matrix (n x n, NaN where not determined), its axes numbered 1..n;
  /// empty in a build without pictures.
  std::function<std::string(const std::vector<std::vector<double>>&)> correlation;
  /// Why there are no pictures (shown on the page when `plots` is empty).
  std::string none;
};

/// Writes the page of `report` to `path` (whole or nothing), its pictures drawn by `pictures`;
/// "" when written, else why not.
std::string WriteHtmlPage(const std::string& path, const HtmlReport& report,
                          const PagePictures& pictures);

}  // namespace caliper::calibration
