"""The simulated drive's register map (docs/drives.md): CiA 402 objects in
Modbus registers, and the 16/32-bit conversions."""

import threading

from pymodbus.datastore import ModbusSequentialDataBlock

# Holding registers (FC 3, 6, 16, 23): what the master writes. 32-bit values
# take two registers, high word first (as syncplc's own server by default).
HR_CONTROLWORD = 0          # 6040h UINT16
HR_MODES = 1                # 6060h INT8 (sign-extended to 16 bits)
HR_TARGET_POSITION = 2      # 607Ah INT32, counts
HR_TARGET_VELOCITY = 4      # 60FFh INT32, counts/s
HR_VELOCITY_OFFSET = 6      # 60B1h INT32, counts/s (CSP feed-forward)
HR_TARGET_TORQUE = 8        # 6071h INT16, 0.1 % of rated torque
HR_QUICK_STOP_OPTION = 9    # 605Ah INT16
HR_PROFILE_ACCELERATION = 10  # 6083h UINT32, counts/s^2
HR_PROFILE_DECELERATION = 12  # 6084h UINT32, counts/s^2
HR_QUICK_STOP_DECELERATION = 14  # 6085h UINT32, counts/s^2
HR_FOLLOWING_ERROR_WINDOW = 16   # 6065h UINT32, counts; FFFFFFFFh = off
HR_FOLLOWING_ERROR_TIMEOUT = 18  # 6066h UINT16, ms
HR_ABORT_CONNECTION = 19    # 6007h INT16, abort connection option code (state_machine.py)
HR_HOMING_METHOD = 20       # 6098h INT8 (sign-extended), homing.py
HR_HOME_OFFSET = 21         # 607Ch INT32, counts: the position the home point gets
HR_HOMING_SPEED_SWITCH = 23  # 6099h:1 UINT32, counts/s (search for the switch)
HR_HOMING_SPEED_ZERO = 25    # 6099h:2 UINT32, counts/s (search for its edge)
HR_HOMING_ACCELERATION = 27  # 609Ah UINT32, counts/s^2 (0: 6083h)
HR_COUNT = 29
# Input registers (FC 4): what the drive reports; also mirrored read-only at
# holding register MIRROR + i, so one FC 23 can write the commands and read
# the actual values in one round trip.
IR_STATUSWORD = 0           # 6041h UINT16
IR_MODES_DISPLAY = 1        # 6061h INT8 (sign-extended)
IR_POSITION_ACTUAL = 2      # 6064h INT32, counts
IR_VELOCITY_ACTUAL = 4      # 606Ch INT32, counts/s
IR_TORQUE_ACTUAL = 6        # 6077h INT16, 0.1 % of rated torque
IR_ERROR_CODE = 7           # 603Fh UINT16
IR_FOLLOWING_ERROR = 8      # 60F4h INT32, counts
IR_CYCLE_COUNTER = 10       # UINT32, drive cycles since start (vendor-specific)
IR_COUNT = 12
MIRROR = 100

# 603Fh error codes (CiA 402-2 / CiA 301 error code table).
ERROR_FOLLOWING = 0x8611      # following error
ERROR_COMMUNICATION = 0x8100  # communication: the master's requests stopped (6007h = 1)


def s16(v):
    return v - 0x10000 if v & 0x8000 else v


def s32(hi, lo):
    v = (hi << 16) | lo
    return v - 0x100000000 if v & 0x80000000 else v


def u32(hi, lo):
    return (hi << 16) | lo


def words32(v):
    v &= 0xFFFFFFFF
    return [v >> 16, v & 0xFFFF]


class LockedBlock(ModbusSequentialDataBlock):
    """A register block read and written whole under a lock: the drive thread
    and the server's requests never see half of a 32-bit value."""

    def __init__(self, address, values):
        super().__init__(address, values)
        self.lock = threading.Lock()

    def getValues(self, address, count=1):  # noqa: N802 (pymodbus's name)
        with self.lock:
            return super().getValues(address, count)

    def setValues(self, address, values):  # noqa: N802
        with self.lock:
            super().setValues(address, values)
