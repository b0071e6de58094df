#!/usr/bin/env python3
"""The paper's link experiments (Fig. 14-17): edgeslam under each emulated link, with and without
self-adaptation, and the offload baseline for contrast.

For every link profile (none, wifi5, wifi24, lte, lte-congested) it runs
  - `edge` mode with `--adapt on` and with `--adapt off`,
  - `offload` mode,
on a 7-Scenes sequence at the camera's rate (`--realtime`, monocular), collects metrics.json
(e2e_ms, client_ms, slice_latency_ms, uplink/downlink bytes, ate_final, adapt counters) and the
per-frame errors of trajectory_final.tum against the ground truth, then writes
  - a markdown table into docs/benchmarks.md between <!-- link-bench --> markers,
  - docs/figures/link_latency.svg         (Fig. 14: end-to-end latency per link),
  - docs/figures/link_error_cdf.svg       (Fig. 15: CDF of the per-frame error per link),
  - docs/figures/link_adapt_latency.svg   (Fig. 16: latency with / without adaptation),
  - docs/figures/link_adapt_accuracy.svg  (Fig. 17: error and uplink with / without adaptation).

Topology (--topology):
  split (default)  three processes, as client and edge would be on two machines:
                   `edgeslam server` and `edgeslam linkem` pinned to --edge-cpu (core 1), and
                   `edgeslam client` pinned to --client-cpu (core 0).
  embedded         one `edgeslam run --link PROFILE` pinned to --client-cpu: the embedded edge
                   server (mapping, bundle adjustment) and the emulator share the client's core.
Python 3 standard library only (the figures are SVG written here).

  bench/link_experiments.py [--frames 1000] [--runs 1] [--build-dir build] [--quick]
"""
import argparse
import json
import math
import os
import re
import shutil
import signal
import socket
import statistics
import subprocess
import sys
import tempfile
import time

from host_check import host_check, host_line

PROFILES = ["none", "wifi5", "wifi24", "lte", "lte-congested"]
VARIANTS = [("edge", "on"), ("edge", "off"), ("offload", None)]
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def variant_name(mode, adapt):
    return f"{mode} (adapt {adapt})" if adapt else mode


# ---------------------------------------------------------------------------------------------
# Running edgeslam


def free_port():
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def wait_for_port(port, proc, timeout_s=20.0):
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if proc.poll() is not None:
            raise RuntimeError(f"{proc.args[0]} exited with {proc.returncode} before listening")
        try:
            with socket.create_connection(("127.0.0.1", port), timeout=0.5):
                return
        except OSError:
            time.sleep(0.1)
    raise RuntimeError(f"nothing listens on port {port} after {timeout_s:.0f} s")


def pinned(cmd, cpu):
    return cmd if cpu is None else ["taskset", "-c", str(cpu)] + cmd


def stop_process(proc):
    if proc.poll() is not None:
        return
    proc.send_signal(signal.SIGINT)
    try:
        proc.wait(timeout=10)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait()


