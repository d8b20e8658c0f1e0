// Millard 2012 equilibrium muscle: the quintic Bezier curves as OpenSim's
// SmoothSegmentedFunctionFactory defines them (Millard et al. 2013) and the fibre-tendon balance
// with fibre damping. The kind hill_muscle (muscle.cc) integrates the states.

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "caliper/actuators/muscle.h"
#include "muscle_validation.h"

namespace caliper::actuators {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

using muscle_detail::Num;
using muscle_detail::Require;

// polynomial c[0] + c[1] u + ... + c[5] u^5 and its first two derivatives
double Poly0(const std::array<double, 6>& c, double u) {
  return c[0] + u * (c[1] + u * (c[2] + u * (c[3] + u * (c[4] + u * c[5]))));
}
double Poly1(const std::array<double, 6>& c, double u) {
  return c[1] + u * (2 * c[2] + u * (3 * c[3] + u * (4 * c[4] + u * 5 * c[5])));
}
double Poly2(const std::array<double, 6>& c, double u) {
  return 2 * c[2] + u * (6 * c[3] + u * (12 * c[4] + u * 20 * c[5]));
}

// the Bernstein control points of a quintic as power-basis coefficients
std::array<double, 6> PowerBasis(const std::array<double, 6>& p) {
  return {p[0],
          5 * (p[1] - p[0]),
          10 * (p[2] - 2 * p[1] + p[0]),
          10 * (p[3] - 3 * p[2] + 3 * p[1] - p[0]),
          5 * (p[4] - 4 * p[3] + 6 * p[2] - 4 * p[1] + p[0]),
          p[5] - 5 * p[4] + 10 * p[3] - 10 * p[2] + 5 * p[1] - p[0]};
}

// root u in [lo, hi] of an increasing g(u) with g(lo) <= 0 <= g(hi), from u: Newton steps,
// bisection when a step leaves the bracket; g returns (value, derivative)
template <class G>
double SolveParameter(const G& g, double lo, double hi, double u) {
  for (int i = 0; i < 60; ++i) {
    const auto [value, slope] = g(u);
    if (value == 0) return u;
    if (value < 0)
      lo = u;
    else
      hi = u;
    if (slope > 0) {
      // converging quadratically: after a Newton step below 1e-10 the error in u is of the
      // order of its square (times the ratio of curvature to slope, small for these corners)
      const double step = value / slope;
      if (std::abs(step) < 1e-10) return std::clamp(u - step, lo, hi);
      u -= step;
    }
    if (!(u > lo && u < hi)) u = 0.5 * (lo + hi);
    if (hi - lo < 1e-15) return u;
  }
  return u;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// the curve

MillardCurve::MillardCurve(std::vector<Segment> segments) : segments_(std::move(segments)) {
  if (segments_.empty()) throw std::invalid_argument("a Millard curve needs a segment");
  for (const Segment& s : segments_) {
    for (int k = 0; k < 5; ++k)
      if (!(s.x[k + 1] >= s.x[k]) || !std::isfinite(s.y[k]))
        throw std::invalid_argument("a Millard curve's control points must have increasing x");
    if (!(s.x[5] > s.x[0])) throw std::invalid_argument("a Millard curve segment is empty");
    Poly p;
    p.x = PowerBasis(s.x);
    p.y = PowerBasis(s.y);
    for (int k = 0; k <= kSamples; ++k) {
      const double u = static_cast<double>(k) / kSamples;
      p.xs[k] = Poly0(p.x, u);
      p.ys[k] = Poly0(p.y, u);
      p.dxs[k] = Poly1(p.x, u);
      p.dys[k] = Poly1(p.y, u);
    }
    poly_.push_back(p);
  }
  x_end_ = segments_.back().x[5];
  y_begin_ = segments_.front().y[0];
  y_end_ = segments_.back().y[5];
  // the end slopes from the control points next to the ends (exact when on the end lines)
  const Segment& a = segments_.front();
  const Segment& b = segments_.back();
  slope_begin_ = (a.y[1] - a.y[0]) / (a.x[1] - a.x[0]);
  slope_end_ = (b.y[5] - b.y[4]) / (b.x[5] - b.x[4]);
}

template <bool kXOnly>
double MillardCurve::SolveU(std::size_t i, double w, double d, double target) const {
  const Poly& p = poly_[i];
  auto h = [&](int k) { return kXOnly ? p.xs[k] : w * p.ys[k] + d * p.xs[k]; };
  // the sampled interval holding target, by bisection over the samples
  int lo = 0, hi = kSamples;
  while (hi - lo > 1) {
    const int mid = (lo + hi) / 2;
    (h(mid) < target ? lo : hi) = mid;
  }
  // start: the cubic Hermite interpolant of the inverse u(h) on that interval (its error is of
  // the fourth order in the interval), then Newton steps on h(u) - target
  const double h0 = h(lo), h1 = h(hi);
  const double du = 1.0 / kSamples;
  double u = (lo + 0.5) * du;
  const double span = h1 - h0;
  const double g0 = kXOnly ? p.dxs[lo] : w * p.dys[lo] + d * p.dxs[lo];
  const double g1 = kXOnly ? p.dxs[hi] : w * p.dys[hi] + d * p.dxs[hi];
  if (span > 0 && g0 > 0 && g1 > 0) {
    const double t = (target - h0) / span;
    const double m0 = span / g0, m1 = span / g1;  // du/dt at the ends
    const double t2 = t * t, t3 = t2 * t;
    u = lo * du + (-2 * t3 + 3 * t2) * du + (t3 - 2 * t2 + t) * m0 + (t3 - t2) * m1;
    u = std::clamp(u, lo * du, hi * du);
  }
  auto g = [&](double v) {
    if (kXOnly) return std::make_pair(Poly0(p.x, v) - target, Poly1(p.x, v));
    return std::make_pair(w * Poly0(p.y, v) + d * Poly0(p.x, v) - target,
                          w * Poly1(p.y, v) + d * Poly1(p.x, v));
  };
  // one Halley step from that start: its error is of the order of the cube of the start's
  // (below 1e-5 here: below 1e-15); the safeguarded Newton solve when the start was poor
  const auto [value, slope] = g(u);
  const double curvature = kXOnly ? Poly2(p.x, u) : w * Poly2(p.y, u) + d * Poly2(p.x, u);
  const double denominator = 2 * slope * slope - value * curvature;
  if (slope > 0 && denominator > 0) {
    const double step = 2 * value * slope / denominator;
    if (std::abs(step) < 1e-5) return std::clamp(u - step, lo * du, hi * du);
  }
  return SolveParameter(g, lo * du, hi * du, u);
}

std::pair<std::size_t, double> MillardCurve::Locate(double x) const {
  std::size_t i = 0;
  while (i + 1 < poly_.size() && x > segments_[i].x[5]) ++i;
  return {i, SolveU<true>(i, 0, 1, x)};
}

std::pair<double, double> MillardCurve::ValueAndSlope(double x) const {
  if (x <= x_begin()) return {y_begin_ + slope_begin_ * (x - x_begin()), slope_begin_};
  if (x >= x_end_) return {y_end_ + slope_end_ * (x - x_end_), slope_end_};
  const auto [i, u] = Locate(x);
  const Poly& p = poly_[i];
  return {Poly0(p.y, u), Poly1(p.y, u) / Poly1(p.x, u)};
}

double MillardCurve::Value(double x) const { return ValueAndSlope(x).first; }
double MillardCurve::Slope(double x) const { return ValueAndSlope(x).second; }

double MillardCurve::SecondDerivative(double x) const {
  if (x <= x_begin() || x >= x_end_) return 0;
  const auto [i, u] = Locate(x);
  const Poly& p = poly_[i];
  const double dx = Poly1(p.x, u);
  return (Poly2(p.y, u) * dx - Poly2(p.x, u) * Poly1(p.y, u)) / (dx * dx * dx);
}

MillardCurve::Solution MillardCurve::SolveAffine(double w, double d, double target) const {
  auto h = [&](double x, double y) { return w * y + d * x; };
  Solution s;
  // before the first and after the last segment: straight lines
  const double h0 = h(x_begin(), y_begin_);
  if (target <= h0) {
    const double rate = w * slope_begin_ + d;
    s.x = rate > 0 ? x_begin() + (target - h0) / rate : (target == h0 ? x_begin() : kNaN);
    s.y = y_begin_ + slope_begin_ * (s.x - x_begin());
    s.slope = slope_begin_;
    return s;
  }
  const double h1 = h(x_end_, y_end_);
  if (target >= h1) {
    const double rate = w * slope_end_ + d;
    s.x = rate > 0 ? x_end_ + (target - h1) / rate : (target == h1 ? x_end_ : kNaN);
    s.y = y_end_ + slope_end_ * (s.x - x_end_);
    s.slope = slope_end_;
    return s;
  }
  // the segment whose end values bracket target; h is non-decreasing along it
  std::size_t i = 0;
  while (i + 1 < poly_.size() && target > h(segments_[i].x[5], segments_[i].y[5])) ++i;
  const Poly& p = poly_[i];
  const double u = SolveU<false>(i, w, d, target);
  s.x = Poly0(p.x, u);
  s.y = Poly0(p.y, u);
  s.slope = Poly1(p.y, u) / Poly1(p.x, u);
  return s;
}

MillardCurve::Segment MillardCorner(double x0, double y0, double dydx0, double x1, double y1,
                                    double dydx1, double curviness) {
  if (!(curviness >= 0 && curviness <= 1))
    throw std::invalid_argument("curviness " + Num(curviness) + " must be in [0, 1]");
  // where the two end lines meet (the midpoint when they are parallel)
  double xc = 0.5 * (x0 + x1);
  if (std::abs(dydx0 - dydx1) > 1.4901161193847656e-08)  // sqrt(double epsilon)
    xc = (y1 - y0 - x1 * dydx1 + x0 * dydx0) / (dydx0 - dydx1);
  const double yc = (xc - x1) * dydx1 + y1;
  const double a = (xc - x0) * (xc - x0) + (yc - y0) * (yc - y0);
  const double b = (xc - x1) * (xc - x1) + (yc - y1) * (yc - y1);
  const double c = (x1 - x0) * (x1 - x0) + (y1 - y0) * (y1 - y0);
  if (!(x1 > x0 && c > a && c > b))
    throw std::invalid_argument("no C-shaped corner from (" + Num(x0) + ", " + Num(y0) +
                                ") slope " + Num(dydx0) + " to (" + Num(x1) + ", " + Num(y1) +
                                ") slope " + Num(dydx1));
  // doubled inner points: zero curvature at both ends, so corners join C2
  const double k = 0.1 + 0.8 * curviness;
  // each inner point on its own end's line, so that the end slopes are exactly the given ones
  const double x0m = x0 + k * (xc - x0), y0m = y0 + k * dydx0 * (xc - x0);
  const double x1m = x1 + k * (xc - x1), y1m = y1 + k * dydx1 * (xc - x1);
  MillardCurve::Segment s;
  s.x = {x0, x0m, x0m, x1m, x1m, x1};
  s.y = {y0, y0m, y0m, y1m, y1m, y1};
  return s;
}

MillardCurve MillardActiveForceLengthCurve(const MillardCurveParameters& p) {
  const double x0 = p.min_norm_active_fiber_length;
  const double x1 = p.transition_norm_fiber_length;
  const double x2 = 1;
  const double x3 = p.max_norm_active_fiber_length;
  const double ylow = p.minimum_value;
  const double dydx = p.shallow_ascending_slope;
  Require(x0 > 0, "min_norm_active_fiber_length", x0, "must be > 0");
  Require(x1 > x0 && x1 < x2, "transition_norm_fiber_length", x1,
          "must be in (min_norm_active_fiber_length = " + Num(x0) + ", 1)");
  Require(x3 > x2, "max_norm_active_fiber_length", x3, "must be > 1");
  Require(ylow >= 0 && ylow < 1, "minimum_value", ylow, "must be in [0, 1)");
  Require(dydx >= 0 && dydx < (1 - ylow) / (x2 - x1), "shallow_ascending_slope", dydx,
          "must be in [0, (1 - minimum_value) / (1 - transition_norm_fiber_length) = " +
              Num((1 - ylow) / (x2 - x1)) + ")");
  // the plateau's shoulder, 5 % of the optimal length wide (OpenSim's choice)
  const double delta = 0.05 * x2;
  const double xs = x2 - delta;
  const double y1 = 1 - dydx * (xs - x1);
  const double x01 = x0 + 0.5 * (x1 - x0);
  const double y01 = 0.5 * y1;
  const double dydx01 = 1.25 * y1 / (x1 - x0);
  const double x1s = x1 + 0.5 * (xs - x1);
  const double y1s = y1 + 0.5 * (1 - y1);
  const double x23 = (x2 + delta) + 0.5 * (x3 - (x2 + delta));
  const double y23 = 0.5;
  const double dydx23 = -1 / ((x3 - delta) - (x2 + delta));
  const double c = 1;  // ActiveForceLengthCurve's fixed curviness
  try {
    return MillardCurve({MillardCorner(x0, ylow, 0, x01, y01, dydx01, c),
                         MillardCorner(x01, y01, dydx01, x1s, y1s, dydx, c),
                         MillardCorner(x1s, y1s, dydx, x2, 1, 0, c),
                         MillardCorner(x2, 1, 0, x23, y23, dydx23, c),
                         MillardCorner(x23, y23, dydx23, x3, ylow, 0, c)});
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string("active force-length curve: ") + e.what());
  }
}

MillardCurve MillardForceVelocityCurve(const MillardCurveParameters& p) {
  const double fmax = p.max_eccentric_velocity_force_multiplier;
  const double dc = p.concentric_slope_at_vmax, dnc = p.concentric_slope_near_vmax;
  const double de = p.eccentric_slope_at_vmax, dne = p.eccentric_slope_near_vmax;
  const double diso = p.isometric_slope;
  Require(fmax > 1, "max_eccentric_velocity_force_multiplier", fmax, "must be > 1");
  Require(dc >= 0 && dc < 1, "concentric_slope_at_vmax", dc, "must be in [0, 1)");
  Require(dnc > dc && dnc <= 1, "concentric_slope_near_vmax", dnc,
          "must be in (concentric_slope_at_vmax = " + Num(dc) + ", 1]");
  Require(diso > 1, "isometric_slope", diso, "must be > 1");
  Require(de >= 0 && de < fmax - 1, "eccentric_slope_at_vmax", de,
          "must be in [0, max_eccentric_velocity_force_multiplier - 1 = " + Num(fmax - 1) + ")");
  Require(dne >= de && dne < fmax - 1, "eccentric_slope_near_vmax", dne,
          "must be in [eccentric_slope_at_vmax, max_eccentric_velocity_force_multiplier - 1 = " +
              Num(fmax - 1) + ")");
  Require(p.concentric_curviness >= 0 && p.concentric_curviness <= 1, "concentric_curviness",
          p.concentric_curviness, "must be in [0, 1]");
  Require(p.eccentric_curviness >= 0 && p.eccentric_curviness <= 1, "eccentric_curviness",
          p.eccentric_curviness, "must be in [0, 1]");
  // points near vmax (+-0.9) on the mean of the two slopes there
  const double y_near_c = 0.5 * (dnc + dc) * 0.1;
  const double y_near_e = fmax - 0.5 * (dne + de) * 0.1;
  const double cc = p.concentric_curviness, ce = p.eccentric_curviness;
  try {
    return MillardCurve({MillardCorner(-1, 0, dc, -0.9, y_near_c, dnc, cc),
                         MillardCorner(-0.9, y_near_c, dnc, 0, 1, diso, cc),
                         MillardCorner(0, 1, diso, 0.9, y_near_e, dne, ce),
                         MillardCorner(0.9, y_near_e, dne, 1, fmax, de, ce)});
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string("force-velocity curve: ") + e.what());
  }
}

