//! Properties: every message type survives a CDR round trip with arbitrary contents; tf
//! lookups compose (A→C = A→B ∘ B→C); an interpolated translation lies in the box of
//! the two samples that bracket it.

use nalgebra::{Isometry3, Vector3 as NaVector3};
use nbv_bag::TfBuffer;
use nbv_bag::messages::*;
use proptest::collection::vec;
use proptest::prelude::*;

fn f64s() -> impl Strategy<Value = f64> {
    -1e9f64..1e9
}
fn f32s() -> impl Strategy<Value = f32> {
    -1e6f32..1e6
}
fn text() -> impl Strategy<Value = String> {
    "\\PC{0,12}"
}
fn bytes() -> impl Strategy<Value = Vec<u8>> {
    vec(any::<u8>(), 0..40)
}

prop_compose! {
    fn time()(sec in any::<i32>(), nanosec in 0u32..1_000_000_000) -> Time { Time { sec, nanosec } }
}
prop_compose! {
    fn duration()(sec in any::<i32>(), nanosec in 0u32..1_000_000_000) -> Duration { Duration { sec, nanosec } }
}
prop_compose! {
    fn header()(stamp in time(), frame_id in text()) -> Header { Header { stamp, frame_id } }
}
prop_compose! {
    fn vector3()(x in f64s(), y in f64s(), z in f64s()) -> Vector3 { Vector3 { x, y, z } }
}
prop_compose! {
    fn point()(x in f64s(), y in f64s(), z in f64s()) -> Point { Point { x, y, z } }
}
prop_compose! {
    fn quaternion()(x in f64s(), y in f64s(), z in f64s(), w in f64s()) -> Quaternion { Quaternion { x, y, z, w } }
}
prop_compose! {
    fn color()(r in f32s(), g in f32s(), b in f32s(), a in f32s()) -> ColorRGBA { ColorRGBA { r, g, b, a } }
}
prop_compose! {
    fn transform_stamped()(header in header(), child_frame_id in text(), translation in vector3(), rotation in quaternion())
        -> TransformStamped {
        TransformStamped { header, child_frame_id, transform: Transform { translation, rotation } }
    }
}
prop_compose! {
    fn point_field()(name in text(), offset in any::<u32>(), datatype in any::<u8>(), count in any::<u32>()) -> PointField {
        PointField { name, offset, datatype, count }
    }
}
prop_compose! {
    fn point_cloud()(header in header(), height in any::<u32>(), width in any::<u32>(),
                     fields in vec(point_field(), 0..5), is_bigendian in any::<bool>(),
                     point_step in any::<u32>(), row_step in any::<u32>(), data in bytes(),
                     is_dense in any::<bool>()) -> PointCloud2 {
        PointCloud2 { header, height, width, fields, is_bigendian, point_step, row_step, data, is_dense }
    }
}
prop_compose! {
    fn image()(header in header(), height in any::<u32>(), width in any::<u32>(), encoding in text(),
               is_bigendian in any::<u8>(), step in any::<u32>(), data in bytes()) -> Image {
        Image { header, height, width, encoding, is_bigendian, step, data }
    }
}
prop_compose! {
    fn camera_info()(header in header(), height in any::<u32>(), width in any::<u32>(),
                     distortion_model in text(), d in vec(f64s(), 0..8),
                     k in proptest::array::uniform9(f64s()), r in proptest::array::uniform9(f64s()),
                     p in proptest::array::uniform12(f64s()), binning_x in any::<u32>(),
                     binning_y in any::<u32>(), roi in (any::<u32>(), any::<u32>(), any::<u32>(), any::<u32>(), any::<bool>()))
                     -> CameraInfo {
        CameraInfo { header, height, width, distortion_model, d, k, r, p, binning_x, binning_y,
            roi: RegionOfInterest { x_offset: roi.0, y_offset: roi.1, height: roi.2, width: roi.3, do_rectify: roi.4 } }
    }
}
prop_compose! {
    fn joint_state()(header in header(), name in vec(text(), 0..4), position in vec(f64s(), 0..4),
                     velocity in vec(f64s(), 0..4), effort in vec(f64s(), 0..4)) -> JointState {
        JointState { header, name, position, velocity, effort }
    }
}
prop_compose! {
    fn marker()(header in header(), ns in text(), ids in (any::<i32>(), any::<i32>(), any::<i32>()),
                pose in (point(), quaternion()), scale in vector3(), color in color(), lifetime in duration(),
                flags in (any::<bool>(), any::<bool>()), points in vec(point(), 0..4), colors in vec(color(), 0..4),
                strings in (text(), text(), text()), texture in (header(), text(), bytes()),
                uv in vec((f32s(), f32s()), 0..4), mesh in (text(), bytes())) -> Marker {
        Marker {
            header, ns, id: ids.0, r#type: ids.1, action: ids.2,
            pose: Pose { position: pose.0, orientation: pose.1 }, scale, color, lifetime,
            frame_locked: flags.0, points, colors, texture_resource: strings.0,
            texture: CompressedImage { header: texture.0, format: texture.1, data: texture.2 },
            uv_coordinates: uv.into_iter().map(|(u, v)| UVCoordinate { u, v }).collect(),
            text: strings.1, mesh_resource: strings.2,
            mesh_file: MeshFile { filename: mesh.0, data: mesh.1 },
            mesh_use_embedded_materials: flags.1,
        }
    }
}

