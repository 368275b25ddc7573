"""render_paraview.py - draw one snapshot of an fdemd result.xdmf to a PNG
with ParaView, coloured by any field, 2D or 3D.

    xvfb-run -a -s "-screen 0 1280x1024x24 -noreset" \\
        pvpython clients/python/render_paraview.py RESULT.xdmf -o OUT.png \\
        [--field NAME] [--component C] [--snapshot -1 | --time T] [--size 1200x900] \\
        [--warp SCALE] [--view ELEV,AZIM] [--list]

It is run by pvpython (Debian: python3-paraview), not by python3. pvpython
renders through X: on Debian its offscreen mode segfaults, so without a
display run it under xvfb-run (Debian: xvfb, with xauth), which starts a
virtual X server for the one command: 24 bits deep (the default 8-bit
screen has no OpenGL visual) and with -noreset (a server that resets when
its last client leaves drops the connection pvpython opens next, now and
then). The script refuses to start without $DISPLAY rather than crash.

What it draws. The file's two blocks, `elements` (the triangles or
tetrahedra, with their node and cell fields) and `joints` (every joint as
its first face, with `damage`), are read with ParaView's legacy XDMF
Reader: it is the one reader that names the blocks and also opens the
sidecar of a case still running (docs/results.md, "ParaView"). --field
colours the block that carries it: a node (point) field such as
displacement or velocity is interpolated over the elements, an element
(cell) field such as stress, strain, principal_stress, fragment or
element_part is drawn flat per element, and damage draws the joints
coloured from 0 (intact) to 1 (broken) over the elements in grey. A field
the file does not hold is refused, listing the fields it does hold.

--component picks what a field of several components is coloured by:
magnitude (the default), x|y|z of a vector, xx|xy|xz|yx|yy|yz|zx|zy|zz of
stress or strain (3x3 tensors, row by row; a 2D tensor's z entries are 0),
1|2|3 of principal_stress (largest first), or a column number from 0.

--warp SCALE draws the mesh at position0 + SCALE * displacement (it needs
the field "displacement" in output.fields); the geometry of a file that
also stores positions is already position0 + displacement, and the warp
adds the rest. 2D results are seen from +z; 3D ones from --view ELEV,AZIM
(degrees, as plot_result.py: 25,-60). The colour bar spans the values of
that snapshot. --list prints the blocks and their fields as JSON and draws
nothing.

Exit status 0 when the PNG is written, 2 for a usage error (unknown field
or component, no snapshot there, no display), 1 otherwise.
"""
import argparse
import json
import math
import os
import sys
import xml.etree.ElementTree as ET

VECTOR = {"x": 0, "y": 1, "z": 2}
TENSOR = {n: i for i, n in enumerate(("xx", "xy", "xz", "yx", "yy", "yz", "zx", "zy", "zz"))}
PRINCIPAL = {"1": 0, "2": 1, "3": 2}
BLOCKS = ("elements", "joints")
GREY = [0.78, 0.78, 0.78]
BAR_PIXELS = 180  # kept right of the body for the colour bar and its labels


class UsageError(Exception):
    pass


