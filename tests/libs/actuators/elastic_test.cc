// Series-elastic elements: the Zener step response against its closed form (TENDONS.md), the
// tension-only springs, the factory from an actuator description.
#include "caliper/actuators/elastic.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace caliper::actuators {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kE0 = 0.694e6;            // [Pa]
constexpr double kE1 = 0.2116e6;           // [Pa]
constexpr double kMu = 277788.48;          // [Pa s]
constexpr double kArea = kPi * 25e-6 / 4;  // pi (5 mm)^2 / 4 [m^2]
constexpr double kL0 = 0.01;               // [m]
constexpr double kStrain = 0.5;

ZenerParameters Reference() {
  ZenerParameters p;
  p.e0 = kE0;
  p.e1 = kE1;
  p.mu = kMu;
  p.area = kArea;
  p.rest_length = kL0;
  return p;
}

// F(t) after a strain step at t = 0
double ZenerStepForce(double t) { return kArea * kStrain * (kE0 + kE1 * std::exp(-t * kE1 / kMu)); }

bool Contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

TEST(ZenerElement, ReferenceStepGivesTheDocumentedForces) {
  EXPECT_NEAR(ZenerStepForce(0), 8.89, 0.005);
  EXPECT_NEAR(ZenerStepForce(1e6), 6.81, 0.005);
  ZenerElement zener(Reference());
  EXPECT_NEAR(zener.relaxation_time(), 1.313, 0.0005);
  zener.Reset(kL0);
  EXPECT_EQ(zener.Force(kL0, 0, 0), 0);
  EXPECT_NEAR(zener.Force(kL0 * (1 + kStrain), 0, 0), 8.89, 0.005);
  EXPECT_NEAR(zener.strain(), kStrain, 1e-12);
  EXPECT_NEAR(zener.stress(), (kE0 + kE1) * kStrain, 1e-6);
}

TEST(ZenerElement, RelaxationFollowsTheClosedFormOverTheWholeCurve) {
  ZenerElement zener(Reference());
  zener.Reset(kL0);
  const double length = kL0 * (1 + kStrain);
  zener.Force(length, 0, 0);  // the step
  const double dt = 1e-3;
  double worst = 0;
  for (int i = 1; i <= 10000; ++i) {
    const double force = zener.Force(length, 0, dt);
    worst = std::max(worst, std::abs(force / ZenerStepForce(i * dt) - 1));
  }
  EXPECT_LT(worst, 0.005);
  EXPECT_LT(worst, 1e-9);  // the update is exact for a constant strain
  EXPECT_NEAR(zener.Force(length, 0, dt), 6.81, 0.005);
}

TEST(ZenerElement, RampedStepOverOneMillisecondTracksTheClosedForm) {
  for (double dt : {1e-3, 1e-2}) {
    ZenerElement zener(Reference());
    zener.Reset(kL0);
    const double length = kL0 * (1 + kStrain);
    double worst = 0;
    const int steps = static_cast<int>(std::lround(8.0 / dt));
    for (int i = 1; i <= steps; ++i) {
      const double force = zener.Force(length, 0, dt);  // first step: a ramp over dt
      if (i >= 2) worst = std::max(worst, std::abs(force / ZenerStepForce(i * dt) - 1));
    }
    // a ramp over dt instead of a step delays the curve by dt / 2
    EXPECT_LT(worst, 0.005) << "dt " << dt;
    EXPECT_GT(worst, 0) << "dt " << dt;
  }
}

TEST(ZenerElement, IsSlackBelowRestLengthAndNeverPushes) {
  ZenerElement zener(Reference());
  zener.Reset(kL0);
  EXPECT_EQ(zener.Force(0.9 * kL0, -1, 1e-3), 0);
  EXPECT_EQ(zener.strain(), 0);
  // relaxed at strain 0.5, then dropped at once to strain 0.01: the Maxwell arm pulls the
  // stress below zero, the element goes slack instead of pushing
  zener.Reset(kL0 * 1.5);
  EXPECT_NEAR(zener.Force(kL0 * 1.5, 0, 1e-3), kArea * kE0 * 0.5, 1e-9);
  EXPECT_EQ(zener.Force(kL0 * 1.01, 0, 0), 0);
  EXPECT_LT(zener.stress(), -0.9e5);
  EXPECT_EQ(zener.Peek(kL0 * 1.01, 0, 1.0), 0);
  // and recovers the relaxed force E0 e A0 as the arm relaxes
  for (int i = 0; i < 30000; ++i) zener.Force(kL0 * 1.01, 0, 1e-3);
  EXPECT_NEAR(zener.Force(kL0 * 1.01, 0, 1e-3), kArea * kE0 * 0.01, 1e-6);
}