fn round_trip<M: RosMessage + PartialEq + std::fmt::Debug>(m: &M) -> Result<(), TestCaseError> {
    let bytes = m.encode();
    prop_assert_eq!(&M::decode(&bytes).unwrap(), m);
    // Truncation anywhere is an error, never a panic (or a silently shorter message).
    for cut in [0, 3, bytes.len() / 2, bytes.len().saturating_sub(1)] {
        if cut < bytes.len() {
            prop_assert!(M::decode(&bytes[..cut]).is_err() || cut + 3 >= bytes.len());
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn cdr_round_trips(
        t in time(), h in header(), s in text(), ts in transform_stamped(),
        tfs in vec(transform_stamped(), 0..4), cloud in point_cloud(), img in image(),
        info in camera_info(), js in joint_state(), markers in vec(marker(), 0..3),
        c in color(),
    ) {
        round_trip(&t)?;
        round_trip(&h)?;
        round_trip(&RosString { data: s })?;
        round_trip(&ts)?;
        round_trip(&TFMessage { transforms: tfs })?;
        round_trip(&cloud)?;
        round_trip(&img)?;
        round_trip(&info)?;
        round_trip(&js)?;
        round_trip(&MarkerArray { markers })?;
        round_trip(&c)?;
    }

    #[test]
    fn arbitrary_bytes_never_panic(b in vec(any::<u8>(), 0..300)) {
        let _ = MarkerArray::decode(&b);
        let _ = PointCloud2::decode(&b);
        let _ = CameraInfo::decode(&b);
        let _ = JointState::decode(&b);
        let _ = TFMessage::decode(&b);
        let _ = Image::decode(&b);
    }
}

const S: i64 = 1_000_000_000;

prop_compose! {
    fn pose()(t in proptest::array::uniform3(-5.0f64..5.0), r in proptest::array::uniform3(-3.0f64..3.0)) -> Isometry3<f64> {
        Isometry3::new(NaVector3::from(t), NaVector3::from(r))
    }
}

fn stamped(parent: &str, child: &str, t_ns: i64, iso: &Isometry3<f64>) -> TransformStamped {
    TransformStamped {
        header: Header {
            stamp: Time::from_nanos(t_ns),
            frame_id: parent.into(),
        },
        child_frame_id: child.into(),
        transform: Transform::from_isometry(iso),
    }
}

fn close(a: &Isometry3<f64>, b: &Isometry3<f64>) -> bool {
    (a.translation.vector - b.translation.vector).norm() < 1e-9
        && a.rotation.angle_to(&b.rotation) < 1e-9
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(128))]

    /// A tree root→{a, b}, a→c, b→d with two samples per edge (root→a static):
    /// lookups between any three frames compose.
    #[test]
    fn lookups_compose(
        poses in proptest::collection::vec((pose(), pose()), 4),
        t_frac in 0.0f64..=1.0,
        triple in proptest::array::uniform3(0usize..5),
    ) {
        let edges = [("root", "a"), ("root", "b"), ("a", "c"), ("b", "d")];
        let mut buf = TfBuffer::new();
        for (k, ((parent, child), (p0, p1))) in edges.iter().zip(&poses).enumerate() {
            if k == 0 {
                buf.insert_transform(&stamped(parent, child, 0, p0), true);
            } else {
                buf.insert_transform(&stamped(parent, child, S, p0), false);
                buf.insert_transform(&stamped(parent, child, 3 * S, p1), false);
            }
        }
        let t = S + (t_frac * 2.0 * S as f64) as i64;
        let frames = ["root", "a", "b", "c", "d"];
        let [x, y, z] = triple.map(|i| frames[i]);
        let xz = buf.lookup(x, z, t).unwrap();
        let xy = buf.lookup(x, y, t).unwrap();
        let yz = buf.lookup(y, z, t).unwrap();
        prop_assert!(close(&xz, &(xy * yz)), "{x}->{z} vs {x}->{y}->{z}");
        prop_assert!(close(&buf.lookup(z, x, t).unwrap(), &xz.inverse()));
    }

    /// Interpolated translations stay inside the box of the bracketing samples.
    #[test]
    fn interpolation_stays_in_the_box(
        samples in proptest::collection::vec((0i64..1000, pose()), 2..6),
        q in 0.0f64..=1.0,
    ) {
        let mut buf = TfBuffer::new();
        for (t, p) in &samples {
            buf.insert_transform(&stamped("w", "s", t * 1000, p), false);
        }
        let (first, last) = buf.time_range("s").unwrap();
        let t = first + ((last - first) as f64 * q) as i64;
        let got = buf.lookup("w", "s", t).unwrap().translation.vector;
        // The bracketing samples (first kept among equal stamps, as the buffer does).
        let mut kept: Vec<(i64, Isometry3<f64>)> = Vec::new();
        for (ts, p) in &samples {
            if !kept.iter().any(|(k, _)| *k == ts * 1000) {
                kept.push((ts * 1000, *p));
            }
        }
        kept.sort_by_key(|(k, _)| *k);
        let i = kept.partition_point(|(k, _)| *k < t);
        let (lo, hi) = if kept[i].0 == t { (&kept[i].1, &kept[i].1) } else { (&kept[i - 1].1, &kept[i].1) };
        for d in 0..3 {
            let (a, b) = (lo.translation.vector[d], hi.translation.vector[d]);
            prop_assert!(got[d] >= a.min(b) - 1e-9 && got[d] <= a.max(b) + 1e-9, "axis {d}: {} not in [{a}, {b}]", got[d]);
        }
    }
}
