// caliper.Model: loading, stepping and running, commands, parameters and channels by DAQ id.
#include <filesystem>

#include "caliper/rtc/idl_names.h"
#include "model_object.h"

namespace caliper::python {

namespace M = ::Caliper::Simulation;
namespace D = ::Caliper::Daq;
namespace S = ::Caliper::Scene;

namespace {

// the most values a client sends for one parameter (the Model's largest, a mesh's vertices,
// has far fewer)
constexpr size_t kMaxParameterValues = 100000;

S::StringSeq ToSeq(const std::vector<std::string>& ids) {
  S::StringSeq out;
  out.length(static_cast<CORBA::ULong>(ids.size()));
  for (CORBA::ULong i = 0; i < ids.size(); ++i) out[i] = ids[i].c_str();
  return out;
}

py::object Types() { return py::module_::import("caliper.model"); }

py::object StatusObject(const M::SimulationStatus& s) {
  return Types().attr("Status")(rtc::Name(s.state), std::string(s.scene.in()), s.sim_time, s.steps,
                                s.time_step, s.real_time_factor, s.achieved_real_time_factor,
                                std::string(s.last_error.in()));
}

std::string AbsolutePath(const py::object& path) {
  const std::string p = py::str(py::module_::import("os").attr("fspath")(path));
  return std::filesystem::absolute(p).lexically_normal().string();
}

py::list Load(ModelObject& m, const py::object& path, bool send) {
  const std::string absolute = AbsolutePath(path);
  client::SentScene sent;
  m.Run(
      [&] {
        const bool by_content = client::SendsByContent(m.ref.model, absolute, m.ref.local, send,
                                                       core::ConfinedPaths::Access::kRead);
        try {
          sent = client::LoadScene(m.ref.model, absolute, by_content);
        } catch (const M::LoadFailed& e) {
          throw client::LoadFailedError((by_content ? absolute + " (sent by content): " : "") +
                                        e.reason.in());
        } catch (const std::runtime_error& e) {
          throw client::LoadFailedError(e.what());
        }
      },
      kLongCallS);
  return py::cast(sent.warnings);
}

uint32_t Step(ModelObject& m, int64_t n) {
  if (n < 1 || n > 0xffffffffLL)
    throw py::value_error("n must be 1 to 4294967295 steps, not " + std::to_string(n));
  const CORBA::ULong asked = static_cast<CORBA::ULong>(n);
  const CORBA::ULong done = m.Run([&] { return m.ref.model->step(asked); }, kLongCallS);
  RaiseIfFaulted(m, asked, done);
  return done;
}

M::CommandSeq Commands(const py::handle& commands) {
  if (!py::isinstance<py::dict>(commands))
    throw py::type_error("commands must be a dict {actuator: value}, not " +
                         std::string(py::str(py::type::of(commands).attr("__name__"))));
  M::CommandSeq seq;
  seq.length(static_cast<CORBA::ULong>(py::len(commands)));
  CORBA::ULong i = 0;
  for (auto item : commands.cast<py::dict>()) {
    if (!py::isinstance<py::str>(item.first))
      throw py::type_error("commands' keys must be actuator names (str)");
    const std::string name = item.first.cast<std::string>();
    const std::vector<double> v = FiniteValues(item.second, ("commands['" + name + "']").c_str());
    if (v.size() != 1)
      throw py::value_error("commands['" + name + "'] must be one number, not " +
                            std::to_string(v.size()));
    seq[i].actuator = name.c_str();
    seq[i].value = v[0];
    ++i;
  }
  return seq;
}

void SetCommand(ModelObject& m, const std::string& actuator, const py::object& value) {
  const std::vector<double> v = FiniteValues(value, "value");
  if (v.size() != 1)
    throw py::value_error("value must be one number, not " + std::to_string(v.size()));
  m.Run([&] { m.ref.model->set_command(actuator.c_str(), v[0]); });
}

void SetCommands(ModelObject& m, const py::object& commands) {
  const M::CommandSeq seq = Commands(commands);
  m.Run([&] { m.ref.model->set_commands(seq); });
}

py::list Channels(ModelObject& m, const std::string& pattern) {
  D::ChannelInfoSeq_var list = m.Run([&] { return m.ref.model->list(pattern.c_str()); });
  py::list out;
  for (CORBA::ULong i = 0; i < list->length(); ++i) out.append(ChannelObject(list[i]));
  return out;
}

// get(): one id gives one array, a list of ids a list of arrays (each in its channel's shape)
py::object Get(ModelObject& m, const py::object& ids) {
  const std::vector<std::string> list = IdList(ids, "ids");
  const S::StringSeq seq = ToSeq(list);
  D::ValueSeq_var values = m.Run([&] { return m.ref.model->get(seq); });
  py::list out;
  for (CORBA::ULong i = 0; i < values->length(); ++i)
    out.append(ChannelArray(values[i].data.get_buffer(), values[i].rows, values[i].cols));
  if (py::isinstance<py::str>(ids)) return out[0];
  return std::move(out);
}

// get_values(): every value of the ids, one after the other, in one flat array (control loops)
py::array_t<double> GetValues(ModelObject& m, const py::object& ids) {
  const std::vector<std::string> list = IdList(ids, "ids");
  const S::StringSeq seq = ToSeq(list);
  std::vector<double> flat;
  m.Run([&] {
    D::ValueSeq_var values = m.ref.model->get(seq);
    for (CORBA::ULong i = 0; i < values->length(); ++i)
      flat.insert(flat.end(), values[i].data.get_buffer(),
                  values[i].data.get_buffer() + values[i].data.length());
  });
  py::array_t<double> out(static_cast<py::ssize_t>(flat.size()));
  std::copy(flat.begin(), flat.end(), out.mutable_data());
  return out;
}

// control_cycle(): the Model's one-call lock-step cycle; every value of `ids` after the steps
py::array_t<double> ControlCycle(ModelObject& m, const py::object& commands, int64_t n,
                                 const py::object& ids) {
  if (n < 1 || n > 0xffffffffLL)
    throw py::value_error("steps must be 1 to 4294967295, not " + std::to_string(n));
  const M::CommandSeq seq = Commands(commands);
  const S::StringSeq id_seq = ToSeq(IdList(ids, "ids"));
  std::vector<double> flat;
  const CORBA::ULong ran = m.Run(
      [&] {
        M::CycleResult_var r =
            m.ref.model->control_cycle(seq, static_cast<CORBA::ULong>(n), id_seq);
        for (CORBA::ULong i = 0; i < r->values.length(); ++i)
          flat.insert(flat.end(), r->values[i].data.get_buffer(),
                      r->values[i].data.get_buffer() + r->values[i].data.length());
        return r->steps;
      },
      kLongCallS);
  RaiseIfFaulted(m, static_cast<uint64_t>(n), ran);
  py::array_t<double> out(static_cast<py::ssize_t>(flat.size()));
  std::copy(flat.begin(), flat.end(), out.mutable_data());
  return out;
}

void Set(ModelObject& m, const std::string& id, const py::object& value) {
  const std::vector<double> v = FiniteValues(value, "value");
  if (v.size() > kMaxParameterValues)
    throw py::value_error("value has " + std::to_string(v.size()) + " elements; no parameter of " +
                          id + " or any other has more than " +
                          std::to_string(kMaxParameterValues));
  // the channel's shape as the Model has it now (UnknownId naming the id), so that a wrong
  // count is refused here, naming the argument; the Model checks again when it writes
  const S::StringSeq one = ToSeq({id});
  D::ValueSeq_var now = m.Run([&] { return m.ref.model->get(one); });
  const uint32_t rows = now[0].rows, cols = now[0].cols;
  if (v.size() != static_cast<size_t>(rows) * cols)
    throw py::value_error("value must have " + std::to_string(rows * cols) + " elements for " + id +
                          " (" + std::to_string(rows) + " x " + std::to_string(cols) + "), not " +
                          std::to_string(v.size()));
  D::Value value_idl;
  value_idl.rows = rows;
  value_idl.cols = cols;
  value_idl.data.length(static_cast<CORBA::ULong>(v.size()));
  for (size_t i = 0; i < v.size(); ++i) value_idl.data[static_cast<CORBA::ULong>(i)] = v[i];
  m.Run([&] { m.ref.model->set(id.c_str(), value_idl); });
}

py::list Actuators(ModelObject& m) {
  M::ActuatorInfoSeq_var list = m.Run([&] { return m.ref.model->actuators(); });
  py::list out;
  for (CORBA::ULong i = 0; i < list->length(); ++i)
    out.append(Types().attr("Actuator")(
        std::string(list[i].name.in()), std::string(list[i].kind.in()),
        std::string(list[i].tendon.in()), std::string(list[i].command_unit.in())));
  return out;
}

py::list ActuatorStates(ModelObject& m) {
  M::ActuatorStateSeq_var list = m.Run([&] { return m.ref.model->actuator_states(); });
  py::list out;
  for (CORBA::ULong i = 0; i < list->length(); ++i)
    out.append(Types().attr("ActuatorState")(std::string(list[i].name.in()), list[i].command,
                                             list[i].tension));
  return out;
}

template <class Op>
void SetPositive(ModelObject& m, const char* what, const py::object& given, bool zero_ok, Op op) {
  const std::vector<double> v = FiniteValues(given, what);
  if (v.size() != 1)
    throw py::value_error(std::string(what) + " must be one number, not " +
                          std::to_string(v.size()));
  const double value = v[0];
  if (value < 0 || (!zero_ok && value == 0))
    throw py::value_error(std::string(what) + " must be " + (zero_ok ? ">= 0" : "> 0") +
                          " and finite, not " + std::to_string(value));
  m.Run([&] { op(m.ref.model.in(), value); });
}

void BindControl(py::class_<ModelObject, std::shared_ptr<ModelObject>>& c) {
  c.def("load", &Load, py::arg("path"), py::arg("send") = false,
        R"doc(Loads a scene (.dae, .zae or .urdf) into the Model. By path when the Model shares
this host's files and may read it, else by content (always with send=True; a URDF is converted
to COLLADA here). Returns the import's warnings. LoadFailed names the file, the element and the
problem; the Model keeps its scene.)doc")
      .def(
          "load_bytes",
          [](ModelObject& m, const std::string& file_name, const py::bytes& data) {
            const std::string bytes = data;
            m.Run([&] { m.ref.model->load_scene_data(file_name.c_str(), client::ToOctets(bytes)); },
                  kLongCallS);
          },
          py::arg("file_name"), py::arg("data"),
          "Loads a scene from its bytes; `file_name` (NAME.dae or NAME.zae) tells the format.")
      .def(
          "export_scene",
          [](ModelObject& m) {
            M::Octets_var o = m.Run([&] { return m.ref.model->export_scene(); }, kLongCallS);
            return py::bytes(reinterpret_cast<const char*>(o->get_buffer()), o->length());
          },
          "The scene as it is now (edits and tuned parameters included), as COLLADA bytes.")
      .def("step", &Step, py::arg("n") = 1,
           R"doc(Runs `n` steps now (the Model must not be running) and returns the steps run.
RunFailed (with `.steps`) when the physics faulted on the way. Releases the GIL.)doc")
      .def(
          "start", [](ModelObject& m) { m.Run([&] { m.ref.model->start(); }); },
          "Runs the simulation at its real-time factor until pause() or stop().")
      .def(
          "pause", [](ModelObject& m) { m.Run([&] { m.ref.model->pause(); }); }, "Pauses it.")
      .def(
          "stop", [](ModelObject& m) { m.Run([&] { m.ref.model->stop(); }); },
          "Stops it and goes back to the scene's initial state.")
      .def(
          "reset", [](ModelObject& m) { m.Run([&] { m.ref.model->reset(); }); },
          "Back to the scene's initial state (time 0); a running Model runs on from there, a "
          "paused or stopped one stays so; a faulted one is stopped (the fault cleared).")
      .def(
          "status",
          [](ModelObject& m) {
            M::SimulationStatus_var s = m.Run([&] { return m.ref.model->status(); });
            return StatusObject(s.in());
          },
          "The simulation's state, time [s], steps, time step [s] and real-time factors.")
      .def_property(
          "time_step_s",
          [](ModelObject& m) {
            M::SimulationStatus_var s = m.Run([&] { return m.ref.model->status(); });
            return s->time_step;
          },
          [](ModelObject& m, const py::object& v) {
            SetPositive(m, "time_step_s", v, false,
                        [](M::Model_ptr p, double x) { p->set_time_step(x); });
          },
          "The physics time step [s].")
      .def_property(
          "real_time_factor",
          [](ModelObject& m) {
            M::SimulationStatus_var s = m.Run([&] { return m.ref.model->status(); });
            return s->real_time_factor;
          },
          [](ModelObject& m, const py::object& v) {
            SetPositive(m, "real_time_factor", v, true,
                        [](M::Model_ptr p, double x) { p->set_real_time_factor(x); });
          },
          "Simulated seconds per wall second while running: 1 real time, 0 as fast as possible.");
}

void BindDaq(py::class_<ModelObject, std::shared_ptr<ModelObject>>& c) {
  c.def("actuators", &Actuators, "The actuators: name, kind, tendon and command unit.")
      .def("actuator_states", &ActuatorStates,
           "Every actuator's command (in its unit) and tendon tension [N].")
      .def("set_command", &SetCommand, py::arg("actuator"), py::arg("value"),
           "Sets one actuator's command (in its command unit, e.g. V for a DC motor).")
      .def("set_commands", &SetCommands, py::arg("commands"),
           "Sets several commands at once, atomically: a dict {actuator: value}.")
      .def("channels", &Channels, py::arg("pattern") = "*",
           "The DAQ channels whose id matches the glob: id, unit, shape, writable, static.")
      .def("get", &Get, py::arg("ids"),
           R"doc(The values of one id (an array of the channel's shape: () for a scalar, (3,)
for a position) or of a list of ids (a list of such arrays).)doc")
      .def("get_values", &GetValues, py::arg("ids"),
           "Every value of `ids`, one channel after the other, as one flat float64 array.")
      .def("control_cycle", &ControlCycle, py::arg("commands"), py::arg("steps"), py::arg("ids"),
           R"doc(One lock-step control cycle in one round trip: sets `commands` (a dict
{actuator: value}), runs `steps` steps and returns every value of `ids` after them, flat (as
get_values). Refused commands or ids change nothing. RunFailed when the physics faults.)doc")
      .def("set", &Set, py::arg("id"), py::arg("value"),
           R"doc(Writes a parameter by DAQ id (e.g. ecce_arm.forearm.mass, in its unit): a number
or an array with the channel's element count. NaN, infinities and sizes no parameter has raise
ValueError naming the argument before anything is sent (the shape is asked first); the Model's
own bounds raise InvalidParameter.)doc");
}

}  // namespace

