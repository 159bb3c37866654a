#include "pfv/linalg/distributed_rows.hpp"

namespace pfv {

DistributedRows full_rows(const SymmetricMatrix& g) {
  const int n = g.size();
  DistributedRows rows;
  rows.global_rows = n;
  rows.row_start.assign(n + 1, 0);
  for (int j = 0; j < n; ++j)
    for (int e = g.col_start[j]; e < g.col_start[j + 1]; ++e) {
      ++rows.row_start[g.row[e] + 1];
      if (g.row[e] != j) ++rows.row_start[j + 1];
    }
  for (int i = 0; i < n; ++i) rows.row_start[i + 1] += rows.row_start[i];
  rows.column.resize(rows.row_start[n]);
  rows.value.resize(rows.row_start[n]);
  std::vector<int> next(rows.row_start.begin(), rows.row_start.end() - 1);
  // Entry (i, j <= i) of a column j is written to rows i and j (hypre sorts no columns and
  // needs none sorted).
  for (int j = 0; j < n; ++j)
    for (int e = g.col_start[j]; e < g.col_start[j + 1]; ++e) {
      const int i = g.row[e];
      rows.column[next[i]] = j;
      rows.value[next[i]++] = g.value[e];
      if (i != j) {
        rows.column[next[j]] = i;
        rows.value[next[j]++] = g.value[e];
      }
    }
  return rows;
}

}  // namespace pfv
