// An O-ring pressed by a rigid flat plate, axisymmetric: the upper half of the ring's
// circular section (radius Rs, centred at r = rc on the mid-plane y = 0, a symmetry plane).
// The plate (a rigid obstacle in the scene file) touches the section's top point
// (rc, Rs). The contact curve is the arc within 30 degrees of the top; the sizes come from
// one field of the distance to the top point: hc for d <= r_fine, growing by `slope` per
// unit distance, capped at h_far. All quads (Blossom recombination).

DefineConstant[
  rc = {10, Name "Parameters/rc radius of the ring's centre line"},
  Rs = {1, Name "Parameters/Rs radius of the section"},
  hc = {0.008, Name "Parameters/hc size at the contact"},
  r_fine = {0.15, Name "Parameters/r_fine end of the fine zone"},
  slope = {0.4, Name "Parameters/slope size growth per unit distance"},
  h_far = {0.15, Name "Parameters/h_far largest size"}
];

c30 = Cos(Pi / 6); s30 = Sin(Pi / 6);
Point(1) = {rc, 0, 0};  // the centre
Point(2) = {rc + Rs, 0, 0};
Point(3) = {rc + Rs * s30, Rs * c30, 0};
Point(4) = {rc - Rs * s30, Rs * c30, 0};
Point(5) = {rc - Rs, 0, 0};
Circle(1) = {2, 1, 3};
Circle(2) = {3, 1, 4};  // contact: the top 60 degrees
Circle(3) = {4, 1, 5};
Line(4) = {5, 2};       // the mid-plane
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};

Field[1] = MathEval;
Field[1].F = Sprintf("Min(%.17g, %.17g + %.17g * Max(Sqrt((x - %.17g)^2 + (y - %.17g)^2) - %.17g, 0))", h_far, hc, slope, rc, Rs, r_fine);
Background Field = 1;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
Mesh.Algorithm = 8;
Mesh.RecombinationAlgorithm = 3;
Mesh.RecombineAll = 1;
Recombine Surface{1};

Physical Surface("ring") = {1};
Physical Curve("ring_contact") = {2};
Physical Curve("mid_plane") = {4};
