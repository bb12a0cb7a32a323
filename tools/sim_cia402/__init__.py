"""The simulated CiA 402 drive (tools/sim_cia402_drive.py), by job:

  registers      the register map (docs/drives.md) and the 16/32-bit helpers
  plant          sim_table's axis plant, stepped exactly
  state_machine  the PDS finite state automaton (CiA 402-2), and the
                 loss-of-communication reaction (6007h)
  drive          one drive: the objects, the mode loops, the statusword
  faults         injected reply faults on pymodbus's connection handler
  commands       the fault-injection commands (stdin, control socket)
  main           the command line, the drive's clock and the server
"""
