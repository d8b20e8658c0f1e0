#include "caliper/simulation/fault_injection.h"

#include <atomic>
#include <new>
#include <stdexcept>

#include "caliper/core/numbers.h"
#include "caliper/physics_bullet/bullet_scene.h"

namespace caliper::simulation {
namespace {

class FailingScene : public sgal::PhysicsScene {
 public:
  FailingScene(std::unique_ptr<sgal::PhysicsScene> inner, InjectedFault fault)
      : inner_(std::move(inner)), fault_(fault) {}
  void Step() override {
    if (inner_->steps() + 1 == fault_.at_step) {
      using Kind = InjectedFault::Kind;
      switch (fault_.kind) {
        case Kind::kNone: break;
        case Kind::kFault:
          throw sgal::SimulationFault("injected fault: tension is not finite", "injected",
                                      inner_->time());
        case Kind::kBadAlloc: throw std::bad_alloc();
        case Kind::kOutOfRange: throw std::out_of_range("injected fault: index 7 of 3");
        case Kind::kRuntime: throw std::runtime_error("injected fault: solver did not converge");
        case Kind::kUnknownType: throw 42;
      }
    }
    inner_->Step();
  }
  double time() const override { return inner_->time(); }
  uint64_t steps() const override { return inner_->steps(); }
  const sgal::Scene& description() const override { return inner_->description(); }
  std::vector<sgal::BodyState> BodyStates() const override { return inner_->BodyStates(); }
  void ReadBodyStates(std::vector<sgal::BodyState>* out) const override {
    inner_->ReadBodyStates(out);
  }
  std::vector<sgal::TendonState> TendonStates() const override { return inner_->TendonStates(); }
  void SetCommand(const std::string& a, double v) override { inner_->SetCommand(a, v); }
  std::vector<sgal::ParameterInfo> Parameters() const override { return inner_->Parameters(); }
  double GetParameter(const std::string& id) const override { return inner_->GetParameter(id); }
  int ParameterIndex(const std::string& id) const override { return inner_->ParameterIndex(id); }
  double GetParameter(int index) const override { return inner_->GetParameter(index); }
  void SetParameter(const std::string& id, double v) override { inner_->SetParameter(id, v); }
  sgal::DynamicState SaveDynamicState() const override { return inner_->SaveDynamicState(); }
  void RestoreDynamicState(const sgal::DynamicState& s) override { inner_->RestoreDynamicState(s); }
  void SetPull(const sgal::Pull& pull) override { inner_->SetPull(pull); }
  void ClearPull() override { inner_->ClearPull(); }
  void ResetCaches() override { inner_->ResetCaches(); }

 private:
  std::unique_ptr<sgal::PhysicsScene> inner_;
  InjectedFault fault_;
};

}  // namespace

InjectedFault ParseInjectedFault(const std::string& text) {
  InjectedFault fault;
  if (text.empty()) return fault;
  const size_t at = text.find('@');
  if (at == std::string::npos)
    throw std::invalid_argument("inject_fault '" + text + "': expected KIND@STEP");
  const std::string kind = text.substr(0, at);
  using Kind = InjectedFault::Kind;
  if (kind == "simulation_fault") fault.kind = Kind::kFault;
  else if (kind == "bad_alloc") fault.kind = Kind::kBadAlloc;
  else if (kind == "out_of_range") fault.kind = Kind::kOutOfRange;
  else if (kind == "runtime_error") fault.kind = Kind::kRuntime;
  else if (kind == "unknown") fault.kind = Kind::kUnknownType;
  else
    throw std::invalid_argument("inject_fault '" + text + "': unknown kind '" + kind +
                                "' (simulation_fault, bad_alloc, out_of_range, runtime_error, "
                                "unknown)");
  long long step = 0;
  std::string why;
  if (!core::ParseInt(text.substr(at + 1), &step, &why))
    throw std::invalid_argument("inject_fault '" + text + "': STEP: " + why);
  if (step < 1) throw std::invalid_argument("inject_fault '" + text + "': STEP must be >= 1");
  fault.at_step = static_cast<uint64_t>(step);
  return fault;
}

std::unique_ptr<sgal::PhysicsScene> WithInjectedFault(std::unique_ptr<sgal::PhysicsScene> inner,
                                                      InjectedFault fault) {
  return std::make_unique<FailingScene>(std::move(inner), fault);
}

PhysicsFactory FailFirstScene(InjectedFault fault, physics_bullet::Options options) {
  auto built = std::make_shared<std::atomic<int>>(0);
  return [fault, options, built](const sgal::Scene& scene) {
    const bool first = (*built)++ == 0;
    return WithInjectedFault(physics_bullet::MakeScene(scene, options),
                             first ? fault : InjectedFault{});
  };
}

}  // namespace caliper::simulation
