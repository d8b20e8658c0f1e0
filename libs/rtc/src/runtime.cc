#include "caliper/rtc/runtime.h"

#include <algorithm>
#include <pthread.h>
#include <signal.h>
#include <strings.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <optional>
#include <thread>

#include "caliper/core/arguments.h"
#include "caliper/core/system.h"
#include "caliper/logging/batching_appender.h"
#include "caliper/rtc/client_orb.h"
#include "caliper/logging/log.h"
#include "caliper/rtc/local_sockets.h"
#include "caliper/rtc/log_service_sink.h"
#include "caliper/rtc/naming.h"
#include "caliper/rtc/rtobject_servant.h"
#include "caliper/rtc/transport_security.h"

namespace caliper::rtc {

namespace {

using core::ConfigKey;
using Type = ConfigKey::Type;

std::vector<ConfigKey> CommonKeys(const std::string& type_name) {
  return {
      {"naming.service", Type::kString, "", "naming service address corbaname::HOST:PORT "
       "('' = $CALIPER_NAMESERVICE or corbaname::127.0.0.1:2809)"},
      {"naming.instance", Type::kString, type_name, "instance base name (bound as NAME0, NAME1, ...)"},
      {"naming.update.interval", Type::kDouble, "10", "re-registration period [s]", 0.05, 3600},
      {"corba.endpoint", Type::kString, "giop:unix:",
       "omniORB endpoint to listen on (by default a unix socket in a directory only this user "
       "can enter, $CALIPER_SOCKET_DIR or ${XDG_RUNTIME_DIR:-/tmp}/caliper-UID; --listen ADDR "
       "or $CALIPER_LISTEN "
       "make it giop:ssl:ADDR:, reachable from other hosts over TLS, giop:tcp:ADDR: with "
       "--insecure)"},
      {"corba.loopback_tcp", Type::kBool, "false",
       "a local process also listens on loopback TCP (giop:tcp:127.0.0.1:), for clients of other "
       "ORBs (Tcl Combat) that have no unix transport; every user of this host can then reach "
       "it (also $CALIPER_LOOPBACK_TCP=1, launch/caliper session --loopback-tcp); warns"},
      {"corba.insecure", Type::kBool, "false",
       "network mode without TLS: plain GIOP, no authentication (also --insecure, "
       "$CALIPER_INSECURE=1); warns loudly"},
      {"corba.tls.pki_dir", Type::kString, "",
       "network mode: the directory of launch/caliper certs ('' = $CALIPER_PKI, else "
       "~/.config/caliper/pki): ca.pem, hosts/NAME.pem and .pass, users/NAME.pem and .pass"},
      {"corba.tls.identity", Type::kString, "",
       "network mode: the certificate shown to peers, hosts/NAME, users/NAME or a .pem path ('' = "
       "$CALIPER_TLS_IDENTITY, else hosts/<host name>, else users/$USER)"},
      {"corba.max_message_size", Type::kDouble, "256",
       "largest GIOP message sent or received [MiB] (scenes and recordings travel by content)",
       1, 2047},
      {"corba.call_timeout", Type::kDouble, "5", "timeout of outgoing calls [s]", 0.01, 3600},
      {"exec.kind", Type::kString, "periodic", "execution context kind", 0, 0,
       {"periodic", "external"}},
      {"exec.rate", Type::kDouble, "100", "execution context rate [Hz]", 1e-3, 1e6},
      {"exec.auto_activate", Type::kBool, "false", "activate the component once it is bound"},
      {"log.level", Type::kString, "info", "least severe priority printed on the console", 0, 0,
       {"fatal", "alert", "crit", "error", "warn", "notice", "info", "debug"}},
      {"log.service", Type::kString, "logger0", "instance name of the Logging component"},
      {"log.spool_dir", Type::kString, "~/.cache/caliper/spool",
       "where log records wait while the Logging component is unreachable, in a folder per "
       "session (its naming service's address): they reach that session's log only"},
      {"log.spool_max", Type::kDouble, "64",
       "largest spool file [MiB]; records beyond it are dropped and counted (a warning record "
       "says how many once the spool is delivered)", 0.001, 1e6},
  };
}

std::string ConfigDirectory() {
  const char* env = std::getenv("CALIPER_CONFIG_DIR");
  if (env != nullptr && *env != '\0') return env;
  return std::string(CALIPER_SOURCE_DIR) + "/config";
}

void PrintUsage(const ComponentType& type, const core::Config& config) {
  std::string program = "caliper-" + type.name;  // the programs' names have '-' for '_'
  std::replace(program.begin(), program.end(), '_', '-');
  std::cout << "Usage: " << program << " [options]\n"
            << type.description << "\n\n"
            << "Options:\n"
            << "  -f FILE              read configuration FILE (after " << ConfigDirectory() << "/"
            << type.name << ".conf)\n"
            << "  -o KEY=VALUE         set one configuration key (repeatable, applied last;\n"
            << "                       $CALIPER_LISTEN, $CALIPER_INSECURE and $CALIPER_LOOPBACK_TCP\n"
            << "                       apply after the -f files, before -o)\n"
            << "  --nameservice ADDR   naming service (default $CALIPER_NAMESERVICE, else\n"
            << "                       corbaname::127.0.0.1:2809; the launcher passes its session's)\n"
            << "  --instance NAME      instance base name (bound as NAME0, NAME1, ...)\n"
            << "  --listen ADDR        network mode: listen on ADDR (an address of this host that\n"
            << "                       the others reach) instead of loopback, over TLS with the\n"
            << "                       certificates of launch/caliper certs; also $CALIPER_LISTEN\n"
            << "  --insecure           network mode without TLS (plain, unauthenticated GIOP);\n"
            << "                       also $CALIPER_INSECURE=1 or -o corba.insecure=true\n"
            << "  -h, --help           this text\n"
            << "  -ORB...              passed to omniORB\n\n"
            << "Configuration keys:\n"
            << config.Help() << "\n"
            << "The component binds as <host>.host_cxt/<instance>.rtc in the naming service and\n"
            << "stops cleanly on SIGINT or SIGTERM.\n";
}

/// Waits for SIGINT/SIGTERM/SIGHUP on a thread of its own: no signal handler runs at all.
class SignalWatcher {
 public:
  explicit SignalWatcher(Runtime* runtime) : runtime_(runtime) {
    thread_ = std::thread([this] { Watch(); });
  }
  ~SignalWatcher() {
    done_ = true;
    thread_.join();
  }
  static void BlockSignals() {
    sigset_t set = Set();
    pthread_sigmask(SIG_BLOCK, &set, nullptr);
  }

