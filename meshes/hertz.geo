// The Hertz scene (S5): a quarter of a cylinder (radius R) on an elastic block, half model by
// symmetry (x = 0 is the axis).
//
// Open it in gmsh (`gmsh meshes/hertz.geo`, then Mesh > 2D) and change the parameters in its
// menu, or `gmsh -2 -setnumber h_contact 0.05 meshes/hertz.geo`. contactfx builds its `hertz`
// scene (the gmsh mesh) from this file: contactfx/meshes/hertz.py sets every parameter, then
// meshes. Quadrilaterals (Frontal-Delaunay for quads, Blossom recombination), sized by a field
// that grows by `slope` per unit distance from the contact surfaces' part with x <= r_refine
// (the elastic field decays like 1/r in 2D: every decade of distance adds about the same
// error, so the slope, not the far size, sets the error in the compliance); with `edge` = 1
// also from (x_edge, h_edge), the contact edge; `user_sizes` = 1: no field (the adaptive
// loop's background view sets the sizes).

DefineConstant[
  R = {60, Name "Parameters/R: cylinder radius"},
  width = {60, Name "Parameters/width: half width of the block"},
  height = {60, Name "Parameters/height: height of the block"},
  h_contact = {0.02, Name "Parameters/h_contact: element size on the contact zone"},
  r_refine = {1.4, Name "Parameters/r_refine: extent of the refined zone"},
  h_far = {10, Name "Parameters/h_far: largest element size"},
  extent = {15, Name "Parameters/extent: end of the block's contact surface"},
  slope = {0.1, Name "Parameters/slope: growth of the size per unit distance"},
  edge = {0, Choices{0, 1}, Name "Parameters/edge: also refine at the contact edge"},
  x_edge = {1, Name "Parameters/x_edge: the contact edge"},
  h_edge = {0.005, Name "Parameters/h_edge: element size at the contact edge"},
  user_sizes = {0, Choices{0, 1}, Name "Parameters/user_sizes: sizes from a background view"}
];

yc = height + R;
// The block; its top is split at the end of the contact surface.
Point(1) = {0, 0, 0};
Point(2) = {width, 0, 0};
Point(3) = {width, height, 0};
Point(4) = {extent, height, 0};
Point(5) = {0, height, 0};
Line(1) = {1, 2};  // support
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 5};  // contact1
Line(5) = {5, 1};  // symmetry
Curve Loop(1) = {1, 2, 3, 4, 5};
Plane Surface(1) = {1};
// The quarter disc from its own points (point 7 lies on point 5, a distinct node): contact
// needs duplicated interface nodes.
Point(6) = {0, yc, 0};
Point(7) = {0, height, 0};
Point(8) = {extent, yc - Sqrt(R * R - extent * extent), 0};
Point(9) = {R, yc, 0};
Circle(6) = {7, 6, 8};  // contact2
Circle(7) = {8, 6, 9};
Line(8) = {9, 6};  // load
Line(9) = {6, 7};  // symmetry
Curve Loop(2) = {6, 7, 8, 9};
Plane Surface(2) = {2};

// The size grows linearly with the distance from the contact surfaces' part with
// x <= r_refine; each body's distance is to its own surface (the line y = height, the arc),
// and the smaller of the two is the right one on both sides of the interface.
If (!user_sizes)
  d_line = Sprintf("Abs(y - %.17g)", height);
  d_arc = Sprintf("Abs(%.17g - Sqrt(x^2 + (y - %.17g)^2))", R, yc);
  dist = StrCat(Sprintf("Sqrt(Max(x - %.17g, 0)^2 + Min(", r_refine), d_line, ", ", d_arc, ")^2)");
  size = StrCat(Sprintf("%.17g + %.17g * ", h_contact, slope), dist);
  If (edge)
    de = StrCat(Sprintf("Sqrt((x - %.17g)^2 + Min(", x_edge), d_line, ", ", d_arc, ")^2)");
    size = StrCat("Min(", size, Sprintf(", %.17g + %.17g * ", h_edge, slope), de, ")");
  EndIf
  Field[1] = MathEval;
  Field[1].F = StrCat(Sprintf("Min(%.17g, ", h_far), size, ")");
  Background Field = 1;
EndIf
// The field alone sets the size: point sizes and curvature would override it.
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
Mesh.Algorithm = 8;
Mesh.RecombinationAlgorithm = 3;
Mesh.RecombineAll = 1;
Recombine Surface{1, 2};

Physical Surface("body1") = {1};
Physical Surface("body2") = {2};
Physical Curve("contact1") = {4};
Physical Curve("contact2") = {6};
Physical Curve("symmetry") = {5, 9};
Physical Curve("support") = {1};
Physical Curve("load") = {8};
