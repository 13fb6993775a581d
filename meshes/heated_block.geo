// A heated block between two rigid walls: the block [0, L] x [0, H] touches the rigid planes
// x = 0 and x = L (no mesh for them). Only the corner (0, 0) is held (uy = 0); the walls hold
// it in x and against rotation. All quads, unstructured (frontal-Delaunay for quads +
// Blossom full-quad recombination), so the patch test runs on a non-uniform mesh.

DefineConstant[
  L = {2, Name "Parameters/L block width (the walls' distance)"},
  H = {1, Name "Parameters/H block height"},
  h = {0.17, Name "Parameters/h mesh size"}
];

Point(1) = {0, 0, 0, h};
Point(2) = {L, 0, 0, h};
Point(3) = {L, H, 0, 0.6 * h};
Point(4) = {0, H, 0, h};
Line(1) = {1, 2};  // bottom
Line(2) = {2, 3};  // right: against the wall x = L
Line(3) = {3, 4};  // top
Line(4) = {4, 1};  // left: against the wall x = 0
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};

Mesh.Algorithm = 8;
Mesh.RecombinationAlgorithm = 3;
Mesh.RecombineAll = 1;
Mesh.MeshSizeFromCurvature = 0;
Recombine Surface{1};

Physical Surface("block") = {1};
Physical Curve("left") = {4};
Physical Curve("right") = {2};
Physical Curve("free") = {1, 3};
Physical Point("pin") = {1};
