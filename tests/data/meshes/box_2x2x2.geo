// The reader tests' box: 2x2x2 hexahedra on [0,2] x [0,1] x [0,3], two volumes stacked
// in z (the same box as box_2x2x2.exo). Mesh with: gmsh -3 box_2x2x2.geo -format msh41
SetFactory("Built-in");
Point(1) = {0, 0, 0}; Point(2) = {2, 0, 0}; Point(3) = {2, 1, 0}; Point(4) = {0, 1, 0};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Transfinite Curve{1, 2, 3, 4} = 3;
Transfinite Surface{1};
Recombine Surface{1};
lower[] = Extrude {0, 0, 1.5} { Surface{1}; Layers{1}; Recombine; };
upper[] = Extrude {0, 0, 1.5} { Surface{lower[0]}; Layers{1}; Recombine; };
Physical Volume("lower") = {lower[1]};
Physical Volume("upper") = {upper[1]};
Physical Surface("bottom") = {1};
Physical Surface("top") = {upper[0]};
Physical Curve("edge") = {1};
Physical Point("origin") = {1};
