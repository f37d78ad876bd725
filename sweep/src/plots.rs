//! A sweep's plots (SVG, with plotters; no fonts or GPU needed): a heatmap of the mean
//! coverage over the first two swept parameters, the coverage of each episode against
//! its views per object, when the sweep spans several error levels the registration
//! error of each method against the level (Table III's plot), and when it sweeps
//! `nbv.objective` the mean coverage after each view, one line per objective; with the
//! oracle (`oracle = true`), the mean coverage after each view beside the oracle's greedy
//! curve.

use crate::error::{Result, invalid};
use crate::rows::EpisodeRow;
use plotters::prelude::*;
use std::collections::BTreeMap;
use std::path::Path;

/// Writes `heatmap_coverage.svg` (when at least one parameter is swept),
/// `coverage_vs_views.svg`, `registration_vs_level.svg` (when the registrations span
/// two error levels or more), `coverage_by_view_per_objective.svg` (when
/// `nbv.objective` is swept) and `coverage_by_view_vs_oracle.svg` (with the oracle) into
/// `dir`; returns the files written.
pub fn write(dir: &Path, rows: &[EpisodeRow]) -> Result<Vec<String>> {
    std::fs::create_dir_all(dir)?;
    let mut written = Vec::new();
    if rows.first().is_some_and(|r| !r.params.is_empty()) {
        let svg = heatmap(rows)?;
        save(&dir.join("heatmap_coverage.svg"), &svg)?;
        written.push("heatmap_coverage.svg".to_string());
    }
    if !rows.is_empty() {
        let svg = scatter(rows)?;
        save(&dir.join("coverage_vs_views.svg"), &svg)?;
        written.push("coverage_vs_views.svg".to_string());
    }
    let mut levels: Vec<i64> = rows
        .iter()
        .flat_map(|r| &r.registrations)
        .map(|r| (r.level * 1000.0).round() as i64)
        .collect();
    levels.sort_unstable();
    levels.dedup();
    if levels.len() >= 2 {
        let svg = registration_vs_level(rows)?;
        save(&dir.join("registration_vs_level.svg"), &svg)?;
        written.push("registration_vs_level.svg".to_string());
    }
    let objectives: Vec<_> = crate::objectives::objective_table(rows)
        .into_iter()
        .filter(|l| l.scenes == "all")
        .collect();
    if !objectives.is_empty() {
        let svg = coverage_by_view(&objectives)?;
        save(&dir.join("coverage_by_view_per_objective.svg"), &svg)?;
        written.push("coverage_by_view_per_objective.svg".to_string());
    }
    let with_oracle: Vec<&EpisodeRow> = rows
        .iter()
        .filter(|r| !r.greedy_by_view.is_empty())
        .collect();
    if !with_oracle.is_empty() {
        let explored =
            crate::rows::mean_curve(with_oracle.iter().map(|r| r.coverage_by_view.as_slice()));
        let greedy =
            crate::rows::mean_curve(with_oracle.iter().map(|r| r.greedy_by_view.as_slice()));
        let curves = [
            Curve {
                label: "explored (mean over the episodes)".into(),
                values: explored,
                colour: 0,
                width: 3,
            },
            Curve {
                label: "oracle: greedy set cover".into(),
                values: greedy,
                colour: 1,
                width: 2,
            },
        ];
        let svg = curves_svg(
            "coverage after each view, beside the oracle's",
            "mean object coverage",
            &curves,
        )?;
        save(&dir.join("coverage_by_view_vs_oracle.svg"), &svg)?;
        written.push("coverage_by_view_vs_oracle.svg".to_string());
    }
    Ok(written)
}

/// Mean coverage after k views per object, one line per objective.
fn coverage_by_view(lines: &[crate::objectives::ObjectiveLine]) -> Result<String> {
    let curves: Vec<Curve> = lines
        .iter()
        .enumerate()
        .map(|(i, l)| Curve {
            label: l.objective.clone(),
            values: l.coverage_by_view.clone(),
            colour: i,
            width: if l.objective == "paper" { 4 } else { 2 },
        })
        .collect();
    curves_svg(
        "coverage after each view, per objective",
        "mean object coverage",
        &curves,
    )
}

/// One line of [`curves_svg`]: its values after 0, 1, … views.
#[derive(Debug, Clone)]
pub(crate) struct Curve {
    /// The legend's text.
    pub label: String,
    /// The values after 0, 1, … views.
    pub values: Vec<f64>,
    /// Index into plotters' 99-colour palette.
    pub colour: usize,
    /// Stroke width.
    pub width: u32,
}

