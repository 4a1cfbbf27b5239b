// Unit cube [0,1]^3 for the Gmsh loader tests (tests/test_mesh_gmsh.c).
// Regenerate the fixtures (from this directory):
//   gmsh -3 -format msh41 cube.geo -o cube_v41.msh
//   gmsh -3 -format msh41 -bin cube.geo -o cube_v41_bin.msh
//   gmsh -3 -format msh22 cube.geo -o cube_v22.msh
//   gmsh -3 -format msh40 cube.geo -o cube_v40.msh
//   gmsh -2 -format msh41 cube.geo -o cube_surface.msh
SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 1, 1, 1};
Mesh.CharacteristicLengthFromPoints = 0; // size from the maximum only
Mesh.CharacteristicLengthMax = 0.4;
// OpenCASCADE box faces: 1 x=0, 2 x=1, 3 y=0, 4 y=1, 5 z=0, 6 z=1.
Physical Volume("solid") = {1};
Physical Surface("bottom") = {5};
Physical Surface("top") = {6};
