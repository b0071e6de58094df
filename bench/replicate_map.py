#!/usr/bin/env python3
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
INVALID = 0xFFFFFFFFFFFFFFFF


def signed(value):
    return value - (1 << 64) if value >= (1 << 63) else value


def unsigned(value):
    return value + (1 << 64) if value < 0 else value


def shifted(sql_value, copy):
    value = unsigned(sql_value)
    return signed(value if value == INVALID else value + copy * SHIFT)


def shift_observations(blob, copy):
    out = bytearray()
    for offset in range(0, len(blob), 12):
        keyframe, index = struct.unpack_from("<QI", blob, offset)
        out += struct.pack("<QI", keyframe + copy * SHIFT, index)
    return bytes(out)


def insert(db, table, row):
    db.execute(f"INSERT INTO {table} VALUES({', '.join('?' * len(row))})", row)


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
    (map_id,) = db.execute("SELECT id FROM maps WHERE name = ?", (args.target,)).fetchone()
    columns = [r[1] for r in db.execute("PRAGMA table_info(sessions)")
               if r[1] not in ("id", "map_id")]
    db.execute(f"INSERT INTO sessions(map_id, {', '.join(columns)}) SELECT ?, "
               f"{', '.join(columns)} FROM sessions WHERE id = ?", (map_id, source))
    (session,) = db.execute("SELECT max(id) FROM sessions").fetchone()
    rows = {table: db.execute(f"SELECT * FROM {table} WHERE session_id = ?", (source,)).fetchall()
            for table in ("keyframes", "points", "keyframe_places", "masks")}
    for copy in range(args.copies):
        for k in rows["keyframes"]:  # session_id, id, frame_index, timestamp, pose, parent, ...
            row = list(k)
            row[0], row[1], row[5] = session, shifted(k[1], copy), shifted(k[5], copy)
            insert(db, "keyframes", row)
        for p in rows["points"]:  # session_id, id, x..nz, descriptor, min, max, reference, obs
            row = list(p)
            row[0], row[1], row[11] = session, shifted(p[1], copy), shifted(p[11], copy)
            row[12] = shift_observations(p[12], copy)
            insert(db, "points", row)
        for table in ("keyframe_places", "masks"):  # session_id, keyframe, ...
            for r in rows[table]:
                row = list(r)
                row[0], row[1] = session, shifted(r[1], copy)
                insert(db, table, row)
    db.commit()
    print(f"map '{args.target}': {len(rows['keyframes']) * args.copies} keyframes, "
          f"{len(rows['points']) * args.copies} points, "
          f"{len(rows['keyframe_places']) * args.copies} places "
          f"({args.copies} copies of '{args.source}' session {source})")


if __name__ == "__main__":
    main()
