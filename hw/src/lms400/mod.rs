//! SICK LMS400 over Ethernet: CoLa binary framing, the driver and its emulator.
