//! `Robot::from_urdf_str` on arbitrary text: XML parsing, the serial-chain checks and the
//! IK set-up never panic, and errors name the source (`<string>`).
#![no_main]

use libfuzzer_sys::fuzz_target;
use nbv_core::kinematics::Robot;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    if let Err(e) = Robot::from_urdf_str(&text) {
        assert!(e.to_string().starts_with("<string>: "), "{e}");
    }
});