 private:
  static sigset_t Set() {
    sigset_t set;
    sigemptyset(&set);
    sigaddset(&set, SIGINT);
    sigaddset(&set, SIGTERM);
    sigaddset(&set, SIGHUP);
    return set;
  }
  void Watch() {
    const sigset_t set = Set();
    const timespec timeout = {0, 200 * 1000 * 1000};
    while (!done_) {
      const int sig = sigtimedwait(&set, nullptr, &timeout);
      if (sig > 0) {
        logging::Get("rtc").notice("signal %d: shutting down", sig);
        runtime_->RequestExit();
      }
    }
  }
  Runtime* runtime_;
  std::atomic<bool> done_{false};
  std::thread thread_;
};

}  // namespace

Runtime::Runtime(ComponentType type, core::Config config)
    : type_(std::move(type)), config_(std::move(config)), host_(core::HostName()) {}

std::string Runtime::instance() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return instance_;
}

std::string Runtime::naming_path() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return host_ + ".host_cxt/" + instance_ + ".rtc";
}

void Runtime::RequestExit() {
  std::lock_guard<std::mutex> lock(mutex_);
  exit_requested_ = true;
  exit_cv_.notify_all();
}

CORBA::Object_ptr Runtime::Activate(PortableServer::Servant servant) {
  PortableServer::ObjectId_var id = poa_->activate_object(servant);
  servant->_remove_ref();
  return poa_->id_to_reference(id.in());
}

