// What Collada-DOM is given is checked first: a .zae whose entries would be extracted outside the
// DOM's temporary directory (zip-slip), whose manifest names a document outside it, or that would
// send the DOM into endless recursion is refused naming the entry; a file name that the DOM reads
// as a URI ('#', '?', '%XX') is refused instead of opening or writing another file. The archives
// are written here with minizip, the library the DOM extracts with; every file stays in a temporary
// directory (TMPDIR points the DOM's extraction there too).
#include <gtest/gtest.h>
#include <stdlib.h>
#include <zip.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "caliper/collada/exporter.h"
#include "caliper/collada/importer.h"

namespace caliper::collada {
namespace {

namespace fs = std::filesystem;

bool Contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

std::string ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string Source(const std::string& relative) {
  const char* dir = std::getenv("CALIPER_SOURCE_DIR");
  return std::string(dir != nullptr ? dir : ".") + "/" + relative;
}

struct Entry {
  std::string name;
  std::string content;
  bool symlink = false;
};

// a zip archive of `entries` in that order, names taken as they are
void WriteZip(const std::string& path, const std::vector<Entry>& entries) {
  zipFile zip = zipOpen64(path.c_str(), APPEND_STATUS_CREATE);
  ASSERT_NE(zip, nullptr) << path;
  for (const Entry& e : entries) {
    zip_fileinfo info{};
    // made on Unix (3), file type and mode in the high half of the external attributes
    info.external_fa = static_cast<uLong>(e.symlink ? 0120777 : 0100644) << 16;
    ASSERT_EQ(zipOpenNewFileInZip4(zip, e.name.c_str(), &info, nullptr, 0, nullptr, 0, nullptr,
                                   Z_DEFLATED, 6, 0, -MAX_WBITS, DEF_MEM_LEVEL, Z_DEFAULT_STRATEGY,
                                   nullptr, 0, (3 << 8) | 20, 0),
              ZIP_OK)
        << e.name;
    ASSERT_EQ(zipWriteInFileInZip(zip, e.content.data(), static_cast<unsigned>(e.content.size())),
              ZIP_OK);
    ASSERT_EQ(zipCloseFileInZip(zip), ZIP_OK);
  }
  ASSERT_EQ(zipClose(zip, nullptr), ZIP_OK);
}

std::string Zip(const std::string& path, const std::vector<Entry>& entries) {
  WriteZip(path, entries);
  return ReadFile(path);
}

std::string Manifest(const std::string& root) {
  return "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n<dae_root>" + root + "</dae_root>\n";
}

// root/a/b is $TMPDIR, where the DOM makes its extraction directory: an entry '../../x' would land
// in root/a, still inside root
class DomPathsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    char pattern[] = "/tmp/caliper-dom-paths-XXXXXX";
    ASSERT_NE(mkdtemp(pattern), nullptr);
    root_ = pattern;
    fs::create_directories(root_ + "/a/b");
    fs::create_directories(root_ + "/in");
    const char* tmp = std::getenv("TMPDIR");
    if (tmp != nullptr) old_tmp_ = tmp;
    had_tmp_ = tmp != nullptr;
    ::setenv("TMPDIR", (root_ + "/a/b").c_str(), 1);
    pendulum_ = ReadFile(Source("models/pendulum_tendon.dae"));
    ASSERT_FALSE(pendulum_.empty());
  }
  void TearDown() override {
    if (had_tmp_) {
      ::setenv("TMPDIR", old_tmp_.c_str(), 1);
    } else {
      ::unsetenv("TMPDIR");
    }
    std::error_code ignored;
    fs::remove_all(root_, ignored);
  }

  /// ImportError's message for `path` ("" when it imported).
  std::string Refusal(const std::string& path) {
    try {
      Import(path, nullptr);
      return "";
    } catch (const ImportError& e) {
      return e.what();
    }
  }

  /// A .zae in root/in of the pendulum and a manifest naming it, plus `extra` entries.
  std::string Archive(const std::string& name, const std::vector<Entry>& extra) {
    std::vector<Entry> entries{{"manifest.xml", Manifest("./pendulum.dae")},
                               {"pendulum.dae", pendulum_}};
    entries.insert(entries.end(), extra.begin(), extra.end());
    const std::string path = root_ + "/in/" + name;
    WriteZip(path, entries);
    return path;
  }

  std::string root_;
  std::string old_tmp_;
  bool had_tmp_ = false;
  std::string pendulum_;
};

TEST_F(DomPathsTest, AcceptsAnArchiveWhoseEntriesStayInside) {
  const std::string path = Archive("fine.zae", {{"meshes/", ""}, {"meshes/readme.txt", "hello"}});
  EXPECT_EQ(Refusal(path), "");
  const sgal::Scene scene = Import(path, nullptr);
  EXPECT_EQ(scene.bodies.size(), 2u);
}

