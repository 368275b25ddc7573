#!/usr/bin/python3
"""generate.py - writes the example case documents of this folder.

    /usr/bin/python3 examples/generate.py

The JSON files are committed, so this is only needed to change them: it keeps
the layouts that are tedious by hand (the 30 discs of disc-pile.json, the
tetrahedral box of sphere-pile.json) and the gmsh mesh of gmsh-plate.json (made from gmsh-plate.geo with the installed
`gmsh -2 -format msh22`) reproducible. Numbers are written the way a person
would type them (3e10, not 30000000000.0).
"""
import json
import math
import os
import subprocess
import tempfile

OUT = os.path.dirname(os.path.abspath(__file__))


def gmsh_text(geo, dimension=2):
    """The ASCII msh 2.2 text gmsh makes from a .geo file."""
    with tempfile.TemporaryDirectory() as tmp:
        msh = os.path.join(tmp, "mesh.msh")
        subprocess.run(["gmsh", "-%d" % dimension, "-format", "msh22", geo, "-o", msh],
                       check=True, stdout=subprocess.DEVNULL)
        with open(msh) as f:
            return f.read()

def number(v):
    if isinstance(v, bool) or v is None:
        return json.dumps(v)
    if isinstance(v, float) and v != 0 and (abs(v) >= 1e5 or abs(v) < 1e-3):
        return ("%g" % v).replace("e+", "e").replace("e0", "e").replace("e-0", "e-")
    return json.dumps(v)
def fmt(v, ind=0):
    pad = "  " * (ind + 1)
    if isinstance(v, dict):
        items = [pad + json.dumps(k) + ": " + fmt(x, ind + 1) for k, x in v.items()]
        return "{\n" + ",\n".join(items) + "\n" + "  " * ind + "}"
    if isinstance(v, list):
        if all(not isinstance(x, (dict, list)) for x in v) or all(
                isinstance(x, list) and not any(isinstance(y, (dict, list)) for y in x) for x in v) and len(v) < 8:
            return "[" + ", ".join(fmt(x, ind) for x in v) + "]"
        return "[\n" + ",\n".join(pad + fmt(x, ind + 1) for x in v) + "\n" + "  " * ind + "]"
    if isinstance(v, str):
        return json.dumps(v)
    return number(v)
def dump(name, doc):
    with open(os.path.join(OUT, name + ".json"), "w") as f:
        f.write(fmt(doc) + "\n")
soft = {"density": 2000, "young": 1e8, "poisson": 0.25}
dump("freefall", {
    "name": "freefall",
    "materials": {"rock": dict(soft)},
    "parts": [{"name": "block", "material": "rock",
               "rectangle": {"origin": [0, 0], "size": [0.1, 0.1], "divisions": [4, 4]}}],
    "gravity": [0, -9.81],
    "time": {"end": 0.5, "dt": "auto", "safety": 0.5},
    "output": {"interval": 0.01, "fields": ["position", "velocity"]}})
dump("bar-wave", {
    "name": "bar-wave",
    "materials": {"elastic": {"density": 1000, "young": 1e9, "poisson": 0.0}},
    "parts": [{"name": "bar", "material": "elastic",
               "rectangle": {"origin": [0, 0], "size": [1.0, 0.05], "divisions": [40, 2]},
               "velocity": [1.0, 0]}],
    "constraints": [{"box": [-0.001, -0.001, 0.001, 0.051], "fix": ["x", "y"]}],
    "time": {"end": 0.008, "dt": "auto", "safety": 0.5},
    "output": {"interval": 5e-5, "fields": ["position", "velocity", "stress"]}})
dump("collision", {
    "name": "collision",
    "materials": {"rock": dict(soft, friction=0.0)},
    "parts": [{"name": "left", "material": "rock",
               "rectangle": {"origin": [-0.105, 0], "size": [0.1, 0.1], "divisions": [5, 5]},
               "velocity": [2.0, 0]},
              {"name": "right", "material": "rock",
               "rectangle": {"origin": [0.005, 0], "size": [0.1, 0.1], "divisions": [5, 5]}}],
    "time": {"end": 0.015, "dt": "auto", "safety": 0.5},
    "output": {"interval": 2e-4, "fields": ["position", "velocity", "stress"]}})
theta = math.radians(30)
dump("incline", {
    "name": "incline",
    "materials": {"rock": dict(soft, friction=0.3)},
    "parts": [{"name": "slab", "material": "rock",
               "rectangle": {"origin": [-0.2, -0.1], "size": [1.2, 0.1], "divisions": [24, 2]}},
              {"name": "block", "material": "rock",
               "rectangle": {"origin": [0, 0], "size": [0.1, 0.1], "divisions": [4, 4]}}],
    "constraints": [{"part": "slab", "fix": ["x", "y"]}],
    "gravity": [round(9.81 * math.sin(theta), 6), round(-9.81 * math.cos(theta), 6)],
    "time": {"end": 0.5, "dt": "auto", "safety": 0.5},
    "output": {"interval": 0.01, "fields": ["position", "velocity", "stress"]}})
parts = [
    {"name": "floor", "material": "wall",
     "rectangle": {"origin": [-0.5, -0.05], "size": [1.0, 0.05], "divisions": [20, 1]}},
    {"name": "left-wall", "material": "wall",
     "rectangle": {"origin": [-0.55, -0.05], "size": [0.05, 0.8], "divisions": [1, 16]}},
    {"name": "right-wall", "material": "wall",
     "rectangle": {"origin": [0.5, -0.05], "size": [0.05, 0.8], "divisions": [1, 16]}}]
