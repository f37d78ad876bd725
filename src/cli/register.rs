//! `nbv register VIEW…` (or `--bag BAG --topic T`): global registration of user-supplied
//! views (PLY or PCD files, or a ROS 2 bag's point clouds with their poses from `/tf`) by
//! p-ICP-GPA, the MAP registration or the sequential ICP baseline; writes one 4×4
//! transform per view (JSON) and the merged model cloud, both only once everything has
//! succeeded (`nbv_core::registration::RegistrationFiles`). This file parses the
//! arguments, reads the views and prints.

use anyhow::{Context, Result, anyhow, bail};
use clap::{Args, ValueEnum};
use nbv_core::cloud::PointCloud;
use nbv_core::cloud::io::{CloudFormat, read_cloud_with};
use nbv_core::math::Pose;
use nbv_core::math::pose_file::parse_poses;
use nbv_core::registration::{
    Method, MethodReport, PosePrior, RangeNoise, RegistrationFiles, RegistrationParams,
    SensorOrigin, SetRule, ViewModel, assign_sensor_origins, estimate_range_sigma,
    register_coarse_to_fine, register_with_models,
};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

/// Exit status when the registration ran but did not converge (outputs are written).
pub const NOT_CONVERGED: u8 = 3;

/// Arguments of `nbv register`.
#[derive(Debug, Args)]
#[command(after_long_help = "\
POSE FILES (--init, --poses)
  A JSON object mapping each view's file name (without directory) to its pose, the
  4x4 homogeneous view-to-world transform as an array of 4 rows, row-major:
    { \"scan_a.ply\": [[r00, r01, r02, tx], [r10, r11, r12, ty],
                      [r20, r21, r22, tz], [0, 0, 0, 1]], ... }
  A world point is  p_world = R * p_view + t. --init must hold every view (extra names
  are ignored); without it every view starts at the identity (views already roughly
  aligned in one frame). The reference view keeps its initial pose.

MODEL (-o)
  All views moved into the world frame, concatenated in the order given, each point
  tagged with its view index (PLY property `view`, PCD field `view`); binary, 32-bit
  floats. The format follows the extension (.ply or .pcd).

INPUT
  PLY (ascii, binary little or big endian) or PCD (ascii, binary, binary_compressed);
  extra properties are ignored. Points with NaN or infinite coordinates are dropped
  (reported on stderr). Two views may not share a file name.

BAGS (--bag)
  Each PointCloud2 message on --topic is one view (float32 or float64 x, y, z at any
  offsets; organised clouds; NaN points dropped; big-endian refused), named
  \"<topic>#<index>\" in the pose files. Its initial pose is its frame's pose in
  --fixed-frame at the message's stamp, composed through /tf and /tf_static as tf2 does
  (interpolated between stamps, never extrapolated: a missing or out-of-range transform
  is an error naming the message). --poses then holds each view's registered sensor pose
  in that frame.

EXIT STATUS
  0  registered and converged; outputs written.
  1  error (unreadable or degenerate input: fewer than two views, an empty view, bad
     pose file, bad option); nothing is written.
  2  command-line usage error.
  3  the registration ran but did not converge (no overlap, iteration cap, a view not
     tied to the reference); outputs are written and the reason is printed.")]
