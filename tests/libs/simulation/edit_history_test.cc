// Scene editing's bookkeeping on its own, over scenes built in memory: undo and redo stacks with
// their bound and their messages, a walk that a load overtook, the revision, the state an edit
// carries over (actuators by name and kind, removed ones kept for the undo), the selection's
// refusals and how it follows an edit.
#include "caliper/simulation/edit_history.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace caliper::simulation {
namespace {

/// An edit that only has a label (the history never applies edits itself).
EditHistory::Entry Labelled(const std::string& label) {
  EditHistory::Entry e;
  e.base.label = label;
  e.current.label = label + " (engine's copy)";
  return e;
}

std::string Error(const std::function<void()>& f) {
  try {
    f();
  } catch (const sgal::EditError& e) {
    return e.what();
  }
  return "";
}

sgal::PathElement Point(const std::string& body, double x) {
  sgal::PathElement p;
  p.body = body;
  p.position = Eigen::Vector3d(x, 0, 0);
  return p;
}

/// Two bodies, a hinge, an obstacle, a tendon of three points and two motors.
sgal::Scene Arm() {
  sgal::Scene s;
  s.bodies.resize(2);
  s.bodies[0].name = "base";
  s.bodies[1].name = "link";
  s.constraints.resize(1);
  s.constraints[0].name = "elbow";
  s.obstacles.resize(1);
  s.obstacles[0].name = "pulley";
  s.tendons.resize(1);
  s.tendons[0].name = "flexor";
  s.tendons[0].path = {Point("base", 0), Point("link", 1), Point("link", 2)};
  s.actuators = {{"m1", "dc_motor_tendon", "flexor", {}, {}},
                 {"m2", "dc_motor_tendon", "flexor", {}, {}}};
  return s;
}

TEST(EditHistory, SaysWhenThereIsNothingToWalk) {
  EditHistory h;
  size_t depth = 0;
  EXPECT_EQ(Error([&] { h.Next(true, &depth); }), "nothing to undo");
  EXPECT_EQ(Error([&] { h.Next(false, &depth); }), "nothing to redo");
  EXPECT_EQ(h.undo_label(), "");
  EXPECT_EQ(h.redo_label(), "");
}

TEST(EditHistory, WalksEditsBetweenUndoAndRedo) {
  EditHistory h;
  h.Push(Labelled("a"));
  h.Push(Labelled("b"));
  EXPECT_EQ(h.undo_label(), "b");
  size_t depth = 0;
  const EditHistory::Entry next = h.Next(true, &depth);
  EXPECT_EQ(next.base.label, "b");
  EXPECT_EQ(next.current.label, "b (engine's copy)");
  EXPECT_EQ(depth, 2u);
  h.Walked(true, depth);
  EXPECT_EQ(h.undo_label(), "a");
  EXPECT_EQ(h.redo_label(), "b");
  EXPECT_EQ(h.Next(false, &depth).base.label, "b");
  h.Walked(false, depth);
  EXPECT_EQ(h.undo_label(), "b");
  EXPECT_EQ(h.redo_label(), "");
  h.Walked(true, 2);
  h.Push(Labelled("c"));  // a new edit forgets what could be redone
  EXPECT_EQ(h.undo_label(), "c");
  EXPECT_EQ(h.redo_label(), "");
}

TEST(EditHistory, WalkOvertakenByALoadMovesNothing) {
  EditHistory h;
  h.Push(Labelled("a"));
  size_t depth = 0;
  h.Next(true, &depth);
  h.Forget();  // a load while the undo was built
  h.Walked(true, depth);
  EXPECT_EQ(h.redo_label(), "");
  EXPECT_EQ(h.undo_label(), "");
}

TEST(EditHistory, KeepsTheLastEditsOnly) {
  EditHistory h;
  for (size_t i = 0; i <= EditHistory::kMaxUndo; ++i) h.Push(Labelled(std::to_string(i)));
  size_t depth = 0;
  EXPECT_EQ(h.Next(true, &depth).base.label, std::to_string(EditHistory::kMaxUndo));
  EXPECT_EQ(depth, EditHistory::kMaxUndo);
  for (size_t i = 0; i < EditHistory::kMaxUndo - 1; ++i) {
    h.Next(true, &depth);
    h.Walked(true, depth);
  }
  EXPECT_EQ(h.undo_label(), "1");  // "0" was forgotten
}

TEST(EditHistory, CountsRevisionsAcrossLoads) {
  EditHistory h;
  h.Applied("move a point");
  h.Applied("undo move a point");
  EXPECT_EQ(h.revision(), 2u);
  EXPECT_EQ(h.last(), "undo move a point");
  h.Forget();
  EXPECT_EQ(h.revision(), 2u);
  EXPECT_EQ(h.last(), "");
}

TEST(EditHistory, CarriesActuatorsOverByNameAndKeepsRemovedOnes) {
  EditHistory h;
  const sgal::Scene before = Arm();
  sgal::DynamicState state;
  state.time = 1.5;
  state.actuators = {{1, 2}, {3}};
  state.commands = {0.5, 0.7};
  state.engine = {9, 9};
  sgal::Scene without_m1 = Arm();
  without_m1.actuators = {before.actuators[1], {"m3", "ligament", "flexor", {}, {}}};
  const sgal::DynamicState edited = h.CarryOver(before, state, without_m1);
  EXPECT_EQ(edited.time, 1.5);
  EXPECT_TRUE(edited.engine.empty());  // the engine's numbers belong to the old scene
  EXPECT_EQ(edited.actuators, (std::vector<std::vector<double>>{{3}, {}}));
  EXPECT_EQ(edited.commands, (std::vector<double>{0.7, 0.0}));
  EXPECT_EQ(h.removed_actuators(), 1u);
  // the undo brings m1 back with its state and command
  const sgal::DynamicState undone = h.CarryOver(without_m1, edited, before);
  EXPECT_EQ(undone.actuators, (std::vector<std::vector<double>>{{1, 2}, {3}}));
  EXPECT_EQ(undone.commands, (std::vector<double>{0.5, 0.7}));
  EXPECT_EQ(h.removed_actuators(), 1u);  // m3 is aside now
}

TEST(EditHistory, DoesNotCarryAnActuatorOverToAnotherKind) {
  EditHistory h;
  const sgal::Scene before = Arm();
  sgal::DynamicState state;
  state.actuators = {{1, 2}, {3}};
  state.commands = {0.5, 0.7};
  sgal::Scene changed = Arm();
  changed.actuators[0].kind = "hill_muscle";
  const sgal::DynamicState edited = h.CarryOver(before, state, changed);
  EXPECT_TRUE(edited.actuators[0].empty());
  EXPECT_EQ(edited.commands[0], 0.0);
  EXPECT_EQ(edited.commands[1], 0.7);
}

TEST(EditHistory, RefusesSelectionsTheSceneLacks) {
  EditHistory h;
  const sgal::Scene arm = Arm();
  EXPECT_EQ(Error([&] { h.Select(&arm, "joint", "elbow", 0); }),
            "select: unknown kind 'joint' (body, tendon, path_point, obstacle, constraint, or '' "
            "for none)");
  EXPECT_EQ(Error([&] { h.Select(&arm, "body", "hand", 0); }),
            "select: the scene has no body 'hand'");
  EXPECT_EQ(Error([&] { h.Select(&arm, "path_point", "flexor", 3); }),
            "select: the scene has no path_point 'flexor' with element 3");
  EXPECT_EQ(h.selection().revision, 0u);  // refusals change nothing
  for (const char* kind : {"body", "tendon", "obstacle", "constraint"}) {
    const std::string name = std::string(kind) == "body"       ? "link"
                             : std::string(kind) == "tendon"   ? "flexor"
                             : std::string(kind) == "obstacle" ? "pulley"
                                                               : "elbow";
    EXPECT_EQ(Error([&] { h.Select(&arm, kind, name, 7); }), "") << kind;
    EXPECT_EQ(h.selection().kind, kind);
    EXPECT_EQ(h.selection().index, 0u);  // only a path_point has one
  }
  EXPECT_EQ(h.selection().revision, 4u);
  h.Select(nullptr, "", "ignored", 2);  // nothing needs no scene
  EXPECT_EQ(h.selection().name, "");
  EXPECT_EQ(h.selection().revision, 5u);
}

TEST(EditHistory, SelectionFollowsAPathElementThatMoved) {
  EditHistory h;
  const sgal::Scene before = Arm();
  h.Select(&before, "path_point", "flexor", 2);
  sgal::Scene inserted = Arm();
  auto& path = inserted.tendons[0].path;
  path.insert(path.begin() + 1, Point("link", 0.5));
  h.FollowEdit(before, inserted);
  EXPECT_EQ(h.selection().kind, "path_point");
  EXPECT_EQ(h.selection().index, 3u);
  EXPECT_EQ(h.selection().revision, 2u);
  // a move of another element keeps it as it is
  sgal::Scene moved = inserted;
  moved.tendons[0].path[1].position.x() = 0.25;
  h.FollowEdit(inserted, moved);
  EXPECT_EQ(h.selection().index, 3u);
  EXPECT_EQ(h.selection().revision, 2u);
  // its own removal ends it
  sgal::Scene removed = moved;
  removed.tendons[0].path.erase(removed.tendons[0].path.begin() + 3);
  h.FollowEdit(moved, removed);
  EXPECT_EQ(h.selection().kind, "");
  EXPECT_EQ(h.selection().revision, 3u);
}

TEST(EditHistory, SelectionOfWhatAnEditRemovedEnds) {
  EditHistory h;
  const sgal::Scene before = Arm();
  sgal::Scene no_obstacle = Arm();
  no_obstacle.obstacles.clear();
  h.Select(&before, "obstacle", "pulley", 0);
  h.FollowEdit(before, no_obstacle);
  EXPECT_EQ(h.selection().kind, "");
  sgal::Scene no_tendon = Arm();
  no_tendon.tendons.clear();
  h.Select(&before, "tendon", "flexor", 0);
  h.FollowEdit(before, no_tendon);
  EXPECT_EQ(h.selection().kind, "");
  h.Select(&before, "body", "link", 0);
  h.FollowEdit(before, no_tendon);  // a body stays
  EXPECT_EQ(h.selection().name, "link");
}

}  // namespace
}  // namespace caliper::simulation
