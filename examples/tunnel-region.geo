// A 10 m diameter opening at the centre of a 30 m square of rock, for
// examples/tunnel-region.json: an annulus 5 m < r < 9 m around the opening
// is its own physical surface ("near field", where the rock may fracture),
// bonded to the rest ("far field"); elements of 0.25 m on the wall, 0.5 m
// at r = 9 m, 2 m at the edges.
// gmsh -2 -format msh22 tunnel-region.geo -o tunnel-region.msh
B = 15;
a = 5;
b = 9;
h_out = 2;
h_ring = 0.5;
h_wall = 0.25;
Point(1) = {-B, -B, 0, h_out};
Point(2) = {B, -B, 0, h_out};
Point(3) = {B, B, 0, h_out};
Point(4) = {-B, B, 0, h_out};
Point(5) = {0, 0, 0, h_wall};
Point(6) = {a, 0, 0, h_wall};
Point(7) = {0, a, 0, h_wall};
Point(8) = {-a, 0, 0, h_wall};
Point(9) = {0, -a, 0, h_wall};
Point(10) = {b, 0, 0, h_ring};
Point(11) = {0, b, 0, h_ring};
Point(12) = {-b, 0, 0, h_ring};
Point(13) = {0, -b, 0, h_ring};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Circle(5) = {6, 5, 7};
Circle(6) = {7, 5, 8};
Circle(7) = {8, 5, 9};
Circle(8) = {9, 5, 6};
Circle(9) = {10, 5, 11};
Circle(10) = {11, 5, 12};
Circle(11) = {12, 5, 13};
Circle(12) = {13, 5, 10};
Curve Loop(1) = {1, 2, 3, 4};
Curve Loop(2) = {5, 6, 7, 8};
Curve Loop(3) = {9, 10, 11, 12};
Plane Surface(1) = {1, 3};
Plane Surface(2) = {3, 2};
Physical Surface("far field") = {1};
Physical Surface("near field") = {2};
