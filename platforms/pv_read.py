"""Run by ParaView's own Python (``pvpython pv_read.py RUN_FOLDER OUT_JSON FRAME_PNG``): opens the
run's ``fields.xdmf`` the way a user does in ParaView (its XDMF reader) and writes what ParaView
sees: the time steps and, at the last one, every block of the reader's output (the package
writes one grid per time holding every field: one block; folders of earlier versions have one
temporal grid per function) with its point coordinates and point arrays, and its cell centres and
cell arrays, as JSON. It renders the last frame (zeta on the body deformed by u) to a PNG.
``benchmarks/platforms/paraview_check.py`` compares the JSON with the run's own history.csv and
fields_final.npz. Nothing here imports damage_dolfinx: ParaView's Python is another interpreter."""
import json
import sys

from paraview import servermanager
from paraview import simple
from vtkmodules.numpy_interface import dataset_adapter as dsa
from vtkmodules.vtkCommonDataModel import vtkCompositeDataSet
from vtkmodules.vtkFiltersCore import vtkCellCenters

folder, out_json, frame_png = sys.argv[1:4]
reader = None
for name in ("Xdmf3ReaderS", "Xdmf3ReaderT", "XDMFReader"):
    if hasattr(simple, name):
        reader = getattr(simple, name)(FileName=[f"{folder}/fields.xdmf"])
        break
if reader is None:
    reader = simple.OpenDataFile(f"{folder}/fields.xdmf")
times = [float(t) for t in (reader.TimestepValues or [])]
last = times[-1] if times else 0.0
reader.UpdatePipeline(last)
root = servermanager.Fetch(reader)



def leaves(data):
    """(name, dataset) of every leaf block; a single dataset is its own one block."""
    if not hasattr(data, "NewIterator"):
        return [(None, data)]
    found = []
    it = data.NewIterator()
    it.InitTraversal()
    while not it.IsDoneWithTraversal():
        found.append((it.GetCurrentMetaData().Get(vtkCompositeDataSet.NAME()),
                      it.GetCurrentDataObject()))
        it.GoToNextItem()
    return found


grids = {}
for index, (name, block) in enumerate(leaves(root)):
    wrapped = dsa.WrapDataObject(block)
    name = name or "+".join(list(wrapped.PointData.keys()) + list(wrapped.CellData.keys())) \
        or f"block{index}"
    cc = vtkCellCenters()
    cc.SetInputData(block)
    cc.Update()
    grids[name] = {"points": wrapped.Points.tolist(),
                   "point_arrays": {k: wrapped.PointData[k].tolist() for k in wrapped.PointData.keys()},
                   "cell_centres": dsa.WrapDataObject(cc.GetOutput()).Points.tolist(),
                   "cell_arrays": {k: wrapped.CellData[k].tolist() for k in wrapped.CellData.keys()}}

with open(out_json, "w") as f:
    json.dump({"reader": reader.GetXMLName(), "times": times, "grids": grids}, f)

# one frame as a user would look at it: zeta at the last time step, on [min, 1], on the body
# deformed by u (factor 1). zeta's block gets u's point array when u is in another block of the
# same points (earlier versions' one grid per function) and is shown alone.
blocks = {}
for _, b in leaves(root):
    for k in dsa.WrapDataObject(b).PointData.keys():
        blocks[k] = b
view = simple.GetActiveViewOrCreate("RenderView")
view.ViewSize = [900, 700]
try:
    view.UseColorPaletteForBackground = 0
except AttributeError:
    pass
view.Background = [1, 1, 1]
view.OrientationAxesVisibility = 0
if "zeta" in blocks:
    body = blocks["zeta"].NewInstance()
    body.DeepCopy(blocks["zeta"])
    if "u" in blocks and blocks["u"] is not blocks["zeta"] and \
            blocks["u"].GetNumberOfPoints() == body.GetNumberOfPoints():
        body.GetPointData().AddArray(blocks["u"].GetPointData().GetArray("u"))
    source = simple.TrivialProducer()
    source.GetClientSideObject().SetOutput(body)
    shown = simple.WarpByVector(Input=source, Vectors=["POINTS", "u"]) if "u" in blocks else source
    display = simple.Show(shown, view)
    simple.ColorBy(display, ("POINTS", "zeta"))
    lut = simple.GetColorTransferFunction("zeta")
    zmin = min(grids_value for g in grids.values() for grids_value in g["point_arrays"].get("zeta", [1.0]))
    lut.RescaleTransferFunction(min(zmin, 0.999), 1.0)
    display.SetScalarBarVisibility(view, True)
    bar = simple.GetScalarBar(lut, view)
    bar.Title = "zeta (1 = sound), deformed by u (x1)"
    bar.TitleColor = bar.LabelColor = [0, 0, 0]
    try:
        bar.RangeLabelFormat = "%.4g"
    except AttributeError:
        pass
else:
    simple.Show(reader, view)
simple.ResetCamera(view)
simple.Render(view)
simple.SaveScreenshot(frame_png, view, ImageResolution=[900, 700])
print(f"pvpython: {folder}: {len(times)} time steps, grids {sorted(grids)}")
