"""test_excavation.py - a case in stages with excavation (contract 6.1)
through the real daemon on loopback.

A block under in-situ stress, held by rollers, with a hole's worth of
elements that a second stage excavates and relaxes; in 2D and 3D. What the
daemon makes of it: the status' "stage" as the case runs and once it is
finished, /snapshots/stage and /snapshots/active in result.h5 (0 exactly
for the elements whose centroid is in the hole, from the row of the
excavating stage's first step on, and nothing else excavated), the `active`
cell attribute of result.xdmf, GET /state's stage and flags, fdemctl's and
the Python client's stage, a stage's own constraint acting during it only,
a pause plus a daemon restart in the middle of the relaxation giving the
uninterrupted run's bits, an extend running the last stage on, and every
bad stage in one 422 at its pointer. Nothing here waits for wall time: it
waits for states (and sizes the long run by this machine's speed)."""
import json
import os
import shutil
import subprocess
import sys
import unittest

import numpy as np

from fdemd_harness import Daemon, DaemonTestCase, fetched_result

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "clients", "python"))
from fdemd_client import Client, stage_label  # noqa: E402

PVPYTHON = shutil.which("pvpython")
READERS = ("XDMFReader", "Xdmf3ReaderS", "Xdmf3ReaderT")

SIZE = 1.0
HOLE_2D = [0.3, 0.3, 0.7, 0.7]
HOLE_3D = [0.25, 0.25, 0.25, 0.75, 0.75, 0.75]
STRESS = -1e6  # Pa, compression
SHEAR = 1000.0  # N (2D: per metre), along x on the top face, in stage 1 only


def excavation_case(name, end=0.002, divisions=12, dimension=2, interval=None):
    """A SIZE block under STRESS on rollers on every face (at rest at t = 0:
    the rollers carry the stress); stage "in-situ" to end / 2, then
    "excavate" removes the hole and relaxes over 0.6 of its length while
    its own force shears the top face."""
    half = end / 2
    if dimension == 3:
        shape = {"box": {"origin": [0, 0, 0], "size": [SIZE] * 3, "divisions": [divisions] * 3}}
        stress = [STRESS, STRESS, STRESS, 0, 0, 0]
        rollers = [{"box": [-1, -1, at - 1e-6, 2, 2, at + 1e-6], "fix": ["z"]} for at in (0, SIZE)]
        rollers += [{"box": [-1, at - 1e-6, -1, 2, at + 1e-6, 2], "fix": ["y"]} for at in (0, SIZE)]
        rollers += [{"box": [at - 1e-6, -1, -1, at + 1e-6, 2, 2], "fix": ["x"]} for at in (0, SIZE)]
        top = {"box": [-1, -1, SIZE - 1e-6, 2, 2, SIZE + 1e-6], "force": [SHEAR, 0, 0]}
        hole = HOLE_3D
    else:
        shape = {"rectangle": {"origin": [0, 0], "size": [SIZE, SIZE],
                               "divisions": [divisions, divisions]}}
        stress = [STRESS, STRESS, 0]
        rollers = [{"box": [-1, at - 1e-6, 2, at + 1e-6], "fix": ["y"]} for at in (0, SIZE)]
        rollers += [{"box": [at - 1e-6, -1, at + 1e-6, 2], "fix": ["x"]} for at in (0, SIZE)]
        top = {"box": [-1, SIZE - 1e-6, 2, SIZE + 1e-6], "force": [SHEAR, 0]}
        hole = HOLE_2D
    return {
        "name": name, "dimension": dimension,
        "materials": {"rock": {"density": 2500, "young": 1e10, "poisson": 0.25}},
        "parts": [dict({"name": "block", "material": "rock",
                        "initial_stress": {"value": stress}}, **shape)],
        "constraints": rollers,
        "stages": [{"name": "in-situ", "end": half},
                   {"name": "excavate", "end": end, "relax": 0.6 * half,
                    "excavate": [{"box": hole}], "constraints": [top]}],
        "output": {"interval": interval or end / 20,
                   "fields": ["position", "velocity", "stress"]},
    }


def hole_elements(f, hole):
    """Which elements of the file's mesh have their centroid in the hole."""
    x0 = f["/mesh/position0"][...]
    cells = f["/mesh/tetrahedra" if "tetrahedra" in f["/mesh"] else "/mesh/triangles"][...]
    c = x0[cells].mean(axis=1)
    dim = c.shape[1]
    lo, hi = np.array(hole[:dim]), np.array(hole[dim:])
    return np.all((c >= lo) & (c <= hi), axis=1)


