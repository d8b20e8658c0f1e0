// The Graph Plotter in the test process against a real caliper-model (pendulum_tendon.dae):
// the search box filters the channel list, ids go into two stacked plots, the curves fill while
// the simulation runs, pause freezes the view (recording goes on) and resume follows again, clear
// empties, exports (CSV with units and every sample, SVG, PDF, PNG) are well formed and a failed
// one leaves the old file, loading a layout keeps the samples of the curves it keeps; a Model that
// is killed and started again is subscribed to again, a reload without an id marks its curve
// stale (and a reload with it brings it back), a reload that gives plotted ids other shapes keeps
// every curve on its own values; closing does not wait for a hung Model; the buffers stay within
// their memory budget; the data consumer lets no exception into the ORB. The real program is run
// for --help, bad options, Qt's options and the session file (a layout there that does not parse
// is kept aside). Widgets run on QT_QPA_PLATFORM=offscreen.
#include <gtest/gtest.h>
#include <qwt_plot_curve.h>
#include <qwt_symbol.h>
#include <signal.h>
#include <sys/resource.h>

#include <QApplication>
#include <QComboBox>
#include <QElapsedTimer>
#include <QFile>
#include <QImage>
#include <QLabel>
#include <QLineEdit>
#include <QMessageBox>
#include <QMouseEvent>
#include <QPrinter>
#include <QPushButton>
#include <QSettings>
#include <QSpinBox>
#include <QStatusBar>
#include <QSvgRenderer>
#include <QTest>
#include <QToolBar>
#include <QTreeWidget>
#include <QXmlStreamReader>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "caliper/model.hh"
#include "caliper/rtc/naming.h"
#include "daq_link.h"
#include "data_consumer_servant.h"
#include "plot_view.h"
#include "plotter_window.h"
#include "support/gui_test.h"
#include "support/process.h"

