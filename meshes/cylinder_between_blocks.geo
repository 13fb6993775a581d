// A cylinder squeezed between two elastic blocks: three bodies, two contact pairs.
// Half model by symmetry at x = 0 (x >= 0).
//
//   upper block  [0, W] x [R, R + H]       load (pressure) on its top y = R + H
//   cylinder     half disc x >= 0, centre (0, 0), radius R
//   lower block  [0, W] x [-R - H, -R]     base y = -R - H
//
// The cylinder touches the blocks at (0, -R) and (0, R). The cylinder's arc is split at
// x = xc (bottom and top contact arcs, x <= xc; the free arcs in between) and its flat side
// at the centre. Each block's contact edge is split at x = xb (contact part x <= xb, free
// rest). The three bodies are separate geometry (own points and curves): the contact
// points are nodes of both bodies with distinct node tags.
//
// Mesh: all quads (frontal-Delaunay for quads + Blossom full-quad recombination), sizes
// from one MathEval field per body: h_c on its contact surface(s) for x <= r_fine, growing
// by `slope` per unit distance away from there, capped at hf. gmsh multiplies the field by
// Mesh.MeshSizeFactor, so the mesh refines with it (point sizes and curvature are off).

DefineConstant[
  R = {20, Name "Parameters/R cylinder radius"},
  W = {30, Name "Parameters/W block half width"},
  H = {20, Name "Parameters/H block height"},
  xc = {5, Name "Parameters/xc end of the cylinder contact arcs (x)"},
  xb = {6, Name "Parameters/xb end of the block contact edges (x)"},
  r_fine = {1.2, Name "Parameters/r_fine end of the fine zone (x), about 2a"},
  hc_cyl = {0.025, Name "Parameters/hc_cyl cylinder size at the contacts"},
  hc_blk = {0.03, Name "Parameters/hc_blk block size at the contacts"},
  slope = {0.1, Name "Parameters/slope size growth per unit distance"},
  hf = {R / 6, Name "Parameters/hf far size"}
];

yc = Sqrt(R * R - xc * xc);

// Lower block (surface 1).
Point(1) = {0, -R - H, 0, hf};
Point(2) = {W, -R - H, 0, hf};
Point(3) = {W, -R, 0, hf};
Point(4) = {xb, -R, 0, hc_blk};
Point(5) = {0, -R, 0, hc_blk};
Line(1) = {1, 2};  // base
Line(2) = {2, 3};  // right (free)
Line(3) = {3, 4};  // top, free part
Line(4) = {4, 5};  // top, contact part
Line(5) = {5, 1};  // symmetry
Curve Loop(1) = {1, 2, 3, 4, 5};
Plane Surface(1) = {1};

// Cylinder (surface 2): half disc, its own points.
Point(11) = {0, 0, 0, hf};          // centre
Point(12) = {0, -R, 0, hc_cyl};     // bottom contact point
Point(13) = {xc, -yc, 0, hc_cyl};   // end of the bottom contact arc
Point(14) = {R, 0, 0, hf};
Point(15) = {xc, yc, 0, hc_cyl};    // end of the top contact arc
Point(16) = {0, R, 0, hc_cyl};      // top contact point
Circle(11) = {12, 11, 13};  // bottom contact arc
Circle(12) = {13, 11, 14};  // free arc (lower)
Circle(13) = {14, 11, 15};  // free arc (upper)
Circle(14) = {15, 11, 16};  // top contact arc
Line(15) = {16, 11};        // symmetry (upper half)
Line(16) = {11, 12};        // symmetry (lower half)
Curve Loop(2) = {11, 12, 13, 14, 15, 16};
Plane Surface(2) = {2};

// Upper block (surface 3).
Point(21) = {0, R, 0, hc_blk};
Point(22) = {xb, R, 0, hc_blk};
Point(23) = {W, R, 0, hf};
Point(24) = {W, R + H, 0, hf};
Point(25) = {0, R + H, 0, hf};
Line(21) = {21, 22};  // bottom, contact part
Line(22) = {22, 23};  // bottom, free part
Line(23) = {23, 24};  // right (free)
Line(24) = {24, 25};  // top (load)
Line(25) = {25, 21};  // symmetry
Curve Loop(3) = {21, 22, 23, 24, 25};
Plane Surface(3) = {3};

// Size fields, one per body, restricted to it.
// Lower block: distance to its top edge for x <= r_fine.
Field[1] = MathEval;
Field[1].F = Sprintf("Min(%.17g, %.17g + %.17g * Sqrt(Max(x - %.17g, 0)^2 + (y + %.17g)^2))",
                     hf, hc_blk, slope, r_fine, R);
Field[2] = Restrict;
Field[2].InField = 1;
Field[2].SurfacesList = {1};
// Cylinder: distance to its arc for x <= r_fine (both contact zones; exact inside the disc).
Field[3] = MathEval;
Field[3].F = Sprintf("Min(%.17g, %.17g + %.17g * Sqrt(Max(x - %.17g, 0)^2 + (%.17g - Sqrt(x^2 + y^2))^2))",
                     hf, hc_cyl, slope, r_fine, R);
Field[4] = Restrict;
Field[4].InField = 3;
Field[4].SurfacesList = {2};
// Upper block: distance to its bottom edge for x <= r_fine.
Field[5] = MathEval;
Field[5].F = Sprintf("Min(%.17g, %.17g + %.17g * Sqrt(Max(x - %.17g, 0)^2 + (y - %.17g)^2))",
                     hf, hc_blk, slope, r_fine, R);
Field[6] = Restrict;
Field[6].InField = 5;
Field[6].SurfacesList = {3};
Field[7] = Min;
Field[7].FieldsList = {2, 4, 6};
Background Field = 7;

Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
Mesh.Algorithm = 8;              // frontal-Delaunay for quads
Mesh.RecombinationAlgorithm = 3; // Blossom full-quad: no triangle left
Mesh.RecombineAll = 1;
Recombine Surface{1, 2, 3};

Physical Surface("lower_block") = {1};
Physical Surface("cylinder") = {2};
Physical Surface("upper_block") = {3};
Physical Curve("cyl_bottom_contact") = {11};
Physical Curve("cyl_top_contact") = {14};
Physical Curve("lower_block_contact") = {4};
Physical Curve("upper_block_contact") = {21};
Physical Curve("cyl_free") = {12, 13};
Physical Curve("lower_block_free") = {2, 3};
Physical Curve("upper_block_free") = {22, 23};
Physical Curve("symmetry") = {5, 15, 16, 25};
Physical Curve("base") = {1};
Physical Curve("load") = {24};
