//! Writes the views of the registration benchmark (the paper's Table II case by default)
//! to a directory, for `nbv register` and for peer tools (benches/peers/):
//!
//! - `view_0.ply` … `view_{n-1}.ply`: each view in its own sensor frame (binary PLY);
//! - `truth.json`: the true sensor pose of each view (view frame → world);
//! - `initial.json`: the initial poses (the truth with a known error on every view but
//!   view 0, the reference), the input a robot's reported poses would be;
//! - `spec.json`: the parameters used.
//!
//! Pose files map each view's file name to its 4×4 transform as an array of four rows,
//! the format `nbv register --init` reads and `--poses` writes.
//!
//! ```text
//! cargo run --release -p nbv-core --example registration_views -- OUTDIR \
//!     [--views 5] [--points-per-view 3000] [--noise 0.0003] [--rotation-error-deg 1] \
//!     [--translation-error 0.005] [--seed 7] [--format ply|pcd]
//! ```
//!
//! The scene is the synthetic object of the registration tests (a bumpy ellipsoid about
//! 18 × 12 × 14 cm): a top view overlapping every other view and views 36° apart on a
//! ring around it, 0.3 mm range noise; initial poses off by 1° and 5 mm.

use std::path::PathBuf;
use std::process::ExitCode;

use nbv_core::cloud::io::{WriteOptions, write_cloud};

#[path = "support/views_dir.rs"]
mod views_dir;

#[path = "../tests/registration_data/mod.rs"]
mod registration_data;

use registration_data::{Spec, generate};
use views_dir::{write_json, write_poses};

fn main() -> ExitCode {
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run() -> Result<(), String> {
    let mut args = std::env::args().skip(1);
    let mut out: Option<PathBuf> = None;
    let mut spec = Spec {
        views: 5,
        top_view: true,
        points_per_view: 3000,
        noise: 0.0003,
        rotation_error_deg: 1.0,
        translation_error: 0.005,
        ..Spec::default()
    };
    let mut extension = "ply".to_string();
    while let Some(arg) = args.next() {
        let mut value = |name: &str| args.next().ok_or_else(|| format!("{name} needs a value"));
        let number =
            |name: &str, v: String| v.parse::<f64>().map_err(|e| format!("{name} {v}: {e}"));
        match arg.as_str() {
            "--views" => spec.views = number(&arg, value(&arg)?)? as usize,
            "--points-per-view" => spec.points_per_view = number(&arg, value(&arg)?)? as usize,
            "--noise" => spec.noise = number(&arg, value(&arg)?)?,
            "--rotation-error-deg" => spec.rotation_error_deg = number(&arg, value(&arg)?)?,
            "--translation-error" => spec.translation_error = number(&arg, value(&arg)?)?,
            "--seed" => spec.seed = number(&arg, value(&arg)?)? as u64,
            "--format" => {
                extension = value(&arg)?;
                if extension != "ply" && extension != "pcd" {
                    return Err(format!("--format {extension}: expected ply or pcd"));
                }
            }
            other if other.starts_with("--") => return Err(format!("unknown option {other}")),
            other => out = Some(PathBuf::from(other)),
        }
    }
    let out = out.ok_or("usage: registration_views OUTDIR [options]")?;
    if spec.views < 2 || spec.points_per_view == 0 {
        return Err("need at least 2 views and 1 point per view".into());
    }
    std::fs::create_dir_all(&out).map_err(|e| format!("{}: {e}", out.display()))?;
    let s = generate(&spec);
    let names: Vec<String> = (0..spec.views)
        .map(|k| format!("view_{k}.{extension}"))
        .collect();
    for (name, view) in names.iter().zip(&s.views) {
        write_cloud(out.join(name), view, &WriteOptions::default()).map_err(|e| e.to_string())?;
    }
    write_poses(&out.join("truth.json"), &names, &s.truth)?;
    write_poses(&out.join("initial.json"), &names, &s.initial)?;
    let spec_json = serde_json::json!({
        "views": spec.views,
        "points_per_view": spec.points_per_view,
        "noise": spec.noise,
        "rotation_error_deg": spec.rotation_error_deg,
        "translation_error": spec.translation_error,
        "top_view": spec.top_view,
        "seed": spec.seed,
        "files": names,
    });
    write_json(&out.join("spec.json"), &spec_json)?;
    println!(
        "wrote {} views of {} points, truth.json, initial.json and spec.json to {}",
        spec.views,
        spec.points_per_view,
        out.display()
    );
    Ok(())
}
