#!/usr/bin/python3
"""Boot-path faults of the firmware, run through the real main() of stereohash-fw-sim.

Each case starts `stereohash-fw-sim --config FILE` with one piece of its data broken (a
missing, truncated or corrupt table file, a model set with a damaged section, the injected
corrupt tables, a missing calibration, a missing model folder, a table pose or hand-eye file
that is missing, a FIFO or malformed) and checks, from a python-can/socketcand PLC: the
boot-up, an EMCY naming the fault with the firmware state "fault", heartbeats that keep coming
while the process stays alive, and - once the file is repaired - a clear-fault command that is
acknowledged, an EMCY 0x0000 back to "ready" and a trigger that gets its result set. The table
pose and hand-eye files are read at boot only: there the clear-fault is refused and a restart
after the repair brings the node up ready.
"""
import argparse
import os
import shutil
import socket
import struct
import sys
import zlib
import tempfile
import time
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from test_can_socketcand import Plc  # noqa: E402 (skips without python-can)
from test_firmware_e2e import Firmware  # noqa: E402

ARGS = None
NODE = 1
HEARTBEAT_MS = 100
EMCY_DATA_SET = 0x6300
EMCY_SENSOR = 0x7300
DETAIL_TABLES = 1
DETAIL_CALIBRATION = 2
DETAIL_FEATURES = 5
DETAIL_CELL_GEOMETRY = 6
OUTPUT_FRAME_ROBOT_BASE = 2
STATE_READY = 1
STATE_FAULT = 3
CMD_TRIGGER = 1
CMD_CLEAR_FAULT = 4
ACK_NOT_POSSIBLE = 8

def model_set(sections):
    """A model set of (kind, blob) sections, packed from the layout in docs/tables.md."""
    def align(n):
        return (n + 63) // 64 * 64
    offset = align(64 + 32 * len(sections))
    directory, payloads = b"", []
    for kind, blob in sections:
        version = struct.unpack_from("<H", blob, 8)[0]
        directory += struct.pack("<IHHQQII", kind, version, 0, offset, len(blob),
                                 zlib.crc32(blob), 0)
        payloads.append((offset, blob))
        offset = align(offset + len(blob))
    out = bytearray(offset)
    out[64:64 + len(directory)] = directory
    for at, blob in payloads:
        out[at:at + len(blob)] = blob
    struct.pack_into("<8sHHIQIII", out, 0, b"SHMODSET", 1, 0, 64, offset, 0, len(sections), 32)
    struct.pack_into("<I", out, 24, zlib.crc32(bytes(out)))
    return bytes(out)


# The simulator rig's cameras (hal/sim/render/scene_generator.cpp, MakeRig) as a calibration file.
SIM_RIG_YAML = """%YAML:1.0
---
image_width: 756
image_height: 581
K1: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 1136.4, 0., 379.2, 0., 1136.4, 289.6, 0., 0., 1. ]
D1: !!opencv-matrix
   rows: 1
   cols: 5
   dt: d
   data: [ -0.10, 0.06, 0.0002, -0.0001, 0. ]
K2: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 1131.8, 0., 375.9, 0., 1131.8, 292.3, 0., 0., 1. ]
D2: !!opencv-matrix
   rows: 1
   cols: 5
   dt: d
   data: [ -0.095, 0.05, -0.0001, 0.0002, 0. ]
R: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 1., 0., 0., 0., 1., 0., 0., 0., 1. ]
T: !!opencv-matrix
   rows: 3
   cols: 1
   dt: d
   data: [ -120., 0., 0. ]
"""

# A hand-eye file of `stereohash calibrate-handeye` (docs/firmware.md): cameras fixed in the cell,
# 1 m above the robot base.
GOOD_HANDEYE_YAML = """%YAML:1.0
---
eye_in_hand: 0
R_robot_camera: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 1., 0., 0., 0., -1., 0., 0., 0., -1. ]
t_robot_camera: !!opencv-matrix
   rows: 3
   cols: 1
   dt: d
   data: [ 400., 0., 1000. ]
"""

