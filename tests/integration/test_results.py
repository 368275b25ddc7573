"""result.h5 and result.xdmf as served by the daemon, read with h5py and
xml.etree: valid while the case runs (a consistent copy with every
snapshot written before the request), complete once it finished, and an
XDMF whose every HDF5 reference exists in the file."""
import os
import unittest
import xml.etree.ElementTree as ET

import h5py
import numpy as np

from fdemd_harness import DaemonTestCase, tiny_case


class ResultTest(DaemonTestCase):
    PREFIX = "fdemd-results-"

    def download(self, case_id, name):
        status, headers, data = self.d.request("GET", "/cases/%s/%s" % (case_id, name))
        self.assertEqual(status, 200, data[:200])
        path = os.path.join(self.tmp, "%s-%d-%s" % (case_id, len(os.listdir(self.tmp)), name))
        with open(path, "wb") as f:
            f.write(data)
        return path, headers

    def check_h5(self, path, st, fields=("position", "velocity", "stress")):
        """Shapes consistent with each other and with the status object."""
        with h5py.File(path, "r") as f:
            self.assertEqual(f.attrs["format"], b"fdem-result/1" if isinstance(f.attrs["format"], bytes)
                             else "fdem-result/1")
            self.assertEqual(int(f.attrs["dimension"]), 2)
            n, e = st["nodes"], st["elements"]
            self.assertEqual(f["/mesh/position0"].shape, (n, 2))
            self.assertEqual(f["/mesh/triangles"].shape, (e, 3))
            self.assertEqual(f["/mesh/node_mass"].shape, (n,))
            tri = f["/mesh/triangles"][...]
            self.assertTrue(tri.min() >= 0 and tri.max() < n)
            time = f["/snapshots/time"][...]
            step = f["/snapshots/step"][...]
            s = len(time)
            self.assertGreaterEqual(s, 1)
            self.assertEqual(time[0], 0.0)
            self.assertEqual(step.shape, (s,))
            self.assertTrue(np.all(np.diff(step) > 0), step)
            self.assertTrue(np.all(np.diff(time) > 0), time)
            shapes = {"position": (s, n, 2), "velocity": (s, n, 2), "stress": (s, e, 3)}
            for field in fields:
                self.assertEqual(f["/snapshots/" + field].shape, shapes[field], field)
                self.assertTrue(np.all(np.isfinite(f["/snapshots/" + field][...])), field)
            for name in ("kinetic_energy", "elastic_energy"):
                self.assertEqual(f["/snapshots/" + name].shape, (s,))
            self.assertEqual(f["/snapshots/constraint_force"].shape, (s, 1, 2))
            # The first snapshot is the initial state.
            np.testing.assert_array_equal(f["/snapshots/position"][0], f["/mesh/position0"][...])
            return s, time, step

    def check_xdmf(self, xdmf_path, h5_path):
        """Every HDF reference names a dataset of the file, and every
        hyperslab stays inside it."""
        root = ET.parse(xdmf_path).getroot()
        self.assertEqual(root.tag, "Xdmf")
        collections = root.findall("Domain/Grid")
        self.assertIn(len(collections), (1, 2))  # the mesh, and the joints when there are some
        grids = collections[0].findall("Grid[@GridType='Uniform']")
        self.assertGreaterEqual(len(grids), 1)
        if len(collections) == 2:
            self.assertEqual(len(collections[1].findall("Grid[@GridType='Uniform']")), len(grids))
        # the series of every snapshot as field data: (S, 1), (S, C * dimension)
        series = {a.find("DataItem") for a in root.iter("Attribute") if a.get("Center") == "Grid"}
        with h5py.File(h5_path, "r") as f:
            for item in root.iter("DataItem"):
                if item.get("Format") != "HDF":
                    continue
                file_name, _, dataset = item.text.strip().partition(":")
                self.assertEqual(file_name, "result.h5")
                self.assertIn(dataset, f, dataset)
                dims = [int(x) for x in item.get("Dimensions").split()]
                if item in series:  # a running case's file may have more rows by now
                    self.assertLessEqual(dims[0], f[dataset].shape[0], dataset)
                    self.assertEqual(int(np.prod(dims[1:])), int(np.prod(f[dataset].shape[1:])))
                else:
                    self.assertEqual(len(dims), f[dataset].ndim, dataset)
            for grid in root.findall(".//Grid[@GridType='Uniform']"):
                for slab in grid.iter("DataItem"):
                    if slab.get("ItemType") != "HyperSlab":
                        continue
                    select, source = list(slab)
                    start = [int(x) for x in select.text.split()][:3]
                    dataset = source.text.strip().partition(":")[2]
                    self.assertLess(start[0], f[dataset].shape[0], (dataset, start))
            times = [float(g.find("Time").get("Value")) for g in grids]
            np.testing.assert_allclose(times, f["/snapshots/time"][:len(times)], rtol=1e-12)
        return len(grids)

    def test_finished_result(self):
        st = self.d.create(tiny_case("done", end=0.001, interval=0.0001), start=True)
        st = self.d.wait_state(st["id"], "finished")
        path, headers = self.download(st["id"], "result.h5")
        self.assertEqual(headers["content-type"], "application/x-hdf5")
        s, time, step = self.check_h5(path, st)
        self.assertEqual(s, st["snapshots"])
        self.assertEqual(s, 11)
        np.testing.assert_allclose(time, np.arange(11) * 1e-4, atol=2 * st["dt"])
        self.assertEqual(step[-1], st["step"])
        xdmf, headers = self.download(st["id"], "result.xdmf")
        self.assertEqual(headers["content-type"], "application/xml")
        self.assertEqual(self.check_xdmf(xdmf, path), 11)
        # A second download of a finished case is the same file.
        again, _ = self.download(st["id"], "result.h5")
        with open(path, "rb") as a, open(again, "rb") as b:
            self.assertEqual(a.read(), b.read())

    def test_download_while_running(self):
        st = self.d.create(tiny_case("running", end=10.0, interval=2e-5), start=True)
        case_id = st["id"]
        try:
            before = self.d.wait(case_id, lambda s: s["snapshots"] >= 3, what="3 snapshots")
            xdmf, _ = self.download(case_id, "result.xdmf")
            path, _ = self.download(case_id, "result.h5")
            after = self.d.status(case_id)
            self.assertEqual(after["state"], "running")
            s, time, step = self.check_h5(path, after)
            # Every snapshot written before the request is in the copy.
            self.assertGreaterEqual(s, before["snapshots"])
            self.assertLessEqual(s, after["snapshots"])
            self.assertLessEqual(step[-1], after["step"])
            self.check_xdmf(xdmf, path)
            # Several downloads in a row stay valid and only grow.
            path2, _ = self.download(case_id, "result.h5")
            s2, _, _ = self.check_h5(path2, self.d.status(case_id))
            self.assertGreaterEqual(s2, s)
            # No temporary copies are left in the case directory.
            leftovers = [n for n in os.listdir(os.path.join(self.d.data_dir, case_id))
                         if n.startswith(".download")]
            self.assertEqual(leftovers, [])
        finally:
            self.d.request("DELETE", "/cases/" + case_id)

    def test_stopped_case_keeps_results(self):
        st = self.d.create(tiny_case("stopme", end=10.0, interval=2e-5), start=True)
        self.d.wait(st["id"], lambda s: s["snapshots"] >= 2, what="2 snapshots")
        status, st = self.d.json("POST", "/cases/%s/stop" % st["id"])
        self.assertEqual(st["state"], "stopped")
        path, _ = self.download(st["id"], "result.h5")
        s, time, step = self.check_h5(path, st)
        self.assertEqual(s, st["snapshots"])
        self.assertEqual(step[-1], st["step"])  # a final snapshot at the stop step
        xdmf, _ = self.download(st["id"], "result.xdmf")
        self.assertEqual(self.check_xdmf(xdmf, path), s)

    def test_created_case_has_initial_snapshot(self):
        st = self.d.create(tiny_case("fresh"))
        path, _ = self.download(st["id"], "result.h5")
        s, time, step = self.check_h5(path, st)
        self.assertEqual((s, list(step)), (1, [0]))


if __name__ == "__main__":
    unittest.main()
