//! The Dinast driver against the emulated device, backed by fake cameras that see a plane:
//! depth round trip (pinhole → raw bytes → pinhole), valid share, time stamps, and faults.
#![cfg(feature = "dinast")]

use nalgebra::Vector3;
use nbv_core::rig::{DepthCamera, DepthCameraSpec, DepthFrame, RigError};
use nbv_hw::dinast::{
    DinastCamera, DinastConfig, DinastEmulator, DinastFaults, EmulatedTransport, channel_transport,
    range_quantisation_bound, raw_position,
};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread;
use std::time::Duration;

/// Largest angle between a pinhole pixel's ray and the ray whose depth it ends up with.
///
/// The driver picks the raw pixel R nearest to pinhole pixel P: at most half a raw pixel
/// diagonal away, and one raw pixel spans at most 0.4° in any direction (radially 64°/160
/// px, tangentially 0.4°·sin θ/θ ≤ 0.4°), so angle(P, R) ≤ ε = 0.4°/√2. The emulator gives R
/// the depth of P', the pinhole grid point nearest to R in pinhole coordinates (clamped to
/// the image at its border), so |R − P'| ≤ |R − P| in pinhole pixels, and inside the image
/// as well ≤ half a pinhole diagonal. Pinhole pixels per radian range from f/cos φ to f/cos² φ
/// (tangential, radial), so converting pixels back to an angle costs at most a factor
/// 1/cos φ_max (φ_max the corner's angle): angle(R, P') ≤ ε/cos φ_max. In total
/// δ = ε·(1 + 1/cos φ_max).
fn resampling_angle(spec: &DepthCameraSpec) -> f64 {
    let epsilon = 0.4f64.to_radians() * std::f64::consts::FRAC_1_SQRT_2;
    let corner = spec.pixel_ray(0, 0);
    let cos_corner = 1.0 / corner.norm();
    epsilon * (1.0 + 1.0 / cos_corner)
}

/// Safety net of every wait whose outcome is not a timeout: generous, so that no test
/// depends on how fast this machine is; a test that hangs fails after it.
const SAFETY: Duration = Duration::from_secs(60);

fn spec() -> DepthCameraSpec {
    DepthCameraSpec::ipa1110()
}

/// A fake camera that sees the plane `normal · X = offset` (sensor frame), NaN where the
/// ray misses it or the range is outside the spec's.
#[derive(Clone)]
struct PlaneCamera {
    spec: DepthCameraSpec,
    normal: Vector3<f64>,
    offset: f64,
}

impl PlaneCamera {
    fn facing(z: f64) -> Self {
        Self {
            spec: spec(),
            normal: Vector3::z(),
            offset: z,
        }
    }

    /// A plane through (0, 0, `z`) tilted by `degrees` about the camera's y axis.
    fn tilted(z: f64, degrees: f64) -> Self {
        let a = degrees.to_radians();
        let normal = Vector3::new(a.sin(), 0.0, a.cos());
        Self {
            spec: spec(),
            normal,
            offset: normal.z * z,
        }
    }

    fn range_along(&self, unit_ray: &Vector3<f64>) -> Option<f64> {
        let facing = self.normal.dot(unit_ray);
        (facing > 0.0).then(|| self.offset / facing)
    }
}

impl DepthCamera for PlaneCamera {
    fn spec(&self) -> &DepthCameraSpec {
        &self.spec
    }

    fn capture(&mut self) -> Result<DepthFrame, RigError> {
        let [min, max] = self.spec.range;
        let (width, height) = (self.spec.width, self.spec.height);
        let mut depth = Vec::with_capacity(width * height);
        for v in 0..height {
            for u in 0..width {
                let ray = self.spec.pixel_ray(u, v);
                let z = match self.range_along(&ray.normalize()) {
                    Some(range) if (min..=max).contains(&range) => (range / ray.norm()) as f32,
                    _ => f32::NAN,
                };
                depth.push(z);
            }
        }
        Ok(DepthFrame {
            time: 0.0,
            width,
            height,
            depth,
            truth: None,
        })
    }
}

fn emulated(camera: PlaneCamera, faults: DinastFaults) -> EmulatedTransport {
    let device = DinastEmulator::new("IPA-1110 emu").with_faults(faults);
    EmulatedTransport::new(device, Box::new(camera))
}