def hole_size(f, hole):
    """Area (2D) or volume (3D) of the elements with their centroid in the hole."""
    x0 = f["/mesh/position0"][...]
    solid = "tetrahedra" in f["/mesh"]
    cells = f["/mesh/tetrahedra" if solid else "/mesh/triangles"][...]
    corners = x0[cells[hole_elements(f, hole)]]
    edges = corners[:, 1:] - corners[:, :1]
    if solid:
        return np.abs(np.linalg.det(edges)).sum() / 6
    return np.abs(np.cross(edges[:, 0], edges[:, 1])).sum() / 2


def strain_energy_density(dimension, young=1e10, poisson=0.25):
    """Of the hydrostatic in-situ STRESS: 3D s^2 3(1 - 2 nu)/(2E); 2D plane
    strain, where szz = nu (sxx + syy) = 2 nu s, (1/2E)(sxx^2 + syy^2 + szz^2
    - 2 nu (sxx syy + syy szz + szz sxx))."""
    s, nu = STRESS, poisson
    if dimension == 3:
        return 3 * s * s * (1 - 2 * nu) / (2 * young)
    z = 2 * nu * s
    return (2 * s * s + z * z - 2 * nu * (s * s + 2 * s * z)) / (2 * young)


def read_snapshots(daemon, case_id):
    with fetched_result(daemon, case_id) as f:
        return {name: f["/snapshots/" + name][...] for name in f["/snapshots"]}


