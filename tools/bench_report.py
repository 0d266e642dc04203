#!/usr/bin/env python3
"""The benchmark log: one JSON-lines record per run of tools/bench-report.sh, and docs/benchmarks.md
rendered from it. Standard library only; the plots are SVG files written here.

  bench_report.py note --work DIR --name NAME --kind KIND --command CMD --json FILE --exit RC
                       --wall S [--instructions N --tool perf|callgrind] [--noise SIGMA]
                       [--truth DIR] [--threads N]
      One part of a run (a recorded set, the rendered bench, the texture bench, a micro-benchmark
      program) into DIR/manifest.jsonl.
  bench_report.py append --work DIR --log LOG --mode MODE [--load-start "a b c"]
      Builds one record from DIR/manifest.jsonl and the JSON each part wrote, appends it to LOG.
  bench_report.py render --log LOG --md FILE --plots DIR
      Writes FILE (the latest figures of every set, with their commands, and the history) and
      the SVG plots it shows into DIR.
"""
import argparse
import datetime
import html
import json
import os
import statistics
import subprocess
import sys

SCHEMA = 1
VIS_BINS = ("under 40 %", "40-70 %", "70 % and more")
NOISE_BINS = ((0.0, 2.5, "under 2.5"), (2.5, 3.5, "2.5-3.5"), (3.5, 99.0, "3.5 and more"))
REPO = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))


# ---------------------------------------------------------------------------------------------
# Collecting


def note(args):
    os.makedirs(args.work, exist_ok=True)
    entry = {"name": args.name, "kind": args.kind, "command": args.command, "json": args.json,
             "exit": args.exit, "wall_s": args.wall, "threads": args.threads}
    if args.instructions:
        entry["instructions"] = int(args.instructions)
        entry["instructions_tool"] = args.tool
    if args.noise is not None:
        entry["noise_sigma"] = args.noise
    if args.truth:
        entry["truth"] = args.truth
    if args.prepare:
        entry["prepare"] = args.prepare
    with open(os.path.join(args.work, "manifest.jsonl"), "a", encoding="utf-8") as f:
        f.write(json.dumps(entry) + "\n")
    return 0


def status_kib(pid):
    """VmRSS, VmHWM and VmLck of a running process, KiB."""
    out = {}
    try:
        with open(f"/proc/{pid}/status", encoding="utf-8") as f:
            for line in f:
                key = line.split(":", 1)[0]
                if key in ("VmRSS", "VmHWM", "VmLck"):
                    out[key] = int(line.split()[1])
    except OSError:
        pass
    return out