MillardCurve MillardFiberForceLengthCurve(const MillardCurveParameters& p) {
  const double e0 = p.fiber_strain_at_zero_force, e1 = p.fiber_strain_at_one_norm_force;
  const double klow = p.fiber_stiffness_at_low_force, kiso = p.fiber_stiffness_at_one_norm_force;
  Require(std::isfinite(e0), "fiber_strain_at_zero_force", e0, "must be finite");
  Require(e1 > e0, "fiber_strain_at_one_norm_force", e1,
          "must be > fiber_strain_at_zero_force = " + Num(e0));
  Require(kiso > 1 / (e1 - e0), "fiber_stiffness_at_one_norm_force", kiso,
          "must be > 1 / (strain at one - strain at zero) = " + Num(1 / (e1 - e0)));
  Require(klow > 0 && klow < 1 / (e1 - e0), "fiber_stiffness_at_low_force", klow,
          "must be in (0, 1 / (strain at one - strain at zero) = " + Num(1 / (e1 - e0)) + ")");
  Require(p.fiber_curviness >= 0 && p.fiber_curviness <= 1, "fiber_curviness", p.fiber_curviness,
          "must be in [0, 1]");
  const double x0 = 1 + e0, x1 = 1 + e1;
  // a short low-stiffness foot starting halfway into its first tenth
  const double dx = std::min(0.1 / kiso, 0.1 * (x1 - x0));
  const double xlow = x0 + dx;
  const double ylow = klow * (xlow - (x0 + 0.5 * dx));
  try {
    return MillardCurve({MillardCorner(x0, 0, 0, xlow, ylow, klow, p.fiber_curviness),
                         MillardCorner(xlow, ylow, klow, x1, 1, kiso, p.fiber_curviness)});
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string("fibre force-length curve: ") + e.what());
  }
}

