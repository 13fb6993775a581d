// A press fit pushed out (axisymmetric, x = r, y the axis): a solid shaft 0 <= r <= b in a
// hub b <= r <= c of length Lh (0 <= y <= Lh), the shaft standing out above the hub by e
// (0 <= y <= Lh + e), drawn touching at r = b (the scene file prescribes the radial
// interference). Structured quads with the same division along both sides of the interface;
// the cells shrink towards the hub's two ends, where the fit's pressure departs from Lame's.
// Groups: the shaft's top face (pushed), the hub's bottom face (held axially), the axis.

DefineConstant[
  b = {1, Name "Parameters/b interface radius"},
  c = {2, Name "Parameters/c outer radius of the hub"},
  Lh = {8, Name "Parameters/Lh length of the hub"},
  e = {1, Name "Parameters/e the shaft's length above the hub"},
  nr = {6, Name "Parameters/nr cells across each body"},
  ny = {40, Name "Parameters/ny cells along the hub"},
  ne = {4, Name "Parameters/ne cells along the shaft above the hub"}
];

// Shaft inside the hub (surface 1) and above it (surface 2).
Point(1) = {0, 0, 0}; Point(2) = {b, 0, 0}; Point(3) = {b, Lh, 0}; Point(4) = {0, Lh, 0};
Point(5) = {b, Lh + e, 0}; Point(6) = {0, Lh + e, 0};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Line(5) = {3, 5}; Line(6) = {5, 6}; Line(7) = {6, 4};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Curve Loop(2) = {5, 6, 7, -3};
Plane Surface(2) = {2};

// Hub (surface 3): its own points and curves.
Point(12) = {b, 0, 0}; Point(13) = {c, 0, 0}; Point(14) = {c, Lh, 0}; Point(15) = {b, Lh, 0};
Line(11) = {12, 13}; Line(12) = {13, 14}; Line(13) = {14, 15}; Line(14) = {15, 12};
Curve Loop(3) = {11, 12, 13, 14};
Plane Surface(3) = {3};

Transfinite Curve{1, 3, 6, 11, 13} = nr + 1;
Transfinite Curve{2, 12} = ny + 1 Using Bump 0.25;
Transfinite Curve{4, 14} = ny + 1 Using Bump 0.25;
Transfinite Curve{5, 7} = ne + 1;
Transfinite Surface{1, 2, 3};
Recombine Surface{1, 2, 3};

Physical Surface("shaft") = {1, 2};
Physical Surface("hub") = {3};
Physical Curve("shaft_contact") = {2};
Physical Curve("hub_contact") = {14};
Physical Curve("shaft_top") = {6};
Physical Curve("hub_bottom") = {11};
Physical Curve("axis") = {4, 7};