pub struct RegisterArgs {
    /// Views to register (PLY or PCD), each in its own frame.
    #[arg(
        required_unless_present = "bag",
        conflicts_with = "bag",
        value_name = "VIEW"
    )]
    views: Vec<PathBuf>,
    /// The views from a bag instead (see BAGS).
    #[command(flatten)]
    bag: super::bag_views::BagInput,
    /// Initial poses (see POSE FILES); identity for every view if absent.
    #[arg(long, value_name = "POSES.json", conflicts_with = "bag")]
    init: Option<PathBuf>,
    /// Algorithm: the MAP registration that makes the pipeline's models (default), or the
    /// paper's p-ICP-GPA and sequential ICP for comparison.
    #[arg(long, value_enum, default_value_t = MethodArg::Map)]
    method: MethodArg,
    /// Index (0-based, in the order given) of the reference view, whose pose is kept.
    #[arg(long, value_name = "K", default_value_t = 0)]
    reference: usize,
    /// Maximum correspondence distance d_max (metres).
    #[arg(long, value_name = "METRES",
          default_value_t = RegistrationParams::default().max_correspondence_distance)]
    max_distance: f64,
    /// Cap on iterations (sequential ICP: per pair).
    #[arg(long, value_name = "N", default_value_t = RegistrationParams::default().max_iterations)]
    max_iterations: usize,
    /// map: the prior on every non-reference view's initial pose, as
    /// "DEGREES,METRES" (σ of each rotation and translation component, about the view's
    /// sensor origin or centroid); without it the poses follow the data alone.
    #[arg(long, value_name = "DEG,METRES", value_parser = parse_pose_sigma)]
    pose_sigma: Option<PosePrior>,
    /// map, with --bag: each view's prior from this topic of
    /// geometry_msgs/PoseWithCovarianceStamped, the uncertainty of the sensor's pose: the
    /// latest message stamped at or before the view's cloud, its covariance (x, y, z, then
    /// rotations) covered by an isotropic prior (σ the square root of each block's largest
    /// eigenvalue). Instead of --pose-sigma.
    #[arg(
        long,
        value_name = "TOPIC",
        requires = "bag",
        conflicts_with = "pose_sigma"
    )]
    pose_covariance_topic: Option<String>,
    /// map: the range noise σ of every view's points (metres), along the rays from each
    /// view's sensor origin; default: estimated from the views (the spread of each
    /// point's 16 nearest neighbours across their plane, the median over the views).
    #[arg(long, value_name = "METRES")]
    range_sigma: Option<f64>,
    /// map: where a view without per-point sensor origins was taken from: `auto`, the
    /// origin of its own frame where that stands on the side the view was seen from or away
    /// from its points (the convention of scanners' files, PCL's default VIEWPOINT and a ROS sensor frame),
    /// else each point seen along the view's direction estimated from its surface (a
    /// turntable's or an object frame: the Stanford scans); `frame`, always its frame's
    /// origin; or `unknown` (isotropic noise, no test of which way a surface faces).
    #[arg(long, value_enum, value_name = "WHERE", default_value_t = SensorOriginArg::Auto)]
    sensor_origin: SensorOriginArg,
    /// p-ICP-GPA: how the mutual-nearest-neighbour graph becomes independent sets.
    #[arg(long, value_enum, default_value_t = SetRuleArg::Cliques)]
    set_rule: SetRuleArg,
    /// Worker threads (default: all cores). Results do not depend on it.
    #[arg(long, value_name = "N")]
    threads: Option<usize>,
    /// Output model cloud (.ply or .pcd).
    #[arg(short, long, value_name = "MODEL.ply")]
    output: PathBuf,
    /// Output poses (see POSE FILES).
    #[arg(long, value_name = "POSES.json")]
    poses: PathBuf,
    /// Also write the full registration report (JSON).
    #[arg(long, value_name = "REPORT.json")]
    report: Option<PathBuf>,
}

/// `--sensor-origin` values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
enum SensorOriginArg {
    /// The frame's origin unless it stands behind the view's surface among its points,
    /// else along the view's estimated direction.
    Auto,
    /// The origin of the view's own frame.
    Frame,
    /// Unknown.
    Unknown,
}

/// `--set-rule` values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
enum SetRuleArg {
    /// Connected components that are complete graphs (the paper's definition).
    Cliques,
    /// Every connected component with at most one point per view (a public
    /// implementation's rule).
    Components,
}

/// `--method` values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
enum MethodArg {
    /// p-ICP-GPA: all views at once (paper, Figure 4).
    Gpa,
    /// Maximum a posteriori: all views at once, residuals weighted by the range noise,
    /// optionally a prior on each initial pose (--pose-sigma).
    Map,
    /// Sequential point-to-point ICP: view h onto view h−1, chained.
    Icp,
    /// Sequential point-to-plane ICP.
    IcpPlane,
}

impl MethodArg {
    fn method(self) -> Method {
        match self {
            Self::Gpa => Method::Gpa,
            Self::Map => Method::Map,
            Self::Icp => Method::SequentialIcp {
                point_to_plane: false,
            },
            Self::IcpPlane => Method::SequentialIcp {
                point_to_plane: true,
            },
        }
    }

