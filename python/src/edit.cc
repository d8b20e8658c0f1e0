// caliper.Model's scene editing (tendon paths, tendons, obstacles, masses, shapes), undo/redo and
// pulls. Each edit returns the EditStatus; a refused one raises EditRefused and changes nothing.
#include <array>
#include <cmath>

#include "model_object.h"

namespace caliper::python {

namespace M = ::Caliper::Simulation;
namespace S = ::Caliper::Scene;

namespace {

py::object EditStatusObject(const M::EditStatus& e) {
  return py::module_::import("caliper.model")
      .attr("EditStatus")(e.revision, std::string(e.last.in()), std::string(e.undo.in()),
                          std::string(e.redo.in()));
}

std::array<double, 3> Vector(const py::handle& value, const char* argument) {
  const std::vector<double> v = FiniteValues(value, argument);
  if (v.size() != 3)
    throw py::value_error(std::string(argument) + " must have 3 elements (x, y, z), not " +
                          std::to_string(v.size()));
  return {v[0], v[1], v[2]};
}

// A path point: (body, (x, y, z)) in the body's frame [m] ("" body: the world), or the name of
// an obstacle the tendon wraps around.
S::PathPoint Point(const py::handle& point, const char* argument) {
  S::PathPoint p;
  p.x = p.y = p.z = 0;
  if (py::isinstance<py::str>(point)) {
    p.obstacle = point.cast<std::string>().c_str();
    return p;
  }
  if (!py::isinstance<py::sequence>(point) || py::len(point) != 2 ||
      !py::isinstance<py::str>(point.cast<py::sequence>()[0]))
    throw py::type_error(std::string(argument) +
                         " must be (body, (x, y, z)) in the body's frame [m] or an obstacle's "
                         "name");
  py::sequence pair = point.cast<py::sequence>();
  p.body = pair[0].cast<std::string>().c_str();
  const auto xyz = Vector(pair[1], argument);
  p.x = xyz[0];
  p.y = xyz[1];
  p.z = xyz[2];
  return p;
}

M::Vector3 ToVector3(const py::handle& value, const char* argument) {
  const auto v = Vector(value, argument);
  return M::Vector3{v[0], v[1], v[2]};
}

// An edit `f(model)` as a function of the Model object returning the EditStatus.
template <class F>
auto Edit(F f) {
  return [f](ModelObject& m) {
    M::EditStatus_var e = m.Run([&] { return f(m.ref.model.in()); });
    return EditStatusObject(e.in());
  };
}

py::object SetObstacle(ModelObject& m, const std::string& name, const std::string& body,
                       const std::string& kind, const py::object& position_m,
                       const py::object& quaternion, double radius_m, double length_m) {
  const auto p = Vector(position_m, "position_m");
  const std::vector<double> q = FiniteValues(quaternion, "quaternion");
  if (q.size() != 4) throw py::value_error("quaternion must have 4 elements (w, x, y, z)");
  S::Obstacle o;
  o.name = name.c_str();
  o.body = body.c_str();
  o.kind = kind.c_str();
  o.pose = S::Frame{p[0], p[1], p[2], q[0], q[1], q[2], q[3]};
  o.radius = radius_m;
  o.length = length_m;
  M::EditStatus_var e = m.Run([&] { return m.ref.model->set_obstacle(o); });
  return EditStatusObject(e.in());
}

}  // namespace

void BindEditing(py::class_<ModelObject, std::shared_ptr<ModelObject>>& c) {
  c.def(
       "move_path_point",
       [](ModelObject& m, const std::string& tendon, uint32_t index, const py::object& point) {
         const S::PathPoint p = Point(point, "point");
         return Edit([&](M::Model_ptr r) { return r->move_path_point(tendon.c_str(), index, p); })(
             m);
       },
       py::arg("tendon"), py::arg("index"), py::arg("point"),
       "Moves a tendon's path point `index` to `point`: (body, (x, y, z)) in the body's frame "
       "[m], or an obstacle's name.")
      .def(
          "insert_path_point",
          [](ModelObject& m, const std::string& tendon, uint32_t index, const py::object& point) {
            const S::PathPoint p = Point(point, "point");
            return Edit(
                [&](M::Model_ptr r) { return r->insert_path_point(tendon.c_str(), index, p); })(m);
          },
          py::arg("tendon"), py::arg("index"), py::arg("point"),
          "Inserts a path point before `index` (as move_path_point's `point`).")
      .def(
          "remove_path_point",
          [](ModelObject& m, const std::string& tendon, uint32_t index) {
            return Edit(
                [&](M::Model_ptr r) { return r->remove_path_point(tendon.c_str(), index); })(m);
          },
          py::arg("tendon"), py::arg("index"), "Removes a tendon's path point.")
      .def(
          "add_tendon",
          [](ModelObject& m, const std::string& tendon, const py::object& start,
             const py::object& end, double radius_m, const std::string& actuator,
             const std::string& kind) {
            const S::PathPoint a = Point(start, "start"), b = Point(end, "end");
            if (!(radius_m > 0) || radius_m > 1)
              throw py::value_error("radius_m must be in (0, 1] m");
            return Edit([&](M::Model_ptr r) {
              return r->add_tendon(tendon.c_str(), a, b, radius_m, actuator.c_str(), kind.c_str());
            })(m);
          },
          py::arg("tendon"), py::arg("start"), py::arg("end"), py::arg("radius_m") = 0.001,
          py::arg("actuator") = "", py::arg("kind") = "",
          "Adds a tendon from `start` to `end` (points as in move_path_point), with an actuator "
          "of `kind` at its defaults when `actuator` is named (see actuator_kinds()).")
      .def(
          "remove_tendon",
          [](ModelObject& m, const std::string& tendon) {
            return Edit([&](M::Model_ptr r) { return r->remove_tendon(tendon.c_str()); })(m);
          },
          py::arg("tendon"), "Removes a tendon and its actuator.")
      .def("set_obstacle", &SetObstacle, py::arg("name"), py::arg("body"), py::arg("kind"),
           py::arg("position_m"), py::arg("quaternion") = std::vector<double>{1, 0, 0, 0},
           py::arg("radius_m") = 0.02, py::arg("length_m") = 0.1,
           "Adds or changes a wrapping obstacle (kind sphere or cylinder) fixed in `body`.")
      .def(
          "remove_obstacle",
          [](ModelObject& m, const std::string& name) {
            return Edit([&](M::Model_ptr r) { return r->remove_obstacle(name.c_str()); })(m);
          },
          py::arg("name"), "Removes a wrapping obstacle.")
      .def(
          "set_mass",
          [](ModelObject& m, const std::string& body, double mass_kg) {
            if (!std::isfinite(mass_kg) || mass_kg <= 0)
              throw py::value_error("mass_kg must be > 0 and finite");
            return Edit([&](M::Model_ptr r) { return r->set_mass(body.c_str(), mass_kg); })(m);
          },
          py::arg("body"), py::arg("mass_kg"), "Sets a body's mass [kg].")
      .def(
          "set_measurement_delay",
          [](ModelObject& m, const std::string& id, double delay_s) {
            if (!std::isfinite(delay_s) || delay_s < 0)
              throw py::value_error("delay_s must be >= 0 and finite");
            return Edit([&](M::Model_ptr r) {
              return r->set_measurement_delay(id.c_str(), delay_s);
            })(m);
          },
          py::arg("id"), py::arg("delay_s"),
          "Delays channel `id` by `delay_s` [s] for every reader (whole time steps); 0 removes "
          "its delay. `id + '.undelayed'` reads the true value.")
      .def(
          "measurement_delays",
          [](ModelObject& m) {
            S::SensorDelaySeq_var delays = m.Run([&] { return m.ref.model->measurement_delays(); });
            py::dict out;
            for (CORBA::ULong i = 0; i < delays->length(); ++i)
              out[py::str(delays[i].id.in())] = delays[i].delay;
            return out;
          },
          "The channels that read late: {id: delay [s]}, the ids as the DAQ lists them.")
      .def(
          "set_shape_dims",
          [](ModelObject& m, const std::string& body, uint32_t index, const py::object& dims) {
            const std::vector<double> d = FiniteValues(dims, "dims_m");
            S::DoubleSeq seq;
            seq.length(static_cast<CORBA::ULong>(d.size()));
            for (size_t i = 0; i < d.size(); ++i) seq[static_cast<CORBA::ULong>(i)] = d[i];
            return Edit(
                [&](M::Model_ptr r) { return r->set_shape_dims(body.c_str(), index, seq); })(m);
          },
          py::arg("body"), py::arg("index"), py::arg("dims_m"),
          "Sets the dimensions [m] of a body's collision shape `index`.")
      .def("undo", Edit([](M::Model_ptr r) { return r->undo(); }), "Reverts the last edit.")
      .def("redo", Edit([](M::Model_ptr r) { return r->redo(); }), "Applies it again.")
      .def("edit_status", Edit([](M::Model_ptr r) { return r->edit_status(); }),
           "The revision and what undo() and redo() would do.")
      .def(
          "actuator_kinds",
          [](ModelObject& m) {
            M::ActuatorKindSeq_var k = m.Run([&] { return m.ref.model->actuator_kinds(); });
            py::dict out;
            for (CORBA::ULong i = 0; i < k->length(); ++i) {
              py::dict parameters;
              for (CORBA::ULong p = 0; p < k[i].parameters.length(); ++p)
                parameters[py::str(k[i].parameters[p].in())] =
                    py::make_tuple(k[i].defaults[p], std::string(k[i].units[p].in()));
              out[py::str(k[i].kind.in())] = parameters;
            }
            return out;
          },
          "The actuator kinds add_tendon knows: {kind: {parameter: (default, unit)}}.")
      .def(
          "pull",
          [](ModelObject& m, const std::string& body, const py::object& point,
             const py::object& target, double stiffness_n_per_m) {
            const M::Vector3 p = ToVector3(point, "point_m"), t = ToVector3(target, "target_m");
            if (!std::isfinite(stiffness_n_per_m) || stiffness_n_per_m <= 0)
              throw py::value_error("stiffness_n_per_m must be > 0 and finite");
            m.Run([&] { m.ref.model->pull(body.c_str(), p, t, stiffness_n_per_m); });
          },
          py::arg("body"), py::arg("point_m"), py::arg("target_m"),
          py::arg("stiffness_n_per_m") = 100.0,
          "Pulls `body` at `point_m` (its frame) toward `target_m` (world) with a spring.")
      .def(
          "release_pull", [](ModelObject& m) { m.Run([&] { m.ref.model->release_pull(); }); },
          "Lets go of a pull.");
}

}  // namespace caliper::python
