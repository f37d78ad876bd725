//! The terminal summary of `nbv explore`: a few lines per episode and object from the
//! report ([`nbv_sweep::report`]).

use nbv_sweep::report::{
    ExploreReport, HandEyeEntry, ObjectEntry, OracleEntry, QUALITY_TOLERANCE, RegistrationScore,
    WorkcellEntry,
};

/// A few lines for the terminal.
pub fn summary(report: &ExploreReport) -> String {
    let mut s = episode_line(report);
    for o in &report.objects {
        s += &object_line(o);
    }
    for o in &report.objects {
        if let Some(e) = &o.oracle {
            s += &oracle_line(o, e);
        }
    }
    s += &phase_one_notes(report);
    if let Some(w) = &report.workcell_alignment {
        s += &workcell_line(w);
    }
    if let Some(h) = &report.hand_eye {
        let extra = report.objects.iter().map(|o| o.calibration_views).sum();
        s += &hand_eye_lines(h, extra);
    }
    s += &legend();
    s
}

/// The episode in one line: scene, mode, seed, phase 1's points, objects, views,
/// collisions and the mean F-scores.
fn episode_line(report: &ExploreReport) -> String {
    format!(
        "{} ({}, seed {}): {} points in phase 1, {} object(s), {} view(s), {} collision(s), \
             mean F-score {:.1} (as acquired {:.1})\n",
        report.scene,
        report.mode,
        report.seed,
        report.phase_one.points,
        report.objects.len(),
        report.totals.views,
        report.totals.collisions,
        100.0 * report.totals.mean_f_score,
        100.0 * report.totals.mean_f_score_unregistered
    )
}

/// A share in percent with one decimal, `-` without one.
fn pct(v: Option<f64>) -> String {
    v.map_or("-".to_string(), |v| format!("{:.1}", 100.0 * v))
}

/// An alignment error in mm, `!` when the pipeline rejected it, `-` without one.
fn mm(e: &Option<RegistrationScore>) -> String {
    e.as_ref().map_or("-".to_string(), |e| {
        let mark = if e.accepted { "" } else { "!" };
        format!("{:.1} mm{mark}", e.alignment * 1e3)
    })
}

/// One object: the model's quality, the views, the alignment errors and why it stopped.
fn object_line(o: &ObjectEntry) -> String {
    let q = o.quality.as_ref();
    format!(
        "  {:<12} F {:>5}  P {:>5}  C {:>5}  chamfer {:>7}  mesh F@5mm {:>5}  as acquired F {:>5}  views {:>2}  failed {:>2}  alignment as acquired {:>7}  map {:>7}  p-icp-gpa {:>7}  icp {:>7}  ({})\n",
        o.name,
        pct(q.map(|q| q.f_score)),
        pct(q.map(|q| q.precision)),
        pct(q.map(|q| q.completeness)),
        q.map_or("-".to_string(), |q| format!("{:.1} mm", q.chamfer * 1e3)),
        pct(o.mesh_quality.as_ref().map(|m| m.scores.f_score[1])),
        pct(o.quality_unregistered.map(|q| q.f_score)),
        o.views.len(),
        o.viewpoints_failed.len(),
        mm(&o.error_unregistered),
        mm(&o.error_map),
        mm(&o.error_pgpa),
        mm(&o.error_icp),
        o.stop
    )
}

/// One object against the oracle's ceiling.
fn oracle_line(o: &ObjectEntry, e: &OracleEntry) -> String {
    let reached = e.views_to_95.map_or("not reached".to_string(), |v| {
        format!("reached after {v} view(s)")
    });
    format!(
        "  {:<12} ceiling {:.1} % (what every reachable view sees together); coverage {:.1} % of the ceiling; 95 % of the ceiling {reached} (the oracle's greedy cover: {} view(s)); the same views without noise: {}; {} view(s) added under 0.5 point\n",
        o.name,
        100.0 * e.ceiling,
        100.0 * e.coverage_of_ceiling,
        e.oracle_views_to_95,
        e.noise_free_by_view
            .last()
            .map_or("-".to_string(), |c| format!("{:.1} %", 100.0 * c)),
        o.wasted_views,
    )
}

/// What phase 1 got wrong: clusters that are none of the scene's objects, slivers
/// dropped, objects missed or split.
fn phase_one_notes(report: &ExploreReport) -> String {
    let mut s = String::new();
    for o in report.objects.iter().filter(|o| o.truth != "object") {
        s += &format!(
            "  {} matches none of the scene's objects: {}\n",
            o.name, o.truth
        );
    }
    for v in &report.phase_one.slivers {
        s += &format!(
            "  dropped in phase 1: a sliver of {}'s face ({} points, {:.1} mm thick, {:.1} mm in front of its box)\n",
            v.obstacle,
            v.points,
            v.thickness * 1e3,
            v.distance * 1e3
        );
    }
    if !report.missed_objects.is_empty() || !report.split_objects.is_empty() {
        s += &format!(
            "  missed: {}; split into several clusters: {}\n",
            list_or_none(&report.missed_objects),
            list_or_none(&report.split_objects)
        );
    }
    s
}

