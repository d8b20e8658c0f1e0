#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <typeinfo>
#include <utility>
#include <vector>

#include "builtin_kinds.h"
#include "caliper/actuators/actuator.h"
#include "caliper/actuators/dc_motor.h"
#include "caliper/actuators/elastic.h"
#include "caliper/logging/log.h"
#include "command_delay.h"
#include "motor_checks.h"

namespace caliper::actuators {

namespace {

using motor_detail::Check;
using motor_detail::Range;
using motor_detail::Text;

// a motor parameter as a kind parameter and a quantity
struct MotorField {
  const char* name;
  const char* unit;
  double DcMotorParameters::*member;
  const char* help;
};

const MotorField kMotorFields[] = {
    {"resistance", "ohm", &DcMotorParameters::resistance, "armature resistance R"},
    {"inductance", "H", &DcMotorParameters::inductance, "armature inductance L"},
    {"torque_constant", "N m/A", &DcMotorParameters::torque_constant, "torque constant k_t"},
    {"back_emf_constant", "V s/rad", &DcMotorParameters::back_emf_constant,
     "back-EMF constant k_e"},
    {"rotor_inertia", "kg m^2", &DcMotorParameters::rotor_inertia, "rotor inertia J_rotor"},
    {"gear_inertia", "kg m^2", &DcMotorParameters::gear_inertia,
     "gearbox inertia reflected to the motor shaft J_gear"},
    {"gear_ratio", "", &DcMotorParameters::gear_ratio, "gear ratio N (motor / spool speed)"},
    {"efficiency", "", &DcMotorParameters::efficiency, "gearbox efficiency eta, in (0, 1]"},
    {"bridge_resistance", "ohm", &DcMotorParameters::bridge_resistance,
     "H-bridge resistance in series with the armature"},
    {"current_limit", "A", &DcMotorParameters::current_limit, "driver current limit (0: none)"},
    {"spool_radius", "m", &DcMotorParameters::spool_radius, "spool radius r_s"},
    {"max_substep", "s", &DcMotorParameters::max_substep, "longest internal integration step"},
    {"coulomb_friction", "N m", &DcMotorParameters::coulomb_friction,
     "Coulomb friction at the motor shaft tau_c (about k_t times the no-load current)"},
    {"static_friction", "N m", &DcMotorParameters::static_friction,
     "breakaway friction at the motor shaft tau_s (0: tau_c, no Stribeck peak)"},
    {"stribeck_speed", "rad/s", &DcMotorParameters::stribeck_speed,
     "motor speed W_s over which friction falls from tau_s to tau_c"},
    {"viscous_friction", "N m s/rad", &DcMotorParameters::viscous_friction,
     "viscous friction at the motor shaft b"},
    {"friction_smoothing_speed", "rad/s", &DcMotorParameters::friction_smoothing_speed,
     "motor speed W_e over which friction changes sign (tanh)"},
    {"cogging_amplitude", "N m", &DcMotorParameters::cogging_amplitude,
     "cogging torque amplitude A at the motor shaft"},
    {"cogging_count", "", &DcMotorParameters::cogging_count,
     "cogging periods per rotor turn n (a whole number)"},
    {"cogging_phase", "rad", &DcMotorParameters::cogging_phase, "cogging phase psi"},
    {"thermal_resistance_winding_housing", "K/W",
     &DcMotorParameters::thermal_resistance_winding_housing,
     "thermal resistance winding-housing R_wh (datasheet)"},
    {"thermal_resistance_housing_ambient", "K/W",
     &DcMotorParameters::thermal_resistance_housing_ambient,
     "thermal resistance housing-ambient R_ha (datasheet; 0: no thermal model)"},
    {"thermal_time_constant_winding", "s", &DcMotorParameters::thermal_time_constant_winding,
     "thermal time constant of the winding tau_w (datasheet)"},
    {"thermal_time_constant_motor", "s", &DcMotorParameters::thermal_time_constant_motor,
     "thermal time constant of the motor tau_m (datasheet)"},
    {"ambient_temperature", "degC", &DcMotorParameters::ambient_temperature,
     "ambient temperature T_a (and the motor's at reset)"},
    {"reference_temperature", "degC", &DcMotorParameters::reference_temperature,
     "temperature T_ref at which resistance and torque_constant are given"},
    {"resistance_temperature_coefficient", "1/K",
     &DcMotorParameters::resistance_temperature_coefficient,
     "winding resistance change per kelvin alpha (copper 0.0039)"},
    {"torque_constant_temperature_coefficient", "1/K",
     &DcMotorParameters::torque_constant_temperature_coefficient,
     "torque and back-EMF constant change per kelvin of the housing beta (NdFeB about -0.001)"},
    {"max_winding_temperature", "degC", &DcMotorParameters::max_winding_temperature,
     "winding temperature the driver protects (0: none)"},
    {"derating_band", "K", &DcMotorParameters::derating_band,
     "below max_winding_temperature, the band over which the driver lowers its current limit"},
};

// the driver's own parameters, beside supply_voltage and pretension; each 0: off
struct DriverParameters {
  double pwm_levels = 0;     // [-]
  double slew_rate = 0;      // [V/s]
  double command_delay = 0;  // [s]
};

// a driver parameter as a kind parameter and a quantity
struct DriverField {
  const char* name;
  const char* unit;
  double DriverParameters::*member;
  bool whole;  // a whole number
  const char* help;
};

const DriverField kDriverFields[] = {
    {"pwm_levels", "", &DriverParameters::pwm_levels, true,
     "PWM duty steps from 0 to full supply, which also bounds the output (1023 for a 10-bit "
     "PWM's duty values 0..1023; 0: continuous, unbounded)"},
    {"slew_rate", "V/s", &DriverParameters::slew_rate, false,
     "fastest change of the driver's output voltage (0: none)"},
    {"command_delay", "s", &DriverParameters::command_delay, false,
     "time from a command to the driver, rounded to whole time steps (at most 100,000 of them)"},
};

constexpr double kDefaultSupplyVoltage = 12;  // [V]

std::string Number(double value) {
  std::ostringstream s;
  s << value;
  return s.str();
}

std::string Prefix(const sgal::Actuator& a) {
  return "actuator '" + a.name + "' (" + a.kind + "): ";
}

[[noreturn, gnu::cold, gnu::noinline]] void ThrowNotFinite(const std::string& prefix,
                                                           const char* what, double value) {
  throw std::invalid_argument(prefix + what + " must be finite, got " + Number(value));
}

// checked in every step of every actuator: the test inline, the message out of the way
inline void RequireFinite(const std::string& prefix, const char* what, double value) {
  if (!std::isfinite(value)) ThrowNotFinite(prefix, what, value);
}

// the tendon seen from the spool: an inextensible line paid in by the spool, in series with the
// elastic element, along a path that lengthens at a constant speed through the step (the
// actuator contract): each sub-step and stage sees the path length at its own time, so that the
// motor's second-order integration stays second order with the path
class TendonSpoolLoad : public SpoolLoad {
 public:
  TendonSpoolLoad(ElasticElement* elastic, const LinearSpringDamper* linear, double path_length,
                  double path_speed, double line_length, double spool_angle, double spool_radius)
      : elastic_(elastic),
        linear_(linear),
        path_length_(path_length),
        path_speed_(path_speed),
        line_length_(line_length),
        spool_angle_(spool_angle),
        spool_radius_(spool_radius) {}