namespace caliper::testing {
namespace {

using std::chrono::milliseconds;
using std::chrono::seconds;
namespace M = ::Caliper::Simulation;
namespace D = ::Caliper::Daq;
namespace S = ::Caliper::Scene;
using plotter::DaqLink;
using plotter::Layout;
using plotter::LinkStatus;
using plotter::PlotterWindow;

constexpr const char* kAngle = "pendulum_tendon.pivot.position";
constexpr const char* kCurrent = "pendulum_tendon.motor.current";
constexpr const char* kTension = "pendulum_tendon.motor.tension";
constexpr const char* kHeight = "pendulum_tendon.pendulum.position[2]";
constexpr const char* kCommand = "pendulum_tendon.motor.command";

void Pump(milliseconds duration) {
  WaitInGui([] { return false; }, duration);
}

std::string Models() { return std::string(std::getenv("CALIPER_SOURCE_DIR")) + "/models"; }
std::string TestData() {
  return std::string(std::getenv("CALIPER_SOURCE_DIR")) + "/tests/data/plotter";
}

// The channel row (or element row) whose key is `key`, or nullptr.
QTreeWidgetItem* ChannelItem(PlotterWindow& w, const QString& key) {
  auto* tree = w.findChild<QTreeWidget*>("channels");
  for (int k = 0; k < tree->topLevelItemCount(); ++k) {
    QTreeWidgetItem* item = tree->topLevelItem(k);
    if (item->data(0, Qt::UserRole).toString() == key) return item;
    for (int c = 0; c < item->childCount(); ++c)
      if (item->child(c)->data(0, Qt::UserRole).toString() == key) return item->child(c);
  }
  return nullptr;
}

QStringList VisibleChannels(PlotterWindow& w) {
  auto* tree = w.findChild<QTreeWidget*>("channels");
  QStringList ids;
  for (int k = 0; k < tree->topLevelItemCount(); ++k)
    if (!tree->topLevelItem(k)->isHidden()) ids << tree->topLevelItem(k)->text(0);
  return ids;
}

// Clicks the tool bar button of an action.
void ClickAction(PlotterWindow& w, const char* name) {
  auto* action = w.findChild<QAction*>(name);
  ASSERT_NE(action, nullptr) << name;
  QWidget* button = w.findChild<QToolBar*>("toolbar")->widgetForAction(action);
  ASSERT_NE(button, nullptr) << name;
  QTest::mouseClick(button, Qt::LeftButton);
}

// Drags with the left button from `from` to `to` (Qt 5's QTest::mouseMove only moves the cursor,
// which sends no event on the offscreen platform: the moves are sent here).
void Drag(QWidget* widget, QPoint from, QPoint to, Qt::KeyboardModifiers modifiers) {
  QTest::mousePress(widget, Qt::LeftButton, modifiers, from);
  for (int k = 1; k <= 4; ++k) {
    const QPoint p = from + (to - from) * k / 4;
    QMouseEvent move(QEvent::MouseMove, p, widget->mapToGlobal(p), Qt::NoButton, Qt::LeftButton,
                     modifiers);
    QApplication::sendEvent(widget, &move);
  }
  QTest::mouseRelease(widget, Qt::LeftButton, modifiers, to);
}

// The newest value of a series held (NaN when none).
double Newest(const PlotterWindow& w, const std::string& key) {
  const auto& s = w.store();
  const long i = s.Find(key);
  return i < 0 || s.empty() ? std::nan("") : s.value(static_cast<size_t>(i), s.size() - 1);
}

bool Stale(const PlotterWindow& w, const std::string& key) {
  const long i = w.store().Find(key);
  return i >= 0 && w.store().series(static_cast<size_t>(i)).stale;
}

std::vector<std::string> Split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::istringstream in(s);
  for (std::string x; std::getline(in, x, sep);) out.push_back(x);
  return out;
}

// Every value of a series held, oldest first.
std::vector<double> Values(const PlotterWindow& w, const std::string& key) {
  std::vector<double> v;
  const long s = w.store().Find(key);
  if (s < 0) return v;
  w.store().ForEach(static_cast<size_t>(s), 0, w.store().size(),
                    [&](double, double x) { v.push_back(x); });
  return v;
}

// Element `k` of the Model's value of `id` now.
double Get(M::Model_ptr model, const std::string& id, CORBA::ULong k = 0) {
  S::StringSeq ids;
  ids.length(1);
  ids[0] = id.c_str();
  D::ValueSeq_var values = model->get(ids);
  return values[0].data[k];
}

// The newest sample held is the Model's state now (the Model is not running).
bool UpToDate(const PlotterWindow& w, M::Model_ptr model) {
  M::SimulationStatus_var s = model->status();
  return !w.store().empty() && std::abs(w.store().last_time() - s->sim_time) < 1e-9;
}

void WriteText(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

class PlotterTest : public ::testing::Test {
 protected:
  void SetUp() override {
    App();
    Orb();
    naming_ = std::make_unique<NamingService>(dir_.path());
  }

  std::unique_ptr<Process> StartModel(const std::string& scene) {
    return StartModelProcess(naming_->address(), scene, dir_.path(),
                             dir_.path() + "/model" + std::to_string(++models_) + ".out");
  }

  // The Model bound as model0 that answers.
  M::Model_var WaitForModel() { return testing::WaitForModel(naming_->address()); }

  static DaqLink::Options LinkOptions(const std::string& nameservice) {
    DaqLink::Options options;
    options.nameservice = nameservice;
    options.reconnect_period_ms = 300;
    options.poll_period_ms = 100;
    return options;
  }

  std::unique_ptr<PlotterWindow> Window(const std::string& nameservice) {
    return Window(LinkOptions(nameservice));
  }

  std::unique_ptr<PlotterWindow> Window(const DaqLink::Options& options) {
    auto w = std::make_unique<PlotterWindow>(std::make_unique<DaqLink>(options));
    w->resize(1280, 800);
    w->show();
    return w;
  }

  static void SetCommand(M::Model_ptr model, double volts) {
    D::Value v;
    v.rows = 1;
    v.cols = 1;
    v.data.length(1);
    v.data[0] = volts;
    model->set(kCommand, v);
  }

  TempDir dir_;
  std::unique_ptr<NamingService> naming_;
  int models_ = 0;
};

// The search box: text matches anywhere (any case), a glob matches the whole id.
void CheckSearchBox(PlotterWindow& w) {
  auto* search = w.findChild<QLineEdit*>("search");
  const int all = VisibleChannels(w).size();
  QTest::keyClicks(search, "MOTOR.C");
  QStringList shown = VisibleChannels(w);
  EXPECT_GE(shown.size(), 2) << shown.join(" ").toStdString();
  EXPECT_LT(shown.size(), all);
  for (const QString& id : shown) EXPECT_TRUE(id.contains("motor.c")) << id.toStdString();
  EXPECT_TRUE(shown.contains(kCurrent));
  EXPECT_TRUE(ChannelItem(w, kAngle)->isHidden());
  search->clear();
  QTest::keyClicks(search, "*.pivot.?osition");
  shown = VisibleChannels(w);
  EXPECT_EQ(shown, QStringList{kAngle}) << shown.join(" ").toStdString();
  search->clear();
  QTest::keyClicks(search, "*.pivot.*");
  shown = VisibleChannels(w);
  EXPECT_GE(shown.size(), 2) << "position and velocity at least";
  for (const QString& id : shown)
    EXPECT_TRUE(id.startsWith("pendulum_tendon.pivot.")) << id.toStdString();
  EXPECT_EQ(ChannelItem(w, kAngle)->text(1), "rad") << "units are shown";
  search->clear();
  EXPECT_EQ(VisibleChannels(w).size(), all);
}

// Two ids into plot 1, one into a new plot 2, then a vector element into plot 2.
void AddCurvesToTwoPlots(PlotterWindow& w) {
  auto* channels = w.findChild<QTreeWidget*>("channels");
  auto* target = w.findChild<QComboBox*>("target_plot");
  auto* add = w.findChild<QPushButton*>("add");
  channels->clearSelection();
  ChannelItem(w, kAngle)->setSelected(true);
  ChannelItem(w, kCurrent)->setSelected(true);
  target->setCurrentIndex(0);
  QTest::mouseClick(add, Qt::LeftButton);
  ASSERT_EQ(w.plot_count(), 1);
  EXPECT_TRUE(w.plot(0)->HasCurve(kAngle));
  EXPECT_TRUE(w.plot(0)->HasCurve(kCurrent));
  channels->clearSelection();
  ChannelItem(w, kTension)->setSelected(true);
  target->setCurrentIndex(target->count() - 1);
  EXPECT_EQ(target->currentText(), "New plot");
  QTest::mouseClick(add, Qt::LeftButton);
  ASSERT_EQ(w.plot_count(), 2);
  EXPECT_TRUE(w.plot(1)->HasCurve(kTension));
  EXPECT_EQ(target->currentIndex(), 1) << "the new plot becomes the target";
  channels->clearSelection();
  ASSERT_NE(ChannelItem(w, kHeight), nullptr) << "vector ids offer their elements";
  ChannelItem(w, kHeight)->setSelected(true);
  QTest::mouseClick(add, Qt::LeftButton);
  EXPECT_TRUE(w.plot(1)->HasCurve(kHeight));
  EXPECT_EQ(w.plot(0)->legend_titles(), (QStringList{"pendulum_tendon.pivot.position [rad]",
                                                     "pendulum_tendon.motor.current [A]"}));
}

// Pause: the view stops (the buffer keeps filling); resume: it follows again. Then clear while
// streaming: empty at once, then only newer samples.
void CheckPauseResumeAndClear(PlotterWindow& w) {
  ClickAction(w, "pause");
  EXPECT_TRUE(w.paused());
  const double frozen = w.plot(0)->last_drawn_time(kAngle);
  const size_t frozen_points = w.plot(0)->points(kAngle);
  const size_t held = w.store().size();
  Pump(milliseconds(700));
  EXPECT_EQ(w.plot(0)->last_drawn_time(kAngle), frozen);
  EXPECT_EQ(w.plot(0)->points(kAngle), frozen_points);
  EXPECT_GT(w.store().size(), held + 200) << "samples are still recorded while paused";
  EXPECT_TRUE(w.findChild<QLabel*>("rate")->text().contains("paused"));
  ClickAction(w, "pause");
  EXPECT_FALSE(w.paused());
  EXPECT_TRUE(
      WaitInGui([&] { return w.plot(0)->last_drawn_time(kAngle) > frozen + 0.5; }, seconds(5)));

  const double cleared_at = w.store().last_time();
  ClickAction(w, "clear");
  EXPECT_TRUE(w.store().empty());
  EXPECT_EQ(w.plot(0)->points(kAngle), 0u);
  ASSERT_TRUE(WaitInGui([&] { return w.store().size() > 1500; }, seconds(10)));
  EXPECT_GT(w.store().first_time(), cleared_at);
}

// CSV: the header with units, one row per sample held, every simulation step present.
void CheckCsvExport(PlotterWindow& w, const std::string& dir, QString* error) {
  const QString csv = QString::fromStdString(dir + "/data.csv");
  ClickAction(w, "pause");  // the view only; the samples held now are what gets written
  const size_t rows = w.store().size();
  ASSERT_TRUE(w.ExportCsv(csv, error)) << error->toStdString();
  std::ifstream in(csv.toStdString());
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line,
            "time [s],pendulum_tendon.pivot.position [rad],pendulum_tendon.motor.current [A],"
            "pendulum_tendon.motor.tension [N],pendulum_tendon.pendulum.position[2] [m]");
  size_t n = 0;
  double first = 0, last = -1;
  while (std::getline(in, line)) {
    const auto f = Split(line, ',');
    ASSERT_EQ(f.size(), 5u) << line;
    const double t = std::stod(f[0]);
    ASSERT_GT(t, last) << "times ascend: " << line;
    if (n == 0) first = t;
    last = t;
    for (size_t k = 1; k < f.size(); ++k) ASSERT_TRUE(std::isfinite(std::stod(f[k]))) << line;
    EXPECT_NEAR(std::stod(f[4]), 1.1, 0.5) << "the pendulum's height [m]";
    ++n;
  }
  EXPECT_EQ(n, rows);
  EXPECT_EQ(n, static_cast<size_t>(std::llround((last - first) / 0.001)) + 1)
      << "one row per 1 ms step from " << first << " to " << last << " s";
  EXPECT_EQ(w.link().status().batches_missing, 0u);
  ClickAction(w, "pause");
}

// The plot as SVG (valid XML with an <svg> root), PDF and PNG; unknown suffixes and unwritable
// paths fail with a reason.
void CheckPlotExports(PlotterWindow& w, const std::string& dir, QString* error) {
  const QString svg = QString::fromStdString(dir + "/plot.svg");
  ASSERT_TRUE(w.ExportPlot(svg, error)) << error->toStdString();
  QFile svg_file(svg);
  ASSERT_TRUE(svg_file.open(QIODevice::ReadOnly));
  QXmlStreamReader xml(&svg_file);
  QString root;
  while (!xml.atEnd()) {
    xml.readNext();
    if (xml.isStartElement() && root.isEmpty()) root = xml.name().toString();
  }
  EXPECT_FALSE(xml.hasError()) << xml.errorString().toStdString();
  EXPECT_EQ(root, "svg");
  EXPECT_TRUE(QSvgRenderer(svg).isValid());
  EXPECT_TRUE(ReadFile(svg.toStdString()).find("pendulum_tendon.pivot.position [rad]") !=
              std::string::npos)
      << "the legend is in the drawing";
  const QString pdf = QString::fromStdString(dir + "/plot.pdf");
  ASSERT_TRUE(w.ExportPlot(pdf, error)) << error->toStdString();
  const std::string pdf_bytes = ReadFile(pdf.toStdString());
  EXPECT_GT(pdf_bytes.size(), 1000u);
  EXPECT_EQ(pdf_bytes.rfind("%PDF", 0), 0u);
  const QString exported_png = QString::fromStdString(dir + "/plot.png");
  ASSERT_TRUE(w.ExportPlot(exported_png, error)) << error->toStdString();
  const QImage image(exported_png);
  ASSERT_FALSE(image.isNull());
  int coloured = 0;  // pixels of the curves' colours (not grey, not white)
  for (int y = 0; y < image.height(); y += 2)
    for (int x = 0; x < image.width(); x += 2) {
      const QColor c = image.pixelColor(x, y);
      coloured += c.saturation() > 100 ? 1 : 0;
    }
  EXPECT_GT(coloured, 200) << "the curves are drawn";
  EXPECT_FALSE(w.ExportPlot(QString::fromStdString(dir + "/plot.bmp"), error));
  EXPECT_TRUE(error->contains("use .png, .svg or .pdf")) << error->toStdString();
  EXPECT_FALSE(w.ExportCsv("/nonexistent/dir/data.csv", error));
  EXPECT_TRUE(error->startsWith("cannot write /nonexistent/dir/data.csv")) << error->toStdString();
}

// Printing: to a PDF printer.
void CheckPrinting(PlotterWindow& w, const std::string& dir) {
  const QString printed = QString::fromStdString(dir + "/printed.pdf");
  {
    QPrinter printer(QPrinter::HighResolution);
    printer.setOutputFormat(QPrinter::PdfFormat);
    printer.setOutputFileName(printed);
    w.Print(&printer);
  }
  const std::string printed_bytes = ReadFile(printed.toStdString());
  EXPECT_GT(printed_bytes.size(), 1000u);
  EXPECT_EQ(printed_bytes.rfind("%PDF", 0), 0u);
}

// Zoom: dragging a rectangle on plot 1 pauses the view and gives both plots its time range;
// pan: Shift + drag; autoscale; resume.
void CheckZoomPanAndAutoscale(PlotterWindow& w) {
  ASSERT_FALSE(w.paused());
  QWidget* canvas = w.plot(0)->canvas();
  const QRect area = canvas->contentsRect();
  const QwtInterval live = w.plot(0)->axisInterval(QwtPlot::xBottom);
  const QPoint from(area.left() + area.width() / 4, area.top() + 10);
  const QPoint to(area.left() + area.width() / 2, area.bottom() - 10);
  Drag(canvas, from, to, Qt::NoModifier);
  EXPECT_TRUE(w.paused());
  const QwtInterval zoomed = w.plot(0)->axisInterval(QwtPlot::xBottom);
  EXPECT_NEAR(zoomed.width(), live.width() / 4, live.width() / 20);
  EXPECT_NEAR(zoomed.minValue(), live.minValue() + live.width() / 4, live.width() / 20);
  EXPECT_EQ(w.plot(1)->axisInterval(QwtPlot::xBottom), zoomed) << "one time axis for all plots";
  EXPECT_GT(w.plot(1)->points(kTension), 0u);
  EXPECT_LE(w.plot(1)->last_drawn_time(kTension), zoomed.maxValue() + 0.01)
      << "plot 2 is drawn anew for the zoomed range";
  // pan: Shift + drag to the right shows earlier times, in both plots
  const QPoint grab(area.center());
  const QPoint drop(grab.x() + area.width() / 5, grab.y());
  Drag(canvas, grab, drop, Qt::ShiftModifier);
  const QwtInterval panned = w.plot(0)->axisInterval(QwtPlot::xBottom);
  EXPECT_NEAR(panned.minValue(), zoomed.minValue() - zoomed.width() / 5, zoomed.width() / 20);
  EXPECT_NEAR(panned.width(), zoomed.width(), 1e-9);
  EXPECT_EQ(w.plot(1)->axisInterval(QwtPlot::xBottom), panned);
  EXPECT_TRUE(w.paused());
  // autoscale fits the value axis of the zoomed plot to its data again
  ClickAction(w, "autoscale");
  double lo = 1e300, hi = -1e300;
  const auto [in_first, in_last] = w.store().IndexRange(panned.minValue(), panned.maxValue());
  for (const char* key : {kAngle, kCurrent})
    w.store().ForEach(static_cast<size_t>(w.store().Find(key)), in_first, in_last,
                      [&](double, double v) {
                        lo = std::min(lo, v);
                        hi = std::max(hi, v);
                      });
  ASSERT_LT(lo, hi);
  const QwtInterval y = w.plot(0)->axisInterval(QwtPlot::yLeft);
  EXPECT_LE(y.minValue(), lo);
  EXPECT_GE(y.maxValue(), hi);
  EXPECT_LT(y.width(), 1.2 * (hi - lo)) << "fitted: " << lo << " .. " << hi;
  // resume: the live window again
  ClickAction(w, "pause");
  EXPECT_FALSE(w.paused());
  EXPECT_NEAR(w.plot(0)->axisInterval(QwtPlot::xBottom).width(), 10.0, 1e-9);
}

// A curve drawn as scatter, another removed (its samples go with it).
void CheckCurveStyleAndRemoval(PlotterWindow& w) {
  auto* curves = w.findChild<QTreeWidget*>("curves");
  auto* style = w.findChild<QComboBox*>("style");
  QTreeWidgetItem* current_row = curves->topLevelItem(0)->child(1);
  ASSERT_EQ(current_row->text(0), kCurrent);
  curves->setCurrentItem(current_row);
  EXPECT_TRUE(style->isEnabled());
  style->setCurrentIndex(1);
  emit style->activated(1);
  EXPECT_EQ(w.plot(0)->spec().curves[1].style, plotter::CurveStyle::kScatter);
  EXPECT_EQ(w.plot(0)->curve(kCurrent)->style(), QwtPlotCurve::NoCurve);
  ASSERT_NE(w.plot(0)->curve(kCurrent)->symbol(), nullptr);
  curves->setCurrentItem(curves->topLevelItem(1)->child(1));
  ASSERT_EQ(curves->currentItem()->text(0), kHeight);
  QTest::mouseClick(w.findChild<QPushButton*>("remove"), Qt::LeftButton);
  EXPECT_FALSE(w.plot(1)->HasCurve(kHeight));
  EXPECT_LT(w.store().Find(kHeight), 0);
  EXPECT_EQ(curves->topLevelItem(1)->childCount(), 1);
}

// The layout round trip through the window: the recorded samples stay; another layout: the
// angle keeps its samples, the curves it lacks go, a new one has none yet.
void CheckLayoutRoundTrip(PlotterWindow& w) {
  const Layout layout = w.CurrentLayout();
  ASSERT_EQ(layout.plots.size(), 2u);
  EXPECT_EQ(layout.Keys(), (std::vector<std::string>{kAngle, kCurrent, kTension}));
  const size_t held_now = w.store().size();
  const std::vector<double> angles = Values(w, kAngle);
  const std::vector<double> currents = Values(w, kCurrent);
  ASSERT_GT(held_now, 1000u);
  w.ApplyLayout(layout);
  EXPECT_EQ(w.CurrentLayout(), layout);
  EXPECT_EQ(w.store().size(), held_now);
  EXPECT_EQ(Values(w, kAngle), angles) << "loading a layout keeps the recorded data";
  EXPECT_EQ(Values(w, kCurrent), currents);
  Layout other;
  plotter::AddPlot(&other, {kAngle});
  plotter::AddPlot(&other, {kHeight});
  w.ApplyLayout(other);
  EXPECT_EQ(w.CurrentLayout(), other);
  EXPECT_EQ(Values(w, kAngle), angles);
  EXPECT_LT(w.store().Find(kCurrent), 0);
  EXPECT_LT(w.store().Find(kTension), 0);
  const std::vector<double> heights = Values(w, kHeight);
  ASSERT_EQ(heights.size(), held_now);
  EXPECT_TRUE(std::all_of(heights.begin(), heights.end(), [](double v) { return std::isnan(v); }));
}

// One window on one Model throughout, phase after phase (the checks above); a fatal failure in
// a phase ends the test.
TEST_F(PlotterTest, PicksIdsStreamsPausesClearsAndExports) {
  auto process = StartModel(Models() + "/pendulum_tendon.dae");
  M::Model_var model = WaitForModel();
  ASSERT_FALSE(CORBA::is_nil(model)) << process->Output();
  auto w = Window(naming_->address());
  ASSERT_TRUE(WaitInGui([&] { return ChannelItem(*w, kAngle) != nullptr; }, seconds(10)))
      << "the channel list is filled from the Model";

  ASSERT_NO_FATAL_FAILURE(CheckSearchBox(*w));
  ASSERT_NO_FATAL_FAILURE(AddCurvesToTwoPlots(*w));

  // run: the tendon pulls the pendulum up, then lets it swing
  SetCommand(model, 12.0);
  model->start();
  ASSERT_TRUE(WaitInGui(
      [&] {
        return w->store().size() > 500 && w->plot(0)->points(kAngle) > 100 &&
               w->plot(1)->points(kTension) > 100;
      },
      seconds(15)))
      << "held " << w->store().size() << "; " << process->Output();
  EXPECT_TRUE(w->findChild<QLabel*>("connection")->text().startsWith("connected to model0"))
      << w->findChild<QLabel*>("connection")->text().toStdString();
  ASSERT_TRUE(WaitInGui([&] { return w->sample_rate() > 100; }, seconds(5)));
  SetCommand(model, 0.0);

  ASSERT_NO_FATAL_FAILURE(CheckPauseResumeAndClear(*w));

  // the screenshot
  SetCommand(model, 12.0);
  Pump(milliseconds(400));
  SetCommand(model, 0.0);
  Pump(milliseconds(600));
  const std::string png = ArtifactPath("plotter.png", dir_.path());
  EXPECT_TRUE(w->grab().save(QString::fromStdString(png))) << png;

  QString error;
  ASSERT_NO_FATAL_FAILURE(CheckCsvExport(*w, dir_.path(), &error));
  ASSERT_NO_FATAL_FAILURE(CheckPlotExports(*w, dir_.path(), &error));
  ASSERT_NO_FATAL_FAILURE(CheckPrinting(*w, dir_.path()));
  ASSERT_NO_FATAL_FAILURE(CheckZoomPanAndAutoscale(*w));
  ASSERT_NO_FATAL_FAILURE(CheckCurveStyleAndRemoval(*w));
  ASSERT_NO_FATAL_FAILURE(CheckLayoutRoundTrip(*w));

  model->pause();
  w.reset();
  process->Signal(SIGTERM);
  EXPECT_EQ(process->Wait(seconds(10)), 0) << process->Output();
}

TEST_F(PlotterTest, SubscribesAgainToARestartedModelAndMarksVanishedIdsStale) {
  auto process = StartModel(Models() + "/pendulum_tendon.dae");
  M::Model_var model = WaitForModel();
  ASSERT_FALSE(CORBA::is_nil(model)) << process->Output();
  auto w = Window(naming_->address());
  Layout layout;
  plotter::AddPlot(&layout, {kAngle, kCurrent});
  w->ApplyLayout(layout);
  model->start();
  ASSERT_TRUE(WaitInGui([&] { return w->store().size() > 300; }, seconds(15))) << process->Output();
  const uint64_t subscriptions = w->link().status().subscriptions_made;
  EXPECT_GE(subscriptions, 1u);

  // kill the Model: the plotter says so; a new Model: subscribed again, samples arrive again
  process->Signal(SIGKILL);
  process->Wait(seconds(5));
  auto* connection = w->findChild<QLabel*>("connection");
  ASSERT_TRUE(
      WaitInGui([&] { return connection->text().startsWith("not connected"); }, seconds(10)))
      << connection->text().toStdString();
  const uint64_t appended = w->store().samples_appended();
  process = StartModel(Models() + "/pendulum_tendon.dae");
  model = WaitForModel();
  ASSERT_FALSE(CORBA::is_nil(model)) << process->Output();
  model->start();
  ASSERT_TRUE(WaitInGui(
      [&] {
        return w->link().status().subscriptions_made > subscriptions &&
               w->store().samples_appended() > appended + 300;
      },
      seconds(20)))
      << "subscriptions " << w->link().status().subscriptions_made << ", "
      << connection->text().toStdString();
  EXPECT_EQ(w->store().rewinds(), 1u) << "the new Model's time starts at 0 again";
  EXPECT_TRUE(connection->text().startsWith("connected to model0"));
  EXPECT_FALSE(Stale(*w, kCurrent));

  // reload without the motor: its current goes stale (greyed, marked), the angle streams on
  model->load_scene((TestData() + "/pendulum_no_motor.dae").c_str());
  model->start();
  ASSERT_TRUE(WaitInGui([&] { return Stale(*w, kCurrent); }, seconds(10)));
  EXPECT_FALSE(Stale(*w, kAngle));
  ASSERT_TRUE(
      WaitInGui([&] { return w->plot(0)->legend_titles().last().endsWith("(stale)"); }, seconds(5)))
      << w->plot(0)->legend_titles().join(", ").toStdString();
  EXPECT_EQ(w->plot(0)->legend_titles().first(), "pendulum_tendon.pivot.position [rad]");
  const uint64_t before = w->store().samples_appended();
  ASSERT_TRUE(WaitInGui([&] { return w->store().samples_appended() > before + 300; }, seconds(10)));
  EXPECT_TRUE(std::isfinite(Newest(*w, kAngle)));
  EXPECT_TRUE(std::isnan(Newest(*w, kCurrent)));
  EXPECT_EQ(ChannelItem(*w, kCurrent), nullptr) << "the channel list follows the scene";
  Pump(milliseconds(300));
  EXPECT_TRUE(
      w->grab().save(QString::fromStdString(ArtifactPath("plotter_stale.png", dir_.path()))));

  // the motor back: the curve is live again
  model->load_scene((Models() + "/pendulum_tendon.dae").c_str());
  model->start();
  EXPECT_TRUE(WaitInGui([&] { return !Stale(*w, kCurrent) && std::isfinite(Newest(*w, kCurrent)); },
                        seconds(10)));
  EXPECT_FALSE(w->plot(0)->legend_titles().last().endsWith("(stale)"));

  w.reset();
  process->Signal(SIGTERM);
  EXPECT_EQ(process->Wait(seconds(10)), 0) << process->Output();
}

TEST_F(PlotterTest, TheProgramTakesItsOptionsAndKeepsItsSession) {
  const CommandResult help = RunCommand({Bin("caliper-plotter"), "--help"}, seconds(10));
  EXPECT_EQ(help.exit_code, 0);
  for (const char* option :
       {"--nameservice", "--model", "--layout", "--ids", "--geometry", "--session"})
    EXPECT_NE(help.out.find(option), std::string::npos) << option;
  const CommandResult bad = RunCommand({Bin("caliper-plotter"), "--bogus"}, seconds(10));
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("unknown option '--bogus'"), std::string::npos) << bad.err;
  const CommandResult layout =
      RunCommand({Bin("caliper-plotter"), "--layout", "/nonexistent.layout"}, seconds(10));
  EXPECT_EQ(layout.exit_code, 2);
  EXPECT_NE(layout.err.find("cannot read /nonexistent.layout"), std::string::npos) << layout.err;
  // Qt's options pass, values and all: the first unknown one is ours to refuse
  const CommandResult qt_option =
      RunCommand({Bin("caliper-plotter"), "-platform", "offscreen", "-style", "fusion", "--bogus"},
                 seconds(10));
  EXPECT_EQ(qt_option.exit_code, 2);
  EXPECT_NE(qt_option.err.find("unknown option '--bogus'"), std::string::npos) << qt_option.err;

