// Paths sent to a real caliper-model over CORBA stay in its directories: load_scene reads only
// below model.read_dirs and the write directory, save_scene writes only below model.write_dir;
// `..`, absolute paths outside, links leading out and a directory named like a prefix are
// refused with the reason, and nothing is written outside. caliper-ctl load and save still work
// on any local file: they go by content when the Model would refuse the path.
#include <gtest/gtest.h>
#include <stdlib.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "caliper/model.hh"
#include "caliper/rtc/client_orb.h"
#include "corpus.h"
#include "support/corba.h"
#include "support/process.h"

namespace caliper::testing {
namespace {

namespace fs = std::filesystem;
namespace M = ::Caliper::Simulation;
namespace D = ::Caliper::Daq;

using std::chrono::seconds;

std::string Source(const std::string& relative) {
  const char* dir = std::getenv("CALIPER_SOURCE_DIR");
  return std::string(dir != nullptr ? dir : ".") + "/" + relative;
}

// root/models (the search path), root/session (the write directory), root/session-evil and
// root/outside (neither), each with a copy of the pendulum
class ConfinedFilesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::canonical(tmp_.path()).string();
    for (const char* d : {"models", "session", "session-evil", "outside"}) {
      fs::create_directory(root_ + "/" + d);
      fs::copy_file(Source("models/pendulum_tendon.dae"), root_ + "/" + d + "/pendulum.dae");
    }
    std::ofstream(root_ + "/outside/victim.txt") << "precious\n";
  }

  /// Starts the Model with `extra` arguments and waits until it answers.
  void StartModel(const std::vector<std::string>& extra) {
    naming_ = std::make_unique<NamingService>(root_);
    std::vector<std::string> argv{Bin("caliper-model"),
                                  "--nameservice",
                                  naming_->address(),
                                  "-o",
                                  "exec.auto_activate=true",
                                  "-o",
                                  "log.service=none",
                                  "-o",
                                  "log.spool_dir=" + root_ + "/spool"};
    argv.insert(argv.end(), extra.begin(), extra.end());
    model_ = std::make_unique<Process>(argv, root_ + "/model.out");
    ref_ = WaitForModel(rtc::ClientOrb("confined_files_test"), naming_->address(), "model0",
                        seconds(20));
    ASSERT_FALSE(CORBA::is_nil(ref_)) << model_->Output();
  }

  void StartConfinedModel() {
    StartModel({"-o", "model.read_dirs=" + root_ + "/models", "-o",
                "model.write_dir=" + root_ + "/session"});
  }

  std::string LoadRefusal(const std::string& path) {
    return caliper::testing::LoadRefusal(ref_, path);
  }

  /// InvalidParameter's reason for save_scene(path) ("" when it saved).
  std::string SaveRefusal(const std::string& path) {
    try {
      ref_->save_scene(path.c_str());
      return "";
    } catch (const D::InvalidParameter& e) {
      return e.reason.in();
    }
  }

  std::string Scene() { return LoadedScene(ref_); }

  CommandResult Ctl(const std::vector<std::string>& args) {
    return caliper::testing::Ctl(naming_->address(), args);
  }

  TempDir tmp_;
  std::string root_;
  std::unique_ptr<NamingService> naming_;
  std::unique_ptr<Process> model_;
  M::Model_var ref_;
};

TEST_F(ConfinedFilesTest, FileAccessNamesTheConfiguredDirectories) {
  StartConfinedModel();
  M::FileAccess_var files = ref_->file_access();
  ASSERT_EQ(files->read_dirs.length(), 2u);
  EXPECT_EQ(std::string(files->read_dirs[0].in()), root_ + "/models");
  EXPECT_EQ(std::string(files->read_dirs[1].in()), root_ + "/session");
  EXPECT_EQ(std::string(files->write_dir.in()), root_ + "/session");
  EXPECT_TRUE(Contains(model_->Output(), "scene paths from clients: read below " + root_ +
                                             "/models, " + root_ + "/session; written below " +
                                             root_ + "/session"))
      << model_->Output();
}

