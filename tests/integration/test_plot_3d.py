"""test_plot_3d.py - plot_result.py on 3D results (contract 5.2 layout).

A synthetic result.h5 written here with h5py holds a box meshed into six
tetrahedra per cell (the Kuhn split along each cell's main diagonal, which is
conforming between neighbouring cells), so the boundary the plot draws can be
checked against the analytic count: 2 triangles on each of the
2 (nx ny + ny nz + nx nz) cell faces of the box's surface. The same checks
then run on a box the real daemon stepped, when the daemon accepts 3D cases.
"""

import itertools
import os
import subprocess
import sys
import tempfile
import unittest

import h5py
import numpy as np
from matplotlib import image

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(ROOT, "clients", "python"))

import fdemd_harness  # noqa: E402
from fdemd_client import Client, FdemdError  # noqa: E402
from plot_result import TET_FACES, boundary_faces, surface_of_snapshot, von_mises_3d  # noqa: E402

PLOT = os.path.join(ROOT, "clients", "python", "plot_result.py")
PYTHON = "/usr/bin/python3"
SLOW = fdemd_harness.SLOW


def kuhn_box(divisions, size=(1.0, 1.0, 1.0)):
    """Nodes (N, 3) and positive-volume tetrahedra (6 per cell, E, 4)."""
    nx, ny, nz = divisions
    grid = np.stack(np.meshgrid(*(np.linspace(0, s, n + 1) for s, n in zip(size, divisions)),
                                indexing="ij"), axis=-1)
    nodes = grid.reshape(-1, 3)

    def node(i, j, k):
        return (i * (ny + 1) + j) * (nz + 1) + k

    tets = []
    for i, j, k in itertools.product(range(nx), range(ny), range(nz)):
        for order in itertools.permutations(range(3)):
            corner = [i, j, k]
            path = [node(*corner)]
            for axis in order:
                corner[axis] += 1
                path.append(node(*corner))
            tets.append(path)
    tets = np.array(tets, dtype=np.int32)
    edges = nodes[tets[:, 1:]] - nodes[tets[:, :1]]
    negative = np.linalg.det(edges) < 0
    tets[negative, 1], tets[negative, 2] = tets[negative, 2], tets[negative, 1].copy()
    return nodes, tets


def analytic_boundary_faces(divisions):
    nx, ny, nz = divisions
    return 2 * (nx * ny + ny * nz + nx * nz) * 2


def write_synthetic_result(path, divisions, snapshots=3):
    """A result.h5 in the 3D layout of contract 5.2: the box sags along z
    and carries a stress that grows with height, so colours vary."""
    nodes, tets = kuhn_box(divisions, size=(0.3, 0.2, 0.4))
    centroid_z = nodes[tets].mean(axis=1)[:, 2]
    times = np.linspace(0.0, 0.1, snapshots)
    with h5py.File(path, "w") as f:
        f.attrs["format"] = "fdem-result/1"
        f.attrs["name"] = "synthetic-box"
        f.attrs["dimension"] = 3
        f.attrs["dt"] = 1e-5
        f["/mesh/position0"] = nodes
        f["/mesh/tetrahedra"] = tets
        f["/snapshots/time"] = times
        f["/snapshots/step"] = np.arange(snapshots) * 100
        f["/snapshots/position"] = np.stack([nodes - [0, 0, 0.5 * 9.81 * t * t] for t in times])
        velocity = np.zeros((snapshots, nodes.shape[0], 3))
        velocity[:, :, 2] = -9.81 * times[:, None] * (1 + nodes[:, 0])
        f["/snapshots/velocity"] = velocity
        stress = np.zeros((snapshots, tets.shape[0], 6))
        stress[:, :, 2] = -2e6 * (1 + centroid_z)        # szz: compression
        stress[:, :, 5] = 1e5 * np.arange(tets.shape[0])   # sxy: varies
        f["/snapshots/stress"] = stress
        f["/snapshots/constraint_force"] = np.zeros((snapshots, 0, 3))
    return nodes, tets


