//! [`event_json`]: one pipeline event as the JSON object `/nbv/events` carries — its
//! `kind`, the `object` it concerns, and what it says (counts, the reason, the stop, the
//! score, the gain, a view's sensor pose).

use nbv_core::math::Pose;
use nbv_core::pipeline::{ExploreEvent, ObjectExploration};
use serde_json::{Value, json};

/// The event as a JSON object (`kind` first).
pub fn event_json(event: &ExploreEvent<'_>) -> Value {
    match event {
        ExploreEvent::SweepStarted { waypoints } => {
            json!({"kind": "sweep_started", "waypoints": waypoints})
        }
        ExploreEvent::Moved { motion } => json!({
            "kind": "moved",
            "samples": motion.samples.len(),
            "start_s": motion.samples.first().map(|s| s.time),
            "end_s": motion.samples.last().map(|s| s.time),
        }),
        ExploreEvent::SweepCloud { lines, cloud } => {
            json!({"kind": "sweep_cloud", "lines": lines.len(), "points": cloud.len()})
        }
        ExploreEvent::SweepDone { lines, points } => {
            json!({"kind": "sweep_done", "lines": lines, "points": points})
        }
        ExploreEvent::Segmented { objects } => json!({"kind": "segmented", "objects": objects}),
        ExploreEvent::GridUpdated { .. } => json!({"kind": "grid_updated"}),
        ExploreEvent::ObjectStarted { object, cluster } => json!({
            "kind": "object_started", "object": object, "cluster_points": cluster.len(),
        }),
        ExploreEvent::Candidates {
            object,
            candidates,
            list,
        } => json!({
            "kind": "candidates",
            "object": object,
            "candidates": candidates,
            "score": list.candidates.first().map(|c| c.score),
        }),
        ExploreEvent::ViewFailed {
            object,
            reason,
            viewpoint,
        } => json!({
            "kind": "view_failed", "object": object, "reason": reason,
            "viewpoint": pose_json(viewpoint),
        }),
        ExploreEvent::ViewTaken {
            object,
            views,
            gain,
            view,
            ..
        } => json!({
            "kind": "view_taken",
            "object": object,
            "view": views,
            "score": view.score,
            "gain": gain,
            "points": view.cloud.len(),
            "frame_points": view.frame_points,
            "sensor_pose": pose_json(&view.sensor_pose),
        }),
        ExploreEvent::Retreated { object } => json!({"kind": "retreated", "object": object}),
        ExploreEvent::ObjectDone { object, stop, .. } => {
            json!({"kind": "object_done", "object": object, "stop": stop.to_string()})
        }
        ExploreEvent::Registered {
            object,
            exploration,
        } => json!({
            "kind": "registered", "object": object, "outcome": outcome(exploration),
        }),
    }
}

/// A pose as `[x, y, z, qx, qy, qz, qw]` (ROS order).
fn pose_json(pose: &Pose) -> [f64; 7] {
    let t = pose.translation.vector;
    let q = pose.rotation.quaternion();
    [t.x, t.y, t.z, q.i, q.j, q.k, q.w]
}

/// What the registration of an object's views did.
fn outcome(object: &ObjectExploration) -> String {
    match (&object.registration, &object.registration_error) {
        (Some(r), _) if r.map_accepted => "registered (MAP accepted)".to_owned(),
        (Some(_), _) => "registration rejected: the views as acquired".to_owned(),
        (None, Some(e)) => format!("registration failed: {e}"),
        (None, None) => "nothing to register".to_owned(),
    }
}
