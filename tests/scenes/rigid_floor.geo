// Patch test on a rigid floor: one block resting on an inclined rigid plane (no mesh for it).
//
// Unrotated picture: the block [-L/2, L/2] x [0, H] on the floor y = 0; the whole picture is
// rotated by theta about the origin. x0 is the rotated image of (X0, 0), a point of the
// contact edge, off-centre so that the two halves of the edge are not multiples of h.
// Exact solution under pressure p on the three other edges: sigma = -p I (plane strain),
// u(x) = -c (x - x0), c = p (1 + nu)(1 - 2 nu) / E: the normal displacement along the floor
// is zero, the block slides tangentially (frictionless) unless a point is held.
// All-quad, unstructured: frontal-Delaunay for quads + Blossom full-quad recombination.

DefineConstant[
  theta = {30, Name "Parameters/theta (degrees)"},
  L = {6, Name "Parameters/L block width"},
  H = {3, Name "Parameters/H block height"},
  h = {0.15, Name "Parameters/h mesh size"},
  X0 = {-0.7, Name "Parameters/X0 pinned point of the contact edge (unrotated x)"}
];

t = theta * Pi / 180;
ct = Cos(t);
st = Sin(t);
a = L / 2;

Point(1) = {-a * ct, -a * st, 0, h};                    // bottom-left
Point(2) = {X0 * ct, X0 * st, 0, h};                    // x0 (pinned)
Point(3) = { a * ct,  a * st, 0, h};                    // bottom-right
Point(4) = { a * ct - H * st,  a * st + H * ct, 0, h};  // top-right
Point(5) = {-a * ct - H * st, -a * st + H * ct, 0, h};  // top-left

Line(1) = {1, 2};  // bottom, contact (left of x0)
Line(2) = {2, 3};  // bottom, contact (right of x0)
Line(3) = {3, 4};  // right
Line(4) = {4, 5};  // top
Line(5) = {5, 1};  // left
Curve Loop(1) = {1, 2, 3, 4, 5};
Plane Surface(1) = {1};

Mesh.Algorithm = 8;
Mesh.RecombinationAlgorithm = 3;
Mesh.RecombineAll = 1;
Mesh.MeshSizeFromCurvature = 0;
Recombine Surface{1};

Physical Surface("block") = {1};
Physical Curve("bottom") = {1, 2};
Physical Curve("loaded") = {3, 4, 5};
Physical Point("x0") = {2};
Physical Point("corner") = {5};
