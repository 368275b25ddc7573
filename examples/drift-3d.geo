// A drift (radius a = 1 m, axis along y) through a 12 x 1 x 12 m slice of
// jointed rock under gravity (z up) and a K0 = 1.5 in-situ stress, for
// examples/drift-3d.json. Three volumes: "excavation" (the drift's rock,
// removed at stage 2), "near" (the shell a < r < R = 3 m that may
// fracture) and "far" (elastic, bonded on shared nodes); two joint sets
// striking along the drift ("set_a" dipping 60 degrees, "set_b" 120), 1 m
// apart (none tangent to the drift: such a plane leaves slivers that set a
// step hundreds of times smaller), cut to the near field, so that a wedge
// can fall from the roof.
// gmsh -3 -format msh22 drift-3d.geo -o drift-3d.msh
SetFactory("OpenCASCADE");
B = 6; L = 1; a = 1; R = 3;
h_far = 2.0; h_near = 0.5; spacing = 1;
Box(1) = {-B, 0, -B, 2 * B, L, 2 * B};
Cylinder(2) = {0, 0, 0, 0, L, 0, R};
Cylinder(3) = {0, 0, 0, 0, L, 0, a};
// each joint: a plane through the line (x, z) = d (-sin, cos) along y,
// dipping at `angle` in the x-z plane, cut to the near field's cylinder
n = 0; s = 100;
For set In {0:1}
  angle = (set == 0 ? 60 : 120) * Pi / 180;
  For k In {-2:1}
    d = (k + 0.5) * spacing; // none tangent to the drift (|d| = a) or meeting at r = R
    Rectangle(s) = {-2 * R, 0, 0, 4 * R, L};            // in the x-y plane: it holds the drift axis
    Rotate {{0, 1, 0}, {0, 0, 0}, -angle} { Surface{s}; }
    Translate {-Sin(angle) * d, 0, Cos(angle) * d} { Surface{s}; }
    planes[n] = s; n += 1; s += 1;
  EndFor
EndFor
// cut to the shell a < r < R: joints inside the drift would only leave
// slivers in rock that is excavated anyway
Cylinder(4) = {0, 0, 0, 0, L, 0, R};
Cylinder(5) = {0, 0, 0, 0, L, 0, a};
shell_only() = BooleanDifference{ Volume{4}; Delete; }{ Volume{5}; Delete; };
cut() = BooleanIntersection{ Surface{planes()}; Delete; }{ Volume{shell_only()}; Delete; };
out() = BooleanFragments{ Volume{1}; Delete; }{ Volume{2, 3}; Surface{cut()}; Delete; };
e = 1e-3;
hole() = Volume In BoundingBox{-a - e, -e, -a - e, a + e, L + e, a + e};
shell() = Volume In BoundingBox{-R - e, -e, -R - e, R + e, L + e, R + e};
near() = shell(); near() -= hole();
far() = Volume{:}; far() -= shell();
Physical Volume("far") = far();
Physical Volume("near") = near();
Physical Volume("excavation") = hole();
// the joints: surfaces inside the shell's box that span its length (not
// the end caps), are not one of the two cylinders (a box of +-R or +-a)
// and lie outside the drift
candidates() = Surface In BoundingBox{-R - e, -e, -R - e, R + e, L + e, R + e};
inside() = {};
For i In {0:#candidates() - 1}
  bb() = BoundingBox Surface{candidates(i)};
  spans = bb(4) - bb(1) > L - e;
  cylinder = Fabs(bb(3) - bb(0) - 2 * R) < e || Fabs(bb(3) - bb(0) - 2 * a) < e;
  in_drift = bb(0) > -a - e && bb(3) < a + e && bb(2) > -a - e && bb(5) < a + e;
  If (spans && !cylinder && !in_drift)
    inside() += candidates(i);
  EndIf
EndFor
Physical Surface("joints") = inside();
Physical Surface("left") = Surface In BoundingBox{-B - e, -e, -B - e, -B + e, L + e, B + e};
Physical Surface("right") = Surface In BoundingBox{B - e, -e, -B - e, B + e, L + e, B + e};
Physical Surface("top") = Surface In BoundingBox{-B - e, -e, B - e, B + e, L + e, B + e};
Physical Surface("base") = Surface In BoundingBox{-B - e, -e, -B - e, B + e, L + e, -B + e};
Physical Surface("front") = Surface In BoundingBox{-B - e, -e, -B - e, B + e, e, B + e};
Physical Surface("back") = Surface In BoundingBox{-B - e, L - e, -B - e, B + e, L + e, B + e};
MeshSize{ PointsOf{ Volume{far()}; } } = h_far;
MeshSize{ PointsOf{ Volume{near()}; Volume{hole()}; } } = h_near;
Mesh.Optimize = 1;
