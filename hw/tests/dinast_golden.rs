//! Golden fixtures of the Dinast IPA-1110, written by hand from the documented protocol
//! (the vendor's USB protocol and raw-to-distance model as `hw/src/dinast/` documents
//! them), not produced by the code under test:
//! a bulk packet with a few hand-placed raw pixels, decoded by the driver, and the distances
//! and points of those pixels computed by hand from the documented raw-to-distance model;
//! and the control transfers the driver issues, checked against the documented requests.
#![cfg(feature = "dinast")]

use nbv_core::rig::DepthCameraSpec;
use nbv_hw::dinast::{
    ControlSetup, DinastCamera, DinastConfig, DinastTransport, FrameDecoder, TransportError,
    point_from_raw, range_from_raw,
};
use std::time::Duration;

/// The Dinast's public USB protocol: "A sync marker `AA AA 44 44 BB BB 77 77` starts a packet".
const MARKER: [u8; 8] = [0xAA, 0xAA, 0x44, 0x44, 0xBB, 0xBB, 0x77, 0x77];
/// The Dinast's public USB protocol: "Each bulk read is 2×76800 + 512 bytes".
const PACKET_BYTES: usize = 154_112;

/// One hand-placed raw pixel of the first (depth-coded) image: column x, row y, raw value
/// p, its byte offset from the start of the marker, and what the documented model gives.
struct Pixel {
    x: usize,
    y: usize,
    p: u8,
    /// "image data begins 512 bytes after [the marker]; two 320×240 8-bit images follow":
    /// 512 + 320·y + x (row-major; the first image is the depth-coded one).
    offset: usize,
    /// dist/500, metres along the pixel's ray; `None` where the model gives no point.
    range_m: Option<f64>,
    /// (x, y, z) metres, optical frame; `None` where invalid (z outside [0.02, 0.8] m).
    point: Option<[f64; 3]>,
}

/// Hand computation (the Dinast's public driver, "Raw value p at pixel (x, y) …"), r = |(x, y) −
/// (160, 120)|, A = −2e-5·r³ + 0.004·r² + 0.1719·r + 350.03, B = −2e-9·r³ + 3e-7·r² − 1e-5·r
/// − 0.01, K = 7e-7·r³ − 1e-4·r² + 0.004·r + 0.9985, dist = (ln(p/A)/B − 0.1·y)·K·1.5,
/// θ = 64°·r/160, z = dist·cos θ/500, (x, y) = dist·sin θ·(dx, dy)/r/500:
const PIXELS: [Pixel; 5] = [
    // r = 0: A = 350.03, B = −0.01, K = 0.9985; ln(100/350.03)/B = 125.28487;
    // dist = (125.28487 − 12)·0.9985·1.5 = 169.67241 → 0.3393448 m straight ahead.
    Pixel {
        x: 160,
        y: 120,
        p: 100,
        offset: 39_072,
        range_m: Some(0.339_344_8),
        point: Some([0.0, 0.0, 0.339_344_8]),
    },
    // r = 50 (a 30-40-50 triangle): A = 366.125, B = −0.01, K = 1.036, θ = 20°;
    // ln(60/366.125)/B = 180.86302; dist = (180.86302 − 15)·1.036·1.5 = 257.75114
    // → 0.5155023 m; z = ·cos 20°, x = ·sin 20°·0.8, y = ·sin 20°·0.6.
    Pixel {
        x: 200,
        y: 150,
        p: 60,
        offset: 48_712,
        range_m: Some(0.515_502_3),
        point: Some([0.141_049_7, 0.105_787_3, 0.484_413_7]),
    },
    // r = 120 (72-96-120): A = 393.698, B = −0.010336, K = 1.2481, θ = 48°;
    // ln(40/393.698)/B = 221.23691; dist = (221.23691 − 19.2)·1.2481·1.5 = 378.24339
    // → 0.7564868 m; x = ·sin 48°·0.8, y = ·sin 48°·0.6, z = ·cos 48°.
    Pixel {
        x: 256,
        y: 192,
        p: 40,
        offset: 62_208,
        range_m: Some(0.756_486_8),
        point: Some([0.449_743_4, 0.337_307_5, 0.506_188_5]),
    },
    // r = 120, y = 120, p = 5: ln(5/393.698)/B = 422.42127; dist = (422.42127 − 12)·1.2481·1.5
    // = 768.37017 → 1.5367403 m; z = 1.0282800 m > 0.8: a range, but no valid point.
    Pixel {
        x: 40,
        y: 120,
        p: 5,
        offset: 38_952,
        range_m: Some(1.536_740_3),
        point: None,
    },
    // p = 0: no return (ln 0 is undefined): neither range nor point.
    Pixel {
        x: 0,
        y: 0,
        p: 0,
        offset: 512,
        range_m: None,
        point: None,
    },
];

/// Offset of a hand-placed amplitude byte at (160, 120) in the second image:
/// 512 + 76 800 + 320·120 + 160. It must not change any depth.
const AMPLITUDE_OFFSET: usize = 115_872;

/// The packet, written byte by byte from the documented layout.
fn golden_packet() -> Vec<u8> {
    let mut packet = vec![0u8; PACKET_BYTES];
    packet[..8].copy_from_slice(&MARKER);
    for pixel in &PIXELS {
        packet[pixel.offset] = pixel.p;
    }
    packet[AMPLITUDE_OFFSET] = 0xEE;
    packet
}

