#include "caliper/render_coin/scene_editor.h"

#include <QCursor>
#include <QEvent>
#include <QInputDialog>
#include <QKeyEvent>
#include <QMenu>
#include <QMouseEvent>
#include <QTimer>
#include <QToolTip>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>

namespace caliper::render_coin {

namespace {

constexpr int kClickSlop = 4;                // [px] a press and release closer than this click
constexpr double kNewObstacleRadius = 0.02;  // [m], "Add obstacle here"
constexpr double kNewTendonRadius = 0.0015;  // [m], "End tendon here"
constexpr double kOnBody = 0.03;             // [m] a tendon this near a body's surface lies on it
constexpr double kGrow = 1.2;                // "Grow 20%"
constexpr double kShrink = 0.8;              // "Shrink 20%"

constexpr const char* kInsertVia = "Insert via point here";
constexpr const char* kRemoveTendon = "Remove tendon";
constexpr const char* kRemoveVia = "Remove via point";
constexpr const char* kAddObstacle = "Add obstacle here";
constexpr const char* kStartTendon = "Start tendon here";
constexpr const char* kEndTendon = "End tendon here";
constexpr const char* kGrowObstacle = "Grow 20%";
constexpr const char* kShrinkObstacle = "Shrink 20%";
constexpr const char* kRemoveObstacle = "Remove obstacle";

double DistanceToSegment(const double p[3], const double a[3], const double b[3]) {
  double ab[3], ap[3];
  double ab2 = 0, t = 0;
  for (int i = 0; i < 3; ++i) {
    ab[i] = b[i] - a[i];
    ap[i] = p[i] - a[i];
    ab2 += ab[i] * ab[i];
    t += ap[i] * ab[i];
  }
  t = ab2 > 0 ? std::clamp(t / ab2, 0.0, 1.0) : 0.0;
  double d2 = 0;
  for (int i = 0; i < 3; ++i) d2 += std::pow(ap[i] - t * ab[i], 2);
  return std::sqrt(d2);
}

std::string Millimetres(const double p[3]) {
  char text[96];
  std::snprintf(text, sizeof text, "%.1f %.1f %.1f mm", 1000 * p[0], 1000 * p[1], 1000 * p[2]);
  return text;
}

bool DefaultKindChooser(const QStringList& kinds, QString* chosen) {
  bool ok = false;
  *chosen = QInputDialog::getItem(nullptr, "New tendon", "Actuator kind:", kinds, 0, false, &ok);
  return ok && !chosen->isEmpty();
}

}  // namespace

SceneEditor::SceneEditor(SceneGraph& graph, Viewer& viewer, EditClient* client)
    : graph_(graph),
      viewer_(viewer),
      client_(client),
      choose_kind_(DefaultKindChooser),
      poll_client_(client) {
  viewer_.gl_widget()->installEventFilter(this);
  // the Model ends a pull it has not heard of for 2 s: renew it while the button is held
  pull_renewal_.setInterval(500);
  connect(&pull_renewal_, &QTimer::timeout, this, [this] {
    if (mode_ == Mode::kPull) QueuePull();
  });
  worker_ = std::thread([this] { WorkerLoop(); });
}

SceneEditor::~SceneEditor() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    // what is still queued has nobody to answer to; a pull in progress must not outlive us
    jobs_.clear();
    if (mode_ == Mode::kPull && client_ != nullptr) {
      Job release;
      release.client = client_;
      release.call = [](EditClient& c) { c.ReleasePull(); };
      jobs_.push_back(std::move(release));
    }
    stopping_ = true;
  }
  wake_.notify_all();
  worker_.join();
}

void SceneEditor::set_client(EditClient* client) {
  client_ = client;
  std::lock_guard<std::mutex> lock(mutex_);
  poll_client_ = client;
  model_selection_known_ = false;
}

void SceneEditor::set_pull_renewal(std::chrono::milliseconds interval) {
  pull_renewal_.setInterval(static_cast<int>(interval.count()));
}

void SceneEditor::set_selection_poll(std::chrono::milliseconds interval) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    poll_interval_ = interval;
  }
  wake_.notify_all();
}

void SceneEditor::Queue(Job job) {
  ++pending_answers_;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    jobs_.push_back(std::move(job));
  }
  wake_.notify_all();
}

