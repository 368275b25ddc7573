// Disc of radius 1 with a central hole of radius 0.4 (an annulus), coarse:
// exercises curved boundaries, an inner loop and 4.1 entity blocks.
lc = 0.35;
Point(1) = {0, 0, 0, lc};
Point(2) = {1, 0, 0, lc};
Point(3) = {-1, 0, 0, lc};
Point(4) = {0.4, 0, 0, lc};
Point(5) = {-0.4, 0, 0, lc};
Circle(1) = {2, 1, 3};
Circle(2) = {3, 1, 2};
Circle(3) = {4, 1, 5};
Circle(4) = {5, 1, 4};
Curve Loop(1) = {1, 2};
Curve Loop(2) = {3, 4};
Plane Surface(1) = {1, 2};
