// The report page: one self-contained HTML file (inline CSS, pictures as data: URIs, no
// scripts), the same text in every build.
#include "report_html.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <locale>
#include <ostream>
#include <sstream>
#include <stdexcept>

#include "caliper/core/system.h"

namespace caliper::calibration {

namespace {

// above this many parameters the correlation table is headed by numbers and a legend
constexpr size_t kMaxNamedColumns = 8;

constexpr const char* kStyle = R"(
body { font-family: "DejaVu Sans", Arial, sans-serif; color: #222; background: #fff;
       max-width: 1100px; margin: 1.5em auto; padding: 0 1em; line-height: 1.4; }
h1 { font-size: 1.7em; border-bottom: 2px solid #444; padding-bottom: 0.2em; }
h2 { font-size: 1.3em; margin-top: 1.6em; border-bottom: 1px solid #ccc; }
table { border-collapse: collapse; margin: 0.5em 0 1em; font-size: 0.92em; }
th, td { border: 1px solid #bbb; padding: 3px 8px; vertical-align: top; }
th { background: #eef1f5; text-align: left; }
td.num { text-align: right; font-variant-numeric: tabular-nums; white-space: nowrap; }
table.summary th { background: #f5f5f5; font-weight: normal; color: #555; }
table.correlation td { text-align: center; min-width: 3.2em; font-variant-numeric: tabular-nums; }
table.correlation td.nan { background: #c8c8c8; color: #555; }
.nd { color: #a33; font-style: italic; }
.warnings { background: #fff4d6; border-left: 6px solid #e0a000; margin: 0.5em 0;
            padding: 0.6em 1em 0.6em 2.2em; }
.warnings li { margin: 0.2em 0; }
.ok { background: #e8f5e8; border-left: 6px solid #3a9a3a; padding: 0.5em 1em; }
.note { background: #eef1f5; border-left: 6px solid #8899aa; padding: 0.5em 1em; }
figure { margin: 0.8em 0; }
img { max-width: 100%; height: auto; border: 1px solid #ddd; }
.legend { font-size: 0.9em; color: #444; }
)";

std::string Escape(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&#39;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

// `digits` significant digits, the same under every locale; a dash for NaN
std::string Number(double v, int digits = 6) {
  if (std::isnan(v)) return "&ndash;";
  if (std::isinf(v)) return v > 0 ? "&infin;" : "&minus;&infin;";
  std::ostringstream out;
  out.imbue(std::locale::classic());
  out << std::setprecision(digits) << v;
  return out.str();
}

// a correlation: two decimals, never "-0.00"
std::string TwoDecimals(double v) {
  if (std::abs(v) < 0.005) v = 0;
  std::ostringstream out;
  out.imbue(std::locale::classic());
  out << std::fixed << std::setprecision(2) << v;
  return out.str();
}

// the picture's colour map for the table's cells: -1 blue, 0 white, +1 red
std::string CorrelationColour(double v) {
  const double t = std::clamp(v, -1.0, 1.0);
  const int blue[3] = {33, 102, 172}, red[3] = {178, 24, 43};
  const int* end = t < 0 ? blue : red;
  const double a = std::abs(t);
  char colour[8];
  std::snprintf(colour, sizeof colour, "#%02x%02x%02x",
                static_cast<int>(std::lround(255 + a * (end[0] - 255))),
                static_cast<int>(std::lround(255 + a * (end[1] - 255))),
                static_cast<int>(std::lround(255 + a * (end[2] - 255))));
  return colour;
}

std::string AltText(const Plot& plot) {
  std::string alt = "Plot: " + plot.title;
  if (!plot.y_title.empty() || !plot.x_title.empty())
    alt += "; " + plot.y_title + " against " + plot.x_title;
  if (!plot.curves.empty()) {
    alt += "; curves:";
    for (size_t c = 0; c < plot.curves.size(); ++c)
      alt += (c == 0 ? " " : ", ") + plot.curves[c].name;
  }
  return alt;
}

void WriteImage(std::ostream& out, const std::string& base64, const std::string& alt) {
  if (base64.empty()) {
    out << "<p class=\"note\">No picture of " << Escape(alt) << " (it could not be drawn).</p>\n";
    return;
  }
  out << "<figure><img src=\"data:image/png;base64," << base64 << "\" alt=\"" << Escape(alt)
      << "\"></figure>\n";
}

void WriteSummary(std::ostream& out, const HtmlReport& report) {
  out << "<section id=\"summary\">\n<h2>Summary</h2>\n";
  if (report.summary.empty()) {
    out << "<p>No summary.</p>\n</section>\n";
    return;
  }
  out << "<table class=\"summary\">\n";
  for (const auto& [label, value] : report.summary)
    out << "<tr><th scope=\"row\">" << Escape(label) << "</th><td>" << Escape(value)
        << "</td></tr>\n";
  out << "</table>\n</section>\n";
}

void WriteWarnings(std::ostream& out, const HtmlReport& report) {
  out << "<section id=\"warnings\">\n<h2>Warnings</h2>\n";
  if (report.warnings.empty()) {
    out << "<p class=\"ok\">No warnings</p>\n";
  } else {
    out << "<ul class=\"warnings\">\n";
    for (const auto& w : report.warnings) out << "<li>" << Escape(w) << "</li>\n";
    out << "</ul>\n";
  }
  out << "</section>\n";
}

void WriteParameters(std::ostream& out, const HtmlReport& report) {
  out << "<section id=\"parameters\">\n<h2>Parameters</h2>\n";
  if (report.parameters.empty()) {
    out << "<p>No parameters.</p>\n</section>\n";
    return;
  }
  out << "<table class=\"parameters\">\n<tr><th>#</th><th>parameter</th><th>unit</th>"
         "<th>initial</th><th>fitted</th><th>95&nbsp;% interval</th>"
         "<th>&plusmn; [% of fitted]</th><th>search bounds</th></tr>\n";
  for (size_t i = 0; i < report.parameters.size(); ++i) {
    const ReportParameter& p = report.parameters[i];
    out << "<tr><td class=\"num\">" << i + 1 << "</td><td>" << Escape(p.id) << "</td><td>"
        << Escape(p.unit) << "</td><td class=\"num\">" << Number(p.initial)
        << "</td><td class=\"num\">" << Number(p.fitted) << "</td>";
    if (p.determined) {
      out << "<td class=\"num\">[" << Number(p.lower95) << ", " << Number(p.upper95) << "]</td>";
      // half the interval's width against the fitted value
      if (p.fitted != 0)
        out << "<td class=\"num\">&plusmn;&nbsp;"
            << Number(100 * (p.upper95 - p.lower95) / 2 / std::abs(p.fitted), 3) << "&nbsp;%</td>";
      else
        out << "<td class=\"num\">&ndash;</td>";
    } else {
      out << "<td colspan=\"2\" class=\"nd\">not determined</td>";
    }
    out << "<td class=\"num\">[" << Number(p.lower) << ", " << Number(p.upper) << "]</td>";
    out << "</tr>\n";
  }
  out << "</table>\n";
  out << "</section>\n";
}

void WriteNoise(std::ostream& out, const HtmlReport& report) {
  out << "<section id=\"noise\">\n<h2>Noise per channel</h2>\n";
  if (report.noise.empty()) {
    out << "<p>No noise estimates.</p>\n</section>\n";
    return;
  }
  out << "<table class=\"noise\">\n<tr><th>experiment</th><th>channel</th><th>&sigma;</th>"
         "<th>samples</th></tr>\n";
  for (const ReportNoise& n : report.noise)
    out << "<tr><td>" << Escape(n.experiment) << "</td><td>" << Escape(n.column)
        << "</td><td class=\"num\">" << Number(n.sigma) << (n.unit.empty() ? "" : "&nbsp;")
        << Escape(n.unit) << "</td><td class=\"num\">" << n.samples << "</td></tr>\n";
  out << "</table>\n</section>\n";
}

void WritePlots(std::ostream& out, const char* id, const char* heading,
                const std::vector<Plot>& plots, const PagePictures& pictures) {
  out << "<section id=\"" << id << "\">\n<h2>" << heading << "</h2>\n";
  if (plots.empty()) out << "<p>No plots.</p>\n";
  for (const Plot& plot : plots) WriteImage(out, pictures.plots({plot}), AltText(plot));
  out << "</section>\n";
}

void WriteCorrelation(std::ostream& out, const HtmlReport& report, const PagePictures& pictures) {
  out << "<section id=\"correlation\">\n<h2>Parameter correlation</h2>\n";
  const auto& matrix = report.correlation;
  const size_t n = matrix.size();
  if (n == 0) {
    out << "<p>No correlation matrix.</p>\n</section>\n";
    return;
  }
  if (pictures.correlation)
    WriteImage(out, pictures.correlation(matrix),
               "Correlation matrix of the " + std::to_string(n) +
                   " parameters: blue -1, white 0, red +1, grey not determined");
  // the parameters' ids as headers, or their numbers when there are many
  const bool named = n <= kMaxNamedColumns;
  const auto header = [&](size_t i) {
    if (!named || i >= report.parameters.size()) return std::to_string(i + 1);
    return Escape(report.parameters[i].id);
  };
  out << "<table class=\"correlation\">\n<tr><th></th>";
  for (size_t j = 0; j < n; ++j) out << "<th>" << header(j) << "</th>";
  out << "</tr>\n";
  for (size_t i = 0; i < n; ++i) {
    out << "<tr><th>" << header(i) << "</th>";
    for (size_t j = 0; j < n; ++j) {
      const double v = j < matrix[i].size() ? matrix[i][j] : std::nan("");
      if (std::isnan(v))
        out << "<td class=\"nan\" title=\"not determined\">&ndash;</td>";
      else
        out << "<td style=\"background:" << CorrelationColour(v)
            << (std::abs(v) >= 0.5 ? ";color:#fff" : "") << "\">" << TwoDecimals(v) << "</td>";
    }
    out << "</tr>\n";
  }
  out << "</table>\n<p class=\"legend\">&ndash;: not determined.";
  if (!named) {
    out << " Parameters:";
    for (size_t i = 0; i < n && i < report.parameters.size(); ++i)
      out << (i == 0 ? " " : "; ") << i + 1 << "&nbsp;" << Escape(report.parameters[i].id);
    out << ".";
  }
  out << "</p>\n</section>\n";
}

void WritePage(std::ostream& out, const HtmlReport& report, const PagePictures& pictures) {
  const std::string title =
      report.title.empty() ? "Calibration report" : "Calibration report: " + report.title;
  out << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
         "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n<title>"
      << Escape(title) << "</title>\n<style>" << kStyle << "</style>\n</head>\n<body>\n<h1>"
      << Escape(title) << "</h1>\n";
  WriteSummary(out, report);
  WriteWarnings(out, report);
  WriteParameters(out, report);
  WriteNoise(out, report);
  if (pictures.plots) {
    WritePlots(out, "cost", "Cost", report.cost, pictures);
    WritePlots(out, "fitted", "Fitted experiments", report.fitted, pictures);
    if (!report.held_out.empty())
      WritePlots(out, "held-out", "Held-out experiments", report.held_out, pictures);
  } else {
    out << "<section id=\"plots\">\n<h2>Plots</h2>\n<p class=\"note\">No plots: "
        << Escape(pictures.none) << ".</p>\n</section>\n";
  }
  WriteCorrelation(out, report, pictures);
  out << "</body>\n</html>\n";
}

}  // namespace

std::string WriteHtmlPage(const std::string& path, const HtmlReport& report,
                          const PagePictures& pictures) {
  try {
    // written beside and renamed: whole or nothing
    core::WriteFileReplacing(path, [&](std::ostream& out) { WritePage(out, report, pictures); });
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

}  // namespace caliper::calibration
