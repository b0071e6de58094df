#!/usr/bin/env python3
"""Many clients against one edge server: load over minutes on this machine.

For each sensor and client count, one `edgeslam server` (a real map store in a temporary folder)
and N `edgeslam client` processes in edge mode, fed at the camera's rate (--realtime, so a client
that falls behind takes the newest due frame and counts the ones it skipped). Each client slot
plays the dataset --passes times in a row as new sessions, so the server carries the load for
minutes and sees sessions come and go.
The server's RSS and CPU are sampled from /proc every --sample-s seconds.

Writes the table to docs/benchmarks.md (between the CLIENTS markers) unless --no-docs, and
docs/figures/clients_server_rss.svg and clients_server_cpu.svg. Usage:
  bench/clients_bench.py [--build build] [--shared ../shared] [--clients 1,2,4,8]
                         [--sensors mono,rgbd] [--passes 3] [--frames 1000]
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

from host_check import host_check, host_line
from docs_block import replace_block
from link_experiments import (PALETTE, Panel, free_port, legend, nice_ticks, fmt_tick,
                              stop_process, svg_document, wait_for_port, write)

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DOCS = os.path.join(ROOT, "docs", "benchmarks.md")
FIGURES = os.path.join(ROOT, "docs", "figures")
BEGIN, END = "<!-- CLIENTS:BEGIN -->", "<!-- CLIENTS:END -->"
LOCALIZE_BEGIN, LOCALIZE_END = "<!-- LOCALIZE-CLIENTS:BEGIN -->", "<!-- LOCALIZE-CLIENTS:END -->"
TICKS = os.sysconf("SC_CLK_TCK")


def proc_sample(pid):
    """(cpu seconds, rss MiB) of a live process, or None once it is gone."""
    try:
        with open(f"/proc/{pid}/stat") as f:
            fields = f.read().rsplit(")", 1)[1].split()
        cpu = (int(fields[11]) + int(fields[12])) / TICKS
        with open(f"/proc/{pid}/status") as f:
            rss_kb = next(int(line.split()[1]) for line in f if line.startswith("VmRSS:"))
        return cpu, rss_kb / 1024.0
    except (OSError, StopIteration, IndexError, ValueError):
        return None


def client_command(args, port, sensor, out_dir, name):
    command = [os.path.join(args.build, "edgeslam"), "client", "--server", f"127.0.0.1:{port}",
               "--dataset", args.dataset, "--sensor", sensor, "--realtime",
               "--max-frames", str(args.frames), "--out", out_dir] + args.client_args.split()
    if args.localize_only:
        # Every client localises in the one map stored before the runs (stored_map below).
        return command + ["--localize-only", "--map", stored_map_name(sensor),
                          "--frames", args.localize_frames]
    return command + ["--map", name]


def stored_map_name(sensor):
    return f"stored-{sensor}"


def store_map(args, sensor, work):
    """--localize-only: an edge run over the whole dataset maps it into the server's store."""
    out_dir = os.path.join(work, "mapping")
    with open(out_dir + ".log", "w") as log:
        code = subprocess.call(
            [os.path.join(args.build, "edgeslam"), "run", "--dataset", args.dataset, "--mode",
             "edge", "--sensor", sensor, "--maps", os.path.join(work, "maps"), "--map",
             stored_map_name(sensor), "--out", out_dir], stdout=log, stderr=subprocess.STDOUT)
    if code != 0:
        sys.exit(f"clients_bench: mapping the stored map failed (see {out_dir}.log)")


