#!/usr/bin/python3
"""plot_result.py - draw one snapshot of an fdemd result.h5 as a PNG.

    /usr/bin/python3 clients/python/plot_result.py result.h5 -o out.png \\
        [--field stress|velocity|displacement|damage] [--snapshot -1] [--component C]

Draws the deformed mesh of the chosen snapshot (positions from
/snapshots/position, else /mesh/position0 + /snapshots/displacement, else
the initial /mesh/position0). A 2D result is drawn
as its triangles, coloured by

  stress    von Mises stress per element, from the Cauchy stress
            (sxx, syy, sxy) of /snapshots/stress. Plane strain: the
            out-of-plane stress is szz = nu * (sxx + syy) (exact for linear
            elasticity; the small-strain limit of the engine's material), so
                svm = sqrt(((sxx - syy)^2 + (syy - szz)^2 + (szz - sxx)^2) / 2
                           + 3 * sxy^2).
            nu is each part's material's "poisson", read from the case
            document the file carries (root attribute `case`,
            docs/results.md). --case CASE.json reads it from that
            document instead, and --poisson NU uses NU for every element.
            A file without the attribute (written before it existed)
            needs one of the two.
  velocity  speed |v| per node from /snapshots/velocity.
  displacement
            |u| per node, u = position - initial position, from
            /snapshots/displacement (output.fields "displacement"); a file
            without it but with /snapshots/position gives the same numbers
            as /snapshots/position - /mesh/position0.
  damage    every joint of /mesh/joints as a segment coloured by its damage
            (0 intact ... 1 broken) over the mesh in grey.

A 3D result (root attribute dimension = 3, /mesh/tetrahedra) is drawn as
the boundary faces of its tetrahedral mesh (faces of exactly one
tetrahedron and of no joint still holding: a broken joint's faces show the
crack) in an equal-aspect perspective view (--view ELEV,AZIM), each
face coloured by its tetrahedron's von Mises stress, exact from the six
components (xx, yy, zz, yz, xz, xy) of /snapshots/stress, or by the mean
speed of its three nodes for --field velocity (the mean |u| for --field
displacement). Only the surface is drawn:
stress inside a body does not show.

--component xx|yy|xy (3D also zz|yz|xz) colours by that Cauchy stress
component instead of von Mises, on a diverging scale centred on zero.

The elements a case with stages has excavated by the snapshot
(/snapshots/active 0) are left out, in 2D and 3D.

The default field is stress when the file has it, else velocity, else
displacement.
The file may still be written by a running case: it is opened plainly first,
then as an HDF5 SWMR reader.
"""

import argparse
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")  # files only; no display needed
import h5py  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import LineCollection  # noqa: E402
from matplotlib.tri import Triangulation  # noqa: E402
from mpl_toolkits.mplot3d.art3d import Poly3DCollection  # noqa: E402

# Stress components as stored: 2D (sxx, syy, sxy); 3D (docs/results.md)
# (sxx, syy, szz, syz, sxz, sxy).
COMPONENTS = {2: ("xx", "yy", "xy"), 3: ("xx", "yy", "zz", "yz", "xz", "xy")}


def open_result(path):
    """Opens result.h5 read-only, as a SWMR reader if a writer holds it."""
    # The .xdmf beside a fetched .h5 is what the docs say to open in
    # ParaView, so it is the file a user hands over by mistake; h5py would
    # only say "file signature not found".
    try:
        with open(path, "rb") as f:
            head = f.read(64).lstrip()
    except OSError:
        head = b""
    if head.startswith(b"<?xml") or head.startswith(b"<Xdmf"):
        h5 = os.path.splitext(path)[0] + ".h5"
        raise OSError("it is the XDMF sidecar for ParaView, not the HDF5 result: "
                      "give its .h5 (%s)" % h5)
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


def von_mises_3d(stress):
    """von Mises stress of (E, 6) [sxx, syy, szz, syz, sxz, sxy]."""
    sxx, syy, szz, syz, sxz, sxy = (stress[:, k] for k in range(6))
    return np.sqrt(0.5 * ((sxx - syy) ** 2 + (syy - szz) ** 2 + (szz - sxx) ** 2)
                   + 3.0 * (syz ** 2 + sxz ** 2 + sxy ** 2))


class MissingMaterial(Exception):
    """The file does not say which Poisson's ratio to use."""


def case_document(f, case_path):
    """The case: the --case file when given, else the one the result
    carries (root attribute `case`); None when neither exists."""
    if case_path:
        with open(case_path) as c:
            return json.load(c)
    text = attr_text(f, "case")
    return json.loads(text) if text else None