TEST_F(ConfinedFilesTest, LoadSceneReadsOnlyBelowTheSearchPath) {
  StartConfinedModel();
  EXPECT_EQ(LoadRefusal(root_ + "/models/pendulum.dae"), "");
  EXPECT_EQ(Scene(), root_ + "/models/pendulum.dae");
  EXPECT_EQ(LoadRefusal("pendulum.dae"), "") << "relative to the first read directory";
  EXPECT_EQ(LoadRefusal(root_ + "/session/pendulum.dae"), "") << "the write directory is readable";

  fs::create_symlink(root_ + "/outside/pendulum.dae", root_ + "/models/escape.dae");
  fs::create_directory_symlink(root_ + "/outside", root_ + "/models/out");
  fs::create_symlink(root_ + "/models/pendulum.dae", root_ + "/models/alias.dae");
  for (const std::string& path :
       {root_ + "/outside/pendulum.dae", root_ + "/models/../outside/pendulum.dae",
        std::string("../outside/pendulum.dae"), root_ + "/models/escape.dae",
        root_ + "/models/out/pendulum.dae", root_ + "/session-evil/pendulum.dae"}) {
    const std::string why = LoadRefusal(path);
    EXPECT_TRUE(Contains(why, "load_scene: '" + path + "'")) << path << ": " << why;
    EXPECT_TRUE(Contains(why, "is outside the directories where the Model reads scenes (" + root_ +
                                  "/models, " + root_ +
                                  "/session; set by "
                                  "model.read_dirs, model.write_dir)"))
        << why;
    EXPECT_TRUE(Contains(why, "sent by content (load_scene_data")) << why;
  }
  // the scene loaded before stays
  EXPECT_EQ(Scene(), root_ + "/session/pendulum.dae");
  EXPECT_TRUE(Contains(LoadRefusal("/etc/passwd"), "'/etc/passwd' is outside"));
  EXPECT_EQ(LoadRefusal(root_ + "/models/alias.dae"), "") << "a link that stays inside";
  EXPECT_EQ(Scene(), root_ + "/models/pendulum.dae");
  // a missing file inside: the importer's message, not a refusal
  const std::string missing = LoadRefusal(root_ + "/models/missing.dae");
  EXPECT_FALSE(Contains(missing, "load_scene:")) << missing;
  EXPECT_TRUE(Contains(missing, root_ + "/models/missing.dae")) << missing;
}

TEST_F(ConfinedFilesTest, SaveSceneWritesOnlyBelowTheWriteDirectory) {
  StartConfinedModel();
  ASSERT_EQ(LoadRefusal("pendulum.dae"), "");
  EXPECT_EQ(SaveRefusal(root_ + "/session/saved.dae"), "");
  EXPECT_TRUE(fs::is_regular_file(root_ + "/session/saved.dae"));
  EXPECT_EQ(SaveRefusal("relative.dae"), "");
  EXPECT_TRUE(fs::is_regular_file(root_ + "/session/relative.dae"));
  EXPECT_EQ(LoadRefusal(root_ + "/session/saved.dae"), "") << "what was saved loads back";

  fs::create_directory_symlink(root_ + "/outside", root_ + "/session/out");
  fs::create_symlink(root_ + "/outside/created.dae", root_ + "/session/dangling.dae");
  fs::create_symlink(root_ + "/outside/victim.txt", root_ + "/session/victim.txt");
  for (const std::string& path :
       {root_ + "/outside/victim.txt", root_ + "/outside/new.dae",
        root_ + "/session/../outside/new.dae", std::string("../outside/new.dae"),
        root_ + "/session/out/new.dae", root_ + "/session/victim.txt",
        root_ + "/session-evil/new.dae", root_ + "/models/new.dae", root_ + "/session"}) {
    const std::string why = SaveRefusal(path);
    EXPECT_TRUE(Contains(why, "save_scene: '" + path + "'")) << path << ": " << why;
    EXPECT_TRUE(Contains(why, "model.write_dir")) << why;
    EXPECT_TRUE(Contains(why, "export_scene")) << why;
  }
  EXPECT_TRUE(Contains(SaveRefusal(root_ + "/session/dangling.dae"),
                       "is a symbolic link to a missing target"));
  // nothing was written outside
  EXPECT_EQ(ReadFile(root_ + "/outside/victim.txt"), "precious\n");
  EXPECT_FALSE(fs::exists(root_ + "/outside/new.dae"));
  EXPECT_FALSE(fs::exists(root_ + "/outside/created.dae"));
  EXPECT_FALSE(fs::exists(root_ + "/session-evil/new.dae"));
  EXPECT_FALSE(fs::exists(root_ + "/models/new.dae"));
  EXPECT_TRUE(Contains(model_->Output(), "save_scene refused: '" + root_ + "/outside/victim.txt'"))
      << model_->Output();
  // a path inside that cannot be written fails with the writer's reason
  const std::string why = SaveRefusal(root_ + "/session/no-such-dir/x.dae");
  EXPECT_TRUE(Contains(why, "cannot save " + root_ + "/session/no-such-dir/x.dae")) << why;
}

