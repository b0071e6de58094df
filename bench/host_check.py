"""How much of the client's core the host takes away, as bench/host_jitter sees it: the SLAM and
link benches run it before and after their runs and print the line under their tables."""
import json
import os
import subprocess


def host_check(build_dir, cpu, seconds=10):
    """host_jitter's JSON for `seconds` pinned to `cpu` (None: unpinned); None if it is absent."""
    exe = os.path.join(build_dir, "bench", "host_jitter")
    if not os.path.exists(exe):
        return None
    cmd = [exe, str(seconds)]
    if cpu is not None:
        cmd = ["taskset", "-c", str(cpu)] + cmd
    out = subprocess.run(cmd, capture_output=True, text=True)
    return json.loads(out.stdout) if out.returncode == 0 else None


def host_line(before, after):
    """One markdown sentence from the checks before and after the runs ('' when neither ran)."""
    parts = [f"{label} the runs: {h['gaps']} gaps over {h['threshold_ms']:.0f} ms in "
             f"{h['seconds']:.0f} s ({h['gaps_over_20ms']} over 20 ms), {h['lost_ms']:.0f} ms lost, "
             f"worst {h['worst_ms']:.0f} ms" for label, h in (("before", before), ("after", after))
             if h]
    if not parts:
        return ""
    return ("Host preemption of the client core (`bench/host_jitter`, a busy loop pinned there, "
            "nothing else running): " + "; ".join(parts) + ".")
