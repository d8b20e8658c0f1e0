// caliper-calibrate: fits a model's parameters to a real robot's recordings with pagmo's
// evolution strategies, evaluating candidates on every Model of a session or cluster.
#include <signal.h>
#include <unistd.h>

#include <boost/archive/text_iarchive.hpp>
#include <boost/archive/text_oarchive.hpp>
#include <boost/serialization/vector.hpp>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "caliper/calibration/analysis.h"
#include "caliper/calibration/calibration.h"
#include "caliper/calibration/evaluator.h"
#include "caliper/calibration/refine.h"
#include "caliper/client/experiments.h"
#include "caliper/client/model_pool.h"
#include "caliper/client/scene_transfer.h"
#include "caliper/client/session.h"
#include "caliper/core/arguments.h"
#include "caliper/core/system.h"
#include "caliper/logging/log.h"
#include "caliper/rtc/client_orb.h"
#include "caliper/rtc/naming.h"
#include "optimiser.h"
#include "report.h"

namespace fs = std::filesystem;
using namespace caliper;
using namespace caliper::calibration;
namespace M = ::Caliper::Simulation;

namespace {

const char kUsage[] =
    "Usage: caliper-calibrate FILE [--out DIR] [--dry-run] [--resume] [--generations N]\n"
    "                         [--iterations N] [--models GLOB] [--islands N] [--run-timeout S]\n"
    "                         [--nameservice corbaname::HOST:PORT]\n"
    "Fits the parameters named in FILE (a calibration file: docs/calibration.md) so that the\n"
    "simulated experiments match the measured CSVs, and says how sure the fit is. Two stages:\n"
    "a global search (pagmo's CMA-ES or xNES, one island per Model of the session, restarts with\n"
    "larger populations when it stalls), then a Levenberg-Marquardt refinement (Ceres) whose\n"
    "finite-difference Jacobian is one batch of runs over every Model. At the optimum: 95 %\n"
    "intervals, correlations, the noise per channel and warnings on what the experiments cannot\n"
    "determine. Models: every one whose name matches --models (default model*).\n"
    "  --out DIR         results (default FILE's name + -calibration): result.json,\n"
    "                    parameters.csv, correlation.csv, noise.csv, cost.csv,\n"
    "                    channels-EXPERIMENT.csv, report.html, report.png, tuned.dae, checkpoints\n"
    "  --dry-run         evaluate the model as it is once: cost and plots, no search\n"
    "  --resume          go on from DIR's checkpoint (the last generation or refinement step)\n"
    "  --generations N   instead of the file's optimiser.generations (0: no global search)\n"
    "  --iterations N    instead of the file's refinement.iterations (0: no refinement)\n"
    "  --islands N       islands (parallel populations); default one per Model\n"
    "  --run-timeout S   the longest one run may take (300 s)\n"
    "Progress on stderr per generation and per refinement step; the end says whether it\n"
    "converged and why. Ctrl-C stops after the current generation or step and keeps the best so\n"
    "far (and a checkpoint for --resume). Exit 0 done (converged or not: see the output), 1\n"
    "error, 2 bad usage, 130 Ctrl-C.\n";

std::string Format(double v, int digits = 4) {
  std::ostringstream s;
  s << std::setprecision(digits) << v;
  return s.str();
}

std::string Duration(double s) {
  if (s < 90) return Format(std::round(s), 3) + " s";
  if (s < 5400) return Format(std::round(s / 60), 3) + " min";
  return Format(s / 3600, 2) + " h";
}

struct Options {
  std::string file, out, models = "model*", nameservice;
  bool dry_run = false, resume = false;
  unsigned generations = 0, iterations = 0, islands = 0;
  bool generations_set = false, iterations_set = false;
  double run_timeout_s = 300;
};

unsigned Whole(const std::string& flag, const std::string& text, long least = 1) {
  char* end = nullptr;
  const long v = std::strtol(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0' || v < least || v > 1000000)
    throw core::UsageError(flag + " takes a whole number from " + std::to_string(least) +
                           " to 1000000");
  return static_cast<unsigned>(v);
}

Options Parse(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  if (core::TakeFlag(args, "-h") || core::TakeFlag(args, "--help")) {
    std::cout << kUsage;
    std::exit(0);
  }
  Options o;
  std::string value;
  core::TakeOption(args, "--out", &o.out);
  core::TakeOption(args, "--models", &o.models);
  core::TakeOption(args, "--nameservice", &o.nameservice);
  o.dry_run = core::TakeFlag(args, "--dry-run");
  o.resume = core::TakeFlag(args, "--resume");
  if (core::TakeOption(args, "--generations", &value)) {
    o.generations = Whole("--generations", value, 0);
    o.generations_set = true;
  }
  if (core::TakeOption(args, "--iterations", &value)) {
    o.iterations = Whole("--iterations", value, 0);
    o.iterations_set = true;
  }
  if (core::TakeOption(args, "--islands", &value)) o.islands = Whole("--islands", value);
  if (core::TakeOption(args, "--run-timeout", &value))
    o.run_timeout_s = Whole("--run-timeout", value);
  core::RejectOptions(args);
  if (args.size() != 1) throw core::UsageError("expected one calibration FILE");
  o.file = args[0];
  if (o.out.empty()) o.out = fs::path(o.file).stem().string() + "-calibration";
  return o;
}

// The parameters' values in the scene as it is (asked of a Model), and their units into `spec`.
std::vector<double> SceneValues(Spec& spec, client::ModelPool& pool) {
  // a URDF is imported here and sent converted: its import warnings are said here, once
  std::vector<std::string> warnings;
  const std::string bytes = client::ReadScene(spec.experiments.front().scene, &warnings);
  for (const auto& w : warnings) std::cerr << "caliper-calibrate: warning: " << w << "\n";
  std::vector<double> values;
  pool.WithModel([&](M::Model_ptr model) {
    try {
      model->load_scene_data(client::SceneFileName(spec.experiments.front().scene).c_str(),
                             client::ToOctets(bytes));
      // the scene's parameters from the Model; the timing ones start at 0 (inside the bounds)
      std::vector<size_t> scene;
      for (size_t i = 0; i < spec.parameters.size(); ++i)
        if (spec.parameters[i].kind == ParameterKind::kScene) scene.push_back(i);
      ::Caliper::Scene::StringSeq ids;
      ids.length(static_cast<CORBA::ULong>(scene.size()));
      for (CORBA::ULong k = 0; k < ids.length(); ++k) ids[k] = spec.parameters[scene[k]].id.c_str();
      ::Caliper::Daq::ValueSeq_var got = model->get(ids);
      values.clear();
      for (const auto& p : spec.parameters) values.push_back(std::clamp(0.0, p.lower, p.upper));
      for (CORBA::ULong k = 0; k < got->length(); ++k) {
        if (got[k].data.length() != 1)
          throw client::SetupError(spec.parameters[scene[k]].id + " is not a scalar parameter");
        values[scene[k]] = got[k].data[0];
        ::Caliper::Daq::ChannelInfoSeq_var info =
            model->channels(spec.parameters[scene[k]].id.c_str());
        if (info->length() == 1) spec.parameters[scene[k]].unit = info[0].unit.in();
      }
    } catch (const M::LoadFailed& e) {
      throw client::SetupError(e.reason.in());
    } catch (const M::NotAvailable& e) {
      throw client::NotAvailableError(e.reason.in());  // another Model, or this one once it is idle
    } catch (const ::Caliper::Daq::UnknownId& e) {
      throw client::SetupError(std::string(e.reason.in()) + " (a parameter to fit)");
    } catch (const ::Caliper::Daq::NotAvailable& e) {
      throw client::SetupError(e.reason.in());
    } catch (const ::Caliper::Daq::LimitExceeded& e) {
      throw client::SetupError(e.reason.in());
    }
  });
  return values;
}

struct ChannelPlots {
  std::vector<Plot> fitted, held_out;
};

// channels-EXPERIMENT.csv: the measured, initial and fitted values of every compared column at
// the simulated sample times; and its plots (fitted and held-out experiments apart).
ChannelPlots WriteChannels(const Options& o, const Spec& spec, const Evaluation& before,
                           const Evaluation* after) {
  ChannelPlots plots;
  for (size_t r = 0; r < before.recordings.size(); ++r) {
    const size_t i = before.recorded[r];
    const auto& rec = before.recordings[r];
    const experiment::Recording* fit = nullptr;
    if (after)
      for (size_t k = 0; k < after->recorded.size(); ++k)
        if (after->recorded[k] == i) fit = &after->recordings[k];
    const Measured& m = spec.measured[i];
    const auto columns = ColumnNames(rec.channels);
    // (recorded column, measured column) of every channel that has measurements
    std::vector<std::pair<size_t, size_t>> shown;
    for (size_t c = 0; c < columns.size(); ++c) {
      const auto k = std::find(m.columns.begin(), m.columns.end(), columns[c]);
      if (k != m.columns.end()) shown.emplace_back(c, static_cast<size_t>(k - m.columns.begin()));
    }
    core::WriteFileReplacing(
        o.out + "/channels-" + spec.experiments[i].name + ".csv", [&](std::ostream& out) {
          out << "time [s]";
          for (const auto& [c, k] : shown) {
            const std::string unit = " [" + (m.units[k].empty() ? "-" : m.units[k]) + "]";
            out << "," << columns[c] << " measured" << unit << "," << columns[c] << " initial"
                << unit;
            if (fit) out << "," << columns[c] << " fitted" << unit;
          }
          out << "\n" << std::setprecision(10);
          for (size_t s = 0; s < rec.times.size(); ++s) {
            const double t = rec.times[s];
            if (t < m.times.front() || t > m.times.back()) continue;
            out << t;
            for (const auto& [c, k] : shown) {
              out << "," << m.At(k, t) << "," << rec.data[s * rec.values_per_sample + c];
              if (fit) out << "," << fit->data[s * rec.values_per_sample + c];
            }
            out << "\n";
          }
        });
    for (const auto& [c, k] : shown) {
      Plot p;
      p.title = spec.experiments[i].name + (spec.held_out[i] ? " (held out): " : ": ") + columns[c];
      p.x_title = "time [s]";
      p.y_title = m.units[k].empty() ? "[-]" : "[" + m.units[k] + "]";
      p.curves.push_back({"measured", m.times, m.values[k]});
      Curve initial{"initial", {}, {}}, fitted{"fitted", {}, {}};
      for (size_t s = 0; s < rec.times.size(); ++s) {
        initial.x.push_back(rec.times[s]);
        initial.y.push_back(rec.data[s * rec.values_per_sample + c]);
        if (fit) {
          fitted.x.push_back(rec.times[s]);
          fitted.y.push_back(fit->data[s * rec.values_per_sample + c]);
        }
      }
      p.curves.push_back(initial);
      if (fit) p.curves.push_back(fitted);
      (spec.held_out[i] ? plots.held_out : plots.fitted).push_back(p);
    }
  }
  return plots;
}

// --dry-run: the initial cost per channel and its plots, no search.
int DryRun(const Options& o, const Spec& spec, const Evaluation& before) {
  auto channels = WriteChannels(o, spec, before, nullptr);
  auto plots = channels.fitted;
  plots.insert(plots.end(), channels.held_out.begin(), channels.held_out.end());
  const std::string png = o.out + "/report.png";
  const std::string why = WritePng(png, plots);
  std::cout << "initial cost " << Format(before.cost, 6) << " (dry run: no search)\n";
  for (const auto& c : before.channels)
    std::cout << "  " << std::left << std::setw(44) << c.column << " rms " << Format(c.rms)
              << " of a range of " << Format(c.range) << "\n";
  if (before.held_out_cost >= 0)
    std::cout << "held-out cost " << Format(before.held_out_cost, 6) << "\n";
  std::cout << (why.empty() ? "plots: " + png : "no plots: " + why) << "\nchannels: " << o.out
            << "/channels-*.csv\n";
  return 0;
}

// The tuned scene as a .dae (a run with the fitted values leaves it loaded in a Model, which
// exports it); "" when written, else why not.
std::string ExportTuned(client::ModelPool& pool, const Spec& spec,
                        const std::vector<double>& fitted, const std::string& tuned) {
  std::string export_error;
  try {
    pool.WithModel([&](M::Model_ptr model) {
      const auto e = WithParameters(spec.experiments.front(), spec.parameters, fitted);
      M::Recording_var ignored = model->run_experiment(
          client::ToIdl(e, client::ReadScene(e.scene)));  // leaves the tuned scene loaded
      M::Octets_var data = model->export_scene();
      core::WriteFileReplacing(tuned, [&](std::ostream& out) {
        out.write(reinterpret_cast<const char*>(data->get_buffer()), data->length());
      });
    });
  } catch (const std::exception& e) {
    export_error = e.what();
  } catch (const CORBA::Exception& e) {
    export_error = rtc::Describe(e);
  }

  return export_error;
}

// The refinement's checkpoint: the stage reached and its point (Boost text archive).
struct RefineCheckpoint {
  std::vector<double> unit;
  unsigned iterations = 0;
  uint64_t evaluations = 0;
  double cost = 0;
};

void SaveRefine(const std::string& path, const RefineCheckpoint& c) {
  core::WriteFileReplacing(path, [&](std::ostream& out) {
    boost::archive::text_oarchive archive(out);
    archive << c.unit << c.iterations << c.evaluations << c.cost;
  });
}

std::optional<RefineCheckpoint> LoadRefine(const std::string& path, size_t dimension) {
  std::ifstream in(path);
  if (!in) return std::nullopt;
  RefineCheckpoint c;
  try {
    boost::archive::text_iarchive archive(in);
    archive >> c.unit >> c.iterations >> c.evaluations >> c.cost;
  } catch (const boost::archive::archive_exception& e) {
    throw std::runtime_error(path + ": not a refinement checkpoint of this program (" + e.what() +
                             ")");
  }
  if (c.unit.size() != dimension)
    throw std::runtime_error(path + ": " + std::to_string(c.unit.size()) +
                             " parameters, the calibration file has " + std::to_string(dimension));
  return c;
}

// What the run found, for the files and the printout.
struct Outcome {
  std::vector<double> initial, fitted;
  Evaluation before, after;
  std::string global_reason, refine_reason, uncertainty_error;
  bool converged = false, interrupted = false;
  double global_cost = 0, noise_floor = 0, wall_s = 0;
  unsigned generations = 0, restarts = 0, refine_iterations = 0;
  uint64_t evaluations = 0, refine_evaluations = 0;
  std::vector<std::pair<uint64_t, double>> refine_history;  // (evaluations, cost)
  std::optional<Uncertainty> uncertainty;
};

// result.json: everything a script or the Python package reads (numbers as numbers).
void WriteResult(const Options& o, const Spec& spec, const Outcome& r, size_t models) {
  using nlohmann::json;
  const auto number = [](double v) -> json { return std::isfinite(v) ? json(v) : json(nullptr); };
  json j;
  j["file"] = fs::absolute(o.file).string();
  j["models"] = models;
  j["converged"] = r.converged;
  j["interrupted"] = r.interrupted;
  j["reason"] = r.refine_reason.empty() ? r.global_reason : r.refine_reason;
  j["global_search"] = {{"reason", r.global_reason},
                        {"generations", r.generations},
                        {"restarts", r.restarts},
                        {"cost", number(r.global_cost)}};
  j["refinement"] = {{"reason", r.refine_reason},
                     {"iterations", r.refine_iterations},
                     {"evaluations", r.refine_evaluations}};
  j["evaluations"] = r.evaluations;
  j["wall_s"] = r.wall_s;
  j["cost"] = {{"initial", number(r.before.cost)},
               {"fitted", number(r.after.cost)},
               {"noise_floor", number(r.noise_floor)}};
  json held = json::array();
  for (size_t i = 0; i < spec.experiments.size(); ++i)
    if (spec.held_out[i]) held.push_back(spec.experiments[i].name);
  j["held_out"] = {
      {"experiments", held},
      {"initial", r.before.held_out_cost < 0 ? json(nullptr) : number(r.before.held_out_cost)},
      {"fitted", r.after.held_out_cost < 0 ? json(nullptr) : number(r.after.held_out_cost)}};
  json parameters = json::array();
  for (size_t i = 0; i < spec.parameters.size(); ++i) {
    const Parameter& p = spec.parameters[i];
    json e = {{"id", p.id},
              {"unit", p.Unit()},
              {"initial", r.initial[i]},
              {"fitted", r.fitted[i]},
              {"lower", p.lower},
              {"upper", p.upper},
              {"scale", p.log_scale ? "log" : "linear"}};
    if (r.uncertainty) {
      const auto& u = r.uncertainty->parameters[i];
      e["sigma"] = number(u.sigma);
      e["lower95"] = number(u.lower95);
      e["upper95"] = number(u.upper95);
      e["determined"] = u.determined;
      e["most_sensitive_channel"] = u.most_sensitive_channel;
    }
    parameters.push_back(e);
  }
  j["parameters"] = parameters;
  json correlation = json::array(), noise = json::array(), warnings = json::array();
  if (r.uncertainty) {
    const auto& c = r.uncertainty->correlation;
    for (Eigen::Index i = 0; i < c.rows(); ++i) {
      json row = json::array();
      for (Eigen::Index k = 0; k < c.cols(); ++k) row.push_back(number(c(i, k)));
      correlation.push_back(row);
    }
    for (const auto& n : r.uncertainty->noise)
      noise.push_back({{"experiment", n.experiment},
                       {"column", n.column},
                       {"unit", n.unit},
                       {"sigma", number(n.sigma)},
                       {"samples", n.samples}});
    for (const auto& w : r.uncertainty->warnings) warnings.push_back(w);
  }
  if (!r.uncertainty_error.empty()) warnings.push_back("no uncertainty: " + r.uncertainty_error);
  j["correlation"] = correlation;
  j["noise"] = noise;
  j["warnings"] = warnings;
  json history = json::array();
  for (const auto& [n, c] : r.refine_history) history.push_back({n, c});
  j["refinement"]["history"] = history;
  core::WriteFileReplacing(o.out + "/result.json",
                           [&](std::ostream& out) { out << j.dump(2) << "\n"; });
}

// uncertainty.csv, correlation.csv and noise.csv.
void WriteUncertainty(const Options& o, const Spec& spec, const Uncertainty& u) {
  core::WriteFileReplacing(o.out + "/correlation.csv", [&](std::ostream& out) {
    out << "id";
    for (const auto& p : spec.parameters) out << "," << p.id;
    out << "\n" << std::setprecision(6);
    for (Eigen::Index i = 0; i < u.correlation.rows(); ++i) {
      out << spec.parameters[static_cast<size_t>(i)].id;
      for (Eigen::Index k = 0; k < u.correlation.cols(); ++k) out << "," << u.correlation(i, k);
      out << "\n";
    }
  });
  core::WriteFileReplacing(o.out + "/noise.csv", [&](std::ostream& out) {
    out << "experiment,column,unit,sigma,samples\n" << std::setprecision(6);
    for (const auto& n : u.noise)
      out << n.experiment << "," << n.column << "," << n.unit << "," << n.sigma << "," << n.samples
          << "\n";
  });
}

std::string Interval(const ParameterUncertainty& u) {
  if (!u.determined) return "not determined";
  const std::string interval = "[" + Format(u.lower95, 6) + ", " + Format(u.upper95, 6) + "]";
  const double half = 1.96 * u.sigma;
  // around 0 (a delay at its bound) a percentage of the value says nothing
  if (u.value == 0 || std::abs(u.value) * 1e3 < half)
    return interval + " (+-" + Format(half, 2) + ")";
  return interval + " (+-" + Format(100 * half / std::abs(u.value), 2) + " %)";
}

// parameters.csv, cost.csv and the cost curve's plot (global search, then the refinement from
// where it ended); without a global search (`searched` false) the refinement starts at the
// start's cost, the one point before it.
std::vector<Plot> WriteParameters(const Options& o, const Spec& spec, const Outcome& r,
                                  const Progress& p, bool searched) {
  const char* first_stage = searched ? "global" : "start";
  core::WriteFileReplacing(o.out + "/parameters.csv", [&](std::ostream& out) {
    out << "id,unit,initial,fitted,sigma,lower95,upper95,lower,upper,scale,change [%]\n"
        << std::setprecision(10);
    for (size_t i = 0; i < r.fitted.size(); ++i) {
      const Parameter& q = spec.parameters[i];
      out << q.id << "," << q.Unit() << "," << r.initial[i] << "," << r.fitted[i] << ",";
      if (r.uncertainty) {
        const auto& u = r.uncertainty->parameters[i];
        out << u.sigma << "," << u.lower95 << "," << u.upper95;
      } else {
        out << ",,";
      }
      out << "," << q.lower << "," << q.upper << "," << (q.log_scale ? "log" : "linear") << ","
          << (r.initial[i] != 0 ? 100 * (r.fitted[i] - r.initial[i]) / r.initial[i] : 0.0) << "\n";
    }
  });
  core::WriteFileReplacing(o.out + "/cost.csv", [&](std::ostream& out) {
    out << "evaluations,best cost [-],stage\n" << std::setprecision(10);
    for (const auto& [n, c] : p.history) out << n << "," << c << "," << first_stage << "\n";
    for (const auto& [n, c] : r.refine_history)
      out << p.history.back().first + n << "," << c << ",refinement\n";
  });
  std::vector<Plot> plots;
  Plot cost{"best cost", "evaluations", "cost [-] (normalised RMS)", {}, true};
  Curve global{searched ? "global search" : "start", {}, {}}, refine{"refinement (LM)", {}, {}};
  for (const auto& [n, c] : p.history) {
    global.x.push_back(static_cast<double>(n));
    global.y.push_back(c);
  }
  if (!r.refine_history.empty()) {
    refine.x.push_back(global.x.back());
    refine.y.push_back(global.y.back());
  }
  for (const auto& [n, c] : r.refine_history) {
    refine.x.push_back(static_cast<double>(p.history.back().first + n));
    refine.y.push_back(c);
  }
  if (searched || refine.x.empty()) cost.curves.push_back(global);
  if (!refine.x.empty()) cost.curves.push_back(refine);
  plots.push_back(cost);
  return plots;
}

HtmlReport MakeReport(const Options& o, const Spec& spec, const Outcome& r,
                      const std::vector<Plot>& cost, const ChannelPlots& channels, bool searched) {
  HtmlReport h;
  h.title = fs::path(o.file).filename().string();
  const auto add = [&](const std::string& k, const std::string& v) {
    h.summary.emplace_back(k, v);
  };
  add("calibration file", fs::absolute(o.file).string());
  const std::string reason = r.refine_reason.empty() ? r.global_reason : r.refine_reason;
  add("result", r.converged ? reason : "NOT CONVERGED: " + reason);
  add("global search", searched ? r.global_reason + " (" + std::to_string(r.generations) +
                                      " generations, " + std::to_string(r.restarts) + " restarts)"
                                : r.global_reason);
  if (!r.refine_reason.empty())
    add("refinement (Levenberg-Marquardt)",
        r.refine_reason + " (" + std::to_string(r.refine_iterations) + " iterations)");
  add("cost [-]", Format(r.before.cost, 6) + " initial, " +
                      (searched ? Format(r.global_cost, 6) + " after the global search, " : "") +
                      Format(r.after.cost, 6) + " fitted");
  add("noise floor of the measurements [-]", Format(r.noise_floor, 3));
  if (r.after.held_out_cost >= 0) {
    std::string names;
    for (size_t i = 0; i < spec.experiments.size(); ++i)
      if (spec.held_out[i]) names += (names.empty() ? "" : ", ") + spec.experiments[i].name;
    add("held-out cost [-] (" + names + ")", Format(r.before.held_out_cost, 6) + " initial, " +
                                                 Format(r.after.held_out_cost, 6) + " fitted");
  }
  add("evaluations", std::to_string(r.evaluations) + " in " + Duration(r.wall_s));
  h.warnings = r.uncertainty ? r.uncertainty->warnings : std::vector<std::string>{};
  if (!r.uncertainty_error.empty()) h.warnings.push_back("no uncertainty: " + r.uncertainty_error);
  if (!r.converged)
    h.warnings.insert(
        h.warnings.begin(),
        "not converged: " + (r.refine_reason.empty() ? r.global_reason : r.refine_reason));
  for (size_t i = 0; i < spec.parameters.size(); ++i) {
    ReportParameter p;
    p.id = spec.parameters[i].id;
    p.unit = spec.parameters[i].Unit();
    p.initial = r.initial[i];
    p.fitted = r.fitted[i];
    p.lower = spec.parameters[i].lower;
    p.upper = spec.parameters[i].upper;
    if (r.uncertainty) {
      const auto& u = r.uncertainty->parameters[i];
      p.sigma = u.sigma;
      p.lower95 = u.lower95;
      p.upper95 = u.upper95;
      p.determined = u.determined;
    } else {
      p.determined = false;
    }
    h.parameters.push_back(p);
  }
  if (r.uncertainty) {
    const auto& c = r.uncertainty->correlation;
    for (Eigen::Index i = 0; i < c.rows(); ++i) {
      h.correlation.emplace_back();
      for (Eigen::Index k = 0; k < c.cols(); ++k) h.correlation.back().push_back(c(i, k));
    }
    for (const auto& n : r.uncertainty->noise)
      h.noise.push_back({n.experiment, n.column, n.unit, n.sigma, n.samples});
  }
  h.cost = cost;
  h.fitted = channels.fitted;
  h.held_out = channels.held_out;
  return h;
}

// The global search until a stopping rule or the budget says so, with IPOP restarts.
void SearchStage(const Spec& spec, Search& search, const std::string& checkpoint,
                 client::ModelPool& pool, Outcome& r, std::vector<double>& best_unit) {
  std::cerr << search.islands() << " island(s) of " << search.progress().population << " ("
            << spec.optimiser.algorithm << ")\n";
  const uint64_t evaluations_at_start = search.progress().evaluations;
  const unsigned first_generation = search.progress().generation;
  const auto search_begin = std::chrono::steady_clock::now();
  for (;;) {
    const Progress& p = search.progress();
    StopCheck check = CheckStop(p.CostsSinceRestart(), p.spread, spec.optimiser.generations,
                                spec.optimiser, p.generation);
    if (check.stop) {
      // IPOP: stalled far above the noise: start again with larger populations
      const bool far = p.best_cost > 2 * r.noise_floor && p.best_cost > spec.optimiser.target_cost;
      if (check.stalled && far && p.restarts < spec.optimiser.restarts &&
          p.generation < spec.optimiser.generations) {
        std::cerr << "restart " << p.restarts + 1 << "/" << spec.optimiser.restarts << ": "
                  << check.reason.substr(check.reason.find(':') + 2) << " at cost "
                  << Format(p.best_cost) << ", "
                  << Format(p.best_cost / std::max(r.noise_floor, 1e-300), 3)
                  << "x the noise floor; populations of " << 2 * p.population << "\n";
        search.Restart();
        continue;
      }
      r.global_reason = check.reason;
      r.converged = check.converged;
      break;
    }
    r.interrupted = !search.Generation(core::InterruptPending);
    search.Save(checkpoint);
    pool.Refresh();  // Models that appeared or came back join the next generation
    const Progress& q = search.progress();
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - search_begin).count();
    const double rate = static_cast<double>(q.evaluations - evaluations_at_start) / elapsed;
    const double per_generation = elapsed / (q.generation - first_generation);
    std::cerr << "gen " << q.generation << "/" << spec.optimiser.generations << "  evals "
              << q.evaluations << "  " << Format(rate, 3) << " evals/s  best "
              << Format(q.best_cost) << " (initial " << Format(r.before.cost) << ")  step "
              << Format(q.spread, 3) << "  ETA "
              << Duration(per_generation * (spec.optimiser.generations - q.generation)) << "\n";
    if (r.interrupted) {
      std::cerr << "interrupted: keeping the best so far; --resume goes on from generation "
                << q.generation << "\n";
      r.global_reason = "stopped: interrupted at generation " + std::to_string(q.generation);
      break;
    }
  }
  best_unit = search.progress().best_unit;
  r.global_cost = search.progress().best_cost;
  r.generations = search.progress().generation;
  r.restarts = search.progress().restarts;
  std::cerr << "global search: " << r.global_reason << " (cost " << Format(r.global_cost) << ", "
            << r.generations << " generations, " << r.restarts << " restart(s))\n";
}

// The Levenberg-Marquardt refinement from `best_unit` (the global search's best or a
// checkpoint's point), which it moves to the refined point.
void RefineStage(const Spec& spec, const BatchResiduals& batch,
                 const std::optional<RefineCheckpoint>& resumed, const std::vector<double>& steps,
                 const std::string& refine_checkpoint, size_t models, bool have_search, Outcome& r,
                 std::vector<double>& best_unit) {
  if (!r.interrupted && spec.refinement.iterations > 0) {
    const unsigned done_before = resumed ? resumed->iterations : 0;
    const uint64_t evaluations_before = resumed ? resumed->evaluations : 0;
    RefineOptions ro;
    ro.max_iterations =
        spec.refinement.iterations - std::min(spec.refinement.iterations, done_before);
    ro.central = spec.refinement.central;
    ro.steps = steps;
    ro.interrupted = core::InterruptPending;
    const auto refine_begin = std::chrono::steady_clock::now();
    ro.on_iteration = [&](const RefineProgress& p) {
      const double elapsed =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - refine_begin).count();
      // the best so far (a rejected step's trial cost is not progress)
      const double best =
          r.refine_history.empty() ? p.cost : std::min(p.cost, r.refine_history.back().second);
      r.refine_history.emplace_back(evaluations_before + p.evaluations, best);
      std::cerr << "refine " << done_before + p.iteration << "/" << spec.refinement.iterations
                << "  evals " << evaluations_before + p.evaluations << "  "
                << Format(p.evaluations / std::max(elapsed, 1e-9), 3) << " evals/s  cost "
                << Format(p.cost) << " (global " << Format(r.global_cost) << ")\n";
      SaveRefine(refine_checkpoint,
                 {p.unit, done_before + p.iteration, evaluations_before + p.evaluations, p.cost});
    };
    const size_t residuals = r.before.residuals.size();
    std::cerr << "refinement: Levenberg-Marquardt on " << residuals << " residuals, "
              << (ro.central ? 2 : 1) * spec.parameters.size() << " runs per Jacobian over "
              << models << " Model(s)\n";
    const RefineResult refined = Refine(batch, best_unit, residuals, ro);
    const double refine_wall =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - refine_begin).count();
    r.refine_reason = refined.reason;
    r.refine_iterations = done_before + refined.iterations;
    r.refine_evaluations = evaluations_before + refined.evaluations;
    r.interrupted = refined.interrupted;
    r.converged = refined.converged;
    if (refined.cost <= r.global_cost || !have_search) best_unit = refined.unit;
    std::cerr << "refinement: " << refined.reason << " (cost " << Format(refined.start_cost)
              << " -> " << Format(refined.cost) << ", " << refined.iterations << " iterations, "
              << refined.evaluations << " evaluations in " << Format(refine_wall, 3) << " s)\n";
    if (refined.interrupted)
      std::cerr << "interrupted: keeping the best so far; --resume goes on in the refinement\n";
  }
}

