// The mpshade binary's operator new (linked into the executable only, not mpshade_app): a
// block of 1 MiB or more -- a frame's visibility buffer, sample arrays, shading points, the
// sample layout's tables -- is 2 MiB-aligned, rounded up to whole 2 MiB and advised for
// transparent huge pages, so its first touch faults once per 2 MiB rather than once per
// 4 KiB. Most Linux systems run THP in "madvise" mode, where memory not advised stays in
// small pages; on a virtual machine each fault is dearer still. Those first touches were
// most of a run's first frame: a warm gallery's first frame took 11.7 k page faults and
// 0.18-0.20 s with a 4 MiB threshold, 8.1 k and 0.15 s with this one (the same peak
// resident size), and a warm vase's whole sequence 1.28-1.33x its steady frames with no
// huge pages at all (docs/store.md has the figures). A block between 1 and 2 MiB may
// occupy a whole huge page: few blocks are that size, and none is per shading point.
//
// Blocks come from aligned_alloc and every operator delete ends in free(), which takes
// both. Left out under AddressSanitizer, which checks that what operator new returned is
// released by operator delete and must see its own allocator here.
#include <sys/mman.h>

#include <cstddef>
#include <cstdlib>
#include <new>

#if defined(__SANITIZE_ADDRESS__)
#define MPSHADE_HUGE_PAGE_NEW 0
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define MPSHADE_HUGE_PAGE_NEW 0
#endif
#endif
#ifndef MPSHADE_HUGE_PAGE_NEW
#define MPSHADE_HUGE_PAGE_NEW 1
#endif

#if MPSHADE_HUGE_PAGE_NEW

namespace {

constexpr std::size_t kHugePage = std::size_t{2} << 20;
constexpr std::size_t kLarge = std::size_t{1} << 20;

void* allocate(std::size_t bytes) noexcept {
    if (bytes < kLarge) return std::malloc(bytes > 0 ? bytes : 1);
    const std::size_t rounded = (bytes + kHugePage - 1) / kHugePage * kHugePage;
    if (rounded < bytes) return nullptr;  // wrapped: no such block
    void* p = std::aligned_alloc(kHugePage, rounded);
#ifdef MADV_HUGEPAGE
    if (p) madvise(p, rounded, MADV_HUGEPAGE);  // advice only: ignored where unsupported
#endif
    return p;
}

// The standard's loop: the new-handler may free memory and let the allocation retry.
void* allocateOrThrow(std::size_t bytes) {
    for (;;) {
        if (void* p = allocate(bytes)) return p;
        std::new_handler handler = std::get_new_handler();
        if (!handler) throw std::bad_alloc();
        handler();
    }
}

}  // namespace

void* operator new(std::size_t bytes) {
    return allocateOrThrow(bytes);
}

void* operator new[](std::size_t bytes) {
    return allocateOrThrow(bytes);
}

void* operator new(std::size_t bytes, const std::nothrow_t&) noexcept {
    try {
        return allocateOrThrow(bytes);
    } catch (...) {
        return nullptr;
    }
}

void* operator new[](std::size_t bytes, const std::nothrow_t&) noexcept {
    try {
        return allocateOrThrow(bytes);
    } catch (...) {
        return nullptr;
    }
}

#endif
