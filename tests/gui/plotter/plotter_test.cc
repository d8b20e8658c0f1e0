// The Graph Plotter in the test process against a real caliper-model (pendulum_tendon.dae):
// the search box filters the channel list, ids go into two stacked plots, the curves fill while
// the simulation runs, pause freezes the view (recording goes on) and resume follows again, clear
// empties, exports (CSV with units and every sample, SVG, PDF, PNG) are well formed; a Model that
// is killed and started again is subscribed to again, a reload without an id marks its curve
// stale (and a reload with it brings it back). The real program is run for --help, bad options
// and the session file. Widgets run on QT_QPA_PLATFORM=offscreen.
#include <gtest/gtest.h>
#include <signal.h>

#include <QApplication>
#include <QComboBox>
#include <QElapsedTimer>
#include <QFile>
#include <QImage>
#include <QLabel>
#include <QLineEdit>
#include <QMouseEvent>
#include <QPrinter>
#include <QPushButton>
#include <QSettings>
#include <QSvgRenderer>
#include <QTest>
#include <QToolBar>
#include <QTreeWidget>
#include <QXmlStreamReader>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <thread>

#include <qwt_plot_curve.h>
#include <qwt_symbol.h>

#include "caliper/model.hh"
#include "caliper/rtc/naming.h"
#include "daq_link.h"
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
using plotter::DaqLink;
using plotter::Layout;
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

/// The channel row (or element row) whose key is `key`, or nullptr.
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

/// Clicks the tool bar button of an action.
void ClickAction(PlotterWindow& w, const char* name) {
  auto* action = w.findChild<QAction*>(name);
  ASSERT_NE(action, nullptr) << name;
  QWidget* button = w.findChild<QToolBar*>("toolbar")->widgetForAction(action);
  ASSERT_NE(button, nullptr) << name;
  QTest::mouseClick(button, Qt::LeftButton);
}

/// Drags with the left button from `from` to `to` (Qt 5's QTest::mouseMove only moves the cursor,
/// which sends no event on the offscreen platform: the moves are sent here).
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

/// The newest value of a series held (NaN when none).
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

class PlotterTest : public ::testing::Test {
 protected:
  void SetUp() override {
    App();
    Orb();
    naming_ = std::make_unique<NamingService>(dir_.path());
  }

  std::unique_ptr<Process> StartModel(const std::string& scene) {
    return std::make_unique<Process>(
        std::vector<std::string>{Bin("caliper-model"), "-o", "model.scene=" + scene, "-o",
                                 "exec.auto_activate=true", "--nameservice", naming_->address(),
                                 "-o", "log.service=none", "-o",
                                 "log.spool_dir=" + dir_.path() + "/spool"},
        dir_.path() + "/model" + std::to_string(++models_) + ".out");
  }

  /// The Model bound as model0 that answers.
  M::Model_var WaitForModel() {
    M::Model_var model;
    WaitFor(
        [&] {
          try {
            CosNaming::NamingContext_var root = rtc::ResolveRoot(Orb(), naming_->address());
            model = M::Model::_narrow(rtc::FindComponent(root, "model0").object);
            return !CORBA::is_nil(model) && !model->_non_existent();
          } catch (...) {
            return false;
          }
        },
        seconds(20));
    return model;
  }

