// A disk of radius R (centre at the origin) between two rigid plates (scene
// disk_between_plates.toml): the disk alone is meshed, its whole rim is the contact surface
// of both plates. The rim is split at the top and bottom points so that both are nodes.

DefineConstant[
  R = {1, Name "Parameters/R radius"},
  h = {0.25, Name "Parameters/h mesh size"}
];

Point(1) = {0, 0, 0, h};
Point(2) = {R, 0, 0, h};
Point(3) = {0, R, 0, h};
Point(4) = {-R, 0, 0, h};
Point(5) = {0, -R, 0, h};
Circle(1) = {2, 1, 3};
Circle(2) = {3, 1, 4};
Circle(3) = {4, 1, 5};
Circle(4) = {5, 1, 2};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};

Mesh.Algorithm = 8;
Mesh.RecombinationAlgorithm = 3;
Mesh.RecombineAll = 1;
Mesh.MeshSizeFromCurvature = 0;
Recombine Surface{1};

Physical Surface("disk") = {1};
Physical Curve("rim") = {1, 2, 3, 4};
