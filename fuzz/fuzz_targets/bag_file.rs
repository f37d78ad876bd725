//! `BagReader::from_mcap_bytes` on arbitrary bytes (a bare rosbag2 .mcap): never panics;
//! errors name the file; a bag that opens can be read through every helper (messages,
//! typed decoding, point clouds, the tf buffer and its lookups) without panicking.
#![no_main]

use libfuzzer_sys::fuzz_target;
use nbv_bag::BagReader;
use nbv_bag::messages::{CameraInfo, Image, JointState, MarkerArray, RosString};

fuzz_target!(|data: &[u8]| {
    let bag = match BagReader::from_mcap_bytes("fuzz.mcap", data) {
        Ok(bag) => bag,
        Err(e) => {
            assert!(e.to_string().starts_with("fuzz.mcap"), "{e}");
            return;
        }
    };
    let topics: Vec<String> = bag.topics().map(|t| t.name.clone()).collect();
    for t in &topics {
        if let Ok(msgs) = bag.messages(t) {
            let times: Vec<u64> = msgs.map(|m| m.log_time_ns).collect();
            assert!(times.windows(2).all(|w| w[0] <= w[1]), "log-time order");
        }
        let _ = bag.point_clouds(t);
        let _ = bag.read::<CameraInfo>(t);
        let _ = bag.read::<JointState>(t);
        let _ = bag.read::<Image>(t);
        let _ = bag.read::<MarkerArray>(t);
        let _ = bag.read::<RosString>(t);
    }
    if let Ok(tf) = bag.tf_buffer() {
        let frames: Vec<String> = tf.frames().iter().map(|s| (*s).to_owned()).collect();
        for a in frames.iter().take(8) {
            for b in frames.iter().take(8) {
                let _ = tf.lookup(a, b, 0);
            }
        }
    }
});
