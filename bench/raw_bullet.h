#pragma once
// The baseline: the same bodies and hinges stepped by plain Bullet, with 80 tension-only springs
// applied by hand. Only benchmarks include this (the product uses libs/physics_bullet).

#include <memory>

#include "caliper/sgal/scene.h"

namespace caliper::bench {

class RawBulletWorld {
 public:
  explicit RawBulletWorld(const sgal::Scene& scene);
  ~RawBulletWorld();
  void Step(double dt);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace caliper::bench
