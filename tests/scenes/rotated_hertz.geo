// A displacement-controlled Hertz contact, full model, rotated by phi: a half disc of
// radius R (centre (0, R) before the rotation, its diameter on top) pressed onto a block
// [-W, W] x [-H, 0]; they touch at the origin, the centre of the rotation.
//
// Each body is its own geometry (own points and curves: the origin is a node of both). The
// contact curves are the parts |x| <= xc of the disc's arc and of the block's top (before
// the rotation); the rest is free. The sizes come from one field of the distance r to the
// origin (rotation-invariant): h_c for r <= r_fine, growing by `slope` per unit distance,
// capped at h_far; gmsh multiplies it by Mesh.MeshSizeFactor (studies refine with it).
// All quads: frontal-Delaunay for quads + Blossom recombination. Geometry.AutoCoherence = 0:
// otherwise the Rotate below merges the two points at the origin (one shared node glues the
// bodies there).

Geometry.AutoCoherence = 0;

DefineConstant[
  phi = {30, Name "Parameters/phi rotation (degrees)"},
  R = {10, Name "Parameters/R disc radius"},
  W = {10, Name "Parameters/W block half-width"},
  H = {10, Name "Parameters/H block height"},
  xc = {3, Name "Parameters/xc end of the contact curves (x, before the rotation)"},
  r_fine = {1.2, Name "Parameters/r_fine end of the fine zone"},
  hc = {0.04, Name "Parameters/hc size at the contact"},
  slope = {0.25, Name "Parameters/slope size growth per unit distance"},
  h_far = {2, Name "Parameters/h_far largest size"}
];

// Block (surface 1): bottom, right, top split at -xc and xc, left.
Point(1) = {-W, -H, 0}; Point(2) = {W, -H, 0}; Point(3) = {W, 0, 0};
Point(4) = {xc, 0, 0}; Point(5) = {0, 0, 0}; Point(6) = {-xc, 0, 0}; Point(7) = {-W, 0, 0};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 5}; Line(5) = {5, 6};
Line(6) = {6, 7}; Line(7) = {7, 1};
Curve Loop(1) = {1, 2, 3, 4, 5, 6, 7};
Plane Surface(1) = {1};

// Half disc (surface 2): arc from (-R, R) down through the origin to (R, R), diameter on top.
yc = R - Sqrt(R * R - xc * xc);
Point(11) = {0, R, 0}; Point(12) = {-R, R, 0}; Point(13) = {-xc, yc, 0};
Point(14) = {0, 0, 0}; Point(15) = {xc, yc, 0}; Point(16) = {R, R, 0};
Circle(11) = {12, 11, 13}; Circle(12) = {13, 11, 14}; Circle(13) = {14, 11, 15};
Circle(14) = {15, 11, 16}; Line(15) = {16, 12};
Curve Loop(2) = {11, 12, 13, 14, 15};
Plane Surface(2) = {2};

Rotate {{0, 0, 1}, {0, 0, 0}, phi * Pi / 180} { Surface{1, 2}; }

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
Physical Surface("disc") = {2};
Physical Curve("block_contact") = {4, 5};
Physical Curve("disc_contact") = {12, 13};
Physical Curve("block_bottom") = {1};
Physical Curve("disc_top") = {15};
