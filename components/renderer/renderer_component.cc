#include "renderer_component.h"

#include "caliper/client/model.h"

#include "caliper/logging/log.h"
#include "caliper/rtc/naming.h"
#include "observer_servant.h"

namespace caliper::renderer {

namespace M = ::Caliper::Simulation;
namespace S = ::Caliper::Scene;

std::vector<core::ConfigKey> RendererComponent::ConfigKeys() {
  using Type = core::ConfigKey::Type;
  return {
      {"renderer.model", Type::kString, "model0", "instance name of the Model"},
      {"renderer.check_interval", Type::kDouble, "1", "registration check period [s]", 0.05, 3600},
      {"renderer.max_fps", Type::kDouble, "30", "largest frame rate of the view [Hz]", 1, 240},
      {"renderer.width", Type::kInt, "1024", "screenshot width [px]", 16, 8192},
      {"renderer.height", Type::kInt, "768", "screenshot height [px]", 16, 8192},
      {"renderer.show_constraint_axes", Type::kBool, "false",
       "draw the hinge and slider axes of the constraints"},
      {"renderer.write_dir", Type::kString, "",
       "the directory the screenshot operation writes into ('' = $CALIPER_FILES_DIR, the "
       "session's files/ directory when the launcher started the renderer; unset = none: "
       "clients take screenshot_png)"},
  };
}

RendererComponent::RendererComponent(rtc::Runtime& runtime, SceneMailbox& mailbox,
                                     ModelReference& model)
    : runtime_(runtime), mailbox_(mailbox), shared_model_(model) {}

RendererComponent::~RendererComponent() { shared_model_.Set(M::Model::_nil()); }

rtc::ReturnCode RendererComponent::OnInitialize() {
  const auto& c = runtime_.config();
  ViewSettings settings;
  settings.max_fps = c.GetDouble("renderer.max_fps");
  settings.width = static_cast<int>(c.GetInt("renderer.width"));
  settings.height = static_cast<int>(c.GetInt("renderer.height"));
  settings.show_constraint_axes = c.GetBool("renderer.show_constraint_axes");
  mailbox_.SetSettings(settings);
  CORBA::Object_var obj = runtime_.Activate(new ObserverServant(mailbox_));
  observer_ = S::SceneObserver::_narrow(obj);
  return rtc::ReturnCode::kOk;
}

rtc::ReturnCode RendererComponent::OnActivated() {
  next_check_ = {};
  CheckRegistration();
  return rtc::ReturnCode::kOk;
}

rtc::ReturnCode RendererComponent::OnExecute() {
  if (std::chrono::steady_clock::now() >= next_check_) CheckRegistration();
  return rtc::ReturnCode::kOk;
}

rtc::ReturnCode RendererComponent::OnDeactivated() {
  Unregister();
  return rtc::ReturnCode::kOk;
}

void RendererComponent::CheckRegistration() {
  auto& log = logging::Get("renderer");
  const auto& c = runtime_.config();
  next_check_ = std::chrono::steady_clock::now() +
                std::chrono::milliseconds(
                    static_cast<int64_t>(c.GetDouble("renderer.check_interval") * 1000));
  const std::string name = c.GetString("renderer.model");
  M::Model_var found;
  try {
    CosNaming::NamingContext_var root = rtc::ResolveRoot(runtime_.orb(), runtime_.naming_address());
    found = client::FindModel(root, name).model._retn();
  } catch (const CORBA::Exception& e) {
    if (!reported_missing_) log.info("no Model '%s' yet: %s", name.c_str(), rtc::Describe(e).c_str());
    reported_missing_ = true;
  } catch (const std::exception& e) {
    if (!reported_missing_) log.info("no Model '%s' yet: %s", name.c_str(), e.what());
    reported_missing_ = true;
  }
  if (CORBA::is_nil(found)) return;  // not bound (yet), or the naming service is away
  // registering again is cheap and keeps the id while the Model still has us; a Model that
  // dropped us (unreachable too long) or a new Model process gives a new id
  try {
    const bool same_model = !CORBA::is_nil(model_) && model_->_is_equivalent(found);
    if (!CORBA::is_nil(model_) && !same_model)
      log.notice("the Model '%s' was replaced", name.c_str());
    const CORBA::ULongLong id = found->add_observer(observer_);
    if (!same_model || id != observer_id_)
      log.notice("observing the Model '%s' (observer %llu)", name.c_str(),
                 static_cast<unsigned long long>(id));
    observer_id_ = id;
    model_ = found._retn();
    shared_model_.Set(model_.in());
    reported_missing_ = false;
  } catch (const CORBA::Exception& e) {
    if (!CORBA::is_nil(model_) || !reported_missing_)
      log.info("Model '%s' unreachable: %s", name.c_str(), rtc::Describe(e).c_str());
    reported_missing_ = true;
    model_ = M::Model::_nil();
    shared_model_.Set(M::Model::_nil());
  }
}

void RendererComponent::Unregister() {
  if (CORBA::is_nil(model_)) return;
  try {
    model_->remove_observer(observer_id_);
  } catch (const CORBA::Exception&) {
    // the Model is gone: nothing to unregister from
  }
  model_ = M::Model::_nil();
  shared_model_.Set(M::Model::_nil());
}

}  // namespace caliper::renderer
