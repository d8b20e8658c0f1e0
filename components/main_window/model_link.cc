#include "model_link.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <utility>
#include <vector>

#include "caliper/core/confined_path.h"
#include "caliper/model.hh"
#include "caliper/rtc.hh"
#include "caliper/rtc/client_orb.h"
#include "caliper/rtc/idl_names.h"
#include "caliper/rtc/naming.h"
#include "caliper/urdf/model_file.h"

namespace caliper::main_window {

namespace M = ::Caliper::Simulation;
namespace D = ::Caliper::Daq;
namespace S = ::Caliper::Scene;
namespace RTC = ::Caliper::RTC;
using Clock = std::chrono::steady_clock;

/// The worker's CORBA state; touched by the worker thread only.
struct ModelLink::Impl {
  CORBA::ORB_var orb;
  M::Model_var model;
  std::string scene;              // the scene the channel list belongs to
  bool channels_listed = false;
  Clock::time_point last_lookup{};
  Clock::time_point last_listing{};
  CosNaming::NamingContext_var root;  // nil until resolved; dropped on failure

  CosNaming::NamingContext_ptr Root(const std::string& nameservice) {
    if (CORBA::is_nil(root)) root = rtc::ResolveRoot(orb, rtc::NamingAddress(nameservice));
    return root.in();
  }
};

ModelLink::ModelLink(Options options)
    : impl_(std::make_unique<Impl>()), options_(std::move(options)) {
  impl_->orb = rtc::ClientOrb();
  snapshot_.connection_message = "no Model: looking for " + options_.instance + " ...";
  worker_ = std::thread([this] { Run(); });
}

ModelLink::~ModelLink() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  worker_.join();
}

Snapshot ModelLink::snapshot() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return snapshot_;
}

void ModelLink::Queue(std::string what, std::function<void(Impl&)> call, bool needs_model) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    queue_.push_back(Command{std::move(what), std::move(call), needs_model});
  }
  wake_.notify_all();
}

void ModelLink::LoadScene(const std::string& path) {
  const int long_ms = options_.long_call_timeout_ms;
  Queue("load " + path, [this, path, long_ms](Impl& i) {
    omniORB::setClientThreadCallTimeout(static_cast<CORBA::ULong>(long_ms));
    // the Model reads only below its search path: other files go by content
    M::FileAccess_var files = i.model->file_access();
    std::vector<std::string> dirs;
    for (CORBA::ULong k = 0; k < files->read_dirs.length(); ++k)
      dirs.push_back(files->read_dirs[k].in());
    const core::ConfinedPaths confined(dirs, "", "", true);
    const auto kRead = core::ConfinedPaths::Access::kRead;
    // a URDF goes by path only when its meshes lie there too (the Model refuses it otherwise)
    bool by_path = confined.Allows(path, kRead);
    if (by_path) {
      try {
        for (const auto& file : model_file::FilesRead(path))
          by_path &= confined.Allows(file, kRead);
      } catch (const collada::ImportError&) {
        // not XML: the Model says so, naming the file
      }
    }
    if (by_path) {
      i.model->load_scene(path.c_str());
    } else {
      // by content a Model takes COLLADA: a URDF is imported here and sent converted (NAME.dae)
      std::vector<std::string> warnings;
      const model_file::Content content = model_file::ContentToSend(path, &warnings);
      if (!warnings.empty()) {
        // the Model imports the converted COLLADA without a word: the URDF's warnings are said
        // here, in the status bar and on the terminal
        std::string notice = content.file_name + " (converted from " + path + "): " +
                             std::to_string(warnings.size()) + " import warning" +
                             (warnings.size() == 1 ? "" : "s") + ": " + warnings.front();
        for (const auto& w : warnings) std::fprintf(stderr, "caliper-main: warning: %s\n", w.c_str());
        std::lock_guard<std::mutex> lock(mutex_);
        snapshot_.last_notice = std::move(notice);
        ++snapshot_.notice_serial;
      }
      const std::string& bytes = content.bytes;
      if (bytes.size() > static_cast<size_t>(rtc::kMaxMessageBytes) - (1u << 20))
        throw std::runtime_error(path + " is larger than one CORBA message carries");
      M::Octets data(static_cast<CORBA::ULong>(bytes.size()));
      data.length(static_cast<CORBA::ULong>(bytes.size()));
      std::copy(bytes.begin(), bytes.end(), reinterpret_cast<char*>(data.get_buffer()));
      i.model->load_scene_data(content.file_name.c_str(), data);
    }
    i.channels_listed = false;
  });
}
void ModelLink::Start() { Queue("start", [](Impl& i) { i.model->start(); }); }
void ModelLink::Pause() { Queue("pause", [](Impl& i) { i.model->pause(); }); }
void ModelLink::Stop() { Queue("stop", [](Impl& i) { i.model->stop(); }); }
void ModelLink::Reset() { Queue("reset", [](Impl& i) { i.model->reset(); }); }
void ModelLink::Step(unsigned n) {
  const int long_ms = options_.long_call_timeout_ms;
  Queue("step " + std::to_string(n), [n, long_ms](Impl& i) {
    omniORB::setClientThreadCallTimeout(static_cast<CORBA::ULong>(long_ms));
    i.model->step(n);
  });
}
void ModelLink::SetTimeStep(double seconds) {
  Queue("set the time step", [seconds](Impl& i) { i.model->set_time_step(seconds); });
}
void ModelLink::SetRealTimeFactor(double factor) {
  Queue("set the real-time factor", [factor](Impl& i) { i.model->set_real_time_factor(factor); });
}
void ModelLink::Set(const std::string& id, double value) {
  Queue("set " + id, [id, value](Impl& i) {
    D::Value v;
    v.rows = 1;
    v.cols = 1;
    v.data.length(1);
    v.data[0] = value;
    i.model->set(id.c_str(), v);
  });
}

