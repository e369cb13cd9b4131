// The plugin's modes on a decomposed case (-parallel; serving.hpp), on meshmotion's parallel
// layer over OpenFOAM's own MPI_COMM_WORLD: the distributed mover through the cells or the
// points alone, or, for a method without one, the case gathered on rank 0.

#include "serving.hpp"

#include "meshmotion/parallel/petsc.hpp"
#include "meshmotion/parallel/registry.hpp"

#include <algorithm>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>

namespace meshmotion::foam {
namespace {

// Global ids and owners of a decomposed case's auxiliary nodes (to_mesh(): the centres of the
// faces of more than three points, then of the cells), after the points' own in `ids` and
// `owners`. A cell's centre, and the centre of a face no other rank holds, is this rank's,
// numbered after the case's points and the shared centres, rank after rank. The centre of a
// face between two ranks (`coupled`) is held by both: the sorted global ids of the face's
// points name it alike on both, and the lower rank owns it. Only for cells cut into tetrahedra
// (every rank's, or none: the centres it numbers must exist, or the ids written past `nodes`
// overrun the arrays). Collective.
void number_auxiliary_nodes(const PolyMesh& poly, Index nodes, const std::vector<char>& coupled,
                            std::vector<std::int64_t>& ids, std::vector<int>& owners) {
  const MPI_Comm comm = MPI_COMM_WORLD;
  const Index np = poly.points.cols();
  std::int64_t points_total = 0;
  for (const std::int64_t g : ids) points_total = std::max(points_total, g + 1);
  MPI_Allreduce(MPI_IN_PLACE, &points_total, 1, MPI_INT64_T, MPI_MAX, comm);
  // This rank's shared centres, each as its key: the point count, then the sorted ids.
  std::vector<std::int64_t> keys;
  std::vector<Index> shared;
  Index centre = np;
  for (Index f = 0; f < poly.num_faces(); ++f) {
    const auto v = poly.face(f);
    if (v.size() <= 3) continue;
    const Index node = centre++;
    if (!coupled[static_cast<std::size_t>(f)]) continue;
    keys.push_back(static_cast<std::int64_t>(v.size()));
    const auto first = keys.size();
    for (const Index p : v) keys.push_back(ids[static_cast<std::size_t>(p)]);
    std::sort(keys.begin() + static_cast<std::ptrdiff_t>(first), keys.end());
    shared.push_back(node);
  }
  const auto key_at = [](const std::vector<std::int64_t>& list, std::size_t at) {
    const auto begin = list.begin() + static_cast<std::ptrdiff_t>(at) + 1;
    return std::vector<std::int64_t>(begin, begin + list[at]);
  };
  std::vector<int> counts;
  const std::vector<std::int64_t> every = parallel::all_gather(comm, keys, &counts);
  struct Holder {
    int owner;
    std::int64_t id;
  };
  std::map<std::vector<std::int64_t>, Holder> holders;  // emplace keeps the lowest rank
  std::size_t at = 0;
  for (std::size_t r = 0; r < counts.size(); ++r)
    for (const std::size_t end = at + static_cast<std::size_t>(counts[r]); at < end; at += 1 + static_cast<std::size_t>(every[at]))
      holders.emplace(key_at(every, at), Holder{static_cast<int>(r), 0});
  std::int64_t next = points_total;
  for (auto& [key, holder] : holders) holder.id = next++;
  const auto n_own = static_cast<std::int64_t>(nodes - np) - static_cast<std::int64_t>(shared.size());
  std::int64_t first_own = 0;
  MPI_Exscan(&n_own, &first_own, 1, MPI_INT64_T, MPI_SUM, comm);
  if (parallel::rank_of(comm) == 0) first_own = 0;
  ids.resize(static_cast<std::size_t>(nodes), -1);
  owners.resize(static_cast<std::size_t>(nodes), parallel::rank_of(comm));
  at = 0;
  for (const Index node : shared) {
    const Holder& holder = holders.at(key_at(keys, at));
    ids[static_cast<std::size_t>(node)] = holder.id;
    owners[static_cast<std::size_t>(node)] = holder.owner;
    at += 1 + static_cast<std::size_t>(keys[at]);
  }
  std::int64_t own = next + first_own;
  for (std::size_t i = static_cast<std::size_t>(np); i < ids.size(); ++i)
    if (ids[i] < 0) ids[i] = own++;
}

// The whole case on rank 0, from every rank's processor mesh, for the methods that have no
// distributed mover: points by global id, cells numbered rank after rank, each face between
// two ranks once, as an internal face oriented out of the lower-numbered of its cells (as
// OpenFOAM orients it), and a coupled face with no partner on another rank (a cyclic patch's)
// as a boundary face the mover leaves interior (`coupled`). Collective; empty off rank 0.
struct WholeCase {
  PolyMesh poly;
  std::vector<char> coupled;
};
WholeCase gather_case(const PolyMesh& poly, const std::vector<char>& coupled, const std::vector<std::int64_t>& ids,
                      const std::vector<int>& owners) {
  const MPI_Comm comm = MPI_COMM_WORLD;
  std::int64_t num_points = 0;
  for (const std::int64_t g : ids) num_points = std::max(num_points, g + 1);
  MPI_Allreduce(MPI_IN_PLACE, &num_points, 1, MPI_INT64_T, MPI_MAX, comm);
  const auto cells = static_cast<std::int64_t>(poly.num_cells);
  std::int64_t first_cell = 0;
  MPI_Exscan(&cells, &first_cell, 1, MPI_INT64_T, MPI_SUM, comm);
  if (parallel::rank_of(comm) == 0) first_cell = 0;
  // Per face: its point count, its points' global ids, its owner and neighbour cell (-1 on the
  // boundary), whether it is coupled.
  std::vector<std::int64_t> faces;
  for (Index f = 0; f < poly.num_faces(); ++f) {
    const auto v = poly.face(f);
    faces.push_back(static_cast<std::int64_t>(v.size()));
    for (const Index p : v) faces.push_back(ids[static_cast<std::size_t>(p)]);
    faces.push_back(first_cell + poly.owner[static_cast<std::size_t>(f)]);
    faces.push_back(f < poly.num_internal_faces() ? first_cell + poly.neighbour[static_cast<std::size_t>(f)] : -1);
    faces.push_back(!coupled.empty() && coupled[static_cast<std::size_t>(f)] ? 1 : 0);
  }
  const Points<3> points = parallel::gather_owned(parallel::PartitionView<3>{comm, poly.points, ids, owners}, poly.points, num_points);
  const std::vector<std::int64_t> every = parallel::gather_to(comm, 0, faces);
  std::int64_t total_cells = first_cell + cells;
  MPI_Bcast(&total_cells, 1, MPI_INT64_T, parallel::size_of(comm) - 1, comm);
  WholeCase out;
  if (parallel::rank_of(comm) != 0) return out;
  struct Face {
    std::vector<Index> points;
    Index owner, neighbour;
  };
  std::vector<Face> internal, boundary;
  std::vector<char> boundary_coupled;
  std::map<std::vector<Index>, Face> waiting;  // coupled faces by their sorted points, until their partner comes
  for (std::size_t at = 0; at < every.size();) {
    const auto n = static_cast<std::size_t>(every[at]);
    Face face{std::vector<Index>(every.begin() + static_cast<std::ptrdiff_t>(at + 1), every.begin() + static_cast<std::ptrdiff_t>(at + 1 + n)),
              static_cast<Index>(every[at + 1 + n]), static_cast<Index>(every[at + 2 + n])};
    const bool is_coupled = every[at + 3 + n] != 0;
    at += n + 4;
    if (face.neighbour >= 0) {
      internal.push_back(std::move(face));
    } else if (!is_coupled) {
      boundary.push_back(std::move(face));
      boundary_coupled.push_back(0);
    } else {
      std::vector<Index> key = face.points;
      std::sort(key.begin(), key.end());
      const auto partner = waiting.find(key);
      if (partner == waiting.end()) {
        waiting.emplace(std::move(key), std::move(face));
        continue;
      }
      Face& first = partner->second;
      Face& owner_side = first.owner < face.owner ? first : face;
      internal.push_back({std::move(owner_side.points), std::min(first.owner, face.owner), std::max(first.owner, face.owner)});
      waiting.erase(partner);
    }
  }
  for (auto& [key, face] : waiting) {
    boundary.push_back(std::move(face));
    boundary_coupled.push_back(1);
  }
  out.poly.points = points;
  out.poly.num_cells = static_cast<Index>(total_cells);
  out.coupled.assign(internal.size(), 0);
  out.coupled.insert(out.coupled.end(), boundary_coupled.begin(), boundary_coupled.end());
  for (const auto* list : {&internal, &boundary})
    for (const Face& face : *list) {
      out.poly.face_nodes.insert(out.poly.face_nodes.end(), face.points.begin(), face.points.end());
      out.poly.face_offsets.push_back(static_cast<Index>(out.poly.face_nodes.size()));
      out.poly.owner.push_back(face.owner);
      if (face.neighbour >= 0) out.poly.neighbour.push_back(face.neighbour);
    }
  out.poly.patches = {{"boundary", "patch", static_cast<Index>(internal.size()), static_cast<Index>(boundary.size())}};
  return out;
}

// The distributed mover (the distributed registry's) on this rank's part: through its cells,
// cut as the serial run cuts them, with the face centres' entries, or through its points alone.
class DistributedServing final : public Serving {
 public:
  DistributedServing(const BridgeInput& input, const MoverConfig<3>& config, const parallel::ParallelOptions& parallel)
      : ids_(input.global_ids.begin(), input.global_ids.end()), owners_(input.owners),
        mover_(parallel::make_distributed_mover(config, parallel)), cells_(mover_method<3>(config.method).needs_cells) {
    const MPI_Comm comm = MPI_COMM_WORLD;
    const auto n = static_cast<Index>(input.points.size() / 3);
    points_ = n;
    ResolvedBoundary<3> b = input_boundary(input);
    entries_ = b.size();
    if (cells_) {
      const PolyMesh poly = input_cells(input);
      const std::vector<char> coupled = input_coupled(input);
      mesh_ = to_mesh(poly);
      // Every rank cuts its cells into tetrahedra when any rank must, as the serial run does.
      int cut = mesh_.num_auxiliary_nodes > 0 ? 1 : 0;
      MPI_Allreduce(MPI_IN_PLACE, &cut, 1, MPI_INT, MPI_MAX, comm);
      if (cut == 1 && mesh_.num_auxiliary_nodes == 0) mesh_ = to_mesh(poly, true);
      if (cut == 1) number_auxiliary_nodes(poly, mesh_.num_nodes(), coupled, ids_, owners_);
      centres_ = FaceCentres(poly, mesh_, coupled, b);
      mover_->setup(parallel::PartitionView<3>{comm, mesh_.points, ids_, owners_}, mesh_, b);
    } else {
      mesh_.points = Eigen::Map<const Points<3>>(input.points.data(), 3, n);
      mover_->setup(parallel::PartitionView<3>{comm, mesh_.points, ids_, owners_}, b);
    }
    given_.setZero(3, b.size());
    moved_.resize(3, mesh_.num_nodes());
  }

