#include "caliper/physics_bullet/bullet_scene.h"

#include <LinearMath/btConvexHullComputer.h>
#include <btBulletDynamicsCommon.h>
#include <omp.h>
#include <sched.h>
#include <unistd.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <functional>
#include <limits>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <typeinfo>
#include <unordered_map>
#include <utility>

#if defined(__GNUG__)
#include <cxxabi.h>
#endif

#include "caliper/actuators/actuator.h"
#include "caliper/actuators/tendon_contact.h"
#include "caliper/actuators/tendon_path.h"
#include "caliper/core/numbers.h"

namespace caliper::physics_bullet {

namespace {

using Eigen::Isometry3d;
using Eigen::Vector3d;

// the most constraint solver iterations a scene may ask for per step
constexpr int kMaxSolverIterations = actuators::kMaxSubstepsPerStep;

inline btVector3 ToBt(const Vector3d& v, double s = 1.0) {
  return btVector3(static_cast<btScalar>(v.x() * s), static_cast<btScalar>(v.y() * s),
                   static_cast<btScalar>(v.z() * s));
}

inline Vector3d FromBt(const btVector3& v, double s = 1.0) {
  return Vector3d(v.x(), v.y(), v.z()) / s;
}

btTransform ToBt(const Isometry3d& t, double s) {
  const Eigen::Quaterniond q(t.rotation());
  return btTransform(btQuaternion(static_cast<btScalar>(q.x()), static_cast<btScalar>(q.y()),
                                  static_cast<btScalar>(q.z()), static_cast<btScalar>(q.w())),
                     ToBt(Vector3d(t.translation()), s));
}


struct BodyData {
  const sgal::Body* desc = nullptr;
  // null when the body's one shape sits at its centre-of-mass frame and Bullet gets it directly
  std::unique_ptr<btCompoundShape> compound;
  std::vector<std::unique_ptr<btCollisionShape>> children;
  std::unique_ptr<btRigidBody> rigid;
  Isometry3d com_in_body = Isometry3d::Identity();  // principal-axes frame at the com
  // the inverse of com_in_body's rotation as a quaternion (BodyStates), taken once
  Eigen::Quaterniond body_in_com_rotation = Eigen::Quaterniond::Identity();
  bool com_is_body_frame = true;  // com_in_body is the identity: body and Bullet frames coincide
  bool dynamic = false;           // moved by forces (neither static nor kinematic)
  std::vector<actuators::WorldShape> world_shapes;  // refreshed each step when contact is on
  std::vector<Isometry3d> shape_poses;               // shapes in the body frame
};

struct JointData {
  const sgal::Constraint* desc = nullptr;
  Isometry3d frame_a = Isometry3d::Identity();  // joint frames in the body frames
  Isometry3d frame_b = Isometry3d::Identity();
  // the frame axes the joint's reading needs, in the body frames: a's x, b's x, y and z
  Vector3d a_x = Vector3d::UnitX(), b_x = Vector3d::UnitX(), b_y = Vector3d::UnitY(),
           b_z = Vector3d::UnitZ();
  std::unique_ptr<btTypedConstraint> constraint;
  int body_a = -1, body_b = -1;
  // [m] for a slider. For a hinge, where its whole turns are counted from (0 at a build, a
  // restored state's angle): JointPosition() gives its angle [rad].
  double position = 0;
  double velocity = 0;  // [rad/s] or [m/s]
  Vector3d axis = Vector3d::UnitZ();  // world, this step
  // a hinge's last reading: the cosine and sine of its angle (both scaled by the same factor);
  // the whole turns to add to atan2's angle; false: count them afresh from `position` at the next
  // UpdateJoints
  double reading_cos = 1, reading_sin = 0;
  double turns = 0;
  bool turns_counted = false;
};

/// A joint's position: a hinge's angle [rad], whole turns counted (read on demand: the step only
/// counts turns, so that an angle nobody reads costs no atan2), a slider's travel [m].
double JointPosition(const JointData& j) {
  if (j.desc->kind != sgal::ConstraintKind::kHinge) return j.position;
  return std::atan2(j.reading_sin, j.reading_cos) + 2 * M_PI * j.turns;
}

/// A path element with its names resolved once.
struct ElementRef {
  const sgal::PathElement* desc = nullptr;
  int body = -1;
  const sgal::WrapObstacle* obstacle = nullptr;
};

struct TendonData {
  const sgal::Tendon* desc = nullptr;
  std::vector<ElementRef> elements;
  std::vector<actuators::WorldElement> world;  // reused every step
  actuators::TendonPath path;
  actuators::PathGeometry geometry;
  // at the start of the last step [m]; -1 after a build or an edit, when no step has measured
  // the path's speed yet (kept so in an exact state, so that a replay knows it too)
  double previous_length = -1;
  // the last step's mean lengthening speed [m/s] (geometry.speed until the path is evaluated
  // again), when previous_length says it was measured
  double mean_speed = 0;
  bool speed_known = false;
  // the lengthening speed at the end of the last step [m/s] (extrapolated from the last two
  // means): what the tendon's speed channel reports, at the bodies' instant
  double end_speed = 0;
  double tension = 0;
  int contacts = 0;
  // what the last contact searches proved (lets a step skip them; never changes a path)
  actuators::ContactMemory contact_memory;
  std::vector<int> actuators;
  bool has_wraps = false;  // the path keeps a side per wrap from step to step
  // points alone, at least two (a path TendonPath::Evaluate accepts): EvaluateTendon places them
  bool points_only = false;
  // the directions of a path of points alone, kept from placing them for the forces of the next
  // step; they are the geometry's only while `straight` (no contact point was inserted since)
  std::vector<Vector3d> units;
  bool straight = false;
  // the state at the start of the step, put back when the step fails
  actuators::TendonPath saved_path;       // only when has_wraps
  double saved_speed = 0;
  double saved_end_speed = 0;
  double saved_previous_length = -1;
  double saved_tension = 0;
};

/// A coupling q_follower = ratio * q_leader + offset held by a stiff, critically damped
/// spring-damper on the error, acting on both joints (the follower's load reaches the leader).
struct CouplingData {
  const sgal::Coupling* desc = nullptr;
  int leader = -1, follower = -1;  // joints
  double stiffness = 0;            // [N m/rad], [N/m] or mixed: per unit of error of the follower
  double damping = 0;              // per unit of error speed
};

struct ActuatorData {
  const sgal::Actuator* desc = nullptr;
  std::unique_ptr<actuators::TendonActuator> model;
  int tendon = -1;
  size_t state_offset = 0;  // of its SaveStepState() in the scene's buffer
};

struct Snapshot {
  btTransform transform;
  btVector3 linear, angular;
};

/// A step's own fault (a non-finite tension, an exploding body): passed on as it is.
class StepFault : public sgal::SimulationFault {
 public:
  using sgal::SimulationFault::SimulationFault;
};

/// The part of a step that runs, for the message of a fault: an actuator, a tendon or the world.
struct StepStage {
  enum Kind { kWorld, kTendon, kActuator } kind = kWorld;
  int index = -1;
};

/// A parameter read late (sgal::MeasurementDelay): a ring of its last steps + 1 true values, one
/// pushed after every completed step; the oldest, at `head`, is what the parameter reads.
struct DelayLine {
  std::function<double()> truth;  // the parameter's true value now
  StepStage stage;                // whose value it is (an actuator's, a tendon's, the world's)
  int steps = 0;                  // round(delay / dt)
  std::vector<double> ring;       // steps + 1 values [the parameter's unit]
  size_t head = 0;                // index of the oldest value
  // where the step's push wrote and what it overwrote, put back when the step fails
  size_t saved_head = 0;
  double saved_oldest = 0;
};

// the most steps a channel may lag (each one a double per step and channel kept and recorded)
constexpr int kMaxDelaySteps = 1000;
// the most values the rings of all delayed channels hold together (each keyframe and saved
// state carries them): 160 kB, 20 channels a second late at 1 ms
constexpr double kMaxDelayedValues = 20000;

/// A number as text, shortest round-trip form, independent of the locale.
std::string Text(double v) { return core::FormatDouble(v); }

/// The readable name of a type.
std::string TypeName(const std::type_info& type) {
#if defined(__GNUG__)
  int status = 0;
  char* name = abi::__cxa_demangle(type.name(), nullptr, nullptr, &status);
  if (status == 0 && name != nullptr) {
    std::string readable(name);
    std::free(name);
    return readable;
  }
#endif
  return type.name();
}

/// What the exception being handled says: its type, and its message when it has one that is not
/// just the type's name.
std::string CurrentException() {
  try {
    throw;
  } catch (const std::exception& e) {
    const std::string type = TypeName(typeid(e));
    const std::string what = e.what();
    return what.empty() || what == type ? type : type + ": " + what;
  } catch (...) {
#if defined(__GNUG__)
    if (const std::type_info* type = abi::__cxa_current_exception_type())
      return "an exception of type " + TypeName(*type);
#endif
    return "an exception of unknown type";
  }
}

// A Bullet world whose contact search for the next step can run at the end of this one, when
// nothing it reads changes in between: the poses a step starts from are those the last one ended
// at, and stepSimulation's work before its search (kinematic bodies' velocities, gravity, each
// moving body's swept pose from its velocity) changes none of what the search reads. So the
// search can run beside the tendons' end-of-step work, which reads Caliper's copy of the poses.
class AheadWorld : public btDiscreteDynamicsWorld {
 public:
  using btDiscreteDynamicsWorld::btDiscreteDynamicsWorld;

  /// The next step's contact search, now, for a step of dt [s]: the moving bodies' boxes swept to
  /// where their velocities take them, as predictUnconstraintMotion will sweep them (their own
  /// swept poses are put back: they are part of the saved state). Nothing when a body has
  /// damping, which that sweep applies to its velocity first (Caliper's bodies have none).
  void DetectAhead(btScalar dt) {
    swept_.resize(m_nonStaticRigidBodies.size());
    for (int i = 0; i < m_nonStaticRigidBodies.size(); ++i) {
      const btRigidBody* body = m_nonStaticRigidBodies[i];
      if (body->getLinearDamping() != 0 || body->getAngularDamping() != 0) return;
    }
    for (int i = 0; i < m_nonStaticRigidBodies.size(); ++i) {
      btRigidBody* body = m_nonStaticRigidBodies[i];
      swept_[i] = body->getInterpolationWorldTransform();
      if (!body->isStaticOrKinematicObject())
        body->predictIntegratedTransform(dt, body->getInterpolationWorldTransform());
    }
    btDispatcherInfo& info = getDispatchInfo();  // as internalSingleStepSimulation sets it
    info.m_timeStep = dt;
    info.m_stepCount = 0;
    info.m_debugDraw = getDebugDrawer();
    btCollisionWorld::performDiscreteCollisionDetection();
    for (int i = 0; i < m_nonStaticRigidBodies.size(); ++i)
      m_nonStaticRigidBodies[i]->setInterpolationWorldTransform(swept_[i]);
    ahead_ = true;
  }
  /// After anything that may change what the search reads (a parameter, a restored state, new
  /// caches): the next step searches again itself.
  void ForgetAhead() { ahead_ = false; }

  void performDiscreteCollisionDetection() override {
    if (ahead_) {
      ahead_ = false;  // found already, for these poses
      return;
    }
    btCollisionWorld::performDiscreteCollisionDetection();
  }

 private:
  bool ahead_ = false;
  std::vector<btTransform> swept_;
};

class BulletScene : public sgal::PhysicsScene {
 public:
  BulletScene(const sgal::Scene& scene, Options options);
  ~BulletScene() override;

  void Step() override;
  double time() const override { return time_; }
  uint64_t steps() const override { return steps_; }
  const sgal::Scene& description() const override { return scene_; }
  std::vector<sgal::BodyState> BodyStates() const override;
  void ReadBodyStates(std::vector<sgal::BodyState>* out) const override;
  std::vector<sgal::TendonState> TendonStates() const override;
  void SetCommand(const std::string& actuator, double value) override;
  std::vector<sgal::ParameterInfo> Parameters() const override;
  double GetParameter(const std::string& id) const override;
  int ParameterIndex(const std::string& id) const override;
  double GetParameter(int index) const override;
  void SetParameter(const std::string& id, double value) override;
  sgal::DynamicState SaveDynamicState() const override;
  void RestoreDynamicState(const sgal::DynamicState& state) override;
  void SetPull(const sgal::Pull& pull) override;
  void ClearPull() override {
    pull_.reset();
    pull_force_.setZero();
  }
  void ResetCaches() override;

