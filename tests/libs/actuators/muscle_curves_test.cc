// The muscle curves of muscle.h against their formulas, Hill's hyperbola and the tables Debian's
// MuJoCo 2.2.2 produced (../shared/corpus/reference/mujoco222_generated/).

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <string>

#include "caliper/actuators/muscle.h"
#include "corpus.h"

namespace caliper::actuators {
namespace {

using caliper::testing::CorpusDir;
using caliper::testing::ReadCsv;

std::string Sci(double v) {
  std::ostringstream s;
  s << std::scientific << std::setprecision(2) << v;
  return s.str();
}

std::string Generated(const std::string& file) {
  return CorpusDir() + "/reference/mujoco222_generated/" + file;
}

// ---------------------------------------------------------------------------------------------
// Thelen 2003

TEST(ThelenCurves, ActiveForceLengthIsAGaussianPeakingAtOptimalLength) {
  EXPECT_DOUBLE_EQ(ThelenActiveForceLength(1.0), 1.0);
  // exp(-0.25 / 0.45)
  EXPECT_NEAR(ThelenActiveForceLength(0.5), 0.573753420737, 1e-12);
  EXPECT_NEAR(ThelenActiveForceLength(1.5), 0.573753420737, 1e-12);
  EXPECT_NEAR(ThelenActiveForceLength(1.2, 0.5), std::exp(-0.04 / 0.5), 1e-15);
  EXPECT_LT(ThelenActiveForceLength(0.9), 1.0);
  EXPECT_LT(ThelenActiveForceLength(1.1), 1.0);
}

TEST(ThelenCurves, PassiveForceLengthIsZeroUpToOptimalAndOneAtFmaxMuscleStrain) {
  EXPECT_EQ(ThelenPassiveForceLength(0.7), 0.0);
  EXPECT_EQ(ThelenPassiveForceLength(1.0), 0.0);
  EXPECT_NEAR(ThelenPassiveForceLength(1.6), 1.0, 1e-14);  // 1 + e0M, e0M = 0.6
  // (exp(5 * 0.3 / 0.6) - 1) / (exp(5) - 1)
  EXPECT_NEAR(ThelenPassiveForceLength(1.3), 0.075858180021, 1e-12);
  // the block_hanging_from_muscle values: kPE 4, e0M 0.6
  EXPECT_NEAR(ThelenPassiveForceLength(1.6, 4.0, 0.6), 1.0, 1e-14);
}

TEST(ThelenCurves, TendonToeConstantsAreOpenSims) {
  const ThelenTendonConstants c = ThelenTendonToe(0.04);
  EXPECT_NEAR(c.toe_strain / 0.04, 0.6086155379, 1e-9);
  EXPECT_NEAR(c.linear_stiffness, 42.7967934882, 1e-9);
  EXPECT_DOUBLE_EQ(c.toe_force, 0.33);
  EXPECT_DOUBLE_EQ(c.toe_shape, 3.0);
  const ThelenTendonConstants paper = ThelenTendonToe(0.033);
  EXPECT_NEAR(paper.toe_strain, 0.0200843127, 1e-9);
  EXPECT_NEAR(paper.linear_stiffness, 51.8749011978, 1e-9);
}

TEST(ThelenCurves, TendonForceIsOneAtFmaxTendonStrainAndZeroWhenSlack) {
  EXPECT_NEAR(ThelenTendonForceStrain(0.04), 1.0, 1e-14);
  EXPECT_NEAR(ThelenTendonForceStrain(0.033, 0.033), 1.0, 1e-14);
  EXPECT_EQ(ThelenTendonForceStrain(0.0), 0.0);
  EXPECT_EQ(ThelenTendonForceStrain(-0.01), 0.0);
  EXPECT_EQ(ThelenTendonStiffness(-0.01), 0.0);
  EXPECT_GT(ThelenTendonForceStrain(0.001), 0.0);
}

TEST(ThelenCurves, TendonToeJoinsTheLinearPartInValueAndSlope) {
  for (double e0 : {0.04, 0.033}) {
    const ThelenTendonConstants c = ThelenTendonToe(e0);
    const double e = c.toe_strain;
    const double d = 1e-9;
    EXPECT_NEAR(ThelenTendonForceStrain(e - d, e0), c.toe_force, 1e-7) << e0;
    EXPECT_NEAR(ThelenTendonForceStrain(e + d, e0), c.toe_force, 1e-7) << e0;
    // the toe's slope at its end equals k_lin
    EXPECT_NEAR(ThelenTendonStiffness(e * (1 - 1e-12), e0), c.linear_stiffness, 1e-8) << e0;
    EXPECT_DOUBLE_EQ(ThelenTendonStiffness(e * (1 + 1e-12), e0), c.linear_stiffness) << e0;
    // the stiffness is the derivative of the force (central differences)
    for (double s : {0.2 * e, 0.7 * e, 1.3 * e}) {
      const double h = 1e-7;
      const double fd =
          (ThelenTendonForceStrain(s + h, e0) - ThelenTendonForceStrain(s - h, e0)) / (2 * h);
      EXPECT_NEAR(ThelenTendonStiffness(s, e0), fd, 1e-5 * c.linear_stiffness) << s;
    }
  }
}

TEST(ThelenCurves, ShorteningBranchIsHillsHyperbolaAtFullActivation) {
  // Hill: (F + a)(w + b) = (F0 + a) b with a = b = 0.25 (F0 = vmax = 1), w the shortening
  // speed; in OpenSim's sign (v = -w) Thelen's branch with Af 0.25 at a = 1 is (1 + v)/(1 - 4 v)
  ThelenCurveParameters p;
  EXPECT_NEAR(ThelenForceVelocity(-0.25, 1.0, p), 0.375, 1e-6);
  EXPECT_NEAR(ThelenForceVelocity(-0.5, 1.0, p), 0.1667, 1e-4);
  EXPECT_NEAR(ThelenForceVelocity(-0.5, 1.0, p), 1.0 / 6.0, 1e-6);
  EXPECT_NEAR(ThelenForceVelocity(-1.0, 1.0, p), 0.0, 1e-6);
  EXPECT_NEAR(ThelenForceVelocity(0.0, 1.0, p), 1.0, 1e-6);
  for (double v = -1.0; v <= 0.0; v += 0.05) {
    const double f = ThelenForceVelocity(v, 1.0, p);
    EXPECT_NEAR(f, (1 + v) / (1 - 4 * v), 1e-6) << v;
    EXPECT_NEAR((f + 0.25) * (-v + 0.25), (1 + 0.25) * 0.25, 1e-6) << v;
  }
}

TEST(ThelenCurves, MaximumShorteningSpeedScalesWithActivation) {
  ThelenCurveParameters p;
  for (double a : {0.0, 0.01, 0.3, 1.0}) {
    const double vmax = 0.25 + 0.75 * a;
    EXPECT_NEAR(ThelenForceVelocity(-vmax, a, p), 0.0, 1e-14) << a;
    EXPECT_NEAR(ThelenForceVelocity(0.0, a, p), 1.0, 1e-14) << a;
    // linear below zero force, with the slope of the curve at zero force
    const double h = 1e-7;
    const double slope_in = (ThelenForceVelocity(-vmax + h, a, p) - 0) / h;
    const double slope_out = (0 - ThelenForceVelocity(-vmax - 0.1, a, p)) / 0.1;
    EXPECT_NEAR(slope_in, slope_out, 1e-5 * slope_out) << a;
  }
}

TEST(ThelenCurves, LengtheningBranchApproachesFlenAndIsLinearBeyondTheThreshold) {
  for (const ThelenCurveParameters& p :
       {ThelenCurveParameters{}, ThelenCurveParameters{0.5, 4, 0.6, 0.033, 0.3, 1.8, 0.95}}) {
    const double fv_thr = p.fv_linear_extrap_threshold * p.flen;
    const double v_thr = ThelenForceVelocityInverse(fv_thr, 1.0, p);
    EXPECT_GT(v_thr, 0);
    EXPECT_NEAR(ThelenForceVelocity(v_thr, 1.0, p), fv_thr, 1e-12);
    // continuous slope at the threshold, linear beyond it
    const double s = ThelenForceVelocityInverseSlope(fv_thr, 1.0, p);
    const double h = 1e-6;
    EXPECT_NEAR((ThelenForceVelocity(v_thr, 1.0, p) - ThelenForceVelocity(v_thr - h, 1.0, p)) / h,
                1 / s, 1e-4 / s);
    EXPECT_NEAR(ThelenForceVelocity(v_thr + 1.0, 1.0, p), fv_thr + 1.0 / s, 1e-12);
    EXPECT_LT(ThelenForceVelocity(0.5 * v_thr, 1.0, p), fv_thr);
    EXPECT_GT(ThelenForceVelocity(0.5 * v_thr, 1.0, p), 1.0);
  }
}

TEST(ThelenCurves, InverseForceVelocityUndoesTheForwardCurve) {
  for (const ThelenCurveParameters& p :
       {ThelenCurveParameters{}, ThelenCurveParameters{0.5, 4, 0.6, 0.033, 0.3, 1.8, 0.95}}) {
    for (double a : {0.01, 0.2, 0.6, 1.0}) {
      for (double v = -1.5; v <= 1.5; v += 0.01) {
        const double fv = ThelenForceVelocity(v, a, p);
        EXPECT_NEAR(ThelenForceVelocityInverse(fv, a, p), v, 1e-12) << "a " << a << " v " << v;
        // the slope is the derivative of the inverse (away from the kink at fv = 1, where
        // Thelen's lengthening slope is twice the shortening one)
        if (std::abs(fv - 1) < 1e-5) continue;
        const double h = 1e-7;
        const double fd =
            (ThelenForceVelocityInverse(fv + h, a, p) - ThelenForceVelocityInverse(fv - h, a, p)) /
            (2 * h);
        const double slope = ThelenForceVelocityInverseSlope(fv, a, p);
        EXPECT_NEAR(slope, fd, 1e-5 * std::max(1.0, slope)) << "a " << a << " v " << v;
      }
    }
  }
}

TEST(ThelenCurves, InverseForceVelocityIsOpenSimsCalcdlceN) {
  // OpenSim: shortening b = afl + F / Af; lengthening b = (2 + 2/Af)(afl Flen - F)/(Flen - 1);
  // dlceN = (0.25 + 0.75 a)(F - afl) / b, with F = a fal fv; here a = 0.4, fal = 0.8
  ThelenCurveParameters p;
  const double a = 0.4, fal = 0.8, afl = a * fal;
  for (double fv : {0.1, 0.5, 0.9, 1.1, 1.3}) {
    const double F = afl * fv;
    const double b = fv <= 1 ? afl + F / p.af : (2 + 2 / p.af) * (afl * p.flen - F) / (p.flen - 1);
    EXPECT_NEAR(ThelenForceVelocityInverse(fv, a, p), (0.25 + 0.75 * a) * (F - afl) / b, 1e-14)
        << fv;
  }
}

TEST(ActivationDynamics, TimeConstantGrowsWithActivationWhenRisingAndShrinksWhenFalling) {
  // tau = 0.015 (0.5 + 1.5 a) rising, 0.05 / (0.5 + 1.5 a) falling
  EXPECT_NEAR(ActivationRate(1.0, 0.0, 0.015, 0.05), 1.0 / (0.015 * 0.5), 1e-12);
  EXPECT_NEAR(ActivationRate(1.0, 0.5, 0.015, 0.05), 0.5 / (0.015 * 1.25), 1e-12);
  EXPECT_NEAR(ActivationRate(0.0, 0.5, 0.015, 0.05), -0.5 / (0.05 / 1.25), 1e-12);
  EXPECT_NEAR(ActivationRate(0.0, 1.0, 0.015, 0.05), -1.0 / (0.05 / 2.0), 1e-12);
  // the minimum activation bounds both the target and the state
  EXPECT_NEAR(ActivationRate(0.0, 0.01, 0.015, 0.05, 0.01), 0.0, 1e-15);
  EXPECT_NEAR(ActivationRate(2.0, 1.0, 0.015, 0.05), 0.0, 1e-15);
}

TEST(Pennation, ConstantThicknessKeepsTheFibreHeight) {
  const double lopt = 0.1, phi0 = 0.3;
  EXPECT_NEAR(PennatedFiberLength(lopt * std::cos(phi0), lopt, phi0), lopt, 1e-15);
  EXPECT_NEAR(PennationAngle(lopt, lopt, phi0), phi0, 1e-15);
  const double l = 0.13;
  EXPECT_NEAR(l * std::sin(PennationAngle(l, lopt, phi0)), lopt * std::sin(phi0), 1e-15);
  EXPECT_EQ(PennationAngle(0.05, lopt, 0.0), 0.0);
  EXPECT_NEAR(PennatedFiberLength(0.07, lopt, 0.0), 0.07, 1e-15);
}

// ---------------------------------------------------------------------------------------------
// MuJoCo

TEST(MujocoCurves, ActiveForceLengthMatchesUpstreamUnitTest) {
  // engine_util_misc_test.cc MuscleGainLength: lmin 0.5, lmax 1.5
  EXPECT_EQ(MujocoActiveForceLength(0.0, 0.5, 1.5), 0.0);
  EXPECT_EQ(MujocoActiveForceLength(0.5, 0.5, 1.5), 0.0);
  EXPECT_DOUBLE_EQ(MujocoActiveForceLength(0.75, 0.5, 1.5), 0.5);
  EXPECT_DOUBLE_EQ(MujocoActiveForceLength(1.0, 0.5, 1.5), 1.0);
  EXPECT_DOUBLE_EQ(MujocoActiveForceLength(1.25, 0.5, 1.5), 0.5);
  EXPECT_EQ(MujocoActiveForceLength(1.5, 0.5, 1.5), 0.0);
  EXPECT_EQ(MujocoActiveForceLength(2.0, 0.5, 1.5), 0.0);
  // below lmin: 0 as upstream since 3.1.2 (Debian's 2.2.2 returns 1 - 0.5 x^2 < 0 there)
  EXPECT_EQ(MujocoActiveForceLength(0.3), 0.0);
}

TEST(MujocoCurves, ActiveAndPassiveForceLengthMatchMuJoCo222Table) {
  CALIPER_REQUIRE_CORPUS();
  const auto table = ReadCsv(Generated("mujoco222_muscle_curves_FL_FP.csv"));
  const int L = table.Column("L_norm"), fl = table.Column("FL_active"),
            fp = table.Column("FP_passive");
  ASSERT_GE(L, 0);
  ASSERT_GE(fl, 0);
  ASSERT_GE(fp, 0);
  ASSERT_EQ(table.rows.size(), 131u);
  EXPECT_DOUBLE_EQ(table.rows.front()[L], 0.5);  // the table starts at lmin
  // the file's prm: lengthrange = range = (0.75, 1.05), so L0 = 1 and L = length; values are
  // printed with 12 significant digits, so 1e-10 is the file's precision
  double worst = 0;
  for (const auto& row : table.rows) {
    ASSERT_GE(row[L], 0.5);
    const double Ln = MujocoNormalizedLength(row[L], 0.75, 1.05, 0.75, 1.05);
    EXPECT_NEAR(Ln, row[L], 1e-14);
    EXPECT_NEAR(MujocoActiveForceLength(Ln, 0.5, 1.6), row[fl], 1e-10) << "L " << row[L];
    EXPECT_NEAR(MujocoPassiveForceLength(Ln, 1.6, 1.3), row[fp], 1e-10) << "L " << row[L];
    worst = std::max({worst, std::abs(MujocoActiveForceLength(Ln, 0.5, 1.6) - row[fl]),
                      std::abs(MujocoPassiveForceLength(Ln, 1.6, 1.3) - row[fp])});
  }
  RecordProperty("max_abs_error", Sci(worst));
}

TEST(MujocoCurves, ForceVelocityMatchesMuJoCo222Table) {
  CALIPER_REQUIRE_CORPUS();
  const auto table = ReadCsv(Generated("mujoco222_muscle_curves_FV.csv"));
  const int V = table.Column("V_norm"), fv = table.Column("FV");
  ASSERT_GE(V, 0);
  ASSERT_GE(fv, 0);
  ASSERT_EQ(table.rows.size(), 161u);
  double worst = 0;
  for (const auto& row : table.rows) {
    EXPECT_NEAR(MujocoForceVelocity(row[V], 1.2), row[fv], 1e-10) << "V " << row[V];
    worst = std::max(worst, std::abs(MujocoForceVelocity(row[V], 1.2) - row[fv]));
  }
  RecordProperty("max_abs_error", Sci(worst));
}

TEST(MujocoCurves, ActivationDynamicsMatchMuJoCo222Table) {
  CALIPER_REQUIRE_CORPUS();
  const auto table = ReadCsv(Generated("mujoco222_muscle_activation_dynamics.csv"));
  const int ctrl = table.Column("ctrl"), act = table.Column("act"), rate = table.Column("act_dot");
  ASSERT_GE(ctrl, 0);
  ASSERT_GE(act, 0);
  ASSERT_GE(rate, 0);
  ASSERT_EQ(table.rows.size(), 49u);
  for (const auto& row : table.rows) {
    // 12 significant digits of rates up to 220 1/s
    const double expected = row[rate];
    EXPECT_NEAR(MujocoActivationRate(row[ctrl], row[act], 0.01, 0.04), expected,
                1e-10 * std::max(1.0, std::abs(expected)))
        << "ctrl " << row[ctrl] << " act " << row[act];
    // inside [0, 1] OpenSim's first-order model is the same law
    if (row[ctrl] >= 0 && row[ctrl] <= 1 && row[act] >= 0 && row[act] <= 1) {
      EXPECT_NEAR(ActivationRate(row[ctrl], row[act], 0.01, 0.04), expected,
                  1e-10 * std::max(1.0, std::abs(expected)));
    }
  }
}

TEST(MujocoCurves, NormalisationMapsTheLengthRangeOnTheRange) {
  // arm26 SF: lengthrange (0.10242022997, 0.340386464984)
  const double lo = 0.10242022997, hi = 0.340386464984;
  EXPECT_NEAR(MujocoOptimalLength(lo, hi), (hi - lo) / 0.3, 1e-15);
  EXPECT_NEAR(MujocoNormalizedLength(lo, lo, hi), 0.75, 1e-14);
  EXPECT_NEAR(MujocoNormalizedLength(hi, lo, hi), 1.05, 1e-14);
  EXPECT_NEAR(MujocoNormalizedLength(0.5 * (lo + hi), lo, hi, 0.5, 1.5), 1.0, 1e-14);
}

TEST(MujocoCurves, ForceScaleUsesScaleOverAcc0WhenForceIsNegative) {
  EXPECT_NEAR(MujocoForceScale(-1, 200, 0.558692074634), 357.978945971, 1e-8);
  EXPECT_DOUBLE_EQ(MujocoForceScale(150, 200, 0.558692074634), 150);
  EXPECT_DOUBLE_EQ(MujocoForceScale(0, 200, 0.5), 0);
}

}  // namespace
}  // namespace caliper::actuators
