#include "caliper/core/config.h"

#include <gtest/gtest.h>
#include <stdlib.h>
#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <string>
#include <vector>

#include "comma_locale.h"

namespace caliper::core {
namespace {

using Type = ConfigKey::Type;

const std::vector<std::string> kKinds = {"periodic", "external"};

std::vector<ConfigKey> Schema() {
  return {
      {"exec.rate", Type::kDouble, "100", "tick rate [Hz]", 0.1, 1000},
      {"exec.kind", Type::kString, "periodic", "execution context kind", 0, 0, kKinds},
      {"log.level", Type::kString, "info", "console log level"},
      {"queue.depth", Type::kInt, "8", "queue length [records]", 1, 64},
      {"gui.enabled", Type::kBool, "false", "show the window"},
  };
}

// a temporary file that is removed again
class TempFile {
 public:
  explicit TempFile(const std::string& text) {
    char name[] = "/tmp/caliper_config_test_XXXXXX";
    const int fd = mkstemp(name);
    EXPECT_GE(fd, 0);
    close(fd);
    path_ = name;
    std::ofstream(path_) << text;
  }
  ~TempFile() { unlink(path_.c_str()); }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

// the message of the ConfigError that `fn` throws ("" when it throws none)
template <typename Fn>
std::string ErrorOf(Fn fn) {
  try {
    fn();
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(ConfigTest, ReturnsDefaultsBeforeAnythingIsSet) {
  Config config(Schema());
  EXPECT_DOUBLE_EQ(config.GetDouble("exec.rate"), 100.0);
  EXPECT_EQ(config.GetString("exec.kind"), "periodic");
  EXPECT_EQ(config.GetInt("queue.depth"), 8);
  EXPECT_FALSE(config.GetBool("gui.enabled"));
  EXPECT_TRUE(config.warnings().empty());
}

TEST(ConfigTest, ConvertsTypedValues) {
  Config config(Schema());
  config.Set("exec.rate", "250.5", "test");
  config.Set("queue.depth", "+42", "test");
  config.Set("gui.enabled", "Yes", "test");
  EXPECT_DOUBLE_EQ(config.GetDouble("exec.rate"), 250.5);
  EXPECT_EQ(config.GetInt("queue.depth"), 42);
  EXPECT_TRUE(config.GetBool("gui.enabled"));
}

TEST(ConfigTest, AcceptsEveryBoolSpelling) {
  Config config(Schema());
  for (const char* text : {"true", "TRUE", "yes", "on", "1"}) {
    config.Set("gui.enabled", text, "test");
    EXPECT_TRUE(config.GetBool("gui.enabled")) << text;
  }
  for (const char* text : {"false", "False", "no", "OFF", "0"}) {
    config.Set("gui.enabled", text, "test");
    EXPECT_FALSE(config.GetBool("gui.enabled")) << text;
  }
}

TEST(ConfigTest, HasOnlyDeclaredKeys) {
  Config config(Schema());
  EXPECT_TRUE(config.Has("exec.rate"));
  EXPECT_FALSE(config.Has("exec.speed"));
  EXPECT_EQ(ErrorOf([&] { config.GetString("exec.speed"); }),
            "no configuration key 'exec.speed' is declared");
}

TEST(ConfigTest, AddKeysExtendsTheSchemaWithDefaults) {
  Config config(Schema());
  config.AddKeys({{"model.mass", Type::kDouble, "2.5", "mass [kg]", 0, 100}});
  EXPECT_TRUE(config.Has("model.mass"));
  EXPECT_DOUBLE_EQ(config.GetDouble("model.mass"), 2.5);
  EXPECT_NE(ErrorOf([&] { config.Set("model.mass", "-1", "test"); }), "");
}

TEST(ConfigTest, LoadsFileWithCommentsAndBlankLines) {
  TempFile file(
      "# a comment line\n"
      "\n"
      "exec.rate = 50   # trailing comment\n"
      "   exec.kind=external\r\n"
      "\t\n"
      "log.level = a value with spaces\n"
      "gui.enabled = on\n");
  Config config(Schema());
  config.LoadFile(file.path());
  EXPECT_DOUBLE_EQ(config.GetDouble("exec.rate"), 50.0);
  EXPECT_EQ(config.GetString("exec.kind"), "external");
  EXPECT_EQ(config.GetString("log.level"), "a value with spaces");
  EXPECT_TRUE(config.GetBool("gui.enabled"));
  EXPECT_EQ(config.GetInt("queue.depth"), 8);  // untouched keys keep their default
  EXPECT_TRUE(config.warnings().empty());
}

TEST(ConfigTest, LaterValuesOverrideEarlierOnes) {
  TempFile file("queue.depth = 4\nqueue.depth = 5\n");
  Config config(Schema());
  config.LoadFile(file.path());
  EXPECT_EQ(config.GetInt("queue.depth"), 5);
  config.SetAssignment("queue.depth=6", "-o");
  EXPECT_EQ(config.GetInt("queue.depth"), 6);
}

TEST(ConfigTest, RejectsMissingFile) {
  Config config(Schema());
  EXPECT_EQ(ErrorOf([&] { config.LoadFile("/nonexistent/caliper.conf"); }),
            "/nonexistent/caliper.conf: cannot open configuration file");
}

TEST(ConfigTest, ParsesAssignments) {
  Config config(Schema());
  config.SetAssignment("exec.rate=20", "-o");
  config.SetAssignment("  log.level =  debug ", "-o");
  config.SetAssignment("log.level=a=b", "-o");  // only the first '=' separates
  EXPECT_DOUBLE_EQ(config.GetDouble("exec.rate"), 20.0);
  EXPECT_EQ(config.GetString("log.level"), "a=b");
}

TEST(ConfigTest, RejectsAssignmentWithoutEquals) {
  Config config(Schema());
  EXPECT_EQ(ErrorOf([&] { config.SetAssignment("exec.rate", "-o"); }),
            "-o: 'exec.rate' is not of the form key=value");
}

TEST(ConfigTest, WarnsAboutUnknownKeys) {
  TempFile file("exec.rate = 10\nexec.speed = 3\n");
  Config config(Schema());
  config.LoadFile(file.path());
  config.SetAssignment("no.such=1", "-o");
  ASSERT_EQ(config.warnings().size(), 2u);
  EXPECT_EQ(config.warnings()[0], file.path() + ":2: unknown key 'exec.speed' (ignored)");
  EXPECT_EQ(config.warnings()[1], "-o: unknown key 'no.such' (ignored)");
  EXPECT_FALSE(config.Has("exec.speed"));
  EXPECT_DOUBLE_EQ(config.GetDouble("exec.rate"), 10.0);  // the rest of the file still applies
}

TEST(ConfigTest, RejectsBadValueInFileNamingFileLineKeyAndReason) {
  TempFile file("# rates\nexec.rate = 10\nexec.rate = fast\n");
  Config config(Schema());
  const std::string message = ErrorOf([&] { config.LoadFile(file.path()); });
  EXPECT_EQ(message, file.path() +
                         ":3: exec.rate = 'fast': expected a finite number (allowed 0.1 .. 1000); "
                         "exec.rate is tick rate [Hz]");
}

TEST(ConfigTest, RejectsLineWithoutEqualsInFile) {
  TempFile file("exec.rate = 10\n\njust words\n");
  Config config(Schema());
  EXPECT_EQ(ErrorOf([&] { config.LoadFile(file.path()); }),
            file.path() + ":3: 'just words' is not of the form key=value");
}

TEST(ConfigTest, RejectsNonInteger) {
  Config config(Schema());
  for (const char* bad : {"", "abc", "4.5", "12abc", "1e3", "0x10"}) {
    const std::string message = ErrorOf([&] { config.Set("queue.depth", bad, "-o"); });
    EXPECT_EQ(message, std::string("-o: queue.depth = '") + bad +
                           "': expected an integer (allowed 1 .. 64); queue.depth is queue "
                           "length [records]")
        << bad;
  }
  EXPECT_EQ(config.GetInt("queue.depth"), 8);  // a rejected value changes nothing
}

TEST(ConfigTest, RejectsNonFiniteOrMalformedNumber) {
  Config config(Schema());
  for (const char* bad : {"", "nan", "inf", "-inf", "1e999", "10 Hz", "ten"}) {
    EXPECT_NE(ErrorOf([&] { config.Set("exec.rate", bad, "-o"); }).find("expected a finite number"),
              std::string::npos)
        << bad;
  }
  EXPECT_DOUBLE_EQ(config.GetDouble("exec.rate"), 100.0);
}

TEST(ConfigTest, ReadsDecimalPointsUnderACommaDecimalLocale) {
  // a Qt process under LANG=de_DE.UTF-8 reads configuration files too
  CALIPER_COMMA_DECIMAL_LOCALE(locale);
  const TempFile file("exec.rate = 0.25\nqueue.depth = +12\n");
  Config config(Schema());
  config.LoadFile(file.path());
  EXPECT_EQ(config.GetDouble("exec.rate"), 0.25);
  EXPECT_EQ(config.GetInt("queue.depth"), 12);
  config.Set("exec.rate", "2.5e2", "-o");
  EXPECT_EQ(config.GetDouble("exec.rate"), 250.0);
  // the locale's own spelling is not ours, and bounds print with a point
  EXPECT_EQ(ErrorOf([&] { config.Set("exec.rate", "2,5", "-o"); }),
            "-o: exec.rate = '2,5': expected a finite number (allowed 0.1 .. 1000); exec.rate is "
            "tick rate [Hz]");
}

TEST(ConfigTest, RejectsBadBool) {
  Config config(Schema());
  EXPECT_EQ(ErrorOf([&] { config.Set("gui.enabled", "maybe", "f.conf:7"); }),
            "f.conf:7: gui.enabled = 'maybe': expected true or false; gui.enabled is show the "
            "window");
  EXPECT_FALSE(config.GetBool("gui.enabled"));
}

TEST(ConfigTest, EnforcesInclusiveBounds) {
  Config config(Schema());
  config.Set("queue.depth", "1", "-o");
  EXPECT_EQ(config.GetInt("queue.depth"), 1);
  config.Set("queue.depth", "64", "-o");
  EXPECT_EQ(config.GetInt("queue.depth"), 64);
  config.Set("exec.rate", "0.1", "-o");
  EXPECT_DOUBLE_EQ(config.GetDouble("exec.rate"), 0.1);
  config.Set("exec.rate", "1000", "-o");

  EXPECT_EQ(ErrorOf([&] { config.Set("queue.depth", "65", "-o"); }),
            "-o: queue.depth = '65': out of range (allowed 1 .. 64); queue.depth is queue length "
            "[records]");
  EXPECT_EQ(ErrorOf([&] { config.Set("queue.depth", "0", "-o"); }),
            "-o: queue.depth = '0': out of range (allowed 1 .. 64); queue.depth is queue length "
            "[records]");
  EXPECT_EQ(ErrorOf([&] { config.Set("exec.rate", "0.05", "-o"); }),
            "-o: exec.rate = '0.05': out of range (allowed 0.1 .. 1000); exec.rate is tick rate "
            "[Hz]");
  EXPECT_NE(ErrorOf([&] { config.Set("exec.rate", "1000.001", "-o"); }).find("out of range"),
            std::string::npos);
  EXPECT_EQ(config.GetInt("queue.depth"), 64);
  EXPECT_DOUBLE_EQ(config.GetDouble("exec.rate"), 1000.0);
}

TEST(ConfigTest, RestrictsStringToChoices) {
  Config config(Schema());
  config.Set("exec.kind", "external", "-o");
  EXPECT_EQ(config.GetString("exec.kind"), "external");
  EXPECT_EQ(ErrorOf([&] { config.Set("exec.kind", "Periodic", "-o"); }),
            "-o: exec.kind = 'Periodic': expected one of periodic external; exec.kind is "
            "execution context kind");
  EXPECT_EQ(config.GetString("exec.kind"), "external");
}

TEST(ConfigTest, AcceptsAnyStringWithoutChoices) {
  Config config(Schema());
  config.Set("log.level", "", "-o");
  EXPECT_EQ(config.GetString("log.level"), "");
  config.Set("log.level", "anything at all", "-o");
  EXPECT_EQ(config.GetString("log.level"), "anything at all");
}

TEST(ConfigTest, ItemsListsEveryKeyInSchemaOrder) {
  Config config(Schema());
  config.Set("queue.depth", "3", "-o");
  config.Set("unknown.key", "3", "-o");
  const auto items = config.Items();
  ASSERT_EQ(items.size(), 5u);
  EXPECT_EQ(items[0], std::make_pair(std::string("exec.rate"), std::string("100")));
  EXPECT_EQ(items[3], std::make_pair(std::string("queue.depth"), std::string("3")));
  EXPECT_EQ(items[4].first, "gui.enabled");
}

TEST(ConfigTest, HelpListsEveryKeyWithTypeDefaultAndHelp) {
  Config config(Schema());
  const std::string help = config.Help();
  EXPECT_NE(help.find("  exec.rate    tick rate [Hz] (number in [0.1, 1000], default '100')\n"), std::string::npos)
      << help;
  EXPECT_NE(help.find("  exec.kind    execution context kind (string one of "
                      "periodic|external, default 'periodic')\n"),
            std::string::npos)
      << help;
  EXPECT_NE(help.find("  queue.depth  queue length [records] (integer in [1, 64], default '8')\n"),
            std::string::npos)
      << help;
  EXPECT_NE(help.find("  gui.enabled  show the window (true|false, default 'false')\n"),
            std::string::npos)
      << help;
  EXPECT_NE(help.find("log.level"), std::string::npos);
  // one line per key
  EXPECT_EQ(std::count(help.begin(), help.end(), '\n'), 5);
}

TEST(ConfigTest, HelpShowsDefaultsNotCurrentValues) {
  Config config(Schema());
  config.Set("queue.depth", "33", "-o");
  EXPECT_EQ(config.Help().find("33"), std::string::npos);
}

TEST(TrimTest, RemovesSurroundingWhiteSpaceOnly) {
  EXPECT_EQ(Trim("  a b \t\r\n"), "a b");
  EXPECT_EQ(Trim(" \t "), "");
  EXPECT_EQ(Trim(""), "");
  EXPECT_EQ(Trim("x"), "x");
}

}  // namespace
}  // namespace caliper::core