MillardCurve MillardTendonForceLengthCurve(const MillardCurveParameters& p) {
  const double eiso = p.tendon_strain_at_one_norm_force;
  const double kiso = p.tendon_stiffness_at_one_norm_force;
  const double ftoe = p.tendon_norm_force_at_toe_end;
  Require(eiso > 0, "tendon_strain_at_one_norm_force", eiso, "must be > 0");
  Require(kiso > 1 / eiso, "tendon_stiffness_at_one_norm_force", kiso,
          "must be > 1 / tendon_strain_at_one_norm_force = " + Num(1 / eiso));
  Require(ftoe > 0 && ftoe < 1, "tendon_norm_force_at_toe_end", ftoe, "must be in (0, 1)");
  Require(p.tendon_curviness >= 0 && p.tendon_curviness <= 1, "tendon_curviness",
          p.tendon_curviness, "must be in [0, 1]");
  const double xiso = 1 + eiso;
  // the linear part from the toe's end (ftoe) through (xiso, 1)
  const double xtoe = (ftoe - 1) / kiso + xiso;
  // the toe aims at a foot a tenth of the way in, to bound its curvature
  const double xfoot = 1 + (xtoe - 1) / 10;
  const double ymid = 0.5 * ftoe;
  const double xmid = (ymid - 1) / kiso + xiso;
  const double dydx_mid = ymid / (xmid - xfoot);
  const double xctrl = xfoot + 0.5 * (xmid - xfoot);
  const double yctrl = dydx_mid * (xctrl - xfoot);
  try {
    return MillardCurve(
        {MillardCorner(1, 0, 0, xctrl, yctrl, dydx_mid, p.tendon_curviness),
         MillardCorner(xctrl, yctrl, dydx_mid, xtoe, ftoe, kiso, p.tendon_curviness)});
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string("tendon force-length curve: ") + e.what());
  }
}