  double LineLength(double spool_angle) const {
    return line_length_ - spool_radius_ * (spool_angle - spool_angle_);
  }
  // the path length h [s] after the last accepted sub-step [m]
  double PathLength(double h) const { return path_length_ + path_speed_ * (elapsed_ + h); }
  double ElasticLength(double spool_angle, double h) const {
    return PathLength(h) - LineLength(spool_angle);
  }
  double ElasticSpeed(double spool_speed) const {
    return path_speed_ + spool_radius_ * spool_speed;
  }
  double TorqueAt(double spool_angle, double spool_speed, double h) const override {
    const double length = ElasticLength(spool_angle, h);
    const double speed = ElasticSpeed(spool_speed);
    // the default element without a second virtual call
    return spool_radius_ * (linear_ ? linear_->LinearSpringDamper::Peek(length, speed, h)
                                    : elastic_->Peek(length, speed, h));
  }
  double TorqueAlong(double spool_angle, double spool_speed, double h, double angle_per_speed,
                     double* slope, double* low, double* high) const override {
    // the elastic length and speed grow by r_s per radian and per rad/s
    const double length = ElasticLength(spool_angle, h);
    const double speed = ElasticSpeed(spool_speed);
    const double d_length = spool_radius_ * angle_per_speed;
    double d_force;
    const double force =
        linear_
            ? linear_->LinearSpringDamper::PeekAlong(length, speed, h, d_length, spool_radius_,
                                                     &d_force, low, high)
            : elastic_->PeekAlong(length, speed, h, d_length, spool_radius_, &d_force, low, high);
    *slope = spool_radius_ * d_force;
    return spool_radius_ * force;
  }
  void Advance(double spool_angle, double spool_speed, double h) override {
    const double length = ElasticLength(spool_angle, h);
    const double speed = ElasticSpeed(spool_speed);
    // the linear element is stateless (its Force() is its Peek()): no virtual call
    force_ = linear_ ? linear_->LinearSpringDamper::Peek(length, speed, h)
                     : elastic_->Force(length, speed, h);
    elapsed_ += h;
  }
  int TorqueSign() const override { return 1; }  // tension only
  double force() const { return force_; }

