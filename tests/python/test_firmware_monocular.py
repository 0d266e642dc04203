#!/usr/bin/python3
"""The one-camera fallback of stereohash-fw-sim, seen from a PLC on the simulated CAN bus.

For each scene seed, starts `stereohash-fw-sim` with `sim_camera_fault = right_silent` or
`left_silent` (`--side`: that camera stops after three frames until the firmware restarts it) and
the recognition pipeline,
connects with python-can's socketcand client and decodes every frame with canmatrix from
firmware/stereohash.dbc. Checks: three stereo sets (status 0); then EMCY 0x7300 with the
one-camera detail (kind 4, the silent side) and no fault state; result sets with status 4,
which the DBC's value table names "monocular", whose poses match the renderer's ground truth
(modulo model symmetries); a clear-fault acknowledged with 0 and the error reset (EMCY 0x0000);
and stereo sets (status 0) again. Prints how many monocular poses were correct.
"""
import argparse
import os
import statistics
import sys
import time
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from test_can_socketcand import Plc  # noqa: E402 (skips without python-can)
from test_firmware_e2e import Firmware, nearest_truth  # noqa: E402

ARGS = None
NODE = 1
EMCY_SENSOR = 0x7300
SENSOR_ONE_CAMERA = 4
SIDES = {"left": 0, "right": 1}  # the side byte of the one-camera EMCY detail
STATE_FAULT = 3
STATUS_OK = 0
STATUS_MONOCULAR = 4
CMD_TRIGGER = 1
CMD_CLEAR_FAULT = 4