TEST(ZenerElement, PeekDoesNotChangeTheState) {
  ZenerElement zener(Reference());
  zener.Reset(kL0);
  const double peeked = zener.Peek(kL0 * 1.5, 0, 0);
  EXPECT_NEAR(peeked, 8.89, 0.005);
  EXPECT_EQ(zener.strain(), 0);
  EXPECT_EQ(zener.Force(kL0 * 1.5, 0, 0), peeked);
  EXPECT_NEAR(zener.RelaxedLength(kArea * kE0 * 0.2), kL0 * 1.2, 1e-12);
}

TEST(LinearSpringDamper, PullsWithSpringAndDamperOnlyInTension) {
  LinearSpringDamper spring(200, 5, 0.1);
  EXPECT_NEAR(spring.Force(0.12, 0.1, 1e-3), 200 * 0.02 + 5 * 0.1, 1e-12);
  EXPECT_NEAR(spring.Force(0.12, -0.2, 1e-3), 200 * 0.02 - 5 * 0.2, 1e-12);
  // slack: no force, whatever the speed
  EXPECT_EQ(spring.Force(0.09, 1.0, 1e-3), 0);
  EXPECT_EQ(spring.Force(0.1, 1.0, 1e-3), 0);
  // shortening fast while stretched: the damper would push; it does not
  EXPECT_EQ(spring.Force(0.101, -1.0, 1e-3), 0);
  EXPECT_NEAR(spring.RelaxedLength(10), 0.15, 1e-12);
  EXPECT_EQ(spring.RelaxedLength(0), 0.1);
}

TEST(PolynomialSpring, SumsPowersOfTheExtension) {
  PolynomialSpring spring({100, 1e4, 1e6}, 2, 0.2);
  EXPECT_NEAR(spring.Force(0.21, 0, 1e-3), 1 + 1 + 1, 1e-12);
  EXPECT_NEAR(spring.Force(0.22, 0, 1e-3), 2 + 4 + 8, 1e-12);
  EXPECT_NEAR(spring.Force(0.21, 0.5, 1e-3), 3 + 1, 1e-12);
  EXPECT_EQ(spring.Force(0.19, 0.5, 1e-3), 0);
  EXPECT_EQ(spring.Force(0.21, -5, 1e-3), 0);
  EXPECT_NEAR(spring.RelaxedLength(14), 0.22, 1e-12);
  EXPECT_NEAR(spring.Get("poly_c3"), 1e6, 0);
  EXPECT_EQ(spring.Get("poly_c5"), 0);
  EXPECT_THROW(PolynomialSpring({1, 2, 3, 4, 5, 6}, 0, 0.1), std::invalid_argument);
  PolynomialSpring flat({0}, 0, 0.1);
  EXPECT_THROW(flat.RelaxedLength(1), std::invalid_argument);
}

TEST(TableSpring, InterpolatesFromTheOriginAndExtrapolatesTheLastSegment) {
  TableSpring spring(TableSpring::Parse("0.01 1; 0.02 5"), 0, 0.1);
  EXPECT_NEAR(spring.Force(0.105, 0, 1e-3), 0.5, 1e-12);
  EXPECT_NEAR(spring.Force(0.115, 0, 1e-3), 3, 1e-12);
  EXPECT_NEAR(spring.Force(0.13, 0, 1e-3), 9, 1e-12);
  EXPECT_EQ(spring.Force(0.099, 0, 1e-3), 0);
  EXPECT_NEAR(spring.RelaxedLength(3), 0.115, 1e-12);
  EXPECT_NEAR(spring.RelaxedLength(9), 0.13, 1e-12);
  EXPECT_EQ(TableSpring::Parse("0.01, 1, 0.02, 5").size(), 2u);
  EXPECT_THROW(TableSpring::Parse("0.01 1; 0.02"), std::invalid_argument);
  EXPECT_THROW(TableSpring::Parse("0.01 one"), std::invalid_argument);
  EXPECT_THROW(TableSpring(TableSpring::Parse("0.02 1; 0.01 5"), 0, 0.1), std::invalid_argument);
}

