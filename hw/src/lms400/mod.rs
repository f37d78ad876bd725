//! SICK LMS400 over Ethernet: CoLa binary framing, the driver and its emulator.

mod frame;
mod telegram;

pub use frame::{
    FRAME_OVERHEAD, FrameDecoder, FrameError, MAX_FRAME_LEN, MAX_PAYLOAD_LEN, STX, checksum,
    encode_frame,
};
pub use telegram::{
    MAX_POINTS, MeasurementPoint, MeasurementTelegram, TELEGRAM_MARKER, TelegramError,
};
