//! The LMS400 driver against its emulator on loopback: round trip of lines, session set-up,
//! the device's refusals, and every injected fault (no test can hang: every read has a
//! timeout).
#![cfg(feature = "lms400")]

use nbv_core::rig::{LineScanner, LineScannerSpec, RigError, ScanLine};
use nbv_hw::lms400::{FrameDecoder, SopasError};
use nbv_hw::lms400::{
    Lms400Config, Lms400Emulator, Lms400Faults, Lms400Scanner, Reply, ScanConfig, encode_frame,
};
use std::io::{Read, Write};
use std::net::TcpStream;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

const LINES_PER_STOP: usize = 40;
/// First line time: just below the device clock's wrap at 2³² µs.
const FIRST_TIME: f64 = 4294.9;
const LINE_PERIOD: f64 = 1.0 / 190.0;
const CLOCK_OFFSET: f64 = 2.5;
/// Safety net of every wait whose outcome is not a timeout: generous, so that no test
/// depends on how fast this machine is; a test that hangs fails after it.
const SAFETY: Duration = Duration::from_secs(60);

fn spec() -> LineScannerSpec {
    LineScannerSpec::lms400()
}

/// Line `k` of the fake scanner's endless stream.
fn expected_line(k: usize) -> ScanLine {
    let spec = spec();
    let ranges = (0..spec.beams())
        .map(|i| {
            if (i + k).is_multiple_of(17) {
                f32::NAN
            } else {
                0.7 + ((i * 7 + k * 13) % 2300) as f32 * 1e-3
            }
        })
        .collect();
    ScanLine {
        time: FIRST_TIME + k as f64 * LINE_PERIOD,
        start_angle: -0.5 * spec.fov,
        angle_step: spec.resolution,
        ranges,
        truth: None,
    }
}

/// A backing scanner that returns the next [`LINES_PER_STOP`] lines at each stop.
struct FakeScanner {
    spec: LineScannerSpec,
    streaming: bool,
    next_line: usize,
    fail_start: Arc<AtomicBool>,
}

impl LineScanner for FakeScanner {
    fn spec(&self) -> &LineScannerSpec {
        &self.spec
    }

    fn start(&mut self) -> Result<(), RigError> {
        if self.fail_start.load(Ordering::SeqCst) || self.streaming {
            return Err(RigError::State {
                device: "fake".into(),
                detail: "cannot start".into(),
            });
        }
        self.streaming = true;
        Ok(())
    }

    fn stop(&mut self) -> Result<Vec<ScanLine>, RigError> {
        if !self.streaming {
            return Err(RigError::State {
                device: "fake".into(),
                detail: "stop without start".into(),
            });
        }
        self.streaming = false;
        let lines = (self.next_line..self.next_line + LINES_PER_STOP)
            .map(expected_line)
            .collect();
        self.next_line += LINES_PER_STOP;
        Ok(lines)
    }
}

#[derive(Debug, Default, Clone)]
struct Snapshot {
    logins: usize,
    connections: usize,
    has_client: bool,
    scan_config: Option<ScanConfig>,
    range_filter_mm: Option<(u16, u16)>,
}

/// The emulator serving a fake scanner in its own thread.
struct Harness {
    address: String,
    quit: Arc<AtomicBool>,
    faults: Arc<Mutex<Lms400Faults>>,
    drop_client: Arc<AtomicBool>,
    fail_start: Arc<AtomicBool>,
    snapshot: Arc<Mutex<Snapshot>>,
    polls: Arc<AtomicUsize>,
    thread: Option<JoinHandle<()>>,
}

impl Harness {
    fn start() -> Self {
        let mut emulator = Lms400Emulator::bind("127.0.0.1:0").unwrap();
        let address = emulator.local_addr().unwrap().to_string();
        let quit = Arc::new(AtomicBool::new(false));
        let faults = Arc::new(Mutex::new(Lms400Faults::default()));
        let drop_client = Arc::new(AtomicBool::new(false));
        let fail_start = Arc::new(AtomicBool::new(false));
        let snapshot = Arc::new(Mutex::new(Snapshot::default()));
        let polls = Arc::new(AtomicUsize::new(0));
        let thread = {
            let (quit, faults, drop_client, fail_start, snapshot, polls) = (
                quit.clone(),
                faults.clone(),
                drop_client.clone(),
                fail_start.clone(),
                snapshot.clone(),
                polls.clone(),
            );
            std::thread::spawn(move || {
                let mut fake = FakeScanner {
                    spec: spec(),
                    streaming: false,
                    next_line: 0,
                    fail_start,
                };
                while !quit.load(Ordering::SeqCst) {
                    emulator.set_faults(faults.lock().unwrap().clone());
                    if drop_client.swap(false, Ordering::SeqCst) {
                        emulator.disconnect_client();
                    }
                    let busy = emulator.poll(&mut fake).unwrap_or(true);
                    *snapshot.lock().unwrap() = Snapshot {
                        logins: emulator.logins(),
                        connections: emulator.connections(),
                        has_client: emulator.has_client(),
                        scan_config: Some(emulator.scan_config()),
                        range_filter_mm: emulator.range_filter_mm(),
                    };
                    polls.fetch_add(1, Ordering::SeqCst);
                    if !busy {
                        std::thread::sleep(Duration::from_millis(1));
                    }
                }
            })
        };
        Self {
            address,
            quit,
            faults,
            drop_client,
            fail_start,
            snapshot,
            polls,
            thread: Some(thread),
        }
    }