 private:
  void BuildBody(size_t index);
  void BuildConstraint(size_t index);
  void BuildTendons();
  void CacheBodyPoses();
  void UpdateJoints();
  void RefreshWorldShapes();
  void EvaluateTendons();
  // one tendon's path (bent around the bodies, with this thread's buffers) at this step's poses;
  // with `placed`, a path of points alone is where PlaceStraight put it and is only bent
  void EvaluateTendon(size_t index, actuators::ContactScratch* scratch, bool placed = false);
  // a path of points alone at this step's poses, straight: its points, length and directions
  // (never throws)
  void PlaceStraight(TendonData& t) const;
  // the end of a step for every tendon: its path, its speed over the step and its actuators'
  // step, on options_.threads threads (each tendon on one; the same bits whatever the count); the
  // first failing tendon's exception (in tendon order) is rethrown with stage_ naming it
  void AdvanceTendons();
  // AdvanceTendons' work for one tendon; sets *stage to what it is doing
  void AdvanceTendon(size_t index, actuators::ContactScratch* scratch, StepStage* stage);
  // its parts: what the step starts from (never throws), and the path's speed with the actuators'
  // step once the path is evaluated
  static void BeginTendonStep(TendonData& t);
  void ActuateTendon(size_t index, StepStage* stage);
  void ApplyTendonForces();
  void ApplyJointSprings();
  void ApplyJointFriction();
  void ApplyPull();
  void BuildCouplings();
  double JointInverseInertia(const JointData& j) const;
  void ApplyCouplings();
  void PushJoint(const JointData& j, double load);
  void CheckState();  // of what CacheBodyPoses took from Bullet: call it first
  void BuildParameters();
  // the delayed channels (after BuildParameters): their rings, their parameters read late and
  // the `.undelayed` parameters
  void BuildMeasurementDelays();
  // each measurement delay in steps of `dt`; std::invalid_argument starting with `refused` and
  // naming the id for a delay that is negative, not finite or longer than kMaxDelaySteps
  std::vector<int> DelaySteps(double dt, const std::string& refused) const;
  // appends every delayed channel's true value now to its ring (the end of a step)
  void PushMeasurements();
  // the part of the scene a parameter id belongs to, for a fault's message
  StepStage OwnerOf(const std::string& id) const;
  // the rings from a dynamic state's measurements, or filled with the present values (empty)
  void RestoreMeasurements(const std::vector<double>& values);
  // the state at the start of a step (bodies, tendons, actuators, delayed channels), and putting
  // it back
  void SaveStepState();
  // each actuator's place in actuator_states_, after anything that may change a StateSize()
  void LayOutActuatorStates();
  void RestoreStepState();
  [[noreturn]] void FailStep();
  std::string Describe(const StepStage& stage) const;

  /// One parameter with its accessors, built once.
  struct ParameterEntry {
    sgal::ParameterInfo info;
    std::function<double()> get;
    std::function<void(double)> set;  // empty: read-only
  };

  sgal::Scene scene_;
  Options options_;
  double scale_;  // engine units per metre
  double dt_;
  double time_ = 0;
  uint64_t steps_ = 0;
  std::optional<sgal::Pull> pull_;  // the GUI's spring on a body, while it lasts
  Vector3d pull_force_ = Vector3d::Zero();  // what it applied in the last step [N]

  std::unique_ptr<btDefaultCollisionConfiguration> configuration_;
  std::unique_ptr<btCollisionDispatcher> dispatcher_;
  std::unique_ptr<btDbvtBroadphase> broadphase_;
  std::unique_ptr<btSequentialImpulseConstraintSolver> solver_;
  std::unique_ptr<AheadWorld> world_;
  std::unique_ptr<btRigidBody> fixed_body_;  // the world side of joints with one body
  std::vector<BodyData> bodies_;
  std::vector<JointData> joints_;
  std::vector<CouplingData> couplings_;
  std::vector<TendonData> tendons_;
  std::vector<ActuatorData> actuators_;
  std::unordered_map<std::string, int> actuator_index_;  // into actuators_, by name
  std::vector<Isometry3d> poses_;                        // body frames this step [m]
  std::vector<Vector3d> coms_;           // centres of mass this step [m]
  std::vector<Vector3d> velocities_;     // of the centres of mass [m/s]
  std::vector<Vector3d> spins_;          // angular velocities [rad/s]
  std::vector<Snapshot> snapshot_;          // bodies at the start of the step
  std::vector<double> actuator_states_;     // actuators' SaveStepState() at the start of the step,
                                            // sized once
  StepStage stage_;                         // what the step is doing (for a fault's message)
  double detour_reach_ = 0.1;  // 2.1 times the largest finite shape bounding radius [m]
  // tendon-body contact's buffers, one per thread, reused by every tendon and step (no
  // allocation per step)
  std::vector<actuators::ContactScratch> contact_scratch_;
  int threads_ = 1;  // that advance the tendons (options_.threads resolved)
  // per job of AdvanceTendons (the contact search, then a tendon each): the exception it threw, and
  // where
  std::vector<std::exception_ptr> job_faults_;
  std::vector<StepStage> job_fault_stages_;
  // Which way AdvanceTendons runs, by whole steps' times (threads_ > 1): ChooseThreads() before
  // a step, TimeStep() after it
  struct ThreadChoice {
    bool parallel_preferred = false;
    uint64_t step = 0;        // in this cycle
    double mean[2] = {0, 0};  // a step's time one way (serial, parallel) [s]; 0: not measured
    double sum[2] = {0, 0};   // this cycle's steps each way [s]
    int count[2] = {0, 0};
  } choice_;
  bool parallel_now_ = false;  // this step's way
  void ChooseThreads();
  void TimeStep(double seconds);
  // every shape's bounding ball at this step's poses, packed for QueryShapes' scan
  struct ContactBall {
    double x, y, z;  // centre [m]
    double radius;   // [m], infinite for planes
    const actuators::WorldShape* shape;
  };
  std::vector<ContactBall> contact_balls_;
  // the sum over refreshes of the largest move of a finite shape's origin [m]: bounds how far
  // any shape went since a tendon's contact memory measured its clearance
  double contact_travel_ = 0;
  void QueryShapes(const Vector3d& a, const Vector3d& b, double pad,
                   std::vector<const actuators::WorldShape*>* out);
  std::vector<ParameterEntry> parameters_;
  std::unordered_map<std::string, int> parameter_index_;
  // in Scene::measurement_delays order, sized once (the delayed parameters' getters point here)
  std::vector<DelayLine> delays_;
};

// A ring holding the present value `steps` + 1 times: a sensor that read it since ever.
void Fill(DelayLine* line) {
  line->ring.assign(static_cast<size_t>(line->steps) + 1, line->truth());
  line->head = 0;
}

std::unique_ptr<btCollisionShape> MakeShape(const sgal::Geometry& geometry, double s, bool dynamic,
                                            const std::string& where) {
  return std::visit(
      [&](const auto& g) -> std::unique_ptr<btCollisionShape> {
        using T = std::decay_t<decltype(g)>;
        if constexpr (std::is_same_v<T, sgal::Box>) {
          return std::make_unique<btBoxShape>(ToBt(g.size / 2, s));
        } else if constexpr (std::is_same_v<T, sgal::Sphere>) {
          return std::make_unique<btSphereShape>(static_cast<btScalar>(g.radius * s));
        } else if constexpr (std::is_same_v<T, sgal::Capsule>) {
          return std::make_unique<btCapsuleShapeZ>(static_cast<btScalar>(g.radius * s),
                                                   static_cast<btScalar>(g.length * s));
        } else if constexpr (std::is_same_v<T, sgal::Cylinder>) {
          return std::make_unique<btCylinderShapeZ>(
              ToBt(Vector3d(g.radius, g.radius, g.length / 2), s));
        } else if constexpr (std::is_same_v<T, sgal::Cone>) {
          return std::make_unique<btConeShapeZ>(static_cast<btScalar>(g.radius * s),
                                                static_cast<btScalar>(g.length * s));
        } else if constexpr (std::is_same_v<T, sgal::Plane>) {
          if (dynamic) throw std::invalid_argument(where + ": a plane can only belong to a static body");
          return std::make_unique<btStaticPlaneShape>(ToBt(g.normal),
                                                      static_cast<btScalar>(g.offset * s));
        } else {
          // convex hulls, and triangle meshes of moving bodies, collide as their convex hull
          if (!g.mesh || g.mesh->vertices.empty())
            throw std::invalid_argument(where + ": mesh without vertices");
          btAlignedObjectArray<btVector3> points;
          points.reserve(static_cast<int>(g.mesh->vertices.size()));
          for (const auto& v : g.mesh->vertices) points.push_back(ToBt(v.template cast<double>(), s));
          // Bullet adds a hull's collision margin outside it (0.04 engine units unless told:
          // a hull rested 4 cm above a floor). The hull's corners moved inwards by the margin
          // give back the mesh's own surface, rounded at the edges; and a CAD mesh's thousands of
          // vertices inside the hull or on its flat faces, which every contact query would walk,
          // are gone. A mesh whose hull has no volume (flat) keeps its points with a thin margin.
          btConvexHullComputer computer;
          const btScalar shrunk = computer.compute(&points[0].x(), sizeof(btVector3), points.size(),
                                                   static_cast<btScalar>(0.04), static_cast<btScalar>(0.25));
          btScalar margin = static_cast<btScalar>(1e-4 * s);
          if (shrunk >= 0 && computer.vertices.size() >= 4) {
            points = computer.vertices;
            margin = std::max(shrunk, margin);
          }
          auto hull = std::make_unique<btConvexHullShape>();
          for (int i = 0; i < points.size(); ++i) hull->addPoint(points[i], false);
          hull->setMargin(margin);
          hull->recalcLocalAabb();
          return hull;
        }
      },
      geometry);
}

BulletScene::BulletScene(const sgal::Scene& scene, Options options)
    : scene_(scene),
      options_(options),
      scale_(scene.settings.world_scale),
      dt_(scene.settings.time_step) {
  const auto errors = sgal::Validate(scene_);
  if (!errors.empty()) {
    std::ostringstream msg;
    msg << (scene_.source.empty() ? scene_.name : scene_.source) << ": " << errors.size()
        << " problem(s):";
    for (const auto& e : errors) msg << "\n  " << e;
    throw std::invalid_argument(msg.str());
  }
  threads_ = ThreadCount(options_.threads);
  parallel_now_ = threads_ > 1 && !options_.choose_threads;  // else ChooseThreads, each step
  contact_scratch_.resize(static_cast<size_t>(threads_));
  configuration_ = std::make_unique<btDefaultCollisionConfiguration>();
  dispatcher_ = std::make_unique<btCollisionDispatcher>(configuration_.get());
  broadphase_ = std::make_unique<btDbvtBroadphase>();
  solver_ = std::make_unique<btSequentialImpulseConstraintSolver>();
  world_ = std::make_unique<AheadWorld>(dispatcher_.get(), broadphase_.get(), solver_.get(),
                                        configuration_.get());
  world_->setGravity(ToBt(scene_.gravity, scale_));
  // each solver iteration sweeps every constraint and contact: bounded like actuator sub-steps
  if (scene_.settings.solver_iterations < 1 ||
      scene_.settings.solver_iterations > kMaxSolverIterations)
    throw std::invalid_argument((scene_.source.empty() ? scene_.name : scene_.source) +
                                ": solver_iterations = " +
                                std::to_string(scene_.settings.solver_iterations) +
                                " is out of range: it sets the work of every step and must be "
                                "in [1, " + std::to_string(kMaxSolverIterations) + "]");
  world_->getSolverInfo().m_numIterations = scene_.settings.solver_iterations;
  fixed_body_ = std::make_unique<btRigidBody>(0, nullptr, nullptr);
  fixed_body_->setMassProps(0, btVector3(0, 0, 0));

  bodies_.resize(scene_.bodies.size());
  for (size_t i = 0; i < scene_.bodies.size(); ++i) BuildBody(i);
  joints_.resize(scene_.constraints.size());
  for (size_t i = 0; i < scene_.constraints.size(); ++i) BuildConstraint(i);
  BuildCouplings();
  BuildTendons();
  BuildParameters();
  BuildMeasurementDelays();
}

BulletScene::~BulletScene() {
  for (auto& j : joints_) world_->removeConstraint(j.constraint.get());
  for (auto& b : bodies_) world_->removeRigidBody(b.rigid.get());
}

void BulletScene::BuildBody(size_t index) {
  const sgal::Body& desc = scene_.bodies[index];
  BodyData& data = bodies_[index];
  data.desc = &desc;
  data.dynamic = desc.type == sgal::BodyType::kDynamic;
  const bool dynamic = data.dynamic;
  const double s = scale_;

  // Bullet wants the body frame at the centre of mass along the principal axes
  btVector3 principal(0, 0, 0);
  bool shape_frame = false;  // Bullet's frame is the one shape's own: it goes to Bullet as itself
  if (dynamic) {
    const Eigen::Matrix3d& tensor = desc.inertia.tensor;
    // a body whose one shape sits at the centre of mass with the tensor's principal axes (the
    // tensor diagonal in the shape's axes, to 1e-12 of its trace: a capsule along the body's z,
    // or a link along x drawn as a capsule along z turned) takes the shape's axes as Bullet's
    // frame, and the shape goes to Bullet as itself. Eigen's solver sorts the moments and would
    // turn such a frame needlessly, and the shape would then need a compound; every other body
    // keeps the solver's frame (and its numbers)
    const bool shape_centred =
        desc.shapes.size() == 1 && desc.shapes[0].pose.position == desc.inertia.com;
    const Eigen::Matrix3d shape_axes = shape_centred
                                           ? desc.shapes[0].pose.ToIsometry().linear()
                                           : Eigen::Matrix3d(Eigen::Matrix3d::Identity());
    const Eigen::Matrix3d in_shape = shape_axes.transpose() * tensor * shape_axes;
    const double off_diagonal =
        std::abs(in_shape(0, 1)) + std::abs(in_shape(0, 2)) + std::abs(in_shape(1, 2));
    if (shape_centred && off_diagonal <= 1e-12 * in_shape.trace()) {
      data.com_in_body.linear() = shape_axes;
      principal = ToBt(Vector3d(in_shape.diagonal()), s * s);
      shape_frame = true;
    } else {
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(tensor);
      Eigen::Matrix3d axes = eig.eigenvectors();
      if (axes.determinant() < 0) axes.col(2) *= -1;
      data.com_in_body.linear() = axes;
      principal = ToBt(eig.eigenvalues(), s * s);
    }
    data.com_in_body.translation() = desc.inertia.com;
  }
  data.body_in_com_rotation = Eigen::Quaterniond(data.com_in_body.linear()).conjugate();
  data.com_is_body_frame = data.com_in_body.matrix() == Eigen::Matrix4d::Identity();
  const Isometry3d body_to_com = data.com_in_body.inverse();
  std::vector<btTransform> child_poses;  // in the centre-of-mass frame
  for (const auto& shape : desc.shapes) {
    data.children.push_back(MakeShape(shape.geometry, s, dynamic,
                                      "body '" + desc.name + "' shape '" + shape.name + "'"));
    // in the shape's own frame by construction: exactly the identity, not its rounded product
    child_poses.push_back(shape_frame ? btTransform::getIdentity()
                                      : ToBt(body_to_com * shape.pose.ToIsometry(), s));
  }
  // one shape at the identity in Bullet's own (float) numbers collides as itself: a compound
  // would only add its own collision algorithm and a manifold made and freed every step per pair
  btCollisionShape* collision_shape = nullptr;
  if (data.children.size() == 1 && child_poses[0].getOrigin().isZero() &&
      child_poses[0].getBasis() == btMatrix3x3::getIdentity()) {
    collision_shape = data.children[0].get();
  } else {
    data.compound = std::make_unique<btCompoundShape>();  // also a body without shapes
    for (size_t k = 0; k < data.children.size(); ++k)
      data.compound->addChildShape(child_poses[k], data.children[k].get());
    collision_shape = data.compound.get();
  }
  const double mass = dynamic ? desc.inertia.mass : 0.0;
  btRigidBody::btRigidBodyConstructionInfo info(static_cast<btScalar>(mass), nullptr,
                                                collision_shape, principal);
  info.m_startWorldTransform = ToBt(desc.pose.ToIsometry() * data.com_in_body, s);
  double friction = 0.5, restitution = 0.0;
  if (!desc.shapes.empty())
    for (const auto& m : scene_.materials)
      if (m.name == desc.shapes.front().material) {
        friction = m.friction;
        restitution = m.restitution;
      }
  info.m_friction = static_cast<btScalar>(friction);
  info.m_restitution = static_cast<btScalar>(restitution);
  data.rigid = std::make_unique<btRigidBody>(info);
  data.rigid->setUserIndex(static_cast<int>(index));
  if (desc.type == sgal::BodyType::kKinematic) {
    data.rigid->setCollisionFlags(data.rigid->getCollisionFlags() |
                                  btCollisionObject::CF_KINEMATIC_OBJECT);
  }
  if (dynamic) {
    data.rigid->setActivationState(DISABLE_DEACTIVATION);
    data.rigid->setLinearVelocity(ToBt(desc.linear_velocity, s));
    data.rigid->setAngularVelocity(ToBt(desc.angular_velocity));
  }
  uint32_t group = 0, mask = 0;
  for (const auto& shape : desc.shapes) {
    group |= shape.group;
    mask |= shape.mask;
  }
  if (desc.shapes.empty()) {
    group = 0;  // a body without shapes collides with nothing
    mask = 0;
  }
  world_->addRigidBody(data.rigid.get(), static_cast<int>(group & 0x7fff),
                       static_cast<int>(mask & 0x7fff));
}


void BulletScene::CacheBodyPoses() {
  const size_t n = bodies_.size();
  poses_.resize(n);
  coms_.resize(n);
  velocities_.resize(n);
  spins_.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const btRigidBody& rb = *bodies_[i].rigid;
    const btTransform& t = rb.getCenterOfMassTransform();
    const btMatrix3x3& basis = t.getBasis();
    Eigen::Matrix3d com_rotation;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) com_rotation(r, c) = basis[r][c];
    const Vector3d com = FromBt(t.getOrigin(), scale_);
    const Isometry3d& com_in_body = bodies_[i].com_in_body;
    // body frame = com frame * inverse(com in body), in matrices (no quaternion round trip on
    // the path every tendon and joint reads)
    Isometry3d& frame = poses_[i];
    if (bodies_[i].com_is_body_frame) {
      frame.linear() = com_rotation;
      frame.translation() = com;
    } else {
      frame.linear().noalias() = com_rotation * com_in_body.linear().transpose();
      frame.translation() = com - frame.linear() * com_in_body.translation();
    }
    coms_[i] = com;
    velocities_[i] = FromBt(rb.getLinearVelocity(), scale_);
    spins_[i] = FromBt(rb.getAngularVelocity());
  }
}