/// A chart of `curves` against short-range views (0: the laser cluster), values in [0, 1].
pub(crate) fn curves_svg(title: &str, y_desc: &str, curves: &[Curve]) -> Result<String> {
    let mut svg = String::new();
    let k_max = curves
        .iter()
        .map(|c| c.values.len())
        .max()
        .unwrap_or(1)
        .saturating_sub(1)
        .max(1);
    // From the tenth below the lowest value: the curves' differences near the top show.
    let lowest = curves
        .iter()
        .flat_map(|c| c.values.iter().copied())
        .filter(|v| v.is_finite())
        .fold(1.0f64, f64::min);
    let y_min = ((lowest * 10.0).floor() / 10.0).clamp(0.0, 0.9);
    let root = SVGBackend::with_string(&mut svg, (800, 600)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| invalid!("{e}"))?;
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 20))
        .margin(20)
        .x_label_area_size(50)
        .y_label_area_size(60)
        .build_cartesian_2d(0f64..k_max as f64, y_min..1f64)
        .map_err(|e| invalid!("{e}"))?;
    chart
        .configure_mesh()
        .x_desc("short-range views per object (0: the laser cluster)")
        .y_desc(y_desc)
        .draw()
        .map_err(|e| invalid!("{e}"))?;
    for c in curves {
        let colour = Palette99::pick(c.colour).to_rgba();
        let points: Vec<(f64, f64)> = c
            .values
            .iter()
            .enumerate()
            .map(|(k, v)| (k as f64, *v))
            .collect();
        let width = c.width;
        chart
            .draw_series(LineSeries::new(points, colour.stroke_width(width)))
            .map_err(|e| invalid!("{e}"))?
            .label(c.label.clone())
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(width))
            });
    }
    legend_and_present(&mut chart, &root, SeriesLabelPosition::LowerRight)?;
    drop(chart);
    drop(root);
    Ok(svg)
}

/// `coverage_by_view.svg` of an episode: each matched object's coverage after each view
/// (thick), the same views seen without noise (medium) and the oracle's greedy curve
/// (thin), one colour per object, when the report carries the oracle.
pub fn write_episode_coverage(dir: &Path, report: &crate::report::ExploreReport) -> Result<bool> {
    let mut curves = Vec::new();
    for (i, o) in report.objects.iter().enumerate() {
        let Some(oracle) = &o.oracle else { continue };
        curves.push(Curve {
            label: format!("{}: explored", o.name),
            values: o.coverage_by_view.clone(),
            colour: i,
            width: 3,
        });
        if !oracle.noise_free_by_view.is_empty() {
            curves.push(Curve {
                label: format!("{}: the same views without noise", o.name),
                values: oracle.noise_free_by_view.clone(),
                colour: i,
                width: 2,
            });
        }
        curves.push(Curve {
            label: format!(
                "{}: oracle (greedy), ceiling {:.1} %",
                o.name,
                100.0 * oracle.ceiling
            ),
            values: oracle.greedy.clone(),
            colour: i,
            width: 1,
        });
    }
    if curves.is_empty() {
        return Ok(false);
    }
    let svg = curves_svg(
        "coverage after each view, beside the oracle's",
        "coverage",
        &curves,
    )?;
    save(&dir.join("coverage_by_view.svg"), &svg)?;
    Ok(true)
}

/// Draws the legend of a line chart at `position` and finishes the picture.
fn legend_and_present<'a, 'b: 'a>(
    chart: &mut ChartContext<
        'a,
        SVGBackend<'b>,
        Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
    >,
    root: &DrawingArea<SVGBackend<'b>, plotters::coord::Shift>,
    position: SeriesLabelPosition,
) -> Result<()> {
    chart
        .configure_series_labels()
        .position(position)
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(|e| invalid!("{e}"))?;
    root.present().map_err(|e| invalid!("{e}"))?;
    Ok(())
}

fn save(path: &Path, svg: &str) -> Result<()> {
    nbv_scenes::paths::write_atomic(path, svg.as_bytes())
        .map_err(|e| invalid!("writing {}: {e}", path.display()))
}

