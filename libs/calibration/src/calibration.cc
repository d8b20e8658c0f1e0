#include "caliper/calibration/calibration.h"

#include <algorithm>
#include <boost/property_tree/json_parser.hpp>
#include <boost/property_tree/ptree.hpp>
#include <boost/tokenizer.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <locale>
#include <set>

#include "caliper/core/numbers.h"

namespace caliper::calibration {

namespace fs = std::filesystem;
using boost::property_tree::ptree;

namespace {

[[noreturn]] void Fail(const std::string& where, const std::string& what) {
  throw SpecError(where + ": " + what);
}

double Number(const std::string& text, const std::string& where) {
  double v = 0;
  if (!core::ParseDouble(text, &v) || !std::isfinite(v))
    Fail(where, "'" + text + "' is not a finite number");
  return v;
}

std::string Resolve(const std::string& path, const std::string& relative_to) {
  if (fs::path(path).is_absolute()) return path;
  return (fs::absolute(relative_to).parent_path() / path).lexically_normal().string();
}

// `name [unit]` -> name, unit.
std::pair<std::string, std::string> SplitHeader(const std::string& field) {
  const auto open = field.rfind(" [");
  if (open == std::string::npos || field.back() != ']') return {field, ""};
  return {field.substr(0, open), field.substr(open + 2, field.size() - open - 3)};
}

}  // namespace

double Parameter::FromUnit(double u) const {
  u = std::clamp(u, 0.0, 1.0);
  return log_scale ? lower * std::pow(upper / lower, u) : lower + u * (upper - lower);
}

double Parameter::ToUnit(double value) const {
  const double u = log_scale ? std::log(value / lower) / std::log(upper / lower)
                             : (value - lower) / (upper - lower);
  return std::clamp(u, 0.0, 1.0);
}

double Measured::At(size_t c, double t) const {
  const auto it = std::upper_bound(times.begin(), times.end(), t);
  if (it == times.begin()) return values[c].front();
  if (it == times.end()) return values[c].back();
  const size_t i = static_cast<size_t>(it - times.begin());
  const double t0 = times[i - 1], t1 = times[i];
  const double a = t1 > t0 ? (t - t0) / (t1 - t0) : 0;
  return values[c][i - 1] + a * (values[c][i] - values[c][i - 1]);
}

Measured LoadMeasured(const std::string& path) {
  std::ifstream in(path);
  if (!in) Fail(path, "cannot be read");
  Measured m;
  m.file = path;
  std::string line;
  using Tokens = boost::tokenizer<boost::escaped_list_separator<char>>;
  for (int number = 1; std::getline(in, line); ++number) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    std::vector<std::string> fields;
    try {
      Tokens tokens(line);
      fields.assign(tokens.begin(), tokens.end());
    } catch (const boost::escaped_list_error& e) {
      Fail(path + ":" + std::to_string(number), e.what());
    }
    const std::string at = path + ":" + std::to_string(number);
    if (m.columns.empty() && m.times.empty() && m.units.empty()) {
      if (fields.size() < 2 || SplitHeader(fields[0]).first != "time")
        Fail(at, "the header must be `time [s],name [unit],...`");
      if (SplitHeader(fields[0]).second != "s") Fail(at, "time must be in seconds: `time [s]`");
      for (size_t i = 1; i < fields.size(); ++i) {
        const auto [name, unit] = SplitHeader(fields[i]);
        m.columns.push_back(name);
        m.units.push_back(unit);
      }
      m.values.resize(m.columns.size());
      continue;
    }
    if (fields.size() != m.columns.size() + 1)
      Fail(at, std::to_string(fields.size()) + " fields, the header has " +
                   std::to_string(m.columns.size() + 1));
    const double t = Number(fields[0], at);
    if (!m.times.empty() && t <= m.times.back()) Fail(at, "times must increase");
    m.times.push_back(t);
    for (size_t i = 1; i < fields.size(); ++i)
      m.values[i - 1].push_back(Number(fields[i], at + " column " + std::to_string(i + 1)));
  }
  if (m.times.size() < 2) Fail(path, "needs at least two rows of measurements");
  return m;
}

