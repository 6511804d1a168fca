// Unit square meshed with quadrilaterals (recombined): psmpm must reject it.
Mesh.CharacteristicLengthMax = 0.5;
Point(1) = {0, 0, 0};
Point(2) = {1, 0, 0};
Point(3) = {1, 1, 0};
Point(4) = {0, 1, 0};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Recombine Surface {1};
Physical Curve("wall") = {1, 2, 3, 4};
Physical Surface("domain") = {1};
