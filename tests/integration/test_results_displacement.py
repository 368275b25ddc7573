"""The displacement field (issue 33, item 1; contract 6.2) through the real
daemon, in 2D and 3D.

Each case runs three times, differing only in `output.fields`: with
position and displacement ("with"), without displacement ("without") and
with displacement alone ("alone"). Then:

- /snapshots/displacement is (S, N, dimension) float64 and, to the bit,
  /snapshots/position - /mesh/position0 of the same file ("with") and of
  the run that never asked for it ("without" against "alone");
- asking for it changes nothing else: every other dataset and attribute of
  result.h5 (but the `case` document, which lists the fields), the status
  and the state are the bits of the run without it;
- result.xdmf names it in every grid as a Node Vector of 3 components (the
  /xdmf view, z = 0 in 2D) once the case is finished, and as a HyperSlab
  of row s while the case runs (legacy reader);
- GET /state?fields=displacement is the last row of the file and position
  - position0 of GET /state; "displacment" is a 400 there and a 422 at
  /output/fields/<i> with "did you mean" in a case;
- the dry run's result_bytes count it;
- plot_result.py --field displacement draws it to a PNG (2D and 3D, with
  and without position in the file), and says what to add when the file
  has neither.
The ParaView readers (and Warp By Vector) are checked in test_paraview.py.
"""
import os
import shutil
import subprocess
import unittest
import xml.etree.ElementTree as ET

import h5py
import numpy as np
from matplotlib import image

from fdemd_harness import ROOT, SLOW, DaemonTestCase, tiny_case
from test_observation_3d import file_items

PLOT = os.path.join(ROOT, "clients", "python", "plot_result.py")
PYTHON = "/usr/bin/python3"
FRACTURE = {"tensile_strength": 1e6, "cohesion": 2e6, "friction_angle": 30,
            "energy_I": 10, "energy_II": 50}
FIELDS = {"with": ["position", "velocity", "stress", "displacement"],
          "without": ["position", "velocity", "stress"],
          "alone": ["displacement"]}


def case_2d(name):
    """A fracturing block hitting a fixed base: it deforms, joints break."""
    case = tiny_case(name, end=0.002, divisions=(5, 5), interval=0.0002)
    case["materials"]["rock"]["fracture"] = FRACTURE
    case["parts"][0]["fracture"] = True
    case["gravity"] = [0, -9.81]
    return case


def case_3d(name):
    """A box dropped on its fixed base at 1 m/s, under gravity."""
    return {"name": name, "dimension": 3,
            "materials": {"rock": {"density": 2700, "young": 3e10, "poisson": 0.25}},
            "parts": [{"name": "body", "material": "rock", "velocity": [0.2, 0, -1],
                       "box": {"origin": [0, 0, 0], "size": [0.1, 0.1, 0.1],
                               "divisions": [2, 2, 2]}}],
            "constraints": [{"box": [-1, -1, -0.001, 1, 1, 0.001], "fix": ["x", "y", "z"]}],
            "gravity": [0, 0, -9.81], "time": {"end": 0.001},
            "output": {"interval": 0.0001}}


CASES = {2: case_2d, 3: case_3d}


def with_fields(case, fields):
    case["output"]["fields"] = list(fields)
    return case


def bits(a):
    return np.ascontiguousarray(a).tobytes()


def pad3(rows):
    out = np.zeros((len(rows), 3))
    out[:, :rows.shape[1]] = rows
    return out


