// MuJoCo's arm26 driven by its six muscles, simulated by Caliper (Bullet, maximal coordinates)
// and compared with the trajectory Debian's MuJoCo 2.2.2 computed for the same controls.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "arm26.h"
#include "caliper/physics_bullet/bullet_scene.h"
#include "corpus.h"

namespace caliper::testing {
namespace {

TEST(Arm26Trajectory, FollowsMuJoCoUnderConstantMuscleControls) {
  CALIPER_REQUIRE_CORPUS();
  const CsvTable ref =
      ReadCsv(CorpusDir() + "/reference/mujoco222_generated/mujoco222_arm26_trajectory.csv");
  // MuJoCo has no tendon-body contact; compare like with like
  physics_bullet::Options options;
  options.tendon_body_contact = false;
  sgal::Scene arm = MakeArm26();
  // MuJoCo's step order for the muscles: force from the activation at the start of the step,
  // then an explicit Euler step of the activation
  for (auto& a : arm.actuators) a.options["integrator"] = "mujoco";
  auto scene = physics_bullet::MakeScene(arm, options);
  const std::vector<std::pair<std::string, double>> controls = {
      {"SF", 0.5}, {"SE", 0}, {"EF", 0.3}, {"EE", 0}, {"BF", 0.2}, {"BE", 0}};
  for (const auto& [name, u] : controls) scene->SetCommand(name, u);

  const int t = ref.Column("time");
  const int qs = ref.Column("q_shoulder"), qe = ref.Column("q_elbow");
  const int act_sf = ref.Column("act_SF"), len_bf = ref.Column("len_BF");
  const double limit = 120.0 * M_PI / 180;
  double worst_free = 0, worst_act = 0, worst_len = 0;
  double caliper_at_limit = -1, mujoco_at_limit = -1;
  for (const auto& row : ref.rows) {
    while (scene->time() < row[t] - 1e-9) scene->Step();
    const double shoulder = scene->GetParameter("shoulder.position");
    const double elbow = scene->GetParameter("elbow.position");
    if (std::getenv("CALIPER_VERBOSE"))
      std::printf("%.2f  %.4f %.4f  |  %.4f %.4f\n", row[t], shoulder, elbow, row[qs], row[qe]);
    if (caliper_at_limit < 0 && shoulder > limit - 0.01) caliper_at_limit = row[t];
    if (mujoco_at_limit < 0 && row[qs] > limit - 0.01) mujoco_at_limit = row[t];
    // the free motion, until the shoulder reaches its limit in either simulator
    if (caliper_at_limit < 0 && mujoco_at_limit < 0)
      worst_free = std::max({worst_free, std::abs(shoulder - row[qs]) / std::max(row[qs], 0.1),
                             std::abs(elbow - row[qe]) / std::max(row[qe], 0.1)});
    worst_act = std::max(worst_act, std::abs(scene->GetParameter("SF.activation") - row[act_sf]));
    if (caliper_at_limit < 0) worst_len = std::max(worst_len, std::abs(scene->GetParameter("BF.tendon.length") - row[len_bf]));
  }
  const auto& last = ref.rows.back();
  const double final_error = std::max(std::abs(scene->GetParameter("shoulder.position") - last[qs]),
                                      std::abs(scene->GetParameter("elbow.position") - last[qe]));
  std::printf("arm26: activation within %.1e; free motion within %.1f %% (relative, angles over "
              "0.1 rad); BF length within %.2f mm; shoulder at its limit at %.2f s (MuJoCo %.2f s); "
              "final pose within %.4f rad\n",
              worst_act, 100 * worst_free, 1e3 * worst_len, caliper_at_limit, mujoco_at_limit,
              final_error);
  // Same muscle step order as MuJoCo (integrator=mujoco): activations agree to rounding.
  EXPECT_LT(worst_act, 1e-9);
  // The free motion at MuJoCo's 5 ms step: the two first-order integrators (Bullet's in maximal
  // coordinates, MuJoCo's in generalised ones) carry different O(dt) errors; MuJoCo itself moves
  // up to 15 % differently at 5 ms than at 0.5 ms on this motion. Measured here: 17.6 % and
  // 13.7 mm; at 0.5 ms the two agree within 0.5 % (the next test), which is the physics check.
  EXPECT_LT(worst_free, 0.20);
  EXPECT_LT(worst_len, 0.015);
  // Both reach the 120 degree shoulder limit within 30 ms of each other and come to rest at the
  // limits (MuJoCo's soft limits let it sit 1 mrad beyond them, Bullet's hard ones do not).
  EXPECT_NEAR(caliper_at_limit, mujoco_at_limit, 0.03);
  EXPECT_LT(final_error, 0.005);
}

TEST(Arm26Trajectory, MatchesMuJoCoWhenBothStepFinely) {
  // tests/data/arm26_mujoco222_dt0.5ms.csv: MuJoCo 2.2.2 at 0.5 ms (bench/arm26_reference.cc)
  const char* source = std::getenv("CALIPER_SOURCE_DIR");
  ASSERT_NE(source, nullptr) << "CALIPER_SOURCE_DIR is not set: run it through ctest";
  const CsvTable ref = ReadCsv(std::string(source) + "/tests/data/arm26_mujoco222_dt0.5ms.csv");
  physics_bullet::Options options;
  options.tendon_body_contact = false;
  sgal::Scene arm = MakeArm26();
  arm.settings.time_step = 0.0005;
  for (auto& a : arm.actuators) a.options["integrator"] = "mujoco";
  auto scene = physics_bullet::MakeScene(arm, options);
  scene->SetCommand("SF", 0.5);
  scene->SetCommand("EF", 0.3);
  scene->SetCommand("BF", 0.2);
  const int t = ref.Column("time"), qs = ref.Column("q_shoulder"), qe = ref.Column("q_elbow");
  const int len_bf = ref.Column("len_BF");
  double worst = 0, worst_len = 0;
  for (const auto& row : ref.rows) {
    while (scene->time() < row[t] - 1e-9) scene->Step();
    worst = std::max({worst,
                      std::abs(scene->GetParameter("shoulder.position") - row[qs]) /
                          std::max(row[qs], 0.1),
                      std::abs(scene->GetParameter("elbow.position") - row[qe]) /
                          std::max(row[qe], 0.1)});
    worst_len = std::max(worst_len, std::abs(scene->GetParameter("BF.tendon.length") - row[len_bf]));
  }
  std::printf("arm26 at 0.5 ms over 0.6 s: joint angles within %.2f %%, BF length within %.3f mm\n",
              100 * worst, 1e3 * worst_len);
  EXPECT_LT(worst, 0.015);
  EXPECT_LT(worst_len, 0.001);
}

}  // namespace
}  // namespace caliper::testing
