// The tendon actuator kind hill_muscle through actuators::Make: activation dynamics, tension-only
// forces, MuJoCo 2.2.2's arm26 muscle forces and OpenSim's Thelen2003Muscle references.
//
// OpenSim references in ../shared/corpus/reference/opensim/ and what is checked here:
// - tugOfWar_model.osim + std_tugOfWar_states.sto + std_tugOfWar_forces.mot: reproduced. The
//   block pose of every stored state gives both muscle path lengths; driven along them with the
//   stored activation, the elastic-tendon Thelen muscle follows the stored fibre lengths and
//   tensions (ThelenTugOfWar below). The stored activations themselves come from OpenSim 3's
//   activation model (deactivation time tau_d (0.5 + 1.5 a') on a' = (a - a_min)/(1 - a_min)),
//   not from the law TENDONS.md specifies and this kind implements (tau_d / (0.5 + 1.5 a)); with
//   the model's excitations u1 = 1 - t/3, u2 = 0.05 + 0.316667 t that law differs from the file
//   by up to 0.023 in activation, so activation is prescribed from the file there.
// - block_hanging_from_muscle.osim (+ _controls.sto): its default state is reproduced (fibre
//   length) and static equilibrium is checked. Its CMC results (the block's motion under those
//   excitations) are not in the corpus, so the dynamics cannot be compared.
// - Tug_of_War_Millard_Iso.osim and Tug_of_War_*.sto: a Millard2012EquilibriumMuscle and no
//   stored outputs; its equilibrium and smoothness checks are in millard_muscle_test.cc.

#include "caliper/actuators/muscle.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "caliper/actuators/actuator.h"
#include "corpus.h"
#include "make_muscle.h"