TEST_F(DomPathsTest, RefusesEntriesThatLeadOutOfTheExtractionDirectory) {
  for (const std::string& name :
       {std::string("../../escaped.txt"), std::string("x/../../../escaped.txt")}) {
    const std::string path = Archive("slip.zae", {{name, "written outside\n"}});
    const std::string why = Refusal(path);
    EXPECT_TRUE(Contains(why, path + ": the archive's entry '" + name +
                                  "' is refused: its name has a '..' component"))
        << why;
    EXPECT_FALSE(fs::exists(root_ + "/a/escaped.txt")) << name;
    EXPECT_FALSE(fs::exists(root_ + "/escaped.txt")) << name;
  }
}

TEST_F(DomPathsTest, RefusesAbsoluteEmptyLongAndSymbolicLinkEntries) {
  const std::string absolute = root_ + "/absolute.txt";
  EXPECT_TRUE(Contains(Refusal(Archive("abs.zae", {{absolute, "x"}})),
                       "entry '" + absolute + "' is refused: its name is an absolute path"));
  EXPECT_FALSE(fs::exists(absolute));
  EXPECT_TRUE(Contains(Refusal(Archive("empty.zae", {{"", "x"}})),
                       "entry '' is refused: its name is empty"));
  const std::string long_name(300, 'n');
  EXPECT_TRUE(Contains(Refusal(Archive("long.zae", {{long_name, "x"}})),
                       "its name has 300 bytes, more than Collada-DOM reads (255)"));
  EXPECT_TRUE(Contains(Refusal(Archive("link.zae", {{"link.dae", "/etc/passwd", true}})),
                       "entry 'link.dae' is refused: it is a symbolic link"));
  EXPECT_TRUE(Contains(Refusal(Archive("twice.zae", {{"./manifest.xml", Manifest("x.dae")}})),
                       "entry './manifest.xml' is refused: another entry has the same name"));
}

TEST_F(DomPathsTest, RefusesAnArchiveInsideWhoseEntriesLeadOut) {
  // the DOM extracts every extracted file that is itself an archive, into a directory of its name
  const std::string inner = Zip(root_ + "/in/inner.zip", {{"../../../../nested.txt", "out\n"}});
  const std::string path = Archive("nested.zae", {{"inner.zip", inner}});
  const std::string why = Refusal(path);
  EXPECT_TRUE(Contains(why,
                       "entry 'inner.zip/../../../../nested.txt' is refused: its name has a "
                       "'..' component"))
      << why;
  EXPECT_FALSE(fs::exists(root_ + "/nested.txt"));
  EXPECT_FALSE(fs::exists(root_ + "/a/nested.txt"));
  // archives nested deeper than the limit
  std::string deep = Zip(root_ + "/in/d0.zip", {{"leaf.txt", "leaf"}});
  for (int i = 1; i <= 3; ++i)
    deep = Zip(root_ + "/in/d" + std::to_string(i) + ".zip", {{"d.zip", deep}});
  EXPECT_TRUE(Contains(Refusal(Archive("deep.zae", {{"d.zip", deep}})),
                       "entry 'd.zip/d.zip/d.zip/d.zip' is refused: it is an "
                       "archive nested more than "
                       "3 "
                       "deep"));
}

TEST_F(DomPathsTest, RefusesAManifestNamingADocumentOutsideTheArchive) {
  // a scene outside that a manifest could make the DOM read (and a client then export)
  std::ofstream(root_ + "/a/outside.dae") << pendulum_;
  const std::string up = root_ + "/in/up.zae";
  WriteZip(up, {{"manifest.xml", Manifest("../../outside.dae")}, {"pendulum.dae", pendulum_}});
  EXPECT_TRUE(Contains(Refusal(up),
                       "the archive's manifest.xml is refused: its <dae_root> "
                       "'../../outside.dae' has a '..' component"))
      << Refusal(up);
  const std::string absolute = root_ + "/in/absolute.zae";
  WriteZip(absolute,
           {{"manifest.xml", Manifest(root_ + "/a/outside.dae")}, {"pendulum.dae", pendulum_}});
  EXPECT_TRUE(Contains(Refusal(absolute), "is an absolute path")) << Refusal(absolute);
  const std::string escaped = root_ + "/in/escaped.zae";
  WriteZip(escaped,
           {{"manifest.xml", Manifest("%2e%2e/%2e%2e/outside.dae")}, {"pendulum.dae", pendulum_}});
  EXPECT_TRUE(Contains(Refusal(escaped), "holds '#', '?' or '%'")) << Refusal(escaped);
}

TEST_F(DomPathsTest, RefusesAManifestTheDomWouldRecurseOnWithoutEnd) {
  // the DOM compares the first element with dae_root and calls itself again on the same node
  const std::string path = root_ + "/in/wrapped.zae";
  WriteZip(path, {{"manifest.xml", "<manifest><dae_root>./pendulum.dae</dae_root></manifest>"},
                  {"pendulum.dae", pendulum_}});
  EXPECT_TRUE(Contains(Refusal(path), "its first element is <manifest>, not <dae_root>"))
      << Refusal(path);
  const std::string none = root_ + "/in/none.zae";
  WriteZip(none, {{"pendulum.dae", pendulum_}});
  EXPECT_TRUE(Contains(Refusal(none), "the archive has no manifest.xml")) << Refusal(none);
}

