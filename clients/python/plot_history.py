#!/usr/bin/python3
"""plot_history.py - what a lab or tunnel engineer plots first from a run's
history output (docs/results.md, "History"): load against displacement and the energy
balance, as one PNG with two panels.

    /usr/bin/python3 clients/python/plot_history.py result.h5 [-o OUT.png] \\
        [--constraint K] [--axis x|y|z] [--print]
    /usr/bin/python3 clients/python/plot_history.py --server URL --case ID \\
        [-o OUT.png] [--token T] [--constraint K] [--axis x|y|z] [--print]

  load     constraint K's force (/history/constraint_force) against the
           mean displacement of its nodes (/history/constraint_displacement),
           both along --axis (default: the axis along which that constraint
           moved most), e.g. a platen's load against its travel.
  energy   every energy account (/history/energy/<term>) against time, with
           the residual of the balance, so a user sees it close.

OUT defaults to the result file's name (or the case id) with -history.png.
From a server the rows come from GET /cases/ID/history. --print writes the
numbers drawn, as JSON, to stdout.
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
from fdemd_client import Client  # noqa: E402
from plot_result import open_result  # noqa: E402  (plain, else as a SWMR reader)

TERMS = ("kinetic", "elastic", "joint", "contact", "friction", "fracture", "damping",
         "gravity_work", "external_work", "excavated", "residual")


def history_from_file(path):
    """The history columns of a result file, as Client.history_columns gives them."""
    with open_result(path) as f:
        if "history" not in f:
            raise SystemExit("%s has no /history (written before history output)" % path)
        h = f["history"]
        n = len(h["time"])  # the commit marker: rows past it may be half written
        return {
            "names": [x.decode() if isinstance(x, bytes) else str(x)
                      for x in h["points"].attrs.get("names", [])],
            "time": h["time"][:n],
            "step": h["step"][:n],
            "point_displacement": h["points/displacement"][:n],
            "point_velocity": h["points/velocity"][:n],
            "constraint_force": h["constraint_force"][:n],
            "constraint_displacement": h["constraint_displacement"][:n],
            "energy": {k: h["energy/" + k][:n] for k in TERMS if "energy/" + k in h},
        }


def pick_axis(displacement, axis):
    if axis is not None:
        return "xyz".index(axis)
    return int(np.argmax(np.max(np.abs(displacement), axis=0))) if len(displacement) else 0


def draw(columns, constraint, axis, out):
    force = np.asarray(columns["constraint_force"], dtype=float)
    disp = np.asarray(columns["constraint_displacement"], dtype=float)
    if force.ndim != 3 or constraint >= force.shape[1]:
        raise SystemExit("the case has %d constraints; no constraint %d"
                         % (force.shape[1] if force.ndim == 3 else 0, constraint))
    a = pick_axis(disp[:, constraint, :], axis)
    u, load = disp[:, constraint, a], force[:, constraint, a]
    t = np.asarray(columns["time"], dtype=float)
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.2))
    left.plot(u * 1e3, load, "-o", ms=2)
    left.set_xlabel("constraint %d mean displacement %s (mm)" % (constraint, "xyz"[a]))
    left.set_ylabel("constraint %d force %s (N)" % (constraint, "xyz"[a]))
    left.set_title("load against displacement")
    left.grid(True, alpha=0.3)
    for term, values in columns["energy"].items():
        values = np.asarray(values, dtype=float)
        if term == "residual" or np.any(values != 0):
            right.plot(t, values, "--" if term == "residual" else "-", label=term)
    right.set_xlabel("time (s)")
    right.set_ylabel("energy (J)")
    right.set_title("energy balance")
    right.legend(fontsize=7)
    right.grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    plt.close(fig)
    return {"axis": "xyz"[a], "displacement": u.tolist(), "force": load.tolist(),
            "time": t.tolist(),
            "energy": {k: np.asarray(v, dtype=float).tolist() for k, v in columns["energy"].items()}}


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("result", nargs="?", help="result.h5")
    p.add_argument("--server", help="daemon URL, with --case")
    p.add_argument("--case", help="case id on the server")
    p.add_argument("--token")
    p.add_argument("-o", "--output")
    p.add_argument("--constraint", type=int, default=None,
                   help="the constraint whose load is drawn (default: the last)")
    p.add_argument("--axis", choices=("x", "y", "z"))
    p.add_argument("--print", action="store_true", dest="print_numbers")
    args = p.parse_args(argv)
    if args.server and args.case:
        client = Client(args.server, token=args.token)
        columns = Client.history_columns(client.history(args.case, since=None))
        stem = args.case
    elif args.result:
        columns = history_from_file(args.result)
        stem = os.path.splitext(args.result)[0]
    else:
        p.error("give a result.h5, or --server and --case")
    if len(columns["time"]) == 0:
        raise SystemExit("the history has no rows yet")
    constraints = np.asarray(columns["constraint_force"]).shape[1]
    constraint = args.constraint if args.constraint is not None else constraints - 1
    out = args.output or stem + "-history.png"
    numbers = draw(columns, constraint, args.axis, out)
    if args.print_numbers:
        json.dump(numbers, sys.stdout)
        sys.stdout.write("\n")
    else:
        print("wrote %s" % out)


if __name__ == "__main__":
    main()
