// The `dds` driver (docs/dds.md): a node's tags published as one sample per
// scan on Cyclone DDS, and the samples of other nodes subscribed to, with the
// quality of each subscription as status channels and a reaction when it goes
// stale.
//
// Channels, for a publication TOPIC of n values:
//   TOPIC            out  ARRAY[1..n] OF LREAL (or LREAL when n = 1)
// and for a subscription TOPIC of n values (subscription_latch.hpp):
//   TOPIC            in   ARRAY[1..n] OF LREAL
//   TOPIC_ok         in   BOOL
//   TOPIC_age        in   UDINT, scans
//   TOPIC_lost       in   UDINT
//   TOPIC_late       in   UDINT
//   TOPIC_scan       in   ULINT, the publisher's scan count of the values
//   TOPIC_reaction   in   BOOL
//   TOPIC_phase      in   LREAL, us
//   TOPIC_fresh      in   BOOL, a new sample was taken at this scan
#pragma once

#include "runtime/core/io_driver.hpp"

namespace syncplc {

DriverTypeInfo dds_driver_type();

}  // namespace syncplc
