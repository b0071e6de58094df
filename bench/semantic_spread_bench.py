#!/usr/bin/env python3
"""Semantic culling over a spread of generated dynamic sequences (issue 21): N sequences made by
`edgeslam synth-dynamic` from 7-Scenes redkitchen, each with its own seed, frame range, number of
people (1-3) and their size (target coverage 10-38 %; the walks' speeds come from the seed),
alternately RGB-D and monocular. Each is run three times, in local mode or (`--mode edge`) as a
server and a client on a core each, behind an emulated link (`--link`) with or without the
client's adaptation: on the source frames (static), with semantic culling off, and on. Reported per sequence and as a distribution (median,
worst): transferred-mask IoU on non-keyframes and on keyframes, culled-feature precision and
recall, ATE of the run against the static run (semantic on and off), mask age.

Two sets with disjoint seeds: `tuning` (seeds 1000+i: for trying changes) and `report` (seeds
2000+i: for the figures in docs; not to tune on). The tables go into docs/dynamic_benchmark.md
between <!-- semantic-spread-SET-PACING[-edge-LINK] --> markers.

  bench/semantic_spread_bench.py [--set report] [--count 20] [--length 240]
                                 [--pacing realtime|fast] [--mode local|edge] [--link NAME]
                                 [--adapt on|off] [--build-dir build] [--no-docs]
"""
import argparse
import json
import os
import random
import re
import statistics
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from semantic_bench import ROOT, ate_cm, ensure_sequence, run_once  # noqa: E402

SET_SEEDS = {"tuning": 1000, "report": 2000}
SOURCE = "datasets/7scenes-redkitchen-1000"
SOURCE_FRAMES = 1000


def plan(set_name, count, length):
    """The set's sequences: the same every time (drawn from the set's seeds)."""
    sequences = []
    for i in range(count):
        seed = SET_SEEDS[set_name] + i
        rng = random.Random(seed)
        start = rng.randrange(0, SOURCE_FRAMES - length + 1)
        sequences.append({
            "name": f"{set_name}-{i:02d}", "seed": seed,
            "frames": f"{start}-{start + length - 1}",
            "people": rng.choice([1, 2, 3]),
            "coverage": rng.choice([10, 16, 22, 30, 38]),
            "sensor": "rgbd" if i % 2 == 0 else "mono",
        })
    return sequences


def generate(binary, shared, work, seq):
    out = ensure_sequence(binary, shared, work, seq["frames"], seq["seed"],
                          name=f"{seq['name']}-seed{seq['seed']}",
                          extra=["--num-people", str(seq["people"]),
                                 "--coverage", str(seq["coverage"])])
    with open(os.path.join(out, "synth.json")) as f:
        synth = json.load(f)
    speeds = [
        ((w["to_m"][0] - w["from_m"][0]) ** 2 + (w["to_m"][1] - w["from_m"][1]) ** 2) ** 0.5
        / w["duration_s"]
        for person in synth["people"] for w in person["walks"] if w["duration_s"] > 0]
    seq["walk_speed"] = statistics.median(speeds) if speeds else None
    seq["coverage_median"] = synth["coverage"]["median"]
    seq["frames_with_people"] = synth["coverage"]["frames_with_people"]
    return out


def semantic(m, key):
    value = m.get("semantic", {}).get(key)
    return value


def distribution(values, worst):
    values = [v for v in values if v is not None]
    if not values:
        return None, None
    return statistics.median(values), worst(values)


def fmt(value, spec):
    return "-" if value is None else format(value, spec)


def runs_cm(values):
    return " / ".join(f"{v:.2f}" for v in values)


