// The C++ side of `launch/caliper bench python`: a lock-step control cycle through the client
// library (libs/client) on a running Model: one get of the ids given, one set_commands of two
// actuators, step(1). Prints `cycle_us <best of the rounds>` for bench/python_bench.py, which runs
// the same cycle from Python against the same Model and prints the ratio.
//
//   control_cycle_bench NAMESERVICE MODEL CYCLES ROUNDS ACTUATOR1 ACTUATOR2 ID...
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "caliper/client/client.h"

namespace {

namespace M = ::Caliper::Simulation;
using namespace caliper;

int Main(int argc, char** argv) {
  if (argc < 8) {
    std::fprintf(stderr,
                 "usage: control_cycle_bench NAMESERVICE MODEL CYCLES ROUNDS ACTUATOR1 ACTUATOR2 "
                 "ID...\n");
    return 2;
  }
  client::Session session({argv[1], 30.0, "control_cycle_bench"});
  client::ModelRef m = client::ConnectModel(session, argv[2]);
  const long cycles = std::stol(argv[3]), rounds = std::stol(argv[4]);
  ::Caliper::Scene::StringSeq ids;
  ids.length(static_cast<CORBA::ULong>(argc - 7));
  for (int i = 7; i < argc; ++i)
    ids[static_cast<CORBA::ULong>(i - 7)] = static_cast<const char*>(argv[i]);  // copied
  M::CommandSeq commands;
  commands.length(2);
  commands[0].actuator = static_cast<const char*>(argv[5]);
  commands[1].actuator = static_cast<const char*>(argv[6]);
  double best = 1e300;
  for (long r = 0; r < rounds; ++r) {
    const auto start = std::chrono::steady_clock::now();
    client::Call(m, [&] {
      for (long c = 0; c < cycles; ++c) {
        ::Caliper::Daq::ValueSeq_var values = m.model->get(ids);
        commands[0].value = 1.0 + 0.5 * values[0].data[0];
        commands[1].value = 1.0 - 0.5 * values[0].data[0];
        m.model->set_commands(commands);
        m.model->step(1);
      }
    });
    const double us =
        std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start)
            .count() /
        cycles;
    best = std::min(best, us);
  }
  std::printf("cycle_us %.3f\n", best);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return Main(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "control_cycle_bench: %s\n", e.what());
    return 1;
  }
}
