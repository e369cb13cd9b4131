// The core of the compiled library (target meshmotion::compiled) that every layer uses: the
// sparse and dense solvers with their Eigen factorizations, the numbering of sub-entities
// (edges, facets, faces) and the boundary conditions, behind the extern template declarations
// consumers see. Without them each test, program and mover object compiled its own copies.

#include "meshmotion/core/topology.hpp"
#include "meshmotion/movers/boundary.hpp"
#include "meshmotion/solvers/dense_solver.hpp"
#include "meshmotion/solvers/linear_solver.hpp"

namespace meshmotion {

template std::unique_ptr<detail::SparseBackend> detail::make_backend<0>(const SolverOptions&);
template class BasicLinearSolver<>;
template class BasicDenseSolver<>;

template void validate<2>(const Mesh<2>&);
template void validate<3>(const Mesh<3>&);

template EdgeTopology detail::edges_of_source<detail::BlockListSource>(const detail::BlockListSource&);
template FacetTopology detail::facets_of_source<2, detail::BlockListSource>(const detail::BlockListSource&, detail::SubEntity);
template FacetTopology detail::facets_of_source<4, detail::BlockListSource>(const detail::BlockListSource&, detail::SubEntity);
template FacetTopology unique_facets<Mesh<2>>(const Mesh<2>&);
template FacetTopology unique_facets<Mesh<3>>(const Mesh<3>&);
template std::vector<ElementBlock> boundary_facets<Mesh<2>>(const Mesh<2>&, const FacetTopology&, int);
template std::vector<ElementBlock> boundary_facets<Mesh<3>>(const Mesh<3>&, const FacetTopology&, int);

template PlaneFit<2> fit_plane<2>(const Points<2>&, std::span<const Index>);
template PlaneFit<3> fit_plane<3>(const Points<3>&, std::span<const Index>);
template class BoundaryCollector<2>;
template class BoundaryCollector<3>;
template class BoundarySpec<2>;
template class BoundarySpec<3>;

}  // namespace meshmotion
