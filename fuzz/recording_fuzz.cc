// Fuzz target: session recordings (libs/recording) read from outside: `caliper-ctl replay
// --info/--verify/--csv FILE` and a Model's open_replay take files anyone may hand them.
// The input is written as a file and read as a recording; the first input bytes also serve as a
// keyframe's state (DecodeState). Properties: Reader either opens or throws RecordingError naming
// the file; every read of an opened file (header, keyframes, events, samples, log, the CSV)
// returns or throws RecordingError; DecodeState returns or throws RecordingError, and what it
// returns encodes back to the same bytes.
#include <cstdint>
#include <string>

#include "caliper/recording/recording.h"
#include "fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using caliper::fuzz::Check;
  namespace R = caliper::recording;
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  try {
    const caliper::sgal::DynamicState state = R::DecodeState(bytes);
    Check(R::EncodeState(state) == bytes, "a decoded state encodes back to other bytes");
  } catch (const R::RecordingError&) {
  }
  const caliper::fuzz::InputFile input(data, size, "input.caliper");
  try {
    R::Reader reader(input.path());
    const uint64_t last = reader.last_step();
    (void)reader.duration();
    reader.scenes();
    for (uint64_t step : reader.keyframe_steps()) reader.KeyframeAtOrBefore(step);
    reader.Events(0, last + 1);
    reader.Samples(0, last + 1);
    reader.Log();
    reader.ExportCsv(input.path() + ".csv");
  } catch (const R::RecordingError& e) {
    Check(std::string(e.what()).find(input.path()) != std::string::npos,
          std::string("the error does not name the file: ") + e.what());
  }
  return 0;
}