k = 0
for row in range(5):
    for col in range(6):
        x = -0.3 + 0.12 * col + (0.02 if row % 2 else -0.02)
        y = 0.1 + 0.12 * row
        parts.append({"name": "disc-%d" % k, "material": "grain",
                      "disc": {"center": [round(x, 4), round(y, 4)], "radius": 0.04, "divisions": 12}})
        k += 1
dump("disc-pile", {
    "name": "disc-pile",
    "materials": {"grain": {"density": 2000, "young": 5e7, "poisson": 0.25, "damping": 0.2,
                            "friction": 0.4},
                  "wall": {"density": 2000, "young": 5e7, "poisson": 0.25, "friction": 0.4}},
    "parts": parts,
    "constraints": [{"part": p, "fix": ["x", "y"]} for p in ("floor", "left-wall", "right-wall")],
    "gravity": [0, -9.81],
    "time": {"end": 0.8, "dt": "auto", "safety": 0.5},
    "output": {"interval": 0.01, "fields": ["position", "velocity"]}})
# OpenFDEM's Brazilian set in this format's names: "friction" 0.3 is the
# contact's Coulomb coefficient; the joints' friction angle is not part of
# the set, so it takes a common value for rock, 30 degrees.
rock = {"density": 2700, "young": 3e10, "poisson": 0.3, "damping": 0.6, "friction": 0.3,
        "fracture": {"tensile_strength": 1e6, "cohesion": 3e6,
                     "friction_angle": 30,
                     "energy_I": 10, "energy_II": 50}}
steel = {"density": 7800, "young": 2e11, "poisson": 0.3, "friction": 0.3}
dump("brazilian-disc", {
    "name": "brazilian-disc",
    "materials": {"rock": rock, "steel": steel},
    "parts": [
        {"name": "disc", "material": "rock", "fracture": True,
         "gmsh": gmsh_text(os.path.join(OUT, "brazilian-disc.geo"))},
        {"name": "top", "material": "steel",
         "rectangle": {"origin": [-0.01, 0.025], "size": [0.02, 0.004], "divisions": [8, 2]}},
        {"name": "bottom", "material": "steel",
         "rectangle": {"origin": [-0.01, -0.029], "size": [0.02, 0.004], "divisions": [8, 2]}}],
    "constraints": [{"part": "top", "velocity": [0, -0.025]},
                    {"part": "bottom", "velocity": [0, 0.025]}],
    "time": {"end": 0.0008, "dt": "auto", "safety": 0.5},
    "output": {"interval": 1e-5, "fields": ["position", "velocity", "stress", "damage"]}})
dump("uniaxial-compression", {
    "name": "uniaxial-compression",
    "materials": {"rock": rock, "steel": steel},
    "parts": [
        {"name": "specimen", "material": "rock", "fracture": True,
         "gmsh": gmsh_text(os.path.join(OUT, "uniaxial-compression.geo"))},
        {"name": "top", "material": "steel",
         "rectangle": {"origin": [-0.0175, 0.025], "size": [0.035, 0.004], "divisions": [10, 2]}},
        {"name": "bottom", "material": "steel",
         "rectangle": {"origin": [-0.0175, -0.029], "size": [0.035, 0.004], "divisions": [10, 2]}}],
    "constraints": [{"part": "top", "velocity": [0, -0.05]},
                    {"part": "bottom", "velocity": [0, 0.05]}],
    "time": {"end": 0.0004, "dt": "auto", "safety": 0.5},
    "output": {"interval": 5e-6, "fields": ["position", "velocity", "stress", "damage"]}})
dump("gmsh-plate", {
    "name": "gmsh-plate",
    "materials": {"polymer": {"density": 2000, "young": 1e9, "poisson": 0.25, "damping": 0.3}},
    "parts": [{"name": "plate", "material": "polymer", "gmsh": gmsh_text(os.path.join(OUT, "gmsh-plate.geo"))}],
    "constraints": [{"box": [-1e-6, -1e-6, 1e-6, 0.100001], "fix": ["x", "y"]},
                    {"box": [0.199999, -1e-6, 0.200001, 0.100001], "velocity": [0.01, None]}],
    "time": {"end": 0.003, "dt": "auto", "safety": 0.5},
    "output": {"interval": 5e-5, "fields": ["position", "velocity", "stress"]}})
# ------------------------------------------------------------------- 3D
# Contract 5.2: "dimension": 3, every vector with three components, z up.
dump("freefall-3d", {
    "name": "freefall-3d",
    "dimension": 3,
    "materials": {"rock": dict(soft)},
    "parts": [{"name": "block", "material": "rock",
               "box": {"origin": [0, 0, 0], "size": [0.1, 0.1, 0.1], "divisions": [4, 4, 4]}}],
    "gravity": [0, 0, -9.81],
    "time": {"end": 0.5, "dt": "auto", "safety": 0.5},
    "output": {"interval": 0.01, "fields": ["position", "velocity"]}})