void Runtime::WaitForExit() {
  const auto interval = std::chrono::duration<double>(config_.GetDouble("naming.update.interval"));
  std::unique_lock<std::mutex> lock(mutex_);
  while (!exit_requested_) {
    if (exit_cv_.wait_for(lock, interval, [&] { return exit_requested_; })) break;
    lock.unlock();
    Rebind();
    lock.lock();
  }
}

namespace {

CosNaming::NamingContext_ptr HostContext(CosNaming::NamingContext_ptr root,
                                         const std::string& host) {
  CosNaming::Name name;
  name.length(1);
  name[0].id = host.c_str();
  name[0].kind = "host_cxt";
  try {
    return root->bind_new_context(name);
  } catch (const CosNaming::NamingContext::AlreadyBound&) {
    CORBA::Object_var obj = root->resolve(name);
    return CosNaming::NamingContext::_narrow(obj);
  }
}

CosNaming::Name Leaf(const std::string& instance) {
  CosNaming::Name name;
  name.length(1);
  name[0].id = instance.c_str();
  name[0].kind = "rtc";
  return name;
}

}  // namespace

void Runtime::BindUnique() {
  CosNaming::NamingContext_var root = ResolveRoot(orb_, naming_address_);
  CosNaming::NamingContext_var host = HostContext(root, host_);
  const std::string base = config_.GetString("naming.instance");
  for (int i = 0;; ++i) {
    const std::string candidate = base + std::to_string(i);
    const CosNaming::Name leaf = Leaf(candidate);
    try {
      host->bind(leaf, self_);
    } catch (const CosNaming::NamingContext::AlreadyBound&) {
      CORBA::Object_var existing = host->resolve(leaf);
      if (!existing->_is_equivalent(self_) && ObjectAlive(existing)) continue;
      host->rebind(leaf, self_);  // a stale binding of a process that died
      logging::Get("rtc").info("took over the stale name %s", candidate.c_str());
    }
    std::lock_guard<std::mutex> lock(mutex_);
    instance_ = candidate;
    bound_ = true;
    break;
  }
  logging::SetInstance(instance());
}

void Runtime::Rebind() {
  std::string failure;
  // a restarted naming service first fails the call on the old connection: try twice
  for (int attempt = 0; attempt < 2; ++attempt) {
    try {
      CosNaming::NamingContext_var root = ResolveRoot(orb_, naming_address_);
      CosNaming::NamingContext_var host = HostContext(root, host_);
      host->rebind(Leaf(instance()), self_);
      if (rebind_warned_) logging::Get("rtc").notice("registered again in %s", naming_address_.c_str());
      rebind_warned_ = false;
      return;
    } catch (const std::exception& e) {
      failure = e.what();
    } catch (const CORBA::Exception& e) {
      failure = Describe(e);
    }
  }
  if (!rebind_warned_)
    logging::Get("rtc").warn("re-registration failed (will retry): %s", failure.c_str());
  rebind_warned_ = true;
}

void Runtime::Unbind() {
  try {
    CosNaming::NamingContext_var root = ResolveRoot(orb_, naming_address_);
    const CosNaming::Name name = ComponentName(host_, instance());
    CORBA::Object_var existing = root->resolve(name);
    if (existing->_is_equivalent(self_)) root->unbind(name);
  } catch (...) {
    // the naming service is gone or the name was taken over: nothing of ours to remove
  }
}

