"""Cases with "dimension": 3 through the real daemon (contract 5.2): a box,
a sphere and a gmsh cube falling freely, checked against free fall
(centroid drop 1/2 g t^2, velocity g t, kinetic energy 1/2 M (g t)^2, each
to 1 %), the state with three components per node and six stress
components per element, result.h5 in the 3D layout (every dataset shape,
positive tetrahedron volumes, lumped masses summing to rho V) and a
result.xdmf with Tetrahedron topology; the displacement of the falling box
(1/2 g t^2 at every node); a bad 3D document is a 422 naming
the pointer; two boxes colliding once contact between tetrahedral parts is
in the engine."""
import os
import signal
import unittest
import xml.etree.ElementTree as ET

import h5py
import numpy as np

from fdemd_harness import ROOT, Daemon, DaemonTestCase

G = 9.81
RHO = 2700.0


def solid_case(name, shape, end=0.01, snapshots=10, gravity=(0, 0, -G), **extra):
    """One part of rock with `shape` ({"box": {...}} or the like) falling."""
    part = {"name": "body", "material": "rock"}
    part.update(shape)
    case = {
        "name": name,
        "dimension": 3,
        "materials": {"rock": {"density": RHO, "young": 3e10, "poisson": 0.25}},
        "parts": [part],
        "gravity": list(gravity),
        "time": {"end": end},
        "output": {"interval": end / snapshots, "fields": ["position", "velocity", "stress"]},
    }
    case.update(extra)
    return case


BOX = {"box": {"origin": [0, 0, 0], "size": [0.1, 0.1, 0.1], "divisions": [3, 3, 3]}}
SPHERE = {"sphere": {"center": [0, 0, 1], "radius": 0.05, "divisions": 12}}


def tet_volumes(x, tets):
    """Signed volume of every tetrahedron of nodes x (N, 3)."""
    p = x[tets]
    e = p[:, 1:, :] - p[:, :1, :]
    return np.linalg.det(e) / 6.0


