// The tendon actuator kind hill_muscle with curves=millard2012 (OpenSim's
// Millard2012EquilibriumMuscle): Tug_of_War_Millard_Iso.osim read with libxml2 and driven by its
// testAnalyzeTool inputs (Tug_of_War_ConstantVelocity*.sto): the fibre-tendon equilibrium holds at
// every state and the force changes smoothly. Also: rigid against elastic with a stiff tendon,
// fibre damping acting only while the fibre moves, second-order convergence of the elastic step
// with the path moving through the step, and the option and parameter errors.

#include <gtest/gtest.h>
#include <libxml/parser.h>
#include <libxml/xpath.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <iostream>
#include <limits>
#include <map>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "caliper/actuators/actuator.h"
#include "caliper/actuators/muscle.h"
#include "corpus.h"
#include "make_muscle.h"

namespace caliper::actuators {
namespace {

using caliper::testing::CorpusDir;

using test_support::MakeMuscle;

std::string MakeError(std::map<std::string, std::string> options,
                      std::map<std::string, double> parameters) {
  try {
    MakeMuscle(std::move(options), std::move(parameters));
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

// an .osim file through libxml2's XPath: the text of the one element an expression selects
class Osim {
 public:
  explicit Osim(const std::string& path) : path_(path) {
    doc_ = xmlReadFile(path.c_str(), nullptr, XML_PARSE_NONET);
    if (doc_ == nullptr) throw std::runtime_error(path + ": not well-formed XML");
    context_ = xmlXPathNewContext(doc_);
  }
  ~Osim() {
    xmlXPathFreeContext(context_);
    xmlFreeDoc(doc_);
  }
  Osim(const Osim&) = delete;
  Osim& operator=(const Osim&) = delete;

  std::string Text(const std::string& xpath) const {
    xmlXPathObjectPtr r =
        xmlXPathEvalExpression(reinterpret_cast<const xmlChar*>(xpath.c_str()), context_);
    const int n = r != nullptr && r->nodesetval != nullptr ? r->nodesetval->nodeNr : 0;
    if (n != 1) {
      xmlXPathFreeObject(r);
      throw std::runtime_error(path_ + ": " + std::to_string(n) + " elements match " + xpath);
    }
    xmlChar* content = xmlNodeGetContent(r->nodesetval->nodeTab[0]);
    std::string text(reinterpret_cast<const char*>(content));
    xmlFree(content);
    xmlXPathFreeObject(r);
    return text;
  }
  std::vector<double> Numbers(const std::string& xpath) const {
    std::istringstream s(Text(xpath));
    std::vector<double> v;
    for (double x; s >> x;) v.push_back(x);
    return v;
  }
  double Number(const std::string& xpath) const {
    const auto v = Numbers(xpath);
    if (v.size() != 1) throw std::runtime_error(path_ + ": " + xpath + " is not one number");
    return v[0];
  }
  // an element left empty in the file (OpenSim then uses its default)
  bool Empty(const std::string& xpath) const { return Numbers(xpath).empty(); }

 private:
  std::string path_;
  xmlDocPtr doc_ = nullptr;
  xmlXPathContextPtr context_ = nullptr;
};

// an OpenSim storage (.sto): header up to "endheader", a line of names, rows of numbers
struct Storage {
  std::vector<std::string> columns;
  std::vector<std::vector<double>> rows;
  int Column(const std::string& name) const {
    for (size_t i = 0; i < columns.size(); ++i)
      if (columns[i] == name) return static_cast<int>(i);
    throw std::runtime_error("no column '" + name + "'");
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
    std::istringstream ss(line);
    if (s.columns.empty()) {
      for (std::string name; ss >> name;) s.columns.push_back(name);
      continue;
    }
    std::vector<double> row;
    for (double v; ss >> v;) row.push_back(v);
    if (row.empty()) continue;
    if (row.size() != s.columns.size()) throw std::runtime_error(path + ": short row");
    s.rows.push_back(std::move(row));
  }
  return s;
}

// The muscle of Tug_of_War_Millard_Iso.osim as hill_muscle parameters, and the path length as a
// function of the block's slider coordinate.
struct TugOfWar {
  std::map<std::string, double> parameters;
  bool elastic = true;
  double default_activation = 0;
  Eigen::Vector3d ground_point, block_point, child_location;
  // the slider's joint frames have the same orientation in ground and block, rotated so that the
  // joint's x axis is ground z: the block origin is at (0, 0, q) - child_location
  double PathLength(double q) const {
    const Eigen::Vector3d block_origin = Eigen::Vector3d(0, 0, q) - child_location;
    return (ground_point - (block_origin + block_point)).norm();
  }
};

TugOfWar ReadTugOfWar(const std::string& path) {
  const Osim osim(path);
  const std::string m = "//Millard2012EquilibriumMuscle[@name='LeftMuscle']/";
  TugOfWar t;
  auto& p = t.parameters;
  for (const char* name : {"max_isometric_force", "optimal_fiber_length", "tendon_slack_length",
                           "max_contraction_velocity", "minimum_activation"})
    p[name] = osim.Number(m + name);
  p["pennation_angle"] = osim.Number(m + "pennation_angle_at_optimal");
  t.elastic = osim.Text(m + "ignore_tendon_compliance").find("false") != std::string::npos;
  t.default_activation = osim.Number(m + "default_activation");
  p["default_activation"] = t.default_activation;
  const std::string fal = m + "ActiveForceLengthCurve/";
  for (const char* name :
       {"min_norm_active_fiber_length", "transition_norm_fiber_length",
        "max_norm_active_fiber_length", "shallow_ascending_slope", "minimum_value"})
    p[name] = osim.Number(fal + name);
  const std::string fv = m + "ForceVelocityCurve/";
  for (const char* name : {"concentric_slope_at_vmax", "concentric_slope_near_vmax",
                           "isometric_slope", "eccentric_slope_at_vmax",
                           "eccentric_slope_near_vmax", "max_eccentric_velocity_force_multiplier"})
    p[name] = osim.Number(fv + name);
  // empty stiffness and curviness elements: OpenSim's defaults for the given strains
  const std::string fpe = m + "FiberForceLengthCurve/";
  p["fiber_strain_at_zero_force"] = osim.Number(fpe + "strain_at_zero_force");
  p["fiber_strain_at_one_norm_force"] = osim.Number(fpe + "strain_at_one_norm_force");
  EXPECT_TRUE(osim.Empty(fpe + "stiffness_at_one_norm_force"));
  p["fiber_stiffness_at_one_norm_force"] =
      2 / (p["fiber_strain_at_one_norm_force"] - p["fiber_strain_at_zero_force"]);
  const std::string fse = m + "TendonForceLengthCurve/";
  p["tendon_strain_at_one_norm_force"] = osim.Number(fse + "strain_at_one_norm_force");
  EXPECT_TRUE(osim.Empty(fse + "stiffness_at_one_norm_force"));
  p["tendon_stiffness_at_one_norm_force"] = 1.375 / p["tendon_strain_at_one_norm_force"];
  const auto ground = osim.Numbers(m + "GeometryPath//PathPoint[body='ground']/location");
  const auto block = osim.Numbers(m + "GeometryPath//PathPoint[body='block']/location");
  const auto child = osim.Numbers("//SliderJoint[@name='ground_block']/location");
  const auto parent_rotation =
      osim.Numbers("//SliderJoint[@name='ground_block']/orientation_in_parent");
  const auto child_rotation = osim.Numbers("//SliderJoint[@name='ground_block']/orientation");
  EXPECT_EQ(parent_rotation, child_rotation);  // what PathLength assumes
  EXPECT_NEAR(parent_rotation.at(1), -M_PI / 2, 1e-12);
  t.ground_point = {ground.at(0), ground.at(1), ground.at(2)};
  t.block_point = {block.at(0), block.at(1), block.at(2)};
  t.child_location = {child.at(0), child.at(1), child.at(2)};
  return t;
}

std::string Reference(const std::string& file) { return CorpusDir() + "/reference/" + file; }

// the balance from the reported quantities and the curves themselves: tendon force and the
// fibres' force along the tendon [N]
struct Balance {
  double tendon = 0, fibre = 0;
};
Balance BalanceOf(const TendonActuator& m, const MillardMuscleParameters& p) {
  const MillardCurve fal = MillardActiveForceLengthCurve(p.curves);
  const MillardCurve fv = MillardForceVelocityCurve(p.curves);
  const MillardCurve fpe = MillardFiberForceLengthCurve(p.curves);
  const MillardCurve fse = MillardTendonForceLengthCurve(p.curves);
  const double l = m.Get("normalized_fiber_length");
  const double v = m.Get("normalized_fiber_velocity");
  const double a = m.Get("activation");
  Balance b;
  b.tendon = p.max_isometric_force * fse.Value(m.Get("tendon_length") / p.tendon_slack_length);
  b.fibre = p.max_isometric_force *
            (a * fal.Value(l) * fv.Value(v) + fpe.Value(l) + p.fiber_damping * v) *
            std::cos(m.Get("pennation"));
  return b;
}

MillardMuscleParameters AsStruct(const std::map<std::string, double>& p) {
  MillardMuscleParameters m;
  m.max_isometric_force = p.at("max_isometric_force");
  m.tendon_slack_length = p.at("tendon_slack_length");
  m.optimal_fiber_length = p.at("optimal_fiber_length");
  auto& c = m.curves;
  c.min_norm_active_fiber_length = p.at("min_norm_active_fiber_length");
  c.transition_norm_fiber_length = p.at("transition_norm_fiber_length");
  c.max_norm_active_fiber_length = p.at("max_norm_active_fiber_length");
  c.shallow_ascending_slope = p.at("shallow_ascending_slope");
  c.minimum_value = p.at("minimum_value");
  c.concentric_slope_at_vmax = p.at("concentric_slope_at_vmax");
  c.concentric_slope_near_vmax = p.at("concentric_slope_near_vmax");
  c.isometric_slope = p.at("isometric_slope");
  c.eccentric_slope_at_vmax = p.at("eccentric_slope_at_vmax");
  c.eccentric_slope_near_vmax = p.at("eccentric_slope_near_vmax");
  c.max_eccentric_velocity_force_multiplier = p.at("max_eccentric_velocity_force_multiplier");
  c.fiber_strain_at_zero_force = p.at("fiber_strain_at_zero_force");
  c.fiber_strain_at_one_norm_force = p.at("fiber_strain_at_one_norm_force");
  c.fiber_stiffness_at_one_norm_force = p.at("fiber_stiffness_at_one_norm_force");
  c.tendon_strain_at_one_norm_force = p.at("tendon_strain_at_one_norm_force");
  c.tendon_stiffness_at_one_norm_force = p.at("tendon_stiffness_at_one_norm_force");
  return m;
}

// Drives the model's muscle along the block motion of a testAnalyzeTool input at 1 ms steps
// (activation from the file's column when it has one, else `activation`), and checks at every
// stored state: the equilibrium (tendon force = fibre force along the tendon), the fibre
// velocity against the fibre length's change, and a bounded second difference of the force.
// Then, as testAnalyzeTool does, a fresh muscle per stored row, Reset at that row's path length
// and activation (the equilibrium solved from scratch, not carried from the previous state):
// balanced to sqrt(eps) F0, the fibre no shorter than its minimum, the force smooth over rows.
// min_range_n: how much the input must change the integrated force [N].
void CheckTugOfWarInput(const std::string& input, double activation, double minimum_activation,
                        double min_range_n) {
  const TugOfWar tug = ReadTugOfWar(Reference("opensim/Tug_of_War_Millard_Iso.osim"));
  ASSERT_TRUE(tug.elastic);
  const Storage s = ReadStorage(Reference("opensim/" + input));
  const int tz = s.Column("block_tz");
  int act = -1;
  for (size_t i = 0; i < s.columns.size(); ++i)
    if (s.columns[i] == "LeftMuscle.activation") act = static_cast<int>(i);
  auto tug_parameters = tug.parameters;
  tug_parameters["minimum_activation"] = minimum_activation;
  const MillardMuscleParameters p = AsStruct(tug_parameters);
  const double a_min = minimum_activation;
  auto activation_at = [&](size_t row, double fraction) {
    if (act < 0) return std::max(a_min, activation);
    const double a0 = s.rows[row][act];
    const double a1 = s.rows[std::min(row + 1, s.rows.size() - 1)][act];
    return std::max(a_min, a0 + fraction * (a1 - a0));
  };
  // Reset puts the activation at default_activation: the file's first one
  auto parameters = tug_parameters;
  parameters["default_activation"] = activation_at(0, 0);
  auto m = MakeMuscle({{"curves", "millard2012"}, {"tendon", "elastic"}}, parameters);
  m->SetCommand(activation_at(0, 0));
  m->Reset(tug.PathLength(s.rows[0][tz]));
  EXPECT_NEAR(m->Get("activation"), activation_at(0, 0), 0);
  // Reset's fibre is at rest
  EXPECT_NEAR(m->Get("fiber_velocity"), 0, 1e-9);
  std::vector<double> force, fibre_length, fibre_velocity;  // per row, per 1 ms step
  double worst_balance = 0;
  for (size_t r = 0;; ++r) {
    const Balance b = BalanceOf(*m, p);
    worst_balance = std::max(worst_balance, std::abs(b.tendon - b.fibre));
    EXPECT_NEAR(m->tension(), b.tendon, 1e-9 * p.max_isometric_force) << "row " << r;
    force.push_back(m->tension());
    if (r + 1 == s.rows.size()) break;
    // 10 steps of 1 ms between stored rows; the block moves linearly between them
    const double dt_row = s.rows[r + 1][0] - s.rows[r][0];
    const double q0 = s.rows[r][tz], q1 = s.rows[r + 1][tz];
    const int n = static_cast<int>(std::lround(dt_row / 1e-3));
    ASSERT_GT(n, 0);
    for (int k = 0; k < n; ++k) {
      // the excitation held at the activation the file has at the step's end, the activation
      // itself set at its start: a follows the file's ramp within its own dynamics
      const double l0 = tug.PathLength(q0 + (q1 - q0) * k / n);
      const double l1 = tug.PathLength(q0 + (q1 - q0) * (k + 1) / n);
      const double dt = dt_row / n;
      m->Set("activation", activation_at(r, static_cast<double>(k) / n));
      m->SetCommand(activation_at(r, static_cast<double>(k + 1) / n));
      m->Step(l0, (l1 - l0) / dt, dt);
      fibre_length.push_back(m->Get("fiber_length"));
      fibre_velocity.push_back(m->Get("fiber_velocity"));
    }
  }
  // the equilibrium, with the fibre velocity solved from it, to solver precision
  EXPECT_LT(worst_balance, 1e-9 * p.max_isometric_force);
  // the fibre velocity is the fibre length's rate of change (central differences over 2 ms)
  const double scale = p.max_contraction_velocity * p.optimal_fiber_length;
  double worst_rate = 0;
  size_t worst_row = 0;
  // (from 30 ms on: Reset leaves the fibre at rest while the block starts at full speed)
  for (size_t i = 30; i + 1 < fibre_length.size(); ++i) {
    const double rate = (fibre_length[i + 1] - fibre_length[i - 1]) / (2 * 1e-3);
    const double error = std::abs(rate - fibre_velocity[i]) / scale;
    if (error > worst_rate) worst_rate = error, worst_row = i;
  }
  EXPECT_LT(worst_rate, 2e-3) << "normalised fibre velocity against the length's change, step "
                              << worst_row << " of " << fibre_length.size() << ": "
                              << fibre_velocity[worst_row - 1] / scale << " "
                              << fibre_velocity[worst_row] / scale << " "
                              << fibre_velocity[worst_row + 1] / scale;
  // smooth force: the second difference over 10 ms rows, against the force's own range
  double worst_second = 0;
  for (size_t i = 1; i + 1 < force.size(); ++i)
    worst_second = std::max(worst_second, std::abs(force[i + 1] - 2 * force[i] + force[i - 1]));
  const auto [lo, hi] = std::minmax_element(force.begin(), force.end());
  EXPECT_GT(*hi - *lo, min_range_n) << "the input should change the force";
  EXPECT_LT(worst_second, 0.01 * (*hi - *lo)) << "force not smooth";

  // independent equilibria, one fresh muscle per stored row
  const double tolerance =
      std::sqrt(std::numeric_limits<double>::epsilon()) * p.max_isometric_force;
  // the shortest fibre: the active curve's left shoulder, or the height at maximum pennation
  const double minimum_fibre_length = std::max(
      p.curves.min_norm_active_fiber_length * p.optimal_fiber_length,
      p.optimal_fiber_length * std::sin(p.pennation_angle) / std::sin(p.maximum_pennation_angle));
  std::vector<double> fresh_force;
  double worst_fresh_balance = 0;
  int at_minimum = 0;
  for (size_t r = 0; r < s.rows.size(); ++r) {
    auto row_parameters = tug_parameters;
    row_parameters["default_activation"] = activation_at(r, 0);
    auto fresh = MakeMuscle({{"curves", "millard2012"}, {"tendon", "elastic"}}, row_parameters);
    fresh->Reset(tug.PathLength(s.rows[r][tz]));
    EXPECT_NEAR(fresh->Get("activation"), activation_at(r, 0), 0) << "row " << r;
    EXPECT_NEAR(fresh->Get("fiber_velocity"), 0, 1e-9) << "row " << r;
    const Balance b = BalanceOf(*fresh, p);
    EXPECT_NEAR(b.tendon, b.fibre, tolerance) << "row " << r;
    worst_fresh_balance = std::max(worst_fresh_balance, std::abs(b.tendon - b.fibre));
    EXPECT_GE(fresh->Get("fiber_length"), minimum_fibre_length) << "row " << r;
    if (fresh->Get("fiber_length") <= minimum_fibre_length * (1 + 1e-12)) ++at_minimum;
    fresh_force.push_back(fresh->tension());
  }
  double worst_fresh_second = 0;
  for (size_t i = 1; i + 1 < fresh_force.size(); ++i)
    worst_fresh_second = std::max(
        worst_fresh_second, std::abs(fresh_force[i + 1] - 2 * fresh_force[i] + fresh_force[i - 1]));
  const auto [flo, fhi] = std::minmax_element(fresh_force.begin(), fresh_force.end());
  EXPECT_GT(*fhi - *flo, min_range_n) << "the input should change the equilibrium force";
  // rows are 1 mm of path apart (3 % of the optimal fibre length): the active curve's
  // shoulders bend the equilibrium force by ~1.1 % of its range per row (21 N at activation 1);
  // a wrong root or a jump between neighbouring solves exceeds 2 %
  EXPECT_LT(worst_fresh_second, 0.02 * (*fhi - *flo)) << "equilibrium force not smooth";
  // the short end of the input leaves the tendon slack and the fibre at its minimum
  EXPECT_GT(at_minimum, 0);

  std::ostringstream numbers;
  numbers << std::scientific << "balance " << worst_balance << " N, rate " << worst_rate
          << ", second difference " << worst_second << " N of a range " << *hi - *lo
          << " N; fresh equilibria: balance " << worst_fresh_balance << " N, second difference "
          << worst_fresh_second << " N of a range " << *fhi - *flo << " N, " << at_minimum
          << " rows at the minimum fibre length";
  ::testing::Test::RecordProperty("worst", numbers.str());
  std::cout << input << " activation " << activation << ": " << numbers.str() << "\n";
}

// upstream's three cases: constant velocity at activation 0.01 (passive fibres only) and 1, and
// the activation ramp from 0 with minimum_activation 0 (allowed with fibre damping)
TEST(MillardMuscle, TugOfWarConstantVelocityPassiveHoldsEquilibriumAndIsSmooth) {
  CALIPER_REQUIRE_CORPUS();
  CheckTugOfWarInput("Tug_of_War_ConstantVelocity.sto", 0.01, 0.01, 0.05 * 1000);
}

TEST(MillardMuscle, TugOfWarConstantVelocityHoldsEquilibriumAndIsSmooth) {
  CALIPER_REQUIRE_CORPUS();
  CheckTugOfWarInput("Tug_of_War_ConstantVelocity.sto", 1.0, 0.01, 0.05 * 1000);
}

TEST(MillardMuscle, TugOfWarRampActivationHoldsEquilibriumAndIsSmooth) {
  CALIPER_REQUIRE_CORPUS();
  CheckTugOfWarInput("Tug_of_War_ConstantVelocity_RampActivation.sto", 0.0, 0.0, 0.05 * 1000);
}

const std::map<std::string, double> kMuscle = {{"optimal_fiber_length", 0.1},
                                               {"tendon_slack_length", 0.2},
                                               {"max_isometric_force", 1000},
                                               {"pennation_angle", 0.2},
                                               {"default_activation", 0.5}};

// a path that stretches and shortens the muscle over 0.4 s, at 1 ms steps; tension per step
std::vector<double> Drive(TendonActuator* m, double excitation) {
  m->Reset(0.3);
  m->SetCommand(excitation);
  std::vector<double> tension;
  const double dt = 1e-3;
  for (int i = 0; i < 400; ++i) {
    const double t = i * dt;
    const double l0 = 0.3 + 0.02 * std::sin(2 * M_PI * 2.5 * t);
    const double l1 = 0.3 + 0.02 * std::sin(2 * M_PI * 2.5 * (t + dt));
    tension.push_back(m->Step(l0, (l1 - l0) / dt, dt));
  }
  return tension;
}

TEST(MillardMuscle, RigidAndStiffElasticTendonAgree) {
  auto stiff = kMuscle;
  stiff["tendon_strain_at_one_norm_force"] = 0.0005;
  stiff["tendon_stiffness_at_one_norm_force"] = 1.375 / 0.0005;
  auto rigid = MakeMuscle({{"curves", "millard2012"}, {"tendon", "rigid"}}, stiff);
  auto elastic = MakeMuscle({{"curves", "millard2012"}, {"tendon", "elastic"}}, stiff);
  const auto fr = Drive(rigid.get(), 0.8);
  const auto fe = Drive(elastic.get(), 0.8);
  double worst = 0, largest = 0;
  for (size_t i = 50; i < fr.size(); ++i) {  // after the first 50 ms of activation rise
    worst = std::max(worst, std::abs(fr[i] - fe[i]));
    largest = std::max(largest, fr[i]);
  }
  EXPECT_GT(largest, 300);
  EXPECT_LT(worst, 0.01 * largest);
  // with the default (compliant) tendon they differ clearly
  auto compliant = MakeMuscle({{"curves", "millard2012"}, {"tendon", "elastic"}}, kMuscle);
  auto rigid_default = MakeMuscle({{"curves", "millard2012"}, {"tendon", "rigid"}}, kMuscle);
  const auto fc = Drive(compliant.get(), 0.8);
  const auto fd = Drive(rigid_default.get(), 0.8);
  double differ = 0;
  for (size_t i = 50; i < fc.size(); ++i) differ = std::max(differ, std::abs(fc[i] - fd[i]));
  EXPECT_GT(differ, 10 * worst);
}

TEST(MillardMuscle, DampingActsOnlyWhileTheFibreMoves) {
  for (const char* tendon : {"rigid", "elastic"}) {
    SCOPED_TRACE(tendon);
    auto p = kMuscle;
    // an invertible force-velocity curve, which an undamped elastic muscle needs
    p["concentric_slope_at_vmax"] = 0.1;
    p["eccentric_slope_at_vmax"] = 0.1;
    auto damped_p = p, undamped_p = p;
    damped_p["fiber_damping"] = 0.1;
    undamped_p["fiber_damping"] = 0;
    auto damped = MakeMuscle({{"curves", "millard2012"}, {"tendon", tendon}}, damped_p);
    auto undamped = MakeMuscle({{"curves", "millard2012"}, {"tendon", tendon}}, undamped_p);
    // at rest: the same equilibrium
    for (auto* m : {damped.get(), undamped.get()}) {
      m->Reset(0.3);
      m->SetCommand(0.5);
      for (int i = 0; i < 300; ++i) m->Step(0.3, 0, 1e-3);
    }
    EXPECT_NEAR(damped->tension(), undamped->tension(), 1e-6 * damped->tension());
    EXPECT_NEAR(damped->Get("fiber_velocity"), 0, 1e-6);
    // moving: they differ, by the order of beta v F0
    const auto fd = Drive(damped.get(), 0.5);
    const auto fu = Drive(undamped.get(), 0.5);
    double differ = 0;
    for (size_t i = 0; i < fd.size(); ++i) differ = std::max(differ, std::abs(fd[i] - fu[i]));
    EXPECT_GT(differ, 1.0) << "N";
    EXPECT_LT(differ, 0.2 * 1000) << "N";
  }
}

TEST(MillardMuscle, RigidFibreClampedAtItsMinimumLength) {
  // kMuscle: lopt 0.1 m, slack 0.2 m, pennation 0.2 rad; the shortest fibre is the active
  // curve's left shoulder, 0.4441 lopt (the height over sin(maximum pennation) is 0.020 m)
  auto m = MakeMuscle({{"curves", "millard2012"}, {"tendon", "rigid"}}, kMuscle);
  const double minimum = 0.4441 * 0.1;
  const double height = 0.1 * std::sin(0.2);
  const double along_at_minimum = std::sqrt(minimum * minimum - height * height);
  m->Reset(0.3);
  // 0.03 m of path beyond the slack tendon: the fibre would be 0.036 m, below its minimum
  for (const double speed : {-0.1, 0.0, 0.1}) {
    SCOPED_TRACE(speed);
    m->Step(0.23, speed, 1e-3);
    EXPECT_NEAR(m->Get("fiber_length"), minimum, 1e-15);
    EXPECT_EQ(m->Get("fiber_velocity"), 0);
    EXPECT_EQ(m->Get("force_velocity"), 1);
    EXPECT_EQ(m->Get("active_fiber_force"), 0);
    EXPECT_EQ(m->tension(), 0);
    // the tendon buckles: shorter than its slack length by what the fibre cannot give
    EXPECT_NEAR(m->Get("tendon_length"), 0.23 + speed * 1e-3 - along_at_minimum, 1e-15);
  }
  // 0.1 mm of path above it the fibre follows the path again and pulls, either way it moves
  // (a fal F0 fv cos, fal >= minimum_value 0.1): the clamp holds only at the minimum
  const double above = 0.2 + along_at_minimum + 1e-4;
  for (const double speed : {-0.1, 0.1}) {
    SCOPED_TRACE(speed);
    m->Step(above, 0, 1e-3, speed);
    EXPECT_GT(m->Get("fiber_length"), minimum);
    EXPECT_NEAR(m->Get("fiber_velocity"), speed * std::cos(m->Get("pennation")), 1e-12);
    EXPECT_GT(m->tension(), 0.5 * 0.1 * 1000 * 0.1);
  }
}

TEST(MillardMuscle, ElasticStepIsSecondOrder) {
  // the path moves through each step and the excitation changes: error against a fine run
  auto run = [](double dt) {
    auto m = MakeMuscle({{"curves", "millard2012"}, {"tendon", "elastic"}}, kMuscle);
    m->Reset(0.3);
    const int n = static_cast<int>(std::lround(0.1 / dt));
    for (int i = 0; i < n; ++i) {
      const double t = i * dt;
      m->SetCommand(t < 0.05 ? 1.0 : 0.2);
      const double l0 = 0.3 + 0.03 * std::sin(2 * M_PI * 5 * t);
      const double l1 = 0.3 + 0.03 * std::sin(2 * M_PI * 5 * (t + dt));
      m->Step(l0, (l1 - l0) / dt, dt);
    }
    return m->Get("fiber_length");
  };
  const double reference = run(1e-3 / 32);
  const double e1 = std::abs(run(1e-3) - reference);
  const double e2 = std::abs(run(0.5e-3) - reference);
  const double e4 = std::abs(run(0.25e-3) - reference);
  std::ostringstream errors;
  errors << std::scientific << e1 << " " << e2 << " " << e4;
  RecordProperty("fibre_length_errors_1_0.5_0.25ms_m", errors.str());
  EXPECT_GT(e1 / e2, 3.0) << e1 << " " << e2;
  EXPECT_GT(e2 / e4, 3.0) << e2 << " " << e4;
  EXPECT_LT(e1, 1e-5 * 0.1);  // 1e-5 optimal fibre lengths at 1 ms
}

TEST(MillardMuscle, ResetAtEquilibriumAndQuantities) {
  auto m = MakeMuscle({{"curves", "millard2012"}, {"tendon", "elastic"}}, kMuscle);
  m->Reset(0.31);
  EXPECT_NEAR(m->Get("fiber_velocity"), 0, 1e-9);
  EXPECT_GT(m->tension(), 0);
  EXPECT_NEAR(m->Get("activation"), 0.5, 0);
  EXPECT_NEAR(m->Get("fiber_damping"), 0.1, 0);
  EXPECT_NEAR(m->Get("activation_time_constant"), 0.010, 0);
  EXPECT_NEAR(m->Get("deactivation_time_constant"), 0.040, 0);
  EXPECT_GT(m->Get("tendon_strain"), 0);
  EXPECT_NEAR(m->Get("pennation"),
              PennationAngle(m->Get("fiber_length"), 0.1, kMuscle.at("pennation_angle")), 1e-12);
  // a curve parameter set at run time rebuilds the curves
  const double before = m->tension();
  m->Set("tendon_strain_at_one_norm_force", 0.1);
  m->Set("tendon_stiffness_at_one_norm_force", 1.375 / 0.1);
  m->Reset(0.31);
  EXPECT_LT(m->tension(), before);  // a softer tendon lets the fibres shorten
  EXPECT_THROW(m->Set("tendon_stiffness_at_one_norm_force", 5), std::invalid_argument);
}

TEST(MillardMuscle, RejectsWrongOptionsAndParameters) {
  const auto p = kMuscle;
  EXPECT_EQ(MakeError({{"curves", "millard2012"}, {"tendon", "elastic"}}, p), "");
  EXPECT_NE(MakeError({{"curves", "millard"}}, p).find("known: thelen2003, mujoco, millard2012"),
            std::string::npos);
  auto thelen_only = p;
  thelen_only["kshape_active"] = 0.5;
  EXPECT_NE(MakeError({{"curves", "millard2012"}}, thelen_only)
                .find("parameter 'kshape_active' does not apply to curves=millard2012"),
            std::string::npos);
  auto millard_only = p;
  millard_only["fiber_damping"] = 0.1;
  EXPECT_NE(MakeError({{"curves", "thelen2003"}}, millard_only)
                .find("parameter 'fiber_damping' does not apply to curves=thelen2003"),
            std::string::npos);
  auto undamped = p;
  undamped["fiber_damping"] = 0;
  EXPECT_NE(MakeError({{"curves", "millard2012"}, {"tendon", "elastic"}}, undamped)
                .find("'concentric_slope_at_vmax' = 0: must be > 0 with fiber_damping = 0"),
            std::string::npos);
  EXPECT_EQ(MakeError({{"curves", "millard2012"}, {"tendon", "rigid"}}, undamped), "");
  EXPECT_NE(MakeError({{"curves", "millard2012"}, {"integrator", "mujoco"}}, p)
                .find("integrator=mujoco needs curves=thelen2003 or mujoco"),
            std::string::npos);
  auto missing = p;
  missing.erase("tendon_slack_length");
  EXPECT_NE(MakeError({{"curves", "millard2012"}}, missing)
                .find("missing parameter 'tendon_slack_length' [m] needed by curves=millard2012"),
            std::string::npos);
  // registered once, with both curve sets' help
  int count = 0;
  for (const auto& spec : KindParameters("hill_muscle"))
    if (spec.name == "activation_time_constant") {
      ++count;
      EXPECT_NE(spec.help.find("millard2012: 0.010"), std::string::npos);
    }
  EXPECT_EQ(count, 1);
}

}  // namespace
}  // namespace caliper::actuators
