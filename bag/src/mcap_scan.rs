//! Pulls the header profile, the channels and the messages out of MCAP bytes, checking
//! every CRC, without letting malformed input panic inside `mcap` 0.26.0.
//!
//! Two of that crate's paths panic on crafted input (found by the `bag_file` fuzz target):
//! - `parse_record` of an Attachment record shorter than its own header slices out of
//!   bounds (`read.rs:176`); `MessageReader`, `MessageStream` and `Summary::read` parse
//!   every record they meet. This module never parses attachments (a bag needs none) and
//!   drives `sans_io::LinearReader` itself, parsing only schemas, channels and messages.
//! - `LinearReader` subtracts a record's length from what is left of an *uncompressed*
//!   chunk without a check (`sans_io/linear_reader.rs:745`): overflow. The top-level
//!   records are framed here first and each uncompressed chunk's records are checked to fit.
//!
//! A decoded record may be at most `max(256 MiB, 64 × file size)` bytes, so a corrupt
//! length cannot ask for an unbounded allocation.

use std::borrow::Cow;
use std::collections::BTreeMap;

use mcap::read::ChannelAccumulator;
use mcap::records::{Record, op};
use mcap::sans_io::{LinearReadEvent, LinearReader, LinearReaderOptions};
use mcap::{McapError, parse_record};

/// The MCAP magic.
const MAGIC: &[u8; 8] = b"\x89MCAP0\r\n";
/// Opcode and length of a record.
const RECORD_PREFIX: usize = 9;

/// A channel of the file.
#[derive(Debug, Clone)]
pub(crate) struct ScannedChannel {
    pub topic: String,
    pub schema_name: String,
    pub message_encoding: String,
    pub metadata: BTreeMap<String, String>,
}

/// A message of the file, in file order.
#[derive(Debug)]
pub(crate) struct ScannedMessage {
    pub topic: String,
    pub log_time: u64,
    pub data: Vec<u8>,
}

/// What the scan found.
#[derive(Debug, Default)]
pub(crate) struct Scan {
    pub profile: String,
    /// By channel id, every channel of the data and summary sections.
    pub channels: BTreeMap<u16, ScannedChannel>,
    pub messages: Vec<ScannedMessage>,
}

/// Top-level records after the magic as `(opcode, body)`. A record that runs past the end
/// of the file comes last, with the bytes there are (the linear reader streams a chunk's
/// records before it notices the file is short, so such a chunk must be checked too).
fn top_level_records(bytes: &[u8]) -> impl Iterator<Item = (u8, &[u8])> {
    let mut rest = bytes.get(MAGIC.len()..).unwrap_or_default();
    std::iter::from_fn(move || {
        let (prefix, after) = rest.split_at_checked(RECORD_PREFIX)?;
        let len = u64::from_le_bytes(prefix[1..].try_into().ok()?);
        let len = usize::try_from(len).unwrap_or(usize::MAX).min(after.len());
        let (body, next) = after.split_at(len);
        rest = next;
        Some((prefix[0], body))
    })
}

/// The profile of the header record, which must follow the magic.
fn profile(bytes: &[u8]) -> Result<String, McapError> {
    if bytes.get(..MAGIC.len()) != Some(&MAGIC[..]) {
        return Err(McapError::BadMagic);
    }
    match top_level_records(bytes).next() {
        Some((op::HEADER, body)) => match parse_record(op::HEADER, body)? {
            Record::Header(h) => Ok(h.profile),
            _ => Err(McapError::UnexpectedEof),
        },
        _ => Err(McapError::UnexpectedEof),
    }
}

/// Every record of every uncompressed chunk fits in its chunk.
fn check_uncompressed_chunks(bytes: &[u8]) -> Result<(), McapError> {
    for (opcode, body) in top_level_records(bytes) {
        if opcode == op::FOOTER {
            break;
        }
        if opcode != op::CHUNK {
            continue;
        }
        let Record::Chunk { header, data } = parse_record(op::CHUNK, body)? else {
            continue;
        };
        if !header.compression.is_empty() {
            continue;
        }
        let mut rest: &[u8] = &data;
        while !rest.is_empty() {
            let fits = rest
                .get(1..RECORD_PREFIX)
                .and_then(|b| <[u8; 8]>::try_from(b).ok())
                .map(u64::from_le_bytes)
                .and_then(|len| usize::try_from(len).ok())
                .filter(|&len| len <= rest.len() - RECORD_PREFIX);
            let Some(len) = fits else {
                return Err(McapError::UnexpectedEoc);
            };
            rest = &rest[RECORD_PREFIX + len..];
        }
    }
    Ok(())
}

