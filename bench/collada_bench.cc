// COLLADA benchmark: the load time of the largest corpus file, the PR2
// (collada_robots/willowgarage-pr2.zae, 88 bodies), as the median of several imports. Prints
//   RATIO collada_pr2_load_s <seconds> (target 2.0)
// measured in this run, never compared with stored times. The corpus is $CALIPER_CORPUS, else
// ../shared/corpus beside the source tree.
#include <sys/stat.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "caliper/collada/importer.h"

namespace caliper::bench {
namespace {

constexpr double kTargetSeconds = 2.0;
constexpr const char* kPr2 = "collada/collada_robots/willowgarage-pr2.zae";

bool IsFile(const std::string& path) {
  struct stat st;
  return stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

std::string CorpusDir() {
  const char* dir = std::getenv("CALIPER_CORPUS");
  return dir != nullptr && *dir != '\0' ? dir : CALIPER_CORPUS_DEFAULT;
}

}  // namespace
}  // namespace caliper::bench

int main(int argc, char** argv) {
  using namespace caliper::bench;
  int repeats = 5;
  std::string file = CorpusDir() + "/" + kPr2;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--repeats") && i + 1 < argc) {
      repeats = std::max(1, std::atoi(argv[++i]));
    } else if (!std::strcmp(argv[i], "--file") && i + 1 < argc) {
      file = argv[++i];
    } else {
      std::printf(
          "Usage: collada_bench [--repeats R] [--file FILE]\n"
          "  median load time of FILE (default $CALIPER_CORPUS/%s) over R imports (5)\n",
          kPr2);
      return std::strcmp(argv[i], "--help") == 0 ? 0 : 2;
    }
  }
  if (!IsFile(file)) {
    std::fprintf(stderr,
                 "collada_bench: %s not found (set CALIPER_CORPUS to the reference corpus)\n",
                 file.c_str());
    return 1;
  }

  std::vector<double> seconds;
  caliper::sgal::Scene scene;
  std::vector<std::string> warnings;
  for (int r = 0; r < repeats; ++r) {
    warnings.clear();
    const auto begin = std::chrono::steady_clock::now();
    try {
      scene = caliper::collada::Import(file, &warnings);
    } catch (const caliper::collada::ImportError& e) {
      std::fprintf(stderr, "collada_bench: %s\n", e.what());
      return 1;
    }
    seconds.push_back(
        std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count());
  }
  std::printf("# %s: %zu bodies, %zu constraints, %zu warnings\n", file.c_str(),
              scene.bodies.size(), scene.constraints.size(), warnings.size());
  std::printf("# load times [s]:");
  for (double s : seconds) std::printf(" %.3f", s);
  std::printf("\n");
  std::sort(seconds.begin(), seconds.end());
  const double median = seconds[seconds.size() / 2];
  std::printf("RATIO collada_pr2_load_s %.3f (target %.1f)%s\n", median, kTargetSeconds,
              median <= kTargetSeconds ? "" : "  <- above target");
  return 0;
}
