#include "caliper/actuators/elastic.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>

#include "caliper/core/numbers.h"

namespace caliper::actuators {

namespace {

constexpr double kPi = 3.14159265358979323846;

const char* const kElasticKinds = "linear, zener, polynomial, table";

std::string PolynomialName(int i) { return "poly_c" + std::to_string(i); }

std::string PolynomialUnit(int i) { return i == 1 ? "N/m" : "N/m^" + std::to_string(i); }

std::string Number(double value) {
  std::ostringstream s;
  s << value;
  return s.str();
}

}  // namespace

std::vector<Quantity> ElasticElement::Quantities() const {
  std::vector<Quantity> quantities;
  for (const Field& field : const_cast<ElasticElement*>(this)->Fields())
    quantities.push_back(field.quantity);
  return quantities;
}

double ElasticElement::Get(const std::string& name) const {
  for (const Field& field : const_cast<ElasticElement*>(this)->Fields())
    if (field.quantity.name == name) return *field.value;
  throw std::out_of_range("elastic element (" + kind() + "): unknown quantity '" + name + "'");
}

void ElasticElement::Set(const std::string& name, double value) {
  for (const Field& field : Fields()) {
    if (field.quantity.name != name) continue;
    CheckValue(field, value);
    *field.value = value;
    Changed();
    return;
  }
  throw std::out_of_range("elastic element (" + kind() + "): unknown quantity '" + name + "'");
}

void ElasticElement::CheckValue(const Field& field, double value) {
  const Quantity& q = field.quantity;
  if (field.range == Range::kReadOnly)
    throw std::invalid_argument("'" + q.name + "' [" + q.unit + "] is a state, not writable");
  bool ok = std::isfinite(value);
  std::string expected = "finite";
  if (field.range == Range::kPositive) {
    ok = ok && value > 0;
    expected = "> 0";
  } else if (field.range == Range::kNonNegative) {
    ok = ok && value >= 0;
    expected = ">= 0";
  }
  if (!ok)
    throw std::invalid_argument("parameter '" + q.name + "' must be " + expected + " [" + q.unit +
                                "], got " + Number(value));
}

double ElasticElement::PeekWithSlopes(double length, double rate, double dt, double* d_length,
                                      double* d_rate) const {
  const double dl = 1e-9 * std::max(1.0, std::abs(length));
  const double dv = 1e-9 * std::max(1.0, std::abs(rate));
  *d_length = (Peek(length + dl, rate, dt) - Peek(length - dl, rate, dt)) / (2 * dl);
  *d_rate = (Peek(length, rate + dv, dt) - Peek(length, rate - dv, dt)) / (2 * dv);
  return Peek(length, rate, dt);
}

double ElasticElement::PeekAlong(double length, double rate, double dt, double d_length,
                                 double d_rate, double* slope, double* low, double* high) const {
  double by_length;
  double by_rate;
  const double force = PeekWithSlopes(length, rate, dt, &by_length, &by_rate);
  *slope = by_length * d_length + by_rate * d_rate;
  *low = *high = 0;
  return force;
}

ElasticElement::Field ElasticElement::Parameter(const std::string& name, const std::string& unit,
                                                double* value, Range range) {
  return Field{Quantity{name, unit, true, true}, value, range};
}

ElasticElement::Field ElasticElement::State(const std::string& name, const std::string& unit,
                                            double* value) {
  return Field{Quantity{name, unit, false, false}, value, Range::kReadOnly};
}

LinearSpringDamper::LinearSpringDamper(double stiffness, double damping, double rest_length)
    : stiffness_(stiffness), damping_(damping) {
  rest_length_ = rest_length;
  for (const Field& field : Fields()) CheckValue(field, *field.value);
}

double LinearSpringDamper::RelaxedLength(double force) const {
  return rest_length_ + std::max(force, 0.0) / stiffness_;
}

std::vector<ElasticElement::Field> LinearSpringDamper::Fields() {
  return {Parameter("stiffness", "N/m", &stiffness_, Range::kPositive),
          Parameter("damping", "N s/m", &damping_, Range::kNonNegative),
          Parameter("rest_length", "m", &rest_length_, Range::kPositive)};
}

ZenerElement::ZenerElement(const ZenerParameters& p)
    : e0_(p.e0), e1_(p.e1), mu_(p.mu), area_(p.area) {
  rest_length_ = p.rest_length;
  for (const Field& field : Fields())
    if (field.range != Range::kReadOnly) CheckValue(field, *field.value);
  Reset(rest_length_);
}

const ZenerElement::Factors& ZenerElement::FactorsFor(double dt) const {
  dt = std::max(dt, 0.0);
  for (const Factors& f : factors_)
    if (f.dt == dt) return f;
  Factors& f = factors_[factors_next_];
  factors_next_ = 1 - factors_next_;
  const double x = dt * e1_ / mu_;
  f.dt = dt;
  f.decay = std::exp(-x);
  f.ramp = x > 0 ? -std::expm1(-x) / x : 1.0;
  return f;
}

ZenerElement::Next ZenerElement::Advance(double length, double dt) const {
  Next next;
  next.strain = std::max(length / rest_length_ - 1, 0.0);
  // exact for a strain moving linearly: q decays, the ramp adds E1 de (1 - e^-x) / x
  const Factors& f = FactorsFor(dt);
  next.maxwell_stress = maxwell_stress_ * f.decay + e1_ * (next.strain - strain_) * f.ramp;
  next.stress = e0_ * next.strain + next.maxwell_stress;
  return next;
}

void ZenerElement::Reset(double length) {
  strain_ = std::max(length / rest_length_ - 1, 0.0);
  maxwell_stress_ = 0;
  stress_ = e0_ * strain_;
}

double ZenerElement::Peek(double length, double, double dt) const {
  return std::max(Advance(length, dt).stress * area_, 0.0);
}

double ZenerElement::PeekWithSlopes(double length, double, double dt, double* d_length,
                                    double* d_rate) const {
  const Factors& f = FactorsFor(dt);
  const double strain = std::max(length / rest_length_ - 1, 0.0);
  const double stress =
      e0_ * strain + (maxwell_stress_ * f.decay + e1_ * (strain - strain_) * f.ramp);  // Advance()
  *d_rate = 0;
  const double force = stress * area_;
  if (!(force > 0)) {
    *d_length = 0;
    return 0;
  }
  *d_length = strain > 0 ? area_ * (e0_ + e1_ * f.ramp) / rest_length_ : 0.0;
  return force;
}

double ZenerElement::PeekAlong(double length, double, double dt, double d_length, double,
                               double* slope, double* low, double* high) const {
  const Factors& f = FactorsFor(dt);
  const double raw = length / rest_length_ - 1;  // the strain before clamping at 0
  const double strain = std::max(raw, 0.0);
  const double stress =
      e0_ * strain + (maxwell_stress_ * f.decay + e1_ * (strain - strain_) * f.ramp);  // Advance()
  // stress is affine in the length while the strain is positive, constant while it is clamped
  const double d_stress = raw > 0 ? (e0_ + e1_ * f.ramp) * d_length / rest_length_ : 0.0;
  *low = -kUnbounded;
  *high = kUnbounded;
  KeepSign(raw, d_length / rest_length_, low, high);
  KeepSign(stress, d_stress, low, high);
  const double force = stress * area_;
  if (!(force > 0)) {
    *slope = 0;
    return 0;
  }
  *slope = area_ * d_stress;
  return force;
}

double ZenerElement::Force(double length, double, double dt) {
  const Next next = Advance(length, dt);
  strain_ = next.strain;
  maxwell_stress_ = next.maxwell_stress;
  stress_ = next.stress;
  return std::max(stress_ * area_, 0.0);
}

double ZenerElement::RelaxedLength(double force) const {
  return rest_length_ * (1 + std::max(force, 0.0) / (e0_ * area_));
}

std::vector<ElasticElement::Field> ZenerElement::Fields() {
  return {Parameter("zener_E0", "Pa", &e0_, Range::kPositive),
          Parameter("zener_E1", "Pa", &e1_, Range::kPositive),
          Parameter("zener_mu", "Pa s", &mu_, Range::kPositive),
          Parameter("zener_area", "m^2", &area_, Range::kPositive),
          Parameter("rest_length", "m", &rest_length_, Range::kPositive),
          State("strain", "", &strain_),
          State("stress", "Pa", &stress_)};
}

void ZenerElement::Changed() {
  stress_ = e0_ * strain_ + maxwell_stress_;
  factors_[0] = factors_[1] = Factors{};  // E1 or mu may have changed
}

PolynomialSpring::PolynomialSpring(std::vector<double> coefficients, double damping,
                                   double rest_length)
    : coefficients_(std::move(coefficients)), damping_(damping) {
  rest_length_ = rest_length;
  if (static_cast<int>(coefficients_.size()) > kMaxOrder)
    throw std::invalid_argument("polynomial spring: at most " + std::to_string(kMaxOrder) +
                                " coefficients, got " + std::to_string(coefficients_.size()));
  coefficients_.resize(kMaxOrder, 0.0);
  for (const Field& field : Fields()) CheckValue(field, *field.value);
}

double PolynomialSpring::Static(double extension) const {
  double force = 0;
  for (auto c = coefficients_.rbegin(); c != coefficients_.rend(); ++c)
    force = (force + *c) * extension;
  return force;
}

double PolynomialSpring::Peek(double length, double rate, double) const {
  const double extension = length - rest_length_;
  if (extension <= 0) return 0;
  return std::max(Static(extension) + damping_ * rate, 0.0);
}

double PolynomialSpring::PeekWithSlopes(double length, double rate, double, double* d_length,
                                        double* d_rate) const {
  const double extension = length - rest_length_;
  double force = 0;
  double slope = 0;
  if (extension > 0) {
    for (auto c = coefficients_.rbegin(); c != coefficients_.rend(); ++c) {
      slope = slope * extension + (force + *c);
      force = (force + *c) * extension;
    }
    force += damping_ * rate;
  }
  if (extension <= 0 || !(force > 0)) {
    *d_length = *d_rate = 0;
    return 0;
  }
  *d_length = slope;
  *d_rate = damping_;
  return force;
}

double PolynomialSpring::RelaxedLength(double force) const {
  if (force <= 0) return rest_length_;
  double low = 0;
  double high = 1e-3;  // [m]
  while (Static(high) < force) {
    low = high;
    high *= 2;
    if (high > 1e6)
      throw std::invalid_argument("polynomial spring never reaches " + Number(force) + " N");
  }
  for (int i = 0; i < 200 && high - low > 1e-15 * high; ++i) {
    const double middle = 0.5 * (low + high);
    (Static(middle) < force ? low : high) = middle;
  }
  return rest_length_ + high;
}

std::vector<ElasticElement::Field> PolynomialSpring::Fields() {
  std::vector<Field> fields;
  for (int i = 0; i < kMaxOrder; ++i)
    fields.push_back(
        Parameter(PolynomialName(i + 1), PolynomialUnit(i + 1), &coefficients_[i], Range::kAny));
  fields.push_back(Parameter("damping", "N s/m", &damping_, Range::kNonNegative));
  fields.push_back(Parameter("rest_length", "m", &rest_length_, Range::kPositive));
  return fields;
}

TableSpring::TableSpring(std::vector<std::pair<double, double>> points, double damping,
                         double rest_length)
    : damping_(damping) {
  rest_length_ = rest_length;
  if (points.empty()) throw std::invalid_argument("table spring: no points");
  double previous = -1;
  for (const auto& [x, f] : points) {
    if (!std::isfinite(x) || !std::isfinite(f) || x < 0 || x <= previous)
      throw std::invalid_argument(
          "table spring: extensions must be finite, >= 0 and strictly increasing, forces "
          "finite; got point (" +
          Number(x) + " m, " + Number(f) + " N)");
    previous = x;
  }
  if (points.back().first <= 0)
    throw std::invalid_argument("table spring: the last extension must be > 0 [m]");
  if (points.front().first > 0) points_.push_back({0.0, 0.0});
  points_.insert(points_.end(), points.begin(), points.end());
  for (const Field& field : Fields()) CheckValue(field, *field.value);
}

std::vector<std::pair<double, double>> TableSpring::Parse(const std::string& text) {
  std::string cleaned = text;
  std::replace(cleaned.begin(), cleaned.end(), ',', ' ');
  std::replace(cleaned.begin(), cleaned.end(), ';', ' ');
  std::istringstream in(cleaned);
  std::vector<double> numbers;
  std::string word;
  while (in >> word) {
    double value = 0;
    if (!core::ParseDouble(word, &value))
      throw std::invalid_argument("table spring: '" + word + "' is not a number in '" + text + "'");
    numbers.push_back(value);
  }
  if (numbers.empty() || numbers.size() % 2 != 0)
    throw std::invalid_argument(
        "table spring: expected pairs 'extension force' (e.g. \"0.01 1; 0.02 5\"), got '" + text +
        "'");
  std::vector<std::pair<double, double>> points;
  for (std::size_t i = 0; i < numbers.size(); i += 2)
    points.push_back({numbers[i], numbers[i + 1]});
  return points;
}

double TableSpring::Static(double extension, double* slope) const {
  std::size_t i = 1;
  while (i + 1 < points_.size() && points_[i].first < extension) ++i;
  const auto& [x0, f0] = points_[i - 1];
  const auto& [x1, f1] = points_[i];
  if (slope) *slope = (f1 - f0) / (x1 - x0);
  return f0 + (f1 - f0) * (extension - x0) / (x1 - x0);
}

double TableSpring::PeekWithSlopes(double length, double rate, double, double* d_length,
                                   double* d_rate) const {
  const double extension = length - rest_length_;
  double slope = 0;
  const double force = extension > 0 ? Static(extension, &slope) + damping_ * rate : 0.0;
  if (!(force > 0)) {
    *d_length = *d_rate = 0;
    return 0;
  }
  *d_length = slope;
  *d_rate = damping_;
  return force;
}

double TableSpring::Peek(double length, double rate, double) const {
  const double extension = length - rest_length_;
  if (extension <= 0) return 0;
  return std::max(Static(extension) + damping_ * rate, 0.0);
}

double TableSpring::RelaxedLength(double force) const {
  if (force <= 0) return rest_length_;
  for (std::size_t i = 1; i < points_.size(); ++i) {
    const auto& [x0, f0] = points_[i - 1];
    const auto& [x1, f1] = points_[i];
    const bool last = i + 1 == points_.size();
    if ((f1 >= force || last) && f1 > f0 && force >= f0)
      return rest_length_ + x0 + (force - f0) * (x1 - x0) / (f1 - f0);
  }
  throw std::invalid_argument("table spring never reaches " + Number(force) + " N");
}

std::vector<ElasticElement::Field> TableSpring::Fields() {
  return {Parameter("damping", "N s/m", &damping_, Range::kNonNegative),
          Parameter("rest_length", "m", &rest_length_, Range::kPositive)};
}

std::vector<ParameterSpec> ElasticParameterSpecs() {
  const ZenerParameters zener;
  std::vector<ParameterSpec> specs = {
      {"stiffness", "N/m", 1000, false, "linear series spring stiffness"},
      {"damping", "N s/m", 0, false, "series damping, in tension only (linear, polynomial, table)"},
      {"rest_length", "m", 0.05, false, "length below which the elastic element is slack (L_0)"},
      {"zener_E0", "Pa", zener.e0, false, "Zener equilibrium modulus"},
      {"zener_E1", "Pa", zener.e1, false, "Zener Maxwell arm modulus"},
      {"zener_mu", "Pa s", zener.mu, false, "Zener Maxwell arm viscosity"},
      {"zener_area", "m^2", kPi * 25e-6 / 4, false, "Zener cross-section A_0"}};
  for (int i = 1; i <= PolynomialSpring::kMaxOrder; ++i)
    specs.push_back({PolynomialName(i), PolynomialUnit(i), 0, false,
                     "polynomial spring coefficient of extension^" + std::to_string(i)});
  return specs;
}

std::unique_ptr<ElasticElement> MakeElasticElement(const sgal::Actuator& a) {
  std::map<std::string, double> defaults;
  for (const ParameterSpec& spec : ElasticParameterSpecs())
    defaults[spec.name] = spec.default_value;
  auto value = [&](const std::string& name) { return ParameterOr(a, name, defaults.at(name)); };
  const auto option = a.options.find("elastic");
  const std::string kind = option == a.options.end() ? "linear" : option->second;
  const std::string prefix = "actuator '" + a.name + "' (" + a.kind + "): ";
  try {
    if (kind == "linear")
      return std::make_unique<LinearSpringDamper>(value("stiffness"), value("damping"),
                                                  value("rest_length"));
    if (kind == "zener") {
      ZenerParameters p;
      p.e0 = value("zener_E0");
      p.e1 = value("zener_E1");
      p.mu = value("zener_mu");
      p.area = value("zener_area");
      p.rest_length = value("rest_length");
      return std::make_unique<ZenerElement>(p);
    }
    if (kind == "polynomial") {
      std::vector<double> coefficients;
      for (int i = 1; i <= PolynomialSpring::kMaxOrder; ++i)
        coefficients.push_back(value(PolynomialName(i)));
      return std::make_unique<PolynomialSpring>(coefficients, value("damping"),
                                                value("rest_length"));
    }
    if (kind == "table") {
      const auto table = a.options.find("elastic_table");
      if (table == a.options.end())
        throw std::invalid_argument(
            "options[\"elastic\"] = table needs options[\"elastic_table\"] (pairs 'extension "
            "force', e.g. \"0.01 1; 0.02 5\")");
      return std::make_unique<TableSpring>(TableSpring::Parse(table->second), value("damping"),
                                           value("rest_length"));
    }
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(prefix + e.what());
  }
  throw std::invalid_argument(prefix + "unknown elastic element '" + kind +
                              "' in options[\"elastic\"] (known: " + kElasticKinds + ")");
}

}  // namespace caliper::actuators