TEST(ElasticElement, GetsAndSetsParametersAndRejectsBadValues) {
  LinearSpringDamper spring(200, 5, 0.1);
  spring.Set("stiffness", 300);
  EXPECT_EQ(spring.Get("stiffness"), 300);
  EXPECT_NEAR(spring.Force(0.12, 0, 1e-3), 6, 1e-12);
  try {
    spring.Set("stiffness", -1);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_TRUE(Contains(e.what(), "stiffness")) << e.what();
    EXPECT_TRUE(Contains(e.what(), "N/m")) << e.what();
  }
  EXPECT_THROW(spring.Set("damping", std::nan("")), std::invalid_argument);
  EXPECT_THROW(spring.Get("zener_E0"), std::out_of_range);
  EXPECT_EQ(spring.Get("stiffness"), 300);
  ZenerElement zener(Reference());
  EXPECT_THROW(zener.Set("stress", 1), std::invalid_argument);
  EXPECT_EQ(zener.Quantities().size(), 7u);
  zener.Set("zener_E0", 2 * kE0);
  zener.Reset(kL0 * 1.5);
  EXPECT_NEAR(zener.Force(kL0 * 1.5, 0, 1e-3), 2 * kE0 * 0.5 * kArea, 1e-9);
}

TEST(ElasticElement, FactoryReadsTheOptionsAndParameters) {
  sgal::Actuator a;
  a.name = "shin";
  a.kind = "dc_motor_tendon";
  EXPECT_EQ(MakeElasticElement(a)->kind(), "linear");
  a.options["elastic"] = "zener";
  a.parameters["zener_E0"] = kE0;
  a.parameters["rest_length"] = kL0;
  const auto zener = MakeElasticElement(a);
  EXPECT_EQ(zener->kind(), "zener");
  EXPECT_NEAR(zener->Peek(kL0 * 1.5, 0, 0), 8.89, 0.005);
  a.options["elastic"] = "polynomial";
  a.parameters["poly_c2"] = 1e4;
  EXPECT_NEAR(MakeElasticElement(a)->Peek(kL0 + 0.01, 0, 0), 1, 1e-12);
  a.options["elastic"] = "table";
  try {
    MakeElasticElement(a);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_TRUE(Contains(e.what(), "shin")) << e.what();
    EXPECT_TRUE(Contains(e.what(), "elastic_table")) << e.what();
  }
  a.options["elastic_table"] = "0.01 2";
  EXPECT_NEAR(MakeElasticElement(a)->Peek(kL0 + 0.005, 0, 0), 1, 1e-12);
  a.options["elastic"] = "rubber";
  try {
    MakeElasticElement(a);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_TRUE(Contains(e.what(), "shin")) << e.what();
    EXPECT_TRUE(Contains(e.what(), "rubber")) << e.what();
  }
  a.options["elastic"] = "linear";
  a.parameters["stiffness"] = 0;
  try {
    MakeElasticElement(a);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_TRUE(Contains(e.what(), "shin")) << e.what();
    EXPECT_TRUE(Contains(e.what(), "stiffness")) << e.what();
  }
}

// ---------------------------------------------------------------------------------------------
// the slopes and affine ranges a motor's Newton iteration uses

// the elements of this file in a state where each has its kinks within reach
std::vector<std::unique_ptr<ElasticElement>> Elements() {
  std::vector<std::unique_ptr<ElasticElement>> elements;
  elements.push_back(std::make_unique<LinearSpringDamper>(200, 5, 0.1));
  auto zener = std::make_unique<ZenerElement>(Reference());
  zener->Reset(kL0 * 1.2);
  zener->Force(kL0 * 1.3, 0, 1e-3);  // the Maxwell arm loaded
  elements.push_back(std::move(zener));
  elements.push_back(
      std::make_unique<PolynomialSpring>(std::vector<double>{100, 1e4, 1e6}, 2, 0.1));
  elements.push_back(std::make_unique<TableSpring>(TableSpring::Parse("0.01 1; 0.02 5"), 3, 0.1));
  return elements;
}

TEST(ElasticElement, SlopesAreTheDerivativesOfPeek) {
  for (const auto& element : Elements()) {
    const double rest = element->rest_length();
    for (double extension : {0.13 * rest, 0.27 * rest, 0.6 * rest}) {
      for (double rate : {-0.01, 0.0, 0.3}) {
        const double length = rest + extension;
        double d_length;
        double d_rate;
        const double force = element->PeekWithSlopes(length, rate, 1e-3, &d_length, &d_rate);
        EXPECT_EQ(force, element->Peek(length, rate, 1e-3)) << element->kind();
        const double dl = 1e-7 * rest;
        const double numeric_length =
            (element->Peek(length + dl, rate, 1e-3) - element->Peek(length - dl, rate, 1e-3)) /
            (2 * dl);
        const double numeric_rate =
            (element->Peek(length, rate + 1e-6, 1e-3) - element->Peek(length, rate - 1e-6, 1e-3)) /
            2e-6;
        EXPECT_NEAR(d_length, numeric_length, 1e-6 * (1 + std::abs(numeric_length)))
            << element->kind() << " extension " << extension << " rate " << rate;
        EXPECT_NEAR(d_rate, numeric_rate, 1e-6 * (1 + std::abs(numeric_rate)))
            << element->kind() << " extension " << extension << " rate " << rate;
      }
    }
  }
}

