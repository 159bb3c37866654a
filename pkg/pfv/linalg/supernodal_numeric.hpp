// The numeric phase of a supernodal Cholesky factorisation, P G P' = L L', on the symbolic
// factor of a CHOLMOD analysis: left-looking, one supernode at a time, its updates from the
// supernodes below it as dense BLAS-3 products (Ng and Peyton, "Block sparse Cholesky
// algorithms on advanced uniprocessor computers", SIAM J. Sci. Comput. 14, 1993).
//
// Why not cholmod_factorize: Debian's CHOLMOD enters OpenMP parallel regions around the
// clearing and scattering of every supernode, and a region costs libgomp a team set-up and a
// barrier with futex system calls even when it runs on one thread. On a pore network most
// supernodes are a few columns wide, so those regions can cost as much as the arithmetic
// (doc/solvers.md). This routine does the same arithmetic with the same BLAS and LAPACK, without
// the regions, and computes the updates of the smallest supernodes without a BLAS call.
#pragma once
#include <vector>

#include "pfv/linalg/symmetric_matrix.hpp"

namespace pfv {

// CHOLMOD's supernodal symbolic factor (cholmod_factor with itype CHOLMOD_INT): supernode s
// holds columns super[s]..super[s+1]-1 (elimination order) and rows rows[pi[s]..pi[s+1]-1],
// its own columns first; its values are a column-major nsrow x nscol block at values + px[s].
// perm[k] is the unknown eliminated k-th.
struct SupernodalSymbolic {
  int n = 0, nsuper = 0;
  const int* super = nullptr;
  const int* pi = nullptr;
  const int* px = nullptr;
  const int* rows = nullptr;
  const int* perm = nullptr;
  long max_update = 0;  // entries of the largest update block (cholmod_factor::maxcsize)
};

// Scratch space, kept between factorisations of like size.
struct SupernodalWorkspace {
  std::vector<int> inverse, fill, map, relative, head, next, position, owner, column_start, column_row, column_entry;
  std::vector<double> update;
};

// Writes L into values (the layout of SupernodalSymbolic; the strict upper triangles of the
// diagonal blocks are left as they are). Returns -1, or the elimination position of the first
// pivot that is not positive (G not positive definite; values are then incomplete).
int supernodal_numeric(const SupernodalSymbolic& symbolic, const SymmetricMatrix& g, double* values,
                       SupernodalWorkspace& work);

}  // namespace pfv