def median_run(runs, run):
    """The run of median ATE among `runs` runs of one cell (a monocular map's start alone moves
    one run's ATE by 2-6x); its other figures come with it. The cell's ATE spread is kept."""
    done = sorted((run() for _ in range(runs)), key=ate_cm)
    chosen = dict(done[len(done) // 2])
    chosen["ate_runs_cm"] = [ate_cm(m) for m in done]
    return chosen


def main():
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--build-dir", default=os.path.join(ROOT, "build"))
    parser.add_argument("--shared", default=os.environ.get("EDGESLAM_SHARED",
                                                           os.path.join(ROOT, "..", "shared")))
    parser.add_argument("--work", default="/tmp/edgeslam-semantic-spread",
                        help="where the generated sequences are kept (reused when present)")
    parser.add_argument("--set", choices=sorted(SET_SEEDS), default="report")
    parser.add_argument("--count", type=int, default=20)
    parser.add_argument("--length", type=int, default=240, help="frames per sequence")
    parser.add_argument("--pacing", choices=["realtime", "fast"], default="realtime")
    parser.add_argument("--mode", choices=["local", "edge"], default="local",
                        help="edge: `edgeslam server` on core 1, `edgeslam client` on core 0")
    parser.add_argument("--link", default="none",
                        help="edge mode: emulated link of the client (none, wifi5, wifi24, lte, "
                             "lte-congested)")
    parser.add_argument("--adapt", choices=["on", "off"], default="on",
                        help="edge mode: the client's adaptation to the link (paper Table I)")
    parser.add_argument("--runs", type=int, default=1,
                        help="runs per cell; the cell is its median-ATE run")
    parser.add_argument("--only", help="comma-separated sequence numbers to run (for trying)")
    parser.add_argument("--no-docs", action="store_true")
    args = parser.parse_args()

    binary = os.path.join(args.build_dir, "edgeslam")
    os.makedirs(args.work, exist_ok=True)
    source = os.path.join(args.shared, SOURCE)
    pacing = "--" + args.pacing
    if args.mode == "local" and args.link != "none":
        parser.error("--link needs --mode edge")
    mode_args = [] if args.mode == "local" else ["--link", args.link, "--adapt", args.adapt]
    setting = "local mode" if args.mode == "local" else (
        f"edge mode (server and client on a core each), link `{args.link}`, adaptation "
        f"{args.adapt}")
    suffix = "" if args.mode == "local" else f"-edge-{args.link}"
    sequences = plan(args.set, args.count, args.length)
    if args.only:
        wanted = {int(v) for v in args.only.split(",")}
        sequences = [s for i, s in enumerate(sequences) if i in wanted]
    started = time.monotonic()
    rows = []
    for seq in sequences:
        dataset = generate(binary, args.shared, args.work, seq)
        sensor = seq["sensor"]
        static = median_run(args.runs, lambda: run_once(
            binary, source, sensor, args.mode, "off", 0, ["--frames", seq["frames"]] + mode_args,
            pacing))
        off = median_run(args.runs, lambda: run_once(binary, dataset, sensor, args.mode, "off", 0,
                                                     mode_args, pacing))
        on = median_run(args.runs, lambda: run_once(binary, dataset, sensor, args.mode, "on", 0,
                                                    mode_args, pacing))
        age = semantic(on, "mask_age_frames") or {}
        row = dict(seq)
        row.update({
            "ate_static": ate_cm(static), "ate_off": ate_cm(off), "ate_on": ate_cm(on),
            "ate_runs_static": static["ate_runs_cm"], "ate_runs_on": on["ate_runs_cm"],
            "tracked_static": static["tracked"], "tracked_off": off["tracked"],
            "tracked_on": on["tracked"], "frames_run": on["frames"],
            "iou": semantic(on, "mask_iou_median"),
            "iou_keyframes": semantic(on, "mask_iou_keyframes_median"),
            "precision": semantic(on, "culled_precision"),
            "recall": semantic(on, "culled_recall"),
            "mask_age_median": age.get("median"),
            "seg_ms": (on.get("segmentation_ms") or {}).get("median"),
            "extra_ms": (semantic(on, "client_ms") or {}).get("median"),
        })
        row["ratio_on"] = row["ate_on"] / row["ate_static"] if row["ate_static"] else None
        row["ratio_off"] = row["ate_off"] / row["ate_static"] if row["ate_static"] else None
        rows.append(row)
        print(f"{seq['name']} {sensor} frames {seq['frames']} people {seq['people']} "
              f"coverage {seq['coverage_median']:.2f}: IoU {fmt(row['iou'], '.2f')} "
              f"(keyframes {fmt(row['iou_keyframes'], '.2f')}), precision "
              f"{fmt(row['precision'], '.2f')} recall {fmt(row['recall'], '.2f')}, ATE static "
              f"{row['ate_static']:.2f} off {row['ate_off']:.2f} on {row['ate_on']:.2f} cm "
              f"(on/static {fmt(row['ratio_on'], '.2f')}, off/static {fmt(row['ratio_off'], '.2f')})",
              flush=True)
    elapsed = time.monotonic() - started

    lines = [
        f"Set `{args.set}` ({len(rows)} sequences of {args.length} frames, seeds "
        f"{SET_SEEDS[args.set]}+), `--{args.pacing}`, {setting}, "
        f"{'one run per cell' if args.runs == 1 else f'{args.runs} runs per cell (each cell its median-ATE run; the ATE of every run in the last columns)'}; "
        f"`bench/semantic_spread_bench.py --set {args.set} --pacing {args.pacing}"
        f"{'' if args.runs == 1 else f' --runs {args.runs}'}"
        f"{'' if args.mode == 'local' else f' --mode edge --link {args.link} --adapt {args.adapt}'}`, "
        f"{elapsed / 60:.0f} min, {time.strftime('%Y-%m-%d')}.",
        "",
        "| sequence | sensor | frames | people | coverage median | walk m/s | mask IoU (non-kf / kf) "
        "| culled precision / recall | ATE static / off / on cm | on / static | off / static "
        "| tracked static / off / on | mask age median | seg ms | client extra ms |"
        + (" ATE runs static | ATE runs on |" if args.runs > 1 else ""),
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
        + ("---|---|" if args.runs > 1 else ""),
    ]
    for r in rows:
        lines.append(
            f"| {r['name']} | {r['sensor']} | {r['frames']} | {r['people']} | "
            f"{100 * r['coverage_median']:.0f} % | {fmt(r['walk_speed'], '.1f')} | "
            f"{fmt(r['iou'], '.2f')} / {fmt(r['iou_keyframes'], '.2f')} | "
            f"{fmt(r['precision'], '.2f')} / {fmt(r['recall'], '.2f')} | "
            f"{r['ate_static']:.2f} / {r['ate_off']:.2f} / {r['ate_on']:.2f} | "
            f"{fmt(r['ratio_on'], '.2f')} | {fmt(r['ratio_off'], '.2f')} | "
            f"{r['tracked_static']} / {r['tracked_off']} / {r['tracked_on']} of {r['frames_run']} | "
            f"{fmt(r['mask_age_median'], '.0f')} | {fmt(r['seg_ms'], '.0f')} | "
            f"{fmt(r['extra_ms'], '.2f')} |" + (
                f" {runs_cm(r['ate_runs_static'])} | {runs_cm(r['ate_runs_on'])} |"
                if args.runs > 1 else ""))
    lines += ["", "| over | sequences | mask IoU non-kf median (worst) | kf median (worst) | "
              "precision median | recall median (worst) | on / static median (worst) | "
              "off / static median (worst) |", "|---|---|---|---|---|---|---|---|"]
    for label, subset in [("all", rows), ("RGB-D", [r for r in rows if r["sensor"] == "rgbd"]),
                          ("mono", [r for r in rows if r["sensor"] == "mono"])]:
        if not subset:
            continue
        iou = distribution([r["iou"] for r in subset], min)
        iou_kf = distribution([r["iou_keyframes"] for r in subset], min)
        precision = distribution([r["precision"] for r in subset], min)
        recall = distribution([r["recall"] for r in subset], min)
        on = distribution([r["ratio_on"] for r in subset], max)
        off = distribution([r["ratio_off"] for r in subset], max)
        lines.append(
            f"| {label} | {len(subset)} | {fmt(iou[0], '.2f')} ({fmt(iou[1], '.2f')}) | "
            f"{fmt(iou_kf[0], '.2f')} ({fmt(iou_kf[1], '.2f')}) | {fmt(precision[0], '.2f')} | "
            f"{fmt(recall[0], '.2f')} ({fmt(recall[1], '.2f')}) | {fmt(on[0], '.2f')} "
            f"({fmt(on[1], '.2f')}) | {fmt(off[0], '.2f')} ({fmt(off[1], '.2f')}) |")
    table = "\n".join(lines)
    print()
    print(table)
    with open(os.path.join(args.work, f"{args.set}-{args.pacing}{suffix}.json"), "w") as f:
        json.dump(rows, f, indent=1)
    if not args.no_docs and not args.only:
        path = os.path.join(ROOT, "docs", "dynamic_benchmark.md")
        with open(path) as f:
            text = f.read()
        marker = f"semantic-spread-{args.set}-{args.pacing}{suffix}"
        block = f"<!-- {marker} -->\n{table}\n<!-- /{marker} -->"
        if f"<!-- {marker} -->" in text:
            text = re.sub(rf"<!-- {marker} -->.*?<!-- /{marker} -->", lambda _: block, text,
                          flags=re.S)
        else:
            text += f"\n### {args.set} set, --{args.pacing}, {setting}\n\n{block}\n"
        with open(path, "w") as f:
            f.write(text)
        print(f"wrote {path} ({marker})")


if __name__ == "__main__":
    main()
