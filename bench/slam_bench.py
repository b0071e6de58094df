#!/usr/bin/env python3
"""SLAM accuracy/speed benchmark: the issue's reference rows, each run N times, in each run mode.

Frames are fed at the dataset's rate (--feed realtime, the default), as ORB-SLAM2's example programs
feed them when its reference times were taken; --feed fast feeds them back to back.
local: the whole run pinned to one core. edge / offload: an `edgeslam server` process pinned to core 1
and the `edgeslam client` pinned to core 0, over loopback gRPC (as the edge issue asks).
Prints a markdown table (median of the runs and [min-max] spread) and writes it to docs/benchmarks.md
(between the SLAM markers) unless --no-docs. Usage:
  bench/slam_bench.py [--build build] [--runs 3] [--shared ../shared] [--rows mono,rgbd,kitti]
                      [--modes local,edge,offload]
"""
import argparse
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time

from host_check import host_check, host_line

ROWS = {
    "mono": ("7-Scenes redkitchen 1000", "datasets/7scenes-redkitchen-1000", "mono",
             "4.40 cm [4.32-4.43]", "28.8 / 35.2"),
    "rgbd": ("7-Scenes redkitchen 1000", "datasets/7scenes-redkitchen-1000", "rgbd",
             "4.75 cm [4.67-4.84]", "30.9 / 40.3"),
    "kitti": ("KITTI 07 0-159", "datasets/kitti07-160", "mono", "29.98 cm [28.06-32.12]",
              "30.3 / 41.0"),
}


def pinned(cmd, cpu):
    return cmd if cpu is None else ["taskset", "-c", str(cpu)] + cmd


