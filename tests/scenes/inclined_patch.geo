// Contact patch test with an inclined straight interface (cf. SPEC S4, full model).
//
// Unrotated picture: lower block [-L1/2, L1/2] x [-H1, 0], upper block [-L2/2, L2/2] x [0, H2]
// centred on it; the interface is y = 0. The whole picture is rotated by theta about the
// origin. x0 is the rotated image of (X0, 0), a point of the interface; X0 is off-centre so
// that the two halves of each interface edge have lengths that are not multiples of the
// mesh sizes: few interface nodes of the two sides coincide (a stricter patch test).
// Exact solution under pressure p on every outer edge (not the interface): sigma = -p I in
// both bodies, u_i(x) = -c_i (x - x0), c_i = p (1 + nu_i)(1 - 2 nu_i) / E_i (plane strain).
//
// The two bodies are separate geometry (own points and curves): the interface nodes are
// duplicated. Both interface edges are split at x0, so x0 is a node of both bodies.
// All-quad, unstructured: frontal-Delaunay for quads + Blossom full-quad recombination.
// Sizes come from the point sizes h1, h2 only, so Mesh.MeshSizeFactor refines the mesh.

DefineConstant[
  theta = {30, Name "Parameters/theta (degrees)"},
  L1 = {10, Name "Parameters/L1 lower width"},
  H1 = {3, Name "Parameters/H1 lower height"},
  L2 = {6, Name "Parameters/L2 upper width"},
  H2 = {3, Name "Parameters/H2 upper height"},
  h1 = {0.12, Name "Parameters/h1 lower mesh size"},
  h2 = {0.15, Name "Parameters/h2 upper mesh size"},
  X0 = {-0.7, Name "Parameters/X0 interface point (unrotated x)"}
];

t = theta * Pi / 180;
ct = Cos(t);
st = Sin(t);
a1 = L1 / 2;
a2 = L2 / 2;

// Lower body (body 1): corners, the upper block's corner locations on its top edge, x0.
Point(1) = {-a1 * ct + H1 * st, -a1 * st - H1 * ct, 0, h1};  // bottom-left  = B1
Point(2) = { a1 * ct + H1 * st,  a1 * st - H1 * ct, 0, h1};  // bottom-right
Point(3) = { a1 * ct,            a1 * st,           0, h1};  // top-right
Point(4) = { a2 * ct,            a2 * st,           0, h1};  // under the upper right corner
Point(5) = {X0 * ct, X0 * st, 0, h1};                                     // x0 on body 1 = A1
Point(6) = {-a2 * ct,           -a2 * st,           0, h1};  // under the upper left corner
Point(7) = {-a1 * ct,           -a1 * st,           0, h1};  // top-left

Line(1) = {1, 2};  // bottom
Line(2) = {2, 3};  // right
Line(3) = {3, 4};  // top, free part (right)
Line(4) = {4, 5};  // top, interface (right of x0)
Line(5) = {5, 6};  // top, interface (left of x0)
Line(6) = {6, 7};  // top, free part (left)
Line(7) = {7, 1};  // left
Curve Loop(1) = {1, 2, 3, 4, 5, 6, 7};
Plane Surface(1) = {1};

// Upper body (body 2): its own points, x0 again as a distinct point.
Point(11) = {-a2 * ct,           -a2 * st,           0, h2};  // bottom-left
Point(12) = {X0 * ct, X0 * st, 0, h2};                                     // x0 on body 2 = A2
Point(13) = { a2 * ct,            a2 * st,           0, h2};  // bottom-right
Point(14) = { a2 * ct - H2 * st,  a2 * st + H2 * ct, 0, h2};  // top-right
Point(15) = {-a2 * ct - H2 * st, -a2 * st + H2 * ct, 0, h2};  // top-left = B2

Line(11) = {11, 12};  // bottom, interface (left of x0)
Line(12) = {12, 13};  // bottom, interface (right of x0)
Line(13) = {13, 14};  // right
Line(14) = {14, 15};  // top
Line(15) = {15, 11};  // left
Curve Loop(2) = {11, 12, 13, 14, 15};
Plane Surface(2) = {2};

Mesh.Algorithm = 8;             // frontal-Delaunay for quads
Mesh.RecombinationAlgorithm = 3; // Blossom full-quad: no triangle left
Mesh.RecombineAll = 1;
Mesh.MeshSizeFromCurvature = 0;
Recombine Surface{1, 2};

Physical Surface("lower") = {1};
Physical Surface("upper") = {2};
Physical Curve("lower_contact") = {4, 5};
Physical Curve("upper_contact") = {11, 12};
Physical Curve("lower_pressure") = {1, 2, 3, 6, 7};
Physical Curve("upper_pressure") = {13, 14, 15};
Physical Point("A1") = {5};
Physical Point("B1") = {1};
Physical Point("A2") = {12};
Physical Point("B2") = {15};
