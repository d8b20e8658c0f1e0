// The parameter sets of the kind hill_muscle: the validation of the Thelen 2003 and MuJoCo sets
// (Millard 2012's is in millard.cc) and the table of every parameter by curve set.

#include "muscle_parameters.h"

#include <cmath>
#include <string>
#include <vector>

#include "caliper/actuators/muscle.h"
#include "muscle_validation.h"

namespace caliper::actuators {

// ---------------------------------------------------------------------------------------------
// parameter validation

using muscle_detail::Num;
using muscle_detail::Require;

void Validate(const ThelenMuscleParameters& p, bool elastic_tendon) {
  const ThelenCurveParameters& c = p.curves;
  muscle_detail::RequireHillCommon(p, elastic_tendon);
  if (elastic_tendon)
    Require(p.minimum_activation > 0 && p.minimum_activation < 1, "minimum_activation",
            p.minimum_activation,
            "must be in (0, 1) with an elastic tendon (the fibre velocity is singular at 0)");
  else
    Require(p.minimum_activation >= 0 && p.minimum_activation < 1, "minimum_activation",
            p.minimum_activation, "must be in [0, 1)");
  Require(c.kshape_active > 0, "kshape_active", c.kshape_active, "must be > 0");
  Require(c.kshape_passive > 0, "kshape_passive", c.kshape_passive, "must be > 0");
  Require(c.fmax_muscle_strain > 0, "fmax_muscle_strain", c.fmax_muscle_strain, "must be > 0");
  Require(c.fmax_tendon_strain > 0, "fmax_tendon_strain", c.fmax_tendon_strain, "must be > 0");
  Require(c.af > 0, "af", c.af, "must be > 0");
  Require(c.flen > 1, "flen", c.flen, "must be > 1");
  Require(c.fv_linear_extrap_threshold > 1 / c.flen && c.fv_linear_extrap_threshold < 1,
          "fv_linear_extrap_threshold", c.fv_linear_extrap_threshold,
          "must be in (1/flen = " + Num(1 / c.flen) + ", 1)");
}

void Validate(const MujocoMuscleParameters& p) {
  Require(std::isfinite(p.range1) && p.range0 < p.range1, "range0", p.range0,
          "must be < range1 = " + Num(p.range1));
  Require(p.lmin > 0 && p.lmin < 1, "lmin", p.lmin, "must be in (0, 1)");
  Require(p.lmax > 1, "lmax", p.lmax, "must be > 1");
  Require(p.vmax > 0, "vmax", p.vmax, "must be > 0 L0/s");
  Require(p.fpmax >= 0, "fpmax", p.fpmax, "must be >= 0");
  Require(p.fvmax >= 1, "fvmax", p.fvmax, "must be >= 1");
  Require(std::isfinite(p.lengthrange_lo) && p.lengthrange_lo < p.lengthrange_hi, "lengthrange_hi",
          p.lengthrange_hi, "must be > lengthrange_lo = " + Num(p.lengthrange_lo) + " m");
  Require(std::isfinite(p.force), "force", p.force, "must be finite");
  if (p.force < 0) {
    Require(p.scale >= 0, "scale", p.scale, "must be >= 0 (force < 0 uses scale / acc0)");
    Require(p.acc0 > 0, "acc0", p.acc0, "must be > 0 when force < 0 (F0 = scale / acc0)");
  }
  Require(p.tau_act > 0, "tau_act", p.tau_act, "must be > 0 s");
  Require(p.tau_deact > 0, "tau_deact", p.tau_deact, "must be > 0 s");
}

// ---------------------------------------------------------------------------------------------
// the parameter table

namespace muscle_detail {

const std::vector<ParameterEntry>& ParameterTable() {
  using P = AllParameters;
  static const std::vector<ParameterEntry> table = {
      {"default_activation", "", Applies::kBoth, false,
       [](P& p) -> double& { return p.default_activation; },
       "activation at Reset, in [0, 1] (raised to minimum_activation)"},
      // thelen2003
      {"max_isometric_force", "N", Applies::kThelen, false,
       [](P& p) -> double& { return p.thelen.max_isometric_force; }, "F0 (thelen2003)"},
      {"optimal_fiber_length", "m", Applies::kThelen, true,
       [](P& p) -> double& { return p.thelen.optimal_fiber_length; },
       "fibre length of maximum active force (thelen2003, required)"},
      {"tendon_slack_length", "m", Applies::kThelen, true,
       [](P& p) -> double& { return p.thelen.tendon_slack_length; },
       "tendon length below which it carries no force (thelen2003, required)"},
      {"pennation_angle", "rad", Applies::kThelen, false,
       [](P& p) -> double& { return p.thelen.pennation_angle; },
       "pennation at optimal fibre length; constant muscle thickness (thelen2003)"},
      {"max_contraction_velocity", "1/s", Applies::kThelen, false,
       [](P& p) -> double& { return p.thelen.max_contraction_velocity; },
       "in optimal fibre lengths per second (thelen2003)"},
      {"activation_time_constant", "s", Applies::kThelen, false,
       [](P& p) -> double& { return p.thelen.activation_time_constant; }, "(thelen2003)"},
      {"deactivation_time_constant", "s", Applies::kThelen, false,
       [](P& p) -> double& { return p.thelen.deactivation_time_constant; }, "(thelen2003)"},
      {"minimum_activation", "", Applies::kThelen, false,
       [](P& p) -> double& { return p.thelen.minimum_activation; },
       "lower bound of the activation (thelen2003; > 0 with an elastic tendon)"},
      {"maximum_pennation_angle", "rad", Applies::kThelen, false,
       [](P& p) -> double& { return p.thelen.maximum_pennation_angle; },
       "sets the shortest fibre, height / sin(maximum) (thelen2003)"},
      {"kshape_active", "", Applies::kThelen, false,
       [](P& p) -> double& { return p.thelen.curves.kshape_active; },
       "gamma of the active force-length Gaussian (thelen2003)"},
      {"kshape_passive", "", Applies::kThelen, false,
       [](P& p) -> double& { return p.thelen.curves.kshape_passive; },
       "passive force-length exponent (thelen2003)"},
      {"fmax_muscle_strain", "", Applies::kThelen, false,
       [](P& p) -> double& { return p.thelen.curves.fmax_muscle_strain; },
       "fibre strain of passive force F0 (thelen2003)"},
      {"fmax_tendon_strain", "", Applies::kThelen, false,
       [](P& p) -> double& { return p.thelen.curves.fmax_tendon_strain; },
       "tendon strain of force F0 (thelen2003)"},
      {"af", "", Applies::kThelen, false, [](P& p) -> double& { return p.thelen.curves.af; },
       "force-velocity shape factor (thelen2003)"},
      {"flen", "", Applies::kThelen, false, [](P& p) -> double& { return p.thelen.curves.flen; },
       "maximum lengthening force / F0 (thelen2003)"},
      {"fv_linear_extrap_threshold", "", Applies::kThelen, false,
       [](P& p) -> double& { return p.thelen.curves.fv_linear_extrap_threshold; },
       "force-velocity linear beyond this * flen (thelen2003)"},
      // mujoco
      {"range0", "", Applies::kMujoco, false, [](P& p) -> double& { return p.mujoco.range0; },
       "normalised length at lengthrange_lo (mujoco)"},
      {"range1", "", Applies::kMujoco, false, [](P& p) -> double& { return p.mujoco.range1; },
       "normalised length at lengthrange_hi (mujoco)"},
      {"force", "N", Applies::kMujoco, false, [](P& p) -> double& { return p.mujoco.force; },
       "F0; < 0: scale / acc0 (mujoco)"},
      {"scale", "rad/s^2", Applies::kMujoco, false, [](P& p) -> double& { return p.mujoco.scale; },
       "F0 = scale / acc0 when force < 0 (mujoco)"},
      {"acc0", "rad/s^2/N", Applies::kMujoco, false, [](P& p) -> double& { return p.mujoco.acc0; },
       "joint acceleration norm of a unit actuator force, from MuJoCo's compiler (mujoco)"},
      {"lmin", "", Applies::kMujoco, false, [](P& p) -> double& { return p.mujoco.lmin; },
       "shortest normalised length with active force (mujoco)"},
      {"lmax", "", Applies::kMujoco, false, [](P& p) -> double& { return p.mujoco.lmax; },
       "longest normalised length with active force (mujoco)"},
      {"vmax", "1/s", Applies::kMujoco, false, [](P& p) -> double& { return p.mujoco.vmax; },
       "shortening speed of zero force, in L0 per second (mujoco)"},
      {"fpmax", "", Applies::kMujoco, false, [](P& p) -> double& { return p.mujoco.fpmax; },
       "passive force / F0 is fpmax / 2 at (1 + lmax) / 2, linear beyond (mujoco)"},
      {"fvmax", "", Applies::kMujoco, false, [](P& p) -> double& { return p.mujoco.fvmax; },
       "lengthening force limit / F0 (mujoco)"},
      {"lengthrange_lo", "m", Applies::kMujoco, true,
       [](P& p) -> double& { return p.mujoco.lengthrange_lo; },
       "actuator length mapped to range0 (mujoco, required)"},
      {"lengthrange_hi", "m", Applies::kMujoco, true,
       [](P& p) -> double& { return p.mujoco.lengthrange_hi; },
       "actuator length mapped to range1 (mujoco, required)"},
      {"tau_act", "s", Applies::kMujoco, false, [](P& p) -> double& { return p.mujoco.tau_act; },
       "activation time constant (mujoco)"},
      {"tau_deact", "s", Applies::kMujoco, false,
       [](P& p) -> double& { return p.mujoco.tau_deact; }, "deactivation time constant (mujoco)"},
      // millard2012: the names shared with thelen2003 are separate entries (own defaults)
      {"max_isometric_force", "N", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.max_isometric_force; }, "F0 (millard2012)"},
      {"optimal_fiber_length", "m", Applies::kMillard, true,
       [](P& p) -> double& { return p.millard.optimal_fiber_length; },
       "fibre length of maximum active force (millard2012, required)"},
      {"tendon_slack_length", "m", Applies::kMillard, true,
       [](P& p) -> double& { return p.millard.tendon_slack_length; },
       "tendon length below which it carries no force (millard2012, required)"},
      {"pennation_angle", "rad", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.pennation_angle; },
       "pennation at optimal fibre length; constant muscle thickness (millard2012)"},
      {"max_contraction_velocity", "1/s", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.max_contraction_velocity; },
       "in optimal fibre lengths per second (millard2012)"},
      {"activation_time_constant", "s", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.activation_time_constant; }, "(millard2012: 0.010)"},
      {"deactivation_time_constant", "s", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.deactivation_time_constant; },
       "(millard2012: 0.040)"},
      {"minimum_activation", "", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.minimum_activation; },
       "lower bound of the activation (millard2012)"},
      {"maximum_pennation_angle", "rad", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.maximum_pennation_angle; },
       "sets the shortest fibre with min_norm_active_fiber_length (millard2012)"},
      {"fiber_damping", "", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.fiber_damping; },
       "beta: fibre force F0 beta v / (vmax lopt) (millard2012)"},
      {"min_norm_active_fiber_length", "", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.curves.min_norm_active_fiber_length; },
       "left shoulder of the active force-length curve (millard2012)"},
      {"transition_norm_fiber_length", "", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.curves.transition_norm_fiber_length; },
       "steep to shallow ascending limb (millard2012)"},
      {"max_norm_active_fiber_length", "", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.curves.max_norm_active_fiber_length; },
       "right shoulder of the active force-length curve (millard2012)"},
      {"shallow_ascending_slope", "", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.curves.shallow_ascending_slope; },
       "active force-length slope of the shallow limb (millard2012)"},
      {"minimum_value", "", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.curves.minimum_value; },
       "active force-length value at and beyond the shoulders (millard2012)"},
      {"concentric_slope_at_vmax", "", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.curves.concentric_slope_at_vmax; },
       "force-velocity slope at -vmax (millard2012)"},
      {"concentric_slope_near_vmax", "", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.curves.concentric_slope_near_vmax; },
       "force-velocity slope at -0.9 vmax (millard2012)"},
      {"isometric_slope", "", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.curves.isometric_slope; },
       "force-velocity slope at 0 (millard2012)"},
      {"eccentric_slope_at_vmax", "", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.curves.eccentric_slope_at_vmax; },
       "force-velocity slope at +vmax (millard2012)"},
      {"eccentric_slope_near_vmax", "", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.curves.eccentric_slope_near_vmax; },
       "force-velocity slope at +0.9 vmax (millard2012)"},
      {"max_eccentric_velocity_force_multiplier", "", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.curves.max_eccentric_velocity_force_multiplier; },
       "force-velocity value at +vmax (millard2012)"},
      {"concentric_curviness", "", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.curves.concentric_curviness; },
       "force-velocity bend below 0, 0..1 (millard2012)"},
      {"eccentric_curviness", "", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.curves.eccentric_curviness; },
       "force-velocity bend above 0, 0..1 (millard2012)"},
      {"fiber_strain_at_zero_force", "", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.curves.fiber_strain_at_zero_force; },
       "passive fibre curve (millard2012)"},
      {"fiber_strain_at_one_norm_force", "", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.curves.fiber_strain_at_one_norm_force; },
       "passive fibre curve (millard2012)"},
      {"fiber_stiffness_at_low_force", "", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.curves.fiber_stiffness_at_low_force; },
       "passive fibre curve (millard2012)"},
      {"fiber_stiffness_at_one_norm_force", "", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.curves.fiber_stiffness_at_one_norm_force; },
       "passive fibre curve; OpenSim's default 2 / strain at one (millard2012)"},
      {"fiber_curviness", "", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.curves.fiber_curviness; },
       "passive fibre curve bend, 0..1 (millard2012)"},
      {"tendon_strain_at_one_norm_force", "", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.curves.tendon_strain_at_one_norm_force; },
       "tendon curve (millard2012)"},
      {"tendon_stiffness_at_one_norm_force", "", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.curves.tendon_stiffness_at_one_norm_force; },
       "tendon curve; OpenSim's default 1.375 / strain at one (millard2012)"},
      {"tendon_norm_force_at_toe_end", "", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.curves.tendon_norm_force_at_toe_end; },
       "tendon curve (millard2012)"},
      {"tendon_curviness", "", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.curves.tendon_curviness; },
       "tendon curve bend, 0..1 (millard2012)"},
  };
  return table;
}

bool AppliesTo(Applies applies, Curves curves) {
  return applies == Applies::kBoth || (applies == Applies::kThelen && curves == Curves::kThelen) ||
         (applies == Applies::kMujoco && curves == Curves::kMujoco) ||
         (applies == Applies::kMillard && curves == Curves::kMillard);
}

const char* CurvesName(Curves c) {
  return c == Curves::kThelen ? "thelen2003" : c == Curves::kMujoco ? "mujoco" : "millard2012";
}

}  // namespace muscle_detail

}  // namespace caliper::actuators