def parse_args(argv):
    p = argparse.ArgumentParser(
        prog="render_paraview.py",
        description="Draw one snapshot of an fdemd result.xdmf to a PNG with ParaView "
                    "(run as: xvfb-run -a pvpython render_paraview.py ...).")
    p.add_argument("xdmf", help="result.xdmf (next to its .h5, as fdemctl fetch saves them)")
    p.add_argument("-o", "--output", help="PNG file to write")
    p.add_argument("--field", help="what to colour by (default: displacement, else stress, "
                                   "else velocity, else element_part)")
    p.add_argument("--component", default="magnitude",
                   help="magnitude, x|y|z, xx|xy|...|zz, 1|2|3 or a column number")
    when = p.add_mutually_exclusive_group()
    when.add_argument("--snapshot", type=int, default=-1,
                      help="snapshot index, negative from the end (default -1: the last)")
    when.add_argument("--time", type=float, help="the snapshot nearest this time (s)")
    p.add_argument("--size", default="1200x900", help="PNG size WIDTHxHEIGHT in pixels")
    p.add_argument("--warp", type=float, metavar="SCALE",
                   help="draw at position0 + SCALE * displacement")
    p.add_argument("--view", default="25,-60", help="3D only: elevation,azimuth in degrees")
    p.add_argument("--list", action="store_true", help="print blocks and fields as JSON")
    args = p.parse_args(argv)
    if not args.list and not args.output:
        p.error("-o/--output is required (or --list)")
    try:
        w, h = (int(v) for v in args.size.lower().split("x"))
        assert 16 <= w <= 8192 and 16 <= h <= 8192
        args.size = [w, h]
    except (ValueError, AssertionError):
        p.error("--size must be WIDTHxHEIGHT, each 16..8192, e.g. 1200x900")
    try:
        args.view = [float(v) for v in args.view.split(",")]
        assert len(args.view) == 2
    except (ValueError, AssertionError):
        p.error("--view must be ELEV,AZIM in degrees, e.g. 25,-60")
    return args


def sidecar_facts(path):
    """What the XML says: the dimension, whether the geometry is the
    initial one (/mesh/position0: no positions stored), which blocks."""
    try:
        root = ET.parse(path).getroot()
    except (OSError, ET.ParseError) as e:
        raise UsageError("%s is not a readable XDMF file: %s" % (path, e))
    geometry = root.find(".//Geometry")
    if geometry is None:
        raise UsageError("%s has no snapshot (no Geometry element)" % path)
    items = [d.text.strip() for d in geometry.iter("DataItem") if d.text and d.text.strip()]
    names = [g.get("Name") for g in root.findall("./Domain/Grid")]
    return {"dimension": 3 if geometry.get("GeometryType") == "XYZ" else 2,
            "initial_geometry": any(t.endswith(":/mesh/position0") for t in items),
            "blocks": [n for n in names if n in BLOCKS]}


def pick_time(times, args):
    if not times:
        raise UsageError("the file has no snapshot")
    if args.time is not None:
        return min(range(len(times)), key=lambda i: abs(times[i] - args.time))
    s = args.snapshot if args.snapshot >= 0 else len(times) + args.snapshot
    if not 0 <= s < len(times):
        raise UsageError("no snapshot %d: the file has %d (0..%d, or -1 for the last)"
                         % (args.snapshot, len(times), len(times) - 1))
    return s


def arrays_of(source, time):
    """{"point": {name: components}, "cell": {...}} of a block at `time`."""
    source.UpdatePipeline(time)
    info = source.GetDataInformation()
    out = {}
    for kind, attrs in (("point", info.GetPointDataInformation()),
                        ("cell", info.GetCellDataInformation())):
        out[kind] = {}
        for i in range(attrs.GetNumberOfArrays()):
            a = attrs.GetArrayInformation(i)
            out[kind][a.GetName()] = a.GetNumberOfComponents()
    return out


def find_field(field, fields):
    """(block, "POINTS"|"CELLS", components) of `field`, elements first."""
    for block in BLOCKS:
        for kind, association in (("point", "POINTS"), ("cell", "CELLS")):
            if field in fields.get(block, {}).get(kind, {}):
                return block, association, fields[block][kind][field]
    listing = "; ".join("%s: %s" % (block, ", ".join(
        sorted(fields[block]["point"]) + sorted(fields[block]["cell"])))
        for block in BLOCKS if block in fields)
    raise UsageError("unknown field %r; this result has %s" % (field, listing))


def default_field(fields):
    for name in ("displacement", "stress", "velocity", "element_part"):
        for kind in ("point", "cell"):
            if name in fields["elements"][kind]:
                return name
    raise UsageError("the elements carry no field to colour by")


