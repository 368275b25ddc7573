"""In-situ stress through the real daemon (contract 5.3 "initial_stress"):
a block (2D) and a box (3D) under in-situ stress, held by the matching
boundary pressures, write that stress in every snapshot of result.h5 (1 %)
and close their energy account; examples/borehole.json reproduces the
Kirsch + Lame hoop stress at the bore wall and examples/tunnel.json the
elastic convergence of an unsupported tunnel, u = P0 a / (2 G), with the
wall's hoop stress 2 P0."""
import json
import os

import h5py
import numpy as np

from fdemd_harness import ROOT, DaemonTestCase

E, NU = 2e10, 0.25
G = E / (2 * (1 + NU))


def block_case(dimension):
    """A block under in-situ stress with p = -sigma_aa on its faces."""
    if dimension == 2:
        stress = [-10e6, -6e6, 0]
        shape = {"rectangle": {"origin": [0, 0], "size": [2, 1], "divisions": [8, 4]}}
        faces = [[-1, -1, 0.01, 2], [1.99, -1, 3, 2], [-1, -1, 3, 0.01], [-1, 0.99, 3, 2]]
    else:
        stress = [-10e6, -6e6, -8e6, 0, 0, 0]
        shape = {"box": {"origin": [0, 0, 0], "size": [2, 1, 1], "divisions": [4, 2, 2]}}
        faces = [[-1, -1, -1, 0.01, 2, 2], [1.99, -1, -1, 3, 2, 2], [-1, -1, -1, 3, 0.01, 2],
                 [-1, 0.99, -1, 3, 2, 2], [-1, -1, -1, 3, 2, 0.01], [-1, -1, 0.99, 3, 2, 2]]
    part = {"name": "block", "material": "rock", "initial_stress": {"value": stress}}
    part.update(shape)
    return {
        "name": "in-situ %dD" % dimension,
        "dimension": dimension,
        "materials": {"rock": {"density": 2600, "young": E, "poisson": NU}},
        "parts": [part],
        "constraints": [{"box": box, "pressure": -stress[k // 2]} for k, box in enumerate(faces)],
        "time": {"end": 0.002},
        "output": {"interval": 0.0005, "fields": ["position", "stress"]},
    }, stress


def example(name):
    with open(os.path.join(ROOT, "examples", name + ".json")) as f:
        return json.load(f)


def hoop_and_radial(s, theta):
    """sigma_tt and sigma_rr of 2D stresses s (n, 3) at angles theta."""
    c, z = np.cos(theta), np.sin(theta)
    hoop = s[:, 0] * z * z + s[:, 1] * c * c - 2 * s[:, 2] * z * c
    radial = s[:, 0] * c * c + s[:, 1] * z * z + 2 * s[:, 2] * z * c
    return hoop, radial


class InitialStressTest(DaemonTestCase):
    PREFIX = "fdemd-insitu-"

    def test_block_at_rest_shows_its_stress(self):
        for dimension in (2, 3):
            case, stress = block_case(dimension)
            st, path = self.run_case(case, timeout=120)
            with h5py.File(path, "r") as f:
                s = f["/snapshots/stress"][...]
                x, x0 = f["/snapshots/position"][...], f["/mesh/position0"][...]
            self.assertEqual(s.shape[2], len(stress))
            self.assertGreaterEqual(s.shape[0], 4)
            worst = np.abs(s - np.array(stress)).max() / np.abs(stress).max()
            self.assertLess(worst, 0.01, "%dD: stress off sigma0 by %.3g" % (dimension, worst))
            self.assertLess(np.abs(x - x0).max(), 1e-9, "%dD: the block moved" % dimension)
            energy = st["energy"]
            self.assertGreater(energy["elastic"], 0)
            self.assertLess(energy["kinetic"], 1e-6 * energy["elastic"])
            self.assertLess(abs(energy["residual"]), 1e-6 * energy["elastic"])

    def test_fracturing_block_starts_at_rest(self):
        """Contract 6.1: with fracture on, the joints carry sigma.n from
        t = 0, so the block stays as still as the continuous one: no
        fracture event, joint energy from the first snapshot on."""
        for dimension in (2, 3):
            case, stress = block_case(dimension)
            case["materials"]["rock"]["fracture"] = {
                "tensile_strength": 2e6, "cohesion": 6e6, "friction_angle": 30,
                "energy_I": 20, "energy_II": 100}
            case["parts"][0]["fracture"] = True
            st, path = self.run_case(case, timeout=120)
            with h5py.File(path, "r") as f:
                s = f["/snapshots/stress"][...]
                x, x0 = f["/snapshots/position"][...], f["/mesh/position0"][...]
                events = f["/events/time"].shape[0] if "/events/time" in f else 0
            self.assertLess(np.abs(x - x0).max(), 1e-9, "%dD: the block moved" % dimension)
            worst = np.abs(s - np.array(stress)).max() / np.abs(stress).max()
            self.assertLess(worst, 0.01, "%dD: stress off sigma0 by %.3g" % (dimension, worst))
            energy = st["energy"]
            self.assertGreater(energy["joint"], 0.05 * energy["elastic"],
                               "%dD: the joints hold %g J" % (dimension, energy["joint"]))
            self.assertLess(energy["kinetic"], 1e-6 * (energy["elastic"] + energy["joint"]))
            self.assertEqual(energy["fracture"], 0)
            self.assertEqual(events, 0, "%dD: %d joints broke" % (dimension, events))

    def test_borehole_hoop_stress_is_kirsch_plus_lame(self):
        case = example("borehole")
        sx, sy, _ = case["parts"][0]["initial_stress"]["value"]
        p = case["constraints"][-1]["pressure"]
        a = 0.1  # examples/borehole.geo
        _, path = self.run_case(case, timeout=120)
        with h5py.File(path, "r") as f:
            x0, tri = f["/mesh/position0"][...], f["/mesh/triangles"][...]
            s = f["/snapshots/stress"][-1]
        on_wall = np.abs(np.hypot(x0[:, 0], x0[:, 1]) - a) < 1e-6 * a
        wall = on_wall[tri].sum(axis=1) == 2  # elements with an edge on the bore
        c = x0[tri[wall]].mean(axis=1)
        theta = np.arctan2(c[:, 1], c[:, 0])
        hoop, radial = hoop_and_radial(s[wall], theta)
        want = sx + sy - 2 * (sx - sy) * np.cos(2 * theta) + p
        scale = abs(sx + sy)
        err = hoop - want
        self.assertLess(np.sqrt(np.mean(err ** 2)), 0.015 * scale, err)
        self.assertLess(np.abs(err).max(), 0.04 * scale, err)
        # the extremes (sx - sy > 0): sx + sy -/+ 2 (sx - sy) + p = -45 and -5 MPa
        self.assertAlmostEqual(hoop.min(), sx + sy - 2 * (sx - sy) + p, delta=0.015 * scale)
        self.assertAlmostEqual(hoop.max(), sx + sy + 2 * (sx - sy) + p, delta=0.015 * scale)
        # and the radial stress next to the wall is near -p (it is -p on it)
        self.assertAlmostEqual(radial.mean(), -p, delta=0.05 * scale)

    def test_tunnel_converges_as_the_ground_reaction_line(self):
        case = example("tunnel")
        p0 = -case["parts"][0]["initial_stress"]["value"][0]
        a = 1.0  # examples/tunnel.geo
        _, path = self.run_case(case, timeout=120)
        with h5py.File(path, "r") as f:
            x0, tri = f["/mesh/position0"][...], f["/mesh/triangles"][...]
            x, s = f["/snapshots/position"][-1], f["/snapshots/stress"][-1]
        on_wall = np.abs(np.hypot(x0[:, 0], x0[:, 1]) - a) < 1e-6 * a
        u = x[on_wall] - x0[on_wall]
        ur = (u[:, 0] * x0[on_wall, 0] + u[:, 1] * x0[on_wall, 1]) / a
        self.assertAlmostEqual(ur.mean() / (-p0 * a / (2 * G)), 1, delta=0.015)
        wall = on_wall[tri].sum(axis=1) == 2
        c = x0[tri[wall]].mean(axis=1)
        hoop, _ = hoop_and_radial(s[wall], np.arctan2(c[:, 1], c[:, 0]))
        self.assertAlmostEqual(hoop.mean() / (-2 * p0), 1, delta=0.02)