// A key of `node` not in `known` is a typo (a "scael" would otherwise be taken for the default).
void RejectUnknownKeys(const ptree& node, const std::vector<std::string>& known,
                       const std::string& where) {
  for (const auto& [key, child] : node) {
    if (std::find(known.begin(), known.end(), key) != known.end()) continue;
    std::string list;
    for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
    Fail(where, "unknown key '" + key + "' (known: " + list + ")");
  }
}

// The optimiser, refinement, uncertainty and held_out keys of a calibration file.
void ReadSearchKeys(const ptree& root, const std::string& path, Spec& spec) {
  if (const auto o = root.get_child_optional("optimiser")) {
    const std::string where = path + ": optimiser";
    RejectUnknownKeys(*o,
                      {"algorithm", "generations", "population", "sigma0", "window",
                       "cost_tolerance", "step_tolerance", "target_cost", "restarts"},
                      where);
    spec.optimiser.algorithm = o->get<std::string>("algorithm", "cmaes");
    if (spec.optimiser.algorithm != "cmaes" && spec.optimiser.algorithm != "xnes")
      Fail(where, "algorithm is cmaes or xnes (pagmo's evolution strategies)");
    const double generations = Number(o->get<std::string>("generations", "40"), where);
    const double population = Number(o->get<std::string>("population", "10"), where);
    if (generations < 0 || generations > 1e6 || population < 5 || population > 1e4)
      Fail(where, "generations >= 0 (0: no global search), population >= 5 (CMA-ES needs a few)");
    spec.optimiser.generations = static_cast<unsigned>(generations);
    spec.optimiser.population = static_cast<unsigned>(population);
    spec.optimiser.sigma0 = Number(o->get<std::string>("sigma0", "0.25"), where + ": sigma0");
    if (!(spec.optimiser.sigma0 > 0 && spec.optimiser.sigma0 <= 1))
      Fail(where, "sigma0 is in (0, 1] (the search space is scaled to [0, 1])");
    const double window = Number(o->get<std::string>("window", "20"), where + ": window");
    if (!(window >= 2 && window <= 1e6)) Fail(where + ": window", "generations, from 2");
    spec.optimiser.window = static_cast<unsigned>(window);
    spec.optimiser.cost_tolerance =
        Number(o->get<std::string>("cost_tolerance", "1e-6"), where + ": cost_tolerance");
    spec.optimiser.step_tolerance =
        Number(o->get<std::string>("step_tolerance", "1e-4"), where + ": step_tolerance");
    spec.optimiser.target_cost =
        Number(o->get<std::string>("target_cost", "0"), where + ": target_cost");
    if (spec.optimiser.cost_tolerance < 0 || spec.optimiser.step_tolerance < 0 ||
        spec.optimiser.target_cost < 0)
      Fail(where, "cost_tolerance, step_tolerance and target_cost are >= 0");
    const double restarts = Number(o->get<std::string>("restarts", "2"), where + ": restarts");
    if (!(restarts >= 0 && restarts <= 20)) Fail(where + ": restarts", "from 0 to 20");
    spec.optimiser.restarts = static_cast<unsigned>(restarts);
  }
  if (const auto r = root.get_child_optional("refinement")) {
    const std::string where = path + ": refinement";
    RejectUnknownKeys(*r, {"iterations", "jacobian", "step"}, where);
    const double iterations =
        Number(r->get<std::string>("iterations", "30"), where + ": iterations");
    if (!(iterations >= 0 && iterations <= 10000)) Fail(where, "iterations from 0 (off) to 10000");
    spec.refinement.iterations = static_cast<unsigned>(iterations);
    const std::string jacobian = r->get<std::string>("jacobian", "central");
    if (jacobian != "central" && jacobian != "forward")
      Fail(where, "jacobian is central or forward (finite differences)");
    spec.refinement.central = jacobian == "central";
    spec.refinement.step = Number(r->get<std::string>("step", "1e-3"), where + ": step");
    if (!(spec.refinement.step > 0 && spec.refinement.step <= 0.1))
      Fail(where, "step is in (0, 0.1] of the unit search space");
  }
  if (const auto u = root.get_child_optional("uncertainty")) {
    const std::string where = path + ": uncertainty";
    RejectUnknownKeys(*u, {"max_relative_interval", "max_correlation"}, where);
    spec.uncertainty.max_relative_interval = Number(
        u->get<std::string>("max_relative_interval", "0.1"), where + ": max_relative_interval");
    spec.uncertainty.max_correlation =
        Number(u->get<std::string>("max_correlation", "0.95"), where + ": max_correlation");
    if (!(spec.uncertainty.max_relative_interval > 0) ||
        !(spec.uncertainty.max_correlation > 0 && spec.uncertainty.max_correlation <= 1))
      Fail(where, "max_relative_interval > 0, max_correlation in (0, 1]");
  }
  spec.held_out.assign(spec.experiments.size(), false);
  if (const auto h = root.get_child_optional("held_out")) {
    for (const auto& [k, node] : *h) {
      const std::string name = node.data();
      size_t i = 0;
      while (i < spec.experiments.size() && spec.experiments[i].name != name) ++i;
      if (i == spec.experiments.size())
        Fail(path + ": held_out", "no experiment named '" + name + "'");
      spec.held_out[i] = true;
    }
    if (spec.Fitted() == 0) Fail(path + ": held_out", "every experiment is held out: none to fit");
  }
}