// At the optimum: one more Jacobian, and how sure the fit is (or why that is not known).
void UncertaintyStage(const Options& o, const Spec& spec, Evaluator& evaluator,
                      const std::vector<double>& best_unit, const std::vector<double>& steps,
                      size_t pool_size, Outcome& r) {
  if (r.after.faulted) {
    r.uncertainty_error = "the fitted model faults: " + r.after.fault;
  } else if (!r.interrupted) {
    try {
      // the Jacobian of the raw residuals (simulated - measured, each in its channel's unit)
      const BatchResiduals raw = [&](const std::vector<std::vector<double>>& units) {
        return evaluator.Residuals(units, false);
      };
      const auto jacobian_begin = std::chrono::steady_clock::now();
      const Eigen::MatrixXd j =
          Jacobian(raw, best_unit, r.after.residuals, steps, spec.refinement.central);
      const double jacobian_s =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - jacobian_begin).count();
      std::cerr << "Jacobian at the optimum: "
                << (spec.refinement.central ? 2 : 1) * spec.parameters.size() << " runs in "
                << Format(jacobian_s, 4) << " s over " << pool_size << " Model(s)\n";
      r.uncertainty =
          Analyse(spec, j, r.after.residuals, r.after.blocks, r.fitted, spec.uncertainty);
      WriteUncertainty(o, spec, *r.uncertainty);
    } catch (const std::runtime_error& e) {
      r.uncertainty_error = e.what();
    }
  } else {
    r.uncertainty_error = "interrupted before the uncertainty was computed";
  }
}