    fn name(self) -> &'static str {
        match self {
            Self::Gpa => "p-ICP-GPA",
            Self::Map => "MAP registration",
            Self::Icp => "sequential ICP (point-to-point)",
            Self::IcpPlane => "sequential ICP (point-to-plane)",
        }
    }
}

/// The views to register: their names (the pose files' keys), labels for messages, clouds
/// and initial poses.
struct Input {
    names: Vec<String>,
    labels: Vec<String>,
    views: Vec<PointCloud>,
    initial: Vec<Pose>,
    /// Each view's pose prior, where the bag gives it.
    priors: Option<Vec<PosePrior>>,
}

/// Reads the views from the files or the bag.
fn read_input(args: &RegisterArgs) -> Result<Input> {
    if let Some(read) = args.bag.read(args.pose_covariance_topic.as_deref())? {
        check_count_and_reference(args, read.clouds.len(), "the bag's topic")?;
        return Ok(Input {
            labels: read.names.clone(),
            names: read.names,
            views: read.clouds,
            initial: read.poses,
            priors: read.priors,
        });
    }
    let names = file_names(&args.views)?;
    check_count_and_reference(args, args.views.len(), &args.views[0].display().to_string())?;
    let views = args
        .views
        .iter()
        .map(|path| read_view(path))
        .collect::<Result<Vec<_>>>()?;
    let initial = match &args.init {
        Some(path) => read_poses(path, &names)?,
        None => vec![Pose::identity(); views.len()],
    };
    Ok(Input {
        names,
        labels: args.views.iter().map(|p| p.display().to_string()).collect(),
        views,
        initial,
        priors: None,
    })
}

/// Runs `nbv register …`.
pub fn run(args: RegisterArgs) -> Result<ExitCode> {
    check_outputs(&args)?;
    let Input {
        names,
        labels,
        mut views,
        initial,
        priors,
    } = read_input(&args)?;
    if let Some(p) = &priors {
        let (r, t): (Vec<f64>, Vec<f64>) = p
            .iter()
            .map(|p| (p.rotation_sigma.to_degrees(), p.translation_sigma * 1e3))
            .unzip();
        let range = |v: &[f64]| {
            let (lo, hi) = v
                .iter()
                .fold((f64::MAX, f64::MIN), |(lo, hi), x| (lo.min(*x), hi.max(*x)));
            format!("{lo:.3}–{hi:.3}")
        };
        println!(
            "pose priors from {}: rotation σ {}°, translation σ {} mm",
            args.pose_covariance_topic.as_deref().unwrap_or_default(),
            range(&r),
            range(&t)
        );
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.threads.unwrap_or(0))
        .build()
        .context("cannot start the worker threads")?;
    let start = Instant::now();
    if args.method == MethodArg::Map {
        pool.install(|| set_sensor_origins(&mut views, &labels, args.sensor_origin));
    }
    let range_sigma = match args.range_sigma {
        Some(sigma) => sigma,
        None if args.method == MethodArg::Map => {
            let sigma = pool.install(|| estimate_range_sigma(&views)).context(
                "cannot estimate the range noise (too few points per view): give --range-sigma",
            )?;
            println!(
                "range noise σ estimated from the views: {:.3} mm",
                sigma * 1e3
            );
            sigma
        }
        None => DEFAULT_RANGE_SIGMA,
    };
    let (params, models) = registration_params(&args, views.len(), range_sigma, priors)?;
    let registration = pool
        .install(|| {
            if args.method == MethodArg::Map {
                register_coarse_to_fine(&views, &initial, &models, &params)
            } else {
                register_with_models(&views, &initial, &models, &params)
            }
        })
        .map_err(|e| anyhow!(name_view(&e.to_string(), &labels)))?;
    let elapsed = start.elapsed();
    let model = registration.merged(&views)?;
    RegistrationFiles {
        model: &args.output,
        poses: &args.poses,
        report: args.report.as_deref(),
    }
    .write(&names, &registration, &model)?;

    let points: usize = views.iter().map(PointCloud::len).sum();
    let rms = registration
        .rms
        .map_or("-".to_string(), |r| format!("{:.3} mm", r * 1e3));
    println!(
        "registered {} views ({points} points) by {} in {:.1} ms: {}, rms {rms}; {}",
        views.len(),
        args.method.name(),
        elapsed.as_secs_f64() * 1e3,
        if registration.converged {
            "converged"
        } else {
            "NOT converged"
        },
        method_detail(&registration.report, &names, &labels),
    );
    println!(
        "wrote {} and {}",
        args.output.display(),
        args.poses.display()
    );
    if registration.converged {
        Ok(ExitCode::SUCCESS)
    } else {
        eprintln!("warning: the registration did not converge; the poses may be wrong");
        Ok(ExitCode::from(NOT_CONVERGED))
    }
}

