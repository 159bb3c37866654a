#include "pfv/linalg/system_io.hpp"

#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace pfv {
namespace {

std::ofstream open_out(const std::string& path) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error("cannot write " + path);
  out.precision(17);
  return out;
}

void write_array(const std::string& path, const std::vector<double>& v) {
  std::ofstream out = open_out(path);
  out << "%%MatrixMarket matrix array real general\n" << v.size() << " 1\n";
  for (double x : v) out << x << '\n';
  if (!out) throw std::runtime_error("cannot write " + path);
}

std::ifstream open_in(const std::string& path, const char* header) {
  std::ifstream in(path);
  std::string line;
  if (!in || !std::getline(in, line) || line.rfind(header, 0) != 0)
    throw std::runtime_error(path + " is missing or not a Matrix Market file of the kind '" + header + "'");
  while (in.peek() == '%') std::getline(in, line);
  return in;
}

std::vector<double> read_array(const std::string& path, int first, int count) {
  std::ifstream in = open_in(path, "%%MatrixMarket matrix array real general");
  long long rows = 0, columns = 0;
  if (!(in >> rows >> columns) || columns != 1 || first + count > rows)
    throw std::runtime_error(path + ": not a column of at least " + std::to_string(first + count) + " values");
  std::vector<double> v(count);
  double x = 0;
  for (long long i = 0; i < first + count; ++i) {
    if (!(in >> x)) throw std::runtime_error(path + ": ends before value " + std::to_string(i));
    if (i >= first) v[i - first] = x;
  }
  return v;
}

}  // namespace

void write_system(const std::string& folder, const SymmetricMatrix& s, const std::vector<double>& b,
                  const std::vector<double>& x) {
  const int n = s.size();
  if (static_cast<int>(b.size()) != n || static_cast<int>(x.size()) != n)
    throw std::invalid_argument("write_system needs one value of b and x per unknown");
  {
    std::ofstream out = open_out(folder + "/G.mtx");
    out << "%%MatrixMarket matrix coordinate real symmetric\n"
        << "% the pressure system G p = b of a PFV engine (lower triangle)\n"
        << n << ' ' << n << ' ' << s.value.size() << '\n';
    // Stored as the upper triangle by column: entry (i <= j) of column j is (j, i) of the lower.
    for (int j = 0; j < n; ++j)
      for (int e = s.col_start[j]; e < s.col_start[j + 1]; ++e)
        out << j + 1 << ' ' << s.row[e] + 1 << ' ' << s.value[e] << '\n';
    if (!out) throw std::runtime_error("cannot write " + folder + "/G.mtx");
  }
  write_array(folder + "/b.mtx", b);
  write_array(folder + "/x.mtx", x);
}

long long saved_system_size(const std::string& folder) {
  std::ifstream in = open_in(folder + "/G.mtx", "%%MatrixMarket matrix coordinate real symmetric");
  long long rows = 0, columns = 0, entries = 0;
  if (!(in >> rows >> columns >> entries) || rows != columns || rows <= 0)
    throw std::runtime_error(folder + "/G.mtx: not a square matrix");
  return rows;
}

SavedRows read_system_rows(const std::string& folder, int first, int count) {
  const std::string path = folder + "/G.mtx";
  std::ifstream in = open_in(path, "%%MatrixMarket matrix coordinate real symmetric");
  long long n = 0, columns = 0, entries = 0;
  if (!(in >> n >> columns >> entries) || n != columns || first < 0 || count <= 0 || first + count > n)
    throw std::runtime_error(path + ": not a square matrix holding rows " + std::to_string(first) + ".." +
                             std::to_string(first + count - 1));
  // Both triangles of the rows asked for: (i, j) and its mirror (j, i).
  std::vector<std::vector<std::pair<int, double>>> row(count);
  for (long long k = 0; k < entries; ++k) {
    long long i = 0, j = 0;
    double v = 0;
    if (!(in >> i >> j >> v) || i < 1 || j < 1 || i > n || j > n)
      throw std::runtime_error(path + ": malformed entry " + std::to_string(k));
    --i, --j;
    if (i >= first && i < first + count) row[i - first].emplace_back(static_cast<int>(j), v);
    if (i != j && j >= first && j < first + count) row[j - first].emplace_back(static_cast<int>(i), v);
  }
  SavedRows out;
  out.rows.global_rows = n;
  out.rows.first_row = first;
  out.rows.row_start.assign(1, 0);
  for (const auto& r : row) {
    for (const auto& [j, v] : r) {
      out.rows.column.push_back(j);
      out.rows.value.push_back(v);
    }
    out.rows.row_start.push_back(static_cast<int>(out.rows.column.size()));
  }
  out.b = read_array(folder + "/b.mtx", first, count);
  out.x = read_array(folder + "/x.mtx", first, count);
  return out;
}

}  // namespace pfv
