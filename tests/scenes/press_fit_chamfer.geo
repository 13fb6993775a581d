// Axisymmetric shaft-hub press fit with a chamfer at the hub's bore edge (x = r, y the axis),
// half model by symmetry at y = 0. The solid shaft, radius R + delta, runs to y = Ls beyond
// the hub (bore R, outer radius Rh, half length Lh); the shaft is drawn overlapping the hub
// by the radial interference delta (the scene file says interference = true). The hub's
// bore ends in a 45-degree chamfer of leg c: the contact ends at the chamfer's corner
// (R, Lh - c), inside the hub's contact surface (bore and chamfer), where the pressure peaks.
// One size h everywhere, hc within r_fine of that corner (an ungraded start for adapt).

DefineConstant[
  R = {1, Name "Parameters/R bore of the hub"},
  delta = {0.001, Name "Parameters/delta radial interference"},
  Rh = {2, Name "Parameters/Rh outer radius of the hub"},
  Lh = {1, Name "Parameters/Lh half length of the hub"},
  Ls = {2.5, Name "Parameters/Ls half length of the shaft"},
  c = {0.1, Name "Parameters/c chamfer leg"},
  h = {0.1, Name "Parameters/h size"},
  hc = {0.025, Name "Parameters/hc size near the chamfer's corner"},
  r_fine = {0.3, Name "Parameters/r_fine radius of the finer zone"}
];

Rs = R + delta;

// Shaft (surface 1).
Point(1) = {0, 0, 0}; Point(2) = {Rs, 0, 0}; Point(3) = {Rs, Ls, 0}; Point(4) = {0, Ls, 0};
Line(1) = {1, 2};  // symmetry plane
Line(2) = {2, 3};  // outer surface: contact
Line(3) = {3, 4};  // end: free
Line(4) = {4, 1};  // axis
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};

// Hub (surface 2).
Point(11) = {R, 0, 0}; Point(12) = {Rh, 0, 0}; Point(13) = {Rh, Lh, 0};
Point(14) = {R + c, Lh, 0}; Point(15) = {R, Lh - c, 0};
Line(11) = {11, 12};  // symmetry plane
Line(12) = {12, 13};  // outside: free
Line(13) = {13, 14};  // end face: free
Line(14) = {14, 15};  // chamfer: contact (the shaft leaves it)
Line(15) = {15, 11};  // bore: contact
Curve Loop(2) = {11, 12, 13, 14, 15};
Plane Surface(2) = {2};

Field[1] = MathEval;
Field[1].F = Sprintf("Min(%.17g, %.17g + (%.17g - %.17g) * Sqrt((x - %.17g)^2 + (y - %.17g)^2) / %.17g)",
                     h, hc, h, hc, R, Lh - c, r_fine);
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
Physical Curve("shaft_contact") = {2};
Physical Curve("hub_contact") = {14, 15};
Physical Curve("symmetry") = {1, 11};
Physical Curve("axis") = {4};
Physical Curve("shaft_end") = {3};
Physical Curve("hub_outside") = {12, 13};