TEST_F(DomPathsTest, RefusesADocumentInsideThatWouldCrashTheDom) {
  // the DOM unzips a .zae itself: the .dae inside gets the libxml2 check a .dae file gets, before
  // the DOM reads it (a <p> inside a <p> made it dereference a null pointer)
  const std::string crash = ReadFile(Source("tests/data/collada/malformed_p_inside_p.dae"));
  ASSERT_NE(crash.find("<p>0 1 2<p/></p>"), std::string::npos);
  const std::string path = root_ + "/in/crash.zae";
  WriteZip(path, {{"manifest.xml", Manifest("./scene/robot.dae")},
                  {"scene/", ""},
                  {"scene/robot.dae", crash}});
  std::string why = Refusal(path);
  EXPECT_TRUE(Contains(why, path + ": the archive's entry 'scene/robot.dae' is refused: line 28: "
                                   "<p> inside <p>: COLLADA does not nest this element in itself"))
      << why;
  // any .dae the DOM extracts, not only the root document, also inside an archive inside
  why = Refusal(Archive("other.zae", {{"extra/", ""}, {"extra/other.DAE", crash}}));
  EXPECT_TRUE(Contains(why, "entry 'extra/other.DAE' is refused: line 28: <p> inside <p>")) << why;
  const std::string inner = Zip(root_ + "/in/inner.zip", {{"deep.dae", crash}});
  why = Refusal(Archive("nested_crash.zae", {{"inner.zip", inner}}));
  EXPECT_TRUE(Contains(why, "entry 'inner.zip/deep.dae' is refused: line 28: <p> inside <p>"))
      << why;
  // a root document whose name does not end in .dae
  const std::string named = root_ + "/in/named.zae";
  WriteZip(named, {{"manifest.xml", Manifest("scene.xml")}, {"scene.xml", crash}});
  why = Refusal(named);
  EXPECT_TRUE(Contains(why, "entry 'scene.xml' is refused: line 28: <p> inside <p>")) << why;
  // malformed XML (the DOM's reader can loop on some) with libxml2's reason and line
  const std::string broken = root_ + "/in/broken.zae";
  WriteZip(broken,
           {{"manifest.xml", Manifest("a.dae")}, {"a.dae", "<COLLADA>\n<asset>\n</COLLADA>"}});
  why = Refusal(broken);
  EXPECT_TRUE(Contains(why, "entry 'a.dae' is refused: line 3: malformed XML: ")) << why;
  // the same scene without the inner <p> loads from an archive
  std::string fixed = crash;
  fixed.replace(fixed.find("<p>0 1 2<p/></p>"), 16, "<p>0 1 2</p>");
  const std::string fine = root_ + "/in/fixed.zae";
  WriteZip(fine, {{"manifest.xml", Manifest("./scene/robot.dae")},
                  {"scene/", ""},
                  {"scene/robot.dae", fixed}});
  EXPECT_EQ(Refusal(fine), "");
}

TEST_F(DomPathsTest, RefusesFileNamesTheDomReadsAsUris) {
  // the file named holds the pendulum; the file the DOM would open instead holds another scene
  const std::string arm = ReadFile(Source("models/two_link_antagonistic.dae"));
  ASSERT_FALSE(arm.empty());
  for (const auto& [named, opened] :
       std::vector<std::pair<std::string, std::string>>{{"scene#part.dae", "scene"},
                                                        {"scene?x.dae", "scene"},
                                                        {"my%20scene.dae", "my scene.dae"},
                                                        {"other%2edae", "other.dae"}}) {
    std::ofstream(root_ + "/in/" + named) << pendulum_;
    std::ofstream(root_ + "/in/" + opened) << arm;
    const std::string why = Refusal(root_ + "/in/" + named);
    EXPECT_TRUE(Contains(why, "which Collada-DOM reads as part of a URI")) << named << ": " << why;
  }
  // a scene written through such a name would go to another file
  const sgal::Scene scene = Import(root_ + "/in/scene", nullptr);
  fs::create_directory(root_ + "/out");
  for (const char* name : {"saved#x.dae", "saved?x.dae", "saved%41.dae"}) {
    try {
      Export(scene, root_ + "/out/" + name);
      ADD_FAILURE() << name << " was written";
    } catch (const ExportError& e) {
      EXPECT_TRUE(Contains(e.what(), "which Collada-DOM reads as part of a URI")) << e.what();
    }
  }
  EXPECT_TRUE(fs::is_empty(root_ + "/out")) << "nothing written, not even an empty file";
  // a first component with ':' is read as a URI scheme
  const fs::path cwd = fs::current_path();
  fs::current_path(root_ + "/in");
  fs::create_directory("file:");
  std::ofstream("file:/x.dae") << pendulum_;
  const std::string why = Refusal("file:/x.dae");
  fs::current_path(cwd);
  EXPECT_TRUE(Contains(why, "reads as a URI scheme")) << why;
}

}  // namespace
}  // namespace caliper::collada
