#pragma once
// The plugin's two halves meet here: OpenFOAM v1912's headers compile as C++17 only, the
// library needs C++20, so each side is its own translation unit and they pass plain arrays.
// Nothing here names an OpenFOAM or a meshmotion type.

#include <memory>
#include <string>
#include <vector>

namespace meshmotion::foam {

/// A boundary point's part in the motion.
/// held (rbf): prescribed by a patch whose value is zero at setup (a plain fixedValue wall), so
/// not part of a moving body's rigid fit; its value still comes from the field at every move.
enum class PointRole { prescribed = 0, sliding_plane = 1, sliding_line = 2, held = 3 };

/// The mesh and its boundary as the OpenFOAM side sees them (3 × n, point after point).
struct BridgeInput {
  std::string method;                 ///< a registered mover (rbf, elasticity, ...)
  std::string options;                ///< "key=value key=value" of that mover's typed options
  std::vector<double> points;         ///< 3 × n: points0
  std::vector<long> boundary;         ///< the boundary points, ascending
  std::vector<int> roles;             ///< PointRole of each
  std::vector<double> directions;     ///< 3 × boundary: the plane's normal, or the line's direction
  /// A decomposed case (-parallel), else empty: each point's number among the whole case's
  /// points (a point shared by ranks has one) and the rank that owns it. The ranks then set
  /// the mover up together over MPI_COMM_WORLD, as OpenFOAM's own communicator.
  std::vector<long> global_ids;
  std::vector<int> owners;
  /// The cells, for a method that needs them (needs_cells()): OpenFOAM's faces (face f's points
  /// are face_points[face_offsets[f] .. face_offsets[f + 1])), each face's owner cell and
  /// each internal face's neighbour (internal faces first), and the number of cells.
  std::vector<long> face_offsets, face_points, owner, neighbour;
  long cells = 0;
  /// A decomposed case's faces between ranks (on processor patches) and on cyclic patches:
  /// interior to the mover, whatever their points are.
  std::vector<long> coupled_faces;
};

class Serving;

/// Whether the plugin hands `method` the cells: the registry's needs_cells, and, where the
/// plugin moves decomposed cases, every method without a distributed mover (such a case is
/// gathered on rank 0, which moves it with the serial mover and sends each rank its points).
bool needs_cells(const std::string& method);

class Bridge {
 public:
  /// Sets the mover up (its factorization is reused by every move). Throws std::runtime_error
  /// with meshmotion's message. Collective on a decomposed case.
  explicit Bridge(const BridgeInput& input);
  ~Bridge();
  Bridge(const Bridge&) = delete;
  Bridge& operator=(const Bridge&) = delete;
  /// `boundary_displacements` (3 × boundary; sliding entries ignored) to every point's
  /// displacement (3 × n). Collective on a decomposed case, where each entry's owner gives it.
  void move(const std::vector<double>& boundary_displacements, std::vector<double>& out);
  /// The RBF's support radius (0 for other methods). Without a given one it grows with the
  /// motion: a move whose largest prescribed displacement outgrew it sets the mover up again
  /// (RbfMover's radius_outgrown()).
  [[nodiscard]] double support_radius() const;
  /// The RBF blends each move's rigid part before interpolating (RigidPartAtMove: a body
  /// whose ball clears the held walls).
  [[nodiscard]] bool rigid_part() const;
  /// How many times the mover was set up: once here, then once per growth of its radius.
  [[nodiscard]] int setups() const;
  /// The iterations of the last move's linear solve (0 for direct solves and interpolation).
  [[nodiscard]] long solver_iterations() const;
  /// Of the last move on this rank (seconds): what it set up again or built first, and its
  /// solves (MoverStats::rebuild_seconds, solve_seconds); the rest of it is evaluation.
  [[nodiscard]] double rebuild_seconds() const;
  [[nodiscard]] double solve_seconds() const;

 private:
  std::unique_ptr<Serving> serving_;  // serving.hpp: one type per mode
};

}  // namespace meshmotion::foam
