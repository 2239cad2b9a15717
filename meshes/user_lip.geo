// An example user design for `cupcheck stiffness --mesh`: a cup with a curved outer surface and a
// lip at the rim, drawn in Gmsh (units: mm; x = r, y = z; the rim's inner corner on y = 0).
// Mesh it with:  gmsh user_lip.geo -2 -o user_lip.msh   (or: python meshes/generate.py)
// cupcheck needs the physical curves "top_plate" and "cavity"; "outer" and "rim" are optional.
lc = 0.8;
Point(1) = {5, 7, 0, lc};        // top-plate edge, cavity side
Point(2) = {19, 0, 0, lc / 3};   // rim, inner corner (rests on the substrate)
Point(3) = {19.6, 0.7, 0, lc / 3};   // rim, outer corner (the lip)
Point(4) = {5, 9.2, 0, lc};      // top-plate edge, outer side
Point(5) = {14, 3.7, 0, lc};     // outer-surface control points
Point(6) = {9, 6.8, 0, lc};
Line(1) = {1, 2};                // cavity-facing surface
Line(2) = {2, 3};                // rim
Spline(3) = {3, 5, 6, 4};        // outer surface
Line(4) = {4, 1};                // edge clamped to the top plate
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Physical Curve("cavity") = {1};
Physical Curve("rim") = {2};
Physical Curve("outer") = {3};
Physical Curve("top_plate") = {4};
Physical Surface("wall") = {1};
Mesh.ElementOrder = 2;
Mesh.RecombineAll = 1;           // quadrilaterals (quad9); drop this line for triangle6
Mesh.SecondOrderIncomplete = 0;
