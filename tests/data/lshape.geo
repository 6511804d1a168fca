// L-shaped domain (a reflex corner at (0.5, 0.5)), one tag for the whole boundary.
Mesh.CharacteristicLengthMax = 0.125;
Point(1) = {0, 0, 0};
Point(2) = {1, 0, 0};
Point(3) = {1, 0.5, 0};
Point(4) = {0.5, 0.5, 0};
Point(5) = {0.5, 1, 0};
Point(6) = {0, 1, 0};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 5};
Line(5) = {5, 6};
Line(6) = {6, 1};
Curve Loop(1) = {1, 2, 3, 4, 5, 6};
Plane Surface(1) = {1};
Physical Curve("wall") = {1, 2, 3, 4, 5, 6};
Physical Surface("domain") = {1};
