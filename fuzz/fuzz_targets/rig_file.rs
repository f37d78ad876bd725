//! `RigFile::parse` on arbitrary text, then `mount_sensors` on the Comau model: never
//! panic, and every error names the file (and, for hand-eye mounts, the key).
#![no_main]

use std::path::Path;
use std::sync::OnceLock;

use libfuzzer_sys::fuzz_target;
use nbv_core::kinematics::Robot;
use nbv_hw::rig_file::RigFile;

fn robot() -> &'static Robot {
    static ROBOT: OnceLock<Robot> = OnceLock::new();
    ROBOT.get_or_init(|| nbv_core::kinematics::comau_smart_six().expect("the Comau URDF loads"))
}

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    match RigFile::parse(&text, Path::new("fuzz.toml")) {
        Ok(rig) => {
            let mut robot = robot().clone();
            if let Err(e) = rig.mount_sensors(&mut robot, "lms400", "dinast") {
                assert!(e.to_string().starts_with("fuzz.toml: "), "{e}");
            }
        }
        Err(e) => assert!(e.to_string().starts_with("fuzz.toml: "), "{e}"),
    }
});