def element_poisson(f, case_path=None, poisson=None):
    """Poisson's ratio per element: `poisson` for all when given, else each
    element's part's material in the case document (case_document())."""
    elements = f["/mesh/triangles"].shape[0]
    if poisson is not None:
        return np.full(elements, poisson)
    case = case_document(f, case_path)
    if case is None:
        raise MissingMaterial("the file carries no case document (it predates the `case` "
                              "attribute); give --poisson NU or --case CASE.json")
    try:
        per_part = [case["materials"][p["material"]]["poisson"] for p in case["parts"]]
    except (KeyError, TypeError) as e:
        raise MissingMaterial("the case document names no Poisson's ratio for every part "
                              "(%s); give --poisson NU" % e) from None
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


def scaled_length(values):
    """Lengths in m rescaled to mm, \u00b5m or nm when small, for the colourbar."""
    peak = float(np.nanmax(np.abs(values))) if values.size else 0.0
    for factor, unit in ((1.0, "m"), (1e-3, "mm"), (1e-6, "\u00b5m")):
        if peak >= factor:
            return values / factor, unit
    return (values / 1e-9, "nm") if peak > 0 else (values, "m")


def node_displacement(f, s):
    """(N, dimension) displacement of snapshot s: /snapshots/displacement,
    else /snapshots/position - /mesh/position0 (the same numbers)."""
    if "/snapshots/displacement" in f:
        return f["/snapshots/displacement"][s]
    if "/snapshots/position" in f:
        return f["/snapshots/position"][s] - f["/mesh/position0"][:]
    require(f, "/snapshots/displacement", 'add "displacement" (or "position") to output.fields')


def displacement_magnitude(f, s):
    """|u| per node, rescaled, and the colourbar label."""
    values, unit = scaled_length(np.linalg.norm(node_displacement(f, s), axis=1))
    return values, "displacement |u| [%s]" % unit


def stress_component(f, s, dimension, component):
    """One Cauchy stress component per element, and its colourbar label."""
    names = COMPONENTS[dimension]
    if component not in names:
        sys.exit("plot_result: --component %s does not exist in %dD (use %s)"
                 % (component, dimension, ", ".join(names)))
    stress = require(f, "/snapshots/stress", 'add "stress" to output.fields')[s]
    values, unit = scaled_unit(stress[:, names.index(component)], "Pa")
    return values, "stress s%s [%s]" % (component, unit)


def symmetric_limits(values):
    """Colour limits centred on zero, so tension and compression read apart."""
    peak = float(np.nanmax(np.abs(values))) if values.size else 0.0
    return (-peak, peak) if peak > 0 else (-1.0, 1.0)


def draw_stress(ax, f, tri, s, args):
    if args.component:
        values, label = stress_component(f, s, 2, args.component)
        art = ax.tripcolor(tri, facecolors=values, cmap="coolwarm")
        art.set_clim(*symmetric_limits(values if tri.mask is None else values[~tri.mask]))
        return art, label
    stress = require(f, "/snapshots/stress", 'add "stress" to output.fields')[s]
    vm = von_mises_plane_strain(stress, element_poisson(f, args.case, args.poisson))
    values, unit = scaled_unit(vm, "Pa")
    art = ax.tripcolor(tri, facecolors=values, cmap="viridis")
    return art, "von Mises stress [%s] (plane strain)" % unit


def draw_velocity(ax, f, tri, s, args):
    v = require(f, "/snapshots/velocity", 'add "velocity" to output.fields')[s]
    art = ax.tripcolor(tri, np.hypot(v[:, 0], v[:, 1]), shading="gouraud", cmap="plasma")
    return art, "speed |v| [m/s]"


def draw_displacement(ax, f, tri, s, args):
    values, label = displacement_magnitude(f, s)
    art = ax.tripcolor(tri, values, shading="gouraud", cmap="cividis")
    return art, label


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


DRAW = {"stress": draw_stress, "velocity": draw_velocity, "displacement": draw_displacement,
        "damage": draw_damage}


def snapshot_positions(f, s):
    """Node positions of snapshot s, and which positions they are."""
    if "/snapshots/position" in f:
        return f["/snapshots/position"][s], "deformed"
    if "/snapshots/displacement" in f:
        return f["/mesh/position0"][:] + f["/snapshots/displacement"][s], "deformed"
    return f["/mesh/position0"][:], "initial positions"


def title(f, args, s, count, where):
    name = attr_text(f, "name", args.result)
    t = float(f["/snapshots/time"][s])
    return "%s   t = %.4g s   (snapshot %d of %d, %s)" % (name, t, s + 1, count, where)


def active_elements(f, s):
    """Which elements are still there in snapshot s: /snapshots/active of a
    case with stages (0 once excavated), None when every element is."""
    if "/snapshots/active" not in f:
        return None
    return f["/snapshots/active"][s] != 0


