// The report's pictures with Qwt, rendered offscreen: the PNG file and the page's embedded PNGs.
#include <qwt_color_map.h>
#include <qwt_legend.h>
#include <qwt_matrix_raster_data.h>
#include <qwt_plot.h>
#include <qwt_plot_curve.h>
#include <qwt_plot_grid.h>
#include <qwt_plot_layout.h>
#include <qwt_plot_renderer.h>
#include <qwt_plot_spectrogram.h>
#include <qwt_scale_div.h>
#include <qwt_scale_engine.h>
#include <qwt_scale_widget.h>
#include <sys/stat.h>
#include <unistd.h>

#include <QApplication>
#include <QBuffer>
#include <QByteArray>
#include <QImage>
#include <QPainter>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <string>

#include "report.h"
#include "report_html.h"

namespace caliper::calibration {

namespace {

// the page's pictures, in pixels
constexpr int kPageWidth = 900;
constexpr int kPageHeightPerPlot = 300;
constexpr int kCorrelationWidth = 620;
constexpr int kCorrelationHeight = 540;

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

// `plots` stacked, each width x height_per_plot pixels
QImage RenderPlots(const std::vector<Plot>& plots, int width, int height_per_plot) {
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
      curve->setLegendAttribute(QwtPlotCurve::LegendShowLine);
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
  return image;
}

// -1 blue, 0 white, +1 red
QwtLinearColorMap* DivergingColourMap() {
  auto* map = new QwtLinearColorMap(QColor(33, 102, 172), QColor(178, 24, 43));
  map->addColorStop(0.5, Qt::white);
  return map;
}

// cells centred on 1..n, row 1 at the top; the ticks thinned to about 15
QwtScaleDiv IndexScale(int n, bool top_down) {
  const int step = (n + 14) / 15;
  QList<double> ticks[QwtScaleDiv::NTickTypes];
  for (int i = 1; i <= n; i += step) ticks[QwtScaleDiv::MajorTick].append(i);
  return top_down ? QwtScaleDiv(n + 0.5, 0.5, ticks) : QwtScaleDiv(0.5, n + 0.5, ticks);
}

// the matrix as coloured cells with a colour bar; NaN cells left transparent over a grey canvas
QImage RenderCorrelation(const std::vector<std::vector<double>>& matrix, int width, int height) {
  EnsureApplication();
  const int n = static_cast<int>(matrix.size());
  QVector<double> values;
  values.reserve(n * n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      values.append(static_cast<size_t>(j) < matrix[i].size() ? matrix[i][j] : std::nan(""));
  auto* data = new QwtMatrixRasterData;
  data->setValueMatrix(values, n);
  data->setInterval(Qt::XAxis, QwtInterval(0.5, n + 0.5));
  data->setInterval(Qt::YAxis, QwtInterval(0.5, n + 0.5));
  data->setInterval(Qt::ZAxis, QwtInterval(-1.0, 1.0));
  data->setResampleMode(QwtMatrixRasterData::NearestNeighbour);

  QwtPlot plot;
  plot.setTitle("correlation of the parameters (grey: not determined)");
  plot.setCanvasBackground(QColor(190, 190, 190));
  plot.plotLayout()->setAlignCanvasToScales(true);
  auto* spectrogram = new QwtPlotSpectrogram;
  spectrogram->setRenderThreadCount(1);
  spectrogram->setColorMap(DivergingColourMap());
  spectrogram->setData(data);
  spectrogram->attach(&plot);
  plot.setAxisTitle(QwtPlot::xBottom, "parameter #");
  plot.setAxisTitle(QwtPlot::yLeft, "parameter #");
  plot.setAxisScaleDiv(QwtPlot::xBottom, IndexScale(n, false));
  plot.setAxisScaleDiv(QwtPlot::yLeft, IndexScale(n, true));
  QwtScaleWidget* bar = plot.axisWidget(QwtPlot::yRight);
  bar->setTitle("correlation");
  bar->setColorBarEnabled(true);
  bar->setColorBarWidth(18);
  bar->setColorMap(QwtInterval(-1.0, 1.0), DivergingColourMap());
  plot.enableAxis(QwtPlot::yRight);
  plot.setAxisScale(QwtPlot::yRight, -1.0, 1.0, 0.5);
  plot.replot();

  QImage image(width, height, QImage::Format_RGB32);
  image.fill(Qt::white);
  QPainter painter(&image);
  QwtPlotRenderer renderer;
  renderer.render(&plot, &painter, QRectF(0, 0, width, height));
  painter.end();
  return image;
}

// the PNG as base64 text, "" when it cannot be encoded
std::string PngBase64(const QImage& image) {
  QByteArray png;
  QBuffer buffer(&png);
  if (image.isNull() || !buffer.open(QIODevice::WriteOnly) || !image.save(&buffer, "PNG"))
    return "";
  return png.toBase64().toStdString();
}

}  // namespace

std::string WritePng(const std::string& path, const std::vector<Plot>& plots, int width,
                     int height_per_plot) {
  const QImage image = RenderPlots(plots, width, height_per_plot);
  // written beside and renamed: whole or nothing
  const QString temporary = QString::fromStdString(path + ".tmp.png");
  if (!image.save(temporary, "PNG")) return "cannot write " + path;
  if (std::rename(temporary.toStdString().c_str(), path.c_str()) != 0)
    return "cannot write " + path;
  return "";
}

std::string WriteHtml(const std::string& path, const HtmlReport& report) {
  PagePictures pictures;
  pictures.plots = [](const std::vector<Plot>& plots) {
    return PngBase64(RenderPlots(plots, kPageWidth, kPageHeightPerPlot));
  };
  pictures.correlation = [](const std::vector<std::vector<double>>& matrix) {
    return PngBase64(RenderCorrelation(matrix, kCorrelationWidth, kCorrelationHeight));
  };
  return WriteHtmlPage(path, report, pictures);
}

}  // namespace caliper::calibration