def run_once(args, profile, mode, adapt, out_dir):
    """Runs one configuration; returns metrics.json as a dict (raises on failure)."""
    binary = os.path.join(args.build_dir, "edgeslam")
    frames = args.frames if mode == "edge" else min(args.frames, args.offload_frames)
    common = ["--dataset", args.dataset, "--sensor", "mono", "--mode", mode, "--max-frames",
              str(frames), "--realtime", "--out", out_dir]
    if adapt:
        common += ["--adapt", adapt]
    log_path = os.path.join(out_dir, "client.log")
    os.makedirs(out_dir, exist_ok=True)
    helpers = []
    try:
        with open(log_path, "w") as log:
            if args.topology == "embedded":
                cmd = pinned([binary, "run"] + common + ["--link", profile], args.client_cpu)
            else:
                server_port = free_port()
                helpers.append(subprocess.Popen(
                    pinned([binary, "server", "--listen", f"127.0.0.1:{server_port}",
                            "--status-every", "0"], args.edge_cpu),
                    stdout=subprocess.DEVNULL, stderr=log))
                wait_for_port(server_port, helpers[-1])
                port = server_port
                if profile != "none":
                    port = free_port()
                    helpers.append(subprocess.Popen(
                        pinned([binary, "linkem", "--listen", f"127.0.0.1:{port}", "--target",
                                f"127.0.0.1:{server_port}", "--profile", profile, "--interval",
                                "3600"], args.edge_cpu),
                        stdout=subprocess.DEVNULL, stderr=log))
                    wait_for_port(port, helpers[-1])
                cmd = pinned([binary, "client", "--server", f"127.0.0.1:{port}"] + common,
                             args.client_cpu)
            log.write("$ " + " ".join(cmd) + "\n")
            log.flush()
            result = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=log,
                                    timeout=args.run_timeout)
    finally:
        for proc in reversed(helpers):
            stop_process(proc)
    if result.returncode != 0:
        raise RuntimeError(f"exit {result.returncode}; see {log_path}:\n" + tail(log_path))
    with open(os.path.join(out_dir, "metrics.json")) as f:
        return json.load(f)


def tail(path, lines=15):
    with open(path, errors="replace") as f:
        return "".join(f.readlines()[-lines:])


# ---------------------------------------------------------------------------------------------
# Per-frame errors: trajectory_final.tum against the 7-Scenes ground truth, Sim(3)-aligned


def read_tum(path):
    poses = {}
    with open(path) as f:
        for line in f:
            parts = line.split()
            if not parts or parts[0].startswith("#"):
                continue
            poses[float(parts[0])] = [float(v) for v in parts[1:4]]
    return poses


def read_seven_scenes_positions(folder):
    """frame number -> camera position (the 4x4 camera-to-world translation), finite ones only."""
    positions = {}
    for name in os.listdir(folder):
        m = re.fullmatch(r"frame-(\d+)\.pose\.txt", name)
        if not m:
            continue
        with open(os.path.join(folder, name)) as f:
            rows = [[float(v) for v in line.split()] for line in f if line.strip()]
        t = [rows[0][3], rows[1][3], rows[2][3]]
        if all(math.isfinite(v) for v in t):
            positions[int(m.group(1))] = t
    return positions


def jacobi_max_eigenvector(a):
    """Eigenvector of the largest eigenvalue of a small symmetric matrix (cyclic Jacobi)."""
    n = len(a)
    a = [row[:] for row in a]
    v = [[float(i == j) for j in range(n)] for i in range(n)]
    for _ in range(100):
        off = sum(a[i][j] ** 2 for i in range(n) for j in range(n) if i != j)
        if off < 1e-22:
            break
        for p in range(n):
            for q in range(p + 1, n):
                if abs(a[p][q]) < 1e-300:
                    continue
                theta = (a[q][q] - a[p][p]) / (2 * a[p][q])
                t = math.copysign(1.0, theta) / (abs(theta) + math.sqrt(theta * theta + 1))
                c = 1 / math.sqrt(t * t + 1)
                s = t * c
                for k in range(n):
                    akp, akq = a[k][p], a[k][q]
                    a[k][p], a[k][q] = c * akp - s * akq, s * akp + c * akq
                for k in range(n):
                    apk, aqk = a[p][k], a[q][k]
                    a[p][k], a[q][k] = c * apk - s * aqk, s * apk + c * aqk
                for k in range(n):
                    vkp, vkq = v[k][p], v[k][q]
                    v[k][p], v[k][q] = c * vkp - s * vkq, s * vkp + c * vkq
    best = max(range(n), key=lambda i: a[i][i])
    return [v[k][best] for k in range(n)]


