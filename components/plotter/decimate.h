#pragma once
// Thinning a series for drawing: a plot `columns` pixels wide cannot show more than a few points
// per pixel column, so each column keeps the smallest and the largest value that fall into it (in
// the order they were taken). Spikes survive, lines look the same, and the cost of drawing depends
// on the plot's width, not on the sample rate. Only drawing is thinned: the store keeps every
// sample. No Qt.

#include <cstddef>
#include <vector>

#include "sample_store.h"

namespace caliper::plotter {

/// Points to draw, as parallel arrays (what QwtPlotCurve::setRawSamples takes).
struct DrawPoints {
  std::vector<double> t;  ///< [s]
  std::vector<double> v;  ///< in the series' unit
  /// Smallest and largest value among the points inside the interval (NaN when none).
  double v_min = 0;
  double v_max = 0;
  /// Samples of the interval that were looked at (before thinning).
  size_t samples = 0;
  void clear() {
    t.clear();
    v.clear();
    samples = 0;
  }
};

/// Fills `out` with the points of series `series` over [t0, t1] [s] for a plot `columns` pixels
/// wide. With at most 2 samples per column every sample is kept; otherwise each column keeps its
/// minimum and maximum (at most 2 * columns points). One sample on each side just outside the
/// interval is added so that lines reach the plot's edges. NaN values (no data, stale) are
/// skipped. `columns` below 1 counts as 1.
void Decimate(const SampleStore& store, size_t series, double t0, double t1, int columns,
              DrawPoints* out);

}  // namespace caliper::plotter
