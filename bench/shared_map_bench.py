#!/usr/bin/env python3
"""Several clients in one map: accuracy of the map they make together, against one client alone.

For each sensor: --runs times, one `edgeslam server` with a map store in a temporary folder and two
`edgeslam client` processes started together, playing two stretches of the dataset (default
frames 0-549 and 450-999 of redkitchen) into one named map; then the same two stretches one after
the other (the second client resumes the stored map); then one client over the whole of both
stretches into a map of its own. Each stored map is exported (`map export --format tum`) and its
keyframe ATE taken against the clients' ground truth together, one alignment for the whole map
(SE(3) with depth, Sim(3) monocular). The server log gives the merge: which client's frame, how
many keyframes moved.

Writes the table to docs/benchmarks.md (between the SHARED-MAP markers) unless --no-docs. Usage:
  bench/shared_map_bench.py [--build build] [--shared ../shared] [--sensors rgbd,mono]
                            [--runs 5] [--first 0-549] [--second 450-999]
                            [--pacing fast|realtime]
"""
import argparse
import json
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

from host_check import host_check, host_line
from link_experiments import free_port, stop_process, wait_for_port, write

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DOCS = os.path.join(ROOT, "docs", "benchmarks.md")
BEGIN, END = "<!-- SHARED-MAP:BEGIN -->", "<!-- SHARED-MAP:END -->"
MERGED = re.compile(r"maps merged: keyframe \d+ \(frame (\d+)\) -> keyframe \d+ \(frame (\d+)\): "
                    r"(\d+) keyframes")


def read_tum(path):
    rows = {}
    with open(path) as f:
        for line in f:
            if line.strip() and not line.startswith("#"):
                rows[float(line.split()[0])] = line
    return rows


def joint_truth(out_dirs, path):
    rows = {}
    for out in out_dirs:
        rows.update(read_tum(os.path.join(out, "groundtruth.tum")))
    write(path, "".join(rows[t] for t in sorted(rows)))


def keyframe_ate(edgeslam, store, map_name, truth, work, sensor):
    keyframes = os.path.join(work, map_name + "_keyframes.tum")
    subprocess.run([edgeslam, "map", "export", map_name, "--format", "tum", "--out", keyframes,
                    "--maps", store], check=True, capture_output=True)
    align = "sim3" if sensor == "mono" else "se3"
    out = subprocess.run([edgeslam, "eval", "ate", "--gt", truth, "--est", keyframes, "--align",
                          align, "--json"], check=True, capture_output=True, text=True)
    return json.loads(out.stdout)["rmse_m"], len(read_tum(keyframes))


class Server:
    def __init__(self, args, store, log_path):
        self.port = free_port()
        self.log_path = log_path
        self.log = open(log_path, "w")
        command = [args.edgeslam, "server", "--listen", f"127.0.0.1:{self.port}",
                   "--status-every", "0", "--semantic", "off", "--maps", store]
        self.proc = subprocess.Popen(command, stdout=self.log, stderr=subprocess.STDOUT)
        wait_for_port(self.port, self.proc)

    def client(self, args, sensor, frames, map_name, out):
        command = [args.edgeslam, "client", "--server", f"127.0.0.1:{self.port}", "--dataset",
                   args.dataset, "--frames", frames, "--sensor", sensor, "--map", map_name,
                   "--out", out, "--" + args.pacing]
        return subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)

    def stop(self):
        stop_process(self.proc)
        self.log.close()
        with open(self.log_path) as f:
            return f.read()


def wait_all(procs, what):
    for proc in procs:
        if proc.wait() != 0:
            sys.exit(f"shared_map_bench: a client of the {what} run failed")


def one_run(args, sensor, work):
    """The figures of one trial: together, one after the other, alone."""
    figures = {}
    for layout in ("together", "in turn", "alone"):
        folder = os.path.join(work, layout.replace(" ", "_"))
        store = os.path.join(folder, "store")
        os.makedirs(folder)
        server = Server(args, store, os.path.join(folder, "server.log"))
        started = time.monotonic()
        outs = [os.path.join(folder, "first"), os.path.join(folder, "second")]
        if layout == "together":
            wait_all([server.client(args, sensor, args.first, "shared", outs[0]),
                      server.client(args, sensor, args.second, "shared", outs[1])], layout)
        elif layout == "in turn":
            wait_all([server.client(args, sensor, args.first, "shared", outs[0])], layout)
            wait_all([server.client(args, sensor, args.second, "shared", outs[1])], layout)
        else:
            lo = args.first.split("-")[0]
            hi = args.second.split("-")[1]
            outs = [os.path.join(folder, "whole")]
            wait_all([server.client(args, sensor, f"{lo}-{hi}", "shared", outs[0])], layout)
        seconds = time.monotonic() - started
        log = server.stop()
        truth = os.path.join(folder, "truth.tum")
        joint_truth(outs, truth)
        ate, keyframes = keyframe_ate(args.edgeslam, store, "shared", truth, folder, sensor)
        merges = MERGED.findall(log)
        figures[layout] = {"ate_m": ate, "keyframes": keyframes, "seconds": seconds,
                           "merges": len(merges),
                           "merge": merges[0] if merges else None,
                           "moved_late": log.count("tracked before its client heard")}
    return figures