def snapshot_triangulation(f, s):
    """The triangles of snapshot s at its positions, the excavated ones
    masked out (drawn neither filled nor as edges)."""
    xy, where = snapshot_positions(f, s)
    tri = Triangulation(xy[:, 0], xy[:, 1], f["/mesh/triangles"][:])
    active = active_elements(f, s)
    if active is not None:
        tri.set_mask(~active)
    return tri, xy, where


def plot_2d(f, args, field):
    s, count = snapshot_index(f, args.snapshot)
    triangles = f["/mesh/triangles"][:]
    tri, xy, where = snapshot_triangulation(f, s)

    width = np.ptp(xy[:, 0]) or 1.0
    height = np.ptp(xy[:, 1]) or 1.0
    wide = width > 2.0 * height    # e.g. a bar: colourbar below, not beside
    fig, ax = plt.subplots(figsize=(10, 5) if wide else (8, 6.5), dpi=args.dpi)
    art, label = DRAW[field](ax, f, tri, s, args)
    if field != "damage" and triangles.shape[0] <= 20000:
        ax.triplot(tri, color="k", linewidth=0.1, alpha=0.4)
    fig.colorbar(art, ax=ax, label=label, fraction=0.046, pad=0.18 if wide else 0.04,
                 orientation="horizontal" if wide else "vertical")
    ax.set_title(title(f, args, s, count, where))
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.autoscale_view()
    return fig


# ------------------------------------------------------------------ 3D

# The faces of a positive-volume tetrahedron (a, b, c, d), each listed so its
# normal by the right-hand rule points out of the element: a face that ends
# up on the boundary then faces the viewer the right way for shading.
TET_FACES = np.array([[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]])


def _face_keys(faces):
    """One comparable key per face, whatever the order of its three nodes."""
    rows = np.ascontiguousarray(np.sort(faces, axis=1).astype(np.int64))
    return rows.view(np.dtype((np.void, rows.dtype.itemsize * 3))).ravel()


def boundary_faces(tetrahedra, held_joints=None):
    """The faces used by exactly one tetrahedron and held by no joint.

    Returns (faces (F, 3) node indices, outward, and element (F,) the
    tetrahedron each belongs to). A face shared by two tetrahedra is inside
    the body; one of a single tetrahedron is on its surface (or on a crack
    or contact surface between parts, which have their own nodes). In a
    fracturing part every tetrahedron has its own nodes, so its inner faces
    are told apart by held_joints, the (K, 6) rows of /mesh/joints still
    holding: both faces of each are inside the body; a broken joint's two
    faces are crack surfaces and are drawn.
    """
    tetrahedra = np.asarray(tetrahedra, dtype=np.int64)
    faces = tetrahedra[:, TET_FACES].reshape(-1, 3)
    element = np.repeat(np.arange(tetrahedra.shape[0]), 4)
    _, first, uses = np.unique(np.sort(faces, axis=1), axis=0,
                               return_index=True, return_counts=True)
    once = np.sort(first[uses == 1])
    if held_joints is not None and len(held_joints):
        held = np.asarray(held_joints).reshape(-1, 3)
        once = once[~np.isin(_face_keys(faces[once]), _face_keys(held))]
    return faces[once], element[once]


def surface_of_snapshot(f, s):
    """The boundary faces of snapshot s: joints with damage below 1 hold;
    of a case with stages, the surface of the elements not excavated (an
    excavation's walls show)."""
    held = None
    if "/mesh/joints" in f and "/snapshots/damage" in f:
        held = f["/mesh/joints"][:][f["/snapshots/damage"][s] < 1.0]
    tetrahedra = f["/mesh/tetrahedra"][:]
    active = active_elements(f, s)
    if active is None:
        return boundary_faces(tetrahedra, held)
    kept = np.flatnonzero(active)
    faces, element = boundary_faces(tetrahedra[kept], held)
    return faces, kept[element]


def face_stress(f, s, element, args):
    """Per boundary face: its tetrahedron's stress value, label, colour map."""
    if args.component:
        values, label = stress_component(f, s, 3, args.component)
        return values[element], label, "coolwarm"
    stress = require(f, "/snapshots/stress", 'add "stress" to output.fields')[s]
    values, unit = scaled_unit(von_mises_3d(stress), "Pa")
    return values[element], "von Mises stress [%s]" % unit, "viridis"


def face_speed(f, s, faces):
    """Per boundary face: the mean speed of its three nodes."""
    v = require(f, "/snapshots/velocity", 'add "velocity" to output.fields')[s]
    speed = np.linalg.norm(v, axis=1)
    return speed[faces].mean(axis=1), "speed |v| [m/s] (face mean of its nodes)", "plasma"