class ExcavationTests(DaemonTestCase):
    PREFIX = "fdemd-excavation-"

    def run_finished(self, case):
        st = self.d.create(case, start=True)
        st = self.d.wait_state(st["id"], ("finished", "failed", "stopped"), timeout=120)
        self.assertEqual(st["state"], "finished", st.get("error"))
        return st

    def check_result(self, case_id, case, hole):
        """stage and active rows against the stage ends and the hole."""
        end0 = case["stages"][0]["end"]
        with fetched_result(self.d, case_id) as f:
            stage = f["/snapshots/stage"][...]
            active = f["/snapshots/active"][...]
            time = f["/snapshots/time"][...]
            dt = f.attrs["dt"]
            self.assertEqual(f["/snapshots/stage"].dtype, np.int32)
            self.assertEqual(f["/snapshots/active"].dtype, np.uint8)
            in_hole = hole_elements(f, hole)
            force = f["/snapshots/constraint_force"][...]
        self.assertEqual(active.shape, (len(time), len(in_hole)))
        self.assertTrue(in_hole.any() and not in_hole.all())
        # the stage of each row: that of the step that ended at it
        want = np.where(time - dt < end0 * (1 - 1e-12), 0, 1)
        want[0] = 0
        np.testing.assert_array_equal(stage, want)
        self.assertEqual(list(np.unique(stage)), [0, 1])
        # every element there in stage 0; the hole's gone (only they) after
        np.testing.assert_array_equal(active[stage == 0], 1)
        np.testing.assert_array_equal(active[stage == 1], np.tile(~in_hole, ((stage == 1).sum(), 1)))
        # the stage's own force (the last constraint) acts in its stage only
        top = force[:, -1, :]
        np.testing.assert_array_equal(top[stage == 0], 0)
        np.testing.assert_allclose(top[stage == 1][:, 0], SHEAR, rtol=1e-12)
        return active[-1]

    def check_xdmf(self, case_id, snapshots):
        with open(os.path.join(self.d.data_dir, case_id, "result.xdmf")) as f:
            text = f.read()
        self.assertEqual(text.count('<Attribute Name="active" AttributeType="Scalar" '
                                    'Center="Cell">'), snapshots)
        self.assertIn('NumberType="UChar" Precision="1"', text)

    def check_excavation(self, dimension, divisions, hole):
        d = self.d
        case = excavation_case("dig-%dd" % dimension, dimension=dimension, divisions=divisions)
        created = d.create(case)
        self.assertEqual(created["stage"], {"index": 0, "name": "in-situ"})
        d.json("POST", "/cases/%s/start" % created["id"])
        st = d.wait_state(created["id"], ("finished", "failed", "stopped"), timeout=120)
        self.assertEqual(st["state"], "finished", st.get("error"))
        self.assertEqual(st["stage"], {"index": 1, "name": "excavate"})
        self.assertEqual(st["end_time"], case["stages"][-1]["end"])
        last_active = self.check_result(st["id"], case, hole)
        self.check_xdmf(st["id"], st["snapshots"])
        status, state = d.json("GET", "/cases/%s/state?fields=position" % st["id"])
        self.assertEqual(status, 200, state)
        self.assertEqual(state["stage"], {"index": 1, "name": "excavate"})
        self.assertEqual(state["active"], [int(a) for a in last_active])
        # at rest in stage 0 (the rollers carry the stress), the hole takes
        # away exactly its in-situ strain energy: the status' account
        with fetched_result(self.d, st["id"]) as f:
            taken = strain_energy_density(dimension) * hole_size(f, hole)
        print("  %dD: excavated %.12g J, closed form %.12g J (%.1e); residual %.3g J"
              % (dimension, st["energy"]["excavated"], taken,
                 st["energy"]["excavated"] / taken - 1, st["energy"]["residual"]), flush=True)
        self.assertAlmostEqual(st["energy"]["excavated"] / taken, 1.0, delta=1e-9)
        self.assertEqual(read_snapshots(d, st["id"])["excavated_energy"][-1],
                         st["energy"]["excavated"])
        return st

    def test_2d_stage_status_result_and_sidecar(self):
        st = self.check_excavation(2, 12, HOLE_2D)
        out = self.d.fdemctl("status", st["id"])
        self.assertEqual(out.returncode, 0, out.stderr)
        self.assertIn('stage         1 "excavate"', out.stdout)
        client = Client("http://127.0.0.1:%d" % self.d.port)
        self.assertEqual(client.stage(st["id"]), (1, "excavate"))
        self.assertEqual(stage_label(client.status(st["id"])), 'stage 1 "excavate"')

    def test_3d_stage_status_result_and_sidecar(self):
        self.check_excavation(3, 4, HOLE_3D)

    def test_plot_result_leaves_excavated_elements_out(self):
        """plot_result.py masks the excavated triangles (2D) and draws the
        surface of the elements still there (3D: the cavity's walls show),
        and writes its PNG."""
        import h5py
        import plot_result
        for dimension, divisions, hole in ((2, 12, HOLE_2D), (3, 4, HOLE_3D)):
            st = self.run_finished(excavation_case("plot-%dd" % dimension, dimension=dimension,
                                                   divisions=divisions))
            path = os.path.join(self.tmp, st["id"] + ".h5")
            status, _, data = self.d.request("GET", "/cases/%s/result.h5" % st["id"])
            with open(path, "wb") as f:
                f.write(data)
            with h5py.File(path, "r") as f:
                gone = hole_elements(f, hole)
                if dimension == 2:
                    tri, _, _ = plot_result.snapshot_triangulation(f, -1)
                    np.testing.assert_array_equal(tri.mask, gone)
                    self.assertFalse(plot_result.snapshot_triangulation(f, 0)[0].mask.any())
                else:
                    faces, element = plot_result.surface_of_snapshot(f, -1)
                    self.assertFalse(gone[element].any())
                    whole, _ = plot_result.surface_of_snapshot(f, 0)
                    self.assertGreater(len(faces), len(whole))  # the cavity's walls
            out = subprocess.run([sys.executable, os.path.join(ROOT, "clients", "python",
                                                               "plot_result.py"),
                                  path, "-o", path + ".png"], capture_output=True, text=True)
            self.assertEqual(out.returncode, 0, out.stderr)
            self.assertGreater(os.path.getsize(path + ".png"), 1000)

    def pvload(self, reader, xdmf, *extra):
        out = subprocess.run([PVPYTHON, os.path.join(HERE, "paraview_load.py"), reader, xdmf]
                             + list(extra), capture_output=True, text=True, timeout=300)
        self.assertEqual(out.returncode, 0, out.stderr[-3000:])
        self.assertEqual(out.stderr.strip(), "", "%s printed:\n%s" % (reader, out.stderr[-3000:]))
        got = json.loads(out.stdout.strip().splitlines()[-1])
        self.assertEqual(got["messages"].strip(), "", reader)
        return got["steps"]

    @unittest.skipUnless(PVPYTHON, "pvpython is not installed (python3-paraview)")
    def test_paraview_colours_and_thresholds_by_active(self):
        """`active` as every ParaView XDMF reader reads it (without a
        message), and Threshold on it (1 to 1) leaves exactly the elements
        not excavated."""
        for dimension, divisions in ((2, 6), (3, 4)):
            case = excavation_case("pv-%dd" % dimension, dimension=dimension,
                                   divisions=divisions, interval=0.0005)
            st = self.run_finished(case)
            folder = os.path.join(self.tmp, st["id"])
            os.makedirs(folder)
            for name in ("result.h5", "result.xdmf"):
                status, _, data = self.d.request("GET", "/cases/%s/%s" % (st["id"], name))
                self.assertEqual(status, 200)
                with open(os.path.join(folder, name), "wb") as f:
                    f.write(data)
            with fetched_result(self.d, st["id"]) as f:
                active = f["/snapshots/active"][...]
            self.assertLess(active[-1].sum(), active.shape[1])
            xdmf = os.path.join(folder, "result.xdmf")
            for reader in READERS:
                first, last = self.pvload(reader, xdmf)
                for step, row in ((first, active[0]), (last, active[-1])):
                    got = np.array(step["blocks"][0]["cell_data"]["active"])[:, 0]
                    np.testing.assert_array_equal(got, row, (reader, dimension))
            # in ParaView's default reader for .xdmf (each load takes seconds)
            first, last = self.pvload("Xdmf3ReaderT", xdmf, "threshold:active")
            self.assertEqual(first["blocks"][0]["cells"], active.shape[1])
            self.assertEqual(last["blocks"][0]["cells"], int(active[-1].sum()))

    def test_case_without_stages_has_no_stage(self):
        case = excavation_case("plain")
        del case["stages"]
        case["time"] = {"end": 0.0005}
        st = self.run_finished(case)
        self.assertIsNone(st["stage"])
        snapshots = read_snapshots(self.d, st["id"])
        self.assertNotIn("stage", snapshots)
        self.assertNotIn("active", snapshots)
        self.assertNotIn("excavated_energy", snapshots)
        state = self.d.json("GET", "/cases/%s/state" % st["id"])[1]
        self.assertEqual(set(state), {"step", "time", "position", "velocity"})
        out = self.d.fdemctl("status", st["id"])
        self.assertNotIn("stage", out.stdout)

    def test_extend_runs_the_last_stage_on(self):
        """An extend rewrites the last stage's end, and the continued run is
        bit for bit the one asked for the new end from the start."""
        d = self.d
        case = excavation_case("extended", end=0.001)
        st = self.run_finished(case)
        before = read_snapshots(d, st["id"])
        status, body = d.json("POST", "/cases/%s/extend" % st["id"], {"end": 0.0015})
        self.assertEqual(status, 200, body)
        doc = d.json("GET", "/cases/%s/case" % st["id"])[1]
        self.assertEqual(doc["stages"][-1]["end"], 0.0015)
        self.assertNotIn("end", doc.get("time", {}))
        d.json("POST", "/cases/%s/start" % st["id"])
        st = d.wait_state(st["id"], ("finished", "failed"), timeout=120)
        self.assertEqual((st["state"], st["time"]), ("finished", 0.0015), st.get("error"))
        self.assertEqual(st["stage"], {"index": 1, "name": "excavate"})
        after = read_snapshots(d, st["id"])
        self.assertEqual(after["stage"][-1], 1)
        case["name"] = "straight"
        case["stages"][1]["end"] = 0.0015
        straight = read_snapshots(d, self.run_finished(case)["id"])
        n = len(before["time"])
        later = straight["time"] > 0.001
        self.assertEqual(len(after["time"]), n + int(later.sum()))
        for name, rows in before.items():
            np.testing.assert_array_equal(after[name][:n], rows, err_msg=name)
            np.testing.assert_array_equal(after[name][n:], straight[name][later], err_msg=name)

    def test_bad_stages_are_one_422_with_pointers(self):
        case = excavation_case("bad")
        case["stages"] = [
            {"name": "in-situ", "end": 0.002, "relx": 0.1},
            {"name": "in-situ", "end": 0.001, "excavate": [{"part": "blok"}, {"box": [1, 2]}]},
            {"name": "late", "excavate": [{"part": "block", "group": "g"}]},
        ]
        case["time"] = {"end": 0.003}
        status, problem = self.d.json("POST", "/cases", case)
        self.assertEqual(status, 422, problem)
        found = {(e["pointer"]) for e in problem["errors"]}
        for pointer in ("/stages/0/relx", "/stages/1", "/stages/1/end",
                        "/stages/1/excavate/0/part", "/stages/1/excavate/1/box", "/stages/2",
                        "/stages/2/excavate/0/group"):
            self.assertIn(pointer, found, problem)
        # a box that takes no element is known once the block is meshed
        case = excavation_case("empty-box")
        case["stages"][1]["excavate"] = [{"box": [5, 5, 6, 6]}]
        status, problem = self.d.json("POST", "/cases", case)
        self.assertEqual(status, 422, problem)
        self.assertEqual([e["pointer"] for e in problem["errors"]], ["/stages/1/excavate/0"])
        case = excavation_case("time-end")
        case["time"] = {"end": 0.005}
        status, problem = self.d.json("POST", "/cases", case)
        self.assertEqual(status, 422, problem)
        self.assertEqual([e["pointer"] for e in problem["errors"]], ["/time/end"])