/// Round-trip statistics of one decoded frame against the fake's.
struct Agreement {
    compared: usize,
    decoded_valid_share: f64,
    max_error_mm: f64,
    mean_error_mm: f64,
}

/// Compares the decoded frame with the fake's depths, asserting the derived bound at every
/// pixel where both are valid.
///
/// Bound: the decoded depth is `(range' ± q)·cos φ`, with φ the pinhole ray's angle, range'
/// the plane's range along a ray at most `resampling_angle` (δ) away, and q the 8-bit
/// quantisation bound ([`range_quantisation_bound`]) at the raw pixel, taken at the far
/// end of range' (q grows with range). For a plane at distance d with incidence angle i,
/// range' ∈ [d / cos(max(i − δ, 0)), d / cos(i + δ)].
fn compare(plane: &PlaneCamera, decoded: &DepthFrame, truth: &DepthFrame) -> Agreement {
    let spec = &plane.spec;
    let delta = resampling_angle(spec);
    let (mut compared, mut decoded_valid, mut truth_valid) = (0, 0, 0);
    let (mut max_error, mut sum_error) = (0f64, 0f64);
    for v in 0..spec.height {
        for u in 0..spec.width {
            let i = v * spec.width + u;
            let (got, want) = (decoded.depth[i], truth.depth[i]);
            if want.is_finite() {
                truth_valid += 1;
                if got.is_finite() {
                    decoded_valid += 1;
                }
            }
            if !(got.is_finite() && want.is_finite()) {
                continue;
            }
            let ray = spec.pixel_ray(u, v).normalize();
            let incidence = plane.normal.dot(&ray).clamp(-1.0, 1.0).acos();
            let near = plane.offset / (incidence - delta).max(0.0).cos();
            let far = plane.offset / (incidence + delta).cos();
            let [x, y] = raw_position(&ray).unwrap();
            let (x, y) = (x.round() as usize, y.round() as usize);
            let q = range_quantisation_bound(x, y, far).unwrap();
            let slack = 1e-6; // f32 depths
            let (low, high) = ((near - q) * ray.z - slack, (far + q) * ray.z + slack);
            let got = f64::from(got);
            assert!(
                (low..=high).contains(&got),
                "pixel ({u}, {v}): decoded {got} outside [{low}, {high}] (fake {want})"
            );
            let error = (got - f64::from(want)).abs();
            max_error = max_error.max(error);
            sum_error += error;
            compared += 1;
        }
    }
    Agreement {
        compared,
        decoded_valid_share: decoded_valid as f64 / truth_valid.max(1) as f64,
        max_error_mm: 1e3 * max_error,
        mean_error_mm: 1e3 * sum_error / compared.max(1) as f64,
    }
}

fn round_trip(plane: PlaneCamera) -> Agreement {
    let truth = plane.clone().capture().unwrap();
    let mut transport = emulated(plane.clone(), DinastFaults::default());
    let mut camera = DinastCamera::open(&mut transport, DinastConfig::new(spec())).unwrap();
    let decoded = camera.capture().unwrap();
    assert_eq!((decoded.width, decoded.height), (320, 240));
    assert!(decoded.truth.is_none());
    compare(&plane, &decoded, &truth)
}

#[test]
fn plane_facing_the_camera_round_trips_within_the_derived_bound() {
    let agreement = round_trip(PlaneCamera::facing(0.5));
    eprintln!(
        "plane z = 0.5 m: {} pixels, max error {:.2} mm, mean {:.2} mm, valid share {:.4}",
        agreement.compared,
        agreement.max_error_mm,
        agreement.mean_error_mm,
        agreement.decoded_valid_share
    );
    // Every pinhole pixel sees the plane (ranges 0.5..0.72 m).
    assert_eq!(agreement.compared, 320 * 240);
    assert_eq!(agreement.decoded_valid_share, 1.0);
    assert!(agreement.mean_error_mm < 3.0, "{}", agreement.mean_error_mm);
}