  // --ids and --geometry go into the session file when the plotter ends on SIGTERM
  const std::string session = dir_.path() + "/session.ini";
  {
    Process p(
        {Bin("caliper-plotter"), "-platform", "offscreen", "--nameservice", naming_->address(),
         "--session", session, "--geometry", "640x480+30+40", "--ids", "a.b, c.d[1]", "--ids", "e"},
        dir_.path() + "/plotter1.out");
    std::this_thread::sleep_for(milliseconds(1500));
    p.Signal(SIGTERM);
    EXPECT_EQ(p.Wait(seconds(10)), 0) << p.Output();
  }
  Layout stored;
  QString error;
  ASSERT_TRUE(PlotterWindow::SessionLayout(QString::fromStdString(session), &stored, &error))
      << error.toStdString() << ReadFile(session);
  ASSERT_EQ(stored.plots.size(), 2u);
  EXPECT_EQ(stored.Keys(), (std::vector<std::string>{"a.b", "c.d[1]", "e"}));
  EXPECT_EQ(QSettings(QString::fromStdString(session), QSettings::IniFormat)
                .value("plotter/geometry")
                .toString(),
            "640x480+30+40");

  // with the session alone both are restored (and written back unchanged)
  {
    Process p({Bin("caliper-plotter"), "--nameservice", naming_->address(), "--session", session},
              dir_.path() + "/plotter2.out");
    std::this_thread::sleep_for(milliseconds(1500));
    p.Signal(SIGINT);
    EXPECT_EQ(p.Wait(seconds(10)), 0) << p.Output();
  }
  Layout again;
  ASSERT_TRUE(PlotterWindow::SessionLayout(QString::fromStdString(session), &again, &error));
  EXPECT_EQ(again, stored);
  EXPECT_EQ(QSettings(QString::fromStdString(session), QSettings::IniFormat)
                .value("plotter/geometry")
                .toString(),
            "640x480+30+40");

