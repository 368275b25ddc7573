// Unit cube, coarse, for tests/unit/test_gmsh.c (4-node tetrahedra):
//   gmsh -3 cube.geo -format msh22 -o cube_v22.msh
//   gmsh -3 cube.geo -format msh41 -o cube_v41.msh
lc = 0.5;
Point(1) = {0, 0, 0, lc};
Point(2) = {1, 0, 0, lc};
Point(3) = {1, 1, 0, lc};
Point(4) = {0, 1, 0, lc};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Extrude {0, 0, 1} { Surface{1}; }
