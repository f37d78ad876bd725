//! Registers the views an episode wrote (`RUN/objects/<name>/views/view_NN.ply`, which
//! carry their sensor origins and true points) with each method, and prints per view how
//! far each leaves it from the truth — the study behind the registration's defaults.
//!
//! ```sh
//! cargo run --release -- explore --scene paper-env1 -o run/ --no-pictures
//! cargo run --release --example register_views -- run/objects/jug/views paper-env1
//! ```
//!
//! Each method's line gives the mean alignment error and per view; `rel.` the same after
//! taking out the laser cluster's own misalignment. Environment switches for studies:
//! `VIEW_TO_VIEW=1` adds the MAP's view-to-view terms (the scene's setting is off);
//! `TRUTH_POINTS=1` replaces every point by its true position (no noise); `FROM_TRUTH=1`
//! also starts the MAP at the true poses without priors (does the data term keep them?)
//! and prints the truth's χ² under each view's prior, and with `START_OFFSET="rx,ry,rz,
//! tx,ty,tz"` (degrees, millimetres) starts every other view that far off its truth (does
//! the data term bring it back?); `NO_PRIOR=1` drops every view's prior; `SET="errors.scale=3 …"` applies the
//! episode's `--set` overrides to the scene; `MAX_STAGES=n` and `MATCH_SIGMAS=x` set the
//! MAP's masking stages and the σ within which a point counts as matched; `DECOMPOSE=1`
//! prints each view's residual misalignment (rotation, shift of its true centroid, world
//! axes); `ONLY_MAP=1` skips the paper's p-ICP-GPA and sequential ICP.

use nbv_core::cloud::PointCloud;
use nbv_core::cloud::io::read_cloud;
use nbv_core::evaluation::alignment_error;
use nbv_core::math::Pose;
use nbv_core::registration::{
    MapPreparation, Method, MethodReport, RegistrationParams, register_prepared,
    register_with_models,
};
use std::time::Instant;

fn subsample(cloud: &PointCloud, n: usize) -> PointCloud {
    if cloud.len() <= n {
        return cloud.clone();
    }
    let idx: Vec<usize> = (0..n).map(|k| k * cloud.len() / n).collect();
    cloud.select(&idx)
}

/// The number in environment variable `name`, if it is set; an error names a value that
/// is not one.
fn env_number<T: std::str::FromStr>(name: &str) -> anyhow::Result<Option<T>> {
    let Ok(text) = std::env::var(name) else {
        return Ok(None);
    };
    let value = text
        .parse()
        .map_err(|_| anyhow::anyhow!("{name}={text:?} is not a number"))?;
    Ok(Some(value))
}

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().collect();
    let (dir, scene) = match &args[..] {
        [_, dir, scene, ..] => (dir.clone(), scene.clone()),
        _ => anyhow::bail!("usage: register_views VIEWS_DIR SCENE"),
    };
    let scene = scene_with_overrides(&scene)?;
    let config = scene.explore_config(nbv_core::pipeline::ExploreMode::Hybrid)?;
    let overrides = MapOverrides::from_env()?;
    let views = read_views(&dir, &config)?;
    let free_space = sweep_free_space(&dir, &views, &config)?;
    let mut models = config
        .uncertainty
        .view_models(&views, config.frames_per_view);
    if std::env::var_os("NO_PRIOR").is_some() {
        for m in &mut models {
            m.prior = None;
        }
    }
    println!("{:?}", config.uncertainty);
    let study = Study::new(views)?;
    register_by_each_method(&study, &models, &config, overrides, free_space)?;
    if std::env::var_os("FROM_TRUTH").is_some() {
        register_from_truth(&study, &models, &config)?;
    }
    Ok(())
}

/// The built-in scene `name` with the episode's `--set` overrides, space-separated
/// (`SET="errors.scale=3"`).
fn scene_with_overrides(name: &str) -> anyhow::Result<nbv_scenes::Scene> {
    let scene = nbv_scenes::builtin::load(name)?;
    let Some(sets) = std::env::var_os("SET") else {
        return Ok(scene);
    };
    let sets = sets.to_string_lossy().into_owned();
    let overrides = sets
        .split_whitespace()
        .map(nbv_scenes::overrides::parse_override)
        .collect::<Result<Vec<_>, _>>()
        .map_err(anyhow::Error::msg)?;
    Ok(nbv_scenes::overrides::with_overrides(
        &scene, &overrides, "SET", "scene",
    )?)
}

