#include <cmath>

#include "caliper/sgal/physics_scene.h"

namespace caliper::sgal {

ChangeFilter::ChangeFilter(double position_tolerance, double angle_tolerance)
    : position_tolerance_(position_tolerance), angle_tolerance_(angle_tolerance) {}

std::vector<int> ChangeFilter::Changed(const std::vector<BodyState>& states) {
  std::vector<int> changed;
  if (last_.size() != states.size()) {
    last_.assign(states.size(), Pose());
    for (size_t i = 0; i < states.size(); ++i) {
      last_[i] = states[i].pose;
      changed.push_back(static_cast<int>(i));
    }
    return changed;
  }
  for (size_t i = 0; i < states.size(); ++i) {
    const Pose& now = states[i].pose;
    const double moved = (now.position - last_[i].position).norm();
    const double turned = now.orientation.angularDistance(last_[i].orientation);
    if (moved > position_tolerance_ || turned > angle_tolerance_) {
      last_[i] = now;
      changed.push_back(static_cast<int>(i));
    }
  }
  return changed;
}

}  // namespace caliper::sgal
