// caliper.Session: the connection to a session's naming service, its components and Models, and
// screenshots from its Scene Renderer.
#include <cstring>

#include "binding.h"
#include "caliper/renderer.hh"
#include "caliper/rtc/naming.h"
#include "model_object.h"

namespace caliper::python {

namespace {

namespace V = ::Caliper::Viewer;

// omniORB has one ORB per process and a Session destroys it: the sessions a program opened stay
// open until the interpreter ends (a session is one naming-service address and a deadline).
std::vector<std::shared_ptr<client::Session>>& Open() {
  static auto* sessions = new std::vector<std::shared_ptr<client::Session>>;
  return *sessions;
}

SessionHandle Connect(const std::string& nameservice, double timeout_s) {
  if (!(timeout_s >= 0) || timeout_s > 86400)
    throw py::value_error("timeout_s must be between 0 (no deadline) and 86400 s, not " +
                          std::to_string(timeout_s));
  auto session = std::make_shared<client::Session>(
      client::SessionOptions{nameservice, timeout_s, "caliper-python"});
  SessionHandle handle{session, timeout_s};
  // kept before it answers: a Session that failed would destroy the process's ORB, which the
  // sessions already open share
  Open().push_back(session);
  {
    py::gil_scoped_release release;
    session->orb();  // the process's ORB first: per-thread deadlines need it
    CallScope scope(timeout_s);
    CosNaming::NamingContext_var root = session->Root();  // ConnectionError when it is away
  }
  return handle;
}

// The interface a bound reference names (Model, Renderer, HostManager, ...), without a call.
std::string KindOf(CORBA::Object_ptr object) {
  const char* type = object->_PR_getobj()->_mostDerivedRepoId();
  std::string id = type == nullptr ? "" : type;  // IDL:Caliper/Simulation/Model:1.0
  const size_t colon = id.rfind(':'), slash = id.rfind('/', colon);
  if (colon == std::string::npos || slash == std::string::npos) return "";
  return id.substr(slash + 1, colon - slash - 1);
}

py::list Components(SessionHandle& s) {
  std::vector<rtc::ComponentEntry> entries;
  {
    py::gil_scoped_release release;
    CallScope scope(s.timeout_s);
    entries = s.session->List();
  }
  py::list out;
  py::object component = py::module_::import("caliper.session").attr("Component");
  for (auto& e : entries)
    out.append(component(e.instance + "@" + e.host, e.host, e.instance, e.path, KindOf(e.object)));
  return out;
}

std::vector<std::string> Models(SessionHandle& s, const std::string& glob) {
  py::gil_scoped_release release;
  CallScope scope(s.timeout_s);
  CosNaming::NamingContext_var root = s.session->Root();
  std::vector<std::string> out;
  for (auto& e : client::FindModels(root, glob)) out.push_back(e.name);
  return out;
}

py::bytes Screenshot(SessionHandle& s, uint32_t width, uint32_t height,
                     const std::string& renderer) {
  if (width < 16 || height < 16 || width > 8192 || height > 8192)
    throw py::value_error("width and height must be 16 to 8192 pixels, not " +
                          std::to_string(width) + "x" + std::to_string(height));
  std::string png;
  {
    py::gil_scoped_release release;
    CallScope scope(std::max(s.timeout_s, 60.0));  // one GUI draw of at most 30 s, then encoding
    std::string name = renderer;
    if (name.empty())
      for (auto& e : s.session->List())
        if (KindOf(e.object) == "Renderer") {
          name = e.host + "/" + e.instance;
          break;
        }
    if (name.empty())
      throw client::NotAvailableError(
          "no Scene Renderer runs in the session at " + s.session->address() +
          " (start one: launch/caliper session --gui, or caliper-renderer)");
    std::string path;
    rtc::ComponentEntry entry = s.session->Find(name);
    V::Renderer_var r = V::Renderer::_narrow(entry.object);
    if (CORBA::is_nil(r)) throw client::Failure(entry.path + " is not a Scene Renderer");
    try {
      V::Png_var bytes = r->screenshot_png(width, height);
      png.assign(reinterpret_cast<const char*>(bytes->get_buffer()), bytes->length());
    } catch (const V::NotAvailable& e) {
      throw client::NotAvailableError(entry.path + ": " + e.reason.in());
    } catch (const CORBA::SystemException& e) {
      throw client::ConnectionError(client::Session::Unreachable(entry.path, e), entry.path);
    }
  }
  return py::bytes(png);
}

}  // namespace

void BindSession(py::module_& m) {
  py::class_<SessionHandle>(m, "Session", R"doc(
A connection to a Caliper session: its naming service, its components and Models.

Made by :func:`caliper.connect`. Every call that waits on the network releases the GIL.
)doc")
      .def(py::init(&Connect), py::arg("nameservice") = "", py::arg("timeout_s") = 5.0,
           R"doc(Connects to the naming service at `nameservice` (corbaname::HOST:PORT; "" for
$CALIPER_NAMESERVICE, else the newest session `launch/caliper session` started on this host,
else corbaname::127.0.0.1:2809). `timeout_s` is every ordinary call's deadline [s] (0: none);
loads, steps and experiments take as long as their work. Raises ConnectionError naming the
address when the naming service does not answer.)doc")
      .def_property_readonly(
          "address", [](SessionHandle& s) { return s.session->address(); },
          "The naming service's address, corbaname::HOST:PORT.")
      .def_property_readonly(
          "timeout_s", [](SessionHandle& s) { return s.timeout_s; },
          "The deadline of ordinary calls [s].")
      .def("components", &Components,
           "Every component bound in the naming service (Models, renderers, host managers, ...), "
           "sorted by host and instance, as caliper.Component tuples.")
      .def("models", &Models, py::arg("glob") = "*",
           R"doc(The names (INSTANCE@HOST, e.g. model1@hostb) of the Models whose instance or
INSTANCE@HOST matches the shell glob `glob`, on every host of the session.)doc")
      .def("model", &OpenModel, py::arg("name") = "model0",
           R"doc(The Model bound as `name`: model0 (this host's first), model1@hostb, hostb/model1
or a naming path. Raises Error when no such Model is bound (the message lists what is),
ConnectionError when it cannot be reached.)doc")
      .def("screenshot", &Screenshot, py::arg("width") = 640, py::arg("height") = 480,
           py::arg("renderer") = "",
           R"doc(A PNG of the Scene Renderer's view (`renderer` by name, or the session's first),
`width` x `height` pixels, as bytes. NotAvailable when no renderer runs.)doc")
      .def("__repr__",
           [](SessionHandle& s) { return "<caliper.Session " + s.session->address() + ">"; });
}

}  // namespace caliper::python
