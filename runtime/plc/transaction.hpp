// Online change as one transaction (docs/architecture.md, "Online change"):
//
//   plan     the new program, loaded and checked beside the running one, is
//            compared with it (runtime/core/program_change.hpp: tasks,
//            instances by their signature, drivers, tags); nothing changes;
//   prepare  every participant gets ready without changing what runs: new
//            drivers open (one that cannot refuses the change, and every
//            participant prepared so far is told to abort), the supervisor
//            learns the new tasks' drivers;
//   commit   the switch instant T is set; participants hold what they serve
//            (commit_begin), the scheduler begins the change (from now on
//            the old tasks mirror into the new program, forces go over) and
//            participants follow the new program (commit): the Modbus and
//            HTTP servers, the store's jobs. Each task then switches on its
//            own thread at its own scan boundary (task_switch.hpp);
//   complete once every task has switched: drivers taken over and the old
//            ones closed, the old program's last events and trend buckets
//            taken, and the old program goes;
//   abort    before commit only: nothing ran differently.
//
// Participants are told in the order they were given (abort: the reverse).
// None guesses when "the switch" happened: the transaction tells each the
// phase that concerns it. All of it runs on one non-real-time thread (the
// PLC's control thread, or a virtual-time test); the task threads see only
// their handovers.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "runtime/core/program_change.hpp"
#include "runtime/plc/change_scheduler.hpp"
#include "runtime/project/loader.hpp"

namespace syncplc::plc {

// What a change loads and why (the project store records origin and source).
struct ChangeSource {
  std::string path;    // the project file
  std::string origin;  // "reload", "rollback", "upload"
  std::string source;  // "version 3", "an upload by eng from 127.0.0.1"; "" for the instance's own file
  // How messages name it: "version 3 (/path/p.yaml)", or the path.
  std::string what() const { return source.empty() ? path : source + " (" + path + ")"; }
};

enum class ChangePhase : std::uint8_t { Planned, Prepared, Committed, Complete, Aborted };
std::string_view change_phase_name(ChangePhase p);

// What a participant may look at, at every phase.
struct ChangeContext {
  Program& from;
  LoadResult& next;  // next.program: the new program
  ProgramChange& change;
  const ChangeSource& source;
};

class ChangeParticipant {
 public:
  virtual ~ChangeParticipant() = default;
  virtual const char* name() const = 0;
  // Get ready without changing what runs. False, with `why`, refuses the change.
  virtual bool prepare(ChangeContext& c, std::string* why) {
    (void)c;
    (void)why;
    return true;
  }
  // The change was refused after this participant prepared: undo it.
  virtual void abort(ChangeContext& c) { (void)c; }
  // Just before the scheduler begins the change: hold what must not be used
  // meanwhile (a server's requests).
  virtual void commit_begin(ChangeContext& c) { (void)c; }
  // The scheduler began the change: follow the new program from now on
  // (and release what commit_begin held).
  virtual void commit(ChangeContext& c) { (void)c; }
  // Every task has switched; the old program goes right after this.
  virtual void complete(ChangeContext& c) { (void)c; }
};

class Transaction {
 public:
  // Plans replacing `from` by `next` (loaded and ok). Nothing runs differently.
  Transaction(Program& from, LoadResult next, ChangeSource source);
  ~Transaction();
  Transaction(const Transaction&) = delete;
  Transaction& operator=(const Transaction&) = delete;

  // Prepares every participant, in order. False (with `why`) when one
  // refuses: those prepared before it are told abort(), in reverse order, and
  // the transaction is Aborted.
  bool prepare(std::vector<ChangeParticipant*> participants, std::string* why);
  // Commits: T = switch_instant after the scheduler's now (or `switch_ns`
  // when given), commit_begin, the scheduler's begin_change, commit.
  void commit(ChangeScheduler& scheduler, std::int64_t switch_ns = -1);
  // Completes the change once every task has switched: true then (phase
  // Complete; the scheduler runs the new program only).
  bool poll();

  ChangePhase phase() const { return phase_; }
  const ProgramChange& change() const { return *change_; }
  ProgramChange& change() { return *change_; }
  LoadResult& next() { return next_; }
  Program& from() { return from_; }
  const ChangeSource& source() const { return source_; }
  // The tasks that have not switched yet (commit to complete).
  std::vector<std::string> waiting_tasks() const;

 private:
  ChangeContext context() { return ChangeContext{from_, next_, *change_, source_}; }

  Program& from_;
  LoadResult next_;
  ChangeSource source_;
  std::unique_ptr<ProgramChange> change_;
  std::vector<ChangeParticipant*> participants_;
  ChangeScheduler* scheduler_ = nullptr;
  ChangePhase phase_ = ChangePhase::Planned;
};

}  // namespace syncplc::plc