namespace {

// Reads the default configuration file, the environment and the command line into `config`;
// the words for omniORB go to `orb_args`. Returns the exit code when the process ends here
// (--help, or a bad option), nothing when it goes on.
std::optional<int> ReadCommandLine(int argc, char** argv, const ComponentType& type,
                                   const std::string& program, core::Config* config,
                                   std::vector<std::string>* orb_args) {
  try {
    const std::string default_file = ConfigDirectory() + "/" + type.name + ".conf";
    if (access(default_file.c_str(), R_OK) == 0) config->LoadFile(default_file);
    std::vector<std::string> overrides;
    if (const char* listen = std::getenv("CALIPER_LISTEN"); listen != nullptr && *listen != '\0')
      overrides.push_back("corba.endpoint=" + ListenEndpoint(listen));
    if (InsecureFromEnvironment()) overrides.push_back("corba.insecure=true");
    if (const char* tcp = std::getenv("CALIPER_LOOPBACK_TCP");
        tcp != nullptr && (std::string(tcp) == "1" || std::string(tcp) == "true"))
      overrides.push_back("corba.loopback_tcp=true");
    core::ArgumentSpec spec;
    spec.valued = {"-f", "-o", "--nameservice", "--listen", "--instance"};
    spec.flags = {"--insecure"};
    spec.pass = [](const std::string& word) { return word.rfind("-ORB", 0) == 0 ? 2 : 0; };
    const std::vector<std::string> words(argv + 1, argv + argc);
    const core::Arguments args = core::ParseArguments(words, spec);
    if (args.help) {
      PrintUsage(type, *config);
      return 0;
    }
    // a component takes no positional word: the first one comes before where the parser stopped
    const std::string unknown = args.positional.empty() ? args.unknown : args.positional[0];
    if (!unknown.empty())
      throw core::ConfigError("unknown argument '" + unknown + "' (see --help)");
    if (!args.missing_value.empty()) throw core::ConfigError(args.Error());
    for (const auto& [option, value] : args.options) {
      if (option == "-f")
        config->LoadFile(value);
      else if (option == "-o")
        overrides.push_back(value);
      else if (option == "--nameservice")
        overrides.push_back("naming.service=" + value);
      else if (option == "--listen")
        overrides.push_back("corba.endpoint=" + ListenEndpoint(value));
      else if (option == "--insecure")
        overrides.push_back("corba.insecure=true");
      else
        overrides.push_back("naming.instance=" + value);
    }
    for (const size_t i : args.passed) orb_args->push_back(words[i]);
    for (const auto& o : overrides) config->SetAssignment(o, "-o");
  } catch (const core::ConfigError& e) {
    std::cerr << program << ": error: " << e.what() << "\n";
    return 2;
  } catch (const std::invalid_argument& e) {
    std::cerr << program << ": error: --listen / CALIPER_LISTEN: " << e.what() << "\n";
    return 2;
  }
  return std::nullopt;
}

// Loopback, or network mode over TLS (the default) or plain (--insecure), as the configuration
// and the omniORB words say. Throws what ResolveSecurity throws.
TransportSecurity ChooseTransport(const core::Config& config, const std::string& naming_address,
                                  const std::vector<std::string>& orb_args) {
  SecurityRequest request;
  request.endpoint = config.GetString("corba.endpoint");
  request.naming_address = naming_address;
  // endpoints passed through to omniORB (-ORBendPoint giop:tcp::) count as its own
  for (size_t i = 1; i + 1 < orb_args.size(); ++i)
    if (strcasecmp(orb_args[i].c_str(), "-ORBendPoint") == 0 ||
        strcasecmp(orb_args[i].c_str(), "-ORBendPointNoPublish") == 0)
      request.extra_endpoints.push_back(orb_args[i + 1]);
  request.insecure = config.GetBool("corba.insecure");
  request.pki_dir = config.GetString("corba.tls.pki_dir");
  request.identity = config.GetString("corba.tls.identity");
  request.component = true;
  return ResolveSecurity(request);
}

// Says which transport the process uses: loudly when it is insecure.
void ReportTransport(const std::string& program, const TransportSecurity& security,
                     log4cpp::Category& log) {
  if (security.transport == Transport::kInsecure) {
    WarnInsecure(program, security.endpoint);
    log.warn("INSECURE network mode: plain GIOP without TLS on %s, no authentication",
             security.endpoint.c_str());
  } else if (security.transport == Transport::kTls) {
    log.notice("network mode over TLS on %s as %s; peers need a certificate of %s",
               security.endpoint.c_str(), security.key_file.c_str(), security.ca_file.c_str());
  }
}

// The transport (ChooseTransport), said and installed for the process; nothing when it cannot
// be had (the reason logged and printed, the logging shut down).
std::optional<TransportSecurity> SetUpTransport(const std::string& program,
                                                const core::Config& config,
                                                const std::string& naming_address,
                                                const std::vector<std::string>& orb_args,
                                                log4cpp::Category& log) {
  TransportSecurity security;
  try {
    security = ChooseTransport(config, naming_address, orb_args);
    // the socket directory, checked now (a refused one is said and the component stops here)
    if (security.endpoint.rfind("giop:unix:", 0) == 0) LocalSocketDir();
  } catch (const std::exception& e) {
    log.error("%s", e.what());
    std::cerr << program << ": error: " << e.what() << "\n";
    logging::Shutdown();
    return std::nullopt;
  }
  ReportTransport(program, security, log);
  if (config.GetBool("corba.loopback_tcp") && security.transport == Transport::kLoopback) {
    log.warn("also listening on loopback TCP (corba.loopback_tcp): every user of this host can "
             "reach this process");
    std::cerr << program << ": warning: also on loopback TCP (corba.loopback_tcp, for other "
              << "ORBs): every user of this host can reach this process\n";
  }
  InstallProcessSecurity(security);
  return security;
}

// The omniORB options of the transport, the call timeout and the largest message.
void AddOrbOptions(const core::Config& config, const TransportSecurity& security,
                   std::vector<std::string>* orb_args) {
  // no clientConnectTimeOutPeriod: omniORB stretches the deadline of a call that opens a
  // connection to it, so a shorter per-object deadline (the Model's pushes to observers) would
  // not hold; without it a connect is bounded by the call's own deadline
  const int timeout_ms = static_cast<int>(config.GetDouble("corba.call_timeout") * 1000);
  for (const auto& option : SecurityOrbOptions(security)) orb_args->push_back(option);
  // other ORBs (Tcl Combat) have no unix transport: loopback TCP beside the socket, when asked
  if (config.GetBool("corba.loopback_tcp") && security.transport == Transport::kLoopback)
    orb_args->insert(orb_args->end(), {"-ORBendPoint", "giop:tcp:127.0.0.1:"});
  orb_args->insert(orb_args->end(),
                   {"-ORBendPoint", security.endpoint, "-ORBclientCallTimeOutPeriod",
                    std::to_string(timeout_ms), "-ORBgiopMaxMsgSize",
                    std::to_string(static_cast<long>(config.GetDouble("corba.max_message_size") *
                                                     1024 * 1024))});
}

// Sends the log records to the Logging component too (spooled while it is unreachable).
void AddRemoteLogging(const ComponentType& type, const core::Config& config, CORBA::ORB_ptr orb,
                      const std::string& naming_address) {
  logging::AppenderOptions options;
  // a folder per session: what waits there is delivered into its own session's log only
  options.spool_dir =
      SessionSpoolDirectory(core::ExpandHome(config.GetString("log.spool_dir")), naming_address);
  options.spool_name = type.name + "-" + std::to_string(getpid());
  options.max_spool_bytes = static_cast<uint64_t>(config.GetDouble("log.spool_max") * 1024 * 1024);
  logging::AddAppender(new logging::BatchingAppender(
      "log-service",
      std::make_unique<LogServiceSink>(orb, naming_address, config.GetString("log.service")),
      options));
}

}  // namespace

