#include "extension.h"

#include <algorithm>
#include <cmath>
#include <set>

#include "caliper/actuators/actuator.h"
#include "caliper_extra.h"
#include "math3d.h"
#include "units.h"

namespace caliper::collada::internal {

namespace {

const char* ObstacleKindName(sgal::ObstacleKind k) {
  return k == sgal::ObstacleKind::kSphere ? "sphere" : "cylinder";
}

class ExtensionReader {
 public:
  explicit ExtensionReader(Context& ctx) : ctx_(ctx) {}

  void Read(const Element& technique) {
    technique_ = &technique;
    for (const auto& c : technique.children) {
      const std::string_view n = c->local_name();
      if (n == "settings")
        Settings(*c);
      else if (n == "obstacle")
        Obstacle(*c);
      else if (n == "tendon")
        Tendon(*c);
      else if (n == "actuator")
        Actuator(*c);
      else if (n == "coupling")
        Coupling(*c);
      else if (n == "measurement_delay")
        MeasurementDelay(*c);
      else
        Unknown(*c, "the Caliper technique");
    }
  }

 private:
  void Unknown(const Element& e, const std::string& where) {
    const int line = ctx_.doc.LineOf(e);
    ctx_.Warn(&e, "unknown element <" + std::string(e.local_name()) + "> in " + where + " (" +
                      (line > 0 ? "line " + std::to_string(line) : "line not known") +
                      "); ignored");
  }

  std::string Required(const Element& e, const char* attribute) {
    const std::string v = e.Attribute(attribute);
    if (v.empty()) ctx_.Fail(&e, std::string("needs a ") + attribute + " attribute");
    return v;
  }

  double AttributeNumber(const Element& e, const char* attribute, double fallback) {
    const std::string* v = e.FindAttribute(attribute);
    if (v == nullptr) return fallback;
    std::vector<double> values;
    std::string bad;
    if (!ParseNumbers(*v, &values, &bad) || values.size() != 1)
      ctx_.Fail(&e, std::string("attribute ") + attribute + "=\"" + *v + "\" is not a number");
    return values[0];
  }

  // A unit from a unit attribute; fails naming it when unknown.
  Unit ParseUnitOf(const Element& e, const std::string& text) {
    Unit u;
    std::string bad, why;
    if (!ParseUnit(text, &u, &bad, &why))
      ctx_.Fail(&e, (why.empty() ? "unknown unit '" + text + "'" : "unit '" + text + "': " + why) +
                        (bad != text ? " (at '" + bad + "')" : ""));
    return u;
  }

  // Seconds per number of an element's time: its own `unit` attribute, a time (1 without one).
  double TimeScale(const Element& e) {
    const std::string* unit = e.FindAttribute("unit");
    if (unit == nullptr) return 1;
    const Unit u = ParseUnitOf(e, *unit);
    if (u.dimension != std::array<int, 5>{0, 0, 1, 0, 0})
      ctx_.Fail(&e, "unit '" + *unit + "' is not a time");
    return u.scale;
  }

  // Metres per number of an element's lengths: the unit attribute of the element or of the
  // nearest enclosing one in the technique, else the document's unit.
  double LengthScale(const Element& e) {
    // up to the technique itself (a <caliper> element of a URDF file has no <technique> above it)
    for (const Element* k = &e; k != nullptr; k = k == technique_ ? nullptr : k->parent) {
      if (k->local_name() == "technique") break;
      const std::string* unit = k->FindAttribute("unit");
      if (unit == nullptr) continue;
      const Unit u = ParseUnitOf(*k, *unit);
      if (u.dimension != std::array<int, 5>{1, 0, 0, 0, 0})
        ctx_.Fail(k, "unit '" + *unit + "' is not a length");
      return u.scale;
    }
    return ctx_.meter;
  }

  bool Boolean(const Element& e, const char* attribute, bool fallback) {
    const std::string* v = e.FindAttribute(attribute);
    if (v == nullptr) return fallback;
    if (*v == "true" || *v == "1") return true;
    if (*v == "false" || *v == "0") return false;
    ctx_.Fail(&e, std::string("attribute ") + attribute + "=\"" + *v + "\" is not true or false");
  }

