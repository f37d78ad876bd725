//! The C4G line protocol's parsers on arbitrary text: `Reply::parse` and `Command::parse`
//! never panic, and whatever parses prints back to a line that parses to the same value.
#![no_main]

use libfuzzer_sys::fuzz_target;
use nbv_hw::comau::protocol::{Command, Reply};

fuzz_target!(|data: &[u8]| {
    let line = String::from_utf8_lossy(data);
    if let Ok(reply) = Reply::parse(&line) {
        let again = Reply::parse(&reply.to_string());
        assert!(again.is_ok(), "{reply} does not parse back");
    }
    if let Ok(command) = Command::parse(&line) {
        let again = Command::parse(&command.to_string());
        assert!(again.is_ok(), "{command} does not parse back");
    }
});