std::shared_ptr<ModelObject> OpenModel(SessionHandle& s, const std::string& name) {
  std::string lookup = name;
  if (const size_t at = name.find('@'); at != std::string::npos)
    lookup = name.substr(at + 1) + "/" + name.substr(0, at);  // model1@hostb
  auto m = std::make_shared<ModelObject>();
  m->s = s;
  py::gil_scoped_release release;
  CallScope scope(s.timeout_s);
  m->ref = client::ConnectModel(*s.session, lookup);
  m->ref.name = name;
  return m;
}

void RaiseIfFaulted(ModelObject& m, uint64_t asked, uint64_t done) {
  if (done >= asked) return;
  M::SimulationStatus_var s = m.Run([&] { return m.ref.model->status(); });
  if (s->state != M::FAULTED) return;  // a pause, a stop or a replay's end
  py::object error =
      py::module_::import("caliper.errors")
          .attr("RunFailed")(m.ref.name + ": the simulation faulted after " + std::to_string(done) +
                             " of " + std::to_string(asked) + " steps: " + s->last_error.in());
  error.attr("steps") = done;
  PyErr_SetObject(error.get_type().ptr(), error.ptr());
  throw py::error_already_set();
}

py::object ChannelObject(const D::ChannelInfo& c) {
  return Types().attr("Channel")(std::string(c.id.in()), std::string(c.unit.in()),
                                 py::tuple(py::cast(ChannelShape(c.rows, c.cols))),
                                 static_cast<bool>(c.writable), static_cast<bool>(c.is_static),
                                 std::string(c.description.in()));
}

