// Axisymmetric shaft-hub press fit (x = r, y the axis): a solid steel shaft r <= b + delta,
// |y| <= L, drawn overlapping by the radial interference delta a steel hub b <= r <= c,
// |y| <= H, H < L (the shaft is longer than the hub: both hub edges are sharp 90-degree
// corners pressed on the shaft, the same edge twice by symmetry about y = 0). Sizes grow from
// hc at the two hub edges (b, +-H) by `slope` per unit distance up to h_far, in both bodies.
// The shaft's contact curve has a node at y = +-(H + f hc): f_top, f_bot in [0, 1) move the
// shaft's nodes across the hub's ends by a fraction of an edge cell (0 = a node on the end).
// Supports: ux = 0 on the axis; uy = 0 at one point of each body on y = 0 (frictionless
// contact holds nothing axially; by symmetry these points carry no load).

DefineConstant[
  b = {1, Name "Parameters/b interface radius (the hub's bore)"},
  c = {2, Name "Parameters/c outer radius of the hub"},
  H = {0.5, Name "Parameters/H half length of the hub"},
  L = {1.5, Name "Parameters/L half length of the shaft"},
  delta = {0.001, Name "Parameters/delta radial interference"},
  hc = {0.005, Name "Parameters/hc size at the hub's edges"},
  slope = {0.05, Name "Parameters/slope size growth per unit distance"},
  h_far = {0.02, Name "Parameters/h_far largest size"},
  f_top = {0, Name "Parameters/f_top shaft node beyond the top edge, in edge cells"},
  f_bot = {0, Name "Parameters/f_bot shaft node beyond the bottom edge, in edge cells"}
];

bs = b + delta;
// Shaft (surface 1): the contact curve r = bs split where its nodes are pinned.
Point(1) = {0, -L, 0};
Point(2) = {bs, -L, 0};
Point(3) = {bs, -H - f_bot * hc, 0};
Point(4) = {bs, H + f_top * hc, 0};
Point(5) = {bs, L, 0};
Point(6) = {0, L, 0};
Point(7) = {0, 0, 0};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 5};
Line(5) = {5, 6};
Line(6) = {6, 7};
Line(7) = {7, 1};
Curve Loop(1) = {1, 2, 3, 4, 5, 6, 7};
Plane Surface(1) = {1};

// Hub (surface 2): its own points and curves.
Point(11) = {b, -H, 0};
Point(12) = {c, -H, 0};
Point(13) = {c, 0, 0};
Point(14) = {c, H, 0};
Point(15) = {b, H, 0};
Line(11) = {11, 12};
Line(12) = {12, 13};
Line(13) = {13, 14};
Line(14) = {14, 15};
Line(15) = {15, 11};  // bore: contact
Curve Loop(2) = {11, 12, 13, 14, 15};
Plane Surface(2) = {2};

Field[1] = MathEval;
Field[1].F = Sprintf("Min(%.17g, %.17g + %.17g * Min(Sqrt((x - %.17g)^2 + (y - %.17g)^2), Sqrt((x - %.17g)^2 + (y + %.17g)^2)))", h_far, hc, slope, b, H, b, H);
Background Field = 1;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
Mesh.Algorithm = 8;
Mesh.RecombinationAlgorithm = 3;
Mesh.RecombineAll = 1;
Recombine Surface{1, 2};

Physical Surface("shaft") = {1};
Physical Surface("hub") = {2};
Physical Curve("shaft_contact") = {2, 3, 4};
Physical Curve("hub_contact") = {15};
Physical Curve("axis") = {6, 7};
Physical Point("shaft_mid") = {7};
Physical Point("hub_mid") = {13};