TEST(ElasticElement, PeekAlongALineIsAffineWithinItsRange) {
  // lines through taut and slack states, some crossing the rest length or a vanishing force
  for (const auto& element : Elements()) {
    const double rest = element->rest_length();
    for (double start : {-0.2, 0.01, 0.3}) {
      for (double d_length : {-0.5 * rest, 0.2 * rest}) {
        for (double d_rate : {-3.0, 0.0, 2.0}) {
          const double length = rest * (1 + start);
          const double rate = 0.05;
          double slope;
          double low;
          double high;
          const double force =
              element->PeekAlong(length, rate, 1e-3, d_length, d_rate, &slope, &low, &high);
          const std::string where = element->kind() + " start " + std::to_string(start) +
                                    " d_length " + std::to_string(d_length) + " d_rate " +
                                    std::to_string(d_rate);
          EXPECT_EQ(force, element->Peek(length, rate, 1e-3)) << where;
          ASSERT_LE(low, 0) << where;
          ASSERT_GE(high, 0) << where;
          // the slope is the derivative along the line
          double d_l;
          double d_r;
          element->PeekWithSlopes(length, rate, 1e-3, &d_l, &d_r);
          EXPECT_NEAR(slope, d_l * d_length + d_r * d_rate, 1e-9 * (1 + std::abs(slope))) << where;
          // and holds exactly over the range it claims (up to 2 units of the line)
          for (double t : {0.0, 0.25, 0.5, 0.999, 1.0}) {
            for (double x : {t * std::max(low, -2.0), t * std::min(high, 2.0)}) {
              const double peeked = element->Peek(length + d_length * x, rate + d_rate * x, 1e-3);
              EXPECT_NEAR(peeked, force + slope * x, 1e-9 * (1 + std::abs(peeked)))
                  << where << " x " << x;
            }
          }
        }
      }
    }
  }
  // the linear and Zener elements know their ranges: up to the kink, not beyond
  LinearSpringDamper spring(200, 0, 0.1);
  double slope;
  double low;
  double high;
  EXPECT_NEAR(spring.PeekAlong(0.12, 0, 1e-3, -0.01, 0, &slope, &low, &high), 4, 1e-12);
  EXPECT_EQ(slope, -2);
  EXPECT_NEAR(high, 2, 1e-8);  // slack from x = 2 on
  EXPECT_LT(high, 2);
  EXPECT_LT(low, -1e299);
  ZenerElement zener(Reference());
  zener.Reset(kL0 * 1.5);
  EXPECT_GT(zener.PeekAlong(kL0 * 1.5, 0, 1e-3, -kL0, 0, &slope, &low, &high), 0);
  EXPECT_GT(high, 0.1);
  EXPECT_LT(high, 0.5);  // the stress reaches zero before the strain does
}

TEST(ZenerElement, FactorsForSeveralStepLengthsGiveTheSameForcesAsAFreshElement) {
  // a motor peeks at two step lengths in turn; a third and a change of E1 must not mix them up
  ZenerElement zener(Reference());
  zener.Reset(kL0);
  zener.Force(kL0 * 1.4, 0, 1e-3);
  for (int round = 0; round < 3; ++round) {
    for (double dt : {2.9e-5, 1e-4, 3e-3, 1e-4, 0.0, 2.9e-5}) {
      ZenerElement fresh(Reference());
      fresh.Reset(kL0);
      fresh.Force(kL0 * 1.4, 0, 1e-3);
      for (int i = 0; i < round; ++i) {
        zener.Force(kL0 * (1.4 + 0.01 * i), 0, 1e-3);
        fresh.Force(kL0 * (1.4 + 0.01 * i), 0, 1e-3);
      }
      EXPECT_EQ(zener.Peek(kL0 * 1.45, 0, dt), fresh.Peek(kL0 * 1.45, 0, dt)) << dt;
      zener.Reset(kL0);
      zener.Force(kL0 * 1.4, 0, 1e-3);
    }
  }
  zener.Peek(kL0 * 1.45, 0, 1e-3);  // cached for E1
  zener.Set("zener_E1", 2 * kE1);
  zener.Reset(kL0);
  zener.Force(kL0 * 1.4, 0, 1e-3);
  ZenerParameters p = Reference();
  p.e1 = 2 * kE1;
  ZenerElement changed(p);
  changed.Reset(kL0);
  changed.Force(kL0 * 1.4, 0, 1e-3);
  EXPECT_EQ(zener.Peek(kL0 * 1.45, 0, 1e-3), changed.Peek(kL0 * 1.45, 0, 1e-3));
}

}  // namespace
}  // namespace caliper::actuators
