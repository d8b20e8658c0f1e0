#pragma once
// The Main Window of a GUI test on a ModelLink to the test's naming service (header only: the
// tests that include it link caliper::main_window, the support library does not).

#include <memory>
#include <string>

#include "main_window.h"
#include "model_link.h"

namespace caliper::testing {

/// A Main Window on the Model found through the naming service at `address`: the link looks it
/// up again every 300 ms while none answers and polls it every `poll_period_ms`; the window
/// shows its snapshot at 20 Hz and starts none of the tools saved in its settings.
inline std::unique_ptr<main_window::MainWindow> MainWindowOnModel(const std::string& address,
                                                                  int poll_period_ms) {
  main_window::ModelLink::Options options;
  options.nameservice = address;
  options.reconnect_period_ms = 300;
  options.poll_period_ms = poll_period_ms;
  return std::make_unique<main_window::MainWindow>(
      std::make_unique<main_window::ModelLink>(options), 20.0, nullptr, false);
}

}  // namespace caliper::testing