# brazilian-disc.json's rock as a 10 mm thick cylinder (D = 50 mm, the
# built-in cylinder: 24 edges round the rim, one layer through) between two
# steel platen slabs closing at 0.1 m/s each; scripts/limits.py
# (brazilian_3d_case) builds the same case at other meshes and speeds
dump("brazilian-disc-3d", {
    "name": "brazilian-disc-3d",
    "dimension": 3,
    "materials": {"rock": rock, "steel": steel},
    "parts": [
        {"name": "disc", "material": "rock", "fracture": True,
         "cylinder": {"center": [0, 0, 0], "axis": "z", "radius": 0.025, "length": 0.01,
                      "divisions": [24, 1]}},
        {"name": "top", "material": "steel",
         "box": {"origin": [-0.01, 0.025, -0.001], "size": [0.02, 0.004, 0.012],
                 "divisions": [6, 1, 2]}},
        {"name": "bottom", "material": "steel",
         "box": {"origin": [-0.01, -0.029, -0.001], "size": [0.02, 0.004, 0.012],
                 "divisions": [6, 1, 2]}}],
    "constraints": [{"part": "top", "velocity": [0, -0.1, 0]},
                    {"part": "bottom", "velocity": [0, 0.1, 0]}],
    "time": {"end": 0.0004, "dt": "auto", "safety": 0.5},
    "output": {"interval": 5e-6, "fields": ["position", "velocity", "stress", "damage"]},
    # the platen load curve at 1 us (400 rows of a few numbers, not snapshots)
    "history": {"interval": 1e-6,
                "points": [{"name": "centre", "at": [0, 0, 0]},
                           {"name": "crown", "at": [0, 0.024, 0]}]}})
# uniaxial-compression.json's specimen extruded 25 mm along z (a square
# prism, the load along y as in 2D), of the built-in box mesh (coarse: 3
# cells across, so that it runs in about a minute and a half), between two
# steel platen slabs wider than it on every side
dump("uniaxial-prism-3d", {
    "name": "uniaxial-prism-3d",
    "dimension": 3,
    "materials": {"rock": rock, "steel": steel},
    "parts": [
        {"name": "specimen", "material": "rock", "fracture": True,
         "box": {"origin": [-0.0125, -0.025, 0], "size": [0.025, 0.05, 0.025],
                 "divisions": [3, 6, 3]}},
        {"name": "top", "material": "steel",
         "box": {"origin": [-0.0175, 0.025, -0.005], "size": [0.035, 0.004, 0.035],
                 "divisions": [4, 1, 4]}},
        {"name": "bottom", "material": "steel",
         "box": {"origin": [-0.0175, -0.029, -0.005], "size": [0.035, 0.004, 0.035],
                 "divisions": [4, 1, 4]}}],
    "constraints": [{"part": "top", "velocity": [0, -0.05, 0]},
                    {"part": "bottom", "velocity": [0, 0.05, 0]}],
    "time": {"end": 0.0004, "dt": "auto", "safety": 0.5},
    "output": {"interval": 5e-6, "fields": ["position", "velocity", "stress", "damage"]}})
dump("collision-3d", {
    "name": "collision-3d",
    "dimension": 3,
    "materials": {"rock": dict(soft, friction=0.0)},
    "parts": [{"name": "left", "material": "rock",
               "box": {"origin": [-0.105, 0, 0], "size": [0.1, 0.1, 0.1], "divisions": [4, 4, 4]},
               "velocity": [2.0, 0, 0]},
              {"name": "right", "material": "rock",
               "box": {"origin": [0.005, 0, 0], "size": [0.1, 0.1, 0.1], "divisions": [4, 4, 4]}}],
    "time": {"end": 0.015, "dt": "auto", "safety": 0.5},
    "output": {"interval": 2e-4, "fields": ["position", "velocity", "stress"]}})


def container_mesh(cells, cell, origin):
    """An open box of cubic cells as one tetrahedral mesh: the floor layer
    and the four side walls of a cells[0] x cells[1] x cells[2] block, each
    cell split into the six Kuhn tetrahedra of its 000-111 diagonal (the
    same split in every cell, so neighbours share their face diagonals)."""
    nx, ny, nz = cells
    kept = [(i, j, k) for i in range(nx) for j in range(ny) for k in range(nz)
            if k == 0 or i in (0, nx - 1) or j in (0, ny - 1)]
    index, nodes, tets = {}, [], []

    def node(ijk):
        if ijk not in index:
            index[ijk] = len(nodes)
            nodes.append([round(o + cell * n, 6) for o, n in zip(origin, ijk)])
        return index[ijk]

    for i, j, k in kept:
        for order in ((0, 1, 2), (0, 2, 1), (1, 0, 2), (1, 2, 0), (2, 0, 1), (2, 1, 0)):
            corner = [i, j, k]
            path = [node(tuple(corner))]
            for axis in order:
                corner[axis] += 1
                path.append(node(tuple(corner)))
            tets.append(path)
    return nodes, tets


# A 0.2 x 0.2 m floor at z = 0 walled in 0.2 m high: one fixed part made of
# the floor slab and four wall slabs (one body, so the slabs do not contact
# each other), and 2 x 2 x 2 spheres dropped into it, the upper layer a few
# mm off the columns of the lower so it topples into the pockets. Every
# element is about as large as a sphere's (0.05 m cells, spheres of 8 edges
# around), since NBS sizes its cells by the largest element; grains are
# soft (1 MPa, the penalty equal to it) so the contact step is 68 us (1 us
# at the default penalty of a 50 MPa grain), which keeps the run near 15 s.
nodes, tets = container_mesh((6, 6, 5), 0.05, (-0.15, -0.15, -0.05))
parts = [{"name": "box", "material": "wall", "mesh": {"nodes": nodes, "tetrahedra": tets}}]
centres = [(-0.05 + 0.1 * i, -0.05 + 0.1 * j, 0.045) for i in range(2) for j in range(2)]
centres += [(x + 0.004, y - 0.003, z + 0.09) for x, y, z in centres]
for k, (x, y, z) in enumerate(centres):
    parts.append({"name": "sphere-%d" % k, "material": "grain",
                  "sphere": {"center": [round(x, 4), round(y, 4), z], "radius": 0.04,
                             "divisions": 8}})
