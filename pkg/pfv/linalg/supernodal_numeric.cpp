#include "pfv/linalg/supernodal_numeric.hpp"

#include <algorithm>
#include <cstddef>

// BLAS and LAPACK (Debian's libblas3 / liblapack3 alternatives, as CHOLMOD uses them), with
// gfortran's hidden string lengths.
extern "C" {
void dsyrk_(const char* uplo, const char* trans, const int* n, const int* k, const double* alpha, const double* a,
            const int* lda, const double* beta, double* c, const int* ldc, std::size_t, std::size_t);
void dgemm_(const char* transa, const char* transb, const int* m, const int* n, const int* k, const double* alpha,
            const double* a, const int* lda, const double* b, const int* ldb, const double* beta, double* c,
            const int* ldc, std::size_t, std::size_t);
void dtrsm_(const char* side, const char* uplo, const char* transa, const char* diag, const int* m, const int* n,
            const double* alpha, const double* a, const int* lda, double* b, const int* ldb, std::size_t, std::size_t,
            std::size_t, std::size_t);
void dpotrf_(const char* uplo, const int* n, double* a, const int* lda, int* info, std::size_t);
}

namespace pfv {
namespace {

// Below this many multiply-adds an update is computed here: a BLAS call costs more than the
// arithmetic of the one- and two-column supernodes that make up most of a pore network's factor.
constexpr long kSmallUpdate = 256;

// C (rows x cols, leading dimension rows; lower triangle of the top cols x cols block) =
// A A1' with A the rows x width block of d from its first row in s and A1 its top cols rows.
void update_block(const double* a, int lda, int rows, int cols, int width, double* c) {
  if (static_cast<long>(rows) * cols * width <= kSmallUpdate) {
    for (int j = 0; j < cols; ++j)
      for (int i = j; i < rows; ++i) {
        double sum = 0;
        for (int k = 0; k < width; ++k) sum += a[i + static_cast<long>(k) * lda] * a[j + static_cast<long>(k) * lda];
        c[i + static_cast<long>(j) * rows] = sum;
      }
    return;
  }
  const double one = 1, zero = 0;
  dsyrk_("L", "N", &cols, &width, &one, a, &lda, &zero, c, &rows, 1, 1);
  const int below = rows - cols;
  if (below > 0) dgemm_("N", "T", &below, &cols, &width, &one, a + cols, &lda, a, &lda, &zero, c + cols, &rows, 1, 1);
}

}  // namespace

int supernodal_numeric(const SupernodalSymbolic& L, const SymmetricMatrix& g, double* values, SupernodalWorkspace& w) {
  const int n = L.n, ns = L.nsuper;
  // G's entries by column of P G P' lower triangle: the column is the earlier of the two
  // elimination positions of an entry of G's upper triangle, the row the later.
  std::vector<int>& inverse = w.inverse;  // elimination position of each unknown
  inverse.resize(n);
  for (int k = 0; k < n; ++k) inverse[L.perm[k]] = k;
  w.column_start.assign(n + 1, 0);
  for (int j = 0; j < n; ++j)
    for (int e = g.col_start[j]; e < g.col_start[j + 1]; ++e)
      ++w.column_start[std::min(inverse[g.row[e]], inverse[j]) + 1];
  for (int k = 0; k < n; ++k) w.column_start[k + 1] += w.column_start[k];
  const int entries = w.column_start[n];
  w.column_row.resize(entries);
  w.column_entry.resize(entries);
  w.fill.assign(w.column_start.begin(), w.column_start.end() - 1);
  for (int j = 0; j < n; ++j)
    for (int e = g.col_start[j]; e < g.col_start[j + 1]; ++e) {
      const int a = inverse[g.row[e]], b = inverse[j];
      const int at = w.fill[std::min(a, b)]++;
      w.column_row[at] = std::max(a, b);
      w.column_entry[at] = e;
    }

  w.owner.resize(n);  // the supernode of each column
  for (int s = 0; s < ns; ++s) std::fill(w.owner.begin() + L.super[s], w.owner.begin() + L.super[s + 1], s);
  w.map.resize(n);
  w.head.assign(ns, -1);  // supernodes waiting to update s, linked through next
  w.next.assign(ns, -1);
  w.position.assign(ns, 0);  // row of each waiting supernode from which it updates the next
  w.update.resize(std::max<long>(L.max_update, 1));
  int max_rows = 0;
  for (int s = 0; s < ns; ++s) max_rows = std::max(max_rows, L.pi[s + 1] - L.pi[s]);
  w.relative.resize(max_rows);

  for (int s = 0; s < ns; ++s) {
    const int k1 = L.super[s], k2 = L.super[s + 1], nscol = k2 - k1;
    const int* srows = L.rows + L.pi[s];
    const int nsrow = L.pi[s + 1] - L.pi[s];
    double* ls = values + L.px[s];
    for (int i = 0; i < nsrow; ++i) w.map[srows[i]] = i;
    std::fill(ls, ls + static_cast<long>(nsrow) * nscol, 0.0);
    for (int k = k1; k < k2; ++k) {
      double* column = ls + static_cast<long>(k - k1) * nsrow;
      for (int e = w.column_start[k]; e < w.column_start[k + 1]; ++e)
        column[w.map[w.column_row[e]]] += g.value[w.column_entry[e]];
    }
    // The updates of the supernodes whose rows reach into s's columns.
    for (int d = w.head[s]; d >= 0;) {
      const int next = w.next[d];
      const int* drows = L.rows + L.pi[d];
      const int ndrow = L.pi[d + 1] - L.pi[d], ndcol = L.super[d + 1] - L.super[d];
      const int first = w.position[d];
      int last = first;  // rows first..last-1 of d lie in s's columns
      while (last < ndrow && drows[last] < k2) ++last;
      const int rows = ndrow - first, cols = last - first;
      if (static_cast<std::size_t>(rows) * cols > w.update.size())
        w.update.resize(static_cast<std::size_t>(rows) * cols);
      double* c = w.update.data();
      update_block(values + L.px[d] + first, ndrow, rows, cols, ndcol, c);
      for (int i = 0; i < rows; ++i) w.relative[i] = w.map[drows[first + i]];
      for (int j = 0; j < cols; ++j) {
        double* target = ls + static_cast<long>(w.relative[j]) * nsrow;
        const double* cj = c + static_cast<long>(j) * rows;
        for (int i = j; i < rows; ++i) target[w.relative[i]] -= cj[i];
      }
      w.position[d] = last;
      if (last < ndrow) {  // d goes on to the supernode of its next row
        const int t = w.owner[drows[last]];
        w.next[d] = w.head[t];
        w.head[t] = d;
      }
      d = next;
    }
    int info = 0;
    dpotrf_("L", &nscol, ls, &nsrow, &info, 1);
    if (info != 0) return k1 + info - 1;
    const int below = nsrow - nscol;
    if (below > 0) {
      const double one = 1;
      dtrsm_("R", "L", "T", "N", &below, &nscol, &one, ls, &nsrow, ls + nscol, &nsrow, 1, 1, 1, 1);
      w.position[s] = nscol;
      const int t = w.owner[srows[nscol]];
      w.next[s] = w.head[t];
      w.head[t] = s;
    }
  }
  return -1;
}

}  // namespace pfv
