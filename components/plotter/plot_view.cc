#include "plot_view.h"

#include <qwt_legend.h>
#include <qwt_plot_canvas.h>
#include <qwt_plot_curve.h>
#include <qwt_plot_grid.h>
#include <qwt_plot_panner.h>
#include <qwt_plot_zoomer.h>
#include <qwt_scale_widget.h>
#include <qwt_symbol.h>
#include <qwt_text.h>

#include <QEvent>
#include <QFontMetrics>
#include <QPen>
#include <algorithm>
#include <cmath>
#include <limits>

namespace caliper::plotter {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
const QColor kStaleColor(150, 150, 150);

// Qwt divides an axis into ticks by adding steps to its lower end: on an interval that is not
// finite, or too narrow for its magnitude (a 10 s window at t = 1e308), that never ends and
// allocated until std::bad_alloc (hostile_corba_test). Such an interval is not set.
bool Divisible(double lo, double hi) {
  return std::isfinite(lo) && std::isfinite(hi) && std::isfinite(hi - lo) && hi > lo &&
         hi - lo > 1e-9 * std::max(std::abs(lo), std::abs(hi));
}

}  // namespace

QString PaletteColor(size_t n) {
  // the "tab10" palette: distinct on white, also for most colour-blind readers
  static const char* const kColors[] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd",
                                        "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf"};
  return kColors[n % 10];
}

struct PlotView::Curve {
  CurveSpec spec;
  QwtPlotCurve* item = nullptr;  // owned by the plot
  DrawPoints points;
  QString unit;
  bool stale = false;
  QString title;
};

PlotView::PlotView(QWidget* parent) : QwtPlot(parent) {
  setAutoReplot(false);
  setCanvasBackground(Qt::white);
  if (auto* c = qobject_cast<QwtPlotCanvas*>(canvas())) c->setFrameStyle(QFrame::NoFrame);
  auto* grid = new QwtPlotGrid;
  grid->setMajorPen(QPen(QColor(220, 220, 220), 0, Qt::SolidLine));
  grid->attach(this);
  auto* legend = new QwtLegend;
  legend->setMaxColumns(2);
  insertLegend(legend, QwtPlot::BottomLegend);
  setAxisTitle(QwtPlot::xBottom, "time [s]");
  setMinimumHeight(110);

  zoomer_ = new QwtPlotZoomer(QwtPlot::xBottom, QwtPlot::yLeft, canvas());
  zoomer_->setRubberBandPen(QPen(Qt::darkGray, 1, Qt::DashLine));
  zoomer_->setTrackerMode(QwtPicker::AlwaysOff);
  panner_ = new QwtPlotPanner(canvas());
  panner_->setMouseButton(Qt::LeftButton, Qt::ShiftModifier);
  canvas()->setToolTip(
      "Drag: zoom in; right click: zoom out; Shift + drag: pan. Zooming or panning pauses the "
      "view; Pause again to follow the live data.");
  auto user_range = [this] {
    if (!on_user_time_range) return;
    const QwtInterval x = axisInterval(QwtPlot::xBottom);
    on_user_time_range(x.minValue(), x.maxValue());
  };
  connect(zoomer_, &QwtPlotZoomer::zoomed, this, [user_range](const QRectF&) { user_range(); });
  connect(panner_, &QwtPlotPanner::panned, this, [user_range](int, int) { user_range(); });
}

PlotView::~PlotView() = default;

bool PlotView::AddCurve(const CurveSpec& spec) {
  if (HasCurve(spec.key)) return false;
  auto c = std::make_unique<Curve>();
  c->spec = spec;
  c->item = new QwtPlotCurve(QString::fromStdString(spec.key));
  c->item->setRenderHint(QwtPlotItem::RenderAntialiased, true);
  c->item->setLegendAttribute(QwtPlotCurve::LegendShowLine, true);
  c->item->setLegendAttribute(QwtPlotCurve::LegendShowSymbol, true);
  c->item->attach(this);
  curves_.push_back(std::move(c));
  Restyle(*curves_.back());
  return true;
}

bool PlotView::RemoveCurve(const std::string& key) {
  const auto it = std::find_if(curves_.begin(), curves_.end(),
                               [&](const auto& c) { return c->spec.key == key; });
  if (it == curves_.end()) return false;
  (*it)->item->detach();
  delete (*it)->item;
  curves_.erase(it);
  // colours follow the position in the plot: restyle the ones that moved up
  for (auto& c : curves_) Restyle(*c);
  return true;
}

bool PlotView::HasCurve(const std::string& key) const { return curve(key) != nullptr; }

bool PlotView::SetStyle(const std::string& key, CurveStyle style) {
  for (auto& c : curves_) {
    if (c->spec.key != key) continue;
    c->spec.style = style;
    Restyle(*c);
    return true;
  }
  return false;
}

PlotSpec PlotView::spec() const {
  PlotSpec p;
  for (const auto& c : curves_) p.curves.push_back(c->spec);
  p.autoscale = autoscale_;
  p.y_min = y_min_;
  p.y_max = y_max_;
  return p;
}

void PlotView::SetAutoscale(bool on) { autoscale_ = on; }

void PlotView::SetYRange(double y_min, double y_max) {
  if (!(y_min < y_max)) return;
  y_min_ = y_min;
  y_max_ = y_max;
  if (!autoscale_) setAxisScale(QwtPlot::yLeft, y_min_, y_max_);
}

