#pragma once
// The scene editing's bookkeeping: the undo and redo stacks of edits, the state of actuators an
// edit removed (for the undo that brings them back), the revision and label of the last edit,
// and what a GUI selected, kept pointing at the same element across edits. It knows no engine
// and no lock: ModelCore builds and swaps the edited scenes and asks it what to carry over.
//
// Threading: not thread-safe. ModelCore owns one and calls it with its lock (ModelCore::mutex_)
// held.

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "caliper/sgal/edits.h"
#include "caliper/sgal/physics_scene.h"
#include "caliper/sgal/scene.h"

namespace caliper::simulation {

/// Undo/redo, removed actuators and the selection of one Model's scene editing.
class EditHistory {
 public:
  /// An edit of the scene as loaded and the same edit of the engine's copy, each made against its
  /// own scene (its revert restores exactly that scene's values).
  struct Entry {
    sgal::SceneEdit base, current;
  };
  /// What a GUI picked: kind body, tendon, path_point, obstacle, constraint, or "" for nothing;
  /// `revision` grows at every change.
  struct Selection {
    std::string kind, name;
    uint32_t index = 0;  // of the path element (path_point), else 0
    uint64_t revision = 0;
  };
  /// Edits kept for undo; an older one is forgotten.
  static constexpr size_t kMaxUndo = 200;
  /// Removed actuators kept aside; more are forgotten.
  static constexpr size_t kMaxRemoved = 256;

  /// A new scene (load, experiment): forgets the edits, the removed actuators and the last edit's
  /// label (the revision keeps counting).
  void Forget();
  /// Forgets the undo and redo stacks only (a replay: its edits are its recording's).
  void ClearUndo();
  /// A new edit: on top of the undo stack (bounded by kMaxUndo); the redo stack is cleared.
  void Push(Entry entry);
  /// The entry an undo (or a redo) would walk, and in `depth` the size of its stack now.
  /// Throws sgal::EditError "nothing to undo" ("nothing to redo") when there is none.
  Entry Next(bool undo, size_t* depth) const;
  /// After the entry Next gave was applied: it moves onto the other stack, unless its stack no
  /// longer holds `depth` entries (a load emptied it meanwhile).
  void Walked(bool undo, size_t depth);
  /// An edit (or an undo, a redo) `what` was applied: the revision grows, `what` is the last.
  void Applied(const std::string& what);

  /// The dynamic state for `edited` (the scene after an edit) from `old_state` of `before`: the
  /// engine's own numbers are dropped; actuators are matched by name and kind, an actuator the
  /// edit removed is kept aside (at most kMaxRemoved), one it brings back takes what was kept;
  /// the delayed channels' memory is kept when the edit changed neither the measurement delays
  /// nor the time step, else dropped (they restart from their present values).
  sgal::DynamicState CarryOver(const sgal::Scene& before, const sgal::DynamicState& old_state,
                               const sgal::Scene& edited);

  /// Selects `kind` `name` (`index`: the path element of a path_point) in `scene`, which may be
  /// null only when `kind` is "" (nothing). Throws sgal::EditError for an unknown kind or a name
  /// the scene lacks, changing nothing.
  void Select(const sgal::Scene* scene, const std::string& kind, const std::string& name,
              uint32_t index);
  /// Selects nothing (a load).
  void ClearSelection();
  /// After an edit from `before` to `edited` (scenes as loaded): a selection of what it removed
  /// is cleared; a selected path element that moved (an insert or a removal before it) is
  /// followed to its new index.
  void FollowEdit(const sgal::Scene& before, const sgal::Scene& edited);

  /// Edits applied so far, undo and redo included.
  uint64_t revision() const { return revision_; }
  /// What the last edit did ("" after a load).
  const std::string& last() const { return last_; }
  /// The label of what an undo would revert ("" when nothing).
  std::string undo_label() const { return undo_.empty() ? "" : undo_.back().base.label; }
  /// The label of what a redo would apply again ("" when nothing).
  std::string redo_label() const { return redo_.empty() ? "" : redo_.back().base.label; }
  /// The current selection.
  const Selection& selection() const { return selection_; }
  /// Actuators kept aside by CarryOver (by name).
  size_t removed_actuators() const { return removed_.size(); }

 private:
  // an actuator an edit removed: its state and command
  struct RemovedActuator {
    std::string kind;
    std::vector<double> state;
    double command = 0;
  };
  void SetSelection(std::string kind, std::string name, uint32_t index);

  std::vector<Entry> undo_, redo_;  // of the loaded scene
  std::map<std::string, RemovedActuator> removed_;
  uint64_t revision_ = 0;
  std::string last_;
  Selection selection_;
};

/// The actuator of a tendon an edit adds: `kind` (a registered actuator kind) with its
/// parameters' defaults, and a parameter without a default (a ligament's stiffness, a muscle's
/// force) copied from `scene`'s first actuator of that kind that has it. Throws sgal::EditError
/// for an unknown kind, listing the known ones, or for a parameter it cannot fill.
sgal::Actuator NewActuator(const sgal::Scene* scene, const std::string& name,
                           const std::string& kind);

}  // namespace caliper::simulation
