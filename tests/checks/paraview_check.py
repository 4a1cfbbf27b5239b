"""In ParaView's pvpython: open a cohfrac ParaView series (cohfrac export
--format pvd), step to the last time and count the connected surface
pieces there (Connectivity filter; each fragment's surface is one piece);
then find the first time that holds deformed tets of fracture mode and
measure them (CellSize filter) and their fields.

    pvpython tests/checks/paraview_check.py DIR/<name>.pvd [OUT.xdmf]

Prints "times N", "last T", "pieces P" and, when the series has
fracture-mode tets, "fracture T0 TETS VOLUME DAMAGE_MAX VON_MISES_MAX"
(s, count, m3, -, Pa); with the run's XDMF sidecar also "xdmf TETS VOLUME":
the tets and their volume that the sidecar's fracture_mode grid holds at
T0."""
import sys

from paraview import servermanager
from paraview.simple import CellSize, Connectivity, OpenDataFile, PVDReader

VTK_TETRA = 10

reader = PVDReader(FileName=sys.argv[1])
reader.UpdatePipelineInformation()
times = list(reader.TimestepValues)
conn = Connectivity(Input=reader)
conn.UpdatePipeline(times[-1])
lo, hi = conn.CellData["RegionId"].GetRange()
print("times", len(times))
print("last", times[-1])
print("pieces", int(hi) + 1)

size = CellSize(Input=reader)
for t in times:
    size.UpdatePipeline(t)
    grid = servermanager.Fetch(size)
    tets = [c for c in range(grid.GetNumberOfCells()) if grid.GetCellType(c) == VTK_TETRA]
    if not tets:
        continue
    cd = grid.GetCellData()
    vol, dmg, vm = cd.GetArray("Volume"), cd.GetArray("damage"), cd.GetArray("von_mises")
    print("fracture", t, len(tets), sum(vol.GetValue(c) for c in tets),
          max(dmg.GetValue(c) for c in tets), max(vm.GetValue(c) for c in tets))
    if len(sys.argv) > 2:
        xsize = CellSize(Input=OpenDataFile(sys.argv[2]))
        xsize.UpdatePipeline(t)
        blocks = servermanager.Fetch(xsize)
        it = blocks.NewIterator()
        it.InitTraversal()
        while not it.IsDoneWithTraversal():
            b = it.GetCurrentDataObject()
            n = b.GetNumberOfCells()
            if n and b.GetCellType(0) == VTK_TETRA:
                v = b.GetCellData().GetArray("Volume")
                print("xdmf", n, sum(v.GetValue(c) for c in range(n)))
            it.GoToNextItem()
    break
