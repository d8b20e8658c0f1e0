#pragma once
// Scene editing with the mouse in the viewer: a click selects (and tells the Model), Ctrl+drag
// pulls a moving body, a drag moves the selected path point or obstacle, the right button opens
// a menu of edits on what is under the cursor. What the Model is asked goes through an
// EditClient, so the interaction runs without CORBA in tests. The EditClient is called on a
// worker thread of the editor, never on the GUI thread: a slow or stopped Model does not freeze
// the view; its answers (a refusal's reason, the shared selection) come back to the GUI thread.
//
// Mouse and keys (on the GL area of the viewer):
//   left click                    select the body, tendon, path point or obstacle (empty: none)
//   left drag on the selected path point / obstacle   move it in the plane facing the camera
//   Ctrl + left drag on a body    pull it towards the cursor (a spring), released with the button
//   right click                   the edits of what is under the cursor
// Any other drag goes to the examiner viewer (rotate, pan, zoom).

#include <QObject>
#include <QPoint>
#include <QString>
#include <QTimer>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "caliper/render_coin/scene_graph.h"
#include "caliper/render_coin/viewer.h"

namespace caliper::render_coin {

/// The Model refused an edit, or could not be reached; what() is the reason.
class EditError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A registered actuator kind (the Model's actuator_kinds()).
struct ActuatorKindInfo {
  std::string kind;
  std::string command_unit;  // "" for passive elements
};

/// The Model's scene-editing operations (idl/caliper/editing.idl), without CORBA. Every method
/// throws EditError with the reason when the Model refuses or cannot be reached. Lengths [m].
/// The editor calls it from its worker thread, one call at a time.
class EditClient {
 public:
  virtual ~EditClient() = default;
  virtual void Select(const Entity& entity) = 0;
  virtual void MovePathPoint(const std::string& tendon, uint32_t index, const PathPoint& p) = 0;
  virtual void InsertPathPoint(const std::string& tendon, uint32_t index, const PathPoint& p) = 0;
  virtual void RemovePathPoint(const std::string& tendon, uint32_t index) = 0;
  virtual void AddTendon(const std::string& tendon, const PathPoint& from, const PathPoint& to,
                         double radius_m, const std::string& actuator, const std::string& kind) = 0;
  virtual void RemoveTendon(const std::string& tendon) = 0;
  virtual void SetObstacle(const Obstacle& obstacle) = 0;
  virtual void RemoveObstacle(const std::string& obstacle) = 0;
  virtual std::vector<ActuatorKindInfo> ActuatorKinds() = 0;
  /// Pulls `point` (body frame) of `body` towards `target` (world); 0 N/m: the Model's default.
  virtual void Pull(const std::string& body, const double point[3], const double target[3],
                    double stiffness_n_per_m) = 0;
  virtual void ReleasePull() = 0;
  /// The selection the Model shares with the other GUIs and its revision (grows with every
  /// select, and when the Model re-points a selected path point); false: the client has none.
  virtual bool CurrentSelection(Entity* /*entity*/, uint64_t* /*revision*/) { return false; }
};

class SceneEditor : public QObject {
 public:
  /// Chooses an actuator kind for a new tendon among `kinds`; false: cancelled. The default asks
  /// with a QInputDialog.
  using KindChooser = std::function<bool(const QStringList& kinds, QString* chosen)>;

  /// Watches the mouse on `viewer`'s GL area; `client` may be null (nothing is sent, the view
  /// still highlights) and must outlive the editor.
  SceneEditor(SceneGraph& graph, Viewer& viewer, EditClient* client);
  /// Releases a pull in progress; waits for the call the worker is in (the client's timeout).
  ~SceneEditor() override;

  /// Calls already queued still go to the client they were queued for: wait for
  /// pending_answers() == 0 before destroying that one.
  void set_client(EditClient* client);
  void set_kind_chooser(KindChooser chooser) { choose_kind_ = std::move(chooser); }
  /// Smallest time between two pull() calls while dragging [ms] (33: about 30 Hz).
  void set_pull_interval(std::chrono::milliseconds interval) { pull_interval_ = interval; }
  /// While a pull lasts, its target is sent again this often even when the mouse rests [ms]:
  /// the Model ends a pull not renewed within 2 s (500).
  void set_pull_renewal(std::chrono::milliseconds interval);
  /// How often the Model's shared selection is read [ms] (200).
  void set_selection_poll(std::chrono::milliseconds interval);

  /// What is selected (kind "" for nothing).
  const Entity& selection() const { return selection_; }
  /// The text naming the selection with its key values, as the tooltip showed it.
  const std::string& description() const { return description_; }
  /// The reason of the last refused edit ("" when the last one went through).
  const std::string& last_error() const { return last_error_; }
  /// Pull calls answered so far (coalesced pulls count once).
  int pulls_sent() const { return pulls_sent_; }
  /// Calls queued or in progress whose answer has not reached the GUI thread yet.
  int pending_answers() const { return pending_answers_; }

  /// The edits the context menu offers at pixel `at` (GL-area coordinates).
  std::vector<std::string> ContextActions(QPoint at);
  /// Runs one of them as if chosen from the menu; false when it is not offered there (or
  /// there is no Model). The Model answers later: a refusal shows in last_error().
  bool RunContextAction(QPoint at, const std::string& action);

  /// "tendon biceps: tension 3.2 N, length 212.4 mm" and the like.
  std::string Describe(const Entity& entity) const;

 protected:
  bool eventFilter(QObject* watched, QEvent* event) override;

 private:
  enum class Mode { kIdle, kMaybeClick, kDragPoint, kDragObstacle, kPull };

  std::vector<Hit> PickAt(QPoint at) const;
  // the point where the ray through `at` meets the plane through `plane_point_` facing the camera
  bool PlanePoint(QPoint at, double world[3]) const;
  void Select(const Entity& entity, QPoint at);
  void BeginPlaneDrag(const double world[3]);
  void DragTo(QPoint at);
  void FinishDrag(QPoint at);
  void PullTo(QPoint at, bool force);
  // shows the reason (status line and tooltip); the markers go back to their declared places
  void Refused(const std::string& what, const std::string& reason, QPoint at);
  // queues `edit` for the worker; its refusal calls Refused when it arrives. false: no client
  bool Send(const std::string& what, QPoint at, std::function<void(EditClient&)> edit);
  // the worker's side: a call to the client; `answer` runs on the GUI thread with the error
  // ("" = done)
  struct Job {
    EditClient* client = nullptr;
    std::function<void(EditClient&)> call;
    std::function<void(const std::string& error)> answer;
    bool pull = false;  // a pull's target: a later pull still queued replaces it
    std::string body;
    double local[3] = {0, 0, 0};
    double target[3] = {0, 0, 0};
  };
  void Queue(Job job);
  void QueuePull();
  void WorkerLoop();
  // the Model's selection read by the worker, on the GUI thread
  void ModelSelected(const Entity& entity, uint64_t revision);
  void Redraw();
  const Tendon* FindTendon(const std::string& name) const;
  const Obstacle* FindObstacle(const std::string& name) const;
  std::string FreeName(const std::string& prefix, bool tendon) const;

  SceneGraph& graph_;
  Viewer& viewer_;
  EditClient* client_ = nullptr;
  KindChooser choose_kind_;
  std::chrono::milliseconds pull_interval_{33};

  Entity selection_;
  std::string description_;
  std::string last_error_;
  Mode mode_ = Mode::kIdle;
  QPoint press_at_;
  Entity press_entity_;
  double plane_point_[3] = {0, 0, 0};  // [m, world]
  double grab_offset_[3] = {0, 0, 0};  // dragged element - grabbed point [m, world]
  // a pull: the body, the grabbed point in its frame, the last target and when it was sent
  std::string pull_body_;
  double pull_local_[3] = {0, 0, 0};
  double pull_target_[3] = {0, 0, 0};
  bool pull_pending_ = false;
  std::chrono::steady_clock::time_point last_pull_{};
  int pulls_sent_ = 0;
  QTimer pull_renewal_;
  int pending_answers_ = 0;
  int selects_in_flight_ = 0;  // the Model's selection read meanwhile may predate them
  bool model_selection_known_ = false;
  uint64_t model_selection_revision_ = 0;
  // shared with the worker, under mutex_
  std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<Job> jobs_;
  EditClient* poll_client_ = nullptr;
  std::chrono::milliseconds poll_interval_{200};
  bool stopping_ = false;
  std::thread worker_;  // last: starts when everything else is built
  // "Start tendon here": the first end of a tendon being added
  bool tendon_started_ = false;
  PathPoint tendon_start_;
};

}  // namespace caliper::render_coin
