// Physics benchmarks: Caliper's step against raw Bullet and MuJoCo 2.2.2 on the same 40-body,
// 80-tendon tree, and the cost of tendon-skeleton contact. Prints one line per figure:
//   RATIO <name> <value> (target <target>)
// measured in this run (medians of several repetitions), never compared with stored times.
#include <mujoco/mujoco.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <string>
#include <vector>

#include "caliper/physics_bullet/bullet_scene.h"
#include "raw_bullet.h"
#include "tree_model.h"

namespace caliper::bench {
namespace {

int steps = 2000;
int repeats = kStarts;
bool verbose = false;  // each run's time

/// One engine on one tree: how to build it from a start of the ensemble, and one step.
struct Case {
  std::function<void(int start)> make;
  std::function<void()> step;
};

/// Each case's time of one step [us] over `repeats` runs of `steps` steps, each after a warm-up.
/// Each run starts the tree from the next start of the ensemble (TreeOptions::start), the same
/// for every engine: the mean over the starts, since the tree tumbles and a run's cost depends on
/// where it lands (a change in the last bits of a force moves a single start's time by several
/// percent). The cases' runs take turns start by start, so that a change in the machine's speed
/// while they run (this shared machine's drifts by several percent over seconds) falls on all of
/// them alike and leaves their ratios alone. With `fastest`, the fastest run's instead (a tree
/// held still: what the work itself costs, interference only adds time).
std::vector<double> Time(const std::vector<const Case*>& cases, bool fastest = false) {
  std::vector<std::vector<double>> runs(cases.size());
  for (int r = 0; r < repeats; ++r)
    for (size_t c = 0; c < cases.size(); ++c) {
      cases[c]->make(r % kStarts);
      for (int i = 0; i < 100; ++i) cases[c]->step();
      const auto begin = std::chrono::steady_clock::now();
      for (int i = 0; i < steps; ++i) cases[c]->step();
      const double us = std::chrono::duration<double, std::micro>(
                            std::chrono::steady_clock::now() - begin)
                            .count();
      runs[c].push_back(us / steps);
    }
  std::vector<double> times;
  for (const std::vector<double>& case_runs : runs) {
    if (verbose) {
      std::printf("#   runs [us]:");
      for (const double us : case_runs) std::printf(" %.1f", us);
      std::printf("\n");
    }
    if (fastest) {
      times.push_back(*std::min_element(case_runs.begin(), case_runs.end()));
    } else {
      double sum = 0;
      for (const double us : case_runs) sum += us;
      times.push_back(sum / static_cast<double>(case_runs.size()));
    }
  }
  return times;
}

double Time(const Case& one, bool fastest = false) { return Time({&one}, fastest)[0]; }

int g_threads = 1;  // physics_bullet::Options::threads of the Caliper cases (--threads)

Case CaliperCase(const TreeOptions& tree, bool contact, int threads = g_threads) {
  auto scene = std::make_shared<std::unique_ptr<sgal::PhysicsScene>>();
  physics_bullet::Options options;
  options.tendon_body_contact = contact;
  options.threads = threads;
  return {[=](int start) {
            TreeOptions o = tree;
            o.start = start;
            const sgal::Scene description = MakeTree(o);
            *scene = physics_bullet::MakeScene(description, options);
            for (const auto& a : description.actuators) (*scene)->SetCommand(a.name, 0.05);  // [V]
          },
          [=] { (*scene)->Step(); }};
}

Case RawBulletCase(const TreeOptions& tree) {
  auto world = std::make_shared<std::unique_ptr<RawBulletWorld>>();
  return {[=](int start) {
            TreeOptions o = tree;
            o.start = start;
            *world = std::make_unique<RawBulletWorld>(MakeTree(o));
          },
          [=] { (*world)->Step(1e-3); }};
}

mjModel* LoadMuJoCo(const TreeOptions& tree) {
  const std::string xml = MakeTreeMjcf(tree);
  const char* path = "/tmp/caliper-bench-tree40.xml";
  FILE* f = std::fopen(path, "w");
  std::fputs(xml.c_str(), f);
  std::fclose(f);
  char error[1000] = "";
  mjModel* m = mj_loadXML(path, nullptr, error, sizeof error);
  if (m == nullptr) {
    std::fprintf(stderr, "MuJoCo rejected the generated model: %s\n", error);
    std::exit(1);
  }
  return m;
}

/// A MuJoCo model and its data, freed with the case.
struct MuJoCoWorld {
  mjModel* m = nullptr;
  mjData* d = nullptr;
  ~MuJoCoWorld() {
    if (d) mj_deleteData(d);
    if (m) mj_deleteModel(m);
  }
};

Case MuJoCoCase(const TreeOptions& tree) {
  auto world = std::make_shared<MuJoCoWorld>();
  return {[=](int start) {
            if (world->d) mj_deleteData(world->d);
            if (world->m) mj_deleteModel(world->m);
            TreeOptions o = tree;
            o.start = start;
            world->m = LoadMuJoCo(o);
            world->d = mj_makeData(world->m);
            for (int i = 0; i < world->m->nu; ++i) world->d->ctrl[i] = 1.0;  // [N]
          },
          [=] { mj_step(world->m, world->d); }};
}

/// The like-for-like case of the raw baseline: ligaments with its springs' law (2000 N/m, 5 N s/m,
/// slack at 98 % of the starting length, so that every one pulls), no tendon-body contact; the
/// same forces give the same motion and the same contacts.
Case PassiveCase(const TreeOptions& tree) {
  TreeOptions springs = tree;
  springs.actuator_kind = "ligament";
  // the ligaments' law, on a scene of any start (a turned tree has the same lengths)
  auto describe = [springs](int start, const std::vector<sgal::TendonState>* lengths) mutable {
    springs.start = start;
    sgal::Scene description = MakeTree(springs);
    for (auto& a : description.actuators) {
      a.parameters["stiffness"] = 2000;
      if (lengths == nullptr) continue;
      for (size_t t = 0; t < description.tendons.size(); ++t)
        if (description.tendons[t].name == a.tendon) {
          a.parameters["damping"] = 5;
          a.parameters["rest_length"] = 0.98 * (*lengths)[t].length;
        }
    }
    return description;
  };
  const auto lengths = physics_bullet::MakeScene(describe(0, nullptr))->TendonStates();
  auto plain = std::make_shared<std::unique_ptr<sgal::PhysicsScene>>();
  physics_bullet::Options no_contact;
  no_contact.tendon_body_contact = false;
  no_contact.threads = g_threads;
  return {[=](int start) mutable {
            *plain = physics_bullet::MakeScene(describe(start, &lengths), no_contact);
          },
          [=] { (*plain)->Step(); }};
}

double TimeCaliper(const TreeOptions& tree, bool contact) {
  return Time(CaliperCase(tree, contact));
}

void Ratio(const char* name, double value, double target) {
  std::printf("RATIO %s %.3f (target %.2f)%s\n", name, value, target,
              value <= target ? "" : "  <- above target");
  std::fflush(stdout);
}

/// One Caliper case alone (for profiling): its step time, no ratio. False for an unknown name.
bool TimeOnly(const std::string& name) {
  TreeOptions o;  // floor and self contact
  bool contact = true;
  if (name == "tree_free" || name == "spanning_on" || name == "spanning_off") {
    o.floor = false;
    o.self_contact = false;
  }
  if (name == "spanning_on" || name == "spanning_off") o.spanning_tendons = true;
  if (name == "spanning_off" || name == "tree_contact_off") contact = false;
  if (name == "tree_bare") o.tendons = 0;
  if (name == "passive") {
    std::printf("# step time [us]: %s %.1f\n", name.c_str(), Time(PassiveCase(o)));
    return true;
  }
  if (name == "raw_bullet") {
    std::printf("# step time [us]: %s %.1f\n", name.c_str(), Time(RawBulletCase(o)));
    return true;
  }
  if (name != "tree_contact" && name != "tree_contact_off" && name != "tree_free" &&
      name != "spanning_on" && name != "spanning_off" && name != "tree_bare")
    return false;
  std::printf("# step time [us]: %s %.1f\n", name.c_str(), TimeCaliper(o, contact));
  return true;
}

}  // namespace
}  // namespace caliper::bench

