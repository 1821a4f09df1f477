// An embankment with 1:2 side slopes on two clay layers, 40 m wide and 10 m deep.
// Regenerate the committed mesh with:
//   gmsh -2 -format msh41 embankment.geo -o embankment.msh
// Physical groups name what embankment.toml refers to: each surface becomes a zone of the
// [[material]] of the same name, each curve a boundary that `on = "..."` selects.
lc_far = 1.5;  // mesh size at the far sides and the base
lc = 0.6;      // mesh size under and in the embankment

Point(1) = {0, 0, 0, lc_far};
Point(2) = {40, 0, 0, lc_far};
Point(3) = {40, 6, 0, lc_far};
Point(4) = {0, 6, 0, lc_far};
Point(5) = {40, 10, 0, lc_far};
Point(6) = {32, 10, 0, lc};    // right toe
Point(7) = {8, 10, 0, lc};     // left toe
Point(8) = {0, 10, 0, lc_far};
Point(9) = {26, 13, 0, lc};    // crest, right
Point(10) = {14, 13, 0, lc};   // crest, left

Line(1) = {1, 2};    // base
Line(2) = {2, 3};    // right side, stiff clay
Line(3) = {3, 4};    // layer interface
Line(4) = {4, 1};    // left side, stiff clay
Line(5) = {3, 5};    // right side, soft clay
Line(6) = {5, 6};    // ground right of the embankment
Line(7) = {6, 7};    // embankment base
Line(8) = {7, 8};    // ground left of the embankment
Line(9) = {8, 4};    // left side, soft clay
Line(10) = {6, 9};   // right slope
Line(11) = {9, 10};  // crest
Line(12) = {10, 7};  // left slope

Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Curve Loop(2) = {-3, 5, 6, 7, 8, 9};
Plane Surface(2) = {2};
Curve Loop(3) = {-7, 10, 11, 12};
Plane Surface(3) = {3};

Physical Surface("stiff-clay") = {1};
Physical Surface("soft-clay") = {2};
Physical Surface("fill") = {3};
Physical Curve("base") = {1};
Physical Curve("sides") = {2, 4, 5, 9};
Physical Curve("ground") = {6, 8};
Physical Curve("slopes") = {10, 12};
Physical Curve("crest") = {11};
