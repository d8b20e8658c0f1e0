#include "caliper/rtc/naming.h"

#include <algorithm>
#include <cstdlib>

#include "caliper/core/system.h"
#include "caliper/rtc/local_sockets.h"
#include "caliper/rtc/transport_security.h"

namespace caliper::rtc {

std::string NamingAddress(const std::string& from_option) {
  if (!from_option.empty()) return from_option;
  const char* env = std::getenv("CALIPER_NAMESERVICE");
  if (env != nullptr && *env != '\0') return env;
  return "corbaname::127.0.0.1:2809";
}

std::string Describe(const CORBA::Exception& e) {
  std::string text = e._name();
  if (const auto* sys = CORBA::SystemException::_downcast(&e)) {
    const char* minor = sys->NP_minorString();
    if (minor != nullptr) text += std::string(" (") + minor + ")";
  }
  // a refused TLS handshake, a reference only TLS can reach: said rather than a bare COMM_FAILURE
  if (const std::string note = TransportFailureNote(e); !note.empty()) text += ": " + note;
  return text;
}

CosNaming::NamingContext_ptr ResolveRoot(CORBA::ORB_ptr orb, const std::string& address) {
  try {
    CORBA::Object_var obj = orb->string_to_object(SecureNamingAddress(address).c_str());
    CosNaming::NamingContext_var root = CosNaming::NamingContext::_narrow(obj);
    if (CORBA::is_nil(root)) throw Unreachable("no naming context at " + address);
    root->_non_existent();  // forces a round trip now rather than at first use
    return root._retn();
  } catch (const CORBA::Exception& e) {
    std::string why = Describe(e);
    if (IsLocalSocketAddress(address)) {
      // another user's session (or one that has ended): said for the naming service itself
      const std::string note = LocalSocketNote(LocalSocketPath(address), "the naming service");
      if (!note.empty()) why = why.substr(0, why.find(": ")) + ": " + note;
    }
    if (why.find(": ", 0) == std::string::npos) {
      // no note from the transport: ask the service for a TLS handshake ourselves
      const std::string probe = ProbeNamingService(address);
      if (!probe.empty()) why += ": " + probe;
    }
    throw Unreachable("cannot reach the naming service at " + SecureNamingAddress(address) +
                      ": " + why);
  }
}

CosNaming::Name ComponentName(const std::string& host, const std::string& instance) {
  CosNaming::Name name;
  name.length(2);
  name[0].id = host.c_str();
  name[0].kind = "host_cxt";
  name[1].id = instance.c_str();
  name[1].kind = "rtc";
  return name;
}

namespace {

std::vector<CosNaming::Binding> ListContext(CosNaming::NamingContext_ptr context) {
  std::vector<CosNaming::Binding> out;
  CosNaming::BindingList_var list;
  CosNaming::BindingIterator_var it;
  context->list(1000, list.out(), it.out());
  for (CORBA::ULong i = 0; i < list->length(); ++i) out.push_back(list[i]);
  if (!CORBA::is_nil(it)) {
    CosNaming::BindingList_var more;
    while (it->next_n(1000, more.out()) && more->length() > 0)
      for (CORBA::ULong i = 0; i < more->length(); ++i) out.push_back(more[i]);
    it->destroy();
  }
  return out;
}

}  // namespace

std::vector<ComponentEntry> ListComponents(CosNaming::NamingContext_ptr root) {
  std::vector<ComponentEntry> entries;
  for (const auto& host : ListContext(root)) {
    if (host.binding_type != CosNaming::ncontext ||
        std::string(host.binding_name[0].kind) != "host_cxt")
      continue;
    CORBA::Object_var obj = root->resolve(host.binding_name);
    CosNaming::NamingContext_var context = CosNaming::NamingContext::_narrow(obj);
    if (CORBA::is_nil(context)) continue;
    for (const auto& b : ListContext(context)) {
      if (b.binding_type != CosNaming::nobject || std::string(b.binding_name[0].kind) != "rtc")
        continue;
      ComponentEntry e;
      e.host = host.binding_name[0].id.in();
      e.instance = b.binding_name[0].id.in();
      e.path = e.host + ".host_cxt/" + e.instance + ".rtc";
      try {
        e.object = context->resolve(b.binding_name);
      } catch (const CosNaming::NamingContext::NotFound&) {
        continue;  // unbound between list and resolve
      }
      entries.push_back(std::move(e));
    }
  }
  std::sort(entries.begin(), entries.end(), [](const auto& a, const auto& b) {
    return a.host != b.host ? a.host < b.host : a.instance < b.instance;
  });
  return entries;
}

ComponentEntry FindComponent(CosNaming::NamingContext_ptr root, const std::string& name) {
  // INSTANCE, INSTANCE@HOST (as batch summaries and the Python package print it), HOST/INSTANCE
  // or HOST.host_cxt/INSTANCE.rtc
  std::string host, instance = name;
  const auto slash = name.find('/');
  const auto at = name.rfind('@');
  if (slash != std::string::npos) {
    host = name.substr(0, slash);
    instance = name.substr(slash + 1);
  } else if (at != std::string::npos && at > 0 && at + 1 < name.size()) {
    instance = name.substr(0, at);
    host = name.substr(at + 1);
  }
  auto strip = [](std::string* s, const std::string& suffix) {
    if (s->size() > suffix.size() && s->compare(s->size() - suffix.size(), suffix.size(), suffix) == 0)
      s->erase(s->size() - suffix.size());
  };
  strip(&host, ".host_cxt");
  strip(&instance, ".rtc");
  const auto entries = ListComponents(root);
  const std::string here = core::HostName();
  const ComponentEntry* found = nullptr;
  for (const auto& e : entries) {
    if (e.instance != instance || (!host.empty() && e.host != host)) continue;
    if (found == nullptr || e.host == here) found = &e;
  }
  if (found == nullptr) {
    // with several hosts, each as INSTANCE@HOST (the name that finds it)
    bool hosts = false;
    for (const auto& e : entries) hosts = hosts || e.host != entries.front().host;
    std::string known;
    for (const auto& e : entries)
      known += (known.empty() ? "" : ", ") + e.instance + (hosts ? "@" + e.host : std::string());
    throw NotFound("no component named '" + name + "' in the naming service (bound: " +
                   (known.empty() ? std::string("none") : known) + ")");
  }
  ComponentEntry copy;
  copy.host = found->host;
  copy.instance = found->instance;
  copy.path = found->path;
  copy.object = CORBA::Object::_duplicate(found->object);
  return copy;
}

bool ObjectAlive(CORBA::Object_ptr object) {
  if (CORBA::is_nil(object)) return false;
  try {
    return !object->_non_existent();
  } catch (const CORBA::Exception&) {
    return false;
  }
}

}  // namespace caliper::rtc