 private:
  ElasticElement* elastic_;
  const LinearSpringDamper* linear_;  // elastic_ when it is the linear element, else null
  double path_length_;                // at the start of the step [m]
  double path_speed_;                 // through the step [m/s]
  double line_length_;                // free line at the start of the step [m]
  double spool_angle_;                // at the start of the step [rad]
  double spool_radius_;               // [m]
  double elapsed_ = 0;                // accepted sub-steps since the start of the step [s]
  double force_ = 0;                  // [N]
};

class DcMotorTendon : public TendonActuator {
 public:
  explicit DcMotorTendon(const sgal::Actuator& a) : prefix_(Prefix(a)) {
    DcMotorParameters p;
    for (const MotorField& field : kMotorFields)
      p.*field.member = ParameterOr(a, field.name, p.*field.member);
    supply_voltage_ = ParameterOr(a, "supply_voltage", kDefaultSupplyVoltage);
    pretension_ = ParameterOr(a, "pretension", 0);
    for (const DriverField& field : kDriverFields)
      driver_.*field.member = ParameterOr(a, field.name, driver_.*field.member);
    const auto input = a.options.find("input");
    if (input != a.options.end()) {
      if (input->second == "duty")
        duty_input_ = true;
      else if (input->second != "voltage")
        throw std::invalid_argument(prefix_ + "unknown input '" + input->second +
                                    "' in options[\"input\"] (known: voltage, duty)");
    }
    try {
      motor_.set_parameters(p);
      CheckSupplyVoltage(supply_voltage_);
      CheckPretension(pretension_);
      for (const DriverField& field : kDriverFields) CheckDriver(field, driver_.*field.member);
      delay_.SetDelay(driver_.command_delay);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(prefix_ + e.what());
    }
    elastic_ = MakeElasticElement(a);
    elastic_state_ = elastic_->StateSize();
    if (typeid(*elastic_) == typeid(LinearSpringDamper))
      linear_ = static_cast<const LinearSpringDamper*>(elastic_.get());
    Reset(elastic_->RelaxedLength(pretension_));
  }

  void Reset(double path_length) override {
    RequireFinite(prefix_, "path length", path_length);
    motor_.Reset();
    double length = 0;
    try {
      length = elastic_->RelaxedLength(pretension_);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(prefix_ + "pretension: " + e.what());
    }
    elastic_->Reset(length);
    // the driver has given the present command since ever
    delay_.Reset(command_);
    driver_voltage_ = TargetVoltage();
    warned_ = false;
    path_length_ = path_length;
    path_speed_ = 0;
    line_length_ = path_length - length;
    elastic_length_ = length;
    tension_ = elastic_->Peek(length, 0, 0);
    if (line_length_ < 0) WarnNegativeLine();
  }