void ModelLink::ComponentAction(const std::string& instance, const std::string& verb) {
  const std::string ns = options_.nameservice;
  Queue(verb + " " + instance, [instance, verb, ns](Impl& i) {
    RTC::LightweightRTObject_var comp =
        RTC::LightweightRTObject::_narrow(rtc::FindComponent(i.Root(ns), instance).object);
    if (CORBA::is_nil(comp)) throw std::runtime_error(instance + " is not a component");
    RTC::ReturnCode rc;
    if (verb == "exit") {
      rc = comp->exit();
    } else {
      RTC::ExecutionContextList_var ecs = comp->get_owned_contexts();
      if (ecs->length() == 0) throw std::runtime_error(instance + " owns no execution context");
      RTC::ExecutionContext_ptr ec = ecs[0];
      rc = verb == "activate"     ? ec->activate_component(comp)
           : verb == "deactivate" ? ec->deactivate_component(comp)
           : verb == "reset"      ? ec->reset_component(comp)
                                  : throw std::runtime_error("unknown action " + verb);
    }
    if (rc != RTC::RTC_OK) {
      std::string msg = rtc::Name(rc);
      CORBA::String_var why = comp->get_last_error();
      if (std::string(why.in()).size() > 0) msg += "; reason: " + std::string(why.in());
      throw std::runtime_error(msg);
    }
  }, false);
}

// Lists the naming service's components with their states; on the worker thread only.
void ModelLink::ListComponents() {
  Impl& i = *impl_;
  std::vector<ComponentInfo> list;
  bool reachable = false;
  try {
    const auto entries = rtc::ListComponents(i.Root(options_.nameservice));
    reachable = true;
    for (const auto& e : entries) {
      ComponentInfo info{e.instance, e.path, "UNREACHABLE"};
      try {
        RTC::LightweightRTObject_var comp = RTC::LightweightRTObject::_narrow(e.object);
        if (!CORBA::is_nil(comp)) {
          RTC::ExecutionContextList_var ecs = comp->get_owned_contexts();
          info.state = ecs->length() == 0 ? "?" : rtc::Name(ecs[0]->get_component_state(comp));
        }
      } catch (const CORBA::Exception&) {
      }
      list.push_back(std::move(info));
    }
  } catch (const CORBA::Exception&) {
    i.root = CosNaming::NamingContext::_nil();
  } catch (const std::exception&) {
    i.root = CosNaming::NamingContext::_nil();
  }
  std::lock_guard<std::mutex> lock(mutex_);
  snapshot_.naming_reachable = reachable;
  snapshot_.components = std::move(list);
  ++snapshot_.components_version;
}

void ModelLink::Watch(std::vector<std::string> ids) {
  std::lock_guard<std::mutex> lock(mutex_);
  watched_ = std::move(ids);
}

