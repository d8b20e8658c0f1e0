#pragma once
// Series-elastic elements, engine-free: what sits between an inextensible kite line and a bone
// (shock cord, a spring) or makes up a ligament. All are tension-only: slack below their rest
// length, never pushing. SI units.

#include <cstddef>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "caliper/actuators/actuator.h"
#include "caliper/sgal/scene.h"

namespace caliper::actuators {

/// A tension-only elastic element. The state (if any) advances with Force(); Peek() evaluates the
/// same step without changing it, so that a motor can treat the element implicitly.
class ElasticElement {
 public:
  virtual ~ElasticElement() = default;

  /// linear, zener, polynomial or table.
  virtual std::string kind() const = 0;

  /// Sets the state relaxed (at rest for a long time) at this length [m].
  virtual void Reset(double length) = 0;

  /// The tension [N] (>= 0) after dt [s] (>= 0; 0 is an instantaneous change) in which the length
  /// moves linearly from the last accepted length to `length` [m], with lengthening speed `rate`
  /// [m/s] at the end. Does not change the state.
  virtual double Peek(double length, double rate, double dt) const = 0;

  /// Peek() and its derivatives by the length [N/m] and by the rate [N s/m] (one-sided at a
  /// kink: those of the branch that gave the force), for a motor's Newton iteration. The default
  /// differentiates Peek() numerically; the elements here give them exactly.
  virtual double PeekWithSlopes(double length, double rate, double dt, double* d_length,
                                double* d_rate) const;

  /// Peek() on the line (length + d_length x, rate + d_rate x): returns the tension at x = 0 and
  /// sets *slope to its derivative by x and [*low, *high] (*low <= 0 <= *high) to the x over
  /// which it is exactly affine with that slope (both 0 when not known). The default uses
  /// PeekWithSlopes() and knows no range; the linear and Zener elements give it.
  virtual double PeekAlong(double length, double rate, double dt, double d_length, double d_rate,
                           double* slope, double* low, double* high) const;

  /// As Peek(), and accepts the step: the element's state moves on.
  virtual double Force(double length, double rate, double dt) = 0;

  /// How many values SaveState() writes (0 for the stateless elements).
  virtual std::size_t StateSize() const { return 0; }
  /// Writes StateSize() values: what Force() changes.
  virtual void SaveState(double* out) const { (void)out; }
  /// Reads back the StateSize() values SaveState() wrote.
  virtual void RestoreState(const double* in) { (void)in; }

  /// The length [m] at which the relaxed element carries this tension [N] (>= 0). Throws
  /// std::invalid_argument when the element never reaches it.
  virtual double RelaxedLength(double force) const = 0;

  /// The length below which the element is slack [m].
  double rest_length() const { return rest_length_; }

  /// Parameters (static, writable) and states (read-only), by name.
  std::vector<Quantity> Quantities() const;
  /// Throws std::out_of_range for an unknown name.
  double Get(const std::string& name) const;
  /// Throws std::out_of_range (unknown) or std::invalid_argument (read-only, non-finite, out of
  /// range), with the name and unit in the message.
  void Set(const std::string& name, double value);

 protected:
  /// How a named value may be set.
  enum class Range { kAny, kPositive, kNonNegative, kReadOnly };
  /// A named value of the element: its description, where it lives, how it is checked.
  struct Field {
    Quantity quantity;
    double* value = nullptr;
    Range range = Range::kAny;
  };
  /// Every named value, parameters first.
  virtual std::vector<Field> Fields() = 0;
  /// Called after Set() changed a value (derived states may need an update).
  virtual void Changed() {}
  /// Checks a value for a field; throws std::invalid_argument naming it.
  static void CheckValue(const Field& field, double value);
  /// A parameter field: static and writable.
  static Field Parameter(const std::string& name, const std::string& unit, double* value,
                         Range range);
  /// A state field: read-only.
  static Field State(const std::string& name, const std::string& unit, double* value);
  /// For PeekAlong(): narrows [*low, *high] to the x over which g0 + g1 x keeps the side of zero
  /// g0 is on (> 0, or <= 0), with a margin of 1e-9 of the distance to the crossing.
  static void KeepSign(double g0, double g1, double* low, double* high) {
    if (g1 == 0) return;
    const double crossing = -g0 / g1 * (1 - 1e-9);
    if ((g0 > 0) == (g1 > 0)) {
      if (crossing > *low) *low = crossing;
    } else if (crossing < *high) {
      *high = crossing;
    }
  }
  static constexpr double kUnbounded = 1e300;

