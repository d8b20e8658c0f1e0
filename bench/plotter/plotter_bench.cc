// Graph Plotter: what one frame costs when 10 curves stream at 1 kHz and the window shows 60 s
// (600,000 samples of a 1,000,000-sample buffer) on a plot whose canvas is 1000 px wide:
//   thin      Decimate() of the 10 series (min/max per pixel column);
//   frame     thinning plus Qwt replotting and repainting the plot widget, as a share of the
//             33.3 ms of a 30 Hz frame;
//   export    QwtPlotRenderer drawing the same plot into an image (what PNG export does);
//   raw       a frame with every sample handed to Qwt (what thinning saves);
// and the cost of taking samples in
// (SampleStore::Append with batches of 50 samples of 10 values, as the Model sends them at 1 kHz)
// as a share of one core, with the slowest batch while the buffer fills (a buffer that grew by
// copying its history would stall the GUI thread there). Medians of several repetitions. Options:
// --frames N (default 15). Runs on QT_QPA_PLATFORM=offscreen unless a platform is set.
#include <QApplication>
#include <QImage>
#include <QPainter>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <string>
#include <vector>

#include <qwt_plot_curve.h>
#include <qwt_plot_renderer.h>

#include "decimate.h"
#include "plot_view.h"
#include "sample_store.h"

