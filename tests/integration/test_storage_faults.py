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
import sys
import tempfile
import time
import unittest
import zlib

import h5py

from fdemd_harness import FDEMD_BIN, SLOW, Daemon, fetched_result, tiny_case


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


def daemon_on_tmpfs(test, size):
    """A started daemon whose data directory is on a fresh tmpfs."""
    where = mount_tmpfs(test, size)
    d = Daemon(data_dir=os.path.join(where, "data"))
    test.addCleanup(d.close)
    d.start()
    return d, where


def edit_checkpoint(path, offset, data, seal=True):
    """Writes `data` at `offset` of a checkpoint.bin and, when `seal`, makes
    its trailer ("FDCK" and the CRC-32 of the bytes before it) hold again,
    as a deliberate edit would; without, the edit is damage."""
    with open(path, "r+b") as f:
        f.seek(offset)
        f.write(data)
        if seal:
            f.seek(0)
            body = f.read()[:-8]
            f.seek(len(body))
            f.write(b"FDCK" + zlib.crc32(body).to_bytes(4, "little"))


def result_snapshots(daemon, case_id):
    """Downloads result.h5 and returns its /snapshots/time (must open)."""
    with fetched_result(daemon, case_id) as f:
        return f["/snapshots/time"][...], f["/snapshots/step"][...]


class DiskFullTest(unittest.TestCase):
    def test_disk_full_fails_the_case_and_keeps_what_was_written(self):
        d, _ = daemon_on_tmpfs(self, "2m")
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
        self.assertEqual(again["step"], st["step"])
        self.assertEqual(d.stop()[0], 0, d.log_tail())


def edit_json(path, **changes):
    with open(path) as f:
        doc = json.load(f)
    doc.update(changes)
    with open(path, "w") as f:
        json.dump(doc, f)


