#!/usr/bin/python3
"""borehole_3d.py - the borehole breakdown of borehole-breakdown.json in 3D:
the same bore, disc, stresses, joints and loads on a slab of tetrahedra one
layer thick (plane strain: both faces on rollers, szz = nu (sxx + syy)),
written as a case document. Not a bundled example or a test: it takes
minutes of CPU (5,472 tetrahedra, 7,444 joints).

    /usr/bin/python3 examples/borehole_3d.py out/borehole-3d.json [--sectors 48]
    bin/fdemctl submit out/borehole-3d.json --start

The bore is fed as in the 2D example ("inject" with "bore": true, Q times
the slab's thickness); its wall is open at the slab's faces, between
rollers, and its volume is measured normal to them (core/fluid/fluid_bore.c).
Measured 2026-12-06 (48 sectors, slab 0.013 m, through bin/fdem-run): the
bore's pressure peaks at 17.96 MPa at 0.76 ms against 3 sh - sH + T =
20 MPa (-10.2 %) and falls to 12.5 MPa by 1.18 ms as the cracks along x
take the fluid (the flow's subcycles, up to 1,900 a step, make the run
dear after the breakdown). With a pressure ramp on the wall instead, the
first wall joint softened by 18.0 MPa (-10 %) and broke by 21.2 MPa
(+6 %); a gmsh mesh of the same slab (unstructured, 3,060 tetrahedra, no
face along theta = 0) gave 22.8 / 26.4 MPa (+14 / +32 %): the crack must
find faces normal to sigma_h at the wall.
"""
import argparse
import json
import math

def polar_gmsh_3d(a, R, sectors, thickness):
    """msh 2.2 of the ring a < r < R extruded by `thickness` in z, one layer of
    prisms each split in three tetrahedra (diagonals by the lower node index, so
    neighbours agree): volume group "rock", surface groups "bore", "outer",
    "back" (z = 0) and "front" (z = thickness)."""
    growth = 1 + 2 * math.pi / sectors
    rings = max(1, round(math.log(R / a) / math.log(growth)))
    radii = [a * (R / a) ** (i / rings) for i in range(rings + 1)]
    per_layer = (rings + 1) * sectors
    nodes = []
    for z in (0.0, thickness):
        for r in radii:
            for j in range(sectors):
                t = 2 * math.pi * j / sectors
                nodes.append((r * math.cos(t), r * math.sin(t), z))
    def node(i, j, top=0):
        return top * per_layer + i * sectors + j % sectors + 1
    tris = []
    for i in range(rings):
        for j in range(sectors):
            a0, a1, b0, b1 = node(i, j), node(i, j + 1), node(i + 1, j), node(i + 1, j + 1)
            if (i + j) % 2 == 0:
                tris += [(a0, a1, b1), (a0, b1, b0)]
            else:
                tris += [(a0, a1, b0), (a1, b1, b0)]
    tets = []
    for t in tris:
        pa, pb, pc = sorted(t)
        qa, qb, qc = pa + per_layer, pb + per_layer, pc + per_layer
        tets += [(pa, pb, pc, qc), (pa, pb, qb, qc), (pa, qa, qb, qc)]
    def quad_faces(i):  # the vertical faces of ring line i, split as the tets do
        out = []
        for j in range(sectors):
            p, q = sorted((node(i, j), node(i, j + 1)))
            out += [(p, q, q + per_layer), (p, p + per_layer, q + per_layer)]
        return out
    groups = [("bore", 2, quad_faces(0)), ("outer", 2, quad_faces(rings)),
              ("back", 2, tris), ("front", 2, [tuple(n + per_layer for n in t) for t in tris])]
    out = ["$MeshFormat", "2.2 0 8", "$EndMeshFormat", "$PhysicalNames", str(len(groups) + 1)]
    out += ['2 %d "%s"' % (k + 1, g[0]) for k, g in enumerate(groups)]
    out += ['3 %d "rock"' % (len(groups) + 1), "$EndPhysicalNames", "$Nodes", str(len(nodes))]
    out += ["%d %.15g %.15g %.15g" % (k + 1, *p) for k, p in enumerate(nodes)]
    count = sum(len(g[2]) for g in groups) + len(tets)
    out += ["$EndNodes", "$Elements", str(count)]
    k = 0
    for tag, (name, dim, faces) in enumerate(groups, 1):
        for f in faces:
            k += 1
            out.append("%d 2 2 %d %d %d %d %d" % (k, tag, tag, *f))
    for t in tets:
        k += 1
        out.append("%d 4 2 %d %d %d %d %d %d" % (k, len(groups) + 1, len(groups) + 1, *t))
    out += ["$EndElements", ""]
    return "\n".join(out), len(tets)


def case(sectors, thickness):
    s = [-15e6, -10e6, -6.25e6, 0, 0, 0]  # sxx, syy, szz = nu (sxx + syy), syz, sxz, sxy
    msh, _ = polar_gmsh_3d(0.1, 1.0, sectors, thickness)
    return {
        "name": "borehole-breakdown-3d", "dimension": 3,
        "materials": {"rock": {"density": 2600, "young": 2e10, "poisson": 0.25, "damping": 0.2,
                               "fracture": {"tensile_strength": 5e6, "cohesion": 3e7,
                                            "friction_angle": 30, "energy_I": 20,
                                            "energy_II": 200, "aperture0": 1e-4}}},
        "fluid": {"viscosity": 1e-4, "bulk_modulus": 2e9, "density": 0},
        "parts": [{"name": "rock", "material": "rock",
                   "fracture": {"box": [-0.6, -0.6, -1, 0.6, 0.6, 1]},
                   "initial_stress": {"value": s}, "gmsh": msh}],
        "constraints": [
            # the 2D example's 0.4 m^2/s per m of thickness
            {"part": "rock", "group": "bore", "inject": round(0.4 * thickness, 6), "bore": True},
            {"part": "rock", "group": "bore", "boundary_stress": {"value": s},
             "amplitude": [[0, 1], [0.0003, 0]]},
            {"part": "rock", "group": "outer", "boundary_stress": {"value": s}},
            {"part": "rock", "group": "outer", "absorb": True},
            {"part": "rock", "group": "front", "fix": ["z"]},
            {"part": "rock", "group": "back", "fix": ["z"]}],
        "time": {"end": 0.0015, "dt": "auto", "safety": 0.5},
        "output": {"interval": 2e-5, "fields": ["position", "damage"]}}


if __name__ == "__main__":
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("out")
    p.add_argument("--sectors", type=int, default=48)
    args = p.parse_args()
    thickness = 2 * math.pi * 0.1 / args.sectors  # about the wall's element size
    with open(args.out, "w") as f:
        json.dump(case(args.sectors, round(thickness, 3)), f)