  double rest_length_ = 0;  // [m]
};

/// F = k (l - l_rest) + c dl/dt when l > l_rest, then F = max(F, 0); 0 when slack. Stateless.
class LinearSpringDamper final : public ElasticElement {
 public:
  /// stiffness [N/m] > 0, damping [N s/m] >= 0, rest_length [m] > 0; throws
  /// std::invalid_argument naming a parameter out of range.
  LinearSpringDamper(double stiffness, double damping, double rest_length);
  std::string kind() const override { return "linear"; }
  void Reset(double) override {}
  double Peek(double length, double rate, double) const override {
    const double extension = length - rest_length_;
    if (extension <= 0) return 0;
    const double force = stiffness_ * extension + damping_ * rate;
    return force < 0 ? 0.0 : force;  // std::max(force, 0.0)
  }
  double PeekWithSlopes(double length, double rate, double, double* d_length,
                        double* d_rate) const override {
    const double extension = length - rest_length_;
    const double force = stiffness_ * extension + damping_ * rate;
    if (extension <= 0 || !(force > 0)) {
      *d_length = *d_rate = 0;
      return 0;
    }
    *d_length = stiffness_;
    *d_rate = damping_;
    return force;
  }
  double PeekAlong(double length, double rate, double, double d_length, double d_rate,
                   double* slope, double* low, double* high) const override {
    const double extension = length - rest_length_;
    const double force = stiffness_ * extension + damping_ * rate;
    const double d_force = stiffness_ * d_length + damping_ * d_rate;
    *low = -kUnbounded;
    *high = kUnbounded;
    KeepSign(extension, d_length, low, high);  // taut or slack
    if (extension <= 0) {
      *slope = 0;
      return 0;
    }
    KeepSign(force, d_force, low, high);  // pulling or not
    *slope = force > 0 ? d_force : 0.0;
    return force < 0 ? 0.0 : force;
  }
  double Force(double length, double rate, double dt) override { return Peek(length, rate, dt); }
  double RelaxedLength(double force) const override;

  double stiffness() const { return stiffness_; }
  double damping() const { return damping_; }

 protected:
  std::vector<Field> Fields() override;

 private:
  double stiffness_;  // k [N/m]
  double damping_;    // c [N s/m]
};

/// Constants of the Zener (standard linear solid) element.
struct ZenerParameters {
  double e0 = 0.694e6;                               // E0, equilibrium modulus [Pa]
  double e1 = 0.2116e6;                              // E1, Maxwell arm modulus [Pa]
  double mu = 277788.48;                             // Maxwell arm viscosity [Pa s]
  double area = 3.14159265358979323846 * 25e-6 / 4;  // A_0, cross-section [m^2]
  double rest_length = 0.01;                         // L_0 [m]
};

/// Zener / standard linear solid (TENDONS.md): strain e = l / L_0 - 1 clamped at 0, stress s with
/// ds/dt + (E1/mu) s = (E0 + E1) de/dt + (E0 E1 / mu) e, F = max(s A_0, 0). Written as
/// s = E0 e + q with the Maxwell arm's stress dq/dt = -(E1/mu) q + E1 de/dt, and q updated exactly
/// for a strain moving linearly over each step (stable and exact for any dt). The strain rate
/// comes from the change of length over the step; the `rate` argument is not used. The exp()
/// factors of the last two step lengths are cached (a motor peeks at two in turn), so the const
/// members must not run concurrently on one element.
class ZenerElement : public ElasticElement {
 public:
  /// Throws std::invalid_argument naming a parameter that is not positive.
  explicit ZenerElement(const ZenerParameters& parameters = {});
  std::string kind() const override { return "zener"; }
  void Reset(double length) override;
  double Peek(double length, double rate, double dt) const override;
  double PeekWithSlopes(double length, double rate, double dt, double* d_length,
                        double* d_rate) const override;
  double PeekAlong(double length, double rate, double dt, double d_length, double d_rate,
                   double* slope, double* low, double* high) const override;
  double Force(double length, double rate, double dt) override;
  double RelaxedLength(double force) const override;
  /// The strain, the Maxwell arm's stress and the stress (the factor cache holds exact values
  /// of its step lengths: not part of the state).
  std::size_t StateSize() const override { return 3; }
  void SaveState(double* out) const override {
    out[0] = strain_;
    out[1] = maxwell_stress_;
    out[2] = stress_;
  }
  void RestoreState(const double* in) override {
    strain_ = in[0];
    maxwell_stress_ = in[1];
    stress_ = in[2];
  }

  /// The strain [-] and stress [Pa] of the last accepted step.
  double strain() const { return strain_; }
  double stress() const { return stress_; }
  /// The relaxation time mu / E1 [s].
  double relaxation_time() const { return mu_ / e1_; }