class StoredFilesTest(unittest.TestCase):
    """Damage done to the files of a stopped daemon gets a clear answer."""

    def setUp(self):
        self.d = Daemon()
        self.addCleanup(self.d.close)
        self.d.start()

    def finished_case(self, end=0.0004):
        cid = self.d.create(tiny_case("done", end=end), start=True)["id"]
        return self.d.wait_state(cid, "finished")

    def paused_and_stopped(self, snapshots):
        """A case paused once it has `snapshots` snapshots, its daemon
        stopped: its id, the pause's status and its checkpoint.bin."""
        d = self.d
        cid = d.create(tiny_case("paused", end=10.0, interval=2e-5), start=True)["id"]
        d.wait(cid, lambda s: s["snapshots"] >= snapshots, what="%d snapshots" % snapshots)
        paused = d.json("POST", "/cases/%s/pause" % cid)[1]
        self.assertEqual(d.stop()[0], 0)
        return cid, paused, os.path.join(d.data_dir, cid, "checkpoint.bin")

    def assert_fails_keeping_snapshots(self, cid, paused, *words):
        """Started again, the case is failed with `words` in its error and
        every snapshot kept; the daemon is stopped again."""
        d = self.d
        d.start()
        st = d.status(cid)
        self.assertEqual(st["state"], "failed", st)
        for word in words:
            self.assertIn(word, st["error"])
        self.assertEqual(st["snapshots"], paused["snapshots"])
        self.assertEqual(d.stop()[0], 0)

    def assert_back_as_paused(self, cid, paused):
        """Started again, the case is paused where it was, every snapshot
        in result.h5."""
        d = self.d
        d.start()
        st = d.status(cid)
        self.assertEqual(st["state"], "paused", st)
        self.assertEqual(st["step"], paused["step"])
        self.assertEqual(st["snapshots"], paused["snapshots"])
        self.assertEqual(len(result_snapshots(d, cid)[0]), paused["snapshots"])

    def test_negative_checkpoint_step_keeps_every_snapshot(self):
        cid, paused, path = self.paused_and_stopped(4)
        # int64 step after six int32, the checksum made to hold: the
        # engine's own checks are what refuse it
        edit_checkpoint(path, 24, (-5).to_bytes(8, "little", signed=True))
        self.assert_fails_keeping_snapshots(cid, paused, "negative step")
        # Nothing was dropped: mend the checkpoint and the case is back.
        edit_checkpoint(path, 24, paused["step"].to_bytes(8, "little", signed=True))
        self.assert_back_as_paused(cid, paused)
        self.assertEqual(self.d.stop()[0], 0, self.d.log_tail())

    def test_a_changed_byte_in_the_checkpoint_fails_the_case_and_mending_it_brings_it_back(self):
        """A byte changed in the middle of a position is still a finite
        number: without the checksum the case came back paused and carried
        on from a state it never had."""
        cid, paused, path = self.paused_and_stopped(3)
        good = open(path, "rb").read()
        self.assertEqual(good[-8:-4], b"FDCK")
        self.assertEqual(int.from_bytes(good[-4:], "little"), zlib.crc32(good[:-8]))
        middle = len(good) // 2
        edit_checkpoint(path, middle, bytes([good[middle] ^ 0x04]), seal=False)
        self.assert_fails_keeping_snapshots(cid, paused, "checkpoint.bin", "CRC-32")
        with open(path, "wb") as f:
            f.write(good)
        self.assert_back_as_paused(cid, paused)
        self.assertEqual(self.d.stop()[0], 0, self.d.log_tail())

    def test_an_unreadable_checkpoint_fails_the_case_and_keeps_every_snapshot(self):
        """checkpoint.bin there but unreadable (here a directory in its
        place: EIO, a file past the size limit and a failed allocation take
        the same path) is not a missing one: the case came back paused at
        step 0 and result.h5 was cut to its first row."""
        cid, paused, path = self.paused_and_stopped(3)
        os.rename(path, path + ".kept")
        os.mkdir(path)
        self.assert_fails_keeping_snapshots(cid, paused, "checkpoint.bin")
        os.rmdir(path)
        os.rename(path + ".kept", path)
        self.assert_back_as_paused(cid, paused)
        self.assertEqual(self.d.stop()[0], 0, self.d.log_tail())

    def test_a_damaged_trailer_is_not_taken_for_a_checkpoint_from_before_the_checksum(self):
        """Every checkpoint of engine version 6 on was written sealed: one
        without its trailer was damaged at its end. It was taken for an
        older daemon's file (the log said so) and refused for its size, an
        error that invites cutting the 8 bytes off, which would restore it
        unchecked."""
        cid, paused, path = self.paused_and_stopped(2)
        good = open(path, "rb").read()
        for damaged in (good[:-8] + b"FDCX" + good[-4:], good[:-8]):
            with open(path, "wb") as f:
                f.write(damaged)
            self.assert_fails_keeping_snapshots(cid, paused, "checkpoint.bin", "trailer")
            self.assertNotIn("has no checksum", self.d.log_tail())
        with open(path, "wb") as f:
            f.write(good)
        self.assert_back_as_paused(cid, paused)
        self.assertEqual(self.d.stop()[0], 0, self.d.log_tail())

    def test_a_checkpoint_from_before_the_checksum_is_restored(self):
        """checkpoint.bin of an earlier daemon has no trailer: it is restored
        on the engine's own checks, and the next checkpoint is sealed."""
        d = self.d
        cid, paused, path = self.paused_and_stopped(2)
        good = open(path, "rb").read()
        # what that daemon wrote: checkpoint version 5, whose header ends
        # before version 6's time_carry (a double at byte 240), no trailer
        # (versions 7 to 11 only add sections at the end, the joints'
        # slip, the stages and the fluid with its bores: this case has none
        # of them)
        body = good[:-8]
        self.assertEqual(int.from_bytes(body[4:8], "little"), 11)
        with open(path, "wb") as f:
            f.write(body[:4] + (5).to_bytes(4, "little") + body[8:240] + body[248:])
        self.assert_back_as_paused(cid, paused)
        self.assertIn("has no checksum", d.log_tail())
        d.json("POST", "/cases/%s/start" % cid)
        d.wait(cid, lambda s: s["step"] > paused["step"], what="a step past the pause")
        d.json("POST", "/cases/%s/pause" % cid)
        self.assertEqual(d.stop()[0], 0)
        self.assertEqual(open(path, "rb").read()[-8:-4], b"FDCK")

    def test_finished_case_edited_to_running_does_not_step_past_its_end(self):
        d = self.d
        done = self.finished_case()
        self.assertEqual(d.stop()[0], 0)
        edit_json(os.path.join(d.data_dir, done["id"], "status.json"), state="running")
        d.start()
        st = d.status(done["id"])
        self.assertEqual(st["state"], "finished", st)
        self.assertEqual(st["step"], done["step"])
        self.assertEqual(d.json("POST", "/cases/%s/start" % done["id"])[0], 409)
        time.sleep(0.2)
        self.assertEqual(d.status(done["id"])["step"], done["step"])
        times, steps = result_snapshots(d, done["id"])
        self.assertEqual(len(times), done["snapshots"])
        self.assertEqual(d.stop()[0], 0, d.log_tail())

    def test_damaged_result_file_is_a_clear_5xx(self):
        d = self.d
        truncated = self.finished_case()["id"]
        directory = self.finished_case()["id"]
        self.assertEqual(d.stop()[0], 0)
        path = os.path.join(d.data_dir, truncated, "result.h5")
        os.truncate(path, os.path.getsize(path) // 2)
        path = os.path.join(d.data_dir, directory, "result.h5")
        os.unlink(path)
        os.mkdir(path)
        d.start()
        for cid in (truncated, directory):
            status, headers, body = d.request("GET", "/cases/%s/result.h5" % cid)
            self.assertEqual(status, 500, body[:200])
            self.assertEqual(headers["content-type"], "application/problem+json")
            problem = json.loads(body)
            self.assertIn("result.h5", problem["detail"])
            self.assertIn("damaged", problem["detail"])
        self.assertEqual(d.request("GET", "/health")[0], 200)
        self.assertEqual(d.stop()[0], 0, d.log_tail())


class CheckpointEveryTest(unittest.TestCase):
    def test_progress_between_snapshots_survives_sigkill(self):
        d = Daemon(args=["--checkpoint-every", "0.5"])
        self.addCleanup(d.close)
        d.start()
        # ~8 s of work with 4 snapshots after t = 0: the 1st comes at ~2 s.
        case = d.case_lasting(8.0, name="slow")
        case["output"]["interval"] = case["time"]["end"] / 4
        cid = d.create(case, start=True)["id"]
        st = d.wait(cid, lambda s: s["snapshots"] >= 2, timeout=30, what="the first snapshot")
        time.sleep(1.5)
        before = d.status(cid)
        d.kill()
        d.start()
        st = d.status(cid)
        self.assertEqual(st["state"], "paused", st)
        # Within two checkpoint intervals of the step reached, not back at the last snapshot.
        self.assertGreater(st["step"], 0)
        # past the last snapshot it kept (timing-proof: a snapshot may have
        # landed between the status read and the kill)
        self.assertGreaterEqual(st["snapshots"], before["snapshots"], (st, before))
        last_snapshot_time = (st["snapshots"] - 1) * case["output"]["interval"]
        self.assertGreater(st["time"], last_snapshot_time, (st, before))
        self.assertEqual(d.json("POST", "/cases/%s/start" % cid)[0], 200)
        st = d.wait_state(cid, "finished", timeout=60)
        times, steps = result_snapshots(d, cid)
        self.assertEqual(len(times), 5, times)
        self.assertEqual(st["snapshots"], 5)
        interval = case["output"]["interval"]
        for k, t in enumerate(times):
            self.assertAlmostEqual(t / interval, k, delta=0.01, msg=list(times))
        self.assertTrue(all(b > a for a, b in zip(steps, steps[1:])), steps)
        self.assertEqual(d.stop()[0], 0, d.log_tail())


def run_mount(test, *args):
    done = subprocess.run(["mount"] + list(args), capture_output=True, text=True)
    if done.returncode != 0:
        test.skipTest("mount %s failed: %s" % (" ".join(args), done.stderr.strip()))


class ReadOnlyDataTest(unittest.TestCase):
    def test_read_only_data_directory_stops_startup(self):
        d, where = daemon_on_tmpfs(self, "4m")
        data = d.data_dir
        cid = d.create(tiny_case("paused", end=10.0), start=True)["id"]
        d.wait(cid, lambda s: s["step"] > 10, what="steps")
        d.json("POST", "/cases/%s/pause" % cid)
        self.assertEqual(d.stop()[0], 0)
        run_mount(self, "-o", "remount,ro", where)
        done = subprocess.run([FDEMD_BIN, "--listen", "127.0.0.1:0", "--data", data],
                              capture_output=True, text=True, timeout=10 * SLOW)
        self.assertEqual(done.returncode, 1, done.stdout + done.stderr)
        self.assertIn(data, done.stderr)
        self.assertIn("Read-only file system", done.stderr)
        self.assertEqual(done.stdout, "")

    def test_delete_answers_204_only_when_the_files_are_gone(self):
        if os.geteuid() != 0:
            self.skipTest("a read-only bind mount needs root")
        d = Daemon()
        self.addCleanup(d.close)
        d.start()
        cid = d.create(tiny_case("kept", end=0.0002), start=True)["id"]
        d.wait_state(cid, "finished")
        case_dir = os.path.join(d.data_dir, cid)
        run_mount(self, "--bind", case_dir, case_dir)
        self.addCleanup(subprocess.run, ["umount", "-l", case_dir], capture_output=True)
        run_mount(self, "-o", "remount,ro,bind", case_dir)
        status, problem = d.json("DELETE", "/cases/" + cid)
        self.assertEqual(status, 500, problem)
        self.assertIn(cid, problem["detail"])
        self.assertTrue(os.path.exists(os.path.join(case_dir, "result.h5")))
        listed = [c["id"] for c in d.json("GET", "/cases")[1]["cases"]]
        self.assertIn(cid, listed)
        self.assertEqual(d.status(cid)["state"], "finished")
        subprocess.run(["umount", case_dir], check=True)
        self.assertEqual(d.request("DELETE", "/cases/" + cid)[0], 204)
        self.assertFalse(os.path.exists(case_dir))
        self.assertEqual(d.request("GET", "/cases/" + cid)[0], 404)
        self.assertEqual(d.stop()[0], 0, d.log_tail())


class WholeOrNothingTest(unittest.TestCase):
    def test_half_made_cases_are_not_listed_after_restart(self):
        d = Daemon()
        self.addCleanup(d.close)
        d.start()
        good = d.create(tiny_case("good"))["id"]
        self.assertEqual(d.stop()[0], 0)
        # What a crash inside POST /cases leaves: a temporary directory (this
        # version) or a case directory without status.json (older versions).
        for name in (".tmp-0123456789abcdef", "fedcba9876543210"):
            os.makedirs(os.path.join(d.data_dir, name))
            shutil.copy(os.path.join(d.data_dir, good, "case.json"), os.path.join(d.data_dir, name))
        d.start()
        listed = {c["id"]: c for c in d.json("GET", "/cases")[1]["cases"]}
        self.assertEqual(list(listed), [good])
        self.assertFalse(os.path.exists(os.path.join(d.data_dir, ".tmp-0123456789abcdef")))
        self.assertEqual(d.stop()[0], 0, d.log_tail())

    def test_sigkill_during_post_leaves_no_half_made_case(self):
        d = Daemon()
        self.addCleanup(d.close)
        d.start()
        # Storing this one takes a while (a 120k-element mesh and result.h5).
        big = json.dumps(tiny_case("big", divisions=(250, 240))).encode()
        t0 = time.monotonic()
        status, _, body = d.request("POST", "/cases", big, {"Content-Type": "application/json"})
        store_time = time.monotonic() - t0
        self.assertEqual(status, 201, body[:300])
        acknowledged = {json.loads(body)["id"]}
        import threading
        for k in range(8):
            def post():
                try:
                    st, _, b = d.request("POST", "/cases", big, {"Content-Type": "application/json"})
                    if st == 201:
                        acknowledged.add(json.loads(b)["id"])
                except OSError:
                    pass
            t = threading.Thread(target=post)
            t.start()
            time.sleep(store_time * (0.1 + 0.8 * k / 7))
            d.kill()
            t.join()
            d.start()
            # each as GET /cases/ID has it: after its start-up check
            cases = [d.status(c["id"]) for c in d.json("GET", "/cases")[1]["cases"]]
            for c in cases:
                self.assertNotEqual(c["state"], "failed", (k, c))
            self.assertLessEqual(acknowledged, {c["id"] for c in cases})
            leftovers = [n for n in os.listdir(d.data_dir) if n.startswith(".tmp-")]
            self.assertEqual(leftovers, [])
        self.assertEqual(d.stop()[0], 0, d.log_tail())


class DownloadTest(unittest.TestCase):
    """Downloads of a running case take a consistent copy off the I/O
    thread, so they hold up neither other requests nor other cases."""

    def big_running_case(self, d, megabytes):
        # 80k elements: ~3.2 MB per snapshot, one snapshot every 2 steps.
        case = tiny_case("big", end=1.0, divisions=(200, 200))
        st = d.create(case)
        case["output"]["interval"] = 2 * st["dt"]
        case["time"]["end"] = 2 * st["dt"] * 100000
        d.request("DELETE", "/cases/" + st["id"])
        cid = d.create(case, start=True)["id"]
        d.wait(cid, lambda s: s["snapshots"] * 3.2 >= megabytes, timeout=60, what="a big result")
        return cid

    def test_concurrent_downloads_do_not_stall_a_tiny_post(self):
        import threading
        d = Daemon()
        self.addCleanup(d.close)
        d.start()
        cid = self.big_running_case(d, 150)

        def tiny_post_latencies(count):
            out = []
            for k in range(count):
                t0 = time.monotonic()
                status, _, _ = d.request("POST", "/cases", tiny_case("tiny%d" % k))
                out.append(time.monotonic() - t0)
                self.assertEqual(status, 201)
            return out
        # The running case's own snapshot writes (3.2 MB each) set the floor.
        baseline = tiny_post_latencies(5)
        sizes, errors = [], []
        kept = os.path.join(d.root, "download.h5")

        def download(keep):
            # Read in pieces and drop them: the client must not be what is slow.
            try:
                conn = d.connection()
                conn.request("GET", "/cases/%s/result.h5" % cid)
                resp = conn.getresponse()
                out = open(kept, "wb") if keep else None
                n = 0
                while True:
                    piece = resp.read(1 << 20)
                    if not piece:
                        break
                    n += len(piece)
                    if out:
                        out.write(piece)
                if out:
                    out.close()
                conn.close()
                sizes.append((resp.status, n))
            except Exception as e:  # pylint: disable=broad-except
                errors.append(e)
        threads = [threading.Thread(target=download, args=(k == 0,)) for k in range(6)]
        for t in threads:
            t.start()
        time.sleep(0.05)
        latencies = tiny_post_latencies(5)
        for t in threads:
            t.join()
        self.assertEqual(errors, [])
        self.assertTrue(all(s == 200 and n > 100e6 for s, n in sizes) and len(sizes) == 6, sizes)
        print("  tiny POST: max %.3f s alone, %.3f s during 6 downloads of ~%.0f MB" %
              (max(baseline), max(latencies), max(n for _, n in sizes) / 1e6), file=sys.stderr)
        self.assertLess(max(latencies), max(0.5 * SLOW, 2 * max(baseline)), (baseline, latencies))
        # A download is a plain, valid HDF5 file of whole snapshots.
        with h5py.File(kept, "r") as f:
            times = f["/snapshots/time"][...]
            self.assertEqual(f["/snapshots/position"].shape[0], len(times))
        self.assertGreater(len(times), 30)
        self.assertTrue(all(b > a for a, b in zip(times, times[1:])))
        d.json("POST", "/cases/%s/stop" % cid)
        self.assertEqual(d.stop()[0], 0, d.log_tail())

    def test_download_on_a_full_disk_is_a_507(self):
        d, _ = daemon_on_tmpfs(self, "64m")
        data = d.data_dir
        # A running case (its file open for writing, so a download needs a
        # copy) that writes nothing more during the test: its next snapshot
        # is half a minute away. (A paused case's file is closed and sent as
        # it is: no copy, no room needed.)
        case = d.case_lasting(60.0, name="running", divisions=(60, 60))
        case["output"]["interval"] = case["time"]["end"] / 2
        cid = d.create(case, start=True)["id"]
        d.wait(cid, lambda s: s["state"] == "running" and s["step"] > 0, what="running")
        # Fill the disk, then ask for the file of the running case.
        filler = os.path.join(data, "filler")
        with open(filler, "wb") as f:
            try:
                while True:
                    f.write(b"\0" * 65536)
                    f.flush()
            except OSError:
                pass
        status, headers, body = d.request("GET", "/cases/%s/result.h5" % cid)
        self.assertIn(status, (500, 507), body[:200])
        self.assertEqual(headers["content-type"], "application/problem+json")
        self.assertIn("No space left on device", json.loads(body)["detail"])
        os.unlink(filler)
        self.assertEqual(d.request("GET", "/cases/%s/result.h5" % cid)[0], 200)
        self.assertEqual(d.stop()[0], 0, d.log_tail())


if __name__ == "__main__":
    unittest.main()
