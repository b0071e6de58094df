#!/usr/bin/env python3
"""The map_resync_test scenario by hand, keeping every output: undisturbed and killed runs.

usage: measure.py BINARY OUTROOT TAG N ["CLIENT ARGS"]  (CLIENT_GLOBAL="--log-level debug" for debug logs)
Each pair: one undisturbed (calm) run and one killed run, alternating. RESYNC_VOCAB: the
vocabulary both processes use (the test's: `edgeslam vocab train --k 10 --levels 4` on TUM fr2desk
and every 8th frame of KITTI 07). docs/map_store.md, "Keyframes after a restart".
"""
import json, os, signal, subprocess, sys, time, shutil

SHARED = os.environ.get("EDGESLAM_SHARED", "../shared")
VOCAB = os.environ.get("RESYNC_VOCAB", "small.vocab")
DATASET = SHARED + "/datasets/7scenes-redkitchen-1000"


def wait_log(path, text, timeout):
    end = time.time() + timeout
    while time.time() < end:
        try:
            with open(path, errors="replace") as f:
                if text in f.read():
                    return True
        except FileNotFoundError:
            pass
        time.sleep(0.05)
    return False


def run(binary, root, name, kill_after, port, extra_client):
    d = os.path.join(root, name)
    shutil.rmtree(d, ignore_errors=True)
    store, out = d + "/store", d + "/out"
    os.makedirs(out)
    serve = [binary, "server", "--listen", f"127.0.0.1:{port}", "--status-every", "0", "--vocab",
             VOCAB, "--semantic", "off", "--maps", store]
    log1 = open(d + "/server1.log", "w")
    server = subprocess.Popen(serve, stdout=log1, stderr=subprocess.STDOUT)
    assert wait_log(d + "/server1.log", "listening", 60)
    clog = open(d + "/client.log", "w")
    t_client = time.time()
    client = subprocess.Popen([binary] + os.environ.get("CLIENT_GLOBAL", "").split() + ["client", "--server", f"127.0.0.1:{port}", "--dataset", DATASET,
                               "--sensor", "rgbd", "--realtime", "--vocab", VOCAB, "--map", "kitchen",
                               "--out", out] + extra_client, stdout=clog, stderr=subprocess.STDOUT)
    events = {"client_start": t_client}
    if kill_after is not None:
        assert wait_log(d + "/server1.log", "opened for", 60)
        events["opened"] = time.time()
        time.sleep(kill_after)
        server.send_signal(signal.SIGKILL)
        events["killed"] = time.time()
        server.wait(60)
        time.sleep(2)
        log2 = open(d + "/server2.log", "w")
        server = subprocess.Popen(serve, stdout=log2, stderr=subprocess.STDOUT)
        events["restarted"] = time.time()
        wait_log(d + "/server2.log", "listening", 60)
        events["listening2"] = time.time()
    else:
        wait_log(d + "/server1.log", "opened for", 60)
        events["opened"] = time.time()
    rc = client.wait(600)
    server.send_signal(signal.SIGTERM)
    src = server.wait(60)
    info = subprocess.run([binary, "map", "info", "kitchen", "--json", "--maps", store],
                          capture_output=True, text=True)
    subprocess.run([binary, "map", "export", "kitchen", "--format", "tum", "--out",
                    out + "/edge_keyframes.tum", "--maps", store], capture_output=True, text=True)
    ate = subprocess.run([binary, "eval", "ate", "--gt", out + "/groundtruth.tum", "--est",
                          out + "/edge_keyframes.tum", "--align", "se3", "--json"],
                         capture_output=True, text=True)
    res = {"name": name, "killed": kill_after is not None, "client_rc": rc, "server_rc": src,
           "events": events, "load": os.getloadavg()}
    try:
        res["map_info"] = json.loads(info.stdout)
    except Exception:
        res["map_info"] = None
    try:
        res["ate"] = json.loads(ate.stdout)["rmse_m"]
    except Exception:
        res["ate"] = None
    with open(out + "/metrics.json") as f:
        res["metrics"] = json.load(f)
    shutil.rmtree(store, ignore_errors=True)
    with open(d + "/result.json", "w") as f:
        json.dump(res, f, indent=1)
    m = res["metrics"]
    print(f"{name}: store kf {res['map_info']['keyframes'] if res['map_info'] else None} "
          f"ate {res['ate']} frames {m['frames']} processed {m.get('frames_processed')} tracked {m['tracked']} "
          f"resync {json.dumps(m.get('resync'))} load {res['load'][0]:.2f}", flush=True)
    return res


def main():
    binary, root, tag, n = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4])
    extra = sys.argv[5].split() if len(sys.argv) > 5 else []
    os.makedirs(root, exist_ok=True)
    port = 47000 + os.getpid() % 500 * 2
    for i in range(n):
        run(binary, root, f"{tag}_calm{i}", None, port, extra)
        run(binary, root, f"{tag}_killed{i}", 13.3, port + 1, extra)


if __name__ == "__main__":
    main()