namespace caliper::actuators {
namespace {

using caliper::testing::CorpusDir;
using caliper::testing::ReadCsv;

using test_support::MakeMuscle;

std::string Sci(double v) {
  std::ostringstream s;
  s << std::scientific << std::setprecision(2) << v;
  return s.str();
}

std::string Reference(const std::string& file) { return CorpusDir() + "/reference/" + file; }

std::string ReadText(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open");
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// the numbers inside the n-th <tag>...</tag> of an XML text
std::vector<double> XmlNumbers(const std::string& xml, const std::string& tag, int n = 0) {
  size_t pos = 0;
  for (int i = 0; i <= n; ++i) {
    pos = xml.find("<" + tag + ">", pos);
    if (pos == std::string::npos)
      throw std::runtime_error("no <" + tag + "> #" + std::to_string(n));
    pos += tag.size() + 2;
  }
  const size_t end = xml.find("</" + tag + ">", pos);
  std::stringstream s(xml.substr(pos, end - pos));
  std::vector<double> values;
  double v;
  while (s >> v) values.push_back(v);
  return values;
}
double XmlNumber(const std::string& xml, const std::string& tag, int n = 0) {
  return XmlNumbers(xml, tag, n).at(0);
}

// an OpenSim storage (.sto/.mot): header up to "endheader", a line of names, rows of numbers
struct Storage {
  std::vector<std::string> columns;
  std::vector<std::vector<double>> rows;
  int Column(const std::string& name) const {
    for (size_t i = 0; i < columns.size(); ++i)
      if (columns[i] == name) return static_cast<int>(i);
    ADD_FAILURE() << "no column '" << name << "'";
    return 0;
  }
};

Storage ReadStorage(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open");
  Storage s;
  std::string line;
  while (std::getline(in, line) && line.rfind("endheader", 0) != 0) {
  }
  while (std::getline(in, line)) {
    std::stringstream ss(line);
    if (s.columns.empty()) {
      std::string name;
      while (ss >> name) s.columns.push_back(name);
      continue;
    }
    std::vector<double> row;
    double v;
    while (ss >> v) row.push_back(v);
    if (row.empty()) continue;
    if (row.size() != s.columns.size()) throw std::runtime_error(path + ": short row");
    s.rows.push_back(std::move(row));
  }
  return s;
}

// the fine-step (1 us) RK4 solution of an activation law under constant u, advanced from a by t
template <class Rate>
double ReferenceActivation(const Rate& rate, double a, double t) {
  const int n = static_cast<int>(std::lround(t / 1e-6));
  const double h = t / std::max(n, 1);
  for (int i = 0; i < n; ++i) {
    const double k1 = rate(a), k2 = rate(a + 0.5 * h * k1), k3 = rate(a + 0.5 * h * k2),
                 k4 = rate(a + h * k3);
    a += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
  }
  return a;
}

// ---------------------------------------------------------------------------------------------
// registration, options, parameters

TEST(HillMuscle, IsRegisteredWithItsParameters) {
  const auto kinds = Kinds();
  EXPECT_NE(std::find(kinds.begin(), kinds.end(), "hill_muscle"), kinds.end());
  bool found = false;
  for (const auto& spec : KindParameters("hill_muscle"))
    if (spec.name == "optimal_fiber_length") {
      found = true;
      EXPECT_EQ(spec.unit, "m");
    }
  EXPECT_TRUE(found);
}

TEST(HillMuscle, RejectsUnknownOptionsAndCombinations) {
  const std::map<std::string, double> thelen = {{"optimal_fiber_length", 0.1},
                                                {"tendon_slack_length", 0.2}};
  auto message = [&](std::map<std::string, std::string> options,
                     std::map<std::string, double> parameters) -> std::string {
    try {
      MakeMuscle(std::move(options), std::move(parameters));
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_NE(message({{"curves", "hill1938"}}, thelen).find("unknown curves 'hill1938'"),
            std::string::npos);
  EXPECT_NE(message({{"tendon", "springy"}}, thelen).find("unknown tendon 'springy'"),
            std::string::npos);
  EXPECT_NE(message({{"colour", "red"}}, thelen).find("unknown option 'colour'"),
            std::string::npos);
  EXPECT_NE(message({{"curves", "mujoco"}, {"tendon", "elastic"}},
                    {{"lengthrange_lo", 0.1}, {"lengthrange_hi", 0.2}, {"acc0", 1}})
                .find("tendon=elastic needs curves=thelen2003"),
            std::string::npos);
  EXPECT_NE(message({}, {{"optimal_fiber_length", 0.1}}).find("'tendon_slack_length'"),
            std::string::npos);
  EXPECT_NE(message({{"curves", "mujoco"}}, {{"lengthrange_lo", 0.1}, {"acc0", 1}})
                .find("missing parameter 'lengthrange_hi'"),
            std::string::npos);
  auto with = thelen;
  with["lmin"] = 0.5;
  EXPECT_NE(message({}, with).find("parameter 'lmin' does not apply to curves=thelen2003"),
            std::string::npos);
  with = thelen;
  with["flen"] = 0.9;
  EXPECT_NE(message({}, with).find("'flen' = 0.9: must be > 1"), std::string::npos);
  EXPECT_NE(message({{"curves", "mujoco"}}, {{"lengthrange_lo", 0.1}, {"lengthrange_hi", 0.2}})
                .find("'acc0' = 0: must be > 0 when force < 0"),
            std::string::npos);
  EXPECT_NE(message({{"tendon", "elastic"}}, {{"optimal_fiber_length", 0.1},
                                              {"tendon_slack_length", 0.2},
                                              {"minimum_activation", 0}})
                .find("'minimum_activation'"),
            std::string::npos);
  EXPECT_NE(
      message({}, {{"optimal_fiber_length", 0.1}, {"tendon_slack_length", 0.2}, {"no_such", 1}})
          .find("unknown parameter 'no_such'"),
      std::string::npos);
}

TEST(HillMuscle, ParametersAreWritableAndValidated) {
  auto m = MakeMuscle({{"curves", "mujoco"}},
                      {{"lengthrange_lo", 0.1}, {"lengthrange_hi", 0.4}, {"acc0", 0.5}});
  EXPECT_DOUBLE_EQ(m->Get("max_isometric_force"), 400);   // scale 200 / acc0 0.5
  EXPECT_DOUBLE_EQ(m->Get("optimal_fiber_length"), 1.0);  // 0.3 m / (1.05 - 0.75)
  m->Set("force", 250);
  EXPECT_DOUBLE_EQ(m->Get("max_isometric_force"), 250);
  m->Set("lmin", 0.4);
  EXPECT_DOUBLE_EQ(m->Get("lmin"), 0.4);
  try {
    m->Set("range0", 1.1);
    FAIL() << "range0 above range1 accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("must be < range1 = 1.05"), std::string::npos);
  }
  EXPECT_DOUBLE_EQ(m->Get("range0"), 0.75);  // unchanged
  EXPECT_THROW(m->Set("lmax", 0.9), std::invalid_argument);
  EXPECT_THROW(m->Set("tension", 1), std::invalid_argument);
  EXPECT_THROW(m->Set("max_isometric_force", 1), std::invalid_argument);  // derived here
  EXPECT_THROW(m->Set("af", 0.3), std::out_of_range);                     // a Thelen parameter
  EXPECT_THROW(m->Get("pennation"), std::out_of_range);
  EXPECT_THROW(m->Set("activation", 1.5), std::invalid_argument);
  m->SetCommand(1.7);
  EXPECT_DOUBLE_EQ(m->command(), 1.0);
  m->SetCommand(-0.2);
  EXPECT_DOUBLE_EQ(m->command(), 0.0);
  EXPECT_THROW(m->SetCommand(std::nan("")), std::invalid_argument);
  EXPECT_THROW(m->Step(0.3, 0, 0), std::invalid_argument);

  auto t = MakeMuscle({{"tendon", "elastic"}},
                      {{"optimal_fiber_length", 0.1}, {"tendon_slack_length", 0.2}});
  t->Set("af", 0.3);
  EXPECT_DOUBLE_EQ(t->Get("af"), 0.3);
  EXPECT_THROW(t->Set("fv_linear_extrap_threshold", 0.5), std::invalid_argument);  // < 1/flen
  EXPECT_THROW(t->Set("pennation_angle", 1.5), std::invalid_argument);             // > acos(0.1)
  t->Set("fiber_length", 0.12);
  EXPECT_DOUBLE_EQ(t->Get("fiber_length"), 0.12);
  EXPECT_THROW(t->Set("fiber_length", 0.0), std::invalid_argument);
}

TEST(HillMuscle, ListsQuantitiesWithUnits) {
  auto rigid = MakeMuscle({}, {{"optimal_fiber_length", 0.1}, {"tendon_slack_length", 0.2}});
  auto elastic = MakeMuscle({{"tendon", "elastic"}},
                            {{"optimal_fiber_length", 0.1}, {"tendon_slack_length", 0.2}});
  auto mujoco = MakeMuscle({{"curves", "mujoco"}},
                           {{"lengthrange_lo", 0.1}, {"lengthrange_hi", 0.4}, {"acc0", 1}});
  auto find = [](const TendonActuator& m, const std::string& name) {
    for (const auto& q : m.Quantities())
      if (q.name == name) return q;
    ADD_FAILURE() << "no quantity " << name;
    return Quantity{};
  };
  for (const char* name : {"activation", "excitation", "fiber_length", "fiber_velocity",
                           "normalized_fiber_length", "active_force_length", "force_velocity",
                           "passive_force", "tension", "max_isometric_force"}) {
    EXPECT_NO_THROW(rigid->Get(name)) << name;
    EXPECT_NO_THROW(elastic->Get(name)) << name;
    EXPECT_NO_THROW(mujoco->Get(name)) << name;
    EXPECT_EQ(find(*mujoco, name).name, name);
  }
  EXPECT_EQ(find(*rigid, "max_isometric_force").unit, "N");
  EXPECT_TRUE(find(*rigid, "max_isometric_force").writable);
  EXPECT_TRUE(find(*rigid, "max_isometric_force").is_static);
  EXPECT_FALSE(find(*mujoco, "max_isometric_force").writable);
  EXPECT_EQ(find(*rigid, "tension").unit, "N");
  EXPECT_FALSE(find(*rigid, "tension").writable);
  EXPECT_FALSE(find(*rigid, "tension").is_static);
  EXPECT_FALSE(find(*rigid, "fiber_length").writable);
  EXPECT_TRUE(find(*elastic, "fiber_length").writable);
  EXPECT_EQ(find(*elastic, "fiber_length").unit, "m");
  EXPECT_EQ(find(*elastic, "pennation").unit, "rad");
  EXPECT_EQ(find(*mujoco, "lengthrange_lo").unit, "m");
  EXPECT_EQ(find(*rigid, "activation_time_constant").unit, "s");
  EXPECT_EQ(rigid->command_unit(), "");
  for (TendonActuator* m : {rigid.get(), elastic.get(), mujoco.get()}) {
    for (const auto& q : m->Quantities()) {
      EXPECT_NO_THROW(m->Get(q.name)) << q.name;
      if (q.writable) {
        EXPECT_NO_THROW(m->Set(q.name, m->Get(q.name))) << q.name;
      }
    }
  }
}

// ---------------------------------------------------------------------------------------------
// activation and isometric force

TEST(HillMuscle, IsometricMuscleAtOptimalLengthReachesF0AsActivationFollowsItsOde) {
  // no pennation, path = slack + optimal: fal = 1, fv = 1, fpe = 0, so tension = F0 a
  const double f0 = 1000, lopt = 0.1, lts = 0.2, dt = 1e-3;
  auto m = MakeMuscle(
      {},
      {{"max_isometric_force", f0}, {"optimal_fiber_length", lopt}, {"tendon_slack_length", lts}});
  m->Reset(lts + lopt);
  EXPECT_DOUBLE_EQ(m->Get("activation"), 0.01);  // default 0, raised to the minimum
  EXPECT_NEAR(m->tension(), 0.01 * f0, 1e-9);
  m->SetCommand(1.0);
  auto rising = [](double a) { return ActivationRate(1.0, a, 0.015, 0.05, 0.01); };
  double worst = 0, expected = 0.01;
  for (int i = 1; i <= 300; ++i) {
    const double tension = m->Step(lts + lopt, 0, dt);
    expected = ReferenceActivation(rising, expected, dt);
    worst = std::max(worst, std::abs(m->Get("activation") - expected));
    ASSERT_NEAR(tension, f0 * m->Get("activation"), 1e-9 * f0) << i;
    if (i == 15) {
      // one activation time constant in: clearly on the way, far from done
      EXPECT_GT(m->Get("activation"), 0.5);
      EXPECT_LT(m->Get("activation"), 0.8);
    }
  }
  EXPECT_LT(worst, 1e-7);  // reached: 1.6e-9 with 1 ms steps
  RecordProperty("max_activation_error_rising", Sci(worst));
  EXPECT_NEAR(m->tension(), f0, 1e-3 * f0);
  EXPECT_DOUBLE_EQ(m->Get("active_force_length"), 1.0);
  EXPECT_DOUBLE_EQ(m->Get("force_velocity"), 1.0);
  EXPECT_NEAR(m->Get("passive_force"), 0.0, 1e-9);

  // and back down with the slower, activation-dependent deactivation
  const double a1 = m->Get("activation");
  m->SetCommand(0.0);
  auto falling = [](double a) { return ActivationRate(0.0, a, 0.015, 0.05, 0.01); };
  worst = 0;
  expected = a1;
  for (int i = 1; i <= 300; ++i) {
    m->Step(lts + lopt, 0, dt);
    expected = ReferenceActivation(falling, expected, dt);
    worst = std::max(worst, std::abs(m->Get("activation") - expected));
  }
  EXPECT_LT(worst, 1e-7);  // reached: 5.5e-13
  RecordProperty("max_activation_error_falling", Sci(worst));
  // deactivation slows down as activation falls: tau_deact / 0.5 = 0.1 s near zero
  EXPECT_GT(m->Get("activation"), 0.015);
  EXPECT_LT(m->Get("activation"), 0.03);
}

TEST(HillMuscle, MujocoMuscleActivationFollowsMujocosOde) {
  auto m = MakeMuscle({{"curves", "mujoco"}},
                      {{"lengthrange_lo", 0.1}, {"lengthrange_hi", 0.4}, {"acc0", 0.5}});
  // L = 1 at 0.1 + 0.25 * 1 m: FL = FV = 1, FP = 0
  const double length = 0.35;
  m->Reset(length);
  EXPECT_DOUBLE_EQ(m->Get("activation"), 0.0);
  EXPECT_DOUBLE_EQ(m->tension(), 0.0);
  m->SetCommand(0.7);
  auto rate = [](double a) { return MujocoActivationRate(0.7, a, 0.01, 0.04); };
  double expected = 0;
  for (int i = 1; i <= 100; ++i) {
    const double tension = m->Step(length, 0, 2e-3);
    expected = ReferenceActivation(rate, expected, 2e-3);
    ASSERT_NEAR(m->Get("activation"), expected, 1e-6) << i;
    ASSERT_NEAR(tension, 400 * m->Get("activation"), 1e-9) << i;
  }
  EXPECT_NEAR(m->Get("activation"), 0.7, 1e-6);
}

TEST(HillMuscle, ActivationIsExactForAnyStepLength) {
  // the activation ODE is solved exactly over each step: long steps, short steps and a mix of
  // them reach the fine-step solution, rising and falling, for both laws
  for (const bool mujoco : {false, true}) {
    auto m = mujoco ? MakeMuscle({{"curves", "mujoco"}},
                                 {{"lengthrange_lo", 0.1}, {"lengthrange_hi", 0.4}, {"acc0", 0.5}})
                    : MakeMuscle({}, {{"optimal_fiber_length", 0.1}, {"tendon_slack_length", 0.2}});
    m->Reset(0.3);
    double expected = m->Get("activation");
    double worst = 0;
    const double steps[] = {0.05, 1e-3, 0.2, 3e-4, 0.011, 0.5, 2e-3};
    for (const double u : {0.9, 0.3, 1.0, 0.0, 0.6}) {
      m->SetCommand(u);
      for (const double dt : steps) {
        m->Step(0.3, 0, dt);
        if (mujoco)
          expected = ReferenceActivation(
              [u](double a) { return MujocoActivationRate(u, a, 0.01, 0.04); }, expected, dt);
        else
          expected = ReferenceActivation(
              [u](double a) { return ActivationRate(u, a, 0.015, 0.05, 0.01); }, expected, dt);
        worst = std::max(worst, std::abs(m->Get("activation") - expected));
      }
    }
    // reached: 1.2e-12, the rounding of the reference over its 1 us steps
    EXPECT_LT(worst, 1e-10) << (mujoco ? "mujoco" : "thelen2003");
  }
}

// ---------------------------------------------------------------------------------------------
// force: tension only, velocity, pennation

TEST(HillMuscle, TensionIsZeroWithoutActivationBelowSlackAndNeverNegative) {
  const double lopt = 0.1, lts = 0.2;
  auto m = MakeMuscle(
      {},
      {{"optimal_fiber_length", lopt}, {"tendon_slack_length", lts}, {"minimum_activation", 0}});
  m->Reset(0.25);
  EXPECT_DOUBLE_EQ(m->Get("activation"), 0.0);
  // zero activation: no force up to slack + optimal length, passive force beyond
  for (double length = 0.05; length <= lts + lopt; length += 0.01)
    EXPECT_EQ(m->Step(length, 0, 1e-3), 0.0) << length;
  EXPECT_GT(m->Step(lts + 1.2 * lopt, 0, 1e-3), 0.0);
  // full activation: still nothing while the path is shorter than the tendon
  m->SetCommand(1);
  m->Set("activation", 1);
  for (double length = 0.0; length <= lts; length += 0.02)
    EXPECT_EQ(m->Step(length, 0, 1e-3), 0.0) << length;
  EXPECT_GT(m->Step(lts + lopt, 0, 1e-3), 0.0);
  // tension only, whatever the speed (beyond the shortening limit fv < 0)
  for (double length = 0.0; length <= 0.45; length += 0.05)
    for (double speed = -3; speed <= 3; speed += 0.25) {
      const double t = m->Step(length, speed, 1e-3);
      EXPECT_GE(t, 0.0) << length << " " << speed;
      EXPECT_TRUE(std::isfinite(t));
    }
  EXPECT_EQ(m->Step(lts + lopt, -2 * 10 * lopt, 1e-3), 0.0);  // shortening at 2 vmax

  auto mj = MakeMuscle({{"curves", "mujoco"}},
                       {{"lengthrange_lo", 0.1}, {"lengthrange_hi", 0.4}, {"acc0", 0.5}});
  mj->Reset(0.3);
  for (double length = 0.0; length <= 0.35; length += 0.01)  // L <= 1
    EXPECT_EQ(mj->Step(length, 0, 1e-3), 0.0) << length;

  auto el = MakeMuscle({{"tendon", "elastic"}},
                       {{"optimal_fiber_length", lopt}, {"tendon_slack_length", lts}});
  el->SetCommand(1);
  el->Reset(0.15);
  for (int i = 0; i < 100; ++i) EXPECT_EQ(el->Step(0.15, 0, 1e-3), 0.0);
  // a path swinging from slack to far beyond optimal at up to 1.9 m/s (1.9 vmax), with the
  // excitation switching: tension stays finite and >= 0, the fibre above its shortest length
  for (int i = 0; i < 2000; ++i) {
    const double t = i * 1e-3;
    el->SetCommand((i / 150) % 2 == 0 ? 1.0 : 0.0);
    const double length = 0.3 + 0.15 * std::sin(12.6 * t);
    const double tension = el->Step(length, 0.15 * 12.6 * std::cos(12.6 * t), 1e-3);
    ASSERT_TRUE(std::isfinite(tension)) << t;
    ASSERT_GE(tension, 0.0) << t;
    ASSERT_GE(el->Get("fiber_length"), 0.01 * lopt) << t;
  }
}

TEST(HillMuscle, RigidTendonForceFollowsFibreSpeedAndPennation) {
  const double f0 = 500, lopt = 0.1, lts = 0.2, vmax = 10, dt = 1e-3;
  auto m = MakeMuscle({}, {{"max_isometric_force", f0},
                           {"optimal_fiber_length", lopt},
                           {"tendon_slack_length", lts},
                           {"default_activation", 1}});
  m->SetCommand(1);
  m->Reset(lts + lopt);
  EXPECT_DOUBLE_EQ(m->tension(), f0);
  // the step ends at path_length + speed dt; shortening at vmax / 4: Hill's 0.375
  const double speed = -0.25 * vmax * lopt;
  EXPECT_NEAR(m->Step(lts + lopt - speed * dt, speed, dt), 0.375 * f0, 1e-9 * f0);
  EXPECT_NEAR(m->Get("fiber_length"), lopt, 1e-15);
  EXPECT_NEAR(m->Get("normalized_fiber_velocity"), -0.25, 1e-12);
  EXPECT_NEAR(m->Get("force_velocity"), 0.375, 1e-12);
  // lengthening at 0.1 vmax: between 1 and flen (1.4)
  const double lengthening = 0.1 * vmax * lopt;
  const double fv = ThelenForceVelocity(0.1, 1.0);
  EXPECT_GT(fv, 1.0);
  EXPECT_LT(fv, 1.4);
  EXPECT_NEAR(m->Step(lts + lopt - lengthening * dt, lengthening, dt), fv * f0, 1e-9 * f0);
  EXPECT_NEAR(m->Get("fiber_velocity"), lengthening, 1e-15);
}

TEST(HillMuscle, PennatedFibresPullAlongTheTendonWithCosine) {
  const double f0 = 500, lopt = 0.1, lts = 0.2, phi0 = 0.4;
  auto m = MakeMuscle({}, {{"max_isometric_force", f0},
                           {"optimal_fiber_length", lopt},
                           {"tendon_slack_length", lts},
                           {"pennation_angle", phi0},
                           {"default_activation", 1}});
  m->SetCommand(1);
  m->Reset(lts + lopt * std::cos(phi0));
  EXPECT_NEAR(m->Get("fiber_length"), lopt, 1e-15);
  EXPECT_NEAR(m->Get("pennation"), phi0, 1e-12);
  EXPECT_NEAR(m->tension(), f0 * std::cos(phi0), 1e-9 * f0);
  // longer path: the fibre keeps its height, the angle shrinks
  m->Reset(lts + 0.12);
  const double lm = std::hypot(0.12, lopt * std::sin(phi0));
  EXPECT_NEAR(m->Get("fiber_length"), lm, 1e-15);
  const double expected =
      f0 * (ThelenActiveForceLength(lm / lopt) + ThelenPassiveForceLength(lm / lopt)) * 0.12 / lm;
  EXPECT_NEAR(m->tension(), expected, 1e-9 * f0);
}

TEST(HillMuscle, StiffElasticTendonBehavesLikeARigidOne) {
  // a pennated muscle lengthened at 0.05 m/s with a tendon 400 times stiffer than OpenSim's:
  // the elastic model (fibre length integrated, tendon stretch 1e-4 of its slack length at F0)
  // must give the rigid model's tension
  const double f0 = 800, lopt = 0.1, lts = 0.2, phi0 = 0.3, speed = 0.05, dt = 1e-3;
  std::map<std::string, double> p = {{"max_isometric_force", f0},  {"optimal_fiber_length", lopt},
                                     {"tendon_slack_length", lts}, {"pennation_angle", phi0},
                                     {"fmax_tendon_strain", 1e-4}, {"default_activation", 1}};
  auto elastic = MakeMuscle({{"tendon", "elastic"}}, p);
  auto rigid = MakeMuscle({}, p);
  const double start = lts + 0.95 * lopt * std::cos(phi0);
  for (auto* m : {elastic.get(), rigid.get()}) {
    m->SetCommand(1);
    m->Reset(start);
  }
  EXPECT_NEAR(elastic->tension(), rigid->tension(), 2e-3 * f0);
  EXPECT_NEAR(elastic->Get("fiber_length"), rigid->Get("fiber_length"), 1e-4 * lts);
  double worst_tension = 0, worst_speed = 0;
  for (int i = 0; i < 200; ++i) {
    const double length = start + speed * i * dt;
    const double te = elastic->Step(length, speed, dt);
    const double tr = rigid->Step(length, speed, dt);
    if (i >= 20) {
      worst_tension = std::max(worst_tension, std::abs(te - tr));
      worst_speed = std::max(
          worst_speed, std::abs(elastic->Get("fiber_velocity") - rigid->Get("fiber_velocity")));
    }
  }
  EXPECT_LT(worst_tension, 2e-4 * f0);   // reached: 0.054 N
  EXPECT_LT(worst_speed, 1e-4 * speed);  // reached: 2.1e-6 m/s
  RecordProperty("max_tension_difference", Sci(worst_tension));
  RecordProperty("max_fiber_velocity_difference", Sci(worst_speed));
  EXPECT_GT(elastic->Get("force_velocity"), 1.0);  // lengthening
  EXPECT_NEAR(elastic->Get("pennation"), rigid->Get("pennation"), 1e-3);
  EXPECT_NEAR(elastic->Get("tendon_length"), lts, 2e-4 * lts);
}

// ---------------------------------------------------------------------------------------------
// MuJoCo 2.2.2: arm26

struct Arm26Muscle {
  std::string name;
  std::vector<double> values;  // lengthrange_lo, lengthrange_hi, acc0, gainprm0..8, dynprm0..1
};

std::vector<Arm26Muscle> ReadArm26Params(const std::string& path) {
  // the header names groups of columns, so ReadCsv cannot read this file
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open");
  std::vector<Arm26Muscle> muscles;
  std::string line;
  bool header = true;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    if (header) {
      header = false;
      continue;
    }
    std::stringstream ss(line);
    std::string cell;
    Arm26Muscle m;
    std::getline(ss, m.name, ',');
    while (std::getline(ss, cell, ',')) m.values.push_back(std::stod(cell));
    muscles.push_back(m);
  }
  return muscles;
}

TEST(HillMuscle, MujocoCurvesReproduceArm26MuscleForcesOfMuJoCo222) {
  CALIPER_REQUIRE_CORPUS();
  const auto params =
      ReadArm26Params(Reference("mujoco222_generated/mujoco222_arm26_model_params.csv"));
  const auto grid = ReadCsv(Reference("mujoco222_generated/mujoco222_arm26_static.csv"));
  ASSERT_EQ(params.size(), 6u);
  ASSERT_EQ(grid.rows.size(), 81u);  // 9 x 9 shoulder x elbow angles
  double worst = 0;
  for (const auto& p : params) {
    ASSERT_EQ(p.values.size(), 14u) << p.name;
    const auto& v = p.values;
    auto m = MakeMuscle({{"curves", "mujoco"}}, {{"lengthrange_lo", v[0]},
                                                 {"lengthrange_hi", v[1]},
                                                 {"acc0", v[2]},
                                                 {"range0", v[3]},
                                                 {"range1", v[4]},
                                                 {"force", v[5]},
                                                 {"scale", v[6]},
                                                 {"lmin", v[7]},
                                                 {"lmax", v[8]},
                                                 {"vmax", v[9]},
                                                 {"fpmax", v[10]},
                                                 {"fvmax", v[11]},
                                                 {"tau_act", v[12]},
                                                 {"tau_deact", v[13]}});
    EXPECT_NEAR(m->Get("max_isometric_force"), v[6] / v[2], 1e-9) << p.name;
    const int len = grid.Column("len_" + p.name), force = grid.Column("force_" + p.name);
    ASSERT_GE(len, 0);
    ASSERT_GE(force, 0);
    m->Reset(grid.rows[0][len]);
    m->SetCommand(1);
    m->Set("activation", 1);  // act = 1, qvel = 0 in the file
    for (const auto& row : grid.rows) {
      const double tension = m->Step(row[len], 0, 1e-3);
      const double expected = -row[force];  // MuJoCo's actuator force is negative when pulling
      ASSERT_GT(expected, 0);
      EXPECT_NEAR(tension, expected, 1e-3 * expected) << p.name << " length " << row[len];
      worst = std::max(worst, std::abs(tension - expected) / expected);
    }
  }
  // reached: 6.7e-12 relative (the file prints 12 significant digits); asserted: 0.1 % per row
  EXPECT_LT(worst, 1e-9);
  RecordProperty("max_relative_error", Sci(worst));
}

// ---------------------------------------------------------------------------------------------
// OpenSim: block_hanging_from_muscle (Thelen2003Muscle with the paper's curve parameters)

struct BlockHanging {
  std::map<std::string, double> parameters;
  double default_activation = 0, default_fiber_length = 0;         // [-], [m]
  double mass = 0, g = 0, default_coordinate = 0, attachment = 0;  // [kg], [m/s^2], [m], [m]
};

BlockHanging ReadBlockHanging() {
  const std::string xml = ReadText(Reference("opensim/block_hanging_from_muscle.osim"));
  BlockHanging b;
  b.parameters = {{"max_isometric_force", XmlNumber(xml, "max_isometric_force")},
                  {"optimal_fiber_length", XmlNumber(xml, "optimal_fiber_length")},
                  {"tendon_slack_length", XmlNumber(xml, "tendon_slack_length")},
                  {"pennation_angle", XmlNumber(xml, "pennation_angle_at_optimal")},
                  {"max_contraction_velocity", XmlNumber(xml, "max_contraction_velocity")},
                  {"activation_time_constant", XmlNumber(xml, "activation_time_constant")},
                  {"deactivation_time_constant", XmlNumber(xml, "deactivation_time_constant")},
                  {"fmax_tendon_strain", XmlNumber(xml, "FmaxTendonStrain")},
                  {"fmax_muscle_strain", XmlNumber(xml, "FmaxMuscleStrain")},
                  {"kshape_active", XmlNumber(xml, "KshapeActive")},
                  {"kshape_passive", XmlNumber(xml, "KshapePassive")},
                  {"af", XmlNumber(xml, "Af")},
                  {"flen", XmlNumber(xml, "Flen")}};
  b.default_activation = XmlNumber(xml, "default_activation");
  b.default_fiber_length = XmlNumber(xml, "default_fiber_length");
  b.mass = XmlNumber(xml, "mass", 1);  // ground is the first body
  b.g = -XmlNumbers(xml, "gravity").at(1);
  b.default_coordinate = XmlNumber(xml, "default_value");
  // muscle-P1 at the ground origin, muscle-P2 at (0, 0.1, 0) on the block; the slider moves
  // the block along ground y by the coordinate
  b.attachment = XmlNumbers(xml, "location", 2).at(1);  // #0 is the joint's
  return b;
}

TEST(HillMuscle, ThelenReproducesBlockHangingDefaultFibreLength) {
  CALIPER_REQUIRE_CORPUS();
  const BlockHanging b = ReadBlockHanging();
  ASSERT_DOUBLE_EQ(b.parameters.at("max_isometric_force"), 100);
  ASSERT_DOUBLE_EQ(b.parameters.at("af"), 0.3);
  ASSERT_DOUBLE_EQ(b.parameters.at("flen"), 1.8);
  ASSERT_DOUBLE_EQ(b.parameters.at("fmax_tendon_strain"), 0.033);
  auto params = b.parameters;
  params["default_activation"] = b.default_activation;
  auto m = MakeMuscle({{"tendon", "elastic"}}, params);
  const double path = -(b.default_coordinate + b.attachment);
  EXPECT_NEAR(path, 0.353943080260763, 1e-15);
  m->SetCommand(b.default_activation);
  m->Reset(path);
  // the equilibrium fibre length at the default pose and activation 0.025 is the file's
  // default_fiber_length 0.253, which is printed to 1 mm: reached 0.25260 m
  EXPECT_NEAR(m->Get("fiber_length"), b.default_fiber_length, 0.0005);
  EXPECT_NEAR(m->Get("fiber_velocity"), 0.0, 1e-9);
  // there the muscle pulls 11.08 N on the 9.81 N block (our value; the file stores no force):
  // the default pose is not a static equilibrium, the CMC test starts the block moving
  EXPECT_NEAR(m->tension(), 11.08, 0.01);
}

TEST(HillMuscle, ThelenHoldsTheHangingBlockInStaticEquilibrium) {
  CALIPER_REQUIRE_CORPUS();
  const BlockHanging b = ReadBlockHanging();
  const Storage controls = ReadStorage(Reference("opensim/block_hanging_from_muscle_controls.sto"));
  ASSERT_EQ(controls.rows.size(), 1002u);
  const double u0 = controls.rows[0][controls.Column("muscle.excitation")];
  EXPECT_DOUBLE_EQ(u0, 0.02505871);
  auto params = b.parameters;
  params["default_activation"] = u0;
  auto m = MakeMuscle({{"tendon", "elastic"}}, params);
  m->SetCommand(u0);
  const double weight = b.mass * b.g;  // [N]
  // the path length where the equilibrium tension carries the block (tension grows with length)
  double lo = 0.3, hi = 0.4;
  for (int i = 0; i < 100; ++i) {
    const double mid = 0.5 * (lo + hi);
    m->Reset(mid);
    (m->tension() > weight ? hi : lo) = mid;
  }
  const double path = 0.5 * (lo + hi);
  m->Reset(path);
  EXPECT_NEAR(m->tension(), weight, 1e-9);
  EXPECT_NEAR(path, 0.349930, 1e-5);  // block at y = -0.44993 m (model default: -0.45394 m)
  // the force balance: fibre force (a fal + fpe) F0 cos = tendon force
  const double f0 = b.parameters.at("max_isometric_force");
  const double fibre = f0 * (u0 * m->Get("active_force_length") + m->Get("passive_force") / f0);
  EXPECT_NEAR(fibre * std::cos(m->Get("pennation")), m->tension(), 1e-9);
  EXPECT_NEAR(m->Get("force_velocity"), 1.0, 1e-9);
  // held there with the same excitation, it stays: no fibre motion, the same tension
  const double lm = m->Get("fiber_length");
  for (int i = 0; i < 1000; ++i) m->Step(path, 0, 1e-3);
  EXPECT_NEAR(m->tension(), weight, 1e-6);
  EXPECT_NEAR(m->Get("fiber_length"), lm, 1e-10);
  EXPECT_NEAR(m->Get("fiber_velocity"), 0.0, 1e-8);
}

// ---------------------------------------------------------------------------------------------
// OpenSim: tugOfWar (two Thelen2003Muscles with OpenSim's default curves, elastic tendons)

// path length of a tugOfWar muscle from a state row: the block's free joint sits at (0, 0.05, 0)
// in ground, rotates by body-fixed X-Y-Z angles and translates; the muscle runs from `ground`
// (ground frame) to `on_block` (block frame)
double TugPathLength(const Storage& s, const std::vector<double>& row, const Eigen::Vector3d& joint,
                     const Eigen::Vector3d& ground, const Eigen::Vector3d& on_block) {
  const std::string j = "blockToGround_";
  const Eigen::Matrix3d r =
      (Eigen::AngleAxisd(row[s.Column(j + "xRotation")], Eigen::Vector3d::UnitX()) *
       Eigen::AngleAxisd(row[s.Column(j + "yRotation")], Eigen::Vector3d::UnitY()) *
       Eigen::AngleAxisd(row[s.Column(j + "zRotation")], Eigen::Vector3d::UnitZ()))
          .toRotationMatrix();
  const Eigen::Vector3d origin =
      joint + Eigen::Vector3d(row[s.Column(j + "xTranslation")], row[s.Column(j + "yTranslation")],
                              row[s.Column(j + "zTranslation")]);
  return (origin + r * on_block - ground).norm();
}

TEST(HillMuscle, ThelenElasticTendonReproducesTugOfWarFibreLengthsAndTensions) {
  CALIPER_REQUIRE_CORPUS();
  const std::string xml = ReadText(Reference("opensim/tugOfWar_model.osim"));
  const Storage states = ReadStorage(Reference("opensim/std_tugOfWar_states.sto"));
  const Storage forces = ReadStorage(Reference("opensim/std_tugOfWar_forces.mot"));
  ASSERT_EQ(states.rows.size(), 2933u);
  ASSERT_EQ(forces.rows.size(), states.rows.size());
  struct Muscle {
    std::string name;
    Eigen::Vector3d ground, on_block;
  };
  auto vec = [&](const std::string& tag, int n) {
    const std::vector<double> v = XmlNumbers(xml, tag, n);
    return Eigen::Vector3d(v.at(0), v.at(1), v.at(2));
  };
  const Eigen::Vector3d joint = vec("location_in_parent", 0);  // the block's free joint
  EXPECT_DOUBLE_EQ(joint.y(), 0.05);
  // muscle1-point1/2 and muscle2-point1/2 (<location> #1-#4; #0 is the joint's)
  const Muscle muscles[] = {{"muscle1", vec("location", 1), vec("location", 2)},
                            {"muscle2", vec("location", 3), vec("location", 4)}};
  EXPECT_DOUBLE_EQ(muscles[1].ground.z(), 0.35);
  EXPECT_DOUBLE_EQ(muscles[1].on_block.z(), 0.05);
  for (int k = 0; k < 2; ++k) {
    const Muscle& mu = muscles[k];
    const int act = states.Column(mu.name + ".activation");
    const int fib = states.Column(mu.name + ".fiber_length");
    const int ten = forces.Column(mu.name);
    // OpenSim's default curves (FmaxTendonStrain 0.04, Flen 1.4, ...) are the kind's defaults
    auto m = MakeMuscle({{"tendon", "elastic"}},
                        {{"max_isometric_force", XmlNumber(xml, "max_isometric_force", k)},
                         {"optimal_fiber_length", XmlNumber(xml, "optimal_fiber_length", k)},
                         {"tendon_slack_length", XmlNumber(xml, "tendon_slack_length", k)},
                         {"pennation_angle", XmlNumber(xml, "pennation_angle_at_optimal", k)},
                         {"default_activation", states.rows[0][act]}});
    std::vector<double> path;
    for (const auto& row : states.rows)
      path.push_back(TugPathLength(states, row, joint, mu.ground, mu.on_block));
    // the initial state is OpenSim's fibre equilibrium
    m->SetCommand(states.rows[0][act]);
    m->Reset(path[0]);
    EXPECT_NEAR(m->Get("fiber_length"), states.rows[0][fib], 1e-5) << mu.name;
    EXPECT_NEAR(m->tension(), forces.rows[0][ten], 1.0) << mu.name;
    // then along the stored motion (steps of 0.1 to 5.8 ms), activation prescribed per interval
    double worst_length = 0, worst_tension = 0;
    for (size_t i = 1; i < states.rows.size(); ++i) {
      const double dt = states.rows[i][0] - states.rows[i - 1][0];
      const double a = 0.5 * (states.rows[i - 1][act] + states.rows[i][act]);
      m->Set("activation", a);
      m->SetCommand(a);
      const double tension = m->Step(path[i - 1], (path[i] - path[i - 1]) / dt, dt);
      ASSERT_NEAR(forces.rows[i][0], states.rows[i][0], 1e-9);
      worst_length = std::max(worst_length, std::abs(m->Get("fiber_length") - states.rows[i][fib]));
      worst_tension = std::max(worst_tension, std::abs(tension - forces.rows[i][ten]));
    }
    // upstream tolerances: 0.1 for states, 10 N for these forces; reached: fibre length within
    // 2.1e-6 m (muscle1) / 5.0e-6 m (muscle2), tension within 0.88 N / 1.74 N, mostly the
    // scatter of the stored forces (+-0.6 N from row to row) around a smooth curve
    EXPECT_LT(worst_length, 1e-5) << mu.name;
    EXPECT_LT(worst_tension, 2.5) << mu.name;
    RecordProperty(mu.name + "_max_fiber_length_error", Sci(worst_length));
    RecordProperty(mu.name + "_max_tension_error", Sci(worst_tension));
  }
}

}  // namespace
}  // namespace caliper::actuators
