// Solves a pressure system saved by the engine (core.save_system, system_io.hpp) with the
// multigrid-preconditioned CG the engine uses (amg_pcg.hpp), over every process of
// MPI_COMM_WORLD, each owning a contiguous block of rows:
//
//     mpirun -np P build/pfv_amg_solve FOLDER [--tolerance=1e-10] [--out=FILE] [--repeat=0]
//         [--strong=0.5] [--coarsen=10] [--interp=6] [--pmax=4] [--relax=8] [--relax-down=R] [--relax-up=R]
//         [--aggressive=0] [--print=0] [--hypre-cycle]
//
// The solve starts from zero and stops by the engine's rule (estimated error below tolerance
// times the spread of the pressures). Prints the processes, unknowns, levels, iterations, the
// set-up and solve times and max |x - x_engine| / spread; --out writes the solution as a Matrix
// Market array (rank 0). --repeat=K then times K solves from the solution perturbed by 1e-3 of
// its spread (a warm start, as the engine's between remeshes). The other options are BoomerAMG's
// (amg_pcg.hpp, AmgParameters); --hypre-cycle runs hypre's V-cycle on one process, where the
// engine runs its own on the OpenMP threads. Exit 1 on any error.
#include <mpi.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "pfv/linalg/amg_pcg.hpp"
#include "pfv/linalg/system_io.hpp"

namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

int run(int argc, char** argv) {
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  if (argc < 2) {
    if (rank == 0) std::fprintf(stderr, "usage: pfv_amg_solve FOLDER [--tolerance=T] [--out=FILE]\n");
    return 1;
  }
  const std::string folder = argv[1];
  double tolerance = 1e-10;
  std::string out;
  int repeat = 0;
  pfv::AmgParameters parameters;
  for (int a = 2; a < argc; ++a) {
    const std::string arg = argv[a];
    const std::string value = arg.substr(arg.find('=') + 1);
    if (arg.rfind("--tolerance=", 0) == 0)
      tolerance = std::stod(value);
    else if (arg.rfind("--out=", 0) == 0)
      out = value;
    else if (arg.rfind("--repeat=", 0) == 0)
      repeat = std::stoi(value);
    else if (arg.rfind("--strong=", 0) == 0)
      parameters.strong_threshold = std::stod(value);
    else if (arg.rfind("--coarsen=", 0) == 0)
      parameters.coarsen_type = std::stoi(value);
    else if (arg.rfind("--interp=", 0) == 0)
      parameters.interp_type = std::stoi(value);
    else if (arg.rfind("--pmax=", 0) == 0)
      parameters.max_row_entries = std::stoi(value);
    else if (arg.rfind("--relax=", 0) == 0)
      parameters.relax_type = std::stoi(value);
    else if (arg.rfind("--relax-down=", 0) == 0)
      parameters.relax_down = std::stoi(value);
    else if (arg.rfind("--relax-up=", 0) == 0)
      parameters.relax_up = std::stoi(value);
    else if (arg.rfind("--aggressive=", 0) == 0)
      parameters.aggressive_levels = std::stoi(value);
    else if (arg == "--hypre-cycle")
      parameters.hypre_cycle = true;
    else if (arg.rfind("--print=", 0) == 0)
      parameters.print_level = std::stoi(value);
    else
      throw std::invalid_argument("unknown argument " + arg);
  }
  const long long n = pfv::saved_system_size(folder);
  const int first = static_cast<int>(n * rank / size), last = static_cast<int>(n * (rank + 1) / size);
  pfv::SavedRows saved = pfv::read_system_rows(folder, first, last - first);

  auto t0 = std::chrono::steady_clock::now();
  pfv::AmgPcg pcg(MPI_COMM_WORLD, saved.rows, parameters);
  const double setup = seconds_since(t0);
  std::vector<double> x(last - first, 0.0);
  t0 = std::chrono::steady_clock::now();
  const pfv::AmgSolveStats stats = pcg.solve(saved.b, x, tolerance, 100000);
  const double solve = seconds_since(t0);
  // Warm solves: from the solution plus a smooth perturbation of 1e-3 of the spread.
  double warm_seconds = 0, warm_iterations = 0;
  if (repeat > 0) {
    double range[2] = {0, 0}, reduced[2];
    for (double v : x) range[0] = std::max(range[0], -v), range[1] = std::max(range[1], v);
    MPI_Allreduce(range, reduced, 2, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
    const double amplitude = 1e-3 * (reduced[0] + reduced[1]);
    for (int k = 0; k < repeat; ++k) {
      std::vector<double> start(x);
      for (std::size_t i = 0; i < start.size(); ++i) start[i] += amplitude * std::sin(1e-4 * (first + i) + k);
      t0 = std::chrono::steady_clock::now();
      warm_iterations += pcg.solve(saved.b, start, tolerance, 100000).iterations;
      warm_seconds += seconds_since(t0);
    }
  }

  // max |x - x_engine| over the spread of x_engine, over all processes.
  double local[3] = {0, -1e300, -1e300};  // max difference, -min, max of the engine's pressures
  for (std::size_t i = 0; i < x.size(); ++i) {
    local[0] = std::max(local[0], std::abs(x[i] - saved.x[i]));
    local[1] = std::max(local[1], -saved.x[i]);
    local[2] = std::max(local[2], saved.x[i]);
  }
  double global[3];
  MPI_Allreduce(local, global, 3, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  const double spread = global[1] + global[2];

  std::vector<int> counts(size), starts(size);
  for (int r = 0; r < size; ++r) {
    starts[r] = static_cast<int>(n * r / size);
    counts[r] = static_cast<int>(n * (r + 1) / size) - starts[r];
  }
  std::vector<double> all(rank == 0 ? n : 0);
  MPI_Gatherv(x.data(), static_cast<int>(x.size()), MPI_DOUBLE, all.data(), counts.data(), starts.data(), MPI_DOUBLE, 0,
              MPI_COMM_WORLD);
  if (rank == 0) {
    std::printf(
        "processes %d unknowns %lld levels %d operator_complexity %.3f iterations %d converged %d setup_s %.4f "
        "solve_s %.4f error_over_spread %.3e",
        size, n, pcg.levels(), pcg.operator_complexity(), stats.iterations, stats.converged ? 1 : 0, setup, solve,
        spread > 0 ? global[0] / spread : global[0]);
    if (repeat > 0)
      std::printf(" warm_iterations %.2f warm_solve_s %.5f", warm_iterations / repeat, warm_seconds / repeat);
    std::printf("\n");
    if (!out.empty()) {
      std::ofstream f(out);
      f.precision(17);
      f << "%%MatrixMarket matrix array real general\n" << n << " 1\n";
      for (double v : all) f << v << '\n';
      if (!f) throw std::runtime_error("cannot write " + out);
    }
  }
  return stats.converged ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  int status = 1;
  try {
    status = run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "pfv_amg_solve: %s\n", e.what());
    MPI_Abort(MPI_COMM_WORLD, 1);
  }
  MPI_Finalize();
  return status;
}
