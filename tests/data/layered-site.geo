// Regenerate the committed mesh with: gmsh -2 -format msh41 -clscale 2.5 layered-site.geo -o layered-site.msh
// A 20 m wide site: 3 m of soft clay over 4 m of stiff clay, meshed at about lc = 1 m.
// Physical groups name what a scene refers to: the two surfaces become zones, the curves
// become boundaries a selection can use (on = "seabed").
lc = 1.0;
Point(1) = {0, 0, 0, lc};
Point(2) = {20, 0, 0, lc};
Point(3) = {20, 4, 0, lc};
Point(4) = {0, 4, 0, lc};
Point(5) = {20, 7, 0, lc};
Point(6) = {0, 7, 0, lc};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Line(5) = {3, 5};
Line(6) = {5, 6};
Line(7) = {6, 4};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Curve Loop(2) = {-3, 5, 6, 7};
Plane Surface(2) = {2};
Physical Surface("stiff-clay") = {1};
Physical Surface("soft-clay") = {2};
Physical Curve("base") = {1};
Physical Curve("seabed") = {6};
Physical Curve("sides") = {2, 4, 5, 7};