void SceneEditor::QueuePull() {
  pull_pending_ = false;
  last_pull_ = std::chrono::steady_clock::now();
  if (client_ == nullptr) return;
  {
    // a pull still waiting for the worker takes the new target: only the latest is sent
    std::lock_guard<std::mutex> lock(mutex_);
    if (!jobs_.empty() && jobs_.back().pull && jobs_.back().client == client_ &&
        jobs_.back().body == pull_body_) {
      for (int i = 0; i < 3; ++i) jobs_.back().target[i] = pull_target_[i];
      return;
    }
  }
  Job job;
  job.client = client_;
  job.pull = true;
  job.body = pull_body_;
  for (int i = 0; i < 3; ++i) {
    job.local[i] = pull_local_[i];
    job.target[i] = pull_target_[i];
  }
  const std::string body = pull_body_;
  job.answer = [this, body](const std::string& error) {
    if (error.empty()) {
      ++pulls_sent_;
      if (mode_ == Mode::kPull) last_error_.clear();
      return;
    }
    if (mode_ == Mode::kPull && pull_body_ == body) {
      mode_ = Mode::kIdle;
      pull_renewal_.stop();
      graph_.SetPullLine(-1, nullptr, nullptr);
    }
    Refused("pull on " + body, error, viewer_.gl_widget()->mapFromGlobal(QCursor::pos()));
  };
  Queue(std::move(job));
}

void SceneEditor::WorkerLoop() {
  auto next_poll = std::chrono::steady_clock::now();
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    wake_.wait_until(lock, next_poll, [&] {
      return stopping_ || !jobs_.empty() || std::chrono::steady_clock::now() >= next_poll;
    });
    if (!jobs_.empty()) {
      Job job = std::move(jobs_.front());
      jobs_.pop_front();
      lock.unlock();
      std::string error;
      try {
        if (job.pull)
          job.client->Pull(job.body, job.local, job.target, 0);
        else
          job.call(*job.client);
      } catch (const std::exception& e) {
        error = e.what();
        if (error.empty()) error = "unknown error";
      }
      if (job.answer)
        QMetaObject::invokeMethod(
            this,
            [this, answer = std::move(job.answer), error] {
              --pending_answers_;
              answer(error);
            },
            Qt::QueuedConnection);
      lock.lock();
      continue;
    }
    if (stopping_) return;
    if (std::chrono::steady_clock::now() < next_poll) continue;
    next_poll = std::chrono::steady_clock::now() + poll_interval_;
    EditClient* client = poll_client_;
    if (client == nullptr) continue;
    lock.unlock();
    Entity entity;
    uint64_t revision = 0;
    bool known = false;
    try {
      known = client->CurrentSelection(&entity, &revision);
    } catch (const std::exception&) {
      // no Model (yet) or one that does not answer: the next poll asks again
    }
    if (known)
      QMetaObject::invokeMethod(
          this, [this, entity, revision] { ModelSelected(entity, revision); },
          Qt::QueuedConnection);
    lock.lock();
  }
}

void SceneEditor::ModelSelected(const Entity& entity, uint64_t revision) {
  // read before a select of ours reached the Model: it would undo the click for a moment
  if (selects_in_flight_ > 0) return;
  const bool changed = !model_selection_known_ || revision != model_selection_revision_;
  model_selection_known_ = true;
  model_selection_revision_ = revision;
  // a drag in progress keeps what it drags until it is dropped
  if (!changed || entity == selection_ || mode_ == Mode::kDragPoint || mode_ == Mode::kDragObstacle)
    return;
  selection_ = entity;
  graph_.SetHighlight(entity);
  description_ = Describe(entity);
  graph_.SetStatus(description_);
  Redraw();
}

std::vector<Hit> SceneEditor::PickAt(QPoint at) const {
  const QSize size = viewer_.view_size();
  return graph_.Pick(at.x(), at.y(), size.width(), size.height());
}

bool SceneEditor::PlanePoint(QPoint at, double world[3]) const {
  const QSize size = viewer_.view_size();
  double origin[3], direction[3];
  graph_.Ray(at.x(), at.y(), size.width(), size.height(), origin, direction);
  const auto normal = graph_.view_direction();
  double along = 0, offset = 0;
  for (int i = 0; i < 3; ++i) {
    along += direction[i] * normal[i];
    offset += (plane_point_[i] - origin[i]) * normal[i];
  }
  if (std::abs(along) < 1e-9) return false;  // the ray runs in the plane
  const double t = offset / along;
  for (int i = 0; i < 3; ++i) world[i] = origin[i] + t * direction[i];
  return true;
}

