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

int ObserverHub::Add(SceneObserver* observer) {
  entries_.push_back({next_id_, observer, ChangeFilter(position_tolerance_, angle_tolerance_)});
  return next_id_++;
}

void ObserverHub::Remove(int id) {
  for (auto it = entries_.begin(); it != entries_.end(); ++it)
    if (it->id == id) {
      entries_.erase(it);
      return;
    }
}

void ObserverHub::Notify(const PhysicsScene& scene) {
  if (entries_.empty()) return;
  const std::vector<BodyState> states = scene.BodyStates();
  for (auto& e : entries_) {
    const std::vector<int> changed = e.filter.Changed(states);
    if (changed.empty()) continue;
    std::vector<BodyState> subset;
    subset.reserve(changed.size());
    for (int i : changed) subset.push_back(states[i]);
    e.observer->OnTransforms(scene.steps(), scene.time(), changed, subset);
  }
}

}  // namespace caliper::sgal