Spec LoadSpec(const std::string& path) {
  ptree root;
  try {
    boost::property_tree::read_json(path, root, std::locale::classic());
  } catch (const boost::property_tree::json_parser_error& e) {
    throw SpecError(path + ":" + std::to_string(e.line()) + ": " + e.message());
  }
  RejectUnknownKeys(root,
                    {"experiments", "measured", "parameters", "channels", "optimiser", "refinement",
                     "uncertainty", "held_out", "seed"},
                    path);
  Spec spec;
  spec.file = path;
  const std::string runs = root.get<std::string>("experiments", "");
  if (runs.empty()) Fail(path, "experiments: name the experiment file");
  try {
    spec.experiments = experiment::LoadFile(Resolve(runs, path));
  } catch (const experiment::FormatError& e) {
    Fail(path, std::string("experiments: ") + e.what());
  }
  const auto measured = root.get_child_optional("measured");
  for (const auto& e : spec.experiments) {
    const auto file =
        measured ? measured->get_optional<std::string>(boost::property_tree::path(e.name, '\0'))
                 : boost::none;
    if (!file) Fail(path, "measured: no file for experiment '" + e.name + "'");
    try {
      spec.measured.push_back(LoadMeasured(Resolve(*file, path)));
    } catch (const SpecError& error) {
      Fail(path, "measured: '" + e.name + "': " + error.what());
    }
  }
  const auto parameters = root.get_child_optional("parameters");
  if (!parameters || parameters->empty()) Fail(path, "parameters: name at least one to fit");
  std::set<std::string> ids;
  for (const auto& [k, node] : *parameters) {
    Parameter p;
    p.id = node.get<std::string>("id", "");
    const std::string where = path + ": parameters: '" + p.id + "'";
    if (p.id.empty()) Fail(path, "parameters: an entry without \"id\"");
    RejectUnknownKeys(node, {"id", "lower", "upper", "scale"}, where);
    if (!ids.insert(p.id).second) Fail(where, "listed twice");
    const auto colon = p.id.find(':');
    const std::string kind = colon == std::string::npos ? "" : p.id.substr(0, colon);
    if (p.id == "time_shift") {
      p.kind = ParameterKind::kTimeShift;
    } else if (kind == "sensor_delay" || kind == "command_delay") {
      p.kind = kind == "sensor_delay" ? ParameterKind::kSensorDelay : ParameterKind::kCommandDelay;
      p.target = p.id.substr(colon + 1);
      if (p.target.empty())
        Fail(where, kind == "sensor_delay" ? "name the measured column: sensor_delay:CHANNEL"
                                           : "name the actuator: command_delay:ACTUATOR");
    } else if (!kind.empty()) {
      Fail(where, "unknown kind '" + kind +
                      ":' (time_shift, sensor_delay:CHANNEL, "
                      "command_delay:ACTUATOR, or a scene parameter's id)");
    }
    p.lower = Number(node.get<std::string>("lower", ""), where + ": lower");
    p.upper = Number(node.get<std::string>("upper", ""), where + ": upper");
    const std::string scale = node.get<std::string>("scale", "linear");
    if (scale != "linear" && scale != "log") Fail(where, "scale is linear or log");
    p.log_scale = scale == "log";
    if (!(p.lower < p.upper)) Fail(where, "lower must be below upper");
    if (p.log_scale && !(p.lower > 0)) Fail(where, "a log scale needs lower > 0");
    // the search space's span: finite, or every value mapped from it would be inf or NaN
    if (!std::isfinite(p.log_scale ? p.upper / p.lower : p.upper - p.lower))
      Fail(where, p.log_scale ? "upper / lower is too large for a log scale"
                              : "upper - lower is too large");
    if (p.kind == ParameterKind::kSensorDelay || p.kind == ParameterKind::kCommandDelay)
      if (p.lower < 0) Fail(where, "a delay cannot be negative: lower >= 0");
    if (p.kind == ParameterKind::kSensorDelay) {
      bool measured_somewhere = false;
      for (const auto& m : spec.measured)
        measured_somewhere = measured_somewhere || std::find(m.columns.begin(), m.columns.end(),
                                                             p.target) != m.columns.end();
      if (!measured_somewhere) Fail(where, "no measured file has a column '" + p.target + "'");
    }
    spec.parameters.push_back(p);
  }
  if (const auto channels = root.get_child_optional("channels"))
    for (const auto& [k, node] : *channels) {
      const std::string id = node.get<std::string>("id", "");
      const std::string where = path + ": channels: '" + id + "'";
      if (id.empty()) Fail(path, "channels: an entry without \"id\"");
      RejectUnknownKeys(node, {"id", "weight", "window_s"}, where);
      ChannelWeight w;
      w.weight = Number(node.get<std::string>("weight", "1"), where + ": weight");
      if (!(w.weight >= 0)) Fail(where, "weight must be >= 0");
      if (const auto window = node.get_child_optional("window_s")) {
        std::vector<double> bounds;
        for (const auto& [k2, b] : *window)
          bounds.push_back(Number(b.data(), where + ": window_s"));
        if (bounds.size() != 2 || !(bounds[0] < bounds[1]))
          Fail(where, "window_s is [from, to] with from < to");
        w.from_s = bounds[0];
        w.to_s = bounds[1];
      }
      spec.channels[id] = w;
    }
  ReadSearchKeys(root, path, spec);
  const double seed = Number(root.get<std::string>("seed", "1"), path + ": seed");
  // exactly representable whole numbers only (a cast of a negative or larger one is undefined)
  if (!(seed >= 0 && seed <= 9007199254740992.0 && seed == std::floor(seed)))
    Fail(path + ": seed", "a whole number in [0, 2^53]");
  spec.seed = static_cast<uint64_t>(seed);
  return spec;
}