class MonocularFallbackTest(unittest.TestCase):
    def trigger(self, plc, fw, request_id):
        """One trigger: its header values, its objects (RO_* per index) and the RESULT line."""
        plc.send("SH_Command", {"CMD_Code": CMD_TRIGGER, "CMD_TriggerRequestId": request_id})
        frames = plc.receive_until(lambda n, v, m: n == "SH_ResultEnd", timeout=120)
        start = max(i for i, f in enumerate(frames) if f[0] == "SH_ResultHeader")
        header = frames[start][1]
        self.assertEqual(header["RH_RequestId"], request_id)
        objects = {}
        for k, (name, values, _) in enumerate(
                f for f in frames[start + 1:] if f[0] == "SH_ResultObject"):
            objects.setdefault(k // 4, {}).update(values)
        self.assertEqual(len(objects), int(header["RH_ObjectCount"]))
        return header, objects, frames, fw.result(request_id, timeout=60)

    def score(self, models, objects, truth):
        """Objects within the tolerances of a ground-truth object (each matched once), false."""
        correct = false = 0
        used = set()
        for got in objects.values():
            best = nearest_truth(models, got, truth, used)
            if best is None or best[1] > ARGS.max_position_error_mm or \
                    best[2] > ARGS.max_rotation_error_deg:
                false += 1
                continue
            used.add(best[0])
            correct += 1
            self.position_errors.append(best[1])
            self.rotation_errors.append(best[2])
        return correct, false

    def run_seed(self, seed):
        fw = Firmware(ARGS.firmware, "\n".join([
            "node_id = %d" % NODE, "heartbeat_ms = 100", "sim_port = 0", "sim_seed = %d" % seed,
            # Every scene is seen by the same fixed rig over one table, the pose the fallback lays
            # the objects onto; the sets go through several scenes.
            "sim_scenes = %d" % ARGS.scenes, "sim_objects = %d" % ARGS.objects,
            "budget_ms = 5000",
            "recognition = pipeline", "sim_camera_fault = %s_silent" % ARGS.side,
            "sim_wait_for_client = true", ""]))
        try:
            time.sleep(0.2)
            if fw.proc.poll() is not None:
                raise AssertionError("stereohash-fw exited:\n" + "\n".join(fw.stderr_lines))
            plc = Plc(fw.port, ARGS.dbc, NODE)
            try:
                self.session(fw, plc)
            finally:
                plc.close()
        finally:
            fw.stop()

    def session(self, fw, plc):
        plc.receive_until(lambda n, v, m: n == "SH_Heartbeat" and v["HB_NmtState"] == 5,
                          timeout=60)
        self.assertTrue(fw.models_seen.wait(30))
        status_names = plc.frame_def("SH_ResultHeader").signal_by_name("RH_Status").values
        request = 1
        for _ in range(3):  # frames 0..2: both cameras
            header, _, _, _ = self.trigger(plc, fw, request)
            self.assertEqual(header["RH_Status"], STATUS_OK)
            request += 1

        # One camera is silent: the warning, and this trigger answered from the other one.
        header, objects, frames, report = self.trigger(plc, fw, request)
        request += 1
        self.assertEqual(header["RH_Status"], STATUS_MONOCULAR, "\n".join(fw.stderr_lines[-5:]))
        self.assertEqual(status_names[int(header["RH_Status"])], "monocular")
        emcys = [v for n, v, _ in frames if n == "SH_Emcy" and v["EMCY_ErrorCode"] == EMCY_SENSOR]
        self.assertEqual(len(emcys), 1, "one EMCY 0x7300 for the failed camera")
        detail = int(emcys[0]["EMCY_Detail"])
        self.assertEqual(detail >> 24, SENSOR_ONE_CAMERA)
        self.assertEqual((detail >> 16) & 0xFF, SIDES[ARGS.side], "the %s camera" % ARGS.side)
        self.assertNotEqual(emcys[0]["EMCY_FirmwareState"], STATE_FAULT, "a warning, no fault")

        sets = [(objects, report)]
        for _ in range(ARGS.sets - 1):
            header, objects, frames, report = self.trigger(plc, fw, request)
            request += 1
            self.assertEqual(header["RH_Status"], STATUS_MONOCULAR)
            self.assertEqual([v for n, v, _ in frames if n == "SH_Emcy"], [])
            sets.append((objects, report))
        for objects, report in sets:
            truth = report["truth"]
            correct, false = self.score(fw.models, objects, truth)
            self.truth_objects += len(truth)
            self.correct += correct
            self.false += false
            self.reported += len(objects)

        plc.send("SH_Command", {"CMD_Code": CMD_CLEAR_FAULT})
        frames = plc.receive_until(
            lambda n, v, m: n == "SH_CommandAck" and v["ACK_CommandCode"] == CMD_CLEAR_FAULT,
            timeout=60)
        self.assertEqual(frames[-1][1]["ACK_Status"], 0, "\n".join(fw.stderr_lines[-5:]))
        frames = plc.receive_until(
            lambda n, v, m: n == "SH_Emcy" and v["EMCY_ErrorCode"] == 0, timeout=30)
        self.assertEqual(frames[-1][1]["EMCY_ErrorRegister"], 0)
        for _ in range(2):
            header, _, _, _ = self.trigger(plc, fw, request)
            request += 1
            self.assertEqual(header["RH_Status"], STATUS_OK, "stereo again")

    def test_one_camera_silent(self):
        self.truth_objects = self.correct = self.false = self.reported = 0
        self.position_errors, self.rotation_errors = [], []
        for seed in ARGS.seeds:
            self.run_seed(seed)
        print("\nmonocular fallback, %s camera silent: %d seeds x %d sets: %d of %d ground-truth objects within "
              "%.1f mm / %.1f deg, %d of %d reported objects false"
              % (ARGS.side, len(ARGS.seeds), ARGS.sets, self.correct, self.truth_objects,
                 ARGS.max_position_error_mm, ARGS.max_rotation_error_deg, self.false,
                 self.reported))
        if self.position_errors:
            print("  correct ones: position median %.2f mm, max %.2f mm; rotation median %.2f deg, "
                  "max %.2f deg" % (statistics.median(self.position_errors),
                                    max(self.position_errors),
                                    statistics.median(self.rotation_errors),
                                    max(self.rotation_errors)))
        sys.stdout.flush()
        self.assertGreaterEqual(self.correct, ARGS.min_recall * self.truth_objects)
        self.assertLessEqual(self.false, ARGS.max_false_fraction * self.reported)


def main():
    global ARGS
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--firmware", required=True, help="path of stereohash-fw-sim")
    parser.add_argument("--dbc", required=True)
    parser.add_argument("--seeds", type=lambda s: [int(v) for v in s.split(",")],
                        default=[1, 2, 3], help="scene seeds, one firmware run each")
    parser.add_argument("--sets", type=int, default=4, help="monocular sets per seed")
    parser.add_argument("--objects", type=int, default=3)
    parser.add_argument("--scenes", type=int, default=4, help="sim_scenes")
    parser.add_argument("--side", choices=sorted(SIDES), default="right",
                        help="the camera that goes silent")
    parser.add_argument("--max-position-error-mm", type=float, default=5.0)
    parser.add_argument("--max-rotation-error-deg", type=float, default=5.0)
    parser.add_argument("--min-recall", type=float, default=0.6)
    parser.add_argument("--max-false-fraction", type=float, default=0.2)
    ARGS, rest = parser.parse_known_args()
    unittest.main(argv=[sys.argv[0]] + rest, verbosity=2)


if __name__ == "__main__":
    main()