def component_index(field, components, wanted):
    """None for the magnitude, else the column to colour by."""
    wanted = wanted.lower()
    if components == 1 or wanted == "magnitude":
        return None
    names = TENSOR if components == 9 else PRINCIPAL if field == "principal_stress" else VECTOR
    if wanted in names and names[wanted] < components:
        return names[wanted]
    if wanted.isdigit() and int(wanted) < components:
        return int(wanted)
    raise UsageError("%s has %d components: --component is magnitude, %s or 0..%d"
                     % (field, components, "|".join(n for n, i in names.items()
                                                    if i < components), components - 1))


def require_display():
    if not os.environ.get("DISPLAY"):
        raise UsageError("no X display: pvpython renders through X (its offscreen mode "
                         "segfaults on Debian); run it as\n  xvfb-run -a -s \"-screen 0 "
                         "1280x1024x24 -noreset\" pvpython %s ..."
                         % sys.argv[0])


def plot_width(size):
    """The fraction of the image left of the colour bar."""
    return max(0.5, 1.0 - BAR_PIXELS / size[0])


def place_camera(view, bounds, dimension, elev_azim, size):
    """2D: seen from +z, parallel, the body filling the part of the image
    left of the colour bar; 3D: from ELEV,AZIM, then fitted by ParaView."""
    center = [(bounds[2 * k] + bounds[2 * k + 1]) / 2 for k in range(3)]
    extent = [bounds[2 * k + 1] - bounds[2 * k] for k in range(3)]
    reach = 10 * (max(extent) or 1.0)
    if dimension == 2:
        free = plot_width(size) * size[0] / size[1]  # width/height of the free area
        half_height = 0.5 * max(extent[1], extent[0] / free) * 1.12 or 1.0
        # shift the focus right so that the body is centred in the free area
        shift = half_height * (size[0] / size[1]) * (1 - plot_width(size))
        view.InteractionMode = "2D"
        view.CameraParallelProjection = 1
        view.CameraFocalPoint = [center[0] + shift, center[1], center[2]]
        view.CameraPosition = [center[0] + shift, center[1], center[2] + reach]
        view.CameraViewUp = [0, 1, 0]
        view.CameraParallelScale = half_height
        return
    elev, azim = (math.radians(v) for v in elev_azim)
    direction = [math.cos(elev) * math.cos(azim), math.cos(elev) * math.sin(azim),
                 math.sin(elev)]
    view.CameraFocalPoint = center
    view.CameraPosition = [c + reach * d for c, d in zip(center, direction)]
    view.CameraViewUp = [0, 0, 1]
    view.ResetCamera(False)
    # ResetCamera fits the whole image: step back until the body fits left
    # of the colour bar, and pan so that it is centred there
    fraction = plot_width(size)
    camera = view.GetActiveCamera()
    camera.Dolly(fraction)
    half_width = (camera.GetDistance() * math.tan(math.radians(camera.GetViewAngle()) / 2)
                  * size[0] / size[1])
    look = [f - p for f, p in zip(camera.GetFocalPoint(), camera.GetPosition())]
    up = camera.GetViewUp()
    right = [look[1] * up[2] - look[2] * up[1], look[2] * up[0] - look[0] * up[2],
             look[0] * up[1] - look[1] * up[0]]
    norm = math.sqrt(sum(r * r for r in right)) or 1.0
    pan = [(1 - fraction) * half_width * r / norm for r in right]
    camera.SetFocalPoint(*[f + d for f, d in zip(camera.GetFocalPoint(), pan)])
    camera.SetPosition(*[p + d for p, d in zip(camera.GetPosition(), pan)])


def style_scalar_bar(pv, lut, view, title, size):
    bar = pv.GetScalarBar(lut, view)
    bar.Title = title
    bar.ComponentTitle = ""
    bar.TitleColor = bar.LabelColor = [0.1, 0.1, 0.1]
    bar.TitleFontSize = bar.LabelFontSize = 16
    bar.RangeLabelFormat = "%-#.3g"
    bar.HorizontalTitle = 1
    bar.WindowLocation = "Any Location"
    bar.Orientation = "Vertical"
    bar.Position = [plot_width(size) + 0.02, 0.08]
    bar.ScalarBarLength = 0.75
    bar.Visibility = 1


