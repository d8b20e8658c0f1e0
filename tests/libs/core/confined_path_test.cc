// Paths from clients confined to directories: `..`, absolute paths outside, symbolic links
// leading out or staying in, files to be written, and directories named like a prefix.
#include "caliper/core/confined_path.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "support/process.h"

namespace caliper::core {
namespace {

namespace fs = std::filesystem;
using Access = ConfinedPaths::Access;

bool Contains(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

// the message of the PathRefused that Resolve throws ("" when it accepts the path)
std::string Refusal(const ConfinedPaths& c, const std::string& path, Access access) {
  try {
    c.Resolve(path, access);
    return "";
  } catch (const PathRefused& e) {
    return e.what();
  }
}

// root/allowed (a scene, a sub-directory, links), root/allowed-evil, root/outside
class ConfinedPathsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::canonical(tmp_.path()).string();
    allowed_ = root_ + "/allowed";
    fs::create_directories(allowed_ + "/sub");
    fs::create_directories(root_ + "/allowed-evil");
    fs::create_directories(root_ + "/outside");
    std::ofstream(allowed_ + "/scene.dae") << "inside\n";
    std::ofstream(allowed_ + "/sub/deeper.dae") << "inside\n";
    std::ofstream(root_ + "/allowed-evil/scene.dae") << "evil\n";
    std::ofstream(root_ + "/outside/secret.dae") << "secret\n";
  }

  ConfinedPaths Allowed() const { return ConfinedPaths({allowed_}, "test.dirs", "tests read"); }

