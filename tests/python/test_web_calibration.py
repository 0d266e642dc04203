#!/usr/bin/python3
"""The commissioning page's chessboard-pair helper against `stereohash-fw-sim`.

Checks that a capture without a login is refused and writes nothing; that each capture with a
login writes the next pair under record_dir/calibration at the cameras' full size (the PNG
headers against the sizes the status reports) and lists it; that a pair downloads as a tar of
its two images and capture.json, in the file names `stereohash calibrate` globs; that names
outside the folder are refused; and that without record_dir the capture says why.
"""
import http.client
import io
import json
import os
import shutil
import struct
import sys
import tarfile
import tempfile
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import firmware_test_main  # noqa: E402
from test_firmware_e2e import Firmware  # noqa: E402 (skips without python-can)

ARGS = None
PASSWORD = "calibrate-me"


def config(record_dir):
    text = ("backend = sim\nrecognition = truth\nnode_id = 1\nheartbeat_ms = 100\n"
            "sim_scenes = 2\nsim_objects = 2\nhttp_password = %s\n" % PASSWORD)
    if record_dir:
        text += "record_dir = %s\nrecord_all = false\n" % record_dir
    return text


class Page:
    """HTTP to the page with a session once logged in."""

    def __init__(self, port):
        self.port, self.cookie, self.csrf = port, "", ""

    def request(self, method, path, body=b""):
        conn = http.client.HTTPConnection("127.0.0.1", self.port, timeout=30)
        headers = {"Content-Type": "text/plain"}
        if self.cookie:
            headers["Cookie"] = self.cookie
            headers["X-CSRF-Token"] = self.csrf
        conn.request(method, path, body=body, headers=headers)
        answer = conn.getresponse()
        data = answer.read()
        conn.close()
        return answer, data

    def login(self):
        answer, data = self.request("POST", "/api/login", PASSWORD.encode())
        assert answer.status == 200, data
        self.cookie = answer.getheader("Set-Cookie").split(";")[0]
        self.csrf = json.loads(data)["csrf"]


def png_size(path):
    with open(path, "rb") as f:
        head = f.read(24)
    assert head[:8] == b"\x89PNG\r\n\x1a\n", path
    return list(struct.unpack(">II", head[16:24]))


class WebCalibrationTest(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp(prefix="stereohash_calib_page_")
        self.record_dir = os.path.join(self.dir, "rec")

    def tearDown(self):
        shutil.rmtree(self.dir, ignore_errors=True)

    def start(self, record_dir):
        fw = Firmware(ARGS.firmware, config(record_dir))
        if not fw.http_seen.wait(120) or not fw.http_port:
            fw.stop()
            self.fail("no HTTP_PORT:\n" + "\n".join(fw.stderr_lines[-20:]))
        return fw

    def test_pairs_are_captured_listed_and_downloaded(self):
        fw = self.start(self.record_dir)
        try:
            page = Page(fw.http_port)
            answer, _ = page.request("POST", "/api/calibration/capture")
            self.assertEqual(answer.status, 403)
            self.assertFalse(os.path.exists(os.path.join(self.record_dir, "calibration")))
            page.login()
            for n in (1, 2):
                answer, data = page.request("POST", "/api/calibration/capture")
                self.assertEqual(answer.status, 200, data)
                reply = json.loads(data)
                self.assertEqual((reply["pair"], reply["pairs"]), ("%08d" % n, n))
            answer, data = page.request("GET", "/api/calibration")
            self.assertEqual(json.loads(data)["pairs"], ["00000001", "00000002"])
            _, status = page.request("GET", "/api/status")
            sizes = json.loads(status)["result"]["image_size"]
            pair = os.path.join(self.record_dir, "calibration", "00000002")
            self.assertEqual(png_size(os.path.join(pair, "left.png")), sizes[0])
            self.assertEqual(png_size(os.path.join(pair, "right.png")), sizes[1])
            self.assertGreaterEqual(sizes[0][0], 640)
            answer, data = page.request("GET", "/api/calibration?pair=00000001")
            self.assertEqual(answer.status, 200)
            with tarfile.open(fileobj=io.BytesIO(data)) as tar:
                self.assertEqual(sorted(tar.getnames()),
                                 ["00000001/capture.json", "00000001/left.png",
                                  "00000001/right.png"])
            for bad in ("../rec", "00000001/../../x", "%2e%2e", "1"):
                answer, _ = page.request("GET", "/api/calibration?pair=" + bad)
                self.assertIn(answer.status, (400, 404), bad)
            # No recorded pair beside them: none was asked for (record_all = false).
            self.assertEqual([n for n in os.listdir(self.record_dir) if n.isdigit()], [])
        finally:
            fw.stop()

    def test_without_record_dir_the_capture_says_why(self):
        fw = self.start(None)
        try:
            page = Page(fw.http_port)
            page.login()
            answer, data = page.request("POST", "/api/calibration/capture")
            self.assertEqual(answer.status, 404)
            self.assertIn("record_dir", json.loads(data)["message"])
        finally:
            fw.stop()


if __name__ == "__main__":
    sys.exit(firmware_test_main.main(sys.modules[__name__], __doc__))