// ---------------------------------------------------------------------------------------------
// parameters

void Validate(const MillardMuscleParameters& p, bool elastic_tendon) {
  muscle_detail::RequireHillCommon(p, elastic_tendon);
  Require(p.minimum_activation >= 0 && p.minimum_activation < 1, "minimum_activation",
          p.minimum_activation, "must be in [0, 1)");
  Require(p.fiber_damping >= 0, "fiber_damping", p.fiber_damping, "must be >= 0");
  MillardActiveForceLengthCurve(p.curves);
  MillardForceVelocityCurve(p.curves);
  MillardFiberForceLengthCurve(p.curves);
  MillardTendonForceLengthCurve(p.curves);
  if (elastic_tendon && p.fiber_damping == 0) {
    // undamped: the velocity comes from the inverse force-velocity curve, a fal > 0 divides
    const std::string why = "must be > 0 with fiber_damping = 0 and an elastic tendon";
    Require(p.curves.concentric_slope_at_vmax > 0, "concentric_slope_at_vmax",
            p.curves.concentric_slope_at_vmax, why + " (invertible force-velocity curve)");
    Require(p.curves.eccentric_slope_at_vmax > 0, "eccentric_slope_at_vmax",
            p.curves.eccentric_slope_at_vmax, why + " (invertible force-velocity curve)");
    Require(p.minimum_activation > 0, "minimum_activation", p.minimum_activation, why);
    Require(p.curves.minimum_value > 0, "minimum_value", p.curves.minimum_value, why);
  }
}

