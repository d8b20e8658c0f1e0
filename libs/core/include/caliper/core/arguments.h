#pragma once
// The one command-line parser of Caliper's programs: the components (rtc::RunComponent), the GUI
// tools before Qt sees argv (gui_session::SplitToolArguments), the renderer's own options and
// caliper-ctl's global ones. Each program declares its options and words its own errors.
//
// Boost.Program_options does not serve: it cannot stop at the first positional word (the verb
// of caliper-ctl, whose options follow it), it cannot pass another parser's options on with
// their values (Qt's `-platform NAME`, omniORB's `-ORBendPoint ADDRESS`: it does not know how
// many words an option it does not know takes), and it words its own errors.

#include <cstddef>
#include <functional>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace caliper::core {

/// What a program's command line may hold.
struct ArgumentSpec {
  std::set<std::string> valued;                   ///< options followed by a value; may repeat
  std::set<std::string> flags;                    ///< options without a value
  std::set<std::string> help = {"-h", "--help"};  ///< words that ask for the help text
  /// For a word that is none of these: how many words, itself included, go on to another parser
  /// (1 or 2: Qt's `-platform NAME`, omniORB's `-ORBendPoint ADDRESS`); 0 when none do.
  std::function<int(const std::string& word)> pass;
  /// The first positional word ends the options: it and all after it are positional (a verb).
  bool stop_at_positional = false;
};

/// A command line taken apart, up to its first error.
struct Arguments {
  /// Options in the order given, with their values ("" for flags).
  std::vector<std::pair<std::string, std::string>> options;
  std::vector<std::string> positional;  ///< the other words, in order
  std::vector<size_t> passed;           ///< indices of the words passed on, in order
  bool help = false;                    ///< a help word was given
  std::string unknown;        ///< the first word that looks like an option and is none ("")
  std::string missing_value;  ///< the option that lacks its value at the end ("")

  /// "option --x needs a value", "unknown option '--x'", or "" when neither.
  std::string Error() const;
  /// The last value of `option`, `fallback` when it was not given.
  std::string Value(const std::string& option, const std::string& fallback = "") const;
  /// Every value of `option`, in order.
  std::vector<std::string> Values(const std::string& option) const;
  /// Whether `option` (or flag) was given.
  bool Has(const std::string& option) const;
};

/// Takes `words` (argv without argv[0]) apart. A word that starts with '-' and is not a number
/// (`-1.5` is positional) looks like an option. Stops at the first unknown option or missing
/// value.
Arguments ParseArguments(const std::vector<std::string>& words, const ArgumentSpec& spec);

/// A usage error of a command-line tool: the message, then the tool's help; exit code 2.
struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Options taken out of a word list one at a time, wherever they stand among the positional
// words and some more than once (caliper-ctl's verbs, caliper-calibrate), before RejectOptions
// refuses what is left that looks like an option.

/// Takes `--flag VALUE` out of args; returns true when it was there. UsageError without a value.
bool TakeOption(std::vector<std::string>& args, const std::string& flag, std::string* value);
/// Takes `--flag` out of args; returns true when it was there.
bool TakeFlag(std::vector<std::string>& args, const std::string& flag);
/// UsageError for the first remaining argument that looks like an option (`--x`), so that a
/// misspelt option is not taken for a positional argument. Negative numbers pass.
void RejectOptions(const std::vector<std::string>& args);

}  // namespace caliper::core
