// Online change as one transaction (runtime/plc/transaction.hpp), in virtual
// time: every participant is told each phase in order, a refusal aborts
// those prepared (in reverse) and leaves the running program untouched, and
// the change completes only once every task has switched on its own grid.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "runtime/plc/transaction.hpp"
#include "tests/support/project_fixture.hpp"

namespace syncplc::plc {
namespace {

const char* kProject = R"(
tasks:
  - {name: fast, period: 1ms}
  - {name: slow, period: 10ms}
tags:
  - {name: total, type: LREAL}
blocks:
  - {name: acc, type: ACC, task: fast, inputs: {IN: 1.0}}
connections:
  - acc.SUM -> total
)";

struct Log {
  std::vector<std::string> calls;
};

class Recorder final : public ChangeParticipant {
 public:
  Recorder(std::string name, Log& log, bool refuse = false) : name_(std::move(name)), log_(log), refuse_(refuse) {}
  const char* name() const override { return name_.c_str(); }
  bool prepare(ChangeContext& c, std::string* why) override {
    log_.calls.push_back(name_ + ".prepare");
    EXPECT_EQ(&c.from != c.next.program.get(), true);
    if (refuse_) *why = name_ + " says no";
    return !refuse_;
  }
  void abort(ChangeContext&) override { log_.calls.push_back(name_ + ".abort"); }
  void commit_begin(ChangeContext& c) override {
    log_.calls.push_back(name_ + ".commit_begin");
    EXPECT_EQ(c.from.tasks[0]->handover(), nullptr) << "before the scheduler begins the change";
  }
  void commit(ChangeContext& c) override {
    log_.calls.push_back(name_ + ".commit");
    EXPECT_NE(c.from.tasks[0]->handover(), nullptr) << "the old tasks mirror from now on";
  }
  void complete(ChangeContext& c) override {
    log_.calls.push_back(name_ + ".complete");
    for (const auto& h : c.change.handovers) EXPECT_TRUE(h->done.load()) << "every task switched";
  }

 private:
  std::string name_;
  Log& log_;
  bool refuse_;
};

LoadResult load(const std::string& text) { return load_test_result(text); }

TEST(Transaction, TellsEveryParticipantEachPhaseInOrder) {
  auto running = load_test_project(kProject);
  VirtualClock clock(*running);
  clock.run_until(20'000'000);
  VirtualScheduler scheduler(clock);
  Log log;
  Recorder a("a", log), b("b", log);
  Transaction tx(*running, load(std::string(kProject) + "# edited\n"), ChangeSource{"p.yaml", "reload", ""});
  EXPECT_EQ(tx.phase(), ChangePhase::Planned);
  std::string why;
  ASSERT_TRUE(tx.prepare({&a, &b}, &why)) << why;
  tx.commit(scheduler, 35'000'000);
  EXPECT_EQ(tx.phase(), ChangePhase::Committed);
  EXPECT_FALSE(tx.poll());
  EXPECT_EQ(tx.waiting_tasks(), (std::vector<std::string>{"fast", "slow"}));
  clock.run_until(41'000'000);  // slow switches at its release at 40 ms
  ASSERT_TRUE(tx.poll());
  EXPECT_EQ(tx.phase(), ChangePhase::Complete);
  EXPECT_EQ(log.calls, (std::vector<std::string>{"a.prepare", "b.prepare", "a.commit_begin", "b.commit_begin", "a.commit",
                                                 "b.commit", "a.complete", "b.complete"}));
  EXPECT_EQ(&clock.program(), tx.next().program.get());
  EXPECT_EQ(tag_cell(*tx.next().program, "total").get<double>(), 41.0) << "acc kept its sum: one per fast scan";
}

TEST(Transaction, ARefusalAbortsThosePreparedInReverseAndChangesNothing) {
  auto running = load_test_project(kProject);
  VirtualClock clock(*running);
  clock.run_until(20'000'000);
  Log log;
  Recorder a("a", log), b("b", log), no("no", log, true), c("c", log);
  Transaction tx(*running, load(std::string(kProject) + "# edited\n"), ChangeSource{"p.yaml", "reload", ""});
  std::string why;
  EXPECT_FALSE(tx.prepare({&a, &b, &no, &c}, &why));
  EXPECT_EQ(why, "no says no");
  EXPECT_EQ(tx.phase(), ChangePhase::Aborted);
  EXPECT_EQ(log.calls, (std::vector<std::string>{"a.prepare", "b.prepare", "no.prepare", "b.abort", "a.abort"}));
  EXPECT_EQ(running->tasks[0]->handover(), nullptr);
  clock.run_until(40'000'000);
  EXPECT_EQ(&clock.program(), running.get()) << "the running program goes on";
  EXPECT_EQ(tag_cell(*running, "total").get<double>(), 40.0);
}

TEST(Transaction, APreparedTransactionGivenUpIsAborted) {
  auto running = load_test_project(kProject);
  Log log;
  Recorder a("a", log);
  {
    Transaction tx(*running, load(kProject), ChangeSource{"p.yaml", "reload", ""});
    std::string why;
    ASSERT_TRUE(tx.prepare({&a}, &why));
  }
  EXPECT_EQ(log.calls, (std::vector<std::string>{"a.prepare", "a.abort"}));
}

}  // namespace
}  // namespace syncplc::plc
