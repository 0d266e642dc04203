#!/usr/bin/python3
"""End-to-end test of stereohash-fw-sim, seen from a PLC on the simulated CAN bus.

Starts `stereohash-fw-sim` in its own process, connects with python-can's socketcand client,
waits for the boot-up and heartbeats, triggers N recognitions, decodes every frame with canmatrix
from firmware/stereohash.dbc (independently of the C++ decoders), checks sequence counters,
frame counts and CRC-8 (no frame lost), compares the decoded poses with what the firmware encoded
and with the renderer's ground truth (modulo model symmetries), and reports the errors and the
trigger-to-last-frame latency (median, p99).

With --result-mode pdo or both the PLC reads the poses the way a PLC with a fixed PDO image does:
after each result header it asks for object 0, 1, ... through RPDO2 (a request counter and the
object index) and takes the answer from TPDO5..8 once both copies of the counter came back. In
mode both the stream runs beside it and every answered pose must equal the stream's.

With --printed STEREOHASH (the tools program) the scenes also hold the printed cartons of
models/textured: the program learns their feature database (`stereohash tables build`), the
firmware maps it (`features`) and reports the cartons with the model ids after the tables'
polyhedra, and every carton of the ground truth must be found (--min-printed-recall). Counts
are printed per model. --config-line adds configuration lines (repeatable).

With --colour STEREOHASH the scenes also hold single-colour parts (the can and the bracket of
models/colour, `sim_colour_models`), which the simulated cameras deliver as NV12 colour frames:
the program builds one model set of the six polyhedra and the two parts (HASH3D and SHAPE_VIEWS,
`tables`), the firmware reports the parts with the model ids after the polyhedra, and every part
of the ground truth must be found (--min-colour-recall), none reported where the truth has none.
"""
import argparse
import json
import math
import os
import queue
import statistics
import subprocess
import sys
import tempfile
import threading
import time
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from test_can_socketcand import Plc, crc8, POSITION_LSB_MM, QUATERNION_LSB  # noqa: E402 (skips without python-can)

ARGS = None
NODE = 1


class Firmware:
    """stereohash-fw-sim and its stdout lines (SOCKETCAND_PORT, MODELS, RESULT, EMCY, STATE,
    HTTP_PORT)."""

    def __init__(self, binary, config_text):
        self.config = tempfile.NamedTemporaryFile("w", suffix=".conf", delete=False)
        self.config.write(config_text)
        self.config.close()
        self.proc = subprocess.Popen([binary, "--config", self.config.name],
                                     stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                     bufsize=1)
        self.results = queue.Queue()
        self.emcys = queue.Queue()
        self.models = None
        self.port = None
        self.http_port = None  # the web page's, printed once the core runs
        self.stderr_lines = []
        port_seen, models_seen = threading.Event(), threading.Event()
        self.http_seen = threading.Event()

        def read_stdout():
            for line in self.proc.stdout:
                line = line.strip()
                if line.startswith("SOCKETCAND_PORT="):
                    self.port = int(line.split("=", 1)[1])
                    port_seen.set()
                elif line.startswith("MODELS "):
                    self.models = json.loads(line.split(" ", 1)[1])
                    models_seen.set()
                elif line.startswith("RESULT "):
                    self.results.put(json.loads(line.split(" ", 1)[1]))
                elif line.startswith("EMCY "):
                    self.emcys.put(json.loads(line.split(" ", 1)[1]))
                elif line.startswith("HTTP_PORT="):
                    self.http_port = int(line.split("=", 1)[1])
                    self.http_seen.set()
            port_seen.set()
            models_seen.set()
            self.http_seen.set()

        def read_stderr():
            for line in self.proc.stderr:
                self.stderr_lines.append(line.rstrip())

        threading.Thread(target=read_stdout, daemon=True).start()
        threading.Thread(target=read_stderr, daemon=True).start()
        self.models_seen = models_seen
        if not port_seen.wait(120) or self.port is None:
            self.stop()
            raise RuntimeError("stereohash-fw did not report SOCKETCAND_PORT:\n" +
                               "\n".join(self.stderr_lines[-20:]))

    def result(self, request_id, timeout=30.0):
        deadline = time.time() + timeout
        while time.time() < deadline:
            try:
                r = self.results.get(timeout=max(0.01, deadline - time.time()))
            except queue.Empty:
                break
            if r["request_id"] == request_id:
                return r
        raise AssertionError("no RESULT line for request %d" % request_id)

    def stop(self):
        if self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(20)
            except subprocess.TimeoutExpired:
                self.proc.kill()
        os.unlink(self.config.name)


