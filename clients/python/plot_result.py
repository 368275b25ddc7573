#!/usr/bin/python3
"""plot_result.py - draw one snapshot of an fdemd result.h5 as a PNG.

    /usr/bin/python3 clients/python/plot_result.py result.h5 -o out.png \\
        [--field stress|velocity|damage] [--snapshot -1]

Draws the deformed mesh of the chosen snapshot (positions from
/snapshots/position, else the initial /mesh/position0) coloured by

  stress    von Mises stress per element, from the Cauchy stress
            (sxx, syy, sxy) of /snapshots/stress. Plane strain: the
            out-of-plane stress is szz = nu * (sxx + syy) (exact for linear
            elasticity; the small-strain limit of the engine's material), so
                svm = sqrt(((sxx - syy)^2 + (syy - szz)^2 + (szz - sxx)^2) / 2
                           + 3 * sxy^2).
            nu comes from --poisson (default 0.25) or, per part, from the
            materials of the case document given with --case.
  velocity  speed |v| per node from /snapshots/velocity.
  damage    every joint of /mesh/joints as a segment coloured by its damage
            (0 intact ... 1 broken) over the mesh in grey.

The default field is stress when the file has it, else velocity.
The file may still be written by a running case: it is opened plainly first,
then as an HDF5 SWMR reader.
"""

import argparse
import json
import sys

import matplotlib

matplotlib.use("Agg")  # files only; no display needed
import h5py  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import LineCollection  # noqa: E402
from matplotlib.tri import Triangulation  # noqa: E402


def open_result(path):
    """Opens result.h5 read-only, as a SWMR reader if a writer holds it."""
    try:
        return h5py.File(path, "r")
    except OSError as plain_error:
        try:
            return h5py.File(path, "r", libver="latest", swmr=True)
        except OSError:
            raise plain_error from None


def attr_text(f, key, default=""):
    value = f.attrs.get(key, default)
    return value.decode() if isinstance(value, bytes) else str(value)


def von_mises_plane_strain(stress, nu):
    """von Mises stress of (E, 3) [sxx, syy, sxy] with szz = nu (sxx + syy)."""
    sxx, syy, sxy = stress[:, 0], stress[:, 1], stress[:, 2]
    szz = nu * (sxx + syy)
    return np.sqrt(0.5 * ((sxx - syy) ** 2 + (syy - szz) ** 2 + (szz - sxx) ** 2) + 3.0 * sxy ** 2)


def element_poisson(f, case_path, default_nu):
    """Poisson's ratio per element: from the case's materials, else default."""
    elements = f["/mesh/triangles"].shape[0]
    if not case_path:
        return np.full(elements, default_nu)
    with open(case_path) as c:
        case = json.load(c)
    per_part = [case["materials"][p["material"]].get("poisson", default_nu) for p in case["parts"]]
    return np.asarray(per_part, dtype=float)[f["/mesh/element_part"][:]]


def snapshot_index(f, requested):
    count = f["/snapshots/time"].shape[0]
    if count == 0:
        sys.exit("plot_result: the file holds no snapshot yet")
    index = requested + count if requested < 0 else requested
    if not 0 <= index < count:
        sys.exit("plot_result: snapshot %d out of range (the file holds %d)" % (requested, count))
    return index, count


def require(f, dataset, hint):
    if dataset not in f:
        sys.exit("plot_result: %s is not in this file (%s)" % (dataset, hint))
    return f[dataset]


def scaled_unit(values, unit):
    """Values rescaled to a readable SI prefix for the colourbar."""
    peak = float(np.nanmax(np.abs(values))) if values.size else 0.0
    for factor, prefix in ((1e9, "G"), (1e6, "M"), (1e3, "k")):
        if peak >= factor:
            return values / factor, prefix + unit
    return values, unit


