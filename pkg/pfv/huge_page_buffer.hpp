// Memory for an array streamed end to end at every step (the Cholesky factor's values), asked
// of the kernel in 2 MB pages (transparent huge pages, madvise mode on Debian): a sweep over
// 48 MB then touches 24 pages instead of 12 288, and on this VM streaming 48 MB forwards and
// back after an eviction took 6.3 instead of 8.7 ms (development measurement; the project
// scripts' numbers are in doc/benchmarks.md). Where the kernel refuses, the memory is ordinary
// pages and works the same, only without the gain.
#pragma once
#include <cstddef>

namespace pfv {

class HugePageBuffer {
 public:
  HugePageBuffer() = default;
  // At least `bytes` bytes, 2 MB aligned, not yet touched; throws std::bad_alloc.
  explicit HugePageBuffer(std::size_t bytes);
  ~HugePageBuffer();
  HugePageBuffer(HugePageBuffer&& other) noexcept;
  HugePageBuffer& operator=(HugePageBuffer&& other) noexcept;
  HugePageBuffer(const HugePageBuffer&) = delete;
  HugePageBuffer& operator=(const HugePageBuffer&) = delete;

  void* data() const { return data_; }
  std::size_t size() const { return size_; }
  bool huge_pages_advised() const { return advised_; }  // the kernel accepted MADV_HUGEPAGE

 private:
  void* data_ = nullptr;
  std::size_t size_ = 0;
  bool advised_ = false;
};

// Hands the whole pages inside [begin, end) back to the kernel; reading them afterwards gives
// zeros. For an array whose contents have been copied elsewhere and that will be rewritten
// before it is read again, so that the copy does not double the memory at its peak.
void release_pages(void* begin, void* end);

}  // namespace pfv
