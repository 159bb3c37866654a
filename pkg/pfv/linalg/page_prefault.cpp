#include "pfv/linalg/page_prefault.hpp"

#include <sched.h>
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <system_error>

namespace pfv {

namespace {

bool more_than_one_cpu() {
  cpu_set_t set;
  CPU_ZERO(&set);
  return sched_getaffinity(0, sizeof set, &set) == 0 && CPU_COUNT(&set) > 1;
}

}  // namespace

void PagePrefault::start(void* begin, std::size_t bytes) {
  stop();
  started_ = false;
#ifdef MADV_POPULATE_WRITE
  const auto page = static_cast<std::uintptr_t>(sysconf(_SC_PAGESIZE));
  // madvise takes page-aligned ranges: the whole pages inside the block.
  const std::uintptr_t first = (reinterpret_cast<std::uintptr_t>(begin) + page - 1) / page * page;
  const std::uintptr_t end = (reinterpret_cast<std::uintptr_t>(begin) + bytes) / page * page;
  if (end <= first || !more_than_one_cpu()) return;
  stop_.store(false);
  try {
    helper_ = std::thread([this, first, end] {
      // Chunks of 16 MB: a stop request is seen soon, and each call stays short.
      constexpr std::uintptr_t kChunk = std::uintptr_t{16} << 20;
      for (std::uintptr_t at = first; at < end && !stop_.load(std::memory_order_relaxed); at += kChunk)
        if (madvise(reinterpret_cast<void*>(at), std::min(kChunk, end - at), MADV_POPULATE_WRITE) != 0)
          return;  // an older kernel (EINVAL) or no memory (ENOMEM): the owner's writes fault as usual
    });
    started_ = true;
  } catch (const std::system_error&) {
    // no thread: nothing is populated ahead
  }
#else
  (void)begin;
  (void)bytes;
#endif
}

void PagePrefault::stop() {
  stop_.store(true);
  wait();
}

void PagePrefault::wait() {
  if (helper_.joinable()) helper_.join();
}

}  // namespace pfv
