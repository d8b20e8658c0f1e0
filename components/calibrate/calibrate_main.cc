// caliper-calibrate: fits a model's parameters to a real robot's recordings with pagmo's
// evolution strategies, evaluating candidates on every Model of a session or cluster.
#include <signal.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "caliper/calibration/calibration.h"
#include "caliper/client/experiments.h"
#include "caliper/client/model_pool.h"
#include "caliper/client/scene_transfer.h"
#include "caliper/client/session.h"
#include "caliper/core/arguments.h"
#include "caliper/core/system.h"
#include "caliper/logging/log.h"
#include "caliper/rtc/client_orb.h"
#include "caliper/rtc/naming.h"
#include "caliper/calibration/evaluator.h"
#include "optimiser.h"
#include "report.h"

namespace fs = std::filesystem;
using namespace caliper;
using namespace caliper::calibration;
namespace M = ::Caliper::Simulation;

namespace {

const char kUsage[] =
    "Usage: caliper-calibrate FILE [--out DIR] [--dry-run] [--resume] [--generations N]\n"
    "                         [--models GLOB] [--islands N] [--run-timeout S]\n"
    "                         [--nameservice corbaname::HOST:PORT]\n"
    "Fits the parameters named in FILE (a calibration file: docs/calibration.md) so that the\n"
    "simulated experiments match the measured CSVs, with pagmo's CMA-ES (or xNES) on one island\n"
    "per Model of the session (every Model whose name matches --models, default model*).\n"
    "  --out DIR        results (default FILE's name + -calibration): parameters.csv, cost.csv,\n"
    "                   channels-EXPERIMENT.csv, tuned.dae, report.png, checkpoint.txt\n"
    "  --dry-run        evaluate the model as it is once: cost and plots, no search\n"
    "  --resume         go on from DIR/checkpoint.txt (the last completed generation)\n"
    "  --generations N  instead of the file's optimiser.generations\n"
    "  --islands N      islands (parallel populations); default one per Model\n"
    "  --run-timeout S  the longest one run may take (300 s)\n"
    "Progress on stderr per generation; Ctrl-C stops after the current generation and keeps the\n"
    "best so far (and a checkpoint for --resume). Exit 0 done, 1 error, 2 bad usage, 130 Ctrl-C.\n";

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
  unsigned generations = 0, islands = 0;
  double run_timeout_s = 300;
};

