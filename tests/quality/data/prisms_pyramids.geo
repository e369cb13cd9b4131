// Prisms and pyramids with curved sides (python/tests/test_element_catalogue.py): a quarter
// annulus of triangles extruded into prisms, one of quadrilaterals extruded into hexahedra, and
// tetrahedra above the hexahedra, which Gmsh joins to their quadrilateral faces with pyramids.
lc = 0.35;
Point(1) = {0, 0, 0, lc}; Point(2) = {1, 0, 0, lc}; Point(3) = {0, 1, 0, lc};
Point(4) = {2, 0, 0, lc}; Point(5) = {0, 2, 0, lc};
Point(6) = {-1, 0, 0, lc}; Point(7) = {-2, 0, 0, lc};
Circle(1) = {2, 1, 3}; Line(2) = {3, 5}; Circle(3) = {5, 1, 4}; Line(4) = {4, 2};
Circle(5) = {6, 1, 3}; Line(6) = {6, 7}; Circle(7) = {7, 1, 5};
Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};
Curve Loop(2) = {-5, 6, 7, -2}; Plane Surface(2) = {2};
Recombine Surface{2};
Extrude {0, 0, 0.5} { Surface{1}; Layers{2}; Recombine; }
hexes[] = Extrude {0, 0, 0.5} { Surface{2}; Layers{2}; Recombine; };
Extrude {0, 0, 0.6} { Surface{hexes[0]}; }