void SceneEditor::BeginPlaneDrag(const double world[3]) {
  for (int i = 0; i < 3; ++i) plane_point_[i] = world[i];
}

const Tendon* SceneEditor::FindTendon(const std::string& name) const {
  for (const Tendon& t : graph_.scene().tendons)
    if (t.name == name) return &t;
  return nullptr;
}

const Obstacle* SceneEditor::FindObstacle(const std::string& name) const {
  for (const Obstacle& o : graph_.scene().obstacles)
    if (o.name == name) return &o;
  return nullptr;
}

std::string SceneEditor::FreeName(const std::string& prefix, bool tendon) const {
  for (int n = 1;; ++n) {
    const std::string name = prefix + std::to_string(n);
    if (tendon ? FindTendon(name) == nullptr : FindObstacle(name) == nullptr) return name;
  }
}

std::string SceneEditor::Describe(const Entity& e) const {
  const SceneDescription& scene = graph_.scene();
  char text[256];
  if (e.kind == "body") {
    const int index = graph_.body_index(e.name);
    if (index < 0) return "body " + e.name;
    const Body& body = scene.bodies[static_cast<size_t>(index)];
    const Pose pose = graph_.body_pose(static_cast<size_t>(index));
    std::snprintf(text, sizeof text, " (moving, %.3g kg)", body.mass);
    return "body " + e.name + (body.moving ? std::string(text) : std::string(" (fixed)")) + " at " +
           Millimetres(pose.p);
  }
  if (e.kind == "tendon") {
    for (size_t i = 0; i < scene.tendons.size(); ++i) {
      if (scene.tendons[i].name != e.name) continue;
      const TendonState* state = graph_.tendon_state(i);
      if (state == nullptr) return "tendon " + e.name + " (no state received yet)";
      std::snprintf(text, sizeof text, "tendon %s: tension %.2f N, length %.1f mm", e.name.c_str(),
                    state->tension, 1000 * state->length);
      return text;
    }
    return "tendon " + e.name;
  }
  if (e.kind == "path_point") {
    const Tendon* t = FindTendon(e.name);
    if (t == nullptr || e.index >= t->path.size()) return "path point " + e.name;
    const PathPoint& p = t->path[e.index];
    const bool end = e.index == 0 || e.index + 1 == t->path.size();
    const std::string what = !p.obstacle.empty() ? "wrap around " + p.obstacle
                             : end               ? "attachment"
                                                 : "via point";
    double local[3] = {p.p[0], p.p[1], p.p[2]};
    graph_.PathPointMarker(e.name, e.index, local);
    return "tendon " + e.name + " point " + std::to_string(e.index) + " (" + what + ") on " +
           (p.body.empty() ? std::string("the world") : "body " + p.body) + " at " +
           Millimetres(local) + " (body frame)";
  }
  if (e.kind == "obstacle") {
    const Obstacle* o = FindObstacle(e.name);
    if (o == nullptr) return "obstacle " + e.name;
    std::snprintf(
        text, sizeof text, "obstacle %s: %s, radius %.1f mm%s on %s", e.name.c_str(),
        o->kind.c_str(), 1000 * o->radius,
        o->kind == "cylinder"
            ? (", length " + std::to_string(std::lround(1000 * o->length)) + " mm").c_str()
            : "",
        o->body.empty() ? "the world" : ("body " + o->body).c_str());
    return text;
  }
  return "";
}

void SceneEditor::Select(const Entity& entity, QPoint at) {
  selection_ = entity;
  graph_.SetHighlight(entity);
  description_ = Describe(entity);
  graph_.SetStatus(description_);
  QWidget* widget = viewer_.gl_widget();
  if (description_.empty())
    QToolTip::hideText();
  else
    QToolTip::showText(widget->mapToGlobal(at), QString::fromStdString(description_), widget);
  if (client_ != nullptr) {
    ++selects_in_flight_;
    Job job;
    job.client = client_;
    job.call = [entity](EditClient& c) { c.Select(entity); };
    job.answer = [this](const std::string& error) {
      --selects_in_flight_;
      last_error_ = error;
      if (!error.empty()) graph_.SetStatus(description_ + "  (the Model: " + error + ")");
    };
    Queue(std::move(job));
  }
  Redraw();
}

