#include "common/alloc_counter.hpp"

#include "common/allocation_hook.hpp"

#ifdef FEM_ALLOC_COUNTER_DISABLED

namespace fem::alloc {
bool enabled() { return false; }
Counts counts() { return {}; }
}  // namespace fem::alloc

#else

#include <dlfcn.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <new>

namespace {

// Plain atomics with relaxed order: a count, not a synchronization. They are constant
// initialized, so they work for allocations made before main().
std::atomic<long long> g_allocations{0};
std::atomic<long long> g_deallocations{0};
std::atomic<long long> g_bytes{0};
std::atomic<long long> g_new_calls{0};

void count_allocation(std::size_t size) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  g_bytes.fetch_add(static_cast<long long>(size), std::memory_order_relaxed);
}

void count_deallocation(const void* ptr) {
  if (ptr) g_deallocations.fetch_add(1, std::memory_order_relaxed);
}

// The C library's own allocator, the next definition after ours: dlsym(RTLD_NEXT) finds it on
// glibc, musl and macOS alike (glibc's __libc_malloc & co exist on glibc only). dlsym may
// itself allocate while it looks them up; those few allocations (and any other thread's at that
// moment) come from a static arena, never given back.
using MallocFn = void* (*)(std::size_t);
using CallocFn = void* (*)(std::size_t, std::size_t);
using ReallocFn = void* (*)(void*, std::size_t);
using FreeFn = void (*)(void*);
using PosixMemalignFn = int (*)(void**, std::size_t, std::size_t);

struct Real {
  MallocFn malloc = nullptr;
  CallocFn calloc = nullptr;
  ReallocFn realloc = nullptr;
  FreeFn free = nullptr;
  PosixMemalignFn posix_memalign = nullptr;
};
Real g_real;
std::atomic<int> g_state{0};  // 0: not looked up, 1: being looked up, 2: g_real is ready

// The arena: each block starts with a header holding its size (realloc copies that much).
constexpr std::size_t kArenaBytes = 1 << 16;
constexpr std::size_t kHeader = 64;  // keeps every block aligned to 64 bytes
alignas(64) unsigned char g_arena[kArenaBytes];
std::atomic<std::size_t> g_arena_used{0};

bool in_arena(const void* p) {
  const auto* c = static_cast<const unsigned char*>(p);
  return c >= g_arena && c < g_arena + kArenaBytes;
}

void* arena_alloc(std::size_t size, std::size_t alignment) {
  const std::size_t a = std::max<std::size_t>(alignment, kHeader);
  const std::size_t need = (size + kHeader + a - 1) / a * a + a;
  const std::size_t start = g_arena_used.fetch_add(need, std::memory_order_relaxed);
  if (start + need > kArenaBytes) return nullptr;
  const auto base = reinterpret_cast<std::uintptr_t>(g_arena + start + kHeader);
  unsigned char* p = reinterpret_cast<unsigned char*>((base + a - 1) / a * a);
  std::memcpy(p - sizeof(std::size_t), &size, sizeof(std::size_t));
  return p;  // zeroed: the arena is static and never reused, so calloc may take it as it is
}

std::size_t arena_size(const void* p) {
  std::size_t size = 0;
  std::memcpy(&size, static_cast<const unsigned char*>(p) - sizeof(std::size_t), sizeof(size));
  return size;
}

template <class Fn>
Fn next_symbol(const char* name) {
  void* symbol = dlsym(RTLD_NEXT, name);
  if (!symbol) {
    std::fprintf(stderr, "fem_alloc_counter: the C library's %s was not found (dlsym)\n", name);
    std::abort();
  }
  return reinterpret_cast<Fn>(symbol);
}

// Whether g_real can be used; false while the lookup runs (the arena then serves).
bool real_ready() {
  int state = g_state.load(std::memory_order_acquire);
  if (state == 2) return true;
  if (state == 1 || !g_state.compare_exchange_strong(state, 1, std::memory_order_acq_rel))
    return g_state.load(std::memory_order_acquire) == 2;
  g_real.malloc = next_symbol<MallocFn>("malloc");
  g_real.calloc = next_symbol<CallocFn>("calloc");
  g_real.realloc = next_symbol<ReallocFn>("realloc");
  g_real.free = next_symbol<FreeFn>("free");
  g_real.posix_memalign = next_symbol<PosixMemalignFn>("posix_memalign");
  g_state.store(2, std::memory_order_release);
  return true;
}