# Not YAML the parser accepts: the rotation's data cut short.
MALFORMED_TABLE_YAML = """%YAML:1.0
---
R_table: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 1., 0., 0., 0., -1.
"""


class BootFaultTest(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp(prefix="stereohash-boot-")
        self.fw = None
        self.plc = None

    def tearDown(self):
        if self.plc is not None:
            self.plc.close()
        if self.fw is not None:
            self.fw.stop()
        shutil.rmtree(self.dir, ignore_errors=True)

    def path(self, name):
        return os.path.join(self.dir, name)

    def boot(self, *extra):
        self.fw = Firmware(ARGS.firmware, "\n".join([
            "node_id = %d" % NODE, "heartbeat_ms = %d" % HEARTBEAT_MS, "sim_port = 0",
            "sim_seed = 3", "sim_scenes = 2", "sim_objects = 2", "recognition = truth",
            "sim_wait_for_client = true"] + list(extra) + [""]))
        # python-can retries a refused connection for ever: make sure the server is there.
        deadline = time.time() + 60
        while True:
            self.assertIsNone(self.fw.proc.poll(), "stereohash-fw exited (rc %s) at boot:\n%s" % (
                self.fw.proc.returncode, "\n".join(self.fw.stderr_lines[-20:])))
            try:
                socket.create_connection(("127.0.0.1", self.fw.port), timeout=1).close()
                break
            except OSError:
                self.assertLess(time.time(), deadline, "socketcand server never accepted")
                time.sleep(0.1)
        self.plc = Plc(self.fw.port, ARGS.dbc, NODE)
        frames = self.plc.receive_until(lambda n, v, m: n == "SH_Heartbeat", timeout=60)
        self.assertEqual(frames[-1][1]["HB_NmtState"], 0, "boot-up first")

    def expect_fault(self, code, detail=None):
        """The fault EMCY, then heartbeats from a process that stays alive."""
        frames = self.plc.receive_until(
            lambda n, v, m: n == "SH_Emcy" and v["EMCY_ErrorCode"] == code and
            (detail is None or v["EMCY_Detail"] == detail), timeout=60)
        self.assertEqual(frames[-1][1]["EMCY_FirmwareState"], STATE_FAULT)
        self.expect_alive()

    def expect_alive(self, heartbeats=10):
        """`heartbeats` more heartbeats (a second at HEARTBEAT_MS) from a process still running
        after them; a heartbeat that stops fails within ten times that."""
        seen = 0
        watch_until = time.time() + 10.0
        while seen < heartbeats and time.time() < watch_until:
            msg = self.plc.bus.recv(0.1)
            if msg is not None and self.plc.decode(msg)[0] == "SH_Heartbeat":
                seen += 1
        self.assertIsNone(self.fw.proc.poll(), "stereohash-fw exited (rc %s) in fault:\n%s" % (
            self.fw.proc.returncode, "\n".join(self.fw.stderr_lines[-20:])))
        self.assertEqual(seen, heartbeats, "heartbeat stopped in fault")

    def clear_fault(self):
        self.plc.send("SH_Command", {"CMD_Code": CMD_CLEAR_FAULT})
        frames = self.plc.receive_until(
            lambda n, v, m: n == "SH_CommandAck" and v["ACK_CommandCode"] == CMD_CLEAR_FAULT,
            timeout=60)
        return frames[-1][1]["ACK_Status"]

    def expect_recovery(self):
        self.assertEqual(self.clear_fault(), 0, "\n".join(self.fw.stderr_lines[-20:]))
        frames = self.plc.receive_until(
            lambda n, v, m: n == "SH_Emcy" and v["EMCY_ErrorCode"] == 0, timeout=30)
        self.assertEqual(frames[-1][1]["EMCY_FirmwareState"], STATE_READY)
        self.plc.send("SH_Command", {"CMD_Code": CMD_TRIGGER, "CMD_TriggerRequestId": 7})
        frames = self.plc.receive_until(lambda n, v, m: n == "SH_ResultEnd", timeout=60)
        headers = [v for n, v, _ in frames if n == "SH_ResultHeader"]
        self.assertEqual(headers[-1]["RH_RequestId"], 7)
        self.assertEqual(headers[-1]["RH_Status"], 0)

    def table_case(self, write_broken_table):
        table = self.path("tables.bin")
        write_broken_table(table)
        self.boot("tables = " + table)
        self.expect_fault(EMCY_DATA_SET, DETAIL_TABLES)
        shutil.copyfile(ARGS.table, table)
        self.expect_recovery()

    def test_missing_table_file(self):
        self.table_case(lambda path: None)

    def test_truncated_table_file(self):
        def write(path):
            with open(ARGS.table, "rb") as f:
                blob = f.read()
            with open(path, "wb") as f:
                f.write(blob[:len(blob) // 2])
        self.table_case(write)

    def test_corrupt_table_file(self):
        def write(path):
            with open(ARGS.table, "rb") as f:
                blob = bytearray(f.read())
            blob[len(blob) // 2] ^= 0x10
            with open(path, "wb") as f:
                f.write(blob)
        self.table_case(write)

    def test_damaged_model_set_section(self):
        """A model set (docs/tables.md) holding the tables: a flipped byte in its section is a
        tables fault; the repaired set boots to ready."""
        with open(ARGS.table, "rb") as f:
            good = model_set([(1, f.read())])
        damaged = bytearray(good)
        damaged[len(damaged) // 2] ^= 0x10
        table = self.path("models.bin")
        with open(table, "wb") as f:
            f.write(damaged)
        self.boot("tables = " + table)
        self.expect_fault(EMCY_DATA_SET, DETAIL_TABLES)
        with open(table, "wb") as f:
            f.write(good)
        self.expect_recovery()

    def test_tables_other_than_the_pinned_ones(self):
        """tables_crc32 pins the model set: another file, sound but not the pinned one (here the
        same tables in a model-set container), is a tables fault whose message names both
        CRC-32s; the pinned file copied onto the board clears it."""
        with open(ARGS.table, "rb") as f:
            blob = f.read()
        pinned = struct.unpack_from("<I", blob, 24)[0]  # blob_crc32, as `tables info` prints it
        table = self.path("models.bin")
        with open(table, "wb") as f:
            f.write(model_set([(1, blob)]))
        self.boot("tables = " + table, "tables_crc32 = %08x" % pinned)
        self.expect_fault(EMCY_DATA_SET, DETAIL_TABLES)
        log = "\n".join(self.fw.stderr_lines)
        self.assertIn("not the %08x that tables_crc32 pins" % pinned, log)
        shutil.copyfile(ARGS.table, table)
        self.expect_recovery()

    def test_injected_corrupt_tables_stay_in_fault(self):
        self.boot("sim_corrupt_tables = true")
        self.expect_fault(EMCY_DATA_SET, DETAIL_TABLES)
        self.assertEqual(self.clear_fault(), ACK_NOT_POSSIBLE)
        self.expect_alive()

    def test_missing_calibration_file(self):
        calibration = self.path("calib.yaml")
        self.boot("calibration = " + calibration)
        self.expect_fault(EMCY_DATA_SET, DETAIL_CALIBRATION)
        with open(calibration, "w") as f:
            f.write(SIM_RIG_YAML)
        self.expect_recovery()

    def test_missing_model_folder(self):
        # The simulator renders its scenes from the models: without them it has no rig (the
        # calibration fault) and no frames (the camera fault).
        models = self.path("models")
        self.boot("models_dir = " + models)
        self.expect_fault(EMCY_DATA_SET, DETAIL_CALIBRATION)
        shutil.copytree(ARGS.models, models)
        self.expect_recovery()

    def fifo(self, name):
        path = self.path(name)
        os.mkfifo(path)
        return path

    def test_fifo_tables_file(self):
        """A FIFO is refused without waiting for a writer: the node comes up and reports the
        fault; once a real file replaces it, clear-fault loads it."""
        table = self.fifo("tables.bin")
        self.boot("tables = " + table)
        self.expect_fault(EMCY_DATA_SET, DETAIL_TABLES)
        os.unlink(table)
        shutil.copyfile(ARGS.table, table)
        self.expect_recovery()

    def test_fifo_calibration(self):
        calibration = self.fifo("calib.yaml")
        self.boot("calibration = " + calibration)
        self.expect_fault(EMCY_DATA_SET, DETAIL_CALIBRATION)
        os.unlink(calibration)
        with open(calibration, "w") as f:
            f.write(SIM_RIG_YAML)
        self.expect_recovery()

    def test_fifo_features(self):
        self.boot("features = " + self.fifo("features.bin"))
        self.expect_fault(EMCY_DATA_SET, DETAIL_FEATURES)

    def expect_cell_geometry_fault(self, key, path):
        """Up in fault with EMCY 0x6300 detail 6 and the log naming the key and the file; no
        trigger is answered with poses, and a clear-fault cannot repair a file read at boot."""
        self.expect_fault(EMCY_DATA_SET, DETAIL_CELL_GEOMETRY)
        log = "\n".join(self.fw.stderr_lines)
        self.assertTrue(any("cell geometry" in line and "key '%s'" % key in line and path in line
                            for line in self.fw.stderr_lines), log)
        self.plc.send("SH_Command", {"CMD_Code": CMD_TRIGGER, "CMD_TriggerRequestId": 9})
        seen = self.plc.receive_until(
            lambda n, v, m: n == "SH_CommandAck" and v["ACK_CommandCode"] == CMD_TRIGGER,
            timeout=30)
        self.assertEqual(seen[-1][1]["ACK_Status"], ACK_NOT_POSSIBLE, "trigger refused")
        self.plc.send("SH_Command", {"CMD_Code": CMD_CLEAR_FAULT})
        cleared = self.plc.receive_until(
            lambda n, v, m: n == "SH_CommandAck" and v["ACK_CommandCode"] == CMD_CLEAR_FAULT,
            timeout=30)
        self.assertEqual(cleared[-1][1]["ACK_Status"], ACK_NOT_POSSIBLE, "read at boot only")
        # The cause's EMCY again, before the ack.
        again = [v for n, v, _ in cleared
                 if n == "SH_Emcy" and v["EMCY_ErrorCode"] == EMCY_DATA_SET]
        self.assertTrue(again, "no EMCY 0x6300 at the clear-fault")
        self.assertEqual(again[-1]["EMCY_Detail"], DETAIL_CELL_GEOMETRY)
        self.assertEqual(again[-1]["EMCY_FirmwareState"], STATE_FAULT)
        seen += cleared
        # A second of traffic more: still no result set, no error reset.
        seen += self.receive_for(1.0)
        self.assertFalse([v for n, v, _ in seen if n == "SH_ResultHeader"], "a result set")
        # The refused commands are events with their error resets: each keeps the fault's
        # register, nothing was cleared.
        self.assertFalse([v for n, v, _ in seen if n == "SH_Emcy" and v["EMCY_ErrorCode"] == 0
                          and v["EMCY_ErrorRegister"] == 0], "the fault was cleared")
        self.expect_alive()

    def receive_for(self, seconds):
        """The decoded frames of the next `seconds`."""
        frames = []
        end = time.time() + seconds
        while time.time() < end:
            msg = self.plc.bus.recv(0.1)
            if msg is not None:
                frames.append(self.plc.decode(msg) + (msg,))
        return frames

    def restart(self, *config):
        self.plc.close()
        self.plc = None
        self.fw.stop()
        self.boot(*config)

    def expect_ready(self, output_frame):
        """A trigger answered with status 0, its poses in `output_frame`."""
        self.plc.send("SH_Command", {"CMD_Code": CMD_TRIGGER, "CMD_TriggerRequestId": 8})
        frames = self.plc.receive_until(lambda n, v, m: n == "SH_ResultEnd", timeout=60)
        headers = [v for n, v, _ in frames if n == "SH_ResultHeader"]
        self.assertEqual(headers[-1]["RH_RequestId"], 8)
        self.assertEqual(headers[-1]["RH_Status"], 0)
        self.assertEqual(frames[-1][1]["RE_OutputFrame"], output_frame)
        self.assertFalse(any(n == "SH_Emcy" and v["EMCY_ErrorCode"] != 0 for n, v, _ in frames))

    def test_missing_table_pose_file(self):
        table = self.path("table.yaml")
        self.boot("table_file = " + table)
        self.expect_cell_geometry_fault("table_file", table)

    def test_fifo_table_pose_file(self):
        """A FIFO without a writer is refused at once: the node comes up, it does not hang."""
        table = self.fifo("table.yaml")
        self.boot("table_file = " + table)
        self.expect_cell_geometry_fault("table_file", table)
        self.assertTrue(any("FIFO" in line for line in self.fw.stderr_lines),
                        "\n".join(self.fw.stderr_lines[-20:]))

    def test_malformed_table_pose_file(self):
        table = self.path("table.yaml")
        with open(table, "w") as f:
            f.write(MALFORMED_TABLE_YAML)
        self.boot("table_file = " + table)
        self.expect_cell_geometry_fault("table_file", table)

    def test_broken_handeye_file_until_restarted_after_repair(self):
        """output_frame = robot with a hand-eye file that lacks eye_in_hand: fault with the
        parser's message; the repaired file takes effect at the next start."""
        handeye = self.path("handeye.yaml")
        with open(handeye, "w") as f:
            f.write(GOOD_HANDEYE_YAML.replace("eye_in_hand: 0\n", ""))
        config = ("output_frame = robot", "handeye = " + handeye)
        self.boot(*config)
        self.expect_cell_geometry_fault("handeye", handeye)
        self.assertTrue(any("key 'handeye'" in line and "eye_in_hand" in line
                            for line in self.fw.stderr_lines),
                        "\n".join(self.fw.stderr_lines[-20:]))
        with open(handeye, "w") as f:
            f.write(GOOD_HANDEYE_YAML)
        self.restart(*config)
        self.expect_ready(OUTPUT_FRAME_ROBOT_BASE)

    def test_fifo_lss_store_boots_on_the_configured_id(self):
        self.boot("lss_store = " + self.fifo("node-id"))
        self.expect_alive()

    def test_device_in_model_folder(self):
        """An OBJ linked to /dev/zero is refused by its type, never read: the world is not built
        (the calibration fault, as for a missing folder) and the process stays small."""
        models = self.path("models")
        shutil.copytree(ARGS.models, models)
        os.unlink(os.path.join(models, "cube.obj"))
        os.symlink("/dev/zero", os.path.join(models, "cube.obj"))
        self.boot("models_dir = " + models)
        self.expect_fault(EMCY_DATA_SET, DETAIL_CALIBRATION)
        self.assertTrue(any("not a regular file" in line for line in self.fw.stderr_lines),
                        "\n".join(self.fw.stderr_lines[-20:]))


def main():
    global ARGS
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--firmware", required=True, help="path of stereohash-fw-sim")
    parser.add_argument("--dbc", required=True)
    parser.add_argument("--table", required=True, help="a valid table blob file")
    parser.add_argument("--models", required=True, help="the reference model folder")
    ARGS, rest = parser.parse_known_args()
    unittest.main(argv=[sys.argv[0]] + rest, verbosity=2)


if __name__ == "__main__":
    main()