void BulletScene::BuildConstraint(size_t index) {
  const sgal::Constraint& c = scene_.constraints[index];
  JointData& j = joints_[index];
  j.desc = &c;
  j.frame_a = c.frame_a.ToIsometry();
  j.frame_b = c.frame_b.ToIsometry();
  j.a_x = j.frame_a.linear().col(0);
  j.b_x = j.frame_b.linear().col(0);
  j.b_y = j.frame_b.linear().col(1);
  j.b_z = j.frame_b.linear().col(2);
  j.body_a = scene_.BodyIndex(c.body_a);
  j.body_b = c.body_b.empty() ? -1 : scene_.BodyIndex(c.body_b);
  btRigidBody& a = *bodies_[j.body_a].rigid;
  btRigidBody& b = j.body_b < 0 ? *fixed_body_ : *bodies_[j.body_b].rigid;
  // joint frames relative to each Bullet body (centre of mass, principal axes)
  const Isometry3d fa = bodies_[j.body_a].com_in_body.inverse() * c.frame_a.ToIsometry();
  const Isometry3d fb = j.body_b < 0 ? c.frame_b.ToIsometry()
                                     : bodies_[j.body_b].com_in_body.inverse() * c.frame_b.ToIsometry();
  const btTransform ta = ToBt(fa, scale_), tb = ToBt(fb, scale_);
  switch (c.kind) {
    case sgal::ConstraintKind::kHinge: {
      auto hinge = std::make_unique<btHingeConstraint>(a, b, ta, tb);
      if (c.limits[0].enabled())
        hinge->setLimit(static_cast<btScalar>(c.limits[0].lower),
                        static_cast<btScalar>(c.limits[0].upper));
      j.constraint = std::move(hinge);
      break;
    }
    case sgal::ConstraintKind::kSlider: {
      // Bullet slides along x: turn the frames so that our z becomes its x
      const btTransform z_to_x(btQuaternion(btVector3(0, 1, 0), -SIMD_HALF_PI));
      auto slider = std::make_unique<btSliderConstraint>(a, b, ta * z_to_x, tb * z_to_x, true);
      if (c.limits[0].enabled()) {
        slider->setLowerLinLimit(static_cast<btScalar>(c.limits[0].lower * scale_));
        slider->setUpperLinLimit(static_cast<btScalar>(c.limits[0].upper * scale_));
      } else {
        slider->setLowerLinLimit(1);
        slider->setUpperLinLimit(-1);
      }
      slider->setLowerAngLimit(0);
      slider->setUpperAngLimit(0);
      j.constraint = std::move(slider);
      break;
    }
    case sgal::ConstraintKind::kBall:
      j.constraint = std::make_unique<btPoint2PointConstraint>(a, b, ta.getOrigin(), tb.getOrigin());
      break;
    case sgal::ConstraintKind::kFixed:
      j.constraint = std::make_unique<btFixedConstraint>(a, b, ta, tb);
      break;
    case sgal::ConstraintKind::kGeneric6Dof: {
      auto g = std::make_unique<btGeneric6DofSpring2Constraint>(a, b, ta, tb);
      for (int i = 0; i < 6; ++i) {
        const auto& l = c.limits[i];
        const double unit = i < 3 ? scale_ : 1.0;
        // our free (lower > upper) is Bullet's free too
        g->setLimit(i, static_cast<btScalar>(l.lower * unit), static_cast<btScalar>(l.upper * unit));
        const auto& sp = c.springs[i];
        if (sp.stiffness > 0 || sp.damping > 0) {
          const double k_unit = i < 3 ? 1.0 : scale_ * scale_;
          g->enableSpring(i, true);
          g->setStiffness(i, static_cast<btScalar>(sp.stiffness * k_unit));
          g->setDamping(i, static_cast<btScalar>(sp.damping * k_unit));
          g->setEquilibriumPoint(i, static_cast<btScalar>(sp.rest * unit));
        }
      }
      j.constraint = std::move(g);
      break;
    }
  }
  world_->addConstraint(j.constraint.get(), !c.collide_connected);
}

void BulletScene::BuildTendons() {
  tendons_.resize(scene_.tendons.size());
  for (size_t i = 0; i < scene_.tendons.size(); ++i) {
    TendonData& t = tendons_[i];
    t.desc = &scene_.tendons[i];
    for (const auto& e : t.desc->path) {
      ElementRef ref;
      ref.desc = &e;
      if (e.kind == sgal::PathElement::Kind::kPoint) {
        ref.body = e.body.empty() ? -1 : scene_.BodyIndex(e.body);
      } else {
        ref.obstacle = scene_.FindObstacle(e.obstacle);
        ref.body = ref.obstacle->body.empty() ? -1 : scene_.BodyIndex(ref.obstacle->body);
      }
      t.elements.push_back(ref);
      t.has_wraps |= e.kind != sgal::PathElement::Kind::kPoint;
    }
    t.points_only = !t.has_wraps && t.elements.size() >= 2;
    // a side per element, none wrapping, as TendonPath::Evaluate would keep them (the exact
    // state holds them)
    if (t.points_only) t.path.set_wrap_sides(std::vector<int>(t.elements.size(), 0));
  }
  actuators_.resize(scene_.actuators.size());
  for (size_t i = 0; i < scene_.actuators.size(); ++i)
    actuator_index_[scene_.actuators[i].name] = static_cast<int>(i);
  for (size_t i = 0; i < scene_.actuators.size(); ++i) {
    ActuatorData& a = actuators_[i];
    a.desc = &scene_.actuators[i];
    a.model = actuators::Make(*a.desc);
    a.model->SetTimeStep(dt_);  // refuses a step that would take too many sub-steps
    for (size_t t = 0; t < scene_.tendons.size(); ++t)
      if (scene_.tendons[t].name == a.desc->tendon) a.tendon = static_cast<int>(t);
    tendons_[a.tendon].actuators.push_back(static_cast<int>(i));
  }
  LayOutActuatorStates();
  double largest = 0;
  for (const auto& b : scene_.bodies)
    for (const auto& shape : b.shapes) {
      const double r = sgal::BoundingRadius(shape.geometry);
      if (!std::isfinite(r)) continue;  // planes: their contacts come from their normal
      largest = std::max(largest, r + shape.pose.position.norm());
    }
  // a detour point lies within its shape's reach of the shape's origin, which lies within that
  // reach of the segment; an exact wrap's vertices stand out of the surface by up to 8.3 %
  detour_reach_ = 2.1 * largest;
  CacheBodyPoses();
  RefreshWorldShapes();
  EvaluateTendons();
  for (auto& a : actuators_) a.model->Reset(tendons_[a.tendon].geometry.length);
  // the tensions at rest act through the first step
  for (auto& t : tendons_) {
    t.previous_length = -1;
    t.geometry.speed = 0;
    t.tension = 0;
    for (int index : t.actuators) t.tension += actuators_[index].model->tension();
  }
  UpdateJoints();
}

