#!/usr/bin/python3
"""result_check.py - checks a result.h5 (and its result.xdmf) from a reader
independent of the C writer: h5py, the way users read results.

test_result.c writes EXPECTED as JSON (mesh arrays and every snapshot, the
doubles printed with 17 digits so they compare exactly) and runs:

  result_check.py FILE EXPECTED plain  [--count K]   h5py.File(FILE, 'r')
  result_check.py FILE EXPECTED swmr   [--count K]   SWMR reader while the writer runs
  result_check.py FILE EXPECTED follow               SWMR reader racing the writer
  result_check.py FILE EXPECTED frozen               SWMR reader, writer stopped mid-append
                                                     (one check per line on stdin)
  result_check.py FILE EXPECTED xdmf XDMF            the sidecar against the file
  result_check.py FILE - openfails                   plain open must be refused

K defaults to the number of snapshots in EXPECTED. Prints "ok ..." and
exits 0, or prints what differs and exits 1.
"""
import json
import sys
import time
import xml.etree.ElementTree as ET

import h5py
import numpy as np

SERIES = {  # dataset -> key in the expected snapshot
    "step": "step", "time": "time", "position": "position", "velocity": "velocity",
    "stress": "stress", "damage": "damage", "constraint_force": "constraint_force",
    "kinetic_energy": "kinetic_energy", "elastic_energy": "elastic_energy",
    "fragment": "fragment", "strain": "strain", "principal_stress": "principal_stress",
    "displacement": "displacement", "stage": "stage", "active": "active",
    "excavated_energy": "excavated_energy",
}


class Mismatch(Exception):
    pass


def need(cond, message):
    if not cond:
        raise Mismatch(message)


def check_root(f, exp):
    fmt = f.attrs["format"]
    need(isinstance(fmt, str), f"format attribute is {type(fmt).__name__}, not str")
    need(fmt == "fdem-result/1", f"format = {fmt!r}")
    need(f.attrs["name"] == exp["name"], f"name = {f.attrs['name']!r}")
    dim = exp.get("dimension", 2)
    need(int(f.attrs["dimension"]) == dim, f"dimension = {f.attrs['dimension']}, want {dim}")
    need(float(f.attrs["dt"]) == exp["dt"], f"dt = {f.attrs['dt']!r}, want {exp['dt']!r}")


def check_mesh(f, exp):
    mesh = exp["mesh"]
    kinds = {"position0": "f8", "triangles": "i4", "tetrahedra": "i4", "node_mass": "f8",
             "node_part": "i4", "element_part": "i4", "joints": "i4"}
    for name, kind in kinds.items():
        path = "/mesh/" + name
        if name not in mesh:
            need(path not in f, f"{path} exists but the model has none")
            continue
        need(path in f, f"{path} missing")
        got = f[path][()]
        want = np.array(mesh[name], dtype=kind)
        need(got.dtype == np.dtype(kind), f"{path} dtype {got.dtype}, want {kind}")
        need(got.shape == want.shape, f"{path} shape {got.shape}, want {want.shape}")
        need(np.array_equal(got, want), f"{path} values differ")


def want_series(exp, name, snaps):
    """The expected (S, ...) array of a dataset."""
    if name == "constraint_force":
        rows = [s["constraint_force"] for s in snaps]
        return np.array(rows, dtype="f8").reshape(len(snaps), exp["constraints"],
                                                  exp.get("dimension", 2))
    if name == "step":
        return np.array([s["step"] for s in snaps], dtype="i8")
    if name in ("fragment", "stage"):
        return np.array([s[name] for s in snaps], dtype="i4")
    if name == "active":
        return np.array([s["active"] for s in snaps], dtype="u1")
    return np.array([s[name] for s in snaps], dtype="f8")


