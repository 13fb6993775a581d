// Two identical half-cylinders (radius R) touching at the origin, one the other's mirror:
// the upper one's flat face at y = R, the lower one's at y = -R. Mirrored bodies make no
// relative slip while pressed (Cattaneo-Mindlin's assumption), whatever the friction.
// Element size h at the contact, growing to R / 8 away from it. Quads (Blossom).
// Groups: upper, lower; upper_arc / lower_arc (the contact curves), upper_flat, lower_flat.

DefineConstant[
  R = {1, Name "Parameters/R cylinder radius"},
  h = {0.004, Name "Parameters/h element size at the contact"}
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

Point(11) = {0, -R, 0};
Point(12) = {-R, -R, 0};
Point(13) = {0, 0, 0};
Point(14) = {R, -R, 0};
Circle(11) = {13, 11, 12};
Circle(12) = {14, 11, 13};
Line(13) = {12, 14};
Curve Loop(2) = {11, 13, 12};
Plane Surface(2) = {2};

Field[1] = Distance;
Field[1].PointsList = {3, 13};
Field[2] = Threshold;
Field[2].InField = 1;
Field[2].SizeMin = h;
Field[2].SizeMax = R / 8;
Field[2].DistMin = 0.15 * R;
Field[2].DistMax = 0.8 * R;
Background Field = 2;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;

Mesh.Algorithm = 8;
Mesh.RecombinationAlgorithm = 3;
Mesh.RecombineAll = 1;
Recombine Surface{1, 2};

Physical Surface("upper") = {1};
Physical Surface("lower") = {2};
Physical Curve("upper_arc") = {1, 2};
Physical Curve("lower_arc") = {11, 12};
Physical Curve("upper_flat") = {3};
Physical Curve("lower_flat") = {13};