std::vector<std::string> ColumnNames(const std::vector<experiment::Channel>& channels) {
  std::vector<std::string> out;
  for (const auto& c : channels) {
    const uint32_t n = c.rows * c.cols;
    if (n == 1) {
      out.push_back(c.id);
      continue;
    }
    for (uint32_t k = 0; k < n; ++k) {
      if (c.rows > 1 && c.cols > 1)
        out.push_back(c.id + "[" + std::to_string(k / c.cols) + "][" + std::to_string(k % c.cols) +
                      "]");
      else
        out.push_back(c.id + "[" + std::to_string(k) + "]");
    }
  }
  return out;
}

size_t Spec::Fitted() const {
  return static_cast<size_t>(std::count(held_out.begin(), held_out.end(), false));
}

Timing TimingOf(const std::vector<Parameter>& parameters, const std::vector<double>& values) {
  Timing t;
  for (size_t i = 0; i < parameters.size(); ++i) {
    if (parameters[i].kind == ParameterKind::kTimeShift) t.shift_s += values[i];
    if (parameters[i].kind == ParameterKind::kSensorDelay)
      t.sensor_delay_s[parameters[i].target] += values[i];
  }
  return t;
}

std::vector<ChannelCost> CompareRecording(const experiment::Recording& sim, const Measured& m,
                                          const std::map<std::string, ChannelWeight>& weights,
                                          const Timing& timing, std::vector<double>* residuals) {
  const std::vector<std::string> columns = ColumnNames(sim.channels);
  std::vector<ChannelCost> out;
  for (size_t c = 0; c < columns.size(); ++c) {
    const auto mc = std::find(m.columns.begin(), m.columns.end(), columns[c]);
    if (mc == m.columns.end()) continue;
    const size_t k = static_cast<size_t>(mc - m.columns.begin());
    ChannelWeight w;
    if (const auto it = weights.find(columns[c]); it != weights.end()) w = it->second;
    ChannelCost cost;
    cost.column = columns[c];
    cost.unit = m.units[k];
    cost.weight = w.weight;
    double offset = timing.shift_s;
    if (const auto d = timing.sensor_delay_s.find(columns[c]); d != timing.sensor_delay_s.end())
      offset += d->second;
    const auto [lo, hi] = std::minmax_element(m.values[k].begin(), m.values[k].end());
    cost.range = std::max(*hi - *lo, 1e-12);
    double sum = 0;
    for (size_t i = 0; i < sim.times.size(); ++i) {
      const double t = sim.times[i];
      if (t < m.times.front() || t > m.times.back() || t < w.from_s || t > w.to_s) continue;
      // the real sensor read the state at t at t + offset; which samples count does not
      // depend on the offset (a fixed residual vector), At holds the ends
      const double d = sim.data[i * sim.values_per_sample + c] - m.At(k, t + offset);
      sum += d * d;
      if (residuals) residuals->push_back(d);
      ++cost.samples;
    }
    // not finite: the caller treats the candidate as faulted (see Cost)
    cost.rms = cost.samples ? std::sqrt(sum / static_cast<double>(cost.samples)) : 0;
    out.push_back(cost);
  }
  return out;
}

