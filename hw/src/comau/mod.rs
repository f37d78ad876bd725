//! Comau C4G through a PDL2 server program: the client and its emulator.