/// Checks a decoded depth image against the hand-placed pixels and the hand computation.
fn check_pixels(depth_code_at: impl Fn(usize, usize) -> Option<u8>) {
    for pixel in &PIXELS {
        let (x, y) = (pixel.x, pixel.y);
        assert_eq!(
            depth_code_at(x, y),
            Some(pixel.p),
            "raw value at ({x}, {y})"
        );
        let range = range_from_raw(x, y, pixel.p);
        match (range, pixel.range_m) {
            (Some(got), Some(want)) => {
                assert!(
                    (got - want).abs() < 1e-6,
                    "({x}, {y}): range {got} vs {want}"
                )
            }
            (got, want) => assert_eq!(got, want, "({x}, {y}): range"),
        }
        let point = point_from_raw(x, y, pixel.p);
        match (point, pixel.point) {
            (Some(got), Some(want)) => {
                for axis in 0..3 {
                    assert!(
                        (got[axis] - want[axis]).abs() < 1e-6,
                        "({x}, {y}): point {got} vs {want:?}"
                    );
                }
            }
            (None, None) => {}
            (got, want) => panic!("({x}, {y}): point {got:?} vs {want:?}"),
        }
    }
    // Every pixel not placed by hand is 0 (no return), the amplitude byte included.
    assert_eq!(depth_code_at(161, 120), Some(0));
    assert_eq!(depth_code_at(319, 239), Some(0));
}

#[test]
fn a_hand_written_packet_decodes_to_the_documented_distances() {
    // Garbage first, including a partial marker, then the packet across three reads.
    let mut stream = vec![0x00, 0x11, 0xAA, 0xAA, 0x44, 0x44, 0xBB, 0x13];
    stream.extend(golden_packet());
    let mut decoder = FrameDecoder::new();
    for chunk in [&stream[..5], &stream[5..70_000], &stream[70_000..]] {
        assert!(decoder.pop_frame().is_none());
        decoder.push(chunk);
    }
    let frame = decoder.pop_frame().expect("the packet decodes");
    assert_eq!(frame.depth_code.len(), 320 * 240);
    assert_eq!(frame.amplitude.len(), 320 * 240);
    assert_eq!(frame.amplitude[320 * 120 + 160], 0xEE);
    check_pixels(|x, y| frame.depth_code_at(x, y));
    assert_eq!(decoder.stats().skipped_bytes, 8);
}

/// A USB device scripted by hand: answers the documented control requests and serves the
/// golden packet across two bulk reads; records every transfer.
struct ScriptedDevice {
    log: Vec<String>,
    reads: usize,
}

/// The Dinast's public USB protocol: "start 0xC7 and stop 0xC8 (host→device, bmRequestType 0x40, wValue
/// 0x01, wIndex 0, 1 byte); firmware version 0xDC (device→host 0xC0, wValue 0x02, wIndex
/// 0x08, 21 bytes)", "Vendor control transfers, 1000 ms timeout".
fn documented(setup: &ControlSetup) -> &'static str {
    match (setup.request_type, setup.request, setup.value, setup.index) {
        (0x40, 0xC7, 0x01, 0) => "start",
        (0x40, 0xC8, 0x01, 0) => "stop",
        (0xC0, 0xDC, 0x02, 0x08) => "firmware",
        _ => "undocumented",
    }
}

impl DinastTransport for ScriptedDevice {
    fn control_out(
        &mut self,
        setup: ControlSetup,
        data: &[u8],
        timeout: Duration,
    ) -> Result<usize, TransportError> {
        self.log.push(format!(
            "out {} {} bytes {} ms",
            documented(&setup),
            data.len(),
            timeout.as_millis()
        ));
        Ok(data.len())
    }

    fn control_in(
        &mut self,
        setup: ControlSetup,
        buf: &mut [u8],
        timeout: Duration,
    ) -> Result<usize, TransportError> {
        self.log.push(format!(
            "in {} {} bytes {} ms",
            documented(&setup),
            buf.len(),
            timeout.as_millis()
        ));
        let answer = b"IPA-1110 FW 2.1\0\0\0\0\0\0";
        let n = answer.len().min(buf.len());
        buf[..n].copy_from_slice(&answer[..n]);
        Ok(n)
    }

    fn bulk_read(&mut self, buf: &mut [u8], _timeout: Duration) -> Result<usize, TransportError> {
        self.log.push(format!("bulk {} bytes", buf.len()));
        // The packet straddles the two reads: 1000 bytes of the previous frame's tail, then
        // the packet's head; then the rest of the packet.
        let mut stream = vec![0x5A; 1000];
        stream.extend(golden_packet());
        let part = match self.reads {
            0 => &stream[..PACKET_BYTES],
            1 => &stream[PACKET_BYTES..],
            _ => &[][..],
        };
        self.reads += 1;
        buf[..part.len()].copy_from_slice(part);
        Ok(part.len())
    }
}

#[test]
fn the_driver_speaks_the_documented_control_requests_and_decodes_the_golden_packet() {
    let mut device = ScriptedDevice {
        log: Vec::new(),
        reads: 0,
    };
    {
        let mut camera =
            DinastCamera::open(&mut device, DinastConfig::new(DepthCameraSpec::ipa1110())).unwrap();
        assert_eq!(camera.firmware_version(), "IPA-1110 FW 2.1");
        let (_, frame) = camera.capture_raw().unwrap();
        check_pixels(|x, y| frame.depth_code_at(x, y));
    }
    assert_eq!(
        device.log,
        [
            "in firmware 21 bytes 1000 ms",
            "out start 1 bytes 1000 ms",
            "bulk 154112 bytes",
            "bulk 154112 bytes",
            "out stop 1 bytes 1000 ms",
        ]
    );
}
