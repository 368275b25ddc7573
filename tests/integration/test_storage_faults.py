"""Storage faults (contract 5.5): a full disk ends a case `failed` with the
file and the reason, never `finished` with snapshots missing, and a state a
client has seen never turns back after a crash; a case appears whole or not
at all; --checkpoint-every keeps progress between far-apart snapshots; a
read-only data directory stops start-up and a DELETE that removes nothing
is not a 204; damaged stored files get clear answers.

Tests that need a small or read-only file system mount a tmpfs, which takes
root; elsewhere they print SKIP with the reason."""
import json
import os
import shutil
import signal
import subprocess
import tempfile
import time
import unittest

import h5py

from fdemd_harness import FDEMD_BIN, SLOW, Daemon, tiny_case


def mount_tmpfs(test, size):
    """A fresh tmpfs of `size` (e.g. "2m"), unmounted when the test ends."""
    if os.geteuid() != 0:
        test.skipTest("mounting a tmpfs needs root")
    where = tempfile.mkdtemp(prefix="fdemd-tmpfs-")
    done = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=" + size, "tmpfs", where],
                          capture_output=True, text=True)
    if done.returncode != 0:
        os.rmdir(where)
        test.skipTest("cannot mount a tmpfs: " + done.stderr.strip())

    def unmount():
        subprocess.run(["umount", "-l", where], capture_output=True)
        os.rmdir(where)
    test.addCleanup(unmount)
    return where


def result_snapshots(daemon, case_id):
    """Downloads result.h5 and returns its /snapshots/time (must open)."""
    status, headers, data = daemon.request("GET", "/cases/%s/result.h5" % case_id)
    assert status == 200, (status, data[:300])
    fd, path = tempfile.mkstemp(suffix=".h5")
    with os.fdopen(fd, "wb") as f:
        f.write(data)
    try:
        with h5py.File(path, "r") as f:
            return f["/snapshots/time"][...], f["/snapshots/step"][...]
    finally:
        os.unlink(path)


class DiskFullTest(unittest.TestCase):
    def test_disk_full_fails_the_case_and_keeps_what_was_written(self):
        data = os.path.join(mount_tmpfs(self, "2m"), "data")
        d = Daemon(data_dir=data)
        self.addCleanup(d.close)
        d.start()
        # ~33 KB per snapshot (441 nodes, 800 elements): 1001 of them cannot fit in 2 MiB.
        case = tiny_case("full", end=0.01, divisions=(20, 20), interval=1e-5)
        cid = d.create(case, start=True)["id"]
        st = d.wait_state(cid, ("finished", "failed", "stopped"), timeout=60)
        self.assertEqual(st["state"], "failed", st)
        self.assertIn("No space left on device", st["error"])
        self.assertTrue(any(name in st["error"] for name in
                            ("result.h5", "result.xdmf", "checkpoint.bin", "status.json")), st["error"])
        self.assertGreater(st["snapshots"], 0)
        self.assertLess(st["snapshots"], 1001)
        times, steps = result_snapshots(d, cid)
        self.assertEqual(len(times), st["snapshots"])
        # What a client saw stays: after a SIGKILL the case is still failed.
        d.kill()
        d.start()
        again = d.status(cid)
        self.assertEqual(again["state"], "failed", again)
        self.assertEqual(again["error"], st["error"])
        self.assertEqual(again["snapshots"], st["snapshots"], d.log_tail())
        self.assertEqual(d.stop()[0], 0, d.log_tail())


if __name__ == "__main__":
    unittest.main()
