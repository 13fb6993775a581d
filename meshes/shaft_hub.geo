// A shaft-hub shrink fit (Lame), quarter model by symmetry (x >= 0, y >= 0): the hollow shaft
// a <= r <= b + delta drawn overlapping the hub b <= r <= c by the radial interference
// delta (the scene file says interference = true: the drawn overlap is the fit). Symmetry
// supports: ux = 0 on x = 0, uy = 0 on y = 0. All quads, structured in each ring, the same
// number of elements along both quarter arcs (with different counts the chords of the two
// polygons sag by b dtheta^2 / 8, which must stay far below delta: docs/models.md).

DefineConstant[
  a = {0.5, Name "Parameters/a bore of the (hollow) shaft"},
  b = {2, Name "Parameters/b interface radius (the hub's bore)"},
  c = {4, Name "Parameters/c outer radius of the hub"},
  delta = {0.002, Name "Parameters/delta radial interference"},
  nr = {12, Name "Parameters/nr elements across each ring"},
  nt_in = {48, Name "Parameters/nt_in elements along the shaft's quarter arc"},
  nt_out = {48, Name "Parameters/nt_out elements along the hub's quarter arc"}
];

bs = b + delta;
Point(1) = {0, 0, 0};  // the centre (of both rings' arcs, on neither surface)

// Shaft (surface 1).
Point(2) = {a, 0, 0};
Point(3) = {bs, 0, 0};
Point(4) = {0, bs, 0};
Point(5) = {0, a, 0};
Line(1) = {2, 3};       // y = 0
Circle(2) = {3, 1, 4};  // outer arc: contact
Line(3) = {4, 5};       // x = 0
Circle(4) = {5, 1, 2};  // bore
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};

// Hub (surface 2): its own points and curves.
Point(12) = {b, 0, 0};
Point(13) = {c, 0, 0};
Point(14) = {0, c, 0};
Point(15) = {0, b, 0};
Line(11) = {12, 13};       // y = 0
Circle(12) = {13, 1, 14};  // outer arc: free
Line(13) = {14, 15};       // x = 0
Circle(14) = {15, 1, 12};  // bore: contact
Curve Loop(2) = {11, 12, 13, 14};
Plane Surface(2) = {2};

Transfinite Curve{1, 3, 11, 13} = nr + 1;
Transfinite Curve{2, 4} = nt_in + 1;
Transfinite Curve{12, 14} = nt_out + 1;
Transfinite Surface{1} = {2, 3, 4, 5};
Transfinite Surface{2} = {12, 13, 14, 15};
Recombine Surface{1, 2};

Physical Surface("shaft") = {1};
Physical Surface("hub") = {2};
Physical Curve("shaft_contact") = {2};
Physical Curve("hub_contact") = {14};
Physical Curve("sym_x") = {3, 13};
Physical Curve("sym_y") = {1, 11};
Physical Curve("bore") = {4};
Physical Curve("outside") = {12};