class Plot3DTestCase(unittest.TestCase):

    def setUp(self):
        self.work = tempfile.TemporaryDirectory(prefix="plot3d-")
        self.addCleanup(self.work.cleanup)

    def plot(self, h5, *args):
        png = os.path.join(self.work.name, "out-%d.png" % len(os.listdir(self.work.name)))
        r = subprocess.run([PYTHON, PLOT, h5, "-o", png] + list(args),
                           capture_output=True, text=True, timeout=60 * SLOW)
        return r, png

    def assert_drawn(self, r, png):
        """A PNG of real content: a large file, a tenth of it not white, and
        many colours (a colour-mapped surface, not a blank frame)."""
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(png, "rb") as f:
            data = f.read()
        self.assertEqual(data[:8], b"\x89PNG\r\n\x1a\n")
        self.assertGreater(len(data), 20_000)
        pixels = image.imread(png)[:, :, :3]
        self.assertGreater(pixels.shape[0] * pixels.shape[1], 400 * 400)
        inked = np.any(pixels < 0.95, axis=2)
        self.assertGreater(inked.mean(), 0.10)
        colours = np.unique((pixels[inked] * 255).astype(np.uint8), axis=0)
        self.assertGreater(colours.shape[0], 50)

    def assert_surface_of_box(self, nodes, tets, divisions, surface=None):
        """The boundary faces of a box mesh (surface: the (faces, element)
        to check, else boundary_faces(tets)): the analytic count, each face
        on the box's surface, facing out, and taken from its own element."""
        faces, element = surface if surface is not None else boundary_faces(tets)
        self.assertEqual(faces.shape[0], analytic_boundary_faces(divisions))
        low, high = nodes.min(axis=0), nodes.max(axis=0)
        corners = nodes[faces]
        on_a_side = np.any(np.all(np.isclose(corners, low), axis=1)
                           | np.all(np.isclose(corners, high), axis=1), axis=1)
        self.assertTrue(np.all(on_a_side))
        normal = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
        outward = corners.mean(axis=1) - (low + high) / 2
        self.assertTrue(np.all(np.einsum("ij,ij->i", normal, outward) > 0))
        for face, e in zip(faces, element):
            self.assertTrue(set(face) <= set(tets[e]))


class SyntheticResultTests(Plot3DTestCase):
    """Against a file written here, so the plot is checked without a 3D daemon."""

    DIVISIONS = (3, 2, 4)

    def setUp(self):
        super().setUp()
        self.h5 = os.path.join(self.work.name, "box3d.h5")
        self.nodes, self.tets = write_synthetic_result(self.h5, self.DIVISIONS)

    def test_boundary_faces_of_a_box_are_its_surface(self):
        self.assertEqual(self.tets.shape[0], 6 * 3 * 2 * 4)
        self.assert_surface_of_box(self.nodes, self.tets, self.DIVISIONS)

    def test_one_tetrahedron_has_all_four_faces_on_its_boundary(self):
        tet = np.array([[0, 1, 2, 3]])
        faces, element = boundary_faces(tet)
        self.assertEqual(sorted(map(tuple, np.sort(faces, axis=1))),
                         [(0, 1, 2), (0, 1, 3), (0, 2, 3), (1, 2, 3)])
        self.assertEqual(list(element), [0, 0, 0, 0])
        # Each listed face leaves out one node, its opposite vertex.
        self.assertEqual(sorted(set(range(4)) - set(f) for f in TET_FACES.tolist()),
                         [{0}, {1}, {2}, {3}])

    def test_two_tetrahedra_sharing_a_face_hide_it(self):
        faces, element = boundary_faces(np.array([[0, 1, 2, 3], [1, 2, 3, 4]]))
        self.assertEqual(faces.shape[0], 6)
        self.assertNotIn((1, 2, 3), [tuple(sorted(f)) for f in faces])

    def test_an_intact_joint_hides_its_two_faces_and_a_broken_one_shows_them(self):
        # Two tetrahedra of a fracturing part: each on its own nodes (0-3 and
        # 4-7), the face 1 2 3 of the first joined to the face 5 6 7 of the
        # second. While the joint holds the body is one solid whose surface
        # has six faces; once it breaks, the two crack faces are surface too.
        tets = np.array([[0, 1, 2, 3], [4, 5, 6, 7]])
        joints = np.array([[1, 2, 3, 5, 6, 7]])
        self.assertEqual(boundary_faces(tets)[0].shape[0], 8)
        faces, element = boundary_faces(tets, held_joints=joints)
        self.assertEqual(faces.shape[0], 6)
        drawn = [tuple(sorted(f)) for f in faces]
        self.assertNotIn((1, 2, 3), drawn)
        self.assertNotIn((5, 6, 7), drawn)
        self.assertEqual(boundary_faces(tets, held_joints=joints[:0])[0].shape[0], 8)

    def test_stress_plot(self):
        self.assert_drawn(*self.plot(self.h5))

    def test_velocity_plot_of_the_first_moving_snapshot(self):
        self.assert_drawn(*self.plot(self.h5, "--field", "velocity", "--snapshot", "1"))

    def test_stress_component_and_view(self):
        self.assert_drawn(*self.plot(self.h5, "--component", "zz", "--view", "10,30"))

    def test_damage_is_refused_in_3d(self):
        r, png = self.plot(self.h5, "--field", "damage")
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("2D results only", r.stderr)
        self.assertFalse(os.path.exists(png))

    def test_damage_in_3d_says_where_to_look(self):
        r, _ = self.plot(self.h5, "--field", "damage")
        self.assertIn("ParaView", r.stderr)
        self.assertIn("fdemctl events", r.stderr)

    def test_the_xdmf_sidecar_is_pointed_at_its_h5(self):
        # fdemctl fetch leaves R.h5 and R.xdmf side by side, and "open the
        # .xdmf" is what the demo says for ParaView: given to plot_result it
        # was "file signature not found"
        xdmf = os.path.join(self.work.name, "box3d.xdmf")
        with open(xdmf, "w") as f:
            f.write('<?xml version="1.0" ?>\n<Xdmf Version="3.0"></Xdmf>\n')
        r, png = self.plot(xdmf)
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("XDMF", r.stderr)
        self.assertIn("box3d.h5", r.stderr)
        self.assertFalse(os.path.exists(png))

    def test_bad_view_is_a_clear_error(self):
        r, _ = self.plot(self.h5, "--view", "up")
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("ELEVATION,AZIMUTH", r.stderr)

    def test_snapshot_out_of_range(self):
        r, _ = self.plot(self.h5, "--snapshot", "3")
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("out of range", r.stderr)


