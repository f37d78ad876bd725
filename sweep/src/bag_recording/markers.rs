//! Markers: the reduced map M̄ as two `CUBE_LIST`s (occupied, unknown; voxel-sized
//! cubes, world frame) and the candidate viewpoints as a `SPHERE_LIST` coloured by score
//! (blue lowest → red highest).

use super::stamps::header;
use super::topics::WORLD;
use nbv_bag::messages::{ColorRGBA, Marker, MarkerArray, Point, Vector3};
use nbv_core::nbv::ViewpointList;
use nbv_core::occupancy::{OccupancyGrid, ReducedMap};

/// Diameter (m) of a candidate's sphere.
const CANDIDATE_SIZE: f64 = 0.016;

/// The reduced map of `grid`: `(occupied, unknown)`, one `CUBE_LIST` each.
pub fn grid(grid: &OccupancyGrid, ns: u64) -> (MarkerArray, MarkerArray) {
    let reduced = ReducedMap::from_grid(grid);
    let g = reduced.geometry();
    let size = g.resolution();
    let cubes = |name: &str, indices: &[usize], color: ColorRGBA| {
        let points = indices
            .iter()
            .filter_map(|i| g.unlinear(*i))
            .map(|v| {
                let c = g.center(v);
                Point {
                    x: c.x,
                    y: c.y,
                    z: c.z,
                }
            })
            .collect();
        MarkerArray {
            markers: vec![Marker {
                header: header(WORLD, ns),
                ns: name.into(),
                id: 0,
                r#type: Marker::CUBE_LIST,
                action: Marker::ADD,
                scale: Vector3 {
                    x: size,
                    y: size,
                    z: size,
                },
                color,
                points,
                ..Default::default()
            }],
        }
    };
    (
        cubes("occupied", reduced.occupied(), rgba(0.35, 0.35, 0.39, 1.0)),
        cubes("unknown", reduced.unknown(), rgba(0.98, 0.63, 0.16, 0.35)),
    )
}

/// Object `object`'s candidates, one sphere each at its sensor position, coloured by
/// score within the list (marker id = the object); `frame` is the robot's root link (the
/// candidates' poses are in the base frame).
pub fn candidates(object: usize, list: &ViewpointList, frame: &str, ns: u64) -> MarkerArray {
    let (lo, hi) = list
        .candidates
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), c| {
            (a.min(c.score), b.max(c.score))
        });
    let span = if hi > lo { hi - lo } else { 1.0 };
    let points = list
        .candidates
        .iter()
        .map(|c| {
            let p = c.viewpoint.pose.translation.vector;
            Point {
                x: p.x,
                y: p.y,
                z: p.z,
            }
        })
        .collect();
    let colors = list
        .candidates
        .iter()
        .map(|c| ramp((c.score - lo) / span))
        .collect();
    MarkerArray {
        markers: vec![Marker {
            header: header(frame, ns),
            ns: "candidates".into(),
            id: i32::try_from(object).unwrap_or(i32::MAX),
            r#type: Marker::SPHERE_LIST,
            action: Marker::ADD,
            scale: Vector3 {
                x: CANDIDATE_SIZE,
                y: CANDIDATE_SIZE,
                z: CANDIDATE_SIZE,
            },
            color: rgba(1.0, 1.0, 1.0, 1.0),
            points,
            colors,
            ..Default::default()
        }],
    }
}

/// Blue (0) → red (1).
fn ramp(t: f64) -> ColorRGBA {
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0) as f32
    } else {
        0.0
    };
    rgba(t, 0.2, 1.0 - t, 1.0)
}

fn rgba(r: f32, g: f32, b: f32, a: f32) -> ColorRGBA {
    ColorRGBA { r, g, b, a }
}
