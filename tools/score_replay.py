#!/usr/bin/python3
"""Scores the result sets of a firmware replay against a recorded set's ground truth.

stereohash-fw-sim with `camera = directory` plays the scene folders of a recorded set (sorted by
name, pair n = scene n mod count) and prints a RESULT line per set and the MODELS line naming
the model ids. This reads that output, takes the first set of each scene, and scores it as the
recorded sets' README does: correct = same model, within 5 mm and 5 degrees modulo the model's
rotation symmetries (MODELS line; printed models have none), positions compared at the model's
corner centroid (which the symmetries fix); false alarms = reported objects with no ground-truth
partner. Usage:

  stereohash-fw-sim --config replay.conf --run-seconds 30 > replay.out
  tools/score_replay.py SET replay.out
"""
import json
import math
import os
import statistics
import sys


def quat_to_matrix(w, x, y, z):
    return [[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]]


def apply(R, t, p):
    return [sum(R[i][k] * p[k] for k in range(3)) + t[i] for i in range(3)]


def matmul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3)] for i in range(3)]


def angle_deg(a, b):
    """Angle of the rotation a^T b."""
    trace = sum(a[k][i] * b[k][i] for i in range(3) for k in range(3))
    return math.degrees(math.acos(max(-1.0, min(1.0, (trace - 1) / 2))))


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    set_dir, output = sys.argv[1], sys.argv[2]
    models, results = None, []
    with open(output) as f:
        for line in f:
            if line.startswith("MODELS "):
                models = json.loads(line[len("MODELS "):])
            elif line.startswith("RESULT "):
                results.append(json.loads(line[len("RESULT "):]))
    if models is None or not results:
        sys.exit("%s: no MODELS or RESULT lines" % output)
    scenes = sorted(d for d in os.listdir(set_dir)
                    if d.startswith("scene") and os.path.isdir(os.path.join(set_dir, d)))
    seen = set()
    objects = correct = false_alarms = 0
    position_mm, rotation_deg = [], []
    for r in results:
        scene = scenes[r["pair_index"] % len(scenes)]
        if scene in seen:
            continue
        seen.add(scene)
        with open(os.path.join(set_dir, scene, "truth.json")) as f:
            truth = json.load(f)["objects"]
        objects += len(truth)
        used = set()
        for o in r["objects"]:
            m = o["model_id"]
            name = models["names"][m]
            centroid = models["centroids_mm"][m]
            symmetries = [[s[0:3], s[3:6], s[6:9]] for s in models["symmetries"][m]]
            R = quat_to_matrix(*o["q_wxyz"])
            best = None
            for j, t in enumerate(truth):
                if j in used or t["model"] != name:
                    continue
                d = math.dist(apply(R, o["t_mm"], centroid), apply(t["R"], t["t"], centroid))
                a = min(angle_deg(R, matmul(t["R"], S)) for S in symmetries)
                if d < 5 and a < 5 and (best is None or d < best[1]):
                    best = (j, d, a)
            if best is None:
                false_alarms += 1
                print("%s: %s at %s matches nothing" % (scene, name, o["t_mm"]))
                continue
            used.add(best[0])
            correct += 1
            position_mm.append(best[1])
            rotation_deg.append(best[2])
        for j, t in enumerate(truth):
            if j not in used:
                print("%s: %s missed (visible %s)" % (scene, t["model"], t.get("visible")))
    print("%d scenes, %d objects: %d correct, %d false alarms" %
          (len(seen), objects, correct, false_alarms))
    if position_mm:
        print("error of the correct ones: median %.2f mm, %.2f deg; max %.2f mm, %.2f deg" %
              (statistics.median(position_mm), statistics.median(rotation_deg),
               max(position_mm), max(rotation_deg)))
    if len(seen) < len(scenes):
        print("only %d of %d scenes had a result set: run longer" % (len(seen), len(scenes)))


if __name__ == "__main__":
    main()
