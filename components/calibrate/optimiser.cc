#include "optimiser.h"

#include <boost/archive/text_iarchive.hpp>
#include <boost/archive/text_oarchive.hpp>
#include <boost/serialization/utility.hpp>
#include <boost/serialization/vector.hpp>
#include <cmath>
#include <fstream>
#include <future>
#include <pagmo/algorithm.hpp>
#include <pagmo/algorithms/cmaes.hpp>
#include <pagmo/algorithms/xnes.hpp>
#include <pagmo/archipelago.hpp>
#include <pagmo/islands/thread_island.hpp>
#include <pagmo/population.hpp>
#include <pagmo/problem.hpp>
#include <pagmo/s11n.hpp>
// thread_island{false}: a thread per island, not pagmo's pool, which runs at most as many
// islands at once as this machine has cores (the Models may be on other machines)
#include <random>
#include <thread>

#include "caliper/calibration/evaluator.h"
#include "caliper/core/system.h"

namespace caliper::calibration {

namespace {

// The calibration as a pagmo problem in the unit box; fitness is the cost.
struct Fit {
  Evaluator* evaluator = nullptr;
  size_t dimension = 1;
  pagmo::vector_double fitness(const pagmo::vector_double& x) const {
    return {evaluator->CostOfUnit(x)};
  }
  std::pair<pagmo::vector_double, pagmo::vector_double> get_bounds() const {
    return {pagmo::vector_double(dimension, 0.0), pagmo::vector_double(dimension, 1.0)};
  }
  std::string get_name() const { return "Caliper calibration"; }
  pagmo::thread_safety get_thread_safety() const { return pagmo::thread_safety::basic; }
};

pagmo::algorithm MakeAlgorithm(const Optimiser& o, unsigned seed) {
  // one generation per evolve(); memory keeps the adaptation between calls
  if (o.algorithm == "xnes")
    return pagmo::algorithm(pagmo::xnes(1, -1, -1, -1, o.sigma0, 1e-12, 1e-12, true, true, seed));
  return pagmo::algorithm(
      pagmo::cmaes(1, -1, -1, -1, -1, o.sigma0, 1e-12, 1e-12, true, true, seed));
}

}  // namespace

struct Search::Impl {
  Evaluator* evaluator = nullptr;
  const Spec* spec = nullptr;
  unsigned islands = 1;
  uint64_t evaluations_before = 0;  // by earlier runs (a resumed search)
  pagmo::problem problem;
  pagmo::archipelago archipelago;
};

Search::~Search() = default;

unsigned Search::islands() const { return static_cast<unsigned>(impl_->archipelago.size()); }

Search::Search(const Spec& spec, Evaluator& evaluator, unsigned islands,
               const std::vector<double>& start_unit, double start_cost)
    : impl_(std::make_unique<Impl>()) {
  impl_->evaluator = &evaluator;
  impl_->spec = &spec;
  impl_->islands = islands;
  impl_->problem = pagmo::problem(Fit{&evaluator, spec.parameters.size()});
  progress_.population = spec.optimiser.population;
  Populate(start_unit, start_cost, false);
  progress_.evaluations = impl_->evaluations_before + evaluator.evaluations();
  progress_.history.emplace_back(progress_.evaluations, start_cost);
  Measure();
}

void Search::Populate(const std::vector<double>& start_unit, double start_cost,
                      bool random_others) {
  const Spec& spec = *impl_->spec;
  const unsigned population = progress_.population;
  const uint64_t seed = spec.seed + 7919u * progress_.restarts;
  // each island: the start and population-1 points around it, evaluated in parallel; after a
  // restart the other islands start from random points of the box
  std::vector<std::future<pagmo::population>> made;
  for (unsigned i = 0; i < impl_->islands; ++i)
    made.push_back(std::async(std::launch::async, [&, i] {
      std::mt19937_64 rng(seed * 1000003u + i);
      std::uniform_real_distribution<double> uniform(0.0, 1.0);
      std::vector<double> centre = start_unit;
      if (random_others && i > 0)
        for (double& v : centre) v = uniform(rng);
      std::normal_distribution<double> normal(0.0, spec.optimiser.sigma0);
      pagmo::population pop(impl_->problem, 0u, static_cast<unsigned>(seed + i));
      if (i == 0 || !random_others)
        pop.push_back(start_unit, {start_cost});
      else
        pop.push_back(centre);
      for (unsigned k = 1; k < population; ++k) {
        pagmo::vector_double x = centre;
        for (double& v : x) v = std::clamp(v + normal(rng), 0.0, 1.0);
        pop.push_back(x);
      }
      return pop;
    }));
  impl_->archipelago = pagmo::archipelago();
  for (unsigned i = 0; i < impl_->islands; ++i)
    impl_->archipelago.push_back(pagmo::thread_island{false},
                                 MakeAlgorithm(spec.optimiser, static_cast<unsigned>(seed + i)),
                                 made[i].get());
}

void Search::Restart() {
  ++progress_.restarts;
  progress_.population *= 2;
  progress_.restart_generation = progress_.generation;
  Populate(progress_.best_unit, progress_.best_cost, true);
  progress_.evaluations = impl_->evaluations_before + impl_->evaluator->evaluations();
  Measure();
}

std::vector<double> Progress::CostsSinceRestart() const {
  std::vector<double> out;
  for (size_t g = restart_generation; g < history.size(); ++g) out.push_back(history[g].second);
  return out;
}

Search::Search(const Spec& spec, Evaluator& evaluator, const std::string& checkpoint)
    : impl_(std::make_unique<Impl>()) {
  impl_->evaluator = &evaluator;
  impl_->spec = &spec;
  impl_->problem = pagmo::problem(Fit{&evaluator, spec.parameters.size()});
  std::ifstream in(checkpoint);
  if (!in) throw std::runtime_error(checkpoint + ": cannot be read");
  try {
    boost::archive::text_iarchive archive(in);
    size_t dimension = 0, islands = 0;
    archive >> dimension >> islands;
    if (dimension != spec.parameters.size())
      throw std::runtime_error(checkpoint + ": " + std::to_string(dimension) +
                               " parameters, the calibration file has " +
                               std::to_string(spec.parameters.size()));
    archive >> progress_.generation >> progress_.history >> progress_.restarts >>
        progress_.population >> progress_.restart_generation;
    impl_->islands = static_cast<unsigned>(islands);
    uint64_t evaluations = 0;
    archive >> evaluations >> progress_.best_cost >> progress_.best_unit;
    for (size_t i = 0; i < islands; ++i) {
      pagmo::algorithm algorithm;
      std::vector<pagmo::vector_double> xs, fs;
      archive >> algorithm >> xs >> fs;
      pagmo::population pop(impl_->problem, 0u, static_cast<unsigned>(spec.seed + i));
      for (size_t k = 0; k < xs.size(); ++k) pop.push_back(xs[k], fs[k]);
      impl_->archipelago.push_back(pagmo::thread_island{false}, algorithm, pop);
    }
    progress_.evaluations = evaluations;
    impl_->evaluations_before = evaluations - evaluator.evaluations();
  } catch (const boost::archive::archive_exception& e) {
    throw std::runtime_error(checkpoint + ": not a checkpoint of this program (" + e.what() + ")");
  }
  Measure();
}

void Search::Save(const std::string& path) const {
  core::WriteFileReplacing(path, [&](std::ostream& out) {
    boost::archive::text_oarchive archive(out);
    const size_t dimension = impl_->problem.get_nx(), islands = impl_->archipelago.size();
    archive << dimension << islands << progress_.generation << progress_.history
            << progress_.restarts << progress_.population << progress_.restart_generation
            << progress_.evaluations << progress_.best_cost << progress_.best_unit;
    for (const auto& island : impl_->archipelago) {
      const pagmo::algorithm algorithm = island.get_algorithm();
      const pagmo::population pop = island.get_population();
      archive << algorithm << pop.get_x() << pop.get_f();
    }
  });
}

void Search::Measure() {
  // the best ever: CMA-ES replaces whole populations, so keep what was found before
  double best = progress_.best_unit.empty() ? HUGE_VAL : progress_.best_cost;
  double spread = 0;
  for (const auto& island : impl_->archipelago) {
    const pagmo::population pop = island.get_population();
    const auto& f = pop.get_f();
    const auto& x = pop.get_x();
    for (size_t k = 0; k < f.size(); ++k)
      if (f[k][0] < best) {
        best = f[k][0];
        progress_.best_unit = x[k];
      }
    for (size_t d = 0; d < pop.get_problem().get_nx(); ++d) {
      double mean = 0, square = 0;
      for (const auto& xi : x) mean += xi[d];
      mean /= static_cast<double>(x.size());
      for (const auto& xi : x) square += (xi[d] - mean) * (xi[d] - mean);
      spread += std::sqrt(square / static_cast<double>(x.size()));
    }
  }
  progress_.best_cost = best;
  progress_.spread =
      spread / static_cast<double>(impl_->archipelago.size() * impl_->problem.get_nx());
}

bool Search::Generation(const std::function<bool()>& interrupted) {
  impl_->archipelago.evolve(1);
  bool stop = false;
  while (impl_->archipelago.status() == pagmo::evolve_status::busy) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    stop = stop || interrupted();
  }
  impl_->archipelago.wait_check();  // rethrows what a fitness call threw (a set-up error)
  ++progress_.generation;
  progress_.evaluations = impl_->evaluations_before + impl_->evaluator->evaluations();
  Measure();
  progress_.history.emplace_back(progress_.evaluations, progress_.best_cost);
  return !stop;
}

}  // namespace caliper::calibration