/// Two views or more (`n`, from `source`), the reference among them.
fn check_count_and_reference(args: &RegisterArgs, n: usize, source: &str) -> Result<()> {
    if n < 2 {
        bail!("registration needs at least 2 views, got {n} ({source})");
    }
    if args.reference >= n {
        bail!(
            "--reference {} is out of range for {n} views",
            args.reference
        );
    }
    Ok(())
}

/// Checks the outputs before reading anything: none is also a view or the bag, the model
/// has a cloud extension.
fn check_outputs(args: &RegisterArgs) -> Result<()> {
    for out in [&args.output, &args.poses]
        .into_iter()
        .chain(args.report.as_ref())
    {
        if args
            .views
            .iter()
            .chain(args.bag.bag.as_ref())
            .any(|v| same_file(v, out))
        {
            bail!("output {} is also an input view", out.display());
        }
    }
    CloudFormat::from_path(&args.output)
        .with_context(|| format!("output model {}", args.output.display()))?;
    Ok(())
}

/// The registration's parameters from the options, validated, and the model of each of the
/// `n` views (the range noise and the pose prior: `priors`' per view where the bag gives
/// them, else `--pose-sigma`'s).
fn registration_params(
    args: &RegisterArgs,
    n: usize,
    range_sigma: f64,
    priors: Option<Vec<PosePrior>>,
) -> Result<(RegistrationParams, Vec<ViewModel>)> {
    let params = RegistrationParams {
        method: args.method.method(),
        reference: args.reference,
        max_correspondence_distance: args.max_distance,
        max_iterations: args.max_iterations,
        set_rule: match args.set_rule {
            SetRuleArg::Cliques => SetRule::Cliques,
            SetRuleArg::Components => SetRule::Components,
        },
        ..RegistrationParams::default()
    };
    params.validate().context("bad option")?;
    let noise = RangeNoise::constant(range_sigma);
    if !noise.is_valid() {
        bail!("--range-sigma must be finite and > 0, got {range_sigma}");
    }
    // Each view's own prior from the bag, else --pose-sigma's for all.
    let models = (0..n)
        .map(|k| ViewModel {
            noise,
            prior: priors.as_ref().map_or(args.pose_sigma, |p| Some(p[k])),
        })
        .collect();
    Ok((params, models))
}

/// Gives every view without per-point sensor origins its sensor (`--sensor-origin`) and
/// says which views were seen along their estimated direction.
fn set_sensor_origins(views: &mut [PointCloud], labels: &[String], rule: SensorOriginArg) {
    let rule = match rule {
        SensorOriginArg::Auto => SensorOrigin::Auto,
        SensorOriginArg::Frame => SensorOrigin::Frame,
        SensorOriginArg::Unknown => SensorOrigin::Unknown,
    };
    let along = assign_sensor_origins(views, rule);
    if along.is_empty() {
        return;
    }
    let rest = if along.len() < views.len() {
        ", the rest without a sensor"
    } else {
        ""
    };
    let names: Vec<&str> = along.iter().map(|&k| labels[k].as_str()).collect();
    println!(
        "sensor: {} of {} views seen along the direction estimated from their surface \
         (their frame's origin stands behind it, among their points){rest}: {}",
        along.len(),
        views.len(),
        names.join(", ")
    );
}

/// The range noise of the methods that do not estimate it (p-ICP-GPA and ICP ignore it).
const DEFAULT_RANGE_SIGMA: f64 = 0.002;