int main(int argc, char** argv) {
  using namespace caliper;
  using namespace caliper::bench;
  // waiting threads spin as long as in the Model (GOMP_SPINCOUNT, unless the environment sets it)
  physics_bullet::BoundThreadSpin(argv);
  std::string only;  // one case to time alone
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--steps") && i + 1 < argc) steps = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--repeats") && i + 1 < argc) repeats = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--only") && i + 1 < argc) only = argv[++i];
    else if (!std::strcmp(argv[i], "--threads") && i + 1 < argc)
      g_threads = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--verbose")) verbose = true;
    else {
      std::printf(
          "Usage: physics_bench [--steps N] [--repeats R] [--threads N] [--only CASE] [--verbose]\n"
          "40-body tree, 39 hinges, 80 tendons, dt = 1 ms. A step time is the mean over\n"
          "R runs of N steps (default %d and %d), each run from the next of %d starting\n"
          "poses (upright and tilted by %.2f rad), the same for every engine.\n"
          "--verbose prints each run's time.\n"
          "--threads N runs the Caliper cases on N threads (Options::threads; 1).\n"
          "--only times one case (for profiling): tree_contact, tree_contact_off (its\n"
          "tendons without tendon-body contact), tree_free,\n"
          "spanning_on, spanning_off, tree_bare (no tendons), passive (ligaments, no tendon\n"
          "contact), raw_bullet.\n",
          steps, repeats, kStarts, kStartTilt);
      return std::strcmp(argv[i], "--help") ? 2 : 0;
    }
  }
  if (!only.empty()) {
    if (TimeOnly(only)) return 0;
    std::fprintf(stderr, "physics_bench: unknown case '%s' for --only\n", only.c_str());
    return 2;
  }
  TreeOptions contact;  // floor and self contact
  TreeOptions free;
  free.floor = false;
  free.self_contact = false;

  // the cases a ratio compares run by turns (Time)
  const Case caliper_contact_case = CaliperCase(contact, true);
  const Case raw_contact_case = RawBulletCase(contact), passive_case = PassiveCase(contact);
  const Case mujoco_contact_case = MuJoCoCase(contact);
  const std::vector<double> contact_times =
      Time({&caliper_contact_case, &raw_contact_case, &passive_case, &mujoco_contact_case});
  const double caliper_contact = contact_times[0], raw_contact = contact_times[1];
  std::printf("# step time [us]: Caliper %.1f, raw Bullet with 80 springs %.1f (floor + self contact)\n",
              caliper_contact, raw_contact);
  // the targets of issue #34; issue #16's in parentheses
  Ratio("caliper_vs_raw_bullet", caliper_contact / raw_contact, 1.25);  // (1.5)

  // like for like with the baseline's plain springs: passive tendons, no tendon-body contact
  const double caliper_springs = contact_times[2];
  std::printf("# step time [us]: Caliper with 80 passive tendons and no tendon contact %.1f "
              "(information: the cost of the DC motors and of tendon contact is the rest)\n",
              caliper_springs);
  Ratio("caliper_passive_tendons_vs_raw_bullet", caliper_springs / raw_contact, 1.05);  // (1.15)

  const double mujoco_contact = contact_times[3];
  std::printf("# step time [us]: MuJoCo 2.2.2 %.1f (floor + self contact)\n", mujoco_contact);
  Ratio("caliper_vs_mujoco_contact", caliper_contact / mujoco_contact, 0.75);  // (1.0)

  const Case caliper_free_case = CaliperCase(free, true), mujoco_free_case = MuJoCoCase(free);
  const std::vector<double> free_times = Time({&caliper_free_case, &mujoco_free_case});
  const double caliper_free = free_times[0], mujoco_free = free_times[1];
  std::printf("# step time [us]: Caliper %.1f, MuJoCo 2.2.2 %.1f (no contact)\n", caliper_free,
              mujoco_free);
  Ratio("caliper_vs_mujoco_no_contact", caliper_free / mujoco_free, 1.0);  // (1.5)

  TreeOptions spanning = free;
  spanning.spanning_tendons = true;
  const Case on_case = CaliperCase(spanning, true), off_case = CaliperCase(spanning, false);
  const std::vector<double> spanning_times = Time({&on_case, &off_case});
  const double on = spanning_times[0], off = spanning_times[1];
  std::printf("# step time [us]: tendons pressing on bodies, contact on %.1f, off %.1f\n", on, off);
  Ratio("tendon_contact_on_vs_off", on / off, 1.25);  // (1.5)

  // cost growth: the step time of the same tree with more tendons, and of larger trees; the
  // exponent p of a least-squares fit time = c n^p on log-log axes
  auto exponent = [](const std::vector<std::pair<double, double>>& points) {
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (const auto& [n, t] : points) {
      const double x = std::log(n), y = std::log(t);
      sx += x, sy += y, sxx += x * x, sxy += x * y;
    }
    const double k = static_cast<double>(points.size());
    return (k * sxy - sx * sy) / (k * sxx - sx * sx);
  };
  std::vector<std::pair<double, double>> by_tendons, by_bodies;
  // The tendons' cost alone: the tree held still (its bodies kinematic, no joints), so that what
  // Bullet does is the same at every tendon count; every tendon is still evaluated each step
  // (path, contact search against the skeleton, DC motor, forces). With a moving tree, more
  // tendons hold it up and change what collides, and the rest of the step changes with them.
  auto time_held = [&](int tendons) {
    TreeOptions o = contact;
    o.tendons = tendons;
    sgal::Scene held = MakeTree(o);
    for (auto& body : held.bodies)
      if (body.type == sgal::BodyType::kDynamic) body.type = sgal::BodyType::kKinematic;
    held.constraints.clear();
    auto scene = std::make_shared<std::unique_ptr<sgal::PhysicsScene>>();
    const Case still{[=](int) {
                       *scene = physics_bullet::MakeScene(held);
                       for (const auto& a : held.actuators)
                         (*scene)->SetCommand(a.name, 0.05);  // [V]
                     },
                     [=] { (*scene)->Step(); }};
    return Time(still, true);
  };
  // the fastest runs: the tendons' share is a difference, and at 10 tendons (under 2 us) a
  // disturbed median of either time would make it nothing; the tree without tendons is timed
  // before and after the others, its faster time taken
  const std::vector<int> counts = {0, 10, 40, 80, 160, 320};
  std::vector<double> held;
  for (const int n : counts) held.push_back(time_held(n));
  const double without = std::min(held[0], time_held(0));
  std::printf("# step time [us] by tendons, the tree held still (fastest of %d runs): 0: %.1f",
              repeats, without);
  std::string unmeasured;  // counts whose share the timing could not see: left out of the fit
  for (size_t k = 1; k < counts.size(); ++k) {
    if (held[k] > without)
      by_tendons.emplace_back(counts[k], held[k] - without);
    else
      unmeasured += " " + std::to_string(counts[k]);
    std::printf(" %d: %.1f", counts[k], held[k]);
  }
  if (!unmeasured.empty())
    std::printf("\n# no longer than without tendons, left out of the fit:%s", unmeasured.c_str());
  std::printf("\n# step time [us] by tendons, the tree moving (information):");
  for (const int n : {10, 40, 80, 160, 320}) {
    TreeOptions o = contact;
    o.tendons = n;
    std::printf(" %d: %.1f", n, TimeCaliper(o, true));
  }
  std::printf("\n# step time [us] by bodies (80 tendons):");
  for (const int n : {20, 40, 80, 160}) {
    TreeOptions o = contact;
    o.bodies = n;
    by_bodies.emplace_back(n, TimeCaliper(o, true));
    std::printf(" %d: %.1f", n, by_bodies.back().second);
  }
  std::printf("\n# fitted growth exponent by bodies %.2f (information)\n", exponent(by_bodies));
  std::printf("# the tendons' share [us]:");
  for (const auto& [n, t] : by_tendons) std::printf(" %.0f: %.1f", n, t);
  std::printf("\n");
  Ratio("tendon_cost_growth_exponent", exponent(by_tendons), 1.05);

  // Options::threads: the contact tree on two threads against one, by turns (the figures above
  // are on --threads, one by default)
  if (physics_bullet::ThreadCount(0) >= 2) {
    const Case one = CaliperCase(contact, true, 1), two = CaliperCase(contact, true, 2);
    const std::vector<double> by_threads = Time({&one, &two});
    std::printf("# step time [us], floor + self contact: one thread %.1f, two %.1f\n",
                by_threads[0], by_threads[1]);
    Ratio("two_threads_vs_one_contact_tree", by_threads[1] / by_threads[0], 0.9);
  } else {
    std::printf(
        "# two_threads_vs_one_contact_tree not measured: this process may run on one "
        "processor only\n");
  }
  return 0;
}
