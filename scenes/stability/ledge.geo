// Stability matrix, case free-ledge-gmsh: a ledge 0.5 high on the left, a floor
// below on the right, a room 2.5 wide and 1.2 high (Gmsh 4.8.4:
// gmsh -2 -format msh41 ledge.geo -o ledge.msh).
Mesh.CharacteristicLengthMax = 0.08;
Point(1) = {0, 0.5, 0};
Point(2) = {1, 0.5, 0};
Point(3) = {1, 0, 0};
Point(4) = {2.5, 0, 0};
Point(5) = {2.5, 1.2, 0};
Point(6) = {0, 1.2, 0};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 5};
Line(5) = {5, 6};
Line(6) = {6, 1};
Curve Loop(1) = {1, 2, 3, 4, 5, 6};
Plane Surface(1) = {1};
Physical Curve("ledge") = {1};
Physical Curve("step") = {2};
Physical Curve("floor") = {3};
Physical Curve("right") = {4};
Physical Curve("top") = {5};
Physical Curve("left") = {6};
Physical Surface("domain") = {1};
