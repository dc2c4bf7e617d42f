"""An unstructured tetrahedral mesh around the sample hull, made by gmsh from the STEP
file (its OpenCASCADE kernel), for crates/mesh/tests/gmsh_hull.rs.

    python hull_tets.py HULL.stp OUT.msh

The domain is the box x 0..300, y 0..40, z -30..12.5 m (in the file's metres): the half
hull's open borders lie on its faces (the centreplane y = 0, the deck z = 12.5, the
transom x = 0), so fragmenting the box by the hull's three faces cuts it into the hull's
inside and the fluid around it; the inside is removed. Element size 8 m, 2 m on the hull.
MSH 4.1, elements of the physical groups "fluid" (tetrahedra), "hull" and "outer"
(triangles); each triangle block carries its surface's tag. Prints JSON: the hull's and
the other surfaces' tags and the element counts."""
import json
import sys
import gmsh

src, dst = sys.argv[1], sys.argv[2]
gmsh.initialize()
gmsh.option.setNumber("General.Terminal", 0)
gmsh.option.setString("Geometry.OCCTargetUnit", "M")
hull = [d for d in gmsh.model.occ.importShapes(src) if d[0] == 2]
box = gmsh.model.occ.addBox(0, 0, -30, 300, 40, 42.5)
_, maps = gmsh.model.occ.fragment([(3, box)], hull)
gmsh.model.occ.synchronize()
vols = sorted(gmsh.model.getEntities(3), key=lambda v: gmsh.model.occ.getMass(*v))
if len(vols) != 2:
    sys.exit(f"the hull does not cut the box in two ({len(vols)} volumes)")
inner, fluid = vols
hull_faces = sorted({t for m in maps[1:] for (d, t) in m if d == 2})
gmsh.model.removeEntities([inner])
outer = [t for (_, t) in gmsh.model.getBoundary([fluid], oriented=False) if t not in hull_faces]
gmsh.model.addPhysicalGroup(3, [fluid[1]], name="fluid")
gmsh.model.addPhysicalGroup(2, hull_faces, name="hull")
gmsh.model.addPhysicalGroup(2, outer, name="outer")
gmsh.option.setNumber("Mesh.MeshSizeMax", 8.0)
gmsh.model.mesh.setSize(gmsh.model.getEntities(0), 8.0)
gmsh.model.mesh.setSize(gmsh.model.getBoundary([(2, t) for t in hull_faces], combined=False, recursive=True), 2.0)
gmsh.model.mesh.generate(3)
gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
gmsh.write(dst)
count = lambda dim: sum(len(t) for t in gmsh.model.mesh.getElements(dim)[1])
print(json.dumps({"hull": hull_faces, "outer": outer, "tetrahedra": count(3), "triangles": count(2)}))
gmsh.finalize()