#[test]
fn tilted_plane_round_trips_within_the_derived_bound() {
    let plane = PlaneCamera::tilted(0.4, 30.0);
    let agreement = round_trip(plane);
    eprintln!(
        "plane tilted 30° through z = 0.4 m: {} pixels, max error {:.2} mm, mean {:.2} mm, \
         valid share {:.4}",
        agreement.compared,
        agreement.max_error_mm,
        agreement.mean_error_mm,
        agreement.decoded_valid_share
    );
    assert!(agreement.compared > 50_000, "{}", agreement.compared);
    assert!(
        agreement.decoded_valid_share > 0.98,
        "{}",
        agreement.decoded_valid_share
    );
    assert!(agreement.mean_error_mm < 4.0, "{}", agreement.mean_error_mm);
}

#[test]
fn open_reads_the_firmware_and_drop_stops_streaming() {
    let mut transport = emulated(PlaneCamera::facing(0.5), DinastFaults::default());
    let mut config = DinastConfig::new(spec());
    config.clock_offset = 100.0;
    {
        let mut camera = DinastCamera::open(&mut transport, config).unwrap();
        assert_eq!(camera.firmware_version(), "IPA-1110 emu");
        let first = camera.capture().unwrap();
        let second = camera.capture().unwrap();
        assert!(first.time >= 100.0 && second.time >= first.time);
    }
    assert!(!transport.emulator.is_started());
    assert_eq!(transport.emulator.bulk_reads(), 2);
}

#[test]
fn close_stops_streaming() {
    let mut transport = emulated(PlaneCamera::facing(0.5), DinastFaults::default());
    let camera = DinastCamera::open(&mut transport, DinastConfig::new(spec())).unwrap();
    camera.close().unwrap();
    assert!(!transport.emulator.is_started());
}

#[test]
fn unplug_mid_stream_is_a_disconnection() {
    let faults = DinastFaults {
        unplug_after_reads: Some(2),
        ..DinastFaults::default()
    };
    let mut transport = emulated(PlaneCamera::facing(0.5), faults);
    let mut camera = DinastCamera::open(&mut transport, DinastConfig::new(spec())).unwrap();
    camera.capture().unwrap();
    camera.capture().unwrap();
    match camera.capture() {
        Err(RigError::Disconnected { detail, .. }) => assert_eq!(detail, "device unplugged"),
        other => panic!("expected a disconnection, got {other:?}"),
    }
}

#[test]
fn silent_device_is_a_timeout() {
    let faults = DinastFaults {
        silent_after_reads: Some(1),
        ..DinastFaults::default()
    };
    let mut transport = emulated(PlaneCamera::facing(0.5), faults);
    let mut camera = DinastCamera::open(&mut transport, DinastConfig::new(spec())).unwrap();
    camera.capture().unwrap();
    assert!(matches!(camera.capture(), Err(RigError::Timeout { .. })));
}

#[test]
fn garbage_before_sync_still_decodes_the_same_depths() {
    let plane = PlaneCamera::tilted(0.45, -20.0);
    let mut clean = emulated(plane.clone(), DinastFaults::default());
    let expected = DinastCamera::open(&mut clean, DinastConfig::new(spec()))
        .unwrap()
        .capture()
        .unwrap();
    let faults = DinastFaults {
        garbage_before_sync: 5000,
        ..DinastFaults::default()
    };
    let mut transport = emulated(plane, faults);
    let mut camera = DinastCamera::open(&mut transport, DinastConfig::new(spec())).unwrap();
    for _ in 0..3 {
        let frame = camera.capture().unwrap();
        assert!(
            frame
                .depth
                .iter()
                .zip(&expected.depth)
                .all(|(a, b)| a == b || (a.is_nan() && b.is_nan()))
        );
    }
    assert!(camera.decoder_stats().skipped_bytes >= 5000);
}

#[test]
fn truncated_packet_is_skipped_and_the_next_one_decodes() {
    let faults = DinastFaults {
        truncate_packet: true,
        ..DinastFaults::default()
    };
    let plane = PlaneCamera::facing(0.5);
    let truth = plane.clone().capture().unwrap();
    let mut transport = emulated(plane.clone(), faults);
    let mut camera = DinastCamera::open(&mut transport, DinastConfig::new(spec())).unwrap();
    let frame = camera.capture().unwrap();
    assert_eq!(camera.decoder_stats().truncated_packets, 1);
    assert_eq!(compare(&plane, &frame, &truth).decoded_valid_share, 1.0);
}

