#!/usr/bin/python3
"""A command flood on the simulated bus, and clients that say nothing.

Starts `stereohash-fw-sim` and talks the socketcand text protocol over a plain TCP socket
(python-can is too slow to flood). Checks that:
  * N triggers sent back to back, before reading anything, are each answered with an ack, or
    counted in an overrun EMCY (0x8110) where the firmware's receive queue lost them: nothing
    vanishes without a trace;
  * connections that never finish the handshake, as many as there are client slots, do not
    lock the PLC out: it connects, completes the handshake and gets its answers, and the silent
    ones are closed.
"""
import argparse
import os
import re
import socket
import sys
import threading
import time
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from test_firmware_e2e import Firmware  # noqa: E402 (skips without python-can)

ARGS = None
ACK_ID = 0x481
EMCY_ID = 0x81
CMD_TRIGGER = 1
EMCY_OVERRUN = 0x8110


def start_firmware(extra_config=""):
    return Firmware(ARGS.firmware,
                    "node_id = 1\nheartbeat_ms = 100\nsim_port = 0\nsim_scenes = 2\n"
                    "sim_objects = 2\nrecognition = truth\nsim_print_truth = false\n" +
                    extra_config)


class Connection:
    """One socketcand client: whole '< ... >' messages in, text out."""

    def __init__(self, port):
        self.sock = socket.create_connection(("127.0.0.1", port), timeout=30)
        self.buffer = b""

    def read(self, timeout=10.0):
        self.sock.settimeout(timeout)
        while True:
            m = re.search(rb"<[^<>]*>", self.buffer)
            if m:
                self.buffer = self.buffer[m.end():]
                return m.group(0).decode()
            try:
                data = self.sock.recv(65536)
            except socket.timeout:
                return None
            if not data:
                return None
            self.buffer += data

    def handshake(self):
        assert self.read() == "< hi >"
        self.sock.sendall(b"< open can0 >")
        assert self.read() == "< ok >"
        self.sock.sendall(b"< rawmode >")
        assert self.read() == "< ok >"

    def close(self):
        self.sock.close()


def frames(conn, until, seconds=120.0):
    """Yields (id, data) of frame messages until until() is true, nothing comes for 5 s or
    `seconds` have passed."""
    deadline = time.time() + seconds
    while not until() and time.time() < deadline:
        msg = conn.read(5.0)
        if msg is None:
            return
        fields = msg.split()
        if len(fields) >= 5 and fields[1] == "frame":
            data = bytes.fromhex(fields[4]) if len(fields) > 5 else b""
            yield int(fields[2], 16), data


class FloodTest(unittest.TestCase):
    def test_every_trigger_is_answered_or_counted(self):
        fw = start_firmware()
        try:
            conn = Connection(fw.port)
            conn.handshake()
            # A PLC starts once the node is there: after its first heartbeat.
            heartbeat = []
            for can_id, data in frames(conn, lambda: bool(heartbeat), 60):
                if can_id == 0x701 and data and data[0] == 5:
                    heartbeat.append(data)
            self.assertTrue(heartbeat, "no operational heartbeat")
            n = ARGS.triggers
            flood = b"".join(b"< send 201 3 1 %x %x >" % (i & 0xFF, i >> 8)
                             for i in range(1, n + 1))
            # Written from another thread: the bridge reads commands only as fast as their
            # answers are read (backpressure).
            writer = threading.Thread(target=conn.sock.sendall, args=(flood,))
            writer.start()
            acks, overrun = set(), 0
            for can_id, data in frames(conn, lambda: len(acks) + overrun >= n, 30):
                if can_id == ACK_ID and data[0] == CMD_TRIGGER:
                    acks.add(data[2] | data[3] << 8)
                elif can_id == EMCY_ID and (data[0] | data[1] << 8) == EMCY_OVERRUN:
                    overrun += int.from_bytes(data[4:8], "little")
            writer.join()
            conn.close()
            print("\n%d triggers: %d acks, %d counted in overrun EMCYs" % (n, len(acks), overrun))
            self.assertEqual(len(acks) + overrun, n, "triggers without ack or overrun count:\n" +
                             "\n".join(fw.stderr_lines[-15:]))
            self.assertIsNone(fw.proc.poll())
            lost = [l for l in fw.stderr_lines if "lost" in l]
            self.assertEqual(lost, [], "the bridge lost frames")
        finally:
            fw.stop()

    def test_silent_connections_do_not_lock_the_plc_out(self):
        fw = start_firmware("sim_socketcand_clients = 4\nsim_socketcand_handshake_ms = 60000\n")
        try:
            silent = [socket.create_connection(("127.0.0.1", fw.port)) for _ in range(4)]
            time.sleep(0.2)
            plc = Connection(fw.port)
            plc.handshake()
            plc.sock.sendall(b"< send 201 3 1 7 0 >")
            acks = []
            for can_id, data in frames(plc, lambda: bool(acks)):
                if can_id == ACK_ID and data[0] == CMD_TRIGGER:
                    acks.append(data)
            self.assertTrue(acks, "no ack for the PLC's trigger")
            self.assertEqual(acks[0][2], 7)
            plc.close()
            # The oldest silent connection made room and was closed.
            silent[0].settimeout(10)
            text = b""
            while b"< error" not in text:
                chunk = silent[0].recv(4096)
                if not chunk:
                    break
                text += chunk
            self.assertIn(b"< error slot taken", text)
            for s in silent:
                s.close()
        finally:
            fw.stop()


def main():
    global ARGS
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--firmware", required=True, help="path of stereohash-fw-sim")
    parser.add_argument("--triggers", type=int, default=2000)
    ARGS, rest = parser.parse_known_args()
    unittest.main(argv=[sys.argv[0]] + rest, verbosity=2)


if __name__ == "__main__":
    main()
