// The elastic block of a rigid cylinder pressed with friction (Spence, demos/scenes/
// spence_indenter.toml): rigid_block.geo's mesh (h_c on the top for x <= r_fine, growing by
// `slope` per unit distance), on a block five times wider and deeper, W = H = 100, so that the
// contact (a <= 0.7) sees a half-plane: on the 20 x 20 block the stick zone widened with a/H
// (docs/friction.md, Spence, "Against the solver"). The far size hf = 5 keeps it as cheap.
//
// Half model by symmetry at x = 0: the block [0, W] x [-H, 0], its top y = 0 the surface
// the obstacle may touch, the contact zone around x = 0, with a node at x = x_edge (where a
// punch's edge comes).
//
// Mesh: all quads (frontal-Delaunay for quads + Blossom full-quad recombination), sizes
// from one MathEval field: h_c on the top for x <= r_fine, growing by `slope` per unit
// distance away from there, capped at hf. gmsh multiplies the field by
// Mesh.MeshSizeFactor, so the mesh refines with it (point sizes and curvature are off).

DefineConstant[
  W = {100, Name "Parameters/W block half width"},
  H = {100, Name "Parameters/H block height"},
  r_fine = {1.5, Name "Parameters/r_fine end of the fine zone (x)"},
  x_edge = {1.0, Name "Parameters/x_edge a node of the top inside the fine zone (a punch edge)"},
  hc = {0.015, Name "Parameters/hc size on the top for x <= r_fine"},
  slope = {0.1, Name "Parameters/slope size growth per unit distance"},
  hf = {5.0, Name "Parameters/hf far size"}
];

Point(1) = {0, -H, 0, hf};
Point(2) = {W, -H, 0, hf};
Point(3) = {W, 0, 0, hf};
Point(4) = {r_fine, 0, 0, hc};
Point(5) = {0, 0, 0, hc};
Point(6) = {x_edge, 0, 0, hc};
Line(1) = {1, 2};  // base
Line(2) = {2, 3};  // right side (free)
Line(3) = {3, 4};  // top, outside the fine zone
Line(4) = {4, 6};  // top, the fine zone beyond x_edge
Line(6) = {6, 5};  // top, the fine zone up to x_edge
Line(5) = {5, 1};  // symmetry
Curve Loop(1) = {1, 2, 3, 4, 6, 5};
Plane Surface(1) = {1};

Field[1] = MathEval;
Field[1].F = Sprintf("Min(%.17g, %.17g + %.17g * Sqrt(Max(x - %.17g, 0)^2 + y^2))",
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
Physical Curve("top") = {3, 4, 6};
Physical Curve("side") = {2};
Physical Curve("base") = {1};
Physical Curve("symmetry") = {5};
Physical Point("corner") = {5};