def face_displacement(f, s, faces):
    """Per boundary face: the mean |u| of its three nodes."""
    values, label = displacement_magnitude(f, s)
    return values[faces].mean(axis=1), label + " (face mean of its nodes)", "cividis"


def equal_aspect_3d(ax, xyz):
    """One metre is as long along x, y and z: a cube around the points."""
    low, high = xyz.min(axis=0), xyz.max(axis=0)
    centre, half = (low + high) / 2.0, max(float(np.max(high - low)) / 2.0, 1e-12)
    ax.set_xlim(centre[0] - half, centre[0] + half)
    ax.set_ylim(centre[1] - half, centre[1] + half)
    ax.set_zlim(centre[2] - half, centre[2] + half)
    ax.set_box_aspect((1, 1, 1))


def view_angles(text):
    try:
        elevation, azimuth = (float(x) for x in text.split(","))
    except ValueError:
        sys.exit("plot_result: --view takes ELEVATION,AZIMUTH in degrees, not %r" % text)
    return elevation, azimuth


def plot_3d(f, args, field):
    if field == "damage":
        sys.exit("plot_result: --field damage is drawn for 2D results only; in 3D open the "
                 ".xdmf in ParaView (its joints block is coloured by damage) or list the "
                 "broken joints with fdemctl events ID")
    s, count = snapshot_index(f, args.snapshot)
    xyz, where = snapshot_positions(f, s)
    faces, element = surface_of_snapshot(f, s)
    if field == "stress":
        values, label, cmap = face_stress(f, s, element, args)
    elif field == "displacement":
        values, label, cmap = face_displacement(f, s, faces)
    else:
        values, label, cmap = face_speed(f, s, faces)

    fig = plt.figure(figsize=(8, 7), dpi=args.dpi)
    ax = fig.add_subplot(projection="3d")
    surface = Poly3DCollection(xyz[faces], cmap=cmap,
                               edgecolors=(0, 0, 0, 0.25) if faces.shape[0] <= 20000 else "none",
                               linewidths=0.2)
    surface.set_array(np.asarray(values, dtype=float))
    if args.component:
        surface.set_clim(*symmetric_limits(values))
    ax.add_collection3d(surface)
    equal_aspect_3d(ax, xyz)
    ax.view_init(*view_angles(args.view))
    fig.colorbar(surface, ax=ax, label=label, shrink=0.7, pad=0.1)
    ax.set_title(title(f, args, s, count, where), fontsize=10)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_zlabel("z [m]")
    return fig


def result_dimension(f):
    """3 for a tetrahedral result (docs/results.md, "Three dimensions"), else 2."""
    return int(f.attrs.get("dimension", 3 if "/mesh/tetrahedra" in f else 2))


def default_field(f):
    """stress when the file has it, else velocity, else displacement."""
    for field in ("stress", "velocity", "displacement"):
        if "/snapshots/" + field in f:
            return field
    return "velocity"  # which then says what to add to output.fields


def plot(args):
    with open_result(args.result) as f:
        field = args.field or default_field(f)
        draw = plot_3d if result_dimension(f) == 3 else plot_2d
        fig = draw(f, args, field)
        fig.tight_layout()
        fig.savefig(args.output)
        plt.close(fig)


def main(argv=None):
    p = argparse.ArgumentParser(description="Draw one snapshot of an fdemd result.h5 as a PNG.")
    p.add_argument("result", help="result.h5 (as fetched by fdemctl fetch)")
    p.add_argument("-o", "--output", required=True, help="PNG file to write")
    p.add_argument("--field", choices=sorted(DRAW), help="colouring (default stress if present)")
    p.add_argument("--snapshot", type=int, default=-1, help="index, negative from the end (-1)")
    p.add_argument("--poisson", type=float,
                   help="Poisson's ratio for the plane-strain szz of every element "
                        "(default: each part's material, from the case in the file)")
    p.add_argument("--case", help="case JSON: take each part's Poisson's ratio from it "
                                  "instead of from the case the file carries")
    p.add_argument("--component", choices=COMPONENTS[3],
                   help="colour by this stress component instead of von Mises "
                        "(2D: xx, yy, xy)")
    p.add_argument("--view", default="25,-60",
                   help="3D only: ELEVATION,AZIMUTH of the view in degrees (25,-60)")
    p.add_argument("--dpi", type=int, default=120)
    args = p.parse_args(argv)
    try:
        plot(args)
    except (OSError, KeyError) as e:
        sys.exit("plot_result: cannot read %s: %s" % (args.result, e))
    except MissingMaterial as e:
        sys.exit("plot_result: %s: %s" % (args.result, e))
    print(args.output)


if __name__ == "__main__":
    main()