def check_snapshots(f, exp, count, refresh=False, growing=False):
    """The first `count` rows of every dataset equal the expected ones; unless
    the writer may still be appending (`growing`), time has exactly `count`."""
    snaps = exp["snapshots"][:count]
    need(len(snaps) == count, f"EXPECTED has only {len(exp['snapshots'])} snapshots")
    group = f["snapshots"]
    t = group["time"]
    if refresh:
        t.refresh()
    need(t.shape == (count,) or (growing and t.shape[0] >= count),
         f"/snapshots/time has shape {t.shape}, want ({count},)")
    opened = {}
    for name in SERIES:
        present = name in exp["series"]
        need((name in group) == present,
             f"/snapshots/{name} {'missing' if present else 'unexpected'}")
        if not present:
            continue
        ds = opened[name] = group[name]
        if refresh:
            ds.refresh()
        need(ds.maxshape[0] is None, f"/snapshots/{name} is not extendible along S")
        need(ds.chunks is not None, f"/snapshots/{name} is not chunked")
        need(ds.shape[0] >= count, f"/snapshots/{name} has {ds.shape[0]} rows < {count}")
        if count == 0:
            continue
        got = ds[:count]
        want = want_series(exp, name, snaps)
        need(got.shape == want.shape, f"/snapshots/{name} shape {got.shape}, want {want.shape}")
        need(got.dtype == want.dtype, f"/snapshots/{name} dtype {got.dtype}, want {want.dtype}")
        if not np.array_equal(got, want):
            bad = np.argwhere(got != want)[0]
            raise Mismatch(f"/snapshots/{name}{list(bad)} = {got[tuple(bad)]!r}, "
                           f"want {want[tuple(bad)]!r}")
    if count and "displacement" in opened and "position" in opened:
        check_displacement(opened["displacement"], opened["position"], f["/mesh/position0"][()],
                           count)


def check_displacement(u, x, position0, count):
    """/snapshots/displacement is /snapshots/position - /mesh/position0,
    subtracted here by numpy, to the bit. u and x are the handles the
    caller opened (and refreshed): a SWMR reader must not open a dataset
    twice ("can't insert duplicate key")."""
    got = u[:count]
    want = x[:count] - position0
    need(got.shape == want.shape, f"displacement shape {got.shape}, position {want.shape}")
    if got.tobytes() != want.tobytes():
        bad = np.argwhere(got.view(np.uint64) != want.view(np.uint64))[0]
        raise Mismatch(f"/snapshots/displacement{list(bad)} = {got[tuple(bad)]!r}, "
                       f"position - position0 = {want[tuple(bad)]!r}")


def check_file(f, exp, count, refresh=False):
    check_root(f, exp)
    check_mesh(f, exp)
    check_snapshots(f, exp, count, refresh)


def follow(path, exp):
    """Reads while the writer appends: every time /snapshots/time grows, the
    rows it covers must be complete in every dataset."""
    total = len(exp["snapshots"])
    f = h5py.File(path, "r", libver="latest", swmr=True)
    print("ready", flush=True)
    seen, checks = 0, 0
    deadline = time.monotonic() + 30
    while seen < total:
        need(time.monotonic() < deadline, f"timed out at {seen} of {total} snapshots")
        f["snapshots/time"].refresh()
        n = f["snapshots/time"].shape[0]
        if n == seen:
            time.sleep(0.0005)
            continue
        check_snapshots(f, exp, n, refresh=True, growing=True)
        seen, checks = n, checks + 1
    f.close()
    return f"followed {total} snapshots in {checks} distinct states"


def frozen(path, exp):
    """One check per line on stdin, each while the test holds the writer
    stopped (SIGSTOP) at an arbitrary point, perhaps in the middle of an
    append: whatever time admits must be complete in every dataset."""
    failures, counts = 0, []
    for _ in sys.stdin:
        try:
            with h5py.File(path, "r", libver="latest", swmr=True) as f:
                n = f["snapshots/time"].shape[0]
                check_file(f, exp, n, refresh=True)
            counts.append(n)
            print("checked", n, flush=True)
        except Mismatch as e:
            failures += 1
            print("mismatch:", e, flush=True)
    need(failures == 0, f"{failures} of {failures + len(counts)} frozen states inconsistent")
    return f"{len(counts)} frozen states consistent, {counts[0]}..{counts[-1]} snapshots"


def dataitem_dims(item):
    return tuple(int(v) for v in item.get("Dimensions").split())


def check_hdf_item(f, item, h5_name):
    ref = item.text.strip()
    need(ref.startswith(h5_name + ":/"), f"DataItem refers to {ref!r}")
    path = ref.split(":", 1)[1]
    need(path in f, f"XDMF refers to {path}, which is not in the file")
    need(dataitem_dims(item) == f[path].shape,
         f"XDMF says {path} is {dataitem_dims(item)}, file has {f[path].shape}")
    return f[path]


