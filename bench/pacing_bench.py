#!/usr/bin/env python3
"""Accuracy against pacing (issue 24, items 1, 2 and 4): each sequence x mode x pacing cell run
--runs times, min / median / max of the ATE, and the runs worse than 1.5x their cell's median named.

Pacing: --fast (frames back to back, tracking waits for a back end that falls behind) and
--realtime (frames at the camera's rate). Modes: local (pinned to core 0), edge (`edgeslam
server` on core 1, `edgeslam client` on core 0, over loopback) and offload (the same, `client
--mode offload`: the edge tracks every frame). KITTI rows add the KITTI odometry
metric (t_rel %, r_rel deg/100 m; `edgeslam eval kitti`, Sim(3) aligned for monocular).

Writes the table into docs/benchmarks.md between the PACING markers unless --no-docs. Usage:
  bench/pacing_bench.py [--rows kitti03,mono,rgbd] [--modes local,edge,offload] [--pacings fast,realtime]
                        [--runs 5] [--max-frames N] [--keep DIR]
"""
import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

from docs_block import replace_block
from host_check import host_check, host_line
from pinned_run import CLIENT_CPU, SERVER_CPU, run_pinned

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DOCS = os.path.join(ROOT, "docs", "benchmarks.md")
BEGIN, END = "<!-- PACING:BEGIN -->", "<!-- PACING:END -->"
OUTLIER_RATIO = 1.5
LOST_RATIO = 0.9  # of the cell's best tracked share

# key: (label, dataset folder under the shared folder, sensor, unit of the ATE, KITTI metric)
ROWS = {
    "kitti03": ("KITTI 03 0-399 (285 m)", "datasets/kitti03-400", "mono", "m", True),
    "kitti07": ("KITTI 07 0-159", "datasets/kitti07-160", "mono", "cm", True),
    "mono": ("7-Scenes redkitchen", "datasets/7scenes-redkitchen-1000", "mono", "cm", False),
    "rgbd": ("7-Scenes redkitchen", "datasets/7scenes-redkitchen-1000", "rgbd", "cm", False),
}


def run_once(args, dataset, sensor, mode, pacing, out):
    common = ["--dataset", dataset, "--sensor", sensor, f"--{pacing}", "--out", out]
    if args.max_frames:
        common += ["--max-frames", str(args.max_frames)]
    return run_pinned(os.path.join(args.build, "edgeslam"), mode, common, out,
                      server_args=["--status-every", "0"])


def kitti_metric(args, dataset, trajectory):
    exe = os.path.join(args.build, "edgeslam")
    cmd = [exe, "eval", "kitti", "--gt", os.path.join(dataset, "poses.txt"), "--times",
           os.path.join(dataset, "times.txt"), "--est", trajectory, "--align", "sim3", "--json"]
    out = subprocess.run(cmd, capture_output=True, text=True)
    if out.returncode != 0:
        return None
    return json.loads(out.stdout)


def spread(values, fmt):
    if not values:
        return "-"
    return f"{fmt(statistics.median(values))} [{fmt(min(values))}-{fmt(max(values))}]"