  std::unique_ptr<PlotterWindow> Window(const std::string& nameservice) {
    DaqLink::Options options;
    options.nameservice = nameservice;
    options.reconnect_period_ms = 300;
    options.poll_period_ms = 100;
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

TEST_F(PlotterTest, PicksIdsStreamsPausesClearsAndExports) {
  auto process = StartModel(Models() + "/pendulum_tendon.dae");
  M::Model_var model = WaitForModel();
  ASSERT_FALSE(CORBA::is_nil(model)) << process->Output();
  auto w = Window(naming_->address());
  ASSERT_TRUE(WaitInGui([&] { return ChannelItem(*w, kAngle) != nullptr; }, seconds(10)))
      << "the channel list is filled from the Model";

  // the search box: text matches anywhere (any case), a glob matches the whole id
  auto* search = w->findChild<QLineEdit*>("search");
  const int all = VisibleChannels(*w).size();
  QTest::keyClicks(search, "MOTOR.C");
  QStringList shown = VisibleChannels(*w);
  EXPECT_GE(shown.size(), 2) << shown.join(" ").toStdString();
  EXPECT_LT(shown.size(), all);
  for (const QString& id : shown) EXPECT_TRUE(id.contains("motor.c")) << id.toStdString();
  EXPECT_TRUE(shown.contains(kCurrent));
  EXPECT_TRUE(ChannelItem(*w, kAngle)->isHidden());
  search->clear();
  QTest::keyClicks(search, "*.pivot.?osition");
  shown = VisibleChannels(*w);
  EXPECT_EQ(shown, QStringList{kAngle}) << shown.join(" ").toStdString();
  search->clear();
  QTest::keyClicks(search, "*.pivot.*");
  shown = VisibleChannels(*w);
  EXPECT_GE(shown.size(), 2) << "position and velocity at least";
  for (const QString& id : shown)
    EXPECT_TRUE(id.startsWith("pendulum_tendon.pivot.")) << id.toStdString();
  EXPECT_EQ(ChannelItem(*w, kAngle)->text(1), "rad") << "units are shown";
  search->clear();
  EXPECT_EQ(VisibleChannels(*w).size(), all);

  // two ids into plot 1, one into a new plot 2, then a vector element into plot 2
  auto* channels = w->findChild<QTreeWidget*>("channels");
  auto* target = w->findChild<QComboBox*>("target_plot");
  auto* add = w->findChild<QPushButton*>("add");
  channels->clearSelection();
  ChannelItem(*w, kAngle)->setSelected(true);
  ChannelItem(*w, kCurrent)->setSelected(true);
  target->setCurrentIndex(0);
  QTest::mouseClick(add, Qt::LeftButton);
  ASSERT_EQ(w->plot_count(), 1);
  EXPECT_TRUE(w->plot(0)->HasCurve(kAngle));
  EXPECT_TRUE(w->plot(0)->HasCurve(kCurrent));
  channels->clearSelection();
  ChannelItem(*w, kTension)->setSelected(true);
  target->setCurrentIndex(target->count() - 1);
  EXPECT_EQ(target->currentText(), "New plot");
  QTest::mouseClick(add, Qt::LeftButton);
  ASSERT_EQ(w->plot_count(), 2);
  EXPECT_TRUE(w->plot(1)->HasCurve(kTension));
  EXPECT_EQ(target->currentIndex(), 1) << "the new plot becomes the target";
  channels->clearSelection();
  ASSERT_NE(ChannelItem(*w, kHeight), nullptr) << "vector ids offer their elements";
  ChannelItem(*w, kHeight)->setSelected(true);
  QTest::mouseClick(add, Qt::LeftButton);
  EXPECT_TRUE(w->plot(1)->HasCurve(kHeight));
  EXPECT_EQ(w->plot(0)->legend_titles(), (QStringList{"pendulum_tendon.pivot.position [rad]",
                                                      "pendulum_tendon.motor.current [A]"}));

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

  // pause: the view stops (the buffer keeps filling); resume: it follows again
  ClickAction(*w, "pause");
  EXPECT_TRUE(w->paused());
  const double frozen = w->plot(0)->last_drawn_time(kAngle);
  const size_t frozen_points = w->plot(0)->points(kAngle);
  const size_t held = w->store().size();
  Pump(milliseconds(700));
  EXPECT_EQ(w->plot(0)->last_drawn_time(kAngle), frozen);
  EXPECT_EQ(w->plot(0)->points(kAngle), frozen_points);
  EXPECT_GT(w->store().size(), held + 200) << "samples are still recorded while paused";
  EXPECT_TRUE(w->findChild<QLabel*>("rate")->text().contains("paused"));
  ClickAction(*w, "pause");
  EXPECT_FALSE(w->paused());
  EXPECT_TRUE(
      WaitInGui([&] { return w->plot(0)->last_drawn_time(kAngle) > frozen + 0.5; }, seconds(5)));

  // clear while streaming: empty at once, then only newer samples
  const double cleared_at = w->store().last_time();
  ClickAction(*w, "clear");
  EXPECT_TRUE(w->store().empty());
  EXPECT_EQ(w->plot(0)->points(kAngle), 0u);
  ASSERT_TRUE(WaitInGui([&] { return w->store().size() > 1500; }, seconds(10)));
  EXPECT_GT(w->store().first_time(), cleared_at);

  // the screenshot
  SetCommand(model, 12.0);
  Pump(milliseconds(400));
  SetCommand(model, 0.0);
  Pump(milliseconds(600));
  const std::string png = ArtifactPath("plotter.png", dir_.path());
  EXPECT_TRUE(w->grab().save(QString::fromStdString(png))) << png;

  // CSV: the header with units, one row per sample held, every simulation step present
  const QString csv = QString::fromStdString(dir_.path() + "/data.csv");
  QString error;
  ClickAction(*w, "pause");  // the view only; the samples held now are what gets written
  const size_t rows = w->store().size();
  ASSERT_TRUE(w->ExportCsv(csv, &error)) << error.toStdString();
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
  EXPECT_EQ(w->link().status().batches_missing, 0u);
  ClickAction(*w, "pause");

  // the plot as SVG (valid XML with an <svg> root), PDF and PNG
  const QString svg = QString::fromStdString(dir_.path() + "/plot.svg");
  ASSERT_TRUE(w->ExportPlot(svg, &error)) << error.toStdString();
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
  const QString pdf = QString::fromStdString(dir_.path() + "/plot.pdf");
  ASSERT_TRUE(w->ExportPlot(pdf, &error)) << error.toStdString();
  const std::string pdf_bytes = ReadFile(pdf.toStdString());
  EXPECT_GT(pdf_bytes.size(), 1000u);
  EXPECT_EQ(pdf_bytes.rfind("%PDF", 0), 0u);
  const QString exported_png = QString::fromStdString(dir_.path() + "/plot.png");
  ASSERT_TRUE(w->ExportPlot(exported_png, &error)) << error.toStdString();
  const QImage image(exported_png);
  ASSERT_FALSE(image.isNull());
  int coloured = 0;  // pixels of the curves' colours (not grey, not white)
  for (int y = 0; y < image.height(); y += 2)
    for (int x = 0; x < image.width(); x += 2) {
      const QColor c = image.pixelColor(x, y);
      coloured += c.saturation() > 100 ? 1 : 0;
    }
  EXPECT_GT(coloured, 200) << "the curves are drawn";
  EXPECT_FALSE(w->ExportPlot(QString::fromStdString(dir_.path() + "/plot.bmp"), &error));
  EXPECT_TRUE(error.contains("use .png, .svg or .pdf")) << error.toStdString();
  EXPECT_FALSE(w->ExportCsv("/nonexistent/dir/data.csv", &error));
  EXPECT_TRUE(error.startsWith("cannot write /nonexistent/dir/data.csv")) << error.toStdString();

  // printing: to a PDF printer
  const QString printed = QString::fromStdString(dir_.path() + "/printed.pdf");
  {
    QPrinter printer(QPrinter::HighResolution);
    printer.setOutputFormat(QPrinter::PdfFormat);
    printer.setOutputFileName(printed);
    w->Print(&printer);
  }
  const std::string printed_bytes = ReadFile(printed.toStdString());
  EXPECT_GT(printed_bytes.size(), 1000u);
  EXPECT_EQ(printed_bytes.rfind("%PDF", 0), 0u);

  // zoom: dragging a rectangle on plot 1 pauses the view and gives both plots its time range
  ASSERT_FALSE(w->paused());
  QWidget* canvas = w->plot(0)->canvas();
  const QRect area = canvas->contentsRect();
  const QwtInterval live = w->plot(0)->axisInterval(QwtPlot::xBottom);
  const QPoint from(area.left() + area.width() / 4, area.top() + 10);
  const QPoint to(area.left() + area.width() / 2, area.bottom() - 10);
  Drag(canvas, from, to, Qt::NoModifier);
  EXPECT_TRUE(w->paused());
  const QwtInterval zoomed = w->plot(0)->axisInterval(QwtPlot::xBottom);
  EXPECT_NEAR(zoomed.width(), live.width() / 4, live.width() / 20);
  EXPECT_NEAR(zoomed.minValue(), live.minValue() + live.width() / 4, live.width() / 20);
  EXPECT_EQ(w->plot(1)->axisInterval(QwtPlot::xBottom), zoomed) << "one time axis for all plots";
  EXPECT_GT(w->plot(1)->points(kTension), 0u);
  EXPECT_LE(w->plot(1)->last_drawn_time(kTension), zoomed.maxValue() + 0.01)
      << "plot 2 is drawn anew for the zoomed range";
  // pan: Shift + drag to the right shows earlier times, in both plots
  const QPoint grab(area.center());
  const QPoint drop(grab.x() + area.width() / 5, grab.y());
  Drag(canvas, grab, drop, Qt::ShiftModifier);
  const QwtInterval panned = w->plot(0)->axisInterval(QwtPlot::xBottom);
  EXPECT_NEAR(panned.minValue(), zoomed.minValue() - zoomed.width() / 5, zoomed.width() / 20);
  EXPECT_NEAR(panned.width(), zoomed.width(), 1e-9);
  EXPECT_EQ(w->plot(1)->axisInterval(QwtPlot::xBottom), panned);
  EXPECT_TRUE(w->paused());
  // autoscale fits the value axis of the zoomed plot to its data again
  ClickAction(*w, "autoscale");
  double lo = 1e300, hi = -1e300;
  const auto [in_first, in_last] = w->store().IndexRange(panned.minValue(), panned.maxValue());
  for (const char* key : {kAngle, kCurrent})
    w->store().ForEach(static_cast<size_t>(w->store().Find(key)), in_first, in_last,
                       [&](double, double v) {
                         lo = std::min(lo, v);
                         hi = std::max(hi, v);
                       });
  ASSERT_LT(lo, hi);
  const QwtInterval y = w->plot(0)->axisInterval(QwtPlot::yLeft);
  EXPECT_LE(y.minValue(), lo);
  EXPECT_GE(y.maxValue(), hi);
  EXPECT_LT(y.width(), 1.2 * (hi - lo)) << "fitted: " << lo << " .. " << hi;
  // resume: the live window again
  ClickAction(*w, "pause");
  EXPECT_FALSE(w->paused());
  EXPECT_NEAR(w->plot(0)->axisInterval(QwtPlot::xBottom).width(), 10.0, 1e-9);

  // a curve drawn as scatter, another removed (its samples go with it)
  auto* curves = w->findChild<QTreeWidget*>("curves");
  auto* style = w->findChild<QComboBox*>("style");
  QTreeWidgetItem* current_row = curves->topLevelItem(0)->child(1);
  ASSERT_EQ(current_row->text(0), kCurrent);
  curves->setCurrentItem(current_row);
  EXPECT_TRUE(style->isEnabled());
  style->setCurrentIndex(1);
  emit style->activated(1);
  EXPECT_EQ(w->plot(0)->spec().curves[1].style, plotter::CurveStyle::kScatter);
  EXPECT_EQ(w->plot(0)->curve(kCurrent)->style(), QwtPlotCurve::NoCurve);
  ASSERT_NE(w->plot(0)->curve(kCurrent)->symbol(), nullptr);
  curves->setCurrentItem(curves->topLevelItem(1)->child(1));
  ASSERT_EQ(curves->currentItem()->text(0), kHeight);
  QTest::mouseClick(w->findChild<QPushButton*>("remove"), Qt::LeftButton);
  EXPECT_FALSE(w->plot(1)->HasCurve(kHeight));
  EXPECT_LT(w->store().Find(kHeight), 0);
  EXPECT_EQ(curves->topLevelItem(1)->childCount(), 1);

  // the layout round trip through the window
  const Layout layout = w->CurrentLayout();
  ASSERT_EQ(layout.plots.size(), 2u);
  EXPECT_EQ(layout.Keys(), (std::vector<std::string>{kAngle, kCurrent, kTension}));
  w->ApplyLayout(layout);
  EXPECT_EQ(w->CurrentLayout(), layout);

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

  // --ids and --geometry go into the session file when the plotter ends on SIGTERM
  const std::string session = dir_.path() + "/session.ini";
  {
    Process p({Bin("caliper-plotter"), "--nameservice", naming_->address(), "--session", session,
               "--geometry", "640x480+30+40", "--ids", "a.b, c.d[1]", "--ids", "e"},
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
  QElapsedTimer t;
  t.start();
  qint64 longest = 0;
  while (t.elapsed() < 2000) {
    QElapsedTimer one;
    one.start();
    QApplication::processEvents(QEventLoop::AllEvents, 20);
    longest = std::max(longest, one.elapsed());
    QTest::qWait(20);
  }
  EXPECT_LT(longest, 300) << "the GUI thread was blocked for " << longest << " ms";
  EXPECT_FALSE(Stale(*w, kAngle)) << "not stale: no Model said it lacks the id";
  QElapsedTimer closing;
  closing.start();
  w.reset();
  EXPECT_LT(closing.elapsed(), 3000) << "closing does not hang";
}

}  // namespace
}  // namespace caliper::testing
