// The meshmotion half of the OpenFOAM plugin (C++20): the mover by name, set up once.

#include "bridge.hpp"

#include "meshmotion/io/openfoam_polymesh.hpp"
#include "meshmotion/movers/registry.hpp"
#include "meshmotion/movers/rbf_options.hpp"
#ifdef MESHMOTION_FOAM_PARALLEL
#include "meshmotion/parallel/petsc.hpp"
#include "meshmotion/parallel/registry.hpp"
#endif

#include <algorithm>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>

namespace meshmotion::foam {

#ifdef MESHMOTION_FOAM_PARALLEL
namespace {

// Global ids and owners of a decomposed case's auxiliary nodes (to_mesh(): the centres of the
// faces of more than three points, then of the cells), after the points' own in `ids` and
// `owners`. A cell's centre, and the centre of a face no other rank holds, is this rank's,
// numbered after the case's points and the shared centres, rank after rank. The centre of a
// face between two ranks (`coupled`) is held by both: the sorted global ids of the face's
// points name it alike on both, and the lower rank owns it. Collective.
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

}  // namespace
#endif

// A polyhedral case's cells are cut into tetrahedra around the centres of their cells and of
// their faces of more than three points (to_mesh()). A boundary face's centre is on the
// boundary, so it joins the mover's boundary: prescribed when all the face's points are, by
// their mean displacement (exact for a rigid motion, the centre being their mean), else
// sliding in the face's plane. A face between ranks (`coupled`, empty: none) is interior.
// Its entries come after the points'; per entry, the entries of its face's points (empty:
// sliding).
std::vector<std::vector<Index>> add_face_centres(const PolyMesh& poly, const Mesh<3>& mesh, const std::vector<char>& coupled,
                                                 ResolvedBoundary<3>& b) {
  std::vector<std::vector<Index>> out;
  if (mesh.num_auxiliary_nodes == 0) return out;
  const Index np = poly.points.cols();
  std::vector<Index> entry(static_cast<std::size_t>(np), -1);
  for (std::size_t k = 0; k < b.nodes.size(); ++k) entry[static_cast<std::size_t>(b.nodes[k])] = static_cast<Index>(k);
  std::vector<Index> nodes;
  std::vector<Vec<3>> normals;
  Index centre = np;
  for (Index f = 0; f < poly.num_faces(); ++f) {
    const auto v = poly.face(f);
    if (v.size() <= 3) continue;
    const Index node = centre++;
    if (f < poly.num_internal_faces() || (!coupled.empty() && coupled[static_cast<std::size_t>(f)])) continue;
    std::vector<Index> entries;
    bool all_prescribed = true;
    for (const Index p : v) {
      const Index e = entry[static_cast<std::size_t>(p)];
      if (e < 0) break;
      entries.push_back(e);
      all_prescribed = all_prescribed && b.kinds[static_cast<std::size_t>(e)] == BoundaryKind::prescribed;
    }
    if (entries.size() < v.size()) continue;  // a face of an unlisted patch: interior, as its points
    nodes.push_back(node);
    normals.push_back(all_prescribed ? Vec<3>::Zero() : Vec<3>(poly.face_area(f).normalized()));
    out.push_back(all_prescribed ? std::move(entries) : std::vector<Index>{});
  }
  const Index nb = b.size(), added = static_cast<Index>(nodes.size());
  for (Index k = 0; k < added; ++k) {
    b.nodes.push_back(nodes[static_cast<std::size_t>(k)]);
    b.kinds.push_back(out[static_cast<std::size_t>(k)].empty() ? BoundaryKind::sliding : BoundaryKind::prescribed);
  }
  b.displacements.conservativeResize(3, nb + added);
  b.normals.conservativeResize(3, nb + added);
  b.directions.conservativeResize(3, nb + added);
  for (Index k = 0; k < added; ++k) {
    b.displacements.col(nb + k).setZero();
    b.normals.col(nb + k) = normals[static_cast<std::size_t>(k)];
    b.directions.col(nb + k).setZero();
  }
  return out;
}

struct Bridge::Impl {
  std::optional<AnyMover<3>> mover;
  MoverConfig<3> config;
  Mesh<3> mesh;                                    // serial: what the mover was set up on
  ResolvedBoundary<3> boundary;                    // with the face centres' entries
  std::vector<std::vector<Index>> centre_entries;  // add_face_centres()
  Points<3> given, moved;                         // with the face centres' entries and nodes; kept between moves
#ifdef MESHMOTION_FOAM_PARALLEL
  // A decomposed case whose method has a distributed mover (the distributed registry's):
  // through the cells (with the face centres' entries) or through the points alone.
  std::unique_ptr<parallel::DistributedMover<3>> distributed;
  bool distributed_cells = false;
  // The options of a decomposed case's solves, taken out of the method's: a case's dictionary
  // runs alike serially, where they do nothing.
  parallel::ParallelOptions parallel;
  Points<3> points;  // the distributed mover's view of them must outlive its setup
  std::vector<std::int64_t> global_ids;  // with the auxiliary nodes' where the cells are moved
  std::vector<int> owners;
  // A method without a distributed mover: rank 0 moves the whole case (gather_case()) with the
  // serial mover; per entry of its boundary, the gathered entry giving its displacement; per
  // rank, its points' global ids, in its order, to send their displacements back.
  bool gathered = false;
  std::vector<std::size_t> picks;
  std::vector<std::vector<std::int64_t>> rank_points;
#endif
  Index points_count = 0, entries = 0;