/// Mean coverage per (first parameter, second parameter) cell; one row when only one
/// parameter is swept.
fn heatmap(rows: &[EpisodeRow]) -> Result<String> {
    let mut svg = String::new();
    let keys: Vec<String> = rows[0].params.iter().map(|(k, _)| k.clone()).collect();
    let x_key = keys[0].clone();
    let y_key = keys.get(1).cloned();
    let mut xs: Vec<String> = Vec::new();
    let mut ys: Vec<String> = Vec::new();
    let mut cells: BTreeMap<(usize, usize), Vec<f64>> = BTreeMap::new();
    for r in rows {
        let x = r.params[0].1.clone();
        let y = r.params.get(1).map_or(String::new(), |p| p.1.clone());
        let xi = xs.iter().position(|v| v == &x).unwrap_or_else(|| {
            xs.push(x);
            xs.len() - 1
        });
        let yi = ys.iter().position(|v| v == &y).unwrap_or_else(|| {
            ys.push(y);
            ys.len() - 1
        });
        cells.entry((xi, yi)).or_default().push(r.coverage);
    }
    let root = SVGBackend::with_string(&mut svg, (800, 600)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| invalid!("{e}"))?;
    let title = format!(
        "mean coverage over {x_key}{}",
        y_key.as_ref().map_or(String::new(), |y| format!(" x {y}"))
    );
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 20))
        .margin(20)
        .x_label_area_size(50)
        .y_label_area_size(80)
        .build_cartesian_2d(
            (0..xs.len() as i32).into_segmented(),
            (0..ys.len() as i32).into_segmented(),
        )
        .map_err(|e| invalid!("{e}"))?;
    let (xs_l, ys_l) = (xs.clone(), ys.clone());
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc(x_key)
        .y_desc(y_key.unwrap_or_default())
        .x_label_formatter(&move |v| label_at(&xs_l, v))
        .y_label_formatter(&move |v| label_at(&ys_l, v))
        .draw()
        .map_err(|e| invalid!("{e}"))?;
    for (&(xi, yi), v) in &cells {
        let c = v.iter().sum::<f64>() / v.len() as f64;
        let (x, y) = (xi as i32, yi as i32);
        // From dark blue (0) to yellow (1).
        let t = c.clamp(0.0, 1.0);
        let colour = RGBColor(
            (40.0 + 215.0 * t) as u8,
            (40.0 + 180.0 * t) as u8,
            (140.0 - 100.0 * t) as u8,
        );
        chart
            .draw_series(std::iter::once(Rectangle::new(
                [
                    (SegmentValue::Exact(x), SegmentValue::Exact(y)),
                    (SegmentValue::Exact(x + 1), SegmentValue::Exact(y + 1)),
                ],
                colour.filled(),
            )))
            .map_err(|e| invalid!("{e}"))?;
        chart
            .draw_series(std::iter::once(Text::new(
                format!("{:.1}%", 100.0 * c),
                (SegmentValue::CenterOf(x), SegmentValue::CenterOf(y)),
                ("sans-serif", 16).into_font().color(&BLACK),
            )))
            .map_err(|e| invalid!("{e}"))?;
    }
    root.present().map_err(|e| invalid!("{e}"))?;
    drop(chart);
    drop(root);
    Ok(svg)
}

/// The label of a cell centre; nothing at cell edges.
fn label_at(labels: &[String], v: &SegmentValue<i32>) -> String {
    match v {
        SegmentValue::CenterOf(k) => usize::try_from(*k)
            .ok()
            .and_then(|k| labels.get(k).cloned())
            .unwrap_or_default(),
        _ => String::new(),
    }
}

/// One point per episode: views per object against mean coverage.
fn scatter(rows: &[EpisodeRow]) -> Result<String> {
    let mut svg = String::new();
    let pts: Vec<(f64, f64)> = rows
        .iter()
        .map(|r| {
            let objects = (r.objects - r.missed).max(1) as f64;
            (r.views as f64 / objects, 100.0 * r.coverage)
        })
        .collect();
    let x_max = pts.iter().map(|p| p.0).fold(1.0, f64::max) * 1.1;
    let root = SVGBackend::with_string(&mut svg, (800, 600)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| invalid!("{e}"))?;
    let mut chart = ChartBuilder::on(&root)
        .caption("coverage against views", ("sans-serif", 20))
        .margin(20)
        .x_label_area_size(50)
        .y_label_area_size(60)
        .build_cartesian_2d(0f64..x_max, 0f64..100f64)
        .map_err(|e| invalid!("{e}"))?;
    chart
        .configure_mesh()
        .x_desc("short-range views per object")
        .y_desc("mean surface coverage (%)")
        .draw()
        .map_err(|e| invalid!("{e}"))?;
    chart
        .draw_series(
            pts.iter()
                .map(|&p| Circle::new(p, 4, RGBColor(31, 119, 180).filled())),
        )
        .map_err(|e| invalid!("{e}"))?;
    root.present().map_err(|e| invalid!("{e}"))?;
    drop(chart);
    drop(root);
    Ok(svg)
}