// ---------------------------------------------------------------------------------------------
// the fibre model

struct MillardFiberModel::Terms {
  double along = 0, cos = 1, dcos = 0;  // fibre along the tendon [m], cos, dcos/dlm [1/m]
  double tendon_length = 0;             // [m]
  double fse = 0, dfse = 0;             // tendon force [-], d/dlm [1/m]
  double fal = 0, dfal = 0;             // [-], [1/m]
  double fpe = 0, dfpe = 0;             // [-], [1/m]
};

MillardFiberModel::MillardFiberModel(const MillardMuscleParameters& p)
    : p_(p),
      fal_(MillardActiveForceLengthCurve(p.curves)),
      fv_(MillardForceVelocityCurve(p.curves)),
      fpe_(MillardFiberForceLengthCurve(p.curves)),
      fse_(MillardTendonForceLengthCurve(p.curves)) {
  height_ = p.optimal_fiber_length * std::sin(p.pennation_angle);
  minimum_fiber_length_ = std::max(p.curves.min_norm_active_fiber_length * p.optimal_fiber_length,
                                   height_ / std::sin(p.maximum_pennation_angle));
}

MillardFiberModel::Terms MillardFiberModel::TermsAt(double lm, double path_length) const {
  Terms t;
  const double h = height_;
  t.along = std::sqrt(std::max(lm * lm - h * h, 0.0));
  t.cos = std::max(t.along / lm, 1e-12);
  t.dcos = h * h / (lm * lm * lm * t.cos);
  t.tendon_length = path_length - t.along;
  const double lts = p_.tendon_slack_length;
  const auto [fse, kse] = fse_.ValueAndSlope(t.tendon_length / lts);
  t.fse = fse;
  t.dfse = -kse / (lts * t.cos);  // d(tendon length)/dlm = -1/cos
  const double lopt = p_.optimal_fiber_length;
  const auto [fal, dfal] = fal_.ValueAndSlope(lm / lopt);
  const auto [fpe, dfpe] = fpe_.ValueAndSlope(lm / lopt);
  t.fal = fal;
  t.dfal = dfal / lopt;
  t.fpe = fpe;
  t.dfpe = dfpe / lopt;
  return t;
}