/// The method's own figures for the printed line: steps and correspondences (MAP), sets
/// and the views not tied to the reference (p-ICP-GPA), or each pair (sequential ICP).
fn method_detail(report: &MethodReport, names: &[String], views: &[String]) -> String {
    match report {
        MethodReport::Map(m) => format!(
            "{} steps, {} correspondences, stop: {:?}; {}",
            m.iterations, m.inliers, m.stop, m.verdict
        ),
        MethodReport::Gpa(g) => format!(
            "{} iterations, {} independent sets, stop: {:?}{}",
            g.iterations,
            g.independent_sets,
            g.stop,
            if g.unconnected_views.is_empty() {
                String::new()
            } else {
                format!(
                    ", views not tied to the reference: {}",
                    list_views(&g.unconnected_views, views)
                )
            }
        ),
        MethodReport::SequentialIcp(s) => s
            .pairs
            .iter()
            .map(|p| {
                format!(
                    "{} onto {}: {} iterations, {:?}",
                    names[p.source], names[p.target], p.icp.iterations, p.icp.stop
                )
            })
            .collect::<Vec<_>>()
            .join("; "),
    }
}

/// Parses `--pose-sigma DEG,METRES`.
fn parse_pose_sigma(text: &str) -> Result<PosePrior, String> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    let [deg, m] = parts[..] else {
        return Err(format!(
            "expected DEGREES,METRES (e.g. 0.5,0.004), got {text:?}"
        ));
    };
    let number = |s: &str, what: &str| {
        s.parse::<f64>()
            .ok()
            .filter(|v| v.is_finite() && *v > 0.0)
            .ok_or_else(|| format!("{what} {s:?} is not a positive number"))
    };
    Ok(PosePrior {
        rotation_sigma: number(deg, "rotation σ")?.to_radians(),
        translation_sigma: number(m, "translation σ")?,
    })
}

/// The file name of every view (the keys of the pose files); names must be distinct.
fn file_names(views: &[PathBuf]) -> Result<Vec<String>> {
    let mut seen = BTreeMap::new();
    views
        .iter()
        .map(|path| {
            let name = path
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .ok_or_else(|| anyhow!("{}: not a file name", path.display()))?;
            if let Some(other) = seen.insert(name.clone(), path) {
                bail!(
                    "{} and {} have the same file name, which keys the pose files",
                    other.display(),
                    path.display()
                );
            }
            Ok(name)
        })
        .collect()
}

/// Whether two paths name the same file (by canonical path when both exist).
fn same_file(a: &Path, b: &Path) -> bool {
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        _ => a == b,
    }
}

/// Reads one view; non-finite points are dropped and reported.
fn read_view(path: &Path) -> Result<PointCloud> {
    let file = read_cloud_with(path, &Default::default())
        .with_context(|| format!("cannot read view {}", path.display()))?;
    if file.dropped_non_finite > 0 {
        eprintln!(
            "warning: {}: dropped {} points with NaN or infinite values",
            path.display(),
            file.dropped_non_finite
        );
    }
    if file.cloud.is_empty() {
        bail!("view {} has no (finite) point", path.display());
    }
    Ok(file.cloud)
}

/// Reads `--init`: a pose for every name in `names`.
fn read_poses(path: &Path, names: &[String]) -> Result<Vec<Pose>> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("cannot read initial poses {}", path.display()))?;
    parse_poses(&text, names).with_context(|| path.display().to_string())
}

/// Adds the view's label (its file or bag message) after the first "view K" of a library
/// message.
fn name_view(message: &str, views: &[String]) -> String {
    let Some(at) = message.find("view ") else {
        return message.to_string();
    };
    let digits_start = at + "view ".len();
    let digits = message[digits_start..]
        .bytes()
        .take_while(u8::is_ascii_digit)
        .count();
    let end = digits_start + digits;
    match message[digits_start..end]
        .parse::<usize>()
        .ok()
        .and_then(|k| views.get(k))
    {
        Some(label) => format!("{} ({label}){}", &message[..end], &message[end..]),
        None => message.to_string(),
    }
}

/// "k (file), …" for view indices.
fn list_views(indices: &[usize], views: &[String]) -> String {
    indices
        .iter()
        .map(|&k| format!("{k} ({})", views[k]))
        .collect::<Vec<_>>()
        .join(", ")
}