  double Step(double path_length, double path_speed, double dt, double end_speed) override {
    RequireFinite(prefix_, "path length", path_length);
    RequireFinite(prefix_, "path speed", path_speed);
    RequireFinite(prefix_, "path speed at the end", end_speed);
    if (!(dt > 0) || !std::isfinite(dt))
      throw std::invalid_argument(prefix_ + "time step must be > 0 [s], got " + Number(dt));
    const double angle = motor_.state().spool_angle;
    TendonSpoolLoad load(elastic_.get(), linear_, path_length, path_speed, line_length_, angle,
                         motor_.parameters().spool_radius);
    DriveStep(dt);
    motor_.Step(driver_voltage_, dt, load);
    if (motor_.parameters().thermal()) WatchTemperature();
    // everything reported is at the end of the step, where the tension is
    path_length_ = path_length + path_speed * dt;
    path_speed_ = path_speed;
    line_length_ = load.LineLength(motor_.state().spool_angle);
    elastic_length_ = path_length_ - line_length_;
    // a stateless element's damper (linear, polynomial, table) reads the path's speed at the
    // end, where the tension acts from (its force evaluated again); an element with states of
    // its own (zener) integrated them along the mean speed and has no such direct term
    const double spool_line_speed =
        motor_.parameters().spool_radius * motor_.state().spool_speed;  // [m/s]
    tension_ =
        linear_
            ? linear_->LinearSpringDamper::Peek(elastic_length_, end_speed + spool_line_speed, dt)
        : elastic_state_ == 0 ? elastic_->Peek(elastic_length_, end_speed + spool_line_speed, dt)
                              : load.force();
    return tension_;
  }

  double tension() const override { return tension_; }

  // the motor's, what the step reports and the driver's, the elastic element's, the delay line's
  std::size_t StateSize() const override { return kOwnState + elastic_state_ + delay_.StateSize(); }

  bool Restorable(const double* in, std::size_t n) const override {
    const std::size_t fixed = kOwnState + elastic_state_;
    return n > fixed && CommandDelay::Readable(in + fixed, n - fixed);
  }

  void SaveState(double* out) const override {
    SaveOwnState(out);
    delay_.SaveState(out + kOwnState + elastic_state_);
  }
  void SaveStepState(double* out) const override {
    SaveOwnState(out);
    delay_.SaveStepState(out + kOwnState + elastic_state_);
  }

  void RestoreState(const double* in) override {
    RestoreOwnState(in);
    delay_.RestoreState(in + kOwnState + elastic_state_);
  }
  void RestoreStepState(const double* in) override {
    RestoreOwnState(in);
    delay_.RestoreStepState(in + kOwnState + elastic_state_);
  }

  void SetTimeStep(double dt) override {
    if (!(dt > 0) || !std::isfinite(dt))
      throw std::invalid_argument(prefix_ + "time step must be > 0 [s], got " + Number(dt));
    try {
      DcMotor::CheckSubsteps(dt, motor_.parameters().max_substep);
      delay_.SetTimeStep(dt);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(prefix_ + e.what());
    }
    time_step_ = dt;
  }

  void SetCommand(double value) override {
    RequireFinite(prefix_, "command", value);
    command_ = duty_input_ ? std::clamp(value, -1.0, 1.0) : value;
    delay_.Issue(command_);
  }
  double command() const override { return command_; }
  std::string command_unit() const override { return duty_input_ ? "" : "V"; }

  std::vector<Quantity> Quantities() const override {
    std::vector<Quantity> q;
    for (const MotorField& field : kMotorFields) q.push_back({field.name, field.unit, true, true});
    q.push_back({"supply_voltage", "V", true, true});
    q.push_back({"pretension", "N", true, true});
    for (const DriverField& field : kDriverFields)
      q.push_back({field.name, field.unit, true, true});
    for (const Quantity& e : elastic_->Quantities()) q.push_back(e);
    for (const auto& [name, unit] : kStates)
      q.push_back({name, unit ? unit : command_unit(), false, false});
    return q;
  }