  void move(const std::vector<double>& boundary_displacements, std::vector<double>& out) override {
    const Eigen::Map<const Points<3>> d(boundary_displacements.data(), 3, entries_);
    if (cells_) {
      centres_.prescribe(d, given_);
      mover_->move_into(given_, moved_);
    } else {
      mover_->move_into(d, moved_);
    }
    out.assign(moved_.data(), moved_.data() + 3 * points_);
  }
  [[nodiscard]] MoverStats stats() const override { return mover_->stats(); }

 private:
  // The mover's view of the part: the points (cells: with the centres), their global ids and
  // owners, kept for the mover's lifetime.
  Mesh<3> mesh_;
  std::vector<std::int64_t> ids_;
  std::vector<int> owners_;
  std::unique_ptr<parallel::DistributedMover<3>> mover_;
  bool cells_;
  FaceCentres centres_;
  Index points_ = 0, entries_ = 0;
  Points<3> given_, moved_;
};

// A method without a distributed mover: rank 0 moves the whole case (gather_case()) with the
// serial mover, each point on several ranks' boundaries once, as the lowest rank gives it; per
// entry of its boundary, the gathered entry giving its displacement (`picks_`); per rank, its
// points' global ids, in its order, to send their displacements back.
class GatheredServing final : public Serving {
 public:
  GatheredServing(const BridgeInput& input, const MoverConfig<3>& config) {
    const MPI_Comm comm = MPI_COMM_WORLD;
    const std::vector<std::int64_t> ids(input.global_ids.begin(), input.global_ids.end());
    const WholeCase whole = gather_case(input_cells(input), input_coupled(input), ids, input.owners);
    std::vector<std::int64_t> entry_ids;
    for (const long v : input.boundary) entry_ids.push_back(ids[static_cast<std::size_t>(v)]);
    const std::vector<std::int64_t> all_ids = parallel::gather_to(comm, 0, entry_ids);
    const std::vector<int> all_roles = parallel::gather_to(comm, 0, input.roles);
    const std::vector<double> all_directions = parallel::gather_to(comm, 0, input.directions);
    const std::vector<std::int64_t> all_points = parallel::gather_to(comm, 0, ids);
    const std::vector<std::int64_t> counts = parallel::gather_to(comm, 0, std::vector<std::int64_t>{static_cast<std::int64_t>(ids.size())});
    parallel::collective(comm, [&] {
      if (parallel::rank_of(comm) != 0) return;
      std::map<std::int64_t, std::size_t> first;  // emplace keeps the lowest rank's
      for (std::size_t f = 0; f < all_ids.size(); ++f) first.emplace(all_ids[f], f);
      std::vector<long> points;  // the whole case's boundary points, their roles and directions
      std::vector<int> roles;
      std::vector<double> directions;
      for (const auto& [id, f] : first) {
        points.push_back(static_cast<long>(id));
        roles.push_back(all_roles[f]);
        directions.insert(directions.end(), all_directions.begin() + static_cast<std::ptrdiff_t>(3 * f),
                          all_directions.begin() + static_cast<std::ptrdiff_t>(3 * f + 3));
        picks_.push_back(f);
      }
      ResolvedBoundary<3> b = resolved_boundary(points, roles, directions);
      Mesh<3> mesh = to_mesh(whole.poly);
      const FaceCentres centres(whole.poly, mesh, whole.coupled, b);
      std::size_t at = 0;
      for (const std::int64_t count : counts) {
        rank_points_.emplace_back(all_points.begin() + static_cast<std::ptrdiff_t>(at),
                                  all_points.begin() + static_cast<std::ptrdiff_t>(at + static_cast<std::size_t>(count)));
        at += static_cast<std::size_t>(count);
      }
      whole_.emplace(config, std::move(mesh), std::move(b), centres, whole.poly.points.cols());
    });
  }

