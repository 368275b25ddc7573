#!/usr/bin/env python3
"""Runs every tests/integration/test_*.py with unittest against the real
daemon and prints one "PASS <test id>" or "FAIL <test id>" line per test
(tracebacks go to stderr). Exits non-zero when any test failed or erred.

    FDEMD_BIN=bin-san/fdemd /usr/bin/python3 tests/integration/run.py [pattern]

INTEGRATION_JOBS=N (default 1) runs the test modules in N processes side by
side, whole modules each (a module's classes share daemons and fixtures),
spread by how long each took in CI so the shares end together: most of a
test's time is spent waiting for a daemon, a file or a deadline, so two
shares on two cores take about 60 % of the time of one.
"""
import subprocess
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
        # wall seconds per module, class set-ups included: the time since
        # the last test ended goes to the module of the one ending now
        # (what MODULE_SECONDS below should say)
        self.module_seconds = {}
        self._last_end = time.monotonic()

    def startTest(self, test):
        super().startTest(test)
        self._started[test.id()] = time.monotonic()

    def stopTest(self, test):
        super().stopTest(test)
        now = time.monotonic()
        name = test.id().split(".", 1)[0]
        self.module_seconds[name] = self.module_seconds.get(name, 0.0) + now - self._last_end
        self._last_end = now

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


# Seconds a module took in the sanitizer pass of CI (2026-12-06); any other
# counts 5. Only the split between shares depends on them.
MODULE_SECONDS = {"test_paraview": 70, "test_observation_3d": 47, "test_hostile_input": 37,
                  "test_clients": 33, "test_trust": 31, "test_storage_faults": 31,
                  "test_excavation": 27, "test_plot_3d": 22, "test_heavy_work": 21,
                  "test_hostile_requests": 16, "test_crash_consistency": 13,
                  "test_hostile_resources": 12, "test_results_displacement": 11,
                  "test_history": 10, "test_memory": 8, "test_3d": 8, "test_stream": 32,
                  "test_web": 20, "test_fluid": 22, "test_estimate": 15, "test_ranks": 30,
                  "test_fdem_run": 20}


def module_of(test):
    return test.id().split(".", 1)[0]


def flatten(suite):
    for item in suite:
        if isinstance(item, unittest.TestSuite):
            yield from flatten(item)
        else:
            yield item


def shard_modules(modules, shards):
    """Whole modules to `shards` shares, the longest first to the lightest
    share: the same split every run."""
    load, owner = [0.0] * shards, {}
    for name in sorted(modules, key=lambda m: (-MODULE_SECONDS.get(m, 5), m)):
        k = load.index(min(load))
        owner[name] = k
        load[k] += MODULE_SECONDS.get(name, 5)
    return owner


def run_shards(jobs):
    """This runner again in `jobs` processes, one share each; their lines
    go straight to this one's output. Returns the exit status."""
    children = [subprocess.Popen([sys.executable] + sys.argv,
                                 env=dict(os.environ, INTEGRATION_SHARD="%d/%d" % (k, jobs)))
                for k in range(jobs)]
    return 1 if any(c.wait() != 0 for c in children) else 0


def main():
    pattern = sys.argv[1] if len(sys.argv) > 1 else "test_*.py"
    jobs = int(os.environ.get("INTEGRATION_JOBS", "1") or 1)
    shard = os.environ.get("INTEGRATION_SHARD")
    if jobs > 1 and not shard:
        return run_shards(jobs)
    sys.path.insert(0, HERE)
    suite = unittest.defaultTestLoader.discover(HERE, pattern=pattern, top_level_dir=HERE)
    if shard:
        k, n = (int(x) for x in shard.split("/"))
        tests = list(flatten(suite))
        owner = shard_modules({module_of(t) for t in tests}, n)
        suite = unittest.TestSuite(t for t in tests if owner[module_of(t)] == k)
    result = LineResult()
    started = time.monotonic()
    suite.run(result)
    failed = len(result.failures) + len(result.errors) + len(result.unexpectedSuccesses)
    longest = sorted(result.module_seconds.items(), key=lambda kv: -kv[1])[:12]
    print("integration modules, longest: " + ", ".join("%s %.0f s" % kv for kv in longest),
          file=sys.stderr)
    print("integration: %d run, %d failed, %.1f s" % (result.testsRun, failed, time.monotonic() - started),
          file=sys.stderr)
    return 1 if failed or result.testsRun == 0 else 0


if __name__ == "__main__":
    sys.exit(main())
