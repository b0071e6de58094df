#!/usr/bin/env python3
"""The weak device (issue 25, item 3): the client under a CPU quota, local mode against edge mode.

Each cell runs `edgeslam run --mode local` or `edgeslam client` (against an `edgeslam server` on
another core) pinned to one core and limited to a share of it by a CPU quota: cgroup v2 `cpu.max`
where the unified hierarchy has the cpu controller, else cgroup v1 `cpu.cfs_quota_us`, with a
10 ms period (a slower core rather than a core taken away for long stretches). Without cgroups
(not root), busy processes on the client's core stand in: one for 50 %, three for 25 %.
Frames come at the camera's rate (--realtime) from memory (--preload: the camera's decoding is not
charged to the device), so what the client does not finish in a frame's period is skipped.

Per cell (sensor, CPU share, mode, client compute adaptation on/off), --runs runs: frames
processed of those the camera produced, processed fps, e2e p50 / p95 (frame due to pose), tracked,
ATE, and what the compute budget gave up (least features and levels, frames with fewer).

Writes the table to docs/benchmarks.md (between the WEAK-DEVICE markers) unless --no-docs, and
docs/figures/weak_device_e2e.svg. Usage:
  bench/weak_device_bench.py [--build build] [--shared ../shared] [--runs 3] [--frames 600]
                             [--shares 100,50,25] [--sensors mono,rgbd]
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

from host_check import host_check, host_line
from docs_block import replace_block
from link_experiments import PALETTE, Panel, legend, svg_document, write
from pinned_run import CLIENT_CPU, SERVER_CPU, run_pinned

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DOCS = os.path.join(ROOT, "docs", "benchmarks.md")
FIGURES = os.path.join(ROOT, "docs", "figures")
BEGIN, END = "<!-- WEAK-DEVICE:BEGIN -->", "<!-- WEAK-DEVICE:END -->"
PERIOD_US = 10000
# (label, mode, compute adaptation)
VARIANTS = [("local", "local", True), ("edge", "edge", True), ("edge, no compute adaptation",
                                                                "edge", False)]


class CpuQuota:
    """A cgroup holding the client at `share` % of one core; .wrap(cmd) runs cmd inside it."""

    def __init__(self, share):
        self.share = share
        self.path = None
        self.kind = None
        self.hogs = []
        if share >= 100:
            self.kind = "none"
            return
        unified = "/sys/fs/cgroup"
        v2 = os.path.join(unified, "cgroup.controllers")
        name = f"edgeslam-weak-{os.getpid()}-{share}"
        try:
            if os.path.exists(v2) and "cpu" in open(v2).read().split():
                with open(os.path.join(unified, "cgroup.subtree_control"), "w") as f:
                    f.write("+cpu")
                self.path = os.path.join(unified, name)
                os.makedirs(self.path, exist_ok=True)
                with open(os.path.join(self.path, "cpu.max"), "w") as f:
                    f.write(f"{share * PERIOD_US // 100} {PERIOD_US}")
                self.kind = "cgroup v2 cpu.max"
            elif os.path.isdir("/sys/fs/cgroup/cpu"):
                self.path = os.path.join("/sys/fs/cgroup/cpu", name)
                os.makedirs(self.path, exist_ok=True)
                with open(os.path.join(self.path, "cpu.cfs_period_us"), "w") as f:
                    f.write(str(PERIOD_US))
                with open(os.path.join(self.path, "cpu.cfs_quota_us"), "w") as f:
                    f.write(str(share * PERIOD_US // 100))
                self.kind = "cgroup v1 cfs quota"
        except OSError as e:
            print(f"weak_device_bench: no cgroup ({e}); busy processes share the core instead",
                  file=sys.stderr)
            self.path = None
        if self.path is None:
            hogs = max(1, round(100 / share) - 1)
            self.kind = f"{hogs} busy process{'es' if hogs > 1 else ''} on the core"
            for _ in range(hogs):
                self.hogs.append(subprocess.Popen(
                    ["taskset", "-c", str(CLIENT_CPU), sys.executable, "-c", "while True: pass"]))

    def wrap(self, cmd):
        cmd = ["taskset", "-c", str(CLIENT_CPU)] + cmd
        if self.path is None:
            return cmd
        procs = os.path.join(self.path, "cgroup.procs")
        return ["sh", "-c", f'echo $$ > "{procs}" && exec "$@"', "sh"] + cmd

    def close(self):
        for hog in self.hogs:
            hog.kill()
            hog.wait()
        if self.path:
            for _ in range(50):
                try:
                    os.rmdir(self.path)
                    break
                except OSError:
                    time.sleep(0.1)


def run_cell(args, sensor, quota, mode, compute_adapt, out_dir):
    common = ["--dataset", args.dataset, "--sensor", sensor, "--realtime", "--preload",
              "--max-frames", str(args.frames), "--out", out_dir,
              "--compute-adapt", "on" if compute_adapt else "off"]
    return run_pinned(os.path.join(args.build, "edgeslam"), mode, common, out_dir, quota.wrap,
                      server_args=["--semantic", "off"], log_name="client.log")


def camera_seconds(metrics):
    """How long the camera ran: its frames at its rate (the compute budget's period, else 30 fps)."""
    period_ms = metrics.get("compute_budget", {}).get("period_ms", 1000.0 / 30.0)
    return max(1e-9, metrics["frames"] * period_ms / 1000.0)


def summarize(runs):
    ok = [m for m in runs if m]
    if not ok:
        return None

    def med(values):
        values = [v for v in values if v is not None]
        return statistics.median(values) if values else None

    def spread(values):
        values = [v for v in values if v is not None]
        return (min(values), statistics.median(values), max(values)) if values else None

    row = {
        "runs": len(ok),
        "failed": len(runs) - len(ok),
        "processed": spread([m["frames_processed"] / max(1, m["frames"]) * 100 for m in ok]),
        "fps": spread([m["frames_processed"] / camera_seconds(m) for m in ok]),
        "e2e_p50": med([m["e2e_ms"]["median"] for m in ok]),
        "e2e_p95": med([m["e2e_ms"]["p95"] for m in ok]),
        "client_p50": med([m["client_ms"]["median"] for m in ok]),
        "tracked": med([m["tracked"] / max(1, m["frames_processed"]) * 100 for m in ok]),
        "ate": spread([m["ate"]["rmse_m"] * 100 for m in ok if m.get("ate")]),
    }
    budgets = [m["compute_budget"] for m in ok if m.get("compute_budget")]
    if budgets:
        row["least_features"] = min(b["least"]["features"] for b in budgets)
        row["least_levels"] = min(b["least"]["levels"] for b in budgets)
        row["reduced"] = med([b["frames_with_fewer_features"] / max(1, sum(b["frames_per_step"]))
                              * 100 for b in budgets])
    return row


def fmt_spread(s, digits=1):
    if s is None:
        return "-"
    lo, mid, hi = s
    return f"{mid:.{digits}f} [{lo:.{digits}f}-{hi:.{digits}f}]"


def fmt(v, digits=1):
    return "-" if v is None else f"{v:.{digits}f}"


def table(results, args, quota_kinds, host):
    lines = [
        f"{args.frames} frames of {os.path.basename(args.dataset)} at the camera's rate "
        f"(--realtime, frames decoded in memory beforehand: --preload), {args.runs} runs per "
        f"cell, median [min-max]. The client is pinned to core {CLIENT_CPU} and held to a share "
        f"of it ({', '.join(sorted(set(quota_kinds) - {'none'}))}, period {PERIOD_US // 1000} ms); edge "
        f"mode's server runs on core {SERVER_CPU}. Processed: frames the client handled, of "
        "those the camera produced (the rest it skipped, busy with an earlier one). e2e: frame "
        "due to pose. Gave up: with compute adaptation, the least features / pyramid levels "
        "frames had, and the share of frames with fewer features than configured (edge mode's "
        "Table I may lower the levels for the link as well).",
        "",
        "| sensor | CPU share | mode | processed % | processed fps | e2e p50 / p95 ms | client "
        "ms p50 | tracked % | ATE cm | gave up |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for (sensor, share, label), row in results:
        if row is None:
            lines.append(f"| {sensor} | {share} % | {label} | failed | | | | | | |")
            continue
        gave = "-"
        if "least_features" in row:
            gave = (f"{row['least_features']} / {row['least_levels']}, "
                    f"{row['reduced']:.0f} % of frames" if row["reduced"] else "nothing")
        lines.append(
            f"| {sensor} | {share} % | {label} | {fmt_spread(row['processed'])} | "
            f"{fmt_spread(row['fps'])} | {fmt(row['e2e_p50'])} / {fmt(row['e2e_p95'])} | "
            f"{fmt(row['client_p50'])} | {fmt(row['tracked'])} | {fmt_spread(row['ate'], 2)} | "
            f"{gave} |")
    if host:
        lines += ["", host]
    return "\n".join(lines)


def figure(results, args):
    """Per sensor, e2e p50 against the CPU share, one line per variant."""
    shares = args.shares
    rows = dict(results)
    values = [row["e2e_p50"] for row in rows.values() if row and row["e2e_p50"] is not None]
    y_max = max(values + [34.0])
    body = []
    x = 80
    for sensor in args.sensors:
        panel = Panel(x, 40, 300, 260, y_max, "e2e p50 ms (frame due to pose)",
                      x_label="CPU share of one core (%)", title=sensor)
        out = panel.axes()
        period_y = panel.y(1000.0 / 30.0)
        out.append(f'<line x1="{panel.x0}" y1="{period_y:.1f}" x2="{panel.x0 + panel.w}" '
                   f'y2="{period_y:.1f}" stroke="#999" stroke-dasharray="4 3"/>')
        out.append(f'<text x="{panel.x0 + panel.w - 4}" y="{period_y - 4:.1f}" text-anchor="end" '
                   f'font-size="10" fill="#666">camera period</text>')
        for v_index, (label, _, _) in enumerate(VARIANTS):
            pts = []
            for i, share in enumerate(shares):
                row = rows.get((sensor, share, label))
                if row and row["e2e_p50"] is not None:
                    px = panel.x0 + (i + 0.5) * panel.w / len(shares)
                    pts.append((px, panel.y(row["e2e_p50"])))
            color = PALETTE[v_index % len(PALETTE)]
            if len(pts) > 1:
                out.append('<polyline fill="none" stroke="{}" stroke-width="2" points="{}"/>'.format(
                    color, " ".join(f"{px:.1f},{py:.1f}" for px, py in pts)))
            for px, py in pts:
                out.append(f'<circle cx="{px:.1f}" cy="{py:.1f}" r="3" fill="{color}"/>')
        for i, share in enumerate(shares):
            px = panel.x0 + (i + 0.5) * panel.w / len(shares)
            out.append(f'<text x="{px:.1f}" y="{panel.y0 + panel.h + 16}" '
                       f'text-anchor="middle">{share}</text>')
        body += out
        x += panel.w + 90
    body += legend(x - 60, 40, [label for label, _, _ in VARIANTS], PALETTE)
    write(os.path.join(FIGURES, "weak_device_e2e.svg"),
          svg_document(x + 200, 360, body, "Latency of the client under a CPU quota"))


def update_docs(block):
    replace_block(DOCS, BEGIN, END, block,
                  "The weak device: the client under a CPU quota (`bench/weak_device_bench.py`)")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--build", default=os.path.join(ROOT, "build"))
    parser.add_argument("--shared", default=os.environ.get("EDGESLAM_SHARED",
                                                           os.path.join(ROOT, "..", "shared")))
    parser.add_argument("--dataset", default=None)
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--frames", type=int, default=600)
    parser.add_argument("--shares", default="100,50,25")
    parser.add_argument("--sensors", default="mono,rgbd")
    parser.add_argument("--keep", default=None, help="keep run outputs in this folder")
    parser.add_argument("--reuse", action="store_true",
                        help="with --keep: take the runs found there instead of running them again")
    parser.add_argument("--no-docs", action="store_true")
    args = parser.parse_args()
    args.build = os.path.abspath(args.build)
    args.dataset = args.dataset or os.path.join(args.shared, "datasets",
                                                "7scenes-redkitchen-1000")
    args.shares = [int(s) for s in args.shares.split(",")]
    args.sensors = args.sensors.split(",")
    if not os.path.exists(os.path.join(args.build, "edgeslam")):
        sys.exit(f"weak_device_bench: no {args.build}/edgeslam (build first)")
    if not os.path.isdir(args.dataset):
        sys.exit(f"weak_device_bench: no dataset at {args.dataset} (--shared, --dataset)")
    work = args.keep or tempfile.mkdtemp(prefix="edgeslam-weak-")
    before = None if args.reuse else host_check(args.build, CLIENT_CPU)
    results, kinds = [], []
    total = len(args.sensors) * len(args.shares) * len(VARIANTS) * args.runs
    done = 0
    started = time.monotonic()
    for sensor in args.sensors:
        for share in args.shares:
            quota = CpuQuota(share if not args.reuse else 100)
            if args.reuse:
                quota.kind = "cgroup v1 cfs quota" if share < 100 else "none"
            kinds.append(quota.kind)
            try:
                for label, mode, compute_adapt in VARIANTS:
                    runs = []
                    for run in range(args.runs):
                        out = os.path.join(work, f"{sensor}-{share}-{mode}-"
                                           f"{'adapt' if compute_adapt else 'fixed'}-{run}")
                        os.makedirs(out, exist_ok=True)
                        kept = os.path.join(out, "metrics.json")
                        if args.reuse and os.path.exists(kept):
                            with open(kept) as f:
                                runs.append(json.load(f))
                        else:
                            runs.append(run_cell(args, sensor, quota, mode, compute_adapt, out))
                        done += 1
                        m = runs[-1]
                        print(f"[{done}/{total}, {time.monotonic() - started:.0f} s] {sensor} "
                              f"{share} % {label} run {run + 1}: " +
                              (f"{m['frames_processed']}/{m['frames']} processed, e2e p50 "
                               f"{m['e2e_ms']['median']:.1f} ms, ATE "
                               f"{m['ate']['rmse_m'] * 100:.2f} cm" if m and m.get("ate")
                               else "failed"), flush=True)
                    results.append(((sensor, share, label), summarize(runs)))
            finally:
                quota.close()
    after = None if args.reuse else host_check(args.build, CLIENT_CPU)
    block = table(results, args, kinds, host_line(before, after))
    print(block)
    if not args.no_docs:
        update_docs(block)
        figure(results, args)
    if not args.keep:
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
