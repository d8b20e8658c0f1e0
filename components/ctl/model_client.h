#pragma once
// What caliper-ctl's verbs on a Model (model_verbs, recording_verbs) share: finding the Model by
// instance name, turning what its calls raise into messages, label/value lines and numbers from
// the command line.

#include <string>
#include <vector>

#include "caliper/model.hh"
#include "caliper/rtc/idl_names.h"
#include "client.h"

namespace caliper::ctl {

/// The Model a verb works on.
struct ModelRef {
  std::string name;
  std::string path;
  bool local = true;  // on this host: it shares our files
  ::Caliper::Simulation::Model_var model;
};

/// Takes `--model NAME` out of args: the Model's instance name, model0 without it.
std::string TakeModel(std::vector<std::string>& args);

/// The Model bound as `name`; Failure when it is not bound, not reachable or not a Model.
ModelRef Connect(Client& client, const std::string& name);

/// Runs calls on the Model and turns what they raise into messages: a user exception's reason
/// (exit 1), or that the Model cannot be reached.
template <class F>
auto Call(const ModelRef& m, F&& f) -> decltype(f()) {
  try {
    return f();
  } catch (const ::Caliper::Daq::UnknownId& e) {
    const std::string reason = e.reason.in(), id = e.id.in();
    throw Failure(reason.find("'" + id + "'") != std::string::npos
                      ? reason
                      : "unknown id '" + id + "': " + reason);
  } catch (const ::Caliper::Daq::InvalidParameter& e) {
    throw Failure(e.reason.in());
  } catch (const ::Caliper::Simulation::NotAvailable& e) {
    throw Failure(m.name + ": " + e.reason.in());
  } catch (const ::Caliper::Daq::NotAvailable& e) {
    throw Failure(m.name + ": " + e.reason.in());
  } catch (const ::Caliper::Simulation::LoadFailed& e) {
    throw Failure(e.reason.in());
  } catch (const ::Caliper::Simulation::EditRefused& e) {
    throw Failure(m.name + ": edit refused: " + e.reason.in());
  } catch (const CORBA::UserException& e) {
    throw Failure(m.path + ": " + rtc::Describe(e));
  } catch (const CORBA::SystemException& e) {
    throw Failure(Client::Unreachable(m.path, e));
  }
}

/// The Model's status (through Call); the caller owns it.
::Caliper::Simulation::SimulationStatus* StatusOf(const ModelRef& m);

/// A value with `precision` significant digits: 7 for values (Bullet computes in single
/// precision), more for times.
std::string Num(double v, int precision = 7);

/// Prints `label` left-aligned in `label_width` columns, then `value`, on one line of stdout.
void Line(const std::string& label, const std::string& value, int label_width = 22);

/// `path` made absolute from this process's working directory: the Model's process has another.
std::string Absolute(const std::string& path);

/// A number given on the command line (nan and inf pass: the Model judges values); UsageError
/// "WHAT: why" otherwise.
double ParseNumber(const std::string& text, const std::string& what);

/// A whole number from 1 to `max`; UsageError "WHAT: 'TEXT' is not a whole number from 1 to MAX"
/// otherwise.
unsigned long long ParseWhole(const std::string& text, const std::string& what,
                              unsigned long long max);

/// A count from 1 to 2^32 - 1 (ParseWhole).
CORBA::ULong ParseCount(const std::string& text, const std::string& what);

/// UsageError for any option or argument left in args.
void NoArguments(const std::vector<std::string>& args);

}  // namespace caliper::ctl
