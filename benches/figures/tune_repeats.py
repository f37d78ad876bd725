#!/usr/bin/env python3
"""`nbv tune` against random search over repeated optimiser seeds: the best objective so far
after n trials, mean and standard error over the runs, and the paired difference.

Each TUNE_DIR is one `nbv tune` run of the same tune file with `random_baseline = true` and
its own `seed` (the training episodes are the same; only the optimiser's draws differ).
Prints the table docs/tuning.md quotes and, with --svg, writes the two mean curves with a
band of one standard error.

    python3 benches/figures/tune_repeats.py TUNE_DIR... [--metric f_score_mean] [--svg OUT.svg]
"""

import argparse
import csv
import os
import statistics as st
import sys


def curves(directory, metric):
    """Best feasible value so far after each trial, per arm (larger is better)."""
    path = os.path.join(directory, "trials.csv")
    if not os.path.exists(path):
        sys.exit(f"error: {path}: no such file (not a finished `nbv tune` run)")
    rows = list(csv.DictReader(open(path)))
    if rows and metric not in rows[0]:
        sys.exit(f"error: {path}: no column {metric!r}")
    out = {}
    for arm in ("tuned", "random"):
        best, curve = float("-inf"), []
        for r in sorted((r for r in rows if r["arm"] == arm), key=lambda r: int(r["trial"])):
            if r["feasible"] == "true":
                best = max(best, float(r[metric]))
            curve.append(best)
        if not curve:
            sys.exit(f"error: {path}: no {arm} trials (random_baseline = true is needed)")
        out[arm] = curve
    return out


def mean_se(values):
    m = st.mean(values)
    return m, (st.stdev(values) / len(values) ** 0.5 if len(values) > 1 else 0.0)


def svg(tuned, random, metric, path):
    """Mean best-so-far curves with ±1 standard error bands, as a plain SVG."""
    n = len(tuned)
    w, h, left, right, top, bottom = 800, 500, 80, 20, 50, 60
    lo = min(m - s for m, s in tuned + random)
    hi = max(m + s for m, s in tuned + random)
    pad = 0.05 * (hi - lo or 1.0)
    lo, hi = lo - pad, hi + pad
    x = lambda i: left + (w - left - right) * i / max(n - 1, 1)
    y = lambda v: top + (h - top - bottom) * (hi - v) / (hi - lo)
    parts = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" '
             f'font-family="sans-serif" font-size="13">',
             f'<rect width="{w}" height="{h}" fill="white"/>',
             f'<text x="{w / 2}" y="28" text-anchor="middle" font-size="17">best {metric} '
             f'so far against trials (mean of the runs, band ±1 standard error)</text>']
    for k in range(6):
        v = lo + (hi - lo) * k / 5
        parts.append(f'<line x1="{left}" x2="{w - right}" y1="{y(v):.1f}" y2="{y(v):.1f}" '
                     f'stroke="#ddd"/><text x="{left - 6}" y="{y(v) + 4:.1f}" '
                     f'text-anchor="end">{v:.3f}</text>')
    for i in range(0, n, 4 if n > 12 else 1):
        parts.append(f'<text x="{x(i):.1f}" y="{h - bottom + 18}" text-anchor="middle">{i + 1}</text>')
    parts.append(f'<text x="{(left + w - right) / 2}" y="{h - 15}" text-anchor="middle">trials</text>')
    for (name, curve, colour), row in zip(
            (("tuned", tuned, "#1f77b4"), ("random search", random, "#ff7f0e")), (0, 1)):
        band = [(x(i), y(m + s)) for i, (m, s) in enumerate(curve)] + \
               [(x(i), y(m - s)) for i, (m, s) in reversed(list(enumerate(curve)))]
        parts.append('<polygon fill="%s" fill-opacity="0.2" points="%s"/>'
                     % (colour, " ".join(f"{a:.1f},{b:.1f}" for a, b in band)))
        parts.append('<polyline fill="none" stroke="%s" stroke-width="2" points="%s"/>'
                     % (colour, " ".join(f"{x(i):.1f},{y(m):.1f}" for i, (m, _) in enumerate(curve))))
        ly = h - bottom - 40 + 20 * row
        parts.append(f'<line x1="{w - 200}" x2="{w - 175}" y1="{ly}" y2="{ly}" stroke="{colour}" '
                     f'stroke-width="2"/><text x="{w - 168}" y="{ly + 4}">{name}</text>')
    parts.append("</svg>")
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        f.write("\n".join(parts) + "\n")
    os.replace(tmp, path)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("runs", nargs="+")
    ap.add_argument("--metric", default="f_score_mean")
    ap.add_argument("--svg")
    args = ap.parse_args()
    runs = [curves(d, args.metric) for d in args.runs]
    n = min(len(c[arm]) for c in runs for arm in c)
    scale = 100.0 if args.metric.startswith(("f_score", "coverage")) else 1.0
    print(f"{len(runs)} runs, {n} trials each; {args.metric}{' (%)' if scale == 100 else ''}")
    print("| after n trials | tuned | random search | tuned − random (paired) | tuned ahead / behind |")
    print("|---|---|---|---|---|")
    tuned, random = [], []
    for i in range(n):
        t = [scale * c["tuned"][i] for c in runs]
        r = [scale * c["random"][i] for c in runs]
        d = [a - b for a, b in zip(t, r)]
        tuned.append(mean_se([v / scale for v in t]))
        random.append(mean_se([v / scale for v in r]))
        if i + 1 in (1, 2, 4, 8, 12, 16, 20, 24) or i + 1 == n:
            (tm, ts), (rm, rs), (dm, ds) = mean_se(t), mean_se(r), mean_se(d)
            print(f"| {i + 1} | {tm:.2f} ± {ts:.2f} | {rm:.2f} ± {rs:.2f} | {dm:+.2f} ± {ds:.2f} | "
                  f"{sum(v > 0 for v in d)} / {sum(v < 0 for v in d)} |")
    area = lambda c: scale * sum(c[:n]) / n
    print("mean of the best-so-far curve over the trials, run by run: tuned "
          + ", ".join(f"{area(c['tuned']):.2f}" for c in runs) + "; random "
          + ", ".join(f"{area(c['random']):.2f}" for c in runs))
    if args.svg:
        svg(tuned, random, args.metric, args.svg)
        print(f"wrote {args.svg}")


if __name__ == "__main__":
    main()