class Solid3DTest(DaemonTestCase):
    PREFIX = "fdemd-3d-"

    def download(self, case_id, name):
        status, _, data = self.d.request("GET", "/cases/%s/%s" % (case_id, name))
        self.assertEqual(status, 200, data[:200])
        path = os.path.join(self.tmp, "%s-%s" % (case_id, name))
        with open(path, "wb") as f:
            f.write(data)
        return path

    def run_case(self, case):
        st = self.d.create(case, start=True)
        return self.d.wait_state(st["id"], ("finished", "failed"), timeout=60)

    # ---------------------------------------------------------- checks
    def check_result_h5(self, path, st, constraints=0):
        """Every 5.2 dataset with its shape; returns what the physics
        checks need."""
        n, e = st["nodes"], st["elements"]
        with h5py.File(path, "r") as f:
            self.assertEqual(int(f.attrs["dimension"]), 3)
            self.assertNotIn("/mesh/triangles", f)
            x0 = f["/mesh/position0"][...]
            tets = f["/mesh/tetrahedra"][...]
            self.assertEqual(x0.shape, (n, 3))
            self.assertEqual(tets.shape, (e, 4))
            self.assertEqual(tets.dtype, np.int32)
            self.assertTrue(tets.min() >= 0 and tets.max() < n)
            volumes = tet_volumes(x0, tets)
            self.assertTrue(np.all(volumes > 0), "some tetrahedra have volume <= 0")
            mass = f["/mesh/node_mass"][...]
            self.assertEqual(mass.shape, (n,))
            # lumped rho V / 4 per node: the masses add up to rho times the volume
            np.testing.assert_allclose(mass.sum(), RHO * volumes.sum(), rtol=1e-12)
            self.assertEqual(f["/mesh/node_part"].shape, (n,))
            self.assertEqual(f["/mesh/element_part"].shape, (e,))
            time = f["/snapshots/time"][...]
            s = len(time)
            self.assertEqual(s, st["snapshots"])
            self.assertEqual(f["/snapshots/step"].shape, (s,))
            self.assertEqual(f["/snapshots/position"].shape, (s, n, 3))
            self.assertEqual(f["/snapshots/velocity"].shape, (s, n, 3))
            self.assertEqual(f["/snapshots/stress"].shape, (s, e, 6))
            self.assertEqual(f["/snapshots/constraint_force"].shape, (s, constraints, 3))
            for name in ("kinetic_energy", "elastic_energy", "contact_energy", "friction_energy",
                         "joint_energy", "fracture_energy", "damping_energy", "gravity_work",
                         "external_work"):
                self.assertEqual(f["/snapshots/" + name].shape, (s,), name)
            self.assertNotIn("/snapshots/damage", f)
            position = f["/snapshots/position"][...]
            velocity = f["/snapshots/velocity"][...]
            np.testing.assert_array_equal(position[0], x0)
            return {"time": time, "mass": mass, "position": position, "velocity": velocity,
                    "kinetic": f["/snapshots/kinetic_energy"][...],
                    "stress": f["/snapshots/stress"][...]}

    def check_free_fall(self, r):
        """Centroid drop 1/2 g t^2 and velocity g t at every snapshot after the
        first, kinetic energy 1/2 M (g t)^2, to 1 %; nothing sideways."""
        m, t = r["mass"], r["time"]
        total = m.sum()
        centroid = np.einsum("n,snk->sk", m, r["position"]) / total
        mean_v = np.einsum("n,snk->sk", m, r["velocity"]) / total
        drop = centroid[0, 2] - centroid[:, 2]
        for s in range(1, len(t)):
            self.assertAlmostEqual(drop[s] / (0.5 * G * t[s] ** 2), 1.0, delta=0.01,
                                   msg="drop at t = %g" % t[s])
            self.assertAlmostEqual(-mean_v[s, 2] / (G * t[s]), 1.0, delta=0.01)
            self.assertAlmostEqual(r["kinetic"][s] / (0.5 * total * (G * t[s]) ** 2), 1.0,
                                   delta=0.01)
        sideways = np.abs(centroid[:, :2] - centroid[:1, :2]).max()
        self.assertLess(sideways, 1e-12, "the centroid moved %g m sideways" % sideways)
        return drop[-1], t[-1]

    def check_xdmf(self, path, st, s):
        root = ET.parse(path).getroot()
        grids = root.findall("Domain/Grid")[0].findall("Grid[@GridType='Uniform']")
        self.assertEqual(len(grids), s)
        for grid in grids:
            topo = grid.find("Topology")
            self.assertEqual(topo.get("TopologyType"), "Tetrahedron")
            self.assertEqual(int(topo.get("NumberOfElements")), st["elements"])
            self.assertEqual(topo.find("DataItem").text.strip(), "result.h5:/mesh/tetrahedra")
            self.assertEqual(grid.find("Geometry").get("GeometryType"), "XYZ")
            names = sorted(a.get("Name") for a in grid.findall("Attribute")
                           if a.get("Center") != "Grid")  # the series are field data
            self.assertEqual(names, ["element_part", "fragment", "node_part", "stress",
                                     "velocity"])
            stress = [a for a in grid.findall("Attribute") if a.get("Name") == "stress"][0]
            self.assertEqual(stress.get("AttributeType"), "Tensor")
        return root

    def check_state(self, st):
        status, body = self.d.json("GET", "/cases/%s/state?fields=position,velocity,stress"
                                   % st["id"])
        self.assertEqual(status, 200, body)
        self.assertEqual(len(body["position"]), st["nodes"])
        self.assertEqual({len(row) for row in body["position"]}, {3})
        self.assertEqual({len(row) for row in body["velocity"]}, {3})
        self.assertEqual(len(body["stress"]), st["elements"])
        self.assertEqual({len(row) for row in body["stress"]}, {6})
        return body

    def run_free_fall(self, case):
        st = self.run_case(case)
        self.assertEqual(st["state"], "finished", st.get("error"))
        self.assertEqual(st["dimension"], 3)
        self.assertEqual(st["joints"], 0)
        self.assertEqual(st["fragments"], 1)
        state = self.check_state(st)
        h5 = self.download(st["id"], "result.h5")
        r = self.check_result_h5(h5, st)
        drop, t = self.check_free_fall(r)
        # the state is the last snapshot
        np.testing.assert_array_equal(np.array(state["position"]), r["position"][-1])
        # free fall strains nothing: stress is rounding next to rho g L (~3 kPa)
        self.assertLess(np.abs(r["stress"]).max(), 1e-3 * RHO * G * 0.1)
        # gravity's work in J: M g drop
        energy = st["energy"]
        self.assertAlmostEqual(energy["gravity_work"] / (r["mass"].sum() * G * drop), 1.0,
                               delta=0.01)
        xdmf = self.download(st["id"], "result.xdmf")
        self.check_xdmf(xdmf, st, len(r["time"]))
        return st, h5, xdmf

    # ----------------------------------------------------------- tests
    def test_box_falls_freely(self):
        st, _, _ = self.run_free_fall(solid_case("box", BOX))
        # 4 x 4 x 4 lattice nodes, six tetrahedra per cell
        self.assertEqual((st["nodes"], st["elements"]), (64, 162))

    def test_sphere_falls_freely(self):
        self.run_free_fall(solid_case("sphere", SPHERE))

    def test_gmsh_cube_falls_freely(self):
        with open(os.path.join(ROOT, "tests", "data", "cube_v41.msh")) as f:
            text = f.read()
        st, _, _ = self.run_free_fall(solid_case("gmsh", {"gmsh": text}, end=0.02, snapshots=4))
        # tests/data/cube.geo as the installed gmsh meshes it
        self.assertEqual((st["nodes"], st["elements"]), (45, 100))

    def test_free_fall_displacement_is_half_g_t_squared(self):
        """/snapshots/displacement of a falling box (contract 6.2): (S, N, 3),
        position - position0 to the bit, every node down by 1/2 g t^2 (1 %)
        and not sideways; GET /state's displacement is the last row."""
        case = solid_case("box-u", BOX)
        case["output"]["fields"] = ["position", "displacement"]
        st = self.run_case(case)
        self.assertEqual(st["state"], "finished", st.get("error"))
        with h5py.File(self.download(st["id"], "result.h5"), "r") as f:
            u, t = f["/snapshots/displacement"][...], f["/snapshots/time"][...]
            self.assertEqual(u.shape, (len(t), st["nodes"], 3))
            x = f["/snapshots/position"][...] - f["/mesh/position0"][...]
            self.assertEqual(u.tobytes(), x.tobytes())
        for s in range(1, len(t)):
            np.testing.assert_allclose(-u[s, :, 2] / (0.5 * G * t[s] ** 2), 1.0, atol=0.01,
                                       err_msg="t = %g" % t[s])
        self.assertLess(np.abs(u[:, :, :2]).max(), 1e-6 * 0.5 * G * t[-1] ** 2)
        status, state = self.d.json("GET", "/cases/%s/state?fields=displacement" % st["id"])
        self.assertEqual(status, 200, state)
        np.testing.assert_array_equal(np.array(state["displacement"]), u[-1])

    def test_fixed_box_holds_its_weight(self):
        """A box fixed at its base: the reaction of the fixed nodes carries
        the weight (3 components per constraint), once the elastic waves of
        the sudden load are damped out."""
        case = solid_case("held", BOX, end=0.02, snapshots=4,
                          constraints=[{"box": [-1, -1, -0.001, 1, 1, 0.001],
                                        "fix": ["x", "y", "z"]}])
        case["materials"]["rock"]["damping"] = 0.5
        st = self.run_case(case)
        self.assertEqual(st["state"], "finished", st.get("error"))
        h5 = self.download(st["id"], "result.h5")
        r = self.check_result_h5(h5, st, constraints=1)
        with h5py.File(h5, "r") as f:
            force = f["/snapshots/constraint_force"][-1, 0]
        weight = r["mass"].sum() * G
        self.assertAlmostEqual(force[2] / weight, 1.0, delta=0.01)
        self.assertLess(abs(force[0]) + abs(force[1]), 1e-6 * weight)

    def test_bad_3d_input_is_422_at_the_pointer(self):
        bad = [
            (dict(solid_case("d", BOX), dimension=4), "/dimension"),
            (dict(solid_case("g", BOX), gravity=[0, -9.81]), "/gravity"),
            (solid_case("r", {"rectangle": {"size": [1, 1], "divisions": [1, 1]}}),
             "/parts/0/rectangle"),
            # fracture needs the material's "fracture" block, which rock lacks here
            (solid_case("f", dict(BOX, fracture=True)), "/parts/0/fracture"),
            (solid_case("m", {"mesh": {"nodes": [[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]],
                                       "tetrahedra": [[0, 1, 2, 3]]}}),
             "/parts/0/mesh/tetrahedra/0"),
            (solid_case("c", BOX, constraints=[{"box": [0, 0, 1, 1], "fix": ["z"]}]),
             "/constraints/0/box"),
            # the same tetrahedron twice, and a second body inside the first
            (solid_case("t", {"mesh": {"nodes": [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]],
                                       "tetrahedra": [[0, 1, 2, 3], [3, 1, 2, 0]]}}),
             "/parts/0/mesh/tetrahedra/1"),
            (dict(solid_case("o", BOX), parts=[
                {"name": "a", "material": "rock", **BOX},
                {"name": "b", "material": "rock",
                 "box": {"origin": [0.05, 0, 0], "size": [0.1, 0.1, 0.1], "divisions": [1, 1, 1]}}]),
             "/parts/1"),
        ]
        for case, pointer in bad:
            status, body = self.d.json("POST", "/cases", case)
            self.assertEqual(status, 422, (pointer, body))
            self.assertIn(pointer, [e["pointer"] for e in body["errors"]], body)


