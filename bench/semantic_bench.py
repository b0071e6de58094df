#!/usr/bin/env python3
"""Dynamic-scene benchmark (issue: semantic layer): generated dynamic sequences (real people from
../shared/datasets/people pasted over real 7-Scenes frames by `edgeslam synth-dynamic`, with
ground-truth masks), each run with semantic culling on and off, in local and edge mode, plus the
static original frames, in monocular and RGB-D.

local: `edgeslam run` on both cores (tracking, mapping and segmentation threads, as one machine
would run them). edge: `edgeslam server` pinned to core 1 and `edgeslam client` to core 0, over
loopback gRPC.

Reports per row: ATE (final, Sim3 for mono, SE3 for RGB-D) static / semantic off / semantic on,
transferred-mask IoU median on non-keyframes, the share of features on people that reached
tracking, segmentation time per keyframe and the client's extra time per frame (transfer and
culling). Writes the table into docs/benchmarks.md between <!-- semantic-bench --> markers.

  bench/semantic_bench.py [--build-dir build] [--seeds 3,11] [--frames 0-299]
                          [--sensors rgbd,mono] [--modes local,edge] [--runs 1] [--no-docs]
"""
import argparse
import json
import os
import re
import socket
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def free_port():
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def pinned(cmd, cpu):
    return ["taskset", "-c", str(cpu)] + cmd


def wait_for_port(port, proc, timeout_s=30.0):
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if proc.poll() is not None:
            raise RuntimeError(f"server exited with {proc.returncode} before listening")
        try:
            with socket.create_connection(("127.0.0.1", port), timeout=0.5):
                return
        except OSError:
            time.sleep(0.1)
    raise RuntimeError(f"nothing listens on port {port}")