void BulletScene::RefreshWorldShapes() {
  if (!options_.tendon_body_contact) return;
  for (size_t i = 0; i < bodies_.size(); ++i) {
    BodyData& b = bodies_[i];
    const Isometry3d& pose = poses_[i];
    if (b.shape_poses.size() != b.desc->shapes.size()) {
      b.shape_poses.clear();
      for (const auto& shape : b.desc->shapes) b.shape_poses.push_back(shape.pose.ToIsometry());
    }
    if (b.world_shapes.size() != b.desc->shapes.size()) {
      // what does not move with the body, once: the geometry, its bounding radius and box
      b.world_shapes.resize(b.desc->shapes.size());
      for (size_t s = 0; s < b.desc->shapes.size(); ++s) {
        b.world_shapes[s].geometry = &b.desc->shapes[s].geometry;
        actuators::PrepareShape(&b.world_shapes[s]);
        b.world_shapes[s].body = static_cast<int>(i);
      }
    }
    for (size_t s = 0; s < b.desc->shapes.size(); ++s)
      b.world_shapes[s].pose = pose * b.shape_poses[s];
  }
  // the balls are rebuilt in the same order: the old one at each index is the same shape's
  size_t k = 0;
  bool same_shapes = true;
  double moved2 = 0;  // the largest squared move of a finite shape's origin [m^2]
  for (const BodyData& b : bodies_)
    for (const auto& shape : b.world_shapes) {
      const Vector3d c = shape.pose.translation();
      const ContactBall ball{c.x(), c.y(), c.z(), shape.bounding_radius, &shape};
      if (k < contact_balls_.size() && contact_balls_[k].shape == &shape) {
        const ContactBall& old = contact_balls_[k];
        if (std::isfinite(ball.radius))
          moved2 = std::max(moved2, (c - Vector3d(old.x, old.y, old.z)).squaredNorm());
        contact_balls_[k] = ball;
      } else {
        same_shapes = false;
        contact_balls_.resize(k);
        contact_balls_.push_back(ball);
      }
      ++k;
    }
  same_shapes &= k == contact_balls_.size();
  contact_balls_.resize(k);
  // rounded up: however large the sum grows, no move is lost to rounding (the memories' proof
  // rests on it)
  if (moved2 > 0)
    contact_travel_ = std::nextafter(contact_travel_ + std::sqrt(moved2),
                                     std::numeric_limits<double>::infinity());
  // other shapes than the memories hold: they start again
  if (!same_shapes)
    for (auto& t : tendons_) t.contact_memory.Clear();
}

// Every shape whose bounding ball comes within `pad` of the box around a-b, in body order. A scan
// of the poses of this step rather than Bullet's broadphase: its boxes were computed before the
// step moved the bodies (and not at all after a state restore), and for a robot's few dozen
// shapes its tree walk with this padding cost more than the scan.
void BulletScene::QueryShapes(const Vector3d& a, const Vector3d& b, double pad,
                              std::vector<const actuators::WorldShape*>* out) {
  const Vector3d lo = a.cwiseMin(b) - Vector3d::Constant(pad);
  const Vector3d hi = a.cwiseMax(b) + Vector3d::Constant(pad);
  for (const ContactBall& c : contact_balls_) {
    const double r = c.radius;  // infinite for planes: always taken
    if (c.x >= lo.x() - r && c.x <= hi.x() + r && c.y >= lo.y() - r && c.y <= hi.y() + r &&
        c.z >= lo.z() - r && c.z <= hi.z() + r)
      out->push_back(c.shape);
  }
}

void BulletScene::EvaluateTendons() {
  for (size_t ti = 0; ti < tendons_.size(); ++ti) {
    stage_ = {StepStage::kTendon, static_cast<int>(ti)};
    EvaluateTendon(ti, &contact_scratch_[0]);
  }
}

const Isometry3d kWorldPose = Isometry3d::Identity();  // where a point on the world (-1) is

// a point of a path in the world (rotation and translation written out: at -O2 Eigen's transform
// product went out of line here, and GCC left even this function out of line unless told)
[[gnu::always_inline]] inline void Place(const std::vector<Isometry3d>& poses,
                                         const ElementRef& ref, Vector3d* out) {
  const Isometry3d& body_pose = ref.body < 0 ? kWorldPose : poses[ref.body];
  out->noalias() = body_pose.linear() * ref.desc->position;
  *out += body_pose.translation();
}

void BulletScene::PlaceStraight(TendonData& t) const {
  // what TendonPath::Evaluate makes of points alone, without going through its elements (the
  // cost of most of a light scene's tendons): the points where their bodies are and straight
  // pieces between them; the speed is measured from lengths (AdvanceTendon)
  std::vector<actuators::PathPoint>& points = t.geometry.points;
  points.resize(t.elements.size());  // contacts inserted last step go
  for (size_t k = 0; k < t.elements.size(); ++k) {
    const ElementRef& ref = t.elements[k];
    actuators::PathPoint& p = points[k];
    Place(poses_, ref, &p.position);
    p.body = ref.body;
    p.friction = ref.desc->friction;
    p.on_wrap = false;
    p.contact = false;
  }
  t.geometry.length = actuators::StraightPieces(points, &t.units);
  t.geometry.speed = 0;
}

void BulletScene::EvaluateTendon(size_t ti, actuators::ContactScratch* scratch, bool placed) {
  // the path's speed is measured from its lengths at the ends of a step (Step): the points'
  // velocities are not needed
  TendonData& t = tendons_[ti];
  if (t.points_only) {
    if (!placed) PlaceStraight(t);
  } else {
    t.world.resize(t.elements.size());
    for (size_t k = 0; k < t.elements.size(); ++k) {
      const ElementRef& ref = t.elements[k];
      const sgal::PathElement& e = *ref.desc;
      actuators::WorldElement& w = t.world[k];
      w.kind = e.kind;
      w.body = ref.body;
      if (e.kind == sgal::PathElement::Kind::kPoint) {
        Place(poses_, ref, &w.point);
        w.velocity.setZero();
        w.friction = e.friction;
      } else {
        const sgal::WrapObstacle* o = ref.obstacle;
        const Isometry3d& body_pose = ref.body < 0 ? kWorldPose : poses_[ref.body];
        w.obstacle.kind = o->kind;
        w.obstacle.pose = body_pose * o->pose.ToIsometry();
        w.obstacle.radius = o->radius;
        w.obstacle.length = o->length;
        w.velocity.setZero();
        if (e.side) w.side = body_pose * (*e.side);
      }
    }
    t.path.Evaluate(t.world, &t.geometry);
  }
  t.contacts = 0;
  t.straight = t.points_only;
  if (options_.tendon_body_contact && t.desc->collide_with_bodies) {
    // captures only `this`: held inside the std::function, no allocation
    const actuators::ShapeQuery query = [this](const Vector3d& a, const Vector3d& b, double pad,
                                               std::vector<const actuators::WorldShape*>* out) {
      QueryShapes(a, b, pad, out);
    };
    actuators::ContactOptions contact;
    contact.margin = t.desc->radius;
    contact.detour_reach = detour_reach_ + 2 * contact.margin;  // the reaches grow by it
    t.contacts = actuators::WrapAroundBodies(&t.geometry, query, contact, scratch,
                                             &t.contact_memory, contact_travel_);
    t.straight = t.points_only && t.contacts == 0;
  }
}

// Handing the work to the threads and waiting for the last costs a few microseconds, more than a
// light scene's tendons (springs, no contact) cost on one, and a thread that waits for work keeps
// a processor busy, which may slow the rest of the step where processors share a core. So whole
// steps are timed each way, in cycles: the first kProbe steps of a cycle go the other way. A
// way's mean is taken over a cycle's steps but the first after a change (which still follows the
// other way), each at most four times the last mean (a step the system held up once does not
// decide); each cycle decides afresh, as contacts come and go.
// Several threads are kept for the next cycle only when they save at least 5 % of a step, since
// the waiting thread keeps a processor busy that other programs (the GUI, other Models) could
// use. Either way gives the same bits.
constexpr uint64_t kCycle = 256, kProbe = 8;
constexpr double kGain = 0.95;

void BulletScene::ChooseThreads() {
  const ThreadChoice& c = choice_;
  parallel_now_ = c.step < kProbe ? !c.parallel_preferred : c.parallel_preferred;
}

void BulletScene::TimeStep(double seconds) {
  ThreadChoice& c = choice_;
  const int way = parallel_now_ ? 1 : 0;
  if (c.step != 0 && c.step != kProbe) {
    c.sum[way] += c.mean[way] > 0 ? std::min(seconds, 4 * c.mean[way]) : seconds;
    ++c.count[way];
  }
  if (++c.step < kCycle) return;
  for (int w = 0; w < 2; ++w) {
    if (c.count[w] == 0) continue;
    c.mean[w] = c.sum[w] / c.count[w];  // this cycle's: the load changes as contacts come and go
    c.sum[w] = 0;
    c.count[w] = 0;
  }
  if (c.mean[0] > 0 && c.mean[1] > 0) c.parallel_preferred = c.mean[1] < kGain * c.mean[0];
  c.step = 0;
}

void BulletScene::AdvanceTendons() {
  const int n = static_cast<int>(tendons_.size());
  if (threads_ <= 1 || !parallel_now_) {  // Bullet searches the contacts inside the next step
    // the straight paths placed first, all of them, so that their roots and divisions overlap
    // (between the actuators' calls one tendon's ran alone); nothing of this throws
    for (TendonData& t : tendons_) {
      BeginTendonStep(t);
      if (t.points_only) PlaceStraight(t);
    }
    for (int ti = 0; ti < n; ++ti) {
      stage_ = {StepStage::kTendon, ti};
      EvaluateTendon(ti, &contact_scratch_[0], true);
      ActuateTendon(ti, &stage_);
    }
    return;
  }
  const bool ahead = options_.search_contacts_ahead;
  // job 0 is Bullet's contact search for the next step (AheadWorld), the others a tendon each:
  // each tendon's work reads Caliper's copy of the poses and the shapes of this step and writes
  // only its own tendon and actuators. A thread takes the next job when done with one.
  job_faults_.assign(tendons_.size() + 1, nullptr);
  job_fault_stages_.resize(tendons_.size() + 1);
  auto run = [&](int job, int thread) {
    StepStage stage;
    try {
      if (job == 0) {
        if (ahead) world_->DetectAhead(static_cast<btScalar>(dt_));
      } else {
        AdvanceTendon(job - 1, &contact_scratch_[thread], &stage);
      }
    } catch (...) {  // an exception must not leave the parallel loop
      job_faults_[job] = std::current_exception();
      job_fault_stages_[job] = stage;
    }
  };
#if defined(__SANITIZE_THREAD__)
  // ThreadSanitizer cannot see libgomp's fork and join (libgomp is not built with it): the same
  // jobs, claimed the same way, on threads it sees start and end, so that it still finds two jobs
  // that touch the same data
  std::atomic<int> next{0};
  auto claim = [&](int thread) {
    for (int job = next++; job <= n; job = next++) run(job, thread);
  };
  std::vector<std::thread> helpers;
  for (int thread = 1; thread < threads_; ++thread) helpers.emplace_back(claim, thread);
  claim(0);
  for (auto& helper : helpers) helper.join();
#else
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads_)
  for (int job = 0; job <= n; ++job) run(job, omp_get_thread_num());
#endif
  // the first fault in the serial order: the tendons', then the search's
  for (int k = 1; k <= n + 1; ++k) {
    const int job = k % (n + 1);
    if (job_faults_[job]) {
      stage_ = job_fault_stages_[job];
      std::rethrow_exception(job_faults_[job]);
    }
  }
}

void BulletScene::BeginTendonStep(TendonData& t) {
  t.speed_known = t.previous_length >= 0;
  t.previous_length = t.geometry.length;
  t.mean_speed = t.geometry.speed;
}