def memory(args):
    """Resident memory of `recognize` on one recorded pair and of the firmware simulator's demo
    (rendered world) unlocked and with mlock, sampled from /proc while it runs."""
    import resource
    import time
    result = {"commands": []}
    scene = os.path.join(args.scene_set, "scene00")
    cmd = [args.stereohash, "recognize", "--calib", os.path.join(args.scene_set, "calib.yaml"),
           "--left", os.path.join(scene, "left.png"), "--right", os.path.join(scene, "right.png")]
    before = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    rc = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL).returncode
    after = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    result["recognize"] = {"exit": rc, "max_rss_kib": after if after > before else None,
                           "pair": os.path.relpath(scene, REPO)}
    result["commands"].append(" ".join(cmd))
    if args.firmware and os.access(args.firmware, os.X_OK):
        for lock in ("false", "true"):
            conf = os.path.join(args.work, f"memory-mlock-{lock}.conf")
            with open(conf, "w", encoding="utf-8") as f:
                f.write(f"mlock = {lock}\n")
            fw = [args.firmware, "--config", conf, "--demo", "--run-seconds", "8"]
            proc = subprocess.Popen(fw, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            time.sleep(6)
            sample = status_kib(proc.pid)
            rc = proc.wait()
            result[f"firmware_sim_mlock_{lock}"] = {
                "exit": rc, "rss_kib_at_6s": sample.get("VmRSS"), "hwm_kib_at_6s": sample.get("VmHWM"),
                "locked_kib_at_6s": sample.get("VmLck")}
            result["commands"].append(f"printf 'mlock = {lock}\\n' > memory.conf; "
                                      f"{' '.join(fw[:2])} memory.conf --demo --run-seconds 8")
    with open(args.out, "w", encoding="utf-8") as f:
        json.dump(result, f)
    return 0


def read_json(path):
    try:
        with open(path, encoding="utf-8") as f:
            return json.load(f)
    except (OSError, ValueError):
        return None


def git(*args):
    try:
        return subprocess.run(["git", "-C", REPO, *args], check=True, capture_output=True,
                              text=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return ""


def machine(load_start):
    cpu = ""
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as f:
            for line in f:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    try:
        load_end = [round(x, 2) for x in os.getloadavg()]
    except OSError:
        load_end = None
    return {"cpu": cpu, "cores": os.cpu_count(), "loadavg_start": load_start,
            "loadavg_end": load_end}


def percentile(values, q):
    """The q-quantile (0..1) by linear interpolation between the sorted values."""
    if not values:
        return None
    v = sorted(values)
    pos = q * (len(v) - 1)
    lo = int(pos)
    hi = min(lo + 1, len(v) - 1)
    return round(v[lo] + (v[hi] - v[lo]) * (pos - lo), 2)


def pct(num, den):
    return round(100.0 * num / den, 1) if den else None


def recall_by_noise(scenes, truth_dir):
    """Recall of the scenes grouped by their camera's read noise (truth.json "look", the
    factory-floor sets); None when the set's truth carries no noise."""
    bins = {label: [0, 0] for _, _, label in NOISE_BINS}
    seen = False
    for s in scenes:
        truth = read_json(os.path.join(truth_dir, s.get("scene", ""), "truth.json"))
        read = (truth or {}).get("look", {}).get("read")
        if read is None:
            continue
        seen = True
        for lo, hi, label in NOISE_BINS:
            if lo <= read < hi:
                bins[label][0] += s.get("correct", 0)
                bins[label][1] += s.get("objects", 0)
    return bins if seen else None


def recorded_set(entry, data):
    summary = data.get("summary", {})
    scenes = data.get("scenes", [])
    times = [s["total_ms"] for s in scenes if "total_ms" in s]
    vis = {}
    for b in data.get("visibility", []):
        vis[b.get("visible")] = [b.get("correct", 0), b.get("objects", 0)]
    out = {
        "scenes": summary.get("scenes"),
        "objects": summary.get("objects"),
        "correct": summary.get("correct"),
        "false_alarms": summary.get("false_alarms"),
        "correct_pct": summary.get("correct_pct"),
        "false_alarm_pct": summary.get("false_alarm_pct"),
        "recall_by_visibility": vis,
        "median_t_err_mm": summary.get("median_t_err_mm"),
        "median_r_err_deg": summary.get("median_r_err_deg"),
        "frame_ms": {"median": percentile(times, 0.5) if times else summary.get("median_ms"),
                     "p95": percentile(times, 0.95),
                     "worst": round(max(times), 2) if times else summary.get("worst_ms")},
        "miss_causes": summary.get("miss_causes"),
        "table": data.get("table"),
    }
    if entry.get("truth"):
        noise = recall_by_noise(scenes, entry["truth"])
        if noise:
            out["recall_by_noise"] = noise
    return out


def rendered_bench(data):
    rows = data.get("rows", [])
    total = next((r for r in rows if r.get("background") == "all"), None) or {}
    reported = (total.get("correct") or 0) + (total.get("false_alarms") or 0)
    return {
        "scenes": total.get("scenes"),
        "objects": total.get("objects"),
        "correct": total.get("correct"),
        "false_alarms": total.get("false_alarms"),
        "correct_pct": pct(total.get("correct") or 0, total.get("objects") or 0),
        "false_alarm_pct": pct(total.get("false_alarms") or 0, reported),
        "recall_by_visibility": None,
        "median_t_err_mm": total.get("median_t_err_mm"),
        "median_r_err_deg": total.get("median_r_err_deg"),
        "frame_ms": {"median": total.get("median_ms"), "p95": None,
                     "worst": total.get("worst_ms")},
        "rows": [{k: r.get(k) for k in ("background", "occlusion", "objects", "correct",
                                         "false_alarms", "median_ms", "worst_ms")}
                 for r in rows if r.get("background") != "all"],
    }


def texture_score(score, scenes):
    if not score:
        return None
    vis = {}
    for label, pair in zip(VIS_BINS, score.get("recall_by_visibility", [])):
        vis[label] = [pair[0], pair[1]]
    return {
        "scenes": scenes,
        "objects": score.get("objects"),
        "correct": score.get("correct"),
        "false_alarms": score.get("false_alarms"),
        "correct_pct": pct(score.get("correct") or 0, score.get("objects") or 0),
        "false_alarm_pct": pct(score.get("false_alarms") or 0, score.get("reported") or 0),
        "recall_by_visibility": vis,
        "median_t_err_mm": score.get("median_t_err_mm"),
        "median_r_err_deg": score.get("median_r_err_deg"),
        "frame_ms": {"median": score.get("median_ms"), "p95": None,
                     "worst": score.get("worst_ms")},
    }


def micro_bench(data):
    out = []
    for b in data.get("benchmarks", []):
        if b.get("run_type") == "aggregate" and b.get("aggregate_name") != "median":
            continue
        out.append({"name": b.get("name"), "real_time": b.get("real_time"),
                    "cpu_time": b.get("cpu_time"), "time_unit": b.get("time_unit"),
                    "iterations": b.get("iterations")})
    return out


def append(args):
    manifest = os.path.join(args.work, "manifest.jsonl")
    entries = []
    if os.path.exists(manifest):
        with open(manifest, encoding="utf-8") as f:
            entries = [json.loads(line) for line in f if line.strip()]
    if not entries:
        print("bench_report: nothing was run, no record written", file=sys.stderr)
        return 1
    dirty = git("status", "--porcelain", "--untracked-files=no", "--", ".", ":(exclude)docs",
                ":(exclude)*.md")
    load_start = [float(x) for x in args.load_start.split()] if args.load_start else None
    record = {
        "schema": SCHEMA,
        "date": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"),
        "commit": git("rev-parse", "HEAD"),
        "dirty": bool(dirty),
        "mode": args.mode,
        "machine": machine(load_start),
        "sets": {},
        "micro": {},
    }
    for e in entries:
        data = read_json(e["json"]) if e.get("json") else None
        base = {"command": e["command"], "exit": e["exit"], "wall_s": e["wall_s"],
                "threads": e.get("threads"), "instructions": e.get("instructions"),
                "instructions_tool": e.get("instructions_tool")}
        if e.get("prepare"):
            base["prepare"] = e["prepare"]
        if e["kind"] == "micro":
            record["micro"][e["name"]] = {**base, "benchmarks": micro_bench(data or {})}
            continue
        if data is None:
            record["sets"][e["name"]] = {**base, "kind": e["kind"], "error": "no JSON written"}
            continue
        if e["kind"] in ("recorded", "colour", "noise"):
            figures = recorded_set(e, data)
        elif e["kind"] == "sweep":
            figures = {"noise_levels": data.get("noise_levels", []),
                       "degradation": data.get("degradation")}
        elif e["kind"] == "scenes":
            figures = rendered_bench(data)
        elif e["kind"] in ("memory", "web"):
            figures = dict(data)
        elif e["kind"] == "textured":
            figures = texture_score(data.get("texture"), data.get("scenes"))
            peer = texture_score(data.get("opencv"), data.get("scenes"))
            if peer:
                figures["peer"] = peer
        else:
            figures = {}
        entry = {**base, "kind": e["kind"], **(figures or {})}
        if "noise_sigma" in e:
            entry["noise_sigma"] = e["noise_sigma"]
        record["sets"][e["name"]] = entry
    os.makedirs(os.path.dirname(os.path.abspath(args.log)), exist_ok=True)
    with open(args.log, "a", encoding="utf-8") as f:
        f.write(json.dumps(record, sort_keys=True) + "\n")
    print(f"bench_report: record of {len(record['sets'])} sets and {len(record['micro'])} "
          f"micro-benchmark programs appended to {args.log}")
    return 0


# ---------------------------------------------------------------------------------------------
# Rendering


def load_log(path):
    records = []
    if os.path.exists(path):
        with open(path, encoding="utf-8") as f:
            for n, line in enumerate(f, 1):
                if not line.strip():
                    continue
                try:
                    r = json.loads(line)
                except ValueError:
                    print(f"bench_report: {path}: line {n} is not JSON, skipped", file=sys.stderr)
                    continue
                r["_n"] = n
                records.append(r)
    return records


def fmt(v, digits=1, unit=""):
    if v is None:
        return "-"
    if isinstance(v, float):
        return f"{v:.{digits}f}{unit}"
    return f"{v}{unit}"


def fraction(pair):
    if not pair or not pair[1]:
        return "-"
    return f"{pair[0]}/{pair[1]}"


def duration(v, unit):
    """A Google Benchmark time in the largest unit that keeps it at 1 or more."""
    if v is None:
        return "-"
    ns = v * {"ns": 1, "us": 1e3, "ms": 1e6, "s": 1e9}.get(unit, 1)
    for scale, name in ((1e9, "s"), (1e6, "ms"), (1e3, "us")):
        if ns >= scale:
            return f"{ns / scale:.3g} {name}"
    return f"{ns:.3g} ns"


def instructions(s):
    n = s.get("instructions")
    if not n:
        return "-"
    return f"{n / 1e9:.2f} G ({s.get('instructions_tool')})"


def loaded(r):
    """True when the machine was busy with other work during the record (1-minute load average
    of at least half the cores at its start or end): its wall-clock times are upper bounds."""
    m = r.get("machine", {})
    cores = m.get("cores") or 1
    loads = [x[0] for x in (m.get("loadavg_start"), m.get("loadavg_end")) if x]
    return bool(loads) and max(loads) >= 0.5 * cores


def when(r):
    notes = [f"record {r['_n']}"]
    if r.get("dirty"):
        notes.append("modified tree")
    if loaded(r):
        notes.append("loaded machine")
    return f"{r['date'][:10]} ({', '.join(notes)})"


PALETTE = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2",
           "#7f7f7f", "#bcbd22", "#17becf")


class Svg:
    def __init__(self, width, height, title):
        self.w, self.h = width, height
        self.parts = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" '
                      f'viewBox="0 0 {width} {height}" font-family="sans-serif" font-size="12">',
                      f'<rect width="{width}" height="{height}" fill="white"/>',
                      f'<text x="{width / 2}" y="18" text-anchor="middle" font-size="14">'
                      f'{html.escape(title)}</text>']

    def add(self, s):
        self.parts.append(s)

    def text(self, x, y, s, anchor="middle", size=12, rotate=None, colour="black"):
        r = f' transform="rotate({rotate} {x} {y})"' if rotate is not None else ""
        self.add(f'<text x="{x:.1f}" y="{y:.1f}" text-anchor="{anchor}" font-size="{size}" '
                 f'fill="{colour}"{r}>{html.escape(str(s))}</text>')

    def line(self, x1, y1, x2, y2, colour="black", width=1, dash=None):
        d = f' stroke-dasharray="{dash}"' if dash else ""
        self.add(f'<line x1="{x1:.1f}" y1="{y1:.1f}" x2="{x2:.1f}" y2="{y2:.1f}" '
                 f'stroke="{colour}" stroke-width="{width}"{d}/>')

    def save(self, path):
        self.add("</svg>")
        with open(path, "w", encoding="utf-8") as f:
            f.write("\n".join(self.parts) + "\n")