    fn config(&self, timeout: Duration) -> Lms400Config {
        Lms400Config {
            address: self.address.clone(),
            spec: spec(),
            timeout,
            clock_offset_s: CLOCK_OFFSET,
            reconnect_attempts: 2,
        }
    }

    fn set_faults(&self, faults: Lms400Faults) {
        *self.faults.lock().unwrap() = faults;
        // Two polls later the emulator has taken them over.
        let seen = self.polls.load(Ordering::SeqCst);
        self.wait_for(|_| self.polls.load(Ordering::SeqCst) >= seen + 2);
    }

    fn snapshot(&self) -> Snapshot {
        self.snapshot.lock().unwrap().clone()
    }

    /// Waits until `condition` holds (failing after [`SAFETY`]).
    fn wait_for(&self, condition: impl Fn(&Snapshot) -> bool) {
        let deadline = Instant::now() + SAFETY;
        while !condition(&self.snapshot()) {
            assert!(
                Instant::now() < deadline,
                "emulator never reached the expected state"
            );
            std::thread::sleep(Duration::from_millis(1));
        }
    }
}

impl Drop for Harness {
    fn drop(&mut self) {
        self.quit.store(true, Ordering::SeqCst);
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}

fn assert_lines_match(lines: &[ScanLine], first: usize) {
    assert_eq!(lines.len(), LINES_PER_STOP);
    for (k, line) in lines.iter().enumerate() {
        let expected = expected_line(first + k);
        assert!(
            (line.time - expected.time - CLOCK_OFFSET).abs() < 1e-6,
            "line {k}: time {} vs {}",
            line.time,
            expected.time + CLOCK_OFFSET
        );
        assert!((line.start_angle - expected.start_angle).abs() < 1e-6);
        assert!((line.angle_step - expected.angle_step).abs() < 1e-8);
        assert_eq!(line.ranges.len(), expected.ranges.len());
        for (got, want) in line.ranges.iter().zip(&expected.ranges) {
            if want.is_nan() {
                assert!(got.is_nan());
            } else {
                assert!((got - want).abs() <= 1e-3, "{got} vs {want}");
            }
        }
        assert!(line.truth.is_none());
    }
}

#[test]
fn lines_round_trip_and_the_session_is_configured_from_the_spec() {
    let harness = Harness::start();
    let mut scanner = Lms400Scanner::connect(harness.config(SAFETY)).unwrap();
    let snapshot = harness.snapshot();
    assert_eq!(snapshot.logins, 1);
    let applied = snapshot.scan_config.unwrap();
    assert_eq!(applied.to_args(), "+190.00 +0.25 +55.00 +70.00");
    assert_eq!(applied, scanner.scan_config());
    assert_eq!(snapshot.range_filter_mm, Some((700, 3000)));

    assert!(matches!(scanner.stop(), Err(RigError::State { .. })));
    scanner.start().unwrap();
    assert!(matches!(scanner.start(), Err(RigError::State { .. })));
    let first = scanner.stop().unwrap();
    assert_lines_match(&first, 0);
    // The second batch crosses the device clock's wrap at 2^32 µs.
    scanner.start().unwrap();
    let second = scanner.stop().unwrap();
    assert_lines_match(&second, LINES_PER_STOP);
    assert!(second.last().unwrap().time > 4_294.967_296 + CLOCK_OFFSET);
    assert_eq!(harness.snapshot().connections, 1);
}

#[test]
fn garbage_before_telegrams_is_skipped() {
    let harness = Harness::start();
    let mut scanner = Lms400Scanner::connect(harness.config(SAFETY)).unwrap();
    harness.set_faults(Lms400Faults {
        garbage_before_telegrams: true,
        ..Default::default()
    });
    scanner.start().unwrap();
    assert_lines_match(&scanner.stop().unwrap(), 0);
}

#[test]
fn a_bad_checksum_is_a_protocol_error() {
    let harness = Harness::start();
    let mut scanner = Lms400Scanner::connect(harness.config(SAFETY)).unwrap();
    harness.set_faults(Lms400Faults {
        corrupt_checksum: true,
        ..Default::default()
    });
    scanner.start().unwrap();
    match scanner.stop() {
        Err(RigError::Protocol { detail, .. }) => assert!(detail.contains("checksum"), "{detail}"),
        other => panic!("expected a protocol error, got {other:?}"),
    }
}

#[test]
fn a_disconnect_mid_telegram_fails_the_stop_and_the_next_call_reconnects() {
    let harness = Harness::start();
    let mut scanner = Lms400Scanner::connect(harness.config(SAFETY)).unwrap();
    // A telegram of 281 beams is 894 bytes framed: cut inside the second one.
    harness.set_faults(Lms400Faults {
        disconnect_after_bytes: Some(1_000),
        ..Default::default()
    });
    scanner.start().unwrap();
    let result = scanner.stop();
    assert!(
        matches!(
            result,
            Err(RigError::Disconnected { .. } | RigError::Protocol { .. })
        ),
        "{result:?}"
    );
    harness.set_faults(Lms400Faults::default());
    scanner.start().unwrap();
    assert_lines_match(&scanner.stop().unwrap(), LINES_PER_STOP);
    let snapshot = harness.snapshot();
    assert_eq!(snapshot.logins, 2);
    assert_eq!(snapshot.connections, 2);
}

#[test]
fn a_connection_dropped_between_calls_is_re_established_with_its_session() {
    let harness = Harness::start();
    let mut scanner = Lms400Scanner::connect(harness.config(SAFETY)).unwrap();
    scanner.start().unwrap();
    assert_lines_match(&scanner.stop().unwrap(), 0);
    harness.drop_client.store(true, Ordering::SeqCst);
    harness.wait_for(|s| !s.has_client);
    scanner.start().unwrap();
    assert_lines_match(&scanner.stop().unwrap(), LINES_PER_STOP);
    let snapshot = harness.snapshot();
    assert_eq!(snapshot.logins, 2);
    assert_eq!(snapshot.connections, 2);
    assert_eq!(snapshot.range_filter_mm, Some((700, 3000)));
}

#[test]
fn a_slow_peer_times_out() {
    let harness = Harness::start();
    // The session is set up with the safety net; then the replies are held far beyond the
    // short timeout, so they cannot come in time however the threads are scheduled.
    let mut scanner = Lms400Scanner::connect(harness.config(SAFETY)).unwrap();
    harness.set_faults(Lms400Faults {
        delay_replies: Some(Duration::from_secs(3600)),
        ..Default::default()
    });
    let timeout = Duration::from_millis(100);
    scanner.set_timeout(timeout);
    assert!(matches!(
        scanner.start(),
        Err(RigError::Timeout { seconds, .. }) if seconds == 0.1
    ));
    assert!(matches!(
        Lms400Scanner::connect(harness.config(timeout)),
        Err(RigError::Timeout { .. })
    ));
}

#[test]
fn a_refused_command_is_a_protocol_error_naming_the_code() {
    let harness = Harness::start();
    let mut scanner = Lms400Scanner::connect(harness.config(SAFETY)).unwrap();
    harness.fail_start.store(true, Ordering::SeqCst);
    match scanner.start() {
        Err(RigError::Protocol { detail, .. }) => assert!(detail.contains("sFA 4"), "{detail}"),
        other => panic!("expected a protocol error, got {other:?}"),
    }
}

#[test]
fn a_configuration_the_device_refuses_fails_the_connection() {
    let harness = Harness::start();
    for (line_rate_hz, fov_deg, status) in [(100.0, 70.0, "status 1"), (190.0, 80.0, "status 4")] {
        let mut config = harness.config(SAFETY);
        config.spec.line_rate_hz = line_rate_hz;
        config.spec.fov = f64::to_radians(fov_deg);
        match Lms400Scanner::connect(config) {
            Err(RigError::Protocol { detail, .. }) => assert!(detail.contains(status), "{detail}"),
            Err(other) => panic!("expected a protocol error, got {other:?}"),
            Ok(_) => panic!("configuration accepted"),
        }
    }
}

#[test]
fn nothing_listening_is_a_disconnect() {
    // The port is held (listening on 127.0.0.1) for the whole test, so no other test's
    // emulator can take it; nobody listens at 127.0.0.2 on it: connecting is refused.
    let held = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let port = held.local_addr().unwrap().port();
    let config = Lms400Config {
        address: format!("127.0.0.2:{port}"),
        timeout: SAFETY,
        ..Default::default()
    };
    let result = Lms400Scanner::connect(config);
    assert!(
        matches!(result, Err(RigError::Disconnected { .. })),
        "{result:?}"
    );
    drop(held);
}

#[test]
fn a_peer_that_is_no_scanner_fails_the_connection_cleanly() {
    // An HTTP server where the scanner should be: it answers text, never a CoLa frame;
    // first keeping the connection open, then closing it.
    for close in [false, true] {
        let listener = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
        let address = listener.local_addr().unwrap().to_string();
        let (done, wait) = std::sync::mpsc::channel::<()>();
        let server = std::thread::spawn(move || {
            let (mut stream, _) = listener.accept().unwrap();
            let mut request = [0u8; 256];
            let _ = stream.read(&mut request);
            let _ = stream.write_all(b"HTTP/1.1 400 Bad Request\r\nContent-Length: 0\r\n\r\n");
            if !close {
                // Keep the connection open until the client has given up (or the test
                // failed and dropped the sender).
                let _ = wait.recv();
            }
        });
        // Open: the client can only time out (no frame ever comes), so the timeout may be
        // short. Closed: the outcome is no timeout, so the safety net.
        let config = Lms400Config {
            address,
            timeout: if close {
                SAFETY
            } else {
                Duration::from_millis(200)
            },
            reconnect_attempts: 1,
            ..Default::default()
        };
        let err = Lms400Scanner::connect(config).unwrap_err();
        match (&err, close) {
            (RigError::Timeout { device, .. }, false) => assert_eq!(device, "LMS400"),
            (RigError::Disconnected { device, .. } | RigError::Protocol { device, .. }, true) => {
                assert_eq!(device, "LMS400")
            }
            _ => panic!("close = {close}: unexpected {err}"),
        }
        let _ = done.send(());
        server.join().unwrap();
    }
}

/// A raw CoLa client: sends text commands and returns the replies' text.
struct RawClient {
    stream: TcpStream,
    decoder: FrameDecoder,
}

impl RawClient {
    fn connect(address: &str) -> Self {
        let stream = TcpStream::connect(address).unwrap();
        stream.set_read_timeout(Some(SAFETY)).unwrap();
        Self {
            stream,
            decoder: FrameDecoder::new(),
        }
    }