class Restart3DTest(unittest.TestCase):
    """A paused 3D case comes back after a restart (the case document is
    rebuilt and its checkpoint restored): same step, the same state to the
    bit, and it runs on to the end in free fall."""

    def test_paused_3d_case_survives_a_restart(self):
        d = Daemon().start()
        try:
            st = d.create(solid_case("restart", SPHERE, end=0.01), start=True)
            d.wait(st["id"], lambda s: s["step"] > 50, what="steps")
            paused = d.json("POST", "/cases/%s/pause" % st["id"])[1]
            fields = "/cases/%s/state?fields=position,velocity,stress" % st["id"]
            before = d.json("GET", fields)[1]
            code, _ = d.stop(signal.SIGTERM)
            self.assertEqual(code, 0, d.log_tail())
            d.start()
            again = d.status(st["id"])
            self.assertEqual((again["state"], again["step"]), ("paused", paused["step"]))
            self.assertEqual(d.json("GET", fields)[1], before)
            self.assertEqual(d.json("POST", "/cases/%s/start" % st["id"])[0], 200)
            done = d.wait_state(st["id"], ("finished", "failed"), timeout=60)
            self.assertEqual(done["state"], "finished", done.get("error"))
            z = np.array(d.json("GET", "/cases/%s/state" % st["id"])[1]["position"])[:, 2]
            # the sphere's nodes are symmetric about its centre: mean z is the centroid
            self.assertAlmostEqual((1.0 - z.mean()) / (0.5 * G * done["time"] ** 2), 1.0,
                                   delta=0.01)
        finally:
            d.close()


