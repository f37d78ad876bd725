//! SICK LMS400 over Ethernet: CoLa binary framing, the driver and its emulator.

mod client;
mod command;
mod config;
mod emulator;
mod faults;
mod frame;
mod line_mapping;
mod link;
mod reply;
mod scan_config;
mod telegram;

pub use client::Lms400Scanner;
pub use command::{
    Command, CommandError, DataMode, FILTER_EDGE, FILTER_MEAN, FILTER_MEDIAN, FILTER_RANGE,
    SERVICE_LEVEL, SERVICE_PASSWORD,
};
pub use config::Lms400Config;
pub use emulator::{EmulatorError, Lms400Emulator};
pub use faults::Lms400Faults;
pub use frame::{
    FRAME_OVERHEAD, FrameDecoder, FrameError, MAX_FRAME_LEN, MAX_PAYLOAD_LEN, STX, checksum,
    encode_frame,
};
pub use line_mapping::{
    EMULATED_DISTANCE_SCALING, LineMappingError, TelegramSettings, TimestampUnwrapper,
    line_to_telegram, telegram_to_line,
};
pub use reply::{Reply, ReplyError, SopasError};
pub use scan_config::{
    DEVICE_ANGLE_RANGE_DEG, DEVICE_CENTRE_DEG, ScanConfig, ScanConfigAnswer, ScanConfigError,
    device_to_spec_angle, spec_to_device_angle,
};
pub use telegram::{
    MAX_POINTS, MeasurementPoint, MeasurementTelegram, TELEGRAM_MARKER, TelegramError,
};