  caliper::testing::TempDir tmp_;
  std::string root_;
  std::string allowed_;
};

TEST_F(ConfinedPathsTest, AcceptsAFileInsideAndResolvesRelativePathsAgainstTheFirstDirectory) {
  const ConfinedPaths c({allowed_, root_ + "/outside"}, "test.dirs", "tests read");
  EXPECT_EQ(c.Resolve(allowed_ + "/scene.dae", Access::kRead), fs::path(allowed_ + "/scene.dae"));
  EXPECT_EQ(c.Resolve("scene.dae", Access::kRead), fs::path(allowed_ + "/scene.dae"));
  EXPECT_EQ(c.Resolve("sub/./deeper.dae", Access::kRead), fs::path(allowed_ + "/sub/deeper.dae"));
  EXPECT_EQ(c.Resolve(allowed_ + "/sub/../scene.dae", Access::kRead),
            fs::path(allowed_ + "/scene.dae"));
  // the second directory is allowed too, by absolute path
  EXPECT_EQ(c.Resolve(root_ + "/outside/secret.dae", Access::kRead),
            fs::path(root_ + "/outside/secret.dae"));
}

TEST_F(ConfinedPathsTest, RefusesDotDotLeadingOut) {
  const ConfinedPaths c = Allowed();
  for (const std::string& path :
       {std::string("../outside/secret.dae"), allowed_ + "/../outside/secret.dae",
        allowed_ + "/sub/../../outside/secret.dae",
        allowed_ + "/missing/../../outside/secret.dae"}) {
    const std::string why = Refusal(c, path, Access::kRead);
    EXPECT_TRUE(Contains(why, "is outside the directories where tests read"))
        << path << ": " << why;
    EXPECT_TRUE(Contains(why, "'" + path + "'")) << why;
    EXPECT_TRUE(Contains(why, "resolved: '" + root_ + "/outside/secret.dae'")) << why;
    EXPECT_FALSE(c.Allows(path, Access::kWrite)) << path;
  }
}

TEST_F(ConfinedPathsTest, RefusesAnAbsolutePathOutsideNamingTheDirectoriesAndTheKey) {
  const ConfinedPaths c = Allowed();
  const std::string why = Refusal(c, "/etc/passwd", Access::kRead);
  EXPECT_EQ(why, "'/etc/passwd' is outside the directories where tests read (" + allowed_ +
                     "; set by test.dirs)");
  EXPECT_FALSE(c.Allows("/etc/passwd", Access::kWrite));
  EXPECT_FALSE(c.Allows(root_ + "/outside/new.dae", Access::kWrite));
}

TEST_F(ConfinedPathsTest, RefusesADirectoryNamedLikeAPrefix) {
  const ConfinedPaths c = Allowed();
  EXPECT_TRUE(Contains(Refusal(c, root_ + "/allowed-evil/scene.dae", Access::kRead),
                       "is outside the directories"));
  EXPECT_FALSE(c.Allows(root_ + "/allowed-evil/new.dae", Access::kWrite));
  EXPECT_FALSE(c.Allows(root_ + "/allowedx", Access::kWrite));
  EXPECT_FALSE(IsWithin("/data/allowed-evil/x", "/data/allowed"));
  EXPECT_TRUE(IsWithin("/data/allowed/x", "/data/allowed/"));
  EXPECT_TRUE(IsWithin("/data/allowed", "/data/allowed"));
  EXPECT_FALSE(IsWithin("/data", "/data/allowed"));
}

TEST_F(ConfinedPathsTest, RefusesSymbolicLinksThatLeadOut) {
  fs::create_directory_symlink(root_ + "/outside", allowed_ + "/to-outside");
  fs::create_symlink(root_ + "/outside/secret.dae", allowed_ + "/secret.dae");
  const ConfinedPaths c = Allowed();
  for (const std::string& path : {allowed_ + "/to-outside/secret.dae", allowed_ + "/secret.dae",
                                  std::string("to-outside/secret.dae")}) {
    const std::string why = Refusal(c, path, Access::kRead);
    EXPECT_TRUE(Contains(why, "resolved: '" + root_ + "/outside/secret.dae') is outside"))
        << path << ": " << why;
    EXPECT_FALSE(c.Allows(path, Access::kWrite)) << path;
  }
  // a new file through the link to a directory outside
  EXPECT_TRUE(Contains(Refusal(c, allowed_ + "/to-outside/new.dae", Access::kWrite),
                       "is outside the directories"));
}

TEST_F(ConfinedPathsTest, AcceptsSymbolicLinksThatStayInside) {
  fs::create_directory_symlink(allowed_ + "/sub", allowed_ + "/to-sub");
  fs::create_symlink(allowed_ + "/scene.dae", allowed_ + "/alias.dae");
  const ConfinedPaths c = Allowed();
  EXPECT_EQ(c.Resolve(allowed_ + "/to-sub/deeper.dae", Access::kRead),
            fs::path(allowed_ + "/sub/deeper.dae"));
  EXPECT_EQ(c.Resolve("alias.dae", Access::kRead), fs::path(allowed_ + "/scene.dae"));
  // writing through the link writes its target, which is inside
  EXPECT_EQ(c.Resolve("alias.dae", Access::kWrite), fs::path(allowed_ + "/scene.dae"));
  EXPECT_EQ(c.Resolve("to-sub/new.dae", Access::kWrite), fs::path(allowed_ + "/sub/new.dae"));
}

TEST_F(ConfinedPathsTest, AnAllowedDirectoryReachedThroughALinkIsTheSameDirectory) {
  fs::create_directory_symlink(allowed_, root_ + "/link-to-allowed");
  const ConfinedPaths c({root_ + "/link-to-allowed"}, "test.dirs", "tests read");
  EXPECT_EQ(c.Resolve(allowed_ + "/scene.dae", Access::kRead), fs::path(allowed_ + "/scene.dae"));
  EXPECT_EQ(c.Resolve("scene.dae", Access::kRead), fs::path(allowed_ + "/scene.dae"));
  EXPECT_FALSE(c.Allows(root_ + "/outside/secret.dae", Access::kRead));
}

TEST_F(ConfinedPathsTest, AcceptsANewFileToBeWrittenInAnAllowedDirectory) {
  const ConfinedPaths c = Allowed();
  EXPECT_EQ(c.Resolve(allowed_ + "/new.dae", Access::kWrite), fs::path(allowed_ + "/new.dae"));
  EXPECT_EQ(c.Resolve("sub/new.png", Access::kWrite), fs::path(allowed_ + "/sub/new.png"));
  EXPECT_EQ(c.Resolve(allowed_ + "/scene.dae", Access::kWrite), fs::path(allowed_ + "/scene.dae"));
  // a missing file to read is the reader's to report
  EXPECT_EQ(c.Resolve(allowed_ + "/new.dae", Access::kRead), fs::path(allowed_ + "/new.dae"));
}

TEST_F(ConfinedPathsTest, RefusesADanglingLinkThatWritingWouldFollowOut) {
  fs::create_symlink(root_ + "/outside/created-by-the-model.dae", allowed_ + "/dangling.dae");
  const ConfinedPaths c = Allowed();
  const std::string why = Refusal(c, allowed_ + "/dangling.dae", Access::kWrite);
  EXPECT_TRUE(Contains(why, "is a symbolic link to a missing target")) << why;
  EXPECT_FALSE(c.Allows(allowed_ + "/dangling.dae", Access::kRead));
  EXPECT_FALSE(fs::exists(root_ + "/outside/created-by-the-model.dae"));
}

TEST_F(ConfinedPathsTest, RefusesWritingAFileWithOtherHardLinks) {
  fs::create_hard_link(allowed_ + "/scene.dae", allowed_ + "/second-name.dae");
  const ConfinedPaths c = Allowed();
  EXPECT_TRUE(Contains(Refusal(c, allowed_ + "/scene.dae", Access::kWrite), "other hard links"));
  EXPECT_TRUE(c.Allows(allowed_ + "/scene.dae", Access::kRead));
}

TEST_F(ConfinedPathsTest, ForAReaderOfUrisRefusesNamesAUriReadsOtherwise) {
  // Collada-DOM opens 'link#x' as 'link' and 'a%20b' as 'a b': the file checked must be the one
  // opened
  const ConfinedPaths uri({allowed_}, "test.dirs", "tests read", true);
  fs::create_symlink(root_ + "/outside/secret.dae", allowed_ + "/link");
  for (const std::string& name :
       std::vector<std::string>{"link#x", "link?x", "scene%2edae", "a%20b.dae"}) {
    const std::string why = Refusal(uri, name, Access::kWrite);
    EXPECT_TRUE(Contains(why, "'" + name + "' (resolved: '" + allowed_ + "/" + name + "') holds '"))
        << why;
    EXPECT_TRUE(Contains(why,
                         "tests read with a library that reads file names as URIs, which "
                         "would open another file; give a name without '#', '?' or '%' (" +
                             allowed_ + "; set by test.dirs)"))
        << why;
    EXPECT_FALSE(uri.Allows(allowed_ + "/" + name, Access::kRead));
    // a reader of file names takes them as they are
    EXPECT_EQ(Refusal(Allowed(), name, Access::kWrite), "") << name;
  }
  // a link inside whose target's name holds one
  std::ofstream(allowed_ + "/odd#name.dae") << "inside\n";
  fs::create_symlink(allowed_ + "/odd#name.dae", allowed_ + "/plain.dae");
  EXPECT_TRUE(Contains(Refusal(uri, "plain.dae", Access::kRead), "holds '#'"));
  EXPECT_EQ(Refusal(uri, "scene.dae", Access::kRead), "");
}

TEST_F(ConfinedPathsTest, RefusesDirectoriesEmptyPathsAndAnEmptyConfiguration) {
  const ConfinedPaths c = Allowed();
  EXPECT_TRUE(Contains(Refusal(c, allowed_, Access::kWrite), "names the directory")) << allowed_;
  EXPECT_TRUE(Contains(Refusal(c, allowed_ + "/", Access::kRead), "names the directory"));
  EXPECT_EQ(Refusal(c, allowed_ + "/sub", Access::kRead),
            "'" + allowed_ + "/sub' is not a regular file (" + allowed_ + "; set by test.dirs)");
  EXPECT_TRUE(Contains(Refusal(c, allowed_ + "/sub", Access::kWrite), "is not a regular file"));
  EXPECT_TRUE(Contains(Refusal(c, "", Access::kRead), "an empty path is refused"));
  const std::string why = Refusal(c, allowed_ + "/" + std::string(10 << 20, 'x'), Access::kWrite);
  EXPECT_TRUE(Contains(why, "bytes is refused: longer than any the system opens")) << why.size();
  EXPECT_LT(why.size(), 1000u);

  const ConfinedPaths none({}, "model.write_dir", "the Model writes scenes");
  EXPECT_EQ(Refusal(none, "/tmp/x.dae", Access::kWrite),
            "'/tmp/x.dae' is refused: no directory is configured where the Model writes scenes "
            "(set model.write_dir)");
  EXPECT_EQ(none.Describe(), "none");
}

TEST(SplitSearchPathTest, SplitsAtColonsAndDropsEmptyEntries) {
  EXPECT_EQ(SplitSearchPath("/a:/b c: :/d:"), (std::vector<std::string>{"/a", "/b c", "/d"}));
  EXPECT_TRUE(SplitSearchPath("").empty());
  EXPECT_EQ(ConfinedPaths({"/a/b/", "", "/"}, "k", "w").dirs(),
            (std::vector<std::string>{"/a/b", "/"}));
}

}  // namespace
}  // namespace caliper::core