class TwoBoxes3DTest(DaemonTestCase):
    """Two equal boxes, one moving onto the other at 1 m/s, no gravity:
    momentum is conserved and passed on. Needs contact between tetrahedral
    parts (branch contact-3d); until then the daemon refuses the case with
    that reason and the test is skipped."""
    PREFIX = "fdemd-3d-contact-"

    def test_two_boxes_collide(self):
        lower = {"name": "lower", "material": "rock",
                 "box": {"origin": [0, 0, 0], "size": [0.1, 0.1, 0.1], "divisions": [2, 2, 2]}}
        upper = {"name": "upper", "material": "rock", "velocity": [0, 0, -1],
                 "box": {"origin": [0, 0, 0.105], "size": [0.1, 0.1, 0.1],
                         "divisions": [2, 2, 2]}}
        case = solid_case("collide", BOX, end=0.008, snapshots=8, gravity=(0, 0, 0))
        case["parts"] = [lower, upper]
        status, body = self.d.json("POST", "/cases?start=true", case)
        if status == 422 and "contact between tetrahedral parts is not built yet" in str(body):
            self.skipTest("contact between tetrahedral parts is not in the engine yet")
        self.assertEqual(status, 201, body)
        st = self.d.wait_state(body["id"], ("finished", "failed"), timeout=120)
        self.assertEqual(st["state"], "finished", st.get("error"))
        path = os.path.join(self.tmp, "collide.h5")
        status, _, data = self.d.request("GET", "/cases/%s/result.h5" % st["id"])
        self.assertEqual(status, 200)
        with open(path, "wb") as f:
            f.write(data)
        with h5py.File(path, "r") as f:
            mass = f["/mesh/node_mass"][...]
            part = f["/mesh/node_part"][...]
            v = f["/snapshots/velocity"][...]
            x = f["/snapshots/position"][...]
        p = np.einsum("n,snk->sk", mass, v)
        p0 = mass[part == 1].sum() * 1.0  # |initial momentum|, along -z
        # momentum is conserved (equal and opposite contact forces)
        np.testing.assert_allclose(p, np.broadcast_to(p[0], p.shape), atol=1e-9 * p0)
        lower_p = np.einsum("n,nk->k", mass[part == 0], v[-1][part == 0])
        # the lower box has taken at least half the momentum of the upper one
        self.assertLess(lower_p[2], -0.5 * p0)
        # and the boxes did not pass through each other
        gap = x[:, part == 1, 2].min(axis=1) - x[:, part == 0, 2].max(axis=1)
        self.assertGreater(gap.min(), -0.01 * 0.1)


if __name__ == "__main__":
    unittest.main()