  double Get(const std::string& name) const override { return Reader(name)(); }

  std::function<double()> Reader(const std::string& name) const override {
    for (const MotorField& field : kMotorFields)
      if (name == field.name)
        return [this, member = field.member] { return motor_.parameters().*member; };
    if (name == "supply_voltage") return [this] { return supply_voltage_; };
    if (name == "pretension") return [this] { return pretension_; };
    for (const DriverField& field : kDriverFields)
      if (name == field.name) return [this, member = field.member] { return driver_.*member; };
    for (size_t k = 0; k < std::size(kStates); ++k)
      if (name == kStates[k].first) return [this, k] { return State(k); };
    if (HasElastic(name)) return [this, name] { return elastic_->Get(name); };
    throw std::out_of_range(prefix_ + "unknown quantity '" + name + "'");
  }

  void Set(const std::string& name, double value) override {
    try {
      for (const MotorField& field : kMotorFields) {
        if (name != field.name) continue;
        DcMotorParameters p = motor_.parameters();
        p.*field.member = value;
        p.Validate();
        // the engine's time step must not need more sub-steps than one step may take
        if (time_step_ > 0) {
          try {
            DcMotor::CheckSubsteps(time_step_, p.max_substep);
          } catch (const std::invalid_argument& e) {
            throw std::invalid_argument("parameter '" + name + "' = " + Number(value) + " [" +
                                        field.unit + "] refused: " + e.what());
          }
        }
        motor_.set_parameters(p);
        return;
      }
      if (name == "supply_voltage") {
        CheckSupplyVoltage(value);
        supply_voltage_ = value;
        return;
      }
      if (name == "pretension") {
        CheckPretension(value);
        pretension_ = value;
        return;
      }
      for (const DriverField& field : kDriverFields) {
        if (name != field.name) continue;
        CheckDriver(field, value);
        if (field.member == &DriverParameters::command_delay) delay_.SetDelay(value);
        driver_.*field.member = value;
        return;
      }
      for (const auto& [state, unit] : kStates)
        if (name == state)
          throw std::invalid_argument("'" + name + "' [" + (unit ? unit : command_unit()) +
                                      "] is a state, not writable");
      if (HasElastic(name)) return elastic_->Set(name, value);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(prefix_ + e.what());
    }
    throw std::out_of_range(prefix_ + "unknown quantity '" + name + "'");
  }

 private:
  // the motor's, what the step reports and the driver's, the elastic element's
  void SaveOwnState(double* out) const {
    motor_.SaveState(out);
    out += DcMotor::kStateSize;
    out[0] = path_length_;
    out[1] = path_speed_;
    out[2] = line_length_;
    out[3] = elastic_length_;
    out[4] = tension_;
    out[5] = driver_voltage_;
    out[6] = warned_ ? 1 : 0;
    out += kOwnState - DcMotor::kStateSize;
    if (elastic_state_ > 0) elastic_->SaveState(out);
  }

  void RestoreOwnState(const double* in) {
    motor_.RestoreState(in);
    in += DcMotor::kStateSize;
    path_length_ = in[0];
    path_speed_ = in[1];
    line_length_ = in[2];
    elastic_length_ = in[3];
    tension_ = in[4];
    driver_voltage_ = in[5];
    warned_ = in[6] != 0;
    in += kOwnState - DcMotor::kStateSize;
    if (elastic_state_ > 0) elastic_->RestoreState(in);
  }

  static constexpr std::pair<const char*, const char*> kStates[] = {
      {"current", "A"},
      {"spool_speed", "rad/s"},
      {"spool_angle", "rad"},
      {"motor_speed", "rad/s"},
      {"line_length", "m"},
      {"elastic_length", "m"},
      {"tension", "N"},
      {"voltage", "V"},
      {"power", "W"},
      {"winding_temperature", "degC"},
      {"housing_temperature", "degC"},
      {"motor_torque", "N m"},
      {"friction_torque", "N m"},
      {"cogging_torque", "N m"},
      {"hot_resistance", "ohm"},
      {"hot_torque_constant", "N m/A"},
      {"current_limit_now", "A"},
      {"derating", ""},
      {"driver_voltage", "V"},
      {"delayed_command", nullptr}};  // null: the command's unit

