#pragma once
// The Log Viewer's filters and the rows they leave: five filters (priority, category, component,
// text, time), each either hiding the records it does not match or highlighting those it does.
// LogView turns a RecordStore and the settings into a vector of row indices, recomputing only
// the filters whose settings changed and classifying appended records incrementally. No Qt, no
// CORBA.

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "caliper/logging/message_pattern.h"
#include "caliper/logging/record.h"
#include "record_store.h"

namespace caliper::log_viewer {

/// What a filter does with the records it matches.
enum class FilterMode {
  kHide,       ///< records that do not match are not shown
  kHighlight,  ///< every record is shown; those that match are highlighted
};

/// The filters, in the order of FilterSettings::mode.
enum FilterKind : int { kPriority = 0, kCategory, kComponent, kText, kTime, kFilterKinds };

/// Every filter's parameters. A filter whose parameters select everything is off (it neither
/// hides nor highlights).
struct FilterSettings {
  /// Least severe priority that matches (log4cpp numbers, lower is more severe);
  /// logging::kDebug or above: off.
  int max_priority = logging::kDebug;
  /// Unchecked nodes of the category tree: `caliper.model` also excludes `caliper.model.rtc`.
  /// Empty: off.
  std::set<std::string> excluded_categories;
  /// Unchecked component instances. Empty: off.
  std::set<std::string> excluded_components;
  /// Searched in the message; empty: off.
  std::string text;
  /// `text` is a regular expression in RE2 syntax (no backreferences or lookaround, at most
  /// logging::kMaxPatternBytes), searched in the whole message like plain text.
  bool regex = false;
  bool case_sensitive = false;
  int64_t from_time_us = 0;  ///< earliest matching time [us since 1970 UTC]; 0: unbounded
  int64_t to_time_us = 0;    ///< latest matching time [us since 1970 UTC]; 0: unbounded
  /// Per filter (index FilterKind): hide what does not match, or highlight what matches.
  std::array<FilterMode, kFilterKinds> mode{};

  bool operator==(const FilterSettings& o) const;
  bool operator!=(const FilterSettings& o) const { return !(*this == o); }
};

/// True when `category` is `prefix` or lies below it in the dotted hierarchy
/// (`caliper.model.rtc` is under `caliper.model`, `caliper.modeller` is not).
bool UnderCategory(const std::string& category, const std::string& prefix);

/// `FilterMode` as `hide` or `highlight`, and back (false for anything else).
const char* ModeName(FilterMode mode);
bool ParseMode(const std::string& text, FilterMode* mode);

/// The rows a RecordStore shows under a FilterSettings: indices into the store, oldest first,
/// and which of them are highlighted (they match every active highlighting filter).
class LogView {
 public:
  /// Takes new settings and recomputes, over every record already classified, only the filters
  /// whose parameters changed; then rebuilds rows(). A bad or too long regular expression turns
  /// the text filter off and sets error() (logging::MessagePattern's reason).
  void Apply(const FilterSettings& settings, const RecordStore& store);

  /// Classifies the records appended to `store` since the last call and appends those shown to
  /// rows(); returns how many rows were added.
  size_t Update(const RecordStore& store);

  /// Forgets every classification (after the store was cleared or trimmed); rows() is empty until
  /// the next Update or Apply.
  void Reset();

  /// Store indices of the shown rows, oldest first.
  const std::vector<uint32_t>& rows() const { return rows_; }
  /// Whether shown row `row` (an index into rows()) is highlighted.
  bool highlighted(size_t row) const {
    return highlight_mask_ != 0 && (bits_[rows_[row]] & highlight_mask_) == highlight_mask_;
  }
  /// How many shown rows are highlighted.
  size_t highlighted_count() const { return highlighted_count_; }
  /// Whether a filter is on (its parameters do not select everything and it has no error).
  bool active(FilterKind kind) const { return (active_mask_ >> kind) & 1u; }
  /// Why the text filter is off although it has text (a bad regular expression), or "".
  const std::string& error() const { return error_; }
  const FilterSettings& settings() const { return settings_; }

 private:
  void Compile();
  void Classify(const RecordStore& store, size_t begin, size_t end, uint8_t kinds);
  void ExtendNameCaches(const RecordStore& store, bool all_categories, bool all_components);
  bool TextMatches(const std::string& message) const;
  bool ContainsNeedle(const std::string& message) const;
  void Rebuild();
  void AddRow(uint32_t index);

  FilterSettings settings_;
  std::string error_;
  uint8_t active_mask_ = 0;
  uint8_t hide_mask_ = 0;       ///< active filters that hide
  uint8_t highlight_mask_ = 0;  ///< active filters that highlight
  /// The compiled text when it is a regular expression (RE2: linear in the message's length).
  std::shared_ptr<const logging::MessagePattern> regex_;
  /// The plain text searched (lower-cased for a case-insensitive search).
  std::string needle_;

  std::vector<uint8_t> bits_;         ///< per classified record: bit k set when filter k matches it
  std::vector<uint8_t> category_ok_;  ///< per category id: the category filter matches
  std::vector<uint8_t> component_ok_;  ///< per component id
  std::vector<uint32_t> rows_;
  size_t highlighted_count_ = 0;
};

}  // namespace caliper::log_viewer
