//! What the drivers cost on the host, per device period: decoding an LMS400 measurement
//! telegram into a scan line (the device sends 190–500 per second), and a Dinast packet into
//! a pinhole depth frame (decoder + vendor model + resampling); also what the emulators pay
//! to encode them. Figures in benches/README.md.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use nbv_core::rig::{DepthCameraSpec, DepthFrame, ScanLine};
use nbv_hw::dinast::{FrameDecoder as PacketDecoder, PinholeResampler, RawEncoder};
use nbv_hw::lms400::{
    FrameDecoder, Lms400Config, MeasurementTelegram, TelegramSettings, encode_frame,
    line_to_telegram, telegram_to_line,
};
use std::hint::black_box;

fn scan_line() -> ScanLine {
    let spec = Lms400Config::default().spec;
    let n = spec.beams();
    ScanLine {
        time: 12.345,
        start_angle: -0.5 * spec.fov,
        angle_step: spec.resolution,
        ranges: (0..n).map(|i| 1.2 + 0.001 * i as f32).collect(),
        truth: None,
    }
}

fn lms400(c: &mut Criterion) {
    let line = scan_line();
    let settings = TelegramSettings {
        format: 20,
        scan_frequency: 19_000,
        range_filter_mm: Some((700, 3000)),
    };
    let telegram = line_to_telegram(&line, &settings, 7).expect("telegram");
    let payload = telegram.encode().expect("payload");
    let frame = encode_frame(&payload).expect("frame");
    let mut group = c.benchmark_group("lms400");
    group.throughput(Throughput::Elements(1));
    group.bench_function("decode_line_281_beams", |b| {
        b.iter(|| {
            let mut decoder = FrameDecoder::new();
            decoder.push(black_box(&frame));
            let payload = decoder.next_frame().expect("frame").expect("complete");
            let telegram = MeasurementTelegram::parse(&payload).expect("telegram");
            black_box(telegram_to_line(&telegram, 12.345, [0.7, 3.0]))
        })
    });
    group.bench_function("encode_line_281_beams", |b| {
        b.iter(|| {
            let t = line_to_telegram(black_box(&line), &settings, 7).expect("telegram");
            black_box(encode_frame(&t.encode().expect("payload")).expect("frame"))
        })
    });
    group.finish();
}

fn dinast(c: &mut Criterion) {
    let spec = DepthCameraSpec::ipa1110();
    // A tilted plane 0.3–0.6 m away.
    let depth = (0..spec.height)
        .flat_map(|v| (0..spec.width).map(move |u| 0.3 + 0.3 * (u + v) as f32 / 560.0))
        .collect();
    let frame = DepthFrame {
        time: 0.0,
        width: spec.width,
        height: spec.height,
        depth,
        truth: None,
    };
    let encoder = RawEncoder::new(&spec);
    let resampler = PinholeResampler::new(&spec);
    let packet = encoder.encode(&frame).expect("raw").to_packet();
    let mut group = c.benchmark_group("dinast");
    group.throughput(Throughput::Elements(1));
    group.bench_function("decode_frame_320x240", |b| {
        b.iter(|| {
            let mut decoder = PacketDecoder::new();
            decoder.push(black_box(&packet));
            let raw = decoder.pop_frame().expect("frame");
            black_box(resampler.depth(&raw))
        })
    });
    group.bench_function("encode_frame_320x240", |b| {
        b.iter(|| black_box(encoder.encode(black_box(&frame)).expect("raw").to_packet()))
    });
    group.finish();
}

criterion_group!(benches, lms400, dinast);
criterion_main!(benches);