// The end on stdout: the costs, the verdict, the parameters with intervals, noise, warnings.
void PrintSummary(const Options& o, const Spec& spec, const Outcome& r, uint64_t faults,
                  const std::string& tuned, const std::string& export_error, const std::string& png,
                  const std::string& why, const std::string& html_why) {
  std::cout << "cost " << Format(r.before.cost, 6) << " -> " << Format(r.after.cost, 6) << " ("
            << (r.after.cost > 0 ? Format(r.before.cost / r.after.cost, 3) + "x lower"
                                 : std::string("an exact fit"))
            << ") after " << r.evaluations << " evaluations in " << Duration(r.wall_s) << " ("
            << r.generations << " generations, " << r.refine_iterations
            << " refinement iterations; " << faults << " faulted)\n";
  std::cout << (r.converged ? "" : "NOT CONVERGED: ")
            << (r.refine_reason.empty() ? r.global_reason : r.refine_reason) << "\n";
  if (!r.refine_reason.empty()) std::cout << "global search: " << r.global_reason << "\n";
  if (r.after.held_out_cost >= 0)
    std::cout << "held-out cost " << Format(r.before.held_out_cost, 6) << " -> "
              << Format(r.after.held_out_cost, 6) << " (fitted " << Format(r.after.cost, 6) << ")"
              << (r.after.held_out_cost > 2 * r.after.cost ? ": worse than the fitted "
                                                             "experiments, over-fitted?"
                                                           : "")
              << "\n";
  std::cout << "  " << std::left << std::setw(44) << "parameter" << std::right << std::setw(12)
            << "initial" << std::setw(14) << "fitted"
            << "   95 % interval\n";
  for (size_t i = 0; i < r.fitted.size(); ++i) {
    const std::string unit =
        spec.parameters[i].Unit().empty() ? "" : " " + spec.parameters[i].Unit();
    std::cout << "  " << std::left << std::setw(44) << spec.parameters[i].id << std::right
              << std::setw(12) << Format(r.initial[i], 6) << " -> " << std::setw(11)
              << Format(r.fitted[i], 6) << "   "
              << (r.uncertainty ? Interval(r.uncertainty->parameters[i]) : "-") << unit << "\n";
  }
  if (r.uncertainty) {
    std::cout << "noise per channel (from the residuals):\n";
    for (const auto& n : r.uncertainty->noise)
      std::cout << "  " << std::left << std::setw(56) << (n.experiment + ": " + n.column)
                << std::right << " " << Format(n.sigma, 3) << (n.unit.empty() ? "" : " " + n.unit)
                << "\n";
    for (const auto& w : r.uncertainty->warnings) std::cout << "warning: " << w << "\n";
  } else {
    std::cout << "no uncertainty: " << r.uncertainty_error << "\n";
  }
  std::cout << "results: " << o.out << "/result.json, parameters.csv, "
            << (export_error.empty() ? "tuned scene: " + tuned
                                     : "no tuned scene (" + export_error + ")")
            << ", "
            << (html_why.empty() ? "report: " + o.out + "/report.html"
                                 : "no HTML report: " + html_why)
            << (why.empty() ? ", " + png : ", no plots: " + why) << "\n";
}

