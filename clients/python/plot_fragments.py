#!/usr/bin/python3
"""plot_fragments.py - the sieve curve of a run's fragments and its crack
history (fracture events) as two PNGs.

    /usr/bin/python3 clients/python/plot_fragments.py result.h5 [-o PREFIX] \\
        [--snapshot -1] [--parts A,B] [--print]
    /usr/bin/python3 clients/python/plot_fragments.py --server URL --case ID \\
        [-o PREFIX] [--token T] [--parts A,B] [--exclude-host] [--print]

writes PREFIX-sieve.png and PREFIX-events.png (PREFIX defaults to the
result file's name without .h5, or to the case id).

  sieve   the mass fraction of fragments no larger than each equivalent
          diameter (the diameter of the circle, in 3D the sphere, of the
          fragment's area or volume), on a logarithmic diameter axis. From a
          result file: the fragment of every element in /snapshots/fragment
          at the chosen snapshot, each fragment's size the sum of its
          elements' initial areas (volumes) from /mesh/position0, its mass
          the lumped masses of its nodes (/mesh/node_mass), as GET
          /cases/ID/fragments computes them. From a server: that route.
  events  the fracture events (/events/time and /events/energy, or GET
          /cases/ID/events): cumulative count and cumulative dissipated
          energy against time, one step per event, as acoustic-emission
          catalogues are read.

--parts keeps the fragments of the named parts (/mesh/part_names, or the
case's part names on the server); --exclude-host (server only: which nodes
a constraint holds is not in the file) leaves out the host body as GET
/cases/ID/fragments?exclude_host=true does: the fragments a fix or velocity
constraint holds, and one holding more than half the model's mass.

--print writes the numbers drawn, as JSON, to stdout: {"dimension",
"fragments", "distribution": [{"diameter", "passing"}, ...], "events":
{"time": [...], "count": [...], "energy": [...]}}.
"""

import argparse
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")  # files only; no display needed
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from plot_result import open_result  # noqa: E402  (plain, else as a SWMR reader)


def element_sizes(x0, elements):
    """Initial area (triangles) or volume (tetrahedra) of every element."""
    p = x0[elements]
    if elements.shape[1] == 3:
        a, b = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
        return 0.5 * np.abs(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0])
    a, b, c = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0], p[:, 3] - p[:, 0]
    return np.abs(np.einsum("ij,ij->i", a, np.cross(b, c))) / 6.0


def equivalent_diameter(size, dimension):
    return np.cbrt(6.0 * size / np.pi) if dimension == 3 else np.sqrt(4.0 * size / np.pi)


def sieve_curve(diameter, mass):
    """[(d, passing)] for each distinct diameter, increasing: the mass
    fraction of fragments no larger than d. Equal pieces whose areas were
    summed in another order than the engine's differ by an ulp or so: they
    count as one diameter, as they do in GET /cases/ID/fragments."""
    order = np.argsort(diameter, kind="stable")
    d, m = diameter[order], mass[order]
    below = np.cumsum(m) / m.sum()
    last = np.append(d[1:] > d[:-1] * (1 + 1e-12), True)  # the last of each run of equal ones
    return [{"diameter": float(x), "passing": float(p)} for x, p in zip(d[last], below[last])]


def wanted_parts(f, parts):
    """The indices in /mesh/part_names of the names in `parts` ("a,b")."""
    names = [n.decode() if isinstance(n, bytes) else str(n) for n in f["/mesh/part_names"][...]]
    wanted = [p for p in parts.split(",")]
    unknown = [p for p in wanted if p not in names]
    if unknown or not wanted:
        raise SystemExit("--parts: no part named %s; the parts are %s"
                         % (", ".join(repr(p) for p in unknown), ", ".join(map(repr, names))))
    return [names.index(p) for p in wanted]


def fragments_from_file(f, snapshot, parts=None):
    """(dimension, fragment count, sieve curve) at one snapshot of a result,
    of the fragments of `parts` ("a,b", None: all)."""
    dimension = int(f.attrs.get("dimension", 2))
    elements = f["/mesh/tetrahedra" if dimension == 3 else "/mesh/triangles"][...]
    x0 = f["/mesh/position0"][...]
    node_mass = f["/mesh/node_mass"][...]
    if "fragment" not in f["/snapshots"]:
        raise SystemExit("this result has no /snapshots/fragment (written before fragments "
                         "were recorded)")
    rows = f["/snapshots/time"].shape[0]
    if rows == 0:
        raise SystemExit("this result has no snapshot yet")
    if not -rows <= snapshot < rows:
        raise SystemExit("snapshot %d out of range: the result has %d" % (snapshot, rows))
    label = f["/snapshots/fragment"][snapshot % rows]
    if (label < 0).any():
        raise SystemExit("snapshot %d has no fragments recorded" % snapshot)
    count = int(label.max()) + 1
    size = np.bincount(label, weights=element_sizes(x0, elements), minlength=count)
    node_piece = np.empty(len(node_mass), dtype=np.int64)
    node_piece[elements.ravel()] = np.repeat(label, elements.shape[1])
    mass = np.bincount(node_piece, weights=node_mass, minlength=count)
    keep = np.ones(count, dtype=bool)
    if parts is not None:
        part = np.zeros(count, dtype=np.int64)
        part[label] = f["/mesh/element_part"][...]  # a fragment lies in one part
        keep = np.isin(part, wanted_parts(f, parts))
    if not keep.any():
        return dimension, 0, []
    return (dimension, int(keep.sum()),
            sieve_curve(equivalent_diameter(size[keep], dimension), mass[keep]))


