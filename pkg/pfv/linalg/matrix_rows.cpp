#include "pfv/linalg/matrix_rows.hpp"

#include <algorithm>
#include <cstddef>

namespace pfv {

MatrixRows index_rows(const SymmetricMatrix& g) {
  const int n = g.size();
  MatrixRows r;
  std::vector<int> count(n, 0);
  for (int j = 0; j < n; ++j)
    for (int e = g.col_start[j]; e < g.col_start[j + 1]; ++e)
      if (g.row[e] != j) {
        ++count[j];
        ++count[g.row[e]];
      }
  const int w = n > 0 ? *std::max_element(count.begin(), count.end()) : 0;
  r.width = w;
  r.column.resize(static_cast<std::size_t>(n) * w);
  r.value.assign(static_cast<std::size_t>(n) * w, 0.0);
  r.diagonal.assign(n, 0.0);
  for (int u = 0; u < n; ++u) std::fill_n(r.column.begin() + static_cast<std::size_t>(u) * w, w, u);
  std::fill(count.begin(), count.end(), 0);
  for (int j = 0; j < n; ++j)
    for (int e = g.col_start[j]; e < g.col_start[j + 1]; ++e) {
      const int i = g.row[e];
      if (i == j) {
        r.diagonal[j] += g.value[e];
        continue;
      }
      const std::size_t a = static_cast<std::size_t>(j) * w + count[j]++,
                        b = static_cast<std::size_t>(i) * w + count[i]++;
      r.column[a] = i;
      r.value[a] = g.value[e];
      r.column[b] = j;
      r.value[b] = g.value[e];
    }
  return r;
}

}  // namespace pfv