void BulletScene::AdvanceTendon(size_t ti, actuators::ContactScratch* scratch, StepStage* stage) {
  BeginTendonStep(tendons_[ti]);
  *stage = {StepStage::kTendon, static_cast<int>(ti)};
  EvaluateTendon(ti, scratch);
  ActuateTendon(ti, stage);
}

void BulletScene::ActuateTendon(size_t ti, StepStage* stage) {
  TendonData& t = tendons_[ti];
  // the mean lengthening speed over the step: the path's motion the actuators integrate along
  // (length at the start + speed * dt is exactly the length at the end); the speed at the end,
  // for what reads it directly (dampers, force-velocity), from the last two means to second
  // order (the mean lags it by half a step)
  t.geometry.speed = (t.geometry.length - t.previous_length) / dt_;
  const double end_speed =
      t.speed_known ? t.geometry.speed + 0.5 * (t.geometry.speed - t.mean_speed) : t.geometry.speed;
  t.end_speed = end_speed;
  t.tension = 0;
  for (int index : t.actuators) {
    *stage = {StepStage::kActuator, index};
    ActuatorData& a = actuators_[index];
    const double f = a.model->Step(t.previous_length, t.geometry.speed, dt_, end_speed);
    if (!std::isfinite(f))
      throw StepFault(Describe(*stage) + ": tension is not finite (" + std::to_string(f) +
                          ") at t = " + std::to_string(time_ + dt_) +
                          " s; simulation stopped at t = " + std::to_string(time_) + " s (step " +
                          std::to_string(steps_) + ")",
                      a.desc->name, time_ + dt_);
    if (std::abs(f) > options_.max_tension)
      throw StepFault(
          Describe(*stage) + ": tension " + std::to_string(f) + " N beyond the engine's bound of " +
              std::to_string(options_.max_tension) + " N (path speed " +
              std::to_string(t.geometry.speed) + " m/s) at t = " + std::to_string(time_ + dt_) +
              " s; simulation stopped at t = " + std::to_string(time_) + " s (step " +
              std::to_string(steps_) + ")",
          a.desc->name, time_ + dt_);
    t.tension += f;
  }
}

void BulletScene::ApplyTendonForces() {
  for (size_t ti = 0; ti < tendons_.size(); ++ti) {
    const TendonData& t = tendons_[ti];
    if (t.tension <= 0) continue;
    stage_ = {StepStage::kTendon, static_cast<int>(ti)};
    const std::vector<actuators::PathPoint>& points = t.geometry.points;
    auto apply = [&](size_t k, const Vector3d& force) {
      const int body = points[k].body;
      if (body < 0 || !bodies_[body].dynamic) return;
      bodies_[body].rigid->applyForce(ToBt(force, scale_),
                                      ToBt(points[k].position - coms_[body], scale_));
    };
    if (t.straight) {  // the directions placing the points found (the same bits)
      actuators::EmitPathForces(
          points, t.geometry.speed, t.tension, [&](size_t k) { return t.units[k]; }, apply);
    } else {
      actuators::EmitPathForces(points, t.geometry.speed, t.tension, apply);
    }
  }
}

void BulletScene::UpdateJoints() {
  static const Isometry3d kWorld = Isometry3d::Identity();
  auto pose = [&](int body) -> const Isometry3d& { return body < 0 ? kWorld : poses_[body]; };
  auto spin = [&](int body) { return body < 0 ? Vector3d::Zero() : spins_[body]; };
  auto velocity = [&](int body, const Vector3d& p) -> Vector3d {
    if (body < 0) return Vector3d::Zero();
    return velocities_[body] + spins_[body].cross(p - coms_[body]);
  };
  for (auto& j : joints_) {
    const sgal::Constraint& c = *j.desc;
    if (c.kind != sgal::ConstraintKind::kHinge && c.kind != sgal::ConstraintKind::kSlider) continue;
    const Isometry3d& pa = pose(j.body_a);
    const Isometry3d& pb = pose(j.body_b);
    // the joint frames' axes in the world, only those read (body rotation times frame axis)
    const Eigen::Matrix3d rb = pb.linear();
    const Vector3d axis = rb * j.b_z;
    j.axis = axis;
    if (c.kind == sgal::ConstraintKind::kHinge) {
      // rotation of body_a's joint frame relative to body_b's (the parent's), about z: the
      // angle of a's x axis in b's x-y plane, read in body_b's frame
      const Vector3d xa = rb.transpose() * (pa.linear() * j.a_x);
      const double cos = xa.dot(j.b_x);
      const double sin = xa.dot(j.b_y);
      // whole turns counted, so that a continuous joint, a multi-turn limit (a UR5's +-2 pi) and
      // a coupling's leader read on past +-pi instead of jumping: the angle's branch nearest the
      // position carried over, then one turn more or less each time the reading passes +-pi (a
      // hinge turns far less than half a turn in a step). It passes there when the sine's sign
      // (atan2's branch) changes where the chord between the two readings crosses the negative
      // x axis.
      if (!j.turns_counted) {
        j.turns = std::nearbyint((j.position - std::atan2(sin, cos)) * (0.5 / M_PI));
        j.turns_counted = true;
      } else if (std::signbit(sin) != std::signbit(j.reading_sin)) {
        const double x = j.reading_cos * std::abs(sin) + cos * std::abs(j.reading_sin);
        if (x < 0 || (x == 0 && j.reading_cos + cos < 0)) j.turns += std::signbit(sin) ? 1 : -1;
      }
      j.reading_cos = cos;
      j.reading_sin = sin;
      j.velocity = axis.dot(spin(j.body_a) - spin(j.body_b));
    } else {
      const Vector3d at_a = pa * j.frame_a.translation();
      const Vector3d at_b = pb * j.frame_b.translation();
      j.position = axis.dot(at_a - at_b);
      j.velocity = axis.dot(velocity(j.body_a, at_a) - velocity(j.body_b, at_a));
    }
  }
}

void BulletScene::ApplyJointSprings() {
  for (auto& j : joints_) {
    const sgal::Constraint& c = *j.desc;
    if (c.kind != sgal::ConstraintKind::kHinge && c.kind != sgal::ConstraintKind::kSlider) continue;
    const sgal::JointSpring& sp = c.springs[0];
    if (sp.stiffness == 0 && sp.damping == 0) continue;
    PushJoint(j, -(sp.stiffness * (JointPosition(j) - sp.rest) + sp.damping * j.velocity));
  }
}

double BulletScene::JointInverseInertia(const JointData& j) const {
  // What the joint's coordinate sees of its own two bodies: body_a turning about the joint axis
  // (parallel axes), body_b about its centre of mass (it may be free), or their masses for a
  // slider. Whatever hangs on them through other joints only adds inertia.
  const sgal::Constraint& c = *j.desc;
  auto inverse = [&](int body, const sgal::Pose& frame, bool about_joint) -> double {
    if (body < 0 || scene_.bodies[body].type != sgal::BodyType::kDynamic) return 0;
    const sgal::Inertia& in = scene_.bodies[body].inertia;
    if (c.kind == sgal::ConstraintKind::kSlider) return 1 / in.mass;
    const Vector3d axis = frame.orientation.normalized() * Vector3d::UnitZ();
    double inertia = axis.dot(in.tensor * axis);
    if (about_joint) {
      const Vector3d r = in.com - frame.position;
      inertia += in.mass * (r - r.dot(axis) * axis).squaredNorm();
    }
    return 1 / inertia;
  };
  return inverse(j.body_a, c.frame_a, true) + inverse(j.body_b, c.frame_b, false);
}

void BulletScene::BuildCouplings() {
  std::unordered_map<std::string, int> joint_index;
  for (size_t k = 0; k < joints_.size(); ++k)
    joint_index[joints_[k].desc->name] = static_cast<int>(k);
  for (const auto& k : scene_.couplings) {
    CouplingData data;
    data.desc = &k;
    data.leader = joint_index.at(k.leader);  // Validate checked the names and kinds
    data.follower = joint_index.at(k.follower);
    couplings_.push_back(data);
  }
}

void BulletScene::PushJoint(const JointData& j, double load) {
  // a torque (hinge) or force (slider) on body_a along the joint axis, its reaction on body_b
  const bool hinge = j.desc->kind == sgal::ConstraintKind::kHinge;
  auto push = [&](int body, double sign) {
    if (body < 0 || scene_.bodies[body].type != sgal::BodyType::kDynamic) return;
    btRigidBody& rb = *bodies_[body].rigid;
    if (hinge)
      rb.applyTorque(ToBt(j.axis * (sign * load), scale_ * scale_));
    else
      rb.applyCentralForce(ToBt(j.axis * (sign * load), scale_));
  };
  push(j.body_a, 1.0);
  push(j.body_b, -1.0);
}

void BulletScene::ApplyCouplings() {
  // The error e = q_f - (ratio q_l + offset) has the inertia m_e, 1/m_e = 1/M_f + ratio^2 / M_l
  // (M: what each joint sees, see JointInverseInertia). A spring m_e w^2 with critical damping
  // 2 m_e w closes it; explicit forces in Bullet's semi-implicit step stay stable for w dt up to
  // about 0.8, and w dt = 0.2 leaves room for m_e being overestimated five-fold. Set each step:
  // the time step may change. Hinge positions count whole turns (UpdateJoints).
  const double w = 0.2 / dt_;
  for (auto& k : couplings_) {
    const JointData& leader = joints_[k.leader];
    const JointData& follower = joints_[k.follower];
    const double ratio = k.desc->ratio;
    const double inverse =
        JointInverseInertia(follower) + ratio * ratio * JointInverseInertia(leader);
    if (!(inverse > 0)) continue;  // neither joint can move
    const double m = 1 / inverse;
    k.stiffness = m * w * w;
    k.damping = 2 * m * w;
    const double error = JointPosition(follower) - (ratio * JointPosition(leader) + k.desc->offset);
    const double rate = follower.velocity - ratio * leader.velocity;
    // the generalised force on q_f, and by the chain rule -ratio times it on q_l
    const double load = -(k.stiffness * error + k.damping * rate);
    PushJoint(follower, load);
    PushJoint(leader, -ratio * load);
  }
}

void BulletScene::ApplyJointFriction() {
  // Dry friction as PyBullet models it: a velocity motor aiming at rest whose impulse per step is
  // bounded by friction * dt, so the solver holds the joint while the load stays below the
  // friction and brakes it with exactly the friction above. Set every step: the friction (a
  // parameter) and the time step may change between steps. Engine units: forces scale with the
  // world scale, torques with its square. At a hinge or slider limit, the limit's row takes over.
  for (auto& j : joints_) {
    const sgal::Constraint& c = *j.desc;
    switch (c.kind) {
      case sgal::ConstraintKind::kHinge: {
        auto* hinge = static_cast<btHingeConstraint*>(j.constraint.get());
        // Bullet's hinge motor takes an impulse per step, its other motors a force
        const double impulse = c.friction[0] * scale_ * scale_ * dt_;
        hinge->enableAngularMotor(c.friction[0] > 0, 0, static_cast<btScalar>(impulse));
        break;
      }
      case sgal::ConstraintKind::kSlider: {
        auto* slider = static_cast<btSliderConstraint*>(j.constraint.get());
        slider->setPoweredLinMotor(c.friction[0] > 0);
        slider->setTargetLinMotorVelocity(0);
        slider->setMaxLinMotorForce(static_cast<btScalar>(c.friction[0] * scale_));
        break;
      }
      case sgal::ConstraintKind::kGeneric6Dof: {
        auto* g = static_cast<btGeneric6DofSpring2Constraint*>(j.constraint.get());
        for (int i = 0; i < 6; ++i) {
          g->enableMotor(i, c.friction[i] > 0);
          g->setTargetVelocity(i, 0);
          const double unit = i < 3 ? scale_ : scale_ * scale_;
          g->setMaxMotorForce(i, static_cast<btScalar>(c.friction[i] * unit));
        }
        break;
      }
      case sgal::ConstraintKind::kBall:
      case sgal::ConstraintKind::kFixed:
        break;
    }
  }
}

