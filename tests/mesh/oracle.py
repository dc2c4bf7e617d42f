"""Independent mesh readers/writers for the cadmorph-mesh cross-read tests (run with the
venv of setup.sh).

    python oracle.py make DIR      gmsh: a tetrahedral mesh of a box with a spherical
                                   hole; meshio writes it in every format into DIR
    python oracle.py read FILE     meshio reads FILE; prints JSON {points, cells}
    python oracle.py gmsh FILE     gmsh reads FILE (e.g. I-DEAS UNV); prints JSON
                                   {points (by node tag), cells}
    python oracle.py dyna FILE     Ansys PyDyna's keyword deck reads an LS-DYNA .k FILE;
                                   prints JSON {points (file order), cells}

`make` also writes box.unv (gmsh's UNV writer) and box.k (PyDyna's deck writer: the
tetrahedra as *ELEMENT_SOLID in LS-DYNA's degenerate-hexahedron form).
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
    gmsh.write(f"{out}/box.unv")
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
    write_dyna(f"{out}/box.k", m.points, tets[0].data)


def write_dyna(path, points, tets):
    import pandas as pd
    from ansys.dyna.core import Deck, keywords as kwd

    node = kwd.Node()
    node.nodes = pd.DataFrame(
        {"nid": range(1, len(points) + 1), "x": points[:, 0], "y": points[:, 1], "z": points[:, 2]}
    )
    solid = kwd.ElementSolid()
    cols = {"eid": range(1, len(tets) + 1), "pid": [1] * len(tets)}
    for k in range(8):
        cols[f"n{k + 1}"] = tets[:, min(k, 3)] + 1
    solid.elements = pd.DataFrame(cols)
    deck = Deck()
    deck.extend([node, solid])
    with open(path, "w") as f:
        f.write(deck.write())


def gmsh_read(path):
    import gmsh

    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.open(path)
    tags, coords, _ = gmsh.model.mesh.getNodes()
    order = sorted(range(len(tags)), key=lambda i: tags[i])
    points = [[coords[3 * i], coords[3 * i + 1], coords[3 * i + 2]] for i in order]
    names = {2: "triangle", 3: "quad", 4: "tetra", 5: "hexahedron", 1: "line", 15: "vertex"}
    cells = {}
    types, etags, _ = gmsh.model.mesh.getElements()
    for t, e in zip(types, etags):
        name = names.get(int(t), f"gmsh{int(t)}")
        cells[name] = cells.get(name, 0) + len(e)
    gmsh.finalize()
    print(json.dumps({"points": points, "cells": cells}))


def dyna_read(path):
    from ansys.dyna.core import Deck

    deck = Deck()
    with open(path) as f:
        deck.loads(f.read())
    points, cells = [], {}
    for k in deck.keywords:
        name = type(k).__name__
        if name == "Node":
            points += k.nodes[["x", "y", "z"]].astype(float).values.tolist()
        elif name == "ElementShell":
            for row in k.elements[["n1", "n2", "n3", "n4"]].values.tolist():
                kind = "triangle" if row[3] == row[2] or row[3] == 0 else "quad"
                cells[kind] = cells.get(kind, 0) + 1
        elif name == "ElementSolid":
            for row in k.elements[[f"n{i}" for i in range(1, 9)]].values.tolist():
                kind = "tetra" if len(set(row[3:])) == 1 else "hexahedron"
                cells[kind] = cells.get(kind, 0) + 1
    print(json.dumps({"points": points, "cells": cells}))


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
    op = {"make": make, "read": read, "gmsh": gmsh_read, "dyna": dyna_read}[sys.argv[1]]
    op(sys.argv[2])