class DaemonRunTestCase(Plot3DTestCase):
    """Runs cls.case() on a real daemon once per class; self.h5 is the
    fetched result."""

    @classmethod
    def case(cls):
        raise NotImplementedError

    @classmethod
    def setUpClass(cls):
        cls.daemon = fdemd_harness.Daemon().start()
        cls.client = Client("http://127.0.0.1:%d" % cls.daemon.port)
        cls.results = tempfile.TemporaryDirectory(prefix="plot3d-daemon-")
        case = cls.case()
        try:
            case_id = cls.client.submit(case, start=True)
        except FdemdError as e:
            cls.tearDownClass()
            raise AssertionError("the daemon refused %s: %s %s" % (case["name"], e, e.errors))
        cls.client.wait(case_id, interval=0.05, timeout=60 * SLOW)
        cls.h5, _ = cls.client.fetch(case_id, os.path.join(cls.results.name, "result.h5"))

    @classmethod
    def tearDownClass(cls):
        cls.daemon.stop()
        cls.daemon.close()
        cls.results.cleanup()


class DaemonResultTests(DaemonRunTestCase):
    """A box the real daemon stepped: its mesh (mirrored Kuhn cells, not the
    layout above) has the same analytic boundary, and the plot draws it."""

    DIVISIONS = (3, 2, 2)

    @classmethod
    def case(cls):
        return {"name": "box-3d", "dimension": 3,
                "materials": {"rock": {"density": 2000, "young": 1e8, "poisson": 0.25}},
                "parts": [{"name": "block", "material": "rock",
                           "box": {"origin": [0, 0, 0], "size": [0.3, 0.2, 0.2],
                                   "divisions": list(cls.DIVISIONS)},
                           "velocity": [0, 0, 1.0]}],
                "constraints": [{"box": [-1e-6, -1, -1, 1e-6, 1, 1], "fix": ["x", "y", "z"]}],
                "time": {"end": 0.002},
                "output": {"interval": 0.001, "fields": ["position", "velocity", "stress"]}}

    def test_boundary_faces_of_the_daemons_box(self):
        with h5py.File(self.h5, "r") as f:
            nodes, tets = f["/mesh/position0"][:], f["/mesh/tetrahedra"][:]
        self.assertEqual(tets.shape, (6 * 3 * 2 * 2, 4))
        self.assert_surface_of_box(nodes, tets, self.DIVISIONS)

    def test_stress_plot_of_the_bent_box(self):
        self.assert_drawn(*self.plot(self.h5))

    def test_velocity_plot(self):
        self.assert_drawn(*self.plot(self.h5, "--field", "velocity"))


class FracturingResultTests(DaemonRunTestCase):
    """A fracturing box the real daemon stepped: every tetrahedron has its
    own four nodes, so each face is used by one tetrahedron only and the
    faces inside the body are told by the joints that hold them. The plot
    must draw the box's surface, not every face of every tetrahedron (which
    the painter's algorithm then shows through the surface)."""

    DIVISIONS = (2, 1, 1)

    @classmethod
    def case(cls):
        return {"name": "fracturing-box-3d", "dimension": 3,
                "materials": {"rock": {"density": 2000, "young": 1e8, "poisson": 0.25,
                                       "fracture": {"tensile_strength": 1e6, "cohesion": 2e6,
                                                    "friction_angle": 30, "energy_I": 10,
                                                    "energy_II": 50}}},
                "parts": [{"name": "block", "material": "rock", "fracture": True,
                           "box": {"size": [0.2, 0.1, 0.1], "divisions": list(cls.DIVISIONS)}}],
                "time": {"end": 1e-4},
                "output": {"interval": 1e-4, "fields": ["position", "velocity", "stress"]}}

    def test_the_plot_draws_the_surface_of_the_unbroken_box(self):
        with h5py.File(self.h5, "r") as f:
            nodes, tets = f["/mesh/position0"][:], f["/mesh/tetrahedra"][:]
            self.assertEqual(len(np.unique(tets)), 4 * tets.shape[0])
            self.assertFalse(np.any(f["/snapshots/damage"][-1] >= 1))
            surface = surface_of_snapshot(f, -1)
        self.assert_surface_of_box(nodes, tets, self.DIVISIONS, surface)

    def test_stress_plot(self):
        self.assert_drawn(*self.plot(self.h5))


