#include "common/alloc_counter.hpp"

#include "common/allocation_hook.hpp"

#ifdef FEM_ALLOC_COUNTER_DISABLED

namespace fem::alloc {
bool enabled() { return false; }
Counts counts() { return {}; }
}  // namespace fem::alloc

#else

#include <atomic>
#include <cerrno>
#include <cstddef>
#include <cstdlib>
#include <new>

// glibc's own entry points, which its public malloc & co forward to.
extern "C" {
void* __libc_malloc(std::size_t size);
void* __libc_calloc(std::size_t count, std::size_t size);
void* __libc_realloc(void* ptr, std::size_t size);
void __libc_free(void* ptr);
void* __libc_memalign(std::size_t alignment, std::size_t size);
}

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

void* counted_memalign(std::size_t alignment, std::size_t size) {
  count_allocation(size);
  return __libc_memalign(alignment, size);
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
  return __libc_malloc(size);
}

void* calloc(std::size_t count, std::size_t size) {
  count_allocation(count * size);
  return __libc_calloc(count, size);
}

void* realloc(void* ptr, std::size_t size) {
  if (size != 0) count_allocation(size);  // realloc(p, 0) frees
  if (size == 0) count_deallocation(ptr);
  return __libc_realloc(ptr, size);
}

void free(void* ptr) {
  count_deallocation(ptr);
  __libc_free(ptr);
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
