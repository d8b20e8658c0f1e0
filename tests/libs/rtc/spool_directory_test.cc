// Spooled log records are kept per session: a component's spool folder depends on its session's
// naming service, so records a Model spooled while one session's logger was gone are never
// replayed into the next session's log (they stay in the first session's folder).

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "caliper/rtc/log_service_sink.h"

namespace caliper::rtc {
namespace {

const std::string kMonday =
    "corbaname:omniunix:/home/ada/.local/state/caliper/sessions/20261130-090000-s11/sock/"
    "naming.sock";
const std::string kTuesday =
    "corbaname:omniunix:/home/ada/.local/state/caliper/sessions/20261201-090000-s12/sock/"
    "naming.sock";

TEST(SessionSpoolDirectoryTest, OneFolderPerSessionBelowTheBase) {
  const std::string monday = SessionSpoolDirectory("/spool", kMonday);
  const std::string tuesday = SessionSpoolDirectory("/spool", kTuesday);
  EXPECT_NE(monday, tuesday);
  EXPECT_EQ(monday, SessionSpoolDirectory("/spool", kMonday));  // stable: orphans are found again
  EXPECT_EQ(std::filesystem::path(monday).parent_path(), "/spool");
  EXPECT_EQ(std::filesystem::path(tuesday).parent_path(), "/spool");
}

TEST(SessionSpoolDirectoryTest, AFileNameThatSaysWhichSession) {
  const std::string name = std::filesystem::path(SessionSpoolDirectory("/s", kMonday)).filename();
  EXPECT_NE(name.find("20261130-090000-s11"), std::string::npos) << name;
  EXPECT_EQ(name.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                                   "0123456789._-"),
            std::string::npos)
      << name;
  EXPECT_LE(name.size(), 48u + 1 + 16);
}

TEST(SessionSpoolDirectoryTest, AddressesThatLookAlikeStayApart) {
  // the readable part alone would be equal ('/' and ':' both become '_'): the hash tells them apart
  EXPECT_NE(SessionSpoolDirectory("/s", "corbaname::head:2809"),
            SessionSpoolDirectory("/s", "corbaname::head/2809"));
  EXPECT_NE(SessionSpoolDirectory("/s", "corbaname::10.0.0.1:2809"),
            SessionSpoolDirectory("/s", "corbaname::10.0.0.2:2809"));
}

}  // namespace
}  // namespace caliper::rtc
