"""paraview_load.py - run by pvpython (test_paraview.py): opens a result.xdmf
with one of ParaView's XDMF readers and prints, as JSON, what the reader
gives at the first and the last time step, plus every message VTK sent to
its output window (an error or a warning fails the test).

  pvpython paraview_load.py READER FILE.xdmf [WARP | threshold:CELLARRAY]

READER is XDMFReader (the legacy "XDMF Reader"), Xdmf3ReaderS or
Xdmf3ReaderT. With WARP (a point vector array, e.g. displacement) the
reader's output goes through Warp By Vector (scale 1) first, as a user
would apply it, and the blocks described are the warped ones; with
threshold:NAME it goes through Threshold on that cell array between 1 and
1 (`active`: the body without its excavated elements).
"""
import json
import sys

from paraview.simple import Threshold, WarpByVector, XDMFReader, Xdmf3ReaderS, Xdmf3ReaderT
from vtkmodules.vtkCommonCore import vtkOutputWindow, vtkStringOutputWindow

# Everything VTK reports (errors, warnings, the HDF5 layer's complaints
# routed through VTK) lands here instead of the terminal.
window = vtkStringOutputWindow()
vtkOutputWindow.SetInstance(window)


def arrays(attributes):
    """{name: [[component, ...] per tuple]} of a vtkFieldData."""
    out = {}
    for i in range(attributes.GetNumberOfArrays()):
        a = attributes.GetArray(i)
        if a is None:
            continue
        n, k = a.GetNumberOfTuples(), a.GetNumberOfComponents()
        out[a.GetName()] = [[a.GetComponent(t, c) for c in range(k)] for t in range(n)]
    return out


def blocks(data):
    if not data.IsA("vtkCompositeDataSet"):
        return [data]
    found, it = [], data.NewIterator()
    it.InitTraversal()
    while not it.IsDoneWithTraversal():
        found.append(it.GetCurrentDataObject())
        it.GoToNextItem()
    return found


def describe(block):
    points = block.GetPoints()
    return {"cells": block.GetNumberOfCells(),
            "cell_type": block.GetCellType(0) if block.GetNumberOfCells() else None,
            "points": [list(points.GetPoint(i)) for i in range(points.GetNumberOfPoints())],
            "point_data": arrays(block.GetPointData()),
            "cell_data": arrays(block.GetCellData()),
            "field_data": arrays(block.GetFieldData())}


def main(reader_name, path, warp=None):
    if reader_name == "XDMFReader":
        reader = XDMFReader(FileNames=[path])
    else:
        reader = {"Xdmf3ReaderS": Xdmf3ReaderS, "Xdmf3ReaderT": Xdmf3ReaderT}[reader_name](
            FileName=[path])
    times = reader.TimestepValues
    times = list(times) if hasattr(times, "__iter__") else [times]
    last = reader
    if warp and warp.startswith("threshold:"):
        last = Threshold(Input=reader, Scalars=["CELLS", warp[len("threshold:"):]],
                         LowerThreshold=1, UpperThreshold=1)
    elif warp:
        last = WarpByVector(Input=reader, Vectors=["POINTS", warp], ScaleFactor=1.0)
    steps = []
    for index in (0, len(times) - 1):
        last.UpdatePipeline(times[index])
        # pvpython runs the pipeline in-process: the algorithm's own output
        data = last.GetClientSideObject().GetOutputDataObject(0)
        steps.append({"index": index, "blocks": [describe(b) for b in blocks(data)]})
    # pvpython routes print() through the output window too: write around it
    sys.__stdout__.write(json.dumps({"times": times, "steps": steps,
                                     "messages": window.GetOutput()}) + "\n")
    sys.__stdout__.flush()


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2], sys.argv[3] if len(sys.argv) > 3 else None)
