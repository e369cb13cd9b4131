// Small 2D boundary-layer mesh around a cylinder: thin curved layers make Gmsh's plain
// P2 snapping leave invalid triangles.
SetFactory("Built-in");
lc = 0.5;
Point(1) = {0, 0, 0, lc};
Point(2) = {0.5, 0, 0, 0.2}; Point(3) = {0, 0.5, 0, 0.2}; Point(4) = {-0.5, 0, 0, 0.2}; Point(5) = {0, -0.5, 0, 0.2};
Circle(1) = {2, 1, 3}; Circle(2) = {3, 1, 4}; Circle(3) = {4, 1, 5}; Circle(4) = {5, 1, 2};
Point(6) = {-1.2, -1.2, 0, lc}; Point(7) = {1.2, -1.2, 0, lc}; Point(8) = {1.2, 1.2, 0, lc}; Point(9) = {-1.2, 1.2, 0, lc};
Line(5) = {6, 7}; Line(6) = {7, 8}; Line(7) = {8, 9}; Line(8) = {9, 6};
Curve Loop(1) = {5, 6, 7, 8}; Curve Loop(2) = {1, 2, 3, 4};
Plane Surface(1) = {1, 2};
Physical Curve("wall") = {1, 2, 3, 4};
Physical Curve("farfield") = {5, 6, 7, 8};
Physical Surface("fluid") = {1};
Field[1] = BoundaryLayer;
Field[1].EdgesList = {1, 2, 3, 4};
Field[1].hwall_n = 0.002;
Field[1].thickness = 0.06;
Field[1].ratio = 1.5;
Field[1].hfar = 0.2;
Field[1].Quads = 1;
BoundaryLayer Field = 1;
Mesh.ElementOrder = 2;
Mesh.HighOrderOptimize = 0;
Mesh.MshFileVersion = 4.1;
