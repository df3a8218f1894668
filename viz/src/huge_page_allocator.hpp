// Internal: huge pages for big buffers. An allocator for the per-view sort buffers (tens of MB, reused from
// view to view) that asks Linux for transparent huge pages. The first-level scatter writes at thousands of
// places a few kB to MB apart at once; with 4 kB pages nearly every write is a TLB miss once the buffer
// outgrows the TLB's reach (a few MB), with 2 MB pages none is. Small buffers use the plain heap.
#pragma once

#include <cstddef>
#include <cstdlib>
#include <memory>
#include <new>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace foxi {

template <class T>
struct HugePageAllocator {
  using value_type = T;
  static constexpr std::size_t kPage = std::size_t(1) << 21;

  HugePageAllocator() = default;
  template <class U>
  HugePageAllocator(const HugePageAllocator<U>&) noexcept {}

  T* allocate(std::size_t n) {
    if (n > std::size_t(-1) / sizeof(T) - kPage) throw std::bad_alloc();
    const std::size_t bytes = n * sizeof(T);
    if (bytes < kPage) return std::allocator<T>().allocate(n);
    const std::size_t rounded = (bytes + kPage - 1) / kPage * kPage;
    void* p = std::aligned_alloc(kPage, rounded);
    if (p == nullptr) throw std::bad_alloc();
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    madvise(p, rounded, MADV_HUGEPAGE);  // advice only: without it the buffer still works
#endif
    return static_cast<T*>(p);
  }
  void deallocate(T* p, std::size_t n) noexcept {
    if (n * sizeof(T) < kPage)
      std::allocator<T>().deallocate(p, n);
    else
      std::free(p);
  }
  template <class U>
  bool operator==(const HugePageAllocator<U>&) const noexcept {
    return true;
  }
};

// Asks for transparent huge pages on the 2 MB pages inside [p, p + bytes), for a buffer not yet
// touched (e.g. a std::vector after reserve(), before resize()): the per-mesh tables that a view
// reads at random places (a near tie's centre) then cost no TLB miss each. Advice only.
inline void advise_huge_pages(void* p, std::size_t bytes) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  constexpr std::size_t kPage = std::size_t(1) << 21;
  const std::size_t begin = (reinterpret_cast<std::size_t>(p) + kPage - 1) / kPage * kPage;
  const std::size_t end = (reinterpret_cast<std::size_t>(p) + bytes) / kPage * kPage;
  if (end > begin) madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
#else
  (void)p;
  (void)bytes;
#endif
}

}  // namespace foxi