  void Settings(const Element& e) {
    for (const auto& c : e.children) {
      const std::string_view n = c->local_name();
      if (n == "time_step") {
        ctx_.scene.settings.time_step = ctx_.Number(c.get(), 0) * TimeScale(*c);
        if (!(ctx_.scene.settings.time_step > 0)) ctx_.Fail(c.get(), "time step must be positive");
      } else if (n == "solver_iterations") {
        const double v = ctx_.Number(c.get(), 10);
        if (!(v >= 1) || v > 1e6 || v != std::floor(v))
          ctx_.Fail(c.get(), "solver iterations must be a positive integer");
        ctx_.scene.settings.solver_iterations = static_cast<int>(v);
      } else if (n == "world_scale") {
        ctx_.scene.settings.world_scale = ctx_.Number(c.get(), 1);
        if (!(ctx_.scene.settings.world_scale > 0))
          ctx_.Fail(c.get(), "world scale must be positive");
      } else {
        Unknown(*c, "<settings>");
      }
    }
  }

  // A body name from the document (a body name, node id or name, rigid body sid); "" for world.
  std::string Body(const Element& e, const std::string& what) {
    const std::string ref = e.Attribute("body");
    if (ref.empty() || ref == "world") return "";
    const std::string body = ctx_.FindBody(ref);
    if (body.empty())
      ctx_.Fail(&e, "dangling reference: " + what + " on unknown body '" + ref + "'");
    return body;
  }

  void Obstacle(const Element& e) {
    sgal::WrapObstacle o;
    o.name = Required(e, "name");
    if (ctx_.obstacle_source.count(o.name) > 0)
      ctx_.Fail(&e, "obstacle '" + o.name + "' is defined twice");
    o.body = Body(e, "obstacle '" + o.name + "'");
    const std::string kind = e.Attribute("kind", "cylinder");
    if (kind == "sphere")
      o.kind = sgal::ObstacleKind::kSphere;
    else if (kind == "cylinder")
      o.kind = sgal::ObstacleKind::kCylinder;
    else
      ctx_.Fail(&e, "unknown obstacle kind '" + kind + "' (sphere or cylinder)");
    const double scale = LengthScale(e);
    o.radius = AttributeNumber(e, "radius", o.radius / scale) * scale;
    o.length = AttributeNumber(e, "length", o.length / scale) * scale;
    if (!(o.radius > 0)) ctx_.Fail(&e, "radius must be positive");
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    for (const auto& c : e.children) {
      const std::string_view n = c->local_name();
      if (n == "translate") {
        pose.translate(ctx_.Vector3(*c) * LengthScale(*c));
      } else if (n == "rotate") {
        const auto v = ctx_.Numbers(*c, 4);
        pose.rotate(AxisAngleDegrees(Eigen::Vector3d(v[0], v[1], v[2]), v[3]));
      } else {
        Unknown(*c, "obstacle '" + o.name + "'");
      }
    }
    o.pose = sgal::Pose::FromIsometry(pose);
    ctx_.obstacle_source[o.name] = &e;
    ctx_.scene.obstacles.push_back(o);
  }

  Eigen::Vector3d Position(const Element& e) { return ctx_.Vector3(e) * LengthScale(e); }