def run_once(binary, dataset, sensor, mode, semantic, max_frames, extra, pacing="--realtime"):
    with tempfile.TemporaryDirectory() as out:
        # At the camera's rate by default: how many frames late a mask arrives is what the
        # transfer must bridge.
        common = ["--dataset", dataset, "--sensor", sensor, "--semantic", semantic, pacing,
                  "--out", out]
        if max_frames:
            common += ["--max-frames", str(max_frames)]
        common += extra
        server = None
        if mode == "local":
            cmd = pinned([binary, "run", "--mode", "local"] + common, "0,1")
        else:
            port = free_port()
            server = subprocess.Popen(
                pinned([binary, "server", "--listen", f"127.0.0.1:{port}", "--status-every", "0"],
                       1),
                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            wait_for_port(port, server)
            cmd = pinned([binary, "client", "--server", f"127.0.0.1:{port}"] + common, 0)
        try:
            subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        finally:
            if server is not None:
                server.terminate()
                server.wait(timeout=20)
        with open(os.path.join(out, "metrics.json")) as f:
            return json.load(f)


def ate_cm(m):
    return 100.0 * m["ate_final"]["rmse_m"] if "ate_final" in m else float("nan")


def median_of(runs, fn):
    values = [fn(m) for m in runs]
    values = [v for v in values if v is not None]
    return statistics.median(values) if values else None


def fmt(value, spec):
    return "-" if value is None else format(value, spec)


def ensure_sequence(binary, shared, work, frames, seed, name=None, extra=()):
    """The generated sequence (reused when present); `extra`: more synth-dynamic options."""
    out = os.path.join(work, name or f"7scenes-{frames}-seed{seed}")
    if os.path.exists(os.path.join(out, "masks.txt")):
        return out
    subprocess.run([binary, "synth-dynamic", "--dataset",
                    os.path.join(shared, "datasets/7scenes-redkitchen-1000"), "--out", out,
                    "--frames", frames, "--seed", str(seed), "--overwrite"] + list(extra),
                   check=True, stdout=subprocess.DEVNULL)
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--build-dir", default=os.path.join(ROOT, "build"))
    parser.add_argument("--shared", default=os.environ.get("EDGESLAM_SHARED",
                                                           os.path.join(ROOT, "..", "shared")))
    parser.add_argument("--work", default=os.path.join(tempfile.gettempdir(),
                                                       "edgeslam-semantic-bench"),
                        help="where the generated sequences are kept (reused when present)")
    parser.add_argument("--seeds", default="3,11")
    parser.add_argument("--frames", default="0-299", help="7-Scenes frames A-B")
    parser.add_argument("--sensors", default="rgbd,mono")
    parser.add_argument("--modes", default="local,edge")
    parser.add_argument("--runs", type=int, default=1)
    parser.add_argument("--no-docs", action="store_true")
    args = parser.parse_args()

    binary = os.path.join(args.build_dir, "edgeslam")
    first, last = (int(v) for v in args.frames.split("-"))
    if first != 0:
        sys.exit("--frames must start at 0 (the static baseline is the original's first frames)")
    frame_count = last - first + 1
    os.makedirs(args.work, exist_ok=True)
    original = os.path.join(args.shared, "datasets/7scenes-redkitchen-1000")
    sequences = [(seed, ensure_sequence(binary, args.shared, args.work, args.frames, int(seed)))
                 for seed in args.seeds.split(",")]
    rows = []
    started = time.monotonic()
    for sensor in args.sensors.split(","):
        for mode in args.modes.split(","):
            static = [run_once(binary, original, sensor, mode, "off", frame_count, [])
                      for _ in range(args.runs)]
            for seed, dataset in sequences:
                off = [run_once(binary, dataset, sensor, mode, "off", 0, [])
                       for _ in range(args.runs)]
                on = [run_once(binary, dataset, sensor, mode, "on", 0, [])
                      for _ in range(args.runs)]
                row = {
                    "sequence": f"7-Scenes {args.frames} + people (seed {seed})",
                    "sensor": sensor, "mode": mode,
                    "ate_static": median_of(static, ate_cm),
                    "ate_off": median_of(off, ate_cm), "ate_on": median_of(on, ate_cm),
                    "tracked_on": median_of(on, lambda m: m["tracked"]),
                    "frames": frame_count,
                    "iou": median_of(on, lambda m: m["semantic"]["mask_iou_median"]),
                    "kept_off": median_of(off, lambda m: m["semantic"]["dynamic_features_kept_ratio"]),
                    "kept_on": median_of(on, lambda m: m["semantic"]["dynamic_features_kept_ratio"]),
                    "seg_ms": median_of(on, lambda m: m["segmentation_ms"]["median"]),
                    "keyframes_segmented": median_of(on, lambda m: m["semantic"]["keyframes_segmented"]),
                    "extra_ms": median_of(on, lambda m: m["semantic"]["client_ms"]["median"]),
                    "client_off": median_of(off, lambda m: m["client_ms"]["median"]),
                    "client_on": median_of(on, lambda m: m["client_ms"]["median"]),
                }
                rows.append(row)
                print(f"{row['sequence']} {sensor} {mode}: ATE static {row['ate_static']:.2f} "
                      f"off {row['ate_off']:.2f} on {row['ate_on']:.2f} cm, IoU {fmt(row['iou'], '.2f')}, "
                      f"kept {fmt(row['kept_on'], '.2f')}, seg {fmt(row['seg_ms'], '.0f')} ms, "
                      f"extra {fmt(row['extra_ms'], '.2f')} ms", flush=True)
    elapsed = time.monotonic() - started

    lines = [
        f"Generated dynamic sequences (`edgeslam synth-dynamic`, 7-Scenes frames {args.frames}, "
        f"real people from `datasets/people`), {args.runs} run(s) per cell (medians); local mode "
        "on both cores, edge mode = server on core 1 + client on core 0, frames fed at 30 fps "
        "(`--realtime`); `bench/semantic_bench.py`, "
        f"{elapsed:.0f} s.",
        "",
        "| sequence | sensor | mode | ATE static cm | ATE semantic off cm | ATE semantic on cm | on / static | "
        "tracked (on) | mask IoU median | people features kept off / on | segmentation ms / keyframe | "
        "keyframes segmented | client extra ms / frame | client ms off / on |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        ratio = r["ate_on"] / r["ate_static"] if r["ate_static"] else None
        lines.append(
            f"| {r['sequence']} | {r['sensor']} | {r['mode']} | {r['ate_static']:.2f} | "
            f"{r['ate_off']:.2f} | {r['ate_on']:.2f} | {fmt(ratio, '.2f')} | "
            f"{fmt(r['tracked_on'], '.0f')}/{r['frames']} | {fmt(r['iou'], '.2f')} | "
            f"{fmt(r['kept_off'], '.2f')} / {fmt(r['kept_on'], '.2f')} | {fmt(r['seg_ms'], '.0f')} | "
            f"{fmt(r['keyframes_segmented'], '.0f')} | {fmt(r['extra_ms'], '.2f')} | "
            f"{fmt(r['client_off'], '.1f')} / {fmt(r['client_on'], '.1f')} |")
    table = "\n".join(lines)
    print()
    print(table)
    if not args.no_docs:
        path = os.path.join(ROOT, "docs", "benchmarks.md")
        with open(path) as f:
            text = f.read()
        block = f"<!-- semantic-bench -->\n{table}\n<!-- /semantic-bench -->"
        if "<!-- semantic-bench -->" in text:
            text = re.sub(r"<!-- semantic-bench -->.*?<!-- /semantic-bench -->", block, text,
                          flags=re.S)
        else:
            text += "\n## Dynamic scenes: semantic culling\n\n" + block + "\n"
        with open(path, "w") as f:
            f.write(text)
        print(f"wrote {path} (semantic-bench)")


if __name__ == "__main__":
    main()
