"""A fracturing 3D case through the real daemon (contract 5.2, issue 13): a
0.1 x 0.01 x 0.01 m rock bar of 10 x 1 x 1 cells (60 tetrahedra, each with
its own four nodes, a 6-node joint on every interior face) pulled apart at
5 m/s at both ends, as tests/unit/test_fracture_3d.c does in the engine.
What a user sees must hold: the status counts joints, broken joints and
more than one fragment; result.h5 has /mesh/joints (J, 6) of valid node
indices whose two faces are copies of the same points, and
/snapshots/damage (S, J) in [0, 1], never decreasing; the energy accounts
are there, fracture > 0 (at least G_I times one cross-section) and the
residual within 1 % of the work done; the fragments route, the status and
/snapshots/fragment agree on the pieces; result.xdmf parses and draws the
joints as triangles."""
import os
import unittest
import xml.etree.ElementTree as ET

import h5py
import numpy as np

from fdemd_harness import DaemonTestCase

LENGTH, SIDE, SPEED, RHO = 0.1, 0.01, 5.0, 2700.0
ENERGY_I = 10.0
CELLS = 10
TETS = 6 * CELLS
# 4 faces per tetrahedron; the hull has 2 triangles per cell face:
# 4 long sides of CELLS cells each and the two ends
JOINTS = (4 * TETS - 2 * (4 * CELLS + 2)) // 2


def pulled_bar_case():
    end_box = lambda x: [x - 1e-9, -1, -1, x + 1e-9, 1, 1]
    return {
        "name": "pulled-bar-3d",
        "dimension": 3,
        "materials": {"rock": {
            "density": RHO, "young": 3e10, "poisson": 0.25, "damping": 0.1, "friction": 0.3,
            "fracture": {"tensile_strength": 1e6, "cohesion": 3e6, "friction_angle": 30,
                         "energy_I": ENERGY_I, "energy_II": 50}}},
        "parts": [{"name": "bar", "material": "rock", "fracture": True,
                   "box": {"origin": [0, 0, 0], "size": [LENGTH, SIDE, SIDE],
                           "divisions": [CELLS, 1, 1]}}],
        "constraints": [{"box": end_box(0), "velocity": [-SPEED, None, None]},
                        {"box": end_box(LENGTH), "velocity": [SPEED, None, None]}],
        "time": {"end": 2e-4, "safety": 0.5},
        "output": {"interval": 1e-5, "fields": ["position", "velocity", "damage"]},
    }


class PulledBar3DThroughDaemon(DaemonTestCase):
    PREFIX = "fdemd-fracture-3d-"

    @classmethod
    def setUpClass(cls):
        super().setUpClass()
        st = cls.d.create(pulled_bar_case(), start=True)
        cls.final = cls.d.wait_state(st["id"], ("finished", "failed", "stopped"), timeout=120)
        cls.pieces = cls.d.json("GET", "/cases/%s/fragments" % st["id"])
        cls.files = {}
        for name in ("result.h5", "result.xdmf"):
            status, _, data = cls.d.request("GET", "/cases/%s/%s" % (st["id"], name))
            assert status == 200, (name, status)
            cls.files[name] = os.path.join(cls.tmp, name)
            with open(cls.files[name], "wb") as f:
                f.write(data)

    def test_status_counts_the_pieces(self):
        st = self.final
        self.assertEqual(st["state"], "finished", st.get("error"))
        self.assertEqual((st["elements"], st["nodes"]), (TETS, 4 * TETS))
        self.assertEqual(st["joints"], JOINTS)
        self.assertGreater(st["broken_joints"], 0)
        self.assertGreater(st["fragments"], 1)

    def test_joints_and_damage_are_in_the_result(self):
        st = self.final
        with h5py.File(self.files["result.h5"], "r") as f:
            joints = f["/mesh/joints"][...]
            x0 = f["/mesh/position0"][...]
            damage = f["/snapshots/damage"][...]
            s = len(f["/snapshots/time"])
        self.assertEqual(joints.shape, (JOINTS, 6))
        self.assertEqual(joints.dtype, np.int32)
        self.assertTrue(joints.min() >= 0 and joints.max() < st["nodes"])
        # a0, a1, a2 and b0, b1, b2 are copies of the same three points, on
        # six different nodes
        np.testing.assert_array_equal(x0[joints[:, :3]], x0[joints[:, 3:]])
        self.assertTrue(all(len(set(j)) == 6 for j in joints.tolist()))
        self.assertEqual(damage.shape, (s, JOINTS))
        self.assertTrue(np.all((damage >= 0) & (damage <= 1)))
        self.assertTrue(np.all(damage[0] == 0))
        self.assertTrue(np.all(np.diff(damage, axis=0) >= 0), "damage decreased")
        self.assertEqual(int((damage[-1] >= 1).sum()), st["broken_joints"])

    def test_fragments_are_the_pieces_of_the_bar(self):
        """The fragments route, the status and /snapshots/fragment agree, and
        the pieces add up to the bar: its mass rho L A and its volume."""
        status, body = self.pieces
        self.assertEqual(status, 200, body)
        pieces = body["fragments"]
        self.assertEqual(len(pieces), self.final["fragments"])
        self.assertEqual(sum(p["elements"] for p in pieces), TETS)
        volume = LENGTH * SIDE * SIDE
        self.assertAlmostEqual(sum(p["size"] for p in pieces) / volume, 1.0, delta=1e-9)
        self.assertAlmostEqual(sum(p["mass"] for p in pieces) / (RHO * volume), 1.0, delta=1e-9)
        self.assertTrue(all(len(p["centroid"]) == 3 and len(p["velocity"]) == 3 for p in pieces))
        self.assertEqual(body["distribution"][-1]["passing"], 1.0)
        with h5py.File(self.files["result.h5"], "r") as f:
            label = f["/snapshots/fragment"][...]
        self.assertEqual(label.shape[1], TETS)
        self.assertTrue(np.all(label[0] == 0), "the bar starts in one piece")
        self.assertEqual(int(label[-1].max()) + 1, self.final["fragments"])

    def test_energy_balance_closes_with_fracture(self):
        e = self.final["energy"]
        for name in ("kinetic", "elastic", "joint", "contact", "friction", "fracture",
                     "damping", "gravity_work", "external_work", "residual"):
            self.assertIn(name, e)
        # at least one cross-section opened in mode I
        self.assertGreaterEqual(e["fracture"], 0.97 * ENERGY_I * SIDE * SIDE, e)
        self.assertLess(abs(e["residual"]), 0.01 * abs(e["external_work"]), e)
        with h5py.File(self.files["result.h5"], "r") as f:
            fracture = f["/snapshots/fracture_energy"][...]
        self.assertTrue(np.all(np.diff(fracture) >= 0), "fracture energy decreased")
        self.assertGreater(fracture[-1], 0)

    def test_xdmf_draws_the_joints_as_triangles(self):
        root = ET.parse(self.files["result.xdmf"]).getroot()
        topologies = {t.get("TopologyType") for t in root.iter("Topology")}
        self.assertIn("Tetrahedron", topologies)
        self.assertIn("Triangle", topologies)
        self.assertIn("damage", {a.get("Name") for a in root.iter("Attribute")})


if __name__ == "__main__":
    unittest.main()