TEST_F(ConfinedFilesTest, WithoutAWriteDirectoryNoPathIsWritable) {
  ::unsetenv("CALIPER_FILES_DIR");
  StartModel({"-o", "model.read_dirs=" + root_ + "/models"});
  M::FileAccess_var files = ref_->file_access();
  EXPECT_EQ(std::string(files->write_dir.in()), "");
  ASSERT_EQ(files->read_dirs.length(), 1u);
  ASSERT_EQ(LoadRefusal("pendulum.dae"), "");
  EXPECT_EQ(
      SaveRefusal(root_ + "/session/x.dae"),
      "save_scene: '" + root_ +
          "/session/x.dae' is refused: no directory is configured "
          "where the Model writes scenes (set model.write_dir); other clients fetch the scene "
          "with export_scene (as caliper-ctl save does by itself)");
  EXPECT_FALSE(fs::exists(root_ + "/session/x.dae"));
}

TEST_F(ConfinedFilesTest, TheSessionsFilesDirectoryIsTheDefaultWriteDirectory) {
  // the launcher exports its session's files/ directory (not the session's own, where the
  // session log and the naming service's data are)
  ::setenv("CALIPER_FILES_DIR", (root_ + "/session").c_str(), 1);
  StartModel({});
  ::unsetenv("CALIPER_FILES_DIR");
  M::FileAccess_var files = ref_->file_access();
  EXPECT_EQ(std::string(files->write_dir.in()), root_ + "/session");
  ASSERT_EQ(files->read_dirs.length(), 2u);
  EXPECT_EQ(std::string(files->read_dirs[0].in()), Source("models"));
  // the shipped models by name, relative to the search path
  EXPECT_EQ(LoadRefusal("ecce_arm.dae"), "");
  EXPECT_EQ(SaveRefusal("tuned.dae"), "");
  EXPECT_TRUE(fs::is_regular_file(root_ + "/session/tuned.dae"));
}

