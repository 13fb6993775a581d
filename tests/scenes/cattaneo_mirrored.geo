// Two identical half-cylinders (radius R) touching at the origin, the lower one the upper
// one's mirror image node for node (gmsh copies the upper mesh across y = 0): the pressed
// bodies make no relative slip, and no mesh asymmetry locks in a shear.
// Element size h on the arc where the contact lies (|x| < w), growing by g per unit distance
// from it, up to R / 8. Quads (Blossom). Groups: upper, lower; upper_arc / lower_arc (the
// contact curves), upper_flat, lower_flat.

DefineConstant[
  R = {1, Name "Parameters/R cylinder radius"},
  h = {0.0005, Name "Parameters/h element size at the contact"},
  w = {0.13, Name "Parameters/w half-width of the arc meshed at h"},
  g = {0.1, Name "Parameters/g size growth away from it"}
];

Point(1) = {0, R, 0};
Point(2) = {-R, R, 0};
Point(3) = {0, 0, 0};
Point(4) = {R, R, 0};
Circle(1) = {2, 1, 3};
Circle(2) = {3, 1, 4};
Line(3) = {4, 2};
Curve Loop(1) = {1, 2, 3};
Plane Surface(1) = {1};

// The mirror image, each curve running as its original's image.
Point(11) = {0, -R, 0};
Point(12) = {-R, -R, 0};
Point(13) = {0, 0, 0};
Point(14) = {R, -R, 0};
Circle(11) = {12, 11, 13};
Circle(12) = {13, 11, 14};
Line(13) = {14, 12};
Curve Loop(2) = {11, 12, 13};
Plane Surface(2) = {2};

// Distance to the arc within |x| < w (sampled finely), and h + g (d - ...) from there.
Point(21) = {-w, R - Sqrt(R * R - w * w), 0};
Point(22) = {w, R - Sqrt(R * R - w * w), 0};
Circle(21) = {21, 1, 3};
Circle(22) = {3, 1, 22};
Field[1] = Distance;
Field[1].CurvesList = {21, 22};
Field[1].Sampling = 2000;
Field[2] = MathEval;
Field[2].F = Sprintf("Min(%g + %g * F1, %g)", h, g, R / 8);
Background Field = 2;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;

Mesh.Algorithm = 8;
Mesh.RecombinationAlgorithm = 3;
Mesh.RecombineAll = 1;
Recombine Surface{1, 2};

mirror[] = {1, 0, 0, 0, 0, -1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
Periodic Curve{11, 12, 13} = {1, 2, 3} Affine mirror[];
Periodic Surface{2} = {1} Affine mirror[];

Physical Surface("upper") = {1};
Physical Surface("lower") = {2};
Physical Curve("upper_arc") = {1, 2};
Physical Curve("lower_arc") = {11, 12};
Physical Curve("upper_flat") = {3};
Physical Curve("lower_flat") = {13};
