// G by rows in a fixed width (ELLPACK), copied from its upper triangle by column
// (symmetric_matrix.hpp): row u's off-diagonal entries in slots u * width .. (u + 1) * width - 1,
// padded with (u, 0), and its diagonal apart. A pore cell has at most four neighbours, so the
// width is 4 on a tetrahedral mesh, and each entry of G x is a gather of its row, where the
// upper triangle by column needs a scattered read-modify-write for the lower half: the residual
// of every refinement pass (refinement.hpp) and the Gauss-Seidel sweep read it.
#pragma once
#include <vector>

#include "pfv/linalg/symmetric_matrix.hpp"

namespace pfv {

struct MatrixRows {
  int width = 0;
  std::vector<int> column;
  std::vector<double> value, diagonal;

  bool empty() const { return diagonal.empty(); }
};

MatrixRows index_rows(const SymmetricMatrix& g);

}  // namespace pfv
