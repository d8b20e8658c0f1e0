#include "caliper/experiment/experiment.h"

#include <algorithm>
#include <boost/property_tree/json_parser.hpp>
#include <boost/property_tree/ptree.hpp>
#include <boost/tokenizer.hpp>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <locale>
#include <set>

#include "caliper/core/numbers.h"

namespace caliper::experiment {

namespace fs = std::filesystem;
using boost::property_tree::ptree;

namespace {

// Where an error is: `file: experiment 'name': key`.
struct Where {
  std::string file;
  std::string experiment;
  [[noreturn]] void Fail(const std::string& key, const std::string& what) const {
    std::string where;
    auto add = [&where](const std::string& part) { where += (where.empty() ? "" : ": ") + part; };
    if (!file.empty()) add(file);
    if (!experiment.empty()) add("experiment '" + experiment + "'");
    if (!key.empty()) add(key);
    throw FormatError(where + ": " + what);
  }
};

double Number(const std::string& text, const Where& where, const std::string& key) {
  double v = 0;
  if (!core::ParseDouble(text, &v) || !std::isfinite(v))
    where.Fail(key, "'" + text + "' is not a finite number");
  return v;
}

bool IsList(const ptree& node) {
  return !node.empty() && std::all_of(node.begin(), node.end(),
                                      [](const auto& child) { return child.first.empty(); });
}

// A number, or a list of numbers.
std::vector<double> Numbers(const ptree& node, const Where& where, const std::string& key) {
  if (node.empty()) return {Number(node.data(), where, key)};
  if (!IsList(node)) where.Fail(key, "expected a number or a list of numbers");
  std::vector<double> out;
  for (const auto& [k, child] : node) {
    if (!child.empty()) where.Fail(key, "expected a number or a list of numbers");
    out.push_back(Number(child.data(), where, key));
  }
  return out;
}

std::vector<std::string> Strings(const ptree& node, const Where& where, const std::string& key) {
  if (!node.empty() && !IsList(node)) where.Fail(key, "expected a list of strings");
  std::vector<std::string> out;
  for (const auto& [k, child] : node) {
    if (!child.empty()) where.Fail(key, "expected a list of strings");
    out.push_back(child.data());
  }
  if (node.empty() && !node.data().empty()) out.push_back(node.data());
  return out;
}

std::string Resolve(const std::string& path, const std::string& relative_to) {
  if (path.empty()) return path;
  if (fs::path(path).is_absolute()) return fs::path(path).lexically_normal().string();
  return (fs::absolute(relative_to).parent_path() / path).lexically_normal().string();
}

// What one JSON object says; absent keys leave `out` as it is.
void Apply(const ptree& node, const Where& where, Experiment* out,
           std::vector<std::pair<std::string, std::vector<std::vector<double>>>>* sweep) {
  static const std::set<std::string> kKeys = {"name",        "scene",    "duration_s",
                                              "every_n_steps", "record", "set",
                                              "commands",    "commands_csv", "sweep",
                                              "experiments"};
  if (node.empty() && !node.data().empty()) where.Fail("", "expected an object, not a value");
  std::set<std::string> seen;
  for (const auto& [key, child] : node) {
    if (key.empty()) where.Fail("", "expected an object with keys, not a list");
    if (!kKeys.count(key))
      where.Fail(key, "unknown key (known: name, scene, duration_s, every_n_steps, record, set, "
                      "commands, commands_csv, sweep, experiments)");
    if (!seen.insert(key).second) where.Fail(key, "given twice");
  }
  // objects and lists where they belong (an empty list reads as an empty value)
  for (const char* key : {"set", "sweep"})
    if (auto v = node.get_child_optional(key); v && !v->data().empty())
      where.Fail(key, "expected an object {\"id\": ...}");
  if (auto v = node.get_child_optional("commands");
      v && (!v->data().empty() || (!v->empty() && !IsList(*v))))
    where.Fail("commands", "expected a list of [time_s, \"actuator\", value]");
  if (auto v = node.get_child_optional("name")) out->name = v->data();
  if (auto v = node.get_child_optional("scene")) out->scene = Resolve(v->data(), where.file);
  if (auto v = node.get_child_optional("duration_s"))
    out->duration_s = Number(v->data(), where, "duration_s");
  if (auto v = node.get_child_optional("every_n_steps")) {
    const double n = Number(v->data(), where, "every_n_steps");
    if (n < 1 || n > 1e9 || n != std::floor(n))
      where.Fail("every_n_steps", "must be a whole number >= 1");
    out->every_n_steps = static_cast<uint32_t>(n);
  }
  if (auto v = node.get_child_optional("record")) out->record = Strings(*v, where, "record");
  if (auto v = node.get_child_optional("set"))
    for (const auto& [id, value] : *v) {
      if (id.empty()) where.Fail("set", "expected an object {\"id\": value, ...}");
      auto same = [&key = id](const Override& o) { return o.id == key; };
      out->overrides.erase(std::remove_if(out->overrides.begin(), out->overrides.end(), same),
                           out->overrides.end());
      out->overrides.push_back({id, Numbers(value, where, "set." + id)});
    }
  if (auto v = node.get_child_optional("commands")) {
    out->schedule.clear();
    for (const auto& [k, row] : *v) {
      std::vector<const ptree*> fields;
      bool keyed = false;
      for (const auto& [k2, f] : row) {
        fields.push_back(&f);
        keyed = keyed || !k2.empty();
      }
      if (!k.empty() || keyed || fields.size() != 3 || !fields[1]->empty())
        where.Fail("commands", "expected a list of [time_s, \"actuator\", value]");
      out->schedule.push_back({Number(fields[0]->data(), where, "commands"), fields[1]->data(),
                               Number(fields[2]->data(), where, "commands")});
    }
  }
  if (auto v = node.get_child_optional("commands_csv")) {
    try {
      out->schedule = LoadScheduleCsv(Resolve(v->data(), where.file));
    } catch (const FormatError& e) {
      where.Fail("commands_csv", e.what());
    }
  }
  if (auto v = node.get_child_optional("sweep")) {
    sweep->clear();
    for (const auto& [id, values] : *v) {
      if (id.empty() || !IsList(values))
        where.Fail("sweep", "expected an object {\"id\": [value, value, ...], ...}");
      std::vector<std::vector<double>> options;
      for (const auto& [k, value] : values) options.push_back(Numbers(value, where, "sweep." + id));
      sweep->emplace_back(id, options);
    }
  }
}

// One experiment per combination of the sweep's values, named NAME-K; at most kMaxRuns in the
// file (a few hundred bytes of sweep would otherwise ask for billions of runs and exhaust memory).
void Expand(const Experiment& base,
            const std::vector<std::pair<std::string, std::vector<std::vector<double>>>>& sweep,
            const Where& where, std::vector<Experiment>* out) {
  size_t total = 1;
  for (const auto& [id, options] : sweep) {
    if (!options.empty() && total > (kMaxRuns - out->size()) / options.size())
      where.Fail("sweep", "more than " + std::to_string(kMaxRuns) +
                              " runs in the file (the product of the numbers of values)");
    total *= options.size();
  }
  if (sweep.empty() && out->size() >= kMaxRuns)
    where.Fail("experiments", "more than " + std::to_string(kMaxRuns) + " runs in the file");
  if (sweep.empty() || total == 0) {
    if (sweep.empty()) out->push_back(base);
    return;
  }
  const size_t width = std::to_string(total - 1).size();
  for (size_t k = 0; k < total; ++k) {
    Experiment e = base;
    // the first key varies slowest; overrides keep the keys' order
    std::vector<size_t> choice(sweep.size());
    size_t rest = k;
    for (size_t i = sweep.size(); i-- > 0;) {
      choice[i] = rest % sweep[i].second.size();
      rest /= sweep[i].second.size();
    }
    for (size_t i = 0; i < sweep.size(); ++i)
      e.overrides.push_back({sweep[i].first, sweep[i].second[choice[i]]});
    std::string index = std::to_string(k);
    e.name += "-" + std::string(width - index.size(), '0') + index;
    out->push_back(std::move(e));
  }
}

}  // namespace

uint64_t StepCount(double duration_s, double time_step_s) {
  if (!(time_step_s > 0) || !(duration_s >= 0) || !std::isfinite(duration_s / time_step_s))
    throw FormatError("duration " + std::to_string(duration_s) + " s at a time step of " +
                      std::to_string(time_step_s) + " s is no number of steps");
  return static_cast<uint64_t>(std::llround(duration_s / time_step_s));
}

void Validate(const Experiment& e) {
  const Where where{"", e.name};
  if (e.name.empty()) where.Fail("name", "missing");
  for (char c : e.name)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '.' && c != '_' && c != '-')
      where.Fail("name", "use letters, digits, '.', '_' and '-' only (it names files)");
  if (e.scene.empty()) where.Fail("scene", "missing");
  if (!(e.duration_s > 0) || e.duration_s > 1e6)
    where.Fail("duration_s", "must be in (0, 1e6] s");
  if (e.every_n_steps < 1) where.Fail("every_n_steps", "must be >= 1");
  if (e.record.empty()) where.Fail("record", "name at least one id to record");
  for (size_t i = 0; i < e.schedule.size(); ++i) {
    const Command& c = e.schedule[i];
    if (c.actuator.empty()) where.Fail("commands", "a command without an actuator");
    if (!(c.time_s >= 0) || !std::isfinite(c.value))
      where.Fail("commands", "command " + std::to_string(i + 1) + " for '" + c.actuator +
                                 "': time must be >= 0 s and the value finite");
  }
}