 protected:
  std::vector<Field> Fields() override;
  void Changed() override;

 private:
  struct Next {
    double strain;          // [-]
    double maxwell_stress;  // q [Pa]
    double stress;          // s [Pa]
  };
  // the Maxwell arm's factors over a step of dt: decay e^-x and ramp (1 - e^-x) / x,
  // x = dt E1 / mu; cached for the last two step lengths (a motor alternates two)
  struct Factors {
    double dt = -1;    // [s]; < 0: empty
    double decay = 1;  // [-]
    double ramp = 1;   // [-]
  };
  const Factors& FactorsFor(double dt) const;
  Next Advance(double length, double dt) const;

  mutable Factors factors_[2];
  mutable int factors_next_ = 0;  // the entry replaced next
  double e0_;                     // [Pa]
  double e1_;                     // [Pa]
  double mu_;                     // [Pa s]
  double area_;                   // [m^2]
  double strain_ = 0;             // [-]
  double maxwell_stress_ = 0;     // q [Pa]
  double stress_ = 0;             // s [Pa]
};

/// F = sum_i c_i x^i + c dl/dt for the extension x = l - l_rest > 0, then F = max(F, 0); 0 when
/// slack. Stateless.
class PolynomialSpring : public ElasticElement {
 public:
  /// The most coefficients a kind's parameters can give (poly_c1 ... poly_c5).
  static constexpr int kMaxOrder = 5;
  /// coefficients c_1 ... c_n [N/m^i] (finite, n <= kMaxOrder), damping [N s/m] >= 0,
  /// rest_length [m] > 0.
  PolynomialSpring(std::vector<double> coefficients, double damping, double rest_length);
  std::string kind() const override { return "polynomial"; }
  void Reset(double) override {}
  double Peek(double length, double rate, double dt) const override;
  double PeekWithSlopes(double length, double rate, double dt, double* d_length,
                        double* d_rate) const override;
  double Force(double length, double rate, double dt) override { return Peek(length, rate, dt); }
  /// Solved by bisection for the first extension reaching the force.
  double RelaxedLength(double force) const override;

 protected:
  std::vector<Field> Fields() override;

 private:
  double Static(double extension) const;  // [N]
  std::vector<double> coefficients_;      // c_i [N/m^i]
  double damping_;                        // [N s/m]
};

/// A tabulated spring: (extension [m], force [N]) points, linearly interpolated, from (0, 0) to
/// the first point and extrapolated with the last segment's slope; plus c dl/dt in tension,
/// F = max(F, 0); 0 when slack. Stateless.
class TableSpring : public ElasticElement {
 public:
  /// points with strictly increasing extensions >= 0, the last > 0, finite forces;
  /// damping [N s/m] >= 0, rest_length [m] > 0.
  TableSpring(std::vector<std::pair<double, double>> points, double damping, double rest_length);
  /// Points from text: pairs "extension force" separated by commas, semicolons or blanks, e.g.
  /// "0.01 1; 0.02 5". Throws std::invalid_argument on malformed text.
  static std::vector<std::pair<double, double>> Parse(const std::string& text);
  std::string kind() const override { return "table"; }
  void Reset(double) override {}
  double Peek(double length, double rate, double dt) const override;
  double PeekWithSlopes(double length, double rate, double dt, double* d_length,
                        double* d_rate) const override;
  double Force(double length, double rate, double dt) override { return Peek(length, rate, dt); }
  double RelaxedLength(double force) const override;

 protected:
  std::vector<Field> Fields() override;

 private:
  // the force [N] at an extension [m] > 0, and the slope of the segment used [N/m]
  double Static(double extension, double* slope = nullptr) const;
  std::vector<std::pair<double, double>> points_;  // from (0, 0) [m], [N]
  double damping_;                                 // [N s/m]
};

/// The parameters an actuator kind with a series-elastic element takes for it (all with
/// defaults): stiffness, damping, rest_length, zener_E0, zener_E1, zener_mu, zener_area,
/// poly_c1 ... poly_c5.
std::vector<ParameterSpec> ElasticParameterSpecs();

/// The element an actuator description asks for: options["elastic"] = linear (default), zener,
/// polynomial or table (points in options["elastic_table"], see TableSpring::Parse), with the
/// parameters of ElasticParameterSpecs(). Throws std::invalid_argument naming the actuator and the
/// option or parameter at fault.
std::unique_ptr<ElasticElement> MakeElasticElement(const sgal::Actuator& description);

}  // namespace caliper::actuators
