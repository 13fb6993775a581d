// Axisymmetric Hertz: an elastic sphere of radius R on an elastic cylindrical block, the
// half section x = r >= 0 (y the axis). Sphere: the quarter disc of centre (0, R) (its
// flat top is the loaded equatorial disc); block: [0, W] x [-H, 0]. They touch at the origin.
// The contact curves are the parts r <= xc of the sphere's arc and of the block's top. The
// sizes come from one field of the distance to the origin: hc for d <= r_fine, growing by
// `slope` per unit distance, capped at h_far. All quads (Blossom recombination).

DefineConstant[
  R = {10, Name "Parameters/R sphere radius"},
  W = {10, Name "Parameters/W block radius"},
  H = {10, Name "Parameters/H block height"},
  xc = {1.5, Name "Parameters/xc end of the contact curves"},
  r_fine = {0.8, Name "Parameters/r_fine end of the fine zone"},
  hc = {0.025, Name "Parameters/hc size at the contact"},
  slope = {0.3, Name "Parameters/slope size growth per unit distance"},
  h_far = {1.5, Name "Parameters/h_far largest size"}
];

// Block (surface 1): bottom, right, top from W to xc, top from xc to 0, axis.
Point(1) = {0, -H, 0}; Point(2) = {W, -H, 0}; Point(3) = {W, 0, 0};
Point(4) = {xc, 0, 0}; Point(5) = {0, 0, 0};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 5}; Line(5) = {5, 1};
Curve Loop(1) = {1, 2, 3, 4, 5};
Plane Surface(1) = {1};

// Sphere (surface 2): arc from the pole (0, 0) through (xc, yc) to the equator (R, R).
yc = R - Sqrt(R * R - xc * xc);
Point(11) = {0, R, 0}; Point(12) = {0, 0, 0}; Point(13) = {xc, yc, 0}; Point(14) = {R, R, 0};
Circle(11) = {12, 11, 13}; Circle(12) = {13, 11, 14}; Line(13) = {14, 11}; Line(14) = {11, 12};
Curve Loop(2) = {11, 12, 13, 14};
Plane Surface(2) = {2};

Field[1] = MathEval;
Field[1].F = Sprintf("Min(%.17g, %.17g + %.17g * Max(Sqrt(x^2 + y^2) - %.17g, 0))", h_far, hc, slope, r_fine);
Background Field = 1;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
Mesh.Algorithm = 8;
Mesh.RecombinationAlgorithm = 3;
Mesh.RecombineAll = 1;
Recombine Surface{1, 2};

Physical Surface("block") = {1};
Physical Surface("sphere") = {2};
Physical Curve("block_contact") = {4};
Physical Curve("sphere_contact") = {11};
Physical Curve("block_bottom") = {1};
Physical Curve("block_axis") = {5};
Physical Curve("sphere_axis") = {14};
Physical Curve("sphere_top") = {13};
