"""One `edgeslam` run for a bench: local mode (`run --mode local`), or edge or offload mode
(`client`) against an `edgeslam server` started for it on the server's core and stopped after; the
client's command goes through `wrap` (pinning, a CPU quota). Returns metrics.json with
`bench_wall_s` added, or None when the run failed (its log named on stderr)."""
import json
import os
import subprocess
import sys
import time

from link_experiments import free_port, stop_process, wait_for_port

CLIENT_CPU, SERVER_CPU = 0, 1


def pinned_to(cpu):
    return lambda cmd: ["taskset", "-c", str(cpu)] + cmd


def run_pinned(exe, mode, common, out_dir, wrap=pinned_to(CLIENT_CPU), server_args=(),
               log_name="run.log"):
    server = None
    log = open(os.path.join(out_dir, log_name), "w")
    try:
        if mode in ("edge", "offload"):
            port = free_port()
            server = subprocess.Popen(
                ["taskset", "-c", str(SERVER_CPU), exe, "server", "--listen", f"127.0.0.1:{port}",
                 "--maps", "none"] + list(server_args),
                stdout=open(os.path.join(out_dir, "server.log"), "w"), stderr=subprocess.STDOUT)
            wait_for_port(port, server)
            cmd = [exe, "client", "--server", f"127.0.0.1:{port}"] + common
            if mode == "offload":
                cmd += ["--mode", "offload"]
        else:
            cmd = [exe, "run", "--mode", "local", "--maps", "none"] + common
        start = time.monotonic()
        rc = subprocess.run(wrap(cmd), stdout=log, stderr=subprocess.STDOUT).returncode
        wall = time.monotonic() - start
    finally:
        if server:
            stop_process(server)
        log.close()
    if rc != 0:
        print(f"  run failed ({rc}); see {os.path.join(out_dir, log_name)}", file=sys.stderr)
        return None
    with open(os.path.join(out_dir, "metrics.json")) as f:
        metrics = json.load(f)
    metrics["bench_wall_s"] = wall
    return metrics