void BulletScene::CheckState() {
  // what CacheBodyPoses took from Bullet
  for (size_t i = 0; i < bodies_.size(); ++i) {
    const Vector3d& p = coms_[i];
    const Vector3d& v = velocities_[i];
    const Vector3d& w = spins_[i];
    std::string problem;
    if (!p.allFinite() || !v.allFinite() || !w.allFinite()) {
      problem = "non-finite state";
    } else if (p.squaredNorm() > options_.max_distance * options_.max_distance) {
      problem = "flew off to " + std::to_string(p.norm()) + " m";
    } else if (v.squaredNorm() > options_.max_speed * options_.max_speed) {
      problem = "speed " + std::to_string(v.norm()) + " m/s";
    }
    if (!problem.empty()) {
      const std::string name = scene_.bodies[i].name;
      throw StepFault("body '" + name + "': " + problem + " at t = " +
                          std::to_string(time_ + dt_) + " s; simulation stopped at t = " +
                          std::to_string(time_) + " s (step " + std::to_string(steps_) + ")",
                      name, time_ + dt_);
    }
  }
}

void BulletScene::SaveStepState() {
  // what may allocate (and so throw) comes first, before anything of the scene is swapped: a
  // failure here leaves the scene as it was
  snapshot_.resize(bodies_.size());
  for (auto& t : tendons_)
    if (t.has_wraps) t.saved_path = t.path;  // a few ints, no allocation after the first step
  for (size_t i = 0; i < bodies_.size(); ++i) {
    const btRigidBody& rb = *bodies_[i].rigid;
    snapshot_[i] = {rb.getCenterOfMassTransform(), rb.getLinearVelocity(), rb.getAngularVelocity()};
  }
  for (auto& t : tendons_) {
    // the geometry is a function of the poses and wrap sides: a failed step evaluates it again
    // rather than every step copying it
    t.saved_speed = t.geometry.speed;
    t.saved_end_speed = t.end_speed;
    t.saved_previous_length = t.previous_length;
    t.saved_tension = t.tension;
  }
  for (const auto& a : actuators_) a.model->SaveStepState(actuator_states_.data() + a.state_offset);
  for (auto& d : delays_) {
    d.saved_head = d.head;
    d.saved_oldest = d.ring[d.head];
  }
}

void BulletScene::RestoreStepState() {
  world_->ForgetAhead();
  for (size_t i = 0; i < bodies_.size(); ++i) {
    btRigidBody& rb = *bodies_[i].rigid;
    // velocities first: setting the transform copies them into the interpolation state, as a
    // step does
    rb.setLinearVelocity(snapshot_[i].linear);
    rb.setAngularVelocity(snapshot_[i].angular);
    rb.setCenterOfMassTransform(snapshot_[i].transform);
    rb.clearForces();
  }
  for (auto& t : tendons_) {
    if (t.has_wraps) t.path = t.saved_path;
    t.previous_length = t.saved_previous_length;
    t.tension = t.saved_tension;
  }
  // an actuator that cannot put its step back (a broken contract: TendonActuator says when it
  // may not) is reported after everything else was put back
  std::exception_ptr broken;
  for (auto& a : actuators_) {
    try {
      a.model->RestoreStepState(actuator_states_.data() + a.state_offset);
    } catch (...) {
      if (!broken) broken = std::current_exception();
    }
  }
  for (auto& d : delays_) {
    d.head = d.saved_head;
    d.ring[d.head] = d.saved_oldest;
  }
  CacheBodyPoses();
  UpdateJoints();
  // the paths where the step started, as the last step's end evaluated them (the same poses and
  // wrap sides give the same bits)
  RefreshWorldShapes();
  EvaluateTendons();
  for (auto& t : tendons_) {
    t.geometry.speed = t.saved_speed;
    t.end_speed = t.saved_end_speed;
  }
  if (broken) std::rethrow_exception(broken);
}

std::string BulletScene::Describe(const StepStage& stage) const {
  switch (stage.kind) {
    case StepStage::kActuator: {
      const sgal::Actuator& a = *actuators_[stage.index].desc;
      return "actuator '" + a.name + "' (" + a.kind + ")";
    }
    case StepStage::kTendon:
      return "tendon '" + tendons_[stage.index].desc->name + "'";
    case StepStage::kWorld:
      break;
  }
  return "the Bullet world";
}

void BulletScene::FailStep() {
  // called while an exception is handled: back to the start of the step, then say why (the
  // stage that failed, kept: putting the step back evaluates the paths again)
  const StepStage failed = stage_;
  std::string what;
  try {
    throw;
  } catch (const StepFault&) {
    RestoreStepState();
    throw;
  } catch (...) {
    what = CurrentException();
  }
  RestoreStepState();
  stage_ = failed;
  const std::string element = stage_.kind == StepStage::kActuator
                                  ? actuators_[stage_.index].desc->name
                                  : stage_.kind == StepStage::kTendon
                                        ? tendons_[stage_.index].desc->name
                                        : std::string("world");
  throw sgal::SimulationFault(Describe(stage_) + " failed at t = " + std::to_string(time_ + dt_) +
                                  " s: " + what + "; simulation stopped at t = " +
                                  std::to_string(time_) + " s (step " + std::to_string(steps_) +
                                  ")",
                              element, time_ + dt_);
}

void BulletScene::Step() {
  // A failing step leaves the scene as it was at its start: bodies, tendons, every actuator's
  // state, the delayed channels, time and step count. Bullet's contact cache (warm-start impulses)
  // is not rolled back: after a fault inside stepSimulation or an exploding body, a scene with
  // contacts that steps on may differ in the last bits from one that never faulted.
  //
  // Actuators and bodies take turns in Stormer-Verlet order (second order in dt, see
  // TendonActuator::Step): the bodies advance on the tendons' tensions and paths at the start of
  // the step (from the end of the last one), then the paths are evaluated where the bodies went
  // and each actuator advances along the path's motion over the same step. Tendon length, speed
  // and tension at the end of a step belong to the same instant as the bodies' poses.
  // the way for this step and the time it takes, only where there is a choice
  const bool choosing = threads_ > 1 && options_.choose_threads;
  std::chrono::steady_clock::time_point started;
  if (choosing) {
    started = std::chrono::steady_clock::now();
    ChooseThreads();
  }
  SaveStepState();
  try {
    // poses, joints and tendon paths were brought up to date at the end of the last step (or at
    // construction, or a restore)
    ApplyTendonForces();
    stage_ = {StepStage::kWorld, -1};
    ApplyJointSprings();
    ApplyJointFriction();
    ApplyCouplings();
    ApplyPull();
    world_->stepSimulation(static_cast<btScalar>(dt_), 0, static_cast<btScalar>(dt_));
    CacheBodyPoses();
    CheckState();
    UpdateJoints();
    RefreshWorldShapes();
    AdvanceTendons();
    PushMeasurements();
  } catch (...) {
    FailStep();
  }
  if (choosing)
    TimeStep(std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count());
  time_ += dt_;
  ++steps_;
}

void BulletScene::ApplyPull() {
  pull_force_.setZero();
  if (!pull_) return;
  const int i = pull_->body;
  const Vector3d at = poses_[i] * pull_->point;
  const Vector3d v = velocities_[i] + spins_[i].cross(at - coms_[i]);
  const Vector3d force = pull_->stiffness * (pull_->target - at) - pull_->damping * v;
  pull_force_ = force;
  bodies_[i].rigid->applyForce(ToBt(force, scale_), ToBt(at - coms_[i], scale_));
}

void BulletScene::SetPull(const sgal::Pull& pull) {
  if (pull.body < 0 || pull.body >= static_cast<int>(bodies_.size()) ||
      scene_.bodies[pull.body].type != sgal::BodyType::kDynamic)
    throw std::out_of_range("pull: body index " + std::to_string(pull.body) +
                            " is not a moving body");
  if (!pull.point.allFinite() || !pull.target.allFinite() || !std::isfinite(pull.stiffness) ||
      !std::isfinite(pull.damping) || pull.stiffness < 0 || pull.damping < 0)
    throw std::invalid_argument("pull on '" + scene_.bodies[pull.body].name +
                                "': point, target, stiffness and damping must be finite, the "
                                "last two >= 0");
  pull_ = pull;
}

namespace {

// the engine's floats, kept exactly in doubles
void PutTransform(const btTransform& t, std::vector<double>* out) {
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) out->push_back(t.getBasis()[r][c]);
  for (int k = 0; k < 3; ++k) out->push_back(t.getOrigin()[k]);
}

void PutVector(const btVector3& v, std::vector<double>* out) {
  for (int k = 0; k < 3; ++k) out->push_back(v[k]);
}

btTransform TakeTransform(const double*& in) {
  btMatrix3x3 basis;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) basis[r][c] = static_cast<btScalar>(*in++);
  btVector3 origin(0, 0, 0);
  for (int k = 0; k < 3; ++k) origin[k] = static_cast<btScalar>(*in++);
  return btTransform(basis, origin);
}

btVector3 TakeVector(const double*& in) {
  btVector3 v(0, 0, 0);
  for (int k = 0; k < 3; ++k) v[k] = static_cast<btScalar>(*in++);
  return v;
}

constexpr size_t kBodyEngineValues = kEngineValuesPerBody;
static_assert(kBodyEngineValues == 2 * 12 + 4 * 3, "two transforms, four velocities");

}  // namespace

sgal::DynamicState BulletScene::SaveDynamicState() const {
  sgal::DynamicState s;
  s.time = time_;
  s.steps = steps_;
  s.bodies = BodyStates();
  for (const auto& j : joints_) s.joint_positions.push_back(JointPosition(j));
  for (const auto& b : bodies_) {
    const btRigidBody& rb = *b.rigid;
    PutTransform(rb.getCenterOfMassTransform(), &s.engine);
    PutTransform(rb.getInterpolationWorldTransform(), &s.engine);
    PutVector(rb.getLinearVelocity(), &s.engine);
    PutVector(rb.getAngularVelocity(), &s.engine);
    PutVector(rb.getInterpolationLinearVelocity(), &s.engine);
    PutVector(rb.getInterpolationAngularVelocity(), &s.engine);
  }
  for (const auto& t : tendons_) {
    s.engine.push_back(t.previous_length);
    s.engine.push_back(t.geometry.speed);  // the mean, as measured with the step's own dt
    s.engine.push_back(t.end_speed);
    s.engine.push_back(static_cast<double>(t.path.wrap_sides().size()));
    for (int side : t.path.wrap_sides()) s.engine.push_back(side);
  }
  for (const auto& a : actuators_) {
    std::vector<double> state(a.model->StateSize());
    a.model->SaveState(state.data());
    s.actuators.push_back(std::move(state));
    s.commands.push_back(a.model->command());
  }
  for (const auto& d : delays_)
    for (size_t i = 0; i < d.ring.size(); ++i)
      s.measurements.push_back(d.ring[(d.head + i) % d.ring.size()]);
  return s;
}

void BulletScene::ResetCaches() {
  world_->ForgetAhead();
  // every body and constraint out (their contact manifolds go with their pairs), a new broad
  // phase, then all back in the order the constructor adds them, at their present poses
  std::vector<std::pair<int, int>> filters;
  for (auto& j : joints_) world_->removeConstraint(j.constraint.get());
  for (auto& b : bodies_) {
    const btBroadphaseProxy* proxy = b.rigid->getBroadphaseHandle();
    filters.emplace_back(proxy ? proxy->m_collisionFilterGroup : 0,
                         proxy ? proxy->m_collisionFilterMask : 0);
    world_->removeRigidBody(b.rigid.get());
  }
  auto fresh = std::make_unique<btDbvtBroadphase>();
  world_->setBroadphase(fresh.get());
  broadphase_ = std::move(fresh);
  for (size_t i = 0; i < bodies_.size(); ++i)
    world_->addRigidBody(bodies_[i].rigid.get(), filters[i].first, filters[i].second);
  for (auto& j : joints_) world_->addConstraint(j.constraint.get(), !j.desc->collide_connected);
}

