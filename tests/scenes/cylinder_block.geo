// A half-cylinder (radius R, its flat face at y = R) touching a block (width 2 W, height H,
// its top face at y = 0) at the origin. Element size h on the surfaces where the contact lies
// (|x| < w), growing by g per unit distance from there, up to R / 8. Quads (Blossom).
// Groups: cylinder, block; cylinder_arc / block_top (the contact curves), cylinder_flat,
// block_bottom. The mesh of tests/scenes/cylinder_block.toml and of
// benchmarks/getfem_cylinder_block.py (the same mesh in both codes).

DefineConstant[
  R = {1, Name "Parameters/R cylinder radius"},
  W = {1, Name "Parameters/W block half-width"},
  H = {1, Name "Parameters/H block height"},
  h = {0.002, Name "Parameters/h element size at the contact"},
  w = {0.13, Name "Parameters/w half-width meshed at h"},
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

Point(11) = {-W, 0, 0};
Point(12) = {0, 0, 0};
Point(13) = {W, 0, 0};
Point(14) = {W, -H, 0};
Point(15) = {-W, -H, 0};
Line(11) = {11, 12};
Line(12) = {12, 13};
Line(13) = {13, 14};
Line(14) = {14, 15};
Line(15) = {15, 11};
Curve Loop(2) = {11, 12, 13, 14, 15};
Plane Surface(2) = {2};

// Distance to both contact surfaces within |x| < w (sampled finely).
Point(21) = {-w, R - Sqrt(R * R - w * w), 0};
Point(22) = {w, R - Sqrt(R * R - w * w), 0};
Circle(21) = {21, 1, 3};
Circle(22) = {3, 1, 22};
Point(23) = {-w, 0, 0};
Point(24) = {w, 0, 0};
Line(23) = {23, 24};
Field[1] = Distance;
Field[1].CurvesList = {21, 22, 23};
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

Physical Surface("cylinder") = {1};
Physical Surface("block") = {2};
Physical Curve("cylinder_arc") = {1, 2};
Physical Curve("block_top") = {11, 12};
Physical Curve("cylinder_flat") = {3};
Physical Curve("block_bottom") = {14};
