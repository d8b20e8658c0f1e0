#pragma once
// Helpers for the GUI tests that run widgets in the test process: one QApplication, one ORB,
// waiting while processing events, and where screenshots go.

#include <gtest/gtest.h>

#include <QApplication>
#include <chrono>
#include <functional>
#include <memory>
#include <string>

#include "caliper/model.hh"
#include "caliper/rtc.hh"
#include "support/process.h"

namespace caliper::testing {

/// The process's QApplication (made on first use, on $QT_QPA_PLATFORM, offscreen when unset).
QApplication& App();

/// The process's ORB, listening on 127.0.0.1.
CORBA::ORB_ptr Orb();

/// Processes events until `condition` holds or `timeout` passes; returns its last value.
bool WaitInGui(const std::function<bool()>& condition, std::chrono::milliseconds timeout);

/// Turns the event loop for `duration` and returns the longest time one turn took [ms]: how long
/// the GUI thread was blocked at worst.
qint64 LongestEventLoopStall(std::chrono::milliseconds duration);

/// `name` in $CALIPER_ARTIFACT_DIR (the screenshots kept by the test run), else in `fallback_dir`.
std::string ArtifactPath(const std::string& name, const std::string& fallback_dir);
/// The directory ArtifactPath() puts files in (a renderer's renderer.write_dir in tests).
std::string ArtifactDir(const std::string& fallback_dir);

/// caliper-model with `scene` loaded on the naming service at `address`, ACTIVE, logging to no
/// service (its spool in `dir`/spool), its output in `output`; load_scene reads models/,
/// tests/data and `dir`, save_scene writes into `dir`.
std::unique_ptr<Process> StartModelProcess(const std::string& address, const std::string& scene,
                                           const std::string& dir, const std::string& output);

/// The Model bound as `instance` that answers, or nil after 20 s.
::Caliper::Simulation::Model_ptr WaitForModel(const std::string& address,
                                              const std::string& instance = "model0");

/// A test of a window against a real caliper-model: a private naming service and the Model on
/// it (StartModelProcess), its files and the Main Window's settings (CALIPER_MAIN_SETTINGS,
/// caliper-main.ini) in dir_.
class ModelProcessTest : public ::testing::Test {
 protected:
  /// Starts the naming service and the Model with `scene` (a path below $CALIPER_SOURCE_DIR)
  /// and waits for the Model to answer: a fatal failure with its output when it does not
  /// within 20 s (call it in ASSERT_NO_FATAL_FAILURE).
  void StartModelSession(const std::string& scene);
  /// Stops the Model with SIGTERM and expects it to exit 0 within 10 s.
  void StopModel();

  TempDir dir_;
  std::unique_ptr<NamingService> naming_;
  std::unique_ptr<Process> process_;
  ::Caliper::Simulation::Model_var model_;
};

}  // namespace caliper::testing