#[test]
fn no_packet_within_the_read_budget_is_a_timeout() {
    // More garbage than the reads a capture may take: no marker ever arrives in time.
    let faults = DinastFaults {
        garbage_before_sync: 5 * nbv_hw::dinast::PACKET_LEN,
        ..DinastFaults::default()
    };
    let mut transport = emulated(PlaneCamera::facing(0.5), faults);
    let mut camera = DinastCamera::open(&mut transport, DinastConfig::new(spec())).unwrap();
    assert!(matches!(camera.capture(), Err(RigError::Timeout { .. })));
}

/// Runs the emulator behind a channel in its own thread (the fake camera is created
/// there) until `stop` is set; returns whether the device was still streaming at the end.
fn serve(
    device_end: nbv_hw::dinast::DeviceEnd,
    faults: DinastFaults,
    stop: Arc<AtomicBool>,
) -> thread::JoinHandle<bool> {
    thread::spawn(move || {
        let mut device_end = device_end;
        let mut camera = PlaneCamera::facing(0.3);
        let mut emulator = DinastEmulator::new("IPA-1110 emu").with_faults(faults);
        while !stop.load(Ordering::Relaxed) {
            if !device_end.poll(&mut emulator, &mut camera) {
                thread::sleep(Duration::from_millis(1));
            }
        }
        emulator.is_started()
    })
}

#[test]
fn camera_over_the_channel_transport_captures_and_stops() {
    let (transport, device_end) = channel_transport(SAFETY);
    let stop = Arc::new(AtomicBool::new(false));
    let server = serve(device_end, DinastFaults::default(), Arc::clone(&stop));
    let mut config = DinastConfig::new(spec());
    config.timeout = SAFETY;
    config.control_timeout = SAFETY;
    let mut camera = DinastCamera::open(transport, config).unwrap();
    let frame = camera.capture().unwrap();
    let centre = frame.depth[120 * 320 + 160];
    assert!((centre - 0.3).abs() < 0.002, "{centre}");
    camera.close().unwrap();
    stop.store(true, Ordering::Relaxed);
    assert!(!server.join().unwrap(), "still streaming after close");
}

#[test]
fn dropped_device_end_is_a_disconnection() {
    let (transport, device_end) = channel_transport(SAFETY);
    let stop = Arc::new(AtomicBool::new(false));
    let server = serve(device_end, DinastFaults::default(), Arc::clone(&stop));
    let mut config = DinastConfig::new(spec());
    config.timeout = SAFETY;
    config.control_timeout = SAFETY;
    let mut camera = DinastCamera::open(transport, config).unwrap();
    camera.capture().unwrap();
    stop.store(true, Ordering::Relaxed);
    server.join().unwrap(); // the device end is dropped with its thread
    match camera.capture() {
        Err(RigError::Disconnected { detail, .. }) => assert_eq!(detail, "device unplugged"),
        other => panic!("expected a disconnection, got {other:?}"),
    }
}

#[test]
fn device_end_that_never_answers_is_a_timeout() {
    let (transport, _device_end) = channel_transport(Duration::from_millis(50));
    let error = DinastCamera::open(transport, DinastConfig::new(spec())).unwrap_err();
    assert!(matches!(error, RigError::Timeout { .. }), "{error}");
}

#[test]
fn silent_device_behind_the_channel_is_a_timeout() {
    let (transport, device_end) = channel_transport(SAFETY);
    let stop = Arc::new(AtomicBool::new(false));
    let faults = DinastFaults {
        silent_after_reads: Some(1),
        ..DinastFaults::default()
    };
    let server = serve(device_end, faults, Arc::clone(&stop));
    // Opening and the first frame have the safety net; the device then never answers, so
    // the short timeouts cannot expire early whatever the scheduling.
    let mut config = DinastConfig::new(spec());
    config.timeout = SAFETY;
    config.control_timeout = SAFETY;
    let mut camera = DinastCamera::open(transport, config).unwrap();
    camera.capture().unwrap();
    camera.set_timeouts(Duration::from_millis(200), Duration::from_millis(200));
    let result = camera.capture();
    assert!(
        matches!(result, Err(RigError::Timeout { seconds, .. }) if seconds == 0.2),
        "{result:?}"
    );
    drop(camera); // the stop request times out too: dropping must not hang
    stop.store(true, Ordering::Relaxed);
    server.join().unwrap();
}