  void Tendon(const Element& e) {
    sgal::Tendon t;
    t.name = Required(e, "name");
    if (ctx_.tendon_source.count(t.name) > 0)
      ctx_.Fail(&e, "tendon '" + t.name + "' is defined twice");
    const double scale = LengthScale(e);
    t.radius = AttributeNumber(e, "radius", t.radius / scale) * scale;
    t.collide_with_bodies = Boolean(e, "collide_with_bodies", t.collide_with_bodies);
    int points = 0;
    for (const auto& c : e.children) {
      const std::string_view n = c->local_name();
      sgal::PathElement p;
      if (n == "attachment" || n == "via" || n == "point") {
        p.kind = sgal::PathElement::Kind::kPoint;
        p.body = Body(*c, "tendon '" + t.name + "' point");
        p.position = Position(*c);
        p.friction = AttributeNumber(*c, "friction", 0);
        if (p.friction < 0) ctx_.Fail(c.get(), "friction must not be negative");
        ++points;
      } else if (n == "wrap") {
        p.kind = sgal::PathElement::Kind::kWrap;
        p.obstacle = Required(*c, "obstacle");
        const auto* o = ctx_.scene.FindObstacle(p.obstacle);
        if (o == nullptr)
          ctx_.Fail(c.get(), "dangling reference: no obstacle '" + p.obstacle +
                                 "' (declare it before the tendon)");
        for (const auto& s : c->children) {
          if (s->local_name() == "side")
            p.side = Position(*s);
          else
            Unknown(*s, "a wrap of tendon '" + t.name + "'");
        }
      } else {
        Unknown(*c, "tendon '" + t.name + "'");
        continue;
      }
      t.path.push_back(p);
    }
    if (points < 2)
      ctx_.Fail(&e, "tendon '" + t.name + "' needs at least two points (attachment or via), has " +
                        std::to_string(points));
    ctx_.tendon_source[t.name] = &e;
    ctx_.scene.tendons.push_back(std::move(t));
  }

  void Actuator(const Element& e) {
    sgal::Actuator a;
    a.name = Required(e, "name");
    if (ctx_.actuator_source.count(a.name) > 0)
      ctx_.Fail(&e, "actuator '" + a.name + "' is defined twice");
    a.kind = Required(e, "kind");
    a.tendon = Required(e, "tendon");
    const auto kinds = actuators::Kinds();
    if (std::find(kinds.begin(), kinds.end(), a.kind) == kinds.end()) {
      std::string known;
      for (const auto& k : kinds) known += (known.empty() ? "" : ", ") + k;
      ctx_.Fail(&e, "actuator '" + a.name + "': unknown actuator kind '" + a.kind +
                        "' (registered: " + known + ")");
    }
    if (ctx_.scene.FindTendon(a.tendon) == nullptr)
      ctx_.Fail(&e, "dangling reference: actuator '" + a.name + "' acts on unknown tendon '" +
                        a.tendon + "' (declare it before the actuator)");
    const auto& specs = actuators::KindParameters(a.kind);
    for (const auto& c : e.children) {
      const std::string_view n = c->local_name();
      if (n == "param") {
        const std::string name = Required(*c, "name");
        const actuators::ParameterSpec* spec = nullptr;
        for (const auto& s : specs)
          if (s.name == name) spec = &s;
        if (spec == nullptr) {
          std::string known;
          for (const auto& s : specs) known += (known.empty() ? "" : ", ") + s.name;
          ctx_.Fail(c.get(), "actuator '" + a.name + "' (" + a.kind + "): unknown parameter '" +
                                 name + "' (known: " + known + ")");
        }
        if (a.parameters.count(name) > 0)
          ctx_.Fail(c.get(), "parameter '" + name + "' is given twice");
        a.parameters[name] = ctx_.Number(c.get(), 0) * UnitFactor(*c, *spec);
        WarnUnitlessLength(*c, a, *spec);
      } else if (n == "option") {
        a.options[Required(*c, "name")] = c->Trimmed();
      } else {
        Unknown(*c, "actuator '" + a.name + "'");
      }
    }
    for (const auto& s : specs)
      if (s.required && a.parameters.count(s.name) == 0)
        ctx_.Fail(&e, "actuator '" + a.name + "' (" + a.kind + "): missing required parameter '" +
                          s.name + "'" + (s.unit.empty() ? "" : " [" + s.unit + "]") +
                          (s.help.empty() ? "" : ": " + s.help));
    // the kind's own checks (ranges, options, parameters that exclude each other)
    try {
      actuators::Make(a);
    } catch (const std::exception& ex) {
      ctx_.Fail(&e, ex.what());
    }
    ctx_.actuator_source[a.name] = &e;
    ctx_.scene.actuators.push_back(std::move(a));
  }