dump("sphere-pile", {
    "name": "sphere-pile",
    "dimension": 3,
    "materials": {"grain": {"density": 2000, "young": 1e6, "poisson": 0.25, "damping": 0.3,
                            "penalty": 1e6, "friction": 0.4},
                  "wall": {"density": 2000, "young": 1e6, "poisson": 0.25, "penalty": 1e6,
                           "friction": 0.4}},
    "parts": parts,
    "constraints": [{"part": "box", "fix": ["x", "y", "z"]}],
    "gravity": [0, 0, -9.81],
    "time": {"end": 0.7, "dt": "auto", "safety": 0.5},
    "output": {"interval": 0.01, "fields": ["position", "velocity"]}})


# A rock slope, 60 m wide, 30 m high behind a 45 degree face down to a 10 m
# bench, meshed as 30 x 15 columns of 2 m (each quadrilateral split in two),
# on a fixed base with rollers on both sides. Gravity is ramped as 1 - cos
# over 0.6 s, eleven periods 4H/c_p of the slope's vertical mode (H = 30 m,
# c_p = 2191 m/s): the slope settles with almost no kinetic energy, where
# gravity switched on at once makes it ring with about its static elastic
# energy.
def slope_mesh(cols, rows, width, height):
    nodes, triangles = [], []
    for i in range(cols + 1):
        x = width * i / cols
        top = 30 if x <= 20 else (10 if x >= 40 else 30 - (x - 20))
        for j in range(rows + 1):
            nodes.append([round(x, 6), round(top * j / rows, 6)])
    for i in range(cols):
        for j in range(rows):
            a, b = i * (rows + 1) + j, (i + 1) * (rows + 1) + j
            if (i + j) % 2:
                triangles += [[a, b, b + 1], [a, b + 1, a + 1]]
            else:
                triangles += [[a, b, a + 1], [a + 1, b, b + 1]]
    return nodes, triangles


nodes, triangles = slope_mesh(30, 15, 60, 30)
ramp = [[round(0.6 * k / 20, 4), round(0.5 * (1 - math.cos(math.pi * k / 20)), 6)]
        for k in range(21)]
dump("slope-gravity-ramp", {
    "name": "slope-gravity-ramp",
    "materials": {"rock": {"density": 2500, "young": 1e10, "poisson": 0.25}},
    "parts": [{"name": "slope", "material": "rock",
               "mesh": {"nodes": nodes, "triangles": triangles}}],
    "constraints": [{"box": [-1, -0.01, 61, 0.01], "fix": ["x", "y"]},
                    {"box": [-0.01, -1, 0.01, 31], "fix": ["x"]},
                    {"box": [59.99, -1, 60.01, 31], "fix": ["x"]}],
    "gravity": [0, -9.81],
    "gravity_amplitude": ramp,
    "time": {"end": 0.9, "dt": "auto", "safety": 0.5},
    "output": {"interval": 0.01, "fields": ["position", "velocity", "stress"]}})


# A plane P pulse along a 10 m bar (200 x 2 cells, every node held in y so
# the wave is plane, c_p = 2191 m/s): a sin^2 pressure pulse of 1 MPa lasting
# 1/c_p (1 m, 20 cells, long) enters at x = 0 and leaves through a Lysmer
# boundary at x = 10 m. The run ends 1.5 transits after the pulse.
c_p = math.sqrt(1e10 * 0.75 / (2500 * 1.25 * 0.5))
tau = 1 / c_p
pulse = [[float("%.6g" % (tau * k / 20)), round(math.sin(math.pi * k / 20) ** 2, 6)]
         for k in range(21)]
dump("wave-absorb", {
    "name": "wave-absorb",
    "materials": {"rock": {"density": 2500, "young": 1e10, "poisson": 0.25}},
    "parts": [{"name": "bar", "material": "rock",
               "rectangle": {"origin": [0, 0], "size": [10, 0.1], "divisions": [200, 2]}}],
    "constraints": [{"box": [-1, -1, 11, 1], "fix": ["y"]},
                    {"box": [-1, -1, 1e-6, 1], "pressure": 1e6, "amplitude": pulse},
                    {"box": [9.999999, -1, 11, 1], "absorb": True}],
    "time": {"end": float("%.4g" % (tau + 1.5 * 10 / c_p)), "dt": "auto", "safety": 0.5},
    "output": {"interval": 1e-4, "fields": ["position", "velocity", "stress"]}})


# ---------------------------------------------------------- joint sets
# Contract 5.3: a joint set on a gmsh physical curve group of a fracturing
# part, weaker than the rock around it.
dump("jointed-block", {
    "name": "jointed-block",
    "materials": {"rock": {"density": 2500, "young": 1e10, "poisson": 0.2, "damping": 0.1,
                           "fracture": {"tensile_strength": 5e6, "cohesion": 1.5e7,
                                        "friction_angle": 30, "energy_I": 20,
                                        "energy_II": 100}}},
    "parts": [{"name": "block", "material": "rock", "fracture": True,
               "gmsh": gmsh_text(os.path.join(OUT, "jointed-block.geo")),
               "discontinuities": {"joints": {"tensile_strength": 1e6, "cohesion": 3e6,
                                              "energy_I": 5, "energy_II": 25}}}],
    "constraints": [{"part": "block", "group": "base", "fix": ["y"]},
                    {"part": "block", "group": "corner", "fix": ["x"]},
                    {"part": "block", "group": "top", "velocity": [None, 0.01]}],
    "time": {"end": 0.0024, "dt": "auto", "safety": 0.5},
    "output": {"interval": 2e-5, "fields": ["position", "velocity", "stress", "damage"]}})


