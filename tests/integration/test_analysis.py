"""Results you can analyse (contract 5.4) through the real daemon: a
fracturing bar pulled apart at both ends breaks, and GET /cases/ID/fragments
lists pieces whose masses sum to the model's mass (rho x area) to 1e-9
relative and whose count is the status' fragments; /snapshots/fragment in
result.h5 labels the same pieces; the sieve curve is the mass fraction by
hand; fdemctl and the Python client show the same; the route has its
404/405/400; result.h5 carries the uploaded case document (its `case`
attribute parses to it) and the part and material names; strain and
principal_stress are in the state and the file with the contract's shapes;
the dry run's result size counts the new datasets. In 3D, two separate
boxes are two fragments of rho V each (skipped with the daemon's reason
while multi-part 3D cases are refused)."""
import json
import os
import shutil
import subprocess
import sys
import unittest

import h5py
import numpy as np

from fdemd_harness import ROOT, SLOW, DaemonTestCase, tiny_case

sys.path.insert(0, os.path.join(ROOT, "clients", "python"))
import fdemd_client  # noqa: E402

RHO = 2700.0
BAR = (0.1, 0.01)  # m, 20 x 2 divisions


def pulled_bar(end=1e-4):
    """A breakable bar whose end columns are pulled apart at 5 m/s each."""
    return {
        "name": "pulled-bar",
        "materials": {"rock": {"density": RHO, "young": 3e10, "poisson": 0.25, "damping": 0.5,
                               "friction": 0.3,
                               "fracture": {"tensile_strength": 1e6, "cohesion": 3e6,
                                            "friction_angle": 30, "energy_I": 10,
                                            "energy_II": 50}}},
        "parts": [{"name": "bar", "material": "rock", "fracture": True,
                   "rectangle": {"origin": [0, 0], "size": list(BAR), "divisions": [20, 2]}}],
        "constraints": [{"box": [-1e-9, -1, 1e-9, 1], "velocity": [-5, None]},
                        {"box": [BAR[0] - 1e-9, -1, BAR[0] + 1e-9, 1], "velocity": [5, None]}],
        "time": {"end": end},
        "output": {"interval": end / 10,
                   "fields": ["position", "velocity", "stress", "strain", "principal_stress"]},
    }


