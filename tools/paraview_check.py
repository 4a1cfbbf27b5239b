"""In ParaView's pvpython: open a cohfrac ParaView series (cohfrac export
--format pvd), step to the last time and count the connected surface
pieces there (Connectivity filter; each fragment's surface is one piece).

    pvpython tools/paraview_check.py DIR/<name>.pvd

Prints "times N", "last T" and "pieces P"."""
import sys

from paraview.simple import Connectivity, PVDReader

reader = PVDReader(FileName=sys.argv[1])
reader.UpdatePipelineInformation()
times = list(reader.TimestepValues)
conn = Connectivity(Input=reader)
conn.UpdatePipeline(times[-1])
lo, hi = conn.CellData["RegionId"].GetRange()
print("times", len(times))
print("last", times[-1])
print("pieces", int(hi) + 1)
