#!/usr/bin/python3
"""borehole_plot.py - the bore's pressure of examples/borehole-breakdown.json
(or examples/borehole_3d.py's case) against time, beside Hubbert & Willis'
breakdown pressure p_b = 3 sigma_h - sigma_H + T, as one PNG; the broken
joints on a second axis.

    /usr/bin/python3 examples/borehole_plot.py result.h5 [-o OUT.png]

The bore is the first "inject" constraint with "bore": true; its pressure
is that constraint's column of /history/fluid/source_pressure. sigma_H and
sigma_h are the larger and smaller in-plane compressions of the part's
initial_stress (its value, compression negative), T the rock's
tensile_strength, all read from the case document in the file. Prints the
peak (the breakdown), its time and its error against p_b, and the least
pressure after it.
"""
import argparse
import json
import os
import sys

import h5py
import matplotlib

matplotlib.use("Agg")  # files only; no display needed
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def read(path):
    with h5py.File(path, "r") as f:
        case = json.loads(f.attrs["case"])
        t = f["/history/time"][:]
        pressure = f["/history/fluid/source_pressure"][:]
        ts = f["/snapshots/time"][:]
        broken = (f["/snapshots/damage"][:] >= 1).sum(axis=1)
    bore = next(k for k, c in enumerate(case["constraints"]) if c.get("bore"))
    sxx, syy = case["parts"][0]["initial_stress"]["value"][:2]
    sigma_H, sigma_h = max(-sxx, -syy), min(-sxx, -syy)
    T = next(iter(case["materials"].values()))["fracture"]["tensile_strength"]
    return t, pressure[:, bore], ts, broken, 3 * sigma_h - sigma_H + T


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("result")
    ap.add_argument("-o", "--out")
    args = ap.parse_args()
    t, p, ts, broken, pb = read(args.result)
    peak = int(np.argmax(p))
    after = float(p[peak:].min())
    out = args.out or os.path.splitext(args.result)[0] + "-breakdown.png"
    fig, ax = plt.subplots(figsize=(7, 4.2))
    ax.plot(1e3 * t, 1e-6 * p, "-", color="tab:blue", label="bore pressure (computed)")
    ax.axhline(1e-6 * pb, color="k", label="Hubbert & Willis 3σh − σH + T")
    ax.axhspan(0.85e-6 * pb, 1.15e-6 * pb, color="k", alpha=0.08, label="±15 %")
    ax.plot(1e3 * t[peak], 1e-6 * p[peak], "o", color="tab:red", label="breakdown (peak)")
    ax.set_xlabel("time (ms)")
    ax.set_ylabel("pressure (MPa)")
    ax.grid(alpha=0.3)
    twin = ax.twinx()
    twin.step(1e3 * ts, broken, where="post", color="tab:gray", alpha=0.7, label="broken joints")
    twin.set_ylabel("broken joints")
    lines = ax.get_legend_handles_labels()
    more = twin.get_legend_handles_labels()
    ax.legend(lines[0] + more[0], lines[1] + more[1], fontsize=8, loc="upper left")
    fig.suptitle("Borehole breakdown under constant-rate injection")
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    print("%s: peak %.2f MPa at %.3f ms (p_b %.2f MPa: %+.1f %%), least after it %.2f MPa"
          % (out, 1e-6 * p[peak], 1e3 * t[peak], 1e-6 * pb, 100 * (p[peak] / pb - 1), 1e-6 * after),
          file=sys.stderr)


if __name__ == "__main__":
    main()
