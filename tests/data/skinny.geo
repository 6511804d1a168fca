// rectangle [0,4]x[0,1] with transfinite skinny triangles (aspect ~ 40), progression in x
Point(1) = {0,0,0}; Point(2) = {4,0,0}; Point(3) = {4,1,0}; Point(4) = {0,1,0};
Line(1) = {1,2}; Line(2) = {2,3}; Line(3) = {3,4}; Line(4) = {4,1};
Curve Loop(1) = {1,2,3,4}; Plane Surface(1) = {1};
Transfinite Curve{1} = 9 Using Progression 1.0; Transfinite Curve{3} = 9 Using Progression 1.0;
Transfinite Curve{2,4} = 81 Using Progression 1.0;
Transfinite Surface{1};
Physical Curve("floor") = {1}; Physical Curve("right") = {2}; Physical Curve("top") = {3}; Physical Curve("left") = {4};
Physical Surface("domain") = {1};
Mesh.MshFileVersion = 4.1;