# In-situ stress (contract 5.3). A pressurised borehole: the plate of
# borehole.geo starts under the in-situ stress sxx = -10, syy = -20 MPa
# (compression negative), its edges carry the matching pressures and let
# waves out (absorb), the bore is drilled at t = 0 with 5 MPa of fluid in
# it. Kirsch plus Lame give the hoop stress at the bore wall,
# sxx + syy - 2 (sxx - syy) cos 2 theta + p: -45 MPa at theta = 0 and
# -5 MPa at theta = 90 degrees.
B = 2.0
rock = {"density": 2600, "young": 2e10, "poisson": 0.25, "damping": 0.2}
edges = [("x", [-B - 0.01, -B - 0.01, -B + 0.01, B + 0.01], 10e6),
         ("x", [B - 0.01, -B - 0.01, B + 0.01, B + 0.01], 10e6),
         ("y", [-B - 0.01, -B - 0.01, B + 0.01, -B + 0.01], 20e6),
         ("y", [-B - 0.01, B - 0.01, B + 0.01, B + 0.01], 20e6)]
dump("borehole", {
    "name": "borehole",
    "materials": {"rock": dict(rock)},
    "parts": [{"name": "plate", "material": "rock",
               "initial_stress": {"value": [-10e6, -20e6, 0]},
               "gmsh": gmsh_text(os.path.join(OUT, "borehole.geo"))}],
    "constraints": [{"box": box, "pressure": p} for _, box, p in edges] +
                   [{"box": box, "absorb": True} for _, box, _ in edges] +
                   [{"box": [-0.11, -0.11, 0.11, 0.11], "pressure": 5e6}],
    "time": {"end": 0.002, "dt": "auto", "safety": 0.5},
    "output": {"interval": 0.0001, "fields": ["position", "stress"]}})


# A tunnel excavated in a rock mass under the hydrostatic in-situ stress
# -15 MPa: the opening of tunnel.geo starts held by a 15 MPa support
# pressure equal to it (so the model starts in equilibrium), which is
# taken away over 10 ms (amplitude 1 -> 0, slow against the 0.3 ms a wave
# needs to cross the opening: quasi-static). The wall converges along the
# elastic ground reaction line u = (P0 - p) a / (2 G) to 0.9375 mm, and the
# hoop stress at the wall rises to 2 P0 - p = 30 MPa of compression.
A = 1.0
B = 20.0
far = [[-B - 0.1, -B - 0.1, -B + 0.1, B + 0.1], [B - 0.1, -B - 0.1, B + 0.1, B + 0.1],
       [-B - 0.1, -B - 0.1, B + 0.1, -B + 0.1], [-B - 0.1, B - 0.1, B + 0.1, B + 0.1]]
dump("tunnel", {
    "name": "tunnel",
    "materials": {"rock": dict(rock)},
    "parts": [{"name": "rock mass", "material": "rock",
               "initial_stress": {"value": [-15e6, -15e6, 0]},
               "gmsh": gmsh_text(os.path.join(OUT, "tunnel.geo"))}],
    "constraints": [{"box": box, "pressure": 15e6} for box in far] +
                   [{"box": box, "absorb": True} for box in far] +
                   [{"box": [-A - 0.01, -A - 0.01, A + 0.01, A + 0.01], "pressure": 15e6,
                     "amplitude": [[0, 1], [0.01, 0]]}],
    "time": {"end": 0.015, "dt": "auto", "safety": 0.5},
    "output": {"interval": 0.0005, "fields": ["position", "stress"]}})

# Fracture in a region (contract 6.1): a 10 m opening in a 30 m square of
# rock (tunnel-region.geo) loaded on its edges by a pressure ramped to
# 15 MPa over 10 ms and held (edges absorbing). The hoop stress at the
# wall rises towards 2 p = 30 MPa, above the joints' Mohr-Coulomb strength
# 2 c cos(phi) / (1 - sin(phi)) = 23 MPa, and falls to 20 MPa at r = 9 m:
# the rock can break only in the annulus 5 m < r < 9 m (the group "near
# field"); the far field stays one continuous body bonded to it.
B = 15.0
far = [[-B - 0.1, -B - 0.1, -B + 0.1, B + 0.1], [B - 0.1, -B - 0.1, B + 0.1, B + 0.1],
       [-B - 0.1, -B - 0.1, B + 0.1, -B + 0.1], [-B - 0.1, B - 0.1, B + 0.1, B + 0.1]]
dump("tunnel-region", {
    "name": "tunnel-region",
    "materials": {"rock": {"density": 2600, "young": 2e10, "poisson": 0.25, "damping": 0.2,
                           "friction": 0.5,
                           "fracture": {"tensile_strength": 2e6, "cohesion": 6e6,
                                        "friction_angle": 35, "energy_I": 50,
                                        "energy_II": 250}}},
    "parts": [{"name": "rock mass", "material": "rock",
               "fracture": {"group": "near field"},
               "gmsh": gmsh_text(os.path.join(OUT, "tunnel-region.geo"))}],
    "constraints": [{"box": box, "pressure": 15e6, "amplitude": [[0, 0], [0.01, 1]]}
                    for box in far] +
                   [{"box": box, "absorb": True} for box in far],
    "time": {"end": 0.02, "dt": "auto", "safety": 0.5},
    "output": {"interval": 0.001, "fields": ["position", "stress", "damage"]}})


