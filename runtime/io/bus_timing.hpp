// Bus time per cycle of the networks the papers' nodes sit on, checked when
// a project loads so a period the bus cannot carry is refused.
//
// IEEE 1394 (paper 002 eqs. (1)-(11)), times in microseconds, bandwidth B in
// Mbit/s (bits per microsecond), N nodes on the bus:
//   ArbP = (0.023 + 14/B) N + 4 GapCount/B + 1.63                   (4)
//   DTP  = (0.023 + 14/B) N + 8 DataSize/B                           (5)
//   AckP = 0.25 + (0.023 + 14/B) N                                   (6)
//   T_req = T_resp = ArbP + DTP, T_ack1 = T_ack2 = AckP              (7)-(9)
//   T_lant = T_req + T_ack1 + T_exec + T_resp + T_ack2               (3)
//   T_sum = (82 + 48 GapCount)/B                                     (10)
//   N_max = (alpha T_s - CTS) / (2 (T_lant + T_sum))                 (11), alpha = 0.5
// DataSize counts payload and packet overhead (20 B in the paper). In the
// time-triggered schedule of paper 002 (Fig. 4, eq. (2)) every cycle carries a
// cycle-start packet and, per node, one read and one write transaction, in
// the periodic window alpha T_s (eq. (1)).
//
// EtherCAT-style lumped frame (paper 000 §6.2): one frame of 12 B overhead
// (8 B preamble, 4 B CRC) plus the payload passes every node once a cycle:
//   T_frame = 8 (12 + payload)/B + N t_hop.
#pragma once

#include <string>

namespace syncplc {

struct Ieee1394Bus {
  double bandwidth = 393.216;  // Mbit/s (S400)
  int gap_count = 63;          // the paper's worst case
  double overhead = 20;        // bytes of header and CRC per packet
  double exec_us = 0;          // T_exec: the responder's handling time
  double alpha = 0.5;          // share of the period for periodic traffic, eq. (1)
};

double ieee1394_arbitration_us(const Ieee1394Bus& b, int nodes);                       // (4)
double ieee1394_data_us(const Ieee1394Bus& b, int nodes, double data_bytes);          // (5)
double ieee1394_ack_us(const Ieee1394Bus& b, int nodes);                               // (6)
// T1 + T2 of paper 002 Table I: T_req + T_ack1 for a packet carrying `payload` bytes.
double ieee1394_request_ack_us(const Ieee1394Bus& b, int nodes, double payload);
// Eq. (3): a transaction whose request or response carries `payload` bytes.
double ieee1394_latency_us(const Ieee1394Bus& b, int nodes, double payload);
double ieee1394_gaps_us(const Ieee1394Bus& b);                                         // (10)
// Cycle start packet (no payload): arbitration, header, acknowledge.
double ieee1394_cycle_start_us(const Ieee1394Bus& b, int nodes);
// One cycle of the time-triggered schedule: CTS + N (read + write transactions with gaps).
double ieee1394_cycle_us(const Ieee1394Bus& b, int nodes, double payload);
// Eq. (11): how many nodes a period carries.
int ieee1394_max_nodes(const Ieee1394Bus& b, double period_us, double payload);

struct EthercatBus {
  double bandwidth = 100;   // Mbit/s
  double overhead = 12;     // bytes: 8 preamble + 4 CRC
  double hop_us = 0;        // forwarding delay per node
};
double ethercat_frame_us(const EthercatBus& b, int nodes, double payload);

}  // namespace syncplc
