#!/usr/bin/env python3
"""Per-run accounting of the resync runs made by measure.py.

usage: analyze.py RUNS_DIR TAG
For each run: store keyframes, made / culled / lost, keyframes made and stored per phase (before
the kill, the outage up to the session reopened, after), the adaptation rows, ATE, frames.
Phases of the undisturbed runs use the median kill/reopen frames of the killed runs.
"""
import csv, datetime, glob, json, os, re, statistics, sys


def log_time(line, day):
    m = re.match(r"\[(\d\d):(\d\d):(\d\d)\.(\d\d\d)\]", line)
    if not m:
        return None
    h, mi, s, ms = map(int, m.groups())
    return day + h * 3600 + mi * 60 + s + ms / 1000.0


def load(run_dir):
    res = json.load(open(run_dir + "/result.json"))
    frames = list(csv.DictReader(open(run_dir + "/out/frames.csv")))
    stored_ts = []
    if os.path.exists(run_dir + "/out/edge_keyframes.tum"):
        for line in open(run_dir + "/out/edge_keyframes.tum"):
            if line.strip():
                stored_ts.append(float(line.split()[0]))
    ts_to_frame = {round(float(f["timestamp"]), 4): int(f["frame"]) for f in frames}
    stored = sorted(ts_to_frame.get(round(t, 4), -1) for t in stored_ts)
    # times
    opened = res["events"]["opened"]
    day = opened - (opened % 86400)
    t0 = reopened = None
    for line in open(run_dir + "/client.log", errors="replace"):
        if t0 is None and "initialised at frame 0" in line:
            t0 = log_time(line, day)
        if reopened is None and "session reopened" in line:
            reopened = log_time(line, day)
    res["frames"] = frames
    res["stored_frames"] = stored
    res["t0"] = t0
    if res["killed"]:
        res["kill_frame"] = int(round((res["events"]["killed"] - t0) * 30))
        res["reopen_frame"] = int(round((reopened - t0) * 30)) if reopened else None
    return res


def phase_counts(frame_list, a, b):
    return (sum(1 for f in frame_list if f < a), sum(1 for f in frame_list if a <= f < b),
            sum(1 for f in frame_list if f >= b))


def main():
    root, tag = sys.argv[1], sys.argv[2]
    dirs = [d for t in tag.split(",") for d in sorted(glob.glob(f"{root}/{t}_*"))]
    runs = [load(d) for d in dirs if os.path.exists(d + "/result.json")]
    killed = [r for r in runs if r["killed"]]
    K = int(statistics.median([r["kill_frame"] for r in killed])) if killed else 400
    R = int(statistics.median([r["reopen_frame"] for r in killed if r["reopen_frame"]])) if killed else 530
    calm = [r for r in runs if not r["killed"]]
    calm_kf = [r["map_info"]["keyframes"] for r in calm]
    calm_ate = [r["ate"] for r in calm]
    med_kf = statistics.median(calm_kf) if calm_kf else None
    med_ate = statistics.median(calm_ate) if calm_ate else None
    print(f"undisturbed median: {med_kf} keyframes, ATE {med_ate*100:.2f} cm; phases: kill frame {K}, reopened {R} (medians)")
    hdr = ("run", "load", "store kf", "% of median", "made", "culled", "lost", "resent",
           "made before/outage/after", "stored b/o/a", "rows after (frames)", "ATE cm", "ATE ratio",
           "frames/processed/tracked", "decisions r/f/s")
    print(" | ".join(hdr))
    for r in runs:
        m = r["metrics"]
        rs = m["resync"]
        lost = sum(rs["keyframes_lost"].values())
        k = r.get("kill_frame", K)
        rr = r.get("reopen_frame") or R
        made_frames = [int(f["frame"]) for f in r["frames"] if f["keyframe"] == "1"]
        rows_after = {}
        for f in r["frames"]:
            if int(f["frame"]) >= k:
                rows_after[f["adaptation_row"]] = rows_after.get(f["adaptation_row"], 0) + 1
        d = m.get("keyframe_decisions", {})
        kf = r["map_info"]["keyframes"]
        print(" | ".join(str(x) for x in (
            r["name"] + (f" (k{k} r{rr})" if r["killed"] else ""), f"{r['load'][0]:.1f}", kf,
            f"{100.0*kf/med_kf:.0f}", rs["keyframes_made"], rs["keyframes_culled_by_edge"], lost,
            rs["keyframes_resent"], "/".join(map(str, phase_counts(made_frames, k, rr))),
            "/".join(map(str, phase_counts(r["stored_frames"], k, rr))),
            " ".join(f"{int(a)+1}:{b}" for a, b in sorted(rows_after.items())),
            f"{r['ate']*100:.2f}", f"{r['ate']/med_ate:.2f}",
            f"{m['frames']}/{m['frames_processed']}/{m['tracked']}",
            f"{d.get('rules')}/{d.get('forced')}/{d.get('starving')}")))


if __name__ == "__main__":
    main()
