#!/usr/bin/env python3
"""Where the client's time goes, against the floor of each stage on this machine (issue 25, item 4).

Runs the client on redkitchen (edge mode, an `edgeslam server` on core 1, the client on core 0,
--runs runs per sensor, frames back to back) and reads each frame's stages from frames.csv
(features: ORB extraction, undistortion, depth; tracking: matching and pose optimisation against
the local map; keyframe: insertion and upload). Then the micro-benchmarks of the same work in
isolation, pinned to core 0 (build/bench/features_bench and optimize_bench), and the floors of
extraction built from OpenCV's vectorised primitives (pyramid, FAST on every level, blur, ORB
descriptors: what any 8-level ORB extractor does at least).

Writes the table to docs/benchmarks.md (between the CLIENT-STAGES markers) unless --no-docs.
  bench/client_stages_bench.py [--build build] [--shared ../shared] [--runs 3] [--frames 600]
"""
import argparse
import csv
import json
import re
import os
import statistics
import subprocess
import sys
import tempfile

from host_check import host_check, host_line
from docs_block import replace_block
from link_experiments import free_port, stop_process, wait_for_port

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DOCS = os.path.join(ROOT, "docs", "benchmarks.md")
BEGIN, END = "<!-- CLIENT-STAGES:BEGIN -->", "<!-- CLIENT-STAGES:END -->"
CLIENT_CPU, SERVER_CPU = 0, 1


def micro_benchmarks(args, exe, pattern):
    """{name: median real ms} of one benchmark executable's aggregates."""
    path = os.path.join(args.build, "bench", exe)
    if not os.path.exists(path):
        sys.exit(f"client_stages_bench: no {path} (Google Benchmark must be installed)")
    out = subprocess.run(["taskset", "-c", str(CLIENT_CPU), path, f"--benchmark_filter={pattern}",
                          "--benchmark_format=json", "--benchmark_repetitions=5",
                          "--benchmark_report_aggregates_only=true"],
                         capture_output=True, text=True,
                         env=dict(os.environ, EDGESLAM_SHARED=args.shared))
    if out.returncode != 0:
        sys.exit(f"client_stages_bench: {exe} failed:\n{out.stderr[-2000:]}")
    result = {}
    for b in json.loads(out.stdout)["benchmarks"]:
        if b.get("aggregate_name") != "median":
            continue
        ms = b["real_time"] * {"ms": 1.0, "us": 1e-3, "ns": 1e-6}[b["time_unit"]]
        name = re.sub(r"/(repeats:\d+|real_time)", "", b["run_name"])
        counters = {k: v for k, v in b.items() if k in ("keypoints", "corners", "matches")}
        result[name] = {"ms": ms, **counters}
    return result


