// thread_spin_test's program: prints what it starts with, calls BoundThreadSpin, then prints its
// arguments and libgomp's own view of its settings (omp_display_env).
#include <omp.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>

#include "caliper/physics_bullet/bullet_scene.h"

int main(int argc, char** argv) {
  const char* spin = std::getenv("GOMP_SPINCOUNT");
  std::printf("start pid=%d GOMP_SPINCOUNT=%s\n", static_cast<int>(getpid()), spin ? spin : "-");
  std::fflush(stdout);  // the exec would drop what is buffered
  caliper::physics_bullet::BoundThreadSpin(argv);
  for (int i = 1; i < argc; ++i) std::printf("arg %d [%s]\n", i, argv[i]);
  const char* after = std::getenv("GOMP_SPINCOUNT");
  std::printf("after pid=%d GOMP_SPINCOUNT=%s\n", static_cast<int>(getpid()), after ? after : "-");
  // the process's name as ps and pgrep see it
  char name[64] = {};
  if (FILE* comm = std::fopen("/proc/self/comm", "r")) {
    if (std::fgets(name, sizeof(name), comm) == nullptr) name[0] = 0;
    std::fclose(comm);
  }
  std::printf("comm %s", name);
  std::fflush(stdout);
  omp_display_env(1);  // libgomp's settings as it read them when it loaded
  return 0;
}
