// MPI from Python, where the parallel layer is built: a mesh read on one rank partitioned over
// an mpi4py communicator, and the distributed movers (RBF with its reverse derivative,
// elasticity through PETSc) on each rank's part. Warp(comm=...) is built on them.
//
// An mpi4py Comm reaches the library by its Fortran handle (Comm.py2f), which the MPI this
// module links converts back: no mpi4py header is needed, only the MPI mpi4py runs on
// (Debian's Open MPI for both).

#include "bindings.hpp"

#ifdef MESHMOTION_PYTHON_PARALLEL

#include "mover_keywords.hpp"

#include "meshmotion/parallel/partition.hpp"
#include "meshmotion/parallel/petsc.hpp"
#include "meshmotion/parallel/plane_fit.hpp"
#include "meshmotion/parallel/registry.hpp"

#include <petscsys.h>

#include <memory>
#include <numeric>
#include <optional>
#include <span>
#include <string>
#include <variant>
#include <vector>

namespace meshmotion::python {

namespace {

MPI_Comm communicator(const py::object& comm) {
  int initialized = 0;
  MPI_Initialized(&initialized);
  if (!initialized) throw InputError("MPI is not initialized: import mpi4py.MPI before passing a communicator");
  if (!py::hasattr(comm, "py2f"))
    throw InputError("expected an mpi4py communicator (got " + py::repr(py::type::of(comm)).cast<std::string>() + ")");
  const MPI_Comm c = MPI_Comm_f2c(comm.attr("py2f")().cast<MPI_Fint>());
  if (c == MPI_COMM_NULL) throw InputError("the communicator is MPI.COMM_NULL");
  return c;
}

// PETSc starts on the MPI that mpi4py started, on first need, and stops at the interpreter's
// exit before mpi4py finalizes MPI (atexit handlers run before the Py_AtExit one mpi4py
// registers). PETSc started by someone else (petsc4py) is theirs to stop. Python keeps its own
// signal handling.
void ensure_petsc() {
  PetscBool initialized = PETSC_FALSE;
  parallel::detail::petsc_check(PetscInitialized(&initialized), "meshmotion", "PetscInitialized");
  if (initialized) return;
  parallel::detail::petsc_check(PetscOptionsSetValue(nullptr, "-no_signal_handler", nullptr), "meshmotion", "PetscOptionsSetValue");
  parallel::detail::petsc_check(PetscInitializeNoArguments(), "meshmotion", "PetscInitializeNoArguments");
  py::module_::import("atexit").attr("register")(py::cpp_function([] { PetscFinalize(); }));
}

template <class T>
py::array_t<T> read_only_view(const std::vector<T>& values, const py::object& owner) {
  py::array_t<T> view(static_cast<py::ssize_t>(values.size()), values.data(), owner);
  view.attr("setflags")(py::arg("write") = false);
  return view;
}

// A distributed mover chosen by method name through the distributed registry, with the calls
// bind_move_calls binds; it keeps the arrays of a solver's own partition, which the mover views.
template <int Dim>
class DistributedMover {
 public:
  DistributedMover(const std::string& method, const py::kwargs& options) {
    parallel::ParallelOptions parallel;
    const MoverConfig<Dim> config =
        mover_config_from<Dim>(method, options, option_docs(parallel),
                               [&](const std::string& key, const std::string& text) { return set_option(parallel, key, text); });
    mover_ = parallel::make_distributed_mover(config, parallel);
  }

  void setup(const parallel::DistributedMesh<Dim>& mesh, const ResolvedBoundary<Dim>& boundary) { mover_->setup(mesh, boundary); }
  // A solver's own partition: no cells (the registry refuses the methods that need them).
  void setup(MPI_Comm comm, Points<Dim> points, std::vector<std::int64_t> global_ids, std::vector<int> owner,
             const ResolvedBoundary<Dim>& boundary) {
    points_ = std::move(points);
    global_ids_ = std::move(global_ids);
    owner_ = std::move(owner);
    mover_->setup(parallel::PartitionView<Dim>{comm, points_, global_ids_, owner_}, boundary);
  }
  void move_into(PointsView<Dim> d, Points<Dim>& out) { mover_->move_into(d, out); }
  void move_into(PointsView<Dim> d, Eigen::Ref<Points<Dim>> out) { mover_->move_into(d, out); }
  [[nodiscard]] Points<Dim> derivative_reverse(PointsView<Dim> v) { return mover_->derivative_reverse(v); }
  [[nodiscard]] Points<Dim> velocity(PointsView<Dim> v) { return mover_->velocity(v); }
  /// Every distributed mover is linear in the displacements and gives its reverse derivative.
  [[nodiscard]] bool has_derivatives() const { return true; }
  [[nodiscard]] MoverStats stats() const { return mover_->stats(); }
  /// The RBF boundary system is solved through PETSc (false for elasticity, which always is).
  [[nodiscard]] bool petsc_solve() const { return mover_->choices().boundary_solve == "petsc"; }
  /// Where the RBF boundary system is solved (BoundarySolve's name; elasticity: none).
  [[nodiscard]] std::string boundary_solve() const { return mover_->choices().boundary_solve; }