def render(pv, reader, facts, fields, time, args):
    field = args.field or default_field(fields)
    block, association, components = find_field(field, fields)
    column = component_index(field, components, args.component)
    require_display()

    sources = {b: pv.ExtractBlock(Input=reader, Selectors=["/Root/" + b])
               for b in facts["blocks"]}
    if args.warp is not None:
        if "displacement" not in fields["elements"]["point"]:
            raise UsageError('--warp needs the field "displacement": add it to output.fields')
        scale = args.warp - (0.0 if facts["initial_geometry"] else 1.0)
        sources = {b: pv.WarpByVector(Input=s, Vectors=["POINTS", "displacement"],
                                      ScaleFactor=scale) for b, s in sources.items()}

    view = pv.CreateRenderView()
    view.ViewSize = args.size
    view.OrientationAxesVisibility = 0
    if hasattr(view, "UseColorPaletteForBackground"):
        view.UseColorPaletteForBackground = 0
    view.Background = [1, 1, 1]
    view.ViewTime = time

    shown = pv.Show(sources[block], view)
    if block == "joints":  # cracks over the body in grey
        body = pv.Show(sources["elements"], view)
        pv.ColorBy(body, None)
        body.AmbientColor = body.DiffuseColor = GREY
        if facts["dimension"] == 3:
            body.Opacity = 0.25
        shown.LineWidth = 2.0
    if facts["dimension"] == 2:  # a flat drawing: the colours of the bar, unshaded
        for display in (shown, body) if block == "joints" else (shown,):
            display.Ambient, display.Diffuse = 1.0, 0.0
    pv.ColorBy(shown, (association, field))
    lut = pv.GetColorTransferFunction(field)
    if column is None:
        lut.VectorMode = "Magnitude"
        label = "magnitude" if components > 1 else ""
    else:
        lut.VectorMode = "Component"
        lut.VectorComponent = column
        label = args.component.lower()
    if field == "damage":
        lut.RescaleTransferFunction(0.0, 1.0)
    else:
        shown.RescaleTransferFunctionToDataRange(False, True)
    style_scalar_bar(pv, lut, view, "%s %s\nt = %.6g s" % (field, label, time),
                     args.size)

    sources[block].UpdatePipeline(time)
    place_camera(view, sources[block].GetDataInformation().GetBounds(), facts["dimension"],
                 args.view, args.size)
    pv.SaveScreenshot(args.output, view, ImageResolution=args.size, TransparentBackground=0)
    # Let go of the view (and its GL context) now: left to pvpython's exit,
    # it is torn down in an order Xvfb answers with GLXBadContext, and the
    # process exits 1 after writing a good PNG.
    pv.Delete(view)


def main(argv):
    args = parse_args(argv)
    path = os.path.abspath(args.xdmf)  # the Xdmf readers need a directory in the name
    facts = sidecar_facts(path)
    from paraview import simple as pv

    reader = pv.XDMFReader(FileNames=[path])
    reader.UpdatePipelineInformation()
    times = reader.TimestepValues
    times = list(times) if hasattr(times, "__iter__") else [times]
    s = pick_time(times, args)
    fields = {b: arrays_of(pv.ExtractBlock(Input=reader, Selectors=["/Root/" + b]), times[s])
              for b in facts["blocks"]}
    if "elements" not in fields:
        raise UsageError("%s has no block named elements (a sidecar of an older fdemd? "
                         "fetch it again)" % path)
    if args.list:
        sys.__stdout__.write(json.dumps({"snapshots": len(times), "time": times[s],
                                         "dimension": facts["dimension"],
                                         "blocks": fields}) + "\n")
        return 0
    render(pv, reader, facts, fields, times[s], args)
    sys.__stdout__.write("%s: snapshot %d, t = %.6g s\n" % (args.output, s, times[s]))
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main(sys.argv[1:]))
    except UsageError as e:
        sys.__stderr__.write("render_paraview.py: %s\n" % e)
        sys.exit(2)
