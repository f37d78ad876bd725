//! Writes a user's scans of a mesh, as a range scanner outside the twin would take them, for
//! `nbv register` and for peer tools (benches/peers/): no laser anchor, no sensor origins in
//! the files, the reported poses off by a few degrees and millimetres.
//!
//! - `--path ring`: a turntable — the object turns under a fixed scanner, which is the
//!   scanner going round it at one elevation, views evenly spaced over 360°;
//! - `--path handheld`: a hand-held scanner walked once round the object: the azimuth steps,
//!   the elevation (10–55°), the distance, the point looked at and the roll about the
//!   optical axis all wander from view to view.
//!
//! The object is the mesh (STL or OBJ, e.g. `assets/meshes/horse.stl`) standing as it is
//! in its file; the scanner is a pinhole with a 50° field of view at a distance that fits
//! the object, keeping the hits whose incidence is under 75°, with Gaussian noise along
//! each ray (`tests/registration_data/mesh_scans.rs`, which the registration bench shares).
//! The output is the layout of the `registration_views` example:
//! `view_<k>.ply` (each view in its own sensor frame), `truth.json`, `initial.json` (the
//! truth with a random error of `--rotation-error-deg` about a random axis and
//! `--translation-error` in a random direction on every view but view 0, the reference)
//! and `spec.json`.
//!
//! ```text
//! cargo run --release -p nbv-core --example user_scans -- OUTDIR --mesh assets/meshes/horse.stl \
//!     [--path ring|handheld] [--views 12] [--points-per-view 4000] [--noise 0.0003] \
//!     [--rotation-error-deg 2] [--translation-error 0.005] [--seed 7]
//! ```

use std::path::PathBuf;
use std::process::ExitCode;

use nbv_core::cloud::io::{WriteOptions, write_cloud};
use nbv_core::mesh::io::read_mesh;

#[path = "../tests/registration_data/mesh_scans.rs"]
mod mesh_scans;
#[path = "../tests/registration_data/mod.rs"]
mod registration_data;
#[path = "support/views_dir.rs"]
mod views_dir;

use mesh_scans::{MeshScanSpec, ScanPath, scan_mesh};
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
    let mut mesh: Option<PathBuf> = None;
    let mut spec = MeshScanSpec::default();
    while let Some(arg) = args.next() {
        let mut value = |name: &str| args.next().ok_or_else(|| format!("{name} needs a value"));
        let number =
            |name: &str, v: String| v.parse::<f64>().map_err(|e| format!("{name} {v}: {e}"));
        match arg.as_str() {
            "--mesh" => mesh = Some(PathBuf::from(value(&arg)?)),
            "--path" => {
                spec.path = match value(&arg)?.as_str() {
                    "ring" => ScanPath::Ring,
                    "handheld" => ScanPath::Handheld,
                    other => return Err(format!("--path {other}: expected ring or handheld")),
                }
            }
            "--views" => spec.views = number(&arg, value(&arg)?)? as usize,
            "--points-per-view" => spec.points_per_view = number(&arg, value(&arg)?)? as usize,
            "--noise" => spec.noise = number(&arg, value(&arg)?)?,
            "--rotation-error-deg" => spec.rotation_error_deg = number(&arg, value(&arg)?)?,
            "--translation-error" => spec.translation_error = number(&arg, value(&arg)?)?,
            "--seed" => spec.seed = number(&arg, value(&arg)?)? as u64,
            other if other.starts_with("--") => return Err(format!("unknown option {other}")),
            other => out = Some(PathBuf::from(other)),
        }
    }
    let out = out.ok_or("usage: user_scans OUTDIR --mesh MESH [options]")?;
    let mesh = mesh.ok_or("--mesh MESH is missing")?;
    let object = read_mesh(&mesh).map_err(|e| e.to_string())?;
    let (scans, distance) =
        scan_mesh(&object, &spec).map_err(|e| format!("{}: {e}", mesh.display()))?;

    std::fs::create_dir_all(&out).map_err(|e| format!("{}: {e}", out.display()))?;
    let names: Vec<String> = (0..spec.views).map(|k| format!("view_{k}.ply")).collect();
    for (name, view) in names.iter().zip(&scans.views) {
        write_cloud(out.join(name), view, &WriteOptions::default()).map_err(|e| e.to_string())?;
    }
    write_poses(&out.join("truth.json"), &names, &scans.truth)?;
    write_poses(&out.join("initial.json"), &names, &scans.initial)?;
    let spec_json = serde_json::json!({
        "mesh": mesh,
        "path": spec.path.name(),
        "views": spec.views,
        "points_per_view": spec.points_per_view,
        "noise": spec.noise,
        "rotation_error_deg": spec.rotation_error_deg,
        "translation_error": spec.translation_error,
        "distance": distance,
        "seed": spec.seed,
        "files": names,
    });
    write_json(&out.join("spec.json"), &spec_json)?;
    println!(
        "wrote {} {} views of {} from {:.2} m, truth.json, initial.json and spec.json to {}",
        spec.views,
        spec.path.name(),
        mesh.display(),
        distance,
        out.display()
    );
    Ok(())
}
