#pragma once
// One of the Graph Plotter's stacked plots: a QwtPlot with its curves (line or scatter), a legend
// with units, a grid, a zoomer (drag a rectangle; right click zooms out) and a panner (Shift +
// drag). It draws series of a SampleStore thinned to its canvas width; it never changes the store.

#include <QString>
#include <QStringList>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <qwt_plot.h>

#include "decimate.h"
#include "plot_layout.h"
#include "sample_store.h"

class QwtPlotCurve;
class QwtPlotPanner;
class QwtPlotZoomer;

namespace caliper::plotter {

/// One plot of the stack: curves of SampleStore series over a shared time range.
class PlotView : public QwtPlot {
 public:
  explicit PlotView(QWidget* parent = nullptr);
  ~PlotView() override;

  /// Adds a curve; false when the plot has the key already.
  bool AddCurve(const CurveSpec& spec);
  /// False when the plot has no such curve.
  bool RemoveCurve(const std::string& key);
  /// Whether the plot shows `key`.
  bool HasCurve(const std::string& key) const;
  /// Draws a curve as line or scatter; false when the plot has no such curve.
  bool SetStyle(const std::string& key, CurveStyle style);
  /// What the plot shows, as a layout entry.
  PlotSpec spec() const;
  /// Follow the data drawn with the value axis, or keep [y_min, y_max].
  void SetAutoscale(bool on);
  void SetYRange(double y_min, double y_max);
  /// Whether the value axis follows the data.
  bool autoscale() const { return autoscale_; }
  /// Shows or hides the time axis title (only the bottom plot of a stack shows it).
  void ShowTimeTitle(bool on);

  /// Thins each curve's series over [t0, t1] [s] to the canvas width and hands the points to its
  /// QwtPlotCurve; sets the time axis to [t0, t1] and, with `fit_values` and autoscale on, the
  /// value axis to the data drawn (a fixed range otherwise, or the user's zoom when not
  /// `fit_values`). Titles follow units and stale marks. Does not replot.
  void Draw(const SampleStore& store, double t0, double t1, bool fit_values);
  /// Makes the current axes the zoomer's base (after a live redraw).
  void ResetZoomBase();

  /// The Qwt curve of a key, or nullptr.
  QwtPlotCurve* curve(const std::string& key) const;
  /// Points handed to the curve at the last Draw (0 when none).
  size_t points(const std::string& key) const;
  /// Time of the newest point drawn for a key [s]; NaN when none.
  double last_drawn_time(const std::string& key) const;
  /// The legend entries, e.g. `pendulum_tendon.pivot.position [rad]` or `... (stale)`.
  QStringList legend_titles() const;
  /// The rectangle zoomer on the canvas.
  QwtPlotZoomer* zoomer() const { return zoomer_; }
  /// The Shift + drag panner on the canvas.
  QwtPlotPanner* panner() const { return panner_; }

  /// Called with the new time interval when the user zooms or pans this plot.
  std::function<void(double t0, double t1)> on_user_time_range;

 protected:
  /// Keeps the value axis to as many major ticks as its labels fit in the canvas height.
  bool eventFilter(QObject* watched, QEvent* event) override;

 private:
  struct Curve;
  void Restyle(Curve& c);

  std::vector<std::unique_ptr<Curve>> curves_;
  bool autoscale_ = true;
  double y_min_ = -1;
  double y_max_ = 1;
  QwtPlotZoomer* zoomer_ = nullptr;
  QwtPlotPanner* panner_ = nullptr;
};

/// The colour of the n-th curve of a plot when its spec names none (a 10-colour palette).
QString PaletteColor(size_t n);

}  // namespace caliper::plotter
