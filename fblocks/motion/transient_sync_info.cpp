// TRANSIENT_SYNC's declaration: documentation, pins and parameters (paper
// 004, Section III). The scan algorithm is TransientSyncCore
// (transient_sync_core.hpp) behind the pins of transient_sync.cpp, its
// derivations in docs/motion/transient-sync.md.
#include <memory>
#include <string>

#include "fblocks/motion/motion.hpp"
#include "fblocks/motion/transient_sync_block.hpp"
#include "runtime/core/pin_decl.hpp"

namespace syncplc::motion {

void register_transient_sync(BlockRegistry& r) {
  BlockTypeInfo t;
  t.name = "TRANSIENT_SYNC";
  t.category = kCategory;
  t.doc =
      "Synchronizer of n nonlinear filters (paper 004, Section III): n velocity/acceleration-limited filters "
      "(those of NONLINEAR_FILTER, Section II) turn n rough references r[i] (steps and ramps) into smooth "
      "x[i]; every scan the velocity bound of each filter that is faster than the slowest is reduced so that "
      "all transients end on the same scan, which also lowers the viscous-friction energy index "
      "E = integral of x_dot^2 dt (24).\n\n"
      "Every scan k, T the task period, for every axis: (1) n_i = transient time with the "
      "nominal bounds (Table I; -1 when r_dot is outside [v_min, v_max]); carried from the previous scan "
      "minus one while r continues the previous scan's ramp (r_(k-1) + T r_dot) and r_dot, the bounds and T "
      "are unchanged (Table I counts the filter's own samples); t_M = the largest finite n_i "
      "(output arrival). (2) The nominal bounds stay for axes that track, cannot track, have n_i = t_M, or "
      "ran on a reduced bound at the previous scan with unchanged inputs and are in the final approach "
      "(curved part of the boundary layer) of that bound (after a change of its r, r_dot or bounds an axis "
      "is synchronized afresh). (3) The others get, with tf = t_M T, dU = a_min - a_max, "
      "dv = x_dot - r_dot, dx = x - r: behind the reference, v_max := v^ = (a_min a_max tf + a_min x_dot - "
      "a_max r_dot + G1)/dU, G1 = sqrt(a_min a_max (tf a_min (tf a_max + 2 dv) + 2 dx dU + dv^2)) (33), the "
      "smaller root (both can be positive); ahead of it, v_min := v^ = -(a_min a_max tf + a_max x_dot - "
      "a_min r_dot + G2)/dU, G2 = sqrt(a_min a_max (tf a_max (tf a_min + 2 dv) - 2 dx dU + dv^2)) (34). These "
      "make the continuous profile (reach v^ at full acceleration, cruise, brake to r_dot; eqs. 25-32 with "
      "(31) read as s_f2 = r_dot tf) meet the reference at tf. A negative radicand, or v^ not strictly "
      "between r_dot and the nominal bound, keeps the nominal bounds. rule 0 (unified, default): (33) or (34) "
      "by the side on which the discrete filter comes to rest if it brakes at full acceleration now (dx is "
      "shifted so that the continuous model has the same stopping point), whatever the sign of r_dot; when "
      "x_dot already exceeds the solution the first phase brakes with a_min (linear in v^). rule 1 (paper): "
      "(33) only with r > x and r_dot >= 0, (34) only with r < x and r_dot <= 0, as printed; otherwise the "
      "filter is parked with v_max := min(0, v_max) (r > x) or v_min := max(0, v_min) (r < x) as in Fig. 7. "
      "rule 2 (off): never scales, n independent filters. (5) Lock (rule 0): when holding the reduced bound "
      "ends the transient exactly t_M scans from now (Table I with that bound; tried with tf = t_M T and, if "
      "it misses by d scans, once with tf = (t_M - d) T), the bound is locked: held without rescaling, guard "
      "or prediction until the axis's inputs change, t_M grows, or an axis that set t_M changes. (6) "
      "Otherwise, look-ahead guard: a reduced bound is applied only if the nominal transient time of the "
      "state it leads to at k+1 is at most t_M - 1; else the nominal bounds are used this scan, and (3)-(6) "
      "are recomputed at the next scan.\n\n"
      "Outputs at scan k are the filter states at sample k and the accelerations u_k applied from them (as "
      "NONLINEAR_FILTER). Transient window: opens at the first scan at which some axis does not track "
      "(synchronized FALSE) and closes at the next scan at which all track; its scans are those from the "
      "opening one to the last non-tracking one (window_scans of them). energy = T * sum over the window's "
      "scans and over all n axes of x_dot^2 (eq. 24, left rectangle rule), running while the window is open "
      "and held once it closes; energy_last = the value of the last closed window; windows counts closed "
      "windows; spread = in the last closed window, the latest minus the earliest scan at which an axis "
      "that did not track during it (last) began tracking (0: all arrived together). r_dot, when not "
      "connected, is (r_k - r_(k-1)) divided by the time between the scans (0 on the first scan; a step then "
      "looks like a one-scan ramp: give r_dot for references made of steps). A scan that follows skipped "
      "releases first runs the missed samples (up to 10000; filters, synchronizer and window, which count "
      "samples) with its inputs, r taken as a ramp backwards. Start and reset as NONLINEAR_FILTER "
      "A NaN or infinite input on any axis is the finite-input rule's (see ENO): the block does not execute, "
      "every output holds. Inconsistent bounds (v_min >= v_max, a_min >= 0 or a_max <= 0) on an axis set its error, "
      "exclude it from the synchronization (steps_to_go -1, so synchronized stays FALSE) and stop it with "
      "its last valid acceleration bounds; one block-fault event per scan at which axes start a series of "
      "invalid scans (value: their count).";
  t.reference =
      "C. Guarino Lo Bianco, \"An efficient algorithm for the real-time generation of synchronous reference "
      "signals\" (paper 004), Section III, eqs. (23)-(34), Figs. 6-8, Tables II-IV; corrections (eq. 31, "
      "roots of eqs. 33-34, the unified rule, the look-ahead guard) in "
      "docs/motion/transient-sync.md";
  t.pins = {
      input("r", IecType::LREAL).unit("m").array("n").required().doc("reference positions (steps and ramps)"),
      input("r_dot", IecType::LREAL).unit("m/s").array("n")
          .doc("reference velocities; when not connected, derived as (r_k - r_(k-1)) / (time between the scans), 0 on "
               "the first scan"),
      input("v_min", IecType::LREAL).unit("m/s").array("n").required()
          .doc("nominal lower velocity bounds (xdot-), below v_max"),
      input("v_max", IecType::LREAL).unit("m/s").array("n").required()
          .doc("nominal upper velocity bounds (xdot+), above v_min"),
      input("a_min", IecType::LREAL).unit("m/s^2").array("n").required()
          .doc("lower acceleration bounds (U-), negative"),
      input("a_max", IecType::LREAL).unit("m/s^2").array("n").required()
          .doc("upper acceleration bounds (U+), positive"),
      input("x0", IecType::LREAL).unit("m").array("n")
          .doc("start positions for reset (and the first scan when start_at_r is FALSE)"),
      input("v0", IecType::LREAL).unit("m/s").array("n")
          .doc("start velocities for reset (and the first scan when start_at_r is FALSE)"),
      input("reset", IecType::BOOL).doc("while TRUE every filter is held at x = x0, x_dot = v0 (x_ddot = 0)"),
      output("x", IecType::LREAL).unit("m").array("n").doc("filtered positions at this scan"),
      output("x_dot", IecType::LREAL).unit("m/s").array("n").doc("filtered velocities at this scan"),
      output("x_ddot", IecType::LREAL).unit("m/s^2").array("n").doc("accelerations applied from this scan to the next"),
      output("v_min_applied", IecType::LREAL).unit("m/s").array("n")
          .doc("lower velocity bounds applied this scan (v_min, or the scaled/parked bound)"),
      output("v_max_applied", IecType::LREAL).unit("m/s").array("n")
          .doc("upper velocity bounds applied this scan (v_max, or the scaled/parked bound)"),
      output("tracking", IecType::BOOL).array("n")
          .doc("TRUE when x and x_dot equal r and r_dot (within the tolerance)"),
      output("steps_to_go", IecType::LINT).array("n")
          .doc("scans until the axis tracks: its own transient time with its nominal bounds (Table I), or t_M for an "
               "axis on a reduced bound under rule 0 (it arrives with the slowest) (0 tracking, -1 never)"),
      output("error", IecType::BOOL).array("n").doc("TRUE while the axis's bounds or reference are invalid"),
      output("arrival", IecType::LINT)
          .doc("t_M: scans until the common arrival, the largest finite steps_to_go (0 when all track)"),
      output("synchronized", IecType::BOOL).doc("TRUE when every axis tracks its reference"),
      output("scaled", IecType::LINT).doc("number of axes running on a reduced velocity bound this scan"),
      output("energy", IecType::LREAL).unit("m^2/s")
          .doc("E of eq. (24) of the open transient window (held after it closes): T * sum of x_dot^2 over its scans "
               "and all axes"),
      output("energy_last", IecType::LREAL).unit("m^2/s").doc("E of the last closed transient window"),
      output("windows", IecType::LINT).doc("number of closed transient windows"),
      output("window_scans", IecType::LINT)
          .doc("scans in the open transient window so far (held after it closes: its length)"),
      output("spread", IecType::LINT)
          .doc("arrival spread of the last closed window: latest minus earliest arrival scan of the axes that moved "
               "(0 = synchronous)"),
  };
  t.params = {
      parameter("n", IecType::DINT).min(1).max(static_cast<double>(kMaxAxes))
          .doc("number of axes (sets the array pin lengths)"),
      parameter("rule", IecType::DINT).init("0").min(0).max(2)
          .doc("bound-scaling rule: 0 unified (eq. 33 or 34 by the side on which the filter comes to rest, any sign of "
               "r_dot), 1 the paper's (by the signs of r - x and r_dot, zero-bound parking otherwise), 2 off "
               "(independent filters)"),
      parameter("start_at_r", IecType::BOOL).init("TRUE")
          .doc("TRUE: the first scan starts every filter at x = r, x_dot = r_dot; FALSE: at (x0, v0)"),
  };
  t.rewire = true;  // TransientSync::rewire_from: r_dot connected or disconnected online
  t.create = [](BlockSetup& s) -> std::unique_ptr<Block> {
    const auto n = s.param<std::int32_t>("n");
    const auto rule = s.param<std::int32_t>("rule");
    if (n < 1 || n > kMaxAxes) {
      s.error("TRANSIENT_SYNC: n must be 1.." + std::to_string(kMaxAxes));
      return nullptr;
    }
    if (rule < 0 || rule > 2) {
      s.error("TRANSIENT_SYNC: rule must be 0 (unified), 1 (paper) or 2 (off)");
      return nullptr;
    }
    return make_transient_sync(s);
  };
  r.add(std::move(t));
}

}  // namespace syncplc::motion
