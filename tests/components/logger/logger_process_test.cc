// caliper-logger as a hostile client of its IDL sees it: a private omniNames, the real process,
// and this test calling Caliper::Logging::LogService directly. The regular expressions of issue 19
// over a 20 KB message, bad and too long patterns, a forged (source, seq), more listeners than
// allowed, a listener that blocks and one that is gone: each answered, and the logger still
// answers afterwards.
#include <gtest/gtest.h>

#include <condition_variable>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "caliper/logging.hh"
#include "caliper/rtc/naming.h"
#include "support/corba.h"

namespace caliper::testing {
namespace {

namespace L = ::Caliper::Logging;
using std::chrono::seconds;

constexpr const char* kInstance = "attacker0";
constexpr size_t kMaxListenersPerClient = 8;  // the logger's bound for one client process

/// Every call of this test gives up after 10 s: a logger that blocks shows as TIMEOUT.
CORBA::ORB_ptr Orb() { return ServingClientOrb("logger_process_test", 10); }

PortableServer::POA_ptr Poa() { return RootPoa(Orb()); }

L::Record MakeRecord(const std::string& source, CORBA::ULongLong seq, const std::string& message) {
  return TestRecord(kInstance, source, seq, message);
}

L::RecordSeq Batch(const std::vector<L::Record>& records) {
  L::RecordSeq seq;
  seq.length(static_cast<CORBA::ULong>(records.size()));
  for (CORBA::ULong i = 0; i < records.size(); ++i) seq[i] = records[i];
  return seq;
}

/// The records this test submitted (not the logger's own) matching `regex`.
L::RecordFilter Ours(const std::string& regex) { return RecordsOf(kInstance, regex); }

std::vector<std::string> Messages(const L::StoredRecordSeq& records) {
  std::vector<std::string> out;
  for (CORBA::ULong i = 0; i < records.length(); ++i) out.push_back(records[i].rec.message.in());
  return out;
}

/// A listener that counts what it receives; while `blocked`, on_records waits (at most 30 s).
class TestListener : public virtual POA_Caliper::Logging::LogListener {
 public:
  void on_records(const L::StoredRecordSeq& records) override {
    std::unique_lock<std::mutex> lock(mutex_);
    ++calls_;
    received_ += records.length();
    changed_.notify_all();
    changed_.wait_for(lock, seconds(30), [&] { return !blocked_; });
  }
  void Block(bool blocked) {
    std::lock_guard<std::mutex> lock(mutex_);
    blocked_ = blocked;
    changed_.notify_all();
  }
  int calls() {
    std::lock_guard<std::mutex> lock(mutex_);
    return calls_;
  }
  /// Waits (at most `timeout`) until on_records was called at least `calls` times.
  bool WaitForCalls(int calls, std::chrono::milliseconds timeout) {
    std::unique_lock<std::mutex> lock(mutex_);
    return changed_.wait_for(lock, timeout, [&] { return calls_ >= calls; });
  }

 private:
  std::mutex mutex_;
  std::condition_variable changed_;
  bool blocked_ = false;
  int calls_ = 0;
  size_t received_ = 0;
};

/// A TestListener activated in the RootPOA; deactivated when destroyed (or before, as if gone).
class ActiveListener {
 public:
  ActiveListener() : servant_(new TestListener), poa_(Poa()) {
    id_ = poa_->activate_object(servant_);
    CORBA::Object_var obj = poa_->id_to_reference(id_);
    ref_ = L::LogListener::_narrow(obj);
  }
  ~ActiveListener() {
    servant_->Block(false);
    Deactivate();
  }
  void Deactivate() {
    if (active_) poa_->deactivate_object(id_);
    active_ = false;
  }
  TestListener& listener() { return *servant_; }
  L::LogListener_ptr ref() { return ref_.in(); }

