// Plate with a central hole for examples/gmsh-plate.json:
// 0.2 m (x, the loading direction) by 0.1 m, hole of radius 0.01 m.
// gmsh -2 -format msh22 plate.geo -o plate.msh
h = 0.008;      // element size at the outer edges
hh = 0.0025;    // element size on the hole
Point(1) = {0, 0, 0, h};
Point(2) = {0.2, 0, 0, h};
Point(3) = {0.2, 0.1, 0, h};
Point(4) = {0, 0.1, 0, h};
Point(5) = {0.1, 0.05, 0, hh};
Point(6) = {0.11, 0.05, 0, hh};
Point(7) = {0.1, 0.06, 0, hh};
Point(8) = {0.09, 0.05, 0, hh};
Point(9) = {0.1, 0.04, 0, hh};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Circle(5) = {6, 5, 7};
Circle(6) = {7, 5, 8};
Circle(7) = {8, 5, 9};
Circle(8) = {9, 5, 6};
Curve Loop(1) = {1, 2, 3, 4};
Curve Loop(2) = {5, 6, 7, 8};
Plane Surface(1) = {1, 2};
Physical Surface("plate") = {1};