  // A length parameter without a unit attribute is read in its kind's unit (metres), not in the
  // document's <unit>: in a millimetre file `spool_radius 5` means 5 m, which is rarely meant.
  void WarnUnitlessLength(const Element& param, const sgal::Actuator& a,
                          const actuators::ParameterSpec& spec) {
    if (param.FindAttribute("unit") != nullptr || ctx_.meter == 1) return;
    Unit declared;
    std::string bad;
    if (!ParseUnit(spec.unit, &declared, &bad) ||
        declared.dimension != std::array<int, 5>{1, 0, 0, 0, 0})
      return;
    const int line = ctx_.doc.LineOf(param);
    ctx_.Warn(&param, "actuator '" + a.name + "': length parameter '" + spec.name +
                          "' has no unit (" +
                          (line > 0 ? "line " + std::to_string(line) : "line not known") +
                          ") and is read as " + FormatNumber(a.parameters.at(spec.name)) + " " +
                          spec.unit + ", although this file's <unit meter=\"" +
                          FormatNumber(ctx_.meter) + "\"> scales its geometry; write unit=\"" +
                          spec.unit + "\" (or the unit meant) on it");
  }

  // The factor from a <param>'s unit attribute to the unit its kind declares.
  double UnitFactor(const Element& param, const actuators::ParameterSpec& spec) {
    const std::string* unit = param.FindAttribute("unit");
    if (unit == nullptr || *unit == spec.unit) return 1;
    const Unit given = ParseUnitOf(param, *unit);
    Unit declared;
    std::string bad;
    if (!ParseUnit(spec.unit, &declared, &bad))
      ctx_.Fail(&param, "parameter '" + spec.name + "' is in [" + spec.unit +
                            "] and cannot be given in '" + *unit + "'");
    if (!given.SameDimension(declared))
      ctx_.Fail(&param, "unit '" + *unit + "' does not fit parameter '" + spec.name + "' [" +
                            (spec.unit.empty() ? "dimensionless" : spec.unit) + "]");
    return given.scale / declared.scale;
  }

  void Coupling(const Element& e) {
    sgal::Coupling c;
    c.leader = Required(e, "leader");
    c.follower = Required(e, "follower");
    c.ratio = AttributeNumber(e, "ratio", 1);
    c.offset = AttributeNumber(e, "offset", 0);
    for (const auto& name : {c.leader, c.follower})
      if (ctx_.constraint_source.count(name) == 0)
        ctx_.Fail(&e, "dangling reference: no constraint (joint) '" + name + "'");
    for (const auto& child : e.children) Unknown(*child, "a coupling");
    ctx_.scene.couplings.push_back(c);
  }

  // <measurement_delay channel="motor.current" delay="4" unit="ms"/>: the channel's id is checked
  // by the engine that builds the scene (it knows the parameters), the rest here
  void MeasurementDelay(const Element& e) {
    sgal::MeasurementDelay d;
    d.id = Required(e, "channel");
    const double scale = TimeScale(e);
    Required(e, "delay");
    d.delay = AttributeNumber(e, "delay", 0) * scale;
    if (!std::isfinite(d.delay) || d.delay < 0)
      ctx_.Fail(&e, "channel '" + d.id + "': delay=\"" + e.Attribute("delay") +
                        "\" must be finite and not negative");
    if (!delayed_.insert(d.id).second) ctx_.Fail(&e, "channel '" + d.id + "' is delayed twice");
    for (const auto& child : e.children) Unknown(*child, "a measurement_delay");
    ctx_.scene.measurement_delays.push_back(d);
  }

