// Two stacked elastic blocks, half model by symmetry (the paper's scenes S1-S4).
//
// Open it in gmsh (`gmsh meshes/blocks.geo`, then Mesh > 2D) and change the parameters in its
// menu, or `gmsh -2 -setnumber size2 0.25 meshes/blocks.geo`. contactfx builds its `blocks`
// scene from this file (contactfx/meshes/blocks.py sets every parameter, then meshes).
// Body 1 is the base [0, l1/2] x [0, h1], body 2 the top block [0, l2/2] x [h1, h1 + h2]; x = 0
// is the symmetry axis. Quadrilaterals, transfinite (graded along x by `grading`), unless
// `user_sizes` = 1 (the adaptive loop's background view then sets the sizes).

DefineConstant[
  l1 = {10, Name "Parameters/l1: width of the base (full)"},
  l2 = {6, Name "Parameters/l2: width of the top block (full)"},
  h1 = {3, Name "Parameters/h1: height of the base"},
  h2 = {3, Name "Parameters/h2: height of the top block"},
  size1 = {0.125, Name "Parameters/size1: element size in the base"},
  size2 = {0.125, Name "Parameters/size2: element size in the top block"},
  grading1 = {1, Name "Parameters/grading1: size ratio of neighbours along x, base"},
  grading2 = {1, Name "Parameters/grading2: size ratio of neighbours along x, top"},
  user_sizes = {0, Choices{0, 1}, Name "Parameters/user_sizes: sizes from a background view"}
];

half1 = 0.5 * l1;
half2 = 0.5 * l2;
// Body b, a row of rectangles [xs(i), xs(i+1)] x [y0, y1] sharing their vertical curves. The
// narrower body's corner must be a node of the wider body's contact edge, so the wider body is
// built from two rectangles split there (conforming inside the body). Every horizontal curve
// runs left to right and every vertical one bottom to top, so opposite sides of a rectangle
// carry the same progression. Elements along an edge: length / size rounded half to even (as
// Python's round), at least 1.
// Entity tags counted as gmsh's API counts them (one sequence per kind of entity).
np_ = 0; nl_ = 0; ncl_ = 0; ns_ = 0;
For b In {1 : 2}
  mine = (b == 1) ? half1 : half2;
  other = (b == 1) ? half2 : half1;
  If (other < mine)
    xs() = {0, other, mine};
  Else
    xs() = {0, mine};
  EndIf
  y0 = (b == 1) ? 0 : h1;
  y1 = (b == 1) ? h1 : h1 + h2;
  sz = (b == 1) ? size1 : size2;
  grading = (b == 1) ? grading1 : grading2;
  bot() = {}; top() = {}; bottoms() = {}; tops() = {}; verticals() = {}; surfaces() = {};
  For i In {0 : #xs() - 1}
    np_ += 1; bot(i) = np_; Point(bot(i)) = {xs(i), y0, 0};
  EndFor
  For i In {0 : #xs() - 1}
    np_ += 1; top(i) = np_; Point(top(i)) = {xs(i), y1, 0};
  EndFor
  For i In {0 : #xs() - 2}
    nl_ += 1; bottoms(i) = nl_; Line(bottoms(i)) = {bot(i), bot(i + 1)};
  EndFor
  For i In {0 : #xs() - 2}
    nl_ += 1; tops(i) = nl_; Line(tops(i)) = {top(i), top(i + 1)};
  EndFor
  For i In {0 : #xs() - 1}
    nl_ += 1; verticals(i) = nl_; Line(verticals(i)) = {bot(i), top(i)};
  EndFor
  For i In {0 : #xs() - 2}
    ncl_ += 1; Curve Loop(ncl_) = {bottoms(i), verticals(i + 1), -tops(i), -verticals(i)};
    ns_ += 1; Plane Surface(ns_) = {ncl_};
    surfaces() += ns_;
  EndFor
  If (!user_sizes)
    For i In {0 : #xs() - 1}
      If (i < #xs() - 1)
        quot = (xs(i + 1) - xs(i)) / sz;
      Else
        quot = (y1 - y0) / sz;
      EndIf
      ndiv = Floor(quot);
      If (quot - ndiv > 0.5 || (quot - ndiv == 0.5 && ndiv % 2 == 1))
        ndiv = ndiv + 1;
      EndIf
      ndiv = Max(1, ndiv);
      If (i < #xs() - 1)
        Transfinite Curve{bottoms(i), tops(i)} = ndiv + 1 Using Progression grading;
        Transfinite Surface{surfaces(i)} = {bot(i), bot(i + 1), top(i + 1), top(i)};
      Else
        Transfinite Curve{verticals()} = ndiv + 1;
      EndIf
    EndFor
  EndIf
  Recombine Surface{surfaces()};
  If (b == 1)
    body1() = surfaces(); top1() = tops(); left1 = verticals(0); base() = bottoms();
  Else
    body2() = surfaces(); bottom2() = bottoms(); left2 = verticals(0); load() = tops();
  EndIf
EndFor

Physical Surface("body1") = {body1()};
Physical Surface("body2") = {body2()};
Physical Curve("contact1") = {top1()};
Physical Curve("contact2") = {bottom2()};
Physical Curve("symmetry") = {left1, left2};
Physical Curve("support") = {base()};
Physical Curve("load") = {load()};