def cm(values):
    return f"{100 * statistics.median(values):.1f} ({100 * min(values):.1f}-{100 * max(values):.1f})"


def table(args, results, host):
    lines = [
        f"Measured {time.strftime('%Y-%m-%d')} with `bench/shared_map_bench.py --runs {args.runs}` "
        f"({os.path.basename(args.dataset)}, frames {args.first} and {args.second}, two clients "
        f"with --{args.pacing} on one 2-core host with the server). Keyframe ATE of the stored "
        "map against the clients' ground truth together, one alignment for the whole map (SE(3) RGB-D, Sim(3) "
        "monocular): median (min-max) in cm. \"together\": both clients at once into one map; "
        "\"in turn\": the second after the first, resuming the stored map; \"alone\": one client "
        "over both stretches. Merged: runs whose two parts a loop merged; at: the frame of the "
        "merging keyframe (of its own client's stretch), median.",
        host, "",
        "| sensor | together | in turn | alone | together / alone | merged (together, in turn) "
        "| merge at frame (together; in turn) |",
        "|---|---|---|---|---|---|---|"]
    for sensor, runs in results.items():
        def col(layout):
            return [r[layout]["ate_m"] for r in runs]

        def merged(layout):
            return sum(1 for r in runs if r[layout]["merges"] > 0)

        def at(layout):
            frames = [int(r[layout]["merge"][0]) for r in runs if r[layout]["merge"]]
            return f"{statistics.median(frames):.0f}" if frames else "-"

        ratio = statistics.median(col("together")) / statistics.median(col("alone"))
        lines.append(f"| {sensor} | {cm(col('together'))} | {cm(col('in turn'))} | "
                     f"{cm(col('alone'))} | {ratio:.2f} | {merged('together')}/{len(runs)}, "
                     f"{merged('in turn')}/{len(runs)} | {at('together')}; {at('in turn')} |")
    return "\n".join(lines)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--build", default=os.path.join(ROOT, "build"))
    parser.add_argument("--shared", default=os.environ.get("EDGESLAM_SHARED",
                                                           os.path.join(ROOT, "..", "shared")))
    parser.add_argument("--dataset", default=None)
    parser.add_argument("--sensors", default="rgbd,mono")
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--first", default="0-549")
    parser.add_argument("--second", default="450-999")
    parser.add_argument("--pacing", choices=["fast", "realtime"], default="fast")
    parser.add_argument("--no-docs", action="store_true")
    args = parser.parse_args()
    args.edgeslam = os.path.join(args.build, "edgeslam")
    args.dataset = args.dataset or os.path.join(args.shared, "datasets",
                                                "7scenes-redkitchen-1000")
    if not os.path.exists(args.edgeslam):
        sys.exit(f"shared_map_bench: no {args.edgeslam} (build first)")
    if not os.path.isdir(args.dataset):
        sys.exit(f"shared_map_bench: no dataset at {args.dataset}")
    before = host_check(args.build, None)
    results = {}
    for sensor in args.sensors.split(","):
        results[sensor] = []
        for run in range(args.runs):
            work = tempfile.mkdtemp(prefix="edgeslam_shared_map_")
            try:
                figures = one_run(args, sensor, work)
            finally:
                shutil.rmtree(work, ignore_errors=True)
            results[sensor].append(figures)
            print(f"{sensor} run {run + 1}/{args.runs}: " + ", ".join(
                f"{layout} {100 * f['ate_m']:.2f} cm ({f['keyframes']} keyframes, "
                f"{f['merges']} merge(s), {f['seconds']:.0f} s)" for layout, f in figures.items()),
                flush=True)
    text = table(args, results, host_line(before, host_check(args.build, None)))
    print(text)
    if not args.no_docs:
        with open(DOCS) as f:
            docs = f.read()
        if BEGIN in docs and END in docs:
            head, rest = docs.split(BEGIN, 1)
            docs = head + BEGIN + "\n" + text + "\n" + END + rest.split(END, 1)[1]
        else:
            docs += f"\n## Several clients in one map\n\n{BEGIN}\n{text}\n{END}\n"
        write(DOCS, docs)


if __name__ == "__main__":
    main()