# ------------------------------------------------- excavation in stages
# Contract 6.1. A tunnel driven through jointed rock at about 570 m depth:
# gravity, an in-situ stress that grows with depth (sigma_v = 15 MPa at the
# tunnel's centre, K0 = 1.5), the far boundaries carrying that stress
# (boundary_stress: one line per side, gradient included) over a roller
# base. Fracture only in the annulus "near" around the opening (its joints
# carry the in-situ stress from t = 0, so stage 1 is at rest), Weibull
# strengths, two joint sets in the near field weaker than the rock. Stage 1
# holds the rock as it is; stage 2 removes the tunnel's rock and ramps the
# forces it exerted on the wall to zero over 10 ms (the unloading method):
# the crown and invert, where Kirsch's hoop stress 3 sigma_h - sigma_v =
# 52.5 MPa exceeds the rock's uniaxial strength 2 c cos phi / (1 - sin phi)
# = 30.8 MPa, break into a damaged zone, and the joint sets cut a wedge in
# the roof that gravity pulls down; the sidewalls (22.5 MPa) hold.
RHO_G = 2700 * 9.81
SIGMA_V, K0 = 15e6, 1.5


def in_situ(dimension):
    """sigma at the tunnel axis (height 0) and its gradient with height:
    compression negative, so the stress grows less negative upwards."""
    if dimension == 2:
        return {"value": [-K0 * SIGMA_V, -SIGMA_V, 0],
                "gradient": [K0 * RHO_G, RHO_G, 0], "reference": 0}
    return {"value": [-K0 * SIGMA_V, -K0 * SIGMA_V, -SIGMA_V, 0, 0, 0],
            "gradient": [K0 * RHO_G, K0 * RHO_G, RHO_G, 0, 0, 0], "reference": 0}


def jointed_rock():
    return {"density": 2700, "young": 2e10, "poisson": 0.25, "damping": 0.3, "friction": 0.6,
            "fracture": {"tensile_strength": 4e6, "cohesion": 8e6, "friction_angle": 35,
                         "energy_I": 50, "energy_II": 250,
                         "variation": {"distribution": "weibull", "modulus": 8, "seed": 7}}}


joint_set = {"tensile_strength": 0.2e6, "cohesion": 0.5e6, "friction_angle": 30,
             "energy_I": 5, "energy_II": 25}

dump("staged-tunnel", {
    "name": "staged-tunnel",
    "materials": {"rock": jointed_rock()},
    "parts": [{"name": "rock mass", "material": "rock", "fracture": {"group": "near"},
               "initial_stress": in_situ(2),
               "gmsh": gmsh_text(os.path.join(OUT, "staged-tunnel.geo")),
               "discontinuities": {"joints": joint_set}}],
    "gravity": [0, -9.81],
    "constraints": [{"part": "rock mass", "group": side, "boundary_stress": in_situ(2)}
                    for side in ("left", "right", "top")] +
                   [{"part": "rock mass", "group": "base", "fix": ["y"]}],
    "stages": [{"name": "in-situ", "end": 0.002},
               {"name": "excavate", "end": 0.04, "relax": 0.01,
                "excavate": [{"part": "rock mass", "group": "excavation"}]}],
    "time": {"end": 0.04, "dt": "auto", "safety": 0.5},
    "output": {"interval": 0.001, "fields": ["position", "displacement", "stress", "damage"]}})

# The same in 3D: a drift of radius 1 m along y through a 12 x 1 x 12 m block
# (z up), fracture in the shell r < 3 m, the two joint sets striking along
# the drift, the two end faces on rollers (plane strain in the middle).
dump("drift-3d", {
    "name": "drift-3d",
    "dimension": 3,
    "materials": {"rock": jointed_rock()},
    "parts": [{"name": "rock mass", "material": "rock", "fracture": {"group": "near"},
               "initial_stress": in_situ(3),
               "gmsh": gmsh_text(os.path.join(OUT, "drift-3d.geo"), 3),
               "discontinuities": {"joints": joint_set}}],
    "gravity": [0, 0, -9.81],
    "constraints": [{"part": "rock mass", "group": side, "boundary_stress": in_situ(3)}
                    for side in ("left", "right", "top")] +
                   [{"part": "rock mass", "group": "base", "fix": ["z"]},
                    {"part": "rock mass", "group": "front", "fix": ["y"]},
                    {"part": "rock mass", "group": "back", "fix": ["y"]}],
    "stages": [{"name": "in-situ", "end": 0.001},
               {"name": "excavate", "end": 0.008, "relax": 0.003,
                "excavate": [{"part": "rock mass", "group": "excavation"}]}],
    "time": {"end": 0.008, "dt": "auto", "safety": 0.5},
    "output": {"interval": 0.0005, "fields": ["position", "displacement", "stress"]}})


