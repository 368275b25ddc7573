#!/usr/bin/env python3
"""Runs every tests/integration/test_*.py with unittest against the real
daemon and prints one "PASS <test id>" or "FAIL <test id>" line per test
(tracebacks go to stderr). Exits non-zero when any test failed or erred.

    FDEMD_BIN=bin-san/fdemd /usr/bin/python3 tests/integration/run.py [pattern]
"""
import os
import sys
import time
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))


class LineResult(unittest.TestResult):
    """Prints a PASS/FAIL line as each test ends; a skipped test prints SKIP
    with its reason and is not counted as passed."""

    def __init__(self):
        super().__init__()
        self._started = {}

    def startTest(self, test):
        super().startTest(test)
        self._started[test.id()] = time.monotonic()

    def _elapsed(self, test):
        return time.monotonic() - self._started.get(test.id(), time.monotonic())

    def addSuccess(self, test):
        super().addSuccess(test)
        print("PASS %s (%.1f s)" % (test.id(), self._elapsed(test)), flush=True)

    def _fail(self, test, err, kind):
        print("FAIL %s (%s, %.1f s)" % (test.id(), kind, self._elapsed(test)), flush=True)
        sys.stderr.write("---- %s %s\n%s\n" % (kind, test.id(), self._exc_info_to_string(err, test)))
        sys.stderr.flush()

    def addFailure(self, test, err):
        super().addFailure(test, err)
        self._fail(test, err, "failure")

    def addError(self, test, err):
        super().addError(test, err)
        self._fail(test, err, "error")

    def addSkip(self, test, reason):
        super().addSkip(test, reason)
        print("SKIP %s (%s)" % (test.id(), reason), flush=True)

    def addUnexpectedSuccess(self, test):
        super().addUnexpectedSuccess(test)
        print("FAIL %s (unexpected success)" % test.id(), flush=True)


def main():
    pattern = sys.argv[1] if len(sys.argv) > 1 else "test_*.py"
    sys.path.insert(0, HERE)
    suite = unittest.defaultTestLoader.discover(HERE, pattern=pattern, top_level_dir=HERE)
    result = LineResult()
    started = time.monotonic()
    suite.run(result)
    failed = len(result.failures) + len(result.errors) + len(result.unexpectedSuccesses)
    print("integration: %d run, %d failed, %.1f s" % (result.testsRun, failed, time.monotonic() - started),
          file=sys.stderr)
    return 1 if failed or result.testsRun == 0 else 0


if __name__ == "__main__":
    sys.exit(main())
