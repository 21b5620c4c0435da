#pragma once
// A prefetch hint the compiler keeps. GCC treats __builtin_prefetch as free of effects and, at
// -O3, deletes a loop whose only work is prefetching (the cell-head rows and the lookahead's
// member walks were compiled to nothing); an asm statement is kept wherever it is reached.
namespace shaker::md {

[[gnu::always_inline]] inline void prefetch(const void* address) {
#if defined(__x86_64__) || defined(__i386__)
  asm volatile("prefetcht0 %0" : : "m"(*static_cast<const char*>(address)));
#else
  __builtin_prefetch(address);
#endif
}

}  // namespace shaker::md