def sim3_align_errors(est, gt):
    """Per-pair distances after the least-squares similarity est -> gt (Horn's quaternion method
    for the rotation, Umeyama's scale)."""
    n = len(est)
    me = [sum(p[i] for p in est) / n for i in range(3)]
    mg = [sum(p[i] for p in gt) / n for i in range(3)]
    x = [[p[i] - me[i] for i in range(3)] for p in est]
    y = [[p[i] - mg[i] for i in range(3)] for p in gt]
    s = [[sum(x[k][i] * y[k][j] for k in range(n)) for j in range(3)] for i in range(3)]
    (sxx, sxy, sxz), (syx, syy, syz), (szx, szy, szz) = s
    nmat = [[sxx + syy + szz, syz - szy, szx - sxz, sxy - syx],
            [syz - szy, sxx - syy - szz, sxy + syx, szx + sxz],
            [szx - sxz, sxy + syx, -sxx + syy - szz, syz + szy],
            [sxy - syx, szx + sxz, syz + szy, -sxx - syy + szz]]
    w, qx, qy, qz = jacobi_max_eigenvector(nmat)
    r = [[1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - w * qz), 2 * (qx * qz + w * qy)],
         [2 * (qx * qy + w * qz), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz - w * qx)],
         [2 * (qx * qz - w * qy), 2 * (qy * qz + w * qx), 1 - 2 * (qx * qx + qy * qy)]]
    rx = [[sum(r[i][j] * p[j] for j in range(3)) for i in range(3)] for p in x]
    var_x = sum(v * v for p in x for v in p)
    scale = sum(rx[k][i] * y[k][i] for k in range(n) for i in range(3)) / var_x if var_x else 1.0
    return [math.dist([scale * v for v in rx[k]], y[k]) for k in range(n)]


def per_frame_errors(trajectory_path, gt_positions):
    if not os.path.exists(trajectory_path):
        return []
    est, gt = [], []
    for stamp, position in sorted(read_tum(trajectory_path).items()):
        frame = round(stamp * 30.0)
        if frame in gt_positions:
            est.append(position)
            gt.append(gt_positions[frame])
    return sim3_align_errors(est, gt) if len(est) >= 3 else []


# ---------------------------------------------------------------------------------------------
# SVG figures


PALETTE = ["#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b"]


def esc(text):
    return str(text).replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")


def nice_ticks(hi, count=5):
    if hi <= 0:
        return [0, 1]
    raw = hi / count
    mag = 10 ** math.floor(math.log10(raw))
    step = next(m * mag for m in (1, 2, 2.5, 5, 10) if m * mag >= raw)
    return [i * step for i in range(int(math.ceil(hi / step)) + 1)]


def fmt_tick(v):
    return f"{v:g}" if abs(v) >= 0.01 or v == 0 else f"{v:.1e}"


