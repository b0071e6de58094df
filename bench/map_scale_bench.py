#!/usr/bin/env python3
"""Cost against map size (issue 25, item 1): maps of ~100 to ~10,000 keyframes on one edge.

The maps are made of a real one: an edge run over redkitchen RGB-D with the default keyframe
rules, copied N times into one stored map (bench/replicate_map.py: the copies are the
same place at the same coordinates, sharing no points; place recognition finds every copy of a
place, so candidate lists are as long as they get). For each size, on one server (core 1) with the
map store, one client (core 0) at a time:
  - load: `edgeslam map info NAME --load` (read, rebuild, bags of words; ms and peak RSS);
  - mapping: an edge client naming the map (--map, RGB-D, --realtime, a stretch of frames): client
    ms per frame, slice bytes, and the server's per-keyframe costs (server --metrics:
    keyframe_mapping, local_ba, loop_detection, loop_correction, global_ba; store write per
    batch), the server's peak RSS;
  - localisation: a localise-only client on another stretch: the edge's relocalisation against
    the whole map (ms per lost frame asked about), the client's answer latency.
Each curve's growth is named from a log-log fit of its medians (flat, sub-linear, linear, ...).

Writes the table to docs/benchmarks.md (between the MAP-SCALE markers) unless --no-docs, and
docs/figures/map_scale.svg. Usage:
  bench/map_scale_bench.py [--build build] [--shared ../shared] [--sizes 100,300,1000,3000,10000]
                           [--runs 1] [--keep DIR]
"""
import argparse
import json
import math
import os
import shutil
import sqlite3
import statistics
import subprocess
import sys
import tempfile
import time

from docs_block import replace_block
from link_experiments import (PALETTE, Panel, free_port, legend, stop_process, svg_document,
                              wait_for_port, write)

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DOCS = os.path.join(ROOT, "docs", "benchmarks.md")
FIGURES = os.path.join(ROOT, "docs", "figures")
BEGIN, END = "<!-- MAP-SCALE:BEGIN -->", "<!-- MAP-SCALE:END -->"
CLIENT_CPU, SERVER_CPU = 0, 1
SOURCE = "scale-source"


def log(text):
    print(text, flush=True)


def run(cmd, **kwargs):
    result = subprocess.run(cmd, capture_output=True, text=True, **kwargs)
    if result.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed ({result.returncode}):\n"
                           f"{result.stdout[-2000:]}\n{result.stderr[-2000:]}")
    return result


def peak_rss_mib(pid):
    try:
        with open(f"/proc/{pid}/status") as f:
            for line in f:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1]) / 1024.0
    except OSError:
        pass
    return None


def stored_maps(store):
    path = os.path.join(store, "maps.sqlite")
    if not os.path.exists(path):
        return set()
    with sqlite3.connect(path) as db:
        return {name for (name,) in db.execute("SELECT name FROM maps")}


def make_source(args, store):
    """The real map the large ones are copied from; its keyframe count (kept from an earlier run
    of the bench in --keep's folder when it is there)."""
    out = os.path.join(args.work, "source")
    if SOURCE in stored_maps(store) and os.path.exists(os.path.join(out, "metrics.json")):
        with open(os.path.join(out, "metrics.json")) as f:
            metrics = json.load(f)
        return metrics["keyframes"], metrics["ate"]["rmse_m"] * 100
    # The keyframe rules a user runs with. Before session 24 `--fmin 0 --beta 1.0` gave ~91
    # keyframes (the edge, busy, refused most); since frames fed back to back wait for the
    # edge's answer, the edge takes nearly every frame with them (344 keyframes after 12 min).
    run([args.exe, "run", "--dataset", args.dataset, "--sensor", "rgbd", "--mode", "edge",
         "--maps", store, "--map", SOURCE, "--out", out])
    with open(os.path.join(out, "metrics.json")) as f:
        metrics = json.load(f)
    return metrics["keyframes"], metrics["ate"]["rmse_m"] * 100