 private:
  std::unique_ptr<parallel::DistributedMover<Dim>> mover_;
  Points<Dim> points_;  ///< a solver's own partition (setup from arrays)
  std::vector<std::int64_t> global_ids_;
  std::vector<int> owner_;
};

}  // namespace

void bind_parallel(py::module_& m) {
  m.attr("have_mpi") = true;
  m.def(
      "sliding_plane_normal",
      [](const py::object& comm, const std::string& group, const py::array& points) {
        const MPI_Comm c = communicator(comm);
        const auto normal = [&]<int Dim>() {
          const Points<Dim> at(rows_of<Dim>(points, "sliding_plane_normal: points"));
          std::vector<Index> all(static_cast<std::size_t>(at.cols()));
          std::iota(all.begin(), all.end(), Index{0});
          py::gil_scoped_release release;
          const Vec<Dim> n = parallel::sliding_plane_normal<Dim>(c, group, at, all);
          return std::vector<double>(n.data(), n.data() + Dim);
        };
        return points.ndim() == 2 && points.shape(1) == 2 ? normal.template operator()<2>() : normal.template operator()<3>();
      },
      py::arg("comm"), py::arg("group"), py::arg("points"),
      "collective: the normal of a sliding group from its nodes (n, dim) on each rank (each node on one rank), as "
      "BoundarySpec.resolve fits it on one mesh; the same error on every rank when they are too few or not planar");
  for_each_dimension([&]<int Dim>() {
    const std::string suffix = std::to_string(Dim);
    using M = Mesh<Dim>;
    using D = parallel::DistributedMesh<Dim>;
    using B = ResolvedBoundary<Dim>;
    py::class_<D>(m, ("DistributedMesh" + suffix).c_str(),
                  "a rank's part of a mesh: local nodes (owned first, then ghosts, each by ascending global id), cells, "
                  "facets and groups")
        .def_static(
            "partition",
            [](const py::object& comm, const M* whole, std::optional<std::vector<int>> cell_ranks) {
              const MPI_Comm c = communicator(comm);
              const M empty;
              const std::vector<int> ranks = cell_ranks.value_or(std::vector<int>{});
              py::gil_scoped_release release;
              return parallel::partition_mesh(c, whole != nullptr ? *whole : empty, std::span<const int>(ranks));
            },
            py::arg("comm"), py::arg("mesh") = nullptr, py::arg("cell_ranks") = std::nullopt, py::keep_alive<0, 1>(),
            "collective: split the mesh given on rank 0 (None elsewhere) by METIS, or by cell_ranks (rank per cell, on "
            "rank 0)")
        .def_property_readonly("local", [](D& d) -> M& { return d.local; }, py::return_value_policy::reference_internal)
        .def_property_readonly("global_ids", [](const py::object& self) { return read_only_view(self.cast<const D&>().global_ids, self); })
        .def_property_readonly("owner", [](const py::object& self) { return read_only_view(self.cast<const D&>().owner, self); })
        .def_property_readonly("num_owned", [](const D& d) { return d.num_owned; })
        .def_property_readonly("num_global_nodes", [](const D& d) { return d.num_global_nodes; })
        .def("local_index", &D::local_index, py::arg("global_id"), "the local index of a global node (-1: not on this rank)")
        .def(
            "distribute_boundary",
            [](const D& d, const B* whole) {
              const B empty;
              py::gil_scoped_release release;
              return parallel::distribute_boundary(d, whole != nullptr ? *whole : empty);
            },
            py::arg("boundary") = nullptr,
            "collective: the entries of this rank's nodes of a boundary resolved on the whole mesh on rank 0")
        .def(
            "gather_owned",
            [](const D& d, const py::array& field) -> py::object {
              const Points<Dim> local(rows_of<Dim>(field, "gather_owned: field", static_cast<Index>(d.global_ids.size())));
              Points<Dim> whole;
              {
                py::gil_scoped_release release;
                whole = parallel::gather_owned(d.view(), local, d.num_global_nodes);
              }
              if (parallel::rank_of(d.comm) != 0) return py::none();
              return to_rows<Dim>(std::move(whole));
            },
            py::arg("field"), "collective: a node field (n_local, dim) of every rank as (n_global, dim) on rank 0, None elsewhere");

    using A = DistributedMover<Dim>;
    py::class_<A> c(m, ("DistributedMover" + suffix).c_str());
    c.def(py::init([](const std::string& method, const py::kwargs& options) { return std::make_unique<A>(method, options); }),
          py::arg("method"))
        .def(
            "setup",
            [](A& a, const D& mesh, const B& boundary) {
              ensure_petsc();  // elasticity always, RBF when its setup chooses PETSc
              py::gil_scoped_release release;
              a.setup(mesh, boundary);
            },
            py::arg("mesh"), py::arg("boundary"), "collective: set up on each rank's part and its boundary entries")
        .def(
            "setup_partition",
            [](A& a, const py::object& comm, const py::array& points, std::vector<std::int64_t> global_ids,
               std::vector<int> owner, const B& boundary) {
              const MPI_Comm communicator_of_ranks = communicator(comm);
              Points<Dim> local(rows_of<Dim>(points, "setup_partition: points"));
              ensure_petsc();
              py::gil_scoped_release release;
              a.setup(communicator_of_ranks, std::move(local), std::move(global_ids), std::move(owner), boundary);
            },
            py::arg("comm"), py::arg("points"), py::arg("global_ids"), py::arg("owner"), py::arg("boundary"),
            "collective: set up on a solver's own partition, each rank's local nodes (n_local, dim) in its order with "
            "their global ids and owner ranks, and the boundary entries of those nodes (rbf only)")
        .def_property_readonly("petsc_solve", &A::petsc_solve)
        .def_property_readonly("boundary_solve", &A::boundary_solve,
                               "where the last setup solves the RBF boundary system: replicated, petsc or patches "
                               "(the partition of unity, each patch on one rank); none for elasticity");
    bind_move_calls<Dim>(c);
  });
}

}  // namespace meshmotion::python

#else

namespace meshmotion::python {

void bind_parallel(py::module_& m) {
  m.attr("have_mpi") = false;
  m.attr("mpi_missing") = MESHMOTION_PYTHON_PARALLEL_MISSING;
}

}  // namespace meshmotion::python

#endif