  // a session layout that does not parse: said on stderr, kept as plotter/layout.rejected
  const QString rejected = "version = 1\nwindow = 3\n[plot]\ncurve = a.b\n";
  QSettings(QString::fromStdString(session), QSettings::IniFormat)
      .setValue("plotter/layout", rejected);
  {
    Process p({Bin("caliper-plotter"), "--nameservice", naming_->address(), "--session", session},
              dir_.path() + "/plotter3.out");
    std::this_thread::sleep_for(milliseconds(1500));
    p.Signal(SIGTERM);
    EXPECT_EQ(p.Wait(seconds(10)), 0) << p.Output();
    EXPECT_NE(p.Output().find("unknown key 'window'"), std::string::npos) << p.Output();
  }
  QSettings after(QString::fromStdString(session), QSettings::IniFormat);
  EXPECT_EQ(after.value("plotter/layout.rejected").toString(), rejected);
  EXPECT_NE(after.value("plotter/layout").toString(), rejected) << "the window's layout is written";
}

// The layout shown is in the session file from the start, not only once the window closes: a
// plotter that never closes (SIGKILL here; a lost X server or a crash alike) does not leave the
// layout of an earlier session behind for the next one.
TEST_F(PlotterTest, WritesTheLayoutItShowsAtOnceSoAKilledPlotterLeavesIt) {
  const std::string session = dir_.path() + "/killed.ini";
  QSettings(QString::fromStdString(session), QSettings::IniFormat)
      .setValue("plotter/layout", "version = 1\n[plot]\ncurve = earlier.session\n");
  Process p({Bin("caliper-plotter"), "-platform", "offscreen", "--nameservice", naming_->address(),
             "--session", session, "--ids", "demo.elbow.position"},
            dir_.path() + "/killed.out");
  Layout stored;
  QString error;
  const auto deadline = std::chrono::steady_clock::now() + seconds(10);
  while (std::chrono::steady_clock::now() < deadline) {
    if (PlotterWindow::SessionLayout(QString::fromStdString(session), &stored, &error) &&
        stored.Keys() == std::vector<std::string>{"demo.elbow.position"})
      break;
    std::this_thread::sleep_for(milliseconds(50));
  }
  p.Signal(SIGKILL);
  p.Wait(seconds(10));
  ASSERT_TRUE(PlotterWindow::SessionLayout(QString::fromStdString(session), &stored, &error))
      << error.toStdString() << ReadFile(session);
  EXPECT_EQ(stored.Keys(), std::vector<std::string>{"demo.elbow.position"})
      << "the earlier session's layout stayed: " << ReadFile(session);
}

