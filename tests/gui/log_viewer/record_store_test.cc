// The viewer's record store: order, duplicates by (source, seq), interned names (each record
// given back whole), trimming.
#include "record_store.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "known_session.h"
#include "session_file.h"

namespace caliper::log_viewer {
namespace {

logging::Record Make(const std::string& source, uint64_t seq, const std::string& category = "c.a",
                     const std::string& component = "x0") {
  logging::Record r;
  r.source = source;
  r.seq = seq;
  r.category = category;
  r.component = component;
  r.message = source + "#" + std::to_string(seq);
  return r;
}

TEST(RecordStoreTest, KeepsOrderAndInternsCategoriesAndComponents) {
  RecordStore store;
  EXPECT_EQ(store.Append(ReadSessionFile(testing::KnownSessionPath()).records),
            static_cast<size_t>(testing::kKnownRecords));
  EXPECT_EQ(store.size(), static_cast<size_t>(testing::kKnownRecords));
  EXPECT_EQ(store.components(),
            (std::vector<std::string>{"logger0", "model0", "pd0", "renderer0"}));
  EXPECT_EQ(store.categories().size(), 9u);
  for (size_t i = 0; i < store.size(); ++i) {
    EXPECT_EQ(store.categories()[store.entry(i).category], store.record(i).category);
    EXPECT_EQ(store.components()[store.entry(i).component], store.record(i).component);
  }
  EXPECT_EQ(store.record(0).message.rfind("session log /var/log", 0), 0u);
}

TEST(RecordStoreTest, GivesEveryRecordBackWholeWithItsNamesInternedOnce) {
  const auto records = ReadSessionFile(testing::KnownSessionPath()).records;
  RecordStore store;
  store.Append(records);
  ASSERT_EQ(store.size(), records.size());
  for (size_t i = 0; i < store.size(); ++i)
    EXPECT_EQ(store.record(i), records[i]) << i;
  // hosts and sources are kept once each, like categories and components
  EXPECT_EQ(store.hosts(), (std::vector<std::string>{"desk", "node1"}));
  EXPECT_EQ(store.sources().size(), 4u);
  for (size_t i = 0; i < store.size(); ++i) {
    EXPECT_EQ(store.host(store.entry(i)), records[i].host);
    EXPECT_EQ(store.source(store.entry(i)), records[i].source);
  }
}

TEST(RecordStoreTest, DropsRecordsSeenBeforeBySourceAndSeq) {
  RecordStore store;
  const auto records = ReadSessionFile(testing::KnownSessionPath()).records;
  store.Append(records);
  EXPECT_EQ(store.Append(records), 0u) << "the same file twice";
  // a live batch overlapping the file: only the newer seqs of each source go in
  EXPECT_EQ(store.Append({Make("a", 1), Make("a", 2), Make("b", 1), Make("a", 2), Make("a", 1),
                          Make("a", 3)}),
            4u);
  EXPECT_EQ(store.size(), static_cast<size_t>(testing::kKnownRecords) + 4);
  EXPECT_EQ(store.record(store.size() - 1).message, "a#3");
  // seq 0 means "not numbered": never a duplicate
  EXPECT_EQ(store.Append({Make("z", 0), Make("z", 0)}), 2u);
}

TEST(RecordStoreTest, DropOldestKeepsNamesAndClearForgetsEverything) {
  RecordStore store;
  store.Append({Make("a", 1, "c.a", "x0"), Make("a", 2, "c.b", "x1"), Make("a", 3, "c.a", "x0")});
  store.DropOldest(2);
  ASSERT_EQ(store.size(), 1u);
  EXPECT_EQ(store.record(0).message, "a#3");
  EXPECT_EQ(store.categories().size(), 2u);
  EXPECT_EQ(store.Append({Make("a", 2)}), 0u) << "still known as delivered";
  store.Clear();
  EXPECT_TRUE(store.empty());
  EXPECT_TRUE(store.categories().empty());
  EXPECT_EQ(store.Append({Make("a", 2)}), 1u);
}

}  // namespace
}  // namespace caliper::log_viewer