def draw_stress(ax, f, tri, s, args):
    stress = require(f, "/snapshots/stress", 'add "stress" to output.fields')[s]
    vm = von_mises_plane_strain(stress, element_poisson(f, args.case, args.poisson))
    values, unit = scaled_unit(vm, "Pa")
    art = ax.tripcolor(tri, facecolors=values, cmap="viridis")
    return art, "von Mises stress [%s] (plane strain)" % unit


def draw_velocity(ax, f, tri, s, args):
    v = require(f, "/snapshots/velocity", 'add "velocity" to output.fields')[s]
    art = ax.tripcolor(tri, np.hypot(v[:, 0], v[:, 1]), shading="gouraud", cmap="plasma")
    return art, "speed |v| [m/s]"


def draw_damage(ax, f, tri, s, args):
    joints = require(f, "/mesh/joints", "no part of this case fractures")[:]
    damage = require(f, "/snapshots/damage", "no part of this case fractures")[s]
    ax.triplot(tri, color="0.75", linewidth=0.3)
    xy = np.stack([tri.x, tri.y], axis=1)
    segments = np.stack([xy[joints[:, 0]], xy[joints[:, 1]]], axis=1)
    lines = LineCollection(segments, cmap="inferno_r", linewidths=1.2)
    lines.set_array(np.asarray(damage, dtype=float))
    lines.set_clim(0.0, 1.0)
    ax.add_collection(lines)
    return lines, "joint damage [-] (0 intact, 1 broken)"


DRAW = {"stress": draw_stress, "velocity": draw_velocity, "damage": draw_damage}


def plot(args):
    with open_result(args.result) as f:
        s, count = snapshot_index(f, args.snapshot)
        triangles = f["/mesh/triangles"][:]
        if "/snapshots/position" in f:
            xy, where = f["/snapshots/position"][s], "deformed"
        else:
            xy, where = f["/mesh/position0"][:], "initial positions"
        tri = Triangulation(xy[:, 0], xy[:, 1], triangles)
        field = args.field or ("stress" if "/snapshots/stress" in f else "velocity")

        width = np.ptp(xy[:, 0]) or 1.0
        height = np.ptp(xy[:, 1]) or 1.0
        wide = width > 2.0 * height    # e.g. a bar: colourbar below, not beside
        fig, ax = plt.subplots(figsize=(10, 5) if wide else (8, 6.5), dpi=args.dpi)
        art, label = DRAW[field](ax, f, tri, s, args)
        if field != "damage" and triangles.shape[0] <= 20000:
            ax.triplot(tri, color="k", linewidth=0.1, alpha=0.4)
        fig.colorbar(art, ax=ax, label=label, fraction=0.046, pad=0.18 if wide else 0.04,
                     orientation="horizontal" if wide else "vertical")
        name = attr_text(f, "name", args.result)
        t = float(f["/snapshots/time"][s])
        ax.set_title("%s   t = %.4g s   (snapshot %d of %d, %s)" % (name, t, s + 1, count, where))
        ax.set_aspect("equal")
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        ax.autoscale_view()
        fig.tight_layout()
        fig.savefig(args.output)
        plt.close(fig)


def main(argv=None):
    p = argparse.ArgumentParser(description="Draw one snapshot of an fdemd result.h5 as a PNG.")
    p.add_argument("result", help="result.h5 (as fetched by fdemctl fetch)")
    p.add_argument("-o", "--output", required=True, help="PNG file to write")
    p.add_argument("--field", choices=sorted(DRAW), help="colouring (default stress if present)")
    p.add_argument("--snapshot", type=int, default=-1, help="index, negative from the end (-1)")
    p.add_argument("--poisson", type=float, default=0.25,
                   help="Poisson's ratio for the plane-strain szz (default 0.25)")
    p.add_argument("--case", help="case JSON: take each part's Poisson's ratio from it")
    p.add_argument("--dpi", type=int, default=120)
    args = p.parse_args(argv)
    try:
        plot(args)
    except (OSError, KeyError) as e:
        sys.exit("plot_result: cannot read %s: %s" % (args.result, e))
    print(args.output)


if __name__ == "__main__":
    main()
