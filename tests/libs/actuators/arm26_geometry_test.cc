#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "arm26.h"
#include "caliper/actuators/actuator.h"
#include "caliper/actuators/tendon_path.h"
#include "corpus.h"

namespace caliper::testing {
namespace {

using actuators::TendonPath;

constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = kPi / 180;
const char* const kTendons[] = {"SF", "SE", "EF", "EE", "BF", "BE"};

double Length(const sgal::Scene& scene, const sgal::Tendon& tendon, double qs, double qe) {
  TendonPath path;
  return path.Evaluate(Arm26Elements(scene, tendon, qs, qe)).length;
}

// the worst error seen, and where
struct Worst {
  double error = 0;
  std::string where;
  void Update(double e, const std::string& w) {
    if (e > error) {
      error = e;
      where = w;
    }
  }
};

TEST(Arm26GeometryTest, SceneIsValid) {
  const sgal::Scene scene = MakeArm26();
  EXPECT_TRUE(sgal::Validate(scene).empty());
  EXPECT_EQ(scene.tendons.size(), 6u);
  EXPECT_EQ(scene.actuators.size(), 6u);
  EXPECT_EQ(scene.obstacles.size(), 2u);
  // at zero angles the points are where the XML puts them: SF from s0 (-0.15 0 0) to s1
  const auto elements = Arm26Elements(scene, *scene.FindTendon("SF"), 0, 0);
  ASSERT_EQ(elements.size(), 3u);
  EXPECT_TRUE(elements[0].point.isApprox(Eigen::Vector3d(-0.15, 0, 0)));
  EXPECT_TRUE(elements[2].point.isApprox(Eigen::Vector3d(0.15, 0.06, 0)));
  // the elbow turns the forearm's s7 (0.11 0.05 0) about (0.5 0 0)
  const auto ef = Arm26Elements(scene, *scene.FindTendon("EF"), 0, kPi / 2);
  EXPECT_TRUE(ef[2].point.isApprox(Eigen::Vector3d(0.45, 0.11, 0)));
}

TEST(Arm26GeometryTest, LengthsAndMomentArmsMatchMuJoCo) {
  CALIPER_REQUIRE_CORPUS();
  const CsvTable table =
      ReadCsv(CorpusDir() + "/reference/mujoco222_generated/mujoco222_arm26_static.csv");
  ASSERT_EQ(table.rows.size(), 81u);
  const sgal::Scene scene = MakeArm26();
  const int c_shoulder = table.Column("shoulder_deg"), c_elbow = table.Column("elbow_deg");

  const double h = 1e-6;  // [rad] central difference step
  Worst length_error, arm_error, arm_relative, speed_error;
  for (const auto& row : table.rows) {
    const double qs = row[c_shoulder] * kDeg, qe = row[c_elbow] * kDeg;
    for (const char* name : kTendons) {
      const sgal::Tendon& tendon = *scene.FindTendon(name);
      const std::string t(name);
      const std::string where = t + " at shoulder " + std::to_string(int(row[c_shoulder])) +
                                ", elbow " + std::to_string(int(row[c_elbow])) + " deg";
      const double length = Length(scene, tendon, qs, qe);
      const double expected_length = row[table.Column("len_" + t)];
      EXPECT_NEAR(length, expected_length, 0.5e-3) << where;
      length_error.Update(std::abs(length - expected_length), where);

      const double arm[2] = {
          (Length(scene, tendon, qs + h, qe) - Length(scene, tendon, qs - h, qe)) / (2 * h),
          (Length(scene, tendon, qs, qe + h) - Length(scene, tendon, qs, qe - h)) / (2 * h)};
      const char* joint[2] = {"shoulder", "elbow"};
      for (int j = 0; j < 2; ++j) {
        const double expected = row[table.Column("J_" + t + "_" + joint[j])];
        const double error = std::abs(arm[j] - expected);
        const std::string w = where + ", d/d" + joint[j];
        EXPECT_TRUE(error <= 0.01 * std::abs(expected) || error <= 0.5e-3)
            << w << ": " << arm[j] << " m, MuJoCo " << expected << " m";
        arm_error.Update(error, w);
        if (std::abs(expected) > 0.5e-3) arm_relative.Update(error / std::abs(expected), w);

        // the analytic lengthening speed at unit joint speed is the same moment arm
        TendonPath path;
        const double speed =
            path.Evaluate(Arm26Elements(scene, tendon, qs, qe, j == 0 ? 1 : 0, j == 1 ? 1 : 0))
                .speed;
        EXPECT_NEAR(speed, arm[j], 1e-6) << w;
        speed_error.Update(std::abs(speed - expected), w);
      }
    }
  }
  std::cout << "arm26 vs MuJoCo 2.2.2 over 81 poses x 6 tendons:\n"
            << "  worst length error " << length_error.error * 1e3 << " mm (" << length_error.where
            << ")\n"
            << "  worst moment arm error (central difference) " << arm_error.error * 1e3 << " mm ("
            << arm_error.where << ")\n"
            << "  worst relative moment arm error (arms > 0.5 mm) " << arm_relative.error * 100
            << " % (" << arm_relative.where << ")\n"
            << "  worst moment arm error (analytic speed) " << speed_error.error * 1e3 << " mm ("
            << speed_error.where << ")\n";
}

TEST(Arm26GeometryTest, MusclesOnTheGeometryGiveMuJoCosForces) {
  // the builder's muscle parameters are accepted by hill_muscle, and at full activation and rest
  // the muscles on these tendon lengths pull as hard as MuJoCo's (force columns, negative = pull)
  CALIPER_REQUIRE_CORPUS();
  const CsvTable table =
      ReadCsv(CorpusDir() + "/reference/mujoco222_generated/mujoco222_arm26_static.csv");
  const sgal::Scene scene = MakeArm26();
  const int c_shoulder = table.Column("shoulder_deg"), c_elbow = table.Column("elbow_deg");
  Worst force_error;
  for (const sgal::Actuator& description : scene.actuators) {
    sgal::Actuator full = description;
    full.parameters["default_activation"] = 1;
    std::unique_ptr<actuators::TendonActuator> muscle;
    ASSERT_NO_THROW(muscle = actuators::Make(full)) << description.name;
    const sgal::Tendon& tendon = *scene.FindTendon(description.tendon);
    const int column = table.Column("force_" + description.name);
    for (const auto& row : table.rows) {
      const double length =
          Length(scene, tendon, row[c_shoulder] * kDeg, row[c_elbow] * kDeg);  // [m]
      muscle->Reset(length);
      muscle->SetCommand(1);
      const double tension = muscle->Step(length, 0, 0.005);
      const double expected = -row[column];
      EXPECT_NEAR(tension, expected, 0.01 * expected + 0.1) << description.name;
      force_error.Update(std::abs(tension - expected),
                         description.name + " at shoulder " + std::to_string(int(row[c_shoulder])) +
                             ", elbow " + std::to_string(int(row[c_elbow])) + " deg");
    }
  }
  std::cout << "arm26 muscle force at activation 1 vs MuJoCo 2.2.2: worst error "
            << force_error.error << " N (" << force_error.where << ")\n";
}

TEST(Arm26GeometryTest, SweepingTheJointsKeepsLengthsContinuous) {
  // one TendonPath per tendon carried through a slow sweep of both joints over their range: the
  // lengths agree with fresh evaluations (no side kept that MuJoCo would not take) and do not jump
  const sgal::Scene scene = MakeArm26();
  for (const char* name : kTendons) {
    const sgal::Tendon& tendon = *scene.FindTendon(name);
    TendonPath kept;
    double previous = -1;
    for (int k = 0; k <= 3000; ++k) {
      const double u = k / 3000.0;
      const double qs = 120 * kDeg * u, qe = 120 * kDeg * (0.5 - 0.5 * std::cos(6 * kPi * u));
      const double length = kept.Evaluate(Arm26Elements(scene, tendon, qs, qe)).length;
      EXPECT_NEAR(length, Length(scene, tendon, qs, qe), 1e-12) << name << " step " << k;
      if (previous >= 0) {
        EXPECT_LT(std::abs(length - previous), 2e-3) << name << " step " << k;
      }
      previous = length;
    }
  }
}

}  // namespace
}  // namespace caliper::testing
