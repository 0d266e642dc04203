#!/usr/bin/python3
"""Replay of a recorded scene set through stereohash-fw-sim gives the poses `stereohash recognize`
gives on the same pairs.

The simulator program runs with `camera = directory` on the set (recorded-scenes layout:
calib.yaml and table.yaml beside scene folders with left.png and right.png) and free-runs, so
each capture plays the next pair; its RESULT lines are compared, pair by pair, with
`stereohash recognize --scene SET/<scene> --json` (same background preset, no time limit). Both
must report the same objects at the same poses (position within --max-position-mm, rotation
within --max-rotation-deg).

Without --set, a set of --scenes scenes is rendered with `stereohash render` first (CI has no
recorded sets). Prints one line per scene and a summary.

A second test records: the firmware replaying a rendered set with record_dir writes its
triggered pairs with their result.json, and `stereohash recognize --scene` on each recorded pair
must give the recorded poses (a failure seen on the line reproduces on a desk).

A third records the simulator's own light-table scenes (recognised with the light preset) and
replays the recording with `recognize --scene` and with `camera = directory`, neither told the
preset: the recording's settings.conf gives it, and both must give the recorded poses.
"""
import argparse
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile
import threading
import time
import unittest

ARGS = None


def matrix_to_quat(R):
    """Unit quaternion (w, x, y, z) of a rotation matrix (Shepperd's method, renormalised)."""
    trace = R[0][0] + R[1][1] + R[2][2]
    if trace > 0:
        s = math.sqrt(trace + 1.0) * 2
        q = [0.25 * s, (R[2][1] - R[1][2]) / s, (R[0][2] - R[2][0]) / s, (R[1][0] - R[0][1]) / s]
    elif R[0][0] > R[1][1] and R[0][0] > R[2][2]:
        s = math.sqrt(1.0 + R[0][0] - R[1][1] - R[2][2]) * 2
        q = [(R[2][1] - R[1][2]) / s, 0.25 * s, (R[0][1] + R[1][0]) / s, (R[0][2] + R[2][0]) / s]
    elif R[1][1] > R[2][2]:
        s = math.sqrt(1.0 + R[1][1] - R[0][0] - R[2][2]) * 2
        q = [(R[0][2] - R[2][0]) / s, (R[0][1] + R[1][0]) / s, 0.25 * s, (R[1][2] + R[2][1]) / s]
    else:
        s = math.sqrt(1.0 + R[2][2] - R[0][0] - R[1][1]) * 2
        q = [(R[1][0] - R[0][1]) / s, (R[0][2] + R[2][0]) / s, (R[1][2] + R[2][1]) / s, 0.25 * s]
    n = math.sqrt(sum(c * c for c in q))
    return [c / n for c in q]


def rotation_between_deg(a, b):
    """Angle of the rotation between two unit quaternions, well conditioned near 0."""
    n = math.sqrt(sum(c * c for c in a))
    a = [c / n for c in a]
    dot = abs(sum(x * y for x, y in zip(a, b)))
    # |q_a^-1 q_b| vector part, from the identity |v|^2 = 1 - w^2 evaluated stably
    cross = math.sqrt(max(0.0, sum((a[0] * b[i] - b[0] * a[i]) ** 2 for i in (1, 2, 3)) +
                          sum((a[j] * b[k] - a[k] * b[j]) ** 2
                              for j, k in ((1, 2), (2, 3), (1, 3)))))
    return math.degrees(2 * math.atan2(cross, dot))


def background_key():
    """The firmware's `background` line: none for the automatic default."""
    return [] if ARGS.background == "automatic" else ["background = %s" % ARGS.background]


def background_arg():
    return [] if ARGS.background == "automatic" else ["--background", ARGS.background]