def run_config(args, sensor, clients, work):
    if args.localize_only:
        store_map(args, sensor, work)
    port = free_port()
    server_log = os.path.join(work, "server.log")
    with open(server_log, "w") as log:
        server = subprocess.Popen(
            [os.path.join(args.build, "edgeslam"), "server", "--listen", f"127.0.0.1:{port}",
             "--maps", os.path.join(work, "maps"), "--status-every", "0"],
            stdout=log, stderr=subprocess.STDOUT)
    try:
        wait_for_port(port, server)
        start = time.monotonic()
        samples = []  # (t, cpu %, rss MiB)
        last = proc_sample(server.pid)
        last_t = start
        slots = []  # per slot: (pass, process, out dir)
        runs = []   # finished client outputs: (slot, pass, out dir, exit code)

        def launch(slot, pass_index):
            out_dir = os.path.join(work, f"client{slot}-pass{pass_index}")
            log = open(out_dir + ".log", "w")
            name = f"bench-{sensor}-{clients}-{slot}-{pass_index}"
            proc = subprocess.Popen(client_command(args, port, sensor, out_dir, name),
                                    stdout=log, stderr=subprocess.STDOUT)
            return [pass_index, proc, out_dir, log]

        for slot in range(clients):
            slots.append(launch(slot, 0))
            time.sleep(0.25)  # staggered, as devices join
        while any(s is not None for s in slots):
            time.sleep(args.sample_s)
            now = time.monotonic()
            sample = proc_sample(server.pid)
            if sample and last:
                cpu = 100.0 * (sample[0] - last[0]) / max(now - last_t, 1e-3)
                samples.append((now - start, cpu, sample[1]))
            last, last_t = sample, now
            for slot, state in enumerate(slots):
                if state is None or state[1].poll() is None:
                    continue
                pass_index, proc, out_dir, log = state
                log.close()
                runs.append((slot, pass_index, out_dir, proc.returncode))
                slots[slot] = launch(slot, pass_index + 1) if pass_index + 1 < args.passes else None
        elapsed = time.monotonic() - start
    finally:
        stop_process(server)
    return summarize(sensor, clients, runs, samples, elapsed, server_log)


def summarize(sensor, clients, runs, samples, elapsed, server_log):
    metrics = []
    failures = []
    for slot, pass_index, out_dir, code in runs:
        path = os.path.join(out_dir, "metrics.json")
        if code != 0 or not os.path.exists(path):
            failures.append(f"client {slot} pass {pass_index} exited {code}")
            continue
        with open(path) as f:
            metrics.append(json.load(f))
    e2e_p95 = [m["e2e_ms"].get("p95", m["e2e_ms"]["p90"]) for m in metrics]
    e2e_p50 = [m["e2e_ms"]["median"] for m in metrics]
    frames = sum(m["frames"] for m in metrics)
    tracked = sum(m["tracked"] for m in metrics)
    skipped = sum(m.get("frames_skipped_late", m.get("frames_dropped_late", 0)) for m in metrics)
    processed = sum(m.get("frames_processed", m["frames"]) for m in metrics)
    lost = sum(m["lost"] for m in metrics)
    relocalizations = sum(m.get("relocalizations", 0) for m in metrics)
    uploads_lost = sum(m.get("uploads_dropped", 0) + m.get("uploads_overflowed", 0)
                       for m in metrics)
    ates = [m["ate"]["rmse_m"] for m in metrics if "ate" in m]
    client_p95 = [m["client_ms"]["p95"] for m in metrics]
    read_p95 = [m["load_ms"]["p95"] for m in metrics if "load_ms" in m]
    cpu = [c for _, c, _ in samples]
    rss = [r for _, _, r in samples]
    with open(server_log) as f:
        server_errors = sum(1 for line in f if "[error]" in line or "[critical]" in line)
    return {
        "sensor": sensor, "clients": clients, "sessions": len(runs), "failures": failures,
        "elapsed_s": elapsed, "frames": frames, "tracked": tracked, "skipped_late": skipped,
        "processed": processed, "lost": lost, "relocalizations": relocalizations,
        "uploads_lost": uploads_lost, "server_errors": server_errors,
        "e2e_p50_median": statistics.median(e2e_p50) if e2e_p50 else None,
        "e2e_p95_median": statistics.median(e2e_p95) if e2e_p95 else None,
        "e2e_p95_worst": max(e2e_p95) if e2e_p95 else None,
        "ate_cm_median": 100 * statistics.median(ates) if ates else None,
        "client_p95_median": statistics.median(client_p95) if client_p95 else None,
        "read_p95_median": statistics.median(read_p95) if read_p95 else None,
        "cpu_mean": statistics.mean(cpu) if cpu else None,
        "cpu_p95": sorted(cpu)[int(0.95 * (len(cpu) - 1))] if cpu else None,
        "rss_first": rss[0] if rss else None, "rss_max": max(rss) if rss else None,
        "rss_last": rss[-1] if rss else None, "samples": samples,
    }


