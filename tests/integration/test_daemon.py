"""The daemon's command line and signals: --help, refused options, a port
already in use, SIGINT behaving like SIGTERM, and GET /state answering
quickly while the case steps (it waits for at most one step)."""
import signal
import socket
import subprocess
import time
import unittest

from fdemd_harness import FDEMD_BIN, SLOW, Daemon, tiny_case


class CommandLineTest(unittest.TestCase):
    def run_fdemd(self, *args):
        return subprocess.run([FDEMD_BIN] + list(args), capture_output=True, text=True,
                              timeout=20 * SLOW)

    def test_help(self):
        out = self.run_fdemd("--help")
        self.assertEqual(out.returncode, 0)
        for option in ("--listen", "--data", "--token", "--max-upload", "--max-running",
                       "--threads", "--max-case-memory"):
            self.assertIn(option, out.stdout)

    def test_bad_options_are_refused(self):
        for args in (["--max-running", "0"], ["--listen", "nowhere"], ["--listen", "127.0.0.1:99999"],
                     ["--max-upload", "-5"], ["--threads", "two"], ["--bogus"], ["extra"]):
            out = self.run_fdemd(*args)
            self.assertEqual(out.returncode, 2, args)
            self.assertIn("fdemd", out.stderr)
            self.assertEqual(out.stdout, "")

    def test_port_in_use(self):
        with socket.socket() as s:
            s.bind(("127.0.0.1", 0))
            s.listen()
            port = s.getsockname()[1]
            d = Daemon()
            try:
                out = self.run_fdemd("--listen", "127.0.0.1:%d" % port, "--data", d.data_dir)
            finally:
                d.close()
        self.assertNotEqual(out.returncode, 0)
        self.assertIn("cannot listen", out.stderr)


class SignalTest(unittest.TestCase):
    def test_sigint_pauses_and_exits_0(self):
        d = Daemon().start()
        try:
            case_id = d.create(tiny_case("interrupted", end=10.0), start=True)["id"]
            d.wait(case_id, lambda s: s["step"] > 10, what="steps")
            code, took = d.stop(signal.SIGINT)
            self.assertEqual(code, 0, d.log_tail())
            self.assertLess(took, 10.0)
            d.start()
            st = d.status(case_id)
            self.assertEqual(st["state"], "paused")
            self.assertGreater(st["step"], 10)
            self.assertEqual(d.stop()[0], 0)
        finally:
            d.close()


class StateLatencyTest(unittest.TestCase):
    def test_state_while_running_is_quick(self):
        d = Daemon().start()
        try:
            case_id = d.create(tiny_case("busy", end=10.0), start=True)["id"]
            d.wait(case_id, lambda s: s["step"] > 10, what="steps")
            times, steps = [], []
            for _ in range(50):
                t0 = time.perf_counter()
                status, state = d.json("GET", "/cases/%s/state?fields=position" % case_id)
                times.append(time.perf_counter() - t0)
                self.assertEqual(status, 200)
                steps.append(state["step"])
            times.sort()
            self.assertLess(times[-1], 0.5 * SLOW, times[-5:])
            self.assertEqual(steps, sorted(steps))
            self.assertGreater(steps[-1], steps[0])  # it kept stepping in between
            self.assertEqual(d.stop()[0], 0)
        finally:
            d.close()


if __name__ == "__main__":
    unittest.main()
