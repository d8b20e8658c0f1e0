// The report's PNGs with Qwt, rendered offscreen.
#include <qwt_legend.h>
#include <qwt_plot.h>
#include <qwt_plot_curve.h>
#include <qwt_plot_grid.h>
#include <qwt_plot_renderer.h>
#include <qwt_scale_engine.h>

#include <QApplication>
#include <QImage>
#include <QPainter>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdlib>
#include <string>
#include <memory>

#include "report.h"

namespace caliper::calibration {

namespace {

void EnsureApplication() {
  if (QApplication::instance() != nullptr) return;
  // pictures only: no display needed (and no session: a private runtime directory if none)
  setenv("QT_QPA_PLATFORM", "offscreen", 1);
  if (std::getenv("XDG_RUNTIME_DIR") == nullptr) {
    const std::string runtime = "/tmp/caliper-runtime-" + std::to_string(getuid());
    mkdir(runtime.c_str(), 0700);
    struct stat info {};
    // only a directory of our own (another user may have made the name first)
    if (lstat(runtime.c_str(), &info) == 0 && S_ISDIR(info.st_mode) && info.st_uid == getuid())
      setenv("XDG_RUNTIME_DIR", runtime.c_str(), 1);
  }
  static int argc = 1;
  static char name[] = "caliper-calibrate";
  static char* argv[] = {name, nullptr};
  static QApplication* app = new QApplication(argc, argv);  // lives to the end (Qwt)
  (void)app;
}

}  // namespace

std::string WritePng(const std::string& path, const std::vector<Plot>& plots, int width,
                     int height_per_plot) {
  EnsureApplication();
  static const QColor kColors[] = {Qt::black, QColor(200, 40, 40), QColor(30, 100, 220),
                                   QColor(20, 150, 60), QColor(200, 120, 0)};
  QImage image(width, height_per_plot * static_cast<int>(plots.size()), QImage::Format_RGB32);
  image.fill(Qt::white);
  QPainter painter(&image);
  for (size_t i = 0; i < plots.size(); ++i) {
    const Plot& p = plots[i];
    QwtPlot plot;
    plot.setCanvasBackground(Qt::white);
    plot.setTitle(QString::fromStdString(p.title));
    plot.setAxisTitle(QwtPlot::xBottom, QString::fromStdString(p.x_title));
    plot.setAxisTitle(QwtPlot::yLeft, QString::fromStdString(p.y_title));
    if (p.log_y) plot.setAxisScaleEngine(QwtPlot::yLeft, new QwtLogScaleEngine);
    plot.insertLegend(new QwtLegend, QwtPlot::RightLegend);
    auto* grid = new QwtPlotGrid;
    grid->setPen(QColor(220, 220, 220));
    grid->attach(&plot);
    for (size_t c = 0; c < p.curves.size(); ++c) {
      auto* curve = new QwtPlotCurve(QString::fromStdString(p.curves[c].name));
      QPen pen(kColors[c % 5], c == 0 ? 2.0 : 1.5);
      if (c == 1) pen.setStyle(Qt::DashLine);
      curve->setPen(pen);
      curve->setRenderHint(QwtPlotItem::RenderAntialiased);
      curve->setSamples(p.curves[c].x.data(), p.curves[c].y.data(),
                        static_cast<int>(p.curves[c].x.size()));
      curve->attach(&plot);
    }
    plot.replot();
    QwtPlotRenderer renderer;
    renderer.render(&plot, &painter,
                    QRectF(0, static_cast<double>(i) * height_per_plot, width, height_per_plot));
  }
  painter.end();
  // written beside and renamed: whole or nothing
  const QString temporary = QString::fromStdString(path + ".tmp.png");
  if (!image.save(temporary, "PNG")) return "cannot write " + path;
  if (std::rename(temporary.toStdString().c_str(), path.c_str()) != 0)
    return "cannot write " + path;
  return "";
}

}  // namespace caliper::calibration
