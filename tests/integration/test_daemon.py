"""The daemon's command line and signals: --help, refused options, a port
already in use, SIGINT behaving like SIGTERM, GET /state answering
quickly while the case steps (it waits for at most one step), and
--threads giving the same result file as one thread."""
import os
import signal
import socket
import subprocess
import tempfile
import time
import unittest

import h5py
import numpy as np

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

    def test_listen_errors_name_the_part_at_fault(self):
        # each exits 2 like every bad option: an IPv6 address was a failed
        # start (1) after the daemon had begun setting up, and a port out
        # of range or a host name was told only "takes HOST:PORT" or
        # "serves IPv4 only", though neither was the fault
        for listen, needles in (("::1:0", ("IPv4 only",)), ("[::1]:0", ("IPv4 only",)),
                                ("[::1]:8080", ("IPv6",)),
                                ("127.0.0.1:99999", ("PORT is 0 to 65535",)),
                                ("simhost:8080", ("not a host name", "simhost"))):
            out = self.run_fdemd("--listen", listen)
            self.assertEqual(out.returncode, 2, listen + ": " + out.stderr)
            for needle in needles:
                self.assertIn(needle, out.stderr)

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


def colliding_blocks():
    """Two 30x30 blocks meeting at 5 m/s: 3600 elements, so the element
    loops are cut into several blocks, and contact from the first steps."""
    block = {"size": [0.1, 0.1], "divisions": [30, 30]}
    return {
        "name": "threads",
        "materials": {"rock": {"density": 2700, "young": 3e10, "poisson": 0.25,
                               "damping": 0.05, "friction": 0.3}},
        "parts": [
            {"name": "left", "material": "rock", "velocity": [5, 0],
             "rectangle": dict(block, origin=[-0.1005, 0])},
            {"name": "right", "material": "rock", "velocity": [-5, 0.5],
             "rectangle": dict(block, origin=[0.0005, 0.02])},
        ],
        "time": {"end": 2e-4},
        "output": {"interval": 5e-5, "fields": ["position", "velocity", "stress"]},
    }


class ThreadsTest(unittest.TestCase):
    def run_case(self, threads):
        d = Daemon(args=["--threads", str(threads)]).start()
        try:
            case_id = d.create(colliding_blocks(), start=True)["id"]
            st = d.wait_state(case_id, ("finished", "failed"), timeout=60)
            self.assertEqual(st["state"], "finished", st.get("error"))
            self.assertGreater(st["contacts"] + st["snapshots"], 0)
            status, _, data = d.request("GET", "/cases/%s/result.h5" % case_id)
            self.assertEqual(status, 200)
            path = os.path.join(self.tmp, "threads-%d.h5" % threads)
            with open(path, "wb") as f:
                f.write(data)
            self.assertEqual(d.stop()[0], 0)
            return st, path
        finally:
            d.close()

    def test_two_threads_write_the_bits_of_one(self):
        with tempfile.TemporaryDirectory(prefix="fdemd-threads-") as self.tmp:
            one, h1 = self.run_case(1)
            two, h2 = self.run_case(2)
            self.assertEqual(one["step"], two["step"])
            with h5py.File(h1, "r") as f1, h5py.File(h2, "r") as f2:
                self.assertGreaterEqual(len(f1["/snapshots/time"]), 5)
                for name in ("position", "velocity", "stress", "kinetic_energy",
                             "elastic_energy"):
                    a, b = f1["/snapshots/" + name][...], f2["/snapshots/" + name][...]
                    np.testing.assert_array_equal(a, b, err_msg=name)
                # the blocks did meet: the left one was slowed down
                v = f1["/snapshots/velocity"][-1]
                self.assertLess(v[: len(v) // 2, 0].mean(), 4.9)


if __name__ == "__main__":
    unittest.main()
