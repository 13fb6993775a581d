// A full (unmirrored) elastic block for a rigid cylinder pressed at its top's centre: the
// block [-W, W] x [-H, 0] (large: the contact sees a half-plane), the top y = 0 fine (h_c) for |x| <= r_fine, the base held (the
// scene holds u_y on the base and u_x at the base's midpoint). All quads, sizes from one
// MathEval field as meshes/rigid_block.geo's.

DefineConstant[
  W = {100, Name "Parameters/W block half width"},
  H = {100, Name "Parameters/H block height"},
  r_fine = {1.0, Name "Parameters/r_fine end of the fine zone (|x|)"},
  hc = {0.03, Name "Parameters/hc size on the top for |x| <= r_fine"},
  slope = {0.15, Name "Parameters/slope size growth per unit distance"},
  hf = {5.0, Name "Parameters/hf far size"}
];

Point(1) = {-W, -H, 0, hf};
Point(2) = {0, -H, 0, hf};
Point(3) = {W, -H, 0, hf};
Point(4) = {W, 0, 0, hf};
Point(5) = {r_fine, 0, 0, hc};
Point(6) = {-r_fine, 0, 0, hc};
Point(7) = {-W, 0, 0, hf};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 5};
Line(5) = {5, 6};
Line(6) = {6, 7};
Line(7) = {7, 1};
Curve Loop(1) = {1, 2, 3, 4, 5, 6, 7};
Plane Surface(1) = {1};

Field[1] = MathEval;
Field[1].F = Sprintf("Min(%.17g, %.17g + %.17g * Sqrt(Max(Abs(x) - %.17g, 0)^2 + y^2))",
                     hf, hc, slope, r_fine);
Background Field = 1;

Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
Mesh.Algorithm = 8;
Mesh.RecombinationAlgorithm = 3;
Mesh.RecombineAll = 1;
Recombine Surface{1};

Physical Surface("block") = {1};
Physical Curve("top") = {4, 5, 6};
Physical Curve("base") = {1, 2};
Physical Curve("sides") = {3, 7};
Physical Point("base_mid") = {2};
