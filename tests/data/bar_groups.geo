// A bar of two physical surfaces bonded at x = 1 ("soft" x < 1, "stiff"
// x > 1), with named curves at both ends and on the interface and a named
// corner point, for the physical-group tests (test_gmsh.c, test_groups.c).
// gmsh -2 -format msh22 bar_groups.geo -o bar_groups_v22.msh (and msh41).
lc = 0.25;
Point(1) = {0, 0, 0, lc};
Point(2) = {1, 0, 0, lc};
Point(3) = {2, 0, 0, lc};
Point(4) = {2, 0.5, 0, lc};
Point(5) = {1, 0.5, 0, lc};
Point(6) = {0, 0.5, 0, lc};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 5};
Line(5) = {5, 6};
Line(6) = {6, 1};
Line(7) = {2, 5};
Curve Loop(1) = {1, 7, 5, 6};
Plane Surface(1) = {1};
Curve Loop(2) = {2, 3, 4, -7};
Plane Surface(2) = {2};
Physical Surface("soft") = {1};
Physical Surface("stiff") = {2};
Physical Surface("bar") = {1, 2};
Physical Curve("interface") = {7};
Physical Curve("left") = {6};
Physical Curve("right") = {3};
Physical Point("origin") = {1};