def axes(svg, left, top, right, bottom, ymax, ylabel, ticks=5):
    svg.line(left, bottom, right, bottom)
    svg.line(left, top, left, bottom)
    for i in range(ticks + 1):
        v = ymax * i / ticks
        y = bottom - (bottom - top) * i / ticks
        svg.line(left - 4, y, right, y, colour="#dddddd" if i else "black")
        svg.text(left - 6, y + 4, f"{v:g}", anchor="end", size=10)
    svg.text(14, (top + bottom) / 2, ylabel, rotate=-90, size=11)


def nice_max(v):
    if v <= 0:
        return 1
    for mag in range(-2, 7):
        for step in (1, 2, 2.5, 5):
            m = step * 10 ** mag
            if m >= v:
                return m
    return v


def plot_visibility(sets, path):
    """Grouped bars: recall per visibility bin for every set that has the bins."""
    items = [(name, s["recall_by_visibility"]) for name, s in sets
             if s.get("recall_by_visibility")]
    if not items:
        return False
    group_w = 110
    left, top, bottom = 60, 40, 260
    width = left + group_w * len(items) + 170
    svg = Svg(width, 320, "Recall by visible fraction of the object (latest record of each set)")
    right = left + group_w * len(items)
    axes(svg, left, top, right, bottom, 100, "recall %")
    bar = 26
    for i, (name, vis) in enumerate(items):
        x0 = left + i * group_w + 14
        for j, label in enumerate(VIS_BINS):
            pair = vis.get(label)
            if not pair or not pair[1]:
                continue
            r = 100.0 * pair[0] / pair[1]
            y = bottom - (bottom - top) * r / 100
            x = x0 + j * (bar + 2)
            svg.add(f'<rect x="{x}" y="{y:.1f}" width="{bar}" height="{bottom - y:.1f}" '
                    f'fill="{PALETTE[j]}"/>')
            svg.text(x + bar / 2, y - 3, f"{pair[0]}/{pair[1]}", size=8)
        svg.text(left + i * group_w + group_w / 2, bottom + 16, name, size=10)
    for j, label in enumerate(VIS_BINS):
        y = top + 10 + 18 * j
        svg.add(f'<rect x="{right + 16}" y="{y - 9}" width="12" height="12" fill="{PALETTE[j]}"/>')
        svg.text(right + 34, y + 1, f"visible {label}", anchor="start", size=11)
    svg.save(path)
    return True