    fn ask(&mut self, command: &str) -> String {
        self.stream
            .write_all(&encode_frame(command.as_bytes()).unwrap())
            .unwrap();
        let mut buffer = [0u8; 1024];
        loop {
            if let Some(payload) = self.decoder.next_frame().unwrap() {
                return String::from_utf8(payload).unwrap();
            }
            let n = self.stream.read(&mut buffer).unwrap();
            assert!(n > 0, "emulator closed the connection");
            self.decoder.push(&buffer[..n]);
        }
    }
}

#[test]
fn the_emulator_answers_like_the_device() {
    let harness = Harness::start();
    let mut client = RawClient::connect(&harness.address);
    let access_denied = Reply::Error(SopasError::METHOD_ACCESS_DENIED).to_string();
    assert_eq!(access_denied, "sFA 1");
    let exchanges = [
        ("sMN mSCsetscanconfig +190.00 +0.25 +55.00 +70.00", "sFA 1"),
        ("sWN FLrang 700 3000", "sFA A"),
        ("sMN SetAccessMode 4 DEADBEEF", "sAN SetAccessMode 0"),
        ("sMN SetAccessMode 4 81BE23AA", "sAN SetAccessMode 1"),
        (
            "sMN mSCsetscanconfig +150.00 +0.25 +55.00 +70.00",
            "sAN mSCsetscanconfig 1 8CA0 9C4",
        ),
        (
            "sMN mSCsetscanconfig +190.00 +0.25 +55.00 +70.00",
            "sAN mSCsetscanconfig 0 4A38 9C4",
        ),
        (
            "sMN mSCsetscanconfig +360.00 +0.05 +55.00 +70.00",
            "sAN mSCsetscanconfig 2 4A38 9C4",
        ),
        (
            "sMN mSCsetscanconfig +360.00 +0.25 +50.00 +70.00",
            "sAN mSCsetscanconfig 4 4A38 9C4",
        ),
        ("sWN FLsel 4", "sWA FLsel"),
        ("sWN FLrang 700 3000", "sWA FLrang"),
        ("sWN FLrang 3000 700", "sFA 5"),
        ("sMN Run", "sAN Run 1"),
        ("sWN FLsel 4", "sFA A"),
        ("sMN mLRreqdata 21", "sFA 5"),
        ("sMN mLRfoo", "sFA 2"),
        ("sRN LMDscandata", "sFA C"),
        ("sMN mLRstopdata", "sAN mLRstopdata 0"),
        ("sMN mLRreqdata 20", "sMA mLRreqdata"),
        ("sMN mLRreqdata 20", "sFA 4"),
    ];
    for (command, reply) in exchanges {
        assert_eq!(client.ask(command), reply, "reply to `{command}`");
    }
}