  // state k of kStates
  double State(size_t k) const {
    const DcMotorState& s = motor_.state();
    switch (k) {
      case 0:
        return s.current;
      case 1:
        return s.spool_speed;
      case 2:
        return s.spool_angle;
      case 3:
        return motor_.motor_speed();
      case 4:
        return line_length_;
      case 5:
        return elastic_length_;
      case 6:
        return tension_;
      case 7:
        return motor_.applied_voltage();
      case 8:
        return motor_.electrical_power();
      case 9:
        return s.winding_temperature;
      case 10:
        return s.housing_temperature;
      case 11:
        return motor_.motor_torque();
      case 12:
        return motor_.friction_torque();
      case 13:
        return motor_.cogging_torque();
      case 14:
        return motor_.hot_resistance();
      case 15:
        return motor_.hot_torque_constant();
      case 16:
        return motor_.current_limit();
      case 17:
        return motor_.derating();
      case 18:
        return driver_voltage_;
      case 19:
        return delay_.delayed();
    }
    throw std::logic_error("dc motor: no state " + std::to_string(k));
  }
  static_assert(std::size(kStates) == 20, "State() reads each of kStates");

  static void CheckDriver(const DriverField& field, double value) {
    Check(field.name, field.unit, value, field.whole ? Range::kWhole : Range::kNonNegative);
  }
  // the driver's output for the delayed command: with a PWM, quantised to its duty steps within
  // the supply; then moved toward at the slew rate
  double TargetVoltage() const {
    double target = voltage(delay_.delayed());
    const double levels = driver_.pwm_levels;
    if (levels > 0) {
      const double duty = std::clamp(target / supply_voltage_, -1.0, 1.0);
      target = supply_voltage_ * std::round(duty * levels) / levels;
    }
    return target;
  }
  void DriveStep(double dt) {
    try {
      delay_.Take(dt);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(prefix_ + e.what());
    }
    const double target = TargetVoltage();
    if (driver_.slew_rate > 0) {
      const double most = driver_.slew_rate * dt;
      driver_voltage_ += std::clamp(target - driver_voltage_, -most, most);
    } else {
      driver_voltage_ = target;
    }
  }

  // the thermal protection's warning when it starts lowering the current, and a notice when the
  // winding has cooled 2 K below where it starts
  void WatchTemperature() {
    const DcMotorParameters& p = motor_.parameters();
    const double winding = motor_.state().winding_temperature;
    if (!warned_ && motor_.derating() > 0) {
      warned_ = true;
      logging::Get("actuators")
          .warn(
              "%swinding at %.1f degC, within %g K of its maximum %g degC: the driver lowers "
              "its current limit (to %.3g A, the continuous current, at %g degC)",
              prefix_.c_str(), winding, p.derating_band, p.max_winding_temperature,
              motor_.continuous_current(), p.max_winding_temperature);
    } else if (warned_ && winding < p.max_winding_temperature - p.derating_band - 2) {
      warned_ = false;
      logging::Get("actuators")
          .notice("%swinding cooled to %.1f degC: the driver's full current limit is back",
                  prefix_.c_str(), winding);
    }
  }

  static void CheckSupplyVoltage(double value) {
    if (!(value > 0) || !std::isfinite(value))
      throw std::invalid_argument("parameter 'supply_voltage' must be > 0 [V], got " +
                                  Number(value));
  }
  static void CheckPretension(double value) {
    if (!(value >= 0) || !std::isfinite(value))
      throw std::invalid_argument("parameter 'pretension' must be >= 0 [N], got " + Number(value));
  }

  bool HasElastic(const std::string& name) const {
    for (const Quantity& q : elastic_->Quantities())
      if (q.name == name) return true;
    return false;
  }

