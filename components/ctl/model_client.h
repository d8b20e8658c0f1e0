#pragma once
// What caliper-ctl's verbs on a Model (model_verbs, recording_verbs) share beside the client
// library's Model (libs/client: finding it, calls and their errors): label/value lines and
// numbers from the command line.

#include <string>
#include <vector>

#include "caliper/client/model.h"
#include "caliper/rtc/idl_names.h"
#include "client.h"

namespace caliper::ctl {

using client::Call;
using client::ModelRef;
using client::StatusOf;

/// Takes `--model NAME` out of args: the Model's instance name, model0 without it.
std::string TakeModel(std::vector<std::string>& args);

/// The Model bound as `name` (client::ConnectModel).
inline ModelRef Connect(Client& client, const std::string& name) {
  return client::ConnectModel(client, name);
}

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