def plot_lines(series, path, title, xlabel, ylabel, xlabels=None, ymax=None):
    """series: [(name, [(x, y), ...])]; x numeric, or an index into xlabels."""
    pts = [p for _, s in series for p in s if p[1] is not None]
    if not pts:
        return False
    left, top, right, bottom = 60, 40, 520, 250
    width = right + 50 + int(6.6 * max(len(name) for name, _ in series))
    svg = Svg(width, 300, title)
    xs = [p[0] for p in pts]
    xmin, xmax = min(xs), max(xs)
    if xmax == xmin:
        xmin, xmax = xmin - 1, xmax + 1
    ymax = ymax or nice_max(max(p[1] for p in pts) * 1.1)
    axes(svg, left, top, right, bottom, ymax, ylabel)

    def px(x):
        return left + 10 + (right - left - 20) * (x - xmin) / (xmax - xmin)

    def py(y):
        return bottom - (bottom - top) * min(y, ymax) / ymax

    if xlabels:
        for i, label in enumerate(xlabels):
            svg.text(px(i), bottom + 14, label, size=9)
    else:
        for x in sorted(set(xs)):
            svg.text(px(x), bottom + 14, f"{x:g}", size=10)
    svg.text((left + right) / 2, bottom + 34, xlabel, size=11)
    for k, (name, s) in enumerate(series):
        colour = PALETTE[k % len(PALETTE)]
        s = [p for p in s if p[1] is not None]
        if not s:
            continue
        d = " ".join(f"{'M' if i == 0 else 'L'}{px(x):.1f},{py(y):.1f}" for i, (x, y) in
                     enumerate(s))
        svg.add(f'<path d="{d}" fill="none" stroke="{colour}" stroke-width="2"/>')
        for x, y in s:
            svg.add(f'<circle cx="{px(x):.1f}" cy="{py(y):.1f}" r="3" fill="{colour}"/>')
        ly = top + 8 + 16 * k
        svg.line(right + 14, ly, right + 30, ly, colour=colour, width=2)
        svg.text(right + 36, ly + 4, name, anchor="start", size=11)
    svg.save(path)
    return True