def fmt(v, digits=1):
    return "n/a" if v is None else f"{v:.{digits}f}"


def table(results, args):
    what = (f"frames {args.localize_frames} of {os.path.basename(args.dataset)} per session, "
            "each client localising (`--localize-only`) in the map an edge run over the whole "
            "dataset stored first" if args.localize_only else
            f"{args.frames} frames of {os.path.basename(args.dataset)} per session")
    lines = [
        f"{what} at the camera's "
        f"rate, {args.passes} sessions in a row per client slot, edge mode, one server with a map "
        "store, all on this 2-core machine. e2e = frame arrival to pose (ms), the median over "
        "sessions of each session's p50 / p95, and the worst session's p95. Skipped late: frames "
        "the camera produced while the client was busy, never read (the client takes the newest "
        "due frame; `frames_skipped_late` in its metrics.json). Tracked and lost: of the frames "
        "processed. Relocs: relocalisations over all sessions. Client and read ms: the median over "
        "sessions of each session's p95 of tracking a frame and of reading (decoding) it.",
        "",
        "| sensor | clients | sessions | frames | skipped late | processed | tracked | lost | "
        "relocs | uploads lost | e2e p50 / p95 (worst p95) ms | client / read ms p95 | "
        "ATE cm (median) | "
        "server CPU % mean / p95 | server RSS MiB first / max / last | failures |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in results:
        share = lambda n, whole: f"{n} ({100 * n / max(whole, 1):.1f} %)"
        lines.append(
            f"| {r['sensor']} | {r['clients']} | {r['sessions']} | {r['frames']} | "
            f"{share(r['skipped_late'], r['frames'])} | {r['processed']} | "
            f"{share(r['tracked'], r['processed'])} | {r['lost']} | {r['relocalizations']} | "
            f"{r['uploads_lost']} | {fmt(r['e2e_p50_median'])} / {fmt(r['e2e_p95_median'])} "
            f"({fmt(r['e2e_p95_worst'])}) | {fmt(r['client_p95_median'])} / "
            f"{fmt(r['read_p95_median'])} | {fmt(r['ate_cm_median'], 2)} | "
            f"{fmt(r['cpu_mean'], 0)} / {fmt(r['cpu_p95'], 0)} | {fmt(r['rss_first'], 0)} / "
            f"{fmt(r['rss_max'], 0)} / {fmt(r['rss_last'], 0)} | "
            f"{len(r['failures']) + r['server_errors'] or 'none'} |")
    return "\n".join(lines)


def time_chart(path, title, results, column, y_label):
    """One line per configuration: a sample column over the run's time."""
    t_max = max((s[0] for r in results for s in r["samples"]), default=1.0)
    y_max = max((s[column] for r in results for s in r["samples"]), default=1.0)
    panel = Panel(80, 40, 620, 320, y_max, y_label, x_label="time since the first client (s)",
                  title=title)
    body = panel.axes()
    x_ticks = nice_ticks(t_max)
    sx = lambda t: panel.x0 + panel.w * t / x_ticks[-1]
    for t in x_ticks:
        body.append(f'<text x="{sx(t):.1f}" y="{panel.y0 + panel.h + 16}" '
                    f'text-anchor="middle">{fmt_tick(t)}</text>')
    names = []
    for i, r in enumerate(results):
        names.append(f"{r['sensor']} x{r['clients']}")
        d = " ".join(f"{sx(s[0]):.1f},{panel.y(s[column]):.1f}" for s in r["samples"])
        body.append(f'<polyline points="{d}" fill="none" stroke="{PALETTE[i % len(PALETTE)]}" '
                    f'stroke-width="1.5"/>')
    body += legend(panel.x0 + panel.w + 20, panel.y0, names, PALETTE)
    write(path, svg_document(panel.x0 + panel.w + 160, panel.y0 + panel.h + 60, body, title))


def update_docs(block, localize_only):
    begin, end = (LOCALIZE_BEGIN, LOCALIZE_END) if localize_only else (BEGIN, END)
    title = ("Localise-only clients on one server (`bench/clients_bench.py --localize-only`)"
             if localize_only else "Many clients on one server (`bench/clients_bench.py`)")
    replace_block(DOCS, begin, end, block, title)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--build", default="build")
    parser.add_argument("--shared", default=os.environ.get("EDGESLAM_SHARED",
                                                           os.path.join(ROOT, "..", "shared")))
    parser.add_argument("--dataset", help="default: the shared 7-Scenes redkitchen")
    parser.add_argument("--clients", default="1,2,4,8")
    parser.add_argument("--sensors", default="mono,rgbd")
    parser.add_argument("--passes", type=int, default=3)
    parser.add_argument("--frames", type=int, default=1000)
    parser.add_argument("--sample-s", type=float, default=1.0)
    parser.add_argument("--no-docs", action="store_true")
    parser.add_argument("--client-args", default="",
                        help="more arguments for every client (e.g. '--compute-adapt off')")
    parser.add_argument("--localize-only", action="store_true",
                        help="clients localise (--localize-only) in a map stored first by an "
                             "edge run over the whole dataset, instead of mapping")
    parser.add_argument("--localize-frames", default="500-999",
                        help="with --localize-only: the frames each client plays")
    args = parser.parse_args()
    args.dataset = args.dataset or os.path.join(args.shared, "datasets/7scenes-redkitchen-1000")
    if not os.path.isdir(args.dataset):
        sys.exit(f"clients_bench: no dataset at {args.dataset} (set --shared or --dataset)")
    if not os.access(os.path.join(args.build, "edgeslam"), os.X_OK):
        sys.exit(f"clients_bench: no {args.build}/edgeslam (run `make build`)")
    counts = [int(c) for c in args.clients.split(",")]
    results = []
    before = host_check(args.build, None)
    for sensor in args.sensors.split(","):
        for clients in counts:
            with tempfile.TemporaryDirectory(prefix="edgeslam_clients_") as work:
                print(f"{sensor} x{clients}: {args.passes} pass(es) of {args.frames} frames ...",
                      flush=True)
                r = run_config(args, sensor, clients, work)
            print(f"  {r['sessions']} sessions in {r['elapsed_s']:.0f} s, e2e p95 "
                  f"{fmt(r['e2e_p95_median'])} ms, server CPU {fmt(r['cpu_mean'], 0)} %, "
                  f"RSS max {fmt(r['rss_max'], 0)} MiB, failures {r['failures'] or 'none'}",
                  flush=True)
            results.append(r)
    block = table(results, args)
    host = host_line(before, host_check(args.build, None))
    print(block + "\n\n" + host)
    if not args.no_docs:
        update_docs(block + "\n\n" + host, args.localize_only)
    if not args.no_docs and not args.localize_only:
        time_chart(os.path.join(FIGURES, "clients_server_rss.svg"), "Edge server RSS",
                   results, 2, "RSS (MiB)")
        time_chart(os.path.join(FIGURES, "clients_server_cpu.svg"), "Edge server CPU",
                   results, 1, "CPU (% of one core)")
    failed = any(r["failures"] for r in results)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
