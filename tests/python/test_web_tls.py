#!/usr/bin/python3
"""The commissioning page over HTTPS (http_tls_cert, http_tls_key).

Makes a self-signed certificate for 127.0.0.1 with openssl, starts `stereohash-fw-sim` with it
and a password, and checks with Python's ssl module (the certificate as the only trusted CA,
host name checked) that:
  * the page, its status and a login are served over TLS, and the session cookie is Secure;
  * a plain HTTP request to the same port gets no page;
  * a certificate with another certificate's key is refused at start with a message naming both
    keys, and the node still runs: its heartbeat keeps coming on the CAN bus.
Skips (exit 77, saying why) without openssl or python-can's socketcand peers.
"""
import http.client
import json
import os
import shutil
import socket
import ssl
import subprocess
import sys
import tempfile
import time
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import firmware_test_main  # noqa: E402
from test_firmware_e2e import Firmware  # noqa: E402 (skips without python-can)
from test_web_hostile import Plc  # noqa: E402

ARGS = None


def make_certificate(directory, name):
    """A self-signed certificate for 127.0.0.1 and localhost: (cert path, key path)."""
    cert, key = (os.path.join(directory, name + s) for s in ("-cert.pem", "-key.pem"))
    subprocess.run(["openssl", "req", "-x509", "-newkey", "rsa:2048", "-nodes", "-keyout", key,
                    "-out", cert, "-days", "2", "-subj", "/CN=stereohash test",
                    "-addext", "subjectAltName=IP:127.0.0.1,DNS:localhost"],
                   check=True, capture_output=True)
    return cert, key


def config(cert, key, password):
    return ("backend = sim\nrecognition = truth\nnode_id = 1\nheartbeat_ms = 100\n"
            "sim_scenes = 2\nsim_objects = 2\nhttp_password = %s\n"
            "http_tls_cert = %s\nhttp_tls_key = %s\n" % (password, cert, key))


class WebTlsTest(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp(prefix="stereohash_tls_")
        self.cert, self.key = make_certificate(self.dir, "page")

    def tearDown(self):
        shutil.rmtree(self.dir, ignore_errors=True)

    def https(self, port):
        context = ssl.create_default_context(cafile=self.cert)
        return http.client.HTTPSConnection("127.0.0.1", port, timeout=15, context=context)

    def test_page_status_and_login_over_https(self):
        fw = Firmware(ARGS.firmware, config(self.cert, self.key, "s3cret-page"))
        try:
            self.assertTrue(fw.http_seen.wait(120) and fw.http_port,
                            "\n".join(fw.stderr_lines[-20:]))
            conn = self.https(fw.http_port)
            conn.request("GET", "/")
            page = conn.getresponse()
            self.assertEqual(page.status, 200)
            self.assertIn(b"<html", page.read().lower())
            conn.request("GET", "/api/status")
            status = conn.getresponse()
            self.assertEqual(status.status, 200)
            self.assertIn(json.loads(status.read())["health"]["state"], ("init", "ready", "busy"))
            conn.request("POST", "/api/login", body=b"s3cret-page",
                         headers={"Content-Type": "text/plain"})
            login = conn.getresponse()
            login.read()
            self.assertEqual(login.status, 200)
            cookie = login.getheader("Set-Cookie") or ""
            self.assertIn("Secure", cookie)
            self.assertIn("HttpOnly", cookie)
            conn.close()
            # Plain HTTP on the TLS port: no page comes back.
            with socket.create_connection(("127.0.0.1", fw.http_port), timeout=15) as s:
                s.sendall(b"GET / HTTP/1.1\r\nHost: sensor\r\nConnection: close\r\n\r\n")
                answer = b""
                try:
                    while True:
                        data = s.recv(65536)
                        if not data:
                            break
                        answer += data
                except OSError:
                    pass
            self.assertNotIn(b"HTTP/1.1 200", answer)
            self.assertNotIn(b"<html", answer.lower())
        finally:
            fw.stop()

    def test_a_key_of_another_certificate_is_refused_and_the_node_runs(self):
        _, other_key = make_certificate(self.dir, "other")
        fw = Firmware(ARGS.firmware, config(self.cert, other_key, "s3cret-page"))
        try:
            deadline = time.time() + 60
            while time.time() < deadline and not any("web page off" in line
                                                     for line in fw.stderr_lines):
                time.sleep(0.1)
            message = "\n".join(fw.stderr_lines)
            self.assertIn("web page off", message)
            self.assertIn("http_tls_cert", message)
            self.assertIn("http_tls_key", message)
            self.assertIsNone(fw.http_port)
            plc = Plc(fw.port)
            plc.reader.start()
            time.sleep(1.5)
            plc.stopping.set()
            plc.sock.close()
            self.assertGreaterEqual(len(plc.heartbeats), 5, "heartbeats in 1.5 s at 100 ms")
            self.assertIsNone(fw.proc.poll())
        finally:
            fw.stop()


def no_openssl():
    return None if shutil.which("openssl") else "openssl is not installed (Debian openssl)"


if __name__ == "__main__":
    sys.exit(firmware_test_main.main(sys.modules[__name__], __doc__, no_openssl))