def latest_sets(records):
    """For each set name, the latest record that ran it with the programs' default threads, or
    failing that the latest that ran it at all (runs with --threads N are the exceptions)."""
    latest = {}
    for r in records:
        for name, s in r.get("sets", {}).items():
            if not s.get("threads") or name not in latest or latest[name][1].get("threads"):
                latest[name] = (r, s)
    return latest


# The clean set and the factory-floor set of each camera, whose frame times the page compares.
FLOOR_PAIRS = (("thesis-camera", "hard-thesis-camera"), ("wide-camera", "hard-wide-camera"))


def floor_times(records):
    """Per thread setting (None: the programs' default), the latest record that ran both sets of
    a pair that way, with the clean and the factory-floor frame times."""
    rows = {}
    for r in records:
        sets = r.get("sets", {})
        for clean, floor in FLOOR_PAIRS:
            a, b = sets.get(clean), sets.get(floor)
            if not a or not b or a.get("error") or b.get("error"):
                continue
            if a.get("threads") != b.get("threads"):
                continue
            fa, fb = a.get("frame_ms") or {}, b.get("frame_ms") or {}
            if not fa.get("median") or not fb.get("median") or fb.get("worst") is None:
                continue
            rows[(a.get("threads"), clean)] = (r, clean, floor, fa, fb)
    return [rows[k] for k in sorted(rows, key=lambda k: (k[0] or 0, set_key(k[1])))]


def write_floor_times(w, records):
    rows = floor_times(records)
    if not rows:
        return
    w("## Frame time on the factory floor")
    w("")
    w("Each factory-floor set against the clean set of the same camera, from one record (same "
      "machine, same load), warm (`stereohash bench recorded`). The aim: the factory-floor "
      "median within 1.5 times the clean median, its worst frame within 3 times the clean "
      "median. Records with `--threads N` are made by `tools/bench-report.sh --quick --threads "
      "N --sets thesis-camera,wide-camera,hard-thesis-camera,hard-wide-camera`.")
    w("")
    w("| threads | clean set | median | factory-floor set | median | worst | median ratio | "
      "worst / clean median | measured |")
    w("|---|---|---|---|---|---|---|---|---|")
    for r, clean, floor, fa, fb in rows:
        threads = (r["sets"][clean].get("threads")
                   or f"default ({r.get('machine', {}).get('cores', '?')} cores)")
        w(f"| {threads} | {clean} | {fmt(fa['median'])} ms | {floor} | {fmt(fb['median'])} ms | "
          f"{fmt(fb['worst'])} ms | {fb['median'] / fa['median']:.2f} | "
          f"{fb['worst'] / fa['median']:.2f} | {when(r)} |")
    w("")


def latest_micro(records):
    latest = {}
    for r in records:
        for name, m in r.get("micro", {}).items():
            latest[name] = (r, m)
    return latest


# What a part's command needs made first, for records that predate the "prepare" field.
PREPARE_DEFAULTS = {
    "colour": "stereohash tables build --models models/colour --out $WORK/colour-views.bin",
}

SET_ORDER = ("thesis-camera", "wide-camera", "hard-thesis-camera", "hard-wide-camera", "colour",
             "textured", "rendered")


def set_key(name):
    return (SET_ORDER.index(name) if name in SET_ORDER else len(SET_ORDER), name)