def check_hyperslab(f, item, h5_name, s):
    children = item.findall("DataItem")
    need(len(children) == 2, "HyperSlab needs a selection and a source DataItem")
    sel = np.array(children[0].text.split(), dtype=int).reshape(3, -1)
    ds = check_hdf_item(f, children[1], h5_name)
    start, stride, count = sel
    need(start[0] == s and count[0] == 1, f"hyperslab of grid {s} selects snapshot {start[0]}")
    need(all(start + (count - 1) * stride < np.array(ds.shape)),
         f"hyperslab {sel.tolist()} outside {ds.shape}")
    need(int(np.prod(count)) == int(np.prod(dataitem_dims(item))),
         f"hyperslab count {count.tolist()} vs Dimensions {dataitem_dims(item)}")


def check_whole(f, item, h5_name, cells):
    """A topology read through a HyperSlab that selects all of /mesh/<cells>."""
    children = item.findall("DataItem")
    need(len(children) == 2, "HyperSlab needs a selection and a source DataItem")
    ds = check_hdf_item(f, children[1], h5_name)
    need(ds.name == "/mesh/" + cells, f"topology HyperSlab reads {ds.name}")
    sel = np.array(children[0].text.split(), dtype=int).reshape(3, -1)
    need(sel.tolist() == [[0, 0], [1, 1], list(ds.shape)], f"topology selects {sel.tolist()}")


# Row-major 3x3 tensor from the Voigt columns of /snapshots/stress.
TENSOR = {2: [0, 2, None, 2, 1, None, None, None, None], 3: [0, 5, 4, 5, 1, 3, 4, 3, 2]}


def check_view(f, path, s, dim):
    """/xdmf/<s>/<field> shows row s of /snapshots/<field> as the sidecar
    says: tensors 3x3 with the in-plane zeros, velocity with z = 0."""
    _, group, snapshot, field = path.split("/")
    need(group == "xdmf" and int(snapshot) == s, f"grid {s} names the view {path}")
    got = f[path][()]
    row = f["/snapshots/" + field][s]
    if field in ("stress", "strain"):
        want = np.array([row[:, k] if k is not None else np.zeros(len(row))
                         for k in TENSOR[dim]]).T
    elif field in ("velocity", "displacement"):
        want = np.zeros((len(row), 3))
        want[:, :dim] = row
    else:
        want = row
    need(got.shape == want.shape and np.array_equal(got, want), f"view {path} differs from its row")


def dataitem_number_type(item):
    """(NumberType, Precision) of an attribute's data: a HyperSlab's is on
    its inner HDF item."""
    if item.get("ItemType") == "HyperSlab":
        item = item.findall("DataItem")[-1]
    return item.get("NumberType"), item.get("Precision")


def check_node_vector(a, item, n_nodes, dim):
    """velocity and displacement: a Node Vector, three components through a
    view (ParaView warps by it), `dim` through a HyperSlab of a running case."""
    name = a.get("Name")
    need(a.get("AttributeType") == "Vector" and a.get("Center") == "Node",
         f"{name} is {a.get('AttributeType')} at {a.get('Center')}, want a Node Vector")
    width = dim if item.get("ItemType") == "HyperSlab" else 3
    need(dataitem_dims(item) == (n_nodes, width),
         f"{name} is {dataitem_dims(item)}, want ({n_nodes}, {width})")


def check_series(f, item, h5_name, snapshots):
    """A Grid attribute: the whole series, one tuple per snapshot."""
    ref = item.text.strip()
    need(ref.startswith(h5_name + ":/snapshots/"), f"series DataItem refers to {ref!r}")
    ds = f[ref.split(":", 1)[1]]
    dims = dataitem_dims(item)
    need(len(dims) == 2 and dims[0] == snapshots == ds.shape[0] and
         int(np.prod(dims)) == ds.size, f"series {ds.name} {dims} vs {ds.shape}")


