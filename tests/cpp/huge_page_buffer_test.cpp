// HugePageBuffer: 2 MB aligned, rounded up, movable; release_pages gives back whole pages only.
#include "huge_page_buffer.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdint>
#include <cstring>
#include <utility>

namespace pfv {
namespace {

constexpr std::size_t kHuge = std::size_t{1} << 21;

TEST(HugePageBuffer, IsAlignedRoundedUpAndWritable) {
  HugePageBuffer b(3 * kHuge + 5);
  ASSERT_NE(b.data(), nullptr);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(b.data()) % kHuge, 0u);
  EXPECT_EQ(b.size(), 4 * kHuge);
  auto* d = static_cast<double*>(b.data());
  const std::size_t n = b.size() / sizeof(double);
  for (std::size_t i = 0; i < n; ++i) d[i] = static_cast<double>(i);
  double sum = 0;
  for (std::size_t i = 0; i < n; ++i) sum += d[i];
  EXPECT_EQ(sum, 0.5 * static_cast<double>(n) * static_cast<double>(n - 1));
  EXPECT_EQ(HugePageBuffer(0).data(), nullptr);
}

TEST(HugePageBuffer, MovesOwnership) {
  HugePageBuffer a(kHuge);
  void* p = a.data();
  static_cast<char*>(p)[7] = 42;
  HugePageBuffer b(std::move(a));
  EXPECT_EQ(a.data(), nullptr);
  EXPECT_EQ(a.size(), 0u);
  EXPECT_EQ(b.data(), p);
  HugePageBuffer c;
  c = std::move(b);
  EXPECT_EQ(c.data(), p);
  EXPECT_EQ(static_cast<char*>(c.data())[7], 42);
}

TEST(ReleasePages, ZeroesWholePagesInsideTheRangeOnly) {
  const std::size_t page = static_cast<std::size_t>(sysconf(_SC_PAGESIZE));
  HugePageBuffer b(kHuge);
  auto* bytes = static_cast<unsigned char*>(b.data());
  std::memset(bytes, 0xAB, b.size());
  // From the middle of page 1 to the middle of page 5: pages 2, 3, 4 go back.
  release_pages(bytes + page + page / 2, bytes + 5 * page + page / 2);
  for (std::size_t k = 0; k < 7; ++k) {
    const bool released = k >= 2 && k <= 4;
    EXPECT_EQ(bytes[k * page], released ? 0 : 0xAB) << "page " << k;
    EXPECT_EQ(bytes[k * page + page - 1], released ? 0 : 0xAB) << "page " << k;
  }
  release_pages(bytes + page, bytes + page);  // empty range: nothing happens
  EXPECT_EQ(bytes[page], 0xAB);
}

}  // namespace
}  // namespace pfv