def render(args):
    records = load_log(args.log)
    os.makedirs(args.plots, exist_ok=True)
    md_dir = os.path.dirname(os.path.abspath(args.md))
    rel = os.path.relpath(os.path.abspath(args.plots), md_dir)
    log_rel = os.path.relpath(os.path.abspath(args.log), md_dir)
    out = []
    w = out.append
    w("# Benchmarks")
    w("")
    w("<!-- Generated by tools/bench-report.sh from docs/benchmarks/log.jsonl: do not edit; "
      "run `tools/bench-report.sh --render-only` after changing the renderer. -->")
    w("")
    w("How fast and how accurate the product is, as the benchmark log last measured it. Every "
      f"figure on this page comes from [the log]({log_rel}) (one JSON line per run: date, "
      "commit, whether the tree was modified, the machine with its load, and per set the "
      "counts, errors, frame times and instruction counts), and every row names the command "
      "that produced it.")
    w("")
    w("```")
    w("tools/bench-report.sh                      # everything: recorded sets, rendered bench, "
      "noise sweep,")
    w("                                           # texture bench with its OpenCV peer, "
      "micro-benchmarks")
    w("tools/bench-report.sh --quick              # the recorded sets only")
    w("tools/bench-report.sh --sets thesis-camera,colour   # some parts (names as in the tables "
      "below)")
    w("tools/bench-report.sh --quick DIR...       # also other recorded sets "
      "(stereohash render --scenes-per-row)")
    w("tools/bench-report.sh --render-only        # this page again from the log")
    w("```")
    w("")
    w("Scoring, as in `../shared/scenes/README.md`: a detection is correct when the model "
      "matches and the pose is within 5 mm and 5 degrees of a true object not matched yet "
      "(modulo the model's symmetries); false alarms are a share of the reported objects; "
      "recall by visibility bins the objects by the visible fraction of their silhouette (mean "
      "of left and right). `stereohash bench scenes` (our renderer's grid of thesis table 5.4) "
      "scores at 10 mm / 10 degrees and has no visibility. Frame times are wall clock per "
      "frame over the set (p95 where the command reports per-scene times), on the machine "
      "and load the record names: compare them only within one record, or by instruction "
      "counts.")
    w("")
    if not records:
        w("## Latest figures")
        w("")
        w("The log holds no record yet: run `tools/bench-report.sh` on a Release build "
          "(`cmake --preset host-release && cmake --build --preset host-release`).")
        w("")
        with open(args.md, "w", encoding="utf-8") as f:
            f.write("\n".join(out) + "\n")
        print(f"bench_report: {args.md} rendered from an empty log")
        return 0

    latest = latest_sets(records)
    names = sorted(latest, key=set_key)
    w("## Latest figures")
    w("")
    w("| set | correct | false alarms | recall by visibility (< 40 / 40-70 / >= 70 %) | median "
      "error | frame median / p95 / worst | instructions | measured |")
    w("|---|---|---|---|---|---|---|---|")
    mem = latest.get("memory")
    web = latest.get("web-latency")
    sweeps = [n for n in names if latest[n][1].get("kind") == "sweep"]
    names = [n for n in names
             if n not in ("memory", "web-latency")
             and latest[n][1].get("kind") not in ("noise", "sweep")]
    for name in names:
        r, s = latest[name]
        if s.get("error"):
            w(f"| {name} | {s['error']} (exit {s.get('exit')}) | | | | | | {when(r)} |")
            continue
        vis = s.get("recall_by_visibility") or {}
        vis_text = " / ".join(fraction(vis.get(b)) for b in VIS_BINS) if vis else "-"
        fm = s.get("frame_ms") or {}
        w(f"| {name} | {fmt(s.get('correct'))}/{fmt(s.get('objects'))} "
          f"({fmt(s.get('correct_pct'), 1, ' %')}) | {fmt(s.get('false_alarms'))} "
          f"({fmt(s.get('false_alarm_pct'), 1, ' %')}) | {vis_text} | "
          f"{fmt(s.get('median_t_err_mm'), 2, ' mm')} / {fmt(s.get('median_r_err_deg'), 2, ' deg')}"
          f" | {fmt(fm.get('median'))} / {fmt(fm.get('p95'))} / {fmt(fm.get('worst'))} ms | "
          f"{instructions(s)} | {when(r)} |")
    w("")
    w("Commands (`stereohash` is `build/host-release/tools/stereohash`; the script's working "
      "files under a temporary folder are named `$WORK`):")
    w("")
    for name in names:
        r, s = latest[name]
        if s.get("kind") == "textured":
            threads = "one thread"
        else:
            threads = (f"{s['threads']} thread(s)" if s.get("threads")
                       else "the program's default threads (all cores)")
        prep = s.get("prepare") or PREPARE_DEFAULTS.get(s.get("kind"), "")
        prepare = f"`{prep}`, then " if prep else ""
        w(f"- {name}: {prepare}`{s.get('command')}`; {threads}")
    w("")
    write_floor_times(w, records)
    peers = [(n, latest[n][1]["peer"]) for n in names if latest[n][1].get("peer")]
    for name, p in peers:
        fm = p.get("frame_ms") or {}
        w(f"The OpenCV peer on `{name}` (SIFT, FLANN, RANSAC homography, solvePnP, stereo; "
          f"docs/texture.md): {p.get('correct')}/{p.get('objects')} correct, "
          f"{p.get('false_alarms')} false alarms, median error "
          f"{fmt(p.get('median_t_err_mm'), 2, ' mm')} / {fmt(p.get('median_r_err_deg'), 2, ' deg')}, "
          f"frame median {fmt(fm.get('median'))} ms, worst {fmt(fm.get('worst'))} ms.")
        w("")
    rendered = latest.get("rendered")
    if rendered and rendered[1].get("rows"):
        w("Our renderer's grid (`rendered`), per row:")
        w("")
        w("| table | occlusion | correct | false alarms | frame median / worst |")
        w("|---|---|---|---|---|")
        for row in rendered[1]["rows"]:
            w(f"| {row['background']} | {row['occlusion']} | {row['correct']}/{row['objects']} | "
              f"{row['false_alarms']} | {fmt(row.get('median_ms'))} / {fmt(row.get('worst_ms'))} "
              "ms |")
        w("")

    ordered = [(n, latest[n][1]) for n in names]
    if plot_visibility(ordered, os.path.join(args.plots, "recall-visibility.svg")):
        w("## Recall against visibility")
        w("")
        w(f"![recall by visibility]({rel}/recall-visibility.svg)")
        w("")
    noise_series = []
    for n in sweeps:
        levels = latest[n][1].get("noise_levels") or []
        pts = [(x["noise_sigma"], x["correct_pct"]) for x in levels if x.get("objects")]
        if pts:
            noise_series.append((f"{n[len('noise-'):]} with noise added", sorted(pts)))
    sweep = len(noise_series) > 0
    centres = {"under 2.5": 2.0, "2.5-3.5": 3.0, "3.5 and more": 4.0}
    for n, s in ordered:
        bins = s.get("recall_by_noise")
        if bins:
            pts = [(centres[k], 100.0 * v[0] / v[1]) for k, v in bins.items() if v[1]]
            noise_series.append((f"{n}, scenes binned by read noise", sorted(pts)))
    if plot_lines(noise_series, os.path.join(args.plots, "recall-noise.svg"),
                  "Recall against sensor noise", "noise sigma, grey levels", "recall %",
                  ymax=100):
        w("## Recall against noise")
        w("")
        text = []
        if sweep:
            text.append("The clean sets with sensor noise added to every image before "
                        "recognition (`stereohash bench recorded DIR --noise ...`: seeded read "
                        "and shot noise of the given sigma at mid grey, on top of the about 2 "
                        "grey levels the images carry).")
        if len(noise_series) > (1 if sweep else 0):
            text.append("The factory-floor sets (`hard-*`) bin their scenes by the read noise of "
                        "each scene's camera (truth.json `look.read`: 1.5-5 grey levels, with "
                        "shot noise, blur, vignetting and other lamps on top; bins under 2.5, "
                        "2.5-3.5 and from 3.5, plotted at 2, 3 and 4), so their bins differ "
                        "in more than noise.")
        w(" ".join(text))
        w("")
        w(f"![recall against noise]({rel}/recall-noise.svg)")
        w("")
        for n in sweeps:
            r, s = latest[n]
            levels = s.get("noise_levels") or []
            if not levels:
                continue
            w(f"`{n}`: `{s.get('command')}` ({when(r)})")
            w("")
            w("| noise added, sigma | correct | >= 70 % visible | 40-70 % visible | false alarms "
              "| median error | frame median / worst |")
            w("|---|---|---|---|---|---|---|")
            for x in levels:
                w(f"| {x['noise_sigma']:g} | {x['correct']}/{x['objects']} "
                  f"({fmt(x.get('correct_pct'), 1, ' %')}) | {fmt(x.get('visible_70_pct'), 1, ' %')}"
                  f" | {fmt(x.get('visible_40_70_pct'), 1, ' %')} | {x['false_alarms']} "
                  f"({fmt(x.get('false_alarm_pct'), 1, ' %')}) | "
                  f"{fmt(x.get('median_t_err_mm'), 2, ' mm')} / "
                  f"{fmt(x.get('median_r_err_deg'), 2, ' deg')} | "
                  f"{fmt(x.get('median_ms'))} / {fmt(x.get('worst_ms'))} ms |")
            w("")

    history = records[-20:]
    labels = [r["date"][5:10] for r in history]
    time_series, recall_series = [], []
    for name in names:
        if latest[name][1].get("kind") == "noise":
            continue
        t_pts, r_pts = [], []
        for i, r in enumerate(history):
            s = r.get("sets", {}).get(name)
            if not s or s.get("error"):
                continue
            t_pts.append((i, (s.get("frame_ms") or {}).get("median")))
            r_pts.append((i, s.get("correct_pct")))
        if len([p for p in t_pts if p[1] is not None]) >= 1:
            time_series.append((name, t_pts))
            recall_series.append((name, r_pts))
    if len(history) >= 2:
        w("## History")
        w("")
        w(f"The last {len(history)} records; each point is that record's figure for the set "
          "(wall clock depends on the record's machine and load).")
        w("")
        if plot_lines(time_series, os.path.join(args.plots, "history-frame-time.svg"),
                      "Frame median per record", "record date (MM-DD)", "ms", xlabels=labels):
            w(f"![frame median history]({rel}/history-frame-time.svg)")
            w("")
        if plot_lines(recall_series, os.path.join(args.plots, "history-recall.svg"),
                      "Correct objects per record", "record date (MM-DD)", "correct %",
                      xlabels=labels, ymax=100):
            w(f"![recall history]({rel}/history-recall.svg)")
            w("")

    if mem and not mem[1].get("error"):
        r, m = mem
        w("## Memory")
        w("")
        w("Resident memory (KiB, as /proc and getrusage give it; docs/memory.md explains each "
          f"buffer), measured {when(r)} by these commands:")
        w("")
        for c in m.get("commands", []):
            w(f"- `{c}`")
        w("")
        w("| program | resident | peak | locked |")
        w("|---|---|---|---|")
        rec = m.get("recognize") or {}
        w(f"| `stereohash recognize` on `{rec.get('pair')}` | | {fmt(rec.get('max_rss_kib'))} | |")
        for lock in ("false", "true"):
            fw = m.get(f"firmware_sim_mlock_{lock}")
            if fw:
                w(f"| `stereohash-fw-sim --demo` (rendered world), `mlock = {lock}`, 6 s in | "
                  f"{fmt(fw.get('rss_kib_at_6s'))} | {fmt(fw.get('hwm_kib_at_6s'))} | "
                  f"{fmt(fw.get('locked_kib_at_6s'))} |")
        w("")

    if web and not web[1].get("error"):
        r, m = web
        w("## Trigger-to-result latency with the commissioning page open")
        w("")
        w("The firmware simulator (rendered world, the recognition pipeline) triggered over "
          "socketcand by python-can; the latency is the firmware's own, from a trigger's arrival "
          f"to its result set on the bus (docs/web.md). Measured {when(r)} by `{m.get('command')}`:")
        w("")
        w("| page | viewers | answered | median | p95 | p99 | worst | page requests |")
        w("|---|---|---|---|---|---|---|---|")
        for c in m.get("cases", []):
            req = c.get("page_requests") or {}
            w(f"| {c.get('case')} | {c.get('viewers')}"
              f"{'' if not c.get('viewers') else ' every ' + str(c.get('viewer_period_ms')) + ' ms'} "
              f"| {c.get('answered')}/{c.get('triggers')} | {fmt(c.get('median_ms'), 1, ' ms')} | "
              f"{fmt(c.get('p95_ms'), 1, ' ms')} | {fmt(c.get('p99_ms'), 1, ' ms')} | "
              f"{fmt(c.get('max_ms'), 1, ' ms')} | {req.get('status', 0)} status, "
              f"{req.get('images', 0)} images |")
        w("")
        ratio = m.get("page_p99_ratio")
        if ratio:
            w(f"The p99 with one page open is {fmt(100.0 * ratio, 1, ' %')} of the p99 with the "
              "page closed.")
            w("")

    micro = latest_micro(records)
    if micro:
        w("## Micro-benchmarks")
        w("")
        w("Google Benchmark programs under `build/host-release/tests` (built when Google "
          "Benchmark is installed), run with `--benchmark_format=json`:")
        w("")
        w("| program | CPU time per iteration of each benchmark | measured |")
        w("|---|---|---|")
        for prog in sorted(micro):
            r, m = micro[prog]
            items = "; ".join(f"`{b.get('name')}` {duration(b.get('cpu_time'), b.get('time_unit') or 'ns')}"
                              for b in m.get("benchmarks", []))
            w(f"| {prog} | {items or m.get('error', '-')} | {when(r)} |")
        w("")

    w("## Records")
    w("")
    w(f"The last {min(len(records), 8)} of {len(records)} records:")
    w("")
    w("A record is marked *loaded machine* when the 1-minute load average reached half the "
      "cores at its start or end: its frame times are upper bounds.")
    w("")
    w("| record | date (UTC) | mode | machine | load average at start / end | parts |")
    w("|---|---|---|---|---|---|")
    for r in records[-8:]:
        m = r.get("machine", {})
        parts = ", ".join(sorted(r.get("sets", {}), key=set_key) + sorted(r.get("micro", {})))
        w(f"| {r['_n']}{' (modified tree)' if r.get('dirty') else ''} | "
          f"{r['date'].replace('T', ' ').rstrip('Z')} | {r.get('mode')} | {m.get('cpu')}, "
          f"{m.get('cores')} cores | {m.get('loadavg_start')} / {m.get('loadavg_end')} | "
          f"{parts} |")
    w("")
    w("Each record's commit is in the log (`commit`, with `dirty` when tracked files outside "
      "docs/ differed from it).")
    with open(args.md, "w", encoding="utf-8") as f:
        f.write("\n".join(out) + "\n")
    print(f"bench_report: {args.md} rendered from {len(records)} record(s)")
    return 0


