// Uniaxial compression specimen, 25 x 50 mm (height = 2 x width), meshed by
// gmsh's Frontal-Delaunay algorithm at 1.5 mm so that joints run in every
// direction and a shear band is free to choose its angle.
// Regenerate examples/uniaxial-compression.json with generate.py.
W = 0.025; H = 0.05; h = 1.5e-3;
Point(1) = {-W/2, -H/2, 0, h}; Point(2) = {W/2, -H/2, 0, h};
Point(3) = {W/2, H/2, 0, h}; Point(4) = {-W/2, H/2, 0, h};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Mesh.Algorithm = 6;
