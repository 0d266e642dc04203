#!/usr/bin/python3
"""Smoke load of the commissioning page in Firefox (Debian firefox-esr, headless).

Starts `stereohash-fw-sim`, lets `firefox-esr --headless --screenshot` load the page from it with
a fresh profile, and checks that Firefox rendered the page with its stylesheet (the header's
colour across the top of the screenshot; the stylesheet is a request of its own) and that the
firmware still runs. Exits 77 (skipped, saying why) without firefox-esr or python3-opencv (to
read the screenshot).
"""
import argparse
import os
import shutil
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "python"))

SKIP = 77
HEADER_BGR = (0x47, 0x34, 0x24)  # style.css: header { background: #243447 }


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--firmware", required=True)
    parser.add_argument("--firefox", default="/usr/bin/firefox-esr")
    args = parser.parse_args()
    if not os.path.exists(args.firefox):
        print("SKIP: no Firefox at %s (Debian package firefox-esr)" % args.firefox)
        return SKIP
    try:
        import cv2
    except ImportError:
        print("SKIP: python3-opencv is missing (it reads the screenshot)")
        return SKIP
    from test_firmware_e2e import Firmware  # noqa: E402 (skips without python-can)

    fw = Firmware(args.firmware, "backend = sim\nrecognition = truth\n")
    work = tempfile.mkdtemp(prefix="stereohash_firefox_")
    try:
        if not fw.http_seen.wait(120) or fw.http_port is None:
            print("no HTTP_PORT:\n" + "\n".join(fw.stderr_lines[-20:]))
            return 1
        shot = os.path.join(work, "page.png")
        profile = os.path.join(work, "profile")
        os.mkdir(profile)
        run = subprocess.run([args.firefox, "--headless", "--no-remote", "-profile", profile,
                              "--window-size", "1280,900", "--screenshot", shot,
                              "http://127.0.0.1:%d/" % fw.http_port],
                             capture_output=True, text=True, timeout=240,
                             env=dict(os.environ, HOME=work))
        image = cv2.imread(shot) if os.path.exists(shot) else None
        if run.returncode != 0 or image is None:
            print("firefox-esr exited %d without a screenshot:\n%s" % (run.returncode, run.stderr))
            return 1
        top = image[5:30, :, :].reshape(-1, 3)
        header = sum(1 for p in top if all(abs(int(p[k]) - HEADER_BGR[k]) <= 2 for k in range(3)))
        print("Firefox: %d x %d screenshot, %d of %d pixels of the top rows in the header's colour"
              % (image.shape[1], image.shape[0], header, len(top)))
        if header < len(top) // 2:
            print("the page's stylesheet did not apply")
            return 1
        if fw.proc.poll() is not None:
            print("the firmware stopped")
            return 1
        print("PASS")
        return 0
    finally:
        fw.stop()
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
