#pragma once
// tests/data/log_viewer/known_session.log and what is known about it: 30 records (one line, 19,
// malformed) from model0 (16), pd0 (6), renderer0 (4) and logger0 (4), one per second from
// 2024-03-05T10:00:00Z (record i at i-1 s, plus i ms and 7 us).

#include <cstdint>
#include <string>

namespace caliper::log_viewer::testing {

/// The file's path in the source tree.
inline std::string KnownSessionPath() {
  return std::string(CALIPER_LOG_VIEWER_DATA_DIR) + "/known_session.log";
}

constexpr int kKnownRecords = 30;
constexpr int kKnownMalformedLine = 19;
constexpr int64_t kKnownStartUs = 1709632800LL * 1000000;  ///< 2024-03-05T10:00:00Z

// records per component
constexpr int kModel0 = 16;
constexpr int kPd0 = 6;
constexpr int kRenderer0 = 4;
constexpr int kLogger0 = 4;
// records per priority or worse
constexpr int kWarnOrWorse = 9;  ///< FATAL 1, ALERT 1, CRIT 1, ERROR 2, WARN 4
constexpr int kErrorOrWorse = 5;
constexpr int kDebugOnly = 6;
// records per category
constexpr int kModelPhysics = 8;
constexpr int kModelDaq = 3;
// message text
constexpr int kTendonAnyCase = 4;  ///< "tendon" (records 3, 7, 11 "Tendon", 27)
constexpr int kTendonExactCase = 3;
constexpr int kStepRegex = 3;  ///< ^step \d+ (records 4, 5, 22)
// warn or worse, model0 and pd0 only, without caliper.model.daq: records 7, 11, 16, 19, 24, 29
constexpr int kWarnModelPdNoDaq = 6;
// ... and from 10 s to 19.999999 s: records 11, 16, 19
constexpr int kWarnModelPdNoDaqInTime = 3;

}  // namespace caliper::log_viewer::testing