void* real_memalign(std::size_t alignment, std::size_t size) {
  if (!real_ready()) return arena_alloc(size, alignment);
  void* p = nullptr;
  const std::size_t a = std::max(alignment, sizeof(void*));
  return g_real.posix_memalign(&p, a, size) == 0 ? p : nullptr;
}

void* counted_memalign(std::size_t alignment, std::size_t size) {
  count_allocation(size);
  return real_memalign(alignment, size);
}

// operator new counts as one allocation (through malloc) and one new_call.
void* counted_new(std::size_t size) {
  g_new_calls.fetch_add(1, std::memory_order_relaxed);
  if (size == 0) size = 1;
  void* p = std::malloc(size);
  if (!p) throw std::bad_alloc();
  return p;
}

void* counted_new_aligned(std::size_t size, std::size_t alignment) {
  g_new_calls.fetch_add(1, std::memory_order_relaxed);
  if (size == 0) size = 1;
  void* p = counted_memalign(alignment, size);
  if (!p) throw std::bad_alloc();
  return p;
}

long long allocation_count() { return g_allocations.load(std::memory_order_relaxed); }

// Per-phase counts in the step profile read the counter through this hook.
const bool g_hook_installed = (fem::allocation_count_hook = &allocation_count, true);

}  // namespace

extern "C" {

void* malloc(std::size_t size) {
  count_allocation(size);
  return real_ready() ? g_real.malloc(size) : arena_alloc(size, 1);
}

void* calloc(std::size_t count, std::size_t size) {
  count_allocation(count * size);
  return real_ready() ? g_real.calloc(count, size) : arena_alloc(count * size, 1);
}

void* realloc(void* ptr, std::size_t size) {
  if (size != 0) count_allocation(size);  // realloc(p, 0) frees
  if (size == 0) count_deallocation(ptr);
  if (ptr && in_arena(ptr)) {  // the arena's blocks move out, their bytes copied
    void* moved = real_ready() ? g_real.malloc(size) : arena_alloc(size, 1);
    if (moved) std::memcpy(moved, ptr, std::min(size, arena_size(ptr)));
    return moved;
  }
  return real_ready() ? g_real.realloc(ptr, size) : arena_alloc(size, 1);
}

void free(void* ptr) {
  count_deallocation(ptr);
  if (ptr && !in_arena(ptr) && real_ready()) g_real.free(ptr);
}

int posix_memalign(void** out, std::size_t alignment, std::size_t size) {
  if (alignment % sizeof(void*) != 0 || (alignment & (alignment - 1)) != 0) return EINVAL;
  void* p = counted_memalign(alignment, size);
  if (!p) return ENOMEM;
  *out = p;
  return 0;
}

void* aligned_alloc(std::size_t alignment, std::size_t size) {
  return counted_memalign(alignment, size);
}

void* memalign(std::size_t alignment, std::size_t size) {
  return counted_memalign(alignment, size);
}

}  // extern "C"

void* operator new(std::size_t size) { return counted_new(size); }
void* operator new[](std::size_t size) { return counted_new(size); }
void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
  try {
    return counted_new(size);
  } catch (...) {
    return nullptr;
  }
}
void* operator new[](std::size_t size, const std::nothrow_t&) noexcept {
  try {
    return counted_new(size);
  } catch (...) {
    return nullptr;
  }
}
void* operator new(std::size_t size, std::align_val_t alignment) {
  return counted_new_aligned(size, static_cast<std::size_t>(alignment));
}
void* operator new[](std::size_t size, std::align_val_t alignment) {
  return counted_new_aligned(size, static_cast<std::size_t>(alignment));
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }

namespace fem::alloc {

bool enabled() { return g_hook_installed; }

Counts counts() {
  return {g_allocations.load(std::memory_order_relaxed),
          g_deallocations.load(std::memory_order_relaxed), g_bytes.load(std::memory_order_relaxed),
          g_new_calls.load(std::memory_order_relaxed)};
}

}  // namespace fem::alloc

#endif
