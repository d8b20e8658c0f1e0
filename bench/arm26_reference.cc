// Writes tests/data/arm26_mujoco222_dt0.5ms.csv: MuJoCo 2.2.2 (Debian libmujoco) simulating the
// corpus's arm26.xml at a 0.5 ms time step, fine enough that the integrators' own errors are
// small, so that Caliper's physics can be compared with MuJoCo's and not with its 5 ms
// discretisation. Usage: arm26_reference CORPUS_DIR > tests/data/arm26_mujoco222_dt0.5ms.csv
#include <mujoco/mujoco.h>

#include <cmath>
#include <cstdio>
#include <string>

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: arm26_reference CORPUS_DIR\n");
    return 2;
  }
  const std::string path = std::string(argv[1]) + "/reference/mujoco/arm26.xml";
  char error[1000] = "";
  mjModel* m = mj_loadXML(path.c_str(), nullptr, error, sizeof error);
  if (m == nullptr) {
    std::fprintf(stderr, "%s: %s\n", path.c_str(), error);
    return 1;
  }
  m->opt.timestep = 0.0005;
  mjData* d = mj_makeData(m);
  const double ctrl[6] = {0.5, 0, 0.3, 0, 0.2, 0};  // SF SE EF EE BF BE
  for (int i = 0; i < 6; ++i) d->ctrl[i] = ctrl[i];
  std::printf("# arm26.xml from the reference corpus simulated by Debian libmujoco 2.2.2 mj_step at "
              "timestep 0.0005 s from rest, ctrl SF .5 EF .3 BF .2; written by bench/arm26_reference.cc\n");
  std::printf("time,q_shoulder,q_elbow,len_SF,len_BF\n");
  int step = 0;
  while (d->time < 0.6 - 1e-9) {
    mj_step(m, d);
    if (++step % 20 == 0)
      std::printf("%.4f,%.10g,%.10g,%.10g,%.10g\n", d->time, d->qpos[0], d->qpos[1],
                  d->ten_length[0], d->ten_length[4]);
  }
  mj_deleteData(d);
  mj_deleteModel(m);
  return 0;
}
