#pragma once
// Command-line arguments of the Caliper command-line tools (caliper-ctl's verbs,
// caliper-calibrate): options taken out of the list by name, the rest positional. These stay
// beside core::ParseArguments, which parses whole command lines (caliper-ctl's global options
// included): some sixty call sites in the verbs take their options one at a time, wherever they
// stand among the positional words and some more than once (the cluster verbs' `-o`), before
// RejectOptions refuses what is left that looks like an option.

#include <stdexcept>
#include <string>
#include <vector>

namespace caliper::ctl {

/// A usage error: the message, then the verb's help; exit code 2.
struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Takes `--flag VALUE` out of args; returns true when it was there. UsageError without a value.
bool TakeOption(std::vector<std::string>& args, const std::string& flag, std::string* value);
/// Takes `--flag` out of args; returns true when it was there.
bool TakeFlag(std::vector<std::string>& args, const std::string& flag);
/// UsageError for the first remaining argument that looks like an option (`--x`), so that a
/// misspelt option is not taken for a positional argument. Negative numbers pass.
void RejectOptions(const std::vector<std::string>& args);

}  // namespace caliper::ctl
