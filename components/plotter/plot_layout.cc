#include "plot_layout.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <set>
#include <sstream>

#include "caliper/core/numbers.h"
#include "caliper/core/system.h"
#include "number_format.h"

namespace caliper::plotter {

namespace {

std::string Trim(const std::string& s) {
  const size_t b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return "";
  const size_t e = s.find_last_not_of(" \t\r");
  return s.substr(b, e - b + 1);
}

std::vector<std::string> Words(const std::string& s) {
  std::istringstream in(s);
  std::vector<std::string> words;
  for (std::string w; in >> w;) words.push_back(w);
  return words;
}

bool IsColor(const std::string& s) {
  return s.size() == 7 && s[0] == '#' && std::all_of(s.begin() + 1, s.end(), [](char c) {
           return std::isxdigit(static_cast<unsigned char>(c)) != 0;
         });
}

}  // namespace

size_t BufferBytes(size_t samples, size_t curves) {
  return samples * (curves + 1) * sizeof(double);
}

size_t MaxBufferSamples(size_t curves) {
  return std::clamp(kBufferBudgetBytes / ((curves + 1) * sizeof(double)), kMinBuffer, kMaxBuffer);
}

std::string BufferBudgetProblem(size_t samples, size_t curves) {
  if (samples <= MaxBufferSamples(curves)) return "";
  constexpr size_t kMiB = size_t{1} << 20;
  return std::to_string(curves) + (curves == 1 ? " curve" : " curves") + " of " +
         std::to_string(samples) + " samples would need " +
         std::to_string((BufferBytes(samples, curves) + kMiB - 1) / kMiB) + " MiB, more than the " +
         std::to_string(kBufferBudgetBytes / kMiB) + " MiB all buffers may take (at most " +
         std::to_string(MaxBufferSamples(curves)) + " samples for " + std::to_string(curves) +
         (curves == 1 ? " curve)" : " curves)");
}

const char* Name(CurveStyle style) { return style == CurveStyle::kLine ? "line" : "scatter"; }

std::vector<std::string> Layout::Keys() const {
  std::vector<std::string> keys;
  std::set<std::string> seen;
  for (const auto& p : plots)
    for (const auto& c : p.curves)
      if (seen.insert(c.key).second) keys.push_back(c.key);
  return keys;
}

std::string FormatLayout(const Layout& layout) {
  std::ostringstream out;
  out << "# caliper-plotter layout\n"
      << "version = 1\n"
      << "window_s = " << FormatNumber(layout.window_s) << "\n"
      << "buffer_samples = " << layout.buffer_samples << "\n"
      << "every_n_steps = " << layout.every_n_steps << "\n";
  for (const auto& p : layout.plots) {
    out << "\n[plot]\n"
        << "autoscale = " << (p.autoscale ? "true" : "false") << "\n";
    // a range set under autoscale is kept for when autoscale is turned off (it was dropped on
    // saving; found by fuzzing)
    if (!p.autoscale || p.y_min != PlotSpec{}.y_min || p.y_max != PlotSpec{}.y_max)
      out << "y_range = " << FormatNumber(p.y_min) << " " << FormatNumber(p.y_max) << "\n";
    for (const auto& c : p.curves) {
      out << "curve = " << c.key << " " << Name(c.style);
      if (!c.color.empty()) out << " " << c.color;
      out << "\n";
    }
  }
  return out.str();
}

Layout ParseLayout(const std::string& text, const std::string& origin) {
  Layout layout;
  std::istringstream in(text);
  std::string raw;
  int line_no = 0;
  bool y_range_seen = false;
  int buffer_line = 0;  // where buffer_samples was set
  auto fail = [&](const std::string& why) -> LayoutError {
    return LayoutError(origin + ":" + std::to_string(line_no) + ": " + why);
  };
  auto parse_double = [&](const std::string& key, const std::string& v) {
    double d = 0;
    if (!core::ParseDouble(v, &d) || !std::isfinite(d))
      throw fail(key + " wants a number, not '" + v + "'");
    return d;
  };
  auto parse_count = [&](const std::string& key, const std::string& v, unsigned long long lo,
                         unsigned long long hi) {
    char* end = nullptr;
    errno = 0;
    const unsigned long long n = std::strtoull(v.c_str(), &end, 10);
    if (v.empty() || v[0] == '-' || *end != '\0' || errno != 0)
      throw fail(key + " wants a whole number, not '" + v + "'");
    if (n < lo || n > hi)
      throw fail(key + " = " + v + " is out of range [" + std::to_string(lo) + ", " +
                 std::to_string(hi) + "]");
    return n;
  };
  while (std::getline(in, raw)) {
    ++line_no;
    const std::string line = Trim(raw);
    if (line.empty() || line[0] == '#') continue;
    if (line == "[plot]") {
      if (!layout.plots.empty() && !layout.plots.back().autoscale && !y_range_seen)
        throw fail("the plot before has autoscale = false but no y_range");
      layout.plots.emplace_back();
      y_range_seen = false;
      continue;
    }
    if (line[0] == '[') throw fail("unknown section " + line + " (only [plot])");
    const size_t eq = line.find('=');
    if (eq == std::string::npos) throw fail("expected key = value, got '" + line + "'");
    const std::string key = Trim(line.substr(0, eq));
    const std::string value = Trim(line.substr(eq + 1));
    if (layout.plots.empty()) {
      // settings of the whole layout
      if (key == "version") {
        if (value != "1") throw fail("unsupported layout version " + value + " (this reads 1)");
      } else if (key == "window_s") {
        const double w = parse_double(key, value);
        if (w < kMinWindow || w > kMaxWindow)
          throw fail("window_s = " + value + " s is out of range [" + FormatNumber(kMinWindow) +
                     ", " + FormatNumber(kMaxWindow) + "]");
        layout.window_s = w;
      } else if (key == "buffer_samples") {
        layout.buffer_samples = parse_count(key, value, kMinBuffer, kMaxBuffer);
        buffer_line = line_no;
      } else if (key == "every_n_steps") {
        layout.every_n_steps = static_cast<uint32_t>(parse_count(key, value, 1, kMaxEveryNSteps));
      } else if (key == "curve" || key == "autoscale" || key == "y_range") {
        throw fail(key + " before the first [plot]");
      } else {
        throw fail("unknown key '" + key + "'");
      }
      continue;
    }
    PlotSpec& plot = layout.plots.back();
    if (key == "autoscale") {
      if (value == "true")
        plot.autoscale = true;
      else if (value == "false")
        plot.autoscale = false;
      else
        throw fail("autoscale wants true or false, not '" + value + "'");
    } else if (key == "y_range") {
      const auto w = Words(value);
      if (w.size() != 2) throw fail("y_range wants two numbers: MIN MAX");
      plot.y_min = parse_double(key, w[0]);
      plot.y_max = parse_double(key, w[1]);
      if (!(plot.y_min < plot.y_max)) throw fail("y_range wants MIN < MAX, got " + value);
      y_range_seen = true;
    } else if (key == "curve") {
      const auto w = Words(value);
      if (w.empty() || w.size() > 3) throw fail("curve wants KEY [line|scatter] [#rrggbb]");
      CurveSpec c;
      c.key = w[0];
      if (w.size() >= 2) {
        if (w[1] == "line")
          c.style = CurveStyle::kLine;
        else if (w[1] == "scatter")
          c.style = CurveStyle::kScatter;
        else
          throw fail("curve style '" + w[1] + "' is neither line nor scatter");
      }
      if (w.size() == 3) {
        if (!IsColor(w[2])) throw fail("curve colour '" + w[2] + "' is not #rrggbb");
        c.color = w[2];
      }
      plot.curves.push_back(c);
    } else {
      throw fail("unknown key '" + key + "' in a [plot]");
    }
  }
  if (!layout.plots.empty() && !layout.plots.back().autoscale && !y_range_seen) {
    ++line_no;
    throw fail("the last plot has autoscale = false but no y_range");
  }
  // all buffers together stay within the budget
  const std::string budget = BufferBudgetProblem(layout.buffer_samples, layout.Keys().size());
  if (!budget.empty()) {
    if (buffer_line > 0) line_no = buffer_line;
    throw fail("buffer_samples: " + budget);
  }
  return layout;
}

void SaveLayout(const Layout& layout, const std::string& path) {
  const std::string text = FormatLayout(layout);
  try {
    core::WriteFileReplacing(path, [&](std::ostream& out) { out << text; });
  } catch (const std::runtime_error& e) {
    throw LayoutError(e.what());
  }
}

Layout LoadLayout(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw LayoutError("cannot read " + path + ": " + std::strerror(errno));
  std::ostringstream text;
  text << in.rdbuf();
  return ParseLayout(text.str(), path);
}

std::vector<std::string> SplitIds(const std::string& list) {
  std::vector<std::string> ids;
  std::string item;
  std::istringstream in(list);
  while (std::getline(in, item, ',')) {
    item = Trim(item);
    if (!item.empty()) ids.push_back(item);
  }
  return ids;
}

void AddPlot(Layout* layout, const std::vector<std::string>& keys) {
  if (keys.empty()) return;
  PlotSpec plot;
  for (const auto& k : keys) plot.curves.push_back(CurveSpec{k, CurveStyle::kLine, ""});
  layout->plots.push_back(plot);
}

}  // namespace caliper::plotter