  double voltage(double command) const { return duty_input_ ? command * supply_voltage_ : command; }

  // Reset keeps the element just taut at the pretension, whatever the path: a relaxed element
  // longer than the path leaves a negative line, which a file author rarely means (a rest_length
  // in the wrong unit, or a route shorter than drawn), so the load says so in millimetres
  void WarnNegativeLine() const {
    constexpr double kMm = 1000;  // [mm/m]
    std::string rest;
    if (HasElastic("rest_length"))
      rest = "rest_length " + Number(elastic_->Get("rest_length") * kMm) + " mm";
    if (pretension_ > 0)
      rest += (rest.empty() ? "" : ", ") + std::string("relaxed length ") +
              Number(elastic_length_ * kMm) + " mm at pretension " + Number(pretension_) + " N";
    logging::Get("actuators")
        .warn(
            "%sits elastic element (%s) is longer than its tendon path at load (%s mm): the "
            "kite line starts at %s mm, i.e. %s mm of the element counts as already wound on "
            "the spool; it is just taut at %s N and pulls as soon as the spool winds in (an "
            "element shorter than %s mm when relaxed gives a line of positive length)",
            prefix_.c_str(), rest.c_str(), Number(path_length_ * kMm).c_str(),
            Number(line_length_ * kMm).c_str(), Number(-line_length_ * kMm).c_str(),
            Number(pretension_).c_str(), Number(path_length_ * kMm).c_str());
  }

  std::string prefix_;
  DcMotor motor_;
  std::unique_ptr<ElasticElement> elastic_;
  const LinearSpringDamper* linear_ = nullptr;  // elastic_ when it is linear (no virtual calls)
  std::size_t elastic_state_ = 0;               // elastic_->StateSize()
  static constexpr std::size_t kOwnState = DcMotor::kStateSize + 7;
  bool duty_input_ = false;
  double supply_voltage_ = kDefaultSupplyVoltage;  // [V]
  double pretension_ = 0;                          // at Reset [N]
  double command_ = 0;                             // [V] or duty [-]
  DriverParameters driver_;
  CommandDelay delay_;          // the command's way to the driver (driver_.command_delay)
  double driver_voltage_ = 0;   // its output [V]
  bool warned_ = false;         // of the thermal protection
  double time_step_ = 0;        // the engine's, once told [s]
  double path_length_ = 0;      // [m]
  double path_speed_ = 0;       // [m/s]
  double line_length_ = 0;      // free kite line [m]
  double elastic_length_ = 0;   // [m]
  double tension_ = 0;          // [N]
};

// a passive tension-only spring-damper along the tendon
class Ligament final : public TendonActuator {
 public:
  explicit Ligament(const sgal::Actuator& a) : prefix_(Prefix(a)) {
    const double rest = ParameterOr(a, "rest_length", 0);
    rest_from_path_ = rest == 0;
    try {
      spring_ = std::make_unique<LinearSpringDamper>(ParameterOr(a, "stiffness", 0),
                                                     ParameterOr(a, "damping", 0),
                                                     rest_from_path_ ? 1.0 : rest);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(prefix_ + e.what());
    }
  }

  void Reset(double path_length) override {
    RequireFinite(prefix_, "path length", path_length);
    if (rest_from_path_) {
      if (!(path_length > 0))
        throw std::invalid_argument(prefix_ + "rest length from a path of length " +
                                    Number(path_length) + " m: must be > 0");
      spring_->Set("rest_length", path_length);
    }
    length_ = path_length;
    speed_ = 0;
    tension_ = spring_->Peek(length_, 0, 0);
  }

  double Step(double path_length, double path_speed, double dt, double end_speed) override {
    RequireFinite(prefix_, "path length", path_length);
    RequireFinite(prefix_, "path speed", path_speed);
    RequireFinite(prefix_, "path speed at the end", end_speed);
    if (!(dt > 0) || !std::isfinite(dt))
      throw std::invalid_argument(prefix_ + "time step must be > 0 [s], got " + Number(dt));
    // the tension at the end of the step, where the path has moved to and moves at end_speed
    // (the actuator contract; the spring-damper is stateless)
    length_ = path_length + path_speed * dt;
    speed_ = end_speed;
    tension_ = spring_->Force(length_, end_speed, dt);
    return tension_;
  }

