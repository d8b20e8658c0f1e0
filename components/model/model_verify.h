#pragma once
// `caliper-model --verify FILE`: re-simulates a recording in this Model process, with no session
// (caliper-ctl replay --verify starts it), and compares every keyframe and channel sample with the
// recorded bits. Progress on stderr, the verdict on stdout.

#include <string>

namespace caliper::model {

/// Exit status: 0 identical, 1 divergent or not replayable (the reason on stderr).
int VerifyMain(const std::string& path);

}  // namespace caliper::model
