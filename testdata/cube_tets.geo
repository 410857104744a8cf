// The unit cube, the input of cube_tets.msh beside it (polydg's tet mesh reader test).
// To make it again (Gmsh 4.8): gmsh -3 cube_tets.geo -clmax 1 -clmin 1 -format msh41 -o cube_tets.msh
SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 1, 1, 1};