unsigned Whole(const std::string& flag, const std::string& text) {
  char* end = nullptr;
  const long v = std::strtol(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0' || v < 1 || v > 1000000)
    throw core::UsageError(flag + " takes a whole number from 1 to 1000000");
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
  if (core::TakeOption(args, "--generations", &value)) o.generations = Whole("--generations", value);
  if (core::TakeOption(args, "--islands", &value)) o.islands = Whole("--islands", value);
  if (core::TakeOption(args, "--run-timeout", &value))
    o.run_timeout_s = Whole("--run-timeout", value);
  core::RejectOptions(args);
  if (args.size() != 1) throw core::UsageError("expected one calibration FILE");
  o.file = args[0];
  if (o.out.empty()) o.out = fs::path(o.file).stem().string() + "-calibration";
  return o;
}

// The parameters' values in the scene as it is (asked of a Model).
std::vector<double> SceneValues(const Spec& spec, client::ModelPool& pool) {
  // a URDF is imported here and sent converted: its import warnings are said here, once
  std::vector<std::string> warnings;
  const std::string bytes = client::ReadScene(spec.experiments.front().scene, &warnings);
  for (const auto& w : warnings) std::cerr << "caliper-calibrate: warning: " << w << "\n";
  std::vector<double> values;
  pool.WithModel([&](M::Model_ptr model) {
    try {
      model->load_scene_data(client::SceneFileName(spec.experiments.front().scene).c_str(),
                             client::ToOctets(bytes));
      ::Caliper::Scene::StringSeq ids;
      ids.length(static_cast<CORBA::ULong>(spec.parameters.size()));
      for (CORBA::ULong i = 0; i < ids.length(); ++i) ids[i] = spec.parameters[i].id.c_str();
      ::Caliper::Daq::ValueSeq_var got = model->get(ids);
      values.clear();
      for (CORBA::ULong i = 0; i < got->length(); ++i) {
        if (got[i].data.length() != 1)
          throw client::SetupError(spec.parameters[i].id + " is not a scalar parameter");
        values.push_back(got[i].data[0]);
      }
    } catch (const M::LoadFailed& e) {
      throw client::SetupError(e.reason.in());
    } catch (const M::NotAvailable& e) {
      throw client::NotAvailableError(e.reason.in());  // another Model, or this one once it is idle
    } catch (const ::Caliper::Daq::UnknownId& e) {
      throw client::SetupError(std::string(e.reason.in()) + " (a parameter to fit)");
    } catch (const ::Caliper::Daq::NotAvailable& e) {
      throw client::SetupError(e.reason.in());
    }
  });
  return values;
}

// channels-EXPERIMENT.csv: the measured, initial and fitted values of every compared column at
// the simulated sample times; and its plots.
std::vector<Plot> WriteChannels(const Options& o, const Spec& spec, const Evaluation& before,
                                const Evaluation* after) {
  std::vector<Plot> plots;
  for (size_t i = 0; i < spec.experiments.size() && i < before.recordings.size(); ++i) {
    const auto& rec = before.recordings[i];
    const Measured& m = spec.measured[i];
    const auto columns = ColumnNames(rec.channels);
    // (recorded column, measured column) of every channel that has measurements
    std::vector<std::pair<size_t, size_t>> shown;
    for (size_t c = 0; c < columns.size(); ++c) {
      const auto k = std::find(m.columns.begin(), m.columns.end(), columns[c]);
      if (k != m.columns.end()) shown.emplace_back(c, static_cast<size_t>(k - m.columns.begin()));
    }
    core::WriteFileReplacing(o.out + "/channels-" + spec.experiments[i].name + ".csv",
                             [&](std::ostream& out) {
      out << "time [s]";
      for (const auto& [c, k] : shown) {
        const std::string unit = " [" + (m.units[k].empty() ? "-" : m.units[k]) + "]";
        out << "," << columns[c] << " measured" << unit << "," << columns[c] << " initial" << unit;
        if (after) out << "," << columns[c] << " fitted" << unit;
      }
      out << "\n" << std::setprecision(10);
      for (size_t s = 0; s < rec.times.size(); ++s) {
        const double t = rec.times[s];
        if (t < m.times.front() || t > m.times.back()) continue;
        out << t;
        for (const auto& [c, k] : shown) {
          out << "," << m.At(k, t) << "," << rec.data[s * rec.values_per_sample + c];
          if (after)
            out << "," << after->recordings[i].data[s * rec.values_per_sample + c];
        }
        out << "\n";
      }
    });
    for (const auto& [c, k] : shown) {
      Plot p;
      p.title = spec.experiments[i].name + ": " + columns[c];
      p.x_title = "time [s]";
      p.y_title = m.units[k].empty() ? "[-]" : "[" + m.units[k] + "]";
      p.curves.push_back({"measured", m.times, m.values[k]});
      Curve initial{"initial", {}, {}}, fitted{"fitted", {}, {}};
      for (size_t s = 0; s < rec.times.size(); ++s) {
        initial.x.push_back(rec.times[s]);
        initial.y.push_back(rec.data[s * rec.values_per_sample + c]);
        if (after) {
          fitted.x.push_back(rec.times[s]);
          fitted.y.push_back(after->recordings[i].data[s * rec.values_per_sample + c]);
        }
      }
      p.curves.push_back(initial);
      if (after) p.curves.push_back(fitted);
      plots.push_back(p);
    }
  }
  return plots;
}

// --dry-run: the initial cost per channel and its plots, no search.
int DryRun(const Options& o, const Spec& spec, const Evaluation& before) {
  auto plots = WriteChannels(o, spec, before, nullptr);
  const std::string png = o.out + "/report.png";
  const std::string why = WritePng(png, plots);
  std::cout << "initial cost " << Format(before.cost, 6) << " (dry run: no search)\n";
  for (const auto& c : before.channels)
    std::cout << "  " << std::left << std::setw(44) << c.column << " rms " << Format(c.rms)
              << " of a range of " << Format(c.range) << "\n";
  std::cout << (why.empty() ? "plots: " + png : "no plots: " + why) << "\nchannels: " << o.out
            << "/channels-*.csv\n";
  return 0;
}

// parameters.csv, cost.csv and the cost curve's plot.
std::vector<Plot> WriteParameters(const Options& o, const Spec& spec,
                                  const std::vector<double>& initial,
                                  const std::vector<double>& fitted, const Progress& p) {
  core::WriteFileReplacing(o.out + "/parameters.csv", [&](std::ostream& out) {
    out << "id,initial,fitted,lower,upper,scale,change [%]\n" << std::setprecision(10);
    for (size_t i = 0; i < fitted.size(); ++i)
      out << spec.parameters[i].id << "," << initial[i] << "," << fitted[i] << ","
          << spec.parameters[i].lower << "," << spec.parameters[i].upper << ","
          << (spec.parameters[i].log_scale ? "log" : "linear") << ","
          << 100 * (fitted[i] - initial[i]) / initial[i] << "\n";
  });
  core::WriteFileReplacing(o.out + "/cost.csv", [&](std::ostream& out) {
    out << "evaluations,best cost [-]\n" << std::setprecision(10);
    for (const auto& [n, c] : p.history) out << n << "," << c << "\n";
  });
  std::vector<Plot> plots;
  Plot cost{"best cost", "evaluations", "cost [-] (normalised RMS)", {}, true};
  Curve curve{"best", {}, {}};
  for (const auto& [n, c] : p.history) {
    curve.x.push_back(static_cast<double>(n));
    curve.y.push_back(c);
  }
  cost.curves.push_back(curve);
  plots.push_back(cost);
  return plots;
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

int Run(const Options& o) {
  Spec spec = LoadSpec(o.file);
  if (o.generations) spec.optimiser.generations = o.generations;
  fs::create_directories(o.out);
  const std::string checkpoint = o.out + "/checkpoint.txt";
  if (o.resume && !fs::exists(checkpoint))
    throw std::runtime_error("--resume: no checkpoint at " + checkpoint);

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

  const std::vector<double> initial = SceneValues(spec, pool);
  for (size_t i = 0; i < initial.size(); ++i)
    if (initial[i] < spec.parameters[i].lower || initial[i] > spec.parameters[i].upper)
      std::cerr << "note: " << spec.parameters[i].id << " is " << initial[i]
                << " in the scene, outside [" << spec.parameters[i].lower << ", "
                << spec.parameters[i].upper << "]: the search starts at the nearest bound\n";
  std::vector<double> start_unit;
  for (size_t i = 0; i < initial.size(); ++i)
    start_unit.push_back(spec.parameters[i].ToUnit(initial[i]));
  const Evaluation before = evaluator.Evaluate(evaluator.ValuesOf(start_unit), true);
  if (before.faulted) throw std::runtime_error("the initial model faults: " + before.fault);
  std::cerr << spec.experiments.size() << " experiment(s), " << spec.parameters.size()
            << " parameters, " << models << " Model(s); initial cost " << Format(before.cost)
            << "\n";

  if (o.dry_run) return DryRun(o, spec, before);

  const unsigned islands = o.islands ? o.islands : static_cast<unsigned>(models);
  std::unique_ptr<Search> search;
  if (o.resume) {
    search = std::make_unique<Search>(spec, evaluator, checkpoint);
    std::cerr << "resuming at generation " << search->progress().generation << " ("
              << search->progress().evaluations << " evaluations, best cost "
              << Format(search->progress().best_cost) << ")\n";
  } else {
    search = std::make_unique<Search>(spec, evaluator, islands, start_unit, before.cost);
  }
  std::cerr << search->islands() << " island(s) of " << spec.optimiser.population << " ("
            << spec.optimiser.algorithm << ")\n";
  const auto begin = std::chrono::steady_clock::now();
  const uint64_t evaluations_at_start = search->progress().evaluations;
  const unsigned first_generation = search->progress().generation;
  bool interrupted = false;
  while (search->progress().generation < spec.optimiser.generations) {
    interrupted = !search->Generation(core::InterruptPending);
    search->Save(checkpoint);
    pool.Refresh();  // Models that appeared or came back join the next generation
    const Progress& p = search->progress();
    const double wall =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
    const double rate = static_cast<double>(p.evaluations - evaluations_at_start) / wall;
    const double per_generation = wall / (p.generation - first_generation);
    std::cerr << "gen " << p.generation << "/" << spec.optimiser.generations << "  evals "
              << p.evaluations << "  " << Format(rate, 3) << " evals/s  best "
              << Format(p.best_cost) << " (initial " << Format(before.cost) << ")  step "
              << Format(p.spread, 3) << "  ETA "
              << Duration(per_generation * (spec.optimiser.generations - p.generation)) << "\n";
    if (interrupted) {
      std::cerr << "interrupted: keeping the best so far; --resume goes on from generation "
                << p.generation << "\n";
      break;
    }
  }

  // the best: its recordings, the tuned scene, the report
  const Progress& p = search->progress();
  const std::vector<double> fitted = evaluator.ValuesOf(p.best_unit);
  const Evaluation after = evaluator.Evaluate(fitted, true);
  std::vector<Plot> plots = WriteParameters(o, spec, initial, fitted, p);
  for (auto& plot : WriteChannels(o, spec, before, &after)) plots.push_back(plot);
  const std::string png = o.out + "/report.png";
  const std::string why = WritePng(png, plots);
  // the tuned scene last: whatever fails there, the results above are written
  const std::string tuned = o.out + "/tuned.dae";
  const std::string export_error = ExportTuned(pool, spec, fitted, tuned);

  std::cout << "cost " << Format(before.cost, 6) << " -> " << Format(after.cost, 6) << " ("
            << Format(before.cost / std::max(after.cost, 1e-300), 3) << "x lower) after "
            << p.evaluations << " evaluations in " << p.generation << " generations ("
            << evaluator.faults() << " faulted)\n";
  for (size_t i = 0; i < fitted.size(); ++i)
    std::cout << "  " << std::left << std::setw(44) << spec.parameters[i].id << std::right
              << std::setw(12) << Format(initial[i], 6) << " -> " << std::setw(12)
              << Format(fitted[i], 6) << "\n";
  std::cout << "results: " << o.out << "/parameters.csv, "
            << (export_error.empty() ? "tuned scene: " + tuned
                                     : "no tuned scene (" + export_error + ")")
            << ", " << (why.empty() ? "report: " + png : "no plots: " + why) << "\n";
  if (interrupted) return 130;
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
