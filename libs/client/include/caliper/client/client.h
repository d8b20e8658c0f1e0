#pragma once
// caliper::client, the one C++ client library of Caliper: everything a program needs to drive
// the Models of a session or a cluster over CORBA, without Qt. caliper-ctl, caliper-calibrate,
// the Main Window, the Graph Plotter, the Log Viewer, the Scene Renderer's and the PD
// controller's Model lookups, and the Python package are built on it. Link `caliper::client`.
//
//   session.h         Session: the ORB and the naming service (the latest session, or an address;
//                     TLS on a network), components by name
//   errors.h          Failure and its kinds, one per IDL exception (UnknownIdError, ...), and
//                     ConnectionError for a peer that cannot be reached
//   model.h           ModelRef, ConnectModel / FindModel / LookUpModel, Call (the IDL's errors
//                     as the library's), FindModels (only Models, by name, host and glob)
//   scene_transfer.h  the path-or-bytes rule: SendsByContent, LoadScene, ReadScene
//   experiments.h     experiments and recordings to and from the IDL
//   model_pool.h      ModelPool: runs spread over every Model found, lost ones set aside and
//                     probed, late joiners, retries (batch runs, calibration)
//   data_feed.h       DataFeed: a DAQ subscription (lossless or not) delivered to a callback
//   worker.h          Worker: the background thread of a GUI link (jobs, a periodic tick, a
//                     bounded stop)
//
// A minimal program (error handling: every call raises a client::Failure with a message a user
// can read):
//
//   #include "caliper/client/client.h"
//   using namespace caliper;
//   int main() {
//     client::Session session({"", 5.0, "my-controller"});  // $CALIPER_NAMESERVICE or loopback
//     client::ModelRef m = client::ConnectModel(session, "model0");
//     client::Call(m, [&] { m.model->set_command("elbow_flexor", 6.0); });  // [V]
//     client::Call(m, [&] { return m.model->step(1000); });                  // 1 s at 1 ms
//   }
//
// Threads: the library's own threads are known to omniORB; a thread of yours that calls into
// the ORB with a per-thread timeout holds an rtc::OmniThread (libs/rtc/client_orb.h).

#include "caliper/client/data_feed.h"
#include "caliper/client/errors.h"
#include "caliper/client/experiments.h"
#include "caliper/client/model.h"
#include "caliper/client/model_pool.h"
#include "caliper/client/scene_transfer.h"
#include "caliper/client/session.h"
#include "caliper/client/worker.h"