void SceneEditor::Refused(const std::string& what, const std::string& reason, QPoint at) {
  last_error_ = reason;
  const std::string text = what + " refused: " + reason;
  graph_.SetStatus(text);
  QWidget* widget = viewer_.gl_widget();
  QToolTip::showText(widget->mapToGlobal(at), QString::fromStdString(text), widget);
  if (selection_.kind == "path_point")
    graph_.SetPathPointMarker(selection_.name, selection_.index, nullptr);
  if (selection_.kind == "obstacle") graph_.SetObstacleMarker(selection_.name, nullptr);
  Redraw();
}

bool SceneEditor::Send(const std::string& what, QPoint at, std::function<void(EditClient&)> edit) {
  if (client_ == nullptr) {
    Refused(what, "no Model to edit", at);
    return false;
  }
  Job job;
  job.client = client_;
  job.call = std::move(edit);
  const Entity sent_for = selection_;
  job.answer = [this, what, at, sent_for](const std::string& error) {
    if (!error.empty()) {
      // the element dragged goes back even when the selection moved on meanwhile
      if (sent_for.kind == "path_point")
        graph_.SetPathPointMarker(sent_for.name, sent_for.index, nullptr);
      if (sent_for.kind == "obstacle") graph_.SetObstacleMarker(sent_for.name, nullptr);
      Refused(what, error, at);
      return;
    }
    last_error_.clear();
    graph_.SetStatus(what);
    Redraw();
  };
  Queue(std::move(job));
  graph_.SetStatus(what + " (sent)");
  Redraw();
  return true;
}

void SceneEditor::Redraw() { viewer_.ScheduleRedraw(); }

void SceneEditor::DragTo(QPoint at) {
  double world[3];
  if (!PlanePoint(at, world)) return;
  for (int i = 0; i < 3; ++i) world[i] += grab_offset_[i];
  if (mode_ == Mode::kDragPoint) {
    const Tendon* t = FindTendon(selection_.name);
    Pose body;
    if (t == nullptr || selection_.index >= t->path.size() ||
        !graph_.BodyPose(t->path[selection_.index].body, &body))
      return;
    double local[3];
    ToLocal(body, world, local);
    graph_.SetPathPointMarker(selection_.name, selection_.index, local);
  } else {
    const Obstacle* o = FindObstacle(selection_.name);
    Pose body;
    if (o == nullptr || !graph_.BodyPose(o->body, &body)) return;
    Pose pose = o->pose;
    ToLocal(body, world, pose.p);
    graph_.SetObstacleMarker(o->name, &pose);
  }
  Redraw();
}

void SceneEditor::FinishDrag(QPoint at) {
  DragTo(at);
  if (mode_ == Mode::kDragPoint) {
    const Tendon* t = FindTendon(selection_.name);
    if (t == nullptr || selection_.index >= t->path.size()) return;
    PathPoint moved = t->path[selection_.index];
    graph_.PathPointMarker(selection_.name, selection_.index, moved.p);
    const std::string tendon = selection_.name;
    const uint32_t index = selection_.index;
    Send("move point " + std::to_string(index) + " of " + tendon + " to " + Millimetres(moved.p),
         at, [=](EditClient& c) { c.MovePathPoint(tendon, index, moved); });
  } else {
    const Obstacle* o = FindObstacle(selection_.name);
    if (o == nullptr) return;
    Obstacle moved = *o;
    Pose body;
    double world[3];
    if (!graph_.BodyPose(o->body, &body) || !PlanePoint(at, world)) return;
    for (int i = 0; i < 3; ++i) world[i] += grab_offset_[i];
    ToLocal(body, world, moved.pose.p);
    Send("move obstacle " + moved.name + " to " + Millimetres(moved.pose.p), at,
         [=](EditClient& c) { c.SetObstacle(moved); });
  }
}