class Panel:
    """One plot area inside an SVG, with axes; y linear from 0 or log10."""

    def __init__(self, x0, y0, w, h, y_max, y_label, log=False, y_min=None, x_label="",
                 title="", ticks=None):
        self.x0, self.y0, self.w, self.h = x0, y0, w, h
        self.log = log
        if log:
            lo = y_min if y_min and y_min > 0 else 1.0
            self.lo = 10 ** math.floor(math.log10(lo))
            self.hi = 10 ** math.ceil(math.log10(max(y_max, self.lo * 10)))
            self.ticks = []
            v = self.lo
            while v <= self.hi * 1.0001:
                self.ticks.append(v)
                v *= 10
        else:
            self.ticks = ticks or nice_ticks(y_max * 1.05 if y_max > 0 else 1)
            self.lo, self.hi = 0.0, self.ticks[-1]
        self.y_label, self.x_label, self.title = y_label, x_label, title

    def y(self, value):
        if self.log:
            value = max(value, self.lo)
            f = (math.log10(value) - math.log10(self.lo)) / (math.log10(self.hi) - math.log10(self.lo))
        else:
            f = (value - self.lo) / (self.hi - self.lo)
        return self.y0 + self.h * (1 - min(max(f, 0.0), 1.0))

    def axes(self):
        out = []
        for t in self.ticks:
            yy = self.y(t)
            out.append(f'<line x1="{self.x0}" y1="{yy:.1f}" x2="{self.x0 + self.w}" y2="{yy:.1f}" '
                       f'stroke="#ddd"/>')
            out.append(f'<text x="{self.x0 - 6}" y="{yy + 4:.1f}" text-anchor="end">{fmt_tick(t)}</text>')
        out.append(f'<rect x="{self.x0}" y="{self.y0}" width="{self.w}" height="{self.h}" '
                   f'fill="none" stroke="#333"/>')
        cy = self.y0 + self.h / 2
        out.append(f'<text x="{self.x0 - 48}" y="{cy}" text-anchor="middle" '
                   f'transform="rotate(-90 {self.x0 - 48} {cy})">{esc(self.y_label)}</text>')
        if self.x_label:
            out.append(f'<text x="{self.x0 + self.w / 2}" y="{self.y0 + self.h + 40}" '
                       f'text-anchor="middle">{esc(self.x_label)}</text>')
        if self.title:
            out.append(f'<text x="{self.x0 + self.w / 2}" y="{self.y0 - 10}" text-anchor="middle" '
                       f'font-weight="bold">{esc(self.title)}</text>')
        return out


def svg_document(width, height, body, title):
    return "\n".join([
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" '
        f'viewBox="0 0 {width} {height}" font-family="sans-serif" font-size="12">',
        f'<title>{esc(title)}</title>',
        f'<rect width="{width}" height="{height}" fill="white"/>'] + body + ["</svg>", ""])


def legend(x, y, names, colors):
    out = []
    for i, (name, color) in enumerate(zip(names, colors)):
        out.append(f'<rect x="{x}" y="{y + 18 * i}" width="12" height="12" fill="{color}"/>')
        out.append(f'<text x="{x + 18}" y="{y + 18 * i + 10}">{esc(name)}</text>')
    return out


def bar_panel(panel, groups, series, values, whiskers=None):
    """values[s][g] (None = missing); whiskers[s][g] = upper value drawn as a thin line."""
    out = panel.axes()
    group_w = panel.w / len(groups)
    bar_w = group_w * 0.8 / len(series)
    base = panel.y(panel.lo)
    for g, group in enumerate(groups):
        gx = panel.x0 + g * group_w
        out.append(f'<text x="{gx + group_w / 2:.1f}" y="{panel.y0 + panel.h + 16}" '
                   f'text-anchor="middle">{esc(group)}</text>')
        for s in range(len(series)):
            v = values[s][g]
            bx = gx + group_w * 0.1 + s * bar_w
            if v is None:
                out.append(f'<text x="{bx + bar_w / 2:.1f}" y="{base - 4:.1f}" text-anchor="middle" '
                           f'font-size="9">n/a</text>')
                continue
            top = panel.y(v)
            out.append(f'<rect x="{bx:.1f}" y="{top:.1f}" width="{bar_w * 0.92:.1f}" '
                       f'height="{max(base - top, 0.5):.1f}" fill="{PALETTE[s % len(PALETTE)]}">'
                       f'<title>{esc(series[s])}, {esc(group)}: {v:.3g}</title></rect>')
            if whiskers and whiskers[s][g] is not None:
                wy = panel.y(whiskers[s][g])
                cx = bx + bar_w * 0.46
                out.append(f'<line x1="{cx:.1f}" y1="{top:.1f}" x2="{cx:.1f}" y2="{wy:.1f}" '
                           f'stroke="#222"/>')
                out.append(f'<line x1="{cx - 3:.1f}" y1="{wy:.1f}" x2="{cx + 3:.1f}" y2="{wy:.1f}" '
                           f'stroke="#222"/>')
    return out


