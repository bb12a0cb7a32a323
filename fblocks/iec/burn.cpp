// BURN: consumes a given amount of execution time per scan, to test
// watchdogs, overrun detection and scan-time statistics.
#include "fblocks/iec/common.hpp"
#include "runtime/core/monotonic_clock.hpp"

namespace syncplc::iec {
namespace {

enum : int { kExec = 0, kDone = 1 };

class Burn final : public Block {
 public:
  void execute(ScanContext& ctx) noexcept override {
    const std::int64_t exec = in<std::int64_t>(kExec);
    if (exec > 0) {
      if (ctx.virtual_time) {
        std::int64_t sum;
        ctx.consumed_ns = __builtin_add_overflow(ctx.consumed_ns, exec, &sum)
                              ? std::numeric_limits<std::int64_t>::max()
                              : sum;
      } else {
        const std::int64_t start = monotonic_ns();
        while (elapsed_ns(monotonic_ns(), start) < exec) {
        }
      }
    }
    out<bool>(kDone, true);
  }
};

}  // namespace

void register_burn(BlockRegistry& r) {
  BlockTypeInfo t;
  t.name = "BURN";
  t.category = "diagnostics";
  t.doc = "Consumes EXEC of execution time every scan it runs, to exercise watchdogs and overrun handling. "
          "In virtual time it adds EXEC to the scan's consumed execution time (ScanContext::consumed_ns); in "
          "real time it busy-waits on CLOCK_MONOTONIC for EXEC (the CPU is really kept busy, not put to "
          "sleep). EXEC <= 0 consumes nothing. DONE is set TRUE on every scan the block ran (it stays "
          "FALSE until the first execution).";
  t.reference = "syncplc diagnostic block (not an IEC 61131-3 standard block)";
  t.pins = {input("EXEC", IecType::TIME).doc("execution time to consume per scan (default 0)"),
            output("DONE", IecType::BOOL).doc("TRUE each scan the block has run")};
  t.create = make_plain<Burn>();
  r.add(std::move(t));
}

}  // namespace syncplc::iec
