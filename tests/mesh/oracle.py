"""Independent mesh readers/writers for the cadmorph-mesh cross-read tests (run with the
venv of setup.sh).

    python oracle.py make DIR      gmsh: a tetrahedral mesh of a box with a spherical
                                   hole; meshio writes it in every format into DIR
    python oracle.py read FILE     meshio reads FILE; prints JSON {points, cells}
"""
import json
import sys


def make(out):
    import gmsh
    import meshio

    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.model.add("box")
    box = gmsh.model.occ.addBox(0, 0, 0, 2, 1, 1)
    ball = gmsh.model.occ.addSphere(1, 0.5, 0.5, 0.25)
    gmsh.model.occ.cut([(3, box)], [(3, ball)])
    gmsh.model.occ.synchronize()
    gmsh.option.setNumber("Mesh.MeshSizeMax", 0.2)
    gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 16)
    gmsh.model.mesh.generate(3)
    for version, name in [(2.2, "box22.msh"), (4.1, "box41.msh")]:
        gmsh.option.setNumber("Mesh.MshFileVersion", version)
        gmsh.option.setNumber("Mesh.Binary", 0)
        gmsh.write(f"{out}/{name}")
    gmsh.finalize()
    m = meshio.read(f"{out}/box22.msh")
    tets = [c for c in m.cells if c.type == "tetra"]
    tris = [c for c in m.cells if c.type == "triangle"]
    vol = meshio.Mesh(m.points, tets)
    meshio.write(f"{out}/box.vtk", vol, binary=False)
    surf = meshio.Mesh(m.points, tris)
    meshio.write(f"{out}/box.obj", surf)
    meshio.write(f"{out}/box_ascii.stl", surf, binary=False)
    meshio.write(f"{out}/box_bin.stl", surf, binary=True)
    meshio.write(f"{out}/box.mdpa", vol)
    meshio.write(f"{out}/box_zlib.vtu", vol)
    meshio.write(f"{out}/box_b64.vtu", vol, compression=None)
    meshio.write(f"{out}/box_ascii.vtu", vol, binary=False)


def read(path):
    import meshio

    fmt = None
    if path.endswith(".nodes"):
        raise SystemExit("no meshio reader for Elmer")
    m = meshio.read(path, file_format=fmt)
    cells = {}
    for c in m.cells:
        cells[c.type] = cells.get(c.type, 0) + len(c.data)
    print(json.dumps({"points": m.points.tolist(), "cells": cells}))


if __name__ == "__main__":
    if sys.argv[1] == "make":
        make(sys.argv[2])
    else:
        read(sys.argv[2])
