// Faulting in fresh memory on another CPU while its owner computes: the first write to a page
// the process has never used costs a page fault and the kernel's clearing of the page, which on
// virtual machines runs far below memory bandwidth (doc/benchmarks.md, "Start-up"). The first
// Cholesky factor of an engine is written supernode by supernode while the factorisation's
// arithmetic dominates, so a helper thread that asks the kernel to populate the block ahead of
// it (madvise MADV_POPULATE_WRITE, which never changes what a page holds) takes the faults off
// the factorising thread. It adds no arithmetic: the same pages are cleared once either way.
#pragma once
#include <atomic>
#include <cstddef>
#include <thread>

namespace pfv {

class PagePrefault {
 public:
  PagePrefault() = default;
  ~PagePrefault() { stop(); }
  PagePrefault(const PagePrefault&) = delete;
  PagePrefault& operator=(const PagePrefault&) = delete;

  // Starts populating [begin, begin + bytes) from its start, in chunks, unless the process may
  // run on one CPU only (the helper would then take turns with the owner, gaining nothing), the
  // kernel lacks MADV_POPULATE_WRITE, or no thread can be started: the owner's own writes then
  // fault the pages in as usual. Stops a populating helper first.
  void start(void* begin, std::size_t bytes);
  // Stops the helper after its current chunk and joins it; the pages not reached are faulted in
  // by whoever writes them. Call before the block is freed.
  void stop();
  // Joins the helper once it has populated the whole block.
  void wait();
  // Whether a helper was started by the last start() (for tests).
  bool started() const { return started_; }

 private:
  std::thread helper_;
  std::atomic<bool> stop_{false};
  bool started_ = false;
};

}  // namespace pfv
