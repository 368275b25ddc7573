#!/usr/bin/python3
"""penny_mesh.py - the tetrahedral mesh of a quarter of a penny-shaped
hydraulic fracture (x, y >= 0, the crack on z = 0), shared by
examples/generate.py (examples/penny.json) and scripts/limits.py (the penny
at several mesh sizes): a box of cells h wide out to `fine` cells from the
centre along x and y and `fine_z` cells from the plane along z, then cells
growing by `ratio` one after the other out to the far faces, so the crack
is meshed finely where it runs and the fixed boundary stays far away at a
few thousand cells. Each cell is split into the six Kuhn tetrahedra of its
diagonal from (x1, y0, z0) to (x0, y1, z1), the same in every cell, so
neighbours share their face diagonals; a cell of the graded part is a box,
not a cube, so its tetrahedra are stretched along an axis but never flat.
That diagonal keeps the faces on z = 0 of the centre's cell off the
centre's diagonal: the injection feeds every joint touching the centre's
nodes, and the fracture region (the tetrahedra with a face on z = 0) then
has only one there, on the crack plane (tests/unit/test_fluid_penny.c
says why a joint off the plane must not be fed).

tests/unit/test_fluid_penny.c builds the same kind of mesh in C (the
built-in box mesh with its grid lines moved).
"""

# examples/penny.json's rock, fluid and injection (m^3/s into the whole
# crack): the KGD's rock (kgd.json) with the joints' penalty 2 E and
# aperture0 3e-5 m, which lengthen the step 2.1 times, and a tensile
# strength of 4 MPa (kgd.json's 3), so that the cohesive length
# E' G_I / f_t^2 is 1.3 cells and small against the radius, as LEFM's
# closed form assumes (tests/unit/test_fluid_penny.c)
ROCK = {"density": 2500, "young": 1e10, "poisson": 0.2, "damping": 0.1, "penalty": 2e10,
        "fracture": {"tensile_strength": 4e6, "cohesion": 8e6, "friction_angle": 30,
                     "energy_I": 100, "energy_II": 1000, "aperture0": 3e-5}}
FLUID = {"viscosity": 1e-5, "bulk_modulus": 1e8, "density": 0}
Q = 4.5e-3


def grid_lines(h, fine, graded, ratio):
    """0, h, 2h, ... fine h, then cells ratio, ratio^2, ... times h."""
    lines, size = [0.0], h
    for i in range(1, fine + graded + 1):
        if i > fine:
            size *= ratio
        lines.append(lines[-1] + size)
    return [round(x, 6) for x in lines]


def quarter_mesh(h, fine, graded, fine_z, graded_z, ratio):
    """(nodes, tetrahedra, extent): nodes [x, y, z], 0-based tetrahedra,
    extent [X, Y, Z] of the box [0, X] x [0, Y] x [-Z, Z]."""
    across = grid_lines(h, fine, graded, ratio)
    depth = grid_lines(h, fine_z, graded_z, ratio)
    zs = [-z for z in reversed(depth[1:])] + depth
    n = len(across)
    index, nodes, tets = {}, [], []

    def node(i, j, k):
        key = (i, j, k)
        if key not in index:
            index[key] = len(nodes)
            nodes.append([across[i], across[j], zs[k]])
        return index[key]

    for i in range(n - 1):
        for j in range(n - 1):
            for k in range(len(zs) - 1):
                for order in ((0, 1, 2), (0, 2, 1), (1, 0, 2), (1, 2, 0), (2, 0, 1), (2, 1, 0)):
                    corner = [i + 1, j, k]
                    path = [node(*corner)]
                    for axis in order:
                        corner[axis] += -1 if axis == 0 else 1
                        path.append(node(*corner))
                    tets.append(path)
    return nodes, tets, [across[-1], across[-1], depth[-1]]


def quarter_case(name, h, fine, graded, fine_z, graded_z, ratio, rock, fluid, Q, end, interval,
                 fields=("position", "damage")):
    """A case document of the quarter penny: the rock fracturing only in the
    tetrahedra with a face on z = 0 (their centroids lie h/4 off it, the
    rest of the layer's h/2 and 3h/4), the planes x = 0 and y = 0
    held normal to themselves (symmetry), the far faces fixed, Q / 4
    injected at the centre."""
    nodes, tets, (X, Y, Z) = quarter_mesh(h, fine, graded, fine_z, graded_z, ratio)
    e = 1e-6

    def box(*v):
        return [round(x, 7) for x in v]
    return {
        "name": name, "dimension": 3,
        "materials": {"rock": rock},
        "fluid": fluid,
        "parts": [{"name": "rock", "material": "rock",
                   "mesh": {"nodes": nodes, "tetrahedra": tets},
                   "fracture": {"box": box(-e, -e, -0.3 * h, X + e, Y + e, 0.3 * h)}}],
        "constraints": [
            {"box": box(-e, -e, -Z - e, e, Y + e, Z + e), "fix": ["x"]},
            {"box": box(-e, -e, -Z - e, X + e, e, Z + e), "fix": ["y"]},
            {"box": box(X - e, -e, -Z - e, X + e, Y + e, Z + e), "fix": ["x", "y", "z"]},
            {"box": box(-e, Y - e, -Z - e, X + e, Y + e, Z + e), "fix": ["x", "y", "z"]},
            {"box": box(-e, -e, -Z - e, X + e, Y + e, -Z + e), "fix": ["x", "y", "z"]},
            {"box": box(-e, -e, Z - e, X + e, Y + e, Z + e), "fix": ["x", "y", "z"]},
            {"box": box(-e, -e, -e, e, e, e), "inject": Q / 4}],
        "time": {"end": end},
        "output": {"interval": interval, "fields": list(fields)}}