void SceneEditor::PullTo(QPoint at, bool force) {
  if (!PlanePoint(at, pull_target_)) return;
  graph_.SetPullLine(graph_.body_index(pull_body_), pull_local_, pull_target_);
  Redraw();
  const auto now = std::chrono::steady_clock::now();
  if (!force && now - last_pull_ < pull_interval_) {
    // send the latest target when the interval is over, even if the mouse stops here
    if (!pull_pending_)
      QTimer::singleShot(pull_interval_, this, [this] {
        if (mode_ == Mode::kPull && pull_pending_) QueuePull();
      });
    pull_pending_ = true;
    return;
  }
  QueuePull();
}

std::vector<std::string> SceneEditor::ContextActions(QPoint at) {
  const std::vector<Hit> hits = PickAt(at);
  if (hits.empty()) return {};
  const Entity& e = hits.front().entity;
  if (e.kind == "tendon") return {kInsertVia, kRemoveTendon};
  if (e.kind == "path_point") return {kRemoveVia};
  if (e.kind == "body") return {kAddObstacle, tendon_started_ ? kEndTendon : kStartTendon};
  if (e.kind == "obstacle") return {kGrowObstacle, kShrinkObstacle, kRemoveObstacle};
  return {};
}

bool SceneEditor::RunContextAction(QPoint at, const std::string& action) {
  const std::vector<std::string> offered = ContextActions(at);
  if (std::find(offered.begin(), offered.end(), action) == offered.end()) {
    last_error_ = "'" + action + "' is not offered here";
    return false;
  }
  const std::vector<Hit> hits = PickAt(at);
  const Hit& hit = hits.front();
  const Entity& e = hit.entity;
  if (action == kRemoveTendon)
    return Send("remove tendon " + e.name, at, [=](EditClient& c) { c.RemoveTendon(e.name); });
  if (action == kRemoveVia)
    return Send("remove point " + std::to_string(e.index) + " of " + e.name, at,
                [=](EditClient& c) { c.RemovePathPoint(e.name, e.index); });
  if (action == kRemoveObstacle)
    return Send("remove obstacle " + e.name, at, [=](EditClient& c) { c.RemoveObstacle(e.name); });
  if (action == kGrowObstacle || action == kShrinkObstacle) {
    const Obstacle* o = FindObstacle(e.name);
    if (o == nullptr) return false;
    Obstacle resized = *o;
    const double factor = action == kGrowObstacle ? kGrow : kShrink;
    resized.radius *= factor;
    resized.length *= factor;
    return Send(action + " " + e.name, at, [=](EditClient& c) { c.SetObstacle(resized); });
  }
  if (action == kInsertVia) {
    const Tendon* t = FindTendon(e.name);
    if (t == nullptr || t->path.size() < 2) return false;
    // the declared elements where they are now: points on their bodies, wraps at their obstacles
    std::vector<std::array<double, 3>> where(t->path.size());
    std::vector<std::string> body_of(t->path.size());
    for (size_t i = 0; i < t->path.size(); ++i) {
      const PathPoint& p = t->path[i];
      Pose pose;
      if (p.obstacle.empty()) {
        body_of[i] = p.body;
        graph_.BodyPose(p.body, &pose);
        ToWorld(pose, p.p, where[i].data());
      } else if (const Obstacle* o = FindObstacle(p.obstacle)) {
        body_of[i] = o->body;
        graph_.BodyPose(o->body, &pose);
        ToWorld(pose, o->pose.p, where[i].data());
      }
    }
    size_t segment = 0;
    double best = 1e300;
    for (size_t i = 0; i + 1 < where.size(); ++i) {
      const double d = DistanceToSegment(hit.point, where[i].data(), where[i + 1].data());
      if (d < best) {
        best = d;
        segment = i;
      }
    }
    // the body under the cursor where the tendon lies on it (not one far behind), else the
    // body of the segment's nearer end
    std::string body;
    bool found = false;
    for (const Hit& h : hits) {
      if (h.entity.kind != "body" || DistanceToSegment(h.point, hit.point, hit.point) > kOnBody)
        continue;
      body = h.entity.name;
      found = true;
      break;
    }
    if (!found) {
      const double to_start =
          DistanceToSegment(hit.point, where[segment].data(), where[segment].data());
      const double to_end =
          DistanceToSegment(hit.point, where[segment + 1].data(), where[segment + 1].data());
      body = body_of[to_start <= to_end ? segment : segment + 1];
    }
    PathPoint point;
    point.body = body;
    Pose pose;
    graph_.BodyPose(body, &pose);
    ToLocal(pose, hit.point, point.p);
    const uint32_t index = static_cast<uint32_t>(segment + 1);
    return Send("insert a via point into " + e.name + " on " + body + " at " + Millimetres(point.p),
                at, [=](EditClient& c) { c.InsertPathPoint(e.name, index, point); });
  }
  // the rest act on a body at the picked point
  Pose pose;
  graph_.BodyPose(e.name, &pose);
  PathPoint here;
  here.body = e.name;
  ToLocal(pose, hit.point, here.p);
  if (action == kAddObstacle) {
    Obstacle o;
    o.name = FreeName("obstacle", false);
    o.body = e.name;
    o.kind = "sphere";
    for (int i = 0; i < 3; ++i) o.pose.p[i] = here.p[i];
    o.radius = kNewObstacleRadius;
    return Send("add obstacle " + o.name + " on " + e.name, at,
                [=](EditClient& c) { c.SetObstacle(o); });
  }
  if (action == kStartTendon) {
    tendon_started_ = true;
    tendon_start_ = here;
    last_error_.clear();
    graph_.SetStatus("a new tendon starts on " + e.name + " at " + Millimetres(here.p) +
                     ": right-click its other body, End tendon here");
    Redraw();
    return true;
  }
  if (action == kEndTendon) {
    tendon_started_ = false;
    if (client_ == nullptr) {
      Refused("add tendon", "no Model to edit", at);
      return false;
    }
    // the kinds come from the Model (on the worker); the choice and the edit follow the answer
    auto kinds = std::make_shared<std::vector<ActuatorKindInfo>>();
    Job job;
    job.client = client_;
    job.call = [kinds](EditClient& c) { *kinds = c.ActuatorKinds(); };
    const PathPoint from = tendon_start_;
    job.answer = [this, kinds, from, here, at](const std::string& error) {
      if (!error.empty()) {
        Refused("add tendon", error, at);
        return;
      }
      QStringList names;
      for (const ActuatorKindInfo& k : *kinds) names << QString::fromStdString(k.kind);
      QString kind;
      if (names.isEmpty() || !choose_kind_(names, &kind)) {
        graph_.SetStatus("add tendon cancelled");
        return;
      }
      const std::string name = FreeName("tendon", true);
      const std::string actuator = "actuator" + name.substr(6);
      const std::string chosen = kind.toStdString();
      Send("add tendon " + name + " (" + chosen + ")", at, [=](EditClient& c) {
        c.AddTendon(name, from, here, kNewTendonRadius, actuator, chosen);
      });
    };
    Queue(std::move(job));
    graph_.SetStatus("add tendon: asking the Model for the actuator kinds");
    return true;
  }
  return false;
}

