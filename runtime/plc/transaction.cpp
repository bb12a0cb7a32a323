#include "runtime/plc/transaction.hpp"

#include <stdexcept>

namespace syncplc::plc {

std::string_view change_phase_name(ChangePhase p) {
  switch (p) {
    case ChangePhase::Planned: return "planned";
    case ChangePhase::Prepared: return "prepared";
    case ChangePhase::Committed: return "committed";
    case ChangePhase::Complete: return "complete";
    case ChangePhase::Aborted: return "aborted";
  }
  return "?";
}

Transaction::Transaction(Program& from, LoadResult next, ChangeSource source)
    : from_(from), next_(std::move(next)), source_(std::move(source)) {
  if (!next_.program) throw std::logic_error("an online change needs a loaded program");
  change_ = plan_change(from_, *next_.program);
}

Transaction::~Transaction() {
  // A transaction given up before commit: its participants undo what they
  // prepared (a caller that returns early must not leave drivers open).
  if (phase_ == ChangePhase::Prepared) {
    ChangeContext c = context();
    for (auto it = participants_.rbegin(); it != participants_.rend(); ++it) (*it)->abort(c);
  }
}

bool Transaction::prepare(std::vector<ChangeParticipant*> participants, std::string* why) {
  if (phase_ != ChangePhase::Planned) throw std::logic_error("prepare: the transaction is not planned");
  ChangeContext c = context();
  std::vector<ChangeParticipant*> prepared;
  for (ChangeParticipant* p : participants) {
    std::string reason;
    if (!p->prepare(c, &reason)) {
      for (auto it = prepared.rbegin(); it != prepared.rend(); ++it) (*it)->abort(c);
      phase_ = ChangePhase::Aborted;
      if (why) *why = reason.empty() ? std::string(p->name()) + " refused the change" : reason;
      return false;
    }
    prepared.push_back(p);
  }
  participants_ = std::move(participants);
  phase_ = ChangePhase::Prepared;
  return true;
}

void Transaction::commit(ChangeScheduler& scheduler, std::int64_t switch_ns) {
  if (phase_ != ChangePhase::Prepared) throw std::logic_error("commit: the transaction is not prepared");
  scheduler_ = &scheduler;
  ChangeContext c = context();
  for (ChangeParticipant* p : participants_) p->commit_begin(c);
  // T after what commit_begin waited for (a reader's lock, the Modbus hold).
  change_->switch_ns = switch_ns >= 0 ? switch_ns : switch_instant(*change_, scheduler.now_ns());
  scheduler.begin_change(*change_);
  for (ChangeParticipant* p : participants_) p->commit(c);
  phase_ = ChangePhase::Committed;
}

bool Transaction::poll() {
  if (phase_ == ChangePhase::Complete) return true;
  if (phase_ != ChangePhase::Committed || !scheduler_->change_complete()) return false;
  scheduler_->finish_change();
  ChangeContext c = context();
  for (ChangeParticipant* p : participants_) p->complete(c);
  phase_ = ChangePhase::Complete;
  return true;
}

std::vector<std::string> Transaction::waiting_tasks() const {
  std::vector<std::string> out;
  if (phase_ != ChangePhase::Committed) return out;
  for (const auto& h : change_->handovers)
    if (!h->done.load(std::memory_order_acquire) && h->from) out.push_back(h->from->config().name);
  return out;
}

}  // namespace syncplc::plc