/// The MAP's masking stages (`MAX_STAGES=n`) and the σ within which a point counts as
/// matched (`MATCH_SIGMAS=x`), where set.
#[derive(Clone, Copy)]
struct MapOverrides {
    max_stages: Option<usize>,
    match_sigmas: Option<f64>,
}

impl MapOverrides {
    /// The overrides the environment sets.
    fn from_env() -> anyhow::Result<Self> {
        Ok(Self {
            max_stages: env_number("MAX_STAGES")?,
            match_sigmas: env_number("MATCH_SIGMAS")?,
        })
    }
}

/// The views in `dir` (`*.ply`, in name order), subsampled as the pipeline does; every
/// point at its true position with `TRUTH_POINTS=1`.
fn read_views(
    dir: &str,
    config: &nbv_core::pipeline::ExploreConfig,
) -> anyhow::Result<Vec<PointCloud>> {
    let mut paths: Vec<_> = std::fs::read_dir(dir)?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "ply"))
        .collect();
    paths.sort();
    let mut views: Vec<PointCloud> = paths
        .iter()
        .map(|p| read_cloud(p).map(|c| subsample(&c, config.registration_points)))
        .collect::<Result<_, _>>()?;
    if std::env::var_os("TRUTH_POINTS").is_some() {
        for v in &mut views {
            v.points = v.truth.clone().unwrap();
        }
    }
    Ok(views)
}

/// The laser sweep's free space around the cluster, from the episode's `mid_range.ply`
/// (as the pipeline gives it; `NO_FREE_SPACE=1` leaves it out); printed.
fn sweep_free_space(
    dir: &str,
    views: &[PointCloud],
    config: &nbv_core::pipeline::ExploreConfig,
) -> anyhow::Result<Option<nbv_core::registration::FreeSpace>> {
    let sweep = std::path::Path::new(dir).join("../../../mid_range.ply");
    let (mut free_space, mut seconds) = (None, 0.0);
    if sweep.exists() && std::env::var_os("NO_FREE_SPACE").is_none() {
        let sweep = read_cloud(&sweep)?;
        let t = Instant::now();
        free_space = nbv_core::pipeline::sweep_free_space(&sweep, &views[0], config)?;
        seconds = t.elapsed().as_secs_f64();
    }
    match &free_space {
        Some(f) => println!("free space: {} samples, {seconds:.2} s", f.samples()),
        None => println!("free space: none"),
    }
    Ok(free_space)
}

/// The views under study and the anchor's (view 0's) own misalignment, to see the others
/// relative to it.
struct Study {
    views: Vec<PointCloud>,
    anchor_fit: Pose,
}

impl Study {
    /// The study of `views` (which carry their true points).
    fn new(views: Vec<PointCloud>) -> anyhow::Result<Self> {
        let v = &views[0];
        let anchor_fit =
            nbv_core::registration::rigid_procrustes(&v.points, v.truth.as_ref().unwrap())?;
        Ok(Self { views, anchor_fit })
    }

    /// Each view's mean alignment error at `poses`.
    fn per_view(&self, poses: &[Pose]) -> Vec<f64> {
        self.views
            .iter()
            .zip(poses)
            .map(|(v, p)| alignment_error(std::slice::from_ref(v), std::slice::from_ref(p)).mean)
            .collect()
    }

