// The DAQ registry: registration, glob patterns, shapes, handles, and the errors of a bad write
// with their messages.
#include "caliper/daq/registry.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>
#include <memory>

namespace caliper::daq {
namespace {

/// Expects `f` to throw E whose message contains `part`.
template <typename E, typename F>
void ExpectThrowsWith(F f, const std::string& part) {
  try {
    f();
    ADD_FAILURE() << "no exception, expected one containing '" << part << "'";
  } catch (const E& e) {
    EXPECT_NE(std::string(e.what()).find(part), std::string::npos)
        << "message '" << e.what() << "' lacks '" << part << "'";
  }
}

ChannelInfo Info(const std::string& id, const std::string& unit, Shape shape = Shape::Scalar()) {
  ChannelInfo info;
  info.id = id;
  info.unit = unit;
  info.shape = shape;
  info.description = "test channel";
  return info;
}

/// A registry with an arm's motors (writable command, read-only current), a vector, a matrix.
struct Fixture : ::testing::Test {
  void SetUp() override {
    for (const char* m : {"shoulder", "elbow", "wrist"}) {
      const std::string name = m;
      registry.Add(Info("arm." + name + ".current", "A"),
                   [this, name](double* out) { out[0] = currents[name]; });
      registry.Add(
          Info("arm." + name + ".command", "V"),
          [this, name](double* out) { out[0] = commands[name]; },
          [this, name](const double* v) { commands[name] = v[0]; });
    }
    registry.Add(Info("arm.hand.position", "m", Shape::Vector(3)), [this](double* out) {
      for (int i = 0; i < 3; ++i) out[i] = position[i];
    });
    registry.Add(
        Info("arm.hand.rotation", "", Shape::Matrix(3, 3)),
        [this](double* out) {
          for (int i = 0; i < 9; ++i) out[i] = rotation[i];
        },
        [this](const double* v) {
          for (int i = 0; i < 9; ++i) rotation[i] = v[i];
        });
  }