TEST_F(PlotterTest, KeepsARejectedSessionLayoutAsideAndSaysWhy) {
  const QString session = QString::fromStdString(dir_.path() + "/session.ini");
  const QString bad = "buffer_samples = 10\n[plot]\ncurve = a.b\n";
  {
    QSettings st(session, QSettings::IniFormat);
    st.setValue("plotter/layout", bad);
    st.setValue("plotter/geometry", "640x480+30+40");
  }
  auto w = Window(naming_->address());
  QString error;
  EXPECT_FALSE(w->RestoreSessionLayout(session, &error));
  EXPECT_TRUE(error.contains("buffer_samples = 10 is out of range")) << error.toStdString();
  EXPECT_TRUE(error.contains("plotter/layout.rejected")) << error.toStdString();
  EXPECT_EQ(w->statusBar()->currentMessage(), error);
  EXPECT_EQ(QSettings(session, QSettings::IniFormat).value("plotter/layout.rejected").toString(),
            bad)
      << "kept before anything writes the session";
  ASSERT_TRUE(WaitInGui([&] { return w->findChild<QMessageBox*>("session_problem") != nullptr; },
                        seconds(2)));
  auto* box = w->findChild<QMessageBox*>("session_problem");
  EXPECT_TRUE(box->isVisible());
  EXPECT_FALSE(box->isModal()) << "the window stays usable";
  EXPECT_EQ(box->text(), error);
  // closing writes the layout shown; the rejected text stays aside
  w->SetSessionFile(session);
  w->close();
  QSettings st(session, QSettings::IniFormat);
  EXPECT_EQ(st.value("plotter/layout.rejected").toString(), bad);
  EXPECT_NE(st.value("plotter/layout").toString(), bad);
  EXPECT_EQ(st.value("plotter/geometry").toString(), "640x480+30+40");
  // a session without a layout: nothing to say
  const QString empty = QString::fromStdString(dir_.path() + "/empty.ini");
  error.clear();
  auto w2 = Window(naming_->address());
  EXPECT_FALSE(w2->RestoreSessionLayout(empty, &error));
  EXPECT_TRUE(error.isEmpty());
}