std::pair<double, double> MillardFiberModel::FiberVelocity(double lm, double path_length,
                                                           double a) const {
  const Terms t = TermsAt(lm, path_length);
  // a fal fv(v) + beta v = fse / cos - fpe, for the normalised velocity v
  const double target = t.fse / t.cos - t.fpe;
  const double dtarget = t.dfse / t.cos - t.fse * t.dcos / (t.cos * t.cos) - t.dfpe;
  const double weight = a * t.fal;
  const double beta = p_.fiber_damping;
  const MillardCurve::Solution s = fv_.SolveAffine(weight, beta, target);
  const double scale = p_.max_contraction_velocity * p_.optimal_fiber_length;
  const double dv = (dtarget - a * t.dfal * s.y) / std::max(weight * s.slope + beta, 1e-12);
  return {s.x * scale, dv * scale};
}

std::pair<double, double> MillardFiberModel::IsometricExcess(double lm, double path_length,
                                                             double a) const {
  const Terms t = TermsAt(lm, path_length);
  return {a * t.fal + t.fpe - t.fse / t.cos,
          a * t.dfal + t.dfpe - t.dfse / t.cos + t.fse * t.dcos / (t.cos * t.cos)};
}

MillardFiberModel::State MillardFiberModel::Elastic(double lm, double path_length, double a) const {
  const Terms t = TermsAt(lm, path_length);
  const double f0 = p_.max_isometric_force;
  const double lopt = p_.optimal_fiber_length;
  State s;
  s.fiber_length = lm;
  s.cos_pennation = t.cos;
  s.tendon_length = t.tendon_length;
  s.tendon_strain = t.tendon_length / p_.tendon_slack_length - 1;
  s.norm_fiber_length = lm / lopt;
  const MillardCurve::Solution v =
      fv_.SolveAffine(a * t.fal, p_.fiber_damping, t.fse / t.cos - t.fpe);
  s.norm_fiber_velocity = v.x;
  s.fiber_velocity = v.x * p_.max_contraction_velocity * lopt;
  s.active_force_length = t.fal;
  s.force_velocity = v.y;
  s.passive_force_length = t.fpe;
  s.active_fiber_force = f0 * a * t.fal * v.y;
  s.passive_force = f0 * (t.fpe + p_.fiber_damping * v.x);
  s.tendon_force = f0 * t.fse;
  s.tension = std::max(0.0, s.tendon_force);
  return s;
}