TEST_F(ConfinedFilesTest, NamesTheColladaLibraryReadsAsUrisAreRefused) {
  // Collada-DOM takes a file name as a URI: it opened 'link#x' as 'link' (cut at '#', as at '?')
  // and 'l%69nk' as 'link', so the file checked (missing, inside) was not the one written
  StartConfinedModel();
  ASSERT_EQ(LoadRefusal("pendulum.dae"), "");
  fs::create_symlink(root_ + "/outside/victim.txt", root_ + "/session/link");
  fs::create_symlink(root_ + "/outside/pendulum.dae", root_ + "/models/link");
  for (const std::string& name : {std::string("link#x"), std::string("link?x"),
                                  std::string("l%69nk"), std::string("link%20")}) {
    const std::string saved = SaveRefusal(name);
    EXPECT_TRUE(Contains(saved, "save_scene: '" + name + "' (resolved: '" + root_ + "/session/" +
                                    name + "') holds '"))
        << saved;
    EXPECT_TRUE(Contains(saved,
                         "the Model writes scenes with a library that reads file names as "
                         "URIs, which would open another file"))
        << saved;
    EXPECT_FALSE(fs::exists(root_ + "/session/" + name)) << name;
    const std::string loaded = LoadRefusal(name);
    EXPECT_TRUE(Contains(loaded, "load_scene: '" + name + "'")) << loaded;
    EXPECT_TRUE(Contains(loaded, "which would open another file")) << loaded;
  }
  EXPECT_EQ(ReadFile(root_ + "/outside/victim.txt"), "precious\n");
  EXPECT_EQ(Scene(), root_ + "/models/pendulum.dae");
  // a file named so inside the directories: caliper-ctl goes by content, and writes that name
  fs::copy_file(root_ + "/models/pendulum.dae", root_ + "/models/pend#1.dae");
  const auto load = Ctl({"load", root_ + "/models/pend#1.dae"});
  ASSERT_EQ(load.exit_code, 0) << load.err;
  EXPECT_EQ(Scene(), "pend#1.dae (sent by content)");
  const auto save = Ctl({"save", root_ + "/session/saved#1.dae"});
  ASSERT_EQ(save.exit_code, 0) << save.err;
  EXPECT_TRUE(Contains(save.out, "(fetched by content)")) << save.out;
  EXPECT_TRUE(fs::is_regular_file(root_ + "/session/saved#1.dae"));
  EXPECT_EQ(ReadFile(root_ + "/outside/victim.txt"), "precious\n");
}

TEST_F(ConfinedFilesTest, ARejectedArchiveIsNamedAndWritesNothingOutside) {
  // a .zae sent by content whose entry leads out of Collada-DOM's temporary directory: the
  // Model's TMPDIR is root/t/u, so '../../slipped.txt' would land in root/t
  fs::create_directories(root_ + "/t/u");
  const std::string zae = root_ + "/outside/slip.zae";
  const std::string make =
      "python3 -c \"import sys, zipfile\n"
      "with zipfile.ZipFile(sys.argv[1], 'w') as z:\n"
      "    z.writestr('manifest.xml', '<dae_root>./p.dae</dae_root>')\n"
      "    z.writestr('p.dae', open(sys.argv[2]).read())\n"
      "    z.writestr('../../slipped.txt', 'outside')\" " +
      zae + " " + root_ + "/models/pendulum.dae";
  ASSERT_EQ(std::system(make.c_str()), 0) << make;
  const char* old_tmp = std::getenv("TMPDIR");
  const std::string saved_tmp = old_tmp != nullptr ? old_tmp : "";
  ::setenv("TMPDIR", (root_ + "/t/u").c_str(), 1);
  StartConfinedModel();
  if (old_tmp != nullptr) {
    ::setenv("TMPDIR", saved_tmp.c_str(), 1);
  } else {
    ::unsetenv("TMPDIR");
  }
  const std::string bytes = ReadFile(zae);
  M::Octets data(static_cast<CORBA::ULong>(bytes.size()));
  data.length(static_cast<CORBA::ULong>(bytes.size()));
  std::copy(bytes.begin(), bytes.end(), reinterpret_cast<char*>(data.get_buffer()));
  try {
    ref_->load_scene_data("slip.zae", data);
    ADD_FAILURE() << "the archive loaded";
  } catch (const M::LoadFailed& e) {
    EXPECT_TRUE(Contains(e.reason.in(),
                         "slip.zae: the archive's entry '../../slipped.txt' is "
                         "refused: its name has a '..' component"))
        << e.reason.in();
  }
  EXPECT_FALSE(fs::exists(root_ + "/t/slipped.txt"));
  EXPECT_FALSE(fs::exists(root_ + "/slipped.txt"));
}

