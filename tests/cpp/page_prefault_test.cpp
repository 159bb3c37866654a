// The helper that faults in a fresh block on another CPU (page_prefault.hpp): it populates every
// page, changes no byte, whatever the owner writes meanwhile, and a factor whose storage it
// populated while the factorisation ran solves exactly as one factorised in reused storage.
#include <gtest/gtest.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#include "pfv/linalg/cholmod_solver.hpp"
#include "pfv/linalg/page_prefault.hpp"
#include "test_matrices.hpp"

using namespace pfv;

namespace {

// A fresh anonymous mapping (no page present until touched), unmapped on destruction.
struct Mapping {
  explicit Mapping(std::size_t n) : bytes(n) {
    void* p = mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    data = p == MAP_FAILED ? nullptr : static_cast<unsigned char*>(p);
  }
  ~Mapping() {
    if (data) munmap(data, bytes);
  }
  Mapping(const Mapping&) = delete;
  Mapping& operator=(const Mapping&) = delete;
  std::size_t resident_pages() const {
    const std::size_t page = sysconf(_SC_PAGESIZE);
    std::vector<unsigned char> in((bytes + page - 1) / page);
    if (mincore(data, bytes, in.data()) != 0) return 0;
    std::size_t n = 0;
    for (unsigned char c : in) n += c & 1;
    return n;
  }
  std::size_t bytes;
  unsigned char* data;
};

bool kernel_populates() {
  Mapping probe(sysconf(_SC_PAGESIZE));
  return probe.data && madvise(probe.data, probe.bytes, MADV_POPULATE_WRITE) == 0;
}

}  // namespace

TEST(PagePrefault, PopulatesEveryPageAndChangesNoByte) {
  if (!kernel_populates()) GTEST_SKIP() << "the kernel has no MADV_POPULATE_WRITE";
  const std::size_t page = sysconf(_SC_PAGESIZE);
  Mapping m(std::size_t{40} << 20);
  ASSERT_NE(m.data, nullptr);
  for (std::size_t at = 0; at < m.bytes; at += std::size_t{1} << 20) m.data[at + 7] = 0x5a;  // a few pages written
  const std::size_t before = m.resident_pages();
  ASSERT_LT(before, m.bytes / page / 10);
  PagePrefault prefault;
  prefault.start(m.data, m.bytes);
  if (!prefault.started()) GTEST_SKIP() << "one CPU only: no helper";
  prefault.wait();
  EXPECT_EQ(m.resident_pages(), m.bytes / page);
  for (std::size_t at = 0; at < m.bytes; ++at) {
    const unsigned char expected = at % (std::size_t{1} << 20) == 7 ? 0x5a : 0;
    ASSERT_EQ(m.data[at], expected) << "byte " << at;
  }
}

TEST(PagePrefault, TheOwnersConcurrentWritesSurvive) {
  Mapping m(std::size_t{64} << 20);
  ASSERT_NE(m.data, nullptr);
  auto* v = reinterpret_cast<std::uint64_t*>(m.data);
  const std::size_t n = m.bytes / sizeof(std::uint64_t);
  PagePrefault prefault;
  prefault.start(m.data, m.bytes);
  for (std::size_t i = 0; i < n; ++i) v[i] = i * 0x9e3779b97f4a7c15ull;  // races the helper page by page
  prefault.stop();
  for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(v[i], i * 0x9e3779b97f4a7c15ull) << "entry " << i;
}

TEST(PagePrefault, AnEmptyRangeStartsNothingAndStopIsIdempotent) {
  PagePrefault prefault;
  unsigned char byte = 0;
  prefault.start(&byte, 1);  // no whole page inside
  EXPECT_FALSE(prefault.started());
  prefault.stop();
  prefault.stop();
  prefault.wait();
}

// A factor of more than 8 MB: its first factorisation runs with the helper populating the fresh
// storage; factorising again reuses that storage without one. Both solve alike, bit for bit.
TEST(PagePrefault, AFactorInPopulatedStorageSolvesAsInReusedStorage) {
  const SymmetricMatrix s = *test::grid_laplacian(26, 24, 22);
  CholmodSolver solver;
  solver.factorize(s, Ordering::kAmd);
  ASSERT_GE(solver.value_capacity() * sizeof(double), std::size_t{8} << 20) << "the factor must take the helper";
  std::vector<double> b(s.size()), first, second;
  for (int i = 0; i < s.size(); ++i) b[i] = std::cos(0.11 * i);
  solver.solve(b, first);
  const std::size_t capacity = solver.value_capacity();
  solver.factorize(s, Ordering::kAmd);
  EXPECT_EQ(solver.value_capacity(), capacity);  // the same block, no helper this time
  solver.solve(b, second);
  EXPECT_EQ(first, second);
  double largest = 0;
  for (double x : first) largest = std::max(largest, std::abs(x));
  EXPECT_GT(largest, 0);
}