MillardFiberModel::State MillardFiberModel::Rigid(double path_length, double path_speed,
                                                  double a) const {
  const double lopt = p_.optimal_fiber_length;
  const double f0 = p_.max_isometric_force;
  State s;
  const double lts = p_.tendon_slack_length;
  const double along = std::max(path_length - lts, 0.0);
  // OpenSim's clamp: the fibre never shorter than minimum_fiber_length(); a path too short for
  // it leaves the tendon slack (shorter than its slack length, buckled)
  s.fiber_length = std::max(std::sqrt(height_ * height_ + along * along), minimum_fiber_length_);
  const double along_clamped =
      std::sqrt(std::max(s.fiber_length * s.fiber_length - height_ * height_, 0.0));
  s.cos_pennation = along_clamped / s.fiber_length;
  s.tendon_length = path_length - along_clamped;
  // a buckled tendon moves, the fibre does not
  const bool buckled = s.tendon_length < lts - 1e-12 * lts;
  s.fiber_velocity = buckled ? 0.0 : s.cos_pennation * path_speed;
  s.norm_fiber_length = s.fiber_length / lopt;
  s.active_force_length = fal_.Value(s.norm_fiber_length);
  s.passive_force_length = fpe_.Value(s.norm_fiber_length);
  // clamped (at the minimum and not lengthening): at rest (fv = 1) and no fibre force, as
  // OpenSim's isFiberStateClamped; it leaves the minimum as soon as the path lengthens it
  if (s.fiber_length <= minimum_fiber_length_ && s.fiber_velocity <= 0) {
    s.fiber_velocity = 0;
    s.norm_fiber_velocity = 0;
    s.force_velocity = 1;
    return s;  // active, passive, tendon force and tension 0
  }
  s.norm_fiber_velocity = s.fiber_velocity / (p_.max_contraction_velocity * lopt);
  s.force_velocity = fv_.Value(s.norm_fiber_velocity);
  s.active_fiber_force = f0 * a * s.active_force_length * s.force_velocity;
  s.passive_force = f0 * (s.passive_force_length + p_.fiber_damping * s.norm_fiber_velocity);
  s.tendon_force = (s.active_fiber_force + s.passive_force) * s.cos_pennation;
  s.tension = std::max(0.0, s.tendon_force);
  return s;
}

}  // namespace caliper::actuators
