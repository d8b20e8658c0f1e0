#include "caliper/client/model.h"

#include <fnmatch.h>

#include <cstring>

#include "caliper/core/system.h"

namespace caliper::client {

namespace M = ::Caliper::Simulation;

ModelRef FindModel(CosNaming::NamingContext_ptr root, const std::string& name) {
  rtc::ComponentEntry e;
  try {
    e = rtc::FindComponent(root, name);
  } catch (const rtc::NotFound& error) {
    throw Failure(error.what());
  }
  ModelRef ref;
  ref.name = name;
  ref.path = e.path;
  ref.local = e.host == core::HostName();
  try {
    ref.model = M::Model::_narrow(e.object);
  } catch (const CORBA::Exception& ex) {
    throw ConnectionError(Session::Unreachable(e.path, ex), e.path);
  }
  if (CORBA::is_nil(ref.model)) throw Failure(e.path + " is not a Model (caliper-model)");
  return ref;
}

ModelRef LookUpModel(CORBA::ORB_ptr orb, const std::string& nameservice, const std::string& name,
                     unsigned long call_timeout_ms) {
  CosNaming::NamingContext_var root = rtc::ResolveRoot(orb, ResolveNamingAddress(nameservice));
  const auto ms = static_cast<CORBA::ULong>(call_timeout_ms);
  if (ms > 0) omniORB::setClientCallTimeout(root, ms);
  ModelRef ref = FindModel(root, name);
  // the reference's own timeout bounds every call to the Model (omniORB honours the per-thread
  // one only with -ORBsupportPerThreadTimeOut 1)
  if (ms > 0) omniORB::setClientCallTimeout(ref.model, ms);
  return ref;
}

M::Model_ptr TryLookUpModel(CORBA::ORB_ptr orb, const std::string& nameservice,
                            const std::string& name, unsigned long call_timeout_ms,
                            std::string* why) {
  try {
    return LookUpModel(orb, nameservice, name, call_timeout_ms).model._retn();
  } catch (const CORBA::Exception& e) {
    *why = rtc::Describe(e);
  } catch (const std::exception& e) {
    *why = e.what();
  }
  return M::Model::_nil();
}

ModelRef ConnectModel(Session& session, const std::string& name) {
  CosNaming::NamingContext_var root = session.Root();
  return FindModel(root, name);
}

M::SimulationStatus* StatusOf(const ModelRef& m) {
  return Call(m, [&] { return m.model->status(); });
}

namespace {

// Whether a bound object is a Model, from the type its reference names (no call: a discovery
// loop must not wait on a peer that does not answer). No interface derives from Model, so a
// reference naming another type is not one; only a reference naming none is asked.
bool IsModel(CORBA::Object_ptr object) {
  const char* type = object->_PR_getobj()->_mostDerivedRepoId();
  if (type != nullptr && *type != '\0') return std::strcmp(type, M::Model::_PD_repoId) == 0;
  try {
    return object->_is_a(M::Model::_PD_repoId);
  } catch (const CORBA::SystemException&) {
    return true;  // the caller's pool sets it aside and probes it
  }
}

}  // namespace

std::vector<ModelEntry> FindModels(CosNaming::NamingContext_ptr root, const std::string& glob) {
  std::vector<ModelEntry> out;
  for (auto& e : rtc::ListComponents(root)) {
    const std::string name = e.instance + "@" + e.host;
    if (fnmatch(glob.c_str(), e.instance.c_str(), 0) != 0 &&
        fnmatch(glob.c_str(), name.c_str(), 0) != 0)
      continue;
    if (!IsModel(e.object)) continue;
    out.push_back({name, e.path, e.object});
  }
  return out;
}

}  // namespace caliper::client
