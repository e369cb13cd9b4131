// move_mesh_mpi: move_mesh on MPI ranks. Rank 0 reads the mesh and resolves the boundary
// conditions on the whole mesh; METIS partitions the cells; every rank moves its part
// (distributed RBF, or linear/stiffened elasticity through PETSc); rank 0 gathers the moved
// nodes and writes one mesh with the input's numbering (and, with --rank-files, each rank its
// own part).
//
//   mpiexec -n 4 move_mesh_mpi wing.msh -o moved.msh --group wall --rotate 30 --center 0.25,0 --fixed farfield
//   mpiexec -n 2 move_mesh_mpi wing.su2 -o moved.su2 --group wall --translate 0,0.1 --method sle --petsc-solver cg_hypre
//
// Each rank runs --threads threads (default: OMP_NUM_THREADS when set, else the node's cores
// shared among the ranks on it). With rbf, --boundary-solve says where the boundary system is
// solved (automatic: through PETSc on several ranks once it is big enough, see docs/parallel.md).
// PETSc options refine the elasticity solver through PETSC_OPTIONS with the prefix
// meshmotion_ (e.g. PETSC_OPTIONS="-meshmotion_ksp_monitor"). Exit codes as move_mesh: 0
// moved and valid, 1 error (nothing written), 2 written with invalid cells or refused by
// --strict. Every rank exits with the same code.

#include "meshmotion/core/json.hpp"
#include "meshmotion/io.hpp"
#include "meshmotion/movers/registry.hpp"
#include "meshmotion/movers/step_driver.hpp"
#include "meshmotion/parallel/partition.hpp"
#include "meshmotion/parallel/registry.hpp"
#include "meshmotion/quality.hpp"

#include "../motion_arguments.hpp"
#include "../mover_arguments.hpp"
#include "../program.hpp"

#include <CLI/CLI.hpp>

#include <petscsys.h>

#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <memory>

using namespace meshmotion;
using namespace meshmotion::parallel;

