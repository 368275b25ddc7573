// A circular tunnel of radius a = 1 m at the centre of a 40 m square of
// rock, for examples/tunnel.json (a/B = 1/20 as in borehole.geo, whose
// layout this is at twenty times the size); elements of 5 cm on the
// tunnel wall growing to 2.5 m at the edges.
// gmsh -2 -format msh22 tunnel.geo -o tunnel.msh
B = 20;
a = 1;
h_out = 2.5;
h_bore = 0.05;
Point(1) = {-B, -B, 0, h_out};
Point(2) = {B, -B, 0, h_out};
Point(3) = {B, B, 0, h_out};
Point(4) = {-B, B, 0, h_out};
Point(5) = {0, 0, 0, h_bore};
Point(6) = {a, 0, 0, h_bore};
Point(7) = {0, a, 0, h_bore};
Point(8) = {-a, 0, 0, h_bore};
Point(9) = {0, -a, 0, h_bore};
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
Physical Surface("rock") = {1};