void ModelLink::Run() {
  const rtc::OmniThread omni;  // per-thread call timeouts need an omni_thread
  Impl& i = *impl_;
  const auto short_ms = static_cast<CORBA::ULong>(options_.call_timeout_ms);
  omniORB::setClientConnectTimeout(short_ms);
  const auto period = std::chrono::milliseconds(options_.poll_period_ms);
  auto next_poll = Clock::now();

  // drops the Model after a system exception: it is looked up again
  auto lost = [&](const std::string& why) {
    i.model = M::Model::_nil();
    i.channels_listed = false;
    std::lock_guard<std::mutex> lock(mutex_);
    snapshot_.connected = false;
    snapshot_.connection_message = "no Model reachable: " + why;
  };

  for (;;) {
    std::deque<Command> commands;
    std::vector<std::string> watched;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait_until(lock, next_poll, [&] { return stopping_ || !queue_.empty(); });
      if (stopping_) break;
      commands.swap(queue_);
      watched = watched_;
    }

    bool relist_components = false;
    for (auto& [what, call, needs_model] : commands) {
      std::string error;
      if (!needs_model) {
        relist_components = true;
        try {
          omniORB::setClientThreadCallTimeout(short_ms);
          call(i);
        } catch (const CORBA::Exception& e) {
          error = what + ": " + rtc::Describe(e);
        } catch (const std::exception& e) {
          error = what + ": " + e.what();
        }
      } else if (CORBA::is_nil(i.model)) {
        error = what + ": no Model reachable";
      } else {
        try {
          omniORB::setClientThreadCallTimeout(short_ms);
          call(i);
        } catch (const D::UnknownId& e) {
          error = what + ": " + e.reason.in();
        } catch (const D::InvalidParameter& e) {
          error = what + ": " + e.reason.in();
        } catch (const M::NotAvailable& e) {
          error = what + ": " + e.reason.in();
        } catch (const D::NotAvailable& e) {
          error = what + ": " + e.reason.in();
        } catch (const M::LoadFailed& e) {
          error = what + ": " + e.reason.in();
        } catch (const CORBA::SystemException& e) {
          error = what + ": " + rtc::Describe(e);
          lost(rtc::Describe(e));
        } catch (const CORBA::Exception& e) {
          error = what + ": " + rtc::Describe(e);
        }
      }
      std::lock_guard<std::mutex> lock(mutex_);
      ++snapshot_.commands_done;
      if (!error.empty()) {
        snapshot_.last_error = error;
        ++snapshot_.error_serial;
      }
    }

    omniORB::setClientThreadCallTimeout(short_ms);
    if (relist_components || Clock::now() - i.last_listing >=
                                 std::chrono::milliseconds(options_.components_period_ms)) {
      i.last_listing = Clock::now();
      ListComponents();
    }

    if (Clock::now() < next_poll) continue;
    next_poll = Clock::now() + period;

    // look the Model up (not more often than the reconnect period)
    if (CORBA::is_nil(i.model)) {
      if (Clock::now() - i.last_lookup < std::chrono::milliseconds(options_.reconnect_period_ms))
        continue;
      i.last_lookup = Clock::now();
      try {
        CosNaming::NamingContext_var root =
            rtc::ResolveRoot(i.orb, rtc::NamingAddress(options_.nameservice));
        M::Model_var model =
            M::Model::_narrow(rtc::FindComponent(root, options_.instance).object);
        if (CORBA::is_nil(model)) throw std::runtime_error(options_.instance + " is not a Model");
        i.model = model;
      } catch (const CORBA::Exception& e) {
        lost(rtc::Describe(e));
        continue;
      } catch (const std::exception& e) {
        lost(e.what());
        continue;
      }
    }

    try {
      M::SimulationStatus_var s = i.model->status();
      ModelStatus status;
      status.state = rtc::Name(s->state);
      status.scene = s->scene.in();
      status.sim_time = s->sim_time;
      status.steps = s->steps;
      status.time_step = s->time_step;
      status.real_time_factor = s->real_time_factor;
      status.achieved_real_time_factor = s->achieved_real_time_factor;
      status.last_error = s->last_error.in();

      std::vector<Channel> channels;
      const bool relist = !i.channels_listed || status.scene != i.scene;
      if (relist) {
        D::ChannelInfoSeq_var infos = i.model->list("*");
        for (CORBA::ULong k = 0; k < infos->length(); ++k) {
          const D::ChannelInfo& c = infos[k];
          channels.push_back(Channel{c.id.in(), c.unit.in(), c.rows, c.cols, bool(c.writable),
                                     bool(c.is_static), c.description.in()});
        }
        i.channels_listed = true;
        i.scene = status.scene;
      }

      std::map<std::string, double> values;
      if (!watched.empty() && !relist) {
        S::StringSeq ids;
        ids.length(static_cast<CORBA::ULong>(watched.size()));
        for (CORBA::ULong k = 0; k < ids.length(); ++k) ids[k] = watched[k].c_str();
        try {
          D::ValueSeq_var got = i.model->get(ids);
          for (CORBA::ULong k = 0; k < got->length() && k < ids.length(); ++k)
            if (got[k].data.length() == 1) values[watched[k]] = got[k].data[0];
        } catch (const D::UnknownId&) {
          i.channels_listed = false;  // the scene changed under us: list again
        }
      }

      std::lock_guard<std::mutex> lock(mutex_);
      snapshot_.connected = true;
      snapshot_.connection_message.clear();
      snapshot_.status = status;
      if (relist) {
        snapshot_.channels = std::move(channels);
        ++snapshot_.channels_version;
        snapshot_.values.clear();
      }
      for (auto& [id, v] : values) snapshot_.values[id] = v;
    } catch (const CORBA::SystemException& e) {
      lost(rtc::Describe(e));
    } catch (const CORBA::Exception& e) {
      lost(rtc::Describe(e));
    }
  }
  i.model = M::Model::_nil();
  i.root = CosNaming::NamingContext::_nil();
}

}  // namespace caliper::main_window
