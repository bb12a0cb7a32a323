"""Reads typed values from a running `syncplc run` with Debian's python3-pymodbus
(3.0) and prints them as JSON: what tests/hmi/test_real_pages.mjs reads back
after a write from the HMI. Holding registers, high word first (the default
word order, docs/modbus.md).

    /usr/bin/python3 tests/hmi/modbus_read.py PORT ADDRESS TYPE[,TYPE...] [ADDRESS TYPE...]

prints one JSON list of the decoded values per ADDRESS, e.g. [[2.25, 2.25], [10, 25, 30]].
"""

import json
import sys

from pymodbus.client import ModbusTcpClient
from pymodbus.constants import Endian
from pymodbus.payload import BinaryPayloadDecoder

WIDTH = {"INT": 1, "UINT": 1, "DINT": 2, "REAL": 2, "LINT": 4, "LREAL": 4}
CODEC = {"INT": "16bit_int", "UINT": "16bit_uint", "DINT": "32bit_int", "REAL": "32bit_float",
         "LINT": "64bit_int", "LREAL": "64bit_float"}


def main(argv):
    if len(argv) < 4 or len(argv) % 2:
        sys.exit(__doc__)
    client = ModbusTcpClient("127.0.0.1", port=int(argv[1]), timeout=5, retries=0)
    if not client.connect():
        sys.exit("pymodbus could not connect to 127.0.0.1:%s" % argv[1])
    out = []
    try:
        for address, types in zip(argv[2::2], argv[3::2]):
            types = types.split(",")
            count = sum(WIDTH[t] for t in types)
            r = client.read_holding_registers(int(address), count, slave=1)
            if r is None or r.isError():
                sys.exit("reading holding registers %s..%d: %r" % (address, int(address) + count - 1, r))
            d = BinaryPayloadDecoder.fromRegisters(list(r.registers), byteorder=Endian.Big, wordorder=Endian.Big)
            out.append([getattr(d, "decode_" + CODEC[t])() for t in types])
    finally:
        client.close()
    print(json.dumps(out))


if __name__ == "__main__":
    main(sys.argv)
