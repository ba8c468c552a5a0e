// core/heap_policy.hpp: with glibc, a large block comes from the heap (not a private mapping
// that free hands back to the kernel) and stays in the process after free.
#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>

#include "core/heap_policy.hpp"

#if defined(__GLIBC__)
#include <malloc.h>
#endif

TEST(HeapPolicy, LargeBlocksAreReusedNotReturnedToTheKernel) {
#if !defined(__GLIBC__)
  GTEST_SKIP() << "glibc only";
#else
  ASSERT_TRUE(yarnhom::retain_freed_memory());
  const size_t bytes = size_t(64) << 20;  // above glibc's largest mmap threshold (32 MB)
  const struct mallinfo2 before = mallinfo2();
  char* p = static_cast<char*>(std::malloc(bytes));
  ASSERT_NE(p, nullptr);
  std::memset(p, 1, bytes);
  const struct mallinfo2 during = mallinfo2();
  EXPECT_EQ(during.hblkhd, before.hblkhd) << "the block was mapped on its own";
  // The heap grows by the block, less the free memory it already held at its top (earlier tests').
  EXPECT_GE(during.arena + before.fordblks, before.arena + bytes);
  std::free(p);
  const struct mallinfo2 after = mallinfo2();
  EXPECT_GE(after.arena, during.arena) << "the heap was trimmed";
  EXPECT_GE(after.fordblks, bytes) << "the freed block is kept for reuse";
#endif
}