namespace caliper::bench {
namespace {

using Clock = std::chrono::steady_clock;

constexpr int kCurves = 10;
constexpr double kRateHz = 1000;
constexpr double kWindowS = 60;
constexpr double kFrameBudgetMs = 1000.0 / 30;
constexpr size_t kBatch = 50;  // samples per DAQ batch at 1 kHz (the Model sends ~20 per second)

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

/// Milliseconds per call of `f`, the median of `repeats` calls.
double TimeMs(int repeats, const std::function<void()>& f) {
  std::vector<double> ms;
  for (int r = 0; r < repeats; ++r) {
    const auto t0 = Clock::now();
    f();
    ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
  }
  return Median(ms);
}

const char* Verdict(bool ok) { return ok ? "" : "  <- off target"; }

int Run(int frames) {
  // a signal with structure at every scale: slow swings, a fast ripple, sparse spikes
  auto signal = [](int curve, size_t i) {
    const double t = static_cast<double>(i) / kRateHz;
    double v = std::sin(0.5 * t + curve) + 0.1 * std::sin(37.0 * t * (curve + 1));
    if (i % 7919 == static_cast<size_t>(curve)) v += 3.0;
    return v;
  };

  // ingestion: 1,000,000 samples (1000 s at 1 kHz) appended batch by batch
  plotter::SampleStore store(1'000'000);
  std::vector<plotter::SampleStore::Column> columns;
  for (int c = 0; c < kCurves; ++c) {
    store.AddSeries("bench.curve" + std::to_string(c), "rad");
    columns.push_back({static_cast<size_t>(c), static_cast<size_t>(c)});
  }
  const size_t total = 1'000'000;
  std::vector<double> times(total), data(total * kCurves);
  for (size_t i = 0; i < total; ++i) {
    times[i] = static_cast<double>(i + 1) / kRateHz;
    for (int c = 0; c < kCurves; ++c) data[i * kCurves + c] = signal(c, i);
  }
  std::vector<double> batch_ms;
  for (size_t i = 0; i < total; i += kBatch) {
    const auto t0 = Clock::now();
    store.Append(&times[i], kBatch, &data[i * kCurves], kCurves, columns);
    batch_ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
  }
  // once the buffer is full every append overwrites the oldest: time that (the steady state)
  std::vector<double> full_ms;
  for (size_t i = 0; i < 200'000; i += kBatch) {
    for (size_t k = 0; k < kBatch; ++k)
      times[i + k] = static_cast<double>(total + i + k + 1) / kRateHz;
    const auto t0 = Clock::now();
    store.Append(&times[i], kBatch, &data[i * kCurves], kCurves, columns);
    full_ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
  }
  const double ns_per_sample_growing = 1e6 * Median(batch_ms) / kBatch;
  const double worst_growing_ms = *std::max_element(batch_ms.begin(), batch_ms.end());
  const double ns_per_sample = 1e6 * Median(full_ms) / kBatch;

  // the plot: 1000 px of canvas, 10 curves, the last 60 s
  plotter::PlotView view;
  for (int c = 0; c < kCurves; ++c)
    view.AddCurve(
        plotter::CurveSpec{"bench.curve" + std::to_string(c), plotter::CurveStyle::kLine, ""});
  view.resize(1000, 600);
  view.show();
  QApplication::processEvents();
  // widen the widget until its canvas is 1000 px (the axis and its labels take the rest)
  view.resize(1000 + (1000 - view.canvas()->contentsRect().width()), 600);
  QApplication::processEvents();
  const int canvas_px = view.canvas()->contentsRect().width();
  const double t1 = store.last_time();
  const double t0 = t1 - kWindowS;
  const auto [first, last] = store.IndexRange(t0, t1);
  const size_t drawn = (last - first) * kCurves;

  std::printf(
      "# plotter: %d curves x %.0f s x %.0f Hz = %zu samples drawn from a buffer of %zu "
      "per curve; canvas %d px; %d frames\n",
      kCurves, kWindowS, kRateHz, drawn, store.size(), canvas_px, frames);

  std::vector<plotter::DrawPoints> points(kCurves);
  size_t thinned = 0;
  const double thin_ms = TimeMs(frames, [&] {
    thinned = 0;
    for (int c = 0; c < kCurves; ++c) {
      plotter::Decimate(store, static_cast<size_t>(c), t0, t1, canvas_px, &points[c]);
      thinned += points[c].t.size();
    }
  });
  std::printf(
      "plotter_thin_ms[%dx%.0fs@%.0fHz,%dpx] %.2f (%zu points kept of %zu, %.2f per px "
      "per curve)\n",
      kCurves, kWindowS, kRateHz, canvas_px, thin_ms, thinned, drawn,
      static_cast<double>(thinned) / kCurves / canvas_px);

  // a live frame: thin, then Qwt replots and repaints the plot widget
  auto frame = [&] {
    view.Draw(store, t0, t1, true);
    view.replot();
    view.canvas()->repaint();
  };
  const double frame_ms = TimeMs(frames, frame);
  std::printf("plotter_frame_ms[%dx%.0fs@%.0fHz,%dpx] %.2f (thin + replot and repaint)\n", kCurves,
              kWindowS, kRateHz, canvas_px, frame_ms);
  std::printf("RATIO plotter_frame_share_of_30hz[%dx%.0fs@%.0fHz,%dpx] %.3f (target < 0.50)%s\n",
              kCurves, kWindowS, kRateHz, canvas_px, frame_ms / kFrameBudgetMs,
              Verdict(frame_ms / kFrameBudgetMs < 0.5));

  // an export: QwtPlotRenderer (as PNG export does) into an image of the widget's size
  QImage image(view.size(), QImage::Format_ARGB32);
  QwtPlotRenderer renderer;
  const double export_ms = TimeMs(frames, [&] {
    image.fill(Qt::white);
    QPainter painter(&image);
    renderer.render(&view, &painter, QRectF(QPointF(0, 0), QSizeF(view.size())));
  });
  std::printf("plotter_export_render_ms[%dx%d] %.2f (QwtPlotRenderer of the thinned curves)\n",
              image.width(), image.height(), export_ms);

  // every sample of the window handed to Qwt: what a frame would cost without thinning
  std::vector<std::vector<double>> xs(kCurves), ys(kCurves);
  for (int c = 0; c < kCurves; ++c) {
    store.ForEach(static_cast<size_t>(c), first, last, [&](double t, double v) {
      xs[c].push_back(t);
      ys[c].push_back(v);
    });
  }
  const double raw_ms = TimeMs(std::max(3, frames / 5), [&] {
    for (int c = 0; c < kCurves; ++c)
      view.curve("bench.curve" + std::to_string(c))
          ->setRawSamples(xs[c].data(), ys[c].data(), static_cast<int>(xs[c].size()));
    view.replot();
    view.canvas()->repaint();
  });
  std::printf("plotter_raw_frame_ms %.2f (every one of the %zu samples drawn)\n", raw_ms, drawn);
  std::printf("RATIO plotter_thinned_vs_raw_frame %.3f (thinned frame time / raw frame time)\n",
              frame_ms / raw_ms);

  std::printf(
      "plotter_ingest_ns_per_sample[%d values] %.1f while the buffer fills, %.1f when "
      "full (%.2f ns per value)\n",
      kCurves, ns_per_sample_growing, ns_per_sample, ns_per_sample / kCurves);
  std::printf(
      "plotter_ingest_worst_batch_ms[%d values] %.3f while the buffer fills (median %.3f; "
      "%.3f of a 30 Hz frame)\n",
      kCurves, worst_growing_ms, Median(batch_ms), worst_growing_ms / kFrameBudgetMs);
  const double share = std::max(ns_per_sample, ns_per_sample_growing) * kRateHz * 1e-9;
  std::printf("RATIO plotter_ingest_share_of_core[%d curves@%.0fHz] %.5f (target < 0.01)%s\n",
              kCurves, kRateHz, share, Verdict(share < 0.01));
  return 0;
}

}  // namespace
}  // namespace caliper::bench

int main(int argc, char** argv) {
  int frames = 15;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--frames") == 0 && i + 1 < argc) {
      frames = std::max(3, std::atoi(argv[++i]));
    } else {
      std::fprintf(stderr, "usage: plotter_bench [--frames N]\n");
      return 2;
    }
  }
  if (std::getenv("QT_QPA_PLATFORM") == nullptr) qputenv("QT_QPA_PLATFORM", "offscreen");
  QApplication app(argc, argv);
  return caliper::bench::Run(frames);
}