    /// Prints the alignment error at `poses` (mean and per view, mm), absolute and
    /// relative to the anchor's misalignment, and with `DECOMPOSE=1` each view's residual.
    fn show(&self, name: &str, poses: &[Pose], secs: f64) {
        let e = self.per_view(poses);
        let mean = alignment_error(&self.views, poses).mean;
        let cells: Vec<String> = e.iter().map(|x| format!("{:5.1}", x * 1e3)).collect();
        println!(
            "{name:<10} {:6.2} mm {secs:6.2} s | {}",
            mean * 1e3,
            cells.join(" ")
        );
        if std::env::var_os("DECOMPOSE").is_some() {
            self.decompose(poses);
        }
        let rel: Vec<Pose> = poses.iter().map(|p| self.anchor_fit * p).collect();
        let e = self.per_view(&rel);
        let mean = alignment_error(&self.views, &rel).mean;
        let cells: Vec<String> = e.iter().map(|x| format!("{:5.1}", x * 1e3)).collect();
        println!(
            "  rel.     {:6.2} mm          | {}",
            mean * 1e3,
            cells.join(" ")
        );
    }

    /// Prints each view's residual misalignment at `poses`: rotation (°) and the shift of
    /// its true centroid (mm), world axes.
    fn decompose(&self, poses: &[Pose]) {
        for (k, (v, p)) in self.views.iter().zip(poses).enumerate() {
            let Some(truth) = &v.truth else { continue };
            let moved: Vec<_> = v.points.iter().map(|x| p * x).collect();
            let Ok(fit) = nbv_core::registration::rigid_procrustes(&moved, truth) else {
                continue;
            };
            let e = fit.inverse();
            let c = nalgebra::Point3::from(
                truth
                    .iter()
                    .map(|t| t.coords)
                    .sum::<nalgebra::Vector3<f64>>()
                    / truth.len() as f64,
            );
            let w = e.rotation.scaled_axis() * 180.0 / std::f64::consts::PI;
            let t = (e * c - c) * 1e3;
            println!(
                "    v{k:02} rot {:6.2} {:6.2} {:6.2} deg  shift {:6.1} {:6.1} {:6.1} mm",
                w.x, w.y, w.z, t.x, t.y, t.z
            );
        }
    }
}

/// Registers the views as acquired by the MAP (with the sweep's `free_space` and the
/// `overrides`), p-ICP-GPA and sequential ICP (`ONLY_MAP=1`: the MAP alone), and shows
/// each.
fn register_by_each_method(
    study: &Study,
    models: &[nbv_core::registration::ViewModel],
    config: &nbv_core::pipeline::ExploreConfig,
    overrides: MapOverrides,
    mut free_space: Option<nbv_core::registration::FreeSpace>,
) -> anyhow::Result<()> {
    let views = &study.views;
    let initial = vec![Pose::identity(); views.len()];
    study.show("acquired", &initial, 0.0);
    for (name, method) in [
        ("map", Method::Map),
        ("p-icp-gpa", Method::Gpa),
        (
            "icp",
            Method::SequentialIcp {
                point_to_plane: false,
            },
        ),
    ]
    .into_iter()
    .take(if std::env::var_os("ONLY_MAP").is_some() {
        1
    } else {
        3
    }) {
        let mut params = RegistrationParams {
            method,
            reference: 0,
            ..config.registration.clone()
        };
        params.map.view_to_view |= std::env::var_os("VIEW_TO_VIEW").is_some();
        params.map.max_stages = overrides.max_stages.unwrap_or(params.map.max_stages);
        params.map.match_sigmas = overrides.match_sigmas.unwrap_or(params.map.match_sigmas);
        let t = Instant::now();
        let r = match (method, free_space.take()) {
            (Method::Map, Some(free)) => {
                let prepared =
                    MapPreparation::new(views, models, &params)?.with_free_space(0, free)?;
                register_prepared(&prepared, views, &initial, models, &params)?
            }
            _ => register_with_models(views, &initial, models, &params)?,
        };
        study.show(name, &r.poses, t.elapsed().as_secs_f64());
        if let MethodReport::Map(m) = &r.report {
            println!(
                "           {} steps, {} evaluations: {} (objective {:.1} -> {:.1})",
                m.iterations, m.evaluations, m.verdict, m.objective_initial, m.objective_final
            );
        }
    }
    Ok(())
}