  // Sets the mover up on the reference, before anything moves: the mover's default radius
  // then follows the motion by itself (RbfMover's "set up once, moved many times").
  void set_up() {
    boundary.displacements.setZero();
#ifdef MESHMOTION_FOAM_PARALLEL
    if (!global_ids.empty() && !gathered) {
      distributed = parallel::make_distributed_mover(config, parallel);
      distributed_cells = mover_method<3>(config.method).needs_cells;
      if (distributed_cells)
        distributed->setup(parallel::PartitionView<3>{MPI_COMM_WORLD, mesh.points, global_ids, owners}, mesh, boundary);
      else
        distributed->setup(parallel::PartitionView<3>{MPI_COMM_WORLD, points, global_ids, owners}, boundary);
      return;
    }
#endif
    mover.emplace(make_mover(config));
    mover->setup(mesh, boundary);
  }

  // The mover's figures (none on the ranks of a gathered case other than rank 0).
  [[nodiscard]] MoverStats stats() const {
#ifdef MESHMOTION_FOAM_PARALLEL
    if (distributed) return distributed->stats();
#endif
    return mover ? mover->stats() : MoverStats{};
  }

  // The given displacements: the boundary entries' `d`, then the face centres' entries.
  void prescribe(const Eigen::Ref<const Points<3>>& d) {
    given.leftCols(d.cols()) = d;
    for (std::size_t k = 0; k < centre_entries.size(); ++k) {
      const std::vector<Index>& face = centre_entries[k];
      Vec<3> mean = Vec<3>::Zero();
      for (const Index e : face) mean += d.col(e);
      given.col(d.cols() + static_cast<Index>(k)) = face.empty() ? mean : Vec<3>(mean / static_cast<double>(face.size()));
    }
  }

#ifdef MESHMOTION_FOAM_PARALLEL
  // Sets the gathered case up (see `gathered`): rank 0 holds the whole case and its boundary,
  // each point on several ranks' boundaries once, as the lowest rank gives it. Collective.
  void gather(const PolyMesh& poly, const std::vector<char>& coupled, const BridgeInput& input) {
    const MPI_Comm comm = MPI_COMM_WORLD;
    const bool root = parallel::rank_of(comm) == 0;
    const WholeCase whole = gather_case(poly, coupled, global_ids, owners);
    std::vector<std::int64_t> entry_ids;
    for (const Index v : boundary.nodes) entry_ids.push_back(global_ids[static_cast<std::size_t>(v)]);
    const std::vector<std::int64_t> all_ids = parallel::gather_to(comm, 0, entry_ids);
    const std::vector<int> all_roles = parallel::gather_to(comm, 0, input.roles);
    const std::vector<double> all_directions = parallel::gather_to(comm, 0, input.directions);
    const std::vector<std::int64_t> all_points = parallel::gather_to(comm, 0, global_ids);
    const std::vector<std::int64_t> counts = parallel::gather_to(comm, 0, std::vector<std::int64_t>{points_count});
    parallel::collective(comm, [&] {
      if (!root) return;
      std::map<std::int64_t, std::size_t> first;  // emplace keeps the lowest rank's
      for (std::size_t f = 0; f < all_ids.size(); ++f) first.emplace(all_ids[f], f);
      const auto nb = static_cast<Index>(first.size());
      ResolvedBoundary<3>& b = boundary;
      b = ResolvedBoundary<3>{};
      b.displacements = b.normals = b.directions = Points<3>::Zero(3, nb);
      for (const auto& [id, f] : first) {
        const auto k = static_cast<Index>(b.nodes.size());
        const auto role = static_cast<PointRole>(all_roles[f]);
        const Vec<3> along(all_directions[3 * f], all_directions[3 * f + 1], all_directions[3 * f + 2]);
        b.nodes.push_back(static_cast<Index>(id));
        b.kinds.push_back(role == PointRole::prescribed ? BoundaryKind::prescribed : BoundaryKind::sliding);
        if (role == PointRole::sliding_plane) b.normals.col(k) = along;
        if (role == PointRole::sliding_line) b.directions.col(k) = along;
        picks.push_back(f);
      }
      mesh = to_mesh(whole.poly);
      centre_entries = add_face_centres(whole.poly, mesh, whole.coupled, b);
      std::size_t at = 0;
      for (const std::int64_t count : counts) {
        rank_points.emplace_back(all_points.begin() + static_cast<std::ptrdiff_t>(at), all_points.begin() + static_cast<std::ptrdiff_t>(at + static_cast<std::size_t>(count)));
        at += static_cast<std::size_t>(count);
      }
      set_up();
      given.setZero(3, b.size());
      moved.resize(3, mesh.num_nodes());
    });
  }

