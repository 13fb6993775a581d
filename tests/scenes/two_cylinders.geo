// Two elastic cylinders in line contact, half model by symmetry at x = 0 (x >= 0).
//
// Lower quarter disc: centre (0, -R1), radius R1; upper quarter disc: centre (0, R2),
// radius R2; they touch at the origin. Each quarter disc is bounded by
//   - its arc from the contact point (0, 0) to the end of its horizontal radius, split at
//     x = xc (the contact part, x <= xc, and the free rest),
//   - its horizontal radius through the centre (lower: "base", upper: "load"),
//   - its vertical radius on x = 0 ("symmetry").
// The two bodies are separate geometry (own points and curves): the origin is a node of
// both, with two distinct node tags.
//
// Mesh: all quads (frontal-Delaunay for quads + Blossom full-quad recombination), sizes
// from one MathEval field per body: h_c on the arc for x <= r_fine, growing by `slope` per
// unit distance away from that part of the arc, capped at R/6. gmsh multiplies the field by
// Mesh.MeshSizeFactor, so the mesh refines with it (point sizes and curvature are off).

DefineConstant[
  R1 = {40, Name "Parameters/R1 lower radius"},
  R2 = {60, Name "Parameters/R2 upper radius"},
  xc1 = {10, Name "Parameters/xc1 end of the lower contact arc (x)"},
  xc2 = {15, Name "Parameters/xc2 end of the upper contact arc (x)"},
  r_fine = {2.2, Name "Parameters/r_fine end of the fine zone (x), about 2a"},
  hc1 = {0.02, Name "Parameters/hc1 lower size at the contact"},
  hc2 = {0.025, Name "Parameters/hc2 upper size at the contact"},
  slope = {0.1, Name "Parameters/slope size growth per unit distance"},
  hf1 = {R1 / 6, Name "Parameters/hf1 lower far size"},
  hf2 = {R2 / 6, Name "Parameters/hf2 upper far size"}
];

// Lower quarter disc (surface 1).
Point(1) = {0, -R1, 0, hf1};                              // centre
Point(2) = {0, 0, 0, hc1};                                // contact point
Point(3) = {xc1, -R1 + Sqrt(R1 * R1 - xc1 * xc1), 0, hc1};  // end of the contact arc
Point(4) = {R1, -R1, 0, hf1};                             // end of the horizontal radius
Circle(1) = {2, 1, 3};  // contact arc
Circle(2) = {3, 1, 4};  // free arc
Line(3) = {4, 1};       // horizontal radius (base)
Line(4) = {1, 2};       // vertical radius (symmetry)
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};

// Upper quarter disc (surface 2): its own points, the contact point again.
Point(11) = {0, R2, 0, hf2};                               // centre
Point(12) = {0, 0, 0, hc2};                                // contact point
Point(13) = {xc2, R2 - Sqrt(R2 * R2 - xc2 * xc2), 0, hc2};   // end of the contact arc
Point(14) = {R2, R2, 0, hf2};                              // end of the horizontal radius
Circle(11) = {12, 11, 13};  // contact arc
Circle(12) = {13, 11, 14};  // free arc
Line(13) = {14, 11};        // horizontal radius (load)
Line(14) = {11, 12};        // vertical radius (symmetry)
Curve Loop(2) = {11, 12, 13, 14};
Plane Surface(2) = {2};

// Size fields: distance to the part x <= r_fine of each body's own arc (exact for points
// inside the disc), made linear in the distance and capped; restricted to that body.
Field[1] = MathEval;
Field[1].F = Sprintf("Min(%.17g, %.17g + %.17g * Sqrt(Max(x - %.17g, 0)^2 + (%.17g - Sqrt(x^2 + (y + %.17g)^2))^2))",
                     hf1, hc1, slope, r_fine, R1, R1);
Field[2] = Restrict;
Field[2].InField = 1;
Field[2].SurfacesList = {1};
Field[3] = MathEval;
Field[3].F = Sprintf("Min(%.17g, %.17g + %.17g * Sqrt(Max(x - %.17g, 0)^2 + (%.17g - Sqrt(x^2 + (y - %.17g)^2))^2))",
                     hf2, hc2, slope, r_fine, R2, R2);
Field[4] = Restrict;
Field[4].InField = 3;
Field[4].SurfacesList = {2};
Field[5] = Min;
Field[5].FieldsList = {2, 4};
Background Field = 5;

Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
Mesh.Algorithm = 8;              // frontal-Delaunay for quads
Mesh.RecombinationAlgorithm = 3; // Blossom full-quad: no triangle left
Mesh.RecombineAll = 1;
Recombine Surface{1, 2};

Physical Surface("lower") = {1};
Physical Surface("upper") = {2};
Physical Curve("lower_contact") = {1};
Physical Curve("upper_contact") = {11};
Physical Curve("lower_free") = {2};
Physical Curve("upper_free") = {12};
Physical Curve("symmetry") = {4, 14};
Physical Curve("base") = {3};
Physical Curve("load") = {13};