int RunComponent(int argc, char** argv, const ComponentType& type,
                 const ComponentFactory& make_component, const ServantFactory& make_servant) {
  SignalWatcher::BlockSignals();  // before any thread exists, so that all inherit the mask
  const std::string program = "caliper-" + type.name;

  core::Config config(CommonKeys(type.name));
  config.AddKeys(type.config_keys);
  std::vector<std::string> orb_args{argv[0]};
  if (const std::optional<int> done =
          ReadCommandLine(argc, argv, type, program, &config, &orb_args))
    return *done;

  int console_priority = logging::kInfo;
  logging::ParsePriority(config.GetString("log.level"), &console_priority);
  logging::Initialize(type.name, console_priority);
  auto& log = logging::Get("rtc");
  for (const auto& w : config.warnings()) log.warn("%s", w.c_str());

  Runtime runtime(type, config);
  runtime.naming_address_ = NamingAddress(config.GetString("naming.service"));

  // loopback, or network mode over TLS (the default) or plain (--insecure)
  const std::optional<TransportSecurity> security =
      SetUpTransport(program, config, runtime.naming_address_, orb_args, log);
  if (!security) return 2;
  {
    std::lock_guard<std::mutex> lock(runtime.mutex_);
    runtime.instance_ = config.GetString("naming.instance");
  }
  logging::SetInstance(runtime.instance());

  AddOrbOptions(config, *security, &orb_args);
  std::vector<char*> orb_argv;
  for (auto& a : orb_args) orb_argv.push_back(a.data());
  int orb_argc = static_cast<int>(orb_argv.size());

  int exit_code = 0;
  try {
    runtime.orb_ = CORBA::ORB_init(orb_argc, orb_argv.data());
    InstallTransportDiagnostics();
    CORBA::Object_var poa_obj = runtime.orb_->resolve_initial_references("RootPOA");
    runtime.poa_ = PortableServer::POA::_narrow(poa_obj);
    runtime.poa_->the_POAManager()->activate();

    if (type.remote_logging) AddRemoteLogging(type, config, runtime.orb_, runtime.naming_address_);

    runtime.component_ = make_component(runtime);
    runtime.lifecycle_ = std::make_unique<Lifecycle>(runtime.component_.get());
    const bool periodic = config.GetString("exec.kind") == "periodic";
    runtime.context_ = std::make_unique<ExecutionContext>(
        runtime.lifecycle_.get(), periodic ? ContextKind::kPeriodic : ContextKind::kExternal,
        config.GetDouble("exec.rate"));
    runtime.context_ref_ = runtime.Activate(new ExecutionContextServant(runtime));
    runtime.self_ = runtime.Activate(make_servant(runtime, *runtime.component_));

    const ReturnCode init = runtime.lifecycle_->Initialize();
    if (init != ReturnCode::kOk) {
      log.error("initialization failed: %s", runtime.lifecycle_->last_error().c_str());
      exit_code = 1;
    } else {
      runtime.BindUnique();
      log.notice("%s is up as %s in %s (pid %d)", type.name.c_str(), runtime.naming_path().c_str(),
                 runtime.naming_address_.c_str(), static_cast<int>(getpid()));
      runtime.context_->Start();
      if (config.GetBool("exec.auto_activate")) runtime.lifecycle_->Activate();

      SignalWatcher signals(&runtime);
      runtime.WaitForExit();

      log.notice("shutting down");
      if (runtime.lifecycle_->state() == State::kActive) runtime.lifecycle_->Deactivate();
      if (runtime.context_->is_running()) runtime.context_->Stop();
      if (!runtime.lifecycle_->finalized()) runtime.lifecycle_->Finalize();
      runtime.Unbind();
      log.notice("stopped");
    }
  } catch (const Unreachable& e) {
    log.error("%s", e.what());
    exit_code = 1;
  } catch (const CORBA::Exception& e) {
    log.error("CORBA error: %s", Describe(e).c_str());
    exit_code = 1;
  } catch (const std::exception& e) {
    log.error("%s", e.what());
    exit_code = 1;
  }
  logging::Shutdown();  // delivers or spools the last records while the ORB still works
  if (!CORBA::is_nil(runtime.orb_)) {
    try {
      runtime.orb_->shutdown(true);
      runtime.orb_->destroy();
    } catch (const CORBA::Exception&) {
    }
  }
  return exit_code;
}

}  // namespace caliper::rtc