int Run(const Options& o) {
  Spec spec = LoadSpec(o.file);
  if (o.generations_set) spec.optimiser.generations = o.generations;
  if (o.iterations_set) spec.refinement.iterations = o.iterations;
  fs::create_directories(o.out);
  const std::string checkpoint = o.out + "/checkpoint.txt";
  const std::string refine_checkpoint = o.out + "/refinement.txt";
  if (o.resume && !fs::exists(checkpoint) && !fs::exists(refine_checkpoint))
    throw std::runtime_error("--resume: no checkpoint at " + checkpoint);
  if (!o.resume) fs::remove(refine_checkpoint);

  rtc::OmniThread omni;
  const std::string address = client::ResolveNamingAddress(o.nameservice);
  CORBA::ORB_var orb = rtc::ClientOrb("caliper-calibrate", 10, address);  // TLS when on a network
  client::ModelPool::Options pool_options;
  pool_options.run_timeout_s = o.run_timeout_s;
  client::ModelPool pool(
      [&] {
        CosNaming::NamingContext_var root = rtc::ResolveRoot(orb, address);
        return client::FindModels(root, o.models);
      },
      pool_options);
  pool.on_lost = [](const std::string& what) {
    std::cerr << "\nModel lost: " << what << "; its run goes to another Model\n";
  };
  {
    CosNaming::NamingContext_var root = rtc::ResolveRoot(orb, address);  // says which address
  }
  size_t models = 0;
  for (int i = 0; i < 50 && (models = pool.Refresh()) == 0; ++i) usleep(200000);
  if (models == 0)
    throw std::runtime_error("no Model matching '" + o.models + "' in " + address +
                             " (start a session, or managers: launch/caliper node)");
  Evaluator evaluator(spec, pool);
  const auto begin = std::chrono::steady_clock::now();
  const auto wall = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  };

  Outcome r;
  r.initial = SceneValues(spec, pool);
  for (size_t i = 0; i < r.initial.size(); ++i)
    if (r.initial[i] < spec.parameters[i].lower || r.initial[i] > spec.parameters[i].upper)
      std::cerr << "note: " << spec.parameters[i].id << " is " << r.initial[i]
                << " in the scene, outside [" << spec.parameters[i].lower << ", "
                << spec.parameters[i].upper << "]: the search starts at the nearest bound\n";
  std::vector<double> start_unit;
  for (size_t i = 0; i < r.initial.size(); ++i)
    start_unit.push_back(spec.parameters[i].ToUnit(r.initial[i]));
  EvaluateOptions full;
  full.keep_recordings = full.residuals = full.held_out = true;
  r.before = evaluator.Evaluate(evaluator.ValuesOf(start_unit), full);
  if (r.before.faulted) throw std::runtime_error("the initial model faults: " + r.before.fault);
  r.noise_floor = NoiseFloorCost(spec);
  std::cerr << spec.Fitted() << " experiment(s) fitted";
  if (spec.Fitted() < spec.experiments.size())
    std::cerr << ", " << spec.experiments.size() - spec.Fitted() << " held out (cost "
              << Format(r.before.held_out_cost) << ")";
  std::cerr << ", " << spec.parameters.size() << " parameters, " << models
            << " Model(s); initial cost " << Format(r.before.cost)
            << "; the measurements' noise floor is about " << Format(r.noise_floor, 3) << "\n";

  if (o.dry_run) return DryRun(o, spec, r.before);

  // the finite-difference steps: a command delay moves nothing below one time step
  std::vector<double> steps(spec.parameters.size(), spec.refinement.step);
  const auto& first = r.before.recordings.front();
  const double dt = first.times.size() > 1
                        ? (first.times[1] - first.times[0]) /
                              spec.experiments[r.before.recorded.front()].every_n_steps
                        : 0;
  for (size_t i = 0; i < steps.size(); ++i)
    if (spec.parameters[i].kind == ParameterKind::kCommandDelay) {
      steps[i] =
          std::max(steps[i], 1.01 * dt / (spec.parameters[i].upper - spec.parameters[i].lower));
      spec.parameters[i].resolution = dt;
    }

  // 1. the global search
  std::optional<RefineCheckpoint> resumed_refinement =
      o.resume ? LoadRefine(refine_checkpoint, spec.parameters.size()) : std::nullopt;
  const unsigned islands = o.islands ? o.islands : static_cast<unsigned>(models);
  std::unique_ptr<Search> search;
  if (o.resume && fs::exists(checkpoint)) {
    search = std::make_unique<Search>(spec, evaluator, checkpoint);
    std::cerr << "resuming at generation " << search->progress().generation << " ("
              << search->progress().evaluations << " evaluations, best cost "
              << Format(search->progress().best_cost) << ")\n";
  } else if (spec.optimiser.generations > 0 && !resumed_refinement) {
    search = std::make_unique<Search>(spec, evaluator, islands, start_unit, r.before.cost);
  }
  std::vector<double> best_unit = start_unit;
  r.global_cost = r.before.cost;
  // evaluations of earlier runs of this calibration (a resumed one)
  uint64_t prior = search ? search->progress().evaluations - evaluator.evaluations() : 0;
  if (resumed_refinement) prior += resumed_refinement->evaluations;
  if (resumed_refinement) {
    r.global_reason = "resumed in the refinement";
    if (search) {
      r.generations = search->progress().generation;
      r.restarts = search->progress().restarts;
    }
  } else if (!search) {
    r.global_reason = "no global search (generations 0)";
  } else {
    SearchStage(spec, *search, checkpoint, pool, r, best_unit);
  }

  // 2. the refinement: Levenberg-Marquardt from the best point
  if (resumed_refinement) {
    best_unit = resumed_refinement->unit;
    r.global_cost = resumed_refinement->cost;
    std::cerr << "resuming the refinement after iteration " << resumed_refinement->iterations
              << " (cost " << Format(resumed_refinement->cost) << ")\n";
  }
  const BatchResiduals batch = [&](const std::vector<std::vector<double>>& units) {
    return evaluator.Residuals(units, true);
  };
  RefineStage(spec, batch, resumed_refinement, steps, refine_checkpoint, models, search != nullptr,
              r, best_unit);

  // 3. at the optimum: the recordings, the Jacobian and how sure
  r.fitted = evaluator.ValuesOf(best_unit);
  r.after = evaluator.Evaluate(r.fitted, full);
  UncertaintyStage(o, spec, evaluator, best_unit, steps, pool.size(), r);
  r.evaluations = prior + evaluator.evaluations();
  r.wall_s = wall();

  // the files: parameters, cost, channels, report pages, result.json, the tuned scene last
  Progress no_search;
  no_search.history.emplace_back(1, r.before.cost);
  const Progress& p = search ? search->progress() : no_search;
  std::vector<Plot> plots = WriteParameters(o, spec, r, p, search != nullptr);
  auto channels = WriteChannels(o, spec, r.before, &r.after);
  HtmlReport html = MakeReport(o, spec, r, plots, channels, search != nullptr);
  for (auto& plot : channels.fitted) plots.push_back(plot);
  for (auto& plot : channels.held_out) plots.push_back(plot);
  const std::string png = o.out + "/report.png";
  const std::string why = WritePng(png, plots);
  const std::string html_why = WriteHtml(o.out + "/report.html", html);
  WriteResult(o, spec, r, models);
  const std::string tuned = o.out + "/tuned.dae";
  const std::string export_error = ExportTuned(pool, spec, r.fitted, tuned);

  PrintSummary(o, spec, r, evaluator.faults(), tuned, export_error, png, why, html_why);
  if (r.interrupted) return 130;
  return export_error.empty() ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  Options options;
  try {
    options = Parse(argc, argv);
  } catch (const core::UsageError& e) {
    std::cerr << "caliper-calibrate: " << e.what() << "\n" << kUsage;
    return 2;
  }
  // Ctrl-C is read between generations, in every thread blocked
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGINT);
  sigaddset(&set, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &set, nullptr);
  logging::Initialize("calibrate", logging::kWarn);
  int rc = 1;
  try {
    rc = Run(options);
  } catch (const std::exception& e) {
    std::cerr << "caliper-calibrate: error: " << e.what() << "\n";
  } catch (const CORBA::Exception& e) {
    std::cerr << "caliper-calibrate: error: " << rtc::Describe(e) << "\n";
  }
  logging::Shutdown();
  return rc;
}
