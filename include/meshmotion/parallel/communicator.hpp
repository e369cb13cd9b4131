#pragma once
/// \file
/// MPI plumbing of the parallel layer: typed gathers and personalized exchanges over
/// std::vector, and collective(), which turns an exception on some ranks into the same
/// exception on every rank, so that a failure on one rank never leaves the others waiting in
/// the next collective call.
///
/// Counts travel as int (MPI's own limit): one rank's contribution to a gather is at most
/// 2³¹ − 1 values.

#include "meshmotion/core/error.hpp"
#include "meshmotion/core/types.hpp"

#include <mpi.h>

#ifdef __linux__
#include <sched.h>
#endif

#include <algorithm>
#include <climits>
#include <cstdint>
#include <numeric>
#include <span>
#include <string>
#include <thread>
#include <type_traits>
#include <vector>

namespace meshmotion::parallel {

[[nodiscard]] inline int rank_of(MPI_Comm comm) {
  int r = 0;
  MPI_Comm_rank(comm, &r);
  return r;
}
[[nodiscard]] inline int size_of(MPI_Comm comm) {
  int s = 1;
  MPI_Comm_size(comm, &s);
  return s;
}

namespace detail {

template <class T>
[[nodiscard]] MPI_Datatype mpi_type() {
  if constexpr (std::is_same_v<T, double>) return MPI_DOUBLE;
  else if constexpr (std::is_same_v<T, int>) return MPI_INT;
  else if constexpr (std::is_same_v<T, std::int64_t> || std::is_same_v<T, long> || std::is_same_v<T, long long>) {
    static_assert(sizeof(T) == 8);
    return MPI_INT64_T;
  } else if constexpr (std::is_same_v<T, char>) return MPI_CHAR;
  else static_assert(sizeof(T) == 0, "no MPI datatype for this type");
}

[[nodiscard]] inline int checked_count(std::size_t n, const char* where) {
  if (n > static_cast<std::size_t>(INT_MAX))
    throw InputError(std::string(where) + ": " + std::to_string(n) + " values from one rank exceed MPI's int count");
  return static_cast<int>(n);
}

[[nodiscard]] inline std::vector<int> offsets_of(const std::vector<int>& counts) {
  std::vector<int> displs(counts.size() + 1, 0);
  for (std::size_t r = 0; r < counts.size(); ++r) {
    if (static_cast<long long>(displs[r]) + counts[r] > INT_MAX)
      throw InputError("parallel: a gathered array exceeds MPI's int count");
    displs[r + 1] = displs[r] + counts[r];
  }
  return displs;
}

}  // namespace detail

/// Ranks of `comm` on this rank's node (those that can share memory with it). Collective.
[[nodiscard]] inline int ranks_on_node(MPI_Comm comm) {
  MPI_Comm node = MPI_COMM_NULL;
  MPI_Comm_split_type(comm, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &node);
  const int n = size_of(node);
  MPI_Comm_free(&node);
  return n;
}

/// The cores of this node (1 when unknown).
/// Sums, maxima and minima of doubles over the ranks of `comm`, in place (a Reduction, as
/// RigidPartAtMove takes).
struct RanksReduction {
  MPI_Comm comm;
  void sum(double* values, int n) const { MPI_Allreduce(MPI_IN_PLACE, values, n, MPI_DOUBLE, MPI_SUM, comm); }
  void max(double& value) const { MPI_Allreduce(MPI_IN_PLACE, &value, 1, MPI_DOUBLE, MPI_MAX, comm); }
  void min(double& value) const { MPI_Allreduce(MPI_IN_PLACE, &value, 1, MPI_DOUBLE, MPI_MIN, comm); }
};

[[nodiscard]] inline int cores_of_node() { return std::max(1, static_cast<int>(std::thread::hardware_concurrency())); }

/// This rank's even share of its node's cores among the ranks of `comm` on it, at least 1 and
/// at most the cores the process may run on (bound to one core: 1). Give it to
/// set_num_threads when several ranks share a node: each rank's OpenMP loops and CHOLMOD
/// otherwise open a thread per core, and the node runs ranks × cores threads. Collective.
[[nodiscard]] inline int node_share_of_cores(MPI_Comm comm) {
  int cores = cores_of_node();
#ifdef __linux__
  cpu_set_t mask;
  if (sched_getaffinity(0, sizeof(mask), &mask) == 0) cores = std::min(cores, std::max(1, CPU_COUNT(&mask)));
#endif
  return std::max(1, cores / ranks_on_node(comm));
}

/// Every rank's `mine` concatenated in rank order, on every rank; `counts` (optional) receives
/// each rank's count.
template <class T>
[[nodiscard]] std::vector<T> all_gather(MPI_Comm comm, std::span<const T> mine, std::vector<int>* counts = nullptr) {
  const int n = detail::checked_count(mine.size(), "parallel::all_gather");
  std::vector<int> c(static_cast<std::size_t>(size_of(comm)));
  MPI_Allgather(&n, 1, MPI_INT, c.data(), 1, MPI_INT, comm);
  const std::vector<int> displs = detail::offsets_of(c);
  std::vector<T> out(static_cast<std::size_t>(displs.back()));
  MPI_Allgatherv(mine.data(), n, detail::mpi_type<T>(), out.data(), c.data(), displs.data(), detail::mpi_type<T>(), comm);
  if (counts != nullptr) *counts = std::move(c);
  return out;
}
template <class T>
[[nodiscard]] std::vector<T> all_gather(MPI_Comm comm, const std::vector<T>& mine, std::vector<int>* counts = nullptr) {
  return all_gather(comm, std::span<const T>(mine), counts);
}

/// all_gather() as LinearRepair's gathers (LocalGather for one process).
struct RanksGather {
  MPI_Comm comm;
  template <class T>
  [[nodiscard]] std::vector<T> all(const std::vector<T>& mine) const {
    return all_gather(comm, mine);
  }
};

/// Every rank's `mine` concatenated in rank order, on `root` only (empty elsewhere).
template <class T>
[[nodiscard]] std::vector<T> gather_to(MPI_Comm comm, int root, const std::vector<T>& mine) {
  const int n = detail::checked_count(mine.size(), "parallel::gather_to");
  const bool at_root = rank_of(comm) == root;
  std::vector<int> c(at_root ? static_cast<std::size_t>(size_of(comm)) : 0);
  MPI_Gather(&n, 1, MPI_INT, c.data(), 1, MPI_INT, root, comm);
  std::vector<T> out;
  std::vector<int> displs;
  if (at_root) {
    displs = detail::offsets_of(c);
    out.resize(static_cast<std::size_t>(displs.back()));
  }
  MPI_Gatherv(mine.data(), n, detail::mpi_type<T>(), out.data(), c.data(), displs.data(), detail::mpi_type<T>(), root, comm);
  return out;
}

/// Personalized exchange: send[r] goes to rank r; returns what each rank sent to this one.
template <class T>
[[nodiscard]] std::vector<std::vector<T>> exchange(MPI_Comm comm, const std::vector<std::vector<T>>& send) {
  const auto p = static_cast<std::size_t>(size_of(comm));
  if (send.size() != p) throw InputError("parallel::exchange: one list per rank expected");
  std::vector<int> send_counts(p), recv_counts(p);
  for (std::size_t r = 0; r < p; ++r) send_counts[r] = detail::checked_count(send[r].size(), "parallel::exchange");
  MPI_Alltoall(send_counts.data(), 1, MPI_INT, recv_counts.data(), 1, MPI_INT, comm);
  const std::vector<int> sdispls = detail::offsets_of(send_counts), rdispls = detail::offsets_of(recv_counts);
  std::vector<T> flat(static_cast<std::size_t>(sdispls.back())), got(static_cast<std::size_t>(rdispls.back()));
  for (std::size_t r = 0; r < p; ++r) std::copy(send[r].begin(), send[r].end(), flat.begin() + sdispls[r]);
  MPI_Alltoallv(flat.data(), send_counts.data(), sdispls.data(), detail::mpi_type<T>(), got.data(), recv_counts.data(),
                rdispls.data(), detail::mpi_type<T>(), comm);
  std::vector<std::vector<T>> out(p);
  for (std::size_t r = 0; r < p; ++r) out[r].assign(got.begin() + rdispls[r], got.begin() + rdispls[r + 1]);
  return out;
}

/// Runs f() on every rank; when it throws on some ranks, every rank throws: the lowest
/// failing rank's message, prefixed by "rank R: ", as the same kind of meshmotion error
/// (SolverError, InvalidMeshError, IoError, otherwise InputError). Must be called by every
/// rank of `comm`, like any collective; f itself may call collectives only if it cannot throw
/// before them on some ranks and not on others.
template <class F>
void collective(MPI_Comm comm, F&& f) {
  enum Kind : int { none = 0, input = 1, solver = 2, invalid = 3, io = 4 };
  int kind = none;
  std::string message;
  try {
    f();
  } catch (const SolverError& e) {
    kind = solver, message = e.what();
  } catch (const InvalidMeshError& e) {
    kind = invalid, message = e.what();
  } catch (const IoError& e) {
    kind = io, message = e.what();
  } catch (const std::exception& e) {
    kind = input, message = e.what();
  }
  const int p = size_of(comm);
  const int mine = kind == none ? p : rank_of(comm);
  int failing = p;
  MPI_Allreduce(&mine, &failing, 1, MPI_INT, MPI_MIN, comm);
  if (failing == p) return;
  int header[2] = {kind, static_cast<int>(message.size())};
  MPI_Bcast(header, 2, MPI_INT, failing, comm);
  message.resize(static_cast<std::size_t>(header[1]));
  MPI_Bcast(message.data(), header[1], MPI_CHAR, failing, comm);
  // The text already starts with "meshmotion: ", which the error classes add again.
  if (message.starts_with("meshmotion: ")) message.erase(0, 12);
  message = "rank " + std::to_string(failing) + ": " + message;
  switch (header[0]) {
    case solver: throw SolverError(message);
    case invalid: throw InvalidMeshError(message);
    case io: throw IoError(message);
    default: throw InputError(message);
  }
}

}  // namespace meshmotion::parallel
