// Model file benchmark: the load time of the largest COLLADA corpus file, the PR2
// (collada_robots/willowgarage-pr2.zae, 88 bodies), and of the URDF corpus's PR2 (82 links, STL
// meshes) and Panda (134924 visual triangles in COLLADA meshes, through assimp), each the median of
// several imports. Prints
//   RATIO collada_pr2_load_s <seconds> (target 2.0)
//   RATIO urdf_pr2_load_s <seconds> (target 1.0)
//   RATIO urdf_panda_load_s <seconds> (target 1.0)
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
#include "caliper/model_file/model_file.h"

namespace caliper::bench {
namespace {

constexpr double kTargetSeconds = 2.0;
constexpr const char* kPr2 = "collada/collada_robots/willowgarage-pr2.zae";

// URDF robots of the corpus: RATIO name, file, target [s]
struct UrdfCase {
  const char* ratio;
  const char* file;
  double target;
};
constexpr UrdfCase kUrdf[] = {
    {"urdf_pr2_load_s", "urdf/example-robot-data/robots/pr2_description/urdf/pr2.urdf", 1.0},
    {"urdf_panda_load_s", "urdf/example-robot-data/robots/panda_description/urdf/panda.urdf", 1.0},
};

// The median of `repeats` imports of `file` through model_file::Import [s]; -1 on an error.
double MedianLoad(const std::string& file, int repeats, caliper::sgal::Scene* scene,
                  std::vector<std::string>* warnings) {
  std::vector<double> seconds;
  for (int r = 0; r < repeats; ++r) {
    warnings->clear();
    const auto begin = std::chrono::steady_clock::now();
    try {
      *scene = caliper::model_file::Import(file, warnings);
    } catch (const caliper::collada::ImportError& e) {
      std::fprintf(stderr, "collada_bench: %s\n", e.what());
      return -1;
    }
    seconds.push_back(
        std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count());
  }
  std::printf("# %s: %zu bodies, %zu constraints, %zu warnings; load times [s]:", file.c_str(),
              scene->bodies.size(), scene->constraints.size(), warnings->size());
  for (double s : seconds) std::printf(" %.3f", s);
  std::printf("\n");
  std::sort(seconds.begin(), seconds.end());
  return seconds[seconds.size() / 2];
}

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

  caliper::sgal::Scene scene;
  std::vector<std::string> warnings;
  const double median = MedianLoad(file, repeats, &scene, &warnings);
  if (median < 0) return 1;
  std::printf("RATIO collada_pr2_load_s %.3f (target %.1f)%s\n", median, kTargetSeconds,
              median <= kTargetSeconds ? "" : "  <- above target");
  for (const UrdfCase& c : kUrdf) {
    const std::string urdf = CorpusDir() + "/" + c.file;
    if (!IsFile(urdf)) {
      std::fprintf(stderr, "collada_bench: %s not found\n", urdf.c_str());
      return 1;
    }
    const double t = MedianLoad(urdf, repeats, &scene, &warnings);
    if (t < 0) return 1;
    std::printf("RATIO %s %.3f (target %.1f)%s\n", c.ratio, t, c.target,
                t <= c.target ? "" : "  <- above target");
  }
  return 0;
}