  double tension() const override { return tension_; }

  // the spring is stateless: the step changes only what it reports
  std::size_t StateSize() const override { return 3; }
  void SaveState(double* out) const override {
    out[0] = tension_;
    out[1] = length_;
    out[2] = speed_;
  }
  void RestoreState(const double* in) override {
    tension_ = in[0];
    length_ = in[1];
    speed_ = in[2];
  }
  // all of it, in one call (the engine saves it before every step)
  void SaveStepState(double* out) const override { SaveState(out); }
  void RestoreStepState(const double* in) override { RestoreState(in); }

  void SetCommand(double) override {
    throw std::invalid_argument(prefix_ + "a ligament is passive and takes no command");
  }
  double command() const override { return 0; }
  std::string command_unit() const override { return ""; }

  std::vector<Quantity> Quantities() const override {
    std::vector<Quantity> q = spring_->Quantities();
    q.push_back({"tension", "N", false, false});
    q.push_back({"length", "m", false, false});
    q.push_back({"speed", "m/s", false, false});
    return q;
  }

  double Get(const std::string& name) const override {
    if (name == "tension") return tension_;
    if (name == "length") return length_;
    if (name == "speed") return speed_;
    try {
      return spring_->Get(name);
    } catch (const std::out_of_range&) {
      throw std::out_of_range(prefix_ + "unknown quantity '" + name + "'");
    }
  }

  void Set(const std::string& name, double value) override {
    if (name == "tension" || name == "length" || name == "speed")
      throw std::invalid_argument(prefix_ + "'" + name + "' is a state, not writable");
    try {
      spring_->Set(name, value);
    } catch (const std::out_of_range&) {
      throw std::out_of_range(prefix_ + "unknown quantity '" + name + "'");
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(prefix_ + e.what());
    }
    if (name == "rest_length") rest_from_path_ = false;
  }

 private:
  std::string prefix_;
  std::unique_ptr<LinearSpringDamper> spring_;
  bool rest_from_path_ = false;  // rest length = path length at Reset
  double tension_ = 0;           // [N]
  double length_ = 0;            // at the end of the last step [m]
  double speed_ = 0;             // [m/s]
};

std::vector<ParameterSpec> DcMotorTendonParameters() {
  const DcMotorParameters defaults;
  std::vector<ParameterSpec> specs;
  for (const MotorField& field : kMotorFields)
    specs.push_back({field.name, field.unit, defaults.*field.member, false, field.help});
  specs.push_back({"supply_voltage", "V", kDefaultSupplyVoltage, false,
                   "supply voltage, scaled by the duty with options[\"input\"] = duty"});
  specs.push_back({"pretension", "N", 0, false, "tension of the elastic element at Reset"});
  const DriverParameters driver;
  for (const DriverField& field : kDriverFields)
    specs.push_back({field.name, field.unit, driver.*field.member, false, field.help});
  for (const ParameterSpec& spec : ElasticParameterSpecs()) specs.push_back(spec);
  return specs;
}

std::vector<ParameterSpec> LigamentParameters() {
  return {{"stiffness", "N/m", 0, true, "ligament stiffness k"},
          {"damping", "N s/m", 0, false, "ligament damping c, in tension only"},
          {"rest_length", "m", 0, false, "slack length (0: the path length at Reset)"}};
}

}  // namespace

void RegisterMotorKinds() {
  RegisterKind("dc_motor_tendon", DcMotorTendonParameters(), [](const sgal::Actuator& a) {
    return std::unique_ptr<TendonActuator>(std::make_unique<DcMotorTendon>(a));
  });
  RegisterKind("ligament", LigamentParameters(), [](const sgal::Actuator& a) {
    return std::unique_ptr<TendonActuator>(std::make_unique<Ligament>(a));
  });
}

}  // namespace caliper::actuators
