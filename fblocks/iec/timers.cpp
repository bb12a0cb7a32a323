// IEC 61131-3 timers TON, TOF, TP. Time is ScanContext::now_ns (the planned
// release of the scan); elapsed time is always now_ns - start, never a count
// of scans, so skipped or irregular scans do not stretch a timer.
#include "fblocks/iec/common.hpp"

namespace syncplc::iec {
namespace {

enum : int { kIn = 0, kPt = 1, kQ = 2, kEt = 3 };

std::int64_t preset(const Block& b) {
  const std::int64_t pt = b.in<std::int64_t>(kPt);
  return pt < 0 ? 0 : pt;  // a negative PT acts as 0
}

class Ton final : public Block {
 public:
  void execute(ScanContext& ctx) noexcept override {
    const bool in = this->in<bool>(kIn);
    if (!in) {
      running_ = false;
      out<bool>(kQ, false);
      out<std::int64_t>(kEt, 0);
      return;
    }
    if (!running_) {
      running_ = true;
      start_ = ctx.now_ns;
    }
    const std::int64_t pt = preset(*this);
    const std::int64_t el = elapsed_ns(ctx.now_ns, start_);
    const bool q = el >= pt;
    out<bool>(kQ, q);
    out<std::int64_t>(kEt, q ? pt : el);
  }

 private:
  bool running_ = false;
  std::int64_t start_ = 0;
};

class Tof final : public Block {
 public:
  void execute(ScanContext& ctx) noexcept override {
    const bool in = this->in<bool>(kIn);
    if (in) {
      timing_ = false;
      et_ = 0;
      q_ = true;
    } else {
      if (prev_in_) {  // falling edge: start the off-delay
        timing_ = true;
        start_ = ctx.now_ns;
      }
      if (timing_) {
        const std::int64_t pt = preset(*this);
        const std::int64_t el = elapsed_ns(ctx.now_ns, start_);
        if (el >= pt) {
          timing_ = false;
          q_ = false;
          et_ = pt;
        } else {
          q_ = true;
          et_ = el;
        }
      }
    }
    prev_in_ = in;
    out<bool>(kQ, q_);
    out<std::int64_t>(kEt, et_);
  }

 private:
  bool prev_in_ = false;
  bool timing_ = false;
  bool q_ = false;
  std::int64_t start_ = 0;
  std::int64_t et_ = 0;
};

class Tp final : public Block {
 public:
  void execute(ScanContext& ctx) noexcept override {
    const bool in = this->in<bool>(kIn);
    if (!pulsing_ && in && !prev_in_) {
      pulsing_ = true;
      start_ = ctx.now_ns;
    }
    prev_in_ = in;
    bool q = false;
    if (pulsing_) {
      const std::int64_t pt = preset(*this);
      const std::int64_t el = elapsed_ns(ctx.now_ns, start_);
      if (el >= pt) {
        pulsing_ = false;
        et_ = pt;
      } else {
        q = true;
        et_ = el;
      }
    }
    if (!pulsing_ && !in) et_ = 0;
    out<bool>(kQ, q);
    out<std::int64_t>(kEt, et_);
  }

 private:
  bool prev_in_ = false;
  bool pulsing_ = false;
  std::int64_t start_ = 0;
  std::int64_t et_ = 0;
};

BlockTypeInfo timer_info(const char* name, std::string doc, std::string in_doc, std::string q_doc,
                         std::string et_doc) {
  BlockTypeInfo t;
  t.name = name;
  t.category = "IEC timers";
  t.doc = std::move(doc);
  t.reference = kRefFB;
  t.pins = {
      input("IN", IecType::BOOL).doc(std::move(in_doc)),
      input("PT", IecType::TIME).doc("preset time; a negative value acts as 0"),
      output("Q", IecType::BOOL).doc(std::move(q_doc)),
      output("ET", IecType::TIME).doc(std::move(et_doc)),
  };
  return t;
}

}  // namespace

void register_timers(BlockRegistry& r) {
  {
    auto t = timer_info(
        "TON",
        "On-delay timer. A rising edge of IN (including IN TRUE on the first scan) records the start time; "
        "each scan, elapsed = now - start (from the scan's planned release time, not a count of scans). "
        "Q = IN AND elapsed >= PT; ET = MIN(elapsed, PT). IN FALSE resets Q := FALSE and ET := 0. "
        "PT is read every scan: lowering it below the elapsed time sets Q and clamps ET to the new PT at "
        "once; raising it while Q is TRUE makes Q fall back to FALSE and ET continue from the true elapsed "
        "time until the new PT is reached (as in CODESYS). PT = 0 gives Q on the scan IN rises.",
        "timer input; the rising edge starts timing, FALSE resets the timer",
        "TRUE once IN has been TRUE for at least PT",
        "elapsed time since IN rose, limited to PT; 0 while IN is FALSE");
    t.create = make_plain<Ton>();
    r.add(std::move(t));
  }
  {
    auto t = timer_info(
        "TOF",
        "Off-delay timer. Q is TRUE while IN is TRUE and ET is 0. A falling edge of IN records the start "
        "time; Q stays TRUE until elapsed = now - start reaches PT, then Q := FALSE and ET holds PT until "
        "IN rises again, which resets ET to 0. PT is read every scan while timing (raising it extends the "
        "delay, lowering it below the elapsed time ends it at once). PT = 0 drops Q on the scan IN falls. "
        "Starts with Q FALSE and ET 0: there is no delay if IN was never TRUE.",
        "timer input; TRUE sets Q, the falling edge starts the off-delay",
        "TRUE while IN is TRUE and for PT after IN falls",
        "elapsed time since IN fell, limited to PT (holds PT after the delay); 0 while IN is TRUE");
    t.create = make_plain<Tof>();
    r.add(std::move(t));
  }
  {
    auto t = timer_info(
        "TP",
        "Pulse timer. A rising edge of IN while no pulse is running (including IN TRUE on the first scan) "
        "starts a pulse: Q is TRUE while elapsed = now - start < PT. Edges of IN during the pulse are "
        "ignored (no retrigger, no early end). ET counts up to PT; after the pulse ET holds PT as long as "
        "IN is still TRUE and resets to 0 once the pulse is over and IN is FALSE. A new pulse needs a new "
        "rising edge after the pulse. PT is read every scan while pulsing; PT <= 0 gives no pulse.",
        "trigger; a rising edge starts a pulse unless one is running",
        "TRUE for PT from the triggering edge",
        "elapsed pulse time, limited to PT; held at PT after the pulse while IN is TRUE");
    t.create = make_plain<Tp>();
    r.add(std::move(t));
  }
}

}  // namespace syncplc::iec