void BulletScene::RestoreDynamicState(const sgal::DynamicState& s) {
  world_->ForgetAhead();
  auto refuse = [](const std::string& what) {
    throw std::invalid_argument("restoring the dynamic state: " + what);
  };
  if (s.bodies.size() != bodies_.size())
    refuse(std::to_string(s.bodies.size()) + " bodies for a scene of " +
           std::to_string(bodies_.size()));
  if (s.joint_positions.size() != joints_.size())
    refuse(std::to_string(s.joint_positions.size()) + " joint positions for a scene of " +
           std::to_string(joints_.size()) + " constraints");
  if (s.actuators.size() != actuators_.size() || s.commands.size() != actuators_.size())
    refuse(std::to_string(s.actuators.size()) + " actuator states for a scene of " +
           std::to_string(actuators_.size()) + " actuators");
  // a state may be longer or shorter than the actuator's own (a command delay's line saved under
  // another delay): the actuator says whether it reads it
  for (size_t k = 0; k < actuators_.size(); ++k)
    if (!s.actuators[k].empty() &&
        !actuators_[k].model->Restorable(s.actuators[k].data(), s.actuators[k].size()))
      refuse("actuator '" + actuators_[k].desc->name + "' cannot read the " +
             std::to_string(s.actuators[k].size()) + " state values given (its own are " +
             std::to_string(actuators_[k].model->StateSize()) + ")");
  size_t remembered = 0;  // the values the delayed channels hold
  for (const auto& d : delays_) remembered += d.ring.size();
  if (!s.measurements.empty() && s.measurements.size() != remembered)
    refuse(std::to_string(s.measurements.size()) + " measurements for a scene whose " +
           std::to_string(delays_.size()) + " delayed channels hold " + std::to_string(remembered));
  const bool exact = !s.engine.empty();
  if (exact && s.engine.size() < bodies_.size() * kBodyEngineValues + 4 * tendons_.size())
    refuse("the engine state has " + std::to_string(s.engine.size()) + " values, too few for " +
           std::to_string(bodies_.size()) + " bodies");
  // the tendons' part of an exact state, read (and refused) before anything changes: the length
  // at the start of the step that ended here, and the wrap sides the path goes on from (set
  // before the path is evaluated)
  std::vector<double> previous(tendons_.size(), -1);
  std::vector<double> mean_speeds(tendons_.size(), 0);
  std::vector<double> end_speeds(tendons_.size(), 0);
  std::vector<std::vector<int>> wrap_sides(tendons_.size());
  if (exact) {
    // after the bodies' values
    const double* in = s.engine.data() + bodies_.size() * kBodyEngineValues;
    const double* end = s.engine.data() + s.engine.size();
    for (size_t ti = 0; ti < tendons_.size(); ++ti) {
      if (end - in < 4) refuse("the engine state ends before the tendons'");
      previous[ti] = *in++;
      mean_speeds[ti] = *in++;
      end_speeds[ti] = *in++;
      const double count = *in++;
      const size_t elements = tendons_[ti].elements.size();
      if (!(count == 0 || count == static_cast<double>(elements)))
        refuse("tendon '" + tendons_[ti].desc->name + "' has " + std::to_string(elements) +
               " path elements, the engine state gives wrap sides for " + std::to_string(count));
      const size_t n = static_cast<size_t>(count);
      if (static_cast<size_t>(end - in) < n) refuse("the engine state ends in a tendon's wraps");
      std::vector<int> sides(n);
      for (size_t k = 0; k < n; ++k) {
        const double side = *in++;
        if (!(side == -1 || side == 0 || side == 1))
          refuse("tendon '" + tendons_[ti].desc->name + "': a wrap side must be -1, 0 or 1");
        sides[k] = static_cast<int>(side);
      }
      // a path of points alone keeps a side per element, none wrapping (BuildTendons), also
      // from a state that gives none
      if (tendons_[ti].points_only) sides.assign(elements, 0);
      wrap_sides[ti] = std::move(sides);
    }
    if (in != end)
      refuse("the engine state has " + std::to_string(end - in) +
             " values more than this scene's bodies and tendons hold (a state of another scene)");
  }
  const double* in = s.engine.data();
  for (size_t i = 0; i < bodies_.size(); ++i) {
    btRigidBody& rb = *bodies_[i].rigid;
    if (exact) {
      // the engine's own numbers: the same bits as when saved
      const btTransform t = TakeTransform(in);
      const btTransform interpolation = TakeTransform(in);
      const btVector3 v = TakeVector(in), w = TakeVector(in);
      const btVector3 iv = TakeVector(in), iw = TakeVector(in);
      rb.setCenterOfMassTransform(t);
      rb.setLinearVelocity(v);
      rb.setAngularVelocity(w);
      rb.setInterpolationWorldTransform(interpolation);
      rb.setInterpolationLinearVelocity(iv);
      rb.setInterpolationAngularVelocity(iw);
      rb.clearForces();
      continue;
    }
    const sgal::BodyState& b = s.bodies[i];
    // the body frame's pose and velocity to the centre of mass's, as Bullet keeps them
    const Isometry3d com = b.pose.ToIsometry() * bodies_[i].com_in_body;
    const Vector3d v_com =
        b.linear_velocity + b.angular_velocity.cross(com.translation() - b.pose.position);
    const Eigen::Quaterniond q(com.linear());
    btTransform t;
    t.setOrigin(ToBt(com.translation(), scale_));
    t.setRotation(btQuaternion(q.x(), q.y(), q.z(), q.w()));
    if (scene_.bodies[i].type == sgal::BodyType::kDynamic) {
      rb.setLinearVelocity(ToBt(v_com, scale_));
      rb.setAngularVelocity(ToBt(b.angular_velocity));
    }
    rb.setCenterOfMassTransform(t);
    if (rb.getMotionState() == nullptr) rb.setInterpolationWorldTransform(t);
    rb.clearForces();
  }
  time_ = s.time;
  steps_ = s.steps;
  for (size_t j = 0; j < joints_.size(); ++j) {
    joints_[j].position = s.joint_positions[j];
    joints_[j].turns_counted = false;  // a hinge counts on from this angle
  }
  for (size_t ti = 0; ti < tendons_.size(); ++ti)
    if (exact) tendons_[ti].path.set_wrap_sides(std::move(wrap_sides[ti]));
  CacheBodyPoses();
  UpdateJoints();  // counted turns continue from the positions carried over
  RefreshWorldShapes();
  EvaluateTendons();
  for (size_t k = 0; k < actuators_.size(); ++k) {
    ActuatorData& a = actuators_[k];
    if (!s.actuators[k].empty()) a.model->RestoreState(s.actuators[k].data());
    // passive elements take no command (and refuse one): only what differs is set
    if (s.commands[k] != a.model->command()) a.model->SetCommand(s.commands[k]);
  }
  LayOutActuatorStates();  // a restored delay line may be longer than the actuator's was
  // the tension reads what the actuators carried over hold; the speed is the last step's as an
  // exact state gives it, else none (no jump from the length before an edit)
  for (size_t ti = 0; ti < tendons_.size(); ++ti) {
    TendonData& t = tendons_[ti];
    t.previous_length = previous[ti];
    t.geometry.speed = previous[ti] >= 0 ? mean_speeds[ti] : 0;
    t.end_speed = end_speeds[ti];
    t.tension = 0;
    for (int index : t.actuators) t.tension += actuators_[index].model->tension();
  }
  RestoreMeasurements(s.measurements);  // last: an empty one reads the state restored
}

void BulletScene::RestoreMeasurements(const std::vector<double>& values) {
  const double* in = values.data();
  for (auto& d : delays_) {
    if (values.empty()) {
      Fill(&d);
      continue;
    }
    std::copy(in, in + d.ring.size(), d.ring.begin());
    in += d.ring.size();
    d.head = 0;
  }
}

std::vector<sgal::BodyState> BulletScene::BodyStates() const {
  std::vector<sgal::BodyState> states;
  ReadBodyStates(&states);
  return states;
}

void BulletScene::ReadBodyStates(std::vector<sgal::BodyState>* out) const {
  // through Bullet's own quaternion of each body (not the matrices the step reads), so that a
  // state read here and restored (an edit, a rewind) gives back the same poses to 1e-12 m
  std::vector<sgal::BodyState>& states = *out;
  states.resize(bodies_.size());
  for (size_t i = 0; i < bodies_.size(); ++i) {
    const btTransform& t = bodies_[i].rigid->getCenterOfMassTransform();
    const btQuaternion q = t.getRotation();
    const Eigen::Quaterniond com_rotation(q.w(), q.x(), q.y(), q.z());
    sgal::Pose& pose = states[i].pose;
    states[i].angular_velocity = spins_[i];
    if (bodies_[i].com_is_body_frame) {
      // the general case's values without its products (they multiply by the identity and add
      // zeros: only the sign of a zero component can differ)
      pose.orientation = com_rotation.normalized();
      pose.position = coms_[i];
      states[i].linear_velocity = velocities_[i];
      continue;
    }
    // body frame = com frame * inverse(com in body)
    pose.orientation = (com_rotation * bodies_[i].body_in_com_rotation).normalized();
    pose.position = coms_[i] - pose.orientation * bodies_[i].com_in_body.translation();
    states[i].linear_velocity = velocities_[i] + spins_[i].cross(pose.position - coms_[i]);
  }
}

std::vector<sgal::TendonState> BulletScene::TendonStates() const {
  std::vector<sgal::TendonState> states(tendons_.size());
  for (size_t i = 0; i < tendons_.size(); ++i) {
    const TendonData& t = tendons_[i];
    for (const auto& p : t.geometry.points) states[i].points.push_back(p.position);
    states[i].length = t.geometry.length;
    states[i].speed = t.end_speed;
    states[i].tension = t.tension;
    states[i].contacts = t.contacts;
  }
  return states;
}

void BulletScene::SetCommand(const std::string& actuator, double value) {
  if (!std::isfinite(value))
    throw std::invalid_argument("command for '" + actuator + "' is not finite");
  const auto found = actuator_index_.find(actuator);
  if (found == actuator_index_.end()) throw std::out_of_range("no actuator '" + actuator + "'");
  actuators_[found->second].model->SetCommand(value);
}

void BulletScene::BuildParameters() {
  auto add = [&](sgal::ParameterInfo info, std::function<double()> get,
                 std::function<void(double)> set = nullptr) {
    info.writable = static_cast<bool>(set);
    parameter_index_[info.id] = static_cast<int>(parameters_.size());
    parameters_.push_back({std::move(info), std::move(get), std::move(set)});
  };
  // the GUI's pull (a command: recordings and plots show it); body -1 when none
  add({"pull.body", "", false, false}, [this] { return pull_ ? double(pull_->body) : -1.0; });
  for (int k = 0; k < 3; ++k) {
    const std::string axis(1, "xyz"[k]);
    add({"pull.force_" + axis, "N", false, false}, [this, k] { return pull_force_[k]; });
    add({"pull.target_" + axis, "m", false, false},
        [this, k] { return pull_ ? pull_->target[k] : 0.0; });
  }
  add({"simulation.time_step", "s", true, true}, [this] { return dt_; }, [this](double v) {
    if (!(v > 0 && v <= 0.1)) throw std::invalid_argument("simulation.time_step: must be in (0, 0.1] s");
    // the delayed channels' lags in the new steps, checked before anything changes
    const std::vector<int> lags =
        DelaySteps(v, "simulation.time_step = " + Text(v) + " s refused: ");
    // A time step that an actuator cannot take within its bound of sub-steps per step is refused
    // (rather than clamping its sub-steps, which would change its accuracy silently): every
    // actuator is told first, and all keep the old one if one refuses.
    for (size_t k = 0; k < actuators_.size(); ++k) {
      try {
        actuators_[k].model->SetTimeStep(v);
      } catch (const std::invalid_argument& e) {
        for (size_t j = 0; j < k; ++j) actuators_[j].model->SetTimeStep(dt_);
        throw std::invalid_argument("simulation.time_step = " + Text(v) + " s refused: " +
                                    e.what());
      }
    }
    // the speed extrapolation assumes equal steps: after a change it starts again
    if (v != dt_)
      for (auto& t : tendons_) t.previous_length = -1;
    dt_ = v;
    scene_.settings.time_step = v;
    // a channel whose lag in steps changed starts again from its present value
    for (size_t k = 0; k < delays_.size(); ++k)
      if (delays_[k].steps != lags[k]) {
        delays_[k].steps = lags[k];
        Fill(&delays_[k]);
      }
  });
  add({"simulation.time", "s", false, false}, [this] { return time_; });
  for (size_t i = 0; i < bodies_.size(); ++i) {
    if (scene_.bodies[i].type != sgal::BodyType::kDynamic) continue;
    const std::string id = scene_.bodies[i].name + ".mass";
    btRigidBody* rb = bodies_[i].rigid.get();
    add({id, "kg", true, true}, [rb] { return 1.0 / rb->getInvMass(); }, [this, i, rb, id](double value) {
      if (!(value > 0)) throw std::invalid_argument(id + ": mass must be positive");
      const double ratio = value / (1.0 / rb->getInvMass());
      const btVector3 inv = rb->getInvInertiaDiagLocal();
      const btVector3 inertia(inv.x() > 0 ? 1 / inv.x() : 0, inv.y() > 0 ? 1 / inv.y() : 0,
                              inv.z() > 0 ? 1 / inv.z() : 0);
      rb->setMassProps(static_cast<btScalar>(value), inertia * static_cast<btScalar>(ratio));
      rb->updateInertiaTensor();
      scene_.bodies[i].inertia.mass = value;
      scene_.bodies[i].inertia.tensor *= ratio;
    });
  }
  for (size_t k = 0; k < joints_.size(); ++k) {
    JointData* j = &joints_[k];
    const bool hinge = j->desc->kind == sgal::ConstraintKind::kHinge;
    if (!hinge && j->desc->kind != sgal::ConstraintKind::kSlider) continue;
    const std::string& n = j->desc->name;
    sgal::JointSpring* spring = &scene_.constraints[k].springs[0];
    add({n + ".position", hinge ? "rad" : "m", false, false}, [j] { return JointPosition(*j); });
    add({n + ".velocity", hinge ? "rad/s" : "m/s", false, false}, [j] { return j->velocity; });
    add({n + ".spring_stiffness", hinge ? "N m/rad" : "N/m", true, true},
        [spring] { return spring->stiffness; }, [spring, n](double v) {
          if (v < 0) throw std::invalid_argument(n + ".spring_stiffness: must not be negative");
          spring->stiffness = v;
        });
    add({n + ".spring_damping", hinge ? "N m s/rad" : "N s/m", true, true},
        [spring] { return spring->damping; }, [spring, n](double v) {
          if (v < 0) throw std::invalid_argument(n + ".spring_damping: must not be negative");
          spring->damping = v;
        });
    double* friction = &scene_.constraints[k].friction[0];
    add(
        {n + ".friction", hinge ? "N m" : "N", true, true}, [friction] { return *friction; },
        [friction, n, hinge](double v) {
          if (v < 0)
            throw std::invalid_argument(n + ".friction: must not be negative (" +
                                        (hinge ? "N m" : "N") + ")");
          *friction = v;
        });
  }
  for (auto& t : tendons_) {
    // tendons often share their actuator's name: their states live under `.tendon.`
    const std::string n = t.desc->name + ".tendon.";
    TendonData* td = &t;
    add({n + "length", "m", false, false}, [td] { return td->geometry.length; });
    add({n + "speed", "m/s", false, false}, [td] { return td->end_speed; });
    add({n + "tension", "N", false, false}, [td] { return td->tension; });
    add({n + "contacts", "", false, false}, [td] { return static_cast<double>(td->contacts); });
  }
  for (size_t k = 0; k < actuators_.size(); ++k) {
    actuators::TendonActuator* model = actuators_[k].model.get();
    const std::string n = actuators_[k].desc->name + ".";
    add({n + "command", model->command_unit(), true, false}, [model] { return model->command(); },
        [model](double v) { model->SetCommand(v); });
    for (const auto& q : model->Quantities()) {
      const std::string field = q.name;
      std::function<void(double)> set;
      if (q.writable)
        set = [this, model, field, k, is_static = q.is_static](double v) {
          model->Set(field, v);
          // a tuned model parameter goes into the description, so that a saved scene keeps it
          if (is_static) scene_.actuators[k].parameters[field] = v;
        };
      // read through the kind's reader: no name lookup per read
      add({n + field, q.unit, q.writable, q.is_static}, model->Reader(field), std::move(set));
    }
  }
}