TEST_F(ConfinedFilesTest, AReplyLargerThanTheConfiguredMessageSizeIsRefusedWithTheSizes) {
  // corba.max_message_size = 1 MiB: the scene description and the export of a 2.9 MB robot do
  // not fit; the Model says so (a bare MARSHAL before, the check used the 256 MiB default)
  CALIPER_REQUIRE_CORPUS();  // a scene of more than 1 MiB: the corpus's Barrett hand
  const std::string corpus = CorpusDir();
  fs::copy_file(corpus + "/collada/collada_robots/barrett-hand.zae", root_ + "/models/hand.zae");
  StartModel({"-o", "model.read_dirs=" + root_ + "/models", "-o", "corba.max_message_size=1"});
  ASSERT_EQ(LoadRefusal("hand.zae"), "");
  try {
    M::Octets_var bytes = ref_->export_scene();
    ADD_FAILURE() << "export_scene answered " << bytes->length() << " bytes";
  } catch (const M::NotAvailable& e) {
    EXPECT_TRUE(Contains(e.reason.in(),
                         "MiB, more than one GIOP message carries (1.0 MiB, "
                         "corba.max_message_size)"))
        << e.reason.in();
  }
  EXPECT_FALSE(ref_->_non_existent());
}

TEST_F(ConfinedFilesTest, CtlLoadAndSaveGoByContentWhereTheModelRefusesThePath) {
  StartConfinedModel();
  // inside: by path
  const auto inside = Ctl({"load", root_ + "/models/pendulum.dae"});
  ASSERT_EQ(inside.exit_code, 0) << inside.err;
  EXPECT_FALSE(Contains(inside.out, "by content")) << inside.out;
  EXPECT_EQ(Scene(), root_ + "/models/pendulum.dae");
  // outside: by content, the same scene
  const auto outside = Ctl({"load", root_ + "/outside/pendulum.dae"});
  ASSERT_EQ(outside.exit_code, 0) << outside.err;
  EXPECT_TRUE(Contains(outside.out, "(sent by content)")) << outside.out;
  EXPECT_EQ(Scene(), "pendulum.dae (sent by content)");
  // an import error by content names the file, not the Model's private copy
  fs::copy_file(Source("tests/data/collada/malformed_xml.dae"), root_ + "/outside/bad.dae");
  const auto bad = Ctl({"load", root_ + "/outside/bad.dae"});
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_TRUE(Contains(bad.err, root_ + "/outside/bad.dae (sent by content): bad.dae:40: malformed "
                                        "XML"))
      << bad.err;
  EXPECT_FALSE(Contains(bad.err, "caliper-scene")) << bad.err;
  EXPECT_TRUE(Contains(bad.err, "model0 keeps pendulum.dae (sent by content), STOPPED")) << bad.err;
  const auto missing = Ctl({"load", root_ + "/outside/missing.dae"});
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_TRUE(Contains(missing.err, root_ + "/outside/missing.dae cannot be read")) << missing.err;

  // save: by path into the write directory, by content anywhere else
  const auto saved_inside = Ctl({"save", root_ + "/session/by-path.dae"});
  ASSERT_EQ(saved_inside.exit_code, 0) << saved_inside.err;
  EXPECT_FALSE(Contains(saved_inside.out, "by content")) << saved_inside.out;
  EXPECT_TRUE(fs::is_regular_file(root_ + "/session/by-path.dae"));
  const auto saved_outside = Ctl({"save", root_ + "/outside/by-content.dae"});
  ASSERT_EQ(saved_outside.exit_code, 0) << saved_outside.err;
  EXPECT_TRUE(Contains(saved_outside.out, "(fetched by content)")) << saved_outside.out;
  const auto inspect = Ctl({"inspect", root_ + "/outside/by-content.dae"});
  EXPECT_EQ(inspect.exit_code, 0) << inspect.err;
  EXPECT_TRUE(Contains(inspect.out, "bodies (2: 1 dynamic, 1 static)")) << inspect.out;
  // what ctl wrote is what the Model wrote
  EXPECT_EQ(ReadFile(root_ + "/outside/by-content.dae").size(),
            ReadFile(root_ + "/session/by-path.dae").size());
}

}  // namespace
}  // namespace caliper::testing