def run_once(binary, dataset, sensor, mode, cpu, port, feed, extra):
    with tempfile.TemporaryDirectory() as out:
        common = ["--dataset", dataset, "--sensor", sensor, "--mode", mode, "--out", out,
                  f"--{feed}"] + extra
        server = None
        if mode == "local":
            cmd = pinned([binary, "run"] + common, cpu)
        else:
            server = subprocess.Popen(
                pinned([binary, "server", "--listen", f"127.0.0.1:{port}", "--status-every", "0"],
                       None if cpu is None else cpu + 1),
                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            time.sleep(0.5)
            cmd = pinned([binary, "client", "--server", f"127.0.0.1:{port}"] + common, cpu)
        try:
            subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        finally:
            if server is not None:
                server.terminate()
                server.wait(timeout=10)
        with open(os.path.join(out, "metrics.json")) as f:
            return json.load(f)


def spread(values, fmt):
    return f"{fmt(statistics.median(values))} [{fmt(min(values))}-{fmt(max(values))}]"


def main():
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    parser = argparse.ArgumentParser()
    parser.add_argument("--build", default=os.path.join(root, "build"))
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--shared", default=os.environ.get("EDGESLAM_SHARED",
                                                           os.path.join(root, "..", "shared")))
    parser.add_argument("--rows", default="mono,rgbd,kitti")
    parser.add_argument("--modes", default="local", help="comma list of local, edge, offload")
    parser.add_argument("--port", type=int, default=50151)
    parser.add_argument("--cpu", default="0", help="core to pin to; 'none' for no pinning")
    parser.add_argument("--feed", default="realtime", choices=["realtime", "fast"],
                        help="realtime: frames at the dataset's rate; fast: back to back")
    parser.add_argument("--run-args", default="",
                        help="extra arguments for every run, e.g. '--refine-intrinsics off'")
    parser.add_argument("--no-docs", action="store_true")
    args = parser.parse_args()
    binary = os.path.join(args.build, "edgeslam")
    cpu = None if args.cpu == "none" else int(args.cpu)

    lines = ["| sequence | sensor | mode | tracked | frames before init | ATE final RMSE, cm (median [min-max]) "
             "| ATE at frame time, cm | client ms median / p90 / p99 | e2e ms median / p99 "
             "| uplink KB per keyframe (per frame offload) | slice latency ms median | ORB-SLAM2 ATE "
             "| ORB-SLAM2 ms median / p90 | refined intrinsics (fx, k1; median run) |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    host_before = host_check(args.build, cpu)
    for key, mode in [(k, m) for k in args.rows.split(",") for m in args.modes.split(",")]:
        name, rel, sensor, ref_ate, ref_ms = ROWS[key]
        dataset = os.path.join(args.shared, rel)
        if not os.path.isdir(dataset):
            print(f"skip {key}: {dataset} not found", file=sys.stderr)
            continue
        runs = []
        for i in range(args.runs):
            print(f"{key} {mode}: run {i + 1}/{args.runs}", file=sys.stderr, flush=True)
            runs.append(run_once(binary, dataset, sensor, mode, cpu, args.port, args.feed,
                                 args.run_args.split()))
        ate = [100 * r["ate_final"]["rmse_m"] for r in runs if "ate_final" in r]
        ate_t = [100 * r["ate"]["rmse_m"] for r in runs if "ate" in r]
        tracked = [r["tracked"] for r in runs]
        init = [r["frames"] - r["tracked"] - r["lost"] for r in runs]
        med = [r["client_ms"]["median"] for r in runs]
        p90 = [r["client_ms"]["p90"] for r in runs]
        p99 = [r["client_ms"]["p99"] for r in runs]
        e2e = [r["e2e_ms"]["median"] for r in runs]
        e2e99 = [r["e2e_ms"]["p99"] for r in runs]
        if mode == "offload":
            up = [r["uplink_bytes"] / 1000 / max(1, r["frames"]) for r in runs]
        else:
            up = [r["uplink_bytes"] / 1000 / max(1, r.get("keyframes_uploaded", 0)) for r in runs]
        slice_ms = [r["slice_latency_ms"]["median"] for r in runs]
        refined = "-"
        if ate and all("intrinsics_refinement" in r for r in runs):
            by_ate = sorted(runs, key=lambda r: r["ate_final"]["rmse_m"])
            ir = by_ate[len(by_ate) // 2]["intrinsics_refinement"]
            refined = f"{ir['fx']:.1f}, {ir['k1']:.4f}" if ir["adopted"] else "kept"
        f2 = lambda v: f"{v:.2f}"
        f1 = lambda v: f"{v:.1f}"
        lines.append(
            f"| {name} | {sensor} | {mode} | {statistics.median(tracked):.0f}/{runs[0]['frames']} "
            f"| {statistics.median(init):.0f} | {spread(ate, f2) if ate else '-'} "
            f"| {spread(ate_t, f2) if ate_t else '-'} "
            f"| {f1(statistics.median(med))} / {f1(statistics.median(p90))} / {f1(statistics.median(p99))} "
            f"| {f1(statistics.median(e2e))} / {f1(statistics.median(e2e99))} "
            f"| {f1(statistics.median(up)) if mode != 'local' else '-'} "
            f"| {f1(statistics.median(slice_ms)) if mode == 'edge' else '-'} "
            f"| {ref_ate} | {ref_ms} | {refined} |")
    host = host_line(host_before, host_check(args.build, cpu))
    table = "\n".join(lines) + (f"\n\n{host}" if host else "")
    if args.run_args:
        table += f"\n\nEvery run with `{args.run_args}`."
    print(table)
    if not args.no_docs:
        path = os.path.join(root, "docs", "benchmarks.md")
        text = open(path).read() if os.path.exists(path) else "# Benchmarks\n"
        block = f"<!-- slam-bench -->\n{table}\n<!-- /slam-bench -->"
        if "<!-- slam-bench -->" in text:
            text = re.sub(r"<!-- slam-bench -->.*?<!-- /slam-bench -->", block, text, flags=re.S)
        else:
            text += "\n" + block + "\n"
        with open(path, "w") as f:
            f.write(text)


if __name__ == "__main__":
    main()
