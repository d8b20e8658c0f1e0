#include "model_verify.h"

#include <chrono>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "caliper/simulation/model_core.h"

namespace caliper::model {

namespace {

// a value with `precision` significant digits
std::string Num(double v, int precision) {
  std::ostringstream s;
  s << std::setprecision(precision) << v;
  return s.str();
}

int Verify(const std::string& path) {
  const auto t0 = std::chrono::steady_clock::now();
  auto last_print = t0;
  bool printed = false;
  const auto progress = [&](uint64_t step, uint64_t last) {
    const auto now = std::chrono::steady_clock::now();
    if (now - last_print < std::chrono::milliseconds(250)) return;
    last_print = now;
    printed = true;
    std::cerr << "\rverifying: step " << step << " of " << last << std::flush;
  };
  simulation::Verification v = simulation::VerifyRecording(path, progress);
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (printed) std::cerr << "\n";
  std::cerr << "re-simulated " << v.steps << " steps in " << Num(s, 3) << " s ("
            << Num(s > 0 ? v.steps / s : 0, 4) << " steps/s)\n";
  if (v.identical) {
    std::cout << "identical: " << v.steps << " steps, " << v.keyframes << " keyframes, "
              << v.samples << " samples compared bit for bit\n";
    return 0;
  }
  std::cout << "diverges at step " << v.divergent_step << " (after " << v.steps << " steps, "
            << v.keyframes << " keyframes and " << v.samples << " samples identical): " << v.detail
            << "\n";
  return 1;
}

}  // namespace

int VerifyMain(const std::string& path) {
  try {
    return Verify(path);
  } catch (const std::exception& e) {
    std::cerr << "caliper-model --verify: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace caliper::model
