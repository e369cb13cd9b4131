// The parallel tests run on every rank of mpiexec -n N. Each test case calls the same
// collectives in the same order on every rank and checks values reduced over the ranks, so a
// failure fails on every rank instead of leaving the others waiting. Rank 0 reports on the
// console; the other ranks write their report to a file and print it when they fail.
#define CATCH_CONFIG_RUNNER
#include <catch2/catch.hpp>

#include <petscsys.h>

#include <fstream>
#include <iostream>
#include <string>
#include <vector>

int main(int argc, char** argv) {
  // PETSc initializes MPI; its own command-line options are not ours.
  int petsc_argc = 1;
  char** petsc_argv = argv;
  if (PetscInitialize(&petsc_argc, &petsc_argv, nullptr, nullptr) != 0) return 1;
  int rank = 0, size = 1;
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
  MPI_Comm_size(PETSC_COMM_WORLD, &size);
  Catch::Session session;
  int rc = session.applyCommandLine(argc, argv);
  const std::string log = std::string(MESHMOTION_TEST_TMP_DIR) + "/parallel_rank" + std::to_string(rank) + "_of_" +
                          std::to_string(size) + ".txt";
  if (rc == 0) {
    if (rank != 0) session.configData().outputFilename = log;
    rc = session.run();
  }
  if (rc != 0 && rank != 0) {
    std::ifstream in(log);
    std::cerr << "---- rank " << rank << " of " << size << " ----\n" << in.rdbuf();
  }
  int worst = rc;
  MPI_Allreduce(&rc, &worst, 1, MPI_INT, MPI_MAX, PETSC_COMM_WORLD);
  PetscFinalize();
  return worst;
}