namespace {

struct Arguments {
  std::string input, output;
  examples::MotionArguments motion;
  KeyValues parallel;  ///< the flags of ParallelOptions given
  int threads = 0;
  bool json = false, strict = false, overwrite = false, keep_orientation = false, rank_files = false;
  examples::MoverArguments mover;
  examples::FoamSelection foam;
};

// Threads per rank: --threads, else OMP_NUM_THREADS, else the node's cores shared among its ranks.
int threads_per_rank(MPI_Comm comm, int asked) {
  const int share = node_share_of_cores(comm);  // collective: every rank asks, whatever it was given
  if (asked > 0) return asked;
  return std::getenv("OMP_NUM_THREADS") != nullptr ? 0 : share;
}

// rank<R>.<ext> beside OUTPUT: each rank's part with its local numbering.
std::string rank_file(const std::string& output, int rank) {
  std::filesystem::path p(output);
  const std::string ext = p.extension().string();
  return p.replace_extension("").string() + ".rank" + std::to_string(rank) + ext;
}

template <int Dim>
int run(const Arguments& a, std::unique_ptr<Mesh<Dim>> whole) {
  const MPI_Comm comm = MPI_COMM_WORLD;
  const bool root = rank_of(comm) == 0;
  const int ranks = size_of(comm);
  // Rank 0 prepares the whole mesh and its boundary; the others wait for its verdict.
  ResolvedBoundary<Dim> boundary;
  QualityReport before;
  MoverConfig<Dim> config;
  ParallelOptions parallel;
  collective(comm, [&] {
    KeyValues given = a.parallel;
    for (auto& kv : examples::given_options(a.mover)) given.push_back(std::move(kv));
    config = mover_config<Dim>(a.mover.method, take_parallel_options(given, parallel));
    // A method without a distributed mover is refused on every rank, before any work.
    const DistributedMethod<Dim>* method = find_distributed_method<Dim>(config.method);
    if (method == nullptr)
      throw InputError("move_mesh_mpi: --method '" + config.method + "' has no distributed mover (expected " +
                       known_distributed_methods<Dim>() + ")");
    if (!root) return;
    // As move_mesh: an output that cannot hold the mesh's order is refused before any work.
    int order = 1;
    for (const auto& b : whole->cells) order = std::max(order, meshmotion::order(b.type));
    check_mesh_output(a.output, order);
    examples::handle_orientation(*whole, a.input, a.keep_orientation);
    name_unnamed_facet_groups(*whole);
    const BoundarySpec<Dim> spec = examples::boundary_spec<Dim>(a.motion, *whole);
    boundary = spec.resolve(*whole);
    examples::note_unlisted_groups(*whole, boundary);
    before = quality_report(*whole, Metric::skew);
  });
  const Mesh<Dim> empty;
  const DistributedMesh<Dim> part = partition_mesh(comm, root ? *whole : empty);
  const ResolvedBoundary<Dim> local = distribute_boundary(part, boundary);
  const std::unique_ptr<DistributedMover<Dim>> mover = make_distributed_mover(config, parallel);
  // Set up before anything moves, as move_mesh and a solver's time loop do (run_steps): the RBF
  // then takes the motion's rigid part at the move, and gives move_mesh's displacements.
  ResolvedBoundary<Dim> rest = local;
  rest.displacements.setZero();
  mover->setup(part, rest);
  const Points<Dim> displacement = mover->move(local.displacements);
  const MoverStats stats = mover->stats();
  double seconds[2] = {stats.setup_seconds, stats.move_seconds};
  MPI_Allreduce(MPI_IN_PLACE, seconds, 2, MPI_DOUBLE, MPI_MAX, comm);
  const Points<Dim> moved_local = part.local.points + displacement;
  if (a.rank_files) {
    Mesh<Dim> mine = part.local;
    mine.points = moved_local;
    collective(comm, [&] { write_mesh(rank_file(a.output, rank_of(comm)), mine); });
  }
  const Points<Dim> moved = gather_owned(part.view(), moved_local, part.num_global_nodes);

  int code = examples::exit_ok;
  collective(comm, [&] {
    if (!root) return;
    whole->points = moved;
    examples::note_mover_choices(stats);
    const QualityReport after = quality_report(*whole, Metric::skew);
    const examples::MovedVerdict verdict = examples::moved_verdict(*whole, after, a.input);
    const bool invalid = verdict.invalid > 0;
    if (invalid && a.strict)
      throw InvalidMeshError("move_mesh_mpi: " + std::to_string(verdict.invalid) + " of " + std::to_string(verdict.cells) +
                             " cells invalid after the motion (--strict: nothing written)");
    examples::write_output(a.output, *whole, a.input);
    // move_mesh's report: the slowest rank's times, rank 0's other figures.
    MoverStats step = stats;
    step.setup_seconds = seconds[0];
    step.move_seconds = seconds[1];
    const DistributedChoices chose = mover->choices();
    const MoveReport report{config.method, 1, whole->num_nodes(), seconds[0], seconds[1], before, after, {step}};
    if (a.json) {
      JsonWriter w(std::cout);
      w.begin_object().key("input").value(a.input).key("output").value(a.output);
      w.key("ranks").value(ranks).key("threads_per_rank").value(num_threads());
      write_json_fields(w, chose);
      write_json_fields(w, report);
      if (verdict.foam) {
        w.key("checkmesh_after");
        write_json(w, *verdict.foam);
      }
      w.end_object();
      std::cout << "\n";
    } else {
      std::cout << "moved " << whole->num_nodes() << " nodes with " << config.method << " on " << ranks << " rank(s) of "
                << num_threads() << " thread(s)"
                << " (times: the slowest rank)\n";
      write_text(std::cout, chose, 2);
      write_text(std::cout, report, 2);
      if (verdict.foam) {
        std::cout << "  the case's own cells (checkMesh's measures; the validity verdict):\n";
        write_text(std::cout, *verdict.foam, 4);
      }
    }
    if (invalid) {
      std::cerr << "wrote " << a.output << " WITH " << verdict.invalid << " INVALID CELLS of " << verdict.cells << "\n";
      code = examples::exit_invalid;
    } else if (!a.json) {
      std::cout << "wrote " << a.output << "\n";
    }
  });
  MPI_Bcast(&code, 1, MPI_INT, 0, comm);
  return code;
}

int main_body(int argc, char** argv) {
  const MPI_Comm comm = MPI_COMM_WORLD;
  const bool root = rank_of(comm) == 0;
  CLI::App app{"Move a mesh on MPI ranks: read on rank 0, partitioned by METIS, moved by the distributed movers"};
  examples::add_version_flag(app);
  Arguments a;
  app.add_option("input", a.input, "Input mesh (.msh, .su2, .cgns, .vtu) or OpenFOAM case folder")->check(CLI::ExistingPath);
  app.add_option("-o,--output", a.output,
                 "Output mesh (.msh, .su2, .cgns, .vtu), or an OpenFOAM case (its points replaced; give --overwrite when it "
                 "is the input) or a time folder of it (case/0.001), or a new folder (a new case: the input case's cells, "
                 "patches and zones, moved); written by rank 0");
  examples::add_motion_options(app, a.motion);
  examples::add_mover_options(app, a.mover, known_methods<3>());
  examples::add_option_flags(app, option_docs(ParallelOptions{}), a.parallel, "Distributed solves (boundary_solve: rbf; petsc_*: le, sle)");
  app.add_option("--threads", a.threads,
                 "threads per rank (0: OMP_NUM_THREADS if set, else the node's cores shared among its ranks)")
      ->capture_default_str()
      ->check(CLI::Range(0, max_threads));
  app.add_flag("--rank-files", a.rank_files, "also write each rank's part as OUTPUT's stem + .rankR + extension");
  app.add_flag("--strict", a.strict, "write nothing when invalid cells remain (exit 2)");
  app.add_flag("--overwrite", a.overwrite, "allow the output to be the input file");
  app.add_flag("--keep-orientation", a.keep_orientation,
               "refuse a mesh whose cells are all negatively oriented instead of reorienting it");
  app.add_flag("--json", a.json, "Print one JSON object (rank 0)");
  examples::add_foam_options(app, a.foam);
  // Every rank parses the same words; rank 0 alone prints help or the complaint.
  if (const auto rc = meshmotion::examples::parse_command_line(app, argc, argv, root)) return *rc;
  // Rank 0 reports; every rank gets the same exception from the collective calls.
  return examples::guarded(a.json && root, [&] {
    try {
      if (examples::list_options<2>(a.mover)) return examples::exit_ok;
      int dim = 0;
      std::unique_ptr<AnyMesh> mesh;
      set_num_threads(threads_per_rank(comm, a.threads));
      collective(comm, [&] {
        if (a.input.empty() || a.output.empty()) throw InputError("move_mesh_mpi: give an input mesh and -o OUTPUT (see --help)");
        examples::require_motion(a.motion, "move_mesh_mpi");
        a.input = examples::foam_input(a.input, a.foam).string();
        a.output = examples::foam_output(a.output, a.foam).string();
        if (!root) return;
        examples::check_output(a.input, a.output, 1, a.overwrite);
        if (a.rank_files)
          for (int r = 0; r < size_of(comm); ++r) {
            check_mesh_output(rank_file(a.output, r));
            examples::check_side_output(rank_file(a.output, r), {a.input}, {a.output});
          }
        mesh = std::make_unique<AnyMesh>(examples::read_input(a.input));
        dim = std::holds_alternative<Mesh<2>>(*mesh) ? 2 : 3;
      });
      MPI_Bcast(&dim, 1, MPI_INT, 0, comm);
      if (dim == 2) return run<2>(a, root ? std::make_unique<Mesh<2>>(std::move(std::get<Mesh<2>>(*mesh))) : nullptr);
      return run<3>(a, root ? std::make_unique<Mesh<3>>(std::move(std::get<Mesh<3>>(*mesh))) : nullptr);
    } catch (const Error&) {
      if (!root) std::cerr.setstate(std::ios::failbit);  // one message, from rank 0
      throw;
    }
  });
}

}  // namespace

int main(int argc, char** argv) {
  // PETSc's options come from PETSC_OPTIONS: the command line is ours.
  int petsc_argc = 1;
  if (PetscInitialize(&petsc_argc, &argv, nullptr, nullptr) != 0) return examples::exit_error;
  const int code = main_body(argc, argv);
  PetscFinalize();
  return code;
}
