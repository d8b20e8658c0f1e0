#pragma once
// The scene editor's EditClient over the Model's CORBA reference (Caliper::Simulation::
// SceneEditing, idl/caliper/editing.idl). The component's thread finds the Model and keeps the
// reference up to date in a ModelReference; the scene editor's worker thread calls the Model
// through it (never the GUI thread).

#include <mutex>

#include "caliper/model.hh"
#include "caliper/render_coin/scene_editor.h"

namespace caliper::renderer {

/// The Model the renderer observes, shared between the component's thread (which sets it) and
/// the GUI thread (which calls it). Thread-safe.
class ModelReference {
 public:
  /// nil when there is none (not found yet, or unreachable).
  void Set(Caliper::Simulation::Model_ptr model);
  /// A duplicate of the current reference (nil when none); the caller owns it.
  Caliper::Simulation::Model_ptr Get() const;

 private:
  mutable std::mutex mutex_;
  Caliper::Simulation::Model_var model_;
};

class ModelEditClient : public render_coin::EditClient {
 public:
  /// Calls to the Model time out after `timeout_ms` (an edit rebuilds the engine: give it time).
  explicit ModelEditClient(const ModelReference& model, unsigned long timeout_ms = 10000)
      : model_(model), timeout_ms_(timeout_ms) {}

  void Select(const render_coin::Entity& entity) override;
  void MovePathPoint(const std::string& tendon, uint32_t index,
                     const render_coin::PathPoint& p) override;
  void InsertPathPoint(const std::string& tendon, uint32_t index,
                       const render_coin::PathPoint& p) override;
  void RemovePathPoint(const std::string& tendon, uint32_t index) override;
  void AddTendon(const std::string& tendon, const render_coin::PathPoint& from,
                 const render_coin::PathPoint& to, double radius_m, const std::string& actuator,
                 const std::string& kind) override;
  void RemoveTendon(const std::string& tendon) override;
  void SetObstacle(const render_coin::Obstacle& obstacle) override;
  void RemoveObstacle(const std::string& obstacle) override;
  std::vector<render_coin::ActuatorKindInfo> ActuatorKinds() override;
  void Pull(const std::string& body, const double point[3], const double target[3],
            double stiffness_n_per_m) override;
  void ReleasePull() override;
  /// Reads the Model's shared selection with a short timeout (it is polled).
  bool CurrentSelection(render_coin::Entity* entity, uint64_t* revision) override;

 private:
  // the Model with this client's call timeout; throws EditError when there is none
  Caliper::Simulation::Model_ptr Model() const;
  Caliper::Simulation::Model_ptr Model(unsigned long timeout_ms) const;

  const ModelReference& model_;
  unsigned long timeout_ms_;
};

}  // namespace caliper::renderer