def cell_row(label, sensor, mode, pacing, unit, runs):
    ok = [r for r in runs if r]
    scale = 1.0 if unit == "m" else 100.0
    fmt = (lambda v: f"{v:.3f}") if unit == "m" else (lambda v: f"{v:.2f}")
    ate = [scale * r["ate_final"]["rmse_m"] for r in ok if r.get("ate_final")]
    ate_t = [scale * r["ate"]["rmse_m"] for r in ok if r.get("ate")]
    tracked = [100.0 * r["tracked"] / max(1, r["frames"]) for r in ok]
    t_rel = [r["kitti"]["t_rel_percent"] for r in ok if r.get("kitti")]
    r_rel = [r["kitti"]["r_rel_deg_per_100m"] for r in ok if r.get("kitti")]
    wall = [r["bench_wall_s"] for r in ok]
    waits = [r.get("backend_wait_ms", {}).get("total", 0.0) / 1000.0 for r in ok]
    outliers = []
    if len(ate) >= 2:
        median = statistics.median(ate)
        outliers = [f"{fmt(a)} ({a / median:.1f}x)" for a in ate if a > OUTLIER_RATIO * median]
    # A run that lost the camera has a small ATE over the few frames it tracked: named apart.
    if tracked:
        short = [t for t in tracked if t < LOST_RATIO * max(tracked)]
        if short:
            outliers.append(f"{len(short)} run(s) tracked only {', '.join(f'{t:.0f}' for t in short)} %")
    failed = len(runs) - len(ok)
    return (f"| {label} | {sensor} | {mode} | {pacing} | {len(ok)}{f' ({failed} failed)' if failed else ''} "
            f"| {spread(ate, fmt)} | {spread(ate_t, fmt)} | {', '.join(outliers) or 'none'} "
            f"| {spread(tracked, lambda v: f'{v:.1f}')} "
            f"| {spread(t_rel, lambda v: f'{v:.2f}')} | {spread(r_rel, lambda v: f'{v:.2f}')} "
            f"| {spread(wall, lambda v: f'{v:.0f}')} | {spread(waits, lambda v: f'{v:.1f}')} |")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--build", default=os.path.join(ROOT, "build"))
    parser.add_argument("--shared", default=os.environ.get("EDGESLAM_SHARED",
                                                           os.path.join(ROOT, "..", "shared")))
    parser.add_argument("--rows", default="kitti03,mono,rgbd")
    parser.add_argument("--modes", default="local,edge")
    parser.add_argument("--pacings", default="fast,realtime")
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--max-frames", type=int, default=0)
    parser.add_argument("--keep", default=None, help="keep run outputs in this folder")
    parser.add_argument("--no-docs", action="store_true")
    args = parser.parse_args()
    for key in args.rows.split(","):
        if key not in ROWS:
            parser.error(f"unknown row {key!r}; known: {', '.join(ROWS)}")
    for mode in args.modes.split(","):
        if mode not in ("local", "edge", "offload"):
            parser.error(f"unknown mode {mode!r}; known: local, edge, offload")
    for pacing in args.pacings.split(","):
        if pacing not in ("fast", "realtime"):
            parser.error(f"unknown pacing {pacing!r}; known: fast, realtime")
    if args.runs < 1:
        parser.error("--runs must be at least 1")

    work = args.keep or tempfile.mkdtemp(prefix="edgeslam-pacing-")
    os.makedirs(work, exist_ok=True)
    host_before = host_check(args.build, CLIENT_CPU)
    cells = [(k, m, p) for k in args.rows.split(",") for m in args.modes.split(",")
             for p in args.pacings.split(",")]
    lines = []
    started = time.monotonic()
    done = 0
    for key, mode, pacing in cells:
        label, rel, sensor, unit, kitti = ROWS[key]
        dataset = os.path.join(args.shared, rel)
        if not os.path.isdir(dataset):
            print(f"skip {key}: {dataset} not found", file=sys.stderr)
            continue
        runs = []
        for i in range(args.runs):
            out = os.path.join(work, f"{key}-{mode}-{pacing}-{i}")
            shutil.rmtree(out, ignore_errors=True)
            os.makedirs(out)
            metrics = run_once(args, dataset, sensor, mode, pacing, out)
            if metrics and kitti:
                metrics["kitti"] = kitti_metric(args, dataset,
                                                os.path.join(out, "trajectory_final.tum"))
            runs.append(metrics)
            done += 1
            ate = (f"ATE {metrics['ate_final']['rmse_m']:.3f} m" if metrics and
                   metrics.get("ate_final") else "no ATE")
            tracked = f"{metrics['tracked']}/{metrics['frames']}" if metrics else "failed"
            print(f"[{done}/{len(cells) * args.runs}, {time.monotonic() - started:.0f} s] {key} "
                  f"{mode} {pacing} run {i + 1}: tracked {tracked}, {ate}", flush=True)
        lines.append(cell_row(label, sensor, mode, pacing, unit, runs))

    header = [
        f"Each cell {args.runs} runs{f' of the first {args.max_frames} frames' if args.max_frames else ''}; "
        "median [min-max]. ATE RMSE after one alignment (Sim(3) monocular, SE(3) RGB-D) of "
        "`trajectory_final.tum` (the map's poses at the end) and of `trajectory.tum` (as known "
        "at frame time); KITTI rows in m, 7-Scenes in cm. Outliers: runs above "
        f"{OUTLIER_RATIO}x their cell's median, and runs that tracked under "
        f"{LOST_RATIO:.0%} of the frames the cell's best run tracked. Client on core {CLIENT_CPU}, edge server on core "
        f"{SERVER_CPU}. Waits: seconds tracking waited for the back end (`--fast`).",
        "",
        "| sequence | sensor | mode | pacing | runs | ATE final | ATE at frame time | outliers "
        "| tracked % | KITTI t_rel % | r_rel deg/100 m | wall s | waits s |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    host = host_line(host_before, host_check(args.build, CLIENT_CPU))
    block = "\n".join(header + lines) + (f"\n\n{host}" if host else "")
    print(block)
    if not args.no_docs:
        replace_block(DOCS, BEGIN, END, block, "Accuracy against pacing (bench/pacing_bench.py)")
    if not args.keep:
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