TEST_F(PlotterTest, SaysSoAndStaysResponsiveWithNoModelInReach) {
  auto w = Window(naming_->address());
  Layout layout;
  plotter::AddPlot(&layout, {kAngle});
  w->ApplyLayout(layout);
  auto* connection = w->findChild<QLabel*>("connection");
  ASSERT_TRUE(WaitInGui([&] { return connection->text().startsWith("not connected to model0"); },
                        seconds(5)))
      << connection->text().toStdString();
  const qint64 longest = LongestEventLoopStall(std::chrono::milliseconds(2000));
  EXPECT_LT(longest, 300) << "the GUI thread was blocked for " << longest << " ms";
  EXPECT_FALSE(Stale(*w, kAngle)) << "not stale: no Model said it lacks the id";
  QElapsedTimer closing;
  closing.start();
  w.reset();
  EXPECT_LT(closing.elapsed(), 3000) << "closing does not hang";
}

TEST_F(PlotterTest, KeepsEachCurveOnItsOwnValuesWhenAReloadChangesTheShapesOfItsIds) {
  // the scene at a path of the test's own, so that the same path can hold another scene
  const std::string scene = dir_.path() + "/scene.dae";
  WriteText(scene, ReadFile(Models() + "/pendulum_tendon.dae"));
  auto process = StartModel(scene);
  M::Model_var model = WaitForModel();
  ASSERT_FALSE(CORBA::is_nil(model)) << process->Output();
  // no periodic listing: only what the plotter does about a changed layout brings the new one
  DaqLink::Options options = LinkOptions(naming_->address());
  options.relist_period_ms = 600'000;
  auto w = Window(options);
  Layout layout;
  plotter::AddPlot(&layout, {kAngle, kCurrent});
  w->ApplyLayout(layout);
  ASSERT_TRUE(WaitInGui([&] { return w->link().status().subscription != 0; }, seconds(10)));

  // the same path loaded again with the body and the hinge swapping names, before the Model ever
  // ran: nothing says the scene changed but the batches, 4 values a sample ([pivot.position is
  // the body's position now, 3x1] and the current) for a subscription laid out for 2
  WriteText(scene, ReadFile(TestData() + "/pendulum_swapped_names.dae"));
  model->load_scene(scene.c_str());
  SetCommand(model, 12.0);
  const uint64_t made = w->link().status().subscriptions_made;
  model->step(200);
  ASSERT_TRUE(WaitInGui(
      [&] {
        return w->unreadable_batches() > 0 && w->link().status().subscriptions_made > made &&
               w->link().status().subscription != 0;
      },
      seconds(10)))
      << "unreadable " << w->unreadable_batches() << ", "
      << w->findChild<QLabel*>("connection")->text().toStdString();
  w->RefreshStatus();
  EXPECT_TRUE(w->findChild<QLabel*>("rate")->text().contains("batches unreadable"))
      << w->findChild<QLabel*>("rate")->text().toStdString();
  // subscribed anew: the current where the Model has it, the angle's key no longer fits its id
  model->step(200);
  ASSERT_TRUE(WaitInGui([&] { return UpToDate(*w, model); }, seconds(10)))
      << w->store().last_time();
  EXPECT_DOUBLE_EQ(Newest(*w, kCurrent), Get(model, kCurrent));
  EXPECT_TRUE(std::isnan(Newest(*w, kAngle)));
  EXPECT_TRUE(WaitInGui([&] { return Stale(*w, kAngle); }, seconds(5)));

  // the hinge angle by its name in this scene, then pendulum_tendon.dae from its own path: the
  // ids [pivot.position, current, pendulum.position] take 3+1+1 values here and 1+1+3 there,
  // the same width, with the current moving from value 3 to value 1
  const std::string hinge = "pendulum_tendon.pendulum.position";
  ASSERT_TRUE(w->AddCurve(0, hinge));
  ASSERT_TRUE(WaitInGui([&] { return w->link().status().subscribed.size() == 3; }, seconds(10)));
  model->step(200);
  ASSERT_TRUE(WaitInGui([&] { return UpToDate(*w, model); }, seconds(10)));
  EXPECT_DOUBLE_EQ(Newest(*w, hinge), Get(model, hinge));
  EXPECT_DOUBLE_EQ(Newest(*w, kCurrent), Get(model, kCurrent));
  const LinkStatus before = w->link().status();
  model->load_scene((Models() + "/pendulum_tendon.dae").c_str());
  ASSERT_TRUE(WaitInGui(
      [&] {
        const LinkStatus s = w->link().status();
        return s.subscriptions_made > before.subscriptions_made && s.subscription != 0;
      },
      seconds(10)))
      << "a new scene with other shapes is subscribed to anew";
  EXPECT_GT(w->link().status().layout_resubscriptions, before.layout_resubscriptions);
  EXPECT_NE(w->link().status().message.find("pendulum_tendon.pivot.position is 1x1 [rad] now"),
            std::string::npos)
      << w->link().status().message;
  model->step(200);
  ASSERT_TRUE(WaitInGui([&] { return UpToDate(*w, model); }, seconds(10)));
  EXPECT_DOUBLE_EQ(Newest(*w, kAngle), Get(model, kAngle));
  EXPECT_DOUBLE_EQ(Newest(*w, kCurrent), Get(model, kCurrent));
  EXPECT_TRUE(std::isnan(Newest(*w, hinge))) << "a 3x1 position in this scene";
  // never a value of the other layout: every current held is a current (within its limit)
  for (const double a : Values(*w, kCurrent)) ASSERT_LE(std::abs(a), 3.5);
  EXPECT_TRUE(WaitInGui([&] { return !Stale(*w, kAngle) && Stale(*w, hinge); }, seconds(5)));

  w.reset();
  process->Signal(SIGTERM);
  EXPECT_EQ(process->Wait(seconds(10)), 0) << process->Output();
}

