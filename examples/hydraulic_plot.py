#!/usr/bin/python3
"""hydraulic_plot.py - a hydraulic fracture's result (examples/kgd.json in
2D, examples/penny.json in 3D) against the closed forms of its
toughness-dominated regime (Detournay 2016; Savitski & Detournay 2002), as
one PNG of three panels against time: the crack's extent (KGD half-length l,
penny radius R), the opening at the well and the fluid pressure there.

    /usr/bin/python3 examples/hydraulic_plot.py result.h5 [-o OUT.png] [--print]

The crack runs on y = 0 (3D: z = 0) from the injection at the origin; the
case document in the file gives E, nu, G_I (the rock's fracture energy_I)
and Q (the "inject" constraint). A quarter model (no node at x < 0 or
y < 0) holds a fourth of the crack and of Q. Closed forms on V = Q t, with
K_Ic = sqrt(E' G_I), E' = E / (1 - nu^2): uniformly pressurised cracks
holding V, at K_I = K_Ic,
  KGD   l = (E' V / (2 sqrt(pi) K_Ic))^(2/3), p = K_Ic / sqrt(pi l), w(0) = 4 p l / E';
  penny R = (3 E' V / (8 sqrt(pi) K_Ic))^(2/5), p = K_Ic sqrt(pi / (4 R)),
        w(0) = 8 p R / (pi E')  (R = 0.8546 (E' Q t / K')^(2/5), K' = sqrt(32/pi) K_Ic).
Measured per snapshot: the extent is the middle of the crack's process
zone, between the broken joints (damage 1) and the damaged ones (> 0) on
the plane (2D: their farthest ends; 3D: the radius of their area); the
opening and pressure at the well are the means over the plane's joints
with a corner at the origin (/snapshots/aperture, /snapshots/fluid_pressure).
OUT defaults to the result file's name with -hydraulic.png. --print writes
the figures drawn, and the errors at the last snapshot, as JSON.
"""
import argparse
import json
import math
import os
import sys

import h5py
import matplotlib

matplotlib.use("Agg")  # files only; no display needed
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def closed_form(dim, ep, kic, volume):
    """(extent, opening at the well, pressure) of the toughness-dominated crack holding volume."""
    v = np.asarray(volume, dtype=float)
    if dim == 2:
        ext = (ep * v / (2 * math.sqrt(math.pi) * kic)) ** (2 / 3)
        p = kic / np.sqrt(math.pi * np.maximum(ext, 1e-300))
        return ext, 4 * p * ext / ep, p
    ext = (3 * ep * v / (8 * math.sqrt(math.pi) * kic)) ** 0.4
    p = kic * np.sqrt(math.pi / (4 * np.maximum(ext, 1e-300)))
    return ext, 8 * p * ext / (math.pi * ep), p


def read(path):
    with h5py.File(path, "r") as f:
        case = json.loads(f.attrs["case"])
        x0 = f["/mesh/position0"][:]
        joints = f["/mesh/joints"][:]
        t = f["/snapshots/time"][:]
        damage = f["/snapshots/damage"][:]
        pressure = f["/snapshots/fluid_pressure"][:]
        aperture = f["/snapshots/aperture"][:]
    return case, x0, joints, t, damage, pressure, aperture


def measure(case, x0, joints, t, damage, pressure, aperture):
    dim = x0.shape[1]
    face = joints[:, :dim]  # face A's corners
    corners = x0[face]      # (J, dim, dim)
    on = np.all(np.abs(corners[:, :, dim - 1]) < 1e-9, axis=1)
    r = np.hypot(corners[:, :, 0], corners[:, :, 1]) if dim == 3 else np.abs(corners[:, :, 0])
    at_well = on & np.any(r < 1e-9, axis=1)
    quarter = dim == 3 and x0[:, 0].min() > -1e-9 and x0[:, 1].min() > -1e-9
    if dim == 3:
        a, b, c = corners[:, 0], corners[:, 1], corners[:, 2]
        area = 0.5 * np.abs((b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0]))
        scale = 4 if quarter else 1

        def extent(mask):
            return np.sqrt(scale * (area * mask).sum(axis=1) / math.pi)
    else:
        far = r.max(axis=1)

        def extent(mask):
            return np.where(mask, far, 0).max(axis=1)
    broken = extent((damage >= 1) & on)
    damaged = extent((damage > 0) & on)
    q = sum(c.get("inject", 0) for c in case["constraints"])
    volume = (4 if quarter else 1) * q * t
    rock = next(iter(case["materials"].values()))
    ep = rock["young"] / (1 - rock.get("poisson", 0) ** 2)
    kic = math.sqrt(ep * rock["fracture"]["energy_I"])
    return {"dimension": dim, "quarter": bool(quarter), "time": t, "volume": volume,
            "broken": broken, "damaged": damaged, "extent": 0.5 * (broken + damaged),
            "opening": aperture[:, at_well].mean(axis=1), "pressure": pressure[:, at_well].mean(axis=1),
            "ep": ep, "kic": kic, "q": q * (4 if quarter else 1)}