def bar_chart(path, title, groups, series, values, y_label, whiskers=None, log=False, note=""):
    flat = [v for row in values for v in row if v is not None]
    flat += [v for row in (whiskers or []) for v in row if v is not None]
    positive = [v for v in flat if v > 0]
    panel = Panel(80, 40, 130 * len(groups), 300, max(flat, default=1.0), y_label, log=log,
                  y_min=min(positive, default=1.0), x_label="link profile", title=title)
    body = bar_panel(panel, groups, series, values, whiskers)
    body += legend(panel.x0 + panel.w + 20, panel.y0, series, PALETTE)
    if note:
        body.append(f'<text x="{panel.x0}" y="{panel.y0 + panel.h + 62}" font-size="10" '
                    f'fill="#555">{esc(note)}</text>')
    write(path, svg_document(panel.x0 + panel.w + 200, panel.y0 + panel.h + 80, body, title))


def two_bar_charts(path, title, groups, series, left, right, note=""):
    """left/right: (values, y_label, subtitle)."""
    body = []
    width = 95 * len(groups)
    x0 = 80
    for values, y_label, subtitle in (left, right):
        flat = [v for row in values for v in row if v is not None]
        panel = Panel(x0, 50, width, 280, max(flat, default=1.0), y_label, x_label="link profile",
                      title=subtitle)
        body += bar_panel(panel, groups, series, values)
        x0 += width + 100
    body += legend(x0 - 80, 50, series, PALETTE)
    body.append(f'<text x="{x0 / 2:.0f}" y="20" text-anchor="middle" font-weight="bold" '
                f'font-size="14">{esc(title)}</text>')
    if note:
        body.append(f'<text x="80" y="392" font-size="10" fill="#555">{esc(note)}</text>')
    write(path, svg_document(x0 + 120, 400, body, title))


def cdf_chart(path, title, curves, x_label):
    """curves: list of (name, sorted values)."""
    curves = [(n, v) for n, v in curves if v]
    x_max = max((v[-1] for _, v in curves), default=1.0)
    x_ticks = nice_ticks(x_max)
    panel = Panel(80, 40, 560, 320, 1.0, "fraction of frames", x_label=x_label, title=title,
                  ticks=[0, 0.25, 0.5, 0.75, 1.0])
    body = panel.axes()
    sx = lambda v: panel.x0 + panel.w * v / x_ticks[-1]
    for t in x_ticks:
        body.append(f'<text x="{sx(t):.1f}" y="{panel.y0 + panel.h + 16}" '
                    f'text-anchor="middle">{fmt_tick(t)}</text>')
    for i, (name, values) in enumerate(curves):
        n = len(values)
        points = [(sx(0), panel.y(0))]
        for k, v in enumerate(values):
            points.append((sx(v), panel.y(k / n)))
            points.append((sx(v), panel.y((k + 1) / n)))
        d = " ".join(f"{x:.1f},{y:.1f}" for x, y in points)
        body.append(f'<polyline points="{d}" fill="none" stroke="{PALETTE[i % len(PALETTE)]}" '
                    f'stroke-width="2"/>')
    body += legend(panel.x0 + panel.w + 20, panel.y0, [n for n, _ in curves], PALETTE)
    write(path, svg_document(panel.x0 + panel.w + 180, panel.y0 + panel.h + 60, body, title))


def write(path, text):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w") as f:
        f.write(text)


# ---------------------------------------------------------------------------------------------
# Collecting, tabulating


def get(metrics, *keys):
    value = metrics
    for key in keys:
        if not isinstance(value, dict) or key not in value:
            return None
        value = value[key]
    return value


def median_of(runs, *keys):
    values = [v for v in (get(r, *keys) for r in runs) if isinstance(v, (int, float))]
    return statistics.median(values) if values else None


def range_of(runs, *keys):
    """' [min-max]' of the runs' values when there are several, else ''."""
    values = [v for v in (get(r, *keys) for r in runs) if isinstance(v, (int, float))]
    return f" [{min(values):.1f}-{max(values):.1f}]" if len(values) > 1 else ""