bool SceneEditor::eventFilter(QObject* watched, QEvent* event) {
  if (watched != viewer_.gl_widget()) return false;
  switch (event->type()) {
    case QEvent::MouseButtonPress: {
      auto* e = static_cast<QMouseEvent*>(event);
      const QPoint at = e->pos();
      if (e->button() == Qt::RightButton) {
        const std::vector<std::string> actions = ContextActions(at);
        if (actions.empty()) return false;  // the viewer's own menu
        QMenu menu;
        for (const std::string& a : actions) menu.addAction(QString::fromStdString(a));
        const QAction* chosen = menu.exec(e->globalPos());
        if (chosen != nullptr) RunContextAction(at, chosen->text().toStdString());
        return true;
      }
      if (e->button() != Qt::LeftButton) return false;
      const std::vector<Hit> hits = PickAt(at);
      if (e->modifiers() & Qt::ControlModifier) {
        // pull the first moving body under the cursor
        for (const Hit& h : hits) {
          const int index = h.entity.kind == "body" ? graph_.body_index(h.entity.name) : -1;
          if (index < 0 || !graph_.scene().bodies[static_cast<size_t>(index)].moving) continue;
          pull_body_ = h.entity.name;
          ToLocal(graph_.body_pose(static_cast<size_t>(index)), h.point, pull_local_);
          BeginPlaneDrag(h.point);
          mode_ = Mode::kPull;
          pull_pending_ = false;
          last_pull_ = {};
          for (int i = 0; i < 3; ++i) pull_target_[i] = h.point[i];
          pull_renewal_.start();
          graph_.SetPullLine(index, pull_local_, h.point);
          graph_.SetStatus("pulling " + pull_body_);
          Redraw();
          return true;
        }
        return false;
      }
      const Entity top = hits.empty() ? Entity() : hits.front().entity;
      if (!top.kind.empty() && top == selection_ &&
          (top.kind == "path_point" || top.kind == "obstacle")) {
        // drag what is selected; keep the offset between the grabbed point and its centre
        double centre[3] = {0, 0, 0};
        Pose body;
        if (top.kind == "path_point") {
          const Tendon* t = FindTendon(top.name);
          double local[3];
          if (t == nullptr || !graph_.BodyPose(t->path[top.index].body, &body) ||
              !graph_.PathPointMarker(top.name, top.index, local))
            return false;
          ToWorld(body, local, centre);
          mode_ = Mode::kDragPoint;
        } else {
          const Obstacle* o = FindObstacle(top.name);
          if (o == nullptr || !graph_.BodyPose(o->body, &body)) return false;
          ToWorld(body, o->pose.p, centre);
          mode_ = Mode::kDragObstacle;
        }
        for (int i = 0; i < 3; ++i) grab_offset_[i] = centre[i] - hits.front().point[i];
        BeginPlaneDrag(hits.front().point);
        return true;
      }
      mode_ = Mode::kMaybeClick;
      press_at_ = at;
      press_entity_ = top;
      return false;
    }
    case QEvent::MouseMove: {
      auto* e = static_cast<QMouseEvent*>(event);
      switch (mode_) {
        case Mode::kMaybeClick:
          if ((e->pos() - press_at_).manhattanLength() > kClickSlop) mode_ = Mode::kIdle;
          return false;
        case Mode::kDragPoint:
        case Mode::kDragObstacle:
          DragTo(e->pos());
          return true;
        case Mode::kPull:
          PullTo(e->pos(), false);
          return true;
        case Mode::kIdle:
          return false;
      }
      return false;
    }
    case QEvent::MouseButtonRelease: {
      auto* e = static_cast<QMouseEvent*>(event);
      if (e->button() != Qt::LeftButton) return false;
      const Mode mode = mode_;
      mode_ = Mode::kIdle;
      switch (mode) {
        case Mode::kMaybeClick:
          Select(press_entity_, e->pos());
          return false;  // the viewer ends what the press began
        case Mode::kDragPoint:
        case Mode::kDragObstacle:
          mode_ = mode;
          FinishDrag(e->pos());
          mode_ = Mode::kIdle;
          return true;
        case Mode::kPull: {
          pull_renewal_.stop();
          graph_.SetPullLine(-1, nullptr, nullptr);
          graph_.SetStatus("");
          Redraw();
          if (client_ == nullptr) return true;
          Job job;
          job.client = client_;
          job.call = [](EditClient& c) { c.ReleasePull(); };
          job.answer = [this](const std::string& error) {
            if (!error.empty()) last_error_ = error;
          };
          Queue(std::move(job));
          return true;
        }
        case Mode::kIdle:
          return false;
      }
      return false;
    }
    case QEvent::KeyPress: {
      // Delete removes the selected via point, tendon or obstacle; Escape selects nothing
      auto* e = static_cast<QKeyEvent*>(event);
      const QPoint at = viewer_.gl_widget()->mapFromGlobal(QCursor::pos());
      if (e->key() == Qt::Key_Escape && !selection_.kind.empty()) {
        Select(Entity(), at);
        return true;
      }
      if (e->key() != Qt::Key_Delete) return false;
      const Entity s = selection_;
      if (s.kind == "path_point")
        Send("remove point " + std::to_string(s.index) + " of " + s.name, at,
             [=](EditClient& c) { c.RemovePathPoint(s.name, s.index); });
      else if (s.kind == "tendon")
        Send("remove tendon " + s.name, at, [=](EditClient& c) { c.RemoveTendon(s.name); });
      else if (s.kind == "obstacle")
        Send("remove obstacle " + s.name, at, [=](EditClient& c) { c.RemoveObstacle(s.name); });
      else
        return false;
      return true;
    }
    default:
      return false;
  }
}

}  // namespace caliper::render_coin