class DisplacementTest(DaemonTestCase):
    PREFIX = "fdemd-displacement-"

    @classmethod
    def setUpClass(cls):
        super().setUpClass()
        cls.runs = {}
        started = {}
        for dim, make in CASES.items():
            for tag, fields in FIELDS.items():
                st = cls.d.create(with_fields(make("disp-%dd" % dim), fields), start=True)
                started[(dim, tag)] = st["id"]
        for (dim, tag), case_id in started.items():
            st = cls.d.wait_state(case_id, ("finished", "failed", "stopped"), timeout=120)
            assert st["state"] == "finished", st
            folder = os.path.join(cls.tmp, "%dd-%s" % (dim, tag))
            os.makedirs(folder)
            for name in ("result.h5", "result.xdmf"):
                status, _, data = cls.d.request("GET", "/cases/%s/%s" % (case_id, name))
                assert status == 200, (name, status, data[:200])
                with open(os.path.join(folder, name), "wb") as out:
                    out.write(data)
            cls.runs[(dim, tag)] = {"id": case_id, "status": st, "folder": folder,
                                    "h5": os.path.join(folder, "result.h5"),
                                    "xdmf": os.path.join(folder, "result.xdmf")}

    def state(self, case_id, fields=None):
        path = "/cases/%s/state" % case_id + ("?fields=" + fields if fields else "")
        status, body = self.d.json("GET", path)
        self.assertEqual(status, 200, body)
        return body

    # ------------------------------------------------------ result.h5
    def test_displacement_is_position_minus_position0_to_the_bit(self):
        for dim in CASES:
            run = self.runs[(dim, "with")]
            with h5py.File(run["h5"], "r") as f:
                u = f["/snapshots/displacement"]
                s = f["/snapshots/time"].shape[0]
                n = f["/mesh/position0"].shape[0]
                self.assertEqual(u.shape, (s, n, dim), dim)
                self.assertEqual((n, s), (run["status"]["nodes"], run["status"]["snapshots"]))
                self.assertEqual(u.dtype, np.float64)
                self.assertIsNone(u.maxshape[0], "displacement is extendible along S")
                x, x0 = f["/snapshots/position"][...], f["/mesh/position0"][...]
                self.assertEqual(bits(u[...]), bits(x - x0), "%dD: displacement != x - x0" % dim)
                self.assertFalse(np.any(u[0]), "%dD: the first snapshot moved" % dim)
                self.assertGreater(np.abs(u[-1]).max(), 1e-6, "%dD: nothing moved" % dim)

    def test_displacement_alone_is_the_position_of_the_run_without_it(self):
        for dim in CASES:
            with h5py.File(self.runs[(dim, "alone")]["h5"], "r") as alone, \
                    h5py.File(self.runs[(dim, "without")]["h5"], "r") as without, \
                    h5py.File(self.runs[(dim, "with")]["h5"], "r") as both:
                self.assertNotIn("/snapshots/position", alone)
                self.assertNotIn("/snapshots/displacement", without)
                u = alone["/snapshots/displacement"][...]
                x = without["/snapshots/position"][...]
                self.assertEqual(bits(u), bits(x - without["/mesh/position0"][...]), dim)
                self.assertEqual(bits(u), bits(both["/snapshots/displacement"][...]), dim)

    def assert_same_except_displacement(self, a, b, dim):
        """Every item of file a is in b with the same bits, but displacement
        and the `case` document; b has nothing a lacks but those."""
        with h5py.File(a, "r") as fa, h5py.File(b, "r") as fb:
            ia, ib = file_items(fa), file_items(fb)

        def ours(name):
            return (name == "@case" or name == "snapshots/displacement"
                    or (name.startswith("xdmf/") and name.endswith("/displacement")))
        self.assertEqual(sorted(k for k in ia if not ours(k)), sorted(k for k in ib if not ours(k)))
        for name in ia:
            if not ours(name):
                self.assertTrue(ia[name] == ib[name], "%dD: %s differs" % (dim, name))

    def test_asking_for_displacement_changes_no_other_bit(self):
        for dim in CASES:
            with_, without = self.runs[(dim, "with")], self.runs[(dim, "without")]
            self.assert_same_except_displacement(with_["h5"], without["h5"], dim)
            for key in ("step", "time", "dt", "snapshots", "energy", "broken_joints"):
                self.assertEqual(with_["status"].get(key), without["status"].get(key), key)
            everything = "position,velocity,stress,damage,strain,principal_stress"
            self.assertEqual(self.state(with_["id"], everything),
                             self.state(without["id"], everything))
            # and the run with displacement alone reached the same state
            alone = self.runs[(dim, "alone")]
            self.assertEqual(self.state(alone["id"], everything),
                             self.state(without["id"], everything))
            with h5py.File(alone["h5"], "r") as fa, h5py.File(without["h5"], "r") as fw:
                for name in ("step", "time", "kinetic_energy", "elastic_energy",
                             "constraint_force", "fragment"):
                    self.assertEqual(bits(fa["/snapshots/" + name][...]),
                                     bits(fw["/snapshots/" + name][...]), name)
        with h5py.File(self.runs[(2, "with")]["h5"], "r") as f:
            self.assertIn("/snapshots/damage", f)  # the 2D case has joints to compare

    # ------------------------------------------------------ result.xdmf
    def displacement_attributes(self, xdmf, collection=0):
        """The grids of a temporal collection (0 the elements, 1 the joints)
        and the displacement attributes of each."""
        root = ET.parse(xdmf).getroot()
        grids = root.findall("Domain/Grid")[collection].findall("Grid")
        found = []
        for grid in grids:
            attrs = [a for a in grid.findall("Attribute") if a.get("Name") == "displacement"]
            found.append(attrs)
        return grids, found

    def test_xdmf_names_a_node_vector_of_three_components(self):
        for dim in CASES:
            for tag in ("with", "alone"):
                run = self.runs[(dim, tag)]
                grids, found = self.displacement_attributes(run["xdmf"])
                with h5py.File(run["h5"], "r") as f:
                    u = f["/snapshots/displacement"]
                    n = f["/mesh/position0"].shape[0]
                    self.assertEqual(len(grids), u.shape[0])
                    for s, attrs in enumerate(found):
                        where = "%dD %s, grid %d" % (dim, tag, s)
                        self.assertEqual(len(attrs), 1, where)
                        a = attrs[0]
                        self.assertEqual((a.get("AttributeType"), a.get("Center")),
                                         ("Vector", "Node"), where)
                        item = a.find("DataItem")
                        self.assertEqual(item.get("Format"), "HDF", where)
                        self.assertEqual(item.get("Dimensions"), "%d 3" % n, where)
                        self.assertEqual(item.text.strip(), "result.h5:/xdmf/%d/displacement" % s)
                        view = f["/xdmf/%d/displacement" % s][...]
                        self.assertEqual(bits(view), bits(pad3(u[s])), where)
                    if tag == "alone":  # no positions: the geometry is the initial one
                        geometry = grids[-1].find("Geometry/DataItem").text.strip()
                        self.assertEqual(geometry, "result.h5:/mesh/position0")
            grids, found = self.displacement_attributes(self.runs[(dim, "without")]["xdmf"])
            self.assertEqual([len(a) for a in found], [0] * len(grids))
        # the joints of the 2D case sit on the same nodes: the same vector,
        # so that a warp moves them with the elements
        for tag in ("with", "alone"):
            grids, found = self.displacement_attributes(self.runs[(2, tag)]["xdmf"], 1)
            self.assertTrue(grids[0].get("Name").startswith("joints"))
            for s, attrs in enumerate(found):
                self.assertEqual(len(attrs), 1, (tag, s))
                self.assertEqual(attrs[0].find("DataItem").text.strip(),
                                 "result.h5:/xdmf/%d/displacement" % s)

    def test_running_case_xdmf_picks_its_row_with_a_hyperslab(self):
        case = with_fields(tiny_case("disp-running", end=10.0, divisions=(3, 3), interval=2e-5),
                           ["displacement", "velocity"])
        st = self.d.create(case, start=True)
        try:
            self.d.wait(st["id"], lambda s: s["snapshots"] >= 3, what="3 snapshots")
            status, _, xdmf = self.d.request("GET", "/cases/%s/result.xdmf" % st["id"])
            self.assertEqual(status, 200)
            status, _, data = self.d.request("GET", "/cases/%s/result.h5" % st["id"])
            self.assertEqual(status, 200)
        finally:
            self.d.request("DELETE", "/cases/" + st["id"])
        path = os.path.join(self.tmp, "running.h5")
        with open(path, "wb") as out:
            out.write(data)
        root = ET.fromstring(xdmf)
        grids = root.find("Domain/Grid").findall("Grid")
        self.assertGreaterEqual(len(grids), 3)
        with h5py.File(path, "r") as f:
            rows, n = f["/snapshots/displacement"].shape[:2]
            for s, grid in enumerate(grids):
                a, = [a for a in grid.findall("Attribute") if a.get("Name") == "displacement"]
                self.assertEqual((a.get("AttributeType"), a.get("Center")), ("Vector", "Node"))
                slab = a.find("DataItem")
                self.assertEqual(slab.get("ItemType"), "HyperSlab")
                self.assertEqual(slab.get("Dimensions"), "%d 2" % n)
                select, source = list(slab)
                self.assertEqual([int(v) for v in select.text.split()],
                                 [s, 0, 0, 1, 1, 1, 1, n, 2])
                self.assertEqual(source.text.strip(), "result.h5:/snapshots/displacement")
                self.assertEqual(source.get("Dimensions"), "%d %d 2" % (len(grids), n))
                self.assertLess(s, rows)

    # ------------------------------------------------------ GET /state
    def test_state_displacement_is_the_files_last_row_and_position_minus_position0(self):
        for dim in CASES:
            for tag in ("with", "alone", "without"):
                run = self.runs[(dim, tag)]
                state = self.state(run["id"], "displacement,position")
                u = np.array(state["displacement"], dtype=np.float64)
                x = np.array(state["position"], dtype=np.float64)
                self.assertEqual(sorted(state), ["displacement", "position", "step", "time"])
                with h5py.File(run["h5"], "r") as f:
                    x0 = f["/mesh/position0"][...]
                    self.assertEqual(u.shape, x0.shape)
                    self.assertEqual(bits(u), bits(x - x0), "%dD %s" % (dim, tag))
                    if tag != "without":
                        self.assertEqual(bits(u), bits(f["/snapshots/displacement"][-1]))
                    self.assertEqual(state["step"], int(f["/snapshots/step"][-1]))
            # the default state has position and velocity only
            self.assertEqual(sorted(self.state(self.runs[(dim, "with")]["id"])),
                             ["position", "step", "time", "velocity"])

    def test_state_of_a_created_case_has_zero_displacement(self):
        st = self.d.create(with_fields(case_3d("disp-created"), ["displacement"]))
        try:
            u = np.array(self.state(st["id"], "displacement")["displacement"])
            self.assertEqual(u.shape, (st["nodes"], 3))
            self.assertFalse(np.any(u))
        finally:
            self.d.request("DELETE", "/cases/" + st["id"])

    def test_misspelt_field_is_refused(self):
        case = with_fields(case_2d("disp-typo"), ["position", "displacment"])
        status, problem = self.d.json("POST", "/cases", case)
        self.assertEqual(status, 422, problem)
        errors = [e for e in problem["errors"] if e["pointer"] == "/output/fields/1"]
        self.assertEqual(len(errors), 1, problem)
        self.assertIn('unknown field "displacment"', errors[0]["message"])
        self.assertIn('did you mean "displacement"', errors[0]["message"])
        status, problem = self.d.json("GET", "/cases/%s/state?fields=position,displacment"
                                      % self.runs[(2, "with")]["id"])
        self.assertEqual(status, 400, problem)
        self.assertIn('"displacment"', str(problem))
        self.assertIn("displacement", str(problem))

    def test_dry_run_result_bytes_count_displacement(self):
        sizes = {}
        for tag in ("with", "without"):
            status, z = self.d.json("POST", "/cases?dry_run=true",
                                    with_fields(case_3d("disp-dry"), FIELDS[tag]))
            self.assertEqual(status, 200, z)
            sizes[tag] = z
        self.assertEqual(sizes["with"]["result_bytes"] - sizes["without"]["result_bytes"],
                         sizes["with"]["snapshots"] * sizes["with"]["nodes"] * 3 * 8)

    # ------------------------------------------------------ plot_result.py
    def plot(self, h5, *args):
        png = os.path.join(self.tmp, "plot-%d.png" % len(os.listdir(self.tmp)))
        r = subprocess.run([PYTHON, PLOT, h5, "-o", png] + list(args),
                           capture_output=True, text=True, timeout=60 * SLOW)
        return r, png

    def assert_drawn(self, r, png):
        """A PNG of a colour-mapped field: many colours, a tenth inked."""
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(png, "rb") as f:
            self.assertEqual(f.read(8), b"\x89PNG\r\n\x1a\n")
        pixels = image.imread(png)[:, :, :3]
        inked = np.any(pixels < 0.95, axis=2)
        self.assertGreater(inked.mean(), 0.10)
        colours = np.unique((pixels[inked] * 255).astype(np.uint8), axis=0)
        self.assertGreater(colours.shape[0], 50)

    def test_plot_result_draws_displacement(self):
        for dim in CASES:
            for tag in ("with", "alone", "without"):  # "without": x - x0 from position
                r, png = self.plot(self.runs[(dim, tag)]["h5"], "--field", "displacement")
                self.assert_drawn(r, png)
        r, png = self.plot(self.runs[(2, "alone")]["h5"], "--field", "displacement",
                           "--snapshot", "3")
        self.assert_drawn(r, png)
        # a file with neither displacement nor position: what to add
        bare = os.path.join(self.tmp, "bare.h5")
        shutil.copy(self.runs[(2, "without")]["h5"], bare)
        with h5py.File(bare, "r+") as f:
            del f["/snapshots/position"]
        r, png = self.plot(bare, "--field", "displacement")
        self.assertNotEqual(r.returncode, 0)
        self.assertIn('"displacement"', r.stderr)
        self.assertFalse(os.path.exists(png))

    def test_plot_result_help_and_default_field(self):
        r = subprocess.run([PYTHON, PLOT, "--help"], capture_output=True, text=True, timeout=60)
        self.assertEqual(r.returncode, 0)
        self.assertIn("displacement", r.stdout)
        # a file with displacement alone is drawn by it without --field
        r, png = self.plot(self.runs[(3, "alone")]["h5"])
        self.assert_drawn(r, png)


if __name__ == "__main__":
    unittest.main()
