// Fuzz target: the Graph Plotter's layout files (ParseLayout). Properties: it either returns a
// layout within the documented bounds or throws LayoutError naming the origin; an accepted layout
// is written by FormatLayout to text that ParseLayout reads to the same layout.
#include <cstdint>
#include <string>

#include "fuzz_input.h"
#include "plot_layout.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using caliper::fuzz::Check;
  namespace plotter = caliper::plotter;
  const std::string text(reinterpret_cast<const char*>(data), size);
  plotter::Layout layout;
  try {
    layout = plotter::ParseLayout(text, "fuzz.layout");
  } catch (const plotter::LayoutError& e) {
    const std::string message = e.what();
    Check(message.rfind("fuzz.layout", 0) == 0,
          "a LayoutError that does not name the origin: " + message.substr(0, 300));
    return 0;
  }
  Check(layout.window_s >= plotter::kMinWindow && layout.window_s <= plotter::kMaxWindow,
        "window_s out of bounds");
  Check(layout.buffer_samples >= plotter::kMinBuffer && layout.buffer_samples <= plotter::kMaxBuffer,
        "buffer_samples out of bounds");
  Check(layout.every_n_steps >= 1 && layout.every_n_steps <= plotter::kMaxEveryNSteps,
        "every_n_steps out of bounds");
  Check(plotter::BufferBudgetProblem(layout.buffer_samples, layout.Keys().size()).empty(),
        "an accepted layout over the buffer budget");
  const std::string formatted = plotter::FormatLayout(layout);
  plotter::Layout back;
  try {
    back = plotter::ParseLayout(formatted, "formatted");
  } catch (const plotter::LayoutError& e) {
    Check(false, std::string("ParseLayout refuses what FormatLayout wrote: ") + e.what());
  }
  Check(back == layout, "the layout changed in a FormatLayout/ParseLayout round trip:\n" + formatted);
  return 0;
}