# Borehole breakdown (Hubbert & Willis 1957; issue 36). A disc of rock of
# radius R = 10 a around a bore of radius a = 0.1 m, meshed on polar lines
# (64 sectors, rings growing by 1 + 2 pi / 64 so the elements stay about
# square; a node on each axis, so radial element edges run along
# theta = 0 and 90 degrees), under the in-situ stress sigma_H = 15 MPa
# along x and sigma_h = 10 MPa along y (compression positive), held at the
# outer circle by the matching boundary_stress (and absorbing). The bore
# starts held by the same traction (in equilibrium at t = 0), which is
# taken away over 0.3 ms (the bore is drilled), and joints (T = 5 MPa)
# fill r < 0.35 m. The bore is full of water at rest (K_f = 2 GPa) and
# water is injected into it at a constant Q = 0.4 m^2/s ("inject" with
# "bore": true): the bore's stiffness, V/K_f plus the wall's compliance
# 2 pi a^2 (1 + nu)/E, is 1.96e-11 m^2/Pa, so its pressure rises by about
# 20 MPa/ms, slow against the 36 us a wave takes to cross the bore. The
# wall's hoop stress at theta = 0 is 3 sigma_h - sigma_H - p (compression
# positive), so the wall cracks along x at the breakdown pressure
# p_b = 3 sigma_h - sigma_H + T = 20 MPa; the cracking wall joints take
# the water, and the bore's pressure falls (tests/unit/test_borehole_breakdown.c).
def polar_gmsh(a, R, sectors):
    """msh 2.2 text of the ring a < r < R: surface group "rock", curve groups
    "bore" (r = a) and "outer" (r = R)."""
    growth = 1 + 2 * math.pi / sectors
    rings = max(1, round(math.log(R / a) / math.log(growth)))
    radii = [a * (R / a) ** (i / rings) for i in range(rings + 1)]
    nodes = [(r * math.cos(2 * math.pi * j / sectors), r * math.sin(2 * math.pi * j / sectors))
             for r in radii for j in range(sectors)]
    def node(i, j):
        return i * sectors + j % sectors + 1
    lines = [(1, node(0, j + 1), node(0, j)) for j in range(sectors)]  # bore, outward normal in
    lines += [(2, node(rings, j), node(rings, j + 1)) for j in range(sectors)]
    tris = []
    for i in range(rings):
        for j in range(sectors):
            a0, a1, b0, b1 = node(i, j), node(i, j + 1), node(i + 1, j), node(i + 1, j + 1)
            # the diagonal alternates in a checkerboard: no preferred direction
            if (i + j) % 2 == 0:
                tris += [(a0, a1, b1), (a0, b1, b0)]
            else:
                tris += [(a0, a1, b0), (a1, b1, b0)]
    out = ["$MeshFormat", "2.2 0 8", "$EndMeshFormat", "$PhysicalNames", "3",
           '1 1 "bore"', '1 2 "outer"', '2 3 "rock"', "$EndPhysicalNames", "$Nodes",
           str(len(nodes))]
    out += ["%d %.15g %.15g 0" % (k + 1, x, y) for k, (x, y) in enumerate(nodes)]
    out += ["$EndNodes", "$Elements", str(len(lines) + len(tris))]
    k = 0
    for tag, p, q in lines:
        k += 1
        out.append("%d 1 2 %d %d %d %d" % (k, tag, tag, p, q))
    for t in tris:
        k += 1
        out.append("%d 2 2 3 3 %d %d %d" % (k, *t))
    out += ["$EndElements", ""]
    return "\n".join(out)


bore_a, bore_stress = 0.1, [-15e6, -10e6, 0]
dump("borehole-breakdown", {
    "name": "borehole-breakdown",
    "materials": {"rock": {"density": 2600, "young": 2e10, "poisson": 0.25, "damping": 0.2,
                           "fracture": {"tensile_strength": 5e6, "cohesion": 3e7,
                                        "friction_angle": 30, "energy_I": 20,
                                        "energy_II": 200, "aperture0": 1e-4}}},
    "fluid": {"viscosity": 1e-4, "bulk_modulus": 2e9, "density": 0},
    "parts": [{"name": "rock", "material": "rock",
               "fracture": {"box": [-0.6, -0.6, 0.6, 0.6]},
               "initial_stress": {"value": bore_stress},
               "gmsh": polar_gmsh(bore_a, 10 * bore_a, 64)}],
    "constraints": [{"part": "rock", "group": "bore", "inject": 0.4, "bore": True},
                    {"part": "rock", "group": "bore", "boundary_stress": {"value": bore_stress},
                     "amplitude": [[0, 1], [0.0003, 0]]},
                    {"part": "rock", "group": "outer", "boundary_stress": {"value": bore_stress}},
                    {"part": "rock", "group": "outer", "absorb": True}],
    "time": {"end": 0.0015, "dt": "auto", "safety": 0.5},
    "output": {"interval": 0.0001, "fields": ["position", "stress", "damage"]},
    "history": {"interval": 1e-5}})