TEST_F(PlotterTest, ClosingWaitsOnlyBrieflyForAHungModel) {
  auto process = StartModel(Models() + "/pendulum_tendon.dae");
  M::Model_var model = WaitForModel();
  ASSERT_FALSE(CORBA::is_nil(model)) << process->Output();
  model->start();
  // long calls allowed, the next poll far away: closing finds the link between polls
  DaqLink::Options options = LinkOptions(naming_->address());
  options.call_timeout_ms = 4000;
  options.poll_period_ms = 10'000;
  auto link = std::make_unique<DaqLink>(options);
  link->Want({kAngle}, 1);
  ASSERT_TRUE(WaitInGui([&] { return !link->TakeBatches().empty(); }, seconds(10)))
      << process->Output();
  // the Model hangs; the link closes with one short unsubscribe call, not a whole call timeout
  process->Signal(SIGSTOP);
  QElapsedTimer closing;
  closing.start();
  link.reset();
  const qint64 ms = closing.elapsed();
  process->Signal(SIGCONT);
  EXPECT_LT(ms, 1500) << "closing blocked the GUI thread for " << ms << " ms";
  process->Signal(SIGTERM);
  EXPECT_EQ(process->Wait(seconds(10)), 0) << process->Output();
}

TEST_F(PlotterTest, KeepsTheBuffersWithinTheMemoryBudget) {
  auto w = Window(naming_->address());
  Layout layout;
  plotter::AddPlot(&layout, {kAngle, kCurrent});
  w->ApplyLayout(layout);
  auto* spin = w->findChild<QSpinBox*>("buffer_samples");
  EXPECT_EQ(static_cast<size_t>(spin->maximum()), plotter::MaxBufferSamples(2));
  // as many samples as a curve may have: two curves get what the budget leaves them
  w->SetBufferSamples(plotter::kMaxBuffer);
  EXPECT_EQ(w->store().capacity(), plotter::MaxBufferSamples(2));
  EXPECT_TRUE(w->statusBar()->currentMessage().contains("MiB all buffers may take"))
      << w->statusBar()->currentMessage().toStdString();
  // one more curve would take the buffers past the budget: refused, and said
  EXPECT_FALSE(w->AddCurve(0, kTension));
  EXPECT_FALSE(w->plot(0)->HasCurve(kTension));
  EXPECT_LT(w->store().Find(kTension), 0);
  EXPECT_TRUE(w->statusBar()->currentMessage().startsWith(
      "cannot add pendulum_tendon.motor.tension: 3 curves of 44739242 samples would need"))
      << w->statusBar()->currentMessage().toStdString();
  // a smaller buffer makes room
  w->SetBufferSamples(1'000'000);
  EXPECT_TRUE(w->AddCurve(0, kTension));
  EXPECT_EQ(static_cast<size_t>(spin->maximum()), plotter::MaxBufferSamples(3));
  // a layout that asks for more than its curves may have gets the most they may have
  Layout big = layout;
  big.buffer_samples = plotter::kMaxBuffer;
  plotter::AddPlot(&big, {kTension, kHeight});
  w->ApplyLayout(big);
  EXPECT_EQ(w->store().capacity(), plotter::MaxBufferSamples(4));
  EXPECT_EQ(static_cast<size_t>(spin->value()), plotter::MaxBufferSamples(4));
  EXPECT_TRUE(w->statusBar()->currentMessage().contains("the buffer keeps"))
      << w->statusBar()->currentMessage().toStdString();
}

