#pragma once
// A Model of a session: finding it, calling it with its errors turned into the library's
// (errors.h), and the Models of a session or cluster found by name, host and glob.

#include <string>
#include <vector>

#include "caliper/client/session.h"
#include "caliper/model.hh"
#include "caliper/rtc/idl_names.h"

namespace caliper::client {

/// A Model a client works on.
struct ModelRef {
  std::string name;  ///< as asked for (model0, hostb/model1)
  std::string path;  ///< its naming path, hostb.host_cxt/model1.rtc
  bool local = true;  ///< on this host: it shares our files
  ::Caliper::Simulation::Model_var model;
};

/// The Model bound as `name` (model0, host/model0 or a naming path; this host's first) in the
/// naming context `root`; Failure when it is not bound or not a Model, ConnectionError when it
/// cannot be reached. For processes with an ORB of their own (components); clients with a
/// Session call ConnectModel.
ModelRef FindModel(CosNaming::NamingContext_ptr root, const std::string& name);

/// FindModel in the naming service at `nameservice` ("" for $CALIPER_NAMESERVICE or the
/// default) through the process's ORB `orb`, for links that keep their own ORB (the GUI tools).
/// With `call_timeout_ms` > 0, the naming service's root and the Model's reference get that
/// deadline for every call on them. FindModel's errors; CORBA's while the naming service is away.
ModelRef LookUpModel(CORBA::ORB_ptr orb, const std::string& nameservice, const std::string& name,
                     unsigned long call_timeout_ms = 0);

/// LookUpModel saying why instead of throwing: the Model, or nil with `*why` set (FindModel's
/// message, or the CORBA exception while the naming service is away).
::Caliper::Simulation::Model_ptr TryLookUpModel(CORBA::ORB_ptr orb, const std::string& nameservice,
                                               const std::string& name,
                                               unsigned long call_timeout_ms, std::string* why);

/// The Model bound as `name` in the session's naming service (FindModel).
ModelRef ConnectModel(Session& session, const std::string& name);

/// Runs calls on the Model and turns what they raise into the library's errors: a user
/// exception's reason (UnknownIdError, InvalidParameterError, NotAvailableError prefixed with the
/// Model's name, LoadFailedError, EditRefusedError, LimitExceededError, RunFailedError), or
/// ConnectionError saying the Model cannot be reached.
template <class F>
auto Call(const ModelRef& m, F&& f) -> decltype(f()) {
  try {
    return f();
  } catch (const ::Caliper::Daq::UnknownId& e) {
    const std::string reason = e.reason.in(), id = e.id.in();
    throw UnknownIdError(reason.find("'" + id + "'") != std::string::npos
                             ? reason
                             : "unknown id '" + id + "': " + reason,
                         id);
  } catch (const ::Caliper::Daq::InvalidParameter& e) {
    throw InvalidParameterError(e.reason.in());
  } catch (const ::Caliper::Simulation::NotAvailable& e) {
    throw NotAvailableError(m.name + ": " + e.reason.in());
  } catch (const ::Caliper::Daq::NotAvailable& e) {
    throw NotAvailableError(m.name + ": " + e.reason.in());
  } catch (const ::Caliper::Daq::LimitExceeded& e) {
    throw LimitExceededError(m.name + ": " + e.reason.in(), e.limit);
  } catch (const ::Caliper::Simulation::LoadFailed& e) {
    throw LoadFailedError(e.reason.in());
  } catch (const ::Caliper::Simulation::RunFailed& e) {
    throw RunFailedError(e.reason.in());
  } catch (const ::Caliper::Simulation::EditRefused& e) {
    throw EditRefusedError(m.name + ": edit refused: " + e.reason.in());
  } catch (const CORBA::UserException& e) {
    throw Failure(m.path + ": " + rtc::Describe(e));
  } catch (const CORBA::SystemException& e) {
    throw ConnectionError(Session::Unreachable(m.path, e), m.path);
  }
}

/// The Model's status (through Call); the caller owns it.
::Caliper::Simulation::SimulationStatus* StatusOf(const ModelRef& m);

/// A Model bound in the naming service.
struct ModelEntry {
  std::string name;  ///< model1@hostb
  std::string path;  ///< hostb.host_cxt/model1.rtc
  CORBA::Object_var object;
};

/// The Models whose instance (model1) or INSTANCE@HOST matches the glob. Only Models: another
/// component matching the glob (a host's manager for `*@hostb`) is left out, judged by the type
/// its reference names, without a call; a reference that names no type is asked, and kept when
/// it does not answer (a pool sets it aside and probes it).
std::vector<ModelEntry> FindModels(CosNaming::NamingContext_ptr root, const std::string& glob);

}  // namespace caliper::client
