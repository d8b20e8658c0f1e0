// A PlotView in a small tile: the value axis gets only as many major ticks as its labels fit in
// its height (Qwt's default of 8 steps stacked "300 280 260 ..." on top of each other), and a tall
// plot keeps the finer division. Widgets run on QT_QPA_PLATFORM=offscreen.
#include "plot_view.h"

#include <gtest/gtest.h>
#include <qwt_scale_div.h>
#include <qwt_scale_widget.h>

#include <QApplication>
#include <QFontMetrics>
#include <QImage>

#include "support/gui_test.h"

namespace caliper::testing {
namespace {

using plotter::PlotView;

// the major ticks of the value axis after laying the plot out at `height_px`
struct YAxis {
  int ticks = 0;
  int line_px = 0;    // the height of one label line [px]
  int canvas_px = 0;  // the canvas height the labels are spread over [px]
};

YAxis LayOut(PlotView* plot, int height_px) {
  plot->resize(400, height_px);
  plot->show();
  App().processEvents();
  plot->setAxisScale(QwtPlot::yLeft, 125, 305);
  plot->replot();
  App().processEvents();
  YAxis y;
  y.ticks = plot->axisScaleDiv(QwtPlot::yLeft).ticks(QwtScaleDiv::MajorTick).size();
  y.line_px = QFontMetrics(plot->axisWidget(QwtPlot::yLeft)->font()).height();
  y.canvas_px = plot->canvas()->height();
  return y;
}

TEST(PlotViewTest, ASmallTileGetsNoMoreValueLabelsThanFitItsHeight) {
  App();
  PlotView plot;
  plot.AddCurve(plotter::CurveSpec{"arm.elbow.tendon.tension"});
  const YAxis small = LayOut(&plot, 130);
  ASSERT_GT(small.canvas_px, 0);
  EXPECT_GE(small.ticks, 2) << "a value axis needs at least two labels";
  EXPECT_LE(small.ticks * small.line_px, small.canvas_px)
      << small.ticks << " labels of " << small.line_px << " px on a " << small.canvas_px
      << " px canvas overlap";
  // the grab is kept to look at
  plot.grab().save(QString::fromStdString(ArtifactPath("plot_view_small_tile.png", "/tmp")));

  const YAxis tall = LayOut(&plot, 600);
  EXPECT_GT(tall.ticks, small.ticks) << "a tall plot keeps a finer division";
  EXPECT_LE(tall.ticks * tall.line_px, tall.canvas_px);
}

}  // namespace
}  // namespace caliper::testing