  // The entries' displacements to rank 0, the serial mover's displacements back to each
  // rank's points. Collective.
  void move(const std::vector<double>& boundary_displacements, std::vector<double>& out) override {
    const MPI_Comm comm = MPI_COMM_WORLD;
    const std::vector<double> all = parallel::gather_to(comm, 0, boundary_displacements);
    std::vector<std::vector<double>> send(static_cast<std::size_t>(parallel::size_of(comm)));
    parallel::collective(comm, [&] {
      if (!whole_) return;
      Points<3> d(3, static_cast<Index>(picks_.size()));
      for (std::size_t k = 0; k < picks_.size(); ++k) d.col(static_cast<Index>(k)) = Eigen::Map<const Vec<3>>(all.data() + 3 * picks_[k]);
      const Points<3>& moved = whole_->move_entries(d);
      for (std::size_t r = 0; r < rank_points_.size(); ++r)
        for (const std::int64_t g : rank_points_[r])
          send[r].insert(send[r].end(), moved.col(static_cast<Index>(g)).data(), moved.col(static_cast<Index>(g)).data() + 3);
    });
    out = std::move(parallel::exchange(comm, send)[0]);
  }
  [[nodiscard]] MoverStats stats() const override { return whole_ ? whole_->stats() : MoverStats{}; }

 private:
  std::optional<SerialServing> whole_;  // rank 0's
  std::vector<std::size_t> picks_;
  std::vector<std::vector<std::int64_t>> rank_points_;
};

}  // namespace

bool decomposed_needs_cells(const std::string& method) { return parallel::find_distributed_method<3>(method) == nullptr; }

std::unique_ptr<Serving> serve_decomposed(const BridgeInput& input, const MoverConfig<3>& config, const parallel::ParallelOptions& parallel) {
  // OpenFOAM has MPI running; PETSc, which the boundary system may take, is started once.
  PetscBool started = PETSC_FALSE;
  PetscInitialized(&started);
  if (!started && PetscInitializeNoArguments() != 0) throw InputError("PETSc failed to start");
  if (decomposed_needs_cells(config.method)) return std::make_unique<GatheredServing>(input, config);
  return std::make_unique<DistributedServing>(input, config, parallel);
}

}  // namespace meshmotion::foam