class FragmentsThroughDaemon(DaemonTestCase):
    PREFIX = "fdemd-analysis-"

    @classmethod
    def setUpClass(cls):
        super().setUpClass()
        cls.case = pulled_bar()
        st = cls.d.create(cls.case, start=True)
        cls.case_id = st["id"]
        cls.final = cls.d.wait_state(cls.case_id, ("finished", "failed", "stopped"), timeout=120)
        status, cls.fragments = cls.d.json("GET", "/cases/%s/fragments" % cls.case_id)
        assert status == 200, (status, cls.fragments)
        status, _, data = cls.d.request("GET", "/cases/%s/result.h5" % cls.case_id)
        assert status == 200, status
        cls.h5 = os.path.join(cls.tmp, "bar.h5")
        with open(cls.h5, "wb") as f:
            f.write(data)

    def test_masses_sum_to_the_model_and_count_is_the_status(self):
        self.assertEqual(self.final["state"], "finished", self.final.get("error"))
        pieces = self.fragments["fragments"]
        self.assertGreaterEqual(len(pieces), 2, "the bar did not break")
        self.assertEqual(len(pieces), self.final["fragments"])
        total = sum(p["mass"] for p in pieces)
        self.assertAlmostEqual(total / (RHO * BAR[0] * BAR[1]), 1.0, delta=1e-9)
        with h5py.File(self.h5, "r") as f:
            node_mass = f["/mesh/node_mass"][...].sum()
        self.assertAlmostEqual(total / node_mass, 1.0, delta=1e-9)
        self.assertEqual(sum(p["elements"] for p in pieces), self.final["elements"])
        self.assertEqual([p["id"] for p in pieces], list(range(len(pieces))))
        self.assertEqual(self.fragments["step"], self.final["step"])
        for p in pieces:
            self.assertAlmostEqual(p["mass"], RHO * p["size"], delta=1e-12 * p["mass"])
            self.assertAlmostEqual(p["diameter"], np.sqrt(4 * p["size"] / np.pi),
                                   delta=1e-12 * p["diameter"])
            self.assertEqual(len(p["centroid"]), 2)
            self.assertEqual(len(p["velocity"]), 2)
        # momentum: the pieces' sum is the nodes' (both from the same state)
        status, state = self.d.json("GET", "/cases/%s/state?fields=velocity" % self.case_id)
        self.assertEqual(status, 200, state)
        with h5py.File(self.h5, "r") as f:
            nodes = np.einsum("n,nk->k", f["/mesh/node_mass"][...], np.array(state["velocity"]))
        pieces_p = np.sum([np.multiply(p["mass"], p["velocity"]) for p in pieces], axis=0)
        np.testing.assert_allclose(pieces_p, nodes, atol=1e-9 * total * 5)

    def test_fragment_dataset_labels_the_same_pieces(self):
        with h5py.File(self.h5, "r") as f:
            frag = f["/snapshots/fragment"]
            self.assertEqual(frag.dtype, np.int32)
            labels = frag[...]
            step = f["/snapshots/step"][...]
        self.assertEqual(labels.shape, (len(step), self.final["elements"]))
        self.assertTrue(np.all(labels[0] == 0), "the intact bar is one fragment at t = 0")
        self.assertEqual(step[-1], self.fragments["step"])
        last = labels[-1]
        pieces = self.fragments["fragments"]
        self.assertEqual(int(last.max()) + 1, len(pieces))
        counts = np.bincount(last, minlength=len(pieces))
        self.assertEqual(counts.tolist(), [p["elements"] for p in pieces])

    def test_sieve_curve_is_the_mass_fraction(self):
        pieces = self.fragments["fragments"]
        curve = self.fragments["distribution"]
        total = sum(p["mass"] for p in pieces)
        diameters = [c["diameter"] for c in curve]
        self.assertEqual(diameters, sorted(set(p["diameter"] for p in pieces)))
        for c in curve:
            want = sum(p["mass"] for p in pieces if p["diameter"] <= c["diameter"]) / total
            self.assertAlmostEqual(c["passing"], want, delta=1e-12)
        self.assertEqual(curve[-1]["passing"], 1.0)

    def test_case_document_and_names_are_in_the_file(self):
        with h5py.File(self.h5, "r") as f:
            doc = f.attrs["case"]
            parts = [n.decode() if isinstance(n, bytes) else n for n in f["/mesh/part_names"][...]]
            materials = [n.decode() if isinstance(n, bytes) else n
                         for n in f["/mesh/material_names"][...]]
            # fixed-length: Octave's load('-hdf5') cannot read variable-length ones
            self.assertEqual(f["/mesh/part_names"].dtype.kind, "S")
            self.assertEqual(f["/mesh/material_names"].dtype.kind, "S")
        self.assertIsInstance(doc, str)
        self.assertEqual(json.loads(doc), self.case)
        self.assertEqual(parts, ["bar"])
        self.assertEqual(materials, ["rock"])

    def test_strain_and_principal_stress_in_file_and_state(self):
        e = self.final["elements"]
        with h5py.File(self.h5, "r") as f:
            strain = f["/snapshots/strain"][...]
            principal = f["/snapshots/principal_stress"][...]
            stress = f["/snapshots/stress"][...]
        s = len(strain)
        self.assertEqual(strain.shape, (s, e, 3))
        self.assertEqual(principal.shape, (s, e, 2))
        self.assertTrue(np.all(strain[0] == 0), "undeformed at t = 0")
        self.assertTrue(np.all(principal[:, :, 0] >= principal[:, :, 1]))
        # the principal values are those of the stress: trace and determinant
        sxx, syy, sxy = stress[..., 0], stress[..., 1], stress[..., 2]
        scale = np.abs(stress).max()
        np.testing.assert_allclose(principal.sum(axis=2), sxx + syy, atol=1e-9 * scale)
        np.testing.assert_allclose(principal[..., 0] * principal[..., 1], sxx * syy - sxy ** 2,
                                   atol=1e-9 * scale ** 2)
        status, state = self.d.json("GET", "/cases/%s/state?fields=strain,principal_stress"
                                    % self.case_id)
        self.assertEqual(status, 200, state)
        self.assertEqual(np.array(state["strain"]).shape, (e, 3))
        self.assertEqual(np.array(state["principal_stress"]).shape, (e, 2))
        self.assertEqual(state["step"], self.fragments["step"])
        np.testing.assert_array_equal(np.array(state["strain"]), strain[-1])
        np.testing.assert_array_equal(np.array(state["principal_stress"]), principal[-1])

    def test_octave_loads_the_file(self):
        octave = shutil.which("octave-cli")
        if not octave:
            self.skipTest("octave-cli is not installed (Debian's octave package)")
        script = ("r = load('-hdf5', '%s'); printf('%%s|%%s|%%d|%%d\\n', r.mesh.part_names, "
                  "r.mesh.material_names, size(r.snapshots.fragment, 1), "
                  "max(r.snapshots.fragment(:, end)) + 1);" % self.h5)
        r = subprocess.run([octave, "--no-gui", "--eval", script], capture_output=True,
                           text=True, timeout=120 * SLOW)
        line = [x for x in r.stdout.splitlines() if "|" in x]
        self.assertTrue(line, r.stdout + r.stderr)
        self.assertEqual(line[0].split("|"), ["bar", "rock", str(self.final["elements"]),
                                              str(len(self.fragments["fragments"]))])

    def test_fdemctl_prints_table_and_curve(self):
        r = self.d.fdemctl("fragments", self.case_id)
        self.assertEqual(r.returncode, 0, r.stderr)
        n = len(self.fragments["fragments"])
        self.assertIn("%d fragments" % n, r.stdout)
        self.assertIn("kg per metre of thickness", r.stdout)  # a 2D case
        self.assertIn("sieve curve", r.stdout)
        self.assertIn("100.00 %", r.stdout)
        rows = [line for line in r.stdout.splitlines() if line.split()[:1] and
                line.split()[0].isdigit() and len(line.split()) >= 7]
        self.assertEqual(len(rows), n, r.stdout)
        raw = self.d.fdemctl("fragments", self.case_id, "--json")
        self.assertEqual(json.loads(raw.stdout), self.fragments)

    def test_python_client_fragments(self):
        client = fdemd_client.Client("http://127.0.0.1:%d" % self.d.port)
        self.assertEqual(client.fragments(self.case_id), self.fragments)

    def test_route_errors(self):
        status, _ = self.d.json("GET", "/cases/0123456789abcdef/fragments")
        self.assertEqual(status, 404)
        for method in ("POST", "DELETE", "PUT"):
            status, headers, _ = self.d.request(method, "/cases/%s/fragments" % self.case_id)
            self.assertEqual(status, 405, method)
            self.assertEqual(headers["allow"], "GET, HEAD")
        status, problem = self.d.json("GET", "/cases/%s/fragments?fields=stress" % self.case_id)
        self.assertEqual(status, 400)
        self.assertIn("fields", problem["detail"])

    def test_running_case_has_one_piece(self):
        case = tiny_case("long", end=1e3, interval=1.0)
        st = self.d.create(case, start=True)
        try:
            self.d.wait_state(st["id"], ("running",))
            status, body = self.d.json("GET", "/cases/%s/fragments" % st["id"])
            self.assertEqual(status, 200, body)
            self.assertEqual(len(body["fragments"]), 1)
            self.assertAlmostEqual(body["fragments"][0]["mass"] / (RHO * 0.01), 1, delta=1e-9)
            self.assertEqual(body["distribution"], [{"diameter": body["fragments"][0]["diameter"],
                                                     "passing": 1.0}])
        finally:
            self.d.request("DELETE", "/cases/" + st["id"])

    def test_unknown_field_is_still_refused(self):
        case = tiny_case("bad-field")
        case["output"]["fields"] = ["position", "strains"]
        status, problem = self.d.json("POST", "/cases", case)
        self.assertEqual(status, 422, problem)
        self.assertIn("strain", json.dumps(problem))
        status, problem = self.d.json("GET", "/cases/%s/state?fields=principal" % self.case_id)
        self.assertEqual(status, 400)

    def test_dry_run_result_bytes_count_the_new_fields(self):
        # as test_service's file-size check, with strain and principal stress
        case = tiny_case("big-fields", end=0.0006, divisions=(60, 60), interval=0.00001)
        case["output"]["fields"] = ["position", "velocity", "stress", "strain", "principal_stress"]
        z = self.d.json("POST", "/cases?dry_run=true", case)[1]
        st = self.d.create(case, start=True)
        st = self.d.wait_state(st["id"], ("finished", "failed", "stopped"), timeout=120)
        self.assertEqual(st["state"], "finished", st)
        size = os.path.getsize(os.path.join(self.d.data_dir, st["id"], "result.h5"))
        self.d.request("DELETE", "/cases/" + st["id"])
        self.assertLessEqual(z["result_bytes"], size)
        self.assertGreater(z["result_bytes"], 0.95 * size, (z["result_bytes"], size))


