"""The command line of the tests that run `stereohash-fw-sim` (--firmware BINARY, then
unittest's own arguments): parses it and runs the module's test cases."""
import argparse
import sys
import unittest


def parse(description):
    """(arguments, the rest for unittest)."""
    parser = argparse.ArgumentParser(description=description.splitlines()[0])
    parser.add_argument("--firmware", required=True)
    args, rest = parser.parse_known_args()
    return args, rest


def main(module, description, skip_reason=None):
    """Sets module.ARGS and runs its test cases: 0 when they pass, 77 when skipped."""
    module.ARGS, rest = parse(description)
    reason = skip_reason() if skip_reason else None
    if reason:
        print("skipped: " + reason)
        return 77
    program = unittest.main(module=module, argv=[sys.argv[0]] + rest, exit=False)
    return 0 if program.result.wasSuccessful() else 1
