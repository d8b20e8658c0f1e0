#include "decimate.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace caliper::plotter {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// the nearest sample with a value before `first` (searching back at most `limit` samples)
bool ValueBefore(const SampleStore& store, size_t series, size_t first, size_t limit, double* t,
                 double* v) {
  for (size_t k = 0; k < limit && first > k; ++k) {
    const size_t i = first - 1 - k;
    const double value = store.value(series, i);
    if (!std::isnan(value)) {
      *t = store.time(i);
      *v = value;
      return true;
    }
  }
  return false;
}

bool ValueFrom(const SampleStore& store, size_t series, size_t from, size_t limit, double* t,
               double* v) {
  for (size_t i = from; i < store.size() && i < from + limit; ++i) {
    const double value = store.value(series, i);
    if (!std::isnan(value)) {
      *t = store.time(i);
      *v = value;
      return true;
    }
  }
  return false;
}

}  // namespace

void Decimate(const SampleStore& store, size_t series, double t0, double t1, int columns,
              DrawPoints* out) {
  out->clear();
  out->v_min = kNaN;
  out->v_max = kNaN;
  if (columns < 1) columns = 1;
  const auto [first, last] = store.IndexRange(t0, t1);
  out->samples = last - first;
  const size_t budget = 2 * static_cast<size_t>(columns);
  out->t.reserve(std::min(last - first, budget) + 2);
  out->v.reserve(std::min(last - first, budget) + 2);

  double edge_t = 0, edge_v = 0;
  constexpr size_t kEdgeSearch = 64;  // how far to look for a neighbour with a value
  if (ValueBefore(store, series, first, kEdgeSearch, &edge_t, &edge_v)) {
    out->t.push_back(edge_t);
    out->v.push_back(edge_v);
  }

  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  if (last - first <= budget) {
    store.ForEach(series, first, last, [&](double t, double v) {
      if (std::isnan(v)) return;
      out->t.push_back(t);
      out->v.push_back(v);
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    });
  } else {
    // one pass: per pixel column, the minimum and the maximum with their times
    const double scale = columns / (t1 - t0);
    long column = -1;
    double min_t = 0, min_v = 0, max_t = 0, max_v = 0;
    bool any = false;
    auto flush = [&] {
      if (!any) return;
      if (min_t <= max_t) {
        out->t.push_back(min_t);
        out->v.push_back(min_v);
        if (max_t != min_t) {
          out->t.push_back(max_t);
          out->v.push_back(max_v);
        }
      } else {
        out->t.push_back(max_t);
        out->v.push_back(max_v);
        out->t.push_back(min_t);
        out->v.push_back(min_v);
      }
      lo = std::min(lo, min_v);
      hi = std::max(hi, max_v);
      any = false;
    };
    const long last_column = columns - 1;
    store.ForEach(series, first, last, [&](double t, double v) {
      if (std::isnan(v)) return;
      long c = static_cast<long>((t - t0) * scale);
      if (c > last_column) c = last_column;
      if (c != column) {
        flush();
        column = c;
      }
      if (!any) {
        min_t = max_t = t;
        min_v = max_v = v;
        any = true;
      } else if (v < min_v) {
        min_t = t;
        min_v = v;
      } else if (v > max_v) {
        max_t = t;
        max_v = v;
      }
    });
    flush();
  }
  if (lo <= hi) {
    out->v_min = lo;
    out->v_max = hi;
  }

  if (ValueFrom(store, series, last, kEdgeSearch, &edge_t, &edge_v)) {
    out->t.push_back(edge_t);
    out->v.push_back(edge_v);
  }
}

}  // namespace caliper::plotter
