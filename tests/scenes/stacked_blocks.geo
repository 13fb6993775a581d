// Four stacked blocks (a floating-body test scene, a few hundred DOFs).
//
// Block k (k = 1..4) is [0, L] x [(k-1) H, k H], each from its own points and curves (the
// interface nodes are duplicated), meshed with its own size h_k (non-matching meshes).
// Named groups: surfaces b1..b4, curves bK_top / bK_bottom / bK_left, b4_top the loaded edge.
// With ux = 0 on every left edge (a symmetry line) a block's only rigid motion left is the
// translation along y, which its contact pairs must hold.
// All-quad: frontal-Delaunay for quads + Blossom recombination; Mesh.MeshSizeFactor scales it.

DefineConstant[
  L = {2, Name "Parameters/L block width"},
  H = {1, Name "Parameters/H block height"}
];
h[] = {0.25, 0.3, 0.22, 0.28};

For k In {1:4}
  y0 = (k - 1) * H;
  p = newp;
  Point(p) = {0, y0, 0, h[k - 1]};
  Point(p + 1) = {L, y0, 0, h[k - 1]};
  Point(p + 2) = {L, y0 + H, 0, h[k - 1]};
  Point(p + 3) = {0, y0 + H, 0, h[k - 1]};
  c = newc;
  Line(c) = {p, p + 1};          // bottom
  Line(c + 1) = {p + 1, p + 2};  // right
  Line(c + 2) = {p + 2, p + 3};  // top
  Line(c + 3) = {p + 3, p};      // left
  Curve Loop(k) = {c, c + 1, c + 2, c + 3};
  Plane Surface(k) = {k};
  Physical Surface(Sprintf("b%g", k)) = {k};
  Physical Curve(Sprintf("b%g_bottom", k)) = {c};
  Physical Curve(Sprintf("b%g_top", k)) = {c + 2};
  Physical Curve(Sprintf("b%g_left", k)) = {c + 3};
EndFor

Mesh.Algorithm = 8;
Mesh.RecombinationAlgorithm = 3;
Mesh.RecombineAll = 1;
Mesh.MeshSizeFromCurvature = 0;
Recombine Surface{1:4};