def events_from_file(f):
    if "events" not in f:  # a result written before events were recorded
        return np.zeros(0), np.zeros(0)
    n = f["/events/time"].shape[0]  # the commit marker: rows every dataset holds
    return f["/events/time"][:n], f["/events/energy"][:n]


def from_server(args):
    from fdemd_client import Client
    client = Client(args.server, token=args.token)
    pieces = client.fragments(args.case, parts=args.parts, exclude_host=args.exclude_host)
    events = client.events(args.case)["events"]
    dimension = len(pieces["fragments"][0]["centroid"]) if pieces["fragments"] else 2
    return (dimension, len(pieces["fragments"]), pieces["distribution"],
            np.array([e["time"] for e in events]), np.array([e["energy"] for e in events]))


def draw_sieve(path, curve, count, dimension, title):
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    d = [p["diameter"] for p in curve]
    passing = [100 * p["passing"] for p in curve]
    ax.step(d, passing, where="post", color="tab:blue")
    ax.plot(d, passing, "o", color="tab:blue", ms=4)
    if len(d) > 1 and min(d) > 0:
        ax.set_xscale("log")
    ax.set_ylim(0, 105)
    ax.set_xlabel("equivalent %s diameter (m)" % ("sphere" if dimension == 3 else "circle"))
    ax.set_ylabel("mass passing (%)")
    ax.set_title("%s: %d fragment%s" % (title, count, "" if count == 1 else "s"))
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def draw_events(path, time, energy, dimension, title):
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    count = np.arange(1, len(time) + 1)
    cumulative = np.cumsum(energy)
    if len(time):
        ax.step(np.concatenate(([0.0], time)), np.concatenate(([0], count)), where="post",
                color="tab:blue")
    ax.set_xlabel("time (s)")
    ax.set_ylabel("broken joints (cumulative)", color="tab:blue")
    energy_axis = ax.twinx()
    if len(time):
        energy_axis.step(np.concatenate(([0.0], time)), np.concatenate(([0.0], cumulative)),
                         where="post", color="tab:red")
    unit = "J" if dimension == 3 else "J/m"
    energy_axis.set_ylabel("dissipated energy, cumulative (%s)" % unit, color="tab:red")
    ax.set_title("%s: %d fracture event%s" % (title, len(time), "" if len(time) == 1 else "s"))
    ax.grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("result", nargs="?", help="result.h5 (or use --server and --case)")
    parser.add_argument("--server", help="fdemd URL, e.g. http://127.0.0.1:8080")
    parser.add_argument("--case", help="case id on --server")
    parser.add_argument("--token", help="bearer token for --server")
    parser.add_argument("-o", "--output", help="PNG prefix: PREFIX-sieve.png, PREFIX-events.png")
    parser.add_argument("--snapshot", type=int, default=-1,
                        help="snapshot of the result file for the sieve curve (default: last)")
    parser.add_argument("--parts", help="only the fragments of these parts (comma-separated names)")
    parser.add_argument("--exclude-host", action="store_true",
                        help="leave out the host body (held fragments and one holding more than "
                             "half the model's mass; with --server only)")
    parser.add_argument("--print", action="store_true", help="print the numbers as JSON")
    args = parser.parse_args(argv)
    if args.exclude_host and args.result:
        parser.error("--exclude-host needs --server and --case: which nodes a constraint holds "
                     "is not in the result file")
    if bool(args.result) == bool(args.server or args.case) or bool(args.server) != bool(args.case):
        parser.error("give either a result file or both --server and --case")
    if args.result:
        with open_result(args.result) as f:
            dimension, count, curve = fragments_from_file(f, args.snapshot, args.parts)
            time, energy = events_from_file(f)
            title = str(f.attrs.get("name", "")) or os.path.basename(args.result)
        prefix = args.output or os.path.splitext(args.result)[0]
    else:
        dimension, count, curve, time, energy = from_server(args)
        title = "case " + args.case
        prefix = args.output or args.case
    draw_sieve(prefix + "-sieve.png", curve, count, dimension, title)
    draw_events(prefix + "-events.png", time, energy, dimension, title)
    if args.print:
        json.dump({"dimension": dimension, "fragments": count, "distribution": curve,
                   "events": {"time": [float(t) for t in time],
                              "count": list(range(1, len(time) + 1)),
                              "energy": [float(e) for e in np.cumsum(energy)]}},
                  sys.stdout)
        sys.stdout.write("\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