class DemoScriptTests(unittest.TestCase):
    """scripts/demo.sh hands what follows the example to plot_result.py: the
    3D sphere pile, drawn from the default view, is the outside of its box
    and shows no sphere (examples/README.md: look in with --view 75,-60)."""

    def run_demo(self, *args):
        out = tempfile.TemporaryDirectory(prefix="demo-")
        self.addCleanup(out.cleanup)
        env = dict(os.environ, OUT=out.name, PYTHON=PYTHON,
                   BIN=os.path.dirname(fdemd_harness.FDEMD_BIN))
        r = subprocess.run(["bash", os.path.join(ROOT, "scripts", "demo.sh"),
                            "examples/freefall-3d.json"] + list(args),
                           cwd=ROOT, env=env, capture_output=True, text=True,
                           timeout=120 * SLOW)
        return r, out.name

    def test_plot_options_reach_plot_result(self):
        r, out = self.run_demo("--view", "90,0")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertTrue(os.path.exists(os.path.join(out, "freefall-3d.png")))
        self.assertTrue(os.path.exists(os.path.join(out, "demo-fdemd.log")))
        r, _ = self.run_demo("--view", "up")
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("ELEVATION,AZIMUTH", r.stderr)

    def test_a_3d_demo_says_how_to_choose_the_view(self):
        r, _ = self.run_demo()
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("--view", r.stdout)


class VonMises3DTests(unittest.TestCase):
    """The exact 3D von Mises formula on states with a known answer."""

    def test_known_states(self):
        # Uniaxial: svm = |s|.
        self.assertAlmostEqual(von_mises_3d(np.array([[0, 0, -7.0, 0, 0, 0]]))[0], 7.0, places=12)
        # Hydrostatic: svm = 0.
        self.assertAlmostEqual(von_mises_3d(np.array([[4.0, 4.0, 4.0, 0, 0, 0]]))[0], 0.0,
                               places=12)
        # Pure shear on each plane: svm = sqrt(3) |tau|, the three add in squares.
        for k in (3, 4, 5):
            s = np.zeros((1, 6))
            s[0, k] = 2.0
            self.assertAlmostEqual(von_mises_3d(s)[0], 2 * 3 ** 0.5, places=12)
        self.assertAlmostEqual(von_mises_3d(np.array([[0, 0, 0, 1.0, 1.0, 1.0]]))[0], 3.0,
                               places=12)

    def test_invariant_under_rotation(self):
        rng = np.random.default_rng(12)
        a = rng.normal(size=(3, 3))
        sigma = a + a.T
        q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        rotated = q @ sigma @ q.T

        def voigt(m):
            return np.array([[m[0, 0], m[1, 1], m[2, 2], m[1, 2], m[0, 2], m[0, 1]]])
        self.assertAlmostEqual(von_mises_3d(voigt(sigma))[0], von_mises_3d(voigt(rotated))[0],
                               places=12)


class ComponentIn2DTests(unittest.TestCase):
    def test_zz_is_refused_in_2d_naming_the_choices(self):
        with tempfile.TemporaryDirectory() as work:
            h5 = os.path.join(work, "flat.h5")
            with h5py.File(h5, "w") as f:
                f.attrs["dimension"] = 2
                f["/mesh/position0"] = np.array([[0, 0], [1, 0], [0, 1.0]])
                f["/mesh/triangles"] = np.array([[0, 1, 2]], dtype=np.int32)
                f["/snapshots/time"] = np.array([0.0])
                f["/snapshots/stress"] = np.zeros((1, 1, 3))
            r = subprocess.run([PYTHON, PLOT, h5, "-o", os.path.join(work, "x.png"),
                                "--component", "zz"],
                               capture_output=True, text=True, timeout=60 * SLOW)
            self.assertNotEqual(r.returncode, 0)
            self.assertIn("xx, yy, xy", r.stderr)


if __name__ == "__main__":
    unittest.main()