  Registry registry;
  std::map<std::string, double> currents{{"shoulder", 1.5}, {"elbow", -0.5}, {"wrist", 0.25}};
  std::map<std::string, double> commands;
  double position[3] = {0.1, 0.2, 0.3};
  double rotation[9] = {1, 2, 3, 4, 5, 6, 7, 8, 9};
};

TEST(GlobMatch, MatchesStarsAndQuestionMarks) {
  EXPECT_TRUE(GlobMatch("*", ""));
  EXPECT_TRUE(GlobMatch("*", "arm.elbow.current"));
  EXPECT_TRUE(GlobMatch("arm.*.current", "arm.elbow.current"));
  EXPECT_TRUE(GlobMatch("arm.*.current", "arm.elbow.motor.current"));  // '*' crosses dots
  EXPECT_FALSE(GlobMatch("arm.*.current", "arm.elbow.command"));
  EXPECT_TRUE(GlobMatch("arm.?lbow.*", "arm.elbow.current"));
  EXPECT_FALSE(GlobMatch("arm.?bow.*", "arm.elbow.current"));
  EXPECT_TRUE(GlobMatch("*.current", "x.current"));
  EXPECT_FALSE(GlobMatch("*.current", "x.current2"));
  EXPECT_TRUE(GlobMatch("a*b*c", "aXXbYYbZc"));
  EXPECT_FALSE(GlobMatch("arm", "arm.x"));
  EXPECT_TRUE(GlobMatch("arm.x", "arm.x"));
  // no special leading dot or slash (fnmatch without FNM_PERIOD, FNM_PATHNAME)
  EXPECT_TRUE(GlobMatch("*", ".hidden"));
  EXPECT_TRUE(GlobMatch("?arm", ".arm"));
  EXPECT_TRUE(GlobMatch("arm*", "arm/x.y"));
  EXPECT_TRUE(GlobMatch("arm.?", "arm./"));
  EXPECT_FALSE(GlobMatch("?", ""));
}

TEST(GlobMatch, MatchesSetsAndEscapesAsFnmatchDoes) {
  EXPECT_TRUE(GlobMatch("arm.[ew]*.current", "arm.elbow.current"));
  EXPECT_TRUE(GlobMatch("arm.[ew]*.current", "arm.wrist.current"));
  EXPECT_FALSE(GlobMatch("arm.[ew]*.current", "arm.shoulder.current"));
  EXPECT_TRUE(GlobMatch("arm.[!ew]*", "arm.shoulder.current"));
  EXPECT_TRUE(GlobMatch("q[0-9]", "q7"));
  EXPECT_TRUE(GlobMatch("a\\*b", "a*b"));
  EXPECT_FALSE(GlobMatch("a\\*b", "aXb"));
}

TEST_F(Fixture, ListsChannelsMatchingAPatternSortedById) {
  const auto currents_listed = registry.List("arm.*.current");
  ASSERT_EQ(currents_listed.size(), 3u);
  EXPECT_EQ(currents_listed[0].id, "arm.elbow.current");
  EXPECT_EQ(currents_listed[1].id, "arm.shoulder.current");
  EXPECT_EQ(currents_listed[2].id, "arm.wrist.current");
  EXPECT_EQ(currents_listed[0].unit, "A");
  EXPECT_FALSE(currents_listed[0].writable);
  EXPECT_EQ(registry.List().size(), 8u);
  EXPECT_EQ(registry.List("arm.hand.*").size(), 2u);
  EXPECT_TRUE(registry.List("leg.*").empty());

  const auto commands_listed = registry.List("arm.?????.command");
  ASSERT_EQ(commands_listed.size(), 2u);  // elbow, wrist
  EXPECT_TRUE(commands_listed[0].writable);
  EXPECT_EQ(commands_listed[0].unit, "V");
}

TEST_F(Fixture, ReportsShapesAndSamplesValuesWithThem) {
  EXPECT_EQ(registry.Info("arm.hand.position").shape, Shape::Vector(3));
  EXPECT_EQ(registry.Info("arm.hand.rotation").shape.ToString(), "3x3");
  EXPECT_EQ(registry.Info("arm.hand.rotation").description, "test channel");

  const auto readings =
      registry.Sample({"arm.elbow.current", "arm.hand.position", "arm.hand.rotation"});
  ASSERT_EQ(readings.size(), 3u);
  EXPECT_EQ(readings[0].id, "arm.elbow.current");
  EXPECT_EQ(readings[0].shape, Shape::Scalar());
  EXPECT_EQ(readings[0].values, std::vector<double>{-0.5});
  EXPECT_EQ(readings[1].shape, Shape::Vector(3));
  EXPECT_EQ(readings[1].values, (std::vector<double>{0.1, 0.2, 0.3}));
  EXPECT_EQ(readings[2].shape, Shape::Matrix(3, 3));
  EXPECT_EQ(readings[2].values, (std::vector<double>{1, 2, 3, 4, 5, 6, 7, 8, 9}));
  EXPECT_EQ(registry.Get("arm.wrist.current"), std::vector<double>{0.25});
}

// SampleInto, what a controller's `get` reads every cycle: the same shapes and values as Sample
// in flat buffers, which it overwrites; an unknown id is refused before anything is read, and the
// id it names is the one given (not the last one resolved in the same thread)
TEST_F(Fixture, SamplesIntoFlatBuffersAsSampleDoes) {
  const char* ids[] = {"arm.hand.rotation", "arm.elbow.current", "arm.hand.position",
                       "arm.elbow.current"};
  std::vector<Shape> shapes = {Shape::Vector(7)};
  std::vector<double> values(40, -1.0);
  registry.SampleInto(ids, 4, &shapes, &values);
  EXPECT_EQ(shapes, (std::vector<Shape>{Shape::Matrix(3, 3), Shape::Scalar(), Shape::Vector(3),
                                        Shape::Scalar()}));
  EXPECT_EQ(values, (std::vector<double>{1, 2, 3, 4, 5, 6, 7, 8, 9, -0.5, 0.1, 0.2, 0.3, -0.5}));
  std::vector<double> flat;
  for (const Reading& r :
       registry.Sample({"arm.hand.rotation", "arm.elbow.current", "arm.hand.position"}))
    flat.insert(flat.end(), r.values.begin(), r.values.end());
  EXPECT_EQ(flat, std::vector<double>(values.begin(), values.end() - 1));
  // again with fewer: the buffers shrink to them
  currents["elbow"] = 2.5;
  registry.SampleInto(ids + 1, 1, &shapes, &values);
  EXPECT_EQ(shapes, std::vector<Shape>{Shape::Scalar()});
  EXPECT_EQ(values, std::vector<double>{2.5});
  int reads = 0;
  registry.Add(Info("arm.counted", "-"), [&reads](double* out) { out[0] = ++reads; });
  const char* bad[] = {"arm.counted", "arm.knee.current", "arm.elbow.current"};
  ExpectThrowsWith<UnknownId>([&] { registry.SampleInto(bad, 3, &shapes, &values); },
                              "unknown id 'arm.knee.current'");
  EXPECT_EQ(reads, 0) << "a channel was read before the unknown id was refused";
  registry.SampleInto(bad, 1, &shapes, &values);
  EXPECT_EQ(values, std::vector<double>{1});
}

TEST_F(Fixture, SetsWritableChannels) {
  registry.Set("arm.elbow.command", {12.0});
  EXPECT_EQ(commands["elbow"], 12.0);
  EXPECT_EQ(registry.Get("arm.elbow.command"), std::vector<double>{12.0});
  registry.Set("arm.hand.rotation", {1, 0, 0, 0, 1, 0, 0, 0, 1});
  EXPECT_EQ(rotation[4], 1.0);
  EXPECT_EQ(rotation[1], 0.0);
}

TEST_F(Fixture, RejectsUnknownIdsNamingThem) {
  ExpectThrowsWith<UnknownId>([&] { registry.Get("arm.knee.current"); },
                              "unknown id 'arm.knee.current'");
  ExpectThrowsWith<UnknownId>([&] { registry.Resolve("arm.knee.current"); }, "arm.knee.current");
  ExpectThrowsWith<UnknownId>([&] { registry.Set("arm.knee.command", {1.0}); }, "arm.knee.command");
  try {
    registry.Sample({"arm.elbow.current", "nope"});
    FAIL();
  } catch (const UnknownId& e) {
    EXPECT_EQ(e.id(), "nope");
  }
}

TEST_F(Fixture, RejectsAWrongNumberOfValuesForTheShape) {
  ExpectThrowsWith<InvalidValue>(
      [&] {
        registry.Set("arm.hand.rotation", {1, 0, 0});
      },
      "arm.hand.rotation: expected 9 values (shape 3x3), got 3");
  ExpectThrowsWith<InvalidValue>([&] { registry.Set("arm.elbow.command", {}); },
                                 "expected 1 value (shape 1x1), got 0");
  EXPECT_EQ(rotation[0], 1.0) << "nothing applied";
}

TEST_F(Fixture, RejectsNaNAndInfinity) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  ExpectThrowsWith<InvalidValue>([&] { registry.Set("arm.elbow.command", {nan}); },
                                 "arm.elbow.command: value is NaN");
  ExpectThrowsWith<InvalidValue>(
      [&] {
        registry.Set("arm.hand.rotation", {1, 0, 0, 0, inf, 0, 0, 0, 1});
      },
      "arm.hand.rotation: value 4 is infinite");
  EXPECT_EQ(commands.count("elbow"), 0u) << "nothing applied";
}

TEST_F(Fixture, RejectsWritesToReadOnlyChannels) {
  try {
    registry.Set("arm.elbow.current", {1.0});
    FAIL();
  } catch (const InvalidValue& e) {
    EXPECT_EQ(e.id(), "arm.elbow.current");
    EXPECT_EQ(e.reason(), "read-only");
    EXPECT_STREQ(e.what(), "arm.elbow.current: read-only");
  }
}

TEST(Registry, TurnsASetterRefusalIntoInvalidValueWithItsReason) {
  Registry registry;
  registry.Add(
      Info("m.mass", "kg"), [](double* out) { out[0] = 1; },
      [](const double* v) {
        if (v[0] <= 0) throw std::invalid_argument("mass must be positive");
      });
  ExpectThrowsWith<InvalidValue>([&] { registry.Set("m.mass", {-1.0}); },
                                 "m.mass: mass must be positive");
}

TEST(Registry, RejectsBadRegistrations) {
  Registry registry;
  auto get = [](double* out) { out[0] = 0; };
  registry.Add(Info("a", ""), get);
  ExpectThrowsWith<std::invalid_argument>([&] { registry.Add(Info("a", ""), get); },
                                          "a: already registered");
  ExpectThrowsWith<std::invalid_argument>([&] { registry.Add(Info("", ""), get); }, "empty id");
  ExpectThrowsWith<std::invalid_argument>(
      [&] {
        registry.Add(Info("b", "", {0, 3}), get);
      },
      "b: empty shape 0x3");
  ExpectThrowsWith<std::invalid_argument>([&] { registry.Add(Info("c", ""), nullptr); },
                                          "c: no getter");
  EXPECT_EQ(registry.size(), 1u);
}

TEST_F(Fixture, HandlesReadWithoutLookupAndGoStaleWhenTheChannelGoes) {
  const Handle h = registry.Resolve("arm.shoulder.current");
  EXPECT_TRUE(registry.Valid(h));
  double v = 0;
  registry.Read(h, &v);
  EXPECT_EQ(v, 1.5);
  currents["shoulder"] = 3.0;
  registry.Read(h, &v);
  EXPECT_EQ(v, 3.0);
  EXPECT_EQ(registry.Info(h).id, "arm.shoulder.current");

  Handle hv;
  ASSERT_TRUE(registry.TryResolve("arm.hand.position", &hv));
  double p[3];
  registry.Read(hv, p);
  EXPECT_EQ(p[2], 0.3);
  EXPECT_FALSE(registry.TryResolve("arm.hand.velocity", &hv));

  const uint64_t version = registry.version();
  EXPECT_TRUE(registry.Remove("arm.shoulder.current"));
  EXPECT_FALSE(registry.Remove("arm.shoulder.current"));
  EXPECT_NE(registry.version(), version);
  EXPECT_FALSE(registry.Valid(h));
  ExpectThrowsWith<UnknownId>([&] { registry.Read(h, &v); }, "arm.shoulder.current");

  // the same id registered again reuses the slot; the old handle stays stale
  registry.Add(Info("arm.shoulder.current", "A"), [](double* out) { out[0] = 7; });
  EXPECT_FALSE(registry.Valid(h));
  const Handle again = registry.Resolve("arm.shoulder.current");
  EXPECT_EQ(again.slot, h.slot);
  registry.Read(again, &v);
  EXPECT_EQ(v, 7.0);
}

TEST_F(Fixture, ClearAndRemoveMatchingLeaveStaleHandles) {
  const Handle current = registry.Resolve("arm.wrist.current");
  const Handle position = registry.Resolve("arm.hand.position");
  EXPECT_EQ(registry.RemoveMatching("arm.hand.*"), 2u);
  EXPECT_FALSE(registry.Valid(position));
  EXPECT_TRUE(registry.Valid(current));
  EXPECT_EQ(registry.size(), 6u);
  registry.Clear();
  EXPECT_EQ(registry.size(), 0u);
  EXPECT_FALSE(registry.Valid(current));
  EXPECT_TRUE(registry.List().empty());
  EXPECT_FALSE(registry.Valid(Handle{}));
  ExpectThrowsWith<UnknownId>([&] { registry.Read(Handle{}, nullptr); }, "stale handle");
}

TEST_F(Fixture, SetsThroughAHandle) {
  const Handle h = registry.Resolve("arm.wrist.command");
  const double v = 2.5;
  registry.Set(h, &v, 1);
  EXPECT_EQ(commands["wrist"], 2.5);
  ExpectThrowsWith<InvalidValue>([&] { registry.Set(h, &v, 2); }, "got 2");
}

/// Two values read in place; counts its updates.
struct PairBlock : SourceBlock {
  void Update() override {
    ++updates;
    values[0] = 10.0 * updates;
    values[1] = 10.0 * updates + 1;
  }
  double values[2] = {};
  int updates = 0;
};

TEST(Registry, ReadsAChannelAddedWithASourceInPlace) {
  Registry registry;
  auto block = std::make_shared<PairBlock>();
  const Handle h =
      registry.Add(Info("b.pair", "m", Shape::Vector(2)), Source{block, block->values});
  EXPECT_FALSE(registry.Info(h).writable);
  double out[2] = {};
  registry.Read(h, out);
  EXPECT_EQ(out[0], 10.0) << "a read updates the block first";
  EXPECT_EQ(out[1], 11.0);
  EXPECT_EQ(registry.Get("b.pair"), (std::vector<double>{20, 21}));

  const Access a = registry.Resolved(h);
  EXPECT_EQ(a.block, block.get());
  EXPECT_EQ(a.values, block->values);
  EXPECT_EQ(a.size, 2u);
  ASSERT_NE(a.getter, nullptr);

  registry.Remove("b.pair");
  EXPECT_EQ(block.use_count(), 1) << "the registry lets go of a removed channel's block";
  ExpectThrowsWith<UnknownId>([&] { registry.Resolved(h); }, "unknown id 'b.pair'");
  ExpectThrowsWith<UnknownId>([&] { registry.Read(h, out); }, "unknown id 'b.pair'");
}

TEST(Registry, ResolvesAGetterChannelToItsGetter) {
  Registry registry;
  const Handle h = registry.Add(Info("g.x", "m"), [](double* out) { out[0] = 7; });
  const Access a = registry.Resolved(h);
  EXPECT_EQ(a.block, nullptr);
  EXPECT_EQ(a.values, nullptr);
  EXPECT_EQ(a.size, 1u);
  double out = 0;
  (*a.getter)(&out);
  EXPECT_EQ(out, 7.0);
}

TEST(Registry, RejectsASourceWithoutBlockOrValues) {
  Registry registry;
  auto block = std::make_shared<PairBlock>();
  ExpectThrowsWith<std::invalid_argument>(
      [&] {
        registry.Add(Info("b.none", "m"), Source{nullptr, block->values});
      },
      "b.none: source without a block or values");
  ExpectThrowsWith<std::invalid_argument>(
      [&] {
        registry.Add(Info("b.none", "m"), Source{block, nullptr});
      },
      "b.none: source without a block or values");
  EXPECT_EQ(registry.size(), 0u);
}

}  // namespace
}  // namespace caliper::daq