/// `FROM_TRUTH=1`: starts the MAP at the true poses in the anchor's gauge (or
/// `START_OFFSET` off them), data only — does the data term keep them? — and prints the
/// truth's χ² under each view's prior.
fn register_from_truth(
    study: &Study,
    models: &[nbv_core::registration::ViewModel],
    config: &nbv_core::pipeline::ExploreConfig,
) -> anyhow::Result<()> {
    let views = &study.views;
    let truth: Vec<Pose> = views
        .iter()
        .map(|v| {
            let fit =
                nbv_core::registration::rigid_procrustes(&v.points, v.truth.as_ref().unwrap())
                    .unwrap();
            study.anchor_fit.inverse() * fit
        })
        .collect();
    let start = match std::env::var("START_OFFSET") {
        Ok(text) => offset_start(&text, &truth, views)?,
        Err(_) => truth.clone(),
    };
    study.show("truth", &truth, 0.0);
    println!(
        "true χ²               | {}",
        true_chi2(views, &truth, models).join(" ")
    );
    let free: Vec<_> = models
        .iter()
        .map(|m| nbv_core::registration::ViewModel { prior: None, ..*m })
        .collect();
    let params = RegistrationParams {
        method: Method::Map,
        reference: 0,
        ..config.registration.clone()
    };
    if start != truth {
        study.show("start", &start, 0.0);
    }
    let r = register_with_models(views, &start, &free, &params)?;
    study.show("map@start", &r.poses, 0.0);
    if let MethodReport::Map(m) = &r.report {
        println!(
            "           {} steps: obj {} -> {}",
            m.iterations, m.objective_initial, m.objective_final
        );
    }
    Ok(())
}

/// `START_OFFSET="rx,ry,rz,tx,ty,tz"` (degrees, millimetres, world axes): every view but
/// the anchor starts that far off its `truth`, turned about its centroid.
fn offset_start(text: &str, truth: &[Pose], views: &[PointCloud]) -> anyhow::Result<Vec<Pose>> {
    let v: Vec<f64> = text
        .split(',')
        .map(str::trim)
        .map(str::parse)
        .collect::<Result<_, _>>()
        .map_err(|e| anyhow::anyhow!("START_OFFSET={text:?}: {e}"))?;
    let [rx, ry, rz, tx, ty, tz] = v[..] else {
        anyhow::bail!("START_OFFSET={text:?}: six numbers expected");
    };
    let turn = nalgebra::Vector3::new(rx, ry, rz).map(f64::to_radians);
    let shift = nalgebra::Vector3::new(tx, ty, tz) * 1e-3;
    Ok(truth
        .iter()
        .zip(views)
        .enumerate()
        .map(|(k, (p, v))| {
            if k == 0 {
                return *p;
            }
            let c = p * nalgebra::Point3::from(
                v.points
                    .iter()
                    .map(|x| x.coords)
                    .sum::<nalgebra::Vector3<f64>>()
                    / v.len() as f64,
            );
            let off = nalgebra::Translation3::from(c.coords + shift)
                * nalgebra::UnitQuaternion::from_scaled_axis(turn)
                * nalgebra::Translation3::from(-c.coords);
            off * p
        })
        .collect())
}

/// Each view's true correction's χ² under its prior (`-` without one); with `XI=1` the
/// corrections on stderr.
fn true_chi2(
    views: &[PointCloud],
    truth: &[Pose],
    models: &[nbv_core::registration::ViewModel],
) -> Vec<String> {
    views
        .iter()
        .zip(truth)
        .zip(models)
        .map(|((v, c), m)| {
            let o = v
                .origins
                .as_ref()
                .map_or(nalgebra::Point3::origin(), |o| o[0]);
            let w = c.rotation.scaled_axis();
            let t = c * o - o;
            let xi = nalgebra::Vector6::new(w.x, w.y, w.z, t.x, t.y, t.z);
            if std::env::var_os("XI").is_some() {
                eprintln!(
                    "xi rot {:.3} {:.3} {:.3} deg  t {:.1} {:.1} {:.1} mm",
                    w.x.to_degrees(),
                    w.y.to_degrees(),
                    w.z.to_degrees(),
                    t.x * 1e3,
                    t.y * 1e3,
                    t.z * 1e3
                );
            }
            m.prior
                .map_or("  -  ".into(), |p| format!("{:5.1}", p.chi2(&xi)))
        })
        .collect()
}
