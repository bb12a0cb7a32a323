"""A Modbus TCP device for the client driver's tests: Debian's pymodbus
server (not ours) on 127.0.0.1:PORT, unit UNIT, with known start values.

    /usr/bin/python3 tests/peers/mb_device.py PORT [UNIT]

Tables (0-based addresses, zero_mode): holding registers 0..1 = DINT
0x00012345 (high word first), 50..51 = INT 7, -8, the rest 0; input
registers 0..3 = REAL 1.5, -2.25 (high word first); coils 0..3 = 1 0 1 1;
discrete inputs 0..2 = 0 1 1. Prints "ready" once listening. The test kills
it to play a dead device.
"""
import logging
import sys

from pymodbus.datastore import ModbusSequentialDataBlock, ModbusServerContext, ModbusSlaveContext
from pymodbus.server import StartTcpServer

port = int(sys.argv[1])
unit = int(sys.argv[2]) if len(sys.argv) > 2 else 1
logging.disable(logging.CRITICAL)

hr = [0] * 200
hr[0:2] = [0x0001, 0x2345]
hr[50:52] = [7, 0x10000 - 8]
ir = [0] * 200
ir[0:4] = [0x3FC0, 0x0000, 0xC010, 0x0000]  # 1.5f, -2.25f
co = [0] * 200
co[0:4] = [1, 0, 1, 1]
di = [0] * 200
di[0:3] = [0, 1, 1]
store = ModbusSlaveContext(di=ModbusSequentialDataBlock(0, di), co=ModbusSequentialDataBlock(0, co),
                           hr=ModbusSequentialDataBlock(0, hr), ir=ModbusSequentialDataBlock(0, ir), zero_mode=True)
context = ModbusServerContext(slaves={unit: store}, single=False)
print("ready", flush=True)
StartTcpServer(context=context, address=("127.0.0.1", port))
