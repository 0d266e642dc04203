#!/usr/bin/python3
"""Trigger-to-result latency of the firmware simulator with the commissioning page closed and open.

Starts `stereohash-fw-sim` (rendered world, the real recognition pipeline, the page on
127.0.0.1). A PLC on its socketcand bus (python-can, Debian's python3-can) sends a trigger every
--period-ms; the firmware's RESULT lines give each trigger's processing time, from the trigger's
arrival to its result set on the bus. The cases take turns in blocks of --block triggers until
each has had --triggers:
  closed   nobody looks at the page
  page     one browser's worth of polling, as firmware/web/assets/app.js does it: /api/status
           every 500 ms, and both live images whenever the result changed
  4 pages  four such viewers polling every 100 ms (a stress case, beyond what the page does)
Writes the median, p95 and p99 of each case and the p99 ratio of `page` to `closed` as JSON.

  bench_web_latency.py --firmware build/host-release/firmware/stereohash-fw-sim --out web.json
                       [--triggers 100] [--block 20] [--period-ms 250]
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import threading
import time
import urllib.error
import urllib.request

COMMAND_ID = 0x201  # RPDO1 of node 1: the command frame
CMD_TRIGGER = 1


def percentile(values, q):
    s = sorted(values)
    if not s:
        return None
    k = min(len(s) - 1, max(0, int(round(q / 100.0 * (len(s) - 1)))))
    return s[k]


class Sim:
    """stereohash-fw-sim with its socketcand and HTTP ports, and the RESULT lines it prints."""

    def __init__(self, binary, work, name):
        self.config = os.path.join(work, "web-latency-%s.conf" % name)
        with open(self.config, "w", encoding="utf-8") as f:
            f.write("node_id = 1\nheartbeat_ms = 100\nsim_port = 0\nsim_scenes = 4\n"
                    "sim_objects = 3\nbudget_ms = 2000\nrecognition = pipeline\n"
                    "http_bind = 127.0.0.1\nhttp_port = 0\n")
        self.proc = subprocess.Popen([binary, "--config", self.config], stdout=subprocess.PIPE,
                                     stderr=subprocess.DEVNULL, text=True, bufsize=1)
        self.results = {}
        self.can_port = self.http_port = None
        self.ready = threading.Event()
        threading.Thread(target=self.read, daemon=True).start()
        if not self.ready.wait(120) or self.can_port is None or self.http_port is None:
            self.stop()
            raise RuntimeError("%s printed no SOCKETCAND_PORT and HTTP_PORT" % binary)

    def read(self):
        for line in self.proc.stdout:
            line = line.strip()
            if line.startswith("SOCKETCAND_PORT="):
                self.can_port = int(line.split("=", 1)[1])
            elif line.startswith("HTTP_PORT="):
                self.http_port = int(line.split("=", 1)[1])
            elif line.startswith("RESULT "):
                r = json.loads(line.split(" ", 1)[1])
                self.results[r["request_id"]] = r["processing_time_us"]
            if self.can_port is not None and self.http_port is not None:
                self.ready.set()
        self.ready.set()

    def stop(self):
        self.proc.terminate()
        try:
            self.proc.wait(10)
        except subprocess.TimeoutExpired:
            self.proc.kill()


def viewer(port, period_s, stopping, counts):
    """The page's polling: status, and both images when the result changed."""
    last = None
    while not stopping.is_set():
        try:
            with urllib.request.urlopen("http://127.0.0.1:%d/api/status" % port, timeout=5) as r:
                status = json.loads(r.read())
            counts["status"] += 1
            seq = (status.get("result") or {}).get("sequence")
            if seq is not None and seq != last:
                last = seq
                for side in ("left", "right"):
                    with urllib.request.urlopen("http://127.0.0.1:%d/api/image?side=%s"
                                                % (port, side), timeout=5) as r:
                        counts["image_bytes"] += len(r.read())
                    counts["images"] += 1
        except urllib.error.HTTPError as e:
            counts["http_%d" % e.code] = counts.get("http_%d" % e.code, 0) + 1
        except OSError:
            counts["errors"] += 1
        stopping.wait(period_s)


