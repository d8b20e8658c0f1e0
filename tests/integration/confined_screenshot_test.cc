// The Scene Renderer's screenshot over CORBA writes only below renderer.write_dir: paths outside,
// `..` and links leading out are refused with the reason and nothing is written there;
// screenshot_png returns the image by content, and caliper-ctl screenshot writes any local
// file (by path inside the write directory, by content elsewhere). Needs X with GLX.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "caliper/renderer.hh"
#include "caliper/rtc/client_orb.h"
#include "caliper/rtc/naming.h"
#include "support/gui_test.h"
#include "support/process.h"

namespace caliper::testing {
namespace {

namespace fs = std::filesystem;
namespace V = ::Caliper::Viewer;

using std::chrono::seconds;

bool Contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// width and height from a PNG's IHDR chunk (0 x 0 when the bytes are no PNG)
std::pair<unsigned, unsigned> PngSize(const std::string& bytes) {
  if (bytes.size() < 24 || bytes.compare(0, 8, "\x89PNG\r\n\x1a\n") != 0 ||
      bytes.compare(12, 4, "IHDR") != 0)
    return {0, 0};
  auto be32 = [&](size_t at) {
    unsigned v = 0;
    for (size_t i = 0; i < 4; ++i) v = (v << 8) | static_cast<unsigned char>(bytes[at + i]);
    return v;
  };
  return {be32(16), be32(20)};
}

class ConfinedScreenshotTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (const std::string why = NoDisplay("the renderer needs X with GLX"); !why.empty())
      GTEST_SKIP() << why;
    root_ = fs::canonical(tmp_.path()).string();
    fs::create_directory(root_ + "/session");
    fs::create_directory(root_ + "/session-evil");
    fs::create_directory(root_ + "/outside");
    std::ofstream(root_ + "/outside/victim.png") << "precious\n";
    naming_ = std::make_unique<NamingService>(root_);
    model_ = StartModelProcess(naming_->address(), Source("models/pendulum_tendon.dae"), root_,
                               root_ + "/model.out");
    renderer_process_ = std::make_unique<Process>(
        std::vector<std::string>{Bin("caliper-renderer"), "--nameservice", naming_->address(), "-o",
                                 "log.service=none", "-o", "log.spool_dir=" + root_ + "/spool",
                                 "-o", "renderer.check_interval=0.2", "-o",
                                 "renderer.write_dir=" + root_ + "/session"},
        root_ + "/renderer.out");
    ASSERT_TRUE(WaitFor(
        [&] {
          try {
            CosNaming::NamingContext_var root = rtc::ResolveRoot(Orb(), naming_->address());
            renderer_ = V::Renderer::_narrow(rtc::FindComponent(root, "renderer0").object);
            return !CORBA::is_nil(renderer_) && !renderer_->_non_existent();
          } catch (...) {
            return false;
          }
        },
        seconds(20)))
        << renderer_process_->Output();
    // the first image once the Model's scene has arrived
    std::string last;
    ASSERT_TRUE(WaitFor(
        [&] {
          try {
            V::Png_var png = renderer_->screenshot_png(64, 48);
            return true;
          } catch (const V::NotAvailable& e) {
            last = e.reason.in();
            return false;
          }
        },
        seconds(20)))
        << last << "\n"
        << renderer_process_->Output();
  }

  static std::string Source(const std::string& relative) {
    const char* dir = std::getenv("CALIPER_SOURCE_DIR");
    return std::string(dir != nullptr ? dir : ".") + "/" + relative;
  }

  /// NotAvailable's reason for screenshot(path) ("" when it wrote the file).
  std::string Refusal(const std::string& path) {
    try {
      renderer_->screenshot(path.c_str(), 320, 240);
      return "";
    } catch (const V::NotAvailable& e) {
      return e.reason.in();
    }
  }

  TempDir tmp_;
  std::string root_;
  std::unique_ptr<NamingService> naming_;
  std::unique_ptr<Process> model_;
  std::unique_ptr<Process> renderer_process_;
  V::Renderer_var renderer_;
};