py::array_t<double> ChannelArray(const double* values, uint32_t rows, uint32_t cols) {
  py::array_t<double> out(ChannelShape(rows, cols));
  std::copy(values, values + static_cast<size_t>(rows) * cols, out.mutable_data());
  return out;
}

void BindModel(py::module_& m) {
  py::class_<ModelObject, std::shared_ptr<ModelObject>> c(m, "Model", R"doc(
A Model of a session (Session.model): a Bullet world with its tendons, actuators and DAQ.

Every call waits for the Model's answer with the GIL released; the Model's refusals raise
caliper.errors classes with its message.
)doc");
  c.def_property_readonly(
       "name", [](ModelObject& o) { return o.ref.name; },
       "The name it was asked for (model0, model1@hostb).")
      .def_property_readonly(
          "path", [](ModelObject& o) { return o.ref.path; },
          "Its naming path, HOST.host_cxt/INSTANCE.rtc.")
      .def_property_readonly(
          "local", [](ModelObject& o) { return o.ref.local; },
          "Whether it runs on this host (shares its files).")
      .def("__repr__", [](ModelObject& o) { return "<caliper.Model " + o.ref.path + ">"; });
  BindControl(c);
  BindDaq(c);
  BindEditing(c);
  BindSessionRecording(c);
}

}  // namespace caliper::python