# A hydraulic fracture meeting a natural joint (issue 36 item 6). A 1 x 1 m
# plane-strain square (20 x 20 cells), its edges fixed, under the in-situ
# stress sigma_H along x and sigma_h = 1 MPa along y (compression
# positive); fluid injected at the centre drives a fracture along y = 0
# (the fracture region's band two elements high) towards a vertical natural
# joint at x = 0.15 m (a physical curve group with its own weak, frictional
# fracture parameters, in a band of its own). Renshaw & Pollard (1995): the
# fracture crosses a frictional interface it meets at right angles when
# sigma_H / (T0 + sigma_h) > (0.35 + 0.35 / mu) / 1.06, mu = tan(phi) of
# the joint, T0 the rock's tensile strength; otherwise the joint opens or
# slips and holds it. The example crosses (sigma_H = 10 MPa, phi = 30
# degrees: 2.5 against 0.90); the test and examples/README.md run it on
# the other side too (sigma_H = 2 MPa: 0.5; phi = 5 degrees: 2.5 against 4.1).
def square_gmsh(half, cells, joint_x):
    """msh 2.2 text of the square [-half, half]^2 in cells x cells squares
    of two triangles (diagonals alternating): surface group "rock", curve
    groups "left", "right", "bottom", "top" and "natural joint" (the
    vertical line x = joint_x, on the grid)."""
    n = cells + 1
    h = 2 * half / cells
    def node(i, j):
        return j * n + i + 1
    nodes = [(-half + i * h, -half + j * h) for j in range(n) for i in range(n)]
    column = round((joint_x + half) / h)
    groups = {"left": [(node(0, j), node(0, j + 1)) for j in range(cells)],
              "right": [(node(cells, j), node(cells, j + 1)) for j in range(cells)],
              "bottom": [(node(i, 0), node(i + 1, 0)) for i in range(cells)],
              "top": [(node(i, cells), node(i + 1, cells)) for i in range(cells)],
              "natural joint": [(node(column, j), node(column, j + 1)) for j in range(cells)]}
    tris = []
    for j in range(cells):
        for i in range(cells):
            a0, a1, b0, b1 = node(i, j), node(i + 1, j), node(i, j + 1), node(i + 1, j + 1)
            if (i + j) % 2 == 0:
                tris += [(a0, a1, b1), (a0, b1, b0)]
            else:
                tris += [(a0, a1, b0), (a1, b1, b0)]
    names = list(groups)
    out = ["$MeshFormat", "2.2 0 8", "$EndMeshFormat", "$PhysicalNames", str(len(names) + 1)]
    out += ['1 %d "%s"' % (k + 1, g) for k, g in enumerate(names)]
    out += ['2 %d "rock"' % (len(names) + 1), "$EndPhysicalNames", "$Nodes", str(len(nodes))]
    out += ["%d %.15g %.15g 0" % (k + 1, x, y) for k, (x, y) in enumerate(nodes)]
    lines = [(k + 1, p, q) for k, g in enumerate(names) for p, q in groups[g]]
    out += ["$EndNodes", "$Elements", str(len(lines) + len(tris))]
    k = 0
    for tag, p, q in lines:
        k += 1
        out.append("%d 1 2 %d %d %d %d" % (k, tag, tag, p, q))
    for t in tris:
        k += 1
        out.append("%d 2 2 %d %d %d %d %d" % (k, len(names) + 1, len(names) + 1, *t))
    out += ["$EndElements", ""]
    return "\n".join(out)


def hf_natural_joint(sigma_H, friction_angle, half=0.5, cells=20, joint_x=0.15, end=0.008):
    """The case with sigma_H (Pa) and the joint's friction angle (degrees)
    (tests/unit/test_hf_natural_joint.c changes those two of the example)."""
    h = 2 * half / cells
    stress = [-sigma_H, -1e6, 0]
    return {
        "name": "hf-natural-joint",
        "materials": {"rock": {"density": 2500, "young": 1e10, "poisson": 0.2, "damping": 0.1,
                               "fracture": {"tensile_strength": 3e6, "cohesion": 6e6,
                                            "friction_angle": 30, "energy_I": 100,
                                            "energy_II": 1000, "aperture0": 1e-5}}},
        "fluid": {"viscosity": 1e-5, "bulk_modulus": 1e8, "density": 0},
        "parts": [{"name": "rock", "material": "rock",
                   "fracture": [{"box": [-half, -h, half, h]},
                                {"box": [joint_x - h, -half, joint_x + h, half]}],
                   "initial_stress": {"value": stress},
                   "gmsh": square_gmsh(half, cells, joint_x),
                   "discontinuities": {"natural joint": {
                       "tensile_strength": 1e4, "cohesion": 1e4,
                       "friction_angle": friction_angle, "energy_I": 1, "energy_II": 1}}}],
        "constraints": [{"part": "rock", "group": side, "fix": ["x", "y"]}
                        for side in ("left", "right", "bottom", "top")] +
                       [{"box": [-1e-6, -1e-6, 1e-6, 1e-6], "inject": 8e-3}],
        "time": {"end": end},
        "output": {"interval": end / 10, "fields": ["position", "damage"]}}


dump("hf-natural-joint", hf_natural_joint(10e6, 30))
# ------------------------------------------------- hydraulic fracture, 3D
# Contract 6.4: the radial (penny-shaped) hydraulic fracture, the 3D
# companion of kgd.json (tests/unit/test_fluid_penny.c measures the same
# set-up with the joints off the plane made strong). A quarter of it by
# symmetry (x, y >= 0: the planes x = 0 and y = 0 held normal to
# themselves, so the quarter takes Q/4), meshed by penny_mesh.py: 0.05 m
# cells out to 0.4 m across and 0.1 m from the plane z = 0, growing by 1.4
# a cell to fixed faces 1.17 m across and 0.87 m above and below (14,196
# tetrahedra). Fracture only in the tetrahedra with a face on z = 0; the
# joints' penalty 2 E and aperture0 3e-5 m make the step 2.1 times the
# default's; f_t = 4 MPa keeps the cohesive zone small against R.
import sys  # noqa: E402
sys.path.insert(0, OUT)
import penny_mesh  # noqa: E402

dump("penny", penny_mesh.quarter_case("penny", 0.05, 8, 5, 2, 5, 1.4, penny_mesh.ROCK,
                                     penny_mesh.FLUID, penny_mesh.Q, 0.005, 0.00025))
