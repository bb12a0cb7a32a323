// write_safe_outputs of every driver: the listed outputs take their safe
// values, the others keep the last value written, and the scan's later
// write_outputs change nothing until the driver is opened again. (The latch
// against a concurrent scan thread: tests/realtime/test_supervisor.cpp.)
#include <gtest/gtest.h>

#include "runtime/io/memory_driver.hpp"
#include "runtime/io/sim_ring.hpp"
#include "runtime/io/sim_table.hpp"

namespace syncplc {
namespace {

// Backing cells for every channel of a driver, bound to it.
struct OutputRig {
  explicit OutputRig(IoDriver& d) : drv(d) {
    for (const auto& c : d.channels()) storage.emplace_back(c.length, Cell{});
    std::vector<Cell*> cells;
    for (auto& s : storage) cells.push_back(s.data());
    d.bind(cells);
    std::string err;
    EXPECT_TRUE(d.open(&err)) << err;
  }
  void set(int channel, std::uint32_t i, double v) { storage[static_cast<std::size_t>(channel)][i].set<double>(v); }
  double get(int channel, std::uint32_t i) const { return storage[static_cast<std::size_t>(channel)][i].get<double>(); }
  void latch(std::int64_t t) {
    ctx.now_ns = t;
    drv.latch_inputs(ctx);
  }
  void write(std::int64_t t) {
    ctx.now_ns = t;
    drv.write_outputs(ctx);
  }
  IoDriver& drv;
  ScanContext ctx;
  std::vector<std::vector<Cell>> storage;
};

Cell lreal(double v) {
  Cell c;
  c.set<double>(v);
  return c;
}

TEST(SafeOutputs, MemoryDriverHoldsTheSafeValuesAgainstLaterScans) {
  MemoryDriver d({{"a", PinDir::Out, IecType::LREAL, 2, "", ""}, {"b", PinDir::Out, IecType::LREAL, 1, "", ""},
                  {"in", PinDir::In, IecType::LREAL, 1, "", ""}});
  OutputRig r(d);
  r.set(0, 0, 1.0);
  r.set(0, 1, 2.0);
  r.set(1, 0, 3.0);
  r.write(0);
  const SafeOutput safe[] = {{0, 1, lreal(-5.0)}, {2, 0, lreal(9.0)} /* an input: ignored */};
  EXPECT_TRUE(d.write_safe_outputs(safe, 2));
  Cell out[2];
  d.read_output(0, out);
  EXPECT_EQ(out[0].get<double>(), 1.0) << "no safe value: the last value written";
  EXPECT_EQ(out[1].get<double>(), -5.0);
  r.set(0, 0, 7.0);
  r.set(1, 0, 8.0);
  r.write(1'000'000);  // a scan that ends late
  d.read_output(0, out);
  EXPECT_EQ(out[0].get<double>(), 1.0) << "held: the late scan changed nothing";
  EXPECT_EQ(out[1].get<double>(), -5.0);
  d.read_output(1, out);
  EXPECT_EQ(out[0].get<double>(), 3.0);
  std::string err;
  ASSERT_TRUE(d.open(&err));  // a new run
  r.write(2'000'000);
  d.read_output(0, out);
  EXPECT_EQ(out[0].get<double>(), 7.0) << "opened again: written normally";
}

TEST(SafeOutputs, SimTableDrivesTheAxesWithTheSafeCommandsFromTheNextLatch) {
  SimTableConfig c;
  c.axes.assign(2, AxisModel{0.055, 35.6206});
  c.actuation_delay_ns = 200'000;
  SimTableDriver d(c);
  OutputRig r(d);
  r.latch(0);
  r.set(SimTableDriver::kCmd, 0, 0.5);
  r.set(SimTableDriver::kCmd, 1, 0.25);
  r.write(0);
  const SafeOutput safe[] = {{SimTableDriver::kCmd, 0, lreal(0.0)}};
  EXPECT_TRUE(d.write_safe_outputs(safe, 1));
  Cell out[2];
  d.read_output(SimTableDriver::kCmd, out);
  EXPECT_EQ(out[0].get<double>(), 0.0);
  EXPECT_EQ(out[1].get<double>(), 0.25) << "no safe value: the last command";
  r.set(SimTableDriver::kCmd, 0, 1.0);
  r.write(1'000'000);  // ignored
  r.latch(2'000'000);
  r.latch(3'000'000);
  // Over the last period the motors received the safe commands only.
  EXPECT_DOUBLE_EQ(r.get(SimTableDriver::kApplied, 0), 0.0);
  EXPECT_DOUBLE_EQ(r.get(SimTableDriver::kApplied, 1), 0.25);
}

TEST(SafeOutputs, SimRingSendsOneSafeFrameToEveryNode) {
  SimRingConfig c;
  c.nodes = 2;
  c.loss.model = LossConfig::Model::Bernoulli;
  c.loss.p = 1.0;  // the program's frames are all lost; the safe frame is not
  SimRingDriver d(c);
  OutputRig r(d);
  r.latch(0);
  r.set(SimRingDriver::kMasterCmd, 0, 4.0);
  r.set(SimRingDriver::kMasterCmd, 1, 6.0);
  r.write(0);
  const SafeOutput safe[] = {{SimRingDriver::kMasterCmd, 1, lreal(0.0)}};
  EXPECT_TRUE(d.write_safe_outputs(safe, 1));
  r.set(SimRingDriver::kMasterCmd, 1, 99.0);
  r.write(1'000'000);  // ignored
  r.latch(2'000'000);
  EXPECT_EQ(r.get(SimRingDriver::kCmd, 0), 4.0);
  EXPECT_EQ(r.get(SimRingDriver::kCmd, 1), 0.0);
  EXPECT_TRUE(r.storage[SimRingDriver::kCmdValid][1].get<bool>());
  r.latch(3'000'000);
  EXPECT_EQ(r.get(SimRingDriver::kCmd, 1), 0.0) << "held";
  EXPECT_FALSE(r.storage[SimRingDriver::kCmdValid][1].get<bool>()) << "one frame, not one per latch";
}

}  // namespace
}  // namespace syncplc
