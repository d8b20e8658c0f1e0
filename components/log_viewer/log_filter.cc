#include "log_filter.h"

#include <algorithm>
#include <cctype>

namespace caliper::log_viewer {

namespace {

constexpr uint8_t Bit(int kind) { return static_cast<uint8_t>(1u << kind); }
constexpr uint8_t kAllKinds = (1u << kFilterKinds) - 1;

std::string Lower(const std::string& text) {
  std::string out = text;
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

}  // namespace

bool FilterSettings::operator==(const FilterSettings& o) const {
  return max_priority == o.max_priority && excluded_categories == o.excluded_categories &&
         excluded_components == o.excluded_components && text == o.text && regex == o.regex &&
         case_sensitive == o.case_sensitive && from_time_us == o.from_time_us &&
         to_time_us == o.to_time_us && mode == o.mode;
}

bool UnderCategory(const std::string& category, const std::string& prefix) {
  if (category.size() < prefix.size() || category.compare(0, prefix.size(), prefix) != 0)
    return false;
  return category.size() == prefix.size() || category[prefix.size()] == '.';
}

const char* ModeName(FilterMode mode) {
  return mode == FilterMode::kHighlight ? "highlight" : "hide";
}

bool ParseMode(const std::string& text, FilterMode* mode) {
  if (text == "hide") {
    *mode = FilterMode::kHide;
  } else if (text == "highlight") {
    *mode = FilterMode::kHighlight;
  } else {
    return false;
  }
  return true;
}

void LogView::Compile() {
  const FilterSettings& s = settings_;
  error_.clear();
  active_mask_ = 0;
  if (s.max_priority < logging::kDebug) active_mask_ |= Bit(kPriority);
  if (!s.excluded_categories.empty()) active_mask_ |= Bit(kCategory);
  if (!s.excluded_components.empty()) active_mask_ |= Bit(kComponent);
  regex_.reset();
  needle_.clear();
  if (!s.text.empty()) {
    if (s.regex) {
      try {
        regex_ = std::make_shared<const logging::MessagePattern>(s.text, s.case_sensitive);
        active_mask_ |= Bit(kText);
      } catch (const logging::PatternError& e) {
        error_ = e.what();
      }
    } else {
      needle_ = s.case_sensitive ? s.text : Lower(s.text);
      active_mask_ |= Bit(kText);
    }
  }
  if (s.from_time_us != 0 || s.to_time_us != 0) active_mask_ |= Bit(kTime);
  hide_mask_ = 0;
  highlight_mask_ = 0;
  for (int k = 0; k < kFilterKinds; ++k) {
    if ((active_mask_ & Bit(k)) == 0) continue;
    (s.mode[k] == FilterMode::kHide ? hide_mask_ : highlight_mask_) |= Bit(k);
  }
}

void LogView::ExtendNameCaches(const RecordStore& store, bool all_categories, bool all_components) {
  if (all_categories) category_ok_.clear();
  if (all_components) component_ok_.clear();
  const auto& categories = store.categories();
  for (size_t id = category_ok_.size(); id < categories.size(); ++id) {
    bool ok = true;
    for (const auto& prefix : settings_.excluded_categories)
      if (UnderCategory(categories[id], prefix)) ok = false;
    category_ok_.push_back(ok);
  }
  const auto& components = store.components();
  for (size_t id = component_ok_.size(); id < components.size(); ++id)
    component_ok_.push_back(settings_.excluded_components.count(components[id]) == 0);
}

bool LogView::ContainsNeedle(const std::string& message) const {
  if (needle_.empty()) return true;
  if (settings_.case_sensitive) return message.find(needle_) != std::string::npos;
  const auto it =
      std::search(message.begin(), message.end(), needle_.begin(), needle_.end(),
                  [](char a, char b) { return std::tolower(static_cast<unsigned char>(a)) == b; });
  return it != message.end();
}

bool LogView::TextMatches(const std::string& message) const {
  return regex_ ? regex_->Search(message) : ContainsNeedle(message);
}

void LogView::Classify(const RecordStore& store, size_t begin, size_t end, uint8_t kinds) {
  // an inactive filter matches everything; only the kinds asked for are recomputed
  const uint8_t active = kinds & active_mask_;
  const uint8_t fixed = kinds & ~active_mask_;
  const FilterSettings& s = settings_;
  for (size_t i = begin; i < end; ++i) {
    const Entry& e = store.entry(i);
    uint8_t b = static_cast<uint8_t>((bits_[i] & ~kinds) | fixed);
    if (active & Bit(kPriority) && e.priority <= s.max_priority) b |= Bit(kPriority);
    if (active & Bit(kCategory) && category_ok_[e.category]) b |= Bit(kCategory);
    if (active & Bit(kComponent) && component_ok_[e.component]) b |= Bit(kComponent);
    if (active & Bit(kTime) && (s.from_time_us == 0 || e.time_us >= s.from_time_us) &&
        (s.to_time_us == 0 || e.time_us <= s.to_time_us))
      b |= Bit(kTime);
    if (active & Bit(kText) && TextMatches(e.message)) b |= Bit(kText);
    bits_[i] = b;
  }
}

void LogView::AddRow(uint32_t index) {
  rows_.push_back(index);
  if (highlight_mask_ != 0 && (bits_[index] & highlight_mask_) == highlight_mask_)
    ++highlighted_count_;
}

void LogView::Rebuild() {
  rows_.clear();
  highlighted_count_ = 0;
  for (size_t i = 0; i < bits_.size(); ++i)
    if ((bits_[i] & hide_mask_) == hide_mask_) AddRow(static_cast<uint32_t>(i));
}

void LogView::Apply(const FilterSettings& settings, const RecordStore& store) {
  if (bits_.size() > store.size()) Reset();
  const FilterSettings old = settings_;
  settings_ = settings;
  uint8_t dirty = 0;
  if (settings.max_priority != old.max_priority) dirty |= Bit(kPriority);
  if (settings.excluded_categories != old.excluded_categories) dirty |= Bit(kCategory);
  if (settings.excluded_components != old.excluded_components) dirty |= Bit(kComponent);
  if (settings.text != old.text || settings.regex != old.regex ||
      settings.case_sensitive != old.case_sensitive)
    dirty |= Bit(kText);
  if (settings.from_time_us != old.from_time_us || settings.to_time_us != old.to_time_us)
    dirty |= Bit(kTime);
  Compile();
  ExtendNameCaches(store, dirty & Bit(kCategory), dirty & Bit(kComponent));
  Classify(store, 0, bits_.size(), dirty);
  const size_t classified = bits_.size();
  bits_.resize(store.size(), 0);
  Classify(store, classified, store.size(), kAllKinds);
  Rebuild();
}

size_t LogView::Update(const RecordStore& store) {
  if (bits_.size() > store.size()) Reset();
  const size_t begin = bits_.size();
  const size_t end = store.size();
  if (begin == end) return 0;
  ExtendNameCaches(store, false, false);
  bits_.resize(end, 0);
  Classify(store, begin, end, kAllKinds);
  const size_t before = rows_.size();
  for (size_t i = begin; i < end; ++i)
    if ((bits_[i] & hide_mask_) == hide_mask_) AddRow(static_cast<uint32_t>(i));
  return rows_.size() - before;
}

void LogView::Reset() {
  bits_.clear();
  category_ok_.clear();
  component_ok_.clear();
  rows_.clear();
  highlighted_count_ = 0;
}

}  // namespace caliper::log_viewer