def render_set(stereohash, directory, scenes):
    seed = 0
    for k in range(scenes):
        out = os.path.join(directory, "scene%02d" % k)
        while True:  # seeds whose objects cannot be placed are skipped, as the simulator does
            seed += 1
            done = subprocess.run([stereohash, "render", "--out", out, "--seed", str(seed),
                                   "--objects", "3"], stdout=subprocess.DEVNULL,
                                  stderr=subprocess.DEVNULL)
            if done.returncode == 0:
                break
            if seed > 100:
                raise RuntimeError("stereohash render placed no scene in 100 seeds")
        for name in ("calib.yaml", "table.yaml"):
            shared = os.path.join(directory, name)
            if not os.path.exists(shared):
                shutil.copy(os.path.join(out, name), shared)
            os.remove(os.path.join(out, name))


def scene_folders(directory):
    folders = [f for f in os.listdir(directory)
               if os.path.isfile(os.path.join(directory, f, "left.png"))]

    def natural(name):  # the firmware plays folders in natural order: scene2 before scene10
        parts, digits = [], ""
        for c in name + "\0":
            if c.isdigit():
                digits += c
                continue
            if digits:
                parts.append((0, int(digits), ""))
                digits = ""
            parts.append((1, 0, c))
        return parts
    return sorted(folders, key=natural)


