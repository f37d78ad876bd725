#!/usr/bin/env python3
"""Markdown tables of a view-objective sweep's summary.json (docs/objectives.md).

usage: python3 benches/figures/objectives_table.py OUT/summary.json [OUT/episodes]

One table per scene group ("all", then each group the summary has): coverage after 1, 2,
4 and 8 views per object, views to 80 % / 90 % (episodes that reached it), final coverage,
precision, F-score, views per episode, joint distance and the NBV step's time per view.
With the episodes directory, also why each objective's objects stopped.
"""
import collections
import glob
import json
import sys


def pct(x):
    return f"{100 * x:.1f}"


def table(lines):
    out = [
        "| objective | episodes | cov. after 1 / 2 / 4 / 8 views | views to 80 % (reached) "
        "| views to 90 % (reached) | final coverage | precision | F-score | views / episode "
        "| joint distance (rad) | NBV step s / view | collisions |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for o in lines:
        c = o["coverage_by_view"]
        at = lambda k: pct(c[min(k, len(c) - 1)]) if c else "–"
        reach = lambda v, n: (f"{v:.1f}" if n else "–") + f" ({n})"
        out.append(
            f"| {o['objective']} | {o['episodes']} | {at(1)} / {at(2)} / {at(4)} / {at(8)} "
            f"| {reach(o['views_to_80'], o['reached_80'])} | {reach(o['views_to_90'], o['reached_90'])} "
            f"| {pct(o['coverage'])} | {pct(o['precision'])} | {pct(o['f_score'])} "
            f"| {o['views']:.1f} | {o['joint_distance']:.1f} | {o['nbv_time_per_view']:.3f} "
            f"| {o['collisions']} |"
        )
    return "\n".join(out)


def main():
    summary = json.load(open(sys.argv[1]))
    groups = collections.OrderedDict()
    for o in summary["objectives"]:
        groups.setdefault(o["scenes"], []).append(o)
    for name, lines in groups.items():
        print(f"#### {name}\n\n{table(lines)}\n")
    if len(sys.argv) > 2:
        stops = collections.defaultdict(collections.Counter)
        for row in glob.glob(f"{sys.argv[2]}/*/report.json"):
            r = json.load(open(row))
            objective = r.get("config", {}).get("nbv", {}).get("objective", "paper")
            for o in r["objects"]:
                stop = o.get("stop") or "?"
                # "gain 0.436 below threshold 2.5" → the rule, not its figures.
                stop = "gain threshold" if stop.startswith("gain") else stop
                stop = "dropped (not an object)" if stop.startswith("dropped") else stop
                stops[objective][stop] += 1
        print("| objective | stops |\n|---|---|")
        for k, v in sorted(stops.items()):
            print(f"| {k} | " + ", ".join(f"{s} {n}" for s, n in v.most_common()) + " |")


if __name__ == "__main__":
    main()