def f1(v, scale=1.0):
    return "-" if v is None else f"{v * scale:.1f}"


def fmt_count(v):
    return "-" if v is None else f"{v:g}"


def f2(v, scale=1.0):
    return "-" if v is None else f"{v * scale:.2f}"


def adapt_cell(runs):
    adapt = [get(r, "adapt") for r in runs if get(r, "adapt")]
    if not adapt:
        return "-", "-", "-"
    a = adapt[0]
    frames = a.get("frames_per_config")
    return (str(a.get("switches", "-")),
            "/".join(str(v) for v in frames) if isinstance(frames, list) else "-",
            f1(a.get("probe_bytes") / 1e3 if a.get("probe_bytes") is not None else None))


def table(results, args):
    lines = ["| link | mode | frames | tracked | e2e ms median [runs' min-max] / p90 "
             "| client ms median | "
             "slice latency ms median / p90 | uplink MB | downlink MB | ATE final cm | "
             "switches | frames per config (rows 1-5) | probe kB |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for profile in args.profiles:
        for mode, adapt in VARIANTS:
            runs = results.get((profile, mode, adapt), [])
            if not runs:
                continue
            switches, per_config, probe_kb = adapt_cell(runs)
            slice_ms = "-" if mode == "offload" else (
                f"{f1(median_of(runs, 'slice_latency_ms', 'median'))} / "
                f"{f1(median_of(runs, 'slice_latency_ms', 'p90'))}")
            lines.append(
                f"| {profile} | {variant_name(mode, adapt)} | {runs[0].get('frames', '-')} "
                f"| {fmt_count(median_of(runs, 'tracked'))} "
                f"| {f1(median_of(runs, 'e2e_ms', 'median'))}{range_of(runs, 'e2e_ms', 'median')} / "
                f"{f1(median_of(runs, 'e2e_ms', 'p90'))} "
                f"| {f1(median_of(runs, 'client_ms', 'median'))} "
                f"| {slice_ms} "
                f"| {f2(median_of(runs, 'uplink_bytes'), 1e-6)} "
                f"| {f2(median_of(runs, 'downlink_bytes'), 1e-6)} "
                f"| {f2(median_of(runs, 'ate_final', 'rmse_m'), 100)} "
                f"| {switches} | {per_config} | {probe_kb} |")
    return "\n".join(lines)


def update_docs(text_block):
    path = os.path.join(ROOT, "docs", "benchmarks.md")
    text = open(path).read() if os.path.exists(path) else "# Benchmarks\n"
    block = f"<!-- link-bench -->\n{text_block}\n<!-- /link-bench -->"
    if "<!-- link-bench -->" in text:
        text = re.sub(r"<!-- link-bench -->.*?<!-- /link-bench -->", lambda _: block, text,
                      flags=re.S)
    else:
        text = text.rstrip("\n") + "\n\n" + block + "\n"
    with open(path, "w") as f:
        f.write(text)


def figures(results, errors, args, fig_dir):
    groups = args.profiles
    mediator = lambda mode, adapt, *keys: [median_of(results.get((p, mode, adapt), []), *keys)
                                           for p in groups]
    names = [variant_name(m, a) for m, a in VARIANTS]
    note = (f"{args.frames} frames of {os.path.basename(args.dataset.rstrip('/'))}, mono, "
            f"realtime, {args.runs} run(s), topology {args.topology}")
    bar_chart(os.path.join(fig_dir, "link_latency.svg"),
              "End-to-end latency per frame (median, whisker p90)", groups, names,
              [mediator(m, a, "e2e_ms", "median") for m, a in VARIANTS], "ms (log scale)",
              whiskers=[mediator(m, a, "e2e_ms", "p90") for m, a in VARIANTS], log=True,
              note=note)
    cdf_chart(os.path.join(fig_dir, "link_error_cdf.svg"),
              "Per-frame position error, edge mode (adapt on)",
              [(p, sorted(100 * e for e in errors.get((p, "edge", "on"), []))) for p in groups],
              "error after Sim(3) alignment (cm)")
    adapt_variants = [("edge", "on"), ("edge", "off")]
    adapt_names = ["adapt on", "adapt off"]
    two_bar_charts(os.path.join(fig_dir, "link_adapt_latency.svg"),
                   "Latency with and without self-adaptation (edge mode)", groups, adapt_names,
                   ([mediator(m, a, "e2e_ms", "median") for m, a in adapt_variants],
                    "ms", "end-to-end per frame, median"),
                   ([mediator(m, a, "slice_latency_ms", "median") for m, a in adapt_variants],
                    "ms", "keyframe to its slice applied, median"), note=note)
    two_bar_charts(os.path.join(fig_dir, "link_adapt_accuracy.svg"),
                   "Accuracy and traffic with and without self-adaptation (edge mode)", groups,
                   adapt_names,
                   ([[None if v is None else 100 * v for v in mediator(m, a, "ate_final", "rmse_m")]
                     for m, a in adapt_variants], "cm", "ATE final (RMSE)"),
                   ([[None if v is None else v / 1e6 for v in mediator(m, a, "uplink_bytes")]
                     for m, a in adapt_variants], "MB", "uplink"), note=note)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--build-dir", default=os.path.join(ROOT, "build"))
    parser.add_argument("--dataset", default=os.environ.get(
        "EDGESLAM_DATA", os.path.join(ROOT, "..", "shared", "datasets", "7scenes-redkitchen-1000")))
    parser.add_argument("--frames", type=int, default=1000, help="frames per edge-mode run")
    parser.add_argument("--offload-frames", type=int, default=300,
                        help="frames per offload run (at most --frames; offload over a slow link "
                             "runs far below the camera rate)")
    parser.add_argument("--runs", type=int, default=1, help="runs per configuration (medians)")
    parser.add_argument("--profiles", default=",".join(PROFILES))
    parser.add_argument("--topology", choices=["split", "embedded"], default="split")
    parser.add_argument("--client-cpu", default="0", help="core of the client ('none': unpinned)")
    parser.add_argument("--edge-cpu", default="1",
                        help="core of the edge server and emulator, split topology ('none')")
    parser.add_argument("--run-timeout", type=float, default=900.0, help="seconds per run")
    parser.add_argument("--quick", action="store_true",
                        help="smoke test: 60 frames (30 offload), 1 run; docs are not touched "
                             "unless --docs is given")
    parser.add_argument("--docs", action="store_true", help="write docs even with --quick")
    parser.add_argument("--no-docs", action="store_true", help="print only")
    parser.add_argument("--figures-dir",
                        help="where the SVG figures go (default docs/figures; given explicitly, "
                             "figures are written even with --quick or --no-docs)")
    parser.add_argument("--keep", help="keep every run's output folder under this folder")
    args = parser.parse_args()
    if args.quick:
        args.frames, args.offload_frames, args.runs = min(args.frames, 60), 30, 1
    args.profiles = [p.strip() for p in args.profiles.split(",") if p.strip()]
    unknown = [p for p in args.profiles if p not in PROFILES]
    if unknown:
        parser.error(f"unknown profile(s) {', '.join(unknown)}; known: {', '.join(PROFILES)}")
    args.client_cpu = None if args.client_cpu == "none" else args.client_cpu
    args.edge_cpu = None if args.edge_cpu == "none" else args.edge_cpu
    if (args.client_cpu or args.edge_cpu) and not shutil.which("taskset"):
        print("taskset not found: running unpinned", file=sys.stderr)
        args.client_cpu = args.edge_cpu = None
    binary = os.path.join(args.build_dir, "edgeslam")
    if not os.access(binary, os.X_OK):
        parser.error(f"{binary} not found: build first (or pass --build-dir)")
    if not os.path.isdir(args.dataset):
        parser.error(f"dataset {args.dataset} not found (--dataset or EDGESLAM_DATA)")
    gt_positions = read_seven_scenes_positions(args.dataset)
    if not gt_positions:
        print(f"no 7-Scenes poses in {args.dataset}: no error CDF", file=sys.stderr)

    host_before = host_check(args.build_dir, args.client_cpu)
    work = args.keep or tempfile.mkdtemp(prefix="link-bench-")
    results, errors, failures = {}, {}, []
    total = len(args.profiles) * len(VARIANTS) * args.runs
    done = 0
    started = time.monotonic()
    try:
        for profile in args.profiles:
            for mode, adapt in VARIANTS:
                key = (profile, mode, adapt)
                for run in range(args.runs):
                    done += 1
                    label = f"{profile} / {variant_name(mode, adapt)} / run {run + 1}"
                    print(f"[{done}/{total}] {label}", file=sys.stderr, flush=True)
                    out_dir = os.path.join(work, f"{profile}-{mode}-{adapt or 'na'}-{run + 1}")
                    try:
                        metrics = run_once(args, profile, mode, adapt, out_dir)
                    except (RuntimeError, subprocess.TimeoutExpired) as e:
                        print(f"  FAILED: {e}", file=sys.stderr)
                        failures.append(label)
                        continue
                    results.setdefault(key, []).append(metrics)
                    if run == 0 and gt_positions:
                        errors[key] = per_frame_errors(
                            os.path.join(out_dir, "trajectory_final.tum"), gt_positions)
                    print(f"  e2e median {f1(get(metrics, 'e2e_ms', 'median'))} ms, slice latency "
                          f"median {f1(get(metrics, 'slice_latency_ms', 'median'))} ms, ATE final "
                          f"{f2(get(metrics, 'ate_final', 'rmse_m'), 100)} cm, uplink "
                          f"{f2(get(metrics, 'uplink_bytes'), 1e-6)} MB", file=sys.stderr)
    finally:
        if not args.keep:
            shutil.rmtree(work, ignore_errors=True)

    host = host_line(host_before, host_check(args.build_dir, args.client_cpu))
    text = table(results, args) + (f"\n\n{host}" if host else "")
    print(text)
    for key, errs in sorted(errors.items(), key=lambda kv: str(kv[0])):
        if errs:
            rmse = math.sqrt(sum(e * e for e in errs) / len(errs))
            print(f"per-frame errors {key[0]} / {variant_name(key[1], key[2])}: {len(errs)} frames, "
                  f"RMSE {100 * rmse:.2f} cm, median {100 * statistics.median(errs):.2f} cm",
                  file=sys.stderr)
    print(f"{done} runs in {time.monotonic() - started:.0f} s", file=sys.stderr)
    write_docs = not args.no_docs and (not args.quick or args.docs)
    if args.figures_dir or write_docs:
        figures_dir = args.figures_dir or os.path.join(ROOT, "docs", "figures")
        figures(results, errors, args, figures_dir)
        print(f"wrote figures in {figures_dir}", file=sys.stderr)
    if write_docs:
        setup = (f"{args.frames} frames ({min(args.frames, args.offload_frames)} in offload mode) "
                 f"of `{os.path.basename(args.dataset.rstrip('/'))}`, monocular, `--realtime`, "
                 f"{args.runs} run(s) per row (medians), topology `{args.topology}` (client on core "
                 f"{args.client_cpu}, edge and emulator on core {args.edge_cpu}); "
                 f"`bench/link_experiments.py`.")
        update_docs(setup + "\n\n" + text)
        print("wrote docs/benchmarks.md (link-bench)", file=sys.stderr)
    if failures:
        print(f"{len(failures)} run(s) failed: {', '.join(failures)}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