def quat_to_matrix(w, x, y, z):
    n = math.sqrt(w * w + x * x + y * y + z * z)
    w, x, y, z = w / n, x / n, y / n, z / n
    return [[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]]


def matmul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3)] for i in range(3)]


def transpose(a):
    return [[a[j][i] for j in range(3)] for i in range(3)]


def apply(R, t, p):
    return [sum(R[i][k] * p[k] for k in range(3)) + t[i] for i in range(3)]


def angle_deg(R):
    c = max(-1.0, min(1.0, (R[0][0] + R[1][1] + R[2][2] - 1.0) / 2.0))
    return math.degrees(math.acos(c))


def nearest_truth(models, got, truth, used):
    """The unused ground-truth object of the decoded object's model (RO_* values) nearest to it:
    (index, position error in mm at the corner centroid, rotation error in degrees modulo the
    model's symmetries), or None when there is none."""
    model = int(got["RO_ModelId"])
    R = quat_to_matrix(*[got["RO_Quat" + a] for a in "WXYZ"])
    t = [got["RO_Position" + a] for a in "XYZ"]
    c = models["centroids_mm"][model]
    p = apply(R, t, c)
    best = None
    for j, tr in enumerate(truth):
        if j in used or tr["model_id"] != model:
            continue
        Rt = [tr["R"][0:3], tr["R"][3:6], tr["R"][6:9]]
        dp = math.dist(p, apply(Rt, tr["t_mm"], c))
        da = min(angle_deg(matmul(transpose(R), matmul(Rt, [s[0:3], s[3:6], s[6:9]])))
                 for s in models["symmetries"][model])
        if best is None or dp < best[1]:
            best = (j, dp, da)
    return best


def percentile(values, p):
    s = sorted(values)
    return s[min(len(s) - 1, int(math.ceil(p / 100.0 * len(s))) - 1)]


