"""`read_stl_file` / `write_stl_file` of pythonocc's `OCC.Extend.DataExchange`, written
on OCP (StlAPI) for BladeX's shaft module."""
from OCP.BRepMesh import BRepMesh_IncrementalMesh
from OCP.StlAPI import StlAPI_Reader, StlAPI_Writer
from OCP.TopoDS import TopoDS_Shape


def read_stl_file(filename):
    shape = TopoDS_Shape()
    if not StlAPI_Reader().Read(shape, filename):
        raise IOError("cannot read " + filename)
    return shape


def write_stl_file(shape, filename, mode="ascii", linear_deflection=0.9, angular_deflection=0.5):
    BRepMesh_IncrementalMesh(shape, linear_deflection, False, angular_deflection, True).Perform()
    w = StlAPI_Writer()
    w.SetASCIIMode(mode == "ascii")
    if not w.Write(shape, filename):
        raise IOError("cannot write " + filename)
