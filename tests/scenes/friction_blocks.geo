// A block pressed and pushed on a wider base (the frictional scenes' test geometry).
//
// base [0, 2] x [0, 1] with 8 x 4 quads, block [0.5, 1.5] x [1, 2] with 6 x 6 quads: the
// contact interface's nodes do not match (spacing 1/4 against 1/6). Structured quads.
// Groups: base, block; base_bottom/top/left/right, block_bottom/top/left/right.

Point(1) = {0, 0, 0};
Point(2) = {2, 0, 0};
Point(3) = {2, 1, 0};
Point(4) = {0, 1, 0};
Point(5) = {0.5, 1, 0};
Point(6) = {1.5, 1, 0};
Point(7) = {1.5, 2, 0};
Point(8) = {0.5, 2, 0};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Line(5) = {5, 6};
Line(6) = {6, 7};
Line(7) = {7, 8};
Line(8) = {8, 5};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Curve Loop(2) = {5, 6, 7, 8};
Plane Surface(2) = {2};
Transfinite Curve{1, 3} = 9;
Transfinite Curve{2, 4} = 5;
Transfinite Curve{5, 6, 7, 8} = 7;
Transfinite Surface{1, 2};
Recombine Surface{1, 2};
Physical Surface("base") = {1};
Physical Surface("block") = {2};
Physical Curve("base_bottom") = {1};
Physical Curve("base_right") = {2};
Physical Curve("base_top") = {3};
Physical Curve("base_left") = {4};
Physical Curve("block_bottom") = {5};
Physical Curve("block_right") = {6};
Physical Curve("block_top") = {7};
Physical Curve("block_left") = {8};