std::vector<int> BulletScene::DelaySteps(double dt, const std::string& refused) const {
  std::vector<int> steps;
  double held = 0;  // values in all rings
  for (const auto& d : scene_.measurement_delays) {
    const std::string what =
        refused + "measurement delay of '" + d.id + "': delay " + Text(d.delay) + " s ";
    if (!std::isfinite(d.delay) || d.delay < 0)
      throw std::invalid_argument(what + "must be finite and not negative");
    const double lag = std::round(d.delay / dt);
    if (!(lag <= kMaxDelaySteps))  // also a NaN
      throw std::invalid_argument(what + "is " + Text(lag) + " steps of " + Text(dt) +
                                  " s, more than the " + std::to_string(kMaxDelaySteps) +
                                  " steps a channel may lag");
    steps.push_back(static_cast<int>(lag));
    held += lag + 1;
  }
  if (held > kMaxDelayedValues)
    throw std::invalid_argument(refused + "the measurement delays hold " + Text(held) +
                                " values at a time step of " + Text(dt) + " s, more than the " +
                                Text(kMaxDelayedValues) + " all channels may hold together");
  return steps;
}

void BulletScene::BuildMeasurementDelays() {
  const std::string refused = (scene_.source.empty() ? scene_.name : scene_.source) + ": ";
  const std::vector<int> steps = DelaySteps(dt_, refused);
  delays_.resize(scene_.measurement_delays.size());
  std::unordered_map<std::string, int> delayed;  // id -> its index in parameters_
  for (size_t k = 0; k < delays_.size(); ++k) {
    const std::string& id = scene_.measurement_delays[k].id;
    auto refuse = [&](const std::string& why) {
      throw std::invalid_argument(refused + "measurement delay of '" + id + "': " + why);
    };
    const int index = ParameterIndex(id);
    if (index < 0)
      refuse(std::string("the scene has no such parameter (a state as Parameters() lists it, ") +
             "e.g. an actuator's current, a joint's position, a tendon's tendon.tension)");
    ParameterEntry& p = parameters_[index];
    if (p.info.is_static)
      refuse("a model parameter, not a measurement: only a state that changes every step lags");
    if (id == "simulation.time") refuse("the simulation's clock is not a measurement");
    if (p.info.writable)
      refuse("it is written from outside (a command or a setting), not measured: a delayed read "
             "would not show what was written");
    if (!delayed.emplace(id, index).second) refuse("the channel is delayed twice");
    DelayLine& line = delays_[k];
    line.truth = p.get;
    line.stage = OwnerOf(id);
    line.steps = steps[k];
    Fill(&line);
    // what the controller, the DAQ and recordings read: the oldest value of the ring
    p.get = [&line] { return line.ring[line.head]; };
  }
  // the true values under ids of their own, after every other parameter
  for (size_t k = 0; k < delays_.size(); ++k) {
    const std::string& id = scene_.measurement_delays[k].id;
    sgal::ParameterInfo info = parameters_[delayed.at(id)].info;
    info.id = id + ".undelayed";
    info.writable = false;
    parameter_index_[info.id] = static_cast<int>(parameters_.size());
    parameters_.push_back({std::move(info), delays_[k].truth, nullptr});
  }
}

StepStage BulletScene::OwnerOf(const std::string& id) const {
  auto under = [&id](const std::string& prefix) {
    return id.compare(0, prefix.size(), prefix) == 0;
  };
  // a tendon's states first: a tendon often shares its actuator's name
  for (size_t t = 0; t < tendons_.size(); ++t)
    if (under(tendons_[t].desc->name + ".tendon."))
      return {StepStage::kTendon, static_cast<int>(t)};
  for (size_t k = 0; k < actuators_.size(); ++k)
    if (under(actuators_[k].desc->name + ".")) return {StepStage::kActuator, static_cast<int>(k)};
  return {StepStage::kWorld, -1};
}

void BulletScene::PushMeasurements() {
  for (auto& d : delays_) {
    stage_ = d.stage;  // a reading that fails names its owner
    d.ring[d.head] = d.truth();
    d.head = d.head + 1 == d.ring.size() ? 0 : d.head + 1;
  }
}

std::vector<sgal::ParameterInfo> BulletScene::Parameters() const {
  std::vector<sgal::ParameterInfo> out;
  out.reserve(parameters_.size());
  for (const auto& p : parameters_) out.push_back(p.info);
  return out;
}

int BulletScene::ParameterIndex(const std::string& id) const {
  const auto it = parameter_index_.find(id);
  return it == parameter_index_.end() ? -1 : it->second;
}

double BulletScene::GetParameter(int index) const {
  if (index < 0 || index >= static_cast<int>(parameters_.size()))
    throw std::out_of_range("no parameter with index " + std::to_string(index));
  return parameters_[index].get();
}

double BulletScene::GetParameter(const std::string& id) const {
  const int index = ParameterIndex(id);
  if (index < 0) throw std::out_of_range("no parameter '" + id + "'");
  return parameters_[index].get();
}

void BulletScene::SetParameter(const std::string& id, double value) {
  world_->ForgetAhead();  // a friction, a mass, the time step: the next step searches itself
  const int index = ParameterIndex(id);
  if (index < 0) throw std::out_of_range("no parameter '" + id + "'");
  if (!std::isfinite(value)) throw std::invalid_argument(id + ": value is not finite");
  const ParameterEntry& p = parameters_[index];
  if (!p.set) throw std::invalid_argument(id + " is read-only (a state of the simulation)");
  p.set(value);
  LayOutActuatorStates();  // a command delay or a time step may change an actuator's state size
}

void BulletScene::LayOutActuatorStates() {
  size_t offset = 0;
  for (auto& a : actuators_) {
    a.state_offset = offset;
    offset += a.model->StateSize();
  }
  actuator_states_.resize(offset);
}

}  // namespace

int ThreadCount(int threads) {
  constexpr int kMaxThreads = 8;
  if (threads < 0)
    throw std::invalid_argument("physics threads must be >= 0 (0: automatic), got " +
                                std::to_string(threads));
  if (threads == 0) {
    cpu_set_t set;
    CPU_ZERO(&set);
    threads = sched_getaffinity(0, sizeof(set), &set) == 0 ? CPU_COUNT(&set) : 1;
  }
  return std::clamp(threads, 1, kMaxThreads);
}

long SpinTurns(double seconds, double seconds_per_turn) {
  if (!(seconds_per_turn > 0) || !std::isfinite(seconds_per_turn)) return kFallbackSpinTurns;
  const double turns = std::round(seconds / seconds_per_turn);
  if (!(turns >= kMinSpinTurns)) return kMinSpinTurns;
  if (!(turns <= kMaxSpinTurns)) return kMaxSpinTurns;
  return static_cast<long>(turns);
}

double MeasureSpinTurn() {
  constexpr int kTurns = 2000;
  std::atomic<int> word{0};  // what a waiting thread reads at every turn, never set here
  double fastest = std::numeric_limits<double>::infinity();
  const auto start = std::chrono::steady_clock::now();
  for (int run = 0; run < 64; ++run) {
    const auto begin = std::chrono::steady_clock::now();
    for (int i = 0; i < kTurns; ++i) {
      if (word.load(std::memory_order_relaxed) != 0) break;
#if defined(__x86_64__) || defined(__i386__)
      __builtin_ia32_pause();  // libgomp's cpu_relax on x86
#else
      // libgomp's generic cpu_relax; the word's address given to it, so that it is read anew
      __asm__ volatile("" : : "r"(&word) : "memory");
#endif
    }
    const auto end = std::chrono::steady_clock::now();
    fastest = std::min(fastest, std::chrono::duration<double>(end - begin).count() / kTurns);
    // a pause takes a number of the core's cycles: runs over 2 ms, so that a core still raising
    // its clock as the program starts is timed at its speed too (the fastest run counts)
    if (run >= 7 && end - start >= std::chrono::milliseconds(2)) break;
  }
  return fastest;
}

void BoundThreadSpin(char** argv) {
  if (std::getenv("GOMP_SPINCOUNT") != nullptr || std::getenv("OMP_WAIT_POLICY") != nullptr) return;
  const std::string count = std::to_string(SpinTurns(kThreadSpinTime, MeasureSpinTurn()));
  if (setenv("GOMP_SPINCOUNT", count.c_str(), 1) != 0) return;
  // the program's own path, so that the process keeps its name (comm: `ps`, `pgrep NAME`);
  // /proc/self/exe itself if that path is gone (the program rebuilt since it started)
  std::array<char, 4096> path{};
  const ssize_t length = readlink("/proc/self/exe", path.data(), path.size() - 1);
  if (length > 0) execv(path.data(), argv);
  execv("/proc/self/exe", argv);
  const int error = errno;  // execv returns only on failure
  unsetenv("GOMP_SPINCOUNT");  // libgomp has its default: what the Model's log line then says
  std::fprintf(stderr,
               "%s: could not start again with GOMP_SPINCOUNT=%s (%s): threads waiting for work "
               "spin as long as libgomp's default\n",
               argv[0], count.c_str(), std::strerror(error));
}

std::unique_ptr<sgal::PhysicsScene> MakeScene(const sgal::Scene& scene, Options options) {
  return std::make_unique<BulletScene>(scene, options);
}

std::string EngineId() {
  const int v = btGetVersion();
  return "bullet " + std::to_string(v / 100) + "." + std::to_string(v % 100) +
         (sizeof(btScalar) == sizeof(double) ? " double" : " float") + ", state layout 3";
}

}  // namespace caliper::physics_bullet