class FirmwareEndToEndTest(unittest.TestCase):
    def test_triggers_over_socketcand(self):
        recognition = ARGS.recognition
        fw = Firmware(ARGS.firmware, "\n".join([
            "node_id = %d" % NODE, "heartbeat_ms = 100", "sim_port = 0",
            "sim_seed = %d" % ARGS.seed,
            "sim_scenes = %d" % ARGS.scenes, "sim_objects = %d" % ARGS.objects,
            "budget_ms = 2000",
            "recognition = %s" % recognition, "sim_wait_for_client = true",
            "result_mode = %s" % ARGS.result_mode] + self.printed_lines() +
            self.colour_lines() + ARGS.config_line + [""]))
        try:
            time.sleep(0.2)
            if fw.proc.poll() is not None:
                raise AssertionError("stereohash-fw exited:\n" + "\n".join(fw.stderr_lines))
            plc = Plc(fw.port, ARGS.dbc, NODE)
            try:
                self.run_session(fw, plc, recognition)
            finally:
                plc.close()
        finally:
            fw.stop()

    counter = 0

    def printed_lines(self):
        """Configuration lines of the printed cartons (--printed), their database learnt here."""
        if not ARGS.printed:
            return []
        root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
        self.features_dir = tempfile.TemporaryDirectory()
        self.addCleanup(self.features_dir.cleanup)
        features = os.path.join(self.features_dir.name, "cartons.bin")
        models = os.path.join(root, "models", "textured")
        self.printed_names = {f[:-4] for f in os.listdir(models) if f.endswith(".obj")}
        subprocess.run([ARGS.printed, "tables", "build", "--models", models, "--out", features],
                       check=True, stdout=subprocess.DEVNULL)
        return ["features = %s" % features, "sim_printed_models = %s" % models]

    def colour_lines(self):
        """Configuration lines of the colour parts (--colour): one model set of the polyhedra of
        models/ and the can and bracket of models/colour, and those parts in the scenes."""
        if not ARGS.colour:
            return []
        root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
        self.colour_dir = tempfile.TemporaryDirectory()
        self.addCleanup(self.colour_dir.cleanup)
        both = os.path.join(self.colour_dir.name, "mixed")
        parts = os.path.join(self.colour_dir.name, "parts")
        os.mkdir(both)
        os.mkdir(parts)
        polyhedra = ["cube", "hexagon", "pentagon", "star", "trapezium", "wedge"]
        self.colour_names = {"can", "bracket"}
        for name in polyhedra:
            os.symlink(os.path.join(root, "models", name + ".obj"),
                       os.path.join(both, name + ".obj"))
        for name in sorted(self.colour_names):
            for ext in (".obj", ".mtl"):
                src = os.path.join(root, "models", "colour", name + ext)
                os.symlink(src, os.path.join(both, name + ext))
                os.symlink(src, os.path.join(parts, name + ext))
        with open(os.path.join(both, "models.txt"), "w") as f:
            f.write("\n".join(polyhedra + ["can", "bracket"]) + "\n")
        model_set = os.path.join(self.colour_dir.name, "mixed.bin")
        subprocess.run([ARGS.colour, "tables", "build", "--models", both, "--out", model_set],
                       check=True, stdout=subprocess.DEVNULL)
        return ["tables = %s" % model_set, "sim_colour_models = %s" % parts]

    def request_object(self, plc, sequence, count, index):
        """The PDO handshake for one object: RPDO2 out, TPDO5..8 back; fields as RO_* names."""
        self.counter = (self.counter + 1) & 0xFF
        counter = self.counter
        sent = time.time()
        plc.send("SH_ObjectRequest", {"REQ_Counter": counter, "REQ_ObjectIndex": index})
        frames = plc.receive_until(
            lambda n, v, m: n == "SH_AnswerQuat" and v["AN_CounterEnd"] == counter, timeout=10)
        self.handshake_ms.append((time.time() - sent) * 1000.0)
        answer = {}
        for name, values, _ in frames:
            if name in ("SH_AnswerHeader", "SH_AnswerPosition", "SH_AnswerZQuat",
                        "SH_AnswerQuat"):
                answer[name] = values
        self.assertEqual(len(answer), 4, "answer incomplete: %s" % sorted(answer))
        head, quat = answer["SH_AnswerHeader"], answer["SH_AnswerQuat"]
        self.assertEqual(head["AN_Counter"], counter, "first and last frame of one answer")
        self.assertEqual(head["AN_Status"], 0)
        self.assertEqual(head["AN_ObjectIndex"], index)
        self.assertEqual(head["AN_SequenceLow"], sequence & 0xFF, "answer from another set")
        self.assertEqual(quat["AN_ObjectCount"], count)
        pos, zq = answer["SH_AnswerPosition"], answer["SH_AnswerZQuat"]
        return {"RO_ModelId": head["AN_ModelId"], "RO_Instance": head["AN_Instance"],
                "RO_Score": head["AN_Score"], "RO_PositionX": pos["AN_PositionX"],
                "RO_PositionY": pos["AN_PositionY"], "RO_PositionZ": zq["AN_PositionZ"],
                "RO_QuatW": zq["AN_QuatW"], "RO_QuatX": zq["AN_QuatX"],
                "RO_QuatY": quat["AN_QuatY"], "RO_QuatZ": quat["AN_QuatZ"]}

    def run_session(self, fw, plc, recognition):
        mode = ARGS.result_mode
        self.handshake_ms = []
        stream_vs_pdo_mm, stream_vs_pdo_deg = [], []
        startup = plc.receive_until(
            lambda n, v, m: n == "SH_Heartbeat" and v["HB_NmtState"] == 5, timeout=60)
        hb = [v["HB_NmtState"] for n, v, _ in startup if n == "SH_Heartbeat"]
        self.assertEqual(hb[0], 0, "boot-up first")
        self.assertTrue(fw.models_seen.wait(30))
        models = fw.models
        self.assertIsNotNone(models)

        latencies_ms, processing_ms = [], []
        position_errors, rotation_errors = [], []
        truth_objects = matched = false_positives = 0
        truth_per_model, found_per_model, false_per_model = {}, {}, {}
        heartbeats = 0
        last_sequence = None
        for request_id in range(1, ARGS.triggers + 1):
            sent = time.time()
            plc.send("SH_Command", {"CMD_Code": 1, "CMD_TriggerRequestId": request_id})
            if mode == "pdo":  # the header closes what the PLC waits for; no stream follows
                frames = plc.receive_until(
                    lambda n, v, m: n == "SH_ResultHeader" and v["RH_RequestId"] == request_id,
                    timeout=30)
            else:
                frames = plc.receive_until(
                    lambda n, v, m: n == "SH_ResultEnd", timeout=30)
            arrived = time.time()
            heartbeats += sum(1 for n, _, _ in frames if n == "SH_Heartbeat")
            emcys = [v for n, v, _ in frames if n == "SH_Emcy"]
            self.assertEqual(emcys, [], "EMCY during trigger %d" % request_id)
            # The ack of an accepted trigger is on the bus before its result set.
            acks = [i for i, (n, v, _) in enumerate(frames) if n == "SH_CommandAck" and
                    v["ACK_RequestId"] == request_id and v["ACK_Status"] == 0]
            self.assertTrue(acks, "no ack for trigger %d" % request_id)
            start = max(i for i, f in enumerate(frames) if f[0] == "SH_ResultHeader")
            self.assertLess(acks[0], start, "result set overtook the ack of trigger %d" % request_id)
            set_frames = [f for f in frames[start:] if f[0] in
                          ("SH_ResultHeader", "SH_ResultObject", "SH_ResultEnd")]
            header, end = set_frames[0][1], set_frames[-1][1]
            self.assertEqual(header["RH_RequestId"], request_id)
            sequence = int(header["RH_Sequence"])
            if last_sequence is not None:
                self.assertEqual(sequence, (last_sequence + 1) & 0xFFFF, "sequence gap")
            last_sequence = sequence
            count = int(header["RH_ObjectCount"])
            objects = {}
            if mode != "pdo":
                self.assertEqual(len(set_frames), 2 + 4 * count,
                                 "frames lost in set %d" % sequence)
                self.assertEqual(int(end["RE_Sequence"]), sequence)
                self.assertEqual(int(end["RE_ObjectCount"]), count)
                self.assertEqual(int(end["RE_OutputFrame"]), 0, "camera frame")
                crc = 0
                for _, _, msg in set_frames[:-1]:
                    crc = crc8(msg.data, crc)
                self.assertEqual(int(end["RE_Crc8"]), crc)
                for k, (_, values, _) in enumerate(set_frames[1:-1]):
                    self.assertEqual(values["RO_ObjectIndex"], k // 4)
                    self.assertEqual(values["RO_Part"], k % 4)
                    objects.setdefault(k // 4, {}).update(values)
            latencies_ms.append((arrived - sent) * 1000.0)
            processing_ms.append(header["RH_ProcessingTime"])
            if mode != "stream":
                # The PLC's view: only the PDOs. In mode both, each pose equals the stream's.
                answered = {i: self.request_object(plc, sequence, count, i) for i in range(count)}
                for i, got in answered.items():
                    if mode == "both":
                        ref = objects[i]
                        self.assertEqual(got["RO_ModelId"], ref["RO_ModelId"])
                        self.assertEqual(got["RO_Instance"], ref["RO_Instance"])
                        stream_vs_pdo_mm.append(math.dist(
                            [got["RO_Position" + a] for a in "XYZ"],
                            [ref["RO_Position" + a] for a in "XYZ"]))
                        Rg = quat_to_matrix(*[got["RO_Quat" + a] for a in "WXYZ"])
                        Rr = quat_to_matrix(*[ref["RO_Quat" + a] for a in "WXYZ"])
                        stream_vs_pdo_deg.append(angle_deg(matmul(transpose(Rg), Rr)))
                objects = answered

            report = fw.result(request_id)
            self.assertEqual(report["sequence"], sequence)
            self.assertEqual(len(report["objects"]), count)
            truth = report.get("truth", [])
            truth_objects += len(truth)
            for tr in truth:
                truth_per_model[tr["model_id"]] = truth_per_model.get(tr["model_id"], 0) + 1
            used = set()
            for index, expected in enumerate(report["objects"]):
                got = objects[index]
                # What went over the bus is what the firmware encoded.
                self.assertEqual(got["RO_ModelId"], expected["model_id"])
                for axis, value in zip("XYZ", expected["t_mm"]):
                    self.assertAlmostEqual(got["RO_Position" + axis], value,
                                           delta=POSITION_LSB_MM / 2 + 1e-9)
                q = [got["RO_Quat" + a] for a in "WXYZ"]
                eq = expected["q_wxyz"]
                sign = -1.0 if eq[0] < 0 else 1.0
                for a, b in zip(q, eq):
                    self.assertAlmostEqual(a, sign * b, delta=QUATERNION_LSB / 2 + 1e-12)
                # Against the renderer's ground truth, modulo the model's symmetries.
                model = int(got["RO_ModelId"])
                best = nearest_truth(models, got, truth, used)
                if best is None or best[1] > ARGS.max_position_error_mm or \
                        best[2] > ARGS.max_rotation_error_deg:
                    false_positives += 1
                    false_per_model[model] = false_per_model.get(model, 0) + 1
                    if ARGS.verbose:
                        print("  not matching: trigger %d, %s at %s mm; nearest of its model: %s; "
                              "truth: %s" % (
                                  sequence, models["names"][model],
                                  ["%.1f" % got["RO_Position" + a] for a in "XYZ"],
                                  "none" if best is None else "%.1f mm, %.1f deg" % best[1:],
                                  ", ".join("%s at %s" % (models["names"][tr["model_id"]],
                                                          ["%.1f" % v for v in tr["t_mm"]])
                                            for tr in truth)))
                    continue
                used.add(best[0])
                matched += 1
                found_per_model[model] = found_per_model.get(model, 0) + 1
                position_errors.append(best[1])
                rotation_errors.append(best[2])

        recall = matched / truth_objects if truth_objects else 0.0
        print("\nstereohash-fw e2e (recognition = %s): %d triggers, %d result sets, sequences "
              "consecutive, CRC ok" % (recognition, ARGS.triggers, len(latencies_ms)))
        print("  trigger -> last frame latency: median %.1f ms, p99 %.1f ms, max %.1f ms"
              % (statistics.median(latencies_ms), percentile(latencies_ms, 99),
                 max(latencies_ms)))
        print("  firmware processing time: median %.1f ms, p99 %.1f ms"
              % (statistics.median(processing_ms), percentile(processing_ms, 99)))
        print("  objects: %d in the ground truth, %d found, %d not matching any (recall %.2f)"
              % (truth_objects, matched, false_positives, recall))
        name = lambda m: models["names"][m] if 0 <= m < len(models["names"]) else str(m)  # noqa: E731
        print("  per model (found / in the ground truth, not matching any): " + ", ".join(
            "%s %d/%d %d" % (name(m), found_per_model.get(m, 0), truth_per_model.get(m, 0),
                             false_per_model.get(m, 0))
            for m in sorted(set(truth_per_model) | set(false_per_model))))
        if position_errors:
            print("  pose error of found objects: position median %.2f mm, max %.2f mm; "
                  "rotation median %.2f deg, max %.2f deg"
                  % (statistics.median(position_errors), max(position_errors),
                     statistics.median(rotation_errors), max(rotation_errors)))
        # Short runs (ground-truth recognition) can end before the first heartbeat period: the
        # heartbeat must still be there afterwards.
        if heartbeats == 0:
            frames = plc.receive_until(lambda n, v, m: n == "SH_Heartbeat", timeout=15.0)
            heartbeats += sum(1 for n, _, _ in frames if n == "SH_Heartbeat")
        print("  heartbeats seen during the run: %d" % heartbeats)
        if self.handshake_ms:
            print("  PDO handshake (request -> last answer frame): %d objects, median %.1f ms, "
                  "max %.1f ms" % (len(self.handshake_ms), statistics.median(self.handshake_ms),
                                   max(self.handshake_ms)))
        if stream_vs_pdo_mm:
            print("  PDO answers vs stream: position max %.4f mm, rotation max %.4f deg"
                  % (max(stream_vs_pdo_mm), max(stream_vs_pdo_deg)))
            self.assertLessEqual(max(stream_vs_pdo_mm), 1.0)
            self.assertLessEqual(max(stream_vs_pdo_deg), 1.0)
        sys.stdout.flush()
        self.assertEqual(len(latencies_ms), ARGS.triggers)
        self.assertGreater(heartbeats, 0)
        self.assertEqual(false_positives, 0, "reported objects with no ground-truth partner")
        self.assertGreaterEqual(recall, ARGS.min_recall)
        if ARGS.printed:
            printed = [m for m, n in enumerate(models["names"]) if n in self.printed_names]
            truth_printed = sum(truth_per_model[m] for m in printed)
            found_printed = sum(found_per_model.get(m, 0) for m in printed)
            print("  printed cartons: %d of %d found" % (found_printed, truth_printed))
            self.assertGreater(truth_printed, 0, "no carton in the scenes")
            self.assertGreaterEqual(found_printed, ARGS.min_printed_recall * truth_printed)
            self.assertEqual(sum(false_per_model.get(m, 0) for m in printed), 0,
                             "cartons reported where the truth has none")
        if ARGS.colour:
            colour = [m for m, n in enumerate(models["names"]) if n in self.colour_names]
            self.assertEqual(colour, [6, 7], "colour parts follow the six polyhedra")
            truth_colour = sum(truth_per_model.get(m, 0) for m in colour)
            found_colour = sum(found_per_model.get(m, 0) for m in colour)
            print("  colour parts: %d of %d found" % (found_colour, truth_colour))
            self.assertGreater(truth_colour, 0, "no colour part in the scenes")
            self.assertGreaterEqual(found_colour, ARGS.min_colour_recall * truth_colour)
            self.assertEqual(sum(false_per_model.get(m, 0) for m in colour), 0,
                             "colour parts reported where the truth has none")


def main():
    global ARGS
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--firmware", required=True, help="path of stereohash-fw-sim")
    parser.add_argument("--dbc", required=True)
    parser.add_argument("--triggers", type=int, default=50)
    parser.add_argument("--recognition", default="pipeline", choices=("pipeline", "truth"))
    parser.add_argument("--result-mode", default="stream", choices=("stream", "pdo", "both"),
                        help="how the PLC reads the poses: the stream, or PDO requests")
    parser.add_argument("--max-position-error-mm", type=float, default=5.0)
    parser.add_argument("--max-rotation-error-deg", type=float, default=3.0)
    parser.add_argument("--min-recall", type=float, default=0.8)
    parser.add_argument("--scenes", type=int, default=5, help="sim_scenes")
    parser.add_argument("--seed", type=int, default=7, help="sim_seed")
    parser.add_argument("--objects", type=int, default=3, help="sim_objects")
    parser.add_argument("--printed", help="path of the stereohash tools program: add the "
                        "printed cartons of models/textured")
    parser.add_argument("--min-printed-recall", type=float, default=1.0)
    parser.add_argument("--colour", help="path of the stereohash tools program: add the colour "
                        "parts can and bracket of models/colour")
    parser.add_argument("--min-colour-recall", type=float, default=1.0)
    parser.add_argument("--verbose", action="store_true",
                        help="print each reported object that matches no ground truth")
    parser.add_argument("--config-line", action="append", default=[],
                        help="a configuration line added to the simulator's file (repeatable)")
    ARGS, rest = parser.parse_known_args()
    unittest.main(argv=[sys.argv[0]] + rest, verbosity=2)


if __name__ == "__main__":
    main()