TEST_F(ConfinedScreenshotTest, WritesOnlyBelowTheWriteDirectory) {
  CORBA::String_var dir = renderer_->screenshot_dir();
  EXPECT_EQ(std::string(dir.in()), root_ + "/session");
  EXPECT_EQ(Refusal(root_ + "/session/shot.png"), "");
  EXPECT_EQ(PngSize(ReadFile(root_ + "/session/shot.png")), std::make_pair(320u, 240u));
  EXPECT_EQ(Refusal("relative.png"), "");
  EXPECT_TRUE(fs::is_regular_file(root_ + "/session/relative.png"));

  fs::create_directory_symlink(root_ + "/outside", root_ + "/session/out");
  fs::create_symlink(root_ + "/outside/created.png", root_ + "/session/dangling.png");
  for (const std::string& path :
       {root_ + "/outside/victim.png", root_ + "/outside/new.png",
        root_ + "/session/../outside/new.png", std::string("../outside/new.png"),
        root_ + "/session/out/new.png", root_ + "/session-evil/new.png",
        root_ + "/session/dangling.png"}) {
    const std::string why = Refusal(path);
    EXPECT_TRUE(Contains(why, "screenshot: '" + path + "'")) << path << ": " << why;
    EXPECT_TRUE(Contains(why, "renderer.write_dir")) << why;
    EXPECT_TRUE(Contains(why, "screenshot_png")) << why;
  }
  EXPECT_EQ(ReadFile(root_ + "/outside/victim.png"), "precious\n");
  EXPECT_FALSE(fs::exists(root_ + "/outside/new.png"));
  EXPECT_FALSE(fs::exists(root_ + "/outside/created.png"));
  EXPECT_FALSE(fs::exists(root_ + "/session-evil/new.png"));
  EXPECT_TRUE(renderer_process_->Running()) << renderer_process_->Output();
}

TEST_F(ConfinedScreenshotTest, WritesTheFileNamedEvenWithCharactersAUriReadsOtherwise) {
  // the renderer writes by file name (QImage::save), not through a URI: 'shot#1.png' is that file,
  // not 'shot' (a link out, which the Model's COLLADA library would have followed)
  fs::create_symlink(root_ + "/outside/victim.png", root_ + "/session/shot");
  fs::create_symlink(root_ + "/outside/victim.png", root_ + "/session/shot a.png");
  for (const std::string name : {"shot#1.png", "shot?x.png", "shot%20a.png"}) {
    EXPECT_EQ(Refusal(name), "") << name;
    EXPECT_EQ(PngSize(ReadFile(root_ + "/session/" + name)), std::make_pair(320u, 240u)) << name;
  }
  EXPECT_EQ(ReadFile(root_ + "/outside/victim.png"), "precious\n");
}

TEST_F(ConfinedScreenshotTest, ScreenshotPngReturnsTheImageByContent) {
  V::Png_var png = renderer_->screenshot_png(200, 150);
  const std::string bytes(reinterpret_cast<const char*>(png->get_buffer()), png->length());
  EXPECT_EQ(PngSize(bytes), std::make_pair(200u, 150u));
  EXPECT_THROW(renderer_->screenshot_png(8, 8), V::NotAvailable);
}

TEST_F(ConfinedScreenshotTest, CtlScreenshotWritesAnyLocalFile) {
  const auto inside =
      Ctl(naming_->address(), {"screenshot", root_ + "/session/ctl.png", "--size", "160x120"});
  ASSERT_EQ(inside.exit_code, 0) << inside.err;
  EXPECT_FALSE(Contains(inside.out, "by content")) << inside.out;
  EXPECT_EQ(PngSize(ReadFile(root_ + "/session/ctl.png")), std::make_pair(160u, 120u));

  const auto outside = Ctl(naming_->address(), {"screenshot", root_ + "/outside/ctl.png"});
  ASSERT_EQ(outside.exit_code, 0) << outside.err;
  EXPECT_TRUE(Contains(outside.out, "renderer0: 1024x768 screenshot written to " + root_ +
                                        "/outside/ctl.png (fetched by content)"))
      << outside.out;
  EXPECT_EQ(PngSize(ReadFile(root_ + "/outside/ctl.png")), std::make_pair(1024u, 768u));

  const auto bad_size = Ctl(naming_->address(), {"screenshot", "x.png", "--size", "10x10"});
  EXPECT_EQ(bad_size.exit_code, 2);
  EXPECT_TRUE(Contains(bad_size.err, "--size: '10x10' is not WIDTHxHEIGHT")) << bad_size.err;
  const auto unwritable =
      Ctl(naming_->address(), {"screenshot", root_ + "/outside/no-such-dir/x.png"});
  EXPECT_EQ(unwritable.exit_code, 1);
  EXPECT_TRUE(Contains(unwritable.err, root_ + "/outside/no-such-dir/x.png")) << unwritable.err;
}

}  // namespace
}  // namespace caliper::testing