/// The laser sweep's correction from the workcell.
fn workcell_line(w: &WorkcellEntry) -> String {
    format!(
        "  laser sweep aligned to the workcell: {} ({:.2}° and {:.1} mm, {} points on known surfaces, rms {:.1} mm)\n",
        if w.accepted {
            "corrected"
        } else {
            "NOT corrected"
        },
        w.rotation_deg,
        w.translation * 1e3,
        w.inliers,
        w.rms * 1e3
    )
}

/// The self-calibration: the hand-eye estimate (beside the injected error in the twin),
/// its σ and the joint offsets, and the calibration as the views see it.
/// `extra`: the views taken for it alone.
fn hand_eye_lines(h: &HandEyeEntry, extra: usize) -> String {
    let mut s = hand_eye_estimate_line(h, extra);
    s += &joint_offsets_line(h);
    if let (Some(r), Some(t)) = (h.view_rotation_error_deg, h.view_translation_error) {
        s += &format!(
            "    as the views see it (mount and joints together, against the injected errors): \
             off by {:.2}° / {:.1} mm at the median view, {:.2}° / {:.1} mm at the worst\n",
            r[0],
            t[0] * 1e3,
            r[1],
            t[1] * 1e3
        );
    }
    s
}

/// The hand-eye estimate, and in the twin how far it is off the injected error.
fn hand_eye_estimate_line(h: &HandEyeEntry, extra: usize) -> String {
    let e = &h.estimate;
    let r = e.rotation.map(f64::to_degrees);
    let taken_for_it = if extra > 0 {
        format!("{extra} of them taken for it, ")
    } else {
        String::new()
    };
    let mut line = format!(
        "  hand-eye estimate from {} views ({taken_for_it}{} with their table): rotation [{:.2}, {:.2}, {:.2}]° translation [{:.1}, {:.1}, {:.1}] mm",
        e.views,
        e.table_views,
        r[0],
        r[1],
        r[2],
        e.translation[0] * 1e3,
        e.translation[1] * 1e3,
        e.translation[2] * 1e3
    );
    if let (Some(t), Some(dr), Some(dt)) = (h.truth, h.rotation_error_deg, h.translation_error) {
        line += &format!(
            "; injected (joint 6's offset folded in) [{:.2}, {:.2}, {:.2}]° [{:.1}, {:.1}, {:.1}] mm: off by {:.2}° and {:.1} mm",
            t[0].to_degrees(),
            t[1].to_degrees(),
            t[2].to_degrees(),
            t[3] * 1e3,
            t[4] * 1e3,
            t[5] * 1e3,
            dr,
            dt * 1e3
        );
        if let (Some(mr), Some(mt)) = (h.mount_rotation_error_deg, h.mount_translation_error) {
            line += &format!(" ({mr:.2}° and {:.1} mm from the mount alone)", mt * 1e3);
        }
    }
    line + "\n"
}

/// The estimate's σ, the joint offsets (beside the injected ones in the twin) and the
/// calibrated registration passes.
fn joint_offsets_line(h: &HandEyeEntry) -> String {
    let e = &h.estimate;
    let q = e.joint_offsets.map(f64::to_degrees);
    let mut line = format!(
        "    σ {:.2}° / {:.1} mm; joint offsets 1-5 [{:.3}, {:.3}, {:.3}, {:.3}, {:.3}]° (joint 6's is the mount's)",
        e.sigma[0].to_degrees(),
        e.sigma[1] * 1e3,
        q[0],
        q[1],
        q[2],
        q[3],
        q[4]
    );
    if let Some(t) = h.joint_offsets_truth {
        let t = t.map(f64::to_degrees);
        line += &format!(
            " (injected [{:.3}, {:.3}, {:.3}, {:.3}, {:.3}]°, joint 6 {:.3}°)",
            t[0], t[1], t[2], t[3], t[4], t[5]
        );
    }
    line += &format!(
        "; {} calibrated registration pass(es): every object registered again from the calibrated poses",
        e.passes
    );
    line + "\n"
}

/// What the figures mean.
fn legend() -> String {
    let mut s = format!(
        "  (F: F-score, the harmonic mean of P, the share of the model's points within \
             {tau:.0} mm of the true surface, and C, the share of the true surface above the \
             table within {tau:.0} mm of the model (its coverage); chamfer: mean of the mean \
             distances model to surface and surface to model; mesh F@5mm: the F-score at 5 mm \
             of the fused surface, model_mesh.ply; as acquired: the views before \
             registration)\n",
        tau = QUALITY_TOLERANCE * 1e3
    );
    s += "  (alignment: mean displacement of the true points by each view's misalignment; \
              map = the model's registration, refined last along the camera's rays\
              ; ! = rejected (map: not converged or the \
              objective did not fall; p-icp-gpa, icp: not converged or a correction beyond \
              [registration] max_correction_*): the model keeps the reported poses)\n";
    s
}

/// The names joined by commas, or `none`.
fn list_or_none(names: &[String]) -> String {
    if names.is_empty() {
        "none".into()
    } else {
        names.join(", ")
    }
}