def draw(m, out):
    """Three panels against time; the snapshot at t = 0 (nothing injected
    yet) is left out."""
    m = dict(m)
    later = m["time"] > 0
    for k in ("time", "broken", "damaged", "extent", "opening", "pressure"):
        m[k] = m[k][later]
    dim, t = m["dimension"], m["time"]
    tt = np.linspace(0, t[-1], 200)[1:]
    ext, w, p = closed_form(dim, m["ep"], m["kic"], m["q"] * tt)
    name = "radius R" if dim == 3 else "half-length l"
    fig, axes = plt.subplots(1, 3, figsize=(14, 4.2))
    ms = 1e3  # ms
    axes[0].plot(ms * tt, ext, "k-", label="closed form (toughness)")
    axes[0].plot(ms * t, m["extent"], "o", color="tab:red", label="computed: middle of the process zone")
    axes[0].fill_between(ms * t, m["broken"], m["damaged"], color="tab:red", alpha=0.15,
                         label="broken ... damaged")
    axes[0].set_ylabel(name + " (m)")
    axes[1].plot(ms * tt, 1e3 * w, "k-", label="closed form")
    axes[1].plot(ms * t, 1e3 * m["opening"], "o", color="tab:blue", label="computed")
    axes[1].set_ylabel("opening at the well (mm)")
    axes[2].plot(ms * tt, 1e-6 * p, "k-", label="closed form")
    axes[2].plot(ms * t, 1e-6 * m["pressure"], "o", color="tab:green", label="computed")
    axes[2].set_ylabel("pressure at the well (MPa)")
    axes[2].set_ylim(0, 3 * 1e-6 * p[len(p) // 2])
    for ax in axes:
        ax.set_xlabel("time (ms)")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8, loc="best")
    title = ("radial (penny) fracture, 3D%s" % (", a quarter by symmetry" if m["quarter"] else "")
             if dim == 3 else "KGD fracture, plane strain")
    fig.suptitle("%s: toughness-dominated, Q = %g m%s/s" % (title, m["q"], "³" if dim == 3 else "²"))
    fig.tight_layout()
    fig.savefig(out, dpi=110)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("result")
    ap.add_argument("-o", "--out")
    ap.add_argument("--print", action="store_true", help="the figures drawn, as JSON, to stdout")
    args = ap.parse_args()
    m = measure(*read(args.result))
    out = args.out or os.path.splitext(args.result)[0] + "-hydraulic.png"
    draw(m, out)
    ext, w, p = closed_form(m["dimension"], m["ep"], m["kic"], m["volume"][-1])
    last = {"time": float(m["time"][-1]), "extent": float(m["extent"][-1]), "extent_closed": float(ext),
            "opening": float(m["opening"][-1]), "opening_closed": float(w),
            "pressure": float(m["pressure"][-1]), "pressure_closed": float(p)}
    for k in ("extent", "opening", "pressure"):
        last[k + "_error"] = last[k] / last[k + "_closed"] - 1
    if args.print:
        series = {k: [float(x) for x in m[k]] for k in ("time", "broken", "damaged", "extent", "opening", "pressure")}
        json.dump({"last": last, "series": series}, sys.stdout, indent=1)
        print()
    print("%s: t = %.4g s: extent %.4g m (%.4g, %+.1f %%), opening %.4g mm (%.4g, %+.1f %%), "
          "pressure %.4g MPa (%.4g, %+.1f %%)" % (out, last["time"], last["extent"], last["extent_closed"],
                                                  100 * last["extent_error"], 1e3 * last["opening"],
                                                  1e3 * last["opening_closed"], 100 * last["opening_error"],
                                                  1e-6 * last["pressure"], 1e-6 * last["pressure_closed"],
                                                  100 * last["pressure_error"]), file=sys.stderr)


if __name__ == "__main__":
    main()
