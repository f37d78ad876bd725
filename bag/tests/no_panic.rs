//! The stand-in for the `bag_file` fuzz target: arbitrary bytes, and a real bag with bytes
//! flipped, inserted or cut, given to `BagReader` as a bare .mcap never panic; whatever
//! opens can be read through every helper without panicking.

mod common;

use nbv_bag::BagReader;
use nbv_bag::messages::*;
use proptest::prelude::*;

fn exercise(bytes: &[u8]) {
    let Ok(bag) = BagReader::from_mcap_bytes("fuzz.mcap", bytes) else {
        return;
    };
    let topics: Vec<String> = bag.topics().map(|t| t.name.clone()).collect();
    for t in &topics {
        if let Ok(msgs) = bag.messages(t) {
            for m in msgs {
                let _ = TFMessage::decode(&m.data);
                let _ = PointCloud2::decode(&m.data);
                let _ = MarkerArray::decode(&m.data);
            }
        }
        let _ = bag.point_clouds(t);
        let _ = bag.read::<CameraInfo>(t);
        let _ = bag.read::<JointState>(t);
        let _ = bag.read::<Image>(t);
    }
    if let Ok(tf) = bag.tf_buffer() {
        let frames: Vec<String> = tf.frames().iter().map(|s| (*s).to_owned()).collect();
        for a in &frames {
            for b in &frames {
                let _ = tf.lookup(a, b, 0);
            }
        }
    }
}

fn sample_bag() -> Vec<u8> {
    let tmp = tempfile::tempdir().unwrap();
    let dir = common::write_every_type(tmp.path(), "seed");
    std::fs::read(dir.join("seed_0.mcap")).unwrap()
}

/// The same messages in uncompressed chunks (as rosbags writes them).
fn sample_uncompressed() -> Vec<u8> {
    let seed = sample_bag();
    let bag = BagReader::from_mcap_bytes("seed.mcap", &seed).unwrap();
    let mut buf = std::io::Cursor::new(Vec::new());
    let mut w = mcap::WriteOptions::new()
        .profile("ros2")
        .compression(None)
        .create(&mut buf)
        .unwrap();
    for t in bag.topics() {
        let s = w.add_schema(&t.type_name, "ros2msg", b"").unwrap();
        let c = w
            .add_channel(s, &t.name, "cdr", &std::collections::BTreeMap::new())
            .unwrap();
        for m in bag.messages(&t.name).unwrap() {
            let header = mcap::records::MessageHeader {
                channel_id: c,
                sequence: 0,
                log_time: m.log_time_ns,
                publish_time: m.log_time_ns,
            };
            w.write_to_known_channel(&header, &m.data).unwrap();
        }
    }
    w.finish().unwrap();
    drop(w);
    buf.into_inner()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn arbitrary_bytes(mut b in proptest::collection::vec(any::<u8>(), 0..2000), magic in any::<bool>()) {
        if magic && b.len() >= 8 {
            b[..8].copy_from_slice(b"\x89MCAP0\r\n");
        }
        exercise(&b);
    }

    #[test]
    fn mutated_bag(
        edits in proptest::collection::vec((any::<prop::sample::Index>(), any::<u8>(), 0u8..3), 1..6),
        compressed in any::<bool>(),
    ) {
        let mut b = if compressed { sample_bag() } else { sample_uncompressed() };
        for (at, byte, kind) in edits {
            let i = at.index(b.len().max(1));
            match kind {
                0 => b[i] ^= byte | 1,
                1 => b.insert(i, byte),
                _ => b.truncate(i.max(8)),
            }
        }
        exercise(&b);
    }
}

#[test]
fn the_unmutated_seed_opens() {
    let b = sample_bag();
    let bag = BagReader::from_mcap_bytes("seed.mcap", &b).unwrap();
    assert_eq!(bag.topics().count(), 8);
    exercise(&b);
    let u = sample_uncompressed();
    assert_eq!(
        BagReader::from_mcap_bytes("u.mcap", &u)
            .unwrap()
            .topics()
            .count(),
        8
    );
    exercise(&u);
}
