#!/usr/bin/python3
"""tunnel_wall.py - the wall figures of a tunnel.json result, against the
closed form of an unsupported circular opening in hydrostatic elastic rock
(Kirsch): convergence u = P0 a / (2 G) and hoop stress -2 P0 at the wall.

    /usr/bin/python3 examples/tunnel_wall.py out/tunnel.h5 [--radius 1]

Reads the last snapshot: the inward radial displacement of the nodes on the
wall (r = a at t = 0), averaged, and the hoop stress of the elements with
an edge on the wall, averaged (README.md, "Walkthrough")."""
import argparse

import h5py
import numpy as np

p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
p.add_argument("result")
p.add_argument("--radius", type=float, default=1.0, help="tunnel radius a, m (tunnel.geo: 1)")
args = p.parse_args()
with h5py.File(args.result, "r") as f:
    x0, tri = f["/mesh/position0"][:], f["/mesh/triangles"][:]
    u = f["/snapshots/position"][-1] - x0
    s = f["/snapshots/stress"][-1]  # sxx, syy, sxy
r = np.hypot(x0[:, 0], x0[:, 1])
wall = np.abs(r - args.radius) < 1e-6 * args.radius
inward = -(u[wall] * x0[wall]).sum(axis=1) / r[wall]
on_wall = np.isin(tri, np.flatnonzero(wall)).sum(axis=1) == 2
c = x0[tri[on_wall]].mean(axis=1)
t = np.arctan2(c[:, 1], c[:, 0])
hoop = (s[on_wall, 0] * np.sin(t) ** 2 + s[on_wall, 1] * np.cos(t) ** 2
        - 2 * s[on_wall, 2] * np.sin(t) * np.cos(t))
print("wall convergence %.3f mm over %d nodes" % (1e3 * inward.mean(), wall.sum()))
print("hoop stress at the wall %.1f MPa over %d elements" % (1e-6 * hoop.mean(), on_wall.sum()))
