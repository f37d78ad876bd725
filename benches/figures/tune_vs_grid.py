#!/usr/bin/env python3
"""`nbv tune` against a 5 x 5 x 5 grid and random search on the same episodes.

Reads the episode rows of a sweep directory (the grid), of tune directories (their
`trials/NNNN/` and `random/trials/NNNN/`), groups them by setting and prints, per method:
the settings and episodes it ran, its best mean F-score, and the hypervolume its settings
dominate in (mean F-score up, views per object down) after n settings, as a share of the
box between the best and worst values any method saw (the reference point 10 % beyond the
worst). Figures in docs/tuning.md.

    python3 benches/figures/tune_vs_grid.py GRID_DIR|GRID_CSV TUNE_F_DIR [TUNE_2_DIR]

The issue's task (`examples/tune/exploration_grid_5x5x5.toml` and
`exploration_f_score.toml`) has no two-objective run: leave TUNE_2_DIR out.
"""

import csv
import glob
import json
import os
import sys


def rows_in(pattern):
    return [json.load(open(f)) for f in sorted(glob.glob(pattern))]


def figures(rows):
    """Mean F-score and views per object of a setting's rows, as the sweep aggregates."""
    f = sum(r["f_score"] for r in rows) / len(rows)
    views = sum(r["views"] for r in rows) / max(1, sum(r["objects"] for r in rows))
    ok = all(r["collisions"] == 0 and r["missed"] == 0 for r in rows)
    return f, views, ok


TUNED = ("nbv.alpha_u", "nbv.alpha_o", "nbv.gain_threshold")


def grid_settings(d):
    """The grid's settings from a sweep directory's rows, or from a CSV of its episodes
    (the sweep's results.csv, or benches/figures/task_grid_episodes.csv)."""
    by = {}
    if d.endswith(".csv"):
        for r in csv.DictReader(open(d)):
            row = {k: float(r[k]) for k in ("f_score", "views", "objects", "collisions", "missed")}
            by.setdefault(tuple(r[k] for k in TUNED), []).append(row)
    else:
        for r in rows_in(os.path.join(d, "episodes", "*.row.json")):
            key = tuple((k, v) for k, v in r["params"] if k != "registration.baselines")
            by.setdefault(key, []).append(r)
    return [figures(v) for _, v in sorted(by.items())]


def trial_settings(d):
    out = []
    k = 0
    while os.path.isdir(os.path.join(d, "trials", f"{k:04d}")):
        out.append(figures(rows_in(os.path.join(d, "trials", f"{k:04d}", "*.row.json"))))
        k += 1
    return out


def hypervolume(points, ideal, nadir):
    """Area dominated by (F up, views down) points, scaled to the box, reference 1.1."""
    span = (max(ideal[0] - nadir[0], 1e-12), max(nadir[1] - ideal[1], 1e-12))
    # Losses: how far below the best F, how far above the fewest views, in box units.
    pts = sorted(((ideal[0] - f) / span[0], (v - ideal[1]) / span[1]) for f, v in points)
    area, ceiling = 0.0, 1.1
    for x, y in pts:
        if x < 1.1 and y < ceiling:
            area += (1.1 - x) * (ceiling - y)
            ceiling = y
    return area / (1.1 * 1.1)


def main():
    if len(sys.argv) not in (3, 4):
        sys.exit(__doc__)
    grid_dir, tune_f = sys.argv[1:3]
    methods = {
        "grid 5x5x5": grid_settings(grid_dir),
        "tune, F-score (Bayesian)": trial_settings(tune_f),
        "random search (tune_f's)": trial_settings(os.path.join(tune_f, "random")),
    }
    if len(sys.argv) == 4:
        methods["tune, F-score and views (EHVI)"] = trial_settings(sys.argv[3])
    episodes_per_setting = len(rows_in(os.path.join(tune_f, "trials", "0000", "*.row.json")))
    feasible = {m: [(f, v) for f, v, ok in s if ok] for m, s in methods.items()}
    every = [p for s in feasible.values() for p in s]
    # ideal: the best F and the fewest views; nadir: the worst of each.
    ideal = (max(f for f, _ in every), min(v for _, v in every))
    nadir = (min(f for f, _ in every), max(v for _, v in every))
    print(f"box: F {nadir[0]:.4f}..{ideal[0]:.4f}, views {ideal[1]:.2f}..{nadir[1]:.2f}")
    print("| method | settings | episodes | best mean F-score | hypervolume after 12 | after all |")
    print("|---|---|---|---|---|---|")
    for m, pts in feasible.items():
        n = len(methods[m])
        best = max(f for f, _ in pts) if pts else float("nan")
        hv12 = hypervolume(pts[:12], ideal, nadir) if not m.startswith("grid") else float("nan")
        hv = hypervolume(pts, ideal, nadir)
        print(
            f"| {m} | {n} | {n * episodes_per_setting} | {100 * best:.2f} % | "
            f"{hv12:.3f} | {hv:.3f} |"
        )


if __name__ == "__main__":
    main()