def make_map(args, source_store, name, copies):
    """A store of its own holding map `name` (and the source it was copied from), so that what a
    process maps of the store file is this map's."""
    store = os.path.join(args.work, f"store-{name}")
    shutil.rmtree(store, ignore_errors=True)
    os.makedirs(store)
    shutil.copy(os.path.join(source_store, "maps.sqlite"), store)
    run([sys.executable, os.path.join(ROOT, "bench", "replicate_map.py"), "--maps", store,
         "--source", SOURCE, "--target", name, "--copies", str(copies)])
    return store


def measure_load(args, store, name):
    proc = subprocess.Popen(["taskset", "-c", str(SERVER_CPU), args.exe, "map", "info", name,
                             "--maps", store, "--load", "--json", "--vocab", args.vocab],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    peak = None
    while proc.poll() is None:
        peak = max(filter(None, [peak, peak_rss_mib(proc.pid)]), default=None)
        time.sleep(0.05)
    out, err = proc.communicate()
    if proc.returncode != 0:
        raise RuntimeError(f"map info --load failed: {err[-2000:]}")
    info = json.loads(out)
    load = info["load"]
    return {"keyframes": load["keyframes"], "points": load["points"], "bytes": info["bytes"],
            "load_ms": load["load_ms"], "load_cpu_ms": load["load_cpu_ms"],
            "read_ms": load["read_ms"], "rebuild_ms": load["rebuild_ms"],
            "bow_ms": load["bow_ms"], "load_rss_mib": peak}


def server_session(args, store, name, client_args, tag):
    """One server, one client session into map `name`; the client's and the server's metrics."""
    out = os.path.join(args.work, f"{name}-{tag}")
    os.makedirs(out, exist_ok=True)
    port = free_port()
    metrics_file = os.path.join(out, "server_metrics.json")
    server = subprocess.Popen(
        ["taskset", "-c", str(SERVER_CPU), args.exe, "server", "--listen", f"127.0.0.1:{port}",
         "--maps", store, "--semantic", "off", "--vocab", args.vocab, "--metrics", metrics_file,
         "--status-every", "5"],
        stdout=open(os.path.join(out, "server.log"), "w"), stderr=subprocess.STDOUT)
    try:
        wait_for_port(port, server, timeout_s=60)
        started = time.monotonic()
        client = subprocess.run(
            ["taskset", "-c", str(CLIENT_CPU), args.exe, "client", "--server",
             f"127.0.0.1:{port}", "--dataset", args.dataset, "--sensor", "rgbd", "--map", name,
             "--realtime", "--out", out] + client_args,
            capture_output=True, text=True, timeout=1800)
        session_s = time.monotonic() - started
        with open(os.path.join(out, "client.log"), "w") as f:
            f.write(client.stdout + client.stderr)
        if client.returncode != 0:
            raise RuntimeError(f"client failed ({client.returncode}); see {out}/client.log")
        # The loop closer and a global BA may still run: give them until they are done (the
        # session's costs are read from the server's metrics once it has stopped).
        time.sleep(args.settle_s)
        server_rss = peak_rss_mib(server.pid)
    finally:
        stop_process(server)
    with open(os.path.join(out, "metrics.json")) as f:
        client_metrics = json.load(f)
    with open(metrics_file) as f:
        server_metrics = json.load(f)
    recent = server_metrics["closed_sessions"]["recent"]
    session = recent[-1] if recent else {}
    return client_metrics, session, server_metrics.get("store", {}), server_rss, session_s


def stage(session, name, key="median"):
    s = session.get("backend_ms", {}).get(name)
    return s[key] if s and s["count"] > 0 else None


def measure(args, store, name):
    row = measure_load(args, store, name)
    log(f"  load: {row['keyframes']} keyframes, {row['load_ms']:.0f} ms, "
        f"{row['load_rss_mib'] or 0:.0f} MiB")
    client, session, store_metrics, rss, _ = server_session(
        args, store, name, ["--frames", args.mapping_frames], "mapping")
    slices = max(1, client.get("slices_applied", 0))
    row.update({
        "client_ms": client["client_ms"]["median"],
        "client_p95": client["client_ms"]["p95"],
        "slice_bytes": client["downlink_bytes"] / slices,
        "slice_latency_ms": client["slice_latency_ms"]["median"],
        "tracked": client["tracked"] / max(1, client["frames_processed"]) * 100,
        "keyframe_ms": stage(session, "keyframe_mapping"),
        "keyframe_p95": stage(session, "keyframe_mapping", "p95"),
        "local_ba_ms": stage(session, "local_ba"),
        "loop_detection_ms": stage(session, "loop_detection"),
        "loop_detection_p95": stage(session, "loop_detection", "p95"),
        "loop_correction_ms": stage(session, "loop_correction", "max"),
        "loops": (session.get("backend_ms", {}).get("loop_correction") or {}).get("count", 0),
        "global_ba_ms": stage(session, "global_ba", "max"),
        "global_ba_handover_ms": stage(session, "global_ba_handover", "max"),
        "store_write_ms": (store_metrics.get("write_ms") or {}).get("median"),
        "server_rss_mib": rss,
    })
    log(f"  mapping: client {row['client_ms']:.1f} ms, keyframe {row['keyframe_ms']} ms, "
        f"loop detection {row['loop_detection_ms']} ms, server {rss or 0:.0f} MiB")
    client, session, _, rss, _ = server_session(
        args, store, name, ["--frames", args.localize_frames, "--localize-only"], "localize")
    row.update({
        "reloc_ms": stage(session, "relocalization"),
        "reloc_p95": stage(session, "relocalization", "p95"),
        "relocs": (session.get("backend_ms", {}).get("relocalization") or {}).get("count", 0),
        "answer_ms": (client.get("localization", {}).get("edge", {}).get("answer_ms") or {})
        .get("median"),
        "first_pose": client.get("localization", {}).get("first_pose_frame"),
        "localized": client["tracked"] / max(1, client["frames_processed"]) * 100,
        "localize_rss_mib": rss,
    })
    log(f"  localisation: relocalisation {row['reloc_ms']} ms ({row['relocs']}), first pose "
        f"frame {row['first_pose']}, server {rss or 0:.0f} MiB")
    return row


def median_row(runs):
    """Per column, the median of the runs (columns a run lacks are left out); `spread` keeps
    min-max of the main columns."""
    row = {}
    for key in runs[0]:
        values = [r[key] for r in runs if r.get(key) is not None]
        row[key] = statistics.median(values) if values else None
    row["runs"] = len(runs)
    row["spread"] = {key: (min(r[key] for r in runs if r.get(key) is not None),
                           max(r[key] for r in runs if r.get(key) is not None))
                     for key in ("load_ms", "keyframe_ms", "reloc_ms", "loop_correction_ms")
                     if any(r.get(key) is not None for r in runs)}
    return row


def growth(sizes, values):
    """Exponent of a least-squares fit values ~ size^k and its name."""
    pts = [(math.log(s), math.log(v)) for s, v in zip(sizes, values) if v and v > 0]
    if len(pts) < 3:
        return None, "-"
    mx = statistics.mean(p[0] for p in pts)
    my = statistics.mean(p[1] for p in pts)
    k = (sum((x - mx) * (y - my) for x, y in pts) / sum((x - mx) ** 2 for x, _ in pts))
    name = ("flat" if k < 0.15 else "sub-linear" if k < 0.8 else "linear" if k < 1.2
            else "super-linear")
    return k, name


COLUMNS = [  # (key, header, digits)
    ("keyframes", "keyframes", 0), ("points", "points", 0), ("bytes", "store MB", -6),
    ("load_ms", "load ms", 0), ("load_rss_mib", "load peak RSS MiB", 0),
    ("client_ms", "client ms p50", 1), ("slice_bytes", "slice KB", -3),
    ("keyframe_ms", "edge ms per keyframe p50", 1), ("local_ba_ms", "local BA ms p50", 1),
    ("loop_detection_ms", "loop detection ms p50", 1),
    ("loop_detection_p95", "loop detection ms p95", 1),
    ("loop_correction_ms", "loop correction ms (max)", 0),
    ("global_ba_ms", "global BA ms (max)", 0),
    ("global_ba_handover_ms", "global BA handover ms (max)", 0),
    ("store_write_ms", "store write ms per batch", 1),
    ("server_rss_mib", "server peak RSS MiB (mapping)", 0),
    ("reloc_ms", "relocalisation ms p50", 1), ("localized", "localised %", 1),
]


def cell(row, key, digits):
    v = row.get(key)
    if v is None:
        return "-"
    if digits < 0:
        return f"{v / 10 ** -digits:.1f}"
    return f"{v:.{digits}f}"


def table(rows, args, source_keyframes, source_ate):
    sizes = [r["keyframes"] for r in rows]
    lines = [
        f"Maps made of one real map (redkitchen RGB-D, edge mode, the default keyframe rules: "
        f"{source_keyframes} keyframes, ATE {source_ate:.2f} cm) copied into one "
        "stored map (`bench/replicate_map.py`). One server (core 1) with the store, one client "
        f"(core 0) at a time at the camera's rate: an RGB-D edge client mapping frames "
        f"{args.mapping_frames} into the map, then a localise-only client on "
        f"{len(args.localize_frames.split(','))} stretches of 20 frames across the sequence (a "
        "relocalisation by the edge against the whole map at each jump). Edge costs are the "
        "server's (`server --metrics`, per session: "
        f"`backend_ms`). Each size run {args.runs} times on a fresh copy of its map: medians of the "
        "runs' figures (each itself a median over the session's keyframes or relocalisations). "
        "Growth: the exponent k of a log-log fit (cost ~ keyframes^k).",
        "",
        "| " + " | ".join(h for _, h, _ in COLUMNS) + " |",
        "|" + "---|" * len(COLUMNS),
    ]
    for row in rows:
        lines.append("| " + " | ".join(cell(row, k, d) for k, _, d in COLUMNS) + " |")
    spreads = []
    for row in rows:
        parts = [f"{k} {lo:.0f}-{hi:.0f}" for k, (lo, hi) in row.get("spread", {}).items()]
        spreads.append(f"{row['keyframes']:.0f}: " + ", ".join(parts))
    lines += ["", "Spread of the runs (min-max, ms): " + "; ".join(spreads) + "."]
    fits = []
    for key, header, digits in COLUMNS[3:]:
        k, name = growth(sizes, [r.get(key) for r in rows])
        if k is not None:
            fits.append(f"{header}: {name} (k = {k:.2f})")
    lines += ["", "Growth with the map's keyframes: " + "; ".join(fits) + "."]
    return "\n".join(lines)


def figure(rows):
    series = [("load_ms", "load ms"), ("keyframe_ms", "edge ms per keyframe"),
              ("loop_detection_ms", "loop detection ms"), ("reloc_ms", "relocalisation ms"),
              ("client_ms", "client ms per frame")]
    values = [v for r in rows for key, _ in series for v in [r.get(key)] if v]
    sizes = [r["keyframes"] for r in rows]
    panel = Panel(80, 40, 480, 300, max(values), "ms (median)", log=True, y_min=min(values),
                  x_label="keyframes in the map (log scale)", title="Cost against map size")
    lo, hi = math.log10(min(sizes)), math.log10(max(sizes))

    def x(size):
        return panel.x0 + (math.log10(size) - lo) / max(1e-9, hi - lo) * panel.w

    body = panel.axes()
    for size in sizes:
        body.append(f'<text x="{x(size):.1f}" y="{panel.y0 + panel.h + 16}" '
                    f'text-anchor="middle">{size}</text>')
    for i, (key, _) in enumerate(series):
        pts = [(x(r["keyframes"]), panel.y(r[key])) for r in rows if r.get(key)]
        color = PALETTE[i % len(PALETTE)]
        if len(pts) > 1:
            body.append('<polyline fill="none" stroke="{}" stroke-width="2" points="{}"/>'.format(
                color, " ".join(f"{px:.1f},{py:.1f}" for px, py in pts)))
        for px, py in pts:
            body.append(f'<circle cx="{px:.1f}" cy="{py:.1f}" r="3" fill="{color}"/>')
    body += legend(panel.x0 + panel.w + 20, panel.y0, [name for _, name in series], PALETTE)
    write(os.path.join(FIGURES, "map_scale.svg"),
          svg_document(panel.x0 + panel.w + 220, panel.y0 + panel.h + 70, body,
                       "Cost against map size"))


def update_docs(block):
    replace_block(DOCS, BEGIN, END, block,
                  "Cost against map size (`bench/map_scale_bench.py`)")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--build", default=os.path.join(ROOT, "build"))
    parser.add_argument("--shared", default=os.environ.get("EDGESLAM_SHARED",
                                                           os.path.join(ROOT, "..", "shared")))
    parser.add_argument("--sizes", default="100,300,1000,3000,10000",
                        help="keyframes wanted per map (rounded to whole copies)")
    parser.add_argument("--mapping-frames", default="0-299")
    # Short stretches across the sequence: at each jump the client is lost and asks the edge to
    # relocalise it against the whole map, so the relocalisation has a median to speak of.
    parser.add_argument("--localize-frames",
                        default=",".join(f"{a}-{a + 19}" for a in range(40, 1000, 80)))
    parser.add_argument("--settle-s", type=float, default=5.0,
                        help="seconds the server gets after a client, for loops and global BA")
    parser.add_argument("--runs", type=int, default=3,
                        help="runs per size (a fresh copy of the map each): medians in the table")
    parser.add_argument("--keep", default=None, help="keep the store and outputs in this folder")
    parser.add_argument("--no-docs", action="store_true")
    args = parser.parse_args()
    args.build = os.path.abspath(args.build)
    args.exe = os.path.join(args.build, "edgeslam")
    args.vocab = os.path.join(args.build, "vocab", "orb_k10_l5.vocab")
    args.dataset = os.path.join(args.shared, "datasets", "7scenes-redkitchen-1000")
    for path, what in ((args.exe, "build first"), (args.vocab, "make vocab"),
                       (args.dataset, "--shared")):
        if not os.path.exists(path):
            sys.exit(f"map_scale_bench: no {path} ({what})")
    args.work = args.keep or tempfile.mkdtemp(prefix="edgeslam-map-scale-")
    os.makedirs(args.work, exist_ok=True)
    store = os.path.join(args.work, "store")
    started = time.monotonic()
    source_keyframes, source_ate = make_source(args, store)
    log(f"source map: {source_keyframes} keyframes, ATE {source_ate:.2f} cm")
    rows = []
    for wanted in [int(s) for s in args.sizes.split(",")]:
        copies = max(1, round(wanted / source_keyframes))
        name = f"scale-{copies}"
        log(f"[{time.monotonic() - started:.0f} s] {copies} copies (~{copies * source_keyframes} "
            "keyframes)")
        runs = []
        for run in range(args.runs):
            log(f"  run {run + 1}/{args.runs}")
            runs.append(measure(args, make_map(args, store, name, copies), name))
        rows.append(median_row(runs))
    block = table(rows, args, source_keyframes, source_ate)
    print(block)
    if not args.no_docs:
        update_docs(block)
        figure(rows)
    if not args.keep:
        shutil.rmtree(args.work, ignore_errors=True)


if __name__ == "__main__":
    main()
