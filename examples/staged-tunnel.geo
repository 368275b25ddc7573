// A circular tunnel (radius a = 2.5 m) driven through a 30 m square of
// jointed rock under gravity and a K0 = 1.5 in-situ stress, for
// examples/staged-tunnel.json. Three surfaces: "excavation" (the tunnel's
// rock, removed at stage 2), "near" (the annulus a < r < R = 7 m that may
// fracture) and "far" (elastic, bonded on shared nodes); two joint sets
// cross the near field ("set_a" dipping 60 degrees, "set_b" dipping 120),
// 1.25 m apart, so that a wedge can fall from the roof. OpenCASCADE splits
// crossing joints at their intersections and embeds them in the annulus.
// gmsh -2 -format msh22 staged-tunnel.geo -o staged-tunnel.msh
SetFactory("OpenCASCADE");
B = 15; a = 2.5; R = 7;
h_far = 2.0; h_near = 0.3; gap = 0.15; spacing = 1.25;
Rectangle(1) = {-B, -B, 0, 2 * B, 2 * B};
Disk(2) = {0, 0, 0, R};
Disk(3) = {0, 0, 0, a};
// Joint k of a set with unit direction (c, s) lies at signed distance
// d_k = k spacing from the centre; its chord of the circle R - gap, and
// where it crosses the opening, the two pieces outside a + gap.
p = 100; l = 100; la = 0; lb = 0;
For set In {0:1}
  angle = (set == 0 ? 60 : 120) * Pi / 180;
  c = Cos(angle); s = Sin(angle);
  For k In {-5:5}
    d = k * spacing;
    If (Fabs(d) < R - gap - 0.2)
      half = Sqrt((R - gap)^2 - d^2);
      px = -s * d; py = c * d;
      If (Fabs(d) < a + gap)
        inner = Sqrt((a + gap)^2 - d^2);
        Point(p) = {px - half * c, py - half * s, 0}; Point(p + 1) = {px - inner * c, py - inner * s, 0};
        Point(p + 2) = {px + inner * c, py + inner * s, 0}; Point(p + 3) = {px + half * c, py + half * s, 0};
        Line(l) = {p, p + 1}; Line(l + 1) = {p + 2, p + 3};
        If (set == 0) ja[la] = l; ja[la + 1] = l + 1; la += 2; EndIf
        If (set == 1) jb[lb] = l; jb[lb + 1] = l + 1; lb += 2; EndIf
        p += 4; l += 2;
      Else
        Point(p) = {px - half * c, py - half * s, 0}; Point(p + 1) = {px + half * c, py + half * s, 0};
        Line(l) = {p, p + 1};
        If (set == 0) ja[la] = l; la += 1; EndIf
        If (set == 1) jb[lb] = l; lb += 1; EndIf
        p += 2; l += 1;
      EndIf
    EndIf
  EndFor
EndFor
out() = BooleanFragments{ Surface{1}; Delete; }{ Surface{2, 3}; Curve{ja(), jb()}; Delete; };
e = 1e-3;
hole() = Surface In BoundingBox{-a - e, -a - e, -e, a + e, a + e, e};
disc() = Surface In BoundingBox{-R - e, -R - e, -e, R + e, R + e, e};
near() = disc(); near() -= hole();
far() = Surface{:}; far() -= disc();
Physical Surface("far") = far();
Physical Surface("near") = near();
Physical Surface("excavation") = hole();
all_curves() = Curve In BoundingBox{-R + gap / 2, -R + gap / 2, -e, R - gap / 2, R - gap / 2, e};
wall() = Abs(Boundary{ Surface{hole()}; });
all_curves() -= wall();
Physical Curve("joints") = all_curves();
Physical Curve("left") = Curve In BoundingBox{-B - e, -B - e, -e, -B + e, B + e, e};
Physical Curve("right") = Curve In BoundingBox{B - e, -B - e, -e, B + e, B + e, e};
Physical Curve("top") = Curve In BoundingBox{-B - e, B - e, -e, B + e, B + e, e};
Physical Curve("base") = Curve In BoundingBox{-B - e, -B - e, -e, B + e, -B + e, e};
MeshSize{ PointsOf{ Surface{far()}; } } = h_far;
MeshSize{ PointsOf{ Surface{near()}; Curve{all_curves()}; } } = h_near;
MeshSize{ PointsOf{ Surface{hole()}; } } = h_near;
Mesh.Algorithm = 6;