CASES = (("closed", 0, 0.0), ("page", 1, 0.5), ("4 pages", 4, 0.1))


def run_cases(args):
    """One firmware run; the cases take turns in blocks of --block triggers, so that a drift of
    the machine's load falls on every case alike."""
    import can
    sim = Sim(args.firmware, args.work, "run")
    case_of = {}  # request id -> case index
    counts = [{"status": 0, "images": 0, "image_bytes": 0, "errors": 0} for _ in CASES]
    try:
        bus = can.Bus(interface="socketcand", host="127.0.0.1", port=sim.can_port,
                      channel="can0")
        try:
            time.sleep(1.0)  # the world rendered
            request_id = 0
            while request_id < args.triggers * len(CASES):
                for k, (_, viewers, period_s) in enumerate(CASES):
                    stopping = threading.Event()
                    threads = [threading.Thread(target=viewer, args=(sim.http_port, period_s,
                                                                     stopping, counts[k]),
                                                daemon=True) for _ in range(viewers)]
                    for t in threads:
                        t.start()
                    time.sleep(0.5)  # the viewers polling
                    for _ in range(args.block):
                        request_id += 1
                        case_of[request_id] = k
                        bus.send(can.Message(arbitration_id=COMMAND_ID, is_extended_id=False,
                                             data=[CMD_TRIGGER, request_id & 0xFF,
                                                   request_id >> 8]))
                        time.sleep(args.period_ms / 1000.0)
                    stopping.set()
                    for t in threads:
                        t.join(10)
            time.sleep(2.0)  # the last results
        finally:
            bus.shutdown()
    finally:
        sim.stop()
    cases = []
    for k, (name, viewers, period_s) in enumerate(CASES):
        ids = [i for i, c in case_of.items() if c == k]
        ms = [sim.results[i] / 1000.0 for i in ids if i in sim.results]
        cases.append({"case": name, "viewers": viewers,
                      "viewer_period_ms": round(period_s * 1000) if viewers else None,
                      "triggers": len(ids), "answered": len(ms),
                      "median_ms": percentile(ms, 50), "p95_ms": percentile(ms, 95),
                      "p99_ms": percentile(ms, 99), "max_ms": max(ms) if ms else None,
                      "page_requests": counts[k]})
    return cases


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--firmware", required=True)
    p.add_argument("--out", required=True)
    p.add_argument("--work", default=tempfile.gettempdir())
    p.add_argument("--triggers", type=int, default=100, help="per case")
    p.add_argument("--block", type=int, default=20, help="triggers of one case in a row")
    p.add_argument("--period-ms", type=int, default=250)
    args = p.parse_args()
    try:
        import can  # noqa: F401 (Debian's python3-can)
    except ImportError:
        print("bench_web_latency: needs python-can (Debian python3-can)", file=sys.stderr)
        return 1
    os.makedirs(args.work, exist_ok=True)
    cases = run_cases(args)
    closed, page = cases[0], cases[1]
    result = {
        "command": "tools/bench_web_latency.py --firmware %s --triggers %d --block %d "
                   "--period-ms %d" % (os.path.relpath(args.firmware), args.triggers, args.block,
                                       args.period_ms),
        "cases": cases,
        "page_p99_ratio": (page["p99_ms"] / closed["p99_ms"]
                           if page["p99_ms"] and closed["p99_ms"] else None),
    }
    with open(args.out, "w", encoding="utf-8") as f:
        json.dump(result, f)
    for c in cases:
        print("%-8s %3d/%d answered: median %.1f ms, p95 %.1f ms, p99 %.1f ms" % (
            c["case"], c["answered"], c["triggers"], c["median_ms"] or 0, c["p95_ms"] or 0,
            c["p99_ms"] or 0))
    missing = [c["case"] for c in cases if c["answered"] < c["triggers"]]
    if missing:
        print("bench_web_latency: triggers without results in %s" % ", ".join(missing),
              file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
