#include "renderer_verbs.h"

#include <limits.h>
#include <unistd.h>

#include <iostream>
#include <string>
#include <vector>

#include "caliper/core/confined_path.h"
#include "caliper/core/numbers.h"
#include "caliper/core/system.h"
#include "caliper/renderer.hh"
#include "caliper/rtc/idl_names.h"

namespace caliper::ctl {
namespace {

namespace V = ::Caliper::Viewer;

// the renderer draws a screenshot in one GUI call of at most 30 s, then encodes it [ms]
constexpr CORBA::ULong kScreenshotCallMs = 60 * 1000;

// WIDTHxHEIGHT, each 16 .. 8192 px (what the renderer accepts)
void ParseSize(const std::string& text, CORBA::ULong* width, CORBA::ULong* height) {
  const size_t x = text.find('x');
  long long w = 0, h = 0;
  if (x == std::string::npos || !core::ParseInt(text.substr(0, x), &w) ||
      !core::ParseInt(text.substr(x + 1), &h) || w < 16 || h < 16 || w > 8192 || h > 8192)
    throw UsageError("--size: '" + text + "' is not WIDTHxHEIGHT with 16 .. 8192 px each");
  *width = static_cast<CORBA::ULong>(w);
  *height = static_cast<CORBA::ULong>(h);
}

// the renderer's process has another working directory: send it absolute paths
std::string Absolute(const std::string& path) {
  if (path.empty() || path[0] == '/') return path;
  char cwd[PATH_MAX];
  if (getcwd(cwd, sizeof cwd) == nullptr) return path;
  return std::string(cwd) + "/" + path;
}

// Runs a call on the renderer; its NotAvailable prints the reason, an unreachable one says so.
template <class F>
auto Call(const std::string& path, F&& f) -> decltype(f()) {
  try {
    return f();
  } catch (const V::NotAvailable& e) {
    throw Failure(path + ": " + e.reason.in());
  } catch (const CORBA::UserException& e) {
    throw Failure(path + ": " + rtc::Describe(e));
  } catch (const CORBA::SystemException& e) {
    throw Failure(Client::Unreachable(path, e));
  }
}

int Screenshot(Client& client, std::vector<std::string>& args) {
  std::string name = "renderer0", size = "1024x768";
  TakeOption(args, "--renderer", &name);
  TakeOption(args, "--size", &size);
  const bool fetch_flag = TakeFlag(args, "--fetch");
  RejectOptions(args);
  if (args.size() != 1) throw UsageError("expected one FILE (a .png)");
  CORBA::ULong width = 0, height = 0;
  ParseSize(size, &width, &height);
  const std::string path = Absolute(args[0]);

  rtc::ComponentEntry entry;
  try {
    entry = client.Find(name);
  } catch (const client::ConnectionError&) {
    throw;
  } catch (const Failure& e) {
    // a headless session has no renderer: say how to get one
    throw Failure(std::string(e.what()) +
                  "\n  (a headless session has no Scene Renderer; `launch/caliper open renderer` "
                  "starts one on a display, e.g. Xvfb)");
  }
  V::Renderer_var renderer;
  try {
    renderer = V::Renderer::_narrow(entry.object);
  } catch (const CORBA::Exception& e) {
    throw Failure(Client::Unreachable(entry.path, e));
  }
  if (CORBA::is_nil(renderer)) throw Failure(entry.path + " is not a Scene Renderer");
  omniORB::setClientCallTimeout(renderer, kScreenshotCallMs);

  // the renderer writes the file itself only on this host and below its write directory
  bool fetch = fetch_flag || entry.host != core::HostName();
  if (!fetch) {
    CORBA::String_var dir = Call(entry.path, [&] { return renderer->screenshot_dir(); });
    const std::vector<std::string> dirs =
        *dir.in() == '\0' ? std::vector<std::string>{} : std::vector<std::string>{dir.in()};
    fetch = !core::ConfinedPaths(dirs, "", "").Allows(path, core::ConfinedPaths::Access::kWrite);
  }
  if (fetch) {
    V::Png_var png = Call(entry.path, [&] { return renderer->screenshot_png(width, height); });
    try {
      core::WriteFileReplacing(path, [&](std::ostream& out) {
        out.write(reinterpret_cast<const char*>(png->get_buffer()), png->length());
      });
    } catch (const std::exception& e) {
      throw Failure(e.what());
    }
  } else {
    Call(entry.path, [&] { renderer->screenshot(path.c_str(), width, height); });
  }
  std::cout << name << ": " << width << "x" << height << " screenshot written to " << path
            << (fetch ? " (fetched by content)" : "") << "\n";
  return 0;
}

}  // namespace

void AddRendererVerbs(std::map<std::string, Verb>* verbs) {
  (*verbs)["screenshot"] = {
      "screenshot FILE [--size WxH] [--fetch] [--renderer NAME]",
      "a PNG of a Scene Renderer's current view (1024x768 unless --size)", Screenshot, "renderer",
      "  The renderer is renderer0, or --renderer NAME. It writes FILE itself (sent as an\n"
      "  absolute path) when it runs on this host and FILE lies below its write directory\n"
      "  (renderer.write_dir: the session's files/ folder when the launcher started it);\n"
      "  otherwise (another host, --fetch, files elsewhere) the PNG comes back by content and\n"
      "  is written here. A headless session (`session --headless`, `demo --headless`) has no\n"
      "  Scene Renderer: start one with `launch/caliper open renderer` (it needs a display).\n"};
}

}  // namespace caliper::ctl
