// The Millard 2012 curves (millard.cc) against their defining properties: values and slopes at
// the knots OpenSim's parameters name, zero curvature where the curves turn straight, C1/C2
// continuity at every join between Bezier segments, and inverse round trips.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "caliper/actuators/muscle.h"

namespace caliper::actuators {
namespace {

const MillardCurveParameters kDefaults;

// the slope by a central difference, for checking the analytic slope
double NumericSlope(const MillardCurve& c, double x, double h = 1e-6) {
  return (c.Value(x + h) - c.Value(x - h)) / (2 * h);
}

// values and first and second derivatives agree on both sides of every join (and at the ends
// with the straight extensions, whose curvature is 0); the curvature changes fast near a join
// (the doubled control points), so the steps are small and the tolerance scales with its peak
void ExpectC2AtJoins(const MillardCurve& c) {
  double peak = 0;
  for (int i = 0; i <= 4000; ++i)
    peak = std::max(
        peak, std::abs(c.SecondDerivative(c.x_begin() + (c.x_end() - c.x_begin()) * i / 4000.0)));
  ASSERT_GT(peak, 0);
  const double h = 1e-9;
  for (const auto& s : c.segments()) {
    for (const double x : {s.x[0], s.x[5]}) {
      SCOPED_TRACE("join at x = " + std::to_string(x));
      EXPECT_NEAR(c.Value(x + h) - c.Value(x - h), 2 * h * c.Slope(x), 1e-12);
      EXPECT_NEAR(c.Slope(x - h), c.Slope(x + h), 1e-6 * peak);
      EXPECT_NEAR(c.SecondDerivative(x - h), c.SecondDerivative(x + h), 1e-2 * peak);
      EXPECT_NEAR(c.SecondDerivative(x), 0, 1e-2 * peak);
    }
  }
}

void ExpectSlopesMatchDifferences(const MillardCurve& c, double lo, double hi) {
  for (int i = 0; i <= 200; ++i) {
    const double x = lo + (hi - lo) * i / 200.0;
    EXPECT_NEAR(c.Slope(x), NumericSlope(c, x), 1e-5 * (1 + std::abs(c.Slope(x)))) << "x " << x;
  }
}

TEST(MillardCurves, ActiveForceLengthHasItsKnots) {
  const MillardCurve fal = MillardActiveForceLengthCurve();
  EXPECT_NEAR(fal.Value(1), 1, 1e-12);
  EXPECT_NEAR(fal.Slope(1), 0, 1e-9);
  // the shoulders: minimum_value with zero slope, and flat beyond
  for (const double x :
       {kDefaults.min_norm_active_fiber_length, kDefaults.max_norm_active_fiber_length, 0.2, 2.5}) {
    EXPECT_NEAR(fal.Value(x), kDefaults.minimum_value, 1e-12) << x;
    EXPECT_NEAR(fal.Slope(x), 0, 1e-9) << x;
  }
  // the maximum is at the optimal length
  for (double x = 0.3; x < 2; x += 0.01) EXPECT_LE(fal.Value(x), 1 + 1e-12) << x;
  // the shallow ascending limb has its slope between the transition and the shoulder
  EXPECT_NEAR(fal.Slope(0.5 * (kDefaults.transition_norm_fiber_length + 0.95)),
              kDefaults.shallow_ascending_slope, 0.02);
  ExpectC2AtJoins(fal);
  ExpectSlopesMatchDifferences(fal, 0.3, 2);
}

TEST(MillardCurves, ForceVelocityHasItsKnots) {
  const MillardCurve fv = MillardForceVelocityCurve();
  EXPECT_NEAR(fv.Value(0), 1, 1e-12);
  EXPECT_NEAR(fv.Slope(0), kDefaults.isometric_slope, 1e-9);
  EXPECT_NEAR(fv.Value(-1), 0, 1e-12);
  EXPECT_NEAR(fv.Slope(-1), kDefaults.concentric_slope_at_vmax, 1e-9);
  EXPECT_NEAR(fv.Slope(-0.9), kDefaults.concentric_slope_near_vmax, 1e-9);
  EXPECT_NEAR(fv.Slope(0.9), kDefaults.eccentric_slope_near_vmax, 1e-9);
  EXPECT_NEAR(fv.Value(1), kDefaults.max_eccentric_velocity_force_multiplier, 1e-12);
  EXPECT_NEAR(fv.Value(1.5), kDefaults.max_eccentric_velocity_force_multiplier, 1e-12);
  EXPECT_NEAR(fv.Value(-1.5), 0, 1e-12);
  for (double v = -1.2; v < 1.2; v += 0.01) EXPECT_GE(fv.Slope(v), 0) << v;
  ExpectC2AtJoins(fv);
  ExpectSlopesMatchDifferences(fv, -1.1, 1.1);
}

TEST(MillardCurves, FiberForceLengthHasItsKnots) {
  const MillardCurve fpe = MillardFiberForceLengthCurve();
  EXPECT_NEAR(fpe.Value(1 + kDefaults.fiber_strain_at_zero_force), 0, 1e-12);
  EXPECT_NEAR(fpe.Slope(1), 0, 1e-9);
  EXPECT_NEAR(fpe.Value(0.7), 0, 1e-12);  // slack fibres pull nothing
  EXPECT_NEAR(fpe.Value(1.7), 1, 1e-12);
  EXPECT_NEAR(fpe.Slope(1.7), 2 / 0.7, 1e-9);
  EXPECT_NEAR(fpe.Value(1.8), 1 + 0.1 * 2 / 0.7, 1e-12);  // straight beyond
  // the low-force foot has the low stiffness at its end
  const double dx = std::min(0.1 / (2 / 0.7), 0.1 * 0.7);
  EXPECT_NEAR(fpe.Slope(1 + dx), kDefaults.fiber_stiffness_at_low_force, 1e-9);
  ExpectC2AtJoins(fpe);
  ExpectSlopesMatchDifferences(fpe, 0.9, 1.9);
}

TEST(MillardCurves, TendonForceLengthHasItsKnots) {
  const MillardCurve fse = MillardTendonForceLengthCurve();
  const double e0 = kDefaults.tendon_strain_at_one_norm_force;
  const double k = 1.375 / 0.049;
  EXPECT_NEAR(fse.Value(1), 0, 1e-12);
  EXPECT_NEAR(fse.Slope(1), 0, 1e-9);
  EXPECT_NEAR(fse.Value(0.95), 0, 1e-12);
  EXPECT_NEAR(fse.Value(1 + e0), 1, 1e-12);
  EXPECT_NEAR(fse.Slope(1 + e0), k, 1e-9);
  // the toe ends at 2/3 on the line through (1 + e0, 1) of slope k
  const double toe_end = 1 + e0 + (2.0 / 3.0 - 1) / k;
  EXPECT_NEAR(fse.Value(toe_end), 2.0 / 3.0, 1e-12);
  EXPECT_NEAR(fse.Slope(toe_end), k, 1e-9);
  EXPECT_NEAR(fse.SecondDerivative(toe_end - 1e-9), 0, 1e-3);
  EXPECT_GT(fse.SecondDerivative(1 + 0.5 * (toe_end - 1)), 0);  // the toe stiffens
  ExpectC2AtJoins(fse);
  ExpectSlopesMatchDifferences(fse, 0.99, 1.07);
}

// The construction points pinned to 1e-12, as literal numbers worked out by hand from OpenSim's
// SmoothSegmentedFunctionFactory with the default parameters, so that a wrong constant in
// millard.cc fails here even where the curve keeps its knots' values and slopes.
void ExpectJoins(const MillardCurve& c, const std::vector<std::array<double, 2>>& joins) {
  const auto& s = c.segments();
  ASSERT_EQ(s.size() + 1, joins.size());
  for (size_t i = 0; i < joins.size(); ++i) {
    SCOPED_TRACE("join " + std::to_string(i));
    const auto& [x, y] = i < s.size() ? std::array<double, 2>{s[i].x[0], s[i].y[0]}
                                      : std::array<double, 2>{s[i - 1].x[5], s[i - 1].y[5]};
    EXPECT_NEAR(x, joins[i][0], 1e-12);
    EXPECT_NEAR(y, joins[i][1], 1e-12);
    if (i > 0 && i < s.size()) {  // the segments meet
      EXPECT_EQ(s[i - 1].x[5], s[i].x[0]);
      EXPECT_EQ(s[i - 1].y[5], s[i].y[0]);
    }
  }
}

TEST(MillardCurves, ConstructionPointsAreOpenSims) {
  // active force-length: shoulder half-width 0.05, xs = 0.95, y1 = 1 - 0.8616 (0.95 - 0.73)
  // = 0.810448; x01 = 0.4441 + (0.73 - 0.4441) / 2, y01 = y1 / 2; x1s = 0.73 + (0.95 - 0.73) / 2,
  // y1s = (1 + y1) / 2; x23 = 1.05 + (1.8123 - 1.05) / 2, y23 = 1/2
  const MillardCurve fal = MillardActiveForceLengthCurve();
  ExpectJoins(fal, {{{0.4441, 0.1},
                     {0.58705, 0.405224},
                     {0.84, 0.905224},
                     {1, 1},
                     {1.43115, 0.5},
                     {1.8123, 0.1}}});
  // the first corner's doubled inner point, curviness 1 scaled to 0.9 of the way to where the
  // flat shoulder y = 0.1 meets the line through (x01, y01) of slope 1.25 y1 / (0.73 - 0.4441)
  // = 3.5434067855893674: at x = 0.58705 - 0.305224 / 3.5434067855893674 = 0.5009114281483821
  EXPECT_NEAR(fal.segments()[0].x[1], 0.4441 + 0.9 * (0.5009114281483821 - 0.4441), 1e-12);
  EXPECT_EQ(fal.segments()[0].x[1], fal.segments()[0].x[2]);
  EXPECT_NEAR(fal.segments()[0].y[1], 0.1, 1e-12);
  EXPECT_NEAR(fal.Slope(0.58705), 3.5434067855893674, 1e-9);
  // force-velocity: (-0.9, (0.25 + 0) / 2 * 0.1), (0.9, 1.4 - (0.15 + 0) / 2 * 0.1)
  ExpectJoins(MillardForceVelocityCurve(),
              {{{-1, 0}, {-0.9, 0.0125}, {0, 1}, {0.9, 1.3925}, {1, 1.4}}});
  // passive fibre: the foot ends at 1 + min(0.1 / (2 / 0.7), 0.1 * 0.7) = 1.035 on the line of
  // slope 0.2 from 1 + 0.035 / 2: y = 0.2 * 0.0175
  ExpectJoins(MillardFiberForceLengthCurve(), {{{1, 0}, {1.035, 0.0035}, {1.7, 1}}});
  // tendon: the toe ends at 1.049 - (1/3) 0.049 / 1.375 = 1.037121212121212 (force 2/3); the
  // foot at 1 + (toe end - 1) / 10 = 1.0037121212121212; the mid line point at force 1/3 is at
  // 1.049 - (2/3) 0.049 / 1.375 = 1.0252424242424243, its slope from the foot
  // (1/3) / (1.0252424242424243 - 1.0037121212121212) = 15.48205489092182; the control point
  // halfway from the foot to it: x = 1.0144772727272726, y = 1/6
  const MillardCurve fse = MillardTendonForceLengthCurve();
  ExpectJoins(fse, {{{1, 0}, {1.0144772727272726, 1.0 / 6}, {1.037121212121212, 2.0 / 3}}});
  EXPECT_NEAR(fse.Slope(1.0144772727272726), 15.48205489092182, 1e-9);
}

// the Bezier of a segment at parameter u, in long double (Bernstein form)
long double Bernstein(const std::array<double, 6>& p, long double u) {
  const long double v = 1 - u;
  const long double c[6] = {v * v * v * v * v,      5 * u * v * v * v * v, 10 * u * u * v * v * v,
                            10 * u * u * u * v * v, 5 * u * u * u * u * v, u * u * u * u * u};
  long double sum = 0;
  for (int k = 0; k < 6; ++k) sum += c[k] * p[k];
  return sum;
}

TEST(MillardCurves, ValuesMatchTheBezierSolvedByBisection) {
  // the evaluation's fast parameter solve against 80 bisections in long double
  for (const MillardCurve& c : {MillardActiveForceLengthCurve(), MillardForceVelocityCurve(),
                                MillardFiberForceLengthCurve(), MillardTendonForceLengthCurve()}) {
    double worst = 0;
    for (const auto& s : c.segments())
      for (int i = 0; i <= 997; ++i) {
        const double x = s.x[0] + (s.x[5] - s.x[0]) * i / 997.0;
        long double lo = 0, hi = 1;
        for (int k = 0; k < 80; ++k) {
          const long double mid = 0.5L * (lo + hi);
          (Bernstein(s.x, mid) < x ? lo : hi) = mid;
        }
        const double y = static_cast<double>(Bernstein(s.y, 0.5L * (lo + hi)));
        worst = std::max(worst, std::abs(c.Value(x) - y));
      }
    EXPECT_LT(worst, 1e-13);
  }
}

TEST(MillardCurves, InverseRoundTrips) {
  const MillardCurve fv = MillardForceVelocityCurve();
  const MillardCurve fse = MillardTendonForceLengthCurve();
  const MillardCurve fpe = MillardFiberForceLengthCurve();
  for (int i = 1; i < 140; ++i) {
    const double y = i / 100.0;  // inside (0, 1.4)
    EXPECT_NEAR(fv.Value(fv.Inverse(y)), y, 1e-12) << y;
  }
  for (double x = -0.99; x < 1; x += 0.013) EXPECT_NEAR(fv.Inverse(fv.Value(x)), x, 1e-9) << x;
  for (double x = 1.0005; x < 1.1; x += 0.0011) {
    EXPECT_NEAR(fse.Inverse(fse.Value(x)), x, 1e-10) << x;
    EXPECT_NEAR(fpe.Inverse(fpe.Value(x + 0.5)), x + 0.5, 1e-10) << x;
  }
  // the flat ends of the default force-velocity curve have no inverse beyond them
  EXPECT_TRUE(std::isnan(fv.Inverse(1.5)));
  EXPECT_TRUE(std::isnan(fv.Inverse(-0.1)));
}

TEST(MillardCurves, DampedBalanceIsSolvedEverywhere) {
  // a fal fv(v) + beta v = target has one root for every target when beta > 0
  const MillardCurve fv = MillardForceVelocityCurve();
  for (const double weight : {0.0, 0.05, 0.7, 1.0})
    for (double target = -3; target < 3; target += 0.0371) {
      const auto s = fv.SolveAffine(weight, 0.1, target);
      ASSERT_TRUE(std::isfinite(s.x)) << weight << " " << target;
      EXPECT_NEAR(weight * fv.Value(s.x) + 0.1 * s.x, target, 1e-12);
      EXPECT_NEAR(s.y, fv.Value(s.x), 1e-12);
      EXPECT_NEAR(s.slope, fv.Slope(s.x), 1e-9);
    }
}

TEST(MillardCurves, RejectsParametersOutOfRange) {
  auto message = [](MillardCurveParameters p) -> std::string {
    try {
      MillardMuscleParameters m;
      m.curves = p;
      Validate(m, true);
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "";
  };
  MillardCurveParameters p;
  p.transition_norm_fiber_length = 0.3;
  EXPECT_NE(message(p).find("'transition_norm_fiber_length' = 0.3"), std::string::npos);
  p = {};
  p.isometric_slope = 0.5;
  EXPECT_NE(message(p).find("'isometric_slope'"), std::string::npos);
  p = {};
  p.tendon_stiffness_at_one_norm_force = 10;
  EXPECT_NE(message(p).find("'tendon_stiffness_at_one_norm_force' = 10: must be > 1 / "),
            std::string::npos);
  p = {};
  p.fiber_curviness = 1.5;
  EXPECT_NE(message(p).find("'fiber_curviness' = 1.5: must be in [0, 1]"), std::string::npos);
  EXPECT_EQ(message({}), "");
  // lines that meet beyond the end point make no C-shaped corner
  EXPECT_THROW(MillardCorner(0, 0, 0.5, 1, 1, 0.25, 0.5), std::invalid_argument);
}

}  // namespace
}  // namespace caliper::actuators
