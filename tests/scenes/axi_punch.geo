// Axisymmetric flat punch (Boussinesq): a cylindrical block [0, W] x [-H, 0] (x = r, y the
// axis) whose top is pressed by a rigid flat cylindrical punch of radius a (an [[obstacle]]
// plane facing the curve "punched", r <= a; the rest of the top is free). The sizes come
// from the distance to the punch's edge (a, 0): hc within r_fine of it, growing by `slope`.

DefineConstant[
  a = {1, Name "Parameters/a punch radius"},
  W = {15, Name "Parameters/W block radius"},
  H = {15, Name "Parameters/H block height"},
  hc = {0.02, Name "Parameters/hc size near the punch"},
  r_fine = {1.2, Name "Parameters/r_fine end of the fine zone (distance to the axis top)"},
  slope = {0.3, Name "Parameters/slope size growth per unit distance"},
  h_far = {2, Name "Parameters/h_far largest size"}
];

Point(1) = {0, -H, 0}; Point(2) = {W, -H, 0}; Point(3) = {W, 0, 0};
Point(4) = {a, 0, 0}; Point(5) = {0, 0, 0};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 5}; Line(5) = {5, 1};
Curve Loop(1) = {1, 2, 3, 4, 5};
Plane Surface(1) = {1};

Field[1] = MathEval;
Field[1].F = Sprintf("Min(%.17g, %.17g + %.17g * Max(Sqrt(x^2 + y^2) - %.17g, 0))", h_far, hc, slope, r_fine);
Background Field = 1;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
Mesh.Algorithm = 8;
Mesh.RecombinationAlgorithm = 3;
Mesh.RecombineAll = 1;
Recombine Surface{1};

Physical Surface("block") = {1};
Physical Curve("punched") = {4};
Physical Curve("free_top") = {3};
Physical Curve("bottom") = {1};
Physical Curve("axis") = {5};