 private:
  TestListener* servant_;
  PortableServer::ServantBase_var owner_{servant_};
  PortableServer::POA_var poa_;
  PortableServer::ObjectId_var id_;
  L::LogListener_var ref_;
  bool active_ = true;
};

class LoggerProcessTest : public ::testing::Test {
 protected:
  void SetUp() override {
    naming_ = std::make_unique<NamingService>(dir_.path());
    logger_ = std::make_unique<Process>(
        std::vector<std::string>{Bin("caliper-logger"), "--nameservice", naming_->address(), "-o",
                                 "logger.directory=" + dir_.path() + "/logs", "-o",
                                 "logger.session=hostile", "-o", "exec.auto_activate=true", "-o",
                                 "log.spool_dir=" + dir_.path() + "/spool"},
        dir_.path() + "/logger.out");
    // bound, and ACTIVE: an empty batch is accepted
    ASSERT_TRUE(WaitFor(
        [&] {
          try {
            CosNaming::NamingContext_var root = rtc::ResolveRoot(Orb(), naming_->address());
            const rtc::ComponentEntry entry = rtc::FindComponent(root, "logger0");
            logger_ref_ = L::LogService::_narrow(entry.object);
            logger_ref_->submit(L::RecordSeq());
            return true;
          } catch (const CORBA::Exception&) {  // not bound yet, or NotAvailable (not ACTIVE)
          } catch (const std::exception&) {
          }
          return false;
        },
        seconds(15)))
        << logger_->Output();
  }

  /// The logger answers a call and its process runs.
  bool Answers() {
    if (!logger_->Running()) return false;
    try {
      CORBA::String_var file = logger_ref_->session_file();
      return std::string(file.in()).find("hostile") != std::string::npos;
    } catch (const CORBA::Exception&) {
      return false;
    }
  }

  /// The reason of the InvalidQuery that `q` gets, or "" when it is answered.
  std::string InvalidQueryReason(const L::RecordFilter& q) {
    try {
      L::StoredRecordSeq_var answer = logger_ref_->query(q);
    } catch (const L::InvalidQuery& e) {
      return e.reason.in();
    }
    return "";
  }

