#include "channel_layout.h"

#include <algorithm>
#include <stdexcept>

namespace caliper::plotter {

namespace {

// `3x1 [m]`, `1x1 [-]`
std::string ShapeAndUnit(unsigned rows, unsigned cols, const std::string& unit) {
  return std::to_string(rows) + "x" + std::to_string(cols) + " [" + (unit.empty() ? "-" : unit) +
         "]";
}

}  // namespace

std::vector<SubscribedId> LayoutOf(const std::vector<std::string>& ids,
                                   const std::vector<ChannelEntry>& channels) {
  std::vector<SubscribedId> layout;
  layout.reserve(ids.size());
  size_t offset = 0;
  for (const auto& id : ids) {
    const auto c = std::find_if(channels.begin(), channels.end(),
                                [&](const ChannelEntry& e) { return e.id == id; });
    if (c == channels.end()) throw std::invalid_argument("the Model lists no channel " + id);
    layout.push_back(SubscribedId{id, c->unit, c->rows, c->cols, offset});
    offset += static_cast<size_t>(c->rows) * c->cols;
  }
  return layout;
}

size_t Width(const std::vector<SubscribedId>& layout) {
  size_t width = 0;
  for (const SubscribedId& s : layout) width += static_cast<size_t>(s.rows) * s.cols;
  return width;
}

std::string LayoutChange(const std::vector<SubscribedId>& layout,
                         const std::vector<ChannelEntry>& channels) {
  std::string change;
  for (const SubscribedId& s : layout) {
    const auto c = std::find_if(channels.begin(), channels.end(),
                                [&](const ChannelEntry& e) { return e.id == s.id; });
    if (c == channels.end()) continue;
    if (c->rows == s.rows && c->cols == s.cols && c->unit == s.unit) continue;
    if (!change.empty()) change += ", ";
    change += s.id + " is " + ShapeAndUnit(c->rows, c->cols, c->unit) + " now, was " +
              ShapeAndUnit(s.rows, s.cols, s.unit);
  }
  return change;
}

std::string WhyNotPlottable(const ChannelEntry& channel) {
  const size_t n = static_cast<size_t>(channel.rows) * channel.cols;
  const std::string shape = std::to_string(channel.rows) + "x" + std::to_string(channel.cols);
  if (n == 0) return channel.id + " is " + shape + ": it has no values to plot";
  if (n <= kMaxElementCurves) return "";
  return channel.id + " is " + shape + ": " + std::to_string(n) +
         " values are too many to plot one curve each (at most " +
         std::to_string(kMaxElementCurves) + ")";
}

}  // namespace caliper::plotter
