#include "model_edit_client.h"

#include <algorithm>
#include <functional>

#include "caliper/rtc/naming.h"
#include "caliper/rtc/reason.h"

namespace caliper::renderer {

namespace M = ::Caliper::Simulation;
namespace S = ::Caliper::Scene;
namespace R = render_coin;

namespace {

S::PathPoint ToIdl(const R::PathPoint& p) {
  S::PathPoint out;
  out.body = p.body.c_str();
  out.x = p.p[0];
  out.y = p.p[1];
  out.z = p.p[2];
  out.obstacle = p.obstacle.c_str();
  return out;
}

S::Frame ToIdl(const R::Pose& pose) {
  S::Frame f;
  f.px = pose.p[0];
  f.py = pose.p[1];
  f.pz = pose.p[2];
  f.qw = pose.q[0];
  f.qx = pose.q[1];
  f.qy = pose.q[2];
  f.qz = pose.q[3];
  return f;
}

// runs a call to the Model; its refusals and the ORB's failures become EditError
void Call(const char* what, const std::function<void()>& call) {
  try {
    call();
  } catch (const M::EditRefused& e) {
    throw R::EditError(rtc::BoundedReason(e.reason.in()));
  } catch (const M::NotAvailable& e) {
    throw R::EditError(std::string("the Model cannot ") + what +
                       " now: " + rtc::BoundedReason(e.reason.in()));
  } catch (const CORBA::Exception& e) {
    throw R::EditError(std::string("the Model does not answer (") + what +
                       "): " + rtc::Describe(e));
  }
}

}  // namespace

void ModelReference::Set(M::Model_ptr model) {
  std::lock_guard<std::mutex> lock(mutex_);
  model_ = M::Model::_duplicate(model);
}

M::Model_ptr ModelReference::Get() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return M::Model::_duplicate(model_.in());
}

M::Model_ptr ModelEditClient::Model() const { return Model(timeout_ms_); }

M::Model_ptr ModelEditClient::Model(unsigned long timeout_ms) const {
  M::Model_var model = model_.Get();
  if (CORBA::is_nil(model)) throw R::EditError("no Model found yet (renderer.model)");
  omniORB::setClientCallTimeout(model.in(), static_cast<CORBA::ULong>(timeout_ms));
  return model._retn();
}

void ModelEditClient::Select(const R::Entity& e) {
  M::Model_var m = Model();
  Call("select", [&] { m->select(e.kind.c_str(), e.name.c_str(), e.index); });
}

void ModelEditClient::MovePathPoint(const std::string& tendon, uint32_t index,
                                    const R::PathPoint& p) {
  M::Model_var m = Model();
  Call("edit", [&] { m->move_path_point(tendon.c_str(), index, ToIdl(p)); });
}

void ModelEditClient::InsertPathPoint(const std::string& tendon, uint32_t index,
                                      const R::PathPoint& p) {
  M::Model_var m = Model();
  Call("edit", [&] { m->insert_path_point(tendon.c_str(), index, ToIdl(p)); });
}

void ModelEditClient::RemovePathPoint(const std::string& tendon, uint32_t index) {
  M::Model_var m = Model();
  Call("edit", [&] { m->remove_path_point(tendon.c_str(), index); });
}

void ModelEditClient::AddTendon(const std::string& tendon, const R::PathPoint& from,
                                const R::PathPoint& to, double radius_m,
                                const std::string& actuator, const std::string& kind) {
  M::Model_var m = Model();
  Call("edit", [&] {
    m->add_tendon(tendon.c_str(), ToIdl(from), ToIdl(to), radius_m, actuator.c_str(), kind.c_str());
  });
}

void ModelEditClient::RemoveTendon(const std::string& tendon) {
  M::Model_var m = Model();
  Call("edit", [&] { m->remove_tendon(tendon.c_str()); });
}

void ModelEditClient::SetObstacle(const R::Obstacle& o) {
  S::Obstacle out;
  out.name = o.name.c_str();
  out.body = o.body.c_str();
  out.kind = o.kind.c_str();
  out.pose = ToIdl(o.pose);
  out.radius = o.radius;
  out.length = o.length;
  M::Model_var m = Model();
  Call("edit", [&] { m->set_obstacle(out); });
}

void ModelEditClient::RemoveObstacle(const std::string& obstacle) {
  M::Model_var m = Model();
  Call("edit", [&] { m->remove_obstacle(obstacle.c_str()); });
}

std::vector<R::ActuatorKindInfo> ModelEditClient::ActuatorKinds() {
  M::Model_var m = Model();
  std::vector<R::ActuatorKindInfo> out;
  Call("list actuator kinds", [&] {
    M::ActuatorKindSeq_var kinds = m->actuator_kinds();
    for (CORBA::ULong i = 0; i < kinds->length(); ++i)
      out.push_back({kinds[i].kind.in(), kinds[i].command_unit.in()});
  });
  return out;
}

void ModelEditClient::Pull(const std::string& body, const double point[3], const double target[3],
                           double stiffness_n_per_m) {
  const M::Vector3 p = {point[0], point[1], point[2]};
  const M::Vector3 t = {target[0], target[1], target[2]};
  M::Model_var m = Model();
  Call("pull", [&] { m->pull(body.c_str(), p, t, stiffness_n_per_m); });
}

void ModelEditClient::ReleasePull() {
  M::Model_var m = Model();
  Call("release the pull", [&] { m->release_pull(); });
}

bool ModelEditClient::CurrentSelection(R::Entity* entity, uint64_t* revision) {
  // a poll: a Model that does not answer within a second is asked again at the next one
  M::Model_var m = Model(std::min(timeout_ms_, 1000ul));
  Call("read the selection", [&] {
    M::Selection_var s = m->current_selection();
    entity->kind = s->kind.in();
    entity->name = s->name.in();
    entity->index = s->index;
    *revision = s->revision;
  });
  return true;
}

}  // namespace caliper::renderer