/// Scans a whole MCAP file.
pub(crate) fn scan(bytes: &[u8]) -> Result<Scan, McapError> {
    let mut out = Scan {
        profile: profile(bytes)?,
        ..Scan::default()
    };
    check_uncompressed_chunks(bytes)?;
    let limit = bytes.len().saturating_mul(64).max(256 << 20);
    let mut reader = LinearReader::new_with_options(
        LinearReaderOptions::default()
            .with_record_length_limit(limit)
            .with_validate_chunk_crcs(true)
            .with_validate_data_section_crc(true)
            .with_validate_summary_section_crc(true),
    );
    let mut channels = ChannelAccumulator::default();
    let mut past_data_end = false;
    let mut rest = bytes;
    while let Some(event) = reader.next_event() {
        let (opcode, data) = match event? {
            LinearReadEvent::ReadRequest(need) => {
                let n = need.min(rest.len());
                reader.insert(n).copy_from_slice(&rest[..n]);
                reader.notify_read(n);
                rest = &rest[n..];
                continue;
            }
            LinearReadEvent::Record { opcode, data } => (opcode, data),
        };
        match opcode {
            op::DATA_END => past_data_end = true,
            op::SCHEMA => {
                if let Record::Schema { header, data } = parse_record(opcode, data)? {
                    channels.add_schema(header, Cow::Owned(data.into_owned()))?;
                }
            }
            op::CHANNEL => {
                if let Record::Channel(c) = parse_record(opcode, data)? {
                    let id = c.id;
                    channels.add_channel(c)?;
                    if let Some(c) = channels.get(id) {
                        out.channels.entry(id).or_insert_with(|| ScannedChannel {
                            topic: c.topic.clone(),
                            schema_name: c
                                .schema
                                .as_ref()
                                .map(|s| s.name.clone())
                                .unwrap_or_default(),
                            message_encoding: c.message_encoding.clone(),
                            metadata: c.metadata.clone(),
                        });
                    }
                }
            }
            op::MESSAGE if !past_data_end => {
                if let Record::Message { header, data } = parse_record(opcode, data)? {
                    let channel =
                        channels
                            .get(header.channel_id)
                            .ok_or(McapError::UnknownChannel(
                                header.sequence,
                                header.channel_id,
                            ))?;
                    out.messages.push(ScannedMessage {
                        topic: channel.topic.clone(),
                        log_time: header.log_time,
                        data: data.into_owned(),
                    });
                }
            }
            _ => {}
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn short_attachment_is_skipped_not_parsed() {
        // Header, then an attachment record of 4 bytes, then a truncated file.
        let mut b = MAGIC.to_vec();
        b.push(op::HEADER);
        b.extend_from_slice(&12u64.to_le_bytes());
        b.extend_from_slice(&4u32.to_le_bytes());
        b.extend_from_slice(b"ros2");
        b.extend_from_slice(&0u32.to_le_bytes());
        b.push(op::ATTACHMENT);
        b.extend_from_slice(&4u64.to_le_bytes());
        b.extend_from_slice(&[0, 0, 0, 0]);
        assert_eq!(profile(&b).unwrap(), "ros2");
        assert!(scan(&b).is_err());
    }

    #[test]
    fn overrunning_record_in_uncompressed_chunk() {
        let mut buf = std::io::Cursor::new(Vec::new());
        let mut w = mcap::WriteOptions::new()
            .profile("ros2")
            .compression(None)
            .create(&mut buf)
            .unwrap();
        let s = w.add_schema("a/msg/B", "ros2msg", b"").unwrap();
        let c = w.add_channel(s, "/t", "cdr", &BTreeMap::new()).unwrap();
        let header = mcap::records::MessageHeader {
            channel_id: c,
            sequence: 0,
            log_time: 1,
            publish_time: 1,
        };
        w.write_to_known_channel(&header, &[0xAB; 16]).unwrap();
        w.finish().unwrap();
        drop(w);
        let good = buf.into_inner();
        assert_eq!(scan(&good).unwrap().messages.len(), 1);
        // The message record's length inside the chunk: find the 16 0xAB bytes, step back
        // over header (22 bytes) and length (8).
        let at = good.windows(16).position(|w| w == [0xAB; 16]).unwrap() - 22 - 8;
        let mut bad = good.clone();
        bad[at..at + 8].copy_from_slice(&1_000u64.to_le_bytes());
        assert!(matches!(scan(&bad), Err(McapError::UnexpectedEoc)));
    }
}
