// The mpshade binary's operator new (app/large_allocations.cpp), linked into this test
// executable as into the binary.
#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>
#include <new>
#include <vector>

#include <gtest/gtest.h>

namespace {

#if defined(__SANITIZE_ADDRESS__)
constexpr bool kReplaced = false;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr bool kReplaced = false;
#else
constexpr bool kReplaced = true;
#endif
#else
constexpr bool kReplaced = true;
#endif

constexpr size_t kHugePage = size_t{2} << 20;

TEST(LargeAllocations, BlocksFromOneMebibyteAreHugePageAligned) {
    if (!kReplaced) GTEST_SKIP() << "AddressSanitizer keeps its own operator new";
    // At the threshold and past it (a size that is not a multiple of 2 MiB rounds up: the
    // whole block is writable), as scalar, array and vector storage.
    for (size_t bytes : {size_t{1} << 20, (size_t{1} << 20) + 1, size_t{9} << 20}) {
        std::unique_ptr<char[]> block(new char[bytes]);
        EXPECT_EQ(reinterpret_cast<uintptr_t>(block.get()) % kHugePage, 0u) << bytes;
        std::memset(block.get(), 1, bytes);
        void* raw = ::operator new(bytes);
        EXPECT_EQ(reinterpret_cast<uintptr_t>(raw) % kHugePage, 0u) << bytes;
        ::operator delete(raw);
    }
    std::vector<float> samples(size_t{1} << 18);  // 1 MiB
    EXPECT_EQ(reinterpret_cast<uintptr_t>(samples.data()) % kHugePage, 0u);
}

TEST(LargeAllocations, SmallAndImpossibleRequestsBehaveAsTheStandardSays) {
    // Below the threshold: the ordinary allocator (16-byte alignment), zero bytes a unique
    // pointer; an impossible size throws bad_alloc, or is null without throwing.
    void* a = ::operator new(0);
    void* b = ::operator new(0);
    EXPECT_NE(a, nullptr);
    EXPECT_NE(a, b);
    ::operator delete(a);
    ::operator delete(b);
    std::unique_ptr<int[]> small(new int[1000]);
    EXPECT_EQ(reinterpret_cast<uintptr_t>(small.get()) % alignof(std::max_align_t), 0u);
    // Near SIZE_MAX, where rounding up to whole huge pages would wrap to a small block;
    // volatile, so the compiler does not reject the constant. AddressSanitizer's own
    // operator new reports such a request and aborts instead of throwing.
    if (!kReplaced) return;
    volatile size_t hugeRequest = std::numeric_limits<size_t>::max() - 1000;
    const size_t huge = hugeRequest;
    EXPECT_THROW(::operator delete(::operator new(huge)), std::bad_alloc);
    EXPECT_EQ(::operator new(huge, std::nothrow), nullptr);
    EXPECT_EQ(::operator new[](huge, std::nothrow), nullptr);
}

}  // namespace
