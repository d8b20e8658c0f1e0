#pragma once
// The Model's conversions between engine-neutral data (sgal, daq, the simulation's statuses) and
// the IDL's types, for the servant and the senders that push to observers and subscribers.

#include <map>
#include <string>
#include <vector>

#include "caliper/daq/registry.h"
#include "caliper/experiment/experiment.h"
#include "caliper/model.hh"
#include "caliper/sgal/scene.h"
#include "caliper/simulation/model_core.h"

namespace caliper::model {

/// The scene description as viewers receive it.
Caliper::Scene::Description* ToIdl(const sgal::Scene& scene);
/// The scene's measurement delays, their ids as the DAQ lists them (after the Model's id-safe
/// name for the scene).
void SensorDelaysToIdl(const sgal::Scene& scene, Caliper::Scene::SensorDelaySeq* out);
Caliper::Scene::Frame ToFrame(const sgal::Pose& p);
sgal::Pose FromFrame(const Caliper::Scene::Frame& f);
/// A shape's geometry; a mesh gets the index it has (or is given) in `meshes`.
Caliper::Scene::ShapeGeometry ToGeometry(const sgal::Geometry& g,
                                         std::map<const sgal::Mesh*, CORBA::Long>* meshes);
Caliper::Scene::TendonStateSeq ToIdl(const std::vector<sgal::TendonState>& tendons);
Caliper::Daq::Value ToIdl(const daq::Reading& v);
Caliper::Daq::ChannelInfoSeq* ToIdl(const std::vector<daq::ChannelInfo>& channels);
std::vector<std::string> FromIdl(const Caliper::Scene::StringSeq& ids);
sgal::PathElement FromIdl(const Caliper::Scene::PathPoint& p);
Caliper::Simulation::EditStatus* ToIdl(const simulation::ModelCore::EditStatus& s);
Caliper::Simulation::RecordStatus* ToIdl(const simulation::ModelCore::RecordStatus& s);
Caliper::Simulation::ReplayStatus* ToIdl(const simulation::ModelCore::ReplayStatus& s);
/// An experiment as run_experiment received it (its scene's bytes stay in `in`).
experiment::Experiment FromIdl(const Caliper::Simulation::Experiment& in);
/// What run_experiment returns: the recording and where the time went.
Caliper::Simulation::Recording* ToIdl(const simulation::RunResult& result);

}  // namespace caliper::model