  TempDir dir_;
  std::unique_ptr<NamingService> naming_;
  std::unique_ptr<Process> logger_;
  L::LogService_var logger_ref_;
};

TEST_F(LoggerProcessTest, HostileRegularExpressionsAreAnsweredAndTheLoggerGoesOn) {
  std::string ab;
  for (int i = 0; i < 10 * 1024; ++i) ab += "ab";  // 20 KB
  ASSERT_EQ(logger_ref_->submit(Batch({MakeRecord("hostile:1", 1, ab),
                                       MakeRecord("hostile:1", 2, std::string(20, 'a'))})),
            2u);

  // std::regex overflowed the stack here: the logger died
  L::StoredRecordSeq_var alternation = logger_ref_->query(Ours("(a|b)*c"));
  // the 20 KB message is kept cut to 16 KiB, and its marker ("truncated") has a c
  ASSERT_EQ(alternation->length(), 1u);
  const std::string kept = alternation[0].rec.message.in();
  EXPECT_LE(kept.size(), 16u * 1024);
  EXPECT_NE(kept.find("[truncated "), std::string::npos);
  EXPECT_TRUE(Answers());

  // exponential backtracking with std::regex (more than 30 s, and every submit waited)
  L::StoredRecordSeq_var nested = logger_ref_->query(Ours("(a*)*b"));
  EXPECT_EQ(nested->length(), 1u) << "the cut 20 KB message has b's; twenty a's have none";
  L::StoredRecordSeq_var nested_aaa = logger_ref_->query(Ours("^(a*)*b"));
  EXPECT_EQ(Messages(nested_aaa.in()), std::vector<std::string>{kept});
  EXPECT_TRUE(Answers());

  EXPECT_EQ(InvalidQueryReason(Ours("joint (")),
            "bad regular expression 'joint (': missing ): joint (");
  EXPECT_EQ(InvalidQueryReason(Ours("(a)\\1")),
            "bad regular expression '(a)\\1': invalid escape sequence: \\1");
  EXPECT_EQ(InvalidQueryReason(Ours(std::string(1025, 'a'))),
            "regular expression too long: 1025 bytes, at most 1024");

  // still storing and answering
  EXPECT_EQ(logger_ref_->submit(Batch({MakeRecord("hostile:1", 3, "after the attack")})), 1u);
  L::StoredRecordSeq_var after = logger_ref_->query(Ours("^after the attack$"));
  EXPECT_EQ(Messages(after.in()), std::vector<std::string>{"after the attack"});
  EXPECT_TRUE(Answers()) << logger_->Output();
}

TEST_F(LoggerProcessTest, AForgedSeqDoesNotSilenceTheProcessItNames) {
  ASSERT_EQ(logger_ref_->submit(Batch({MakeRecord("victim:7", 1, "victim 1")})), 1u);
  // another client names the victim's source with a huge seq
  ASSERT_EQ(logger_ref_->submit(Batch({MakeRecord("victim:7", 1ULL << 62, "forged")})), 1u);
  EXPECT_EQ(logger_ref_->submit(Batch(
                {MakeRecord("victim:7", 2, "victim 2"), MakeRecord("victim:7", 3, "victim 3")})),
            2u);
  // a retried batch is still stored once
  EXPECT_EQ(logger_ref_->submit(Batch({MakeRecord("victim:7", 2, "victim 2")})), 0u);
  L::StoredRecordSeq_var victim = logger_ref_->query(Ours("^victim"));
  EXPECT_EQ(Messages(victim.in()), (std::vector<std::string>{"victim 1", "victim 2", "victim 3"}));
}

TEST_F(LoggerProcessTest, ListenersAreBoundedAndNeitherABlockedNorAGoneOneHoldsSubmit) {
  std::vector<std::unique_ptr<ActiveListener>> listeners;
  for (size_t i = 0; i < kMaxListenersPerClient; ++i) {
    listeners.push_back(std::make_unique<ActiveListener>());
    logger_ref_->add_listener(listeners.back()->ref());
  }
  ActiveListener extra;
  try {
    logger_ref_->add_listener(extra.ref());
    ADD_FAILURE() << "a listener beyond the bound was taken";
  } catch (const L::LimitExceeded& e) {
    EXPECT_EQ(e.limit, kMaxListenersPerClient);
    EXPECT_NE(std::string(e.reason.in()).find("at most 8 per client"), std::string::npos)
        << e.reason.in();
  }
  EXPECT_THROW(logger_ref_->add_listener(L::LogListener::_nil()), L::NotAvailable);
  // a reference to nothing takes no place: refused with the reason
  ActiveListener gone;
  gone.Deactivate();
  try {
    logger_ref_->add_listener(gone.ref());
    ADD_FAILURE() << "a listener that does not exist was taken";
  } catch (const L::NotAvailable& e) {
    EXPECT_NE(std::string(e.reason.in()).find("does not exist"), std::string::npos)
        << e.reason.in();
  }

  // a listener that blocks in on_records: submits still return (this test's calls time out
  // after 10 s, the listener blocks up to 30 s)
  TestListener& blocked = listeners[0]->listener();
  TestListener& other = listeners[1]->listener();
  blocked.Block(true);
  const int blocked_calls = blocked.calls();
  ASSERT_EQ(logger_ref_->submit(Batch({MakeRecord("quiet:1", 1, "first")})), 1u);
  ASSERT_TRUE(blocked.WaitForCalls(blocked_calls + 1, seconds(10))) << "a push is blocked";
  const int other_calls = other.calls();
  for (CORBA::ULongLong seq = 2; seq <= 5; ++seq)
    EXPECT_EQ(logger_ref_->submit(Batch({MakeRecord("quiet:1", seq, "more")})), 1u) << seq;
  EXPECT_TRUE(other.WaitForCalls(other_calls + 1, seconds(10))) << "the others are served";
  blocked.Block(false);

  // a listener that is gone: the next push drops it and frees its place
  listeners[2]->Deactivate();
  ASSERT_EQ(logger_ref_->submit(Batch({MakeRecord("quiet:1", 6, "wakes the pushes")})), 1u);
  CORBA::ULongLong extra_id = 0;
  EXPECT_TRUE(WaitFor(
      [&] {
        try {
          extra_id = logger_ref_->add_listener(extra.ref());
          return true;
        } catch (const L::LimitExceeded&) {
          return false;
        }
      },
      seconds(10)));
  EXPECT_GT(extra_id, 0u);
  EXPECT_TRUE(Answers()) << logger_->Output();
}

}  // namespace
}  // namespace caliper::testing