TEST_F(PlotterTest, AnExportThatFailsLeavesTheOldFileAndSaysWhy) {
  auto w = Window(naming_->address());
  Layout layout;
  plotter::AddPlot(&layout, {kAngle, kCurrent});
  w->ApplyLayout(layout);
  for (const char* name : {"plot.png", "plot.svg", "plot.pdf", "data.csv"}) {
    const std::string path = dir_.path() + "/" + name;
    WriteText(path, "the user's old file\n");
    QString error;
    bool written = false;
    {
      // as on a full disk: writes fail after 8 bytes
      const FileSizeLimit limit(8);
      written = QString(name).endsWith(".csv")
                    ? w->ExportCsv(QString::fromStdString(path), &error)
                    : w->ExportPlot(QString::fromStdString(path), &error);
    }
    EXPECT_FALSE(written) << name;
    EXPECT_TRUE(error.startsWith(QString::fromStdString("cannot write " + path)))
        << name << ": " << error.toStdString();
    EXPECT_TRUE(error.contains("File too large")) << name << ": " << error.toStdString();
    EXPECT_EQ(ReadFile(path), "the user's old file\n") << name;
    EXPECT_EQ(ListFiles(dir_.path(), std::string(name) + ".").size(), 0u)
        << "no temporary file is left beside " << name;
    // and without the limit the export replaces it
    EXPECT_TRUE(QString(name).endsWith(".csv")
                    ? w->ExportCsv(QString::fromStdString(path), &error)
                    : w->ExportPlot(QString::fromStdString(path), &error))
        << error.toStdString();
    EXPECT_NE(ReadFile(path), "the user's old file\n") << name;
  }
}

// After pushes that timed out (a stalled plotter), the batches still unread in its sockets are
// taken in by several ORB threads at once: one older than a batch already taken is left out, not
// taken for a reset of the Model that would clear the curves.
TEST_F(PlotterTest, LeavesOutABatchThatComesAfterALaterOne) {
  auto process = StartModel(Models() + "/pendulum_tendon.dae");
  M::Model_var model = WaitForModel();
  ASSERT_FALSE(CORBA::is_nil(model)) << process->Output();
  model->step(200);
  auto link = std::make_unique<DaqLink>(LinkOptions(naming_->address()));
  link->Want({kAngle}, 1);
  ASSERT_TRUE(WaitInGui([&] { return link->status().subscription != 0; }, seconds(10)))
      << process->Output();
  model->step(100);  // batches 1, 2, ... of the subscription, then the Model waits
  ASSERT_TRUE(WaitInGui([&] { return model->status()->steps == 300; }, seconds(10)));
  const double end = model->status()->sim_time;
  std::vector<plotter::ReceivedBatch> taken;
  ASSERT_TRUE(WaitInGui(
      [&] {
        for (auto& b : link->TakeBatches()) taken.push_back(std::move(b));
        return !taken.empty() && taken.back().times.back() >= end - 1e-9;
      },
      seconds(10)))
      << process->Output();
  const uint64_t subscription = link->status().subscription;
  const uint64_t last = taken.back().number;
  ASSERT_GE(last, 2u);
  // after a stall: a newer batch read before an older one
  CORBA::Object_var ref = Orb()->string_to_object(link->ConsumerReference().c_str());
  D::DataConsumer_var consumer = D::DataConsumer::_narrow(ref);
  ASSERT_FALSE(CORBA::is_nil(consumer));
  const LinkStatus before = link->status();
  D::SampleBatch batch;
  batch.subscription = subscription;
  batch.layout = 1;
  batch.values_per_sample = 1;
  batch.times.length(1);
  batch.data.length(1);
  batch.batch = last + 2;  // the newer batch first
  batch.times[0] = end + 0.0015;
  batch.data[0] = 0.5;
  consumer->on_samples(batch);
  batch.batch = last + 1;  // then the one skipped
  batch.times[0] = end + 0.0005;
  batch.data[0] = 0.25;
  consumer->on_samples(batch);
  // a batch taken for a reset waits for the link's next poll (100 ms here) to check the layout
  Pump(milliseconds(1000));
  std::vector<plotter::ReceivedBatch> after = link->TakeBatches();
  ASSERT_EQ(after.size(), 1u) << "the late batch " << last + 1 << " was taken in";
  EXPECT_EQ(after[0].number, last + 2);
  const LinkStatus status = link->status();
  EXPECT_EQ(status.batches_late - before.batches_late, 1u);
  EXPECT_EQ(status.batches_missing - before.batches_missing, 1u) << "counted among the lost";
  EXPECT_EQ(status.subscription, subscription) << "no new subscription";
  link.reset();
  process->Signal(SIGTERM);
  EXPECT_EQ(process->Wait(seconds(10)), 0) << process->Output();
}

TEST(DataConsumerServantTest, LetsNoExceptionIntoTheOrb) {
  Orb();
  int calls = 0;
  plotter::DataConsumerServant servant([&](plotter::ReceivedBatch&& b) {
    ++calls;
    if (b.number == 1) throw 42;  // not a std::exception
    if (b.number == 2) throw std::runtime_error("the inbox is full");
  });
  D::SampleBatch batch;
  batch.subscription = 7;
  batch.values_per_sample = 1;
  batch.times.length(1);
  batch.times[0] = 0.001;
  batch.data.length(1);
  batch.data[0] = 1.5;
  for (CORBA::ULongLong n = 1; n <= 3; ++n) {
    batch.batch = n;
    EXPECT_NO_THROW(servant.on_samples(batch)) << "batch " << n;
  }
  EXPECT_EQ(calls, 3);
  EXPECT_EQ(servant.failures(), 2u);
}

}  // namespace
}  // namespace caliper::testing
