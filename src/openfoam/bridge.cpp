// The meshmotion half of the OpenFOAM plugin (C++20): the mover by name, set up once, served
// in the mode the case asks for (serving.hpp).

#include "bridge.hpp"
#include "serving.hpp"

#include <stdexcept>

namespace meshmotion::foam {

ResolvedBoundary<3> resolved_boundary(const std::vector<long>& points, const std::vector<int>& roles,
                                      const std::vector<double>& directions) {
  const auto nb = static_cast<Index>(points.size());
  ResolvedBoundary<3> b;
  b.nodes.assign(points.begin(), points.end());
  b.displacements = b.normals = b.directions = Points<3>::Zero(3, nb);
  const Eigen::Map<const Points<3>> along(directions.data(), 3, nb);
  for (Index k = 0; k < nb; ++k) {
    const auto role = static_cast<PointRole>(roles[static_cast<std::size_t>(k)]);
    b.kinds.push_back(role == PointRole::prescribed ? BoundaryKind::prescribed
                      : role == PointRole::held     ? BoundaryKind::fixed
                                                    : BoundaryKind::sliding);
    if (role == PointRole::sliding_plane) b.normals.col(k) = along.col(k);
    if (role == PointRole::sliding_line) {
      // A line's node keeps a plane's normal too (ResolvedBoundary): any unit vector across the
      // line, from the axis least along it. Without one, every edge where two slip sides meet
      // stopped the run at setup.
      const Vec<3> t = along.col(k);
      Index axis = 0;
      t.cwiseAbs().minCoeff(&axis);
      const Vec<3> across = Vec<3>::Unit(axis) - t(axis) * t;
      b.directions.col(k) = t;
      b.normals.col(k) = across.normalized();
    }
  }
  return b;
}

PolyMesh input_cells(const BridgeInput& input) {
  PolyMesh poly;
  poly.points = Eigen::Map<const Points<3>>(input.points.data(), 3, static_cast<Index>(input.points.size() / 3));
  poly.face_offsets.assign(input.face_offsets.begin(), input.face_offsets.end());
  poly.face_nodes.assign(input.face_points.begin(), input.face_points.end());
  poly.owner.assign(input.owner.begin(), input.owner.end());
  poly.neighbour.assign(input.neighbour.begin(), input.neighbour.end());
  poly.num_cells = input.cells;
  const Index internal = poly.num_internal_faces();
  poly.patches = {{"boundary", "patch", internal, poly.num_faces() - internal}};
  return poly;
}

std::vector<char> input_coupled(const BridgeInput& input) {
  std::vector<char> coupled;
  if (input.coupled_faces.empty()) return coupled;
  coupled.assign(input.face_offsets.size() - 1, 0);
  for (const long f : input.coupled_faces) coupled[static_cast<std::size_t>(f)] = 1;
  return coupled;
}

FaceCentres::FaceCentres(const PolyMesh& poly, const Mesh<3>& mesh, const std::vector<char>& coupled, ResolvedBoundary<3>& b) {
  if (mesh.num_auxiliary_nodes == 0) return;
  const Index np = poly.points.cols();
  std::vector<Index> entry(static_cast<std::size_t>(np), -1);
  for (std::size_t k = 0; k < b.nodes.size(); ++k) entry[static_cast<std::size_t>(b.nodes[k])] = static_cast<Index>(k);
  std::vector<Index> nodes;
  std::vector<Vec<3>> normals;
  std::vector<BoundaryKind> kinds;
  Index centre = np;
  for (Index f = 0; f < poly.num_faces(); ++f) {
    const auto v = poly.face(f);
    if (v.size() <= 3) continue;
    const Index node = centre++;
    if (f < poly.num_internal_faces() || (!coupled.empty() && coupled[static_cast<std::size_t>(f)])) continue;
    std::vector<Index> entries;
    bool all_given = true, all_held = true;  // every point's value given (prescribed or held); held
    for (const Index p : v) {
      const Index e = entry[static_cast<std::size_t>(p)];
      if (e < 0) break;
      entries.push_back(e);
      const BoundaryKind kind = b.kinds[static_cast<std::size_t>(e)];
      all_given = all_given && kind != BoundaryKind::sliding;
      all_held = all_held && kind == BoundaryKind::fixed;
    }
    if (entries.size() < v.size()) continue;  // a face of an unlisted patch: interior, as its points
    nodes.push_back(node);
    normals.push_back(all_given ? Vec<3>::Zero() : Vec<3>(poly.face_area(f).normalized()));
    kinds.push_back(!all_given ? BoundaryKind::sliding : all_held ? BoundaryKind::fixed : BoundaryKind::prescribed);
    entries_.push_back(all_given ? std::move(entries) : std::vector<Index>{});
  }
  const Index nb = b.size(), added = size();
  for (Index k = 0; k < added; ++k) {
    b.nodes.push_back(nodes[static_cast<std::size_t>(k)]);
    b.kinds.push_back(kinds[static_cast<std::size_t>(k)]);
  }
  b.displacements.conservativeResize(3, nb + added);
  b.normals.conservativeResize(3, nb + added);
  b.directions.conservativeResize(3, nb + added);
  for (Index k = 0; k < added; ++k) {
    b.displacements.col(nb + k).setZero();
    b.normals.col(nb + k) = normals[static_cast<std::size_t>(k)];
    b.directions.col(nb + k).setZero();
  }
}

void FaceCentres::prescribe(const Eigen::Ref<const Points<3>>& d, Points<3>& given) const {
  given.leftCols(d.cols()) = d;
  for (std::size_t k = 0; k < entries_.size(); ++k) {
    const std::vector<Index>& face = entries_[k];
    Vec<3> mean = Vec<3>::Zero();
    for (const Index e : face) mean += d.col(e);
    given.col(d.cols() + static_cast<Index>(k)) = face.empty() ? mean : Vec<3>(mean / static_cast<double>(face.size()));
  }
}

// Set up on the reference, before anything moves: the mover's default radius then follows the
// motion by itself, and its rigid part (RbfOptions::rigid_part) is its own to decide.
SerialServing::SerialServing(const MoverConfig<3>& config, Mesh<3> mesh, ResolvedBoundary<3> boundary, const FaceCentres& centres,
                             Index points)
    : mesh_(std::move(mesh)), centres_(centres), points_(points), entries_(boundary.size() - centres.size()), mover_(make_mover(config)) {
  boundary.displacements.setZero();
  mover_.setup(mesh_, boundary);
  given_.setZero(3, boundary.size());
  moved_.resize(3, mesh_.num_nodes());
}

const Points<3>& SerialServing::move_entries(const Eigen::Ref<const Points<3>>& d) {
  centres_.prescribe(d, given_);
  mover_.move_into(given_, moved_);
  return moved_;
}

void SerialServing::move(const std::vector<double>& boundary_displacements, std::vector<double>& out) {
  const Points<3>& moved = move_entries(Eigen::Map<const Points<3>>(boundary_displacements.data(), 3, entries_));
  out.assign(moved.data(), moved.data() + 3 * points_);
}

bool needs_cells(const std::string& method) { return decomposed_needs_cells(method) || mover_method<3>(method).needs_cells; }

namespace {

std::unique_ptr<Serving> serve_serial(const BridgeInput& input, const MoverConfig<3>& config) {
  ResolvedBoundary<3> b = input_boundary(input);
  const auto n = static_cast<Index>(input.points.size() / 3);
  if (!needs_cells(input.method)) {
    Mesh<3> bare;  // the points alone
    bare.points = Eigen::Map<const Points<3>>(input.points.data(), 3, n);
    return std::make_unique<SerialServing>(config, std::move(bare), std::move(b), FaceCentres{}, n);
  }
  const PolyMesh poly = input_cells(input);
  Mesh<3> mesh = to_mesh(poly);
  const FaceCentres centres(poly, mesh, input_coupled(input), b);
  return std::make_unique<SerialServing>(config, std::move(mesh), std::move(b), centres, n);
}

}  // namespace

Bridge::Bridge(const BridgeInput& input) {
  try {
    // A case's dictionary runs alike serially, where the decomposed solves' keys do nothing.
    parallel::ParallelOptions decomposed;
    const KeyValues rest = parallel::take_parallel_options(parse_key_values(input.options), decomposed);
    const MoverConfig<3> config = mover_config<3>(input.method, rest);
    serving_ = input.global_ids.empty() ? serve_serial(input, config) : serve_decomposed(input, config, decomposed);
  } catch (const std::exception& e) {
    throw std::runtime_error(e.what());
  }
}

// Here, where Serving is complete.
Bridge::~Bridge() = default;

double Bridge::support_radius() const { return serving_->stats().support_radius; }

bool Bridge::rigid_part() const { return serving_->stats().rigid_part; }

int Bridge::setups() const { return 1 + static_cast<int>(serving_->stats().radius_growths); }

long Bridge::solver_iterations() const { return static_cast<long>(serving_->stats().iterations); }

double Bridge::rebuild_seconds() const { return serving_->stats().rebuild_seconds; }

double Bridge::solve_seconds() const { return serving_->stats().solve_seconds; }

void Bridge::move(const std::vector<double>& boundary_displacements, std::vector<double>& out) {
  try {
    serving_->move(boundary_displacements, out);
  } catch (const std::exception& e) {
    throw std::runtime_error(e.what());
  }
}

}  // namespace meshmotion::foam