void PlotView::ShowTimeTitle(bool on) { setAxisTitle(QwtPlot::xBottom, on ? "time [s]" : ""); }

void PlotView::Restyle(Curve& c) {
  const size_t index = static_cast<size_t>(
      std::find_if(curves_.begin(), curves_.end(), [&](const auto& p) { return p.get() == &c; }) -
      curves_.begin());
  const QColor color = c.stale
                           ? kStaleColor
                           : QColor(c.spec.color.empty() ? PaletteColor(index)
                                                         : QString::fromStdString(c.spec.color));
  // a 1 px cosmetic pen: wider pens go through Qt's stroker, three times slower for
  // thousands of thinned points (bench/plotter)
  QPen pen(color, 1.0, c.stale ? Qt::DashLine : Qt::SolidLine);
  pen.setCosmetic(true);
  if (c.spec.style == CurveStyle::kLine) {
    c.item->setStyle(QwtPlotCurve::Lines);
    c.item->setSymbol(nullptr);
  } else {
    c.item->setStyle(QwtPlotCurve::NoCurve);
    c.item->setSymbol(new QwtSymbol(QwtSymbol::Ellipse, QBrush(color), QPen(color), QSize(4, 4)));
  }
  c.item->setPen(pen);
  QString title =
      QString::fromStdString(c.spec.key) + " [" + (c.unit.isEmpty() ? QString("-") : c.unit) + "]";
  if (c.stale) title += " (stale)";
  if (title != c.title) {
    c.title = title;
    QwtText text(title);
    if (c.stale) text.setColor(kStaleColor);
    c.item->setTitle(text);
  }
}

void PlotView::Draw(const SampleStore& store, double t0, double t1, bool fit_values) {
  if (!(t1 > t0)) t1 = t0 + 1.0;
  const int width = std::max(1, canvas()->contentsRect().width());
  double lo = std::numeric_limits<double>::infinity();
  double hi = -lo;
  QStringList units;
  for (auto& c : curves_) {
    const long s = store.Find(c->spec.key);
    bool stale = false;
    QString unit;
    if (s >= 0) {
      const SeriesInfo& info = store.series(static_cast<size_t>(s));
      stale = info.stale;
      unit = QString::fromStdString(info.unit);
      Decimate(store, static_cast<size_t>(s), t0, t1, width, &c->points);
    } else {
      c->points.clear();
    }
    if (stale != c->stale || unit != c->unit) {
      c->stale = stale;
      c->unit = unit;
      Restyle(*c);
    }
    c->item->setRawSamples(c->points.t.data(), c->points.v.data(),
                           static_cast<int>(c->points.t.size()));
    if (!std::isnan(c->points.v_min)) {
      lo = std::min(lo, c->points.v_min);
      hi = std::max(hi, c->points.v_max);
    }
    const QString u = "[" + (unit.isEmpty() ? QString("-") : unit) + "]";
    if (!units.contains(u)) units << u;
  }
  const QString y_title = units.join("  ");
  if (axisTitle(QwtPlot::yLeft).text() != y_title) setAxisTitle(QwtPlot::yLeft, y_title);
  if (Divisible(t0, t1)) setAxisScale(QwtPlot::xBottom, t0, t1);
  if (!fit_values) return;
  if (!autoscale_) {
    setAxisScale(QwtPlot::yLeft, y_min_, y_max_);
  } else if (lo <= hi) {
    // a margin of 5 %; a (nearly) constant value gets a band of 10 % of it, at least 1e-3
    const double level = std::max(std::abs(lo), std::abs(hi));
    double margin = 0.05 * (hi - lo);
    if (hi - lo <= 1e-12 + 1e-9 * level) margin = std::max(0.1 * level, 1e-3);
    if (Divisible(lo - margin, hi + margin)) setAxisScale(QwtPlot::yLeft, lo - margin, hi + margin);
  }
}

bool PlotView::eventFilter(QObject* watched, QEvent* event) {
  if (watched == canvas() && event->type() == QEvent::Resize) {
    // Qwt's default of 8 major steps stacks the value labels on top of each other in a small tile:
    // give each label two lines of the axis font, between 2 steps and Qwt's 8
    const int line_px = QFontMetrics(axisWidget(QwtPlot::yLeft)->font()).height();
    const int steps = std::clamp(canvas()->height() / std::max(1, 2 * line_px), 2, 8);
    if (axisMaxMajor(QwtPlot::yLeft) != steps) setAxisMaxMajor(QwtPlot::yLeft, steps);
  }
  return QwtPlot::eventFilter(watched, event);
}

void PlotView::ResetZoomBase() { zoomer_->setZoomBase(false); }

QwtPlotCurve* PlotView::curve(const std::string& key) const {
  for (const auto& c : curves_)
    if (c->spec.key == key) return c->item;
  return nullptr;
}

size_t PlotView::points(const std::string& key) const {
  for (const auto& c : curves_)
    if (c->spec.key == key) return c->points.t.size();
  return 0;
}

double PlotView::last_drawn_time(const std::string& key) const {
  for (const auto& c : curves_)
    if (c->spec.key == key) return c->points.t.empty() ? kNaN : c->points.t.back();
  return kNaN;
}

QStringList PlotView::legend_titles() const {
  QStringList titles;
  for (const auto& c : curves_) titles << c->item->title().text();
  return titles;
}

}  // namespace caliper::plotter
