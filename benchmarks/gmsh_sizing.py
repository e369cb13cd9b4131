"""What the Gmsh-made benchmark cases (bump3d_mesh.py, wing_mesh.py) share: tetrahedra sized by
the distance to the walls, written as a linear .msh 4.1 file."""


def mesh_near_walls(gmsh, out, walls, size_min, size_max, dist_min, dist_max):
    """Meshes the synchronized model with tetrahedra of size_min within dist_min of the surfaces
    `walls`, growing to size_max at dist_max and beyond (the boundary's own sizes ignored), and
    writes it to `out`."""
    field = gmsh.model.mesh.field
    distance = field.add("Distance")
    field.setNumbers(distance, "SurfacesList", walls)
    threshold = field.add("Threshold")
    field.setNumber(threshold, "InField", distance)
    field.setNumber(threshold, "SizeMin", size_min)
    field.setNumber(threshold, "SizeMax", size_max)
    field.setNumber(threshold, "DistMin", dist_min)
    field.setNumber(threshold, "DistMax", dist_max)
    field.setAsBackgroundMesh(threshold)
    gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
    gmsh.model.mesh.generate(3)
    gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
    gmsh.write(out)
