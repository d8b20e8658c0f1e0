#pragma once
// The Model's DAQ channels as the plotter knows them, and how a subscription lays out the values
// of its ids within a sample: which layout a subscription has, whether a fresh channel listing
// still agrees with it (a reloaded scene can give an id another shape or unit, which moves the
// values of the ids after it), and which channels can be plotted as picked. No Qt, no CORBA.

#include <cstddef>
#include <string>
#include <vector>

namespace caliper::plotter {

/// One of the Model's DAQ channels.
struct ChannelEntry {
  std::string id;     ///< e.g. pendulum_tendon.pivot.position
  std::string unit;   ///< SI unit, "" for none
  unsigned rows = 1;  ///< shape of the value
  unsigned cols = 1;
  bool is_static = false;  ///< a parameter (true) or a state changing every step (false)
  std::string description;
};

/// Where one subscribed id's values sit within a sample of the subscription's batches.
struct SubscribedId {
  std::string id;
  std::string unit;
  unsigned rows = 1;
  unsigned cols = 1;
  size_t offset = 0;  ///< index of its first value within a sample
};

/// Elements of a vector or matrix offered as curves of their own; larger values are not.
constexpr size_t kMaxElementCurves = 64;

/// The layout of a subscription to `ids` (in this order, each id's values after the previous
/// one's) with the shapes and units `channels` give them. Throws std::invalid_argument for an id
/// that `channels` lacks.
std::vector<SubscribedId> LayoutOf(const std::vector<std::string>& ids,
                                   const std::vector<ChannelEntry>& channels);

/// Values in one sample of `layout`.
size_t Width(const std::vector<SubscribedId>& layout);

/// "" when every id of `layout` that `channels` lists has the layout's shape and unit there;
/// otherwise what changed, e.g. "pendulum_tendon.pivot.position is 3x1 [m] now, was 1x1 [rad]".
/// Ids that `channels` lacks are no change: the Model keeps their place and shape (as NaN).
std::string LayoutChange(const std::vector<SubscribedId>& layout,
                         const std::vector<ChannelEntry>& channels);

/// Why picking `channel` as a whole adds no curve: "" for a scalar and for a vector or matrix of
/// at most kMaxElementCurves elements (each becomes a curve), else the reason to show.
std::string WhyNotPlottable(const ChannelEntry& channel);

}  // namespace caliper::plotter
