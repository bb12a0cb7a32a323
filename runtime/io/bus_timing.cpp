#include "runtime/io/bus_timing.hpp"

#include <cmath>

namespace syncplc {
namespace {

double per_node(const Ieee1394Bus& b, int nodes) { return (0.023 + 14.0 / b.bandwidth) * nodes; }

}  // namespace

double ieee1394_arbitration_us(const Ieee1394Bus& b, int nodes) {
  return per_node(b, nodes) + b.gap_count * 4.0 / b.bandwidth + 1.63;
}

double ieee1394_data_us(const Ieee1394Bus& b, int nodes, double data_bytes) {
  return per_node(b, nodes) + data_bytes * 8.0 / b.bandwidth;
}

double ieee1394_ack_us(const Ieee1394Bus& b, int nodes) { return 0.25 + per_node(b, nodes); }

double ieee1394_request_ack_us(const Ieee1394Bus& b, int nodes, double payload) {
  return ieee1394_arbitration_us(b, nodes) + ieee1394_data_us(b, nodes, payload + b.overhead) + ieee1394_ack_us(b, nodes);
}

double ieee1394_latency_us(const Ieee1394Bus& b, int nodes, double payload) {
  // The data rides in one of the two packets; the other carries the header only.
  const double with_data = ieee1394_request_ack_us(b, nodes, payload);
  const double header_only = ieee1394_request_ack_us(b, nodes, 0);
  return with_data + b.exec_us + header_only;
}

double ieee1394_gaps_us(const Ieee1394Bus& b) { return (82.0 + 48.0 * b.gap_count) / b.bandwidth; }

double ieee1394_cycle_start_us(const Ieee1394Bus& b, int nodes) { return ieee1394_request_ack_us(b, nodes, 0); }

double ieee1394_cycle_us(const Ieee1394Bus& b, int nodes, double payload) {
  return ieee1394_cycle_start_us(b, nodes) +
         nodes * 2.0 * (ieee1394_latency_us(b, nodes, payload) + ieee1394_gaps_us(b));
}

int ieee1394_max_nodes(const Ieee1394Bus& b, double period_us, double payload) {
  // Eq. (11) has N on both sides (the arbitration terms grow with N): take the
  // largest N that satisfies it.
  int n = 0;
  while (n < 63) {  // a 1394 bus addresses at most 63 nodes
    const int m = n + 1;
    const double need = 2.0 * (ieee1394_latency_us(b, m, payload) + ieee1394_gaps_us(b));
    if (m > (b.alpha * period_us - ieee1394_cycle_start_us(b, m)) / need) break;
    n = m;
  }
  return n;
}

double ethercat_frame_us(const EthercatBus& b, int nodes, double payload) {
  return 8.0 * (b.overhead + payload) / b.bandwidth + nodes * b.hop_us;
}

}  // namespace syncplc