std::vector<Command> LoadScheduleCsv(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw FormatError(path + ": cannot be read");
  std::vector<Command> out;
  std::string line;
  const Where where{path, ""};
  for (int number = 1; std::getline(in, line); ++number) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (number == 1 || line.empty()) continue;  // the header
    using Tokens = boost::tokenizer<boost::escaped_list_separator<char>>;
    std::vector<std::string> fields;
    try {
      Tokens tokens(line);
      fields.assign(tokens.begin(), tokens.end());
    } catch (const boost::escaped_list_error& e) {
      where.Fail("line " + std::to_string(number), e.what());
    }
    for (auto& f : fields) {
      const auto first = f.find_first_not_of(" \t"), last = f.find_last_not_of(" \t");
      f = first == std::string::npos ? "" : f.substr(first, last - first + 1);
    }
    const std::string at = "line " + std::to_string(number);
    if (fields.size() != 3) where.Fail(at, "expected time [s],actuator,value");
    out.push_back({Number(fields[0], where, at), fields[1], Number(fields[2], where, at)});
  }
  return out;
}

std::vector<Experiment> LoadFile(const std::string& path) {
  ptree root;
  try {
    // numbers stay text (Number reads them); the classic locale keeps the stream itself
    // independent of the process's
    boost::property_tree::read_json(path, root, std::locale::classic());
  } catch (const boost::property_tree::json_parser_error& e) {
    throw FormatError(path + ":" + std::to_string(e.line()) + ": " + e.message());
  }
  Where where{path, ""};
  Experiment defaults;
  defaults.name = fs::path(path).stem().string();
  std::vector<std::pair<std::string, std::vector<std::vector<double>>>> sweep;
  Apply(root, where, &defaults, &sweep);
  std::vector<Experiment> out;
  const auto list = root.get_child_optional("experiments");
  if (!list) {
    Expand(defaults, sweep, where, &out);
  } else {
    if (!list->empty() && !IsList(*list)) where.Fail("experiments", "expected a list of objects");
    int index = 0;
    for (const auto& [k, entry] : *list) {
      if (entry.empty() && !entry.data().empty())
        where.Fail("experiments", "expected a list of objects, found '" + entry.data() + "'");
      Experiment e = defaults;
      e.name = "run" + std::to_string(++index);
      if (auto name = entry.get_child_optional("name")) e.name = name->data();
      auto own_sweep = sweep;
      where.experiment = e.name;
      if (entry.count("experiments")) where.Fail("experiments", "experiments do not nest");
      Apply(entry, where, &e, &own_sweep);
      Expand(e, own_sweep, where, &out);
    }
  }
  if (out.empty()) where.Fail("experiments", "no experiment in the file");
  std::set<std::string> names;
  for (auto& e : out) {
    std::stable_sort(e.schedule.begin(), e.schedule.end(),
                     [](const Command& a, const Command& b) { return a.time_s < b.time_s; });
    try {
      Validate(e);
    } catch (const FormatError& error) {
      throw FormatError(path + ": " + error.what());
    }
    if (!names.insert(e.name).second)
      throw FormatError(path + ": experiment '" + e.name + "': the name is used twice");
  }
  return out;
}

}  // namespace caliper::experiment
