#pragma once
// What the Graph Plotter shows, as a small text file: which series go into which of the stacked
// plots, how each is drawn, the time window, the buffer size and the sampling of the DAQ
// subscription. Saved and loaded by the user, kept in the GUI session and given with --layout.
// No Qt.
//
//   # caliper-plotter layout
//   version = 1
//   window_s = 10
//   buffer_samples = 1000000
//   every_n_steps = 1
//
//   [plot]
//   autoscale = true
//   curve = pendulum_tendon.pivot.position line
//   curve = pendulum_tendon.motor.current scatter #d62728
//
//   [plot]
//   autoscale = false
//   y_range = -5 5
//   curve = pendulum_tendon.motor.tension line

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace caliper::plotter {

/// A layout that cannot be read; the message names the file (or origin) and the line.
class LayoutError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// How a curve is drawn.
enum class CurveStyle { kLine, kScatter };

/// `line` or `scatter`.
const char* Name(CurveStyle style);

/// One curve: a series key and its look.
struct CurveSpec {
  std::string key;  ///< e.g. pendulum_tendon.pivot.position or ...position[2]
  CurveStyle style = CurveStyle::kLine;
  std::string color;  ///< `#rrggbb`; "" picks one from the palette
  /// Same key, style and colour.
  bool operator==(const CurveSpec& o) const {
    return key == o.key && style == o.style && color == o.color;
  }
};

/// One of the stacked plots (they share the time axis).
struct PlotSpec {
  std::vector<CurveSpec> curves;
  bool autoscale = true;  ///< the value axis follows the data drawn
  double y_min = -1;      ///< the value axis when not autoscaled
  double y_max = 1;
  /// Same curves and value axis.
  bool operator==(const PlotSpec& o) const {
    return curves == o.curves && autoscale == o.autoscale && y_min == o.y_min && y_max == o.y_max;
  }
};

/// Everything the plotter restores.
struct Layout {
  static constexpr double kDefaultWindow = 10.0;       ///< [s]
  static constexpr size_t kDefaultBuffer = 1'000'000;  ///< samples per series
  std::vector<PlotSpec> plots;
  double window_s = kDefaultWindow;        ///< the span of simulated time drawn [s]
  size_t buffer_samples = kDefaultBuffer;  ///< samples kept per series (what CSV export writes)
  uint32_t every_n_steps = 1;              ///< the subscription takes one sample every n steps

  /// Every curve key, in plot order, each once.
  std::vector<std::string> Keys() const;
  /// Same plots and settings.
  bool operator==(const Layout& o) const {
    return plots == o.plots && window_s == o.window_s && buffer_samples == o.buffer_samples &&
           every_n_steps == o.every_n_steps;
  }
};

/// Bounds the settings are checked against.
constexpr double kMinWindow = 0.001;       ///< [s]
constexpr double kMaxWindow = 86400.0;     ///< [s]
constexpr size_t kMinBuffer = 100;         ///< samples per curve
constexpr size_t kMaxBuffer = 50'000'000;  ///< samples per curve (400 MB of values)
constexpr uint32_t kMaxEveryNSteps = 1'000'000;
/// What the sample buffers of all curves may take together: the time line and one value per
/// curve, 8 bytes each, per sample [bytes].
constexpr size_t kBufferBudgetBytes = size_t{1} << 30;

/// Bytes the buffers of `curves` curves take when they hold `samples` samples.
size_t BufferBytes(size_t samples, size_t curves);
/// The most samples per curve that `curves` curves may keep within kBufferBudgetBytes (never more
/// than kMaxBuffer, never less than kMinBuffer).
size_t MaxBufferSamples(size_t curves);
/// "" when `curves` curves may keep `samples` samples each; otherwise why not, with the numbers.
std::string BufferBudgetProblem(size_t samples, size_t curves);

/// The layout as text (the format above).
std::string FormatLayout(const Layout& layout);
/// Parses the text; `origin` (a file name) goes into error messages. Throws LayoutError naming
/// the line for unknown keys, bad values, curves before the first [plot], out-of-range settings
/// and a buffer that its curves would make larger than kBufferBudgetBytes.
Layout ParseLayout(const std::string& text, const std::string& origin = "layout");
/// Writes `layout` to `path`, whole or not at all (an existing file is replaced only once the new
/// one is complete); throws LayoutError naming the path and the reason.
void SaveLayout(const Layout& layout, const std::string& path);
/// Reads a layout file; throws LayoutError.
Layout LoadLayout(const std::string& path);

/// Splits `a,b, c` into ids (blank entries dropped).
std::vector<std::string> SplitIds(const std::string& list);
/// Adds a plot holding `keys` as lines (nothing when `keys` is empty).
void AddPlot(Layout* layout, const std::vector<std::string>& keys);

}  // namespace caliper::plotter