def client_runs(args, sensor, work):
    stages = {"features": [], "tracking": [], "keyframe": [], "client": []}
    keyframe_rows = []
    exe = os.path.join(args.build, "edgeslam")
    for run in range(args.runs):
        out = os.path.join(work, f"{sensor}-{run}")
        port = free_port()
        server = subprocess.Popen(
            ["taskset", "-c", str(SERVER_CPU), exe, "server", "--listen", f"127.0.0.1:{port}",
             "--maps", "none", "--semantic", "off"],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        try:
            wait_for_port(port, server)
            result = subprocess.run(
                ["taskset", "-c", str(CLIENT_CPU), exe, "client", "--server", f"127.0.0.1:{port}",
                 "--dataset", args.dataset, "--sensor", sensor, "--max-frames", str(args.frames),
                 "--out", out], capture_output=True, text=True)
        finally:
            stop_process(server)
        if result.returncode != 0:
            sys.exit(f"client_stages_bench: client failed:\n{result.stderr[-2000:]}")
        with open(os.path.join(out, "frames.csv")) as f:
            rows = list(csv.DictReader(f))
        tracked = [r for r in rows if r["state"] == "ok"]
        for key in ("features", "tracking", "keyframe"):
            stages[key].append(statistics.median(float(r[f"{key}_ms"]) for r in tracked))
        stages["client"].append(statistics.median(float(r["client_ms"]) for r in tracked))
        keyframe_rows += [float(r["keyframe_ms"]) for r in tracked if r["keyframe"] == "1"]
    medians = {k: statistics.median(v) for k, v in stages.items()}
    spreads = {k: (min(v), max(v)) for k, v in stages.items()}
    medians["keyframe_only"] = statistics.median(keyframe_rows) if keyframe_rows else 0.0
    return medians, spreads


def table(args, sensors, micro, host):
    ours = micro["BM_OrbExtract_7Scenes/1000/8"]["ms"]
    cv_orb = micro["BM_CvOrb_7Scenes/1000"]["ms"]
    pyramid = micro["BM_Floor_Pyramid_7Scenes"]["ms"]
    fast = micro["BM_Floor_PyramidFast_7Scenes"]["ms"]
    blur = micro["BM_Floor_PyramidBlur_7Scenes"]["ms"]
    describe = micro["BM_Describe_CvOrbCompute"]
    describe_1000 = describe["ms"] * 1000.0 / max(1.0, describe.get("keypoints", 1000.0))
    floor = fast + (blur - pyramid) + describe_1000
    match = micro["BM_MatchInWindow_7Scenes"]["ms"]
    pose = micro["BM_PoseOnly_SingleBlock/600"]["ms"]
    steps = {key: micro[f"BM_OrbExtract_7Scenes/{key}"]["ms"]
             for key in ("800/8", "700/6", "600/5")}
    lines = [
        f"The client's stages on 7-Scenes redkitchen ({args.frames} frames, edge mode, frames back "
        f"to back, {args.runs} runs per sensor, medians of tracked frames, [min-max] of the runs' "
        f"medians; client on core {CLIENT_CPU}, server on core {SERVER_CPU}), against the same "
        "work alone (micro-benchmarks pinned to the client's core, medians of 5 repetitions) and "
        "against a floor: extraction from OpenCV's vectorised primitives (an 8-level pyramid at "
        "1.2, FAST at one threshold on every level, a 7x7 blur of every level, ORB descriptors "
        "for 1000 keypoints: what any such extractor does at least); tracking from one pose-only "
        "optimisation of 600 observations (tracking runs two, and matches before each).",
        "",
        "| stage | mono ms | RGB-D ms | the work alone, ms | floor ms | gap |",
        "|---|---|---|---|---|---|",
    ]

    def cell(sensor, key):
        m, s = sensors[sensor]
        return f"{m[key]:.2f} [{s[key][0]:.2f}-{s[key][1]:.2f}]" if key in s else f"{m[key]:.2f}"

    lines.append(
        f"| features | {cell('mono', 'features')} | {cell('rgbd', 'features')} | ORB extraction "
        f"{ours:.2f} (cv::ORB {cv_orb:.2f}) | {floor:.2f} (FAST on the pyramid {fast:.2f}, blur "
        f"{blur - pyramid:.2f}, descriptors {describe_1000:.2f}) | extraction {ours / floor:.2f}x "
        "the floor (it also spreads the features over cells with a retry at a lower FAST "
        "threshold, a quadtree and orientations); the rest of the stage, "
        "undistortion and depth lookup |")
    lines.append(
        f"| tracking | {cell('mono', 'tracking')} | {cell('rgbd', 'tracking')} | matching a "
        f"frame's features in 100 px windows {match:.2f}, pose-only optimisation of 600 "
        f"observations {pose:.2f} | {pose:.2f} (one pose-only optimisation) | the matching "
        "against the motion model's and the local map's projected points (windows of a few "
        "pixels, cheaper than the bench's 100 px) and a second optimisation; RGB-D tracks about "
        "twice the points |")
    lines.append(
        f"| keyframe (median of all frames) | {cell('mono', 'keyframe')} | "
        f"{cell('rgbd', 'keyframe')} | keyframe frames only: mono "
        f"{sensors['mono'][0]['keyframe_only']:.2f}, RGB-D {sensors['rgbd'][0]['keyframe_only']:.2f}"
        " | - | insertion, the upload's encoding (sent on another thread) |")
    lines.append(
        f"| client (whole frame) | {cell('mono', 'client')} | {cell('rgbd', 'client')} | | | |")
    lines += [
        "",
        "The compute budget's steps (adapt/compute_budget.h), extraction alone on the same frame: "
        f"1000 features / 8 levels {ours:.2f} ms, 800 / 8 {steps['800/8']:.2f}, 700 / 6 "
        f"{steps['700/6']:.2f}, 600 / 5 {steps['600/5']:.2f} "
        f"({steps['600/5'] / ours * 100:.0f} % of the first).",
    ]
    if host:
        lines += ["", host]
    return "\n".join(lines)


def update_docs(block):
    replace_block(DOCS, BEGIN, END, block,
                  "The client's stages against their floors (`bench/client_stages_bench.py`)")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--build", default=os.path.join(ROOT, "build"))
    parser.add_argument("--shared", default=os.environ.get("EDGESLAM_SHARED",
                                                           os.path.join(ROOT, "..", "shared")))
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--frames", type=int, default=600)
    parser.add_argument("--no-docs", action="store_true")
    args = parser.parse_args()
    args.build = os.path.abspath(args.build)
    args.shared = os.path.abspath(args.shared)
    args.dataset = os.path.join(args.shared, "datasets", "7scenes-redkitchen-1000")
    if not os.path.isdir(args.dataset):
        sys.exit(f"client_stages_bench: no dataset at {args.dataset} (--shared)")
    before = host_check(args.build, CLIENT_CPU)
    micro = micro_benchmarks(args, "features_bench",
                             "BM_OrbExtract_7Scenes|BM_CvOrb_7Scenes|BM_Floor|BM_Describe_CvOrb|"
                             "BM_MatchInWindow")
    micro.update(micro_benchmarks(args, "optimize_bench", "BM_PoseOnly_SingleBlock"))
    work = tempfile.mkdtemp(prefix="edgeslam-stages-")
    sensors = {sensor: client_runs(args, sensor, work) for sensor in ("mono", "rgbd")}
    after = host_check(args.build, CLIENT_CPU)
    block = table(args, sensors, micro, host_line(before, after))
    print(block)
    if not args.no_docs:
        update_docs(block)


if __name__ == "__main__":
    main()
