#!/usr/bin/env python3
"""Checks on the firmware programs that the unit tests cannot make.

  check_firmware.py symbols NM PROGRAM
      The board program holds no simulator code: none of the simulated world (sh::render), the
      simulator backends (SimCanBus, SocketcandServer, SimCamera, SimGpio, the recorded-pair
      camera), the demo PLC and its result reassembler, ground-truth recognition or the
      simulator's defaults is among its symbols; and it does hold the core. The image files (PNG
      on libpng, PGM) are allowed: the board writes its recordings (record_dir) with them.
  check_firmware.py docs DOC PROGRAM [ARGS...]
      docs/firmware.md's configuration key table is what `PROGRAM --config-keys-markdown` prints
      (the key list of firmware/config_keys.hpp). With --write, rewrites the table in DOC.
"""
import re
import subprocess
import sys

FORBIDDEN = re.compile(
    r"sh::render::|sh::hal::SimCanBus|sh::hal::SimCanEndpoint|sh::hal::SocketcandServer|"
    r"sh::hal::SimCamera|sh::hal::SimGpio|sh::hal::DirectoryCamera|"
    r"sh::fw::DemoClient|sh::protocol::ResultAssembler|sh::fw::TruthRecognition|"
    r"sh::fw::SimDefaults")
REQUIRED = ("sh::fw::FirmwareCore::Start", "sh::fw::FirmwareMain")
BEGIN = "<!-- configuration keys: stereohash-fw-sim --config-keys-markdown -->"
END = "<!-- end of configuration keys -->"


def symbols(nm, program):
    out = subprocess.run([nm, "-C", program], check=True, capture_output=True, text=True).stdout
    bad = sorted({line.split(" ", 2)[-1] for line in out.splitlines() if FORBIDDEN.search(line)})
    missing = [r for r in REQUIRED if r not in out]
    for s in bad:
        print(f"{program}: simulator symbol {s}")
    for r in missing:
        print(f"{program}: no {r}: not the firmware, or stripped")
    print(f"{program}: {len(out.splitlines())} symbols, {len(bad)} of the simulator")
    return 1 if bad or missing else 0


def docs(doc, command, write):
    table = subprocess.run(command + ["--config-keys-markdown"], check=True, capture_output=True,
                           text=True).stdout
    text = open(doc, encoding="utf-8").read()
    if BEGIN not in text or END not in text:
        print(f"{doc}: no '{BEGIN}' ... '{END}' block")
        return 1
    head, rest = text.split(BEGIN, 1)
    current, tail = rest.split(END, 1)
    if current.strip() == table.strip():
        print(f"{doc}: configuration key table is current")
        return 0
    if write:
        open(doc, "w", encoding="utf-8").write(head + BEGIN + "\n" + table + END + tail)
        print(f"{doc}: configuration key table rewritten")
        return 0
    print(f"{doc}: the configuration key table differs from `{' '.join(command)} "
          "--config-keys-markdown`; rewrite it with tools/check_firmware.py docs --write")
    return 1


def main():
    args = sys.argv[1:]
    write = "--write" in args
    args = [a for a in args if a != "--write"]
    if len(args) >= 3 and args[0] == "symbols":
        return symbols(args[1], args[2])
    if len(args) >= 3 and args[0] == "docs":
        return docs(args[1], args[2:], write)
    print(__doc__)
    return 2


if __name__ == "__main__":
    sys.exit(main())