class Fragments3DThroughDaemon(DaemonTestCase):
    """A box alone is one fragment of rho V; two boxes 0.2 m apart, one
    moving away, are two."""
    PREFIX = "fdemd-analysis-3d-"

    def test_one_box_is_one_fragment(self):
        size = [0.1, 0.2, 0.3]
        case = {"name": "box", "dimension": 3,
                "materials": {"rock": {"density": RHO, "young": 3e10, "poisson": 0.25}},
                "parts": [{"name": "box", "material": "rock", "velocity": [0, 0, -2],
                           "box": {"origin": [0, 0, 0], "size": size, "divisions": [2, 3, 3]}}],
                "time": {"end": 1e-4}, "output": {"interval": 5e-5}}
        st = self.d.create(case, start=True)
        st = self.d.wait_state(st["id"], ("finished", "failed"), timeout=120)
        self.assertEqual(st["state"], "finished", st.get("error"))
        status, frag = self.d.json("GET", "/cases/%s/fragments" % st["id"])
        self.assertEqual(status, 200, frag)
        self.assertEqual(len(frag["fragments"]), st["fragments"])
        self.assertEqual(len(frag["fragments"]), 1)
        volume = size[0] * size[1] * size[2]
        piece = frag["fragments"][0]
        self.assertAlmostEqual(piece["mass"] / (RHO * volume), 1, delta=1e-9)
        self.assertAlmostEqual(piece["diameter"], (6 * volume / np.pi) ** (1 / 3), delta=1e-12)
        np.testing.assert_allclose(piece["velocity"], [0, 0, -2], atol=1e-9)
        self.assertEqual(piece["elements"], st["elements"])
        r = self.d.fdemctl("fragments", st["id"])
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertRegex(r.stdout, r"1 fragments, total mass \S+ kg\n")  # 3D: no "per metre"

    def test_separate_boxes_are_two_fragments(self):
        size = [0.1, 0.1, 0.1]
        parts = [{"name": "still", "material": "rock",
                  "box": {"origin": [0, 0, 0], "size": size, "divisions": [2, 2, 2]}},
                 {"name": "moving", "material": "rock", "velocity": [1, 0, 0],
                  "box": {"origin": [0.3, 0, 0], "size": size, "divisions": [2, 2, 2]}}]
        case = {"name": "boxes", "dimension": 3,
                "materials": {"rock": {"density": RHO, "young": 3e10, "poisson": 0.25}},
                "parts": parts, "time": {"end": 1e-3},
                "output": {"interval": 2e-4, "fields": ["position", "strain", "principal_stress"]}}
        status, body = self.d.json("POST", "/cases?start=true", case)
        if status == 422 and "contact between tetrahedral parts" in json.dumps(body):
            self.skipTest("the daemon refuses multi-part 3D cases: %s"
                          % body["errors"][0]["message"] if body.get("errors") else body)
        self.assertEqual(status, 201, body)
        st = self.d.wait_state(body["id"], ("finished", "failed"), timeout=120)
        self.assertEqual(st["state"], "finished", st.get("error"))
        status, frag = self.d.json("GET", "/cases/%s/fragments" % st["id"])
        self.assertEqual(status, 200, frag)
        pieces = frag["fragments"]
        self.assertEqual(len(pieces), 2)
        self.assertEqual(len(pieces), st["fragments"])
        volume = size[0] * size[1] * size[2]
        self.assertAlmostEqual(sum(p["mass"] for p in pieces) / (2 * RHO * volume), 1, delta=1e-9)
        for p in pieces:
            self.assertAlmostEqual(p["size"] / volume, 1, delta=1e-12)
            self.assertAlmostEqual(p["diameter"], (6 * volume / np.pi) ** (1 / 3), delta=1e-12)
        self.assertAlmostEqual(pieces[1]["velocity"][0], 1.0, delta=1e-9)
        status, _, data = self.d.request("GET", "/cases/%s/result.h5" % st["id"])
        path = os.path.join(self.tmp, "boxes.h5")
        with open(path, "wb") as f:
            f.write(data)
        with h5py.File(path, "r") as f:
            e = f["/mesh/tetrahedra"].shape[0]
            s = f["/snapshots/time"].shape[0]
            self.assertEqual(f["/snapshots/fragment"].shape, (s, e))
            self.assertEqual(f["/snapshots/strain"].shape, (s, e, 6))
            self.assertEqual(f["/snapshots/principal_stress"].shape, (s, e, 3))
            self.assertEqual(json.loads(f.attrs["case"]), case)
            self.assertEqual([n.decode() if isinstance(n, bytes) else n
                              for n in f["/mesh/part_names"][...]], ["still", "moving"])


if __name__ == "__main__":
    unittest.main()