double Cost(const std::vector<ChannelCost>& channels) {
  double sum = 0, weights = 0;
  for (const auto& c : channels) {
    if (c.samples == 0) continue;
    sum += c.weight * (c.rms / c.range) * (c.rms / c.range);
    weights += c.weight;
  }
  if (!(weights > 0))
    throw SpecError(
        "no recorded channel has measurements to compare with (the measured "
        "columns must be named like the recorded ids)");
  return std::sqrt(sum / weights);
}

experiment::Experiment WithParameters(const experiment::Experiment& e,
                                      const std::vector<Parameter>& parameters,
                                      const std::vector<double>& values) {
  experiment::Experiment out = e;
  bool delayed = false;
  for (size_t i = 0; i < parameters.size(); ++i) {
    if (parameters[i].kind == ParameterKind::kScene)
      out.overrides.push_back({parameters[i].id, {values[i]}});
    if (parameters[i].kind != ParameterKind::kCommandDelay) continue;
    for (auto& c : out.schedule)
      if (c.actuator == parameters[i].target) c.time_s += values[i];
    delayed = true;
  }
  if (delayed)
    std::stable_sort(out.schedule.begin(), out.schedule.end(),
                     [](const auto& a, const auto& b) { return a.time_s < b.time_s; });
  return out;
}

}  // namespace caliper::calibration
