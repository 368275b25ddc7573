// Brazilian disc, D = 50 mm: gmsh's Frontal-Delaunay mesh at 2 mm gives
// joints in every direction, so a crack can follow the loaded diameter.
// A node sits exactly at the top and bottom of the disc, where the platens
// touch first. Regenerate examples/brazilian-disc.json with generate.py.
R = 0.025; h = 2.0e-3;
Point(1) = {0, 0, 0, h};
Point(2) = {R, 0, 0, h}; Point(3) = {0, R, 0, h};
Point(4) = {-R, 0, 0, h}; Point(5) = {0, -R, 0, h};
Circle(1) = {2, 1, 3}; Circle(2) = {3, 1, 4};
Circle(3) = {4, 1, 5}; Circle(4) = {5, 1, 2};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Mesh.Algorithm = 6;