def check_xdmf(f, exp, xdmf_path, h5_name):
    root = ET.parse(xdmf_path).getroot()
    need(root.tag == "Xdmf" and root.get("Version") == "2.0", "not an XDMF 2.0 document")
    coll = root.find("Domain/Grid")
    need(coll.get("GridType") == "Collection" and coll.get("CollectionType") == "Temporal",
         "top grid is not a temporal collection")
    # ParaView's block names: the elements, then the joints when there are any
    blocks = [g.get("Name") for g in root.findall("Domain/Grid")]
    want = ["elements", "joints"] if len(exp["mesh"].get("joints", [])) else ["elements"]
    need(blocks == want, f"collections are named {blocks}, not {want}")
    grids = coll.findall("Grid")
    times = f["snapshots/time"][()]
    need(len(grids) == len(times), f"{len(grids)} grids for {len(times)} snapshots")
    dim = exp.get("dimension", 2)
    cells, topology, geometry = (("tetrahedra", "Tetrahedron", "XYZ") if dim == 3
                                 else ("triangles", "Triangle", "XY"))
    n_nodes = len(exp["mesh"]["position0"])
    n_elems = len(exp["mesh"][cells])
    names = None
    for s, grid in enumerate(grids):
        need(float(grid.find("Time").get("Value")) == times[s], f"grid {s} time differs")
        topo = grid.find("Topology")
        need(topo.get("TopologyType") == topology, f"topology is not {topology}")
        need(int(topo.get("NumberOfElements")) == n_elems, "NumberOfElements wrong")
        item = topo.find("DataItem")
        if item.get("ItemType") == "HyperSlab":
            check_whole(f, item, h5_name, cells)
        else:
            check_hdf_item(f, item, h5_name)
        geo = grid.find("Geometry")
        need(geo.get("GeometryType") == geometry, f"geometry is not {geometry}")
        item = geo.find("DataItem")
        if item.get("ItemType") == "HyperSlab":
            check_hyperslab(f, item, h5_name, s)
        else:
            ds = check_hdf_item(f, item, h5_name)
            if ds.name.startswith("/xdmf/"):
                check_view(f, ds.name, s, dim)
        need(dataitem_dims(item) == (n_nodes, dim), f"geometry is not N x {dim}")
        attrs = {}
        for a in grid.findall("Attribute"):
            item = a.find("DataItem")
            if a.get("Center") == "Grid":
                check_series(f, item, h5_name, len(times))
                attrs[a.get("Name")] = "Grid"
                continue
            if item.get("ItemType") == "HyperSlab":
                check_hyperslab(f, item, h5_name, s)
            else:
                ds = check_hdf_item(f, item, h5_name)
                if ds.name.startswith("/xdmf/"):
                    check_view(f, ds.name, s, dim)
            rows = n_nodes if a.get("Center") == "Node" else n_elems
            need(dataitem_dims(item)[0] == rows, f"attribute {a.get('Name')} has wrong rows")
            if a.get("Name") in ("velocity", "displacement"):
                check_node_vector(a, item, n_nodes, dim)
            if a.get("Name") == "active":
                need(a.get("Center") == "Cell" and dataitem_number_type(item) == ("UChar", "1"),
                     f"active is {a.get('Center')} {dataitem_number_type(item)}, want a Cell "
                     "UChar of 1 byte")
            attrs[a.get("Name")] = a.get("Center")
        for field in ("velocity", "displacement", "active"):
            need((field in attrs) == (field in exp["series"]),
                 f"grid {s}: attribute {field} {'missing' if field in exp['series'] else 'unexpected'}")
        names = sorted(attrs)
    return f"xdmf: {len(grids)} grids, attributes {names}"


def main(argv):
    path, expected, mode = argv[1], argv[2], argv[3]
    if mode == "openfails":
        try:
            h5py.File(path, "r").close()
        except OSError as e:
            return f"plain open refused: {e}"
        raise Mismatch("plain open of a crashed file succeeded")
    with open(expected) as fh:
        exp = json.load(fh)
    count = len(exp["snapshots"])
    if "--count" in argv:
        count = int(argv[argv.index("--count") + 1])
    if mode == "plain":
        with h5py.File(path, "r") as f:
            check_file(f, exp, count)
        return f"plain: {count} snapshots match"
    if mode == "swmr":
        with h5py.File(path, "r", libver="latest", swmr=True) as f:
            check_file(f, exp, count, refresh=True)
        return f"swmr: {count} snapshots match"
    if mode == "frozen":
        return frozen(path, exp)
    if mode == "follow":
        return follow(path, exp)
    if mode == "xdmf":
        xdmf = argv[4]
        with h5py.File(path, "r", libver="latest", swmr=True) as f:
            check_file(f, exp, count, refresh=True)
            return check_xdmf(f, exp, xdmf, exp["h5_name"])
    raise Mismatch(f"unknown mode {mode}")


if __name__ == "__main__":
    try:
        print("ok", main(sys.argv), flush=True)
    except Mismatch as e:
        print("mismatch:", e, flush=True)
        sys.exit(1)
