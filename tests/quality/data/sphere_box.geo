// Small 3D mesh around a sphere in a box: curved tetrahedra against the sphere, for the
// orders 3 and 4 (`gmsh sphere_box.geo -3 -order 3` and `-order 4`).
SetFactory("OpenCASCADE");
Box(1) = {-1, -1, -1, 2, 2, 2};
Sphere(2) = {0, 0, 0, 0.5};
BooleanDifference{ Volume{1}; Delete; }{ Volume{2}; Delete; }
Mesh.MeshSizeMax = 1.2;
wall() = Surface In BoundingBox{-0.6, -0.6, -0.6, 0.6, 0.6, 0.6};
MeshSize{ PointsOf{ Surface{wall()}; } } = 0.45;
Physical Surface("wall") = wall();
Physical Surface("farfield") = Surface In BoundingBox{-1.1, -1.1, -1.1, 1.1, 1.1, 1.1};
Physical Volume("fluid") = {1};
Mesh.HighOrderOptimize = 0;
Mesh.MshFileVersion = 4.1;
