#pragma once
// caliper-ctl's verbs for cluster runs through the per-host managers (caliper-manager):
// managers, create, destroy. Managers are found in the naming service by their type; one that
// does not answer is reported, never fatal.

#include <map>
#include <ostream>
#include <string>
#include <vector>

#include "client.h"

namespace caliper::ctl {

/// A Model a manager started on request.
struct SpawnedModel {
  std::string instance;      // model3
  std::string path;          // host.host_cxt/model3.rtc
  std::string manager_path;  // host.host_cxt/manager0.rtc
};

/// Starts up to `count` Models through every manager that answers, the freest first, each
/// printed on `report`; returns those that started, with why the others did not in `*why`.
/// Failure when no manager answers.
std::vector<SpawnedModel> SpawnModels(Client& client, unsigned long count, std::ostream& report,
                                      std::string* why);

/// Stops Models started by SpawnModels; what fails is said on `report`, never thrown.
void StopModels(Client& client, const std::vector<SpawnedModel>& models, std::ostream& report);

/// Adds the cluster verbs (group "cluster") to `verbs`.
void AddClusterVerbs(std::map<std::string, Verb>* verbs);

}  // namespace caliper::ctl