def main():
    p = argparse.ArgumentParser(description="The benchmark log of tools/bench-report.sh and "
                                "docs/benchmarks.md rendered from it.")
    sub = p.add_subparsers(dest="cmd", required=True)
    n = sub.add_parser("note")
    n.add_argument("--work", required=True)
    n.add_argument("--name", required=True)
    n.add_argument("--kind", required=True)
    n.add_argument("--command", required=True)
    n.add_argument("--json", default="")
    n.add_argument("--exit", type=int, default=0)
    n.add_argument("--wall", type=float, default=0.0)
    n.add_argument("--instructions", default="")
    n.add_argument("--tool", default="")
    n.add_argument("--noise", type=float)
    n.add_argument("--truth", default="")
    n.add_argument("--threads", type=int)
    n.add_argument("--prepare", default="")
    a = sub.add_parser("append")
    a.add_argument("--work", required=True)
    a.add_argument("--log", required=True)
    a.add_argument("--mode", default="full")
    a.add_argument("--load-start", default="")
    m = sub.add_parser("memory")
    m.add_argument("--work", required=True)
    m.add_argument("--out", required=True)
    m.add_argument("--stereohash", required=True)
    m.add_argument("--firmware", default="")
    m.add_argument("--scene-set", required=True)
    r = sub.add_parser("render")
    r.add_argument("--log", required=True)
    r.add_argument("--md", required=True)
    r.add_argument("--plots", required=True)
    args = p.parse_args()
    return {"note": note, "append": append, "memory": memory, "render": render}[args.cmd](args)


if __name__ == "__main__":
    sys.exit(main())
