#pragma once
/// \file
/// The optional parallel layer (target meshmotion::parallel; MPI, PETSc and METIS): partitioned
/// meshes and the distributed movers. See docs/parallel.md.

#include "meshmotion/parallel/communicator.hpp"
#include "meshmotion/parallel/distributed_elasticity.hpp"
#include "meshmotion/parallel/distributed_mesh.hpp"
#include "meshmotion/parallel/distributed_rbf.hpp"
#include "meshmotion/parallel/parallel_options.hpp"
#include "meshmotion/parallel/partition.hpp"
#include "meshmotion/parallel/registered_movers.hpp"
#include "meshmotion/parallel/registry.hpp"