class ReplayTest(unittest.TestCase):
    def test_replay_matches_recognize(self):
        work = tempfile.mkdtemp(prefix="stereohash_replay_")
        try:
            directory = ARGS.set
            if directory is None:
                directory = os.path.join(work, "set")
                os.makedirs(directory)
                render_set(ARGS.stereohash, directory, ARGS.scenes)
            scenes = scene_folders(directory)
            self.assertTrue(scenes, "no scene folders in %s" % directory)
            firmware_results = self.run_firmware(directory, len(scenes), work)
            self.compare(directory, scenes, firmware_results, work)
        finally:
            shutil.rmtree(work, ignore_errors=True)

    def run_firmware(self, directory, count, work, extra=(), source=None):
        """RESULT lines of the simulator program on `directory` (camera = directory), or on the
        camera lines `source` (with their own background lines)."""
        config = os.path.join(work, "fw.conf")
        if source is None:
            source = ["camera = directory", "camera_directory = %s" % directory] + background_key()
        with open(config, "w") as f:
            f.write("\n".join(list(source) + ["budget_ms = 10000",
                "free_run_dhz = 300", "heartbeat_ms = 1000", "sim_port = 0"] + list(extra) + [""]))
        proc = subprocess.Popen([ARGS.firmware, "--config", config],
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                bufsize=1)
        results, stderr = [], []
        threading.Thread(target=lambda: stderr.extend(proc.stderr), daemon=True).start()
        deadline = time.time() + ARGS.timeout
        try:
            for line in proc.stdout:
                if line.startswith("MODELS "):
                    self.model_names = json.loads(line.split(" ", 1)[1])["names"]
                if line.startswith("RESULT "):
                    results.append(json.loads(line.split(" ", 1)[1]))
                    if len(results) == count:
                        break
                if time.time() > deadline:
                    break
        finally:
            proc.terminate()
            try:
                proc.wait(20)
            except subprocess.TimeoutExpired:
                proc.kill()
        self.assertEqual(len(results), count,
                         "firmware results: %d of %d\n%s" % (len(results), count,
                                                             "".join(stderr[-20:])))
        return results

    def test_recording_reproduces_on_a_desk(self):
        work = tempfile.mkdtemp(prefix="stereohash_record_")
        try:
            directory = os.path.join(work, "set")
            os.makedirs(directory)
            render_set(ARGS.stereohash, directory, ARGS.scenes)
            record = os.path.join(work, "record")
            # Recording while replaying the rendered set, configured as on a board.
            self.run_firmware(directory, ARGS.scenes, work,
                              ["record_dir = %s" % record, "record_max = 50",
                               "record_format = pgm"])
            pairs = sorted(p for p in os.listdir(record) if p.isdigit())
            # Free-run may record a pair or two more before the firmware stops.
            self.assertGreaterEqual(len(pairs), ARGS.scenes, "pairs recorded")
            self.assertTrue(os.path.exists(os.path.join(record, "table.yaml")))
            worst_mm = worst_deg = 0.0
            objects = 0
            for pair in pairs:
                with open(os.path.join(record, pair, "result.json")) as f:
                    recorded = json.load(f)
                out = os.path.join(work, pair + ".json")
                subprocess.run([ARGS.stereohash, "recognize", "--scene",
                                os.path.join(record, pair), "--json", out] + background_arg(),
                               check=True, stdout=subprocess.DEVNULL)
                with open(out) as f:
                    ref = json.load(f)
                self.assertEqual(sorted(o["model"] for o in recorded["objects"]),
                                 sorted(o["model"] for o in ref["objects"]), pair)
                for o in recorded["objects"]:
                    best = min((math.dist(o["t_mm"], r["t"]),
                                rotation_between_deg(o["q_wxyz"], matrix_to_quat(r["R"])))
                               for r in ref["objects"] if r["model"] == o["model"])
                    worst_mm, worst_deg = max(worst_mm, best[0]), max(worst_deg, best[1])
                    objects += 1
            print("recording: %d pairs, %d objects; recognize on the recorded pairs differs by at "
                  "most %.4f mm, %.4f deg" % (len(pairs), objects, worst_mm, worst_deg))
            sys.stdout.flush()
            self.assertGreater(objects, 0)
            self.assertLessEqual(worst_mm, ARGS.max_position_mm)
            self.assertLessEqual(worst_deg, ARGS.max_rotation_deg)
        finally:
            shutil.rmtree(work, ignore_errors=True)

    # The preset, the working volume with the rendered table it lies on (rig_table.yaml), the
    # table estimate and the one-camera fallback are recorded; the firmware's replay takes them
    # all, and `recognize --scene` the preset, the volume and the rig table (for the volume and
    # the one-image rescue). A pair recognised alone cannot carry the table plane of the frames
    # before it, which moves a pose by about a thousandth of a millimetre.
    def test_simulator_recording_replays_to_the_recorded_poses(self):
        """The simulator recognises its light-table scenes with the light preset: the recording
        says so, and both replays (recognize --scene, camera = directory) use it."""
        work = tempfile.mkdtemp(prefix="stereohash_simrecord_")
        try:
            record = os.path.join(work, "record")
            # A few results more than the pairs needed: the recording's writer runs at the lowest
            # priority and may still hold the last pairs, or have dropped some, on a busy machine.
            self.run_firmware(None, ARGS.scenes + 3, work,
                              ["record_dir = %s" % record, "record_max = 50",
                               "record_format = pgm"],
                              source=["camera = sim", "sim_background = light",
                                      "sim_scenes = %d" % ARGS.scenes])
            pairs = sorted(p for p in os.listdir(record) if p.isdigit())
            self.assertGreaterEqual(len(pairs), ARGS.scenes, "pairs recorded")
            with open(os.path.join(record, "settings.conf")) as f:
                settings = f.read()
            self.assertIn("background = light", settings)
            # The identity of the tables recognised with (the built-in ones' header CRC-32).
            self.assertRegex(settings, r"\ntables_crc32 = [0-9a-f]{8}\n")
            recorded = []
            for pair in pairs:
                with open(os.path.join(record, pair, "result.json")) as f:
                    recorded.append(json.load(f))
                self.assertEqual(recorded[-1]["background"], "light", pair)
            # The worst position and rotation difference of each replay. The board carries the
            # table plane through every frame it processed; a pair the recording's writer dropped
            # (its slot ring full: the writer yields to recognition) changes what the replay
            # carries, so the pairs after the first gap in the sequence count as pairs replayed
            # alone.
            worst = {"alone": [0.0, 0.0], "firmware": [0.0, 0.0]}
            objects = 0
            gap = next((k for k, rec in enumerate(recorded) if rec["sequence"] != k),
                       len(recorded))
            self.assertGreater(gap, 0, "the recording's first pair")

            def match(replay, pair, got, want):
                nonlocal objects
                self.assertEqual(sorted(n for n, _, _ in got), sorted(n for n, _, _ in want),
                                 "%s: models differ" % pair)
                for name, t, q in want:
                    best = min(((math.dist(t, gt), rotation_between_deg(q, gq))
                                for gn, gt, gq in got if gn == name), key=lambda e: e[0])
                    w = worst[replay]
                    w[0], w[1] = max(w[0], best[0]), max(w[1], best[1])
                    objects += 1

            # recognize --scene on each pair, without --background: the recorded preset.
            for pair, rec in zip(pairs, recorded):
                out = os.path.join(work, pair + ".json")
                subprocess.run([ARGS.stereohash, "recognize", "--scene",
                                os.path.join(record, pair), "--json", out],
                               check=True, stdout=subprocess.DEVNULL)
                with open(out) as f:
                    ref = json.load(f)
                match("alone", pair,
                      [(o["model"], o["t"], matrix_to_quat(o["R"])) for o in ref["objects"]],
                      [(o["model"], o["t_mm"], o["q_wxyz"]) for o in rec["objects"]])
            # The firmware replaying the recording (no background line: the recorded one).
            self.model_names = None
            replayed = self.run_firmware(record, len(pairs), work,
                                         source=["camera = directory",
                                                 "camera_directory = %s" % record])
            for k, (pair, rec, fw) in enumerate(zip(pairs, recorded, replayed)):
                names = self.model_names
                match("firmware" if k < gap else "alone", pair, [(names[o["model_id"]], o["t_mm"], o["q_wxyz"])
                             for o in fw["objects"]],
                      [(o["model"], o["t_mm"], o["q_wxyz"]) for o in rec["objects"]])
            print("simulator recording: %d pairs (%d in sequence), %d objects; the replay "
                  "in the simulator differs by at most %.4f mm, %.4f deg, recognize --scene (and "
                  "the pairs after a drop) by %.4f mm, %.4f deg"
                  % (len(pairs), gap, objects, *worst["firmware"], *worst["alone"]))
            sys.stdout.flush()
            self.assertGreater(objects, 0)
            self.assertLessEqual(worst["firmware"][0], ARGS.max_position_mm)
            self.assertLessEqual(worst["firmware"][1], ARGS.max_rotation_deg)
            # A pair recognised alone estimates the table plane that the board carried from the
            # frames before: the recording's own tolerance, not the JSON's rounding. The one-image
            # rescue's candidates rest on that plane before their edge fit, whose result keeps a
            # trace of where it started (0.06 deg on the simulator's recording).
            self.assertLessEqual(worst["alone"][0], ARGS.max_alone_position_mm)
            self.assertLessEqual(worst["alone"][1], ARGS.max_alone_rotation_deg)
            self.check_recorded_settings_refusals(record, pairs[0])
        finally:
            shutil.rmtree(work, ignore_errors=True)

    def check_recorded_settings_refusals(self, record, pair):
        """A recording whose model set or volume cannot be had again is refused by name, not
        replayed on other models or unbounded."""
        settings = os.path.join(record, "settings.conf")
        with open(settings) as f:
            original = f.read()

        def replay_error(extra):
            with open(settings, "w") as f:
                f.write(original + extra)
            proc = subprocess.run([ARGS.stereohash, "recognize", "--scene",
                                   os.path.join(record, pair)],
                                  stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
            self.assertNotEqual(proc.returncode, 0, extra)
            return proc.stderr

        self.assertIn("/nonexistent/models.bin", replay_error("tables = /nonexistent/models.bin\n"))
        # Tables rebuilt since the recording (another CRC-32) are refused, naming both values.
        self.assertIn("not the 0badcafe it was recognised with",
                      replay_error("tables_crc32 = 0badcafe\n"))
        self.assertIn("tables_crc32", replay_error("tables_crc32 = 0xnothex\n"))
        self.assertIn("volume_min_mm", replay_error("volume_min_mm = 1 2\n"))
        self.assertIn("below", replay_error("volume_min_mm = 0 0 400\n"))
        self.assertIn("volume_frame", replay_error("volume_frame = robot\n"))
        os.rename(os.path.join(record, "rig_table.yaml"), os.path.join(record, "moved.yaml"))
        self.assertIn("rig_table.yaml", replay_error(""))
        # A settings.conf that is a FIFO is refused at once, not waited on.
        os.remove(settings)
        os.mkfifo(settings)
        proc = subprocess.run([ARGS.stereohash, "recognize", "--scene", os.path.join(record, pair)],
                              stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                              timeout=60)
        self.assertNotEqual(proc.returncode, 0)
        self.assertIn("FIFO", proc.stderr)

    def compare(self, directory, scenes, firmware_results, work):
        worst_mm = worst_deg = 0.0
        objects = 0
        for k, scene in enumerate(scenes):
            fw = firmware_results[k]
            self.assertEqual(fw["status"], 0, "%s: firmware status %d" % (scene, fw["status"]))
            self.assertEqual(fw["output_frame"], "camera")
            out = os.path.join(work, "%s.json" % scene)
            subprocess.run([ARGS.stereohash, "recognize", "--scene",
                            os.path.join(directory, scene), "--json", out] + background_arg(),
                           check=True,
                           stdout=subprocess.DEVNULL)
            with open(out) as f:
                ref = json.load(f)
            self.assertEqual(ref["frame"], "camera")
            names = self.model_names
            fw_objects = [(names[o["model_id"]], o["t_mm"], o["q_wxyz"]) for o in fw["objects"]]
            ref_objects = [(o["model"], o["t"], matrix_to_quat(o["R"])) for o in ref["objects"]]
            self.assertEqual(sorted(n for n, _, _ in fw_objects),
                             sorted(n for n, _, _ in ref_objects), "%s: models differ" % scene)
            for name, t, R in fw_objects:
                best = min(((math.dist(t, rt), rotation_between_deg(R, rR))
                            for rn, rt, rR in ref_objects if rn == name), key=lambda e: e[0])
                worst_mm = max(worst_mm, best[0])
                worst_deg = max(worst_deg, best[1])
                objects += 1
            print("  %s: %d objects" % (scene, len(fw_objects)))
        print("replay of %s: %d pairs, %d objects, largest difference to recognize %.4f mm, "
              "%.4f deg" % (ARGS.set or "a rendered set", len(scenes), objects, worst_mm,
                            worst_deg))
        sys.stdout.flush()
        self.assertLessEqual(worst_mm, ARGS.max_position_mm)
        self.assertLessEqual(worst_deg, ARGS.max_rotation_deg)


def main():
    global ARGS
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--firmware", required=True)
    parser.add_argument("--stereohash", required=True, help="the stereohash host program")
    parser.add_argument("--set", help="recorded scene set (default: render one)")
    parser.add_argument("--scenes", type=int, default=4, help="scenes to render without --set")
    parser.add_argument("--background", default="automatic", choices=("automatic", "dark", "light"),
                        help="detector preset of both, or the automatic default")
    parser.add_argument("--max-position-mm", type=float, default=0.01)
    parser.add_argument("--max-rotation-deg", type=float, default=0.01)
    parser.add_argument("--max-alone-position-mm", type=float, default=0.05,
                        help="recognize --scene on a recorded pair whose board carried the plane")
    parser.add_argument("--max-alone-rotation-deg", type=float, default=0.1)
    parser.add_argument("--timeout", type=float, default=300)
    ARGS, rest = parser.parse_known_args()
    unittest.main(argv=[sys.argv[0]] + rest, verbosity=2)


if __name__ == "__main__":
    main()
