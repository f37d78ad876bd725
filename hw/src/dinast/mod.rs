//! Dinast IPA-1110 over USB: the transport, the frame decoder, the driver and its emulator.
