#include "caliper/simulation/edit_history.h"

#include <algorithm>
#include <set>
#include <utility>

#include "caliper/actuators/actuator.h"
#include "caliper/sgal/edits.h"

namespace caliper::simulation {

void EditHistory::Forget() {
  undo_.clear();
  redo_.clear();
  removed_.clear();
  last_.clear();
}

void EditHistory::ClearUndo() {
  undo_.clear();
  redo_.clear();
}

void EditHistory::Push(Entry entry) {
  undo_.push_back(std::move(entry));
  if (undo_.size() > kMaxUndo) undo_.erase(undo_.begin());  // a bounded history
  redo_.clear();
}

EditHistory::Entry EditHistory::Next(bool undo, size_t* depth) const {
  const std::vector<Entry>& from = undo ? undo_ : redo_;
  if (from.empty()) throw sgal::EditError(undo ? "nothing to undo" : "nothing to redo");
  *depth = from.size();
  return from.back();
}

void EditHistory::Walked(bool undo, size_t depth) {
  std::vector<Entry>& from = undo ? undo_ : redo_;
  std::vector<Entry>& to = undo ? redo_ : undo_;
  // the entry walked is the last one, unless a load emptied the history meanwhile
  if (from.size() == depth) {
    to.push_back(std::move(from.back()));
    from.pop_back();
  }
}

void EditHistory::Applied(const std::string& what) {
  ++revision_;
  last_ = what;
}

sgal::DynamicState EditHistory::CarryOver(const sgal::Scene& before,
                                          const sgal::DynamicState& old_state,
                                          const sgal::Scene& edited) {
  // bodies and constraints are never added by an edit; an actuator that an edit removes keeps
  // its state and command aside, for the undo that brings it back
  sgal::DynamicState state = old_state;
  state.engine.clear();  // the engine's own numbers belong to the scene before the edit
  // the delayed channels' memory fits only the same channels lagging the same steps
  const auto same_delay = [](const sgal::MeasurementDelay& a, const sgal::MeasurementDelay& b) {
    return a.id == b.id && a.delay == b.delay;
  };
  if (before.settings.time_step != edited.settings.time_step ||
      !std::equal(before.measurement_delays.begin(), before.measurement_delays.end(),
                  edited.measurement_delays.begin(), edited.measurement_delays.end(), same_delay))
    state.measurements.clear();
  state.actuators.assign(edited.actuators.size(), {});
  state.commands.assign(edited.actuators.size(), 0.0);
  std::map<std::string, size_t> was_at;
  for (size_t j = 0; j < before.actuators.size(); ++j) was_at[before.actuators[j].name] = j;
  std::set<std::string> kept;
  for (size_t k = 0; k < edited.actuators.size(); ++k) {
    const sgal::Actuator& a = edited.actuators[k];
    const auto was = was_at.find(a.name);
    if (was != was_at.end() && before.actuators[was->second].kind == a.kind) {
      state.actuators[k] = old_state.actuators[was->second];
      state.commands[k] = old_state.commands[was->second];
      kept.insert(a.name);
    } else if (const auto aside = removed_.find(a.name);
               aside != removed_.end() && aside->second.kind == a.kind) {
      state.actuators[k] = aside->second.state;
      state.commands[k] = aside->second.command;
      removed_.erase(aside);
    }
  }
  for (const auto& [name, j] : was_at)
    if (kept.count(name) == 0 && removed_.size() < kMaxRemoved)
      removed_[name] = {before.actuators[j].kind, old_state.actuators[j], old_state.commands[j]};
  return state;
}

void EditHistory::SetSelection(std::string kind, std::string name, uint32_t index) {
  selection_ = {std::move(kind), std::move(name), index, selection_.revision + 1};
}

void EditHistory::ClearSelection() { SetSelection("", "", 0); }

void EditHistory::Select(const sgal::Scene* scene, const std::string& kind,
                         const std::string& name, uint32_t index) {
  if (!kind.empty()) {
    const sgal::Scene& s = *scene;
    bool found = false;
    if (kind == "body") {
      found = s.FindBody(name) != nullptr;
    } else if (kind == "tendon") {
      found = s.FindTendon(name) != nullptr;
    } else if (kind == "path_point") {
      const sgal::Tendon* t = s.FindTendon(name);
      found = t != nullptr && index < t->path.size();
    } else if (kind == "obstacle") {
      found = s.FindObstacle(name) != nullptr;
    } else if (kind == "constraint") {
      found = std::any_of(s.constraints.begin(), s.constraints.end(),
                          [&](const sgal::Constraint& c) { return c.name == name; });
    } else {
      throw sgal::EditError("select: unknown kind '" + kind +
                            "' (body, tendon, path_point, obstacle, constraint, or '' for none)");
    }
    if (!found)
      throw sgal::EditError("select: the scene has no " + kind + " '" + name + "'" +
                            (kind == "path_point" ? " with element " + std::to_string(index) : ""));
  }
  SetSelection(kind, kind.empty() ? "" : name, kind == "path_point" ? index : 0);
}

void EditHistory::FollowEdit(const sgal::Scene& before, const sgal::Scene& edited) {
  // a selection of what the edit removed is gone; a selected path element that an insert or a
  // removal before it shifted keeps pointing at the same element
  if ((selection_.kind == "tendon" || selection_.kind == "path_point") &&
      edited.FindTendon(selection_.name) == nullptr)
    ClearSelection();
  if (selection_.kind == "path_point") {
    const auto& now = edited.FindTendon(selection_.name)->path;
    const sgal::Tendon* was = before.FindTendon(selection_.name);
    if (was != nullptr && was->path.size() != now.size() && selection_.index < was->path.size()) {
      const sgal::PathElement& e = was->path[selection_.index];
      const auto same = [&](const sgal::PathElement& x) {
        return x.kind == e.kind && x.body == e.body && x.position == e.position &&
               x.obstacle == e.obstacle;
      };
      const auto found = std::find_if(now.begin(), now.end(), same);
      if (found == now.end())
        ClearSelection();
      else if (static_cast<uint32_t>(found - now.begin()) != selection_.index)
        SetSelection("path_point", selection_.name, static_cast<uint32_t>(found - now.begin()));
    }
  }
  if (selection_.kind == "obstacle" && edited.FindObstacle(selection_.name) == nullptr)
    ClearSelection();
}

sgal::Actuator NewActuator(const sgal::Scene* scene, const std::string& name,
                           const std::string& kind) {
  const std::vector<std::string> kinds = actuators::Kinds();
  if (std::find(kinds.begin(), kinds.end(), kind) == kinds.end()) {
    std::string known;
    for (const auto& k : kinds) known += (known.empty() ? "" : ", ") + k;
    throw sgal::EditError("add_tendon: no actuator kind '" + kind + "' (" + known + ")");
  }
  sgal::Actuator a;
  a.name = name;
  a.kind = kind;
  std::string missing;
  for (const auto& p : actuators::KindParameters(kind)) {
    if (!p.required) {
      a.parameters[p.name] = p.default_value;
      continue;
    }
    bool found = false;
    for (const auto& other : scene ? scene->actuators : std::vector<sgal::Actuator>{})
      if (other.kind == kind && other.parameters.count(p.name) != 0 && !found) {
        a.parameters[p.name] = other.parameters.at(p.name);
        found = true;
      }
    if (!found) missing += (missing.empty() ? "" : ", ") + p.name;
  }
  if (!missing.empty())
    throw sgal::EditError("add_tendon: a " + kind + " needs " + missing +
                          ", which have no default and no " + kind +
                          " in the scene to copy from: declare it in the model file");
  return a;
}

}  // namespace caliper::simulation
