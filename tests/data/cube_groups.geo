// Two unit cubes bonded at x = 1 ("soft" x < 1, "stiff" x > 1), with named
// end faces, the interface surface and a corner point, for the 3D
// physical-group tests. gmsh -3 -format msh22 / msh41.
SetFactory("OpenCASCADE");
Mesh.CharacteristicLengthMax = 0.5;
Box(1) = {0, 0, 0, 1, 1, 1};
Box(2) = {1, 0, 0, 1, 1, 1};
BooleanFragments{ Volume{1}; Delete; }{ Volume{2}; Delete; }
Physical Volume("soft") = {1};
Physical Volume("stiff") = {2};
Physical Surface("interface") = Surface In BoundingBox{0.99, -0.01, -0.01, 1.01, 1.01, 1.01};
Physical Surface("left") = Surface In BoundingBox{-0.01, -0.01, -0.01, 0.01, 1.01, 1.01};
Physical Surface("right") = Surface In BoundingBox{1.99, -0.01, -0.01, 2.01, 1.01, 1.01};
Physical Point("origin") = Point In BoundingBox{-0.01, -0.01, -0.01, 0.01, 0.01, 0.01};