class PauseRestartTests(unittest.TestCase):
    """Paused during the relaxation and the daemon restarted, or stepped on
    two threads: the same bits as the uninterrupted run on one."""

    def test_two_threads_give_the_same_bits(self):
        runs = []
        for dimension in (2, 3):
            for threads in (1, 2):
                d = Daemon(args=["--threads", str(threads)]).start()
                try:
                    case = excavation_case("threads", dimension=dimension,
                                           divisions=12 if dimension == 2 else 4)
                    case_id = d.create(case, start=True)["id"]
                    st = d.wait_state(case_id, ("finished", "failed"), timeout=120)
                    self.assertEqual(st["state"], "finished", st.get("error"))
                    runs.append(read_snapshots(d, case_id))
                finally:
                    d.close()
        for one, two in (runs[0:2], runs[2:4]):
            self.assertEqual(sorted(one), sorted(two))
            for name in one:
                np.testing.assert_array_equal(one[name], two[name], err_msg=name)
            self.assertEqual(list(np.unique(one["stage"])), [0, 1])

    def test_pause_and_restart_give_the_same_bits(self):
        d = Daemon().start()
        try:
            rate, _ = d.steps_per_second()  # of a 200-element case
            probe = d.create(excavation_case("probe", end=1e-4), start=True)
            probe = d.wait_state(probe["id"], "finished", timeout=60)
            # about three seconds of stepping here, for the pause to land in
            end = 3.0 * rate * 200 / probe["elements"] * probe["dt"]
            case = excavation_case("straight", end=end)
            straight = d.create(case, start=True)["id"]
            case["name"] = "interrupted"
            interrupted = d.create(case, start=True)["id"]
            relaxing = case["stages"][0]["end"] + 0.1 * case["stages"][1]["relax"]
            st = d.wait(interrupted, lambda s: s["time"] > relaxing or s["state"] == "finished",
                        timeout=120, what="the relaxation")
            st = d.json("POST", "/cases/%s/pause" % interrupted)[1]
            st = d.wait_state(interrupted, ("paused", "finished"))
            self.assertEqual(st["state"], "paused", "finished before it could be paused")
            self.assertEqual(st["stage"]["index"], 1)
            self.assertLess(st["time"], case["stages"][0]["end"] + case["stages"][1]["relax"])
            # the straight run ends before the daemon stops (a stop pauses it)
            st = d.wait_state(straight, ("finished", "failed"), timeout=120)
            self.assertEqual(st["state"], "finished", st.get("error"))
            code, _ = d.stop()
            self.assertEqual(code, 0)
            d.start()
            self.assertEqual(d.status(interrupted)["stage"], {"index": 1, "name": "excavate"})
            d.json("POST", "/cases/%s/start" % interrupted)
            for case_id in (straight, interrupted):
                st = d.wait_state(case_id, ("finished", "failed"), timeout=120)
                self.assertEqual(st["state"], "finished", st.get("error"))
            a, b = read_snapshots(d, straight), read_snapshots(d, interrupted)
            self.assertEqual(sorted(a), sorted(b))
            for name in a:
                np.testing.assert_array_equal(a[name], b[name], err_msg=name)
            self.assertEqual(list(np.unique(a["stage"])), [0, 1])
        finally:
            d.close()


if __name__ == "__main__":
    unittest.main()
