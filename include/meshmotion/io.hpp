#pragma once
/// \file
/// The io layer: Gmsh .msh, SU2 .su2, CGNS, VTK .vtu and OpenFOAM reading and writing, mesh
/// summaries.

#include "meshmotion/io/any_mesh.hpp"
#include "meshmotion/io/gmsh_reader.hpp"
#include "meshmotion/io/gmsh_writer.hpp"
#include "meshmotion/io/mesh_summary.hpp"
#include "meshmotion/io/mesh_io.hpp"
#include "meshmotion/io/openfoam.hpp"
#include "meshmotion/io/su2_reader.hpp"
#include "meshmotion/io/su2_writer.hpp"
#include "meshmotion/io/vtu_reader.hpp"
#include "meshmotion/io/vtu_writer.hpp"