  // A move of the gathered case: the entries' displacements to rank 0, the serial mover's
  // displacements back to each rank's points. Collective.
  void move_gathered(const std::vector<double>& boundary_displacements, std::vector<double>& out) {
    const MPI_Comm comm = MPI_COMM_WORLD;
    const std::vector<double> all = parallel::gather_to(comm, 0, boundary_displacements);
    std::vector<std::vector<double>> send(static_cast<std::size_t>(parallel::size_of(comm)));
    parallel::collective(comm, [&] {
      if (parallel::rank_of(comm) != 0) return;
      Points<3> d(3, static_cast<Index>(picks.size()));
      for (std::size_t k = 0; k < picks.size(); ++k) d.col(static_cast<Index>(k)) = Eigen::Map<const Vec<3>>(all.data() + 3 * picks[k]);
      prescribe(d);
      move_cells();
      for (std::size_t r = 0; r < rank_points.size(); ++r)
        for (const std::int64_t g : rank_points[r])
          send[r].insert(send[r].end(), moved.col(static_cast<Index>(g)).data(), moved.col(static_cast<Index>(g)).data() + 3);
    });
    out = std::move(parallel::exchange(comm, send)[0]);
  }
#endif

  // The cells' mover: the serial one, or on a decomposed case the distributed elasticity.
  void move_cells() {
#ifdef MESHMOTION_FOAM_PARALLEL
    if (distributed) {
      distributed->move_into(given, moved);
      return;
    }
#endif
    mover->move_into(given, moved);
  }
};

bool needs_cells(const std::string& method) {
#ifdef MESHMOTION_FOAM_PARALLEL
  // A decomposed case whose method has no distributed mover is gathered on rank 0, cells and all.
  if (parallel::find_distributed_method<3>(method) == nullptr) return true;
#endif
  return mover_method<3>(method).needs_cells;
}

Bridge::Bridge(const BridgeInput& input) {
  try {
    const auto n = static_cast<Index>(input.points.size() / 3), nb = static_cast<Index>(input.boundary.size());
    auto impl = std::make_unique<Impl>();
    ResolvedBoundary<3>& b = impl->boundary;
    b.nodes.assign(input.boundary.begin(), input.boundary.end());
    b.displacements = Points<3>::Zero(3, nb);
    b.normals = Points<3>::Zero(3, nb);
    b.directions = Points<3>::Zero(3, nb);
    const Eigen::Map<const Points<3>> along(input.directions.data(), 3, nb);
    for (Index k = 0; k < nb; ++k) {
      const auto role = static_cast<PointRole>(input.roles[static_cast<std::size_t>(k)]);
      b.kinds.push_back(role == PointRole::prescribed ? BoundaryKind::prescribed : BoundaryKind::sliding);
      if (role == PointRole::sliding_plane) b.normals.col(k) = along.col(k);
      if (role == PointRole::sliding_line) b.directions.col(k) = along.col(k);
    }
    KeyValues given = parse_key_values(input.options);
    impl->points_count = n;
    impl->entries = nb;
    const Eigen::Map<const Points<3>> points(input.points.data(), 3, n);
#ifdef MESHMOTION_FOAM_PARALLEL
    const KeyValues rest = parallel::take_parallel_options(given, impl->parallel);
#else
    if (!input.global_ids.empty())
      throw InputError("this plugin was built without meshmotion's parallel layer (MPI, PETSc, METIS): run the motion serially");
    const KeyValues& rest = given;
#endif
    impl->config = mover_config<3>(input.method, rest);
#ifdef MESHMOTION_FOAM_PARALLEL
    impl->gathered = !input.global_ids.empty() && parallel::find_distributed_method<3>(impl->config.method) == nullptr;
#endif
    if (auto* rbf = std::get_if<RbfOptions>(&impl->config.options)) {
      // One setup serves many time steps: a rigid part blended from one step's motion would
      // be wrong for the next, so the whole motion is interpolated.
      if (rbf->rigid_part == RigidPart::blend)
        throw InputError("rigid_part=blend: the plugin sets its mover up once for many time steps and interpolates "
                         "the whole motion (rigid_part=none)");
      rbf->rigid_part = RigidPart::none;
    }
#ifdef MESHMOTION_FOAM_PARALLEL
    if (!input.global_ids.empty()) {
      // OpenFOAM has MPI running; PETSc, which the boundary system may take, is started once.
      PetscBool started = PETSC_FALSE;
      PetscInitialized(&started);
      if (!started && PetscInitializeNoArguments() != 0) throw InputError("PETSc failed to start");
      impl->points = points;
      impl->global_ids.assign(input.global_ids.begin(), input.global_ids.end());
      impl->owners = input.owners;
    }
#endif
    if (needs_cells(input.method)) {
      std::vector<char> coupled;
      if (!input.coupled_faces.empty()) {
        coupled.assign(input.face_offsets.size() - 1, 0);
        for (const long f : input.coupled_faces) coupled[static_cast<std::size_t>(f)] = 1;
      }
      PolyMesh poly;
      poly.points = points;
      poly.face_offsets.assign(input.face_offsets.begin(), input.face_offsets.end());
      poly.face_nodes.assign(input.face_points.begin(), input.face_points.end());
      poly.owner.assign(input.owner.begin(), input.owner.end());
      poly.neighbour.assign(input.neighbour.begin(), input.neighbour.end());
      poly.num_cells = input.cells;
      const Index internal = poly.num_internal_faces();
      poly.patches = {{"boundary", "patch", internal, poly.num_faces() - internal}};
#ifdef MESHMOTION_FOAM_PARALLEL
      if (impl->gathered) {
        impl->gather(poly, coupled, input);
        impl_ = std::move(impl);
        return;
      }
#endif
      impl->mesh = to_mesh(poly);
#ifdef MESHMOTION_FOAM_PARALLEL
      if (!input.global_ids.empty()) {
        // Every rank cuts its cells into tetrahedra when any rank must, as the serial run does.
        int cut = impl->mesh.num_auxiliary_nodes > 0 ? 1 : 0;
        MPI_Allreduce(MPI_IN_PLACE, &cut, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
        if (cut == 1 && impl->mesh.num_auxiliary_nodes == 0) impl->mesh = to_mesh(poly, true);
        number_auxiliary_nodes(poly, impl->mesh.num_nodes(), coupled, impl->global_ids, impl->owners);
      }
#endif
      impl->centre_entries = add_face_centres(poly, impl->mesh, coupled, b);
    } else if (input.global_ids.empty()) {
      impl->mesh.points = points;
    }
    impl->set_up();
    impl->given.setZero(3, b.size());
    impl->moved.resize(3, impl->mesh.num_nodes());
    impl_ = std::move(impl);
  } catch (const std::exception& e) {
    throw std::runtime_error(e.what());
  }
}

// Here, where Impl is complete.
Bridge::~Bridge() = default;

double Bridge::support_radius() const { return impl_->stats().support_radius; }

int Bridge::setups() const { return 1 + static_cast<int>(impl_->stats().radius_growths); }

void Bridge::move(const std::vector<double>& boundary_displacements, std::vector<double>& out) {
  try {
    Impl& m = *impl_;
    const Eigen::Map<const Points<3>> d(boundary_displacements.data(), 3, m.entries);
#ifdef MESHMOTION_FOAM_PARALLEL
    if (m.distributed && !m.distributed_cells) {
      m.distributed->move_into(d, m.moved);
      out.assign(m.moved.data(), m.moved.data() + m.moved.size());
      return;
    }
    if (m.gathered) return m.move_gathered(boundary_displacements, out);
#endif
    m.prescribe(d);
    m.move_cells();
    out.assign(m.moved.data(), m.moved.data() + 3 * m.points_count);
  } catch (const std::exception& e) {
    throw std::runtime_error(e.what());
  }
}

}  // namespace meshmotion::foam
