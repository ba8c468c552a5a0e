#pragma once
// A std::vector whose resize leaves trivial elements uninitialized: for buffers that a parallel
// loop fills right after, where the serial zeroing of a plain vector's resize would be the
// loop's most expensive part on many threads (millions of entries written twice, once on one
// thread). Elements of a class type are default-constructed as usual.
#include <memory>
#include <type_traits>
#include <utility>
#include <vector>

namespace yarnhom {

template <class T>
struct DefaultInitAllocator : std::allocator<T> {
  template <class U>
  struct rebind {
    using other = DefaultInitAllocator<U>;
  };
  using std::allocator<T>::allocator;
  template <class U>
  void construct(U* p) noexcept(std::is_nothrow_default_constructible_v<U>) {
    ::new (static_cast<void*>(p)) U;  // default-initialization: nothing for a trivial U
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};

template <class T>
using RawVector = std::vector<T, DefaultInitAllocator<T>>;

}  // namespace yarnhom
