#!/usr/bin/env python3
"""Splits a perf profile of an episode by pipeline step.

Reads `perf script -F tid,ip,sym` output of a `perf record --call-graph dwarf` run (with
inlined frames, perf's default) on stdin and attributes every sample to the step of the
leaf-most frame that names one (registration, mapping, NBV, planning, the twin's camera
and arm, phase 1, ...), then splits registration by method (MAP, p-ICP-GPA, sequential
ICP) by any frame of the sample. Prints each step's share of the samples, its CPU-seconds
(samples / the sampling frequency given as the first argument, default 199 Hz) and its
leaf functions.

Usage (docs/throughput.md, "One episode"):
    perf record -F 199 --call-graph dwarf,16384 -o perf.data \
        target/release/nbv explore --scene paper-env1 -o /tmp/prof --no-pictures
    perf script -i perf.data -F tid,ip,sym | python3 benches/profile/episode_steps.py 199
"""

import collections
import re
import sys

STEPS = [
    ("registration", ["nbv_core::registration::", "register_views", "hand_eye", "pose_uncertainty"]),
    ("mapping: grid update", ["nbv_core::occupancy::occupancy_grid", "OccupancyGrid::insert",
                              "trace_scan", "InformationGain::between"]),
    ("mapping: reduced map", ["nbv_core::occupancy::reduced_map"]),
    ("NBV: candidates and scoring", ["nbv_core::nbv::", "pipeline::candidates"]),
    ("planning", ["nbv_core::planning::"]),
    ("acquisition (twin camera)", ["nbv_sim::sensors::", "frame_caster", "TwinState::capture",
                                   "depth_frame_to_cloud", "average_frames", "capture_burst"]),
    ("motion (twin arm, contact checks)", ["TwinState::execute", "contact_at", "contacts_limited",
                                           "in_collision", "SimArm"]),
    ("phase 1 (sweep, segmentation)", ["nbv_core::perception::", "phase_one", "acquire_sweep",
                                       "lines_to_cloud", "outlier_filter", "euclidean_cluster",
                                       "ransac", "nbv_sim::sensors::line_scanner", "LineScanner"]),
    ("cloud utilities (nearest distances, filters, files)", ["nbv_core::cloud::"]),
    ("evaluation and report", ["nbv_core::evaluation::", "explore_report", "nbv_twin::"]),
    ("twin set-up", ["from_scene", "TwinWorld::new"]),
]
METHODS = [
    ("sequential ICP", ["sequential_icp", "registration::icp::"]),
    ("p-ICP-GPA", ["registration::gpa::", "mutual_neighbours", "independent_sets"]),
    ("MAP", ["registration::map::", "map_view", "map_terms"]),
    ("hand-eye, pose uncertainty", ["hand_eye", "pose_uncertainty"]),
]
OTHER = "unattributed (rayon idle, kernel, cut stack)"


def step_of(frames):
    for f in frames:
        for name, pats in STEPS:
            if any(p in f for p in pats):
                return name
    return OTHER


def method_of(frames):
    for name, pats in METHODS:
        if any(p in f for f in frames for p in pats):
            return name
    return "other (normals, view trees, checks)"


def samples(lines):
    frames = []
    for line in lines:
        if not line.strip():
            if frames:
                yield frames
            frames = []
        elif line[0] in "\t ":
            m = re.match(r"\s+[0-9a-f]+\s+(.*?)(\s+\(.*\))?$", line.rstrip())
            if m:
                frames.append(m.group(1))
        else:
            frames = []
    if frames:
        yield frames


def main():
    hz = float(sys.argv[1]) if len(sys.argv) > 1 else 199.0
    steps = collections.Counter()
    leaves = collections.defaultdict(collections.Counter)
    methods = collections.Counter()
    total = 0
    for frames in samples(sys.stdin):
        total += 1
        step = step_of(frames)
        steps[step] += 1
        leaves[step][frames[0][:100]] += 1
        if step == "registration":
            methods[method_of(frames)] += 1
    if total == 0:
        sys.exit("no samples on stdin")
    print(f"{total} samples, {total / hz:.1f} CPU-s at {hz:g} Hz")
    for name, n in steps.most_common():
        print(f"{name:46s} {100 * n / total:6.2f} %  {n / hz:6.2f} CPU-s")
        for leaf, k in leaves[name].most_common(5):
            print(f"      {100 * k / total:5.2f} %  {leaf}")
    print("registration by method:")
    for name, n in methods.most_common():
        print(f"  {name:44s} {100 * n / total:6.2f} %  {n / hz:6.2f} CPU-s")


if __name__ == "__main__":
    main()
