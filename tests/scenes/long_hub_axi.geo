// An axisymmetric shrink fit (Lame, open-ended long cylinder): a solid steel shaft
// 0 <= r <= b in a hub b <= r <= c, both of half-length L (the mid-plane y = 0 is a
// symmetry plane, the ends y = L are free), drawn touching at r = b (the scene file
// prescribes the radial interference). Structured quads, the same division along both
// sides of the interface; the cells shrink towards the free end, where the fit's pressure
// departs from Lame's.

DefineConstant[
  b = {1, Name "Parameters/b interface radius"},
  c = {2, Name "Parameters/c outer radius of the hub"},
  L = {6, Name "Parameters/L half-length"},
  nr = {6, Name "Parameters/nr cells across each body"},
  ny = {30, Name "Parameters/ny cells along the length"}
];

Point(1) = {0, 0, 0}; Point(2) = {b, 0, 0}; Point(3) = {b, L, 0}; Point(4) = {0, L, 0};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};

Point(12) = {b, 0, 0}; Point(13) = {c, 0, 0}; Point(14) = {c, L, 0}; Point(15) = {b, L, 0};
Line(11) = {12, 13}; Line(12) = {13, 14}; Line(13) = {14, 15}; Line(14) = {15, 12};
Curve Loop(2) = {11, 12, 13, 14};
Plane Surface(2) = {2};

Transfinite Curve{1, 3, 11, 13} = nr + 1;
Transfinite Curve{2, 12} = ny + 1 Using Progression 0.96;
Transfinite Curve{4, 14} = ny + 1 Using Progression 1 / 0.96;
Transfinite Surface{1, 2};
Recombine Surface{1, 2};

Physical Surface("shaft") = {1};
Physical Surface("hub") = {2};
Physical Curve("shaft_contact") = {2};
Physical Curve("hub_contact") = {14};
Physical Curve("mid_plane") = {1, 11};
