// A 50 x 100 mm rock block crossed by a set of three parallel joints at
// 30 degrees to the horizontal (the physical curve group "joints"), for
// examples/jointed-block.json: pulled apart along y, it fails along the
// set at the set's strength, not the rock's. The joints are the
// boundaries between four strips, so element edges lie on them; the strips
// form one physical surface, "rock". Regenerate the JSON with generate.py.
W = 0.05; H = 0.1; h = 2.5e-3;
t = Tan(30 * Pi / 180);
y0[] = {-0.025, 0, 0.025};
Point(1) = {-W/2, -H/2, 0, h};
Point(2) = {W/2, -H/2, 0, h};
Point(3) = {W/2, H/2, 0, h};
Point(4) = {-W/2, H/2, 0, h};
For k In {0:2}
  Point(10 + k) = {-W/2, y0[k] - W/2 * t, 0, h}; // left end of joint k
  Point(20 + k) = {W/2, y0[k] + W/2 * t, 0, h};  // right end
  Line(30 + k) = {10 + k, 20 + k};
EndFor
// right side, bottom to top, and left side, top to bottom
Line(1) = {2, 20}; Line(2) = {20, 21}; Line(3) = {21, 22}; Line(4) = {22, 3};
Line(5) = {4, 12}; Line(6) = {12, 11}; Line(7) = {11, 10}; Line(8) = {10, 1};
Line(9) = {1, 2}; Line(10) = {3, 4};
Curve Loop(1) = {9, 1, -30, 8}; Plane Surface(1) = {1};
Curve Loop(2) = {30, 2, -31, 7}; Plane Surface(2) = {2};
Curve Loop(3) = {31, 3, -32, 6}; Plane Surface(3) = {3};
Curve Loop(4) = {32, 4, 10, 5}; Plane Surface(4) = {4};
Physical Surface("rock") = {1, 2, 3, 4};
Physical Curve("joints") = {30, 31, 32};
Physical Curve("base") = {9};
Physical Curve("top") = {10};
Physical Point("corner") = {1};
Mesh.Algorithm = 6;