  Context& ctx_;
  const Element* technique_ = nullptr;  // the technique being read
  std::set<std::string> delayed_;       // the channels measurement_delay names
};

// Adds a vector as the character data of a new <tag>.
Element* AddVector(Element* parent, const char* tag, const Eigen::Vector3d& v) {
  return parent->Add(tag, FormatNumbers(v.data(), 3));
}

}  // namespace

void ImportExtension(Context& ctx) {
  ExtensionReader reader(ctx);
  for (const Element* technique : CaliperTechniques(*ctx.doc.root)) reader.Read(*technique);
}

void ImportTechnique(Context& ctx, const Element& technique) {
  ExtensionReader reader(ctx);
  reader.Read(technique);
}

void ExportExtension(const sgal::Scene& scene, Element* technique) {
  Element* settings = technique->Add("settings");
  settings->Add("time_step", FormatNumber(scene.settings.time_step))->Set("unit", "s");
  settings->Add("solver_iterations", std::to_string(scene.settings.solver_iterations));
  settings->Add("world_scale", FormatNumber(scene.settings.world_scale));
  for (const auto& o : scene.obstacles) {
    Element* e = technique->Add("obstacle");
    e->Set("name", o.name);
    e->Set("body", o.body.empty() ? "world" : o.body);
    e->Set("kind", ObstacleKindName(o.kind));
    e->Set("radius", FormatNumber(o.radius));
    e->Set("length", FormatNumber(o.length));
    e->Set("unit", "m");
    AddVector(e, "translate", o.pose.position)->Set("unit", "m");
    const auto [axis, degrees] = ToAxisAngleDegrees(o.pose.orientation);
    const double r[4] = {axis.x(), axis.y(), axis.z(), degrees};
    e->Add("rotate", FormatNumbers(r, 4));
  }
  for (const auto& t : scene.tendons) {
    Element* e = technique->Add("tendon");
    e->Set("name", t.name);
    e->Set("radius", FormatNumber(t.radius));
    e->Set("unit", "m");
    e->Set("collide_with_bodies", t.collide_with_bodies ? "true" : "false");
    size_t points = 0;
    for (const auto& p : t.path) points += p.kind == sgal::PathElement::Kind::kPoint;
    size_t seen = 0;
    for (const auto& p : t.path) {
      if (p.kind == sgal::PathElement::Kind::kPoint) {
        const bool end = seen == 0 || seen + 1 == points;
        ++seen;
        Element* pe = AddVector(e, end ? "attachment" : "via", p.position);
        pe->Set("body", p.body.empty() ? "world" : p.body);
        pe->Set("unit", "m");
        if (p.friction != 0) pe->Set("friction", FormatNumber(p.friction));
      } else {
        Element* w = e->Add("wrap");
        w->Set("obstacle", p.obstacle);
        if (p.side) AddVector(w, "side", *p.side)->Set("unit", "m");
      }
    }
  }
  for (const auto& a : scene.actuators) {
    const auto kinds = actuators::Kinds();
    if (std::find(kinds.begin(), kinds.end(), a.kind) == kinds.end())
      throw std::invalid_argument("actuator '" + a.name + "': unknown actuator kind '" + a.kind +
                                  "'");
    const auto& specs = actuators::KindParameters(a.kind);
    Element* e = technique->Add("actuator");
    e->Set("name", a.name);
    e->Set("kind", a.kind);
    e->Set("tendon", a.tendon);
    for (const auto& [name, value] : a.parameters) {
      // a lambda captures no structured binding before C++20 (clang refuses; build-fuzz/)
      const std::string& parameter = name;
      const auto spec = std::find_if(specs.begin(), specs.end(),
                                     [&](const auto& s) { return s.name == parameter; });
      if (spec == specs.end())
        throw std::invalid_argument("actuator '" + a.name + "' (" + a.kind +
                                    "): unknown parameter '" + name + "'");
      Element* p = e->Add("param", FormatNumber(value));
      p->Set("name", name);
      if (!spec->unit.empty()) p->Set("unit", spec->unit);
    }
    for (const auto& [name, value] : a.options) e->Add("option", value)->Set("name", name);
  }
  for (const auto& c : scene.couplings) {
    Element* e = technique->Add("coupling");
    e->Set("leader", c.leader);
    e->Set("follower", c.follower);
    e->Set("ratio", FormatNumber(c.ratio));
    e->Set("offset", FormatNumber(c.offset));
  }
  for (const auto& d : scene.measurement_delays) {
    Element* e = technique->Add("measurement_delay");
    e->Set("channel", d.id);
    e->Set("delay", FormatNumber(d.delay));
    e->Set("unit", "s");
  }
}

}  // namespace caliper::collada::internal