/// The registration error against the error level (Table III's plot): per method, the
/// median (solid) and 95th percentile (dashed) over every object registration at a level.
fn registration_vs_level(rows: &[EpisodeRow]) -> Result<String> {
    let mut svg = String::new();
    let mut by: BTreeMap<i64, Vec<&crate::rows::ObjectRegistrationRow>> = BTreeMap::new();
    for r in rows.iter().flat_map(|r| &r.registrations) {
        by.entry((r.level * 1000.0).round() as i64)
            .or_default()
            .push(r);
    }
    // The baselines are absent (None) in episodes that ran without them: a method is
    // drawn only at the levels where some registration has it.
    type Pick = fn(&crate::rows::ObjectRegistrationRow) -> Option<f64>;
    let methods: [(&str, Pick, RGBColor); 4] = [
        ("as acquired", |r| Some(r.acquired), RGBColor(120, 120, 120)),
        ("map (the model's)", |r| Some(r.map), RGBColor(31, 119, 180)),
        ("p-ICP-GPA (paper)", |r| r.pgpa, RGBColor(255, 127, 14)),
        ("sequential ICP", |r| r.icp, RGBColor(44, 160, 44)),
    ];
    let levels: Vec<f64> = by.keys().map(|k| *k as f64 / 1000.0).collect();
    let lines: Vec<Vec<(f64, f64, f64)>> = methods
        .iter()
        .map(|(_, pick, _)| {
            by.iter()
                .filter_map(|(k, regs)| {
                    let v: Vec<f64> = regs
                        .iter()
                        .filter_map(|r| pick(r))
                        .map(|e| 1e3 * e)
                        .collect();
                    let (m, p95) = crate::rows::quantiles(&v);
                    (!v.is_empty()).then_some((*k as f64 / 1000.0, m, p95))
                })
                .collect()
        })
        .collect();
    let y_max = lines
        .iter()
        .flatten()
        .map(|p| p.2)
        .fold(1.0, f64::max)
        .min(100.0)
        * 1.1;
    let x_min = levels.first().copied().unwrap_or(1.0);
    let x_max = levels.last().copied().unwrap_or(1.0);
    let pad = ((x_max - x_min) * 0.05).max(0.1);
    let root = SVGBackend::with_string(&mut svg, (800, 600)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| invalid!("{e}"))?;
    let mut chart = ChartBuilder::on(&root)
        .caption(
            "registration: alignment error against error level",
            ("sans-serif", 20),
        )
        .margin(20)
        .x_label_area_size(50)
        .y_label_area_size(60)
        .build_cartesian_2d((x_min - pad)..(x_max + pad), 0f64..y_max)
        .map_err(|e| invalid!("{e}"))?;
    chart
        .configure_mesh()
        .x_desc("error level (errors.scale: the scene's [errors] times)")
        .y_desc("mean alignment error (mm): median solid, 95th percentile dashed")
        .draw()
        .map_err(|e| invalid!("{e}"))?;
    for ((name, _, colour), line) in methods.iter().zip(&lines) {
        if line.is_empty() {
            continue;
        }
        let colour = *colour;
        let median: Vec<(f64, f64)> = line.iter().map(|p| (p.0, p.1.min(y_max))).collect();
        let p95: Vec<(f64, f64)> = line.iter().map(|p| (p.0, p.2.min(y_max))).collect();
        chart
            .draw_series(LineSeries::new(median.clone(), colour.stroke_width(3)))
            .map_err(|e| invalid!("{e}"))?
            .label(*name)
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour));
        chart
            .draw_series(median.iter().map(|&p| Circle::new(p, 4, colour.filled())))
            .map_err(|e| invalid!("{e}"))?;
        chart
            .draw_series(DashedLineSeries::new(p95, 6, 4, colour.stroke_width(1)))
            .map_err(|e| invalid!("{e}"))?;
    }
    legend_and_present(&mut chart, &root, SeriesLabelPosition::UpperLeft)?;
    drop(chart);
    drop(root);
    Ok(svg)
}
