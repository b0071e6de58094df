#!/ usr / bin / env python3
"""Makes a large stored map out of a real one, to time loading (docs/map_store.md, Loading).

The latest session of map SOURCE in the store is copied N times into one new session of map
TARGET: keyframes (with their places), points and masks, ids shifted by copy << 44 (below the
creator byte), so that the copies are disjoint maps side by side in one session. Loading it costs
what loading as many real keyframes costs (records read, keyframes and points rebuilt,
covisibility, bags of words), though the copies share no points.

  bench/replicate_map.py --maps STORE --source NAME --target NAME --copies N
"""
import argparse
import sqlite3
import struct
import time

SHIFT = 1 << 44


def shifted(value, copy):
    if value < 0:  # ids are unsigned 64-bit stored bit for bit; none here reach the sign bit
        raise SystemExit("unexpected negative id")
    return value + copy * SHIFT if value != 0xFFFFFFFFFFFFFFFF else value


def signed(value):
    return value - (1 << 64) if value >= (1 << 63) else value


def unsigned(value):
    return value + (1 << 64) if value < 0 else value


def shift_observations(blob, copy):
    out = bytearray()
    for offset in range(0, len(blob), 12):
        keyframe, index = struct.unpack_from("<QI", blob, offset)
        out += struct.pack("<QI", keyframe + copy * SHIFT, index)
    return bytes(out)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--maps", required=True)
    parser.add_argument("--source", required=True)
    parser.add_argument("--target", required=True)
    parser.add_argument("--copies", type=int, required=True)
    args = parser.parse_args()
    db = sqlite3.connect(f"{args.maps}/maps.sqlite")
    db.execute("PRAGMA foreign_keys = ON")
    (source,) = db.execute(
        "SELECT s.id FROM sessions s JOIN maps m ON m.id = s.map_id WHERE m.name = ? AND "
        "EXISTS(SELECT 1 FROM keyframes k WHERE k.session_id = s.id) ORDER BY s.id DESC LIMIT 1",
        (args.source,)).fetchone()
    now = time.time()
    db.execute("INSERT INTO maps(name, created, updated) VALUES(?, ?, ?)", (args.target, now, now))
    map_id = db.execute("SELECT id FROM maps WHERE name = ?", (args.target,)).fetchone()[0]
    columns = [r[1] for r in db.execute("PRAGMA table_info(sessions)") if r[1] not in ("id", "map_id")]
    db.execute(f"INSERT INTO sessions(map_id, {', '.join(columns)}) SELECT ?, {', '.join(columns)} "
               "FROM sessions WHERE id = ?", (map_id, source))
    session = db.execute("SELECT max(id) FROM sessions").fetchone()[0]
    keyframes = db.execute("SELECT * FROM keyframes WHERE session_id = ?", (source,)).fetchall()
    points = db.execute("SELECT * FROM points WHERE session_id = ?", (source,)).fetchall()
    places = db.execute("SELECT * FROM keyframe_places WHERE session_id = ?", (source,)).fetchall()
    masks = db.execute("SELECT * FROM masks WHERE session_id = ?", (source,)).fetchall()
    for copy in range(args.copies):
        for k in keyframes:
            row = list(k)
            row[0] = session
            row[1] = signed(shifted(unsigned(k[1]), copy))
            row[5] = signed(shifted(unsigned(k[5]), copy))  # parent
            db.execute(f"INSERT INTO keyframes VALUES({', '.join('?' * len(row))})", row)
        for p in points:
            row = list(p)
            row[0] = session
            row[1] = signed(shifted(unsigned(p[1]), copy))
            row[11] = signed(shifted(unsigned(p[11]), copy))  # reference keyframe
            row[12] = shift_observations(p[12], copy)
            db.execute(f"INSERT INTO points VALUES({', '.join('?' * len(row))})", row)
        for p in places:
            row = list(p)
            row[0] = session
            row[1] = signed(shifted(unsigned(p[1]), copy))
            db.execute(f"INSERT INTO keyframe_places VALUES({', '.join('?' * len(row))})", row)
        for m in masks:
            row = list(m)
            row[0] = session
            row[1] = signed(shifted(unsigned(m[1]), copy))
            db.execute(f"INSERT INTO masks VALUES({', '.join('?' * len(row))})", row)
    db.commit()
    print(f"map '{args.target}': {len(keyframes) * args.copies} keyframes, "
          f"{len(points) * args.copies} points, {len(places) * args.copies} places "
          f"({args.copies} copies of '{args.source}' session {source})")


if __name__ == "__main__":
    main()
